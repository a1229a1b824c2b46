r"""Plane-elasticity prestress (paper eq. [1]): N0 of the paper's case and equilibrium.

The plate and the helpers shared with the MPI scripts (``tests/mpi/pipeline_*.py``) are
in :mod:`support.plates`.
"""

from __future__ import annotations

from mpi4py import MPI

import numpy as np
import pytest

from support.plates import MATERIAL, T, clamped_left_plate, n0_at_quadrature_points, strip_average
from unibuckle_fenicsx.model.mesh import create_plate_mesh
from unibuckle_fenicsx.model.prestress import solve_prestress
from unibuckle_fenicsx.spec import EdgeSpec, MeshSpec, PlateSpec
from unibuckle_fenicsx.spec.cases import paper_case


@pytest.mark.parametrize("degree", [1, 2])
def test_paper_case_is_uniaxial(degree):
    """Free lateral expansion under unit compression on x = +-0.1: N0 = diag(-t, 0) exactly."""
    spec = paper_case("free", 10, 6)
    msh, tags = create_plate_mesh(spec.plate, spec.mesh, MPI.COMM_WORLD)
    ps = solve_prestress(msh, tags, spec.plate, spec.material, degree=degree)
    values = n0_at_quadrature_points(msh, ps.N0)
    exact = np.array([[-T, 0.0], [0.0, 0.0]])
    # MUMPS on a well-conditioned 2D elasticity matrix: relative error near 1e-13.
    err = np.abs(values - exact).max() / T
    assert err < 1e-10, err
    assert ps.pinned_rigid_motions
    assert not ps.indefinite
    assert ps.max_compression == pytest.approx(T, rel=1e-10)
    assert ps.max_tension < 1e-10 * T


def test_clamped_edge_prestress_is_non_uniform_but_in_equilibrium():
    """Left edge clamped in plane, unit compression on the right edge only.

    Equilibrium of the discrete problem with the test function (phi(x), 0), phi the Q1
    ramp across the band x1 < x < x2 of mesh columns (phi = 0 on the clamped edge, 1 on
    the loaded one), gives the band average of N0_xx = the applied force per unit load,
    -t * width, to solver precision; (0, phi) gives zero for N0_xy.
    """
    plate = clamped_left_plate()
    msh, tags = create_plate_mesh(plate, MeshSpec(20, 10), MPI.COMM_WORLD)
    ps = solve_prestress(msh, tags, plate, MATERIAL)
    assert not ps.pinned_rigid_motions
    values = n0_at_quadrature_points(msh, ps.N0)
    # Non-uniform: the clamp blocks the Poisson expansion, so N0_yy != 0 and N0_xx varies.
    nxx, nyy = values[:, 0, 0], values[:, 1, 1]
    assert nxx.max() - nxx.min() > 0.1 * T
    assert np.abs(nyy).max() > 0.1 * T
    force = -T * plate.width
    h = plate.length / 20
    for k1, k2 in [(0, 1), (0, 20), (5, 10), (13, 14), (19, 20)]:
        x1, x2 = -0.1 + k1 * h, -0.1 + k2 * h
        avg = strip_average(msh, ps.N0, x1, x2)
        assert avg == pytest.approx(force, rel=1e-12), (x1, x2, avg)
        shear = strip_average(msh, ps.N0, x1, x2, (0, 1))
        assert abs(shear) < 1e-12 * abs(force), (x1, x2, shear)


def test_clamped_edge_prestress_is_indefinite():
    """With the clamp, corners near the loaded edge see a small tension (B indefinite)."""
    plate = clamped_left_plate()
    msh, tags = create_plate_mesh(plate, MeshSpec(20, 10), MPI.COMM_WORLD)
    ps = solve_prestress(msh, tags, plate, MATERIAL)
    assert ps.max_compression > T
    assert ps.max_tension > 0.0 and ps.indefinite


def test_tensile_load_is_refused():
    """normal_stress = +1 on left and right pulls the plate: no buckling under lambda > 0."""
    edges = (
        EdgeSpec("left", normal_stress=1.0),
        EdgeSpec("right", normal_stress=1.0),
        EdgeSpec("bottom"),
        EdgeSpec("top"),
    )
    plate = PlateSpec(edges=edges)
    msh, tags = create_plate_mesh(plate, MeshSpec(6, 4), MPI.COMM_WORLD)
    with pytest.raises(ValueError, match=r"tension everywhere.*normal_stress"):
        solve_prestress(msh, tags, plate, MATERIAL)


def test_tension_varying_along_the_edge_is_refused():
    """Tension varying linearly along the loaded edges: no compression, no buckling.

    The exact field is sigma_xx linear in y, sigma_yy = 0 (the smaller principal force is
    zero everywhere): a degree-1 displacement cannot represent it, and its solve shows a
    compression of its discretisation error (0.6 % of the tension here), which vanishes at
    degree 2 (exact for this field). The check measures it there and refuses the load
    instead of letting the eigen solve look for a load factor of about 1/noise.
    """
    edges = (
        EdgeSpec("left", normal_stress=(1.0, 0.5)),
        EdgeSpec("right", normal_stress=(1.0, 0.5)),
        EdgeSpec("bottom"),
        EdgeSpec("top"),
    )
    plate = PlateSpec(corners=((0.0, 0.0), (0.4, 0.1)), thickness=0.002, edges=edges)
    msh, tags = create_plate_mesh(plate, MeshSpec(40, 10), MPI.COMM_WORLD)
    noisy = solve_prestress(msh, tags, plate, MATERIAL, fixed=True)
    assert 1e-10 * noisy.max_tension < noisy.max_compression < 1e-2 * noisy.max_tension
    with pytest.raises(ValueError, match=r"tension everywhere.*discretisation error"):
        solve_prestress(msh, tags, plate, MATERIAL)


def test_small_real_compression_is_kept():
    """A real compression of 0.5 % of the tension is kept.

    Tension 1 along x, compression 0.005 along y: the same at degree 2, so not taken for
    the discretisation error.
    """
    edges = (
        EdgeSpec("left", normal_stress=1.0),
        EdgeSpec("right", normal_stress=1.0),
        EdgeSpec("bottom", normal_stress=-0.005),
        EdgeSpec("top", normal_stress=-0.005),
    )
    plate = PlateSpec(corners=((0.0, 0.0), (0.4, 0.1)), thickness=0.002, edges=edges)
    msh, tags = create_plate_mesh(plate, MeshSpec(8, 2), MPI.COMM_WORLD)
    ps = solve_prestress(msh, tags, plate, MATERIAL)
    assert ps.max_compression == pytest.approx(0.005 * 0.002, rel=1e-8)  # 0.005 Pa x t


def test_unloaded_plate_is_refused():
    plate = PlateSpec(edges=tuple(EdgeSpec(n) for n in ("left", "right", "bottom", "top")))
    msh, tags = create_plate_mesh(plate, MeshSpec(4, 2), MPI.COMM_WORLD)
    with pytest.raises(ValueError, match="no edge is loaded"):
        solve_prestress(msh, tags, plate, MATERIAL)


def test_unbalanced_load_on_free_plate_is_refused():
    """Every edge free in plane and a load on one edge only: no equilibrium, clear error."""
    edges = (EdgeSpec("left", normal_stress=-1.0), EdgeSpec("right"), EdgeSpec("bottom"))
    plate = PlateSpec(edges=(*edges, EdgeSpec("top")))
    msh, tags = create_plate_mesh(plate, MeshSpec(4, 2), MPI.COMM_WORLD)
    with pytest.raises(ValueError, match=r"not self-equilibrated.*inplane"):
        solve_prestress(msh, tags, plate, MATERIAL)


def test_equilibrium_of_a_plate_is_checked_once(monkeypatch):
    """The loads of a plate free in its plane are checked on its first mesh only.

    The resultants are exact edge integrals of the applied stresses, the same on every
    mesh the package builds from the plate (``plate_mesh``); a refused load is refused on
    every mesh (a failed check is not remembered), and a mesh from elsewhere, whose tags
    decide where the loads act, is checked every time.
    """
    from unibuckle_fenicsx.model import prestress

    calls = []
    check = prestress.check_self_equilibrated
    monkeypatch.setattr(prestress, "EQUILIBRATED", set())
    monkeypatch.setattr(
        prestress, "check_self_equilibrated", lambda *a: calls.append(1) or check(*a)
    )
    edges = (EdgeSpec("left", normal_stress=-1.0), EdgeSpec("right", normal_stress=-1.0))
    plate = PlateSpec(edges=(*edges, EdgeSpec("bottom"), EdgeSpec("top")))
    for nx, ny in ((8, 4), (4, 2), (8, 4)):
        msh, tags = create_plate_mesh(plate, MeshSpec(nx, ny), MPI.COMM_WORLD)
        assert solve_prestress(msh, tags, plate, MATERIAL, plate_mesh=True).pinned_rigid_motions
    assert len(calls) == 1
    solve_prestress(msh, tags, plate, MATERIAL)  # not known to be the plate's own mesh
    assert len(calls) == 2
    edges = (EdgeSpec("left", normal_stress=-1.0), EdgeSpec("right"), EdgeSpec("bottom"))
    unbalanced = PlateSpec(edges=(*edges, EdgeSpec("top")))
    for nx, ny in ((4, 2), (8, 4)):
        msh, tags = create_plate_mesh(unbalanced, MeshSpec(nx, ny), MPI.COMM_WORLD)
        with pytest.raises(ValueError, match=r"not self-equilibrated"):
            solve_prestress(msh, tags, unbalanced, MATERIAL, plate_mesh=True)
    assert len(calls) == 4


def test_prestress_solves_leave_the_options_database_as_they_found_it():
    """The prestress solves' KSP options are defaults: a database value wins, none stays.

    README, "Command line": ``-unibuckle_prestress_pc_type lu`` reaches the plate's
    prestress solve; the defaults (:data:`~unibuckle_fenicsx.model.prestress.DIRECT_SOLVE`)
    are removed after it; options of other prefixes (a user's unprefixed ``-ksp_type``)
    are left alone. Before, DOLFINx's ``petsc_options`` overwrote the user's value,
    deleted the unprefixed ``ksp_type`` and ``pc_type`` and left its own four entries in
    the database for every later solve of the process. The loads are LU's and Cholesky's
    of the same matrix: equal to rounding.
    """
    from petsc4py import PETSc

    from unibuckle_fenicsx.model.shell.geometry import box_mesh
    from unibuckle_fenicsx.model.shell.prestress import solve_section_prestress

    opts = PETSc.Options()
    mine = {
        "ksp_type": "gmres",
        "pc_type": "jacobi",
        "unibuckle_prestress_pc_type": "lu",
        "unibuckle_section_prestress_pc_type": "lu",
    }
    before = opts.getAll()
    for key, value in mine.items():
        opts.setValue(key, value)
    try:
        spec = paper_case("free", 10, 6)
        msh, tags = create_plate_mesh(spec.plate, spec.mesh, MPI.COMM_WORLD)
        lu = solve_prestress(msh, tags, spec.plate, spec.material)
        section = box_mesh(0.1, 0.1, 0.2, 0.05, MPI.COMM_WORLD)
        solve_section_prestress(section, spec.material, 0.002, -1.0)
        assert opts.getAll() == {**before, **mine}
    finally:
        for key in mine:
            opts.delValue(key)
    assert opts.getAll() == before
    cholesky = solve_prestress(msh, tags, spec.plate, spec.material)
    assert opts.getAll() == before
    assert lu.max_compression == pytest.approx(cholesky.max_compression, rel=1e-12)
