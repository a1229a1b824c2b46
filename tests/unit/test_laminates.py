r"""Laminates: ``[[material.plies]]`` by classical lamination theory with first-order shear.

Expected values:

- one isotropic ply (at any angle), or a symmetric stack of isotropic plies, is the
  isotropic plate: the same A, D and :math:`\kappa_s G t`, and the same loads;
- the simply supported (0/90/90/0) square plate, :math:`E_1/E_2 = 40`,
  :math:`G_{12} = G_{13} = 0.6E_2`, :math:`G_{23} = 0.5E_2`, :math:`\nu_{12} = 0.25`,
  uniaxial compression: :math:`\bar N = N a^2/(E_2 h^3)` = 36.160 by classical
  lamination theory (thin) and 23.453 by first-order shear deformation theory with
  :math:`\kappa_s = 5/6` at a/h = 10 (Reddy, *Mechanics of Laminated Composite Plates and
  Shells*, 2nd ed., 2004, chapter 7, the table of buckling loads of cross-ply plates
  against the three-dimensional value 22.881 of Noor, 1975); both printed values are also
  recomputed here, by the Navier solution (a 3 x 3 system per half-wave number);
- a specially orthotropic plate (:math:`D_{16} = D_{26} = 0`), simply supported, long
  edge b, :math:`k = N b^2/(\pi^2\sqrt{D_{11}D_{22}})`, :math:`\eta = (D_{12} +
  2D_{66})/\sqrt{D_{11}D_{22}}`: bilateral :math:`k = \min_m [\delta (m b/a)^2 + 2\eta +
  (a/(mb))^2/\delta]`, :math:`\delta = \sqrt{D_{11}/D_{22}}` (Lekhnitskii; Jones,
  *Mechanics of Composite Materials*, 1999, section 5.5); against a whole-plate obstacle,
  the long plate buckles in :math:`w = f(x)\sin(\pi y/b)` and, with x stretched by
  :math:`(D_{11}/D_{22})^{1/4}`, f solves the isotropic plate's equation with
  :math:`k - 2\eta` in place of k - 2: the isotropic long-plate values 9/2 (a buckle
  against a simply supported loaded edge) and 16/3 (between two touch-down lines; README,
  "Every plate the schema describes") become :math:`2\eta + 5/2` and :math:`2\eta + 10/3`.
"""

from __future__ import annotations

import math

from mpi4py import MPI

import numpy as np
import pytest
from msgspec.structs import replace

from support.hermite_plate import HermitePlate
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.laminate import laminate
from unibuckle_fenicsx.model.materials import bending_voigt, membrane_voigt, shear_stiffness
from unibuckle_fenicsx.spec import Material, Ply, problem_from_dict, problem_to_dict
from unibuckle_fenicsx.spec.cases import paper_case

REDDY = {"E1": 40.0e9, "E2": 1.0e9, "G12": 0.6e9, "nu12": 0.25, "G13": 0.6e9, "G23": 0.5e9}
GLASS = {"E1": 40.0e9, "E2": 10.0e9, "G12": 4.5e9, "nu12": 0.25, "G13": 4.5e9, "G23": 3.5e9}


def stack(angles, thickness, material):
    return [{"thickness": thickness / len(angles), "angle": a, **material} for a in angles]


def square(angles, h, n, material=REDDY):
    """The simply supported 1 x 1 m plate, uniaxial compression along x, free in its plane."""
    return problem_from_dict(
        {
            "plate": {"corners": [[0, 0], [1, 1]]},
            "material": {"plies": stack(angles, h, material)},
            "mesh": {"nx": n, "ny": n},
        }
    )


def result(spec):
    with solve(spec, MPI.COMM_WORLD) as analysis:
        return analysis.result


def navier_fsdt(D, H, a, b, m_max=6):
    """N_cr (N/m) of a specially orthotropic simply supported plate, first-order shear."""
    best = math.inf
    for m in range(1, m_max + 1):
        al, be = m * math.pi / a, math.pi / b
        # Amplitudes (W, X, Y) of w = W sin sin, theta_x = X cos sin, theta_y = Y sin cos.
        S = np.array(
            [
                [H[0, 0] * al**2 + H[1, 1] * be**2, -H[0, 0] * al, -H[1, 1] * be],
                [
                    -H[0, 0] * al,
                    D[0, 0] * al**2 + D[2, 2] * be**2 + H[0, 0],
                    (D[0, 1] + D[2, 2]) * al * be,
                ],
                [
                    -H[1, 1] * be,
                    (D[0, 1] + D[2, 2]) * al * be,
                    D[2, 2] * al**2 + D[1, 1] * be**2 + H[1, 1],
                ],
            ]
        )
        schur = S[0, 0] - S[0, 1:] @ np.linalg.solve(S[1:, 1:], S[1:, 0])
        best = min(best, schur / al**2)
    return best


# -- schema ------------------------------------------------------------------------------
def test_plies_are_read_converted_and_written_back():
    data = {
        "units": "mm-N-MPa",
        "plate": {"corners": [[0, 0], [300, 100]]},
        "material": {
            "shear_correction": 0.8,
            "plies": stack(
                (0, 90, 90, 0),
                2.0,
                {
                    "E1": 40000.0,
                    "E2": 10000.0,
                    "G12": 4500.0,
                    "nu12": 0.25,
                    "G13": 4500.0,
                    "G23": 3500.0,
                },
            ),
        },
    }
    spec = problem_from_dict(data)
    assert spec.plate.thickness == pytest.approx(2e-3)  # the plies', when not given
    assert (
        spec.material.plies[0].E1 == pytest.approx(40e9) and spec.material.shear_correction == 0.8
    )
    assert problem_from_dict(problem_to_dict(spec, units="mm-N-MPa")) == spec
    written = problem_to_dict(spec, units="mm-N-MPa")["material"]
    assert set(written) == {"shear_correction", "plies", "thermal_expansion"}
    assert written["plies"][1] == pytest.approx(data["material"]["plies"][1])


PLY = {"thickness": 0.001, "angle": 0.0, **GLASS}


@pytest.mark.parametrize(
    "material, plate, match",
    [
        (
            {"plies": [PLY, {**PLY, "angle": 90.0}]},
            {},
            r"material\.plies: the stack is not symmetric",
        ),
        (
            {"plies": [PLY], "E": 1e9},
            {},
            r"material\.E and material\.nu of a laminate are its in-plane constants",
        ),
        ({"plies": [{**PLY, "nu12": 3.0}]}, {}, r"material\.plies\[0\]\.nu12 must satisfy"),
        (
            {"plies": [{**PLY, "G23": 0}]},
            {},
            r"material\.plies\[0\]\.G23 must lie in \[1000, 1e\+13\] Pa",
        ),
        (
            {"plies": [{k: v for k, v in PLY.items() if k != "G13"}]},
            {},
            r"\[material\.plies\[0\]\] needs 'G13'",
        ),
        ({"plies": []}, {}, r"material\.plies must be a list of tables"),
        # A fibre angle of 1e300 degrees ran (its cosine is rounding): one turn either way.
        (
            {"plies": [{**PLY, "angle": 1e300}]},
            {},
            r"material\.plies\[0\]\.angle must lie in \[-360, 360\] degrees, got 1e\+300",
        ),
        ({"plies": [PLY, {**PLY, "angle": -361.0}, PLY]}, {}, r"material\.plies\[1\]\.angle"),
        (
            {"plies": [PLY]},
            {"thickness": 0.002},
            r"plate\.thickness = 0\.002 m differs from the plies",
        ),
    ],
)
def test_bad_laminates_are_refused(material, plate, match):
    with pytest.raises(ValueError, match=match):
        problem_from_dict({"plate": plate, "material": material})


# -- the stiffness --------------------------------------------------------------------------
@pytest.mark.parametrize("angle", [0.0, 30.0, 90.0])
def test_one_isotropic_ply_is_the_isotropic_plate(angle):
    """Same A, D, H to rounding (and three isotropic plies are one)."""
    E, nu, t = 1.0e9, 0.3, 0.006
    G = E / (2 * (1 + nu))
    iso = Material(E=E, nu=nu)
    ply = Ply(t, angle, E, E, G, nu, G, G)
    lam = Material.from_plies([ply])
    assert lam.E == pytest.approx(E, rel=1e-14) and lam.nu == pytest.approx(nu, rel=1e-14)
    scale = {"A": E * t, "D": E * t**3}
    assert np.allclose(
        membrane_voigt(lam, t), membrane_voigt(iso, t), rtol=0, atol=1e-14 * scale["A"]
    )
    assert np.allclose(
        bending_voigt(lam, t), bending_voigt(iso, t), rtol=0, atol=1e-14 * scale["D"]
    )
    assert np.allclose(laminate([ply]).H, shear_stiffness(iso, t) * np.eye(2), rtol=1e-14)
    # Three isotropic plies (0.3 t, 0.4 t, 0.3 t) are one.
    thirds = Material.from_plies([Ply(f * t, angle, E, E, G, nu, G, G) for f in (0.3, 0.4, 0.3)])
    assert np.allclose(
        bending_voigt(thirds, t), bending_voigt(iso, t), rtol=0, atol=1e-14 * scale["D"]
    )


def test_one_isotropic_ply_gives_the_isotropic_unilateral_result():
    """The paper's c1 case with its material as one ply at 30 degrees: same load and Z."""
    E, nu = 1.0e9, 0.3
    G = E / (2 * (1 + nu))
    c1 = paper_case("c1", 10, 10)
    plied = replace(c1, material=Material.from_plies([Ply(0.006, 30.0, E, E, G, nu, G, G)]))
    plain, laminated = result(c1), result(plied)
    assert laminated.critical_load_Pa == pytest.approx(plain.critical_load_Pa, rel=1e-10)
    assert laminated.contact_indices == plain.contact_indices and plain.contact_nodes > 0


def test_published_cross_ply_values():
    """(0/90/90/0), E1/E2 = 40: CLPT 36.160 (thin), FSDT 23.453 (a/h = 10), Reddy (2004)."""
    plies = [Ply(0.025, a, **REDDY) for a in (0.0, 90.0, 90.0, 0.0)]
    lam = laminate(plies)
    D, h, E2 = lam.D, 0.1, REDDY["E2"]
    clpt = math.pi**2 * (D[0, 0] + 2 * (D[0, 1] + 2 * D[2, 2]) + D[1, 1]) / (E2 * h**3)
    assert clpt == pytest.approx(36.160, abs=5e-4)
    assert navier_fsdt(D, lam.H, 1.0, 1.0) / (E2 * h**3) == pytest.approx(23.453, abs=5e-4)


def test_thick_cross_ply_plate_gives_the_published_fsdt_load():
    """MITC4 16 x 16, 32 x 32 of the a/h = 10 plate, Richardson, against 23.453 to 1e-4."""
    N = [
        result(square((0.0, 90.0, 90.0, 0.0), 0.1, n)).critical_load_Pa * 0.1 / (1e9 * 0.1**3)
        for n in (16, 32)
    ]
    richardson = (4 * N[1] - N[0]) / 3
    assert richardson == pytest.approx(23.453, rel=1e-4), (N, richardson)


# -- specially orthotropic closed forms -----------------------------------------------------
THIN = 1e-3  # b = 1 m


def long_plate(n, zone):
    data = {
        "plate": {"corners": [[0, 0], [3, 1]]},
        "material": {"plies": stack((90.0, 0.0, 90.0), THIN, GLASS)},
        "edges": {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}},
        "mesh": {"nx": 3 * n, "ny": n},
    }
    if zone:
        data["obstacle"] = {"zone": "all"}
    return problem_from_dict(data)


def orthotropic_constants():
    D = laminate([Ply(THIN / 3, a, **GLASS) for a in (90.0, 0.0, 90.0)]).D
    assert abs(D[0, 2]) < 1e-12 * D[0, 0] and abs(D[1, 2]) < 1e-12 * D[0, 0]
    return math.sqrt(D[0, 0] / D[1, 1]), (D[0, 1] + 2 * D[2, 2]) / math.sqrt(D[0, 0] * D[1, 1]), D


def test_specially_orthotropic_plate_bilateral():
    """(90/0/90) glass-epoxy, a/b = 3, t/b = 1e-3: MITC4 b/16, b/32, Richardson, to 1e-4."""
    delta, eta, _ = orthotropic_constants()
    exact = min(delta * (m / 3) ** 2 + 2 * eta + (3 / m) ** 2 / delta for m in range(1, 30))
    k = [result(long_plate(n, zone=False)).buckling_coefficient_k for n in (16, 32)]
    richardson = (4 * k[1] - k[0]) / 3
    assert richardson == pytest.approx(exact, rel=1e-4), (k, richardson, exact)


def test_specially_orthotropic_plate_against_a_whole_plate_obstacle():
    """The long plate's buckle at a loaded edge: k = 2 eta + 5/2, 3.5929 here.

    The bicubic Hermite plate (its own active set) gives 3.5928 at 72 x 24 elements; MITC4
    at b/12 and b/16 with Richardson agrees with both to 1e-4 (the isotropic plate's 9/2
    becomes 2 eta + 5/2 < 9/2: these plies are stiffer across the load).
    """
    _, eta, D = orthotropic_constants()
    exact = 2 * eta + 2.5
    bfs = HermitePlate(3.0, 1.0, 36, 12, (D[0, 0], D[0, 1], D[1, 1], D[2, 2]))
    reference = bfs.unilateral_load()[0] / (math.pi**2 * math.sqrt(D[0, 0] * D[1, 1]))
    assert reference == pytest.approx(exact, rel=2e-4)
    k = []
    for n in (12, 16):
        out = result(long_plate(n, zone=True))
        assert out.certificate.kkt
        k.append(out.buckling_coefficient_k)
    richardson = (16 * k[1] - 9 * k[0]) / 7
    assert richardson == pytest.approx(exact, rel=1e-4), (k, richardson, exact)


def test_a_laminate_whose_nu_xy_exceeds_one_half_is_accepted():
    """A stack's in-plane nu_xy may exceed 0.5, the bound of an isotropic nu.

    The file's reader gives a laminate E_x and nu_xy from its plies, and ``material.nu``
    was bounded to (-1, 0.5): a balanced +-45 glass stack (nu_xy = 0.513) or a 0 ply with
    nu12 = 0.6 was refused with "material.nu must be a number, got None (absent)", a key
    the file did not give. By hand (classical lamination theory): at 45 degrees
    Qb11 = (Q11 + Q22 + 2 Q12 + 4 Q66)/4, Qb12 = (Q11 + Q22 - 4 Q66)/4 + Q12/2, A16 = 0
    for the balanced stack, nu_xy = A12/A22 = Qb12/Qb11. The 0 ply (nu_xy = nu12) on the
    simply supported a/h = 10 square: MITC4 on 16 x 16 and 32 x 32, Richardson, against
    the first-order shear Navier load with D = Q h^3/12 and H = (5/6) diag(G13, G23) h.
    """
    E1, E2, G12, nu12 = (GLASS[k] for k in ("E1", "E2", "G12", "nu12"))
    nu21 = nu12 * E2 / E1
    Q11, Q22, Q12 = E1 / (1 - nu12 * nu21), E2 / (1 - nu12 * nu21), nu12 * E2 / (1 - nu12 * nu21)
    Qb11 = (Q11 + Q22 + 2 * Q12 + 4 * G12) / 4
    Qb12 = (Q11 + Q22 - 4 * G12) / 4 + Q12 / 2
    assert Qb12 / Qb11 > 0.5
    angle_ply = square((45.0, -45.0, -45.0, 45.0), 0.01, 4, GLASS)
    assert angle_ply.material.nu == pytest.approx(Qb12 / Qb11, rel=1e-12)

    ply = {**GLASS, "nu12": 0.6}  # |nu12| < sqrt(E1/E2) = 2: a positive definite ply
    h = 0.1
    nu21 = ply["nu12"] * E2 / E1
    den = 1 - ply["nu12"] * nu21
    Q = np.array([[E1 / den, ply["nu12"] * E2 / den, 0], [ply["nu12"] * E2 / den, E2 / den, 0]])
    D = np.vstack([Q, [0, 0, ply["G12"]]]) * h**3 / 12
    H = 5 / 6 * np.diag([ply["G13"], ply["G23"]]) * h
    loads = [result(square((0.0,), h, n, ply)).critical_load_Pa * h for n in (16, 32)]
    assert square((0.0,), h, 4, ply).material.nu == pytest.approx(0.6, rel=1e-12)
    richardson = (4 * loads[1] - loads[0]) / 3
    assert richardson == pytest.approx(navier_fsdt(D, H, 1.0, 1.0), rel=2e-5), loads
