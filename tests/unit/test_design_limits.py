r"""The design output at the edges of EN 1993-1-5 4.4: tension yield, psi < -3, small k.

Expected values are written out here from the codes, not read from the package:

- EN 1993-1-1:2005 6.2.1(5): a point of a cross-section is within its elastic resistance
  while its stress is at most :math:`f_y/\gamma_{M0}`. Under compression plus bending the
  tension edge (or fibre) carries :math:`\sigma_t`; with every stress scaled by one load
  factor it reaches :math:`f_y/\gamma_{M0}` when the compressed edge carries
  :math:`\sigma_1 f_y/(\gamma_{M0}\sigma_t)`, before :math:`\sigma_1` reaches
  :math:`\rho f_y/\gamma_{M1}` (EN 1993-1-5 4.4(2); at :math:`\psi < 1` the reduced
  stress method, section 10, eq. (10.1), with direct stress alone; the one
  ``partial_factor`` stands for both factors) exactly when
  :math:`\sigma_1/\sigma_t < \rho`, i.e. :math:`\sigma_t/\sigma_1 > 1/\rho`. The
  reduction factor is eq. (4.2), :math:`\rho = (\bar\lambda_p - 0.055(3 + \psi))/\bar\lambda_p^2`,
  :math:`\bar\lambda_p = \sqrt{f_y/\sigma_1}`.
- EN 1993-1-5 Table 4.1 and eq. (4.2) cover :math:`1 \ge \psi \ge -3` only.
- A strut (a plate with both long edges free, hinged at its loaded ends) buckles at the
  Euler stress :math:`\pi^2 E t^2/(12 a^2)` (Timoshenko and Gere, *Theory of Elastic
  Stability*, 2nd ed., section 2.1), so its :math:`k = \sigma t b^2/(\pi^2 D) =
  (1 - \nu^2)(b/a)^2`.
"""

from __future__ import annotations

import math

from mpi4py import MPI

import pytest

from unibuckle_fenicsx import SectionParameters
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.cli.sweep import sweep_table
from unibuckle_fenicsx.design import design_output, significant
from unibuckle_fenicsx.section_design import design_line, section_design
from unibuckle_fenicsx.spec import DesignSpec, problem_from_dict

FY = 3.55e8


def _web(pair, *, partial_factor=1.0, mesh=None):
    """A 900 x 300 x 4 mm SSSS plate, ``pair`` on its ends (mm-N-MPa), S355."""
    return problem_from_dict(
        {
            "units": "mm-N-MPa",
            "plate": {"corners": [[0, 0], [900, 300]], "thickness": 4.0},
            "material": {"E": 210000.0, "nu": 0.3},
            "edges": {
                "left": {"normal_stress": pair},
                "right": {"normal_stress": pair},
                "bottom": {},
                "top": {},
            },
            "mesh": mesh or {"nx": 6, "ny": 2},
            "design": {"yield_stress": 355.0, "partial_factor": partial_factor},
        }
    )


def test_a_plate_s_tension_edge_that_yields_first_governs():
    """At psi = -2 and sigma_1 = 400 MPa the tension edge carries 800 MPa.

    By hand: lambda_p = sqrt(355/400) = 0.9421, above 0.5 + sqrt(0.085 + 0.11) = 0.9416,
    so rho = (0.9421 - 0.055)/0.8875 = 0.9995 (eq. (4.2)); sigma_t/sigma_1 = 2 > 1/rho: the
    tension edge reaches f_y/gamma_M0 = 355/1.1 MPa when sigma_1 = 355/1.1/2 = 161.4 MPa,
    far below rho f_y/gamma_M1 = 322.6 MPa (psi < 1: section 10's limit, gamma_M1; the
    note said gamma_M0, 4.6(1)'s, which checks A_eff and W_eff, not sigma_1 alone).
    Before, only 322.6 MPa was given.
    """
    spec = _web([-1.0, 2.0], partial_factor=1.1)
    d = design_output(spec, spec.design, 4.0e8)
    slenderness = math.sqrt(FY / 4.0e8)
    rho = (slenderness - 0.055 * (3.0 - 2.0)) / slenderness**2
    assert d.psi == -2.0 and d.reduction_factor == pytest.approx(rho, rel=1e-14)
    assert d.tension_Pa == pytest.approx(8.0e8, rel=1e-14)
    assert d.sigma_1_at_tension_yield_Pa == pytest.approx(FY / 1.1 / 2.0, rel=1e-14)
    assert d.tension_yield_first is True
    assert any("the tension edge yields first (EN 1993-1-1 6.2.1(5))" in n for n in d.notes)
    assert any(f"below rho f_y/gamma_M1 = {rho * FY / 1.1:#.4g} Pa" in n for n in d.notes)


def test_a_plate_s_tension_edge_below_rho_does_not_govern():
    """At psi = -0.5 and sigma_1 = 400 MPa, sigma_t/sigma_1 = 0.5 < 1/rho.

    lambda_p = 0.9421 above 0.5 + sqrt(0.085 + 0.0275) = 0.8354, so rho = (0.9421 -
    0.1375)/0.8875 = 0.9066 (eq. (4.2)): sigma_1 reaches rho f_y first, tension does not
    govern (it would yield at sigma_1 = 2 f_y).
    """
    spec = _web([-1.0, 0.5])
    d = design_output(spec, spec.design, 4.0e8)
    slenderness = math.sqrt(FY / 4.0e8)
    assert d.reduction_factor == pytest.approx(
        (slenderness - 0.055 * 2.5) / slenderness**2, rel=1e-14
    )
    assert d.tension_Pa == pytest.approx(2.0e8, rel=1e-14)
    assert d.sigma_1_at_tension_yield_Pa == pytest.approx(2.0 * FY, rel=1e-14)
    assert d.tension_yield_first is False
    # Uniform compression: no tension, nothing said.
    uniform = _web(-1.0)
    d = design_output(uniform, uniform.design, 4.0e8)
    assert d.tension_Pa is None and d.tension_yield_first is None


@pytest.mark.parametrize(
    ("pair", "sigma1", "rho"),
    [
        # psi = -1: lambda_p = sqrt(355/200) = 1.3323 > 0.5 + sqrt(0.14) = 0.8742, rho =
        # (1.3323 - 0.11)/1.775 = 0.68861; the tension edge (200 MPa) yields at sigma_1 = f_y
        # = 355 MPa, above rho f_y = 244.5 MPa: buckling governs, whatever rho < 1.
        ([-1.0, 1.0], 2.0e8, 0.688615),
        # psi = -2: lambda_p = sqrt(355/88.75) = 2, rho = (2 - 0.055)/4 = 0.48625; the
        # tension edge yields at sigma_1 = f_y/2 = 177.5 MPa, above rho f_y = 172.6 MPa.
        ([-1.0, 2.0], 8.875e7, 0.48625),
    ],
)
def test_a_plate_s_tension_edge_between_rho_and_one_does_not_govern(pair, sigma1, rho):
    """With rho < sigma_t/sigma_1 < 1/rho, sigma_1 reaches rho f_y/gamma_M1 first (6.2.1(5)).

    The comparison is of sigma_1 at tension yield, f_y sigma_1/sigma_t, with rho f_y;
    sigma_t/sigma_1 > rho alone called yield first here, with a sigma_1 at yield above
    rho f_y/gamma_M1 (unsafe: it is not a stress the element carries).
    """
    spec = _web(pair)
    d = design_output(spec, spec.design, sigma1)
    assert d.reduction_factor == pytest.approx(rho, abs=1e-6)
    ratio = d.tension_Pa / d.sigma_cr_Pa
    assert d.reduction_factor < ratio < 1.0 / d.reduction_factor
    assert d.sigma_1_at_tension_yield_Pa > d.reduction_factor * FY
    assert d.tension_yield_first is False
    assert not any("yields first" in n for n in d.notes)


def test_the_summary_says_the_tension_edge_yields_first():
    """The solve's summary line names it, in the file's MPa (sigma_1 = f_y/|psi| = 177.5)."""
    spec = _web([-1.0, 2.0], mesh={"nx": 12, "ny": 9})
    with solve(spec, MPI.COMM_SELF) as analysis:
        out = analysis.result
    lam = out.critical_load_Pa  # sigma_1 = lambda_c: psi = -2 on a stocky web, rho = 1
    assert out.design.reduction_factor == 1.0 and out.design.tension_yield_first is True
    line = next(s for s in out.summary().splitlines() if "EN 1993-1-5: " in s)
    assert (
        f"the tension edge yields first (EN 1993-1-1 6.2.1(5): {significant(2 * lam / 1e6)} "
        "MPa of tension at sigma_cr), at sigma_1 = 177.5 MPa: yield governs, not rho"
    ) in line, line


def _box(**changes: object) -> SectionParameters:
    base = {
        "thickness": 0.004, "width": 0.2, "depth": 0.3, "diameter": None, "length": 0.6,
        "E": 2.1e11, "nu": 0.3, "mesh_size": 0.04, "ends": "simply_supported",
        "axial_stress": 0.6, "bending_stress": 1.0, "core": False,
    }  # fmt: skip
    return SectionParameters(changes.pop("shape", "box"), **{**base, **changes})


def test_a_box_s_webs_outside_table_4_1_and_its_tension_face_are_said():
    """Axial +0.6 (tension) and bending 1 at z = +d/2: top -1.6, bottom +0.4 compression.

    The webs run from 0.4 to -1.6 in the gross section: psi = -4. The top face's tension
    1.6 lambda reaches f_y at f_y/(1.6 lambda) = 0.3698 x lambda (lambda = 6e8 Pa); the
    bottom face (sigma_1 = 2.4e8 Pa, psi = 1): lambda_p = sqrt(355/240) = 1.2162, rho =
    (1.2162 - 0.22)/1.2162^2 = 0.6735, reaches rho f_y at 0.6735 x 355/240 = 0.9962 x
    lambda: the tension face yields first, which the output did not say. The webs' psi is
    EN 1993-1-5 4.4(3)'s, the bottom (compression) flange effective, 0.6735 x 200 mm, the
    other flange and the webs gross (200 x 300 mm mid-line, t = 1 mm): the neutral axis
    by the first moment of area z' = (134.70 x (-150) - 200 x (-150))/(134.70 + 200 +
    600) = 10.480 mm; the axial part 0.6 plus the bending part, -1 at the bottom (z_c =
    -150 mm) and (150 - 10.48)/(150 + 10.48) = 0.8694 at the top: 1.4694 at the top end,
    -0.4 at the bottom, psi = -3.6735, still outside Table 4.1 (1 >= psi >= -3): no rho,
    and the output said nothing of them.
    """
    load = 6.0e8
    out = section_design(_box(), DesignSpec(yield_stress=FY), load)
    faces = {f.face: f for f in out.faces}
    slenderness = math.sqrt(FY / (0.4 * load))
    rho = (slenderness - 0.22) / slenderness**2
    z_na = (200.0 * rho * -150.0 - 200.0 * -150.0) / (200.0 * rho + 200.0 + 600.0)
    top, bottom = (0.6 - 1.0 * (z - z_na) / (-150.0 - z_na) for z in (150.0, -150.0))
    psi = top / bottom
    assert (z_na, top, bottom, psi) == pytest.approx((10.480, 1.4694, -0.4, -3.6735), abs=1e-3)
    assert faces["right"].psi == pytest.approx(psi, rel=1e-12)
    assert faces["right"].psi_gross == -4.0 and faces["right"].reduction_factor is None
    assert out.faces_outside_table == ["right", "left"]
    assert any(
        "outside EN 1993-1-5 Table 4.1" in n and "right (psi = -3.67)" in n for n in out.notes
    )
    assert faces["bottom"].reduction_factor == pytest.approx(rho, rel=1e-14)
    assert rho * FY / (0.4 * load) == pytest.approx(0.9962, abs=1e-4)
    assert out.governing_face == "bottom"
    assert out.tension_face == "top" and out.tension_Pa == pytest.approx(1.6 * load)
    assert out.tension_yield_multiple == pytest.approx(FY / (1.6 * load), rel=1e-14)
    assert out.tension_yield_first is True
    line = design_line(out, 1e6, "MPa")
    assert "face(s) right, left: psi < -3, outside Table 4.1: no k_sigma or rho" in line
    assert (
        "face top yields in tension first (EN 1993-1-1 6.2.1(5): 960.0 MPa of tension at "
        "sigma_cr, f_y/gamma_M0 at 0.3698 x the critical load): yield governs, not rho"
    ) in line, line


def test_a_box_whose_compressed_faces_govern_says_nothing_of_tension():
    """Axial -1, bending 2: top +1 (tension), bottom -3.

    At lambda = 4e7 Pa the bottom face (120 MPa, lambda_p = 1.720, rho = 0.5071) reaches
    rho f_y at 1.50 x lambda, the top face f_y at 355/40 = 8.875 x lambda.
    """
    out = section_design(
        _box(axial_stress=-1.0, bending_stress=2.0), DesignSpec(yield_stress=FY), 4.0e7
    )
    assert out.tension_Pa == pytest.approx(4.0e7) and out.tension_face == "top"
    assert out.tension_yield_multiple == pytest.approx(8.875)
    assert out.tension_yield_first is False and out.faces_outside_table == []
    assert "tension" not in design_line(out)


def test_a_tube_s_tension_fibre_gets_its_multiple():
    """A tube (no rho) in bending with a tension: the fibre's multiple f_y/sigma_t is given."""
    tube = _box(shape="tube", width=None, depth=None, diameter=0.2, axial_stress=-0.5)
    out = section_design(tube, DesignSpec(yield_stress=FY), 1.0e9)
    assert out.tension_Pa == pytest.approx(0.5e9) and out.tension_face is None
    assert out.tension_yield_multiple == pytest.approx(0.71)
    assert out.tension_yield_first is None
    assert "the tension fibre (500.0 MPa of tension at sigma_cr) reaches f_y/gamma_M0 at " \
        "0.7100 x the critical load" in design_line(out, 1e6, "MPa")  # fmt: skip


def test_a_strut_s_small_k_keeps_four_significant_digits():
    """2000 x 20 x 4 mm, the long edges free: k = (1 - nu^2)(b/a)^2 = 9.1e-5 (Euler).

    The summary printed "k = 0.0001", its one digit wrong; now four significant digits
    (and the sweep table likewise).
    """
    spec = problem_from_dict(
        {
            "units": "mm-N-MPa",
            "plate": {"corners": [[0, 0], [2000, 20]], "thickness": 4.0},
            "material": {"E": 210000.0, "nu": 0.3},
            "edges": {
                "left": {"normal_stress": -1.0},
                "right": {"normal_stress": -1.0},
                "bottom": {"support": "free"},
                "top": {"support": "free"},
            },
            "mesh": {"nx": 40, "ny": 2},
        }
    )
    with solve(spec, MPI.COMM_SELF) as analysis:
        out = analysis.result
    k = out.buckling_coefficient_k
    assert k == pytest.approx((1 - 0.3**2) * (20 / 2000) ** 2, rel=0.01)
    assert f"k = {significant(k)}," in out.summary() and significant(k).startswith("9.1")
    from unibuckle_fenicsx.results.records import coefficient_text

    assert coefficient_text(9.104e-5) == "9.104e-05" and coefficient_text(0.43) == "0.4300"
    assert coefficient_text(4.0) == "4.0000"
    line = {"point": {"plate.length": 2000.0}, "critical_load_Pa": 6.9e5, "ratio_to_free": 1.0,
            "buckling_coefficient_k": 9.104e-5, "units": "mm-N-MPa"}  # fmt: skip
    assert "9.104e-05" in sweep_table([line])


def _thick_plate(thickness_mm, fy):
    """A 2000 x 1000 mm SSSS steel plate, uniform compression across left and right."""
    hinged = {"support": "simply_supported"}
    return problem_from_dict(
        {
            "units": "mm-N-MPa",
            "plate": {"corners": [[0, 0], [2000, 1000]], "thickness": thickness_mm},
            "material": {"E": 210000.0, "nu": 0.3},
            "edges": {
                "left": {**hinged, "normal_stress": -1.0},
                "right": {**hinged, "normal_stress": -1.0},
                "bottom": hinged,
                "top": hinged,
            },
            "mesh": {"nx": 8, "ny": 4},
            "design": {"yield_stress": fy, "partial_factor": 1.0},
        }
    )


@pytest.mark.parametrize(
    ("thickness", "fy", "said"),
    [
        # EN 1993-1-1 Table 3.1, EN 10025-2: S355 355 N/mm^2 up to 40 mm, 335 above.
        (50.0, 355.0, "at t = 50 mm (plate.thickness, 40 < t <= 80 mm) the table gives 335"),
        (60.0, 235.0, "gives 215 N/mm^2"),  # S235: 235, 215
        (45.0, 275.0, "gives 255 N/mm^2"),  # S275: 275, 255
        (70.0, 420.0, "gives 390 N/mm^2"),  # S420 N/NL, M/ML: 420, 390
        (100.0, 355.0, "the table, which stops at 80 mm"),
        (40.0, 355.0, None),  # Table 3.1's first column: t <= 40 mm
        (50.0, 335.0, None),  # the value for 40 < t <= 80 mm itself
    ],
)
def test_a_thick_plate_s_t_40_yield_stress_is_noted(thickness, fy, said):
    """f_y of a grade at t <= 40 mm on a thicker plate: the output notes Table 3.1's value.

    EN 1993-1-1 Table 3.1 gives each hot rolled grade a lower nominal f_y for 40 mm < t
    <= 80 mm (S355: 335 N/mm^2) and stops at 80 mm. The output takes ``yield_stress`` as
    given; a 50 mm plate given 355 N/mm^2 got its slenderness, rho and rho f_y/gamma_M
    from 355 without a word (at sigma_cr = 400 MPa: rho f_y = 288.8 against 278.1
    N/mm^2 with 335, 4 % on the unsafe side).
    """
    from unibuckle_fenicsx.cli.problem import input_notes

    spec = _thick_plate(thickness, fy)
    d = design_output(spec, spec.design, 400e6)
    notes = [n for n in d.notes if "Table 3.1" in n]
    warned = input_notes(spec).get("design yield stress")
    if said is None:
        assert not notes and warned is None, notes
        return
    assert len(notes) == 1 and said in notes[0], notes
    assert notes[0].startswith(f"design.yield_stress: f_y = {fy:g} N/mm^2 is EN 1993-1-1")
    assert warned == notes[0]
    # The numbers of the docstring, eq. (4.2) at psi = 1 by hand.
    lam355, lam335 = math.sqrt(355 / 400), math.sqrt(335 / 400)
    assert 355 * min(1, (lam355 - 0.22) / lam355**2) == pytest.approx(288.8, abs=0.05)
    assert 335 * min(1, (lam335 - 0.22) / lam335**2) == pytest.approx(278.1, abs=0.05)


def test_a_thick_box_s_t_40_yield_stress_is_noted():
    """A box of 50 mm walls given S355's 355 N/mm^2: its design notes say 335 (Table 3.1)."""
    box = _box(thickness=0.05, width=1.0, depth=1.0, length=3.0, mesh_size=0.25)
    out = section_design(box, DesignSpec(yield_stress=FY), 1.0)
    notes = [n for n in out.notes if "Table 3.1" in n]
    assert len(notes) == 1 and "at t = 50 mm (section.thickness" in notes[0], out.notes
    assert "the table gives 335 N/mm^2" in notes[0]
    thin = section_design(_box(), DesignSpec(yield_stress=FY), 1.0)
    assert not [n for n in thin.notes if "Table 3.1" in n]
