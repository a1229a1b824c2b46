"""A section's design output: EN 1993-1-5 per face of a box, EN 1994-1-1's wall limits.

Every expected value is worked out here from the codes' formulas, not read from the
package: the relative slenderness sqrt(f_y/sigma_cr) (EN 1993-1-5, 4.4(2)); the reduction
factor of an internal compression element rho = (lambda_p - 0.055 (3 + psi))/lambda_p^2
(eq. (4.2)); Table 4.1's k_sigma = 7.81 - 6.29 psi + 9.78 psi^2 for 0 > psi > -1; the
limits of EN 1994-1-1 Table 6.3, 52 sqrt(235/f_y) for a filled rectangular section and
90 (235/f_y) for a filled circular one (f_y in N/mm^2). The stresses at the critical state
follow from the load's definition (axial stress plus the bending part times z/(d/2)).
"""

from __future__ import annotations

import json
import math

from mpi4py import MPI

import pytest

from support.fibres import web_psi
from unibuckle_fenicsx import SectionParameters, solve_section
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.section_design import at_lower_bound, design_line, section_design
from unibuckle_fenicsx.spec import DesignSpec, load_problem

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial sections")


def _section(shape: str = "box", **changes: object) -> SectionParameters:
    base = {
        "thickness": 0.002, "width": 0.2, "depth": 0.1, "diameter": None, "length": 0.6,
        "E": 2.1e11, "nu": 0.3, "mesh_size": 0.02,
        "axial_stress": -1.0, "bending_stress": 0.0, "core": False,
    }  # fmt: skip
    return SectionParameters(shape, **{**base, **changes})


def test_uniform_compression_gives_every_face_the_internal_element_s_rho():
    load, fy = 2.0e8, 3.55e8
    out = section_design(_section(), DesignSpec(yield_stress=fy, partial_factor=1.1), load)
    slenderness = math.sqrt(fy / load)  # 1.3323
    rho = (slenderness - 0.055 * 4.0) / slenderness**2
    assert out.sigma_cr_Pa == pytest.approx(load)
    assert out.relative_slenderness == pytest.approx(slenderness)
    assert [f.face for f in out.faces] == ["right", "top", "left", "bottom"]
    for face in out.faces:
        # Both flanges reduced alike (EN 1993-1-5 4.4(3)): no shift, the webs keep psi = 1.
        assert face.psi == 1.0 and face.k_sigma_table == 4.0 and face.psi_gross is None
        assert face.reduction_factor == pytest.approx(rho)
        assert face.reduced_design_stress_Pa == pytest.approx(rho * fy / 1.1)
    assert out.width_to_thickness is None  # no core: no EN 1994-1-1 limit


def test_under_one_compression_the_widest_face_governs():
    # Every face of the 200 x 100 box carries the critical stress: one slenderness, one
    # rho (eq. (4.2)), one multiple of the load to rho f_y. The wide faces (top, bottom:
    # 200 mm) buckle and the narrow ones (right, left: 100 mm, k 4 times smaller by
    # sigma t w^2/(pi^2 D)) restrain them: the tie goes to the first wide face.
    for width, depth, widest in ((0.2, 0.1, "top"), (0.1, 0.2, "right")):
        section = _section(width=width, depth=depth)
        out = section_design(section, DesignSpec(yield_stress=3.55e8), 2.0e8)
        assert len({f.reduction_factor for f in out.faces}) == 1
        assert out.governing_face == widest


def _web_psi_by_hand(b, d, axial, bending, rho_f):
    """A web's psi by EN 1993-1-5 4.4(3), by hand (mid-line dimensions, t = 1).

    The compression flange (the one the bending compresses: z_c = +d/2 for bending < 0,
    -d/2 else) reduced to its effective area rho_f b t, centred on its mid-line; the
    other flange and the webs gross; the neutral axis from the first moment of area, z'
    = (rho_f b z_c - b z_c + 2 d 0)/(rho_f b + b + 2 d). The stress: the axial part plus
    the bending part, linear through z' and equal at z_c to the gross -|bending|,
    sigma(z) = axial - |bending| (z - z')/(z_c - z') (tension > 0); psi the ratio of the
    web's end compressions, the larger as sigma_1.
    """
    z_c = d / 2 if bending < 0 else -d / 2
    z_na = (rho_f * b * z_c - b * z_c) / (rho_f * b + b + 2 * d)
    ends = [-(axial - abs(bending) * (z - z_na) / (z_c - z_na)) for z in (d / 2, -d / 2)]
    return min(ends) / max(ends)


def _rho_internal(slenderness, psi):
    """Eq. (4.2) of EN 1993-1-5 4.4(2), internal element."""
    if slenderness <= 0.5 + math.sqrt(0.085 - 0.055 * psi):
        return 1.0
    return min(1.0, (slenderness - 0.055 * (3.0 + psi)) / slenderness**2)


def test_bending_puts_a_face_in_tension_and_the_webs_in_a_gradient():
    # axial -1, bending +2 at z = +d/2: top +1 (tension), bottom -3, webs from +1 to -3
    # in the gross section (psi = -1/3). EN 1993-1-5 4.4(3) takes the webs' psi from the
    # section with the compression flange (bottom: 120 MPa at this load, lambda_p =
    # sqrt(355/120) = 1.7200, rho = 0.50704) effective and the webs gross: by hand
    # (_web_psi_by_hand, 200 x 100 mm mid-line) the neutral axis z' = (0.50704 x 200 x
    # (-50) - 200 x (-50))/(0.50704 x 200 + 200 + 200) = 9.8316 mm above the mid-depth;
    # the axial -1 plus the bending part, -2 at the bottom (z_c = -50 mm) and 2 (50 -
    # 9.83)/(50 + 9.83) = 1.3427 at the top: the top end at +0.3427, the bottom at -3
    # per unit load, psi = -0.11424. The output gave -1/3 (the gross ratio): rho 0.5318
    # instead of 0.5278, b_c 75 mm instead of 89.75 mm.
    load, fy = 4.0e7, 3.55e8
    out = section_design(_section(bending_stress=2.0), DesignSpec(yield_stress=fy), load)
    faces = {f.face: f for f in out.faces}
    assert out.sigma_cr_Pa == pytest.approx(3.0 * load)
    assert faces["top"].sigma_cr_Pa == pytest.approx(-load)
    assert faces["top"].reduction_factor is None and faces["top"].psi is None
    web = faces["right"]
    slenderness = math.sqrt(fy / (3.0 * load))
    rho_flange = (slenderness - 0.22) / slenderness**2
    assert rho_flange == pytest.approx(0.50704, abs=1e-5)
    psi = _web_psi_by_hand(200.0, 100.0, -1.0, 2.0, rho_flange)
    assert psi == pytest.approx(-0.11424, abs=1e-5)
    assert web.psi == pytest.approx(psi, rel=1e-12)
    assert web.psi_gross == pytest.approx(-1.0 / 3.0, rel=1e-14)
    rho = (slenderness - 0.055 * (3.0 + psi)) / slenderness**2
    assert rho == pytest.approx(0.5278, abs=1e-4)
    assert web.reduction_factor == pytest.approx(rho, rel=1e-12)
    assert web.k_sigma_table == pytest.approx(7.81 - 6.29 * psi + 9.78 * psi**2, rel=1e-12)
    assert web.compressed_width_m == pytest.approx(0.1 / (1.0 - psi), rel=1e-12)
    bottom = faces["bottom"]
    assert bottom.psi == 1.0
    assert bottom.reduction_factor == pytest.approx((slenderness - 0.22) / slenderness**2)
    assert out.governing_face == "bottom"  # rho falls with psi at one slenderness


def test_a_web_s_psi_comes_from_the_effective_compression_flange():
    """EN 1993-1-5 4.4(3): a web's psi from the effective compression flange, gross webs.

    The square box 200 x 200 x 2 mm (mid-line) in pure bending, the top in compression,
    at sigma_cr = 300 MPa (f_y = 355 MPa). The top flange: lambda_p = sqrt(355/300) =
    1.08781, rho_f = (lambda_p - 0.22)/lambda_p^2 = 0.73336 (eq. (4.2), psi = 1). By hand:
    its effective area rho_f b t centred on its mid-line z = +d/2, the bottom flange and
    the webs gross; the neutral axis from the first moment of area, z' = (rho_f b t d/2 -
    b t d/2)/(rho_f b t + b t + 2 d t) = -7.14205 mm; over the web's mid-line depth the
    stress is proportional to z - z', psi = sigma_bottom/sigma_top = (-d/2 - z')/(d/2 -
    z') = -0.86668, where the gross section gives -1. The web's rho (its slenderness the
    same) falls from 0.82632 to 0.82012, its compressed part b_c = d/(1 - psi) grows from
    100 to 107.142 mm (Table 4.1): the gross psi was on the unsafe side.
    """
    b = d = 0.2
    t, fy, sigma = 0.002, 3.55e8, 3.0e8
    section = _section(width=b, depth=d, thickness=t, axial_stress=0.0, bending_stress=-1.0)
    out = section_design(section, DesignSpec(yield_stress=fy), sigma)
    slenderness = math.sqrt(fy / sigma)
    rho_f = (slenderness - 0.22) / slenderness**2
    z_na = (rho_f * b * t * d / 2 - b * t * d / 2) / (rho_f * b * t + b * t + 2 * d * t)
    psi = (-d / 2 - z_na) / (d / 2 - z_na)
    rho = (slenderness - 0.055 * (3.0 + psi)) / slenderness**2
    assert (rho_f, z_na * 1e3, psi) == pytest.approx((0.73336, -7.14205, -0.86668), abs=1e-5)
    assert (rho, d / (1.0 - psi)) == pytest.approx((0.82012, 0.107142), abs=1e-5)
    assert (slenderness - 0.055 * 2.0) / slenderness**2 == pytest.approx(0.82632, abs=1e-5)
    faces = {f.face: f for f in out.faces}
    assert faces["top"].psi == 1.0 and faces["top"].psi_gross is None  # a flange: gross
    assert faces["top"].reduction_factor == pytest.approx(rho_f, rel=1e-12)
    for name in ("right", "left"):
        web = faces[name]
        assert web.psi == pytest.approx(psi, rel=1e-12) and web.psi_gross == -1.0
        assert web.sigma_cr_Pa == pytest.approx(sigma, rel=1e-14)  # unchanged
        assert web.k_sigma_table == pytest.approx(7.81 - 6.29 * psi + 9.78 * psi**2, rel=1e-12)
        assert web.reduction_factor == pytest.approx(rho, rel=1e-12)
        assert web.compressed_width_m == pytest.approx(d / (1.0 - psi), rel=1e-12)
        assert web.effective_width_m == pytest.approx(rho * d / (1.0 - psi), rel=1e-12)
        assert web.effective_widths_placed.endswith(
            "(sigma_1 end: the corner with face top, other end: the corner with face bottom)"
        )
    note = next(n for n in out.notes if "4.4(3)" in n)
    assert "web(s) right, left: psi = -0.8667 (gross -1) by EN 1993-1-5 4.4(3)" in note
    assert "flange top effective (rho = 0.7334)" in note
    assert "7.142 mm below the gross one" in note
    assert "4.4(3)" in out.clauses[0]
    line = design_line(out, 1e6, "MPa", (1e-3, "mm"))
    assert (
        "web(s) right, left: psi = -0.8667 (gross -1), rho = 0.8201 (psi 4.4(3): the "
        "effective compression flange, the gross webs)"
    ) in line, line


@pytest.mark.parametrize(
    ("axial", "bending", "width", "depth", "load"),
    [
        (-1.0, 2.0, 0.2, 0.1, 4.0e7),  # the bottom flange compressed, the top in tension
        (-1.0, -0.5, 0.15, 0.1, 1.8327e8),  # both flanges compressed, the top more
        (0.2, -1.0, 0.1, 0.3, 3.0e8),  # axial tension: top compressed, a deep web
        (-0.3, -1.0, 0.3, 0.15, 2.0e8),  # axial compression, the top and the webs' top
        (-1.0, 0.1, 0.2, 0.2, 2.0e7),  # nearly uniform compression, the bottom more
    ],
)
def test_a_web_s_psi_under_axial_force_and_bending_against_thin_fibres(
    axial, bending, width, depth, load
):
    """4.4(3) under axial force and bending: the web's psi against a strip model.

    The compression flange (the one the bending compresses) reduced to rho b (eq. (4.2)
    at its stress, psi = 1, by hand), the other flange and the webs gross: the neutral
    axis found here by thin fibres (support.fibres: the plane stress with no axial
    resultant, no centroid formula) and by the first moment of area
    (_web_psi_by_hand); the web's stress the axial part plus the bending part through
    that axis, the gross bending stress at the compression flange. psi grows from the
    gross one: the web's compressed part grows.
    """
    fy = 3.55e8
    section = _section(width=width, depth=depth, axial_stress=axial, bending_stress=bending)
    out = section_design(section, DesignSpec(yield_stress=fy), load)
    top, bottom = -(axial + bending), -(axial - bending)  # compression per unit load
    sigma_c = max(top, bottom)  # the compression flange's, the bending's side
    rho_f = _rho_internal(math.sqrt(fy / (sigma_c * load)), 1.0)
    assert rho_f < 1.0
    fibres = web_psi(width, depth, 0.002, axial, bending, rho_f)
    by_hand = _web_psi_by_hand(width, depth, axial, bending, rho_f)
    assert fibres == pytest.approx(by_hand, rel=1e-9)
    web = {f.face: f for f in out.faces}["right"]
    assert web.psi == pytest.approx(by_hand, rel=1e-12)
    gross = min(top, bottom) / sigma_c
    assert web.psi_gross == pytest.approx(gross, rel=1e-14)
    assert web.psi > gross
    assert web.reduction_factor == pytest.approx(
        _rho_internal(math.sqrt(fy / (sigma_c * load)), by_hand), rel=1e-12
    )


def test_a_web_keeps_the_gross_psi_with_a_fully_effective_compression_flange():
    """4.4(3) with rho_f = 1: the effective section is the gross one, psi unchanged.

    The box 200 x 100 x 2 mm in pure bending at sigma_cr = 900 MPa (f_y = 355 MPa): the
    compression flange's lambda_p = sqrt(355/900) = 0.628 <= 0.5 + sqrt(0.085 - 0.055) =
    0.673, rho_f = 1 (eq. (4.2)); the webs keep psi = -1 exactly, no 4.4(3) note or words
    in the summary line. Uniform compression (every face reduced alike, the neutral axis
    unshifted) keeps psi = 1: test_uniform_compression_gives_every_face_the_internal_element_s_rho.
    """
    section = _section(axial_stress=0.0, bending_stress=-1.0)
    out = section_design(section, DesignSpec(yield_stress=3.55e8), 9.0e8)
    assert math.sqrt(355.0 / 900.0) <= 0.5 + math.sqrt(0.085 - 0.055)
    faces = {f.face: f for f in out.faces}
    assert faces["top"].reduction_factor == 1.0
    for name in ("right", "left"):
        assert faces[name].psi == -1.0 and faces[name].psi_gross is None
        assert faces[name].compressed_width_m == pytest.approx(0.05, rel=1e-14)
    assert not any("4.4(3)" in note for note in out.notes)
    assert "4.4(3)" not in design_line(out)


def test_the_governing_face_is_the_one_reaching_its_reduced_stress_first():
    # axial -1, bending -0.5 at z = +d/2: top 1.5, bottom 0.5, webs 1.5 to 0.5 in the gross
    # section (psi = 1/3), at the load 1.8327e8 Pa of a filled box 150 x 100 x 2 mm (its
    # run, S355). By eq. (4.2): top lambda_p = sqrt(355/274.9) = 1.136, rho = 0.7096;
    # bottom (91.6 MPa) lambda_p = 1.968, rho = 0.4513, the smallest rho. The webs' psi by
    # EN 1993-1-5 4.4(3) (_web_psi_by_hand): the bending compresses the top flange, reduced
    # by its rho, z' = -4.771 mm; the axial part 1.5 - 0.5 = 1 plus the bending part 0.5 at
    # the top and -0.5 (50 - 4.771)/(50 + 4.771) = -0.4129 at the bottom: psi = 0.5871/1.5
    # = 0.3914 (the gross 1/3 before), rho 0.7355 (0.7380). The load factor that brings a
    # face to rho f_y: top 0.7096 x 355/274.9 = 0.916, webs 0.7355 x 355/274.9 = 0.950,
    # bottom 0.4513 x 355/91.6 = 1.748: the top face governs, the bottom one least.
    load, fy = 1.8327e8, 3.55e8
    section = _section(width=0.15, depth=0.1, bending_stress=-0.5)
    out = section_design(section, DesignSpec(yield_stress=fy), load)
    rho_top = _rho_internal(math.sqrt(fy / (1.5 * load)), 1.0)
    web_psi = _web_psi_by_hand(150.0, 100.0, -1.0, -0.5, rho_top)
    assert web_psi == pytest.approx(0.3914, abs=1e-4)
    first = {}
    for name, sigma, psi in (("top", 1.5, 1.0), ("right", 1.5, web_psi), ("bottom", 0.5, 1.0)):
        slenderness = math.sqrt(fy / (sigma * load))
        first[name] = _rho_internal(slenderness, psi) * fy / (sigma * load)
    assert first["top"] == pytest.approx(0.916, abs=1e-3)
    assert first["right"] == pytest.approx(0.950, abs=1e-3)
    assert first["bottom"] == pytest.approx(1.748, abs=1e-3)
    faces = {f.face: f for f in out.faces}
    assert faces["bottom"].reduction_factor == pytest.approx(0.4513, abs=1e-4)
    assert faces["right"].psi == pytest.approx(web_psi, rel=1e-12)
    assert faces["right"].psi_gross == pytest.approx(1.0 / 3.0, rel=1e-14)
    assert out.governing_face == "top"


def test_a_web_at_psi_minus_three_keeps_table_4_1_s_row():
    # Axial +0.5 (tension) and bending 1.0 at z = +d/2: the bottom face carries 0.5 per
    # unit load, the top one -1.5, the webs psi = -1.5/0.5 = -3, Table 4.1's last row:
    # k_sigma = 5.98 (1 - psi)^2 = 95.68. At this load the quotient rounds to
    # -3.0000000000000004, outside the table, and the webs had no rho. The compression
    # flange (bottom, 967 MPa) is fully effective: lambda_p = sqrt(355/967.2) = 0.6059
    # <= 0.5 + sqrt(0.085 - 0.055) = 0.673, so EN 1993-1-5 4.4(3) leaves the webs the
    # gross psi; their rho = 1 (lambda_p <= 0.5 + sqrt(0.085 + 0.165) = 1 at psi = -3).
    load, fy = 1934306041.5679479, 3.55e8
    assert (load * -1.5) / (load * 0.5) < -3.0
    section = _section(axial_stress=0.5, bending_stress=1.0)
    out = section_design(section, DesignSpec(yield_stress=fy), load)
    faces = {f.face: f for f in out.faces}
    slenderness = math.sqrt(fy / (0.5 * load))
    assert slenderness <= 0.5 + math.sqrt(0.085 - 0.055)
    assert faces["bottom"].reduction_factor == 1.0
    web = faces["right"]
    assert web.psi == -3.0 and web.psi_gross is None
    assert web.k_sigma_table == pytest.approx(95.68)
    assert web.reduction_factor == 1.0


def test_a_stocky_face_is_fully_effective():
    # lambda_p = 0.5 below the limit 0.5 + sqrt(0.085 - 0.055) = 0.673 of psi = 1.
    out = section_design(_section(), DesignSpec(yield_stress=2.35e8), 4 * 2.35e8)
    assert out.faces[0].relative_slenderness == pytest.approx(0.5)
    assert out.faces[0].reduction_factor == 1.0
    # The summary line keeps four significant digits: f_y itself, 235 MPa, reads
    # "2.350e+08 Pa" (".4g" wrote "2.35e+08", and 2e8 as "2e+08"), rho = 1 "1.000".
    line = design_line(out)
    assert "sigma_cr = 9.400e+08 Pa, slenderness 0.5000" in line, line
    assert "rho = 1.000, rho f_y/gamma_M0 = 2.350e+08 Pa" in line, line


@pytest.mark.parametrize(
    ("shape", "changes", "ratio", "limit"),
    [
        # h = 0.2 + 0.002 (overall) over t = 0.002; 52 sqrt(235/355).
        ("box", {}, 101.0, 52.0 * math.sqrt(235.0 / 355.0)),
        # d = 0.3 + 0.002 over t; 90 * 235/355.
        ("tube", {"width": None, "depth": None, "diameter": 0.3}, 151.0, 90.0 * 235.0 / 355.0),
    ],
)
def test_filled_sections_are_checked_against_en_1994_table_6_3(shape, changes, ratio, limit):
    section = _section(shape, core=True, **changes)
    out = section_design(section, DesignSpec(yield_stress=3.55e8), 3.0e8)
    assert out.width_to_thickness == pytest.approx(ratio)
    assert out.width_to_thickness_limit == pytest.approx(limit)
    assert out.local_buckling_negligible is False
    assert any("unilateral" in note for note in out.notes)
    stocky = section_design(
        _section(shape, core=True, **{**changes, "thickness": 0.01}), DesignSpec(2.35e8), 3e8
    )
    assert stocky.local_buckling_negligible is True  # 21 < 52, 31 < 90


def test_a_tube_gets_its_slenderness_only():
    section = _section("tube", width=None, depth=None, diameter=0.2, bending_stress=-0.5)
    out = section_design(section, DesignSpec(yield_stress=2.35e8), 1.0e9)
    assert out.sigma_cr_Pa == pytest.approx(1.5e9)  # axial 1 plus the bending part 0.5
    assert out.relative_slenderness == pytest.approx(math.sqrt(2.35e8 / 1.5e9))
    assert out.faces == [] and out.governing_face is None
    assert "EN 1993-1-6" in out.clauses[0]
    # No rho of EN 1993-1-5 4.4(2) is applied to a tube, filled or not: no note says it is.
    filled = section_design(_section("tube", width=None, depth=None, diameter=0.2, core=True),
                            DesignSpec(yield_stress=2.35e8), 1.0e9)  # fmt: skip
    assert not any("4.4(2)" in note for note in out.notes + filled.notes)


def test_a_section_file_with_design_writes_it_to_its_json(tmp_path):
    # 40 mm cells: 4 across the 0.1 m faces, the fewest a core is solved on.
    path = tmp_path / "box.toml"
    path.write_text(
        "[section]\nshape = 'box'\nwidth = 0.2\ndepth = 0.1\nthickness = 0.002\n"
        "length = 0.2\nends = 'simply_supported'\n[material]\nE = 2.1e11\nnu = 0.3\n"
        "[obstacle]\ncore = true\n[mesh]\nsize = 0.04\nlevels = 0\n"
        "[design]\nyield_stress = 3.55e8\n"
    )
    spec = load_problem(path)
    with solve_section(spec, MPI.COMM_SELF) as analysis:
        result = analysis.result
        data = json.loads(json.dumps(result.as_dict()))
        assert "design: largest compression" in result.summary()
    design = data["design"]
    load = data["critical_load_Pa"]
    assert design["sigma_cr_Pa"] == pytest.approx(load)
    assert design["relative_slenderness"] == pytest.approx(math.sqrt(3.55e8 / load))
    assert design["width_to_thickness"] == pytest.approx(0.202 / 0.002)
    assert data["input"]["design"]["yield_stress"] == 3.55e8  # the file re-runs it
    # The same file in mm-N-MPa: the summary speaks MPa, the JSON stays SI.
    path.write_text(
        "units = 'mm-N-MPa'\n[section]\nshape = 'box'\nwidth = 200\ndepth = 100\n"
        "thickness = 2\nlength = 200\nends = 'simply_supported'\n[material]\nE = 2.1e5\n"
        "nu = 0.3\n[obstacle]\ncore = true\n[mesh]\nsize = 40\nlevels = 0\n"
        "[design]\nyield_stress = 355\n"
    )
    with solve_section(load_problem(path), MPI.COMM_SELF) as analysis:
        summary = analysis.result.summary()
        assert analysis.result.critical_load_Pa == pytest.approx(load, rel=1e-9)
    assert f"sigma_cr = {load / 1e6:.6e} MPa" in summary
    assert f"largest compression sigma_cr = {load / 1e6:#.4g}".rstrip(".") + " MPa" in summary
    assert " Pa" not in summary.replace("MPa", "")
    without = SectionParameters(
        "box", width=0.2, depth=0.1, thickness=0.002, length=0.2, E=2.1e11, nu=0.3,
        mesh_size=0.1, ends="simply_supported",
    )  # fmt: skip
    with solve_section(without, MPI.COMM_SELF) as analysis:
        assert analysis.result.design is None


#: A 200 x 100 x 2 mm box, 200 mm long, as a mm-N-MPa file with [design].
BOX_MM = (
    "units = 'mm-N-MPa'\n[section]\nshape = 'box'\nwidth = 200\ndepth = 100\n"
    "thickness = 2\nlength = 200\n[material]\nE = {E}\nnu = {nu}\n"
    "[mesh]\nsize = 100\n[design]\nyield_stress = {fy}\n"
)


def test_the_design_of_a_section_not_of_steel_is_refused(tmp_path):
    # EN 1993-1-5 4.4(2)'s rho rests on steel, E = 210 GPa (EN 1993-1-1 3.2.6); an
    # aluminium box (70 GPa) belongs to EN 1999-1-1 6.1.4: refused before any mesh.
    path = tmp_path / "box.toml"
    path.write_text(BOX_MM.format(E=70000, nu=0.33, fy=250))
    with pytest.raises(InputError, match=r"material\.E = 70000 MPa is not a steel's"):
        load_problem(path)
    aluminium = _section(E=7.0e10, nu=0.33)
    with pytest.raises(InputError, match=r"material\.E = 7e\+10 Pa is not a steel's"):
        solve_section(aluminium, MPI.COMM_SELF, design=DesignSpec(yield_stress=2.5e8))
    # Without [design] the aluminium box is a fine problem (only the design is refused).
    path.write_text(path.read_text().replace("[design]\nyield_stress = 250\n", ""))
    assert load_problem(path).material.E == pytest.approx(7.0e10)


def test_a_section_s_yield_stress_in_the_wrong_unit_is_refused(tmp_path):
    # 355 in an SI file is 355 Pa: slenderness sqrt(f_y/sigma_cr) near 0 and rho = 1
    # whatever the walls. Steels have f_y of 235 to 700 MPa (EN 1993-1-1 Table 3.1, EN
    # 1993-1-12), stainless from 200 MPa (EN 1993-1-4): refused, in the file's unit.
    path = tmp_path / "box.toml"
    path.write_text(BOX_MM.format(E=210000, nu=0.3, fy=3.55e8))
    with pytest.raises(InputError, match=r"design\.yield_stress = 3\.55e\+08 MPa is not"):
        load_problem(path)
    with pytest.raises(InputError, match=r"design\.yield_stress = 355 Pa is not a steel's"):
        solve_section(_section(), MPI.COMM_SELF, design=DesignSpec(yield_stress=355.0))


@pytest.mark.parametrize("core", [False, True])
def test_the_design_output_says_the_member_s_buckling_is_not_in_it(core):
    """A long member's design output gave the walls' values only, silent on the column.

    The box 200 x 200 x 2 mm, 6 m between simply supported ends: its walls buckle at
    4 pi^2 D/(t b^2) = 75.9 MPa, a fifth of its Euler stress pi^2 E (b^2/6)/L^2 =
    383.8 MPa (I/A = b^2/6 of the thin-walled square), so no column warning; but as a
    column its relative slenderness sqrt(f_y/sigma_E) = sqrt(355/383.8) = 0.962 (EN
    1993-1-1, 6.3.1.2) is far above the 0.2 below which buckling may be ignored
    (6.3.1.2(4)). The output now says the member's buckling is not part of it, with
    that slenderness; a filled member's needs the infill's stiffness (EN 1994-1-1,
    6.7.3.3).
    """
    section = _section(width=0.2, depth=0.2, length=6.0, ends="simply_supported", core=core)
    euler = math.pi**2 * 2.1e11 * (0.2**2 / 6.0) / 6.0**2
    assert euler == pytest.approx(3.838e8, rel=1e-3)
    out = section_design(section, DesignSpec(yield_stress=3.55e8), 7.59e7)
    notes = [n for n in out.notes if "flexural buckling" in n]
    assert len(notes) == 1
    assert f"sqrt(f_y/sigma_E) = {math.sqrt(3.55e8 / euler):.3g}" in notes[0]
    assert "0.962" in notes[0] and "EN 1993-1-1, 6.3.1" in notes[0]
    # The gross area, as eq. (6.50) of 6.3.1.2(1) for Class 1-3; a Class 4 section's
    # eq. (6.51) takes A_eff (lower slenderness): the note says which one it gives.
    assert "the gross area" in notes[0] and "sqrt(A_eff f_y/N_cr)" in notes[0]
    assert ("EN 1994-1-1, 6.7.3.3" in notes[0]) == core
    tube = _section("tube", width=None, depth=None, diameter=0.2, length=6.0, core=core)
    tube_euler = math.pi**2 * 2.1e11 * (0.1**2 / 2.0) / 3.0**2  # clamped: L_e = L/2
    note = next(n for n in section_design(tube, DesignSpec(yield_stress=3.55e8), 1e9).notes
                if "flexural buckling" in n)  # fmt: skip
    assert f"= {math.sqrt(3.55e8 / tube_euler):.3g} " in note


def _column_chi(slenderness: float) -> float:
    # EN 1993-1-1 eq. (6.49) with buckling curve a (alpha = 0.21), as EN 1993-1-5
    # 4.5.3(5) asks for an unstiffened plate's column-type buckling.
    phi = 0.5 * (1.0 + 0.21 * (slenderness - 0.2) + slenderness**2)
    return 1.0 / (phi + math.sqrt(phi**2 - slenderness**2))


def test_a_stub_shorter_than_its_faces_gets_rho_c():
    """A stub's faces gave the plate-type rho of eq. (4.2), 13 % on the unsafe side.

    The square box 100 x 100 x 1 mm, L = 50 mm between simply supported ends: its faces,
    a/b = 0.5, buckle as plates with hinged edges at (b/a + a/b)^2 sigma_E = 6.25
    sigma_E = 118.63 MPa (Timoshenko and Gere; sigma_E = pi^2 E t^2/(12(1 - nu^2) b^2)
    = 18.98 MPa). The note of EN 1993-1-5 4.4(2) sends a plate with a/b < 1 to 4.5.4:
    sigma_cr,c = pi^2 E t^2/(12(1 - nu^2) a^2) = 4 sigma_E = 75.92 MPa (eq. (4.8)),
    lambda_c = sqrt(355/75.92) = 2.1624, chi_c = 0.19281 (curve a), xi = 6.25/4 - 1 =
    0.5625, lambda_p = sqrt(355/118.63) = 1.7299, rho = 0.50455, rho_c = (rho - chi_c)
    xi (2 - xi) + chi_c = 0.44488 (by hand, 4.5.4(1)); the output gave 0.50455.
    """
    E, nu, t, b, a, fy = 2.1e11, 0.3, 0.001, 0.1, 0.05, 3.55e8
    sigma_e = math.pi**2 * E * t**2 / (12.0 * (1.0 - nu**2) * b**2)
    load = (b / a + a / b) ** 2 * sigma_e
    section = _section(width=b, depth=b, thickness=t, length=a, ends="simply_supported")
    out = section_design(section, DesignSpec(yield_stress=fy, partial_factor=1.1), load)
    slenderness = math.sqrt(fy / load)
    rho = (slenderness - 0.055 * 4.0) / slenderness**2
    column = math.pi**2 * E * t**2 / (12.0 * (1.0 - nu**2) * a**2)
    chi = _column_chi(math.sqrt(fy / column))
    xi = load / column - 1.0
    rho_c = (rho - chi) * xi * (2.0 - xi) + chi
    assert (rho, chi, xi, rho_c) == pytest.approx((0.50455, 0.19281, 0.5625, 0.44488), abs=1e-5)
    for face in out.faces:
        assert face.plate_reduction_factor == pytest.approx(rho, rel=1e-12)
        assert face.column_critical_stress_Pa == pytest.approx(column, rel=1e-12)
        assert face.column_reduction_factor == pytest.approx(chi, rel=1e-12)
        assert face.xi == pytest.approx(xi, rel=1e-12)
        assert face.reduction_factor == pytest.approx(rho_c, rel=1e-12)
        assert face.reduced_design_stress_Pa == pytest.approx(rho_c * fy / 1.1, rel=1e-12)
    assert any("4.5.4(1)" in note for note in out.notes)
    assert any("4.5.4(1)" in clause for clause in out.clauses)
    # Lengthened to a = b the faces are not short (a/b < 1 is the note's condition): rho,
    # and no column fields.
    long = section_design(_section(width=b, depth=b, thickness=t, length=b), DesignSpec(fy), load)
    assert all(f.reduction_factor == pytest.approx(rho, rel=1e-12) for f in long.faces)
    assert all(f.column_critical_stress_Pa is None and f.xi is None for f in long.faces)
    assert not any("4.5.4" in clause for clause in long.clauses)
    # Between clamped ends the face as a column (4.5.3(1): the supports along its long
    # edges removed) is Euler's clamped column, effective length a/2: 4 sigma_cr,c.
    clamped = _section(width=b, depth=b, thickness=t, length=a, ends="clamped")
    face = section_design(clamped, DesignSpec(fy), 2.0 * load).faces[0]
    assert face.column_critical_stress_Pa == pytest.approx(4.0 * column, rel=1e-12)
    # The ratio minus 1 is -0.22: xi = 0 (bounded, 4.5.4(1)) and rho_c = chi_c.
    assert face.xi_unclipped == pytest.approx(2.0 * load / (4.0 * column) - 1.0, rel=1e-12)
    assert face.xi_unclipped < 0.0 and face.xi == 0.0
    assert face.reduction_factor == pytest.approx(face.column_reduction_factor, rel=1e-12)


def test_xi_is_reported_as_used_bounded_to_one():
    """EN 1993-1-5 4.5.4(1) bounds xi = sigma_cr/sigma_cr,c - 1 to 0 <= xi <= 1.

    The stub of :func:`test_a_stub_shorter_than_its_faces_gets_rho_c` (sigma_cr,c =
    75.92 MPa by eq. (4.8)) at sigma_cr = 3 sigma_cr,c: the ratio minus 1 is 2, xi = 1 and
    rho_c = rho (4.5.4(1) by hand). The output gave ``xi`` = 2 while rho_c used 1; now
    ``xi`` is 1 and ``xi_unclipped`` the ratio minus 1, 2.
    """
    E, nu, t, b, a, fy = 2.1e11, 0.3, 0.001, 0.1, 0.05, 3.55e8
    column = math.pi**2 * E * t**2 / (12.0 * (1.0 - nu**2) * a**2)
    section = _section(width=b, depth=b, thickness=t, length=a, ends="simply_supported")
    out = section_design(section, DesignSpec(yield_stress=fy), 3.0 * column)
    for face in out.faces:
        assert face.xi == 1.0
        assert face.xi_unclipped == pytest.approx(2.0, rel=1e-12)
        assert face.reduction_factor == face.plate_reduction_factor


def test_a_rectangular_stub_s_wide_faces_get_rho_c_and_govern():
    # The box 200 x 100 x 2 mm, L = 100 mm, simply supported: the top and bottom faces
    # (200 mm wide) have a/b = 0.5, the webs (100 mm) a/b = 1, not short. At 100 MPa of
    # uniform compression (f_y = 355 MPa): lambda_p = sqrt(3.55) = 1.8841, rho =
    # (1.8841 - 0.22)/3.55 = 0.46877 on every face; the wide faces' sigma_cr,c =
    # pi^2 E (t/a)^2/(12(1 - nu^2)) = 75.92 MPa, xi = 0.3172, chi_c = 0.19281 (curve a):
    # rho_c = 0.34010 (4.5.4(1), by hand). One compression on every face: the smallest
    # rho governs, the top face's.
    E, nu, t, a, fy, load = 2.1e11, 0.3, 0.002, 0.1, 3.55e8, 1.0e8
    section = _section(width=0.2, depth=0.1, thickness=t, length=a, ends="simply_supported")
    out = section_design(section, DesignSpec(yield_stress=fy), load)
    slenderness = math.sqrt(fy / load)
    rho = (slenderness - 0.22) / slenderness**2
    column = math.pi**2 * E * (t / a) ** 2 / (12.0 * (1.0 - nu**2))
    chi = _column_chi(math.sqrt(fy / column))
    xi = load / column - 1.0
    rho_c = (rho - chi) * xi * (2.0 - xi) + chi
    assert (rho, xi, rho_c) == pytest.approx((0.46877, 0.3172, 0.34010), abs=1e-4)
    faces = {f.face: f for f in out.faces}
    for name in ("top", "bottom"):
        assert faces[name].reduction_factor == pytest.approx(rho_c, rel=1e-12)
    for name in ("right", "left"):
        assert faces[name].reduction_factor == pytest.approx(rho, rel=1e-12)
    assert out.governing_face == "top" and out.tied_faces == ["top", "bottom"]
    line = design_line(out)
    assert f"rho_c = {rho_c:.4g} (column-type" in line
    assert "faces top, bottom tie" in line


def test_the_faces_of_a_square_box_in_uniform_compression_tie():
    """Four equal faces under one stress reach rho f_y/gamma_M0 together.

    The square box 200 x 200 x 2 mm at 100 MPa: every face has psi = 1 and the same
    lambda_p = sqrt(3.55), rho = 0.46877 (eq. (4.2)); the line named the right face as
    governing, as if it were the weakest. It says now that the four tie, and by which
    rule one is named.
    """
    square, design = _section(width=0.2, depth=0.2, core=True), DesignSpec(yield_stress=3.55e8)
    out = section_design(square, design, 1.0e8)
    assert out.tied_faces == ["right", "top", "left", "bottom"]
    assert out.governing_face == "right"
    line = design_line(out)
    assert "faces right, top, left, bottom tie" in line
    assert "the widest, then the first" in line
    # EN 1993-1-5 4.6(1): the effective cross-section's factor is gamma_M0.
    assert "rho f_y/gamma_M0" in line and "4.6(1)" in out.clauses[0]
    # The line of the verified lower bound (an unproven core's) says so too.
    at_lower_bound(out, square, design, 5.0e7)
    assert design_line(out).count("faces right, top, left, bottom tie") == 2
    # Under bending the bottom face governs alone (the test above): no tie.
    alone = section_design(_section(bending_stress=2.0), DesignSpec(yield_stress=3.55e8), 4e7)
    assert alone.tied_faces == [] and "face bottom: psi = 1" in design_line(alone)


def test_a_core_over_part_of_the_length_does_not_make_local_buckling_negligible():
    """EN 1994-1-1's limit is a filled section's: a hollow length is not one.

    The box 200 x 100 x 5 mm in S235: h/t = 205/5 = 41 <= 52 sqrt(235/235) = 52 (Table
    6.3), so a core over the whole length lets local buckling be neglected (6.7.1(9));
    with the core over half the length the other half is a hollow steel section, whose
    webs' c/t of about 41 - 3 = 38 would be checked by EN 1993-1-1 Table 5.2, not by the
    composite limit, and the output said "local buckling may be neglected" all the same.
    """
    fy = 2.35e8
    full = section_design(_section(thickness=0.005, core=True), DesignSpec(fy), 3e8)
    assert full.width_to_thickness == pytest.approx(41.0)
    assert full.width_to_thickness_limit == pytest.approx(52.0)
    assert full.local_buckling_negligible is True
    half = _section(thickness=0.005, core=True, core_span=(0.0, 0.3))
    out = section_design(half, DesignSpec(fy), 3e8)
    assert out.width_to_thickness == pytest.approx(41.0)
    assert out.local_buckling_negligible is False
    assert any("x/L = 0 to 0.5 of the length only" in note for note in out.notes)
    assert "may be neglected" not in design_line(out)
    assert "the core does not fill the length" in design_line(out)
    # A span given as the whole length is the whole length.
    whole = _section(thickness=0.005, core=True, core_span=(0.0, 0.6))
    assert section_design(whole, DesignSpec(fy), 3e8).local_buckling_negligible is True
