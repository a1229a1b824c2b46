"""The README's first problem file, its command and its Python example run as written.

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

import pytest

from support.paths import ROOT

README = (ROOT / "README.md").read_text()


def _blocks(language: str) -> list[str]:
    return re.findall(rf"^```{language}\n(.*?)^```$", README, flags=re.S | re.M)


def test_readme_is_short() -> None:
    assert len(README.splitlines()) <= 200


@pytest.mark.serial
def test_first_problem_file_and_command(tmp_path: Path) -> None:
    toml = _blocks("toml")[0]
    assert "size = 0.01 " in toml, "the test coarsens the README's mesh.size = 0.01"
    (tmp_path / "demos").mkdir()
    (tmp_path / "demos" / "plate.toml").write_text(toml.replace("size = 0.01 ", "size = 0.025"))
    lines = [line for block in _blocks("sh") for line in block.splitlines()]
    command = next(line for line in lines if "--config demos/plate.toml" in line)
    argv = shlex.split(command)
    assert argv[0] == ".venv/bin/unibuckle"
    argv[0] = str(Path(sys.executable).with_name("unibuckle"))
    proc = subprocess.run(argv, cwd=tmp_path, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    result = json.loads((tmp_path / "plate.json").read_text())
    assert result["critical_load_Pa"] >= result["free_load_Pa"] * (1 - 1e-8)
    assert result["certificate"]["kkt"] is True
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
