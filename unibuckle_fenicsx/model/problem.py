r"""A set-up buckling problem: mesh, prestress, pencil, eigen solver and contact manager.

:class:`BucklingProblem` is what the algorithms work on. Its primitive is
:meth:`BucklingProblem.evaluate`: the smallest eigenpair of the pencil with a candidate
contact set Z removed, returned as a :class:`Candidate` that owns its mode, oriented
towards the admissible side of the obstacle, with its values and contact forces at the
constrained nodes. Nothing here keeps a "current" mode: whoever holds a candidate holds
its mode.

The discrete critical state (:doc:`/methods/problem`): the smallest :math:`\lambda` and
:math:`u \ne 0` with :math:`u_k \le 0` on the constrained nodes I, :math:`r = Au -
\lambda Bu = 0` off the contact set Z, :math:`u_k < 0` on :math:`I \setminus Z`,
:math:`r_k \le 0` on Z, and :math:`\lambda` the smallest eigenvalue of the pencil with Z
removed (paper, Lemma 5.1).
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import Any

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx

import numpy as np
import numpy.typing as npt
from msgspec.structs import replace

from unibuckle_fenicsx.eigen import (
    EIGEN_OPTIONS,
    EigenPair,
    EigenSolveError,
    GEPSolver,
    Owner,
    SmallestProof,
    SymmetricFactorization,
    abs_matrix,
    lowest_eigenvalues,
    pop_run_options,
    push_run_options,
    release,
)
from unibuckle_fenicsx.errors import InputError, NumericalError
from unibuckle_fenicsx.model.contact import (
    BilateralZoneError,
    ContactSetManager,
    EmptyZoneError,
    check_zone_has_nodes,
    foundation_springs,
    orientation,
)
from unibuckle_fenicsx.model.materials import reference_bending_stiffness
from unibuckle_fenicsx.model.mesh import build_plate_mesh, check_user_mesh
from unibuckle_fenicsx.model.plate.model import PlateModel
from unibuckle_fenicsx.model.points import one_sided_conflicts, point_obstacles
from unibuckle_fenicsx.model.prestress import solve_prestress
from unibuckle_fenicsx.spec import ProblemSpec, temperature_field
from unibuckle_fenicsx.tolerances import SMALLEST_RTOL_FACTOR

__all__ = ["BYTES_PER_DOF", "BucklingProblem", "Candidate", "Mode", "available_memory"]

logger = logging.getLogger(__name__)

#: Options prefix of the LDL^T that checks A - B_fixed (``-unibuckle_fixed_ksp_view``).
FIXED_LOAD_PREFIX = "unibuckle_fixed_"
#: Options prefix of the coarse mesh's eigen solve that estimates the free load.
ESTIMATE_PREFIX = "unibuckle_estimate_"

#: The free solve's shift comes from the plate on a mesh this many times coarser along
#: each side (a sixteenth of the DOFs; its load lies within a few tenths of a percent
#: of the fine one on a mesh that resolves the mode).
FREE_ESTIMATE_COARSENING = 4
#: Meshes of at least this many (w, theta) DOFs get a coarse estimate of their free load:
#: from there the estimate and the shifted solve cost less than the solve at target 0
#: and its check (measured: at 5 673 DOFs 0.076 against 0.091 s, at 2 583 0.050 against
#: 0.033 s; :doc:`/verification/floor`).
FREE_ESTIMATE_DOFS = 5_000
#: ... and whose coarse mesh keeps at least this many cells across (a structured one:
#: with fewer the coarse load lies tens of percent off and the shifts miss).
FREE_ESTIMATE_CELLS = 6

#: Peak memory per (w, theta) DOF of a solve, measured with MUMPS on one rank: 7.8 kB at
#: 155k DOFs, 5.8 kB at 617k (:doc:`/guide/mpi`); the estimate uses 8 kB.
BYTES_PER_DOF = 8000


def available_memory() -> int | None:
    """Bytes of memory available to new processes (Linux ``MemAvailable``), or None."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def _check_memory(spec: ProblemSpec, comm: MPI.Comm) -> None:
    """Refuse a mesh whose estimated memory exceeds what the machine has (collective).

    A plate meshed by gmsh is estimated at 3 DOFs per h^2 of its area (a file: not).
    """
    plate = spec.plate
    if plate.file is not None:
        return
    if plate.meshed_by_gmsh:
        if spec.mesh.size is None:
            raise RuntimeError(
                "_check_memory: expected spec.mesh.size is not None (an internal invariant)"
            )
        dofs = int(3 * plate.area / spec.mesh.size**2)
        what = f"mesh.size = {spec.mesh.size:g} m on {plate.area:.3g} m^2 gives about"
    else:
        dofs = spec.mesh.num_dofs
        what = f"mesh.nx x mesh.ny = {spec.mesh.nx} x {spec.mesh.ny} gives"
    need = BYTES_PER_DOF * dofs
    free = available_memory()
    have = comm.allreduce(free if free is not None else -1, op=MPI.MIN)
    if have > 0 and need > have:
        raise InputError(
            f"{what} {dofs:,} DOFs, which need about {need / 1e9:.3g} GB "
            f"({BYTES_PER_DOF / 1000:.0f} kB per DOF), more than the {have / 1e9:.3g} GB "
            "available: use a coarser mesh or more machines"
        )


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


def _points_label(spec: ProblemSpec, indices: list[int]) -> str:
    """``points[k] (what)`` for each index, for messages, in the file's units."""
    return ", ".join(f"points[{k}] ({spec.points[k].describe(spec.units)})" for k in indices)


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

    Built by :meth:`BucklingProblem.evaluate` (or :meth:`BucklingProblem.candidate` for
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


class BucklingProblem(Owner):
    """Everything an algorithm needs, set up once.

    Args:
        spec: The problem.
        comm: Communicator of the mesh (``MPI.COMM_SELF`` gives each rank its own
            serial copy, for candidate-parallel enumeration).
        eps_options: Extra EPS options of the run: under the prefix ``unibuckle_`` (so
            ``eps_view`` is ``-unibuckle_eps_view``) for this pencil and the coarser
            levels' copies, and under ``unibuckle_penalty_`` and ``unibuckle_foundation_``
            for the penalty stages and the foundation
            (:data:`~unibuckle_fenicsx.eigen.RUN_EPS_PREFIXES`). The problem holds them in
            PETSc's options database until :meth:`destroy`; the command line's win.
        mesh: A quadrilateral DOLFINx mesh to use instead of ``spec.mesh`` (the
            rectangle, or gmsh's plate); ``spec.plate.corners`` must be its bounding
            box (used for tolerances and the buckling coefficient's width), and each
            edge's facet tag must mark facets of it (both checked).
        facet_tags: Edge markers of ``mesh``, matched by :class:`EdgeSpec` ``tag``.

    Attributes:
        eigensolver: The :class:`~unibuckle_fenicsx.eigen.GEPSolver` of the pencil.
        contact: The :class:`~unibuckle_fenicsx.model.contact.ContactSetManager` (None
            without obstacle).
        free: The free mode, once :meth:`solve_free` has run.

    Note:
        Construction and :meth:`destroy` are collective on ``comm``; the problem is a
        context manager that destroys itself on exit.
    """

    def __init__(
        self,
        spec: ProblemSpec,
        comm: MPI.Comm = MPI.COMM_WORLD,
        eps_options: dict[str, str | float | int] | None = None,
        *,
        mesh: dolfinx.mesh.Mesh | None = None,
        facet_tags: dolfinx.mesh.MeshTags | None = None,
    ) -> None:
        t0 = time.perf_counter()
        if spec.has_fixed_load:
            spec.check_scaled_load()
        self.spec = spec
        self.timings: dict[str, float] = {}
        #: The mesh came from the user (not spec.mesh): no coarse copies can be made.
        self.custom_mesh = mesh is not None
        #: The structured rectangle of spec.mesh (coarser copies exist: multilevel).
        self.structured = mesh is None and not spec.plate.meshed_by_gmsh
        if mesh is not None:
            if facet_tags is None:
                raise InputError(
                    "facet_tags: a user mesh needs its edge facet tags (EdgeSpec.tag, or "
                    "tags 1..4 for edges named left, right, bottom, top)"
                )
            if mesh.topology.cell_type != dolfinx.mesh.CellType.quadrilateral:
                raise InputError("mesh: the MITC plate element needs a quadrilateral mesh")
            check_user_mesh(mesh, facet_tags, spec.plate)
            self.mesh, self.facet_tags = mesh, facet_tags
            comm = mesh.comm
        else:
            _check_memory(spec, comm)
            self.mesh, self.facet_tags, plate = build_plate_mesh(
                spec.plate, spec.mesh, comm, spec.all_obstacles
            )
            # A file's edges get their tags, its corners the mesh's bounding box.
            self.spec = spec = replace(spec, plate=plate)
        self.comm = comm
        obstacles = spec.all_obstacles
        if obstacles:
            size = max(spec.plate.length, spec.plate.width)
            labels = [spec.obstacle_label(k) for k in range(len(obstacles))]
            check_zone_has_nodes(self.mesh, obstacles, size, labels)
        degree = spec.solver.prestress_degree
        self.prestress = solve_prestress(
            self.mesh,
            self.facet_tags,
            spec.plate,
            spec.material,
            degree,
            temperature=spec.load.temperature,
            plate_mesh=not self.custom_mesh,
        )
        #: The fixed part of the prestress (applied as is), or None.
        self.fixed_prestress = (
            solve_prestress(
                self.mesh,
                self.facet_tags,
                spec.plate.fixed_part(),
                spec.material,
                degree,
                temperature=spec.load.fixed_temperature,
                fixed=True,
                plate_mesh=not self.custom_mesh,
            )
            if spec.has_fixed_load
            else None
        )
        t1 = time.perf_counter()
        self.timings["prestress_s"] = t1 - t0
        self.model = PlateModel(
            self.mesh,
            self.facet_tags,
            spec.plate,
            spec.material,
            self.prestress,
            spec.solver.shear,
            points=spec.points,
            fixed_prestress=self.fixed_prestress,
            fixed_factor=spec.load.fixed_factor,
        )
        try:
            self._set_up(spec, eps_options, t1)
        except BaseException:
            self.destroy()  # collective: every rank raises (the checks agree)
            raise
        self.timings["setup_s"] = time.perf_counter() - t0

    def _set_up(
        self, spec: ProblemSpec, eps_options: dict[str, str | float | int] | None, t1: float
    ) -> None:
        """The springs, the checks, the eigen solver and the contact sets (collective)."""
        if spec.bilateral_foundations:
            self.model.add_springs(*foundation_springs(self.model, spec.bilateral_foundations))
        t2 = time.perf_counter()
        self.timings["assembly_s"] = t2 - t1
        self._check_geometric_stiffness()
        if self.fixed_prestress is not None:
            self._check_fixed_load()
        unilateral = spec.unilateral_obstacles + tuple(
            point_obstacles(self.model.points, spec.plate)
        )
        self.eigensolver = GEPSolver(
            self.model.A,
            self.model.B,
            indefinite=self.prestress.indefinite,
            tol=spec.solver.eps_tol,
            options={**EIGEN_OPTIONS, **(eps_options or {})},
            reused=bool(unilateral),  # a route's contact sets: many factorisations
        )
        try:
            self.contact = ContactSetManager(self.model, unilateral) if unilateral else None
        except EmptyZoneError as err:
            if not spec.one_sided_points:
                raise
            one_sided = [k for k, p in enumerate(spec.points) if p.kind == "one-sided"]
            raise EmptyZoneError(
                f"{_points_label(spec, one_sided)}: the one-sided points"
                + (" and the obstacle zones" if spec.unilateral_obstacles else "")
                + " act on no free node: each such node is held already (by an edge "
                "support or a bilateral point), so the point restrains nothing; move it off "
                "the support or leave it out"
            ) from err
        except BilateralZoneError as err:
            if not spec.one_sided_points:
                raise
            clash = one_sided_conflicts(self.model.points, spec.unilateral_obstacles, spec.plate)
            raise BilateralZoneError(
                f"{_points_label(spec, clash) if clash else 'points'}: a one-sided point acts "
                "on a node held from the other side too (an obstacle zone or another point): "
                'that holds w = 0, give it kind = "bilateral"'
            ) from err
        self.free: Mode | None = None
        #: Why the free pair is the smallest, if its solve proved it (:meth:`solve_free`).
        self.free_proof: SmallestProof | None = None
        self._free_verified = False  # the free pair was proven the smallest
        self._r: PETSc.Vec | None = None  # work vectors of residual()
        self._Bu: PETSc.Vec | None = None
        self._abs_A: PETSc.Mat | None = None  # abs_pencil(), made when needed
        self._abs_B: PETSc.Mat | None = None
        self.tau = spec.solver.tau
        n_owned_w = self.model.Vw.dofmap.index_map.size_local
        self._w_owned = self.model.w_dofs[:n_owned_w]
        # Last: a refused problem leaves nothing in the options database.
        self._run_options = push_run_options(eps_options)

    def _check_geometric_stiffness(self) -> None:
        """Refuse a B that is round-off (collective).

        Its entries are of the order of the membrane force |N0| (a Q1 stiffness integral
        is O(1)); at 1e-10 of it, b(w, w) vanishes identically on the free deflections,
        e.g. pure shear on a mesh with a single row of free nodes (the contributions
        above and below the row cancel), and no load buckles the plate.
        """
        scale = max(self.prestress.max_compression, self.prestress.max_tension)
        b_norm = float(self.model.B.norm(PETSc.NormType.INFINITY))
        if b_norm <= 1e-10 * scale:
            self.model.destroy()
            raise InputError(
                "the plate has no positive buckling load on this mesh: the geometric "
                f"stiffness b(w, w) vanishes on the free deflections (|B| = {b_norm:.3g} "
                f"against |N0| = {scale:.3g} N/m); refine the mesh or check the edge loads"
            )

    def _check_fixed_load(self) -> None:
        r"""Refuse a fixed load that buckles the plate by itself (collective).

        The pencil is :math:`(A - B_{fixed}, B)`; every algorithm and the certificate need
        its first matrix positive definite, which the inertia of its :math:`LDL^T`
        (MUMPS) tells: no negative and no zero pivot.
        """
        K = self.model.A.duplicate(copy=True)
        try:
            with SymmetricFactorization(K, FIXED_LOAD_PREFIX) as factor:
                negative, zero, _ = factor.inertia()
        finally:
            K.destroy()
        if negative or zero:
            self.model.destroy()
            # With an obstacle the plate may still carry such a fixed part (its unilateral
            # critical load lies higher), but the solvers and certificates here all rest
            # on a positive definite first matrix of the pencil: say so, not that it buckles.
            obstacle = (
                " without its obstacle (with it, the plate may carry this fixed part, but "
                "every solver here needs A - B_fixed positive definite, i.e. the fixed part "
                "below the free plate's critical value)"
                if self.spec.all_obstacles
                else ""
            )
            raise InputError(
                "the fixed load alone buckles the plate"
                f"{obstacle} (fixed_normal_stress, "
                "fixed_shear_stress, fixed_temperature): the stiffness less its geometric "
                f"stiffness, A - B_fixed, has {negative} negative and {zero} zero "
                "eigenvalue(s); lower the fixed part below its own critical value"
            )

    # -- primitives ----------------------------------------------------------------
    @property
    def tensionless(self) -> bool:
        """Whether the contact nodes carry a tensionless foundation (springs), not obstacles."""
        return self.contact is not None and self.contact.stiffness is not None

    @property
    def num_constrained(self) -> int:
        """i, the number of constrained nodes (0 without obstacle)."""
        return 0 if self.contact is None else self.contact.size

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

        On a mesh of at least :data:`FREE_ESTIMATE_DOFS` DOFs that can be coarsened (the
        structured rectangle, or gmsh's plate at a larger cell size), the pencil's lowest
        eigenvalues on a mesh :data:`FREE_ESTIMATE_COARSENING` times coarser set the
        eigen solve's shift, and the inertia of its one factorisation proves the pair the
        smallest (:meth:`~unibuckle_fenicsx.eigen.GEPSolver.smallest`;
        ``free_proof``). Otherwise (or if no shift proves it) the solve runs at
        target 0 and :meth:`verify_free` checks the pair when it matters.

        Note:
            Collective.
        """
        if self.free is None:
            u = self.new_mode("free_mode")
            pair, self.free_proof = self.eigensolver.smallest(
                out=u.x.petsc_vec, estimate=self._free_estimate()
            )
            self._free_verified = self.free_proof is not None
            if not np.isfinite(pair.value):
                raise InputError(
                    "the plate has no positive buckling load on this mesh: the geometric "
                    "stiffness b(w, w) is nowhere positive on the free deflections (edge "
                    "loads in tension, or the supports fix every deflection DOF); check the "
                    "edge loads, refine the mesh or free an edge" + _cooling_hint(self.spec)
                )
            u.x.petsc_vec.scale(1.0 / self.max_abs_w(u.x.petsc_vec))
            u.x.scatter_forward()
            self.free = Mode(pair.value, u, pair)
        return self.free

    def _free_estimate(self) -> tuple[float, ...]:
        """The free pencil's two lowest eigenvalues on a coarser mesh, or () if none is made.

        The plate as it is without its one-sided obstacles and points (the free pencil
        keeps the bilateral foundations and points), on a mesh
        :data:`FREE_ESTIMATE_COARSENING` times coarser; () below
        :data:`FREE_ESTIMATE_DOFS`, for a user's mesh or a file, and when the coarse
        plate is refused (a feature smaller than its cells, no buckling load there).
        Collective.
        """
        spec, k = self.spec, FREE_ESTIMATE_COARSENING
        if self.custom_mesh or int(self.model.A.getSize()[0]) < FREE_ESTIMATE_DOFS:
            return ()
        free = replace(
            spec,
            obstacle=None,
            obstacles=spec.bilateral_foundations,
            points=tuple(p for p in spec.points if p.kind != "one-sided"),
        )
        try:
            if self.structured:
                nx, ny = spec.mesh.nx // k, spec.mesh.ny // k
                if min(nx, ny) < FREE_ESTIMATE_CELLS:
                    return ()
                coarse = free.with_mesh(nx, ny)
            elif spec.plate.file is None and spec.mesh.size is not None:
                coarse = replace(free, mesh=replace(spec.mesh, size=k * spec.mesh.size))
            else:
                return ()
            with BucklingProblem(coarse, self.comm) as problem:
                return lowest_eigenvalues(problem.model.A, problem.model.B, ESTIMATE_PREFIX)
        except (InputError, NumericalError) as err:
            logger.debug("no coarse estimate of the free load: %s", err)
            return ()

    def verify_free(self) -> None:
        r"""Check that the free pair is the pencil's smallest eigenpair (once per problem).

        SLEPc returns the pair nearest its target; with loose options (a tolerance of
        1e-1 and three basis vectors) it stopped on a pair 18 % above the smallest, and
        the free load is a lower bound of the critical load (interlacing). The inertia
        of :math:`A - \sigma B`, :math:`\sigma` just below :math:`\lambda_{free}` (one
        :math:`LDL^T` through the shared factorisation), counts the eigenvalues in
        :math:`(0, \sigma)` (Sylvester's law, A SPD): there must be none. A free pair
        that its shifted solve proved the smallest (``free_proof``) needs nothing
        more.

        Raises:
            EigenSolveError: An eigenvalue lies below the free load.

        Note:
            Collective.
        """
        free = self.solve_free()
        if self._free_verified:
            return
        sigma = free.load * (1.0 - SMALLEST_RTOL_FACTOR * self.spec.solver.eps_tol)
        # Negative pivots only (the reduced pencils' check in the certificate reads the
        # inertia alike).
        below = self.eigensolver.count_below(sigma)
        if below:
            raise EigenSolveError(
                f"the free eigen solve returned lambda = {free.load!r}, but {below} "
                "eigenvalue(s) of the pencil lie below it (inertia of A - sigma B): "
                "the eigen solver stopped on a higher pair; its options "
                "(-unibuckle_eps_tol, -unibuckle_eps_ncv, ...) are too loose"
            )
        self._free_verified = True

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
                (:meth:`~unibuckle_fenicsx.eigen.GEPSolver.solve`).

        The empty set is the free plate's pencil: its candidate is made from
        :meth:`solve_free`'s pair (solved once; the same load to the last bit, so a
        bracket on the free load closes), whatever ``initial`` and ``near`` say.

        Note:
            Collective; ``active`` must be the same on every rank.
        """
        if self.contact is None:
            raise ValueError("evaluate: the problem has no obstacle (this needs an obstacle zone)")
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
        if self.contact is None:
            raise ValueError("candidate: the problem has no obstacle (this needs an obstacle zone)")
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
        r""":math:`k = N b^2/(\pi^2 D)` with N = t lambda and b the plate width (y extent).

        D is :math:`\sqrt{D_{11}D_{22}}` of the bending stiffness (an isotropic plate's D).
        """
        plate, mat = self.spec.plate, self.spec.material
        D = reference_bending_stiffness(mat, plate.thickness)
        return plate.thickness * load * plate.width**2 / (np.pi**2 * D)

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
    def model(self) -> PlateModel:
        """The plate's forms and matrices (A, B); an error once destroyed."""
        return self._live("_model")

    @model.setter
    def model(self, value: PlateModel) -> None:
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
                "this BucklingProblem was destroyed (its with block, or solve()'s, has "
                "ended, or destroy() was called): its PETSc objects are gone; use it "
                "inside the with block (the Analysis' result, mode and certificate stay "
                "usable after it)"
            )
        try:
            return self.__dict__[name]
        except KeyError:
            raise AttributeError(f"BucklingProblem has no {name.lstrip('_')} yet") from None
