"""The assembled buckling pencil (A, B) of a Reissner-Mindlin plate with its edge conditions."""

from __future__ import annotations

from collections.abc import Sequence

from petsc4py import PETSc

import dolfinx
import dolfinx.fem.petsc
import ufl

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.la.ownership import Owner, release
from unibuckle_fenicsx.model.materials import bending_voigt, transverse_shear
from unibuckle_fenicsx.model.mesh import collapsed, edge_normal_axis, edge_tags
from unibuckle_fenicsx.model.plate.forms import (
    bending_form,
    geometric_form,
    shear_force,
    shear_form,
)
from unibuckle_fenicsx.model.plate.spaces import (
    MixedDofs,
    create_plate_space,
    create_shear_space,
    mitc_shear_operator,
)
from unibuckle_fenicsx.model.points import mark_held, point_bcs, point_springs, snap_points
from unibuckle_fenicsx.model.prestress import Prestress, material_constant
from unibuckle_fenicsx.spec import Material, PlateSpec, PointSpec

__all__ = ["PlateModel", "edge_spring_form", "edge_support_bcs", "mitc_shear_matrix"]


class PlateModel(MixedDofs, Owner):
    r"""Reissner-Mindlin plate with the assembled matrices A (stiffness) and B (geometric).

    A :class:`~unibuckle_fenicsx.model.structure.StructuralModel` whose constrained
    component is the deflection w.

    A is the bending stiffness plus the MITC shear stiffness :math:`P^T M_s P`
    (:func:`~unibuckle_fenicsx.model.plate.spaces.mitc_shear_operator`); B is
    :math:`-\int N^0\nabla w\cdot\nabla z`. Edge-constrained DOFs have zero rows and
    columns with diagonal 1 in A and 0 in B, so they map to :math:`\lambda = \infty`.
    Both matrices are assembled once, here.

    Args:
        msh: Quadrilateral plate mesh.
        facet_tags: Edge markers.
        plate: Thickness and edge conditions.
        material: Elastic constants.
        prestress: Membrane force per unit load.
        shear: "mitc" (locking-free) or "full" (plain full integration, locks).
        points: Point restraints (:mod:`~unibuckle_fenicsx.model.points`): bilateral ones
            become zero Dirichlet conditions, springs diagonal entries of A.
        fixed_prestress: The fixed part of the load: A holds :math:`a - b_{fixed}`, so the
            pencil is :math:`(A - B_{fixed}, B)` (A need not be positive definite then:
            :func:`~unibuckle_fenicsx.model.build.build_problem` checks it).
        fixed_factor: Factor on the fixed prestress.

    Note:
        Construction and :meth:`destroy` are collective.
    """

    def __init__(
        self,
        msh: dolfinx.mesh.Mesh,
        facet_tags: dolfinx.mesh.MeshTags,
        plate: PlateSpec,
        material: Material,
        prestress: Prestress,
        shear: str = "mitc",
        points: Sequence[PointSpec] = (),
        fixed_prestress: Prestress | None = None,
        fixed_factor: float = 1.0,
    ) -> None:
        if msh.topology.cell_type != dolfinx.mesh.CellType.quadrilateral:
            raise InputError("the MITC plate element needs a quadrilateral mesh")
        self.mesh = msh
        self.plate = plate
        self.material = material
        self.prestress = prestress
        self.W = create_plate_space(msh)
        w_space = collapsed(self.W, 0)
        self.Vw = w_space.space
        self.w_dofs = w_space.dofs  # Vw local dof -> W local dof
        edge_bcs = self._edge_bcs(facet_tags)
        edge_dofs = [bc.dof_indices()[0] for bc in edge_bcs] or [np.empty(0, np.int32)]
        #: The point restraints on the mesh (snapped to nodes; those on held nodes marked).
        self.points = mark_held(
            self.Vw,
            self.w_dofs,
            np.concatenate(edge_dofs),
            snap_points(self.Vw, plate, points),
            plate,
        )
        self.bcs = edge_bcs + point_bcs(self.W, self.Vw, self.points, plate)
        self.bc_dofs = np.unique(
            np.concatenate([bc.dof_indices()[0] for bc in self.bcs] or [np.empty(0, np.int32)])
        ).astype(np.int32)

        u, v = ufl.TrialFunction(self.W), ufl.TestFunction(self.W)
        D = bending_voigt(material, plate.thickness)
        ks = transverse_shear(material, plate.thickness)
        a = bending_form(u, v, D)
        springs = edge_spring_form(ufl.split(u), ufl.split(v), facet_tags, plate)
        if springs is not None:
            a = a + springs
        if fixed_prestress is not None:  # A - B_fixed: the fixed load's geometric stiffness
            factor = material_constant(fixed_factor, u)
            a = a - factor * geometric_form(u, v, fixed_prestress.N0)
        if shear == "full":
            a = a + shear_form(u, v, ks)
        elif shear != "mitc":
            raise InputError(f'shear must be "mitc" or "full", got {shear!r}')
        self.a_form = dolfinx.fem.form(a)
        self.b_form = dolfinx.fem.form(geometric_form(u, v, prestress.N0))

        self.A = dolfinx.fem.petsc.assemble_matrix(self.a_form, bcs=self.bcs, diag=1.0)
        self.A.assemble()
        if shear == "mitc":
            S = self._mitc_shear_matrix(ks)
            self.A.axpy(1.0, S, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            S.destroy()
        self.B = dolfinx.fem.petsc.assemble_matrix(self.b_form, bcs=self.bcs, diag=0.0)
        self.B.assemble()
        rows, stiffness = point_springs(self.Vw, self.w_dofs, self.points, plate)
        if any(g.spec.kind == "spring" for g in self.points):
            keep = ~np.isin(rows, self.bc_dofs)
            self.add_springs(self.global_dofs(rows[keep]), stiffness[keep])
        self.A.setOption(PETSc.Mat.Option.SPD, True)
        self.A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        self.B.setOption(PETSc.Mat.Option.SYMMETRIC, True)

    def _edge_bcs(self, facet_tags: dolfinx.mesh.MeshTags) -> list[dolfinx.fem.DirichletBC]:
        """Zero Dirichlet conditions of the edge supports (hard SS: w and tangential theta)."""
        return edge_support_bcs(self.W, facet_tags, self.plate)

    def _mitc_shear_matrix(self, ks: float | npt.NDArray[np.float64]) -> PETSc.Mat:
        """:math:`P^T M_s P` with P's columns of edge-constrained DOFs zeroed."""
        return mitc_shear_matrix(self.W, self.bc_dofs, ks)

    def add_springs(self, rows: npt.NDArray[np.int64], stiffness: npt.NDArray[np.float64]) -> None:
        r"""Add nodal springs to A: :math:`A_{kk} \mathrel{+}= k_k` at the global ``rows``.

        A bilateral Winkler foundation (lumped springs at the w-DOFs, see
        :func:`~unibuckle_fenicsx.model.contact.foundation_springs`); A stays SPD.

        Args:
            rows: Global W rows owned by this rank (free w-DOFs).
            stiffness: Spring stiffness (N/m) of each.

        Note:
            Collective.
        """
        diag = self.A.createVecLeft()
        diag.setValues(rows.astype(PETSc.IntType), stiffness)
        diag.assemble()
        self.A.setDiagonal(diag, addv=PETSc.InsertMode.ADD_VALUES)
        diag.destroy()

    @property
    def w_subspace(self) -> dolfinx.fem.FunctionSpace:
        """The sub-space of W holding w."""
        return self.W.sub(0)

    @property
    def extent(self) -> float:
        """The plate's larger side (m)."""
        return max(self.plate.length, self.plate.width)

    def split(self, u: dolfinx.fem.Function) -> tuple[dolfinx.fem.Function, dolfinx.fem.Function]:
        """Deflection and rotation of ``u`` as Functions on collapsed spaces."""
        w = u.sub(0).collapse()
        w.name = "w"
        theta = u.sub(1).collapse()
        theta.name = "theta"
        return w, theta

    def destroy(self) -> None:
        """Destroy A and B (collective)."""
        release(self, "A", "B")

    def __del__(self) -> None:
        self.destroy()


def edge_support_bcs(
    W: dolfinx.fem.FunctionSpace,
    facet_tags: dolfinx.mesh.MeshTags,
    plate: PlateSpec,
    *,
    w_sub: int = 0,
    theta_sub: int = 1,
) -> list[dolfinx.fem.DirichletBC]:
    """Zero Dirichlet conditions of the edge supports on w and theta.

    Hard simple support: w and the tangential rotation; soft: w; clamped: w and theta.

    Args:
        W: Mixed space holding w and theta.
        facet_tags: Edge markers.
        plate: The edge conditions.
        w_sub: Sub-space of W holding w.
        theta_sub: Sub-space of W holding theta.

    Note:
        Collective.
    """
    msh = W.mesh
    fdim = msh.topology.dim - 1
    bcs = []
    for e in plate.edges:
        if e.support == "free":
            continue
        for tag in edge_tags(plate, e):
            facets = facet_tags.find(tag)
            subs: list[tuple[int, ...]] = [(w_sub,)]
            if e.support == "clamped":
                subs += [(theta_sub, 0), (theta_sub, 1)]
            elif e.support == "simply_supported":
                # theta . s = 0: the rotation component along the edge (each segment's).
                normal = edge_normal_axis(msh, facet_tags, tag, e.name)
                subs.append((theta_sub, 1 - normal))
            for path in subs:
                c = collapsed(W, *path)
                dofs = dolfinx.fem.locate_dofs_topological((c.sub, c.space), fdim, facets)
                bcs.append(dolfinx.fem.dirichletbc(0.0, dofs[0], c.sub))
    return bcs


def edge_spring_form(
    u: tuple[ufl.core.expr.Expr, ufl.core.expr.Expr],
    v: tuple[ufl.core.expr.Expr, ufl.core.expr.Expr],
    facet_tags: dolfinx.mesh.MeshTags,
    plate: PlateSpec,
) -> ufl.Form | None:
    r"""Elastic edge restraints :math:`\sum_e \int_e k_r (\theta\cdot n)(\eta\cdot n) + k_t wz\,ds`.

    The second variation of :math:`\tfrac12\int k_r (\theta\cdot n)^2 + k_t w^2\,ds` over the
    edges with a ``rotational_stiffness`` :math:`k_r` or a ``translational_stiffness``
    :math:`k_t` (:class:`~unibuckle_fenicsx.spec.EdgeSpec`); n is the outward normal,
    so :math:`\theta\cdot n` is the rotation about the edge. The springs act on the
    DOFs the support leaves free (the loader refuses the others); assembled with the
    supports' Dirichlet rows, they do not touch the fixed ones.

    Args:
        u: (w, theta) of the trial function (or of a state).
        v: (z, eta) of the test function (or of a state: ``u`` again for the energy).
        facet_tags: Edge markers.
        plate: The edges.

    Returns:
        The form, or None when no edge has a spring.
    """
    sprung = [e for e in plate.edges if e.springs]
    if not sprung:
        return None
    (w, theta), (z, eta) = u, v
    domain = ufl.domain.extract_unique_domain(theta)
    ds = ufl.Measure("ds", domain=domain, subdomain_data=facet_tags)
    n = ufl.FacetNormal(domain)
    form = None
    for e in sprung:
        for tag in edge_tags(plate, e):
            term = (
                material_constant(e.rotational_stiffness, n) * ufl.dot(theta, n) * ufl.dot(eta, n)
                + material_constant(e.translational_stiffness, n) * w * z
            ) * ds(tag)
            form = term if form is None else form + term
    return form


def mitc_shear_matrix(
    W: dolfinx.fem.FunctionSpace,
    bc_dofs: npt.NDArray[np.int32],
    ks: float | npt.NDArray[np.float64],
    *,
    w_sub: int = 0,
    theta_sub: int = 1,
    column_scale: PETSc.Vec | None = None,
) -> PETSc.Mat:
    r"""MITC shear stiffness :math:`P^T M_s P`, P's columns of ``bc_dofs`` zeroed.

    Zeroed columns give zero rows and columns at the edge-constrained DOFs (whose
    values are zero), so the matrix can be added to an operator assembled with
    ``diag=1`` there.

    Args:
        W: Mixed space holding w and theta.
        bc_dofs: Local W DOFs fixed by the edge supports.
        ks: Shear stiffness :math:`\kappa_s G t`, or a 2x2 matrix H (a laminate) (N/m).
        w_sub: Sub-space of W holding w.
        theta_sub: Sub-space of W holding theta.
        column_scale: Optional W-vector D: the matrix becomes :math:`D P^T M_s P D`
            (for scaled unknowns).

    Returns:
        The matrix; the caller must destroy it.

    Note:
        Collective.
    """
    Vs = create_shear_space(W.mesh)
    g, d = ufl.TrialFunction(Vs), ufl.TestFunction(Vs)
    # A laminate's 2x2 H, or the scalar kappa_s G t.
    energy = ufl.inner(shear_force(g, ks), d)
    Ms = dolfinx.fem.petsc.assemble_matrix(dolfinx.fem.form(energy * ufl.dx))
    Ms.assemble()
    P = mitc_shear_operator(W, Vs, w_sub=w_sub, theta_sub=theta_sub)
    keep = P.createVecRight()
    if column_scale is None:
        keep.set(1.0)
    else:
        column_scale.copy(keep)
    n_owned = W.dofmap.index_map.size_local * W.dofmap.index_map_bs
    owned_bc = bc_dofs[bc_dofs < n_owned]
    keep.array[owned_bc] = 0.0
    P.diagonalScale(R=keep)
    S = Ms.PtAP(P)
    for obj in (Ms, P, keep):
        obj.destroy()
    return S
