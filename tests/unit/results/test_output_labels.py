"""What an engineer reads: every number of the summaries and the help says what it is.

The design lines name the clause of the standard each value comes from and the ratio a
limit applies to; the section summary says what its "classical" stress is; the help of
every subcommand shows examples and fits the terminal; the 3-D figure of a section looks
at its largest buckle. Expected values come from the formulas quoted beside them.
"""

from __future__ import annotations

import math

from mpi4py import MPI

import msgspec
import numpy as np
import pytest

from unibuckle_fenicsx import SectionParameters, solve_section
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.cli.flags import build_parser
from unibuckle_fenicsx.model.shell.section import SectionFigureData
from unibuckle_fenicsx.section_design import at_lower_bound, design_line, section_design
from unibuckle_fenicsx.spec import DesignSpec, problem_from_dict

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial summaries")


def _section(shape: str = "box", **changes: object) -> SectionParameters:
    base = {
        "thickness": 0.002, "width": 0.2, "depth": 0.1, "diameter": None, "length": 0.6,
        "E": 2.1e11, "nu": 0.3, "mesh_size": 0.02,
        "axial_stress": -1.0, "bending_stress": 0.0, "core": True,
    }  # fmt: skip
    return SectionParameters(shape, **{**base, **changes})


@pytest.mark.parametrize("command", ["solve", "sweep", "nonlinear", "schema"])
def test_every_subcommand_s_help_shows_examples_within_100_columns(command, monkeypatch):
    # argparse wraps the options' help to $COLUMNS; descriptions and epilogs are printed as
    # written, and the nonlinear description was one line of 180 characters.
    monkeypatch.setenv("COLUMNS", "100")
    _, subcommands = build_parser()
    text = subcommands[command].format_help()
    assert "\nexamples:\n  unibuckle " + command in text, text
    wide = [line for line in text.splitlines() if len(line) > 100]
    assert not wide, wide


def test_solve_help_says_which_flags_a_section_takes(monkeypatch):
    # A section's file takes of [solver] only SOLVER_KEYS (eps_tol has no flag) and only
    # SECTION_METHODS; "auto" switches at INTERIOR_POINT_DOFS (choose_section_method). The
    # help named four plate-only flags of the twelve a section refuses.
    from unibuckle_fenicsx.algorithms.section_levels import INTERIOR_POINT_DOFS
    from unibuckle_fenicsx.spec.section import SECTION_METHODS, SOLVER_KEYS

    monkeypatch.setenv("COLUMNS", "100")
    _, subcommands = build_parser()
    flat = " ".join(subcommands["solve"].format_help().split())
    assert set(SOLVER_KEYS) == {"method", "tau", "eps_tol", "max_iterations"}
    assert [str(m) for m in SECTION_METHODS] == ["auto", "interior-point", "active-set"]
    assert (
        "a section takes --method (auto, interior-point or active-set: the last two with a "
        "rigid core only), --tau and --max-iterations (with a core only); the others," in flat
    ), flat
    assert INTERIOR_POINT_DOFS == 10**4
    assert (
        "section's auto: interior-point from about 10^4 DOFs, checked by the active set's seeds "
        "on its coarsest section" in flat
    ), flat


@pytest.mark.parametrize(
    ("shape", "changes", "text"),
    [
        # EN 1994-1-1 Table 6.3: box h/t <= 52 eps, h = 0.2 + 0.002 (overall), t = 0.002:
        # 101; eps = sqrt(235/355), 52 eps = 42.31.
        ("box", {}, "h/t = 101.0 against 52 eps = 42.31"),
        # tube d/t <= 90 eps^2: d = 0.3 + 0.002, 151; 90 x 235/355 = 59.58.
        ("tube", {"width": None, "depth": None, "diameter": 0.3}, "d/t = 151.0 against 90 eps^2"),
    ],
)
def test_the_section_design_line_names_the_ratio_its_limit_and_the_clause(shape, changes, text):
    out = section_design(_section(shape, **changes), DesignSpec(yield_stress=3.55e8), 3.0e8)
    line = design_line(out)
    assert f"EN 1994-1-1 6.7.1(9), Table 6.3: {text}" in line, line
    # The line printed "101 against 42.31": two numbers without the ratio they compare.
    assert f"{52 * math.sqrt(235 / 355):.2f}" in line or "59.58" in line, line
    if shape == "box":  # EN 1993-1-5 per face: where psi, the slenderness and rho come from
        assert "(psi Table 4.1, slenderness 4.4(2), rho 4.4(2) eq. (4.2)" in line, line
    else:  # a tube: the slenderness only, EN 1993-1-6's reduction is not applied
        assert "sqrt(f_y/sigma_cr) only: EN 1993-1-6" in line, line


def test_the_section_design_line_at_the_lower_bound_keeps_four_digits():
    # 9.44e7 Pa at the lower bound printed as "9.44e+07" (".4g" drops the zero) where the
    # line above it printed "2.121e+08": four significant digits on both lines.
    section, design = _section(), DesignSpec(yield_stress=3.55e8)
    record = at_lower_bound(section_design(section, design, 2.0e8), section, design, 9.44e7)
    low = design_line(record).splitlines()[-1]
    assert "at the verified lower bound" in low, low
    assert "sigma_cr = 9.440e+07 Pa" in low, low
    slenderness = math.sqrt(3.55e8 / 9.44e7)  # 1.939
    rho = (slenderness - 0.055 * 4.0) / slenderness**2  # eq. (4.2), psi = 1: 0.4572
    assert f"slenderness {slenderness:#.4g}" in low and f"rho = {rho:#.4g}" in low, low
    # and the safe stress limit (the line gave rho alone): rho f_y/gamma_M0, psi = 1.
    assert f"rho f_y/gamma_M0 = {rho * 3.55e8:#.4g} Pa" in low, low


def _plate(edges_top: dict[str, object]) -> str:
    hinged = {"support": "simply_supported"}
    spec = problem_from_dict(
        {
            "plate": {"corners": [[0, 0], [0.6, 0.2]], "thickness": 0.004},
            "material": {"E": 2.1e11, "nu": 0.3},
            "edges": {
                "left": {**hinged, "normal_stress": -1.0},
                "right": {**hinged, "normal_stress": -1.0},
                "bottom": hinged,
                "top": edges_top,
            },
            "mesh": {"nx": 6, "ny": 2},
            "design": {"yield_stress": 3.55e8},
        }
    )
    with solve(spec, MPI.COMM_WORLD) as analysis:
        summary = analysis.result.summary()
    return next(s for s in summary.splitlines() if "EN 1993-1-5: " in s)


@pytest.mark.parametrize(
    ("top", "clauses", "limit"),
    [
        # Internal element: psi from Table 4.1, rho by eq. (4.2) of 4.4(2). psi = 1:
        # 4.6(1), eq. (4.14), with A_eff = rho A, reads sigma_1 <= rho f_y/gamma_M0.
        (
            {"support": "simply_supported"},
            "psi Table 4.1, slenderness 4.4(2), rho 4.4(2) eq. (4.2)",
            "rho f_y/gamma_M0 4.6(1)",
        ),
        # Top edge free: an outstand, psi from Table 4.2, rho by eq. (4.3). Uniform
        # compression (psi = 1) reaches the free edge: the table's upper row, "larger
        # compression at the free edge" (psi = 1 lies in both rows; the package takes the
        # free edge's, as the JSON's ``table``). The line said "psi Table 4.2" without the
        # row, which decides psi's range and k_sigma: now it names it. Its rho = 0.32 < 1
        # puts b_eff = rho c at the supported edge, off the gross centroid: 4.6(1) needs
        # e_N, and the limit is section 10's with gamma_M1 (it said gamma_M0 4.6(1)).
        (
            {"support": "free"},
            "psi Table 4.2 (larger compression at the free edge), slenderness 4.4(2), rho "
            "4.4(2) eq. (4.3)",
            "rho f_y/gamma_M1 section 10 eq. (10.1)",
        ),
    ],
)
def test_the_plate_design_line_names_the_clause_of_each_value(top, clauses, limit):
    line = _plate(top)
    assert clauses in line, line
    assert limit in line, line


@pytest.mark.parametrize(
    ("shape", "changes", "what"),
    [
        # A box's classical stress is its widest face's as a long hinged plate, k = 4.
        ("box", {"width": 0.2, "depth": 0.1}, "(the widest face's k = 4)"),
        # A tube's is sigma_cl = E t / (R sqrt(3 (1 - nu^2))).
        ("tube", {"width": None, "depth": None, "diameter": 0.2}, "(sigma_cl = E t/(R sqrt("),
    ],
)
def test_the_section_summary_says_what_its_classical_stress_is(shape, changes, what):
    # "2.4236 x classical 7.592003e+07 Pa" did not say of what; the hollow box's value is
    # 4 pi^2 D/(t b^2) with b = 0.2 m, the tube's E t/(R sqrt(3(1 - nu^2))).
    section = _section(shape, length=0.2, mesh_size=0.1, core=False, **changes)
    with solve_section(section, MPI.COMM_SELF) as analysis:
        result = analysis.result
    first = result.summary().splitlines()[0]
    assert f"x classical {result.classical_stress_Pa:.6e} Pa {what}" in first, first
    t, E, nu = 0.002, 2.1e11, 0.3
    if shape == "box":
        D = E * t**3 / (12 * (1 - nu**2))
        expected = 4 * math.pi**2 * D / (t * 0.2**2)
    else:
        expected = E * t / (0.1 * math.sqrt(3 * (1 - nu**2)))
    assert result.classical_stress_Pa == pytest.approx(expected, rel=1e-12)


def _ring(shape: str, peak: tuple[float, float]) -> SectionFigureData:
    """A section's nodes at x = 0.1 round its wall, the outward buckle largest at ``peak``."""
    if shape == "tube":
        phi = np.linspace(0.0, 2.0 * np.pi, 72, endpoint=False)
        y, z = 0.1 * np.cos(phi), 0.1 * np.sin(phi)
    else:  # a 0.2 x 0.1 box's perimeter
        s = np.linspace(-1.0, 1.0, 9)
        y = np.concatenate([0.1 * s, np.full(9, 0.1), 0.1 * s, np.full(9, -0.1)])
        z = np.concatenate([np.full(9, 0.05), 0.05 * s, np.full(9, -0.05), 0.05 * s])
    points = np.column_stack([np.full(y.size, 0.1), y, z])
    outward = np.exp(-50.0 * ((y - peak[0]) ** 2 + (z - peak[1]) ** 2))
    none = np.zeros((0, 3))
    return SectionFigureData(
        points, np.zeros((0, 4), dtype=np.int64), np.zeros_like(points), outward, none, none,
        shape, (0.2, 0.2, 0.2 if shape == "tube" else 0.1),
    )  # fmt: skip


def _eye(turn: float) -> np.ndarray:
    from unibuckle_fenicsx.viz.section import EYE

    c, s = math.cos(turn), math.sin(turn)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]) @ EYE


def test_the_section_figure_looks_at_its_largest_buckle():
    # The filled tube of the demo buckles outward at its bottom (z < 0); the camera, fixed
    # above it at EYE = (-0.6, -1.4, 1.0), showed a tube with no visible buckle.
    from unibuckle_fenicsx.viz.section import EYE, view_turn

    bottom = _ring("tube", (0.0, -0.1))
    eye = _eye(view_turn(bottom))
    assert eye[2] < 0 and abs(eye[1]) < 1e-9, eye  # straight below, where the buckle is
    assert np.hypot(eye[1], eye[2]) == pytest.approx(np.hypot(EYE[1], EYE[2]))
    # A buckle the camera sees already keeps the view (the stored figures' views).
    assert view_turn(_ring("tube", (-0.1 * 0.8, 0.1 * 0.6))) == 0.0
    assert view_turn(_ring("box", (0.0, 0.05))) == 0.0  # the top face
    assert view_turn(_ring("box", (-0.1, 0.0))) == 0.0  # the face y = -b/2
    # A box turns by quarter turns: the bottom face and the face y = +b/2 come into view.
    for peak, face in (((0.0, -0.05), (0.0, -1.0)), ((0.1, 0.0), (1.0, 0.0))):
        eye = _eye(view_turn(_ring("box", peak)))
        assert np.dot(eye[1:], face) > 0, (peak, eye)


def _chart_legend(certificates: list[dict]) -> list[str]:
    """The legend's labels of a plate's sweep chart over nu, one point per certificate."""
    from unibuckle_fenicsx.sweep import parse_variation
    from unibuckle_fenicsx.viz import charts

    base = {
        "name": "small",
        "plate": {"corners": [[-0.1, -0.05], [0.1, 0.05]], "thickness": 0.006},
        "material": {"E": 1.0e9, "nu": 0.3},
        "mesh": {"nx": 6, "ny": 4},
        "obstacle": {"zone": [[-0.04, 0.04], [-0.05, 0.05]]},
    }
    values = [0.2 + 0.1 * k for k in range(len(certificates))]
    lines = [
        {"point": {"material.nu": nu}, "status": "ok", "buckling_coefficient_k": 4.4,
         "free_load_Pa": 1.0, "critical_load_Pa": 1.1, "certificate": cert}
        for nu, cert in zip(values, certificates, strict=True)
    ]  # fmt: skip
    variation = parse_variation("material.nu=" + ",".join(f"{nu:g}" for nu in values))
    return charts.sweep_figure(lines, [variation], base).axes[0].get_legend_handles_labels()[1]


def test_a_sweep_chart_s_legend_says_what_bilateral_means():
    # "bilateral" alone reads as a two-sided obstacle to an engineer: it is the plate
    # without its obstacle (the points' free loads), "unilateral" the plate against it.
    cert = {"kkt": True, "global_optimum_proven": True, "status": "proven"}
    labels = _chart_legend([cert, cert])
    assert "bilateral (no obstacle)" in labels, labels
    assert "unilateral (with the obstacle)" in labels, labels


def test_a_sweep_chart_s_legend_lists_only_the_markers_drawn():
    # Every point KKT only: the legend listed proven, bracketed and not certified too.
    from unibuckle_fenicsx.viz.charts import CERTIFICATE_MARKERS

    kkt = {"kkt": True, "global_optimum_proven": False, "status": "kkt-only"}
    failed = {"kkt": False, "global_optimum_proven": False, "status": "not-kkt"}
    markers = set(CERTIFICATE_MARKERS)
    labels = _chart_legend([kkt, kkt])
    assert markers & set(labels) == {"KKT only"}, labels
    labels = _chart_legend([kkt, failed])
    assert markers & set(labels) == {"KKT only", "not certified"}, labels


def test_a_sweep_prints_its_points_as_a_table_with_units():
    # The sweep printed "sweep: 3 points in t.jsonl: 3 ok" and nothing of its results: the
    # table has one row per point, the swept number and the load with their units.
    from unibuckle_fenicsx.cli.sweep import sweep_table

    cert = {"status": "kkt-only", "kkt": True}
    lines = [
        {"index": 0, "point": {"plate.thickness": 2.0}, "status": "ok", "units": "mm-N-MPa",
         "critical_load_Pa": 7.935676e8, "ratio_to_free": 1.28875, "buckling_coefficient_k":
         10.45268, "certificate": cert},
        {"index": 1, "point": {"plate.thickness": 3.0}, "status": "eigen-failure",
         "units": "mm-N-MPa", "error": "no pair"},
    ]  # fmt: skip
    rows = [row.split() for row in sweep_table(lines).splitlines()]
    assert rows[0][:5] == ["plate.thickness", "(mm)", "lambda_c", "(MPa)", "x"], rows[0]
    assert rows[1] == ["2", "7.935676e+02", "1.2888", "10.4527", "kkt-only", "ok"], rows[1]
    assert rows[2] == ["3", "-", "-", "-", "-", "eigen-failure"], rows[2]
    # A section's row gives the extreme fibre's stress, as its summary's sigma_cr.
    box = {"point": {"section.thickness": 0.001}, "status": "ok", "units": "SI",
           "critical_load_Pa": 1.0e8, "compression_Pa": 1.5e8, "classical_stress_Pa": 7.6e7,
           "ratio_to_free": 2.1, "buckling_coefficient_k": 9.69, "certificate": cert}  # fmt: skip
    rows = [row.split() for row in sweep_table([box]).splitlines()]
    assert rows[0][:4] == ["section.thickness", "(m)", "sigma_cr", "(Pa)"], rows[0]
    assert rows[1][1] == "1.500000e+08", rows[1]


def test_a_bracket_that_ran_says_what_itverified_text():
    # The quickstart's plate with --bracket: the split route verifies 1.735629e9 Pa below
    # lambda_c = 1.753161e9 (a gap of 1.0e-2, above the 1e-3 that 'bracketed' asks), and
    # the first line read "split bracket not bracketed (estimated cost 432.6 free solves)".
    from unibuckle_fenicsx.results.records import CertificateRecord, verified_text

    lower, upper = 1.735629e9, 1.753161e9
    cert = CertificateRecord(
        feasible=True, feasibility_margin=-1e-5, max_contact_force=-5e-3,
        max_contact_value=0.0, relative_residual=3e-13, tolerance=1e-8, kkt=True,
        smallest_of_reduced=True, lower_bound_Pa=lower, upper_bound_Pa=upper,
        relative_gap=(upper - lower) / upper, global_optimum_proven=False,
        proven_by="split-spn", status="kkt-only", negative_eigenvalues=4,
        refuting_load_Pa=None, copositivity=None, notes=[],
        split_route="not bracketed (estimated cost 432.6 free solves)",
    )  # fmt: skip
    text = verified_text(cert)
    assert "the split bracket verified a gap of 1.0e-02, above the 1e-03 of 'bracketed'" in text
    assert "not bracketed (estimated cost" not in text, text
    # Run, but nothing closer than the free load verified: it says so.
    none = msgspec.structs.replace(cert, proven_by="interlacing", relative_gap=0.22)
    assert "the split bracket verified no higher bound" in verified_text(none), verified_text(none)


@pytest.mark.parametrize(
    ("units", "stress", "shown"), [("SI", -1.0e8, "1e+08"), ("mm-N-MPa", -100.0, "100")]
)
def test_the_summary_gives_the_critical_stress_of_a_non_unit_edge_stress(units, stress, shown):
    """lambda_c is the critical stress only with a unit edge stress: otherwise a line says it.

    A 600 x 200 x 4 mm SSSS steel plate (6 x 2 cells) with an edge stress of -1e8 Pa (or
    -100 MPa) per unit lambda printed "lambda_c = 1.7e+01 Pa" and no stress at buckling.
    The expected stress is the same plate's lambda_c under a unit edge stress (the load is
    linear in the edge stress: lambda scales by its inverse).
    """
    length = 1.0 if units == "SI" else 1.0e3  # m or mm
    modulus = 2.1e11 if units == "SI" else 2.1e5  # Pa or MPa

    def summary(edge: float) -> tuple[str, float]:
        spec = problem_from_dict(
            {
                "units": units,
                "plate": {"corners": [[0, 0], [0.6 * length, 0.2 * length]],
                          "thickness": 0.004 * length},
                "material": {"E": modulus, "nu": 0.3},
                "edges": {"left": {"normal_stress": edge}, "right": {"normal_stress": edge}},
                "mesh": {"nx": 6, "ny": 2},
            }
        )  # fmt: skip
        with solve(spec, MPI.COMM_WORLD) as analysis:
            return analysis.result.summary(), analysis.result.critical_load_Pa

    unit_text, unit_load = summary(-1.0)
    assert "critical edge stress" not in unit_text, unit_text  # lambda_c is that stress
    text, _ = summary(stress)
    scale, unit = (1.0, "Pa") if units == "SI" else (1.0e6, "MPa")
    expected = f"critical edge stress: lambda_c x {shown} = {unit_load / scale:.6e} {unit}"
    assert expected in text, (expected, text)


def test_a_free_plate_s_summary_says_its_load_is_proven_the_smallest():
    """A free plate's summary said nothing of proof; its load is checked the smallest.

    A plate with no node held is the pencil's smallest eigenpair, verified by an LDL^T
    inertia count (analysis.solve); with a bilateral foundation the springs are in that
    pencil, so its "free" load is the plate's on the foundation, which the line says.
    """
    plate = {
        "plate": {"corners": [[0, 0], [0.6, 0.2]], "thickness": 0.004},
        "material": {"E": 2.1e11, "nu": 0.3},
        "edges": {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}},
        "mesh": {"nx": 6, "ny": 2},
    }
    springs = {"zone": "all", "side": "both", "foundation_stiffness": 2.0e8}
    texts = []
    for problem in (plate, {**plate, "obstacle": springs}):
        with solve(problem_from_dict(problem), MPI.COMM_WORLD) as analysis:
            assert analysis.result.method == "free"
            texts.append(analysis.result.summary().splitlines()[0])
    proof = "proven=yes (the smallest eigenvalue, by an LDL^T inertia count"
    assert proof + ")" in texts[0], texts[0]
    assert proof + "; free: with the bilateral foundation)" in texts[1], texts[1]


def _strip(signs: float) -> SectionFigureData:
    """One face of a box, 2 x 1 cells, its outward displacement ``signs`` x (0, ..., 1)."""
    x, y = np.meshgrid([0.0, 0.1, 0.2], [-0.05, 0.05])
    points = np.column_stack([x.ravel(), y.ravel(), np.full(6, 0.05)])
    quads = np.array([[0, 1, 4, 3], [1, 2, 5, 4]], dtype=np.int64)
    outward = signs * np.array([0.0, 0.5, 0.0, 1.0, 0.5, 0.0])
    if signs < 0:
        outward[0] = 1.0  # both signs
    return SectionFigureData(
        points, quads, np.zeros_like(points), outward, points[:1], points[1:2], "box",
        (0.2, 0.1, 0.1),
    )  # fmt: skip


@pytest.mark.parametrize(("signs", "cmap"), [(1.0, "Blues"), (-1.0, "coolwarm")])
def test_a_section_figure_s_legend_tells_the_core_from_the_nodes(
    tmp_path, monkeypatch, signs, cmap
):
    """The core's outline is a line in the legend, the contact nodes dots (both black).

    Before, each entry was a black square: the outline and the pressing nodes alike. A
    mode that moves only outward gets the sequential map from 0, as a plate's one-signed
    mode (``viz.plotting.colour_scale``; THEME's "Blues"), one of both signs the diverging
    "coolwarm" on [-1, 1].
    """
    pytest.importorskip("pyvista")
    import pyvista as pv

    from unibuckle_fenicsx.viz import section

    seen: dict[str, object] = {}
    add_legend, coloured = pv.Plotter.add_legend, section.coloured_surface

    def keep_legend(self, labels=None, **kwargs):
        seen["labels"] = labels
        return add_legend(self, labels=labels, **kwargs)

    def keep_map(*args, **kwargs):
        seen["cmap"], seen["clim"] = kwargs["cmap"], kwargs["clim"]
        return coloured(*args, **kwargs)

    monkeypatch.setattr(pv.Plotter, "add_legend", keep_legend)
    monkeypatch.setattr(section, "coloured_surface", keep_map)
    section.plot_section_mode_3d(_strip(signs), tmp_path / "strip.png", title="strip")
    faces = {label.split(":")[0]: (colour, face) for label, colour, face in seen["labels"]}
    assert faces == {
        "core (outline)": ("black", "line"),
        "presses on the core": ("black", "circle"),
        "on the core, no force": ("gold", "circle"),
    }
    assert seen["cmap"] == cmap
    assert seen["clim"] == ((0.0, 1.0) if signs > 0 else (-1.0, 1.0))


def test_a_plate_figure_s_legend_tells_the_zone_from_the_nodes(tmp_path, monkeypatch):
    """The zone's outline is a line, the contact nodes dots; a touching node is drawn grey.

    Before, the zone (dark grey) and the pressing nodes (black) were both squares, and the
    touching nodes were drawn white, which a one-signed mode's map shows at w = 0, where
    they lie, while the legend said grey. The paper's plate c1 on 10 x 10 cells (9 contact
    nodes: figures/stdout/demo_obstacle_c1.txt).
    """
    pytest.importorskip("pyvista")
    import pyvista as pv

    from unibuckle_fenicsx.spec import paper_case
    from unibuckle_fenicsx.viz import plotting

    seen: dict[str, list] = {"points": []}
    add_legend, add_points = pv.Plotter.add_legend, pv.Plotter.add_points

    def keep_legend(self, labels=None, **kwargs):
        seen["labels"] = labels
        return add_legend(self, labels=labels, **kwargs)

    def keep_points(self, points, **kwargs):
        seen["points"].append(kwargs["color"])
        return add_points(self, points, **kwargs)

    monkeypatch.setattr(pv.Plotter, "add_legend", keep_legend)
    monkeypatch.setattr(pv.Plotter, "add_points", keep_points)
    with solve(paper_case("c1", nx=10, ny=10), MPI.COMM_SELF) as analysis:
        xy = np.asarray(analysis.result.contact_coordinates)
        pressing = np.arange(len(xy)) % 2 == 0  # both kinds drawn
        plotting.plot_mode_3d(
            analysis.problem, analysis.mode, tmp_path / "c1.png",
            contact_coordinates=xy, contact_pressing=pressing,
        )  # fmt: skip
    assert len(xy) >= 2
    entries = [(colour, face) for _, colour, face in seen["labels"]]
    touch = plotting.THEME["touch_color"]
    assert entries == [("black", "line"), ("black", "circle"), (touch, "circle")]
    assert seen["points"] == ["black", touch]


def test_a_state_that_fails_kkt_is_not_called_kkt_only():
    # A tensionless foundation of 1e9 N/m^3 under the plate of test_penalty's cone without
    # a positive load: certificate status "not-kkt" (a lower eigenvalue of the pencil with
    # the pressing springs), and the first line read "KKT=NO  proven=no (KKT only)".
    from unibuckle_fenicsx.results.records import CertificateRecord, verified_text

    cert = CertificateRecord(
        feasible=True, feasibility_margin=-1e-3, max_contact_force=None,
        max_contact_value=0.0, relative_residual=10.3, tolerance=1e-8, kkt=False,
        smallest_of_reduced=False, lower_bound_Pa=1.977372e7, upper_bound_Pa=3.432653e10,
        relative_gap=None, global_optimum_proven=False, proven_by="interlacing",
        status="not-kkt", negative_eigenvalues=None, refuting_load_Pa=None,
        copositivity=None, notes=[], split_route=None,
    )  # fmt: skip
    assert verified_text(cert) == "proven=no (not a KKT point)"
    kkt_only = msgspec.structs.replace(cert, kkt=True, status="kkt-only")
    assert verified_text(kkt_only) == "proven=no (KKT only)"
