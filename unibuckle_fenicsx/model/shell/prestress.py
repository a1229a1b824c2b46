r"""Prestress of a section: a linear shell solve under the axial stress on its loaded ends.

The displacement :math:`U^0` solves
:math:`a(U^0, V) = \int_{ends} t\,\sigma\,\nu\cdot v\,ds` with a the linear shell's
stiffness (:func:`~unibuckle_fenicsx.model.shell.model.shell_stiffness_form`),
:math:`\nu = \mp e_x` the outward conormal of the end x = 0 / x = L and
:math:`\sigma = \sigma_a + \sigma_b\,\zeta` the axial stress per unit load:
uniform :math:`\sigma_a` and a part :math:`\sigma_b` varying linearly over the depth
(an axial force with bending), :math:`\zeta = z/(d/2)` (box), :math:`z/R` (tube), or
:math:`(2y - b)/b` across a flat face. The section is free: its six rigid motions are held
at three nodes, statically determinate
(:func:`~unibuckle_fenicsx.model.shell.model.node_pins`), so the Poisson expansion of the
walls is free and a uniform end stress gives :math:`N^0 = \mathrm{diag}(t\sigma_a, 0)`
exactly (a linear displacement field, which :math:`Q_1` holds). The membrane force is
:math:`N^0 = C_m\varepsilon(U^0)`, in each cell's frame.
"""

from __future__ import annotations

from dataclasses import dataclass

from mpi4py import MPI

import dolfinx
import dolfinx.fem.petsc
import ufl

import numpy as np

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.model.materials import membrane_voigt
from unibuckle_fenicsx.model.prestress import direct_problem, material_constant
from unibuckle_fenicsx.model.shell.forms import ShellFields, membrane_force
from unibuckle_fenicsx.model.shell.geometry import END_FINISH, END_START, SectionMesh
from unibuckle_fenicsx.model.shell.model import (
    create_section_space,
    node_pins,
    shell_stiffness_form,
    support_bcs,
)
from unibuckle_fenicsx.spec import Material

__all__ = ["PRESTRESS_PREFIX", "SectionPrestress", "depth_coordinate", "solve_section_prestress"]

#: Options prefix of the prestress solve (``-unibuckle_section_prestress_ksp_view``).
PRESTRESS_PREFIX = "unibuckle_section_prestress_"


@dataclass(frozen=True)
class SectionPrestress:
    r"""The prestress per unit load.

    Attributes:
        displacement: :math:`U^0` (displacement and rotation, per unit load).
        N0: Membrane force :math:`C_m\varepsilon(U^0)`, 2x2 in the cell frame (N/m), UFL.
        max_compression: Largest compressive membrane force over the cells' centres (N/m).
        max_tension: Largest tensile one (N/m).
    """

    displacement: dolfinx.fem.Function
    N0: ufl.core.expr.Expr
    max_compression: float
    max_tension: float

    @property
    def indefinite(self) -> bool:
        """Tension somewhere (B indefinite): the eigen solver swaps the pencil."""
        return self.max_tension > 1e-8 * max(self.max_compression, self.max_tension)


def depth_coordinate(section: SectionMesh, x: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
    r""":math:`\zeta`, -1 to 1 over the depth: z/(d/2), z/R, or (2y - b)/b on a flat face."""
    if section.shape == "flat":
        return (2.0 * x[1] - section.width) / section.width
    return x[2] / (0.5 * section.depth)


def solve_section_prestress(
    section: SectionMesh,
    material: Material,
    thickness: float,
    axial_stress: float,
    bending_stress: float = 0.0,
) -> SectionPrestress:
    r"""Linear shell solve of the section under its end stress per unit load.

    Args:
        section: The section's mesh.
        material: Isotropic elastic constants.
        thickness: Wall thickness t (m).
        axial_stress: Uniform axial stress :math:`\sigma_a` per unit load (Pa/Pa;
            compression < 0): -1 makes the load factor the compressive stress in Pa.
        bending_stress: Linearly varying part :math:`\sigma_b` at :math:`\zeta = 1`
            (Pa/Pa), 0 by default (uniform compression).

    Note:
        Collective.
    """
    if not (np.isfinite(axial_stress) and np.isfinite(bending_stress)):
        raise InputError("axial_stress and bending_stress must be finite numbers (Pa)")
    if axial_stress == 0.0 and bending_stress == 0.0:
        raise InputError("axial_stress and bending_stress are both 0: the section is unloaded")
    msh = section.mesh
    V = create_section_space(msh)
    fields = ShellFields(msh)
    U, W = ufl.TrialFunction(V), ufl.TestFunction(V)
    a = shell_stiffness_form(U, W, fields, material, thickness)
    x = ufl.SpatialCoordinate(msh)
    sigma = material_constant(axial_stress, x) + material_constant(
        bending_stress, x
    ) * depth_coordinate(section, x)
    ds = ufl.Measure("ds", domain=msh, subdomain_data=section.facet_tags)
    t = material_constant(thickness, x)
    L = t * sigma * W[0] * ds(END_FINISH) - t * sigma * W[0] * ds(END_START)
    bcs = support_bcs(V, section, node_pins(section))
    problem = direct_problem(a, L, bcs, PRESTRESS_PREFIX)
    u0 = problem.solve()
    if not isinstance(u0, dolfinx.fem.Function):
        raise TypeError("solve_section_prestress: expected one Function (an internal invariant)")
    u0.name = "prestress_displacement"
    N0 = membrane_force(u0, fields, membrane_voigt(material, thickness))
    low, high = _extremes(msh, N0)
    del problem
    return SectionPrestress(u0, N0, max(-low, 0.0), max(high, 0.0))


def _extremes(msh: dolfinx.mesh.Mesh, N0: ufl.core.expr.Expr) -> tuple[float, float]:
    """Smallest and largest principal membrane force at the cells' centres (collective)."""
    expr = dolfinx.fem.Expression(N0, np.array([[0.5, 0.5]]))
    n = msh.topology.index_map(2).size_local
    values = expr.eval(msh, np.arange(n, dtype=np.int32)).reshape(n, 2, 2)
    eig = np.linalg.eigvalsh(values) if n else np.zeros((0, 2))
    low = float(eig.min()) if n else np.inf
    high = float(eig.max()) if n else -np.inf
    return float(msh.comm.allreduce(low, op=MPI.MIN)), float(msh.comm.allreduce(high, op=MPI.MAX))
