"""A set-up buckling problem: mesh, prestress, pencil, eigen solver and contact manager.

:class:`BucklingProblem` is what the algorithms work on. Its primitive is
:meth:`BucklingProblem.evaluate`: the smallest eigenpair with a candidate contact set
removed, and whether that mode respects the obstacle. :meth:`BucklingProblem.certify`
checks a result against the optimality conditions of DESIGN.md section 1.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.config import ProblemSpec
from unibuckle_fenicsx.contact import ContactSetManager, check_zone_has_nodes
from unibuckle_fenicsx.eigen import EigenPair, GEPSolver
from unibuckle_fenicsx.materials import bending_stiffness
from unibuckle_fenicsx.mesh import create_plate_mesh
from unibuckle_fenicsx.plate.model import PlateModel
from unibuckle_fenicsx.prestress import solve_prestress

__all__ = ["BucklingProblem", "Candidate", "Certificate"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class Candidate:
    r"""Smallest eigenpair of the pencil with the contact set ``active`` removed.

    Attributes:
        active: Sorted node numbers of the removed (contact) set Z.
        load: :math:`\lambda(Z)` (``inf`` when no geometric stiffness is left).
        values: Mode at the constrained nodes, oriented (sign) for feasibility when
            possible, scaled by the mode's max |w| over the whole plate.
        feasible: The oriented mode satisfies w <= tau max|w| on I \ Z.
        sign: Orientation applied to the raw eigenvector (+1 or -1).
        pair: The raw SLEPc result.
    """

    active: npt.NDArray[np.int64]
    load: float
    values: npt.NDArray[np.float64]
    feasible: bool
    sign: float
    pair: EigenPair

    @property
    def violation(self) -> float:
        r"""Largest oriented value on I \ Z (relative to max|w|); <= tau when feasible."""
        free = np.ones(self.values.size, dtype=bool)
        free[self.active] = False
        return float(self.values[free].max()) if free.any() else -np.inf


@dataclass(frozen=True)
class Certificate:
    r"""Optimality conditions of DESIGN.md section 1 for a mode u and load lambda.

    Attributes:
        feasible: u_k <= tau max|w| on every constrained node.
        feasibility_margin: max over I \ Z of u_k / max|w| (negative: strictly inside).
        max_contact_force: max over Z of r_k / ||A u||_inf, r = A u - lambda B u; must be
            <= tau (the obstacle only pushes); ``-inf`` when Z is empty.
        relative_residual: ||r off Z||_2 / ||A u||_2.
        tolerance: tau.
        kkt: All three conditions hold within tau (and the residual within sqrt(tau)).
        smallest_of_reduced: lambda is the smallest eigenvalue of the pencil with Z
            removed (true by construction for loads from a target-0 shift-invert solve).
        global_optimum_proven: The algorithm proved no admissible mode has a lower load.
    """

    feasible: bool
    feasibility_margin: float
    max_contact_force: float
    relative_residual: float
    tolerance: float
    kkt: bool
    smallest_of_reduced: bool
    global_optimum_proven: bool = False
    notes: tuple[str, ...] = field(default_factory=tuple)

    def as_dict(self) -> dict[str, object]:
        """JSON-ready mapping."""
        return {
            "feasible": self.feasible,
            "feasibility_margin": self.feasibility_margin,
            "max_contact_force": self.max_contact_force,
            "relative_residual": self.relative_residual,
            "tolerance": self.tolerance,
            "kkt": self.kkt,
            "smallest_of_reduced": self.smallest_of_reduced,
            "global_optimum_proven": self.global_optimum_proven,
            "notes": list(self.notes),
        }


class BucklingProblem:
    """Everything an algorithm needs, set up once.

    Args:
        spec: The problem.
        comm: Communicator of the mesh (``MPI.COMM_SELF`` gives each rank its own
            serial copy, for candidate-parallel enumeration).
        eps_options: Extra EPS options under the prefix ``unibuckle_`` (so ``eps_view``
            is ``-unibuckle_eps_view``).
        mesh: A quadrilateral DOLFINx mesh to use instead of ``spec.mesh`` (the
            rectangle); ``spec.plate.corners`` should then be its bounding box (used for
            tolerances and the buckling coefficient's width).
        facet_tags: Edge markers of ``mesh``, matched by :class:`EdgeSpec` ``tag``.

    Note:
        Construction and :meth:`destroy` are collective on ``comm``.
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
        self.spec = spec
        self.timings: dict[str, float] = {}
        #: The mesh came from the user (not spec.mesh): no coarse copies can be made.
        self.custom_mesh = mesh is not None
        if mesh is not None:
            if facet_tags is None:
                raise ValueError(
                    "facet_tags: a user mesh needs its edge facet tags (EdgeSpec.tag, or "
                    "tags 1..4 for edges named left, right, bottom, top)"
                )
            if mesh.topology.cell_type != dolfinx.mesh.CellType.quadrilateral:
                raise ValueError("mesh: the MITC plate element needs a quadrilateral mesh")
            self.mesh, self.facet_tags = mesh, facet_tags
            comm = mesh.comm
        else:
            self.mesh, self.facet_tags = create_plate_mesh(spec.plate, spec.mesh, comm)
        self.comm = comm
        if spec.obstacle is not None:
            size = max(spec.plate.length, spec.plate.width)
            check_zone_has_nodes(self.mesh, spec.obstacle, size)
        self.prestress = solve_prestress(
            self.mesh, self.facet_tags, spec.plate, spec.material, spec.solver.prestress_degree
        )
        t1 = time.perf_counter()
        self.timings["prestress_s"] = t1 - t0
        self.model = PlateModel(
            self.mesh, self.facet_tags, spec.plate, spec.material, self.prestress, spec.solver.shear
        )
        t2 = time.perf_counter()
        self.timings["assembly_s"] = t2 - t1
        options = None
        if eps_options:
            from unibuckle_fenicsx.eigen import EIGEN_OPTIONS

            options = {**EIGEN_OPTIONS, **eps_options}
        self.solver = GEPSolver(
            self.model.A,
            self.model.B,
            indefinite=self.prestress.indefinite,
            tol=spec.solver.eps_tol,
            options=options,
        )
        self.contact = (
            ContactSetManager(self.model, spec.obstacle) if spec.obstacle is not None else None
        )
        self.u = dolfinx.fem.Function(self.model.W, name="mode")
        self.free_mode: dolfinx.fem.Function | None = None
        self._r: PETSc.Vec | None = None  # work vectors of residual()
        self._Bu: PETSc.Vec | None = None
        self.tau = spec.solver.tau
        n_owned_w = self.model.Vw.dofmap.index_map.size_local
        self._w_owned = self.model.w_dofs[:n_owned_w]
        self.timings["setup_s"] = time.perf_counter() - t0

    # -- primitive -----------------------------------------------------------------
    @property
    def num_constrained(self) -> int:
        """i, the number of constrained nodes (0 without obstacle)."""
        return 0 if self.contact is None else self.contact.size

    def max_abs_w(self, u: PETSc.Vec | None = None) -> float:
        """Max |w| over the plate of the W-vector ``u`` (default: the current mode)."""
        arr = (self.u.x.petsc_vec if u is None else u).array_r
        local = float(np.abs(arr[self._w_owned]).max()) if self._w_owned.size else 0.0
        return float(self.comm.allreduce(local, op=MPI.MAX))

    def solve_free(self) -> EigenPair:
        """Smallest eigenpair without obstacle.

        The mode, scaled to max |w| = 1, is left in :attr:`u` and copied to
        :attr:`free_mode`.
        """
        pair = self.solver.solve(out=self.u.x.petsc_vec)
        self.u.x.petsc_vec.scale(1.0 / self.max_abs_w())
        self.u.x.scatter_forward()
        self.free_mode = self.u.copy()
        self.free_mode.name = "free_mode"
        return pair

    def evaluate(
        self,
        active: npt.NDArray[np.int64],
        initial: PETSc.Vec | None = None,
    ) -> Candidate:
        """Smallest eigenpair with the nodes ``active`` removed; mode left in :attr:`u`.

        The mode is oriented (its sign is free) so that it lies on the side away from
        the obstacle where possible, and scaled to max |w| = 1.

        Note:
            Collective; ``active`` must be the same on every rank.
        """
        assert self.contact is not None, "evaluate() needs an obstacle"
        active = np.unique(np.asarray(active, dtype=np.int64))
        vec = self.u.x.petsc_vec
        pair = self.solver.solve(self.contact.removed_rows(active), out=vec, initial=initial)
        if not np.isfinite(pair.value):
            values = np.zeros(self.contact.size)
            return Candidate(active, pair.value, values, False, 1.0, pair)
        scale = self.max_abs_w(vec)
        values = self.contact.values(vec) / scale
        free = np.ones(values.size, dtype=bool)
        free[active] = False
        sign = 1.0
        feasible = True
        if free.any():
            if values[free].max() <= self.tau:
                sign = 1.0
            elif -values[free].min() <= self.tau:
                sign = -1.0
            else:
                feasible = False
                # Orient towards the smaller violation, for reporting.
                sign = 1.0 if values[free].max() <= -values[free].min() else -1.0
        vec.scale(sign / scale)
        self.u.x.scatter_forward()
        return Candidate(active, pair.value, sign * values, feasible, sign, pair)

    # -- certificate ----------------------------------------------------------------
    def residual(
        self,
        load: float,
        u: PETSc.Vec | None = None,
    ) -> tuple[PETSc.Vec, float, float]:
        r"""Residual :math:`r = A u - \lambda B u` with the edge-constrained pencil.

        Args:
            load: :math:`\lambda`.
            u: W-vector (default: the current mode :attr:`u`).

        Returns:
            r in a work vector owned by the problem (valid until the next call), and
            :math:`\|Au\|_\infty`, :math:`\|Au\|_2` for scaling.

        Note:
            Collective.
        """
        vec = self.u.x.petsc_vec if u is None else u
        if self._r is None:
            self._r, self._Bu = vec.duplicate(), vec.duplicate()
        assert self._Bu is not None
        self.model.A.mult(vec, self._r)
        au_inf = self._r.norm(PETSc.NormType.INFINITY)  # type: ignore[arg-type]
        au_2 = self._r.norm()
        self.model.B.mult(vec, self._Bu)
        self._r.axpy(-load, self._Bu)
        return self._r, float(au_inf), float(au_2)  # type: ignore[arg-type]

    def certify(
        self,
        load: float,
        active: npt.NDArray[np.int64],
        u: PETSc.Vec | None = None,
        *,
        smallest_of_reduced: bool = True,
        global_optimum_proven: bool = False,
        notes: tuple[str, ...] = (),
    ) -> Certificate:
        """Check (load, u, Z = active) against DESIGN.md section 1.

        Note:
            Collective.
        """
        assert self.contact is not None
        vec = self.u.x.petsc_vec if u is None else u
        r, au_inf, au_2 = self.residual(load, vec)
        wmax = self.max_abs_w(vec)
        u_I = self.contact.values(vec) / wmax
        r_I = self.contact.values(r)
        # Residual off Z: zero the rows of Z.
        rows = self.contact.removed_rows(active)
        r.setValues(rows.astype(PETSc.IntType), np.zeros(len(rows)))  # type: ignore[arg-type]
        r.assemble()
        residual = float(r.norm()) / au_2  # type: ignore[arg-type]
        free = np.ones(u_I.size, dtype=bool)
        free[active] = False
        margin = float(u_I[free].max()) if free.any() else -np.inf
        force = float(r_I[active].max() / au_inf) if len(active) else -np.inf
        # Contact means u_k = 0 on Z: a mode that still penetrates there (penalty) fails.
        on_z = float(u_I[active].max()) if len(active) else -np.inf
        feasible = margin <= self.tau and on_z <= self.tau
        kkt = feasible and force <= self.tau and residual <= np.sqrt(self.tau)
        return Certificate(
            feasible=bool(feasible),
            feasibility_margin=margin,
            max_contact_force=force,
            relative_residual=float(residual),
            tolerance=self.tau,
            kkt=bool(kkt),
            smallest_of_reduced=smallest_of_reduced,
            global_optimum_proven=global_optimum_proven,
            notes=notes,
        )

    # -- reporting ------------------------------------------------------------------
    def buckling_coefficient(self, load: float) -> float:
        r""":math:`k = N b^2/(\pi^2 D)` with N = t lambda and b the plate width (y extent)."""
        plate, mat = self.spec.plate, self.spec.material
        D = bending_stiffness(mat.E, mat.nu, plate.thickness)
        return plate.thickness * load * plate.width**2 / (np.pi**2 * D)

    def destroy(self) -> None:
        """Destroy the PETSc/SLEPc objects (collective)."""
        for v in (self._r, self._Bu):
            if v is not None:
                v.destroy()
        self._r = self._Bu = None
        self.solver.destroy()
        self.model.destroy()
