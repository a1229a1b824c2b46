r"""Mesh convergence of the section model to its classical anchors (``-m convergence``).

- Square box, b/t = 100, L = 2b, simply supported ends: k = 4.00 (Timoshenko & Gere,
  section 9.2; each face a plate simply supported on four edges). Measured k = 4.0503,
  4.0066, 3.9929 at b/10, b/20, b/40 for L = 3b; the limit lies 0.3 % below 4: at a
  corner a face's tangential rotation is held only by the neighbouring face's membrane
  (the drilling term), a "soft" simple support, whose Reissner-Mindlin boundary layer the
  finer meshes resolve (the plate with soft supports: 4.0515, 4.0077, 3.9941).
- Circular tube, R/t = 100, L = R, simply supported ends (SS3: w = v = 0, N_x = 0):
  :math:`\sigma_{cl} = E t/(R\sqrt{3(1-\nu^2)})` (Timoshenko & Gere, section 11.4)
  with Donnell's geometric stiffness; with the full one (the default) Sanders' equations,
  0.9601 σ_cl in n = 7 waves (:func:`support.cylinders.sanders_stress`): Donnell's
  shallow-shell theory is 4 % high on this short tube's modes of few waves.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from support.cylinders import sanders_stress
from unibuckle_fenicsx.la.eigen import GEPSolver
from unibuckle_fenicsx.model.materials import bending_stiffness
from unibuckle_fenicsx.model.shell.geometry import box_mesh, tube_mesh
from unibuckle_fenicsx.model.shell.model import ShellModel, end_supports
from unibuckle_fenicsx.model.shell.prestress import solve_section_prestress
from unibuckle_fenicsx.spec import Material

pytestmark = pytest.mark.convergence

STEEL = Material(E=2.1e11, nu=0.3)


def _load(section, thickness, **kwargs):
    prestress = solve_section_prestress(section, STEEL, thickness, -1.0)
    model = ShellModel(
        section, STEEL, thickness, prestress.N0, end_supports(section, "simply_supported"),
        **kwargs,
    )  # fmt: skip
    solver = GEPSolver(model.A, model.B, prefix="test_shell_convergence_")
    try:
        return solver.solve().value
    finally:
        solver.destroy()
        model.destroy()


def test_box_converges_to_k_4():
    b, t = 0.2, 0.002
    D = bending_stiffness(STEEL.E, STEEL.nu, t)
    ks = [
        _load(box_mesh(b, b, 2 * b, b / n), t) * t * b**2 / (math.pi**2 * D) for n in (10, 20, 40)
    ]
    print("square box k at b/10, b/20, b/40:", ks)
    for k in ks:
        assert k == pytest.approx(4.0, rel=0.015), ks
    d1, d2 = ks[0] - ks[1], ks[1] - ks[2]
    assert d1 > 0 and d2 > 0 and d1 / d2 > 2.5, f"differences {d1:.4g}, {d2:.4g}"
    limit = ks[2] - d2 / 3.0  # Richardson, rate 2
    assert limit == pytest.approx(4.0, rel=0.005), f"extrapolated k = {limit:.4f}"


def test_tube_converges_to_the_classical_stress():
    R, t = 0.1, 0.001
    sigma_cl = STEEL.E * t / (R * math.sqrt(3.0 * (1.0 - STEEL.nu**2)))
    sizes = (0.004, 0.003, 0.002)
    ratios = [_load(tube_mesh(2 * R, R, h), t, donnell=True) / sigma_cl for h in sizes]
    print("tube sigma/sigma_cl at h = 4, 3, 2 mm:", ratios)
    for r in ratios:
        assert r == pytest.approx(1.0, abs=0.03), ratios
    # Rate 2 between the last two meshes: e(h) = c h^2.
    h1, h2 = sizes[1:]
    limit = ratios[2] - (ratios[1] - ratios[2]) * h2**2 / (h1**2 - h2**2)
    observed = np.log((ratios[0] - ratios[1]) / (ratios[1] - ratios[2]))
    print(f"extrapolated {limit:.4f}; log ratio of differences {observed:.3f}")
    assert limit == pytest.approx(1.0, abs=0.03), f"extrapolated {limit:.4f}"


def _axisymmetric_one_sided(n: int) -> float:
    r"""Load of the one-sided axisymmetric buckle of a long tube over :math:`\sigma_{cl}`.

    The axisymmetric shell equation :math:`D w'''' + \sigma t w'' + (Et/R^2) w = p` (the
    hoop stiffness a Winkler foundation), scaled by :math:`\beta^4 = Et/(4DR^2)`:
    :math:`w'''' + 2 q w'' + 4 w = 0` with :math:`q = 2\sigma/\sigma_{cl}`. A bulge lifted
    off the core over [0, L] has w = w' = 0 at its ends; it is admissible while its first
    mode keeps one sign, and its load falls with L: the critical bulge is the longest one
    whose first mode is positive. Second-order finite differences on n cells.
    """
    import scipy.linalg
    import scipy.optimize

    def first(L: float) -> tuple[float, bool]:
        h = L / n
        m = n - 1
        D2 = (
            np.diag(-2.0 * np.ones(m)) + np.diag(np.ones(m - 1), 1) + np.diag(np.ones(m - 1), -1)
        ) / h**2
        D4 = D2 @ D2
        D4[0, 0] += 1.0 / h**4  # w' = 0 at the ends: the ghost node mirrors its neighbour
        D4[-1, -1] += 1.0 / h**4
        mu, v = scipy.linalg.eigh(D4 + 4.0 * np.eye(m), -D2, subset_by_index=[0, 0])
        w = v[:, 0] * np.sign(v[m // 2, 0])
        return float(mu[0]) / 4.0, bool(np.all(w > -1e-9 * np.abs(w).max()))

    lengths = np.linspace(2.0, 6.0, 41)
    longest = max(L for L in lengths if first(L)[1])
    found = scipy.optimize.minimize_scalar(
        lambda L: first(L)[0] if first(L)[1] else np.inf,
        bounds=(longest - 0.1, longest + 0.1),
        method="bounded",
        options={"xatol": 1e-9},
    )
    return float(found.fun)


def test_one_sided_axisymmetric_buckle_is_five_thirds():
    """The 1-D reference the tube with a core is compared with: 5/3 sigma_cl to 1e-4.

    (A bulge 1 - cos(2 pi x / l) gives the Rayleigh quotient sqrt(3) sigma_cl, an upper
    bound; the exact one-sided buckle is lower.)
    """
    coarse, fine = _axisymmetric_one_sided(200), _axisymmetric_one_sided(400)
    limit = fine + (fine - coarse) / 3.0
    print(f"one-sided axisymmetric buckle: {coarse:.6f}, {fine:.6f}, extrapolated {limit:.6f}")
    assert limit == pytest.approx(5.0 / 3.0, abs=1e-4)


def _plate_with_obstacle(unloaded: str, n: int) -> float:
    """A face as a plate: its k at a/b = 3, b/t = 100, whole-plate obstacle, SS loaded edges."""
    from unibuckle_fenicsx.analysis import solve
    from unibuckle_fenicsx.spec import ObstacleSpec
    from unibuckle_fenicsx.spec.cases import plate_case

    spec = plate_case(
        "face", length=0.6, width=0.2, thickness=0.002, nx=3 * n, ny=n, material=STEEL,
        supports={"bottom": unloaded, "top": unloaded}, zone=ObstacleSpec(zone="all"),
    )  # fmt: skip
    with solve(spec) as analysis:
        k = analysis.result.buckling_coefficient_k
    assert k is not None
    return float(k)


@pytest.mark.slow
def test_core_restrains_the_box_corners():
    r"""Square box with a core, b/t = 100, L = 3b, simply supported ends.

    Every face may only move outward, so neighbouring faces cannot buckle in and out
    alternately; a corner can rotate only by moving outward, which stretches the faces
    (membrane): its rotation is elastically restrained. The box's k lies between the
    face as a plate against a rigid face with simply supported unloaded edges and with
    clamped ones (the package's plate solver, same cells across the face).
    """
    from unibuckle_fenicsx.algorithms.section_levels import solve_levels
    from unibuckle_fenicsx.model.shell.section import SectionParameters

    n = 16
    params = SectionParameters(
        "box", width=0.2, depth=0.2, thickness=0.002, length=0.6, E=STEEL.E, nu=STEEL.nu,
        mesh_size=0.2 / n, ends="simply_supported", core=True, corner_cell=0.002,
    )  # fmt: skip
    section, solution = solve_levels(params, levels=1, route="interior-point")  # 3.1e4 DOFs
    with section:
        k_box = section.buckling_coefficient(solution.load)
        assert solution.candidate.kkt
    k_ss, k_c = _plate_with_obstacle("simply_supported", n), _plate_with_obstacle("clamped", n)
    print(
        f"k: plate SS + obstacle {k_ss:.4f}, box with core {k_box:.4f}, "
        f"plate C + obstacle {k_c:.4f}"
    )
    assert k_ss < k_box < k_c


def test_tube_with_the_full_geometric_stiffness_converges_to_sanders():
    # Measured 0.974, 0.967, 0.962 at h = 4, 3, 2 mm; Sanders' 0.9601 (n = 7).
    R, t = 0.1, 0.001
    sigma_cl = STEEL.E * t / (R * math.sqrt(3.0 * (1.0 - STEEL.nu**2)))
    reference, waves = sanders_stress(R, t, R, STEEL.E, STEEL.nu)
    assert waves == 7 and reference / sigma_cl == pytest.approx(0.9601, abs=1e-4)
    sizes = (0.003, 0.002)
    ratios = [_load(tube_mesh(2 * R, R, h), t) / reference for h in sizes]
    h1, h2 = sizes
    limit = ratios[1] - (ratios[0] - ratios[1]) * h2**2 / (h1**2 - h2**2)
    print("tube (full) sigma/Sanders' at h = 3, 2 mm:", ratios, f"extrapolated {limit:.4f}")
    assert limit == pytest.approx(1.0, abs=0.01), f"extrapolated {limit:.4f}"
