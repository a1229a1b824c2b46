"""The demos run end to end on coarse meshes and write real pictures; plotting helpers."""

from __future__ import annotations

import json
import os
import subprocess
import sys

from mpi4py import MPI

import numpy as np
import pytest

from support.paths import ROOT

CASES = ("free", "c1", "c2", "c3")
COARSE = ("8x8", "16x16")  # the coarse "paper" and "refined" meshes of the demos

serial_only = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="runs its own processes")


def _expected_pngs() -> dict[str, tuple[int, int]]:
    """PNG path (relative to the figures directory) -> (height, width) in pixels."""
    from unibuckle_fenicsx.viz.plotting import THEME

    w3, h3 = THEME["window_size"]
    fw, fh = THEME["figsize"]
    dpi = THEME["dpi"]
    line = (round(fh * dpi), round(fw * dpi))
    conv = (round(fh * dpi), round(1.3 * fw * dpi))
    pngs = {"convergence.png": conv, "free/convergence.png": conv, "sections_A.png": line}
    for mesh in COARSE:
        pngs[f"free/mode_{mesh}.png"] = (h3, w3)
    for case in CASES[1:]:
        pngs[f"{case}/convergence.png"] = conv
        pngs[f"{case}/section_A.png"] = line
        pngs[f"{case}/contact_set.png"] = line
        pngs[f"{case}/contact_force.png"] = line
        for mesh in COARSE:
            pngs[f"{case}/mode_{mesh}.png"] = (h3, w3)
    for name in ("ssss", "loaded_edges_clamped"):  # charts.plot_sweep: 7.5 x 5 in at 150 dpi
        pngs[f"garland/garland_{name}.png"] = (750, 1125)
    # demo_nonlinear: plotting.plot_load_paths is 1.6 x 1.1 times the line figure.
    pngs["nonlinear/load_paths.png"] = (round(1.1 * fh * dpi), round(1.6 * fw * dpi))
    pngs["nonlinear/southwell.png"] = line
    pngs["nonlinear/section_c1.png"] = line
    pngs["nonlinear/deformed_c1.png"] = (h3, w3)
    pngs["realistic/mode.png"] = (h3, w3)  # demo_realistic
    pngs["realistic/contact_map.png"] = line
    pngs["column/mode.png"] = (h3, w3)  # demo_column
    pngs["column/contact_map.png"] = line
    pngs["column/tie_spacing.png"] = (750, 1125)  # charts.plot_sweep
    pngs["ties/tie_spacing_study.png"] = (750, 1125)  # study_ties: charts.plot_sweep
    for name in ("box_filled", "box_hollow", "tube_filled", "tube_hollow"):  # demo_sections
        pngs[f"sections/{name}.png"] = (h3, w3)
    return pngs


def _assert_not_blank(path, height, width, image):
    """The PNG's size, and not blank (test_run_all_coarse_writes_every_figure says how)."""
    pixels = image.imread(path)[..., :3]
    assert pixels.shape[:2] == (height, width), f"{path}: {pixels.shape}"
    away_from_white = np.mean(np.any(pixels < 0.9, axis=-1))
    assert pixels.std() > 0.03 and away_from_white > 0.02, (
        f"{path} looks blank (std {pixels.std():.3g}, non-white {away_from_white:.3g})"
    )


# demo: every demo's run (minutes); two demos end to end with their figures, checked the
# same way, are test_a_plate_and_a_section_demo_write_their_figures, and every demo's
# imports test_demos_use_the_public_api.
@pytest.mark.demo
@serial_only
@pytest.mark.serial
def test_run_all_coarse_writes_every_figure(tmp_path):
    """run_all --coarse exits 0, prints the table and writes non-blank PNGs of the right size.

    ``make demo`` is one of the README's two commands, and a change of the package's API
    has broken its scripts before: every demo runs here (``-m demo``, several minutes of
    one worker), two of them by default
    (test_a_plate_and_a_section_demo_write_their_figures).

    Sizes come from plotting.THEME (pyvista window, matplotlib figsize x dpi); "not blank"
    means a pixel standard deviation above 0.03 (on [0, 1]) and at least 2 % of the pixels
    away from the white background, which an empty or single-colour image cannot meet.
    """
    pytest.importorskip("pyvista")
    image = pytest.importorskip("matplotlib.image")
    figures, vtx = tmp_path / "figures", tmp_path / "vtx"
    env = {**os.environ, "PYVISTA_OFF_SCREEN": "true", "OMP_NUM_THREADS": "1"}
    cmd = [sys.executable, str(ROOT / "demos" / "run_all.py"), "--coarse"]
    cmd += ["--figures", str(figures), "--output", str(vtx)]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=ROOT)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    for demo in (
        "demo_free_plate", "demo_obstacle_c1", "demo_obstacle_c2", "demo_obstacle_c3",
        "demo_garland", "demo_nonlinear", "demo_realistic", "demo_column", "study_ties",
        "demo_sections",
    ):  # fmt: skip
        assert f"{demo}.py: ok" in proc.stdout
    assert "lambda/lambda_free" in proc.stdout and "certificate" in proc.stdout
    assert "check free <= c2 <= c1 <= c3 (nested zones): ok" in proc.stdout
    table = (figures / "results.md").read_text().splitlines()
    assert len(table) == 2 + 2 * len(CASES)  # header, rule, paper + refined mesh per case

    for rel, (height, width) in _expected_pngs().items():
        path = figures / rel
        assert path.is_file(), f"missing {rel}"
        _assert_not_blank(path, height, width, image)

    column = json.loads((figures / "column" / "results.json").read_text())
    assert column["certificate"]["kkt"] and 0.0 < column["design"]["reduction_factor"] <= 1.0
    assert column["critical_stress_MPa"] >= column["free_stress_MPa"] * (1 - 1e-7)
    assert all(row["status"] == "ok" for row in column["tie_spacing_study"])

    for case in CASES:
        data = json.loads((figures / case / "results.json").read_text())
        for r in data["results"]:
            # Interlacing: the obstacle never lowers the load (README, "The problem"), up
            # to the records' eight digits.
            assert r["critical_load_Pa"] >= r["free_load_Pa"] * (1 - 1e-7)
        for mesh in COARSE:
            assert (vtx / case / mesh / f"{case}_w.bp").exists()


@serial_only
@pytest.mark.serial
def test_a_plate_and_a_section_demo_write_their_figures(tmp_path):
    """A plate's and a section's demo run --coarse as run_all runs them, and draw.

    The two quickest demos of ``make demo``, one through the plate's mesh study (modes,
    convergence figure, results.json, VTX files), one through the sections' API: each
    exits 0 (its own assertions passed) and writes its PNGs at the sizes of
    plotting.THEME, not blank (_expected_pngs, the criterion of the full run).
    """
    pytest.importorskip("pyvista")
    image = pytest.importorskip("matplotlib.image")
    figures, vtx = tmp_path / "figures", tmp_path / "vtx"
    env = {**os.environ, "PYVISTA_OFF_SCREEN": "true", "OMP_NUM_THREADS": "1"}
    for script, folder in (("demo_free_plate.py", "free"), ("demo_sections.py", "sections")):
        cmd = [sys.executable, str(ROOT / "demos" / script), "--figures", str(figures)]
        cmd += ["--coarse", "--output", str(vtx)]
        proc = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=ROOT)
        assert proc.returncode == 0, proc.stdout + proc.stderr
        pngs = {rel: hw for rel, hw in _expected_pngs().items() if rel.startswith(f"{folder}/")}
        assert pngs  # the figures this demo writes in the full run
        for rel, (height, width) in pngs.items():
            assert (figures / rel).is_file(), f"missing {rel}"
            _assert_not_blank(figures / rel, height, width, image)
    assert json.loads((figures / "free" / "results.json").read_text())["results"]
    for mesh in COARSE:
        assert (vtx / "free" / mesh / "free_w.bp").exists()


@serial_only
@pytest.mark.serial
def test_section_of_free_mode_is_the_navier_shape():
    """Section A of the free 20 x 20 mode against the Navier mode sin(2 pi (x + a/2) / a).

    The free mode of the simply supported plate is sin(m pi x'/a) sin(pi y'/b), m = 2
    (Navier, Timoshenko & Gere, Theory of Elastic Stability, section 9.2), so along y = 0
    and scaled to max |w| = 1 it is +-sin(2 pi x'/a). The MITC4 mode's nodal values on the
    paper's mesh match it within 2 % of max |w|.
    """
    from unibuckle_fenicsx import paper_case
    from unibuckle_fenicsx.model.build import build_problem
    from unibuckle_fenicsx.viz import fields

    spec = paper_case("free", 20, 20)
    with build_problem(spec, MPI.COMM_WORLD) as problem:
        x, w = fields.section(problem, problem.solve_free().function)
    a = spec.plate.length
    assert x.shape == (21,) and np.allclose(np.diff(x), a / 20)
    exact = np.sin(2 * np.pi * (x - x[0]) / a)
    exact *= np.sign(np.dot(exact, w))
    assert np.abs(w - exact).max() < 2e-2


def test_zone_box_of_the_paper_cases():
    """zone_box returns the paper's zones (section 6), and the plate for "all" (c3)."""
    from unibuckle_fenicsx import paper_case
    from unibuckle_fenicsx.viz.fields import zone_box

    assert zone_box(paper_case("free")) is None
    assert zone_box(paper_case("c1")) == ((-0.04, 0.04), (-0.05, 0.05))
    assert zone_box(paper_case("c2")) == ((-0.04, 0.04), (-0.02, 0.02))
    assert zone_box(paper_case("c3")) == ((-0.1, 0.1), (-0.05, 0.05))


#: The modules the demos may import from, besides the names of ``unibuckle_fenicsx``'s
#: ``__all__``: the public modules of the API page (docs/reference/api.rst).
PUBLIC_MODULES = (
    "unibuckle_fenicsx.sweep",
    "unibuckle_fenicsx.nonlinear",
    "unibuckle_fenicsx.viz",
    "unibuckle_fenicsx.viz.plotting",
    "unibuckle_fenicsx.viz.charts",
    "unibuckle_fenicsx.viz.fields",
    "unibuckle_fenicsx.viz.study",
    "unibuckle_fenicsx.viz.section",
)
#: Scripts that study an algorithm itself and call it directly (not a user's workflow).
ALGORITHM_STUDIES = ("study_penalty.py",)


@pytest.mark.parametrize(
    "script",
    sorted(p.name for p in (ROOT / "demos").glob("*.py") if p.name not in ALGORITHM_STUDIES),
)
def test_demos_use_the_public_api(script):
    """A demo imports only the package's public names and modules (what a user would)."""
    import ast

    import unibuckle_fenicsx

    tree = ast.parse((ROOT / "demos" / script).read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("unibuckle"):
            if node.module == "unibuckle_fenicsx":
                names = {alias.name for alias in node.names}
                assert names <= set(unibuckle_fenicsx.__all__), (script, names)
            else:
                assert node.module in PUBLIC_MODULES, (script, node.module)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                assert not alias.name.startswith("unibuckle") or alias.name in (
                    "unibuckle_fenicsx",
                    *PUBLIC_MODULES,
                ), (script, alias.name)
