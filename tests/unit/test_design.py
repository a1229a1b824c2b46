r"""Design output: EN 1993-1-5 slenderness and reduction factor from this package's σ_cr.

Expected values are the formulas of EN 1993-1-5:2006+AC:2009, 4.4(2), written out here
by hand: :math:`\bar\lambda_p = \sqrt{f_y/\sigma_{cr}}`; for internal compression
elements (both unloaded edges supported), :math:`\rho = (\bar\lambda_p -
0.055(3+\psi))/\bar\lambda_p^2` above :math:`\bar\lambda_p = 0.5 + \sqrt{0.085 -
0.055\psi}`, 1 below (4.2); for outstand elements (one unloaded edge free),
:math:`\rho = (\bar\lambda_p - 0.188)/\bar\lambda_p^2` above 0.748, 1 below (4.3).
The internal threshold is the root of :math:`\lambda^2 - \lambda + 0.055(3 + \psi) =
0`, so ρ is continuous there (1 on both sides); for ψ = 1 it is the familiar 0.673. The
buckling factors k_σ are the values of Tables 4.1 and 4.2 at ψ = 1, 0, -1 and their
formulas between, typed in from the tables.
"""

from __future__ import annotations

import math
import re

from mpi4py import MPI

import pytest

from support.paths import ROOT
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.design import euler_stress, reduction_factor, significant
from unibuckle_fenicsx.spec import problem_from_dict, problem_to_dict


def plate(edges, *, obstacle=None, design=None, **extra):
    data = {
        "units": "mm-N-MPa",
        "plate": {"corners": [[0, 0], [600, 200]], "thickness": 4.0},
        "material": {"E": 210000.0, "nu": 0.3},
        "edges": edges,
        "mesh": {"nx": 12, "ny": 4},
        "design": design or {"yield_stress": 355.0, "partial_factor": 1.1},
        **extra,
    }
    if obstacle:
        data["obstacle"] = obstacle
    return problem_from_dict(data)


def result(spec):
    with solve(spec, MPI.COMM_WORLD) as analysis:
        return analysis.result


@pytest.mark.parametrize(
    "slenderness, psi, rho",
    [
        (0.5, 1.0, 1.0),
        (1.0, 1.0, 0.78),  # (1 - 0.22) / 1
        (2.0, 1.0, 0.445),  # (2 - 0.22) / 4
        (1.0, -1.0, 0.89),  # (1 - 0.11) / 1
        (1.5, 0.0, (1.5 - 0.165) / 2.25),
        (0.79, 0.0, 1.0),  # below 0.5 + sqrt(0.085) = 0.7915
        (1.2, -3.0, 1.0 / 1.2),  # (1.2 - 0) / 1.44
    ],
)
def test_reduction_factor_is_en_1993_1_5_eq_4_2(slenderness, psi, rho):
    assert reduction_factor(slenderness, psi) == pytest.approx(rho, rel=1e-12)


@pytest.mark.parametrize("psi", [1.0, 0.5, 0.0, -1.0, -2.0, -3.0])
def test_reduction_factor_is_continuous_at_its_threshold(psi):
    threshold = 0.5 + math.sqrt(0.085 - 0.055 * psi)
    assert reduction_factor(threshold, psi) == 1.0
    assert reduction_factor(threshold * (1 + 1e-9), psi) == pytest.approx(1.0, abs=1e-8)
    with pytest.raises(ValueError, match=r"psi must lie in \[-3, 1\]"):
        reduction_factor(1.0, -3.5)


def test_design_keys_are_read_converted_and_written_back():
    spec = plate({"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}})
    assert spec.design.yield_stress == pytest.approx(355e6) and spec.design.partial_factor == 1.1
    assert problem_from_dict(problem_to_dict(spec, units="mm-N-MPa")) == spec
    assert problem_to_dict(spec, units="mm-N-MPa")["design"]["yield_stress"] == pytest.approx(355)


@pytest.mark.parametrize(
    "design, extra, match",
    [
        # The file is in mm-N-MPa: its unit (MPa) and its number in the message.
        ({"yield_stress": 0.0}, {}, r"design\.yield_stress must be > 0 MPa, got 0\.0$"),
        ({"yield_stress": 355.0, "partial_factor": -1}, {}, r"design\.partial_factor must be >= 1"),
        # gamma_M0 = 0.9 put rho f_y/gamma_M0 11 % above rho f_y, accepted (EN 1993-1-1,
        # 6.1: recommended 1.0; a resistance factor is not below 1).
        ({"yield_stress": 355.0, "partial_factor": 0.9}, {}, r"partial_factor must be >= 1"),
        ({"partial_factor": 1.0}, {}, r"\[design\] needs 'yield_stress'"),
        ({"yield_stress": 355.0, "gamma": 1.0}, {}, r"unknown key\(s\) \['gamma'\] in \[design\]"),
    ],
)
def test_bad_design_tables_are_refused(design, extra, match):
    with pytest.raises(ValueError, match=match):
        plate({"left": {"normal_stress": -1.0}}, design=design, **extra)


@pytest.mark.parametrize(
    "units, fy, shown",
    [
        ("SI", 355.0, "355 Pa"),
        ("mm-N-MPa", 3.55e8, "3.55e\\+08 MPa"),
        ("SI", 1.2e9, "1.2e\\+09 Pa"),
    ],
)
def test_a_yield_stress_that_is_no_steel_s_is_refused(units, fy, shown):
    """f_y in the wrong unit: 355 in an SI file is 355 Pa.

    The 600 x 200 x 2 mm SSSS S355 plate has sigma_cr = 76.9 MPa (k = 4.05), so
    slenderness sqrt(355/76.9) = 2.148 and rho = (2.148 - 0.22)/2.148^2 = 0.418 (eq.
    (4.2)); with yield_stress = 355 in its SI file the output gave slenderness 0.002,
    rho = 1 and rho f_y/gamma_M0 = 355 Pa, exit 0. Structural steels have f_y of 235 to
    700 MPa (EN 1993-1-1 Table 3.1, EN 1993-1-12), stainless from 200 MPa (EN 1993-1-4
    Table 2.1): refused outside 150 to 1000 MPa, naming the key, in the file's unit.
    """
    scale, length = (1.0, 1.0) if units == "SI" else (1e-6, 1e3)  # Pa, m -> MPa, mm
    data = {
        "units": units,
        "plate": {"corners": [[0, 0], [0.6 * length, 0.2 * length]], "thickness": 0.002 * length},
        "material": {"E": 2.1e11 * scale, "nu": 0.3},
        "edges": {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}},
        "design": {"yield_stress": fy},
    }
    with pytest.raises(ValueError, match=rf"design\.yield_stress = {shown} is not a steel's"):
        problem_from_dict(data)
    problem_from_dict({**data, "design": {"yield_stress": 355e6 * scale}})


def test_design_needs_a_compressive_edge_stress():
    edges = {name: {"inplane": "clamped"} for name in ("left", "right", "bottom", "top")}
    with pytest.raises(ValueError, match=r"design: the EN 1993-1-5 output takes sigma_cr"):
        plate(
            edges,
            load={"temperature": 1.0},
            material={"E": 210000.0, "nu": 0.3, "thermal_expansion": 1.2e-5},
        )


def test_design_of_a_laminate_is_refused():
    # EN 1993-1-5 (Eurocode 3) is a steel code: eq. (4.2)'s rho is calibrated on steel
    # plates (their imperfections and residual stresses). A carbon-epoxy [0/90/0]
    # stack (E1 = 140 GPa, E2 = 10 GPa) with f_y = 355 MPa got rho = 0.3575, exit 0.
    ply = {"E1": 1.4e5, "E2": 1.0e4, "G12": 5.0e3, "nu12": 0.3, "G13": 5.0e3, "G23": 3.0e3}
    plies = [{"thickness": t, "angle": a, **ply} for t, a in ((1.0, 0.0), (2.0, 90.0), (1.0, 0.0))]
    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    with pytest.raises(ValueError, match=r"design: material\.plies"):
        plate(edges, material={"plies": plies})


@pytest.mark.parametrize(
    "material, match",
    [
        # Aluminium, E = 70 GPa: EN 1999-1-1 6.1.4 has its own curves. Before, the 300 x
        # 100 x 3 mm SSSS plate (f_y = 250 MPa) got EN 1993-1-5's rho = 0.7691, exit 0.
        ({"E": 70000.0, "nu": 0.33}, r"material\.E = 70000 MPa is not a steel's .*190000, 220000"),
        ({"E": 250000.0, "nu": 0.3}, r"material\.E = 250000 MPa is not a steel's"),
        (
            {"E": 210000.0, "nu": 0.3, "bending_voigt": [[1e6, 0, 0], [0, 1e6, 0], [0, 0, 1e5]]},
            r"material\.bending_voigt gives a general stiffness",
        ),
    ],
)
def test_design_of_a_plate_not_of_steel_is_refused(material, match):
    # EN 1993-1-5 4.4(2)'s rho rests on steel, E = 210 GPa (EN 1993-1-1 3.2.6).
    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    with pytest.raises(ValueError, match=match):
        plate(edges, material=material)


def test_stainless_steel_keeps_the_design():
    """E = 200 GPa (stainless steel, EN 1993-1-4 Table 2.1) is a steel's: not refused."""
    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    assert plate(edges, material={"E": 200000.0, "nu": 0.3}).design is not None


@pytest.mark.parametrize(("E", "noted"), [(200000.0, True), (210000.0, False), (205000.0, False)])
def test_stainless_steel_s_design_notes_en_1993_1_4(E, noted):
    """E = 200 GPa, stainless steel's: a note that EN 1993-1-4 5.2.3 gives its own rho.

    EN 1993-1-4 5.2.3 replaces eq. (4.2) and (4.3) for stainless steel by reduction
    factors that reduce more (its internal element's 0.772/lambda_p - ... against
    (lambda_p - 0.22)/lambda_p^2); the output applies EN 1993-1-5's, and said nothing.
    A box's faces get the note too, a tube (no rho) not.
    """
    from unibuckle_fenicsx import SectionParameters
    from unibuckle_fenicsx.cli.problem import input_notes
    from unibuckle_fenicsx.design import design_output
    from unibuckle_fenicsx.section_design import section_design
    from unibuckle_fenicsx.spec import DesignSpec

    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    spec = plate(edges, material={"E": E, "nu": 0.3})
    notes = [n for n in design_output(spec, spec.design, 2e8).notes if "EN 1993-1-4 5.2.3" in n]
    assert len(notes) == int(noted), notes
    assert ("design stainless" in input_notes(spec)) == noted
    if noted:
        assert notes[0].startswith("design: material.E = 200 GPa is stainless steel's")
    for shape, sizes in (("box", {"width": 0.2, "depth": 0.1}), ("tube", {"diameter": 0.2})):
        section = SectionParameters(
            shape, thickness=0.002, length=0.6, E=E * 1e6, nu=0.3, mesh_size=0.02,
            axial_stress=-1.0, bending_stress=0.0, core=False,
            **{"width": None, "depth": None, "diameter": None, **sizes},
        )  # fmt: skip
        out = section_design(section, DesignSpec(yield_stress=3.55e8), 1.0e8)
        said = [n for n in out.notes if "EN 1993-1-4 5.2.3" in n]
        assert len(said) == int(noted and shape == "box"), (shape, out.notes)


@pytest.mark.parametrize(
    ("nu", "warned"), [(-0.2, True), (0.45, True), (0.3, False), (0.28, False)]
)
def test_a_poisson_s_ratio_not_a_steel_s_is_noted(nu, warned):
    """With [design], nu = -0.2 was taken without a word: steel's is 0.3 (EN 1993-1-1 3.2.6).

    A note naming material.nu, not a refusal: sigma_cr is still the plate's with that nu
    (D = E t^3/(12 (1 - nu^2))), and eq. (4.2) applies to any sigma_cr.
    """
    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    spec = plate(edges, material={"E": 210000.0, "nu": nu})
    notes = [n for n in result(spec).design.notes if "material.nu" in n]
    if warned:
        assert len(notes) == 1 and f"material.nu = {nu:g} is not a steel's" in notes[0]
        assert "EN 1993-1-1 3.2.6: nu = 0.3" in notes[0]
    else:
        assert notes == []


def test_uniform_compression():
    """Uniform: psi = 1, sigma_cr = lambda_c; slenderness, rho, rho f_y / gamma_M0 by hand."""
    out = result(plate({"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}))
    d = out.design
    assert d.sigma_cr_Pa == out.critical_load_Pa and d.psi == 1.0
    slenderness = math.sqrt(355e6 / out.critical_load_Pa)
    assert d.relative_slenderness == pytest.approx(slenderness, rel=1e-14)
    rho = min(1.0, (slenderness - 0.22) / slenderness**2) if slenderness > 0.5 + 0.03**0.5 else 1
    assert d.reduction_factor == pytest.approx(rho, rel=1e-14)
    assert d.reduced_design_stress_Pa == pytest.approx(rho * 355e6 / 1.1, rel=1e-14)
    assert "calibrated on plates buckling freely to both sides" in d.notes[0]
    assert "4.4(2), eq. (4.2)" in d.clauses
    assert "EN 1993-1-5: sigma_cr" in out.summary()
    # psi = 1: EN 1993-1-5 4.6(1) checks the effective cross-section, A_eff = rho A, with
    # gamma_M0 (gamma_M1 is the member's, EN 1993-1-1 6.3, and section 10's, which is the
    # limit at psi < 1: tests/unit/test_effective_widths.py): the factor is named so.
    assert "4.6(1): rho f_y/gamma_M0" in d.clauses
    assert "rho f_y/gamma_M0 = " in out.summary() and "gamma_M1" not in out.summary()


def test_k_sigma_is_the_plate_s_and_k_sigma_table_the_long_hinged_plate_s():
    """A clamped square (300 x 300 x 2 mm, loaded on bottom and top, 24 x 24 cells).

    ``k_sigma`` = sigma_cr / sigma_E, sigma_E = pi^2 E t^2 / (12 (1 - nu^2) b^2) by
    hand (EN 1993-1-5 eq. (A.2), b the loaded edge's length 300 mm): near Timoshenko
    and Gere's 10.07 (*Theory of elastic stability*, 2nd ed., section 9.5: a clamped
    square; 10.18 on these cells, the mesh's error); ``k_sigma_table`` is Table
    4.1's 4.0 at psi = 1, the long hinged plate's. Before, only the table's 4.0 was
    given, easy to read as this plate's k.
    """
    clamped = {"support": "clamped"}
    edges = {
        "left": clamped,
        "right": clamped,
        "bottom": {**clamped, "normal_stress": -1.0},
        "top": {**clamped, "normal_stress": -1.0},
    }
    square = {"corners": [[0, 0], [300, 300]], "thickness": 2.0}
    spec = plate(edges, mesh={"nx": 24, "ny": 24})
    d = result(problem_from_dict({**problem_to_dict(spec), "plate": square})).design
    euler = math.pi**2 * 210000e6 * (2.0 / 300.0) ** 2 / (12 * (1 - 0.3**2))
    assert d.k_sigma == pytest.approx(d.sigma_cr_Pa / euler, rel=1e-12)
    assert d.k_sigma == pytest.approx(10.07, rel=0.015)
    assert d.k_sigma_table == 4.0
    # b is the loaded edges' length: the x extent for bottom and top (300 of 300 x 450 mm)
    tall = problem_from_dict(
        {**problem_to_dict(spec), "plate": {**square, "corners": [[0, 0], [300, 450]]}}
    )
    assert euler_stress(tall, ("bottom", "top")) == pytest.approx(euler, rel=1e-12)


def test_a_short_plate_gets_the_column_type_reduction_factor():
    """A short SSSS plate, a/b = 0.5 (150 x 300 x 2 mm, loaded on left and right, 8 x 16).

    EN 1993-1-5 4.4(2) notes that a plate with a/b < 1 may buckle like a column and
    4.5.4(1) gives rho_c = (rho - chi_c) xi (2 - xi) + chi_c, xi = sigma_cr / sigma_cr,c
    - 1 in [0, 1], sigma_cr,c = pi^2 E t^2 / (12 (1 - nu^2) a^2) (4.5.3(2)), chi_c of
    EN 1993-1-1 6.3.1.2 with alpha = 0.21 (4.5.3(5)): all by hand here from the
    computed sigma_cr (near Timoshenko and Gere's k = (b/a + a/b)^2 = 6.25). Before,
    rho = 0.3556 was given where rho_c = 0.3109: 14 % on the unsafe side.
    """
    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    spec = plate(edges, mesh={"nx": 8, "ny": 16})
    short = {"corners": [[0, 0], [150, 300]], "thickness": 2.0}
    d = result(problem_from_dict({**problem_to_dict(spec), "plate": short})).design
    sigma_e = math.pi**2 * 210000e6 * (2.0 / 300.0) ** 2 / (12 * (1 - 0.3**2))
    assert d.sigma_cr_Pa == pytest.approx(6.25 * sigma_e, rel=0.03)
    slenderness = math.sqrt(355e6 / d.sigma_cr_Pa)
    rho = (slenderness - 0.22) / slenderness**2  # eq. (4.2), psi = 1
    column = math.pi**2 * 210000e6 * (2.0 / 150.0) ** 2 / (12 * (1 - 0.3**2))
    lam_c = math.sqrt(355e6 / column)
    phi = 0.5 * (1 + 0.21 * (lam_c - 0.2) + lam_c**2)
    chi = 1 / (phi + math.sqrt(phi**2 - lam_c**2))
    xi = d.sigma_cr_Pa / column - 1
    assert 0 < xi < 1
    rho_c = (rho - chi) * xi * (2 - xi) + chi
    assert d.plate_reduction_factor == pytest.approx(rho, rel=1e-12)
    assert d.column_critical_stress_Pa == pytest.approx(column, rel=1e-12)
    assert d.column_reduction_factor == pytest.approx(chi, rel=1e-12)
    assert d.reduction_factor == pytest.approx(rho_c, rel=1e-12)
    assert d.reduced_design_stress_Pa == pytest.approx(rho_c * 355e6 / 1.1, rel=1e-12)
    assert d.reduction_factor < 0.9 * rho


def test_a_column_stress_above_the_plate_s_is_bounded_by_it():
    """sigma_cr,c <= sigma_cr,p (EN 1993-1-5 4.5.3(1), 4.5.4(1)): a plate with a hole.

    150 x 300 x 6 mm SSSS, loaded on left and right (a/b = 0.5), a hole of radius 60 mm
    at its centre, gmsh cells of 15 mm. 4.5.3(1) defines sigma_cr,c as the plate's
    buckling stress with the supports along its unloaded edges removed: fewer
    constraints, so by the Rayleigh quotient never above the plate's own sigma_cr,p.
    Eq. (4.8), pi^2 E t^2/(12 (1 - nu^2) a^2) = 303.68 MPa, knows no hole; the holed
    plate buckles at about 203 MPa. So sigma_cr,c = sigma_cr,p, xi = 0 and rho_c = chi_c
    at sqrt(f_y/sigma_cr,p) (EN 1993-1-1 6.3.1.2, curve a, alpha = 0.21, by hand here):
    0.4575. Before, xi = -0.33 was clipped to 0 with chi_c of 303.68 MPa: rho_c =
    0.6089, 33 % on the unsafe side.
    """
    hinged = {"support": "simply_supported"}
    edges = {
        "left": {**hinged, "normal_stress": -1.0},
        "right": {**hinged, "normal_stress": -1.0},
        "bottom": hinged,
        "top": hinged,
    }
    holed = {"corners": [[0, 0], [150, 300]], "thickness": 6.0}
    holed["holes"] = [{"center": [75.0, 150.0], "radius": 60.0}]
    d = result(plate(edges, plate=holed, mesh={"size": 15.0})).design
    equation_4_8 = math.pi**2 * 210000e6 * (6.0 / 150.0) ** 2 / (12 * (1 - 0.3**2))
    assert equation_4_8 == pytest.approx(303.68e6, rel=1e-5)
    sigma = d.sigma_cr_Pa
    assert 180e6 < sigma < 0.75 * equation_4_8  # the hole: well below the column's

    def chi(column):  # EN 1993-1-1 eq. (6.49), curve a
        lam = math.sqrt(355e6 / column)
        phi = 0.5 * (1 + 0.21 * (lam - 0.2) + lam**2)
        return min(1.0, 1 / (phi + math.sqrt(phi**2 - lam**2)))

    assert chi(sigma) == pytest.approx(0.4575, abs=1e-3)  # at about 203 MPa
    assert chi(equation_4_8) == pytest.approx(0.6089, abs=1e-4)  # the value before
    assert d.column_critical_stress_Pa == pytest.approx(sigma, rel=1e-12)
    assert d.xi == 0.0 and d.xi_unclipped == pytest.approx(0.0, abs=1e-12)
    assert d.column_reduction_factor == pytest.approx(chi(sigma), rel=1e-12)
    assert d.reduction_factor == pytest.approx(chi(sigma), rel=1e-12)
    assert d.reduction_factor < d.plate_reduction_factor
    assert d.reduced_design_stress_Pa == pytest.approx(chi(sigma) * 355e6 / 1.1, rel=1e-12)
    assert any("sigma_cr,c = sigma_cr (xi = 0)" in n for n in d.notes), d.notes


def test_a_long_plate_keeps_the_plate_type_reduction_factor():
    """At a/b = 3 (the 600 x 200 x 4 mm plate) rho_c = rho, and the record says why.

    The note of EN 1993-1-5 4.4(2) asks for the column-type check (4.5.4) for a/b < 1
    only. Before, the record cited 4.5.4(1) and gave sigma_cr,c, chi_c and xi as if
    they were applied; now they are null, a note names a/b and the clause.
    """
    out = result(plate({"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}))
    d = out.design
    assert d.reduction_factor == d.plate_reduction_factor
    assert (d.column_critical_stress_Pa, d.column_reduction_factor, d.xi) == (None, None, None)
    assert "4.5.4" not in d.clauses
    assert any("not applied: a/b = 3 >= 1" in n for n in d.notes), d.notes


@pytest.mark.parametrize("length", [0.8, 1.2])
def test_an_outstand_s_column_type_reduction_is_for_a_b_below_1(length):
    """The outstand of ``_outstand`` cut to a = 0.8 and 1.2 m (b = 1 m, 8 x 10 cells).

    Both have xi < 1 (an outstand's sigma_cr is near (0.425 + (b/a)^2) sigma_E, its
    column's (b/a)^2 sigma_E); EN 1993-1-5 sends a plate to 4.5.4 for a/b < 1 (the
    note of 4.4(2)): rho_c by hand (as in the test above, eq. (4.3)'s rho) at 0.8,
    eq. (4.3)'s rho itself at 1.2, where the column fields are null and the note gives
    xi, by hand here, for the engineer to judge.
    """
    spec = _outstand(mesh={"nx": 8, "ny": 10})
    data = problem_to_dict(spec)
    data["plate"] = {"corners": [[0, 0], [length, 1.0]], "thickness": 0.01}
    d = result(problem_from_dict(data)).design
    slenderness = math.sqrt(355e6 / d.sigma_cr_Pa)
    rho = (slenderness - 0.188) / slenderness**2
    column = math.pi**2 * 2.1e11 * (0.01 / length) ** 2 / (12 * (1 - 0.3**2))
    lam_c = math.sqrt(355e6 / column)
    phi = 0.5 * (1 + 0.21 * (lam_c - 0.2) + lam_c**2)
    chi = 1 / (phi + math.sqrt(phi**2 - lam_c**2))
    xi = d.sigma_cr_Pa / column - 1
    assert d.element == "outstand" and 0 < xi < 1
    if length < 1.0:
        assert d.xi == pytest.approx(xi, rel=1e-12)
        assert d.reduction_factor == pytest.approx((rho - chi) * xi * (2 - xi) + chi, rel=1e-12)
    else:
        assert d.xi is None and d.reduction_factor == pytest.approx(rho, rel=1e-12)
        assert any(f"xi = sigma_cr/sigma_cr,c - 1 = {xi:.3g} < 1" in n for n in d.notes)


def test_a_short_plate_with_xi_above_1_says_rho_c_is_rho():
    """a/b = 0.9 (270 x 300 x 2 mm SSSS, 9 x 10 cells): xi = k (a/b)^2 - 1 > 1, rho_c = rho.

    The column fields are given (4.5.4(1) applied, its interpolation ending at rho) and
    the summary says so, where before it said nothing of the column. ``xi`` is the value
    4.5.4(1) uses, bounded to 0 <= xi <= 1 (it was reported unclipped, 2.3, while rho_c
    used 1); the ratio sigma_cr/sigma_cr,c - 1 itself is ``xi_unclipped``.
    """
    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    data = problem_to_dict(plate(edges, mesh={"nx": 9, "ny": 10}), units="mm-N-MPa")
    data["plate"] = {"corners": [[0, 0], [270, 300]], "thickness": 2.0}
    out = result(problem_from_dict(data))
    d = out.design
    column = math.pi**2 * 210000e6 * (2.0 / 270.0) ** 2 / (12 * (1 - 0.3**2))  # eq. (4.8)
    assert d.column_critical_stress_Pa == pytest.approx(column, rel=1e-12)
    assert d.xi_unclipped == pytest.approx(d.sigma_cr_Pa / column - 1, rel=1e-12)
    assert d.xi_unclipped > 1 and d.xi == 1.0
    assert d.reduction_factor == d.plate_reduction_factor
    assert "4.5.4(1)" in d.clauses
    assert "(column-type: xi 1, the plate's)" in out.summary(), out.summary()
    assert any(f"sigma_cr/sigma_cr,c - 1 = {d.xi_unclipped:.3g} >= 1, xi = 1" in n for n in d.notes)


def test_clamped_loaded_edges_make_the_column_four_times_eq_4_8():
    """sigma_cr,c of a short plate with clamped loaded edges (EN 1993-1-5 4.5.3(1)).

    4.5.3(1): sigma_cr,c is the plate's buckling stress "with the supports along the
    longitudinal edges removed": between clamped loaded edges an Euler column of
    effective length a/2 (Timoshenko and Gere, Theory of Elastic Stability, chapter 2),
    4 pi^2 E t^2 / (12 (1 - nu^2) a^2). The 150 x 300 x 2 mm plate, unloaded edges
    simply supported, loaded edges clamped, at its sigma_cr of 162.634 MPa (16 x 32
    cells; the design output is a function of the load, so no solve here): rho_c by hand
    is 0.4176, where eq. (4.8)'s hinged column gave xi = 3.82 and rho = 0.5761, 38 % on
    the unsafe side.
    """
    from unibuckle_fenicsx.design import design_output

    clamped = {"normal_stress": -1.0, "support": "clamped"}
    data = problem_to_dict(plate({"left": clamped, "right": clamped}), units="mm-N-MPa")
    data["plate"] = {"corners": [[0, 0], [150, 300]], "thickness": 2.0}
    spec = problem_from_dict(data)
    assert spec.design is not None
    sigma = 162.634e6
    d = design_output(spec, spec.design, sigma)
    lam = math.sqrt(355e6 / sigma)
    rho = (lam - 0.22) / lam**2  # eq. (4.2), psi = 1
    column = 4 * math.pi**2 * 210000e6 * (2.0 / 150.0) ** 2 / (12 * (1 - 0.3**2))
    lam_c = math.sqrt(355e6 / column)
    phi = 0.5 * (1 + 0.21 * (lam_c - 0.2) + lam_c**2)  # EN 1993-1-1 6.3.1.2, curve a
    chi = 1 / (phi + math.sqrt(phi**2 - lam_c**2))
    xi = sigma / column - 1
    rho_c = (rho - chi) * xi * (2 - xi) + chi
    assert d.column_critical_stress_Pa == pytest.approx(column, rel=1e-12)
    assert d.xi == pytest.approx(xi, rel=1e-12)
    assert d.reduction_factor == pytest.approx(rho_c, rel=1e-12)
    assert d.reduction_factor == pytest.approx(0.4176, abs=1e-4)


def test_rotationally_restrained_loaded_edges_give_the_restrained_column():
    """Loaded edges on rotational springs k_r: the column between them (4.5.3(1)).

    A column of length a, ends held, each restrained by k_r, buckles symmetrically at
    u = beta a with tan(u/2) = -(2 D/(k_r a)) (u/2) (Timoshenko and Gere, chapter 2: the
    column with elastically restrained ends; solved here by scipy's brentq), sigma_cr,c =
    (u/pi)^2 times eq. (4.8); one end clamped and one hinged: tan u = u, u = 4.4934.
    """
    from scipy.optimize import brentq

    from unibuckle_fenicsx.design import design_output
    from unibuckle_fenicsx.en1993 import column_end_factor

    assert column_end_factor(math.inf, 0.0) == pytest.approx((4.493409457909064 / math.pi) ** 2)
    assert column_end_factor(0.0, 0.0) == 1.0 and column_end_factor(math.inf, math.inf) == 4.0
    k_r = 2.0e4  # N (N mm/mm)
    d_plate = 210000.0 * 2.0**3 / (12 * (1 - 0.3**2))  # N mm
    kappa = k_r * 150.0 / d_plate
    v = brentq(lambda v: math.sin(v) + (2 / kappa) * v * math.cos(v), math.pi / 2, math.pi)
    factor = (2 * v / math.pi) ** 2
    assert column_end_factor(kappa, kappa) == pytest.approx(factor, rel=1e-12)
    spring = {"normal_stress": -1.0, "rotational_stiffness": k_r}
    data = problem_to_dict(plate({"left": spring, "right": spring}), units="mm-N-MPa")
    data["plate"] = {"corners": [[0, 0], [150, 300]], "thickness": 2.0}
    spec = problem_from_dict(data)
    assert spec.design is not None
    # A sigma_cr above the column's 111.6 MPa: the plate buckles at no lower a stress than
    # its column (4.5.3(1); below it the column stress would be bounded by sigma_cr).
    d = design_output(spec, spec.design, 150e6)
    hinged = math.pi**2 * 210000e6 * (2.0 / 150.0) ** 2 / (12 * (1 - 0.3**2))
    assert d.column_critical_stress_Pa == pytest.approx(factor * hinged, rel=1e-12)
    assert 1.0 < factor < 4.0


def test_free_loaded_edges_give_the_column_their_supports():
    """Free loaded edges: the column of 4.5.3(1) is a cantilever, on springs, or a mechanism.

    The 50 x 100 x 2 mm S355 plate, unloaded edges hinged, loaded edges free (k = 1.5548
    on 20 x 40 cells: sigma_cr = 118.04 MPa; Kirchhoff's Rayleigh-Ritz, w = X(x) sin(pi
    y/b) with X a Legendre series of degree 20, gives 1.5820, the package 1.5817 on 40 x
    80 cells at t/b = 0.002), took the hinged column (eq. (4.8), 303.7 MPa, above the
    plate's own sigma_cr): xi = -0.611 clipped to 0 gave rho_c = chi_c = 0.6089 above
    the plate's rho = 0.5035, 21 % on the unsafe side. Without its unloaded supports the
    plate between free edges has no buckling stress (a mechanism): xi >= 1 and rho_c =
    rho. One edge clamped: the cantilever, effective length 2a, a quarter of eq. (4.8)
    (Timoshenko and Gere, Theory of Elastic Stability, 2.1). Free edges on translational
    springs k_t (N/mm per mm) small enough: the column turns as a rigid bar on its end
    springs, P = k_t a/2 per unit width (w = s - 1/2 satisfies the column's equation and
    both end conditions), sigma_cr,c = k_t a/(2 t); a cantilever on a rotational spring
    at its root: u tan u = k_r a/D.
    """
    from scipy.optimize import brentq

    from unibuckle_fenicsx.design import design_output
    from unibuckle_fenicsx.en1993 import column_end_factor

    def design(left, right, sigma):
        data = problem_to_dict(plate({"left": left, "right": right}), units="mm-N-MPa")
        data["plate"] = {"corners": [[0, 0], [50, 100]], "thickness": 2.0}
        data["design"] = {"yield_stress": 355.0}
        spec = problem_from_dict(data)
        assert spec.design is not None
        return design_output(spec, spec.design, sigma)

    def rho(sigma):  # eq. (4.2), psi = 1
        lam = math.sqrt(355e6 / sigma)
        return (lam - 0.22) / lam**2

    hinged = math.pi**2 * 210000e6 * (2.0 / 50.0) ** 2 / (12 * (1 - 0.3**2))  # eq. (4.8)
    free = {"normal_stress": -1.0, "support": "free"}
    d = design(free, free, 118.04e6)
    assert d.column_critical_stress_Pa == 0.0 and d.xi is None
    assert d.reduction_factor == pytest.approx(rho(118.04e6), rel=1e-12)
    assert d.reduction_factor == pytest.approx(0.5035, abs=1e-4)
    # Clamped and free: the cantilever, at a load where xi < 1.
    d = design({"normal_stress": -1.0, "support": "clamped"}, free, 100e6)
    column = hinged / 4
    lam_c = math.sqrt(355e6 / column)
    phi = 0.5 * (1 + 0.21 * (lam_c - 0.2) + lam_c**2)  # EN 1993-1-1 6.3.1.2, curve a
    chi = 1 / (phi + math.sqrt(phi**2 - lam_c**2))
    xi = 100e6 / column - 1
    assert d.column_critical_stress_Pa == pytest.approx(column, rel=1e-12)
    assert d.reduction_factor == pytest.approx((rho(100e6) - chi) * xi * (2 - xi) + chi)
    # Free edges on translational springs: the rigid bar on its springs.
    d_plate = 210000.0 * 2.0**3 / (12 * (1 - 0.3**2))  # N mm
    k_t = d_plate / 50.0**3  # N/mm^2: k_t a^3/D = 1
    sprung = {**free, "translational_stiffness": k_t}
    d = design(sprung, sprung, 100e6)
    assert d.column_critical_stress_Pa == pytest.approx(k_t * 50.0 / (2 * 2.0) * 1e6, rel=1e-9)
    # The factor itself: hinged, clamped and free, mechanisms, the sprung cantilever.
    assert column_end_factor(math.inf, 0.0, math.inf, 0.0) == pytest.approx(0.25, rel=1e-12)
    assert column_end_factor(0.0, 0.0, 0.0, 0.0) == 0.0
    assert column_end_factor(0.0, 0.0, math.inf, 0.0) == 0.0  # hinged and free
    kappa = 2.0
    u = brentq(lambda u: u * math.tan(u) - kappa, 1e-9, math.pi / 2 - 1e-12)
    factor = column_end_factor(kappa, 0.0, math.inf, 0.0)
    assert factor == pytest.approx((u / math.pi) ** 2, rel=1e-10)


def test_stress_gradient_obstacle_shear_and_fixed_part():
    """The critical state's edge stresses give psi; notes for the obstacle and the shear."""
    edges = {
        "left": {"normal_stress": [-1.0, 0.0], "fixed_normal_stress": [-20.0, 20.0]},
        "right": {"normal_stress": [-1.0, 0.0], "fixed_normal_stress": [-20.0, 20.0]},
        "bottom": {"fixed_shear_stress": 5.0},
        "top": {"fixed_shear_stress": 5.0},
    }
    edges["left"]["fixed_shear_stress"] = edges["right"]["fixed_shear_stress"] = -5.0
    out = result(plate(edges, obstacle={"zone": "all"}))
    lam = out.critical_load_Pa
    sigma1, sigma2 = 20e6 + lam, -20e6  # compression positive, at y = 0 and y = b
    d = out.design
    assert d.sigma_cr_Pa == pytest.approx(sigma1, rel=1e-14)
    assert d.psi == pytest.approx(sigma2 / sigma1, rel=1e-14)
    assert any("unilateral" in n for n in d.notes) and any("section 10" in n for n in d.notes)


def test_a_bilateral_foundation_is_not_called_unilateral():
    """A foundation on both sides (springs in tension too) makes a linear eigenproblem.

    Its design note says what sigma_cr includes, not that it is a unilateral one; a
    foundation on one side keeps the unilateral note.
    """
    from unibuckle_fenicsx.design import design_output

    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    for side, word in (("both", "bilateral foundation"), ("below", "unilateral")):
        spec = plate(edges, obstacle={"zone": "all", "side": side, "foundation_stiffness": 1e-3})
        assert spec.design is not None
        notes = design_output(spec, spec.design, 100.0).notes
        assert any(word in n for n in notes), notes
        assert side != "both" or not any("unilateral" in n for n in notes), notes


def test_an_obstacle_and_a_bilateral_foundation_are_both_noted():
    """A rigid obstacle on part of the plate, a foundation on both sides over the rest.

    sigma_cr is then unilateral (the obstacle's cone) and includes the foundation's
    springs: the note says both, not the obstacle alone.
    """
    from unibuckle_fenicsx.design import design_output

    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    spec = plate(
        edges,
        obstacles=[
            {"zone": [[0, 300], [0, 200]], "side": "below"},
            {"zone": [[400, 600], [0, 200]], "side": "both", "foundation_stiffness": 1e-3},
        ],
    )
    assert spec.design is not None
    notes = [n for n in design_output(spec, spec.design, 100.0).notes if "4.4(2)" in n]
    said = [n for n in notes if "unilateral" in n or "foundation" in n]
    assert len(said) == 1, notes
    assert "unilateral critical stress" in said[0], said
    assert 'bilateral foundation (obstacle.side = "both")' in said[0], said


def test_an_obstacle_with_a_gap_is_not_called_unilateral():
    """An obstacle with a gap leaves sigma_cr the free plate's: no unilateral note.

    The linear critical state leaves it out (an infinitesimal buckle does not reach it,
    ``ProblemSpec.unilateral_obstacles``); the design notes called sigma_cr unilateral.
    """
    from unibuckle_fenicsx.design import design_output

    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    for gap, unilateral in ((0.5, False), (0.0, True)):
        spec = plate(edges, obstacle={"zone": "all", "side": "below", "gap": gap})
        assert spec.design is not None
        notes = design_output(spec, spec.design, 100.0).notes
        assert any("unilateral" in n for n in notes) == unilateral, notes


@pytest.mark.parametrize(
    "point", [{"kind": "bilateral"}, {"kind": "spring", "stiffness": 1e3}, {"kind": "one-sided"}]
)
def test_point_restraints_are_noted(point):
    """Ties or springs inside the plate are noted: 4.4 describes a plate held by its edges.

    They raise sigma_cr (a row of ties at mid-width of a 300 x 100 x 3 mm plate: 1106 MPa
    against 689 MPa without) and the design said nothing of them; a one-sided point has
    the unilateral note.
    """
    from unibuckle_fenicsx.design import design_output

    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    point = {"at": [300.0, 100.0], **point} | (
        {"side": "below"} if point["kind"] == "one-sided" else {}
    )
    spec = plate(edges, points=[point])
    assert spec.design is not None
    notes = design_output(spec, spec.design, 100.0).notes
    ties = any("point restraints" in n for n in notes)
    assert ties == (point["kind"] != "one-sided"), notes


SHEARED_TENSION = {  # scaled: tension across left/right and shear; fixed: 10 MPa compression
    name: {"shear_stress": 1.0 if name in ("left", "right") else -1.0}
    | ({"normal_stress": 1.0, "fixed_normal_stress": -10.0} if name in ("left", "right") else {})
    for name in ("left", "right", "bottom", "top")
}


def test_loaded_edges_in_tension_at_the_critical_state_give_no_slenderness():
    """A fixed compression outgrown by the scaled tension: no sigma_cr, no rho.

    At the load factor 2e7, sigma = -10 MPa (fixed) + 2e7 x 1 = +10 MPa on left and right:
    tension, so the largest compression is -10 MPa (by hand) and 4.4(2) has no
    slenderness. Before, psi = sigma_2/sigma_1 divided by zero after the solve (exit 1).
    """
    from unibuckle_fenicsx.design import design_output

    spec = plate(SHEARED_TENSION)
    assert spec.design is not None
    d = design_output(spec, spec.design, 2e7)
    assert d.sigma_cr_Pa == pytest.approx(-10e6, rel=1e-14)
    assert (d.psi, d.relative_slenderness, d.reduction_factor) == (None, None, None)
    assert "in tension at the critical state" in d.notes[-1]
    out = result(spec)  # shear buckles it near 1e9 Pa, far above 10 MPa: in tension
    assert out.design.relative_slenderness is None
    assert "no compression on the loaded edges at the critical state" in out.summary()


def test_a_ratio_a_rounding_below_the_table_end_is_the_end():
    """[-0.7, 2.1] is psi = -3 (2.1/0.7 = 3.0000000000000004 in double precision).

    It was refused as "psi = -3, outside Table 4.1, which covers 1 >= psi >= -3"; Table
    4.1 gives k_sigma = 5.98 (1 - psi)^2 = 95.68 there.
    """
    from unibuckle_fenicsx.design import design_output

    pair = {"normal_stress": [-0.7, 2.1]}
    spec = plate({"left": pair, "right": pair})
    assert spec.design is not None
    d = design_output(spec, spec.design, 1e9)
    assert d.psi == -3.0 and d.sigma_cr_Pa == pytest.approx(0.7e9, rel=1e-14)
    assert d.k_sigma_table == pytest.approx(5.98 * 16, rel=1e-14)


def test_a_fixed_compression_switched_off_by_its_factor_is_no_compression():
    """load.fixed_factor = 0 leaves the scaled tension alone: refused before the solve."""
    with pytest.raises(ValueError, match=r"design: the EN 1993-1-5 output takes sigma_cr"):
        plate(SHEARED_TENSION, load={"fixed_factor": 0.0})


# -- outstand elements (one unloaded edge free) ------------------------------------------
@pytest.mark.parametrize(
    "slenderness, psi, rho",
    [
        (0.748, 1.0, 1.0),
        (0.7, -1.0, 1.0),
        (1.0, 1.0, 0.812),  # (1 - 0.188) / 1
        (1.5, 0.0, (1.5 - 0.188) / 2.25),
        (1.5, -1.0, (1.5 - 0.188) / 2.25),  # psi does not enter (4.3)
        (5.0, -3.0, (5.0 - 0.188) / 25.0),
    ],
)
def test_outstand_reduction_factor_is_en_1993_1_5_eq_4_3(slenderness, psi, rho):
    assert reduction_factor(slenderness, psi, "outstand") == pytest.approx(rho, rel=1e-12)


def test_the_internal_formula_is_unconservative_for_an_outstand_below_psi_0_42():
    """Eq. (4.2) and (4.3) at slenderness 1.5 and psi = -1: 0.618 (internal) > 0.583."""
    internal, outstand = reduction_factor(1.5, -1.0), reduction_factor(1.5, -1.0, "outstand")
    assert internal == pytest.approx((1.5 - 0.11) / 2.25, rel=1e-12)  # 0.6178
    assert outstand == pytest.approx(1.312 / 2.25, rel=1e-12)  # 0.5831
    assert internal > outstand
    # Equal where 0.055 (3 + psi) = 0.188, psi = 0.418; above, the outstand's is larger.
    assert reduction_factor(1.5, 0.5) < reduction_factor(1.5, 0.5, "outstand")


@pytest.mark.parametrize(
    "element, at_free, psi, k",
    [
        ("internal", True, 1.0, 4.0),
        ("internal", True, 0.5, 8.2 / 1.55),
        ("internal", True, 0.0, 7.81),
        ("internal", True, -0.5, 7.81 + 3.145 + 2.445),
        ("internal", True, -1.0, 23.9),
        ("internal", True, -2.0, 5.98 * 9.0),
        ("outstand", True, 1.0, 0.43),
        ("outstand", True, 0.0, 0.57),
        ("outstand", True, -1.0, 0.85),
        ("outstand", True, -3.0, 0.57 + 0.63 + 0.63),
        ("outstand", False, 1.0, 0.43),
        ("outstand", False, 0.5, 0.578 / 0.84),
        ("outstand", False, 0.0, 1.70),
        ("outstand", False, -0.5, 1.70 + 2.5 + 4.275),
        ("outstand", False, -1.0, 23.8),
    ],
)
def test_buckling_factors_of_tables_4_1_and_4_2(element, at_free, psi, k):
    from unibuckle_fenicsx.en1993 import buckling_factor

    assert buckling_factor(element, psi, at_free) == pytest.approx(k, rel=1e-12)


def test_table_4_2_ranges():
    """Larger compression at the supported edge: Table 4.2 stops at psi = -1."""
    from unibuckle_fenicsx.en1993 import buckling_factor

    with pytest.raises(ValueError, match=r"psi must lie in \[-1, 1\] \(EN 1993-1-5, Table 4.2"):
        buckling_factor("outstand", -1.5, False)
    assert buckling_factor("outstand", -1.5, True) > 0.0


OUTSTAND_EDGES = {
    "left": {"normal_stress": -1.0},
    "right": {"normal_stress": -1.0},
    "top": {"support": "free"},
}


def _outstand(edges=None, **extra):
    """An outstand: 3 x 1 m, t = 10 mm, steel, top edge free, f_y = 355 MPa."""
    data = {
        "plate": {"corners": [[0, 0], [3.0, 1.0]], "thickness": 0.01},
        "material": {"E": 2.1e11, "nu": 0.3},
        "edges": edges or OUTSTAND_EDGES,
        "mesh": {"nx": 12, "ny": 4},
        "design": {"yield_stress": 3.55e8},
        **extra,
    }
    return problem_from_dict(data)


def test_an_outstand_gets_the_outstand_reduction_factor():
    """A free unloaded edge: rho = (lambda_p - 0.188) / lambda_p^2, and the JSON says so.

    Before, the internal element's (lambda_p - 0.22) / lambda_p^2 was returned.
    """
    out = result(_outstand())
    d = out.design
    slenderness = math.sqrt(3.55e8 / out.critical_load_Pa)
    assert d.relative_slenderness == pytest.approx(slenderness, rel=1e-14)
    assert d.element == "outstand" and d.free_edge == "top"
    assert d.reduction_factor == pytest.approx((slenderness - 0.188) / slenderness**2, 1e-14)
    assert d.k_sigma_table == 0.43 and d.psi == 1.0
    assert "outstand compression element (edges.top free)" in d.clauses
    assert "eq. (4.3)" in d.clauses and "Table 4.2" in d.clauses
    assert "outstand element (free edge top)" in out.summary()


def test_an_internal_element_says_so():
    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    d = result(_outstand(edges)).design
    assert d.element == "internal" and d.free_edge is None and d.k_sigma_table == 4.0
    assert "internal compression element" in d.clauses and "Table 4.1" in d.clauses


@pytest.mark.parametrize(
    ("free", "at_free", "k"),
    [("top", False, 1.70), ("bottom", True, 0.57)],
)
def test_the_outstand_row_follows_the_larger_compression(free, at_free, k):
    """sigma_x = -lambda (1 - y/b): largest at the bottom edge, zero at the top (psi = 0).

    With the top free the larger compression acts at the supported edge (Table 4.2,
    lower row: k = 1.70), with the bottom free at the free edge (upper row: 0.57).
    """
    gradient = {"normal_stress": [-1.0, 0.0]}
    edges = {"left": gradient, "right": gradient, free: {"support": "free"}}
    d = result(_outstand(edges)).design
    assert d.psi == 0.0 and d.k_sigma_table == k and d.free_edge == free
    where = "free" if at_free else "supported"
    assert f"larger compression at the {where} edge" in d.table


REFUSED = [
    (
        {"top": {"support": "free"}, "bottom": {"support": "free"}},
        {},
        r"edges\.bottom\.support and edges\.top\.support are both \"free\".*strut",
    ),
    (
        {"bottom": {"normal_stress": -0.5}},
        {},
        r"edges\.left\.normal_stress, edges\.right\.normal_stress, edges\.bottom\.normal_stress "
        r"give normal stress in both directions",
    ),
    (
        {"top": {"support": "free", "translational_stiffness": 1e6}},
        {},
        r"edges\.top\.translational_stiffness: an unloaded edge on springs",
    ),
    ({"top": {"inplane": "roller"}}, {}, r"edges\.top\.inplane = \"roller\" holds an unloaded"),
    (
        {"left": {"normal_stress": [-1.0, 2.0]}, "right": {"normal_stress": [-1.0, 2.0]},
         "top": {"support": "free"}},
        {},
        r"edges\.left\.normal_stress gives the stress ratio psi = sigma_2/sigma_1 = -2, "
        r"outside EN 1993-1-5 Table 4\.2 \(outstand .* at the supported edge\)",
    ),
    (
        {"left": {"normal_stress": [-1.0, 4.0]}, "right": {"normal_stress": [-1.0, 4.0]}},
        {},
        r"psi = sigma_2/sigma_1 = -4, outside EN 1993-1-5 Table 4\.1",
    ),
    (
        {"left": {"normal_stress": 0.0, "inplane": "clamped"}},
        {"load": {"temperature": 1.0},
         "material": {"E": 2.1e11, "nu": 0.3, "thermal_expansion": 1.2e-5}},
        r"design: load\.temperature: a temperature rise adds a membrane stress",
    ),
]  # fmt: skip


@pytest.mark.parametrize(("edges", "extra", "match"), REFUSED)
def test_what_clause_4_4_does_not_describe_is_refused(edges, extra, match):
    base = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    merged = {name: {**base.get(name, {}), **edges.get(name, {})} for name in (*base, *edges)}
    with pytest.raises(ValueError, match=match):
        _outstand(merged, **extra)


def test_an_outline_plate_is_refused():
    data = {
        "plate": {"outline": [[0, 0], [3, 0], [3, 1], [0, 1]], "thickness": 0.01},
        "edges": {"ends": {"segments": [1, 3], "normal_stress": -1.0}},
        "mesh": {"size": 0.25},
        "design": {"yield_stress": 3.55e8},
    }
    with pytest.raises(ValueError, match=r"design: .* this plate is given by its outline"):
        problem_from_dict(data)


def test_a_stress_on_the_holes_alone_is_refused_naming_its_key():
    """A normal stress on the holes' boundary only: refused naming that key.

    EN 1993-1-5 4.4 takes the direct stress across two opposite edges of the plate
    element; the 300 x 100 mm plate with a 20 mm hole, held in its plane at its ends and
    loaded by a pressure on the hole's edge alone, was refused as "design:  give normal
    stress in both directions (biaxial)", naming no key and a load it does not have.
    """
    data = {
        "plate": {
            "corners": [[0, 0], [0.3, 0.1]],
            "thickness": 0.002,
            "holes": [{"center": [0.15, 0.05], "radius": 0.02}],
        },
        "material": {"E": 2.1e11, "nu": 0.3},
        "edges": {
            "left": {"inplane": "clamped"},
            "right": {"inplane": "clamped"},
            "bottom": {},
            "top": {},
            "holes": {"support": "free", "normal_stress": -1.0},
        },
        "mesh": {"size": 0.01},
        "design": {"yield_stress": 3.55e8},
    }
    said = r"design: edges\.holes\.normal_stress on none of the rectangle's edges: EN 1993-1-5"
    with pytest.raises(ValueError, match=said) as refused:
        problem_from_dict(data)
    assert "biaxial" not in str(refused.value)


def test_a_rectangle_with_a_hole_is_classified_by_its_edges():
    """The README's plate (clamped all round, a 40 mm hole): an internal element, a note.

    Its unloaded edges (bottom, top) are clamped: internal, Table 4.1. At sigma_cr = 1.753e9
    Pa (the README's load), psi = 1: lambda_p = sqrt(3.55e8/1.753e9) = 0.45 <= 0.673, rho = 1
    by eq. (4.2); the output says that 4.4 describes plates without openings.
    """
    from unibuckle_fenicsx import load_toml
    from unibuckle_fenicsx.design import design_output

    spec = load_toml(ROOT / "demos" / "plate.toml")
    assert spec.plate.holes
    out = design_output(spec, spec.design, 1.753e9)
    assert (out.element, out.free_edge, out.psi) == ("internal", None, 1.0)
    assert out.relative_slenderness == pytest.approx(math.sqrt(3.55e8 / 1.753e9), rel=1e-14)
    assert out.reduction_factor == 1.0
    assert any("without openings" in note for note in out.notes), out.notes


def test_psi_outside_the_table_with_a_fixed_part_gives_no_rho():
    """With a fixed normal stress psi depends on the load: no refusal, no rho, a note.

    In-plane bending (bottom compressed) plus a fixed tension at the free top edge:
    sigma_1 = lambda at the supported bottom, sigma_2 = -(lambda + 1 MPa) at the top,
    psi = -1 - 1e6/lambda < -1, below Table 4.2's lower row.
    """
    gradient = {"normal_stress": [-1.0, 1.0], "fixed_normal_stress": [0.0, 1e6]}
    edges = {"left": gradient, "right": gradient, "top": {"support": "free"}}
    out = result(_outstand(edges))
    d = out.design
    lam = out.critical_load_Pa
    assert d.sigma_cr_Pa == pytest.approx(lam, rel=1e-14)
    assert d.psi == pytest.approx(-1.0 - 1e6 / lam, rel=1e-12)
    assert d.reduction_factor is None and d.k_sigma_table is None
    assert "outside Table 4.2" in d.notes[-1]
    assert "rho = none (psi outside Table 4.2" in out.summary()


def test_an_unproven_critical_load_adds_the_design_at_its_lower_bound():
    """KKT only (certify = false): rho at lambda_c may be unsafe; the lower bound's is given.

    The 600 x 200 x 4 mm plate on a whole face: lambda_c = 381 MPa, not proven the lowest,
    the verified lower bound the free plate's 331 MPa (interlacing, less its rounding). At
    it, by hand, lambda_p = sqrt(355/331.1) = 1.035 and rho = (1.035 - 0.22)/1.035^2 = 0.761, where
    lambda_c's 0.965 gives 0.800: 5 % on the unsafe side.
    """
    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    spec = plate(edges, obstacle={"zone": "all", "side": "below"}, solver={"certify": False})
    with solve(spec, MPI.COMM_SELF) as analysis:
        r = analysis.result
    assert r.certificate is not None and r.certificate.status == "kkt-only"
    assert r.lower_bound_Pa == pytest.approx(r.free_load_Pa, rel=1e-12)
    low = r.design.lower_bound
    slenderness = math.sqrt(355e6 / r.lower_bound_Pa)
    rho = (slenderness - 0.055 * 4) / slenderness**2
    assert low.sigma_cr_Pa == r.lower_bound_Pa
    assert low.relative_slenderness == pytest.approx(slenderness, rel=1e-14)
    assert low.reduction_factor == pytest.approx(rho, rel=1e-14)
    assert low.reduced_design_stress_Pa == pytest.approx(rho * 355e6 / 1.1, rel=1e-14)
    assert low.reduction_factor < r.design.reduction_factor
    assert any("not proven the lowest" in note for note in r.design.notes)
    assert f"slenderness {slenderness:.4g}, rho = {rho:.4g}" in r.summary()
    assert r.as_dict()["design"]["lower_bound"]["reduction_factor"] == low.reduction_factor
    # The safe line gives the safe stress limit too (it gave rho alone): rho f_y/gamma_M0.
    safe = next(s for s in r.summary().splitlines() if "at the verified lower bound" in s)
    assert f"rho f_y/gamma_M0 = {rho * 355 / 1.1:#.4g} MPa" in safe, safe


def test_the_summary_keeps_four_significant_digits_in_pa():
    """A stress in Pa with trailing zeros read as one digit: "2e+08" for 2.000e8.

    The 600 x 200 x 10 mm SSSS steel plate in SI with f_y = 200 MPa and gamma_M0 = 1:
    sigma_cr = k sigma_E, sigma_E = pi^2 E t^2/(12(1 - nu^2) b^2) = 474.5 MPa, k = 4 for the
    long simply supported plate (Timoshenko and Gere, section 9.2; 5.8 on these coarse
    cells): any k above 0.93 puts lambda_p = sqrt(f_y/sigma_cr) below 0.673, where rho =
    1 (EN 1993-1-5 eq. (4.2)), so rho f_y/gamma_M0 is
    f_y = 2e8 Pa exactly. The summary printed "rho = 1, rho f_y/gamma_M0 = 2e+08 Pa", one
    significant digit to the eye where the line gives four elsewhere; it is 2.000e+08.
    """
    hinged = {"support": "simply_supported"}
    spec = problem_from_dict(
        {
            "plate": {"corners": [[0, 0], [0.6, 0.2]], "thickness": 0.01},
            "material": {"E": 2.1e11, "nu": 0.3},
            "edges": {
                "left": {**hinged, "normal_stress": -1.0},
                "right": {**hinged, "normal_stress": -1.0},
                "bottom": hinged,
                "top": hinged,
            },
            "mesh": {"nx": 6, "ny": 2},
            "design": {"yield_stress": 2.0e8, "partial_factor": 1.0},
        }
    )
    out = result(spec)
    assert out.design.relative_slenderness < 0.673
    line = next(s for s in out.summary().splitlines() if "EN 1993-1-5: " in s)
    assert "rho = 1.000, rho f_y/gamma_M0 = 2.000e+08 Pa;" in line, line
    mantissa = re.search(r"sigma_cr = (\d\.\d+)e\+09 Pa", line)
    assert mantissa is not None and len(mantissa[1]) == 5, line  # d.ddd: four digits
    assert significant(2.000149e8) == "2.000e+08" and significant(1234.4) == "1234"
    assert significant(0.45) == "0.4500" and significant(355.0) == "355.0"


def test_a_ratio_beside_a_row_boundary_prints_the_digits_that_show_its_row():
    """A stress ratio psi = -0.9996 is in Table 4.1's row 0 > psi > -1, not at psi = -1.

    That row's k_sigma = 7.81 - 6.29 psi + 9.78 psi^2 = 23.8697 (EN 1993-1-5 Table 4.1),
    not the -1 column's 23.9; the summary printed "psi = -1" (three significant
    digits) while the middle row was used. Likewise xi = 0.9996 < 1 interpolates
    (4.5.4(1)), where xi = 1 is rho itself: the note printed "xi = ... = 1 < 1".
    """
    from unibuckle_fenicsx.design import design_output

    pair = [-1.0, 0.9996]
    hinged = {"support": "simply_supported"}
    spec = problem_from_dict(
        {
            "plate": {"corners": [[0, 0], [0.6, 0.2]], "thickness": 0.01},
            "material": {"E": 2.1e11, "nu": 0.3},
            "edges": {
                "left": {**hinged, "normal_stress": pair},
                "right": {**hinged, "normal_stress": pair},
                "bottom": hinged,
                "top": hinged,
            },
            "mesh": {"nx": 6, "ny": 2},
            "design": {"yield_stress": 3.55e8, "partial_factor": 1.0},
        }
    )
    out = result(spec)
    psi = -0.9996
    assert out.design.psi == pytest.approx(psi, rel=1e-12)
    assert out.design.k_sigma_table == pytest.approx(7.81 - 6.29 * psi + 9.78 * psi**2, 1e-12)
    line = next(s for s in out.summary().splitlines() if "EN 1993-1-5: " in s)
    assert "psi = -0.9996, " in line, line
    # A short plate (a/b = 0.5) at sigma_cr = 1.9996 sigma_cr,c: xi = 0.9996.
    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    short = plate(edges, plate={"corners": [[0, 0], [100, 200]], "thickness": 4.0})
    column = math.pi**2 * 210000e6 * (4.0 / 100.0) ** 2 / (12 * (1 - 0.3**2))  # eq. (4.8)
    assert short.design is not None
    d = design_output(short, short.design, 1.9996 * column)
    assert d.xi == pytest.approx(0.9996, rel=1e-9) and d.reduction_factor < d.plate_reduction_factor
    assert any("sigma_cr/sigma_cr,c - 1 = 0.9996 < 1" in n for n in d.notes), d.notes
