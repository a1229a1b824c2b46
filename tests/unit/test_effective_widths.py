r"""Effective widths (EN 1993-1-5 Tables 4.1, 4.2) and the clause of the stress limit.

Expected widths are the tables' formulas worked out here by hand, one case per row,
from the text of EN 1993-1-5:2006+AC:2009:

- Table 4.1 (internal compression elements): :math:`\psi = 1`: :math:`b_{eff} = \rho\bar
  b`, :math:`b_{e1} = b_{e2} = 0.5 b_{eff}`; :math:`1 > \psi \ge 0`: :math:`b_{eff} =
  \rho\bar b`, :math:`b_{e1} = 2b_{eff}/(5 - \psi)`, :math:`b_{e2} = b_{eff} - b_{e1}`;
  :math:`\psi < 0`: :math:`b_c = \bar b/(1 - \psi)`, :math:`b_{eff} = \rho b_c`,
  :math:`b_{e1} = 0.4 b_{eff}`, :math:`b_{e2} = 0.6 b_{eff}`;
- Table 4.2 (outstand compression elements), both rows (larger compression at the free
  edge, at the supported edge): :math:`b_{eff} = \rho c` for :math:`1 \ge \psi \ge 0`,
  :math:`\rho b_c = \rho c/(1 - \psi)` for :math:`\psi < 0`.

The stress limit :math:`\sigma_1 \le \rho f_y/\gamma_M`: at :math:`\psi = 1` a lone
element's :math:`A_{eff} = \rho A`, and 4.6(1), eq. (4.14), is that check with
:math:`\gamma_{M0}`; at :math:`\psi < 1` it is the reduced stress method of section 10 with
direct stress alone (eq. (10.1), :math:`\rho\alpha_{ult,k}/\gamma_{M1} \ge 1`,
:math:`\alpha_{ult,k} = f_y/\sigma_1`), whose factor is :math:`\gamma_{M1}`. The
reduction factors are eq. (4.2) and (4.3) written out by hand.
"""

from __future__ import annotations

import math

from mpi4py import MPI

import pytest

from unibuckle_fenicsx import SectionParameters
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.en1993 import INTERNAL, OUTSTAND, effective_widths, stress_limit
from unibuckle_fenicsx.section_design import design_line, section_design
from unibuckle_fenicsx.spec import DesignSpec, problem_from_dict


@pytest.mark.parametrize(
    ("element", "at_free", "rho", "width", "psi", "expected", "row"),
    [
        # Table 4.1, psi = 1: b_eff = 0.6 x 0.2 = 0.12, halves 0.06.
        (INTERNAL, True, 0.6, 0.2, 1.0, (0.2, 0.12, 0.06, 0.06), "Table 4.1, psi = 1"),
        # Table 4.1, 1 > psi >= 0: b_eff = 0.8 x 0.3 = 0.24, b_e1 = 2 x 0.24/4.5 = 0.10667,
        # b_e2 = 0.24 - 0.10667 = 0.13333.
        (INTERNAL, True, 0.8, 0.3, 0.5, (0.3, 0.24, 0.48 / 4.5, 0.24 - 0.48 / 4.5),
         "Table 4.1, 1 > psi >= 0"),
        # Table 4.1, psi < 0: b_c = 0.4/2 = 0.2, b_eff = 0.9 x 0.2 = 0.18, 0.072 and 0.108.
        (INTERNAL, True, 0.9, 0.4, -1.0, (0.2, 0.18, 0.072, 0.108), "Table 4.1, psi < 0"),
        # Table 4.2, larger compression at the free edge, 1 >= psi >= 0: 0.5 x 0.1 = 0.05.
        (OUTSTAND, True, 0.5, 0.1, 0.5, (0.1, 0.05, None, None),
         "Table 4.2, larger compression at the free edge, 1 >= psi >= 0"),
        # Table 4.2, free edge, psi < 0: b_c = 0.09/3 = 0.03, b_eff = 0.7 x 0.03 = 0.021.
        (OUTSTAND, True, 0.7, 0.09, -2.0, (0.03, 0.021, None, None),
         "Table 4.2, larger compression at the free edge, psi < 0"),
        # Table 4.2, larger compression at the supported edge, 1 >= psi >= 0 (psi = 0):
        # 0.6 x 0.1 = 0.06.
        (OUTSTAND, False, 0.6, 0.1, 0.0, (0.1, 0.06, None, None),
         "Table 4.2, larger compression at the supported edge, 1 >= psi >= 0"),
        # Table 4.2, supported edge, psi < 0: b_c = 0.15/1.5 = 0.1, b_eff = 0.8 x 0.1 = 0.08.
        (OUTSTAND, False, 0.8, 0.15, -0.5, (0.1, 0.08, None, None),
         "Table 4.2, larger compression at the supported edge, psi < 0"),
    ],
)  # fmt: skip
def test_effective_widths_are_tables_4_1_and_4_2(element, at_free, rho, width, psi, expected, row):
    w = effective_widths(element, rho, width, psi, at_free)
    compressed, effective, first, second = expected
    assert w.width == width and w.row == row
    assert w.compressed == pytest.approx(compressed, rel=1e-14)
    assert w.effective == pytest.approx(effective, rel=1e-14)
    if first is None:
        assert w.first is None and w.second is None
    else:
        assert w.first == pytest.approx(first, rel=1e-14)
        assert w.second == pytest.approx(second, rel=1e-14)


def test_a_psi_outside_the_table_is_refused_naming_it():
    # Table 4.2's lower row stops at psi = -1.
    with pytest.raises(ValueError, match=r"psi must lie in \[-1, 1\]"):
        effective_widths(OUTSTAND, 0.5, 0.1, -2.0, False)


def test_the_stress_limit_is_4_6_1_at_psi_1_and_section_10_below():
    # psi = 1: 4.6(1), eq. (4.14) with A_eff = rho A, gamma_M0.
    name, clause = stress_limit(1.0)
    assert name == "gamma_M0" and clause.startswith("4.6(1): rho f_y/gamma_M0")
    # psi < 1: 4.6(1) needs W_eff and e_N; sigma_1 <= rho f_y/gamma_M1 is section 10's
    # eq. (10.1) with direct stress alone.
    for psi in (0.5, 0.0, -1.0):
        name, clause = stress_limit(psi)
        assert name == "gamma_M1" and clause.startswith("section 10, reduced stress method")
        assert "eq. (10.1)" in clause and "rho f_y/gamma_M1" in clause


def _outstand(thickness=2.0):
    """A 600 x 200 mm steel outstand (top free) in uniform compression across left and right."""
    hinged = {"support": "simply_supported"}
    return problem_from_dict(
        {
            "units": "mm-N-MPa",
            "plate": {"corners": [[0, 0], [600, 200]], "thickness": thickness},
            "material": {"E": 210000.0, "nu": 0.3},
            "edges": {
                "left": {**hinged, "normal_stress": -1.0},
                "right": {**hinged, "normal_stress": -1.0},
                "bottom": hinged,
                "top": {"support": "free"},
            },
            "mesh": {"nx": 12, "ny": 4},
            "design": {"yield_stress": 355.0, "partial_factor": 1.1},
        }
    )


def test_an_outstand_with_rho_below_1_at_psi_1_gets_section_10():
    """An outstand at psi = 1 with rho < 1: section 10 and gamma_M1, not 4.6(1).

    Table 4.2 puts b_eff = rho c at the supported edge: the effective area's centroid
    lies (1 - rho) c/2 off the gross one, so 4.6(1), eq. (4.14), needs the shift e_N and
    W_eff even at psi = 1, and sigma_1 <= rho f_y/gamma_M0 is not what it reads. The
    output's own rule for an effective section it does not compute is the reduced stress
    method, eq. (10.1) with gamma_M1. By hand, at sigma_cr = 50 MPa (f_y = 355 MPa):
    slenderness sqrt(355/50) = 2.6646, rho = (2.6646 - 0.188)/2.6646^2 = 0.34881
    (eq. (4.3)), rho f_y/gamma_M1 = 0.34881 x 355/1.1 = 112.57 MPa, e_N = (1 - rho) 200/2
    = 65.1 mm. Before: "gamma_M0", 4.6(1) "A_eff = rho A, no shift e_N".
    """
    from unibuckle_fenicsx.design import design_output

    spec = _outstand()
    d = design_output(spec, spec.design, 50.0e6)  # the load in Pa: sigma_cr = 50 MPa
    lam = math.sqrt(355.0 / 50.0)
    rho = (lam - 0.188) / lam**2
    assert rho == pytest.approx(0.34881, abs=5e-6)
    assert d.element == "outstand" and d.psi == 1.0
    assert d.reduction_factor == pytest.approx(rho, rel=1e-12)
    assert d.partial_factor_name == "gamma_M1", d.stress_limit_clause
    assert d.stress_limit_clause.startswith("section 10, reduced stress method")
    assert "psi = 1, but the outstand's b_eff = rho c lies at its supported edge" in (
        d.stress_limit_clause
    )
    assert "4.6(1): rho f_y" not in d.clauses
    assert d.reduced_design_stress_Pa == pytest.approx(rho * 355e6 / 1.1, rel=1e-12)
    assert d.reduced_design_stress_Pa == pytest.approx(112.57e6, rel=5e-5)
    assert d.effective_width_m == pytest.approx(rho * 0.2, rel=1e-12)


def test_an_outstand_with_rho_1_at_psi_1_keeps_4_6_1():
    """At rho = 1 (slenderness 0.596 <= 0.748, sigma_cr = 1000 MPa): A_eff = A, no shift."""
    from unibuckle_fenicsx.design import design_output

    spec = _outstand()
    d = design_output(spec, spec.design, 1000.0e6)
    assert math.sqrt(355.0 / 1000.0) <= 0.748 and d.reduction_factor == 1.0
    assert d.partial_factor_name == "gamma_M0" and d.stress_limit_clause.startswith("4.6(1)")
    assert d.reduced_design_stress_Pa == pytest.approx(355e6 / 1.1, rel=1e-12)


def _plate(left_right, thickness, top=None):
    """A 600 x 200 mm steel plate loaded across left and right (b = 200 mm)."""
    hinged = {"support": "simply_supported"}
    spec = problem_from_dict(
        {
            "units": "mm-N-MPa",
            "plate": {"corners": [[0, 0], [600, 200]], "thickness": thickness},
            "material": {"E": 210000.0, "nu": 0.3},
            "edges": {
                "left": {**hinged, "normal_stress": left_right},
                "right": {**hinged, "normal_stress": left_right},
                "bottom": hinged,
                "top": top or hinged,
            },
            "mesh": {"nx": 12, "ny": 4},
            "design": {"yield_stress": 355.0, "partial_factor": 1.1},
        }
    )
    with solve(spec, MPI.COMM_WORLD) as analysis:
        return analysis.result


def _rho(sigma_cr, psi, outstand=False):
    """Eq. (4.2) (internal) or (4.3) (outstand) of EN 1993-1-5 4.4(2), f_y = 355 MPa."""
    lam = math.sqrt(355e6 / sigma_cr)
    if outstand:
        return 1.0 if lam <= 0.748 else min(1.0, (lam - 0.188) / lam**2)
    if lam <= 0.5 + math.sqrt(0.085 - 0.055 * psi):
        return 1.0
    return min(1.0, (lam - 0.055 * (3.0 + psi)) / lam**2)


def test_an_internal_plate_in_bending_gets_table_4_1_s_psi_below_0_widths():
    # [-1, 1] MPa along the left and right edges: compression at the bottom end, psi = -1.
    # 1 mm: sigma_cr about 160 MPa, slenderness about 1.5, rho about 0.6 < 1.
    out = _plate([-1.0, 1.0], 1.0)
    d = out.design
    assert d.psi == -1.0 and d.element == "internal"
    rho = _rho(d.sigma_cr_Pa, -1.0)  # a/b = 3: no column-type check
    assert rho < 0.9
    assert d.reduction_factor == pytest.approx(rho, rel=1e-12)
    b_c = 0.2 / 2.0  # Table 4.1, psi < 0: b/(1 - psi)
    assert d.element_width_m == pytest.approx(0.2, rel=1e-14)
    assert d.compressed_width_m == pytest.approx(b_c, rel=1e-14)
    assert d.effective_width_m == pytest.approx(rho * b_c, rel=1e-12)
    assert d.effective_width_1_m == pytest.approx(0.4 * rho * b_c, rel=1e-12)
    assert d.effective_width_2_m == pytest.approx(0.6 * rho * b_c, rel=1e-12)
    assert d.effective_widths_row == "Table 4.1, psi < 0"
    assert d.effective_widths_placed.endswith("(sigma_1 end: edges.bottom, other end: edges.top)")
    # psi < 1: the reduced stress method (section 10), gamma_M1 = partial_factor = 1.1.
    assert d.partial_factor_name == "gamma_M1" and "section 10" in d.stress_limit_clause
    assert d.reduced_design_stress_Pa == pytest.approx(rho * 355e6 / 1.1, rel=1e-12)
    assert "4.6(1): rho f_y" not in d.clauses
    line = next(s for s in out.summary().splitlines() if "EN 1993-1-5: " in s)
    assert f"rho f_y/gamma_M1 = {rho * 355 / 1.1:#.4g} MPa; effective width b_eff = " in line
    assert f"b_eff = {rho * b_c * 1e3:#.4g} mm (b_e1 {0.4 * rho * b_c * 1e3:#.4g}, " in line
    assert f"of b_c = {b_c * 1e3:#.4g} mm" in line, line
    assert "rho f_y/gamma_M1 section 10 eq. (10.1)" in line, line


@pytest.mark.parametrize(
    ("stress", "row", "placed"),
    [
        # sigma_1 at the bottom (start) end, the supported edge: psi = -0.5, the lower row.
        ([-1.0, 0.5], "supported", "b_eff from the supported edge and the tension zone"),
        # sigma_1 at the top end, the free edge: psi = -0.5, the upper row.
        ([0.5, -1.0], "free", "the tension zone b_t = c - b_c from the supported edge"),
    ],
)
def test_an_outstand_in_bending_gets_its_row_s_widths(stress, row, placed):
    # 2 mm: slenderness above 0.748 in both rows, rho < 1.
    out = _plate(stress, 2.0, top={"support": "free"})
    d = out.design
    assert d.psi == -0.5 and d.element == "outstand" and d.free_edge == "top"
    rho = _rho(d.sigma_cr_Pa, -0.5, outstand=True)
    assert rho < 0.9
    b_c = 0.2 / 1.5  # Table 4.2, psi < 0: c/(1 - psi)
    assert d.effective_width_m == pytest.approx(rho * b_c, rel=1e-12)
    assert d.effective_width_1_m is None and d.effective_width_2_m is None
    assert d.effective_widths_row == f"Table 4.2, larger compression at the {row} edge, psi < 0"
    assert d.effective_widths_placed.startswith(placed)
    assert d.effective_widths_placed.endswith(
        "(supported edge: edges.bottom, free edge: edges.top)"
    )
    line = next(s for s in out.summary().splitlines() if "EN 1993-1-5: " in s)
    assert f"psi Table 4.2 (larger compression at the {row} edge), " in line, line


def _web_psi(b, d, axial, bending, rho_top):
    """A web's psi by EN 1993-1-5 4.4(3), by hand: the compression (top) flange rho_top b.

    Mid-line dimensions, t = 1, bending < 0 (the top compressed): the neutral axis of
    the section of the effective top flange, the gross bottom flange and webs by the
    first moment of area, z' = (rho_top b - b)(d/2)/(rho_top b + b + 2 d); the axial part
    plus the bending part through z', -|bending| at the top: sigma(z) = axial - |bending|
    (z - z')/(d/2 - z'); psi = sigma(-d/2)/sigma(+d/2).
    """
    z_na = (rho_top * b - b) * (d / 2) / (rho_top * b + b + 2 * d)
    top, bottom = (axial - abs(bending) * (z - z_na) / (d / 2 - z_na) for z in (d / 2, -d / 2))
    return bottom / top


def test_a_box_in_bending_gives_each_face_its_widths_and_limit():
    # Axial -1, bending -2 (Pa per unit load): the top fibre carries 3, the bottom -1
    # (tension). At load 1e8: the top face sigma_1 = 3e8, psi = 1; the right and left faces
    # (depth 0.1 m) 3e8 at the top corner, -1e8 at the bottom in the gross section (psi =
    # -1/3). EN 1993-1-5 4.4(3) takes the webs' psi from the section with the top flange
    # effective (rho = 0.73336 at 3e8, eq. (4.2)) and the webs gross: by hand (_web_psi)
    # z' = -4.8775 mm, the bottom end at -1 + 2 (50 - 4.8775)/(50 + 4.8775) = +0.6445,
    # psi = -0.21483, b_c = 0.1/(1 - psi) = 82.316 mm (the gross psi gave 75 mm).
    section = SectionParameters(
        "box", thickness=0.002, width=0.2, depth=0.1, diameter=None, length=0.6, E=2.1e11,
        nu=0.3, mesh_size=0.02, axial_stress=-1.0, bending_stress=-2.0, core=False,
    )  # fmt: skip
    out = section_design(section, DesignSpec(yield_stress=3.55e8, partial_factor=1.1), 1.0e8)
    faces = {f.face: f for f in out.faces}
    top, right = faces["top"], faces["right"]
    rho_top = _rho(3e8, 1.0)  # width 0.2 m, length 0.6 m: no column-type check
    # The top face has psi = 1, but the bent section's effective section (top face
    # reduced, bottom face not) has its own W_eff and shift e_N, which 4.6(1), eq.
    # (4.14), needs: the reduced stress method, section 10, gamma_M1 (it had gamma_M0).
    assert top.partial_factor_name == "gamma_M1", top.stress_limit_clause
    assert top.stress_limit_clause.startswith("section 10")
    assert "psi = 1, but the section is bent" in top.stress_limit_clause
    assert top.effective_width_m == pytest.approx(rho_top * 0.2, rel=1e-12)
    assert top.effective_width_1_m == pytest.approx(0.1 * rho_top, rel=1e-12)
    psi = _web_psi(0.2, 0.1, -1.0, -2.0, rho_top)
    assert psi == pytest.approx(-0.21483, abs=1e-5)
    rho = _rho(3e8, psi)
    b_c = 0.1 / (1.0 - psi)
    assert right.psi == pytest.approx(psi, rel=1e-12)
    assert right.psi_gross == pytest.approx(-1.0 / 3.0, rel=1e-14)
    assert right.partial_factor_name == "gamma_M1"
    assert right.compressed_width_m == pytest.approx(0.082316, rel=1e-5)
    assert right.compressed_width_m == pytest.approx(b_c, rel=1e-12)
    assert right.effective_width_m == pytest.approx(rho * b_c, rel=1e-12)
    assert right.effective_width_1_m == pytest.approx(0.4 * rho * b_c, rel=1e-12)
    assert right.effective_width_2_m == pytest.approx(0.6 * rho * b_c, rel=1e-12)
    assert right.effective_widths_placed.endswith(
        "(sigma_1 end: the corner with face top, other end: the corner with face bottom)"
    )
    assert faces["bottom"].effective_width_m is None  # in tension
    assert "faces right, left: section 10" in out.clauses[0]
    assert "faces top: section 10" in out.clauses[0] and "4.6(1): rho" not in out.clauses[0]
    # The governing face: the smallest rho f_y/sigma_1; both carry 3e8, the right face's
    # rho (psi = -0.215) exceeds the top's (psi = 1), so the top governs, at gamma_M1.
    assert rho > rho_top and out.governing_face == "top"
    line = design_line(out, 1e6, "MPa", (1e-3, "mm"))
    assert f"rho f_y/gamma_M1 = {rho_top * 355 / 1.1:#.4g} MPa" in line, line
    assert "rho f_y/gamma_M1 section 10 eq. (10.1)" in line and "4.6(1)" not in line, line
    assert f"effective width b_eff = {rho_top * 200:#.4g} mm" in line, line
