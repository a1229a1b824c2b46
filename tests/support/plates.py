r"""Plate set-ups used by several test modules and by the MPI scripts.

- :func:`thin_plate`: the thin 3:1 plate (0.3 m x 0.1 m, t = 0.1 mm) against a
  whole-plate obstacle, where the interior-point route and the split certificates are
  exercised (``conftest.py`` gives it as the fixture ``thin_plate``);
- :func:`clamped_left_plate`: the paper's plate held in its plane on the left edge and
  pushed on the right one (a non-uniform prestress), with :func:`n0_at_quadrature_points`
  and :func:`strip_average` to read its membrane force (the prestress tests and
  ``tests/mpi/pipeline_steps.py``);
- :data:`STEEP_TOML`: a plate under a steep stress gradient (psi = -9), as a problem file.
"""

from __future__ import annotations

from mpi4py import MPI

import basix
import dolfinx
import ufl

import numpy as np

from unibuckle_fenicsx.spec import EdgeSpec, Material, ObstacleSpec, PlateSpec, ProblemSpec
from unibuckle_fenicsx.spec.cases import plate_case

#: A 300 x 100 x 3 mm SSSS steel plate under in-plane bending with psi = -9 (edge
#: stresses -1 at y = 0 to 9 at y = b): the compressed strip is b/10, one cell of 30 x 10.
STEEP_TOML = """
name = "steep_gradient"
[plate]
corners = [[0.0, 0.0], [0.3, 0.1]]
thickness = 0.003
[material]
E = 2.1e11
nu = 0.3
[edges.left]
support = "simply_supported"
normal_stress = [-1.0, 9.0]
[edges.right]
support = "simply_supported"
normal_stress = [-1.0, 9.0]
[edges.bottom]
support = "simply_supported"
[edges.top]
support = "simply_supported"
[mesh]
nx = 30
ny = 10
"""


def thin_plate(name: str = "ssss", nx: int = 6, ny: int = 3, **kw) -> ProblemSpec:
    """The thin 3:1 plate against a whole-plate obstacle, ``nx`` x ``ny`` cells.

    ``name`` "cs" clamps the short edges (left and right), any other name is simply
    supported; ``kw`` goes to :func:`~unibuckle_fenicsx.spec.cases.plate_case`.
    """
    kw.setdefault(
        "supports",
        {"cs": {"left": "clamped", "right": "clamped"}}.get(name, "simply_supported"),
    )
    return plate_case(
        name,
        length=0.3,
        width=0.1,
        thickness=1e-4,
        nx=nx,
        ny=ny,
        zone=ObstacleSpec(zone="all"),
        **kw,
    )


T = 0.006
MATERIAL = Material(E=1.0e9, nu=0.3)


def n0_at_quadrature_points(msh, N0, degree=4):
    """N0 (n, 2, 2) at the owned cells' quadrature points of a degree-``degree`` rule."""
    points, _ = basix.make_quadrature(msh.basix_cell(), degree)
    cells = np.arange(msh.topology.index_map(msh.topology.dim).size_local, dtype=np.int32)
    return dolfinx.fem.Expression(N0, points).eval(msh, cells).reshape(-1, 2, 2)


def strip_average(msh, N0, x1, x2, component=(0, 0)):
    r""":math:`\int_{x_1<x<x_2} N^0_{ij}\,dx / (x_2 - x_1)`, summed over ranks.

    For mesh lines x1 < x2 this is :math:`a(u, (\varphi, 0))` (or :math:`(0, \varphi)`
    for the shear component) with the Q1 ramp :math:`\varphi` = 0 left of x1, 1 right of
    x2, so discrete equilibrium makes it equal the load's resultant beyond x2.
    """
    chi = dolfinx.fem.Function(dolfinx.fem.functionspace(msh, ("DG", 0)))
    chi.interpolate(lambda x: ((x[0] > x1) & (x[0] < x2)).astype(np.float64))
    i, j = component
    local = dolfinx.fem.assemble_scalar(dolfinx.fem.form(N0[i, j] * chi * ufl.dx))
    return msh.comm.allreduce(local, op=MPI.SUM) / (x2 - x1)


def clamped_left_plate(thickness=T):
    """Paper's plate held in its plane on the left edge, pushed on the right edge only."""
    edges = (
        EdgeSpec("left", inplane="clamped"),
        EdgeSpec("right", normal_stress=-1.0),
        EdgeSpec("bottom"),
        EdgeSpec("top"),
    )
    return PlateSpec(thickness=thickness, edges=edges)
