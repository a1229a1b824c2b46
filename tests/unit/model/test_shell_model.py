r"""The section shell model against the plate model and analytic buckling loads.

- A flat face embedded in 3-D is the plate: the same MITC4 element (its assumed shear is
  the plate's N1curl interpolation on rectangles), so the same pencil and load to rounding.
- Objectivity: the pencil of a face rotated in space is the rotated pencil.
- The prestress of a uniform end stress is :math:`N^0 = \mathrm{diag}(t\sigma, 0)` exactly.
- Hollow square box, uniform compression, an integer number of half-waves: the faces buckle
  alternately and the corners act as simple supports, k = 4 (Timoshenko & Gere, *Theory of
  Elastic Stability*, 2nd ed., section 9.2, a plate simply supported on four edges; the
  box: Bulson, *The Stability of Flat Plates*, 1970, chapter 9).
- Hollow circular tube, axial compression, moderate length: the classical
  :math:`\sigma_{cl} = E t/(R\sqrt{3(1-\nu^2)})` (Timoshenko & Gere, section 11.4) within 3 %
  (R/t = 100, L = R/2, simply supported ends; the convergence study: ``-m convergence``).
- An axial force with bending (a stress linear over the depth): the prestress converges to
  the linear distribution (Navier's beam formula, exact for pure bending of a prism).
- The drilling term leaves the load unchanged over four decades of its stiffness.
"""

from __future__ import annotations

import math

from mpi4py import MPI

import dolfinx
import ufl

import numpy as np
import pytest

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.la.eigen import GEPSolver
from unibuckle_fenicsx.la.factor import SymmetricFactorization
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.materials import bending_stiffness
from unibuckle_fenicsx.model.shell.geometry import (
    END_FINISH,
    END_START,
    FLAT_BOTTOM,
    FLAT_TOP,
    box_mesh,
    flat_face_mesh,
    tube_mesh,
)
from unibuckle_fenicsx.model.shell.model import (
    RX,
    RY,
    UX,
    UY,
    UZ,
    ShellModel,
    Support,
    end_supports,
)
from unibuckle_fenicsx.model.shell.prestress import solve_section_prestress
from unibuckle_fenicsx.model.shell.section import SectionParameters
from unibuckle_fenicsx.spec import Material
from unibuckle_fenicsx.spec.cases import paper_case

#: The paper's plate (paper, section 6), and a steel box of b/t = 100.
PAPER = Material(E=1.0e9, nu=0.3)
STEEL = Material(E=2.1e11, nu=0.3)


def _smallest(model: ShellModel) -> float:
    solver = GEPSolver(model.A, model.B, prefix="test_shell_")
    try:
        return solver.solve().value
    finally:
        solver.destroy()


def _flat_plate_supports() -> list[Support]:
    """The plate's hard simple support on four edges, and in-plane pins (determinate)."""
    return [
        *(Support((UZ,), tag=tag) for tag in (END_START, END_FINISH, FLAT_BOTTOM, FLAT_TOP)),
        Support((RX,), tag=END_START),  # edges along y: the slope along them, omega_x
        Support((RX,), tag=END_FINISH),
        Support((RY,), tag=FLAT_BOTTOM),  # edges along x: omega_y
        Support((RY,), tag=FLAT_TOP),
        Support((UX, UY), point=(0.0, 0.0, 0.0)),
        Support((UY,), point=(0.2, 0.0, 0.0)),
    ]


def test_box_mesh_is_a_folded_surface():
    sec = box_mesh(0.2, 0.1, 0.3, 0.05)
    msh = sec.mesh
    assert (msh.topology.dim, msh.geometry.dim) == (2, 3)
    # Faces of 4 and 2 cells across (even), 6 cells along; corner nodes shared.
    cells = msh.comm.allreduce(msh.topology.index_map(2).size_local, op=MPI.SUM)
    assert cells == 2 * (4 + 2) * 6
    nodes = msh.geometry.index_map().size_global
    assert nodes == 2 * (4 + 2) * 7
    ends = [msh.comm.allreduce(sec.facet_tags.find(t).size, op=MPI.SUM) for t in (1, 2)]
    assert ends == [12, 12]
    normals = sec.inward_normals(
        np.array([[0.1, 0.1, -0.05], [0.1, 0.0, 0.05], [0.1, 0.0, -0.05]]).T
    )
    assert normals[0].shape == (2, 3) and abs(normals[0][0] @ normals[0][1]) == 0.0
    np.testing.assert_allclose(normals[1], [[0.0, 0.0, -1.0]])


def test_tube_normals_turn_with_the_node():
    sec = tube_mesh(0.2, 0.1, 0.02)
    assert sec.cells_around % 2 == 0 and sec.cells_around >= 8
    phi = 0.3
    (n,) = sec.inward_normals(np.array([[0.05], [0.1 * math.cos(phi)], [0.1 * math.sin(phi)]]))
    np.testing.assert_allclose(n, [[0.0, -math.cos(phi), -math.sin(phi)]], atol=1e-15)


def test_flat_face_is_the_plate():
    """The paper's free plate: the same discrete load as the plate model (to rounding)."""
    nx, ny = 8, 4
    with build_problem(paper_case("free", nx, ny)) as plate:
        expected = plate.solve_free().load
    sec = flat_face_mesh(0.1, 0.2, cells=(nx, ny))
    prestress = solve_section_prestress(sec, PAPER, 0.006, -1.0)
    model = ShellModel(sec, PAPER, 0.006, prestress.N0, _flat_plate_supports())
    try:
        # Both solves to eps_tol = 1e-10: the pencils' bending blocks are the same matrices.
        assert _smallest(model) == pytest.approx(expected, rel=1e-9)
    finally:
        model.destroy()


@pytest.mark.parametrize("donnell", [True, False])
def test_rotated_face_has_the_rotated_pencil(donnell):
    """Objectivity: A and B of a face turned in space are Q^T A Q, Q^T B Q (Q per node)."""
    R = np.linalg.qr(np.array([[0.3, -1.2, 0.4], [0.8, 0.5, -0.2], [0.1, 0.7, 1.1]]))[0]
    mats = []
    for turn in (np.eye(3), R):
        sec = flat_face_mesh(0.1, 0.2, cells=(4, 2), comm=MPI.COMM_SELF)
        sec.mesh.geometry.x[:] = sec.mesh.geometry.x @ turn.T
        N0 = dolfinx.fem.Constant(sec.mesh, np.array([[-0.006, 0.001], [0.001, -0.002]]))
        model = ShellModel(sec, PAPER, 0.006, N0, [], donnell=donnell)
        mats.append([m.convert("dense").getDenseArray().copy() for m in (model.A, model.B)])
        model.destroy()
    n = mats[0][0].shape[0] // 6
    Q = np.kron(np.eye(2 * n), R)  # u and omega of every node turn alike
    for k in range(2):
        base, turned = mats[0][k], mats[1][k]
        assert np.abs(Q @ base @ Q.T - turned).max() <= 1e-12 * np.abs(base).max()


def test_uniform_end_stress_gives_uniaxial_prestress():
    for sec in (box_mesh(0.2, 0.1, 0.3, 0.05), tube_mesh(0.2, 0.2, 0.04)):
        p = solve_section_prestress(sec, STEEL, 0.002, -1.0)
        assert p.max_compression == pytest.approx(0.002, rel=1e-10)
        assert p.max_tension <= 1e-10 * 0.002


def _axial_force_error(size: float) -> float:
    """RMS error of N0_11 at the cells' centres against t (-1 + 0.5 z/(d/2)), relative to t."""
    sec = box_mesh(0.2, 0.1, 0.3, size)
    p = solve_section_prestress(sec, STEEL, 0.002, -1.0, 0.5)
    x = ufl.SpatialCoordinate(sec.mesh)
    expr = dolfinx.fem.Expression(ufl.as_vector([p.N0[0, 0], x[2]]), np.array([[0.5, 0.5]]))
    n = sec.mesh.topology.index_map(2).size_local
    v = expr.eval(sec.mesh, np.arange(n, dtype=np.int32)).reshape(n, 2)
    error = v[:, 0] - 0.002 * (-1.0 + 0.5 * v[:, 1] / 0.05)
    squares = sec.mesh.comm.allreduce(float(error @ error), op=MPI.SUM)
    count = sec.mesh.comm.allreduce(n, op=MPI.SUM)
    return math.sqrt(squares / count) / 0.002


def test_axial_force_with_bending_converges_to_the_linear_stress():
    """Measured: 2.5e-3 and 7.4e-4 at d/4 and d/8 (rate 1.8): the error shrinks with h."""
    coarse, fine = _axial_force_error(0.025), _axial_force_error(0.0125)
    assert fine < 1e-3 and coarse / fine > 3.0, (coarse, fine)


def _box_load(size, ends="simply_supported", **kwargs):
    sec = box_mesh(0.2, 0.2, 0.4, size)
    prestress = solve_section_prestress(sec, STEEL, 0.002, -1.0)
    model = ShellModel(sec, STEEL, 0.002, prestress.N0, end_supports(sec, ends), **kwargs)
    try:
        return _smallest(model)
    finally:
        model.destroy()


def test_square_box_buckles_at_k_4():
    """b/t = 100, L = 2b (two half-waves per face), simply supported ends: k = 4.00 +- 1.5 %."""
    D = bending_stiffness(STEEL.E, STEEL.nu, 0.002)
    k = _box_load(0.2 / 12) * 0.002 * 0.2**2 / (math.pi**2 * D)
    assert k == pytest.approx(4.0, rel=0.015), f"k = {k:.5f}"


def test_tube_buckles_at_the_classical_stress():
    """R/t = 100, L = R/2, cells of 0.04 R (about 4 per axial half-wave 1.73 sqrt(Rt))."""
    sec = tube_mesh(0.2, 0.05, 0.004)
    prestress = solve_section_prestress(sec, STEEL, 0.001, -1.0)
    model = ShellModel(
        sec, STEEL, 0.001, prestress.N0, end_supports(sec, "simply_supported"), donnell=True
    )
    try:
        ratio = _smallest(model) / (STEEL.E * 0.001 / (0.1 * math.sqrt(3 * (1 - STEEL.nu**2))))
    finally:
        model.destroy()
    assert ratio == pytest.approx(1.0, abs=0.03), f"sigma / sigma_cl = {ratio:.4f}"


@pytest.mark.parametrize("ends", ["simply_supported", "clamped"])
@pytest.mark.parametrize("shape", ["box", "tube"])
def test_stiffness_is_positive_definite_after_the_end_supports(shape, ends):
    """MUMPS's inertia of A: no negative and no zero pivot (drilling included)."""
    sec = box_mesh(0.2, 0.1, 0.3, 0.05) if shape == "box" else tube_mesh(0.2, 0.2, 0.04)
    prestress = solve_section_prestress(sec, STEEL, 0.002, -1.0)
    model = ShellModel(sec, STEEL, 0.002, prestress.N0, end_supports(sec, ends))
    factor = SymmetricFactorization(model.A, "test_shell_inertia_")
    try:
        negative, zero, positive = factor.inertia()
    finally:
        factor.destroy()
        model.destroy()
    assert (negative, zero) == (0, 0) and positive == model.num_dofs


def test_drilling_stiffness_does_not_change_the_load():
    """Drilling stiffness 1e-5 to 1e-1 of Gt: the load moves far less than the mesh error."""
    loads = [_box_load(0.05, drilling=d) for d in (1e-5, 1e-3, 1e-1)]
    assert max(loads) / min(loads) - 1.0 < 1e-3, loads


@pytest.mark.parametrize(
    ("changes", "key"),
    [
        ({"shape": "tube", "diameter": 0.2, "width": 0.2}, "section.width"),
        ({"depth": None}, "section.depth"),
        ({"thickness": 0.1}, "section.thickness"),
        ({"core_span": (0.0, 0.1)}, "obstacle.span"),
        ({"ends": "pinned"}, "section.ends"),
        ({"shape": "tube", "width": None, "depth": None}, "section.diameter"),
    ],
)
def test_bad_section_input_is_refused(changes, key):
    base = {
        "shape": "box", "thickness": 0.002, "length": 0.6, "E": 2.1e11, "nu": 0.3,
        "mesh_size": 0.01, "width": 0.2, "depth": 0.2,
    }  # fmt: skip
    with pytest.raises(InputError, match=key.replace(".", r"\.")):
        SectionParameters(**{**base, **changes})


@pytest.mark.parametrize("corner", [None, 0.001, 0.004])
def test_a_face_s_cells_are_counted_as_the_mesh_places_them(corner):
    """grid_nodes and face_cell_width count a face's cells without its arrays: equal to them.

    Box faces 0.013 to 0.3 m on cells of 5 mm to 0.2 m, uniform and graded at the corners
    (a box_mesh face's nodes: _face_fractions).
    """
    from unibuckle_fenicsx.model.shell.geometry import _face_fractions, face_cell_width, grid_nodes

    for extent in (0.013, 0.05, 0.1, 0.2, 0.3):
        for size in (0.005, 0.0125, 0.02, 0.07, 0.2):
            nodes = _face_fractions(extent, size, corner)
            around, _ = grid_nodes("box", (extent, extent), 1.0, size, corner)
            assert around == 4 * (nodes.size - 1), (extent, size)
            widest = extent * float(np.diff(nodes).max())
            assert face_cell_width(extent, size, corner) == pytest.approx(widest, rel=1e-12)
