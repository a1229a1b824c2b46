r"""A long hollow member buckles as a column: the section's shell against Euler's load.

A box 100 × 100 × 4 mm (b/t = 25), 2.5 m between simply supported ends: its walls'
reference stress is :math:`4\pi^2 D/(t b^2)` = 1.215e9 Pa, its Euler stress
:math:`\pi^2 E r^2/L^2` with :math:`r^2 = I/A = b^2/6` (thin-walled mid-line) 5.527e8 Pa,
so it buckles as a column. The shell's column has shear deformation too: Engesser's
:math:`\sigma = \sigma_E/(1 + \sigma_E A/(G A_s))`, the shear area :math:`A_s` the two
faces parallel to the deflection, half of A: 5.452e8 Pa. Donnell's geometric stiffness
(the walls' normal deflection only) leaves out the other two faces' share and gave
1.094e9 Pa, twice the column's load, with k = 3.60 as if the walls had buckled; the
result now warns that its k and face values are the walls' quantities, not a column's.
A long tube likewise, against the Euler load of its faceted wall (below).
"""

from __future__ import annotations

import logging
import math

from mpi4py import MPI

import pytest

from unibuckle_fenicsx import SectionParameters, solve_section

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial sections")

E, NU = 2.1e11, 0.3


def _column(**changes: object) -> SectionParameters:
    base = {
        "width": 0.1, "depth": 0.1, "thickness": 0.004, "length": 2.5, "E": E, "nu": NU,
        "mesh_size": 0.02, "ends": "simply_supported",
    }  # fmt: skip
    return SectionParameters("box", **{**base, **changes})


def test_a_long_box_buckles_at_euler_s_load_with_shear(caplog):
    b, t, L = 0.1, 0.004, 2.5
    euler = math.pi**2 * E * (b * b / 6.0) / L**2
    assert euler == pytest.approx(5.527e8, rel=1e-3)
    shear_modulus = E / (2.0 * (1.0 + NU))
    engesser = euler / (1.0 + euler * 2.0 / shear_modulus)
    with caplog.at_level(logging.WARNING, logger="unibuckle_fenicsx.section_analysis"):
        with solve_section(_column(), MPI.COMM_WORLD) as analysis:
            load = analysis.result.critical_load_Pa
    assert load == pytest.approx(engesser, rel=5e-3)
    assert load < 0.5 * 4.0 * math.pi**2 * E * t * t / (12.0 * (1.0 - NU**2) * b * b)
    assert any("Euler stress" in r.getMessage() for r in caplog.records)  # not the walls'


def test_the_geometric_stiffness_is_the_full_one_unless_asked():
    # Donnell's doubled the column's load above; the full term is the default on every
    # member, short or long (tests/verification/test_section_geometric.py: a tube's
    # few-wave modes).
    short = _column(width=0.2, depth=0.2, thickness=0.002, length=0.6)
    assert short.euler_stress() == pytest.approx(math.pi**2 * E * 0.04 / (6.0 * 0.36))
    assert not short.donnell()
    assert not _column().donnell()
    assert _column(geometric="donnell").donnell()
    # A rectangle's weaker axis: r^2 = d^2 (d + 3b)/(12 (b + d)), 0.2 x 0.1 m: 7/3600 m^2.
    flat = _column(width=0.2, depth=0.1, ends="clamped")
    assert flat.euler_stress() == pytest.approx(math.pi**2 * E * (7.0 / 3600.0) / 1.25**2)


def test_a_long_tube_buckles_at_the_polygon_s_euler_load():
    # A tube D = 0.1 m, t = 4 mm, 3 m between simply supported ends, on 16 facets around
    # (cells of 0.02 m): the 16-gon's thin wall, vertices on R, has I/A = 0.97463 R^2/2
    # (each side's integral of y^2, summed here), Euler's load 2.8056e8 Pa, with
    # Engesser's shear (A_s = A/2) 2.7862e8 Pa. Donnell's stiffness gave 5.62e8 Pa.
    radius, sides, L = 0.05, 16, 3.0
    corners = [(radius * math.cos(a), radius * math.sin(a))
               for a in (2.0 * math.pi * k / sides for k in range(sides + 1))]  # fmt: skip
    second, area = 0.0, 0.0
    for (_, y0), (_, y1), p0, p1 in zip(corners, corners[1:], corners, corners[1:], strict=False):
        side = math.dist(p0, p1)
        area += side
        second += side * (y0 * y0 + y0 * y1 + y1 * y1) / 3.0
    euler = math.pi**2 * E * (second / area) / L**2
    assert second / area == pytest.approx(0.97463 * radius**2 / 2.0, rel=1e-5)
    engesser = euler / (1.0 + 2.0 * euler / (E / (2.0 * (1.0 + NU))))
    tube = SectionParameters(
        "tube", diameter=0.1, thickness=0.004, length=L, E=E, nu=NU, mesh_size=0.02,
        ends="simply_supported",
    )  # fmt: skip
    with solve_section(tube, MPI.COMM_WORLD) as analysis:
        load = analysis.result.critical_load_Pa
    assert engesser < load < euler * (1.0 + 1e-3)
