"""Sweeps: the --vary grammar, the paths, resuming a killed sweep, MPI, and the garland.

The garland test compares the bilateral SSSS curve with the exact thin-plate value
k = min_m (m/phi + phi/m)^2 (Timoshenko and Gere, Theory of Elastic Stability, 1961,
section 9.2); the other tests compare a sweep with itself run differently (killed and
resumed, or under mpiexec), which is what they are about.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

from mpi4py import MPI

import numpy as np
import pytest

from support.paths import ROOT
from support.processes import paused_sweep, run_mpi
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.cli import EXIT_BAD_INPUT, EXIT_OK
from unibuckle_fenicsx.spec import (
    MeshSpec,
    load_toml,
    problem_from_dict,
    problem_to_dict,
)
from unibuckle_fenicsx.sweep import (
    Variation,
    parse_variation,
    point_problem,
    read_lines,
    set_value,
    sweep_points,
)
from unibuckle_fenicsx.viz.charts import reference_k

SCRIPT = Path(sys.executable).parent / "unibuckle"

#: A small plate with a box obstacle: each point is an enumeration of a few sets (~1 s).
SMALL = """\
name = "small"
[plate]
corners = [[-0.1, -0.05], [0.1, 0.05]]
thickness = 0.006
[material]
E = 1.0e9
nu = 0.3
[mesh]
nx = 6
ny = 4
[obstacle]
zone = [[-0.04, 0.04], [-0.05, 0.05]]
"""
VARY = ("--vary", "plate.thickness=0.004,0.005,0.006,0.007")

SSSS = """\
name = "ssss"
[plate]
corners = [[0.0, 0.0], [1.0, 1.0]]
thickness = 0.001
[material]
E = 1.0e9
nu = 0.3
[edges.left]
normal_stress = -1.0
[edges.right]
normal_stress = -1.0
[mesh]
size = {size}
"""


def run_sweep_cli(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    return subprocess.run(
        [str(SCRIPT), "sweep", *args], capture_output=True, text=True, env=env, cwd=cwd
    )


def charted_sweep(
    tmp_path: Path, text: str, vary: str, out: str, png: str
) -> subprocess.CompletedProcess[str]:
    """``unibuckle sweep`` of the problem ``text`` with ``--plot``: exit 0 and a PNG drawn."""
    base = tmp_path / "base.toml"
    base.write_text(text)
    proc = run_sweep_cli(
        "--config", str(base), "--vary", vary, "--json", out, "--plot", png, "-q", cwd=tmp_path
    )  # fmt: skip
    assert proc.returncode == EXIT_OK, proc.stderr
    chart = (tmp_path / png).read_bytes()
    assert chart[:8] == b"\x89PNG\r\n\x1a\n" and len(chart) > 10_000  # more than a blank one
    return proc


# -- the grammar --------------------------------------------------------------------


def test_range_and_list():
    v = parse_variation("plate.corners.1.0=0.1:0.4:7")
    assert v.path == "plate.corners.1.0"
    np.testing.assert_allclose(v.values, np.linspace(0.1, 0.4, 7), rtol=0, atol=1e-15)
    assert v.values[0] == 0.1 and v.values[-1] == 0.4  # ends exactly included
    assert parse_variation("material.nu=0.2, 0.3,0.35").values == (0.2, 0.3, 0.35)
    assert parse_variation("mesh.nx=8:8:1").values == (8.0,)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("plate.thickness", "expected PATH=START:STOP:N"),
        ("plate.thickness=", "expected PATH=START:STOP:N"),
        ("plate.thickness=0.1:0.2:0", "N must be an integer >= 1"),
        ("plate.thickness=0.1:0.2:2.5", "N must be an integer >= 1"),
        ("plate.thickness=0.1:abc:3", "'abc' is not a number"),
        ("plate.thickness=0.1,nan", "not a finite number"),
    ],
)
def test_bad_variation(text, message):
    with pytest.raises(ValueError, match=message):
        parse_variation(text)


def test_grid_order_first_slowest():
    points = sweep_points([Variation("a", (1.0, 2.0)), Variation("b", (10.0, 20.0, 30.0))])
    assert points == [
        {"a": a, "b": b} for a in (1.0, 2.0) for b in (10.0, 20.0, 30.0)
    ]  # fmt: skip
    with pytest.raises(ValueError, match="given twice"):
        sweep_points([Variation("a", (1.0,)), Variation("a", (2.0,))])


def test_paths(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(SMALL)
    base = problem_to_dict(load_toml(path))
    spec = point_problem(base, {"plate.corners.1.0": 0.3, "material.nu": 0.25})
    assert spec.plate.corners == ((-0.1, -0.05), (0.3, 0.05))
    assert spec.material.nu == 0.25
    spec = point_problem(base, {"plate.length": 0.5, "plate.width": 0.2})
    assert spec.plate.corners == ((-0.1, -0.05), (-0.1 + 0.5, -0.05 + 0.2))
    spec = point_problem(base, {"mesh.nx": 10.0, "edges.top.shear_stress": 0.5})
    assert spec.mesh.nx == 10 and isinstance(spec.mesh.nx, int)
    # The base's own loads stay: left/right compressed, top sheared.
    assert spec.plate.edge("left").normal_stress == -1.0
    assert spec.plate.edge("top").shear_stress == 0.5
    for path_, message in (
        ("plate.depth", "plate has no key 'depth'"),
        ("plate.corners.2.0", "is a list of 2"),
        ("edges.left.support", "is not a number"),
        ("mesh.nx", "must be an integer"),
    ):
        with pytest.raises(ValueError, match=message):
            set_value(problem_to_dict(load_toml(path)), path_, 2.5)
    with pytest.raises(ValueError, match=r"plate\.thickness must be > 0"):
        point_problem(base, {"plate.thickness": -1.0})


def test_a_number_the_file_leaves_out_is_varied():
    """--vary adds a number a problem file may hold (a design chart over f_y)."""
    data = problem_to_dict(problem_from_dict(compressed_plate()))
    assert "design" not in data
    spec = point_problem(data, {"design.yield_stress": 2.35e8})
    assert spec.design is not None and spec.design.yield_stress == 2.35e8
    # A key no problem file has is refused naming where it is missing.
    with pytest.raises(ValueError, match=r"--vary design\.spam: the problem file has no key"):
        point_problem(data, {"design.spam": 1.0})


def compressed_plate() -> dict[str, object]:
    """A steel plate compressed on its short edges, with no [design] table."""
    return {
        "plate": {"corners": [[0.0, 0.0], [0.3, 0.1]], "thickness": 0.003},
        "material": {"E": 2.1e11, "nu": 0.3},
        "edges": {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}},
    }


def test_mesh_size_and_units():
    # ceil(0.3/0.01) = 30, ceil(0.1/0.01) = 10: an exact division gives no extra cell.
    assert MeshSpec.cells_for(0.3, 0.1, 0.01) == (30, 10)
    assert MeshSpec.cells_for(0.3, 0.1, 0.07) == (5, 2)
    data = {"plate": {"corners": [[0, 0], [0.3, 0.1]]}, "mesh": {"size": 0.02}}
    spec = problem_from_dict(data)
    assert (spec.mesh.nx, spec.mesh.ny, spec.mesh.size) == (15, 5, 0.02)
    assert problem_from_dict(problem_to_dict(spec)) == spec
    with pytest.raises(ValueError, match=r"size \(a cell size\) or nx and ny, not both"):
        problem_from_dict({"mesh": {"size": 0.02, "nx": 4}})
    # A file in mm-N-MPa written back in its own units reads as the same problem.
    mm = problem_from_dict(
        {"units": "mm-N-MPa", "plate": {"corners": [[0, 0], [300, 100]], "thickness": 1.0},
         "material": {"E": 2.1e5, "nu": 0.3}, "mesh": {"size": 20.0}}
    )  # fmt: skip
    back = problem_to_dict(mm, units="mm-N-MPa")
    assert back["plate"]["corners"] == [[0.0, 0.0], [300.0, 100.0]]
    assert back["material"]["E"] == pytest.approx(2.1e5, rel=1e-15)
    assert problem_from_dict(back) == mm


# -- the command: resume, errors, chart ---------------------------------------------


def test_killed_sweep_resumes_to_the_same_file(tmp_path):
    base = tmp_path / "small.toml"
    base.write_text(SMALL)
    whole = run_sweep_cli("--config", str(base), *VARY, "--json", "whole.jsonl", cwd=tmp_path)
    assert whole.returncode == EXIT_OK, whole.stderr
    expected = (tmp_path / "whole.jsonl").read_text()
    assert [line["status"] for line in read_lines(tmp_path / "whole.jsonl")] == ["ok"] * 4

    # Kill the same sweep once its first line is on disk (paused there: no race with the
    # sweep's speed, which depends on the machine's load).
    out = tmp_path / "killed.jsonl"
    proc = paused_sweep(["--config", str(base), *VARY, "--json", str(out), "-q"], tmp_path)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    done = read_lines(out)
    assert len(done) == 1, "killed after its first point"
    # A line cut by the kill is dropped on resume.
    with out.open("a") as f:
        f.write('{"index": 3, "point": {"plate.thick')
    again = run_sweep_cli("--config", str(base), *VARY, "--json", str(out), cwd=tmp_path)
    assert again.returncode == EXIT_OK, again.stderr
    assert f"{len(done)} of 4 points already in" in again.stderr
    assert out.read_text() == expected

    # Another sweep into the same file is refused before solving.
    other = run_sweep_cli(
        "--config", str(base), "--vary", "plate.thickness=0.001,0.002", "--json", str(out),
        cwd=tmp_path,
    )  # fmt: skip
    assert other.returncode == EXIT_BAD_INPUT
    assert "holds a point of another sweep" in other.stderr


def test_a_line_is_reused_only_for_the_same_input(tmp_path, capsys):
    """Edit the base file (E halved) and re-run: every point is solved again.

    With the edge stress given, N0 does not depend on E and a, the bending and shear
    energy, is proportional to it: the loads halve exactly (to the eigen solver's
    tolerance). A line of the same input is kept; the file ends as a fresh sweep's.
    """
    from unibuckle_fenicsx.cli import main

    base = tmp_path / "small.toml"
    base.write_text(SMALL)
    out = tmp_path / "k.jsonl"
    args = ["sweep", "--config", str(base), "--vary", "plate.thickness=0.005,0.006"]
    assert main([*args, "--json", str(out)]) == EXIT_OK
    before = read_lines(out)
    capsys.readouterr()

    base.write_text(SMALL.replace("E = 1.0e9", "E = 0.5e9"))
    assert main([*args, "--json", str(out)]) == EXIT_OK
    err = capsys.readouterr().err
    assert f"2 line(s) of {out} hold another input" in err, err
    after = read_lines(out)
    for old, new in zip(before, after, strict=True):
        assert new["input"]["material"]["E"] == 0.5e9
        assert new["critical_load_Pa"] == pytest.approx(old["critical_load_Pa"] / 2, rel=1e-8)
    fresh = tmp_path / "fresh.jsonl"
    assert main([*args, "--json", str(fresh)]) == EXIT_OK
    assert out.read_text() == fresh.read_text()

    # One point of the same input is kept, the other (a line of another input) solved.
    lines = out.read_text().splitlines()
    stale = json.loads(lines[1])
    stale["input"]["material"]["E"] = 1.0e9
    stale["critical_load_Pa"] = 1.0
    out.write_text(lines[0] + "\n" + json.dumps(stale) + "\n")
    capsys.readouterr()
    assert main([*args, "--json", str(out)]) == EXIT_OK
    err = capsys.readouterr().err
    assert "1 of 2 points already in" in err and "1 line(s)" in err, err
    assert out.read_text() == fresh.read_text()


def test_bad_sweep_input(tmp_path):
    base = tmp_path / "small.toml"
    base.write_text(SMALL)
    for vary, message in (
        ("plate.thickness=-0.001,0.006", "plate.thickness must be > 0"),
        ("plate.nothing=1,2", "plate has no key 'nothing'"),
        ("plate.thickness=1:2", "a range is START:STOP:N"),
    ):
        proc = run_sweep_cli(
            "--config", str(base), "--vary", vary, "--json", "x.jsonl", cwd=tmp_path
        )
        assert proc.returncode == EXIT_BAD_INPUT, proc.stderr
        assert message in proc.stderr
        assert not (tmp_path / "x.jsonl").exists() or not read_lines(tmp_path / "x.jsonl")


# -- the garland ----------------------------------------------------------------------


@pytest.mark.parametrize("phi", [0.6, 1.0, 1.5, 2.2])
def test_bilateral_garland(tmp_path, phi):
    """SSSS, uniaxial: k within the MITC4 mesh error of min_m (m/phi + phi/m)^2.

    At h = b/12 (t/b = 1e-3) the measured error is 0.9-1.8 %, positive, and it falls as
    h^2: at b/16 it is smaller by (16/12)^2 = 1.78 within 25 %.
    """
    path = tmp_path / "ssss.toml"
    errors = []
    for size in (1 / 12, 1 / 16):
        path.write_text(SSSS.format(size=size))
        spec = point_problem(problem_to_dict(load_toml(path)), {"plate.length": phi})
        exact = reference_k(spec)[0]
        assert exact is not None
        with solve(spec, MPI.COMM_SELF) as analysis:
            errors.append(analysis.result.buckling_coefficient_k / exact - 1.0)
    assert 0.0 < errors[0] < 0.02
    assert errors[0] / errors[1] == pytest.approx((16 / 12) ** 2, rel=0.25)


def test_reference_values():
    """The curves drawn on the charts, at points where they are known by hand."""
    data = {"plate": {"corners": [[0, 0], [1.0, 1.0]], "thickness": 1e-3}}
    square = problem_from_dict(data)
    assert reference_k(square) == (4.0, None, "exact")  # m = 1: (1 + 1)^2
    data["plate"]["corners"] = [[0, 0], [np.sqrt(2), 1.0]]
    data["obstacle"] = {"zone": "all"}
    bil, uni, _ = reference_k(problem_from_dict(data))
    assert bil == pytest.approx(4.5) and uni == pytest.approx(4.5)  # the m = 1, 2 crossing
    data["plate"]["corners"] = [[0, 0], [3.0, 1.0]]
    bil, uni, _ = reference_k(problem_from_dict(data))
    assert bil == pytest.approx(4.0) and uni == 4.5


def test_no_reference_curve_for_a_foundation_or_holes():
    """The rigid obstacle's curve is not drawn for a foundation, nor the plate's for holes.

    A whole-plate tensionless foundation of 0.3 N/m^3 under the 3 x 1 m plate (E = 1e9
    Pa, t = 1 mm): its k is at most the bilateral foundation's, min over m of
    (m/phi + phi/m)^2 + k_f a^2 b^2/(m^2 pi^4 D) = 4.03 (m = 3; Timoshenko & Gere, section
    9.2, with the Winkler term), below the rigid obstacle's 4.5, which was drawn for it;
    the free plate's curve stays (the bilateral k is the plate's without the foundation).
    A plate with a hole is not the garland's plate.
    """
    data = {
        "plate": {"corners": [[0, 0], [3.0, 1.0]], "thickness": 1e-3},
        "obstacle": {"zone": "all", "foundation_stiffness": 0.3},
    }
    spec = problem_from_dict(data)
    mat = spec.material
    D = mat.E * 1e-3**3 / (12 * (1 - mat.nu**2))
    winkler = min((m / 3 + 3 / m) ** 2 + 0.3 * 9 / (m**2 * np.pi**4 * D) for m in range(1, 6))
    assert winkler == pytest.approx(4.03, abs=0.01)
    bilateral, unilateral, _ = reference_k(spec)
    assert bilateral == pytest.approx(4.0) and unilateral is None  # m = 3: (1 + 1)^2
    del data["obstacle"]
    data["plate"]["holes"] = [{"center": [1.5, 0.5], "radius": 0.2}]
    data["mesh"] = {"size": 0.1}
    assert reference_k(problem_from_dict(data)) == (None, None, "")


@pytest.mark.parametrize("held", ["roller", "clamped"])
def test_no_garland_for_unloaded_edges_held_in_their_plane(held):
    """Unloaded edges held in their plane add sigma_y = nu sigma_x: not the garland's plate.

    The SSSS square with rollers on y = 0, b: sigma_x (1 + nu) = 4 pi^2 D/(t b^2) (m = n
    = 1 of the biaxial plate, Timoshenko & Gere, section 9.2), k = 4/(1 + nu) = 3.08,
    where the chart drew the garland's 4 as "exact". Clamped, the edges also shear the
    plate: no exact curve either.
    """
    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    edges |= {name: {"inplane": held} for name in ("bottom", "top")}
    data = {
        "plate": {"corners": [[0, 0], [0.1, 0.1]], "thickness": 1e-4},
        "material": {"E": 2.1e11, "nu": 0.3},
        "edges": edges,
        "mesh": {"nx": 20, "ny": 20},
    }
    spec = problem_from_dict(data)
    assert reference_k(spec) == (None, None, "")
    if held == "roller":
        with solve(spec, MPI.COMM_SELF) as analysis:
            k = analysis.result.buckling_coefficient_k
        assert k == pytest.approx(4.0 / 1.3, rel=0.01)  # MITC4 at b/20: +0.3 %


# -- MPI ----------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.mpi
@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="launches mpiexec itself")
def test_two_ranks_give_the_serial_lines(tmp_path):
    base = tmp_path / "small.toml"
    base.write_text(SMALL)
    serial = run_sweep_cli("--config", str(base), *VARY, "--json", "serial.jsonl", cwd=tmp_path)
    assert serial.returncode == EXIT_OK, serial.stderr
    cli = ROOT / "unibuckle_fenicsx" / "cli" / "__main__.py"
    run_mpi(cli, 2, "sweep", "--config", str(base), *VARY, "--json", str(tmp_path / "p.jsonl"))
    assert (tmp_path / "p.jsonl").read_text() == (tmp_path / "serial.jsonl").read_text()
    # Each point's mesh over both ranks: the same loads within the eigen tolerance.
    run_mpi(
        cli, 2, "sweep", "--config", str(base), *VARY, "--json", str(tmp_path / "r2.jsonl"),
        "--ranks-per-point", "2",
    )  # fmt: skip
    for a, b in zip(
        read_lines(tmp_path / "serial.jsonl"), read_lines(tmp_path / "r2.jsonl"), strict=True
    ):
        assert a["point"] == b["point"] and a["status"] == b["status"] == "ok"
        assert b["mpi_size"] == 2
        assert b["critical_load_Pa"] == pytest.approx(a["critical_load_Pa"], rel=1e-8)
        np.testing.assert_allclose(b["contact_coordinates"], a["contact_coordinates"], atol=1e-15)


def test_plot(tmp_path):
    proc = charted_sweep(tmp_path, SMALL, "plate.length=0.2,0.3", "l.jsonl", "chart.png")
    assert "chart.png" in proc.stdout
    assert json.loads((tmp_path / "l.jsonl").read_text().splitlines()[1])["point"] == {
        "plate.length": 0.3
    }


def test_a_thin_plate_line_is_the_same_on_every_run(thin_plate):
    """A sweep line leaves out every wall time, the interior point's level records' too.

    The route on thin plates records seconds per mesh level and link; a line
    (``as_dict(timings=False)``, README "Sweeps and charts") must not carry them, or two
    runs (and a run on two ranks) would write different lines.
    """
    spec = thin_plate("thin", 12, 4)
    lines = []
    for _ in range(2):
        with solve(spec) as analysis:
            assert analysis.result.method.startswith("interior-point")
            assert analysis.result.details.run.levels[0].seconds > 0.0
            lines.append(json.dumps(analysis.result.as_dict(timings=False), sort_keys=True))
    assert lines[0] == lines[1]
    assert '"seconds"' not in lines[0]


def test_ranks_per_point_errors_name_the_flag(tmp_path):
    """A bad ranks_per_point names the command line's flag as well (--ranks-per-point)."""
    from unibuckle_fenicsx.sweep import run_sweep

    v = [parse_variation("material.nu=0.2,0.3")]
    for bad, why in ((0, r"must be an integer >= 1"), (MPI.COMM_WORLD.size + 1, "must divide")):
        with pytest.raises(ValueError, match=rf"ranks_per_point \(--ranks-per-point\).*{why}"):
            run_sweep({}, v, tmp_path / "s.jsonl", MPI.COMM_WORLD, ranks_per_point=bad)


def test_chart_axes_name_the_swept_number_in_words():
    """An axis reads "tie spacing (m)", not the dotted key ``points.0.spacing``."""
    from unibuckle_fenicsx.viz.charts import axis_label

    base = {"units": "SI", "points": [{"kind": "bilateral", "spacing": 0.5}]}
    assert axis_label("points.0.spacing", base) == "tie spacing (m)"
    assert axis_label("points.0.spacing", {**base, "units": "mm-N-MPa"}) == "tie spacing (mm)"
    assert axis_label("plate.thickness", base) == "plate thickness (m)"
    assert axis_label("edges.top.rotational_stiffness", base) == (
        "rotational stiffness of the top edge (N·m/(m·rad))"
    )
    assert axis_label("obstacle.foundation_stiffness", base) == "foundation modulus (Pa/m)"


def test_an_aspect_chart_s_title_names_its_axis():
    """A sweep of plate.length is drawn against a/b: its title says so, as its axis does.

    The title read "k against the plate length (m)" over an axis of a/b.
    """
    import tomllib

    from unibuckle_fenicsx.viz import charts

    base = tomllib.loads(SMALL)
    lines = [
        {"point": {"plate.length": a}, "status": "ok", "buckling_coefficient_k": 4.4,
         "free_load_Pa": 1.0, "critical_load_Pa": 1.1, "certificate": None}
        for a in (0.2, 0.3)
    ]  # fmt: skip
    ax = charts.sweep_figure(lines, [parse_variation("plate.length=0.2,0.3")], base).axes[0]
    assert ax.get_xlabel() == "aspect ratio a/b"
    assert ax.get_title() == "small: k against the aspect ratio a/b"


def test_an_aspect_chart_shows_every_point():
    """Every k of an aspect sweep lies within the chart's k axis, however short the plate.

    The axis was cut at 2.5 times the smallest k: the clamped garland's a/b = 0.5 point
    (k = 21.70, its stored record) lay above it, with the long plates' 4.29 the smallest.
    The k values here are that record's (bilateral = unilateral at a/b = 0.5).
    """
    import tomllib

    from unibuckle_fenicsx.viz import charts

    base = tomllib.loads(SMALL)
    k = {0.1: 21.702549, 0.2: 6.9752, 0.8: 4.2855}  # the record's a/b = 0.5, 1, 4
    lines = [
        {"point": {"plate.length": a}, "status": "ok", "buckling_coefficient_k": value,
         "free_load_Pa": 1.0, "critical_load_Pa": 1.0, "certificate": None}
        for a, value in k.items()
    ]  # fmt: skip
    variation = parse_variation("plate.length=0.1,0.2,0.8")
    ax = charts.sweep_figure(lines, [variation], base).axes[0]
    low, high = ax.get_ylim()
    assert all(low < value < high for value in k.values()), (ax.get_ylim(), k)
    assert ax.get_yscale() == "log" and ax.get_ylabel().endswith("(log scale)")


# -- sections -----------------------------------------------------------------------

#: A filled square box 100 x 100 mm, L = 200 mm, on 25 mm cells: each point about 1 s.
BOX = """\
name = "box"
[section]
shape = "box"
width = 0.1
depth = 0.1
thickness = 0.001
length = 0.2
ends = "simply_supported"
[material]
E = 2.1e11
nu = 0.3
[obstacle]
core = true
[mesh]
size = 0.025
levels = 0
"""


def test_a_section_is_swept(tmp_path):
    """A section's file sweeps as a plate's: each line is the section solved at its point.

    The hollow box's load (each line's ``free_load_Pa``) follows the Reissner-Mindlin
    plate's sigma = sigma_K / (1 + c), c = k pi^2 t^2 / (6 (1 - nu) kappa b^2) (the
    Kirchhoff load sigma_K ~ t^2 reduced by transverse shear, kappa = 5/6): from b/t = 100
    to 50, k_free falls by the ratio (1 + c(t1)) / (1 + c(t2)), 0.37 % here, not 0 (as it
    would if the thickness were not set) nor more; within 5e-4, a seventh of the effect
    (the formula is the single simply supported plate's, the box's faces on these cells
    follow it to about 3e-4). The filled box's line at t = 2 mm is the section solved
    directly at that thickness.
    """
    import math

    from unibuckle_fenicsx.section_analysis import solve_section
    from unibuckle_fenicsx.spec import section_from_dict

    charted_sweep(tmp_path, BOX, "section.thickness=0.001,0.002", "b.jsonl", "b.png")
    base = tmp_path / "base.toml"
    lines = read_lines(tmp_path / "b.jsonl")
    assert [line["status"] for line in lines] == ["ok", "ok"]
    b, nu, E = 0.1, 0.3, 2.1e11
    k_free = []
    for line in lines:
        t = line["point"]["section.thickness"]
        assert line["input"]["section"]["thickness"] == t
        D = E * t**3 / (12 * (1 - nu**2))
        k_free.append(line["free_load_Pa"] * t * b**2 / (math.pi**2 * D))

    def shear(t: float, k: float) -> float:
        return k * math.pi**2 * t**2 / (6 * (1 - nu) * (5 / 6) * b**2)

    expected = (1 + shear(0.001, k_free[0])) / (1 + shear(0.002, k_free[1]))
    assert k_free[1] / k_free[0] == pytest.approx(expected, rel=5e-4)
    data = problem_to_dict(load_toml(base))
    thick = section_from_dict({**data, "section": {**data["section"], "thickness": 0.002}})
    with solve_section(thick, MPI.COMM_SELF) as analysis:
        direct = analysis.result.critical_load_Pa
    assert lines[1]["critical_load_Pa"] == pytest.approx(direct, rel=1e-10)


def test_a_section_chart_names_its_numbers():
    """A section's axis reads "wall thickness (m)"; a plate's foundation keeps its words."""
    from unibuckle_fenicsx.viz.charts import axis_label

    section = {"units": "SI", "section": {"shape": "box"}}
    assert axis_label("section.thickness", section) == "wall thickness (m)"
    assert axis_label("section.diameter", {**section, "units": "mm-N-MPa"}) == (
        "tube diameter (mm)"
    )
    assert axis_label("obstacle.foundation_stiffness", {"units": "SI"}) == (
        "foundation modulus (Pa/m)"
    )


def test_a_section_chart_draws_the_extreme_fibre_s_stress():
    """With bending the chart's sigma_cr is the extreme fibre's, not the load factor.

    The box of ``BOX`` hollow and filled, axial_stress = -1 and bending_stress = -0.5: the
    top face carries lambda (|sigma_b| - sigma_a) = 1.5 lambda at the load factor lambda
    (``critical_load_Pa``), the summary's sigma_cr; the classical stress 4 pi^2 D/(t b^2)
    (b = 0.1 m, t = 1 mm) = 75.92 MPa by hand. The chart drew lambda over it, 1.5 times low.
    """
    import math
    import tomllib

    from unibuckle_fenicsx.sweep import solve_point
    from unibuckle_fenicsx.viz import charts

    base = tomllib.loads(BOX)
    point = {"load.bending_stress": -0.5}
    line = {"index": 0, "point": point, **solve_point(point_problem(base, point), MPI.COMM_SELF)}
    assert line["status"] == "ok"
    E, nu, t, b = 2.1e11, 0.3, 0.001, 0.1
    classical = 4 * math.pi**2 * E * t**3 / (12 * (1 - nu**2)) / (t * b**2)
    fig = charts.sweep_figure([line], [parse_variation("load.bending_stress=-0.5")], base)
    seen = {line.get_label(): np.asarray(line.get_ydata()) for line in fig.axes[0].lines}
    assert seen["hollow"][0] == pytest.approx(1.5 * line["free_load_Pa"] / classical, rel=1e-5)
    assert seen["core"][0] == pytest.approx(1.5 * line["critical_load_Pa"] / classical, rel=1e-5)


# -- the table as CSV -----------------------------------------------------------------


def _printed_table(out: str) -> list[list[str]]:
    """The rows of the table ``unibuckle sweep`` printed (cells apart by 2 spaces or more)."""
    import re

    rows = out.splitlines()
    end = next(k for k, row in enumerate(rows) if row.startswith("sweep: "))
    return [re.split(r"\s{2,}", row.strip()) for row in rows[:end]]


def test_the_sweep_table_is_written_as_csv(tmp_path, capsys):
    """``--csv`` holds the printed table: its header, and each cell at full precision.

    Read back with the csv module, each number formatted as the terminal's table formats
    it (6 significant digits for the swept value, 7 for the load, 4 decimals for the ratio
    and k) is the printed cell, and the load is the point's JSON line's to the last bit.
    """
    import csv

    from unibuckle_fenicsx.cli import main

    base = tmp_path / "small.toml"
    base.write_text(SMALL)
    out, table = tmp_path / "k.jsonl", tmp_path / "k.csv"
    args = ["sweep", "--config", str(base), "--vary", "plate.thickness=0.005,0.006"]
    assert main([*args, "--json", str(out), "--csv", str(table)]) == EXIT_OK
    printed = _printed_table(capsys.readouterr().out)
    with table.open(newline="", encoding="utf-8") as f:
        written = list(csv.reader(f))
    assert written[0] == printed[0] == [
        "plate.thickness (m)", "lambda_c (Pa)", "x free", "k", "certificate", "status"
    ]  # fmt: skip
    assert len(written) == len(printed) == 3
    formats = (".6g", ".6e", ".4f", ".4f")
    for line, row, shown in zip(read_lines(out), written[1:], printed[1:], strict=True):
        numbers = [float(cell) for cell in row[:4]]
        assert [format(v, f) for v, f in zip(numbers, formats, strict=True)] == shown[:4]
        assert row[4:] == shown[4:] == [line["certificate"]["status"], "ok"]
        assert numbers[0] == line["point"]["plate.thickness"]
        assert numbers[1] == line["critical_load_Pa"]  # SI: the stress unit is Pa
        assert numbers[3] == line["buckling_coefficient_k"]


def test_a_point_without_values_has_empty_csv_cells(tmp_path):
    # The terminal table shows "-" where a point has no value; the CSV leaves it empty.
    import csv

    from unibuckle_fenicsx.cli.sweep import sweep_table, write_sweep_csv

    lines = [
        {"index": 0, "point": {"plate.thickness": 2.0}, "status": "ok", "units": "mm-N-MPa",
         "critical_load_Pa": 7.935676e8, "ratio_to_free": 1.28875,
         "buckling_coefficient_k": 10.45268, "certificate": {"status": "kkt-only"}},
        {"index": 1, "point": {"plate.thickness": 3.0}, "status": "eigen-failure",
         "units": "mm-N-MPa", "error": "no pair"},
    ]  # fmt: skip
    path = tmp_path / "t.csv"
    write_sweep_csv(lines, str(path))
    with path.open(newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    assert rows[0][:2] == ["plate.thickness (mm)", "lambda_c (MPa)"]
    assert rows[1] == ["2.0", "793.5676", "1.28875", "10.45268", "kkt-only", "ok"]
    assert rows[2] == ["3.0", "", "", "", "", "eigen-failure"]
    assert sweep_table(lines).splitlines()[2].split() == ["3", "-", "-", "-", "-", "eigen-failure"]


def test_a_csv_in_a_missing_folder_is_refused_before_any_solve(tmp_path):
    base = tmp_path / "small.toml"
    base.write_text(SMALL)
    proc = run_sweep_cli(
        "--config", str(base), *VARY, "--json", "k.jsonl", "--csv", "no/k.csv", cwd=tmp_path
    )  # fmt: skip
    assert proc.returncode == EXIT_BAD_INPUT, proc.stderr
    assert "--csv: the folder no does not exist" in proc.stderr
    assert not (tmp_path / "k.jsonl").exists()
