r"""Elastically restrained edges: rotational and translational springs along an edge.

Expected values:

- limits on the same mesh: :math:`k_r = 0` is the support alone (the same matrices);
  :math:`k_r \to \infty` the clamped edge and :math:`k_t \to \infty` (with support
  "free") the soft simple support, with an error of first order in :math:`1/k`;
- bilateral, Kirchhoff closed form: a plate a × b simply supported on its loaded edges,
  both long edges simply supported with a rotational spring :math:`k_r`, buckles in
  :math:`w = \sin(m\pi x/a) Y(y)` with :math:`Y = A\cosh r_1\eta + B\cos r_2\eta`
  (:math:`\eta = y - b/2`, the symmetric mode), :math:`r_{1,2}^2 = \sqrt{N/D}\,\alpha \pm
  \alpha^2`, :math:`\alpha = m\pi/a`, and the edge conditions Y = 0,
  :math:`D Y'' + k_r Y' = 0` at :math:`\eta = b/2`: a 2 × 2 determinant, solved here by
  bracketing and Brent's method (the classical treatment of elastically restrained
  edges: Timoshenko and Gere, *Theory of Elastic Stability*, 1961, section 9.2;
  Bleich, *Buckling Strength of Metal Structures*, 1952, chapter IX); its clamped limit
  for the long plate is the published k = 6.97 (Timoshenko and Gere, section 9.2);
- unilateral, a whole-plate obstacle: the Kirchhoff plate on bicubic Hermite elements
  with its own active-set loop (``tests/support/hermite_plate.py``, nothing shared with the
  package).
"""

from __future__ import annotations

import math

from mpi4py import MPI

import numpy as np
import pytest
from msgspec.structs import replace
from scipy.optimize import brentq

from support.hermite_plate import HermitePlate, isotropic
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.model.materials import bending_stiffness
from unibuckle_fenicsx.spec import EdgeSpec, ObstacleSpec, problem_from_dict, problem_to_dict
from unibuckle_fenicsx.spec.cases import plate_case

THICKNESS = 1e-3  # b = 1 m: t/b = 1e-3, Kirchhoff and Reissner-Mindlin agree to ~1e-5
D = bending_stiffness(1.0e9, 0.3, THICKNESS)


def restrained_k(aspect: float, K: float, m_max: int = 30) -> float:
    """Kirchhoff k of the a x 1 plate, long edges with springs K = k_r b/D (closed form)."""
    c = 0.5

    def det(n, al):  # n = N/D; the 2 x 2 determinant over cosh(r1 c)
        r1 = np.sqrt(al * al + al * np.sqrt(n))
        r2 = np.sqrt(al * np.sqrt(n) - al * al)
        a21 = r1 * r1 + K * r1 * np.tanh(r1 * c)
        a22 = -r2 * r2 * np.cos(r2 * c) - K * r2 * np.sin(r2 * c)
        return a22 - np.cos(r2 * c) * a21

    best = math.inf
    for m in range(1, m_max + 1):
        al = m * math.pi / aspect
        grid = np.linspace(al * al * (1 + 1e-12), al * al + 100 * math.pi**2, 4001)
        values = det(grid, al)
        k = np.flatnonzero(values[:-1] * values[1:] < 0)[0]  # the first root
        root = brentq(lambda n, al=al: float(det(n, al)), grid[k], grid[k + 1], xtol=1e-14)
        best = min(best, root)
    return best / math.pi**2


def restrained(spec, names=("bottom", "top"), **springs):
    edges = tuple(replace(e, **springs) if e.name in names else e for e in spec.plate.edges)
    return replace(spec, plate=replace(spec.plate, edges=edges))


def long_plate(n, supports="simply_supported", zone=None, aspect=3.0):
    return plate_case(
        "restrained",
        length=aspect,
        width=1.0,
        thickness=THICKNESS,
        nx=round(aspect * n),
        ny=n,
        supports=supports,
        zone=zone,
    )


def load(spec):
    with solve(spec, MPI.COMM_WORLD) as analysis:
        return analysis.result


# -- schema ------------------------------------------------------------------------------
def test_spring_keys_are_read_converted_and_written_back():
    data = {
        "units": "mm-N-MPa",
        "plate": {"corners": [[0, 0], [300, 100]], "thickness": 1.0},
        "material": {"E": 1000.0, "nu": 0.3},
        "edges": {
            "bottom": {"rotational_stiffness": 5.0},  # N (N mm/mm/rad) in both systems
            "top": {"support": "free", "translational_stiffness": 0.25},  # N/mm^2
            "left": {"normal_stress": -1.0},
        },
    }
    spec = problem_from_dict(data)
    assert spec.plate.edge("bottom").rotational_stiffness == 5.0
    assert spec.plate.edge("top").translational_stiffness == pytest.approx(0.25e6, rel=1e-15)
    assert problem_from_dict(problem_to_dict(spec, units="mm-N-MPa")) == spec
    written = problem_to_dict(spec, units="mm-N-MPa")["edges"]
    assert written["top"]["translational_stiffness"] == pytest.approx(0.25)
    assert written["bottom"]["rotational_stiffness"] == 5.0
    assert written["left"]["rotational_stiffness"] == 0.0


@pytest.mark.parametrize(
    "kw, match",
    [
        ({"rotational_stiffness": -1.0}, r"edges\.e\.rotational_stiffness must be >= 0"),
        ({"rotational_stiffness": "stiff"}, r"edges\.e\.rotational_stiffness must be a number"),
        ({"translational_stiffness": math.inf}, r"translational_stiffness must be a finite"),
        (
            {"support": "clamped", "rotational_stiffness": 1.0},
            r'rotational_stiffness: support = "clamped" fixes the rotation',
        ),
        (
            {"translational_stiffness": 1.0},
            r'translational_stiffness: support = "simply_supported" fixes the deflection',
        ),
    ],
)
def test_bad_springs_are_refused(kw, match):
    with pytest.raises(ValueError, match=match):
        EdgeSpec("e", **kw)


# -- limits ------------------------------------------------------------------------------
def test_spring_limits_are_the_supports():
    """Springs of 0 are the support alone (same matrices); stiff ones clamped or soft, O(1/k)."""
    base = long_plate(8)
    ss = load(base).critical_load_Pa
    assert load(restrained(base, rotational_stiffness=0.0)).critical_load_Pa == ss
    clamped = load(long_plate(8, {"bottom": "clamped", "top": "clamped"})).critical_load_Pa
    errors = []
    for K in (1e6, 1e9):
        sprung = load(restrained(base, rotational_stiffness=K * D)).critical_load_Pa
        errors.append(abs(sprung / clamped - 1))
    assert errors[0] < 1e-4 and errors[1] < 1e-7, errors
    assert 500 < errors[0] / errors[1] < 2000, errors  # first order in 1/k_r

    free = long_plate(8, {"bottom": "free", "top": "free"})
    soft = long_plate(8, {"bottom": "simply_supported_soft", "top": "simply_supported_soft"})
    assert load(restrained(free, translational_stiffness=0.0)).critical_load_Pa == (
        load(free).critical_load_Pa
    )
    soft_load = load(soft).critical_load_Pa
    errors = []
    for K in (1e6, 1e9):
        sprung = load(restrained(free, translational_stiffness=K * D)).critical_load_Pa
        errors.append(abs(sprung / soft_load - 1))
    assert errors[0] < 1e-3 and errors[1] < 1e-6, errors
    assert 500 < errors[0] / errors[1] < 2000, errors


# -- bilateral: the closed form ----------------------------------------------------------
def test_closed_form_against_the_hermite_plate_and_the_published_clamped_value():
    """The two references agree and k -> 6.97 clamped.

    The C1 element converges at rate h^4: at 24 x 8 it is 1e-4 above the closed form,
    at 48 x 16 6e-6.
    """
    for K in (1.0, 10.0):
        bfs = HermitePlate(
            3.0,
            1.0,
            48,
            16,
            isotropic(1.0e9, 0.3, THICKNESS),
            rotational={"bottom": K * D, "top": K * D},
        )
        assert bfs.free_load() / (math.pi**2 * D) == pytest.approx(restrained_k(3.0, K), rel=1e-5)
    # Long plate, clamped unloaded edges: the minimum over the aspect ratio.
    clamped = min(restrained_k(a, 1e9, m_max=1) for a in np.linspace(0.6, 0.72, 25))
    assert clamped == pytest.approx(6.97, abs=0.005)


@pytest.mark.parametrize("K", [1.0, 10.0])
def test_rotational_springs_give_the_closed_form(K):
    """MITC4 at b/16 and b/32, Richardson (rate 2), against the closed form, to 1e-4."""
    k = [
        load(restrained(long_plate(n), rotational_stiffness=K * D)).buckling_coefficient_k
        for n in (16, 32)
    ]
    richardson = (4 * k[1] - k[0]) / 3
    exact = restrained_k(3.0, K)
    assert k[0] > k[1] > exact  # from above, as the element converges
    assert richardson == pytest.approx(exact, rel=1e-4), (k, richardson, exact)


# -- unilateral: the independent Kirchhoff plate -----------------------------------------
def test_long_plate_against_a_whole_plate_obstacle():
    """SSSS a/b = 3 with k_r = 2D/b on the long edges, whole-plate obstacle.

    Reference: the bicubic Hermite plate, 36 x 12 elements (54 x 18 gives 4e-5 more: its
    nodal obstacle converges from below). MITC4 at b/12 and b/16, Richardson (rate 2):
    the two agree to 2e-4; the springs raise k from 9/2 (README, "Every plate the schema
    describes") to 5.25.
    """
    bfs = HermitePlate(
        3.0,
        1.0,
        36,
        12,
        isotropic(1.0e9, 0.3, THICKNESS),
        rotational={"bottom": 2 * D, "top": 2 * D},
    )
    reference = bfs.unilateral_load()[0] / (math.pi**2 * D)
    k = []
    for n in (12, 16):
        result = load(
            restrained(long_plate(n, zone=ObstacleSpec("all")), rotational_stiffness=2 * D)
        )
        assert result.certificate.kkt
        k.append(result.buckling_coefficient_k)
    richardson = (16 * k[1] - 9 * k[0]) / 7
    assert 5.2 < reference < 5.3
    assert richardson == pytest.approx(reference, rel=2e-4), (k, richardson, reference)


# -- the nonlinear path --------------------------------------------------------------------
def test_nonlinear_path_with_springs_and_points_reaches_the_linear_load():
    """The von Karman plate (its own energy) with edge springs, a tie and a spring point.

    Its Southwell load equals the linear critical load of the same model to 1e-3 (the
    imperfection is 1e-3 t), which without the springs and points is 30 % lower: the
    nonlinear model holds every restraint the linear one does.
    """
    from unibuckle_fenicsx.nonlinear import NonlinearOptions, solve_nonlinear

    data = {
        "plate": {"corners": [[0, 0], [2.0, 1.0]], "thickness": 0.01},
        "material": {"E": 2.0e11, "nu": 0.3},
        "edges": {
            "left": {"normal_stress": -1.0},
            "right": {"normal_stress": -1.0},
            "bottom": {"rotational_stiffness": 3.0e5},
            "top": {"support": "free", "translational_stiffness": 5e6, "rotational_stiffness": 1e4},
        },
        "mesh": {"nx": 10, "ny": 5},
        "points": [{"at": [1.2, 0.4], "kind": "spring", "stiffness": 1e6}, {"at": [0.6, 0.6]}],
    }
    spec = problem_from_dict(data)
    bare = problem_from_dict(
        {k: v for k, v in data.items() if k != "points"}
        | {
            "edges": {
                "left": {"normal_stress": -1.0},
                "right": {"normal_stress": -1.0},
                "top": {"support": "free"},
            }
        }
    )
    options = NonlinearOptions(max_load=1.1, max_step=0.1)
    with solve_nonlinear(spec, options, MPI.COMM_WORLD) as analysis:
        nl = analysis.result
    assert nl.completed and nl.southwell_ratio == pytest.approx(1.0, abs=1e-3)
    assert load(bare).critical_load_Pa < 0.75 * nl.linear_critical_load_Pa
