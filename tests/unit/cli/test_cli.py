"""Command line: help, JSON output, and bad input (exit status 2, message on stderr).

Most calls run :func:`unibuckle_fenicsx.cli.main` in-process (cheap); one subprocess per
kind of exit checks the installed console script itself.
"""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from support.paths import ROOT
from unibuckle_fenicsx.cli import EXIT_BAD_INPUT, EXIT_NOT_CERTIFIED, EXIT_OK, build_parser, main
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.model.materials import navier_load_mindlin

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
    return subprocess.run([str(SCRIPT), *args], capture_output=True, text=True, env=env, cwd=cwd)


def test_version(tmp_path):
    """``unibuckle --version`` prints the version pyproject.toml declares, and exits 0."""
    import tomllib

    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    out = run_script("--version", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == f"unibuckle {declared}"


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
        "--quiet",
        "--no-certify",
        "--max-iterations",
        "--bound-budget",
        "--enumeration-budget",
    )
    for flag in flags:
        assert flag in sub.stdout, flag
    # A section's file is a problem the command solves: the help says so.
    assert "[section] table" in " ".join(sub.stdout.split())
    # The exit statuses are documented.
    for status in (EXIT_OK, EXIT_BAD_INPUT, EXIT_NOT_CERTIFIED):
        assert f"\n  {status}  " in sub.stdout
    # Every flag is explained: each option of the sub-command carries a help text.
    solve_parser = build_parser()[1]["solve"]
    for action in solve_parser._actions:
        assert action.help, action.option_strings


def test_importing_the_module_entry_point_runs_nothing(monkeypatch):
    """``python -m unibuckle_fenicsx.cli`` runs the CLI; importing the module does not.

    Sphinx's autosummary imports every module: with the call unguarded, the docs build ran
    ``main()`` on Sphinx's own arguments and printed an argparse error.
    """
    import importlib
    import sys

    monkeypatch.setattr(sys, "argv", ["sphinx-build", "html"])
    monkeypatch.delitem(sys.modules, "unibuckle_fenicsx.cli.__main__", raising=False)
    module = importlib.import_module("unibuckle_fenicsx.cli.__main__")  # no SystemExit
    assert callable(module.main)


def test_an_in_process_run_sets_the_callers_logging_back(tmp_path):
    """``main()`` called in-process leaves the root logger as it found it.

    Its handler holds this run's ``sys.stderr``; left installed, a later log record was
    written to a stream closed in between ("I/O operation on closed file").
    """
    import logging

    root = logging.getLogger()
    before = root.handlers[:], root.level
    out = tmp_path / "free.json"
    assert main(["solve", "--case", "free", "--nx", "4", "--ny", "2", "--json", str(out)]) == 0
    assert (root.handlers, root.level) == before


def test_solve_free_case_writes_json(tmp_path, capsys):
    out = tmp_path / "free.json"
    assert main(["solve", "--case", "free", "--nx", "20", "--ny", "10", "--json", str(out)]) == 0
    stdout = capsys.readouterr().out.strip().splitlines()
    assert len(stdout) == 2 and stdout[0].startswith("free: lambda_c = ")
    assert (
        stdout[1] == "  edge stress per unit lambda (tension > 0): left normal -1; right normal -1"
    )
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


@pytest.mark.parametrize("value", ["-1e-3", "-1E-3", "-0.001", "-1.5e+2", "-.5e-1"])
def test_negative_numbers_in_exponent_form_are_values(value, capsys):
    """``--imperfection -1e-3`` is the value -0.001, refused by its range (exit 2).

    argparse took ``-1e-3`` for an option ("expected one argument"); ``-0.001`` worked.
    """
    parser, _ = build_parser()
    args, rest = parser.parse_known_args(["nonlinear", "--case", "c1", "--imperfection", value])
    assert args.imperfection == float(value) and rest == []
    assert main(["nonlinear", "--case", "c1", "--imperfection", value]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert f"--imperfection must lie in (0, 1], got {float(value)!r}" in err, err
    # A PETSc option's negative value still goes to PETSc, in its place.
    _, rest = parser.parse_known_args(["solve", "--case", "c1", "-unibuckle_eps_target", value])
    assert rest == ["-unibuckle_eps_target", value]


def test_set_changes_the_value_at_its_dotted_path():
    """--set PATH=VALUE changes that value of the problem, read as the kind found there."""
    from unibuckle_fenicsx.cli.problem import spec_from_args
    from unibuckle_fenicsx.spec.cases import paper_case

    parser, _ = build_parser()
    args = parser.parse_args(
        ["solve", "--case", "c1", "--set", "solver.tau=1e-9", "--set", "solver.method=penalty"]
    )
    spec = spec_from_args(args)
    assert spec.solver.tau == 1e-9 and spec.solver.method == "penalty"
    assert paper_case("c1").solver.tau != 1e-9  # the value was changed, not already there
    assert spec.plate == paper_case("c1").plate  # and nothing else


@pytest.mark.parametrize(
    ("flags", "setting", "named"),
    [
        (["--nx", "6"], "mesh.nx=8", "--nx and --set mesh.nx=8 both set mesh.nx"),
        (["--ny", "4"], "mesh={nx = 8, ny = 2}", "--ny and --set mesh={nx"),
        (["--tau", "1e-9"], "solver.tau=1e-8", "--tau and --set solver.tau=1e-8"),
        (["--method", "penalty"], "solver.method=active-set", "--method and --set solver"),
        (["--penalty", "1e4"], "solver.penalty=1e5", "--penalty and --set solver.penalty"),
        (["--no-certify"], "solver.certify=true", "--no-certify and --set solver.certify"),
        (["--bracket"], "solver.bracket=false", "--bracket and --set solver.bracket"),
        (["--set", "solver.tau=1e-9"], "solver.tau=1e-7", "--set solver.tau=1e-9 and --set"),
    ],
)
def test_a_flag_and_set_on_the_same_key_are_refused(capsys, flags, setting, named):
    """A value given by a flag and by --set is refused, naming both, before any solve.

    Before, the flag was taken in silence (``--nx 6 --set mesh.nx=8`` solved 6 cells),
    and of one path set twice the last.
    """
    argv = ["solve", "--case", "c1", *flags, "--set", setting]
    assert main(argv) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert named in err and "give one of them" in err, err
    assert "lambda_c" not in err


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (["--method", "penalty", "--penalty", "1e-30"], "--penalty: solver.penalty"),
        (["--method", "penalty", "--set", "solver.penalty=1e17"], "--set solver.penalty=1e17"),
    ],
)
def test_a_penalty_out_of_its_measured_range_is_refused_before_solving(capsys, argv, named):
    """solver.penalty outside [1e-6, 1e16] is refused, naming the key and the range.

    The range is the one docs/methods/penalty.md measured: below 1e-6 the springs raise
    the free load by less than 3e-4 of it; before, 1e-30 was solved and failed its
    certificate (exit 3). The ends themselves are taken.
    """
    from unibuckle_fenicsx.spec import SolverSpec

    assert main(["solve", "--case", "c1", *argv]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert named in err and "solver.penalty must lie in [1e-06, 1e+16]" in err, err
    assert "lambda_c" not in err
    assert SolverSpec(penalty=1e-6).penalty == 1e-6 and SolverSpec(penalty=1e16).penalty == 1e16


def test_the_petsc_eps_tol_is_the_solver_eps_tol_it_overrides(tmp_path):
    """``-unibuckle_eps_tol`` sets solver.eps_tol: the result records the tolerance used.

    SLEPc takes the command line's option over the file's key; before, the result's
    ``input`` said 1e-10 (the default) after solves to 1e-6. With ``--set
    solver.eps_tol`` it is refused, naming both; out of the key's range, named too.
    (A subprocess: PETSc reads its command line once per process.)
    """
    out = tmp_path / "free.json"
    base = ["solve", "--case", "free", "--nx", "4", "--ny", "2", "-q"]
    done = run_script(*base, "-unibuckle_eps_tol", "1e-6", "--json", str(out), cwd=tmp_path)
    assert done.returncode == EXIT_OK, done.stderr
    assert json.loads(out.read_text())["input"]["solver"]["eps_tol"] == 1e-6
    both = run_script(*base, "-unibuckle_eps_tol", "1e-6", "--set", "solver.eps_tol=1e-8",
                      cwd=tmp_path)  # fmt: skip
    assert both.returncode == EXIT_BAD_INPUT
    assert "-unibuckle_eps_tol and --set solver.eps_tol=1e-8 both set" in both.stderr
    loose = run_script(*base, "-unibuckle_eps_tol", "1e-2", cwd=tmp_path)
    assert loose.returncode == EXIT_BAD_INPUT
    assert "-unibuckle_eps_tol: solver.eps_tol must lie in (0, 0.0001]" in loose.stderr


@pytest.mark.parametrize(
    ("name", "text", "start"),
    [
        ("empty.toml", "", "holds no table or key"),
        ("comments.toml", "# a plate\n\n", "holds no table or key"),
        ("p.json", "{}", "holds no table or key"),
        # Top-level keys alone (name, units: the schema's only keys that are no table).
        ("units.toml", 'units = "SI"\n', "holds no table, only the top-level key(s) units = 'SI':"),
        (
            "named.toml",
            '# a plate\nname = "x"\nunits = "mm-N-MPa"\n',
            "holds no table, only the top-level key(s) name = 'x', units = 'mm-N-MPa':",
        ),
        (
            "units.json",
            '{"units": "SI"}',
            "holds no table, only the top-level key(s) units = 'SI':",
        ),
    ],
)
@pytest.mark.parametrize("command", ["solve", "sweep", "nonlinear"])
def test_a_problem_file_without_a_table_is_refused_at_read(tmp_path, capsys, nothing_built, name,
                                                           text, start, command):  # fmt: skip
    """A problem file with no table is refused: exit 2, no solve.

    Empty, comments only, or only the top-level ``name`` and ``units``: every key has a
    default, and before, such a file solved the default plate (the paper's 0.2 x 0.1 m,
    exit 0) in silence. Expected: the
    message names the file, the keys it holds, and what is missing (a table: [plate] or
    [section]), before any mesh.
    """
    path = tmp_path / name
    path.write_text(text)
    args = {
        "solve": ["solve"],
        "sweep": ["sweep", "--vary", "plate.thickness=0.006", "--json", str(tmp_path / "k")],
        "nonlinear": ["nonlinear"],
    }[command]
    assert main([*args, "--config", str(path)]) == EXIT_BAD_INPUT
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith(f"unibuckle: error: {path}: {start}"), captured.err
    assert "needs at least one table, e.g. [plate]" in captured.err and "[section]" in captured.err


def test_the_top_level_scalars_are_the_schemas():
    """The keys the refusal above allows alone are the schema's top-level non-table keys.

    Read from ``schema/unibuckle-problem.schema.json``: the top-level properties of a plate's
    and a section's problem that are neither a table (``$ref``, object) nor an array.
    """
    import json
    from pathlib import Path

    from unibuckle_fenicsx.spec.files import TOP_LEVEL_SCALARS

    root = Path(__file__).resolve().parents[3]
    schema = json.loads((root / "schema" / "unibuckle-problem.schema.json").read_text())

    def is_table(prop):
        kinds = [prop, *prop.get("anyOf", [])]
        return any("$ref" in k or k.get("type") in ("object", "array") for k in kinds)

    scalars = {
        key
        for spec in ("ProblemSpec", "SectionProblemSpec")
        for key, prop in schema["$defs"][spec]["properties"].items()
        if not is_table(prop)
    }
    assert scalars == set(TOP_LEVEL_SCALARS) == {"name", "units"}


def test_set_reads_a_string_as_toml_writes_it():
    """``--set solver.method="penalty"`` (the file's line, quotes and all) sets ``penalty``.

    The quotes were kept as part of the value, which the schema then refused; TOML's basic
    and literal strings are both read, and a bare word too.
    """
    from unibuckle_fenicsx.cli.problem import spec_from_args

    parser, _ = build_parser()
    for text in ('"penalty"', "'penalty'", "penalty"):
        args = parser.parse_args(["solve", "--case", "c1", "--set", f"solver.method={text}"])
        assert spec_from_args(args).solver.method == "penalty", text
    box = str(ROOT / "demos" / "box.toml")  # a section file's string, a literal string
    args = parser.parse_args(["solve", "--config", box, "--set", "name='a box'"])
    assert spec_from_args(args).name == "a box"


def test_set_adds_a_key_the_file_leaves_out():
    """--set adds an optional key a problem file may hold: a table, a list, a number.

    ``demos/box.toml`` has no ``[design]`` and no ``obstacle.span``; the values are the
    file's units (SI).
    """
    from unibuckle_fenicsx.cli.problem import spec_from_args

    parser, _ = build_parser()
    box = str(ROOT / "demos" / "box.toml")
    args = parser.parse_args(
        ["solve", "--config", box, "--set", "design.yield_stress=3.55e8",
         "--set", "obstacle.span=0.05,0.15", "--set", "mesh.levels=0"]
    )  # fmt: skip
    spec = spec_from_args(args)
    assert spec.design is not None and spec.design.yield_stress == 3.55e8
    assert spec.obstacle.span == (0.05, 0.15) and spec.mesh.levels == 0
    # The list as a TOML file writes it is read too (it said "'[0.05' is not a number").
    args = parser.parse_args(["solve", "--config", box, "--set", "obstacle.span=[0.05, 0.15]"])
    assert spec_from_args(args).obstacle.span == (0.05, 0.15)
    # A key no problem file has is still refused naming the keys there.
    bad = parser.parse_args(["solve", "--config", box, "--set", "obstacle.spam=1"])
    with pytest.raises(InputError, match=r"--set obstacle\.spam: obstacle has no key 'spam'"):
        spec_from_args(bad)
    # A value the schema refuses names the key.
    bad = parser.parse_args(["solve", "--config", box, "--set", "obstacle.span=0.2,0.1"])
    with pytest.raises(InputError, match=r"obstacle\.span"):
        spec_from_args(bad)


def test_set_repairs_a_file_its_checks_refuse(tmp_path):
    """--set applies to a file that fails a check, so that the setting can repair it.

    The file was checked before the setting was applied: a plate too thick for the
    plate model's check (t/b <= 0.5, b = 0.1 m) stayed refused with
    ``--set plate.thickness=0.006``.
    """
    from unibuckle_fenicsx.cli.problem import spec_from_args

    path = tmp_path / "thick.toml"
    path.write_text(FREE_TOML.replace("0.006", "0.08"))
    parser, _ = build_parser()
    with pytest.raises(InputError, match=r"thick\.toml: .*thickness"):
        spec_from_args(parser.parse_args(["solve", "--config", str(path)]))
    args = parser.parse_args(["solve", "--config", str(path), "--set", "plate.thickness=0.006"])
    assert spec_from_args(args).plate.thickness == 0.006
    # A setting that does not repair it names the file, the setting and what is wrong.
    worse = parser.parse_args(["solve", "--config", str(path), "--set", "plate.thickness=0.07"])
    refused = r"thick\.toml: with --set plate\.thickness=0\.07: .*thickness"
    with pytest.raises(InputError, match=refused):
        spec_from_args(worse)
    # A setting that cannot be applied to the file as written: the file's own error.
    other = parser.parse_args(["solve", "--config", str(path), "--set", "mesh.spam=1"])
    with pytest.raises(InputError, match=r"thick\.toml: .*thickness") as refused:
        spec_from_args(other)
    assert "--set" not in str(refused.value)


@pytest.mark.parametrize(
    ("setting", "match"),
    [
        ("solver.nope=1", r"--set solver\.nope: solver has no key 'nope'"),
        ("solver.tau=abc", r"--set solver\.tau: 'abc' is not a number"),
        ("solver.tau", r"--set 'solver\.tau': give PATH=VALUE"),
        ("solver.tau=0.5", r"solver\.tau"),  # the schema's range
    ],
)
def test_bad_set_exits_2_naming_it(setting, match, capsys, no_solve):
    assert main(["solve", "--case", "free", "--set", setting]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert re.search(match, err), err


def test_nonlinear_flag_defaults_are_the_options_defaults():
    """The nonlinear flags' defaults are NonlinearOptions' and its choices the package's.

    The parser reads them from the Struct's module, which imports no DOLFINx.
    """
    import msgspec

    from unibuckle_fenicsx.cli.flags import NONLINEAR_FLAGS
    from unibuckle_fenicsx.nonlinear import CONTROLS, SHAPES, NonlinearOptions

    fields = {f.name: f.default for f in msgspec.structs.fields(NonlinearOptions)}
    parser, _ = build_parser()
    args = parser.parse_args(["nonlinear", "--case", "c1"])
    assert {k: getattr(args, k) for k in NONLINEAR_FLAGS} == {k: fields[k] for k in NONLINEAR_FLAGS}
    choices = {
        a.dest: tuple(a.choices)
        for sub in parser._subparsers._group_actions[0].choices.values()
        for a in sub._actions
        if a.choices
    }
    assert choices["shape"] == SHAPES and choices["control"] == CONTROLS


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


def test_unknown_flag_after_solve_shows_the_solve_usage(capsys):
    with pytest.raises(SystemExit):
        main(["solve", "--case", "free", "--no-such-flag"])
    err = capsys.readouterr().err
    assert "usage: unibuckle solve" in err and "--no-such-flag" in err


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
    assert "Traceback" not in bad.stderr + good.stderr
    assert list(tmp_path.iterdir()) == [path]  # no stray files in the working directory


# -- input a user can trust: refused early, with the parameter or file named --------------
@pytest.fixture
def no_solve(monkeypatch):
    """Fail the test if a solve starts: bad input must be refused before any work."""
    import unibuckle_fenicsx.analysis

    def refuse(*args, **kwargs):
        raise AssertionError("the solve started")

    monkeypatch.setattr(unibuckle_fenicsx.analysis, "solve", refuse)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ('[solver]\ncomplete = "false"\n', r"solver\.complete must be true or false"),
        ('[material]\nE = "abc"\nnu = 0.3\n', r"material\.E must be a number, got 'abc'"),
        ('[plate]\nthickness = "thin"\n', r"plate\.thickness must be a number"),
        ('[solver]\nmax_candidates = "many"\n', r"solver\.max_candidates must be an integer"),
        ("[plate\n", r"invalid TOML"),
        ("[obstacle]\n", r"\[obstacle\] needs zone"),
    ],
)
def test_bad_file_exits_2_naming_key_and_file(tmp_path, capsys, no_solve, text, match):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    assert main(["solve", "--config", str(path)]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert re.search(match, err) and str(path) in err, err
    assert "Traceback" not in err


@pytest.mark.parametrize("flag", ["--json", "--output"])
def test_unwritable_output_is_refused_before_solving(tmp_path, capsys, no_solve, flag):
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    target = blocker / "sub" / ("out.json" if flag == "--json" else "vtx")
    assert main(["solve", "--case", "c1", flag, str(target)]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert f"{flag}: {blocker} is not a directory" in err, err


def test_one_cell_and_huge_meshes_are_refused(capsys, monkeypatch):
    """--nx 1 names mesh.nx; a 100000 x 100000 mesh is refused with its memory estimate."""
    import unibuckle_fenicsx.model.build as build_module

    assert main(["solve", "--case", "free", "--nx", "1"]) == EXIT_BAD_INPUT
    assert "mesh.nx must be an integer >= 2" in capsys.readouterr().err

    def no_mesh(*args, **kwargs):
        raise AssertionError("the mesh was built")

    monkeypatch.setattr(build_module, "build_plate_mesh", no_mesh)
    assert main(["solve", "--case", "free", "--nx", "100000", "--ny", "100000"]) == 2
    err = capsys.readouterr().err
    assert "30,000,600,003 DOFs" in err and "GB" in err and "available" in err, err


def test_plate_far_from_the_origin(tmp_path, capsys):
    """Translation invariance: the plate at (1000, 2000) m has the load of the one at 0."""
    loads = []
    for corners in ("[[1000.0, 2000.0], [1000.2, 2000.1]]", "[[0.0, 0.0], [0.2, 0.1]]"):
        path = tmp_path / "plate.toml"
        path.write_text(f"[plate]\ncorners = {corners}\n[mesh]\nnx = 20\nny = 10\n")
        out = tmp_path / "out.json"
        assert main(["solve", "--config", str(path), "--json", str(out)]) == EXIT_OK
        loads.append(json.loads(out.read_text())["critical_load_Pa"])
    assert loads[0] == pytest.approx(loads[1], rel=1e-9)


def test_mm_file_prints_mpa_and_solves_the_same_problem(tmp_path, capsys):
    path = tmp_path / "mm.toml"
    path.write_text(
        'units = "mm-N-MPa"\n[plate]\ncorners = [[-100.0, -50.0], [100.0, 50.0]]\n'
        "thickness = 6.0\n[material]\nE = 1000.0\nnu = 0.3\n[mesh]\nnx = 8\nny = 4\n"
    )
    out_mm, out_si = tmp_path / "mm.json", tmp_path / "si.json"
    assert main(["solve", "--config", str(path), "--json", str(out_mm)]) == EXIT_OK
    line = capsys.readouterr().out.splitlines()[0]
    assert re.search(r"lambda_c = 1\.\d+e\+01 MPa", line), line
    assert main(["solve", "--case", "free", "--nx", "8", "--ny", "4", "--json", str(out_si)]) == 0
    mm, si = (json.loads(p.read_text()) for p in (out_mm, out_si))
    assert mm["units"] == "mm-N-MPa" and mm["input"]["units"] == "SI"
    assert mm["critical_load_Pa"] == pytest.approx(si["critical_load_Pa"], rel=1e-12)
    # Re-run from the JSON: the file's units again (the same load in MPa, 1e-6 x Pa).
    rerun = tmp_path / "rerun.json"
    capsys.readouterr()
    assert main(["solve", "--config", str(out_mm), "--json", str(rerun)]) == EXIT_OK
    again = capsys.readouterr().out.splitlines()[0]
    assert re.search(r"lambda_c = 1\.\d+e\+01 MPa", again), again
    assert json.loads(rerun.read_text())["units"] == "mm-N-MPa"
    assert json.loads(rerun.read_text())["critical_load_Pa"] == mm["critical_load_Pa"]


def test_options_that_do_not_apply_are_named(capsys):
    args = ["solve", "--case", "c2", "--nx", "8", "--ny", "4", "--method", "active-set"]
    assert main([*args, "--complete", "--until-proven", "--penalty", "5"]) == EXIT_OK
    err = capsys.readouterr().err
    for flag in ("--complete", "--until-proven", "--penalty"):
        assert re.search(rf"warning: {flag} \(applies to --method \w+\) is ignored", err), err


def test_options_that_auto_does_not_use_are_named(capsys):
    """Under auto an enumeration flag waits for auto's choice; the file's method counts.

    c2 at 8x4 has i = 3 (8 candidate sets): max_candidates = 4 makes auto choose the
    active set, which leaves --complete unused; a method set in the problem (here by
    --set) makes --complete inapplicable before the solve, as --method would.
    """
    args = ["solve", "--case", "c2", "--nx", "8", "--ny", "4", "--complete", "-q"]
    assert main([*args, "--set", "solver.max_candidates=4"]) == EXIT_OK
    err = capsys.readouterr().err
    assert re.search(
        r"warning: --complete \(applies to --method enumerate\) was not used: "
        r"auto chose active-set \(2\^3 = 8 candidate sets",
        err,
    ), err
    assert main([*args, "--set", "solver.method=active-set"]) == EXIT_OK
    err = capsys.readouterr().err
    assert (
        "warning: --complete (applies to --method enumerate) is ignored with --method active-set"
        in err
    ), err
    assert main(args) == EXIT_OK  # auto enumerates: --complete applies, no warning
    assert "warning" not in capsys.readouterr().err


def test_the_help_states_the_schemas_ranges_and_inputs():
    """The solver flags' ranges in the help are the schema's; sweep reads a result JSON too.

    ``--tau``'s help said (0, 0.01], while ``solver.tau`` (``--tau`` sets it) allows
    [1e-12, 0.01] (``schema/unibuckle-problem.schema.json``: minimum 1e-12, inclusive) and
    refuses 1e-13. ``sweep --config`` said "(TOML)" while it reads a result JSON's input,
    as ``solve --config`` does (``load_problem``).
    """
    import json

    schema = json.loads((ROOT / "schema" / "unibuckle-problem.schema.json").read_text())
    solver = schema["$defs"]["SolverSpec"]["properties"]
    _, commands = build_parser()
    helps = {
        a.option_strings[0]: " ".join(a.help.split())
        for a in commands["solve"]._actions
        if a.option_strings and a.help
    }
    ranges = {  # flag: its key, and the range its help states
        "--tau": ("tau", r"in \[(\S+), (\S+)\]"),
        "--penalty": ("penalty", r"(\S+) to (\S+) \("),
    }
    for flag, (key, pattern) in ranges.items():
        stated = re.search(pattern, helps[flag])
        assert stated, helps[flag]
        bounds = (solver[key]["minimum"], solver[key]["maximum"])
        assert tuple(map(float, stated.groups())) == bounds, flag
    for flag, key in (("--max-candidates", "max_candidates"), ("--bound-budget", "bound_budget"),
                      ("--max-iterations", "max_iterations")):  # fmt: skip
        assert f"N >= {solver[key]['minimum']}" in helps[flag], flag
    sweep = {a.option_strings[0]: a.help for a in commands["sweep"]._actions if a.option_strings}
    assert "result JSON" in sweep["--config"] and "TOML" in sweep["--config"]


def test_nonlinear_help_names_only_its_own_flags(capsys):
    """The nonlinear help names no --output (it writes no fields).

    An unknown flag is reported with the nonlinear usage line, not the top-level one.
    """
    nonlinear = build_parser()[1]["nonlinear"]
    assert "--output" not in nonlinear.format_help()
    with pytest.raises(SystemExit) as exit_:
        main(["nonlinear", "--case", "c1", "--output", "x"])
    assert exit_.value.code == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert (
        err.startswith("usage: unibuckle nonlinear") and "unrecognized arguments: --output" in err
    )


def test_candidate_parallel_under_auto_enumerates(capsys):
    """--candidate-parallel with no method: auto runs the enumeration (i = 3 here)."""
    assert main(["solve", "--case", "c2", "--nx", "8", "--ny", "4", "--candidate-parallel"]) == 0
    assert "method enumerate" in capsys.readouterr().out
    assert main(["solve", "--case", "c1", "--candidate-parallel"]) == EXIT_BAD_INPUT
    assert "--candidate-parallel runs the enumeration" in capsys.readouterr().err


def test_progress_lines_and_quiet(capsys):
    """Enumeration reports each size p on stderr; -q keeps stderr empty."""
    args = ["solve", "--case", "c2", "--nx", "8", "--ny", "4", "--method", "enumerate"]
    assert main([*args, "--until-proven"]) == EXIT_OK
    err = capsys.readouterr().err
    assert "enumeration p = 0 done: 1 sets" in err and "enumeration p = 1 done: 3 sets" in err
    assert main([*args, "--until-proven", "-q"]) == EXIT_OK
    assert capsys.readouterr().err == ""


def test_json_says_what_it_solved_and_reruns(tmp_path, capsys):
    """The JSON holds input, versions and why auto chose; --config on it gives the same load."""
    out, again = tmp_path / "c2.json", tmp_path / "again.json"
    assert main(["solve", "--case", "c2", "--nx", "8", "--ny", "4", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["input"]["mesh"] == {"nx": 8, "ny": 4}
    assert data["input"]["obstacle"] == {
        "zone": [[-0.04, 0.04], [-0.02, 0.02]],
        "side": "above",
        "gap": 0.0,
    }
    assert data["input"]["solver"]["tau"] == 1e-8  # defaults included
    for key in ("unibuckle_fenicsx", "dolfinx", "PETSc", "SLEPc", "python"):
        assert key in data["versions"], key
    assert data["method"] == "enumerate"
    assert data["method_chosen_by"].startswith("auto: 2^3 = 8 candidate sets")
    assert main(["solve", "--config", str(out), "--json", str(again)]) == EXIT_OK
    rerun = json.loads(again.read_text())
    assert rerun["critical_load_Pa"] == data["critical_load_Pa"]
    assert rerun["contact_indices"] == data["contact_indices"]


def test_output_is_readable_by_pyvista(tmp_path, capsys):
    """--output writes VTK (.pvd) next to the VTX (.bp) files; pyvista reads the fields."""
    pv = pytest.importorskip("pyvista")
    args = ["solve", "--case", "c2", "--nx", "8", "--ny", "4", "--output", str(tmp_path / "o")]
    assert main(args) == EXIT_OK
    mesh = pv.read(tmp_path / "o" / "c2.pvd")
    block = mesh[0] if isinstance(mesh, pv.MultiBlock) else mesh
    for name in ("w", "w_free", "obstacle_zone", "contact", "theta"):
        assert name in block.point_data, name
    assert np.abs(block.point_data["w"]).max() == pytest.approx(1.0)


#: Pure shear on a mesh with one row of free nodes (clamped bottom and top, ny = 2): the
#: contributions of b(w, w) above and below the row cancel, B vanishes identically.
NO_BUCKLING_TOML = """\
name = "shear_one_row"
[plate]
corners = [[0.0, 0.0], [0.3, 0.1]]
thickness = 1e-3
[edges.left]
shear_stress = 1.0
[edges.right]
shear_stress = 1.0
[edges.bottom]
support = "clamped"
shear_stress = -1.0
[edges.top]
support = "clamped"
shear_stress = -1.0
[mesh]
nx = 6
ny = 2
"""

#: Compression along x, tension along y, whole-plate obstacle on a 6x3 mesh: every
#: contact set's mode crosses the obstacle (checked by enumerating all 2^10 sets).
BLOCKED_TOML = """\
name = "blocked"
[plate]
corners = [[0.0, 0.0], [0.5, 0.1]]
thickness = 7.4e-5
[material]
E = 1.0e9
nu = 0.44
[edges.left]
normal_stress = -0.5
[edges.right]
normal_stress = -0.5
[edges.bottom]
support = "clamped"
normal_stress = 0.3
[edges.top]
support = "simply_supported_soft"
normal_stress = 0.3
[mesh]
nx = 6
ny = 3
[obstacle]
zone = "all"
"""


def test_no_buckling_load_exits_2(tmp_path, capsys):
    """A load that buckles nothing on this mesh: refused, not 1/round-off as a load."""
    path = tmp_path / "p.toml"
    path.write_text(NO_BUCKLING_TOML)
    assert main(["solve", "--config", str(path)]) == EXIT_BAD_INPUT
    assert "no positive buckling load" in capsys.readouterr().err


@pytest.mark.parametrize("method", ["enumerate", "active-set"])
def test_no_admissible_mode_exits_3(method, tmp_path, capsys):
    """No contact set has an admissible mode: exit 3 with the lower bound, no traceback."""
    path = tmp_path / "p.toml"
    path.write_text(BLOCKED_TOML)
    out = tmp_path / "r.json"
    args = ["solve", "--config", str(path), "--method", method, "--json", str(out)]
    assert main(args) == EXIT_NOT_CERTIFIED
    err = capsys.readouterr().err
    assert "no admissible mode with a finite load" in err and "lambda_free" in err
    assert not out.exists()


def test_set_gives_either_form_of_a_key_that_takes_both(tmp_path):
    """A stress, a temperature or a zone takes a number (a string) or a list, as the file may.

    ``edges.left.normal_stress = -1`` set to ``[-1, 0]`` said "'[-1, 0]' is not a number",
    the pair set back to ``-1`` "is a table or a list", and ``obstacle.zone = "all"``
    set to a box "must be "all" or [[xmin, xmax], [ymin, ymax]], got '[[0, 0.1], ...]'".
    The values expected are those given.
    """
    from unibuckle_fenicsx.cli.problem import spec_from_args

    path = tmp_path / "p.toml"
    path.write_text(
        "[plate]\ncorners = [[0.0, 0.0], [0.3, 0.1]]\nthickness = 0.002\n"
        "[material]\nE = 2.1e11\nnu = 0.3\nthermal_expansion = 1.2e-5\n"
        "[edges.left]\nnormal_stress = -1.0\n[edges.right]\nnormal_stress = [-1.0, 0.0]\n"
        '[edges.bottom]\ninplane = "roller"\n[edges.top]\n'
        "[mesh]\nnx = 6\nny = 2\n[load]\ntemperature = 0.0\n"
        '[obstacle]\nzone = "all"\n'
    )
    parser, _ = build_parser()

    def spec(*settings):
        sets = [arg for s in settings for arg in ("--set", s)]
        return spec_from_args(parser.parse_args(["solve", "--config", str(path), *sets]))

    got = spec("edges.left.normal_stress=[-1, 0]", "edges.right.normal_stress=-1")
    edges = {e.name: e for e in got.plate.edges}
    assert edges["left"].normal_stress == (-1.0, 0.0) and edges["right"].normal_stress == -1.0
    got = spec("edges.left.normal_stress=-1,-0.5", "edges.right.normal_stress=[-1, -0.5]")
    assert all(e.normal_stress == (-1.0, -0.5) for e in got.plate.edges[:2])
    assert spec("load.temperature=[1, 2, 3]").load.temperature == (1.0, 2.0, 3.0)
    box = spec("obstacle.zone=[[0, 0.1], [0, 0.05]]").obstacle.zone
    assert box == ((0.0, 0.1), (0.0, 0.05))
    # A list where the key takes none is refused by the schema, naming the key.
    with pytest.raises(InputError, match=r"plate\.thickness"):
        spec("plate.thickness=[0.001, 0.002]")
    with pytest.raises(InputError, match=r"--set edges\.left\.normal_stress: .*not a list"):
        spec("edges.left.normal_stress=[-1, x]")
    with pytest.raises(InputError, match=r"not a list of finite numbers"):
        spec("edges.left.normal_stress=[-1, nan]")
