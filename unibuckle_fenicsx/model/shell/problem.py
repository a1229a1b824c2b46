r"""A section's rotated pencil as a :class:`~unibuckle_fenicsx.model.problem.Problem`.

:func:`section_problem` makes a hollow section's :class:`SectionProblem` (a
:class:`~unibuckle_fenicsx.model.problem.Problem`: its free solve only) or, with a core,
a :class:`CoredSectionProblem` (a :class:`~unibuckle_fenicsx.model.problem.UnilateralProblem`).
An adapter, until the problem layer takes a second model: it fills in what the
unilateral algorithms (:func:`~unibuckle_fenicsx.algorithms.active_set.solve_active_set`)
and the certificate (:func:`~unibuckle_fenicsx.certificate.certify.certify`) read of a
problem: the pencil (A', B') in the basis of :mod:`~unibuckle_fenicsx.model.shell.core`,
its eigen solver, and a contact manager whose "nodes" are the constrained directions
(oriented values :math:`z_k = n_k\cdot u \le 0`, sign +1). Its coordinates are the
unrolled (x, s) of each direction's node, with a plate spec of corners
((0, 0), (L, perimeter)) for the algorithms' seeds and tolerances. The deflection scale
``max_abs_w`` is the largest displacement component in the new basis (translations).
"""

from __future__ import annotations

import time
from typing import Any, cast

from petsc4py import PETSc

import dolfinx

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.la.eigen import EIGEN_OPTIONS, GEPSolver
from unibuckle_fenicsx.la.ownership import Owner, release
from unibuckle_fenicsx.model.contact import ContactSetManager, _Owned
from unibuckle_fenicsx.model.materials import bending_stiffness
from unibuckle_fenicsx.model.problem import Problem, SetUp, UnilateralProblem
from unibuckle_fenicsx.model.shell.core import CoreConstraints
from unibuckle_fenicsx.model.shell.model import DOFS_PER_NODE, ShellModel, chop_roundoff
from unibuckle_fenicsx.model.shell.prestress import SectionPrestress
from unibuckle_fenicsx.spec import (
    EdgeSpec,
    Material,
    MeshSpec,
    ObstacleSpec,
    PlateSpec,
    ProblemSpec,
    SolverSpec,
)

__all__ = [
    "CoredSectionProblem",
    "RotatedPencil",
    "SectionContact",
    "SectionProblem",
    "section_problem",
]


class RotatedPencil(Owner):
    r"""The pencil :math:`(T^TAT, T^TBT)` of a shell model and the change of basis T.

    Args:
        model: The assembled shell model (keeps owning A and B).
        T: The change of basis (taken over: destroyed with this object).

    Note:
        Construction and :meth:`destroy` are collective.
    """

    def __init__(self, model: ShellModel, T: PETSc.Mat | None) -> None:
        self.shell = model
        self.mesh = model.mesh
        self.W = model.W
        self.bc_dofs = model.bc_dofs
        self.T = T
        #: Seconds spent forming A' and B' (two PtAP).
        self.rotation_s = 0.0
        if T is None:  # no change of basis: the model's matrices (owned by the model)
            self.A, self.B = model.A, model.B
            return
        t0 = time.perf_counter()
        self.A = model.A.PtAP(T)
        self.B = model.B.PtAP(T)
        chop_roundoff(self.B)
        self.rotation_s = time.perf_counter() - t0
        self.A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        self.B.setOption(PETSc.Mat.Option.SYMMETRIC, True)

    def to_global(self, u: PETSc.Vec, out: PETSc.Vec) -> PETSc.Vec:
        """Global components :math:`u = T u'` of a vector ``u`` of the new basis."""
        if self.T is None:
            u.copy(out)
        else:
            self.T.mult(u, out)
        return out

    def to_rotated(self, u: PETSc.Vec, out: PETSc.Vec) -> PETSc.Vec:
        r"""Components :math:`u' = T^T u` of the new basis of a vector ``u`` of global ones.

        The inverse of :meth:`to_global`: T is orthogonal, its blocks are made from
        orthonormal normals (a box's faces meet at right angles; a tube's node has one).
        """
        if self.T is None:
            u.copy(out)
        else:
            self.T.multTranspose(u, out)
        return out

    def destroy(self) -> None:
        """Destroy A', B' and T (collective); the model's own A, B stay with the model."""
        if getattr(self, "T", None) is None:
            self.__dict__.pop("A", None)
            self.__dict__.pop("B", None)
            return
        release(self, "A", "B", "T")

    def __del__(self) -> None:
        self.destroy()


class SectionContact(ContactSetManager):
    """The constrained directions as the contact manager's "nodes" (sign +1 each).

    Bypasses :class:`~unibuckle_fenicsx.model.contact.ContactSetManager`'s zone search
    (a plate's w-DOFs): the constraints are given. Its methods that read values and
    remove rows then work unchanged on the rotated pencil's DOFs.
    """

    def __init__(
        self,
        pencil: RotatedPencil,
        constraints: CoreConstraints,
        springs: npt.NDArray[np.float64] | None = None,
        symmetries: tuple[npt.NDArray[np.int64], ...] = (),
    ) -> None:
        self.model = cast(Any, pencil)
        self.symmetries = symmetries
        self.obstacles = (ObstacleSpec(zone="all"),)
        self.constraints = constraints
        self.coordinates = constraints.unrolled
        self.signs = np.ones(constraints.size)
        self.gaps = np.zeros(constraints.size)
        self.stiffness = springs
        self.num_edge_fixed = constraints.num_held
        self._owned = _Owned(
            constraints.owned_positions,
            constraints.owned_local_dofs,
            constraints.owned_global_dofs,
        )


def _unrolled_spec(
    model: ShellModel,
    material: Material,
    solver: SolverSpec,
    *,
    core: bool,
    springs: npt.NDArray[np.float64] | None,
) -> ProblemSpec:
    """The plate spec of the section's unrolled walls (length by perimeter).

    With a core its obstacle covers it all, a foundation where ``springs`` are given
    (their stiffness is the springs', not the spec's).
    """
    section = model.section
    k_f = None if springs is None else 1.0  # marks a foundation; the springs are given
    plate = PlateSpec(
        corners=((0.0, 0.0), (section.length, section.perimeter)),
        thickness=model.thickness,
        edges=tuple(EdgeSpec(name) for name in ("left", "right", "bottom", "top")),
    )
    return ProblemSpec(
        name=f"section-{section.shape}",
        plate=plate,
        material=material,
        mesh=MeshSpec(section.cells_along, section.cells_around),
        obstacle=ObstacleSpec("all", foundation_stiffness=k_f) if core else None,
        solver=solver,
    )


def section_problem(
    model: ShellModel,
    prestress: SectionPrestress,
    constraints: CoreConstraints | None,
    T: PETSc.Mat | None,
    material: Material,
    solver: SolverSpec | None = None,
    eps_options: dict[str, str | float | int] | None = None,
    springs: npt.NDArray[np.float64] | None = None,
    compression: float = 1.0,
    symmetries: tuple[npt.NDArray[np.int64], ...] = (),
) -> SectionProblem:
    """A section set up for its free solve, and with a core for the unilateral algorithms.

    Its :class:`~unibuckle_fenicsx.model.problem.SetUp` holds the rotated pencil as its
    model and a plate spec of the unrolled walls (module docstring).

    Args:
        model: The shell model (A, B in global components; kept, owned by the caller).
        prestress: Its prestress.
        constraints: The core's constrained directions (None: no core).
        T: Their change of basis (taken over; None without a core).
        material: The elastic constants.
        solver: Solver options (tolerances, certificate).
        eps_options: EPS options of the pencil's solver.
        springs: (i,) the core's foundation spring of each constrained direction (N/m;
            :func:`~unibuckle_fenicsx.model.shell.core.core_springs`); None: a rigid core.
        compression: The largest compressive stress per unit load (Pa/Pa,
            ``SectionParameters.compression()``): the buckling coefficient's stress is the
            load times it; 1 for a uniform unit compression.
        symmetries: Permutations of the constrained directions under which the rotated
            pencil is invariant (the contact manager's ``symmetries``): a square box's
            quarter turns (:func:`~unibuckle_fenicsx.model.shell.core.quarter_turns`), a
            tube's turns about its axis (:func:`~unibuckle_fenicsx.model.shell.core.axis_turns`).

    Returns:
        A :class:`CoredSectionProblem` with a core, else a :class:`SectionProblem`; the
        caller destroys it.

    Note:
        Collective.
    """
    t0 = time.perf_counter()
    section = model.section
    solver = solver if solver is not None else SolverSpec()
    spec = _unrolled_spec(model, material, solver, core=constraints is not None, springs=springs)
    pencil = RotatedPencil(model, T)
    eigensolver = GEPSolver(
        pencil.A,
        pencil.B,
        indefinite=prestress.indefinite,
        tol=solver.eps_tol,
        options={**EIGEN_OPTIONS, **(eps_options or {})},
        reused=constraints is not None,  # the contact sets: many factorisations
    )
    parts = SetUp(
        spec=spec,
        comm=section.mesh.comm,
        mesh=section.mesh,
        facet_tags=section.facet_tags,
        structured=False,
        custom_mesh=True,
        prestress=cast(Any, prestress),
        fixed_prestress=None,
        model=cast(Any, pencil),
        eigensolver=eigensolver,
        run_options=[],
        timings={"rotation_s": pencil.rotation_s},
    )
    problem = (
        SectionProblem(parts)
        if constraints is None
        else CoredSectionProblem(parts, SectionContact(pencil, constraints, springs, symmetries))
    )
    problem.compression = compression
    problem.timings["setup_s"] = time.perf_counter() - t0
    return problem


class SectionProblem(Problem):
    """A section's rotated pencil and its eigen solver (a hollow section: no contact).

    Made by :func:`section_problem`; its ``model`` is the :class:`RotatedPencil`.

    Note:
        :meth:`destroy` is collective.
    """

    def _owned_deflections(self) -> npt.NDArray[np.int32]:
        """The translations (u, v, w) of the owned nodes: the scale ``max_abs_w`` reads."""
        n_owned = self.pencil.W.dofmap.index_map.size_local
        translations = np.arange(n_owned * DOFS_PER_NODE, dtype=np.int32).reshape(-1, 6)[:, :3]
        return translations.ravel()

    @property
    def pencil(self) -> RotatedPencil:
        """The rotated pencil and its change of basis."""
        return cast(RotatedPencil, self._live("_model"))

    def global_mode(self, u: dolfinx.fem.Function, name: str = "mode") -> dolfinx.fem.Function:
        """The global components :math:`T u'` of a mode of the new basis, as a Function."""
        out = dolfinx.fem.Function(self.pencil.W, name=name)
        self.pencil.to_global(u.x.petsc_vec, out.x.petsc_vec)
        out.x.scatter_forward()
        return out

    #: The largest compressive stress per unit load (Pa/Pa), set by :func:`section_problem`.
    compression: float = 1.0

    def buckling_coefficient(self, load: float) -> float:
        r""":math:`k = \sigma t b^2/(\pi^2 D)` of a box's widest face b; NaN for a tube.

        :math:`\sigma` is that face's largest compressive stress at the load factor
        ``load``: ``load`` times :attr:`compression` (the extreme fibre's; the widest
        faces, a flange pair or a web pair, reach it), so that k is the classical
        coefficient whatever the stress per unit load and its gradient. NaN without
        compression.
        """
        section = self.pencil.shell.section
        t = self.pencil.shell.thickness
        sigma = load * self.compression
        if section.shape == "tube" or sigma <= 0.0:
            return float("nan")
        D = bending_stiffness(self.spec.material.E, self.spec.material.nu, t)
        b = max(section.width, section.depth)
        return float(t * sigma * b**2 / (np.pi**2 * D))


class CoredSectionProblem(SectionProblem, UnilateralProblem):
    """A section with a core, for the unilateral algorithms and the certificate.

    Its contact manager is the :class:`SectionContact` of the core's constrained
    directions. Made by :func:`section_problem`.
    """
