r"""The assembled buckling pencil (A, B) of a section, with its end supports.

The space is the blocked Lagrange space :math:`(Q_1)^6` of the displacement and the
rotation vector in global components (:mod:`~unibuckle_fenicsx.model.shell.forms`):
six DOFs per node everywhere, so a corner node of a box, shared by two faces whose
frames differ, needs nothing special, and the rotation about a face's normal (no
stiffness of its own) gets the drilling term. DOF ``6 k + c`` of the dofmap is
component c of node k: c = 0, 1, 2 the displacement along x, y, z, c = 3, 4, 5 the
rotation about x, y, z.

Supports are zero Dirichlet conditions on global components: A gets diagonal 1 and B
diagonal 0 there, as for the plate (removed DOFs map to :math:`\lambda = \infty`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import dolfinx.fem.petsc
import ufl

import numpy as np

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.la.ownership import Owner, release
from unibuckle_fenicsx.model.materials import (
    bending_voigt,
    membrane_voigt,
    shear_modulus,
    shear_stiffness,
)
from unibuckle_fenicsx.model.plate.spaces import MixedDofs
from unibuckle_fenicsx.model.shell.forms import (
    DRILLING_FACTOR,
    ShellFields,
    bending_form,
    drilling_form,
    geometric_form,
    membrane_form,
    shear_form,
)
from unibuckle_fenicsx.model.shell.geometry import END_FINISH, END_START, SectionMesh
from unibuckle_fenicsx.spec import Material

__all__ = [
    "DOFS_PER_NODE",
    "ENDS",
    "ShellModel",
    "Support",
    "chop_roundoff",
    "create_section_space",
    "end_supports",
    "node_pins",
    "shell_stiffness_form",
]

#: DOFs per node: displacement (x, y, z) and rotation vector (x, y, z).
DOFS_PER_NODE = 6
#: End conditions of the loaded ends.
ENDS = ("clamped", "simply_supported")
UX, UY, UZ, RX, RY, RZ = range(6)


@dataclass(frozen=True)
class Support:
    """Zero global components on the nodes of tagged facets, or at given points.

    Attributes:
        components: Global components (0..5: u_x, u_y, u_z, omega_x, omega_y, omega_z).
        tag: Facet tag whose nodes are held, or
        point: A mesh node's coordinates (m).
    """

    components: tuple[int, ...]
    tag: int | None = None
    point: tuple[float, float, float] | None = None


def create_section_space(msh: dolfinx.mesh.Mesh) -> dolfinx.fem.FunctionSpace:
    """Blocked space :math:`(Q_1)^6`: displacement and rotation vector, global components."""
    return dolfinx.fem.functionspace(msh, ("Lagrange", 1, (DOFS_PER_NODE,)))


def node_pins(section: SectionMesh) -> list[Support]:
    """Point supports removing the six rigid motions of a free section (statically determinate).

    Node a at x = 0 on the line z = 0 with the largest y: all three displacements; node b,
    the same point at x = L: u_y and u_z (no rotation about y or z); node c at x = 0,
    z = 0 with the smallest y: u_z (no rotation about x). Reactions vanish for a
    self-equilibrated load, so the prestress does not depend on them.
    """
    y = 0.5 * section.width
    if section.shape == "flat":
        a, c = (0.0, section.width, 0.0), (0.0, 0.0, 0.0)
    else:
        a, c = (0.0, y, 0.0), (0.0, -y, 0.0)
    b = (section.length, a[1], 0.0)
    return [Support((UX, UY, UZ), point=a), Support((UY, UZ), point=b), Support((UZ,), point=c)]


def end_supports(section: SectionMesh, ends: str) -> list[Support]:
    r"""Supports of the loaded ends x = 0 and x = L.

    - "clamped": all six components at both ends.
    - "simply_supported": the end sections are held in their plane by rigid diaphragms
      and free to warp: :math:`u_y = u_z = 0` and :math:`\omega_x = 0` (no twist of the
      wall along the end: the plate's *hard* simple support, w = 0 and the tangential
      rotation 0), :math:`u_x` free but at one node (the axial rigid motion).

    A flat face (the plate) has its own edges: use the plate's conditions through
    :class:`Support` directly.
    """
    if ends == "clamped":
        every = (UX, UY, UZ, RX, RY, RZ)
        return [Support(every, tag=END_START), Support(every, tag=END_FINISH)]
    if ends == "simply_supported":
        held = (UY, UZ, RX)
        pin = node_pins(section)[0].point
        return [
            Support(held, tag=END_START),
            Support(held, tag=END_FINISH),
            Support((UX,), point=pin),
        ]
    raise InputError(f"ends must be one of {ENDS}, got {ends!r}")


def support_bcs(
    V: dolfinx.fem.FunctionSpace, section: SectionMesh, supports: Sequence[Support]
) -> list[dolfinx.fem.DirichletBC]:
    """Zero Dirichlet conditions of ``supports`` on V (collective)."""
    msh = V.mesh
    fdim = msh.topology.dim - 1
    tol = section.tolerance
    bcs: list[dolfinx.fem.DirichletBC] = []
    for s in supports:
        for c in s.components:
            sub = V.sub(c)
            Vc, _ = sub.collapse()
            if s.tag is not None:
                dofs = dolfinx.fem.locate_dofs_topological(
                    (sub, Vc), fdim, section.facet_tags.find(s.tag)
                )
            elif s.point is not None:
                p = np.asarray(s.point)
                dofs = dolfinx.fem.locate_dofs_geometrical(
                    (sub, Vc), lambda x, p=p: np.linalg.norm(x.T - p, axis=1) < tol
                )
                found = msh.comm.allreduce(int(np.asarray(dofs[0]).size), op=MPI.SUM)
                if found == 0:
                    raise InputError(f"support point {s.point} is no mesh node")
            else:
                raise InputError("a Support needs a tag or a point")
            bcs.append(dolfinx.fem.dirichletbc(0.0, dofs[0], sub))
    return bcs


def shell_stiffness_form(
    U: ufl.core.expr.Expr,
    V: ufl.core.expr.Expr,
    fields: ShellFields,
    material: Material,
    thickness: float,
    drilling: float = DRILLING_FACTOR,
) -> ufl.Form:
    r"""The linear shell's a(U, V): membrane, bending, MITC shear and drilling terms."""
    if material.plies:
        raise InputError("sections take an isotropic material (no plies)")
    C = membrane_voigt(material, thickness)
    D = bending_voigt(material, thickness)
    ks = shear_stiffness(material, thickness)
    kd = drilling * shear_modulus(material.E, material.nu) * thickness
    return (
        membrane_form(U, V, fields, C)
        + bending_form(U, V, fields, D)
        + shear_form(U, V, fields, ks)
        + drilling_form(U, V, fields, kd)
    )


#: Entries of B below this fraction of its infinity norm are round-off and set to zero
#: (:func:`chop_roundoff`).
ROUNDOFF = 1e-14


def chop_roundoff(M: PETSc.Mat) -> None:
    r"""Zero the entries of M below :data:`ROUNDOFF` times its infinity norm (collective).

    The cell frame comes from a normalised cross product, so a wall's normal has
    components of 1e-17 where it should have none, and B couples the in-plane
    displacements by products of them (1e-32 of its norm). With every normal
    direction of a box removed (a contact set Z = I), what is left of B is that
    round-off, which the eigen solver cannot tell from a pencil to solve; zeroed, it
    is recognised as no geometric stiffness (no finite load). Genuine entries are
    sums of terms of the norm's order, so none lies below its rounding.
    """
    M.chop(ROUNDOFF * float(M.norm(PETSc.NormType.INFINITY)))  # type: ignore[arg-type]


class ShellModel(MixedDofs, Owner):
    r"""A section's shell stiffness A and geometric stiffness B, assembled once.

    Args:
        section: The section's mesh.
        material: Isotropic elastic constants.
        thickness: Wall thickness t (m), > 0.
        N0: Membrane force per unit load, 2x2 in the cell frame (N/m)
            (:func:`~unibuckle_fenicsx.model.shell.prestress.solve_section_prestress`).
        supports: The supports (e.g. :func:`end_supports`).
        drilling: Drilling stiffness relative to Gt (:data:`DRILLING_FACTOR`).
        donnell: b with the normal deflection only (Donnell), not all three components.

    Note:
        Construction and :meth:`destroy` are collective.
    """

    def __init__(
        self,
        section: SectionMesh,
        material: Material,
        thickness: float,
        N0: ufl.core.expr.Expr,
        supports: Sequence[Support],
        *,
        drilling: float = DRILLING_FACTOR,
        donnell: bool = False,
    ) -> None:
        if not thickness > 0.0:
            raise InputError(f"thickness must be > 0 (m), got {thickness!r}")
        self.section = section
        self.mesh = section.mesh
        self.material = material
        self.thickness = thickness
        self.W = create_section_space(self.mesh)
        self.fields = ShellFields(self.mesh)
        self.bcs = support_bcs(self.W, section, supports)
        self.bc_dofs = np.unique(
            np.concatenate([bc.dof_indices()[0] for bc in self.bcs] or [np.empty(0, np.int32)])
        ).astype(np.int32)
        U, V = ufl.TrialFunction(self.W), ufl.TestFunction(self.W)
        self.a_form = dolfinx.fem.form(
            shell_stiffness_form(U, V, self.fields, material, thickness, drilling)
        )
        self.b_form = dolfinx.fem.form(geometric_form(U, V, self.fields, N0, donnell=donnell))
        self.A = dolfinx.fem.petsc.assemble_matrix(self.a_form, bcs=self.bcs, diag=1.0)
        self.A.assemble()
        self.B = dolfinx.fem.petsc.assemble_matrix(self.b_form, bcs=self.bcs, diag=0.0)
        self.B.assemble()
        chop_roundoff(self.B)
        self.A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        self.B.setOption(PETSc.Mat.Option.SYMMETRIC, True)

    def destroy(self) -> None:
        """Destroy A and B (collective)."""
        release(self, "A", "B")

    def __del__(self) -> None:
        self.destroy()
