r"""Plane-elasticity prestress solve (paper eq. [1]) giving the membrane force :math:`N^0`.

The in-plane displacement :math:`u^p` solves

.. math::

    \int_\omega N(u^p) : \varepsilon(v) \,dx
    = \int_{\gamma_1} t\,(\sigma_n n + \tau_s s)\cdot v\,ds,

with :math:`N = C_m \varepsilon` the membrane stress resultant (N/m) per unit load.
The actual prestress is :math:`\lambda N^0`; compression makes :math:`N^0` negative.
When no edge holds the plate in its plane, the three rigid motions are pinned at two
mesh nodes, which leaves :math:`N^0` unchanged for a self-equilibrated load.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from mpi4py import MPI
from petsc4py import PETSc

import basix.ufl
import dolfinx
import dolfinx.fem.petsc
import ufl

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.la.options import (
    Options,
    Prefix,
    option_defaults,
    ordering_options,
    set_options,
)
from unibuckle_fenicsx.model.materials import membrane_voigt
from unibuckle_fenicsx.model.mesh import collapsed, edge_line, edge_normal_axis, edge_tags
from unibuckle_fenicsx.spec import (
    EdgeSpec,
    Material,
    PlateSpec,
    Temperature,
    temperature_field,
)

__all__ = [
    "DIRECT_SOLVE",
    "NEAR_TENSION",
    "Prestress",
    "direct_problem",
    "edge_traction",
    "membrane_force",
    "pin_rigid_motions",
    "solve_prestress",
    "thermal_force",
    "voigt_to_ufl",
]

logger = logging.getLogger(__name__)

#: A compression below this fraction of the largest tension is computed again at one
#: degree more (:func:`solve_prestress`): it may be the in-plane solve's discretisation
#: error on a plate in tension everywhere.
NEAR_TENSION = 1e-2

#: Linear solver options for the prestress (options prefix ``unibuckle_prestress_``):
#: MUMPS's symmetric factorisation of the membrane stiffness (symmetric, the edge
#: conditions eliminated on both sides), half an LU's work; its ordering is
#: :func:`~unibuckle_fenicsx.la.options.mumps_ordering`'s.
DIRECT_SOLVE: dict[str, str | bool] = {
    "ksp_type": "preonly",
    "pc_type": "cholesky",
    "pc_factor_mat_solver_type": "mumps",
    "ksp_error_if_not_converged": True,
}


def direct_problem(
    a: ufl.Form, L: ufl.Form, bcs: list[Any], prefix: str, options: Options = DIRECT_SOLVE
) -> dolfinx.fem.petsc.LinearProblem:
    """DOLFINx's linear problem of ``a = L``, its KSP under ``prefix`` with ``options`` as defaults.

    The options go through :func:`~unibuckle_fenicsx.la.options.set_options` (an option
    the database holds already, e.g. from the command line, wins; nothing stays behind),
    not through the problem's ``petsc_options``: DOLFINx 0.11 sets those over the
    database's values and, popping them, removes the unprefixed options of the same
    names while its own prefixed ones stay in the database.
    """
    problem = dolfinx.fem.petsc.LinearProblem(a, L, bcs=bcs, petsc_options_prefix=prefix)
    set_options(problem.solver, prefix, options)
    return problem


def material_constant(value: Any, expr: ufl.core.expr.Expr) -> dolfinx.fem.Constant:
    """``value`` as a :class:`dolfinx.fem.Constant` on the mesh of ``expr``.

    Material and load numbers enter the forms as constants, not as literals: the
    generated code is then the same for every thickness, material and edge stress, and
    a sweep compiles its forms once (a literal would make each new plate a JIT compile
    of several seconds).
    """
    domain = ufl.domain.extract_unique_domain(expr)
    return dolfinx.fem.Constant(domain, np.asarray(value, dtype=dolfinx.default_scalar_type))


def voigt_to_ufl(C: npt.NDArray[np.float64], eps: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
    """Apply a 3x3 Voigt stiffness to a symmetric 2x2 UFL tensor, returning a tensor."""
    e = ufl.as_vector([eps[0, 0], eps[1, 1], 2.0 * eps[0, 1]])
    s = material_constant(C, eps) * e
    return ufl.as_matrix([[s[0], s[2]], [s[2], s[1]]])


def membrane_force(
    u: dolfinx.fem.Function | ufl.Argument, material: Material, thickness: float
) -> ufl.core.expr.Expr:
    r"""Membrane stress resultant :math:`N = C_m \varepsilon(u)` (N/m) as a UFL tensor."""
    return voigt_to_ufl(membrane_voigt(material, thickness), ufl.sym(ufl.grad(u)))


def edge_traction(
    msh: dolfinx.mesh.Mesh,
    facet_tags: dolfinx.mesh.MeshTags,
    plate: PlateSpec,
    edge: EdgeSpec,
    tag: int | None = None,
) -> ufl.core.expr.Expr:
    r"""Edge stress vector per unit load, :math:`\sigma_n n + \tau_s s` (Pa/Pa), in UFL.

    n is the outward normal, :math:`s = (-n_y, n_x)` the counter-clockwise tangent. A
    stress given as a pair (start, end) varies linearly with the position
    :math:`\xi = (x - P)\cdot(Q - P)/|Q - P|^2` between the edge's start P and end Q
    (:func:`~unibuckle_fenicsx.model.mesh.edge_line`; ``tag``: the segment of an edge of
    several, each with its own line).

    Note:
        Collective for an edge given by a facet tag.
    """
    n = ufl.FacetNormal(msh)
    s = ufl.as_vector([-n[1], n[0]])
    if edge.uniform:
        sigma, tau = (material_constant(ends[0], n) for ends in (edge.normal_ends, edge.shear_ends))
        return sigma * n + tau * s
    start, end = edge_line(msh, facet_tags, plate, edge, tag)
    d = end - start
    x = ufl.SpatialCoordinate(msh)
    P, Q = material_constant(start, x), material_constant(d / float(d @ d), x)
    xi = ufl.dot(x - P, Q)
    (n0, n1), (s0, s1) = (
        material_constant(ends, n) for ends in (edge.normal_ends, edge.shear_ends)
    )
    return (n0 + (n1 - n0) * xi) * n + (s0 + (s1 - s0) * xi) * s


@dataclass
class Prestress:
    r"""Result of the prestress solve.

    Attributes:
        displacement: In-plane displacement per unit load.
        N0: Membrane force tensor per unit load (UFL expression of ``displacement``).
        max_compression: Largest compressive principal membrane force over the
            quadrature points, :math:`\max(-\min \mathrm{eig}\, N^0)` (N/m).
        max_tension: Largest tensile principal membrane force (N/m).
        pinned_rigid_motions: Whether rigid motions were removed by point pins.
    """

    displacement: dolfinx.fem.Function
    N0: ufl.core.expr.Expr
    max_compression: float
    max_tension: float
    pinned_rigid_motions: bool

    @property
    def indefinite(self) -> bool:
        """Whether the geometric form b is indefinite (tension somewhere)."""
        return self.max_tension > 1e-10 * self.max_compression


def _nearest_vertex(
    msh: dolfinx.mesh.Mesh, point: npt.NDArray[np.float64]
) -> npt.NDArray[np.float64]:
    """Coordinates of the mesh node nearest ``point`` (collective, same on all ranks)."""
    x = msh.geometry.x
    d = np.linalg.norm(x[:, :2] - point[:2], axis=1)
    k = int(np.argmin(d)) if d.size else -1
    best = (float(d[k]) if d.size else np.inf, msh.comm.rank)
    _, owner = msh.comm.allreduce(best, op=MPI.MINLOC)
    return np.asarray(msh.comm.bcast(x[k].copy() if msh.comm.rank == owner else None, root=owner))


def pin_rigid_motions(
    V: dolfinx.fem.FunctionSpace, msh: dolfinx.mesh.Mesh, only: int | None = None
) -> list[dolfinx.fem.DirichletBC]:
    """Point constraints removing the three in-plane rigid motions of the vector space V.

    Both components at the node nearest the plate's centre, and the component normal to
    the line joining it to a second node. ``only``: just that component at the centre
    node (a translation, when the other motions are held by edge conditions).

    Note:
        Collective.
    """
    x = msh.geometry.x
    local = np.vstack([x.min(axis=0), x.max(axis=0)]) if x.shape[0] else np.zeros((2, 3))
    lo = np.min(msh.comm.allgather(local[0]), axis=0)
    hi = np.max(msh.comm.allgather(local[1]), axis=0)
    p1 = _nearest_vertex(msh, 0.5 * (lo + hi))
    p2 = _nearest_vertex(msh, np.array([hi[0], p1[1], 0.0]))
    if np.linalg.norm(p2 - p1) == 0.0:
        p2 = _nearest_vertex(msh, np.array([p1[0], hi[1], 0.0]))
    size = float(np.linalg.norm(hi - lo))
    # Far below the node spacing, above the rounding of coordinates far from the origin.
    tol = 1e-10 * size + 64 * np.finfo(float).eps * float(np.abs(np.vstack([lo, hi])).max())
    bcs = []
    # p1: both components; p2: the component normal to p2 - p1.
    axis = 1 if abs(p2[0] - p1[0]) >= abs(p2[1] - p1[1]) else 0
    pins = [(p1, (0, 1)), (p2, (axis,))] if only is None else [(p1, (only,))]
    for point, components in pins:
        for c in components:
            sub, Vc, _ = collapsed(V, c)
            dofs = dolfinx.fem.locate_dofs_geometrical(
                (sub, Vc), lambda y, p=point: np.linalg.norm(y[:2].T - p[:2], axis=1) < tol
            )
            bcs.append(dolfinx.fem.dirichletbc(0.0, dofs[0], sub))
    return bcs


def thermal_force(
    msh: dolfinx.mesh.Mesh, material: Material, thickness: float, temperature: Temperature
) -> ufl.core.expr.Expr | None:
    r"""The membrane force of the free thermal strain, :math:`C_m \alpha\Delta T(x) I` (N/m).

    None for a zero rise. :math:`\Delta T = T_0 + T_{,x} x + T_{,y} y`.
    """
    T0, gx, gy = temperature_field(temperature)
    if not (T0 or gx or gy):
        return None
    x = ufl.SpatialCoordinate(msh)
    field = material_constant([T0, gx, gy], x)
    rise = field[0] + field[1] * x[0] + field[2] * x[1]
    strain = material_constant(material.thermal_expansion, x) * rise * ufl.Identity(2)
    return voigt_to_ufl(membrane_voigt(material, thickness), strain)


def solve_prestress(
    msh: dolfinx.mesh.Mesh,
    facet_tags: dolfinx.mesh.MeshTags,
    plate: PlateSpec,
    material: Material,
    degree: int = 1,
    petsc_options: dict[str, str | bool] | None = None,
    *,
    temperature: Temperature = 0.0,
    fixed: bool = False,
    plate_mesh: bool = False,
) -> Prestress:
    r"""Solve the membrane problem under the unit load and return :math:`N^0`.

    With a temperature rise :math:`\Delta T` the membrane force is
    :math:`N = C_m(\varepsilon(u) - \alpha\Delta T I)`, and the thermal strain enters
    the right-hand side as :math:`\int C_m \alpha\Delta T I : \varepsilon(v)`.

    Args:
        msh: Plate mesh.
        facet_tags: Edge markers (:func:`unibuckle_fenicsx.model.mesh.edge_tags`).
        plate: Thickness and edge conditions (in-plane supports and tractions).
        material: Membrane stiffness (and thermal expansion).
        degree: Lagrange degree of the in-plane displacement.
        petsc_options: KSP options (default :data:`DIRECT_SOLVE`), prefix
            ``unibuckle_prestress_``.
        temperature: A temperature rise (K; or the linear field, see
            :class:`~unibuckle_fenicsx.spec.LoadSpec`).
        fixed: The fixed part of the load (applied as is): no check that it compresses.
        plate_mesh: ``msh`` and ``facet_tags`` were built from ``plate`` by the package
            (:func:`~unibuckle_fenicsx.model.mesh.build_plate_mesh`): the self-equilibrium
            of its loads is then checked once per process (exact edge integrals, the same
            on every such mesh); a mesh from elsewhere, whose tags may put the loads on
            other edges, is always checked.

    Returns:
        The prestress; raises ``ValueError`` if nothing is loaded, if the load is not
        self-equilibrated on a plate held by no in-plane support, or (unless ``fixed``)
        if the plate is in tension everywhere (no buckling under a positive load).

    A load whose smaller principal force is zero everywhere (uniaxial tension varying
    along the loaded edge, whose exact field a degree-1 displacement cannot represent)
    shows a compression of the solve's discretisation error, 0.6 % of the tension on a
    0.4 × 0.1 m plate at 40×10 cells: a compression below :data:`NEAR_TENSION` of the
    tension is therefore computed again at one degree more, and taken for that error
    when it falls there to a tenth or less (a real compression stays); the eigen solve
    would otherwise look for a load factor of the order of the inverse of the noise
    and not converge.

    Note:
        Collective.
    """
    uh, N0, thermal, pinned = _solve_membrane(
        msh, facet_tags, plate, material, degree, petsc_options, temperature, plate_mesh
    )
    max_compression, max_tension = _principal_extremes(msh, N0, degree)
    logger.info(
        "prestress%s: max compression %.6g N/m, max tension %.6g N/m%s",
        " (fixed part)" if fixed else "",
        max_compression,
        max_tension,
        "" if fixed else " per unit load",
    )
    if not fixed:

        def again(higher: int) -> float:
            _, N0_higher, _, _ = _solve_membrane(
                msh, facet_tags, plate, material, higher, petsc_options, temperature, plate_mesh
            )
            return _principal_extremes(msh, N0_higher, higher)[0]

        _refuse_tension(max_compression, max_tension, degree, again, thermal is not None)
    return Prestress(uh, N0, max_compression, max_tension, pinned)


def _solve_membrane(
    msh: dolfinx.mesh.Mesh,
    facet_tags: dolfinx.mesh.MeshTags,
    plate: PlateSpec,
    material: Material,
    degree: int,
    petsc_options: dict[str, str | bool] | None,
    temperature: Temperature,
    plate_mesh: bool,
) -> tuple[dolfinx.fem.Function, ufl.core.expr.Expr, ufl.core.expr.Expr | None, bool]:
    """:func:`solve_prestress`'s solve: displacement, N0, thermal force, pinned or not."""
    t = plate.thickness
    loaded = [e for e in plate.edges if e.loaded]
    thermal = thermal_force(msh, material, t, temperature)
    if not loaded and thermal is None:
        raise InputError(
            "no edge is loaded: give at least one edge a non-zero normal_stress or shear_stress"
        )
    cell = msh.basix_cell()
    V = dolfinx.fem.functionspace(msh, basix.ufl.element("Lagrange", cell.name, degree, shape=(2,)))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    ds = ufl.Measure("ds", domain=msh, subdomain_data=facet_tags)

    a = ufl.inner(membrane_force(u, material, t), ufl.sym(ufl.grad(v))) * ufl.dx
    thickness = material_constant(t, v)
    terms = [
        thickness * ufl.dot(edge_traction(msh, facet_tags, plate, e, tag), v) * ds(tag)
        for e in loaded
        for tag in edge_tags(plate, e)
    ]
    if thermal is not None:
        terms.append(ufl.inner(thermal, ufl.sym(ufl.grad(v))) * ufl.dx)
    L = terms[0]
    for term in terms[1:]:
        L = L + term

    bcs = _inplane_bcs(V, msh, facet_tags, plate)
    pinned = not bcs
    if pinned:
        # A thermal strain is self-equilibrated. The loads of a plate checked once are
        # not checked again on a mesh the package built from it: the resultants are
        # exact edge integrals, the same on every such mesh (its coarse copies, a
        # sweep's repeated points). A user's mesh is checked every time: its tags decide
        # where the loads act. Decided on every rank alike (the check is collective).
        key = repr((plate, loaded))
        known = plate_mesh and msh.comm.allreduce(key in EQUILIBRATED, op=MPI.LAND)
        if loaded and not known:
            check_self_equilibrated(msh, facet_tags, ds, plate, loaded)
            if plate_mesh:
                EQUILIBRATED.add(key)
        bcs = pin_rigid_motions(V, msh)

    problem = direct_problem(
        a, L, bcs, Prefix.PRESTRESS, DIRECT_SOLVE if petsc_options is None else petsc_options
    )
    problem.A.setOption(PETSc.Mat.Option.SYMMETRIC, True)  # type: ignore[arg-type]
    # The ordering is read at the symbolic factorisation, inside solve().
    with option_defaults(Prefix.PRESTRESS, ordering_options(problem.A, kind="membrane")):
        uh = problem.solve()
    if not isinstance(uh, dolfinx.fem.Function):
        raise TypeError(
            "solve_prestress: expected isinstance(uh, dolfinx.fem.Function) (an internal invariant)"
        )
    uh.name = "prestress_displacement"
    del problem

    N0 = membrane_force(uh, material, t)
    if thermal is not None:
        N0 = N0 - thermal
    return uh, N0, thermal, pinned


def _inplane_bcs(
    V: dolfinx.fem.FunctionSpace,
    msh: dolfinx.mesh.Mesh,
    facet_tags: dolfinx.mesh.MeshTags,
    plate: PlateSpec,
) -> list[dolfinx.fem.DirichletBC]:
    """The edges' in-plane conditions: "clamped" both components, "roller" the normal one."""
    bcs: list[dolfinx.fem.DirichletBC] = []
    fdim = msh.topology.dim - 1
    for e in plate.edges:
        if e.inplane == "free":
            continue
        for tag in edge_tags(plate, e):
            facets = facet_tags.find(tag)
            components: tuple[int, ...] = (0, 1)
            if e.inplane == "roller":
                components = (edge_normal_axis(msh, facet_tags, tag, e.name),)
            for c in components:
                sub, Vc, _ = collapsed(V, c)
                dofs = dolfinx.fem.locate_dofs_topological((sub, Vc), fdim, facets)
                bcs.append(dolfinx.fem.dirichletbc(0.0, dofs[0], sub))
    return bcs


def _refuse_tension(
    compression: float,
    tension: float,
    degree: int,
    again: Callable[[int], float],
    thermal: bool,
) -> None:
    """Raise if the plate is in tension everywhere (:func:`solve_prestress`'s check).

    A compression below :data:`NEAR_TENSION` of the tension is computed again at one
    degree more (``again``) and refused if it is the discretisation error there.
    """
    noise = ""
    if 1e-10 * max(compression, tension) < compression <= NEAR_TENSION * tension:
        noise = _discretisation_noise(compression, tension, degree, again)
    if compression <= 1e-10 * max(compression, tension) or noise:
        raise InputError(
            "the load puts the plate in tension everywhere (largest compressive membrane "
            f"force {compression:.3g} N/m against tension {tension:.3g} N/m{noise}): no "
            "buckling under a positive load; reverse the sign of the edges' normal_stress"
            + (" or of load.temperature (a negative rise, a cooling)" if thermal else "")
        )


def _discretisation_noise(
    compression: float, tension: float, degree: int, again: Callable[[int], float]
) -> str:
    """Why a small compression is the in-plane solve's error ("" if it is real).

    ``again(degree + 1)`` measures it at one degree more: the discretisation error falls
    there to a tenth or less (to round-off for a field the higher degree represents
    exactly); a real compression stays.
    """
    finer = again(degree + 1)
    logger.info(
        "prestress: compression %.6g N/m is %.2g of the tension; at degree %d %.6g N/m",
        compression, compression / tension, degree + 1, finer,
    )  # fmt: skip
    if finer > max(1e-10 * max(compression, tension), 0.1 * compression):
        return ""
    return (
        f", {compression / tension:.2g} of the tension at solver.prestress_degree = "
        f"{degree} and {finer:.3g} N/m at degree {degree + 1}: the in-plane solve's "
        "discretisation error"
    )


#: The plates (and loaded edges) whose loads were found self-equilibrated in this process.
EQUILIBRATED: set[str] = set()


def check_self_equilibrated(
    msh: dolfinx.mesh.Mesh,
    facet_tags: dolfinx.mesh.MeshTags,
    ds: ufl.Measure,
    plate: PlateSpec,
    loaded: list[EdgeSpec],
) -> None:
    (x0, y0), (x1, y1) = plate.corners
    # Moments about the plate's centre: no cancellation for a plate far from the origin.
    # The centre is a constant and each quantity one form over every loaded segment:
    # four forms whose generated code is the same for every plate (a literal centre,
    # or a form per segment, made a sweep compile and look up new forms for each plate).
    x = ufl.SpatialCoordinate(msh)
    x = x - material_constant([0.5 * (x0 + x1), 0.5 * (y0 + y1)], x)
    parts = [
        (edge_traction(msh, facet_tags, plate, e, tag), ds(tag))
        for e in loaded
        for tag in edge_tags(plate, e)
    ]
    force = [_scalar(sum(tr[c] * m for tr, m in parts)) for c in range(2)]
    moment = _scalar(sum((x[0] * tr[1] - x[1] * tr[0]) * m for tr, m in parts))
    total = _scalar(sum(ufl.sqrt(ufl.dot(tr, tr)) * m for tr, m in parts))
    force = [msh.comm.allreduce(f, op=MPI.SUM) for f in force]
    moment = msh.comm.allreduce(moment, op=MPI.SUM)
    total = msh.comm.allreduce(total, op=MPI.SUM)
    size = max(plate.length, plate.width)
    if max(abs(force[0]), abs(force[1]), abs(moment) / size) > 1e-10 * total:
        # A [start, end] pair on a part of several segments runs along each one.
        trap = [e for e in loaded if not e.uniform and e.segments and len(e.segments) > 1]
        hint = "".join(
            f"; edges.{e.name}: its [start, end] stress runs along each of its segments "
            f"{list(e.segments or ())} from vertex k to vertex k + 1 (documentation: "
            "'Describing a plate', stress gradients)"
            for e in trap
        )
        raise InputError(
            'every edge is free in its plane (inplane = "free") but the load is not '
            f"self-equilibrated (resultant force {force}, moment {moment:.3g} per unit "
            f'thickness): set inplane = "clamped" or "roller" on some edge{hint}'
        )


def _scalar(integrand: ufl.Form) -> float:
    """Process-local value of a scalar form (the caller reduces over ranks)."""
    return float(np.real(dolfinx.fem.assemble_scalar(dolfinx.fem.form(integrand))))


def _principal_extremes(
    msh: dolfinx.mesh.Mesh, N0: ufl.core.expr.Expr, degree: int
) -> tuple[float, float]:
    """Largest compressive and tensile principal value of N0 over quadrature points."""
    points, _ = basix.make_quadrature(msh.basix_cell(), max(2, 2 * degree))
    expr = dolfinx.fem.Expression(N0, np.asarray(points, dtype=np.float64))
    cells = np.arange(msh.topology.index_map(msh.topology.dim).size_local, dtype=np.int32)
    values = expr.eval(msh, cells).reshape(-1, 2, 2)
    if values.size:
        eig = np.linalg.eigvalsh(values)
        local = (float(-eig[:, 0].min()), float(eig[:, 1].max()))
    else:
        local = (-np.inf, -np.inf)
    comp = msh.comm.allreduce(local[0], op=MPI.MAX)
    tens = msh.comm.allreduce(local[1], op=MPI.MAX)
    return max(comp, 0.0), max(tens, 0.0)
