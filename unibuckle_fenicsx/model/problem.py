r"""A set-up buckling problem: pencil and eigen solver, and with an obstacle its contacts.

:class:`Problem` holds the pencil and its eigen solver; :class:`UnilateralProblem` adds
the contact manager of the obstacles.

:func:`~unibuckle_fenicsx.model.build.build_problem` makes one from a problem's
description, stage by stage. What the algorithms work on is a :class:`UnilateralProblem`;
its primitive is :meth:`UnilateralProblem.evaluate`: the smallest eigenpair of the pencil
with a candidate contact set Z removed, returned as a :class:`Candidate` that owns its
mode, oriented towards the admissible side of the obstacle, with its values and contact
forces at the constrained nodes. Nothing here keeps a "current" mode: whoever holds a
candidate holds its mode.

The discrete critical state (:doc:`/methods/problem`): the smallest :math:`\lambda` and
:math:`u \ne 0` with :math:`u_k \le 0` on the constrained nodes I, :math:`r = Au -
\lambda Bu = 0` off the contact set Z, :math:`u_k < 0` on :math:`I \setminus Z`,
:math:`r_k \le 0` on Z, and :math:`\lambda` the smallest eigenvalue of the pencil with Z
removed (paper, Lemma 5.1).
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.errors import EigenSolveError, InputError, NoLoadError
from unibuckle_fenicsx.la.eigen import EigenPair, GEPSolver, SmallestProof
from unibuckle_fenicsx.la.factor import abs_matrix
from unibuckle_fenicsx.la.options import pop_run_options
from unibuckle_fenicsx.la.ownership import Owner, release
from unibuckle_fenicsx.model.contact import ContactSetManager, orientation
from unibuckle_fenicsx.model.materials import reference_bending_stiffness
from unibuckle_fenicsx.model.prestress import Prestress
from unibuckle_fenicsx.model.structure import StructuralModel
from unibuckle_fenicsx.spec import ProblemSpec, temperature_field
from unibuckle_fenicsx.tolerances import FREE_CHECK_RESOLUTION, SMALLEST_RTOL_FACTOR

__all__ = ["Candidate", "Mode", "Problem", "SetUp", "UnilateralProblem", "require_obstacle"]


def _cooling_hint(spec: ProblemSpec) -> str:
    """A clause naming ``load.temperature`` when the scaled rise cools the plate, or ""."""
    if not spec.load.thermal:
        return ""
    T0, gx, gy = temperature_field(spec.load.temperature)
    if max(T0 + gx * x + gy * y for x, y in spec.plate.boundary) > 0.0:
        return ""
    return (
        f"; load.temperature = {spec.load.temperature!r} K per unit load is a cooling "
        "(no rise > 0 anywhere): it puts a plate held in its plane in tension, which no "
        "positive load factor buckles; give a rise (load.temperature > 0)"
    )


@dataclass(frozen=True)
class Mode:
    r"""The smallest eigenpair of the pencil without obstacle (the free plate).

    Attributes:
        load: :math:`\lambda_{free}`.
        function: The mode (w, theta), scaled to max |w| = 1.
        eigen: SLEPc's report.
    """

    load: float
    function: dolfinx.fem.Function
    eigen: EigenPair


@dataclass(frozen=True)
class Candidate:
    r"""The smallest eigenpair of the pencil with the contact set ``active`` removed.

    Built by :meth:`UnilateralProblem.evaluate` (or :meth:`UnilateralProblem.candidate` for
    a mode from elsewhere, e.g. the penalty method). The candidate owns its mode.

    Attributes:
        active: Sorted node numbers of the contact set Z.
        load: :math:`\lambda(Z)` (``inf`` when no geometric stiffness is left).
        mode: The mode (w, theta), oriented (see
            :func:`~unibuckle_fenicsx.model.contact.orientation`) and scaled to max |w| = 1.
        values: The mode at the constrained nodes (max |w| = 1 over the plate).
        forces: :math:`r = Au - \lambda Bu` at the constrained nodes, relative to
            :math:`\|Au\|_\infty` (positive: the node pulls the obstacle).
        margin: Largest value on :math:`I \setminus Z` (``-inf`` if Z = I); negative
            when the mode lies strictly below the obstacle there.
        feasible: :math:`u_k \le \tau` on every constrained node.
        max_force: Largest force on Z (``-inf`` if Z is empty).
        tau: The tolerance used.
        eigen: SLEPc's report (None for a mode not computed by an eigen solve).
    """

    active: npt.NDArray[np.int64]
    load: float
    mode: dolfinx.fem.Function
    values: npt.NDArray[np.float64]
    forces: npt.NDArray[np.float64]
    margin: float
    feasible: bool
    max_force: float
    tau: float
    eigen: EigenPair | None = None

    @property
    def kkt(self) -> bool:
        r"""Feasible and the obstacle only pushes: :math:`r_k \le \tau` on Z."""
        return self.feasible and self.max_force <= self.tau

    def key(self) -> bytes:
        """Hashable identity of the contact set."""
        return self.active.tobytes()


@dataclass(frozen=True)
class SetUp:
    """The parts of a set-up problem (:func:`~unibuckle_fenicsx.model.build.build_problem`).

    Attributes:
        spec: The problem (its plate's edges tagged, a mesh file's corners its bounding
            box).
        comm: Communicator of the mesh.
        mesh: The quadrilateral mesh.
        facet_tags: Its edge markers.
        structured: The structured rectangle of ``spec.mesh`` (coarser copies exist).
        custom_mesh: The mesh came from the user (no coarse copies can be made).
        prestress: Membrane force per unit load.
        fixed_prestress: The fixed part of the load (applied as is), or None.
        model: The structural model: its forms and the pencil (A, B).
        eigensolver: The :class:`~unibuckle_fenicsx.la.eigen.GEPSolver` of the pencil.
        run_options: What the run's EPS options put in PETSc's options database
            (:func:`~unibuckle_fenicsx.la.options.push_run_options`).
        timings: Seconds per set-up stage.
        estimate: Estimates of the pencil's lowest eigenvalues for the free solve's shift
            (:func:`~unibuckle_fenicsx.model.build.free_estimate`; () if none), made
            when first asked for. Collective.
    """

    spec: ProblemSpec
    comm: MPI.Comm
    mesh: dolfinx.mesh.Mesh
    facet_tags: dolfinx.mesh.MeshTags
    structured: bool
    custom_mesh: bool
    prestress: Prestress
    fixed_prestress: Prestress | None
    model: StructuralModel
    eigensolver: GEPSolver
    run_options: list[tuple[str, str]]
    timings: dict[str, float]
    estimate: Callable[[], tuple[float, ...]] = tuple


class Problem(Owner):
    """A problem set up for its solves: mesh, prestress, pencil and eigen solver.

    Made by :func:`~unibuckle_fenicsx.model.build.build_problem` (without an obstacle;
    with one it makes a :class:`UnilateralProblem`). The problem owns every PETSc object
    of its parts (:class:`SetUp`, whose fields it has as attributes); :meth:`destroy`
    takes back the run's options from PETSc's options database too.

    Attributes:
        free: The free mode, once :meth:`solve_free` has run.
        tau: The relative feasibility tolerance (``spec.solver.tau``).

    Note:
        :meth:`destroy` is collective on ``comm``; the problem is a context manager that
        destroys itself on exit.
    """

    def __init__(self, parts: SetUp) -> None:
        self.spec = parts.spec
        self.comm = parts.comm
        self.mesh, self.facet_tags = parts.mesh, parts.facet_tags
        self.structured, self.custom_mesh = parts.structured, parts.custom_mesh
        self.prestress, self.fixed_prestress = parts.prestress, parts.fixed_prestress
        self.model = parts.model
        self.eigensolver = parts.eigensolver
        self._estimate = parts.estimate
        self._run_options = parts.run_options
        # Taking the options back is local to the process (not collective, unlike
        # destroy): a problem discarded without destroy() does it when collected.
        weakref.finalize(self, pop_run_options, self._run_options)
        self.timings = parts.timings
        self.free: Mode | None = None
        #: Why the free pair is the smallest, if its solve proved it (:meth:`solve_free`).
        self.free_proof: SmallestProof | None = None
        #: Eigen solves the free pair took (:meth:`solve_free`): more than one when shifts
        #: were tried, or after a failed solve (the spectral radius, the shifted solve).
        self.free_solves = 0
        self._free_verified = False  # the free pair was proven the smallest
        self._r: PETSc.Vec | None = None  # work vectors of residual()
        self._Bu: PETSc.Vec | None = None
        self._abs_A: PETSc.Mat | None = None  # abs_pencil(), made when needed
        self._abs_B: PETSc.Mat | None = None
        self.tau = parts.spec.solver.tau
        self._w_owned = self._owned_deflections()

    def _owned_deflections(self) -> npt.NDArray[np.int32]:
        """Local DOFs of the deflection owned by this rank (what :meth:`max_abs_w` reads)."""
        n_owned_w = self.model.Vw.dofmap.index_map.size_local
        return self.model.w_dofs[:n_owned_w]

    # -- primitives ----------------------------------------------------------------
    @property
    def tensionless(self) -> bool:
        """Whether the contact nodes carry a tensionless foundation (none here)."""
        return False

    @property
    def num_constrained(self) -> int:
        """i, the number of constrained nodes (none here)."""
        return 0

    @property
    def owned_w_dofs(self) -> npt.NDArray[np.int32]:
        """Local W DOFs of the deflection w owned by this rank."""
        return self._w_owned

    def new_mode(self, name: str = "mode") -> dolfinx.fem.Function:
        """A zero function on the (w, theta) space."""
        return dolfinx.fem.Function(self.model.W, name=name)

    def max_abs_w(self, u: PETSc.Vec) -> float:
        """Max |w| over the plate of the W-vector ``u`` (collective)."""
        arr = u.array_r
        local = float(np.abs(arr[self._w_owned]).max()) if self._w_owned.size else 0.0
        return float(self.comm.allreduce(local, op=MPI.MAX))

    def solve_free(self) -> Mode:
        """Smallest eigenpair without obstacle (computed once, then ``free``).

        Where the set-up can make an estimate of the pencil's lowest eigenvalues (a
        coarser mesh's: :func:`~unibuckle_fenicsx.model.build.free_estimate`), it sets
        the eigen solve's shift, and the inertia of its one factorisation proves the pair
        the smallest (:meth:`~unibuckle_fenicsx.la.eigen.GEPSolver.smallest`;
        ``free_proof``). Otherwise (or if no shift proves it) the solve runs at
        target 0 and :meth:`verify_free` checks the pair when it matters.

        Raises:
            NoLoadError: The pencil has no positive eigenvalue (no load buckles the
                plate on this mesh).

        Note:
            Collective.
        """
        if self.free is None:
            u = self.new_mode("free_mode")
            solves = self.eigensolver.solves
            pair, self.free_proof = self.eigensolver.smallest(
                out=u.x.petsc_vec, estimate=self._estimate()
            )
            self.free_solves = self.eigensolver.solves - solves
            self._free_verified = self.free_proof is not None
            if not np.isfinite(pair.value):
                raise NoLoadError(
                    "the plate has no positive buckling load on this mesh: the geometric "
                    "stiffness b(w, w) is nowhere positive on the free deflections (edge "
                    "loads in tension, or the supports fix every deflection DOF); check the "
                    "edge loads, refine the mesh or free an edge" + _cooling_hint(self.spec)
                )
            u.x.petsc_vec.scale(1.0 / self.max_abs_w(u.x.petsc_vec))
            u.x.scatter_forward()
            self.free = Mode(pair.value, u, pair)
        return self.free

    def verify_free(self) -> None:
        r"""Check that the free pair is the pencil's smallest eigenpair (once per problem).

        SLEPc returns the pair nearest its target; with loose options (a tolerance of
        1e-1 and three basis vectors) it stopped on a pair 18 % above the smallest, and
        the free load is a lower bound of the critical load (interlacing). The inertia
        of :math:`A - \sigma B`, :math:`\sigma` just below :math:`\lambda_{free}` (one
        :math:`LDL^T` through the shared factorisation), counts the eigenvalues in
        :math:`(0, \sigma)` (Sylvester's law, A SPD): there must be none. A free pair
        that its shifted solve proved the smallest (``free_proof``) needs nothing
        more. A count within rounding of the load says nothing, and which way it falls
        depends on the partition: the margin is widened to twice the load's
        :meth:`load_resolution` where that is larger, and a load fixed more loosely
        than ``FREE_CHECK_RESOLUTION`` (:mod:`~unibuckle_fenicsx.tolerances`) is
        refused before the count, alike on any number of ranks.

        Raises:
            EigenSolveError: An eigenvalue lies below the free load, or the load's
                rounding bound exceeds what the check resolves (a plate too thin).

        Note:
            Collective.
        """
        free = self.solve_free()
        if self._free_verified:
            return
        # A plate so thin against its width that double precision fixes its load more
        # loosely than the count's margin (b/t of about 1e6) makes the count rounding,
        # which differs with the partition: the rounding bound, not the count, decides
        # (the same on any number of ranks), before the count.
        resolution = self.load_resolution(free.function.x.petsc_vec, free.load)
        if resolution > FREE_CHECK_RESOLUTION:
            thicken = float(np.sqrt(resolution / FREE_CHECK_RESOLUTION))  # (b/t)^2
            raise EigenSolveError(
                "the free load cannot be checked the pencil's smallest: double precision "
                f"fixes it only to {resolution:.2g} of it "
                f"(load_resolution), above the {FREE_CHECK_RESOLUTION:g} the inertia check "
                f"resolves: the plate (plate.thickness = {self.spec.plate.thickness:g} m; "
                "a section's wall, section.thickness) is too thin against its width for "
                f"its stiffness to keep the digits; make it about {thicken:.2g} times "
                "thicker (the bound grows as (b/t)^2)"
            )
        margin = max(SMALLEST_RTOL_FACTOR * self.spec.solver.eps_tol, 2.0 * resolution)
        sigma = free.load * (1.0 - margin)
        # Negative pivots only (the reduced pencils' check in the certificate reads the
        # inertia alike).
        below = self.eigensolver.count_below(sigma)
        if below:
            raise EigenSolveError(
                f"the free eigen solve returned lambda = {free.load!r}, but {below} "
                f"eigenvalue(s) of the pencil lie below it (inertia of A - sigma B, sigma "
                f"{margin:.2g} below it): the eigen solver stopped on a higher pair; its "
                "options (-unibuckle_eps_tol, -unibuckle_eps_ncv, ...) are too loose"
            )
        self._free_verified = True

    def residual(self, load: float, u: PETSc.Vec) -> tuple[PETSc.Vec, float, float]:
        r"""Residual :math:`r = A u - \lambda B u` with the edge-constrained pencil.

        Args:
            load: :math:`\lambda`.
            u: W-vector.

        Returns:
            r in a work vector owned by the problem (valid until the next call), and
            :math:`\|Au\|_\infty`, :math:`\|Au\|_2` for scaling.

        Note:
            Collective.
        """
        if self._r is None:
            self._r, self._Bu = u.duplicate(), u.duplicate()
        if self._Bu is None:
            raise RuntimeError("residual: expected self._Bu is not None (an internal invariant)")
        self.model.A.mult(u, self._r)
        au_inf = self._r.norm(PETSc.NormType.INFINITY)  # type: ignore[arg-type]
        au_2 = self._r.norm()
        self.model.B.mult(u, self._Bu)
        self._r.axpy(-load, self._Bu)
        return self._r, float(au_inf), float(au_2)  # type: ignore[arg-type]

    def load_resolution(self, u: PETSc.Vec, load: float) -> float:
        r"""How closely double precision fixes ``load``, the eigenvalue of the mode ``u``.

        A backward-stable solve perturbs A by :math:`|E| \le \epsilon |A|`, which moves
        the eigenvalue by up to :math:`\epsilon\,|u|^T|A||u| / u^TBu` (first-order
        perturbation of a generalised eigenvalue); returned relative to ``load``. On a
        thin plate :math:`|A||u| \gg |Au|` (the shear stiffness): 1e-9 to 1e-8, and the
        digits of a load beyond it are rounding (two solves of one contact set at
        different shifts agree to it, not to the last bit).

        Note:
            Collective.
        """
        if self._abs_A is None:  # |B| is not needed here
            self._abs_A = abs_matrix(self.model.A)
        abs_A = self._abs_A
        size, product = u.duplicate(), u.duplicate()
        size.array[:] = np.abs(u.array_r)
        abs_A.mult(size, product)
        stiffness = float(size.dot(product).real)
        self.model.B.mult(u, product)
        geometric = float(u.dot(product).real)
        for vec in (size, product):
            vec.destroy()
        return float(np.finfo(float).eps * stiffness / (geometric * load))

    def abs_pencil(self) -> tuple[PETSc.Mat, PETSc.Mat]:
        """:math:`|A|` and :math:`|B|` entrywise (rounding bounds), made once and kept.

        Shared by :meth:`load_resolution` and the interior-point method's residual floor;
        A and B are not changed after set-up. Owned by the problem. Collective.
        """
        if self._abs_A is None:
            self._abs_A = abs_matrix(self.model.A)
        if self._abs_B is None:
            self._abs_B = abs_matrix(self.model.B)
        return self._abs_A, self._abs_B

    # -- reporting ------------------------------------------------------------------
    def buckling_coefficient(self, load: float) -> float:
        r""":math:`k = \sigma t b^2/(\pi^2 D)` at the load factor ``load`` (:math:`\lambda`).

        :math:`\sigma = \lambda\sigma_1`, :math:`\sigma_1` the largest compressive normal
        edge stress per unit load (or, without one, the largest shear stress) and b the
        width it acts across (``PlateSpec.reference_load``);
        the fixed stresses are not in it. D is :math:`\sqrt{D_{11}D_{22}}` of the bending
        stiffness (an isotropic plate's D).
        """
        plate, mat = self.spec.plate, self.spec.material
        D = reference_bending_stiffness(mat, plate.thickness)
        stress, b = plate.reference_load()
        return plate.thickness * (stress * load) * b**2 / (np.pi**2 * D)

    def destroy(self) -> None:
        """Destroy the PETSc/SLEPc objects (collective) and take back the run's options."""
        release(self, "_r", "_Bu", "_abs_A", "_abs_B")
        pop_run_options(getattr(self, "_run_options", []))
        for name in ("_eigensolver", "_model"):  # absent when the constructor failed early
            owner = self.__dict__.get(name)
            if owner is not None:
                owner.destroy()
        self._destroyed = True

    @property
    def model(self) -> StructuralModel:
        """The plate's forms and matrices (A, B); an error once destroyed."""
        return self._live("_model")

    @model.setter
    def model(self, value: StructuralModel) -> None:
        self._model = value

    @property
    def eigensolver(self) -> GEPSolver:
        """The pencil's eigen solver; an error once destroyed."""
        return self._live("_eigensolver")

    @eigensolver.setter
    def eigensolver(self, value: GEPSolver) -> None:
        self._eigensolver = value

    def _live(self, name: str) -> Any:
        # A destroyed PETSc object used again can end the process (SEGV, MPI_Abort):
        # refuse with a clear error instead.
        if self.__dict__.get("_destroyed"):
            raise RuntimeError(
                "this problem was destroyed (its with block, or solve()'s, has "
                "ended, or destroy() was called): its PETSc objects are gone; use it "
                "inside the with block (the Analysis' result, mode and certificate stay "
                "usable after it)"
            )
        try:
            return self.__dict__[name]
        except KeyError:
            raise AttributeError(f"the problem has no {name.lstrip('_')} yet") from None


class UnilateralProblem(Problem):
    """A problem with one-sided obstacles or tensionless foundations: its contact manager.

    What every unilateral algorithm and certificate works on.

    Args:
        parts: Those of :class:`Problem`.
        contact: The :class:`~unibuckle_fenicsx.model.contact.ContactSetManager` of the
            constrained nodes (owned by the problem; it holds no PETSc object).
    """

    def __init__(self, parts: SetUp, contact: ContactSetManager) -> None:
        super().__init__(parts)
        self.contact = contact

    @property
    def tensionless(self) -> bool:
        """Whether the contact nodes carry a tensionless foundation (springs), not obstacles."""
        return self.contact.stiffness is not None

    @property
    def num_constrained(self) -> int:
        """i, the number of constrained nodes."""
        return self.contact.size

    def evaluate(
        self,
        active: npt.NDArray[np.int64],
        initial: PETSc.Vec | None = None,
        near: float | None = None,
    ) -> Candidate:
        """Smallest eigenpair with the nodes ``active`` removed, as a :class:`Candidate`.

        Args:
            active: Contact set Z (node numbers, any order).
            initial: Optional start vector of the eigen solve (e.g. a previous mode).
            near: Optional estimate of the load (e.g. that of the state Z is read
                from): the eigen solve shifts just below it
                (:meth:`~unibuckle_fenicsx.la.eigen.GEPSolver.solve`).

        The empty set is the free plate's pencil: its candidate is made from
        :meth:`solve_free`'s pair (solved once; the same load to the last bit, so a
        bracket on the free load closes), whatever ``initial`` and ``near`` say.

        Note:
            Collective; ``active`` must be the same on every rank.
        """
        active = np.unique(np.asarray(active, dtype=np.int64))
        u = self.new_mode()
        if not active.size:
            free = self.solve_free()
            free.function.x.petsc_vec.copy(u.x.petsc_vec)
            u.x.scatter_forward()
            return self.candidate(u, free.load, active, eigen=free.eigen)
        pair = self.eigensolver.solve(
            self.contact.removed_rows(active), out=u.x.petsc_vec, initial=initial, near=near
        )
        return self.candidate(u, pair.value, active, eigen=pair)

    def candidate(
        self,
        u: dolfinx.fem.Function,
        load: float,
        active: npt.NDArray[np.int64],
        *,
        eigen: EigenPair | None = None,
        sign: float | None = None,
    ) -> Candidate:
        r"""Make ``u`` a :class:`Candidate`: orient, scale, values and forces at I.

        The one place where a mode's orientation, feasibility and contact forces are
        computed. ``u`` is modified in place (scaled to max |w| = 1, oriented) and
        becomes the candidate's mode.

        Args:
            u: A mode (the candidate takes ownership).
            load: Its load (an eigenvalue, or a Rayleigh quotient).
            active: Sorted contact set Z claimed for it.
            eigen: SLEPc's report, if ``u`` is an eigenvector.
            sign: Orientation to apply instead of
                :func:`~unibuckle_fenicsx.model.contact.orientation`'s.

        Note:
            Collective.
        """
        n = self.contact.size
        vec = u.x.petsc_vec
        if not np.isfinite(load):
            zeros = np.zeros(n)
            return Candidate(active, load, u, zeros, zeros, np.inf, False, np.inf, self.tau, eigen)
        scale = self.max_abs_w(vec)
        values = self.contact.values(vec) / scale
        r, au_inf, _ = self.residual(load, vec)
        forces = self.contact.values(r) / au_inf
        if sign is None:
            sign = orientation(values, forces, active, self.tau)
        vec.scale(sign / scale)
        u.x.scatter_forward()
        values, forces = sign * values, sign * forces
        free = np.ones(n, dtype=bool)
        free[active] = False
        margin = float(values[free].max()) if free.any() else -np.inf
        max_force = float(forces[active].max()) if active.size else -np.inf
        feasible = bool(values.max() <= self.tau)
        return Candidate(
            active, float(load), u, values, forces, margin, feasible, max_force, self.tau, eigen
        )


def require_obstacle(problem: object, who: str) -> None:
    """Refuse a ``problem`` that is not a :class:`UnilateralProblem` (an algorithm's entry).

    Raises:
        InputError: ``who`` needs a problem with an obstacle, and ``problem`` has none.
    """
    if not isinstance(problem, UnilateralProblem):
        raise InputError(f"{who} needs a problem with an obstacle (this one has none)")
