"""The README's first problem file, its command, its Python example and its section run as written.

The problem file and the command are taken from the README's first ``toml`` block and
its ``sh`` block that names ``demos/plate.toml``, the example from its first ``python``
block; only the cell size is coarsened (0.01 m to 0.025 m) so that the test stays fast.
What is asserted holds for every plate (no number of the code under test is an expected value): the
critical load with an obstacle is at least the free one (interlacing: removing degrees
of freedom never lowers the smallest eigenvalue), and the answer satisfies its KKT
certificate (the CLI's exit status 0 says so, and the JSON's certificate).
"""

from __future__ import annotations

import json
import re
import shlex
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from support.paths import ROOT

README = (ROOT / "README.md").read_text()


def _blocks(language: str) -> list[str]:
    return re.findall(rf"^```{language}\n(.*?)^```$", README, flags=re.S | re.M)


def test_readme_is_short() -> None:
    assert len(README.splitlines()) <= 200


def _run_command(tmp_path: Path, name: str, toml: str, size: str, coarse: str) -> dict[str, Any]:
    """Run the README's command that names demos/NAME.toml on ``toml`` made coarse.

    The file is written in ``tmp_path`` with its ``size`` replaced by ``coarse``; the JSON
    the command writes is read back after the assertions that hold for every problem.
    """
    assert f"size = {size} " in toml, f"the test coarsens mesh.size = {size}"
    (tmp_path / "demos").mkdir()
    (tmp_path / "demos" / f"{name}.toml").write_text(
        toml.replace(f"size = {size} ", f"size = {coarse} ")
    )
    lines = [line for block in _blocks("sh") for line in block.splitlines()]
    argv = shlex.split(next(line for line in lines if f"--config demos/{name}.toml" in line))
    assert argv[0] == ".venv/bin/unibuckle"
    argv[0] = str(Path(sys.executable).with_name("unibuckle"))
    proc = subprocess.run(argv, cwd=tmp_path, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    result: dict[str, Any] = json.loads((tmp_path / f"{name}.json").read_text())
    assert result["critical_load_Pa"] >= result["free_load_Pa"] * (1 - 1e-8)
    assert result["certificate"]["kkt"] is True
    return result


@pytest.mark.serial
def test_first_problem_file_and_command(tmp_path: Path) -> None:
    result = _run_command(tmp_path, "plate", _blocks("toml")[0], "0.01", "0.025")
    assert result["input"]["obstacle"]["side"] == "below"
    assert any((tmp_path / "out").glob("*.pvd"))


@pytest.mark.serial
def test_first_python_example(tmp_path: Path) -> None:
    script = tmp_path / "first.py"
    script.write_text(_blocks("python")[0])
    proc = subprocess.run(
        [sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True
    )
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    loads = re.search(r"lambda_c = (\S+) Pa, free (\S+) Pa", proc.stdout)
    assert loads is not None, proc.stdout
    assert float(loads.group(1)) >= float(loads.group(2))
    assert lines[-1] in ("proven", "bracketed", "kkt-only")


@pytest.mark.serial
def test_section_command(tmp_path: Path) -> None:
    """The README's section command on ``demos/box.toml``, coarsened from b/8 to b/4 cells.

    Interlacing again: the core removes directions, so the filled box's load is at least
    the hollow box's (``free_load_Pa``); the JSON has one entry per face of the box.
    """
    toml = (ROOT / "demos" / "box.toml").read_text()
    result = _run_command(tmp_path, "box", toml, "0.0125", "0.025")
    assert [face["face"] for face in result["faces"]] == ["right", "top", "left", "bottom"]


def test_section_numbers_are_the_stored_run_s() -> None:
    """The README quotes the run of its section command that ``make demo`` stores."""
    stored = (ROOT / "figures" / "quickstart" / "box.txt").read_text()
    found = re.search(r"sigma_cr = (\S+) Pa \((\S+) x hollow (\S+) Pa\), k = (\S+),", stored)
    assert found is not None, stored
    critical, gain, hollow, k = (float(x) for x in found.groups())
    text = " ".join(README.split())
    assert f"critical axial stress ({critical / 1e6:.1f} MPa" in text
    assert f"{gain:.2f} × the hollow box's {hollow / 1e6:.1f} MPa" in text
    assert f"widest face ({k:.2f};" in text


def test_results_table_is_the_demo_s() -> None:
    """The README's table of the paper's plate is figures/results.md's, as it says.

    ``make demo`` writes that file; the README copies its rows (the eigen-solve counts had
    drifted by one from the file once).
    """
    rows = [
        line
        for line in (ROOT / "figures" / "results.md").read_text().splitlines()
        if line.startswith("| ") and not line.startswith("| case")
    ]
    assert rows
    for row in rows:
        assert row in README.splitlines(), row
