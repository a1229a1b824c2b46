r"""The von Kármán Reissner–Mindlin plate: mixed space, energy, MITC shear and a SNES VI solver.

Unknowns :math:`x = (u, w, \theta)` in one mixed space :math:`Q_k^2 \times Q_1 \times Q_1^2`
(in-plane displacement, deflection, rotation), from a stress-free imperfect shape
:math:`x_0 = (0, w_0, \theta_0)`. The energy (the von Kármán plate: T. von Kármán,
*Festigkeitsprobleme im Maschinenbau*, Encyklopädie der mathematischen Wissenschaften IV/4,
1910; Timoshenko and Woinowsky-Krieger, *Theory of Plates and Shells*, 1959, ch. 13; here
with Reissner–Mindlin bending and shear) is

.. math::

    \Pi(x) = \tfrac12\int_\omega N(e):e\,dx + \tfrac12\int_\omega M(\kappa):\kappa\,dx
           + \tfrac12 (x - x_0)^T K_s (x - x_0)
           - \lambda \int_{\gamma_1} t\,(\sigma_n n + \tau_s s)\cdot u\,ds,

    e = \mathrm{sym}\nabla u + \tfrac12(\nabla w\otimes\nabla w
        - \nabla w_0\otimes\nabla w_0), \qquad
    \kappa = \mathrm{sym}\nabla(\theta - \theta_0),

with the membrane and bending stiffnesses of the linear model and :math:`K_s = P^T M_s P`
its MITC shear stiffness (:func:`~unibuckle_fenicsx.model.plate.model.mitc_shear_matrix`):
the shear energy is quadratic, so :math:`K_s` is assembled once and adds
:math:`K_s(x - x_0)` to the residual and :math:`K_s` to the Jacobian. The edge supports
and the edge loads are those of the same :class:`~unibuckle_fenicsx.spec.ProblemSpec`.

The obstacle (:math:`w \le g` at the zone's nodes, the nodes of
:class:`~unibuckle_fenicsx.model.contact.ContactSetManager`, g the obstacle's gap, 0 by
default) enters as variable bounds of PETSc's
reduced-space VI Newton method (``vinewtonrsls``); the other bounds are
``PETSc.INFINITY``. DOLFINx's ``NonlinearProblem`` takes no bounds and assembles forms
only (the MITC shear is a matrix), so the SNES is wired here, with the same assembly
calls (``assemble_vector``, ``apply_lifting``, ``set_bc``, ``assemble_matrix``) and the
Jacobian by ``ufl.derivative``. Unknowns are scaled, :math:`\hat u = u/t`,
:math:`\hat w = w/t`, and the energy by :math:`D_{11}`, so that the absolute tolerances
with which the VI method decides that a bound is active act in units of t, not of metres
(w is 1e-7 m at the smallest imperfections).

Two controls: the load :math:`\lambda` (edge tractions), or the end shortening
(prescribed normal displacement of the loaded edges, :math:`\lambda` from their reactions).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from mpi4py import MPI
from petsc4py import PETSc

import basix.ufl
import dolfinx
import dolfinx.fem.petsc
import ufl

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.la.options import Prefix, set_options
from unibuckle_fenicsx.la.ownership import Owner, release
from unibuckle_fenicsx.model.contact import ContactSetManager
from unibuckle_fenicsx.model.materials import bending_voigt, membrane_voigt, transverse_shear
from unibuckle_fenicsx.model.mesh import (
    build_plate_mesh,
    edge_facets,
    edge_normal_axis,
    edge_tag,
    edge_tags,
)
from unibuckle_fenicsx.model.plate.forms import shear_force
from unibuckle_fenicsx.model.plate.model import (
    edge_spring_form,
    edge_support_bcs,
    mitc_shear_matrix,
)
from unibuckle_fenicsx.model.plate.spaces import MixedDofs
from unibuckle_fenicsx.model.points import point_bcs, point_springs, snap_points
from unibuckle_fenicsx.model.prestress import edge_traction, pin_rigid_motions, voigt_to_ufl
from unibuckle_fenicsx.nonlinear.choices import CONTROLS
from unibuckle_fenicsx.spec import EDGE_NAMES, EdgeSpec, PlateSpec, ProblemSpec
from unibuckle_fenicsx.spec.base import file_units

__all__ = [
    "CONTROLS",
    "SNES_OPTIONS",
    "NoZone",
    "StepReport",
    "VonKarmanPlate",
    "displacement_axis",
    "membrane_strain",
]

#: Default SNES options (prefix ``unibuckle_nl_``): Newton with MUMPS LU; the VI type is
#: set when the plate has an obstacle. Tolerances act on the scaled residual.
SNES_OPTIONS: dict[str, str | float | int | bool] = {
    "snes_rtol": 1e-10,
    "snes_stol": 0.0,
    "snes_max_it": 25,
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
}

# Sub-spaces of the mixed space.
U_SUB, W_SUB, THETA_SUB = 0, 1, 2


@dataclass(frozen=True)
class StepReport:
    """Outcome of one nonlinear solve.

    Attributes:
        converged: SNES converged (reason > 0).
        reason: SNES converged reason (negative: diverged).
        iterations: Newton iterations.
    """

    converged: bool
    reason: int
    iterations: int


def displacement_axis(plate: PlateSpec, control: str) -> int | None:
    """Axis of the compression under end-shortening control (None under load control).

    Raises:
        ValueError: ``control`` unknown, or "displacement" for a load that is not a
            uniaxial compression of opposite rectangle edges (checked before any work).
    """
    if control not in CONTROLS:
        raise InputError(f"control must be one of {CONTROLS}, got {control!r}")
    if control != "displacement":
        return None
    loaded = [e for e in plate.edges if e.loaded]
    problem = None
    if not loaded:
        problem = "no edge is loaded"
    elif not all(e.uniform for e in loaded):
        problem = "its loaded edges must carry a uniform stress (not a [start, end] pair)"
    elif any(e.shear_ends[0] != 0.0 or e.normal_ends[0] >= 0.0 for e in loaded):
        problem = "its loaded edges must carry compression only (no shear, no tension)"
    elif len({e.normal_ends[0] for e in loaded}) != 1:
        problem = "its loaded edges must carry the same normal stress"
    elif any(e.name not in EDGE_NAMES or e.tag is not None for e in loaded):
        problem = "its loaded edges must be edges of the rectangle (left, right, bottom, top)"
    elif len({0 if e.name in ("left", "right") else 1 for e in loaded}) != 1:
        problem = "its loaded edges must be opposite edges"
    if problem is not None:
        raise InputError(
            'control = "displacement" (end shortening) needs a uniaxial compression: '
            f'{problem}; use control = "load"'
        )
    return 0 if loaded[0].name in ("left", "right") else 1


def _add_ghosts(vec: PETSc.Vec) -> None:
    """Sum the ghost contributions into their owners (after assembly)."""
    vec.ghostUpdate(addv=True, mode="reverse")  # ADD_VALUES, SCATTER_REVERSE


def _update_ghosts(vec: PETSc.Vec) -> None:
    """Copy the owned values to the ghosts."""
    vec.ghostUpdate(addv=False, mode="forward")  # INSERT_VALUES, SCATTER_FORWARD


def _scalar(form: dolfinx.fem.Form, comm: MPI.Comm) -> float:
    return float(comm.allreduce(dolfinx.fem.assemble_scalar(form), op=MPI.SUM))


def _inplane_bcs(
    W: dolfinx.fem.FunctionSpace,
    facet_tags: dolfinx.mesh.MeshTags,
    plate: PlateSpec,
    axis: int | None,
) -> tuple[list[dolfinx.fem.DirichletBC], list[tuple[dolfinx.fem.Constant, float]]]:
    """In-plane edge conditions, prescribed shortening, and rigid-motion pins.

    Args:
        W: The mixed space (u, w, theta).
        facet_tags: Edge markers of its mesh.
        plate: The plate (its edges' in-plane conditions and loads).
        axis: Axis of the end shortening (:func:`displacement_axis`; None under load
            control).

    Returns:
        The conditions, and per loaded edge under end shortening the constant of its
        prescribed normal displacement and its factor (shortening per unit value).
    """
    msh = W.mesh
    fdim = msh.topology.dim - 1
    U = W.sub(U_SUB)
    bcs: list[dolfinx.fem.DirichletBC] = []
    edge_values: list[tuple[dolfinx.fem.Constant, float]] = []
    held = {0: False, 1: False}  # a component held along an edge (no translation)

    def fix(
        edge: EdgeSpec, c: int, value: float | dolfinx.fem.Constant, tag: int | None = None
    ) -> None:
        Vc, _ = U.sub(c).collapse()
        tags = edge_tags(plate, edge) if tag is None else (tag,)
        facets = edge_facets(facet_tags, tags)
        dofs = dolfinx.fem.locate_dofs_topological((U.sub(c), Vc), fdim, facets)
        bcs.append(dolfinx.fem.dirichletbc(value, dofs[0], U.sub(c)))

    loaded = [e for e in plate.edges if e.loaded]
    for e in plate.edges:
        if axis is not None and e.loaded:
            # u . n = -shortening per loaded edge (outward normal +-axis).
            sign = 1.0 if e.name in ("right", "top") else -1.0
            value = dolfinx.fem.Constant(msh, 0.0)
            edge_values.append((value, -sign / len(loaded)))
            fix(e, axis, value)
            held[axis] = True
            continue
        if e.inplane == "free":
            continue
        for tag in edge_tags(plate, e):
            components: tuple[int, ...] = (0, 1)
            if e.inplane == "roller":
                components = (edge_normal_axis(msh, facet_tags, tag, e.name),)
            for c in components:
                fix(e, c, 0.0, tag)
                held[c] = True
    if axis is None and not bcs:
        bcs += pin_rigid_motions(U, msh)
    elif axis is not None and not held[1 - axis]:
        bcs += pin_rigid_motions(U, msh, only=1 - axis)
    return bcs, edge_values


def membrane_strain(
    u: ufl.core.expr.Expr, w: ufl.core.expr.Expr, w0: ufl.core.expr.Expr
) -> ufl.core.expr.Expr:
    r"""Von Kármán's membrane strain from the stress-free imperfect shape ``w0`` (m).

    :math:`e = \mathrm{sym}\nabla u + \tfrac12(\nabla w\otimes\nabla w
    - \nabla w_0\otimes\nabla w_0)` (the module docstring).
    """
    return ufl.sym(ufl.grad(u)) + 0.5 * (
        ufl.outer(ufl.grad(w), ufl.grad(w)) - ufl.outer(ufl.grad(w0), ufl.grad(w0))
    )


def _norms(form: dolfinx.fem.Form) -> tuple[float, float]:
    """The 2-norm and the largest entry of the assembled vector of ``form`` (collective)."""
    f = dolfinx.fem.petsc.assemble_vector(form)
    _add_ghosts(f)
    norms = float(f.norm()), float(f.norm(PETSc.NormType.INFINITY))  # type: ignore[arg-type]
    f.destroy()
    return norms


def _edge_forms(
    x: dolfinx.fem.Function, plate: PlateSpec, loaded: list[EdgeSpec], ds: ufl.Measure, t: float
) -> list[tuple[dolfinx.fem.Form, float, EdgeSpec]]:
    """Per loaded edge: the form of its normal displacement's integral (m²), its length, itself.

    The end shortening is minus the mean normal displacement, summed over the loaded
    edges. Collective (the lengths).
    """
    msh = x.function_space.mesh
    n = ufl.FacetNormal(msh)
    return [
        (
            dolfinx.fem.form(t * ufl.inner(ufl.split(x)[U_SUB], n) * ds(edge_tags(plate, e))),
            _scalar(dolfinx.fem.form(1.0 * ds(edge_tags(plate, e))), msh.comm),
            e,
        )
        for e in loaded
    ]


class NoZone:
    """The zone of a plate without obstacle: no node.

    A :class:`~unibuckle_fenicsx.model.contact.ContactSetManager` of no node, so that a
    plate's ``contact`` is never None.

    Attributes:
        size: 0.
        coordinates: (0, 2).
        signs: (0,).
        gaps: (0,).
    """

    size = 0

    def __init__(self) -> None:
        self.coordinates: npt.NDArray[np.float64] = np.empty((0, 2))
        self.signs: npt.NDArray[np.float64] = np.empty(0)
        self.gaps: npt.NDArray[np.float64] = np.empty(0)

    def values(self, u: PETSc.Vec) -> npt.NDArray[np.float64]:
        """No entry (as ``ContactSetManager.values``)."""
        return np.empty(0)

    def scatter(self, values: npt.NDArray[np.float64], u: PETSc.Vec) -> PETSc.Vec:
        """``u`` set to zero (as ``ContactSetManager.scatter``)."""
        u.zeroEntries()
        return u

    def global_rows(self) -> npt.NDArray[np.int64]:
        """No row (as ``ContactSetManager.global_rows``)."""
        return np.empty(0, dtype=np.int64)


def _bounds(
    contact: ContactSetManager, template: PETSc.Vec, t: float
) -> tuple[PETSc.Vec, PETSc.Vec]:
    """The SNES VI's lower and upper bounds of the scaled state: the obstacles' only.

    Obstacle above: w <= g (upper bound); below: w >= -g (lower bound); w/t here; every
    other bound infinite. The caller destroys both vectors. Collective.
    """
    lower, upper = template.duplicate(), template.duplicate()
    lower.set(PETSc.NINFINITY)
    upper.set(PETSc.INFINITY)
    rows = contact.global_rows()
    lo, hi = upper.getOwnershipRange()
    mine = (rows >= lo) & (rows < hi)
    above = mine & (contact.signs > 0)
    below = mine & (contact.signs < 0)
    upper.array[rows[above] - lo] = contact.gaps[above] / t
    lower.array[rows[below] - lo] = -contact.gaps[below] / t
    return lower, upper


def _add_to_diagonal(
    K: PETSc.Mat | None,
    rows: npt.NDArray[np.int64],
    values: npt.NDArray[np.float64],
    n_owned: int,
    comm: MPI.Comm,
) -> PETSc.Mat:
    """``K`` plus ``values`` on the diagonal at the global ``rows`` (assembled).

    ``K`` None: a new diagonal matrix of ``n_owned`` rows per rank, which the caller
    destroys. Collective.
    """
    if K is None:
        K = PETSc.Mat().createAIJ(
            ((n_owned, None), (n_owned, None)),  # type: ignore[arg-type]
            nnz=1,
            comm=comm,  # type: ignore[arg-type]
        )
        lo, hi = K.getOwnershipRange()
        for r in range(lo, hi):
            K.setValue(r, r, 0.0)
    K.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)  # type: ignore[arg-type]
    for r, k in zip(rows.tolist(), values.tolist(), strict=True):
        K.setValue(r, r, k, addv=True)
    K.assemble()
    return K


class VonKarmanPlate(MixedDofs, Owner):
    r"""Geometrically nonlinear (von Kármán) plate with the linear model's edges and loads.

    Args:
        spec: The problem (plate, material, edges, loads, mesh, obstacle).
        comm: Communicator of the mesh.
        control: "load" or "displacement" (:data:`CONTROLS`).
        obstacle: Impose the obstacle of ``spec`` (False: the same plate without it).
        degree: Lagrange degree of the in-plane displacement (1 or 2).
        snes_options: SNES options pushed under the prefix ``unibuckle_nl_`` (default
            :data:`SNES_OPTIONS`).
        mesh: The mesh to use (e.g. the linear problem's, to share its functions);
            default: ``spec.mesh``'s rectangle.
        facet_tags: Edge markers of ``mesh``.

    Attributes:
        x: The current state :math:`(u/t, w/t, \theta)` (scaled, see the module note).
        x0: The imperfect, stress-free shape :math:`(0, w_0/t, \theta_0)`.
        load: :math:`\lambda` (Pa) under load control.
        contact: The zone's nodes (a :class:`NoZone` without obstacle).

    Note:
        Construction, :meth:`solve` and :meth:`destroy` are collective.
    """

    def __init__(
        self,
        spec: ProblemSpec,
        comm: MPI.Comm = MPI.COMM_WORLD,
        *,
        control: str = "load",
        obstacle: bool = True,
        degree: int = 1,
        snes_options: Mapping[str, str | float | int | bool] | None = None,
        mesh: dolfinx.mesh.Mesh | None = None,
        facet_tags: dolfinx.mesh.MeshTags | None = None,
    ) -> None:
        if degree not in (1, 2):
            raise InputError(f"degree (in-plane displacement) must be 1 or 2, got {degree!r}")
        self.spec = spec
        self.plate = spec.plate
        self.control = control
        self.thickness = spec.plate.thickness
        loaded = [e for e in spec.plate.edges if e.loaded]
        if not loaded:
            raise InputError(
                "no edge is loaded: give at least one edge a non-zero normal_stress or shear_stress"
            )
        self._displacement_axis = displacement_axis(spec.plate, control)
        if mesh is None or facet_tags is None:
            mesh, facet_tags, plate = build_plate_mesh(
                spec.plate, spec.mesh, comm, spec.all_obstacles
            )
            self.plate = plate
        self.mesh, self.facet_tags = mesh, facet_tags
        self.comm = mesh.comm
        self._spaces(degree)
        inplane, self._edge_values = _inplane_bcs(
            self.W, self.facet_tags, self.plate, self._displacement_axis
        )
        self.bcs = self.bending_bcs + inplane
        self.x = dolfinx.fem.Function(self.W, name="state")
        self.x0 = dolfinx.fem.Function(self.W, name="imperfection")
        self.load = dolfinx.fem.Constant(mesh, 0.0)
        ks = self._forms(loaded)
        self._matrices(ks)
        self.contact: ContactSetManager | NoZone = (
            ContactSetManager(self, spec.all_obstacles)
            if obstacle and spec.all_obstacles
            else NoZone()
        )
        self.snes: PETSc.SNES | None = self._snes(snes_options)

    # -- set-up stages -------------------------------------------------------------
    def _spaces(self, degree: int) -> None:
        """The mixed space (u, w, theta), its w part, the supports' and points' conditions."""
        msh, spec = self.mesh, self.spec
        cell = msh.basix_cell().name
        elements = [
            basix.ufl.element("Lagrange", cell, degree, shape=(2,)),
            basix.ufl.element("Lagrange", cell, 1),
            basix.ufl.element("Lagrange", cell, 1, shape=(2,)),
        ]
        self.W = dolfinx.fem.functionspace(msh, basix.ufl.mixed_element(elements))
        self.Vw, map_w = self.W.sub(W_SUB).collapse()
        self.w_dofs = np.asarray(map_w[0], dtype=np.int32)  # Vw dof -> W dof
        self.bending_bcs = edge_support_bcs(
            self.W, self.facet_tags, self.plate, w_sub=W_SUB, theta_sub=THETA_SUB
        )
        with file_units(spec.units):  # a point outside the plate: in the file's units
            self.points = snap_points(self.Vw, self.plate, spec.points)
        if spec.one_sided_points:
            raise InputError(
                "points: the nonlinear analysis does not model one-sided points (kind = "
                '"one-sided"); give them kind = "bilateral" or "spring", or leave them out'
            )
        self.bending_bcs += point_bcs(self.W, self.Vw, self.points, self.plate, w_sub=W_SUB)
        self.bc_dofs = np.unique(
            np.concatenate(
                [bc.dof_indices()[0] for bc in self.bending_bcs] or [np.empty(0, np.int32)]
            )
        ).astype(np.int32)

    def _forms(self, loaded: list[EdgeSpec]) -> float | npt.NDArray[np.float64]:
        """The energy's residual and Jacobian forms, the load's scale, the end shortening.

        Returns the transverse shear stiffness (N/m; a laminate's 2x2), for the MITC matrix.
        """
        spec, msh, t = self.spec, self.mesh, self.thickness
        D = bending_voigt(spec.material, t)
        self.energy_scale = float(D[0, 0])  # N m
        Cm = membrane_voigt(spec.material, t)
        self._compliance = np.linalg.inv(Cm)

        u_h, w_h, theta_h = ufl.split(self.x)
        _, w0_h, theta0_h = ufl.split(self.x0)
        u, w, w0 = t * u_h, t * w_h, t * w0_h
        e = membrane_strain(u, w, w0)
        kappa = ufl.sym(ufl.grad(theta_h - theta0_h))
        energy = 0.5 * ufl.inner(voigt_to_ufl(Cm, e), e) + 0.5 * ufl.inner(
            voigt_to_ufl(D, kappa), kappa
        )
        ks = transverse_shear(spec.material, t)
        if spec.solver.shear == "full":
            gamma = ufl.grad(w - w0) - (theta_h - theta0_h)
            energy = energy + 0.5 * ufl.inner(shear_force(gamma, ks), gamma)
        Pi = energy / self.energy_scale * ufl.dx
        d = (t * (w_h - w0_h), theta_h - theta0_h)  # from the stress-free imperfect shape
        springs = edge_spring_form(d, d, self.facet_tags, self.plate)
        if springs is not None:
            Pi = Pi + (0.5 / self.energy_scale) * springs
        ds = ufl.Measure("ds", domain=msh, subdomain_data=self.facet_tags)
        tractions = [
            (edge_traction(msh, self.facet_tags, self.plate, e, tag), tag)
            for e in loaded
            for tag in edge_tags(self.plate, e)
        ]
        if self.control == "load":
            for traction, tag in tractions:
                Pi = Pi - (self.load * t / self.energy_scale) * ufl.inner(traction, u) * ds(tag)
        v, dx_ = ufl.TestFunction(self.W), ufl.TrialFunction(self.W)
        # The edge loads' vector per unit lambda: the scale of the residual.
        unit_load = sum(
            (t / self.energy_scale) * ufl.inner(traction, ufl.split(v)[U_SUB]) * ds(tag)
            for traction, tag in tractions
        )
        #: The 2-norm and the largest entry of the scaled load vector per unit lambda (Pa).
        self.unit_load_norm, self.unit_load_inf = _norms(dolfinx.fem.form(unit_load))
        F = ufl.derivative(Pi, self.x, v)
        J = ufl.derivative(F, self.x, dx_)
        self.F_form = dolfinx.fem.form(F)
        self.J_form = dolfinx.fem.form(J)
        self._edge_forms = _edge_forms(self.x, self.plate, loaded, ds, t)
        return ks

    def _matrices(self, ks: float | npt.NDArray[np.float64]) -> None:
        """The MITC shear matrix, the points' springs, the Jacobian and the work vectors."""
        t = self.thickness
        scale = dolfinx.fem.Function(self.W)
        scale.x.array[:] = 1.0
        scale.x.array[self.w_dofs] = t
        self.Ks: PETSc.Mat | None = None
        if self.spec.solver.shear == "mitc":
            self.Ks = mitc_shear_matrix(
                self.W,
                self.bc_dofs,
                ks / self.energy_scale,
                w_sub=W_SUB,
                theta_sub=THETA_SUB,
                column_scale=scale.x.petsc_vec,
            )
        self._add_point_springs(t)
        self.J: PETSc.Mat | None = dolfinx.fem.petsc.create_matrix(self.J_form)
        self._merged = False
        self.b: PETSc.Vec | None = dolfinx.fem.petsc.create_vector(self.W)
        self._xs: PETSc.Vec | None = dolfinx.fem.petsc.create_vector(self.W)
        self._d: PETSc.Vec | None = self._xs.duplicate()
        self._Kd: PETSc.Vec | None = self._xs.duplicate()

    def _snes(self, snes_options: Mapping[str, str | float | int | bool] | None) -> PETSc.SNES:
        """The SNES of the path, with the obstacle's bounds (a variational inequality)."""
        xs = self._xs
        if xs is None:
            raise RuntimeError("_snes: the work vectors come first (an internal invariant)")
        snes = PETSc.SNES().create(self.comm)
        snes.setFunction(self.residual, self.b)
        snes.setJacobian(self._jacobian, self.J)
        options = dict(SNES_OPTIONS if snes_options is None else snes_options)
        self._lower: PETSc.Vec | None = None
        self._upper: PETSc.Vec | None = None
        if isinstance(self.contact, ContactSetManager):
            options.setdefault("snes_type", "vinewtonrsls")
            self._lower, self._upper = _bounds(self.contact, xs, self.thickness)
            snes.setVariableBounds(self._lower, self._upper)
        else:
            options.setdefault("snes_type", "newtonls")
        set_options(snes, Prefix.NONLINEAR, options)
        return snes

    # -- set-up helpers ------------------------------------------------------------
    def _add_point_springs(self, t: float) -> None:
        """Spring points: k_p t^2 / D11 on the diagonal of K_s (the quadratic part, about x0)."""
        if not any(g.spec.kind == "spring" for g in self.points):
            return
        local, stiffness = point_springs(self.Vw, self.w_dofs, self.points, self.plate)
        keep = ~np.isin(local, self.bc_dofs)
        rows = self.global_dofs(local[keep])
        stiffness = stiffness[keep] * t**2 / self.energy_scale
        self.Ks = _add_to_diagonal(self.Ks, rows, stiffness, self.num_owned_dofs, self.comm)

    # -- PlateDofs (for ContactSetManager) -------------------------------------------
    @property
    def w_subspace(self) -> dolfinx.fem.FunctionSpace:
        """The sub-space holding w."""
        return self.W.sub(W_SUB)

    @property
    def extent(self) -> float:
        """The plate's larger side (m)."""
        return max(self.plate.length, self.plate.width)

    # -- SNES callbacks ------------------------------------------------------------
    def _assign(self, x: PETSc.Vec) -> None:
        """State function <- the (owned part of the) vector ``x``, ghosts updated."""
        _update_ghosts(x)  # x is used with its ghosts by the lifting
        self.x.x.array[: self.num_owned_dofs] = x.array_r
        self.x.x.scatter_forward()

    def _to_vector(self, x: PETSc.Vec) -> None:
        """Vector ``x`` <- the state function (owned part)."""
        x.array[:] = self.x.x.array[: self.num_owned_dofs]
        _update_ghosts(x)

    def residual(self, _snes: PETSc.SNES | None, x: PETSc.Vec, b: PETSc.Vec) -> None:
        """SNES function: the scaled residual F(x) with the edge conditions lifted."""
        self._assign(x)
        with b.localForm() as local:
            local.set(0.0)
        dolfinx.fem.petsc.assemble_vector(b, self.F_form)  # type: ignore[arg-type]
        dolfinx.fem.petsc.apply_lifting(b, [self.J_form], bcs=[self.bcs], x0=[x], alpha=-1.0)
        _add_ghosts(b)
        if self.Ks is not None:
            if self._d is None or self._Kd is None:
                raise RuntimeError(
                    "residual: expected self._d is not None and self._Kd is not None (an "
                    "internal invariant)"
                )
            x.copy(self._d)
            self._d.axpy(-1.0, self.x0.x.petsc_vec)
            self.Ks.mult(self._d, self._Kd)
            b.axpy(1.0, self._Kd)
        dolfinx.fem.petsc.set_bc(b, self.bcs, x0=x, alpha=-1.0)

    def _jacobian(self, _snes: PETSc.SNES, x: PETSc.Vec, J: PETSc.Mat, _P: PETSc.Mat) -> None:
        """SNES Jacobian: the assembled derivative of F plus K_s (diagonal 1 on edge DOFs)."""
        self._assign(x)
        J.zeroEntries()
        dolfinx.fem.petsc.assemble_matrix(J, self.J_form, self.bcs, diag=1.0)  # type: ignore[arg-type, misc]
        J.assemble()
        if self.Ks is not None:
            # K_s has structural zeros outside J's cell pattern (the N1curl interpolation
            # rows hold every dof of a cell): merge the patterns once.
            structure = (
                PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN
                if self._merged
                else PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN
            )
            J.axpy(1.0, self.Ks, structure=structure)  # type: ignore[arg-type]
            self._merged = True

    # -- solving -------------------------------------------------------------------
    def set_control(self, value: float) -> None:
        r"""Set the load :math:`\lambda` (Pa), or the end shortening (m) (displacement control)."""
        if self.control == "load":
            self.load.value = value  # type: ignore[assignment]
        else:
            for constant, factor in self._edge_values:
                constant.value = factor * value / self.thickness  # type: ignore[assignment]

    def project(self) -> None:
        """Clip the state onto the obstacles (w <= 0 above, >= 0 below); not collective."""
        if self._upper is None or self._lower is None:
            return  # no obstacle (or destroyed)
        arr = self.x.x.petsc_vec.array
        np.minimum(arr, self._upper.array, out=arr)
        np.maximum(arr, self._lower.array, out=arr)
        self.x.x.scatter_forward()

    def solve(self) -> StepReport:
        """Solve for the current control from the current state (the initial guess).

        On convergence the state is updated; otherwise it is left as it was.

        Note:
            Collective.
        """
        if self.snes is None or self._xs is None:
            raise RuntimeError(
                "solve: expected self.snes is not None and self._xs is not None (an internal "
                "invariant)"
            )
        self._to_vector(self._xs)
        self.snes.solve(None, self._xs)
        reason = int(self.snes.getConvergedReason())  # type: ignore[call-overload]
        its = int(self.snes.getIterationNumber())
        if reason > 0:
            self._assign(self._xs)
        return StepReport(reason > 0, reason, its)

    # -- measures (collective) -------------------------------------------------------
    def max_abs_w(self, x: dolfinx.fem.Function | None = None) -> float:
        """The largest |w| over the plate (m)."""
        x = self.x if x is None else x
        n_owned = self.Vw.dofmap.index_map.size_local
        values = x.x.array[self.w_dofs[:n_owned]]
        local = float(np.abs(values).max()) if values.size else 0.0
        return self.thickness * float(self.comm.allreduce(local, op=MPI.MAX))

    def zone_deflection(self) -> npt.NDArray[np.float64]:
        """Deflection (m) towards the obstacles at the zone nodes, s_k w_k (empty without one)."""
        return self.thickness * self.contact.values(self.x.x.petsc_vec)

    def zone_clearance(self, x: dolfinx.fem.Function | None = None) -> npt.NDArray[np.float64]:
        """s_k w_k - g_k (m) at the zone nodes: <= 0 admissible, 0 on the obstacle."""
        x = self.x if x is None else x
        return self.thickness * self.contact.values(x.x.petsc_vec) - self.contact.gaps

    def contact_nodes(self, rtol: float = 1e-9) -> npt.NDArray[np.int64]:
        """Zone nodes on the obstacle: s w >= g - rtol t (the VI keeps them at s w = g)."""
        return np.flatnonzero(self.zone_clearance() >= -rtol * self.thickness).astype(np.int64)

    def end_shortening(self) -> float:
        """Mean inward normal displacement of the loaded edges, summed over them (m)."""
        total = 0.0
        for form, length, _ in self._edge_forms:
            total -= _scalar(form, self.comm) / length
        return total

    def residual_vector(self) -> PETSc.Vec:
        """The scaled residual at the current state, edge-constrained rows zero.

        Returns a work vector owned by the plate (valid until the next call).
        """
        if self.b is None or self._xs is None:
            raise RuntimeError(
                "residual_vector: expected self.b is not None and self._xs is not None (an "
                "internal invariant)"
            )
        self._to_vector(self._xs)
        self.residual(None, self._xs, self.b)
        dolfinx.fem.petsc.set_bc(self.b, self.bcs, alpha=0.0)
        return self.b

    def edge_reaction_load(self) -> float:
        r""":math:`\lambda` (Pa) from the reactions on the loaded edges (displacement control).

        The support's normal force on each loaded edge, divided by t, its length and its
        normal stress per unit load; the mean over the loaded edges.
        """
        if self._displacement_axis is None or self.b is None:
            raise RuntimeError(
                "edge_reaction_load: expected self._displacement_axis is not None and self.b is "
                "not None (an internal invariant)"
            )
        axis = self._displacement_axis
        b = self.b
        with b.localForm() as local:
            local.set(0.0)
        dolfinx.fem.petsc.assemble_vector(b, self.F_form)  # type: ignore[arg-type]
        _add_ghosts(b)
        n_owned = self.num_owned_dofs
        fdim = self.mesh.topology.dim - 1
        U = self.W.sub(U_SUB).sub(axis)
        Vc, _ = U.collapse()
        loads = []
        for _, length, edge in self._edge_forms:
            facets = self.facet_tags.find(edge_tag(self.plate, edge))
            dofs = dolfinx.fem.locate_dofs_topological((U, Vc), fdim, facets)[0]
            dofs = dofs[dofs < n_owned]
            sign = 1.0 if edge.name in ("right", "top") else -1.0
            force = float(self.comm.allreduce(float(b.array[dofs].sum()), op=MPI.SUM))
            # Scaled residual -> N: times D11 / t.
            force *= sign * self.energy_scale / self.thickness
            loads.append(force / (self.thickness * length * edge.normal_ends[0]))
        return float(np.mean(loads))

    def flat_shortening(self, load: float) -> float:
        """End shortening (m) of the flat plate under ``load`` (linear membrane estimate)."""
        axis = self._displacement_axis if self._displacement_axis is not None else 0
        stress = max(abs(v) for e in self.plate.edges if e.loaded for v in e.normal_ends)
        strain = float(self._compliance[axis, axis]) * load * self.thickness * stress
        length = self.plate.length if axis == 0 else self.plate.width
        return strain * length

    def destroy(self) -> None:
        """Destroy the PETSc objects (collective)."""
        release(self, "snes", "J", "Ks", "b", "_xs", "_d", "_Kd", "_lower", "_upper")

    def __del__(self) -> None:
        self.destroy()
