"""Command line: help, JSON output, and bad input (exit status 2, message on stderr).

Most calls run :func:`unibuckle_fenicsx.cli.main` in-process (cheap); one subprocess per
kind of exit checks the installed console script itself.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from unibuckle_fenicsx.cli import _parser, main
from unibuckle_fenicsx.materials import navier_load_mindlin

SCRIPT = Path(sys.executable).parent / "unibuckle"

#: Fields the README ("Command line") promises in the JSON result.
REQUIRED = (
    "critical_load_Pa",
    "free_load_Pa",
    "ratio_to_free",
    "buckling_coefficient_k",
    "dofs",
    "mesh",
    "method",
    "eigensolves",
    "wall_time_s",
)

FREE_TOML = """\
[plate]
corners = [[-0.1, -0.05], [0.1, 0.05]]
thickness = 0.006
[material]
E = 1.0e9
nu = 0.3
[mesh]
nx = 8
ny = 4
"""


def run_script(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    return subprocess.run(
        [str(SCRIPT), *args], capture_output=True, text=True, timeout=300, env=env, cwd=cwd
    )


def test_help(tmp_path):
    top = run_script("--help", cwd=tmp_path)
    assert top.returncode == 0, top.stderr
    assert "solve" in top.stdout and "PETSc" in top.stdout
    sub = run_script("solve", "--help", cwd=tmp_path)
    assert sub.returncode == 0, sub.stderr
    flags = (
        "--case",
        "--config",
        "--nx",
        "--ny",
        "--method",
        "--complete",
        "--max-candidates",
        "--penalty",
        "--tau",
        "--candidate-parallel",
        "--json",
        "--output",
        "--verbose",
    )
    for flag in flags:
        assert flag in sub.stdout, flag
    # Every flag is explained: each option of the sub-command carries a help text.
    solve_parser = next(
        a for a in _parser()._actions if isinstance(a, argparse._SubParsersAction)
    ).choices["solve"]
    for action in solve_parser._actions:
        assert action.help, action.option_strings


def test_solve_free_case_writes_json(tmp_path, capsys):
    out = tmp_path / "sub" / "free.json"
    assert main(["solve", "--case", "free", "--nx", "20", "--ny", "10", "--json", str(out)]) == 0
    stdout = capsys.readouterr().out.strip().splitlines()
    assert len(stdout) == 1 and stdout[0].startswith("free: lambda_c = ")
    data = json.loads(out.read_text())
    for key in REQUIRED:
        assert key in data, key
    assert data["method"] == "free"
    assert data["mesh"] == [20, 10]
    assert data["dofs"] == 3 * 21 * 11  # (w, theta_x, theta_y) at the Q1 nodes
    assert data["eigensolves"] == 1
    # Navier (hard support, m = 2): the MITC4 load is 1.4 % above it on 20x10 (README,
    # "Verification"), and so is k against the Navier coefficient
    # k_RM = 4 / (1 + pi^2 D (m^2/a^2 + 1/b^2) / (kappa G t)) = 3.9204 (a = 0.2, b = 0.1).
    exact, m = navier_load_mindlin(1.0e9, 0.3, 0.006, 0.2, 0.1)
    assert m == 2
    D = 1.0e9 * 0.006**3 / (12 * (1 - 0.3**2))
    G = 1.0e9 / (2 * 1.3)
    k_rm = 4 / (1 + math.pi**2 * D * (4 / 0.2**2 + 1 / 0.1**2) / (5 / 6 * G * 0.006))
    assert data["critical_load_Pa"] == pytest.approx(exact, rel=2e-2)
    assert data["buckling_coefficient_k"] == pytest.approx(k_rm, rel=2e-2)
    assert data["critical_load_Pa"] / exact == pytest.approx(
        data["buckling_coefficient_k"] / k_rm, rel=1e-12
    )


def test_solve_config_file(tmp_path, capsys):
    path = tmp_path / "myplate.toml"
    path.write_text(FREE_TOML)
    out = tmp_path / "o.json"
    assert main(["solve", "--config", str(path), "--json", str(out)]) == 0
    assert capsys.readouterr().out.startswith("myplate: ")
    data = json.loads(out.read_text())
    assert data["case"] == "myplate" and data["mesh"] == [8, 4]
    # --nx/--ny override the file; the file describes the paper's free plate, so the
    # answer is that of --case free on the same mesh.
    out2, out3 = tmp_path / "o2.json", tmp_path / "o3.json"
    mesh = ["--nx", "20", "--ny", "10"]
    assert main(["solve", "--config", str(path), *mesh, "--json", str(out2)]) == 0
    assert main(["solve", "--case", "free", *mesh, "--json", str(out3)]) == 0
    from_file, from_case = (json.loads(o.read_text()) for o in (out2, out3))
    assert from_file["mesh"] == [20, 10]
    assert from_file["critical_load_Pa"] == pytest.approx(from_case["critical_load_Pa"], rel=1e-12)


BAD_TOML = {
    "thickness": ("[plate]\nthickness = 0.0\n", r"plate\.thickness"),
    "nu": ("[material]\nE = 1.0e9\nnu = 0.5\n", r"material\.nu"),
    "rectangle": ("[plate]\ncorners = [[0.1, 0.0], [0.1, 0.05]]\n", r"plate\.corners"),
    "unknown key": ("[mesh]\nnx = 4\nnz = 4\n", r"unknown key\(s\) \['nz'\] in \[mesh\]"),
    "tension": (
        "[edges.left]\nnormal_stress = 1.0\n[edges.right]\nnormal_stress = 1.0\n"
        "[mesh]\nnx = 4\nny = 2\n",
        r"tension everywhere.*normal_stress",
    ),
    "empty zone": (
        "[mesh]\nnx = 20\nny = 10\n[obstacle]\nzone = [[0.001, 0.002], [0.001, 0.002]]\n",
        r"obstacle\.zone .* holds no free mesh node",
    ),
}


@pytest.mark.parametrize("case", list(BAD_TOML))
def test_bad_config_exits_2(case, tmp_path, capsys):
    text, match = BAD_TOML[case]
    path = tmp_path / "bad.toml"
    path.write_text(text)
    out = tmp_path / "bad.json"
    assert main(["solve", "--config", str(path), "--json", str(out)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith("unibuckle: error: ")
    assert re.search(match, captured.err), captured.err
    assert not out.exists()


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (["--nx", "0"], r"mesh\.nx"),
        (["--tau", "0.5"], r"solver\.tau"),
        (["--max-candidates", "0"], r"solver\.max_candidates"),
    ],
)
def test_bad_flag_value_exits_2(args, match, capsys):
    assert main(["solve", "--case", "free", *args]) == 2
    err = capsys.readouterr().err
    assert re.search(match, err), err


def test_missing_config_file_exits_2(tmp_path, capsys):
    assert main(["solve", "--config", str(tmp_path / "nowhere.toml")]) == 2
    assert "nowhere.toml" in capsys.readouterr().err


@pytest.mark.parametrize(
    "args",
    [
        ["solve"],  # neither --case nor --config
        ["solve", "--case", "c4"],
        ["solve", "--case", "free", "--config", "x.toml"],
        ["solve", "--case", "free", "--no-such-flag"],
    ],
)
def test_usage_errors_exit_2(args, capsys):
    with pytest.raises(SystemExit) as exc:
        main(args)
    assert exc.value.code == 2
    assert "usage: unibuckle" in capsys.readouterr().err


def test_console_script_exit_status(tmp_path):
    """The installed script: 2 with the message on stderr for bad input, 0 otherwise."""
    path = tmp_path / "bad.toml"
    path.write_text("[material]\nE = 1.0e9\nnu = -1.0\n")
    bad = run_script("solve", "--config", str(path), cwd=tmp_path)
    assert bad.returncode == 2
    assert "material.nu" in bad.stderr and bad.stdout == ""
    good = run_script("solve", "--case", "free", "--nx", "8", "--ny", "4", cwd=tmp_path)
    assert good.returncode == 0, good.stderr
    assert good.stdout.startswith("free: lambda_c = ")
    assert list(tmp_path.iterdir()) == [path]  # no stray files in the working directory
