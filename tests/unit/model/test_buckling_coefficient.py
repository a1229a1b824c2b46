r"""The buckling coefficient :math:`k = \sigma t b^2/(\pi^2 D)` of a plate.

Expected values: the classical coefficient of a simply supported plate under uniaxial
compression, :math:`k = (m b/a + a/(m b))^2`, minimal 4 at an integer aspect ratio a/b
(Timoshenko & Gere, *Theory of Elastic Stability*, 1961, section 9.2), b the loaded edge;
in shear :math:`k_\tau = 5.34 + 4(b/a)^2` (section 9.7), b the shorter side;
and the same plate loaded or placed otherwise (the edge stress scaled, the plate
transposed or rotated), whose k must not change.
"""

from __future__ import annotations

import math

from mpi4py import MPI

import numpy as np
import pytest
from msgspec.structs import replace

from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.spec import EdgeSpec, problem_from_dict
from unibuckle_fenicsx.spec.cases import plate_case

#: Thickness (m) of the 0.3 x 0.1 m plates: thin (b/t = 50), so k is near the thin-plate 4.
THICKNESS = 0.002


def k_of(spec):
    with solve(spec, MPI.COMM_WORLD) as analysis:
        return analysis.result.buckling_coefficient_k


def loaded(spec, stress, names):
    """``spec`` with the normal stress ``stress`` on the edges ``names``, none elsewhere."""
    edges = tuple(
        EdgeSpec(e.name, normal_stress=stress if e.name in names else 0.0) for e in spec.plate.edges
    )
    return replace(spec, plate=replace(spec.plate, edges=edges))


def long_plate(length, width, nx, ny):
    return plate_case("k", length=length, width=width, thickness=THICKNESS, nx=nx, ny=ny)


def test_k_does_not_depend_on_the_size_of_the_unit_edge_stress():
    spec = long_plate(0.3, 0.1, 24, 8)
    unit = k_of(spec)
    triple = k_of(loaded(spec, -3.0, ("left", "right")))
    assert triple == pytest.approx(unit, rel=1e-9)
    assert unit == pytest.approx(4.0, rel=0.05)  # a/b = 3: k = 4 (module docstring)


def test_the_critical_force_is_t_times_the_critical_stress():
    """N = t sigma_cr whatever the size of the unit edge stress: near 4 pi^2 D / b^2.

    An edge stress of -3 per unit load: sigma_cr = 3 lambda_c, so N = 3 t lambda_c (it was
    t lambda_c, a third). The thin-plate value N = k pi^2 D / b^2 with k = 4 (module
    docstring) within the 24 x 8 mesh's 5 %.
    """
    spec = loaded(long_plate(0.3, 0.1, 24, 8), -3.0, ("left", "right"))
    with solve(spec, MPI.COMM_WORLD) as analysis:
        result = analysis.result
    mat = spec.material
    D = mat.E * THICKNESS**3 / (12.0 * (1.0 - mat.nu**2))
    assert result.critical_force_N_per_m == pytest.approx(
        THICKNESS * 3.0 * result.critical_load_Pa, rel=1e-12
    )
    assert result.critical_force_N_per_m == pytest.approx(4.0 * math.pi**2 * D / 0.1**2, rel=0.05)


def test_k_of_a_plate_compressed_on_top_and_bottom_uses_the_loaded_width():
    upright = loaded(long_plate(0.1, 0.3, 8, 24), -1.0, ("bottom", "top"))
    lying = long_plate(0.3, 0.1, 24, 8)  # the same plate transposed, loaded left/right
    k = k_of(upright)
    assert k == pytest.approx(k_of(lying), rel=1e-9)
    assert k == pytest.approx(4.0, rel=0.05)


#: The hard simple support needs axis-aligned edges: the soft one, in any direction.
SOFT = "simply_supported_soft"


def rectangle_outline(angle):
    """The 0.3 x 0.1 m rectangle rotated by ``angle`` about its centre, short edges loaded."""
    corners = np.array([[-0.15, -0.05], [0.15, -0.05], [0.15, 0.05], [-0.15, 0.05]])
    c, s = math.cos(angle), math.sin(angle)
    vertices = corners @ np.array([[c, s], [-s, c]])
    return problem_from_dict(
        {
            "plate": {"outline": vertices.tolist(), "thickness": THICKNESS},
            "edges": {
                "loaded": {"segments": [1, 3], "normal_stress": -1.0, "support": SOFT},
                "long": {"segments": [0, 2], "support": SOFT},
            },
            "mesh": {"size": 0.0125},
        }
    )


def test_k_of_a_rotated_outline_is_that_of_the_rectangle():
    pytest.importorskip("gmsh")
    spec = rectangle_outline(math.radians(30.0))
    assert spec.plate.reference_load() == pytest.approx((1.0, 0.1), rel=1e-12)
    k = k_of(spec)
    assert k == pytest.approx(k_of(rectangle_outline(0.0)), rel=1e-9)
    assert k == pytest.approx(4.0, rel=0.05)


def test_k_of_a_skew_plate_uses_its_loaded_edge():
    """A parallelogram compressed on its slanted ends: b is the end's length.

    The 0.3 x 0.1 m plate with its top edge shifted by 0.05 m along x, both ends
    (length sqrt(0.05^2 + 0.1^2) = 0.1118 m, by Pythagoras) loaded. b was the plate's
    extent along the ends' direction, 0.2460 m, which takes in the offset between the two
    ends: at t = 1 mm, k = 40.59 where the plate's k on its loaded edge is 8.39 (and 6.70
    on the 0.1 m between its long edges). An end split in two collinear segments has the
    same b.
    """
    skew = [[0.0, 0.0], [0.3, 0.0], [0.35, 0.1], [0.05, 0.1]]
    data = {
        "plate": {"outline": skew, "thickness": THICKNESS},
        "edges": {
            "ends": {"segments": [1, 3], "normal_stress": -1.0, "support": "clamped"},
            "long": {"segments": [0, 2], "support": "clamped", "inplane": "roller"},
        },
        "mesh": {"size": 0.0125},
    }
    end = math.hypot(0.05, 0.1)
    assert problem_from_dict(data).plate.reference_load() == pytest.approx((1.0, end), rel=1e-12)
    split = dict(data, plate={"outline": [*skew[:2], [0.325, 0.05], *skew[2:]]})
    split["edges"] = {
        "ends": {"segments": [1, 2, 4], "normal_stress": -1.0},
        "long": {"segments": [0, 3]},
    }
    assert problem_from_dict(split).plate.reference_load() == pytest.approx((1.0, end), rel=1e-12)
    pytest.importorskip("gmsh")
    spec = problem_from_dict(data)
    with solve(spec, MPI.COMM_WORLD) as analysis:
        load, k = analysis.result.critical_load_Pa, analysis.result.buckling_coefficient_k
    E, nu = spec.material.E, spec.material.nu
    D = E * THICKNESS**3 / (12.0 * (1.0 - nu**2))
    assert k == pytest.approx(THICKNESS * load * end**2 / (math.pi**2 * D), rel=1e-12)


def test_k_of_a_skew_plate_in_shear_uses_its_sheared_edge():
    """The same parallelogram sheared, its ends listed first: b the end's 0.1118 m.

    It was the smaller of the plate's extents along the ends (0.2460 m, the offset
    between the ends taken in) and across them (0.2683 m): 0.2460 m, for a plate whose
    sides are 0.3 m and 0.1118 m long (k_tau's b is the shorter side).
    """
    skew = [[0.0, 0.0], [0.3, 0.0], [0.35, 0.1], [0.05, 0.1]]
    spec = problem_from_dict(
        {
            "plate": {"outline": skew, "thickness": THICKNESS},
            "edges": {
                "ends": {"segments": [1, 3], "shear_stress": 1.0},
                "long": {"segments": [0, 2], "shear_stress": 1.0},
            },
            "mesh": {"size": 0.0125},
        }
    )
    assert spec.plate.reference_load() == pytest.approx((1.0, math.hypot(0.05, 0.1)), rel=1e-12)


def test_k_of_a_plate_in_shear_uses_its_shorter_side():
    lying = plate_case("k", length=0.3, width=0.1, thickness=THICKNESS, nx=24, ny=8, load="shear")
    tall = plate_case("k", length=0.1, width=0.3, thickness=THICKNESS, nx=8, ny=24, load="shear")
    k = k_of(tall)
    assert k == pytest.approx(k_of(lying), rel=1e-9)
    # k_tau = 5.34 + 4 (b/a)^2 at a/b = 3 (Timoshenko & Gere, section 9.7): the coarse
    # mesh is 11 % stiff in shear (5 % at 36 x 12), far from the 9 k of b = 0.3 m.
    assert k == pytest.approx(5.34 + 4.0 / 9.0, rel=0.15)
