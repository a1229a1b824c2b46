"""A demanding user's command lines: nothing lost, nothing wrong, nothing outside its folder.

Outputs that cannot be written are refused before anything is solved (and nothing is
created that was not asked for); a bad PETSc option, Ctrl-C and an unreadable file give a
message, not a traceback; a problem's name writes nowhere but the output folder; a
mechanism, a tangent or tiny hole and a plate too thick for the plate model are refused
naming their keys; an incomplete nonlinear path says what it validated.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from mpi4py import MPI

import numpy as np
import pytest

from support.paths import ROOT
from support.processes import mpiexec, paused_sweep
from unibuckle_fenicsx.cli import (
    EXIT_BAD_INPUT,
    EXIT_INTERRUPTED,
    EXIT_NOT_CERTIFIED,
    EXIT_OK,
    main,
)
from unibuckle_fenicsx.cli.solve import RESOLUTION_WARNING, resolution_note
from unibuckle_fenicsx.results.assemble import versions
from unibuckle_fenicsx.results.files import file_stem
from unibuckle_fenicsx.spec import problem_from_dict
from unibuckle_fenicsx.spec.plate import MAX_THICKNESS_RATIO, THICK_PLATE_RATIO

SCRIPT = Path(sys.executable).parent / "unibuckle"
serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="runs its own processes")

SMALL = """\
[plate]
corners = [[0.0, 0.0], [0.2, 0.1]]
thickness = 0.006
[mesh]
nx = 8
ny = 4
"""


def run_script(*args: str, cwd: Path, **kwargs) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    return subprocess.run(
        [str(SCRIPT), *args], capture_output=True, text=True, env=env, cwd=cwd, **kwargs
    )


# -- outputs -------------------------------------------------------------------------------
def _output_cases(tmp: Path) -> list[tuple[list[str], str]]:
    blocker = tmp / "a_file"
    blocker.write_text("")
    (tmp / "results.json").mkdir()
    return [
        (["--json", "/proc/nonexistent/o.json"], "--json: the folder /proc/nonexistent does not"),
        (["--json", "/proc/o.json"], "--json: cannot create /proc/o.json"),
        (["--output", "/proc/nope"], "--output: cannot create /proc/nope"),
        (["--json", str(tmp / "missing" / "o.json")], f"the folder {tmp / 'missing'} does not"),
        (["--output", str(tmp / "missing" / "vtx")], f"the folder {tmp / 'missing'} does not"),
        (["--json", str(blocker / "o.json")], f"--json: {blocker} is not a directory"),
        (["--output", str(blocker)], f"--output: {blocker} is not a directory"),
        (["--json", str(tmp / "results.json")], "is a directory; give a file name"),
    ]


@pytest.mark.parametrize("command", ["solve", "nonlinear", "sweep"])
def test_unwritable_outputs_are_refused_at_once(
    tmp_path, capsys, nothing_built, monkeypatch, command
):
    """Exit 2 before anything is built (PETSc not even started), no folder created."""
    import unibuckle_fenicsx.cli as cli

    def no_run(*args, **kwargs):
        raise AssertionError("PETSc was started before the output was refused")

    monkeypatch.setattr(cli, "run_command", no_run)
    config = tmp_path / "plate.toml"
    config.write_text(SMALL)
    before = sorted(tmp_path.rglob("*"))
    for args, message in _output_cases(tmp_path):
        if command != "solve" and args[0] == "--output":
            continue
        head = {
            "solve": ["solve", "--case", "c1", "--nx", "320", "--ny", "160"],
            "nonlinear": ["nonlinear", "--case", "c1"],
            "sweep": ["sweep", "--config", str(config), "--vary", "plate.thickness=0.005,0.006"],
        }[command]
        assert main([*head, *args]) == EXIT_BAD_INPUT, args
        err = capsys.readouterr().err
        assert message in err and "Traceback" not in err, (args, err)
    after = sorted(tmp_path.rglob("*"))
    assert after == sorted({*before, tmp_path / "a_file", tmp_path / "results.json"})
    assert not Path("/proc/nonexistent").exists()


#: ``unibuckle`` run by its console script, reporting which of the heavy modules it loaded.
LOADED = """
import sys
from unibuckle_fenicsx.cli import main

status = main(sys.argv[1:])
heavy = ("petsc4py.PETSc", "slepc4py.SLEPc", "dolfinx", "ufl", "basix")
print("loaded:", [name for name in heavy if name in sys.modules], file=sys.stderr)
sys.exit(status)
"""


@serial
def test_the_console_script_refuses_an_unwritable_json_before_loading_petsc(tmp_path):
    """The command of the report: 30 s of solving, then a traceback; now exit 2 at once.

    "At once" is checked by what ran, not by the clock: the console script exits 2 with
    the message, and the same command line (run as the console script runs it) has
    loaded neither PETSc, SLEPc nor DOLFINx when it exits.
    """
    args = ["solve", "--case", "c1", "--nx", "320", "--ny", "160"]
    script = tmp_path / "loaded.py"
    script.write_text(LOADED)
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    for extra in (["--json", "/proc/nonexistent/o.json"], ["--output", "/proc/nope"]):
        proc = run_script(*args, *extra, cwd=tmp_path)
        assert proc.returncode == EXIT_BAD_INPUT, proc.stderr
        assert proc.stderr.startswith(f"unibuckle: error: {extra[0]}: "), proc.stderr
        assert "Traceback" not in proc.stderr
        probe = subprocess.run(
            [sys.executable, str(script), *args, *extra], capture_output=True, text=True,
            env=env, cwd=tmp_path,
        )  # fmt: skip
        assert probe.returncode == EXIT_BAD_INPUT, probe.stderr
        assert "loaded: []" in probe.stderr, probe.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["loaded.py"]


def test_json_into_an_existing_folder_and_output_creating_one(tmp_path, capsys):
    """What is allowed: --json in an existing folder, --output creating its own folder."""
    out = tmp_path / "o.json"
    vtx = tmp_path / "vtx"
    args = ["solve", "--case", "free", "--nx", "8", "--ny", "4"]
    assert main([*args, "--json", str(out), "--output", str(vtx)]) == EXIT_OK
    assert json.loads(out.read_text())["method"] == "free"
    names = {p.name for p in vtx.iterdir()}
    assert {"free_w.bp", "free_theta.bp", "free.pvd"} <= names
    assert all(name.startswith("free") for name in names), names
    assert {p.name for p in tmp_path.iterdir()} == {"o.json", "vtx"}  # no probe left
    capsys.readouterr()


# -- PETSc options, Ctrl-C -------------------------------------------------------------------
@serial
@pytest.mark.parametrize(
    ("option", "reason"),
    [
        (["-unibuckle_st_type", "nonsense"], "Unable to find requested ST type nonsense"),
        (["-unibuckle_st_shift", "abc"], "Input string abc has no numeric value"),
    ],
)
def test_bad_petsc_option_exit_2(tmp_path, option, reason):
    proc = run_script("solve", "--case", "c1", "--nx", "8", "--ny", "4", *option, cwd=tmp_path)
    assert proc.returncode == EXIT_BAD_INPUT, proc.stderr
    assert "Traceback" not in proc.stderr and proc.stdout == ""
    assert "PETSc/SLEPc refused an option" in proc.stderr and reason in proc.stderr
    assert " ".join(option) in proc.stderr


@serial
def test_a_bad_eps_tol_option_is_refused_before_petsc(tmp_path):
    """``-unibuckle_eps_tol`` is ``solver.eps_tol``'s: the package reads and refuses it."""
    args = ("solve", "--case", "c1", "--nx", "8", "--ny", "4", "-unibuckle_eps_tol", "abc")
    proc = run_script(*args, cwd=tmp_path)
    assert proc.returncode == EXIT_BAD_INPUT, proc.stderr
    assert proc.stdout == ""
    assert proc.stderr == "unibuckle: error: -unibuckle_eps_tol takes a number, got 'abc'\n"


@serial
@pytest.mark.parametrize("command", ["sweep", "nonlinear"])
def test_sweep_and_nonlinear_check_and_record_the_eps_tol_option(tmp_path, command):
    """``-unibuckle_eps_tol`` is ``solver.eps_tol`` under every command, as under solve.

    Out of the key's range (0, 1e-4] (``SolverSpec.eps_tol``) it is refused, exit 2,
    naming the option, the key and the range; in range, the output records it: each
    sweep point's ``input``, the nonlinear JSON's ``options``. Before, both commands
    solved with 1e-2 (exit 0) and the sweep's lines read the file's 1e-10.
    """
    (tmp_path / "base.toml").write_text(SMALL)
    out = tmp_path / "out.json"
    args = {
        "sweep": ["sweep", "--config", "base.toml", "--vary", "plate.thickness=0.006"],
        "nonlinear": ["nonlinear", "--config", "base.toml", "--imperfection", "1e-3"],
    }[command]
    loose = run_script(*args, "--json", str(out), "-unibuckle_eps_tol", "1e-2", cwd=tmp_path)
    assert loose.returncode == EXIT_BAD_INPUT, loose.stderr
    assert loose.stdout == "" and not out.exists()
    assert loose.stderr == (
        "unibuckle: error: -unibuckle_eps_tol: solver.eps_tol must lie in (0, 0.0001], got 0.01\n"
    )
    done = run_script(*args, "--json", str(out), "-q", "-unibuckle_eps_tol", "1e-6", cwd=tmp_path)
    assert done.returncode == EXIT_OK, done.stderr
    if command == "sweep":
        assert json.loads(out.read_text().splitlines()[0])["input"]["solver"]["eps_tol"] == 1e-6
        vary = ["sweep", "--config", "base.toml", "--vary", "solver.eps_tol=1e-8"]
        both = run_script(*vary, "--json", "k.jsonl", "-unibuckle_eps_tol", "1e-6", cwd=tmp_path)
        assert both.returncode == EXIT_BAD_INPUT
        assert "-unibuckle_eps_tol and --vary solver.eps_tol=1e-8 both set" in both.stderr
    else:
        assert json.loads(out.read_text())["options"]["eps_tol"] == 1e-6


@serial
def test_ctrl_c_during_a_sweep(tmp_path):
    """SIGINT: a one-line message, exit 130, the finished lines intact and resumable.

    The sweep is paused after its first point (``support.processes.paused_sweep``), so the
    interrupt lands mid-sweep whatever the machine's load (a loaded machine could finish
    the whole sweep before the test saw its first line).
    """
    base = tmp_path / "base.toml"
    base.write_text(SMALL)
    out = tmp_path / "k.jsonl"
    points = 6
    vary = ["--vary", f"plate.thickness=0.002:0.006:{points}"]
    # A terminal's Ctrl-C: SIGINT at its default in the child even when this test runs in
    # the background (a non-interactive shell starts background jobs with SIGINT ignored,
    # and Python then installs no KeyboardInterrupt handler).
    proc = paused_sweep(
        ["--config", str(base), *vary, "--json", str(out), "-q"], tmp_path,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )  # fmt: skip
    proc.send_signal(signal.SIGINT)
    _, stderr = proc.communicate()
    assert proc.returncode == EXIT_INTERRUPTED, stderr
    assert "Traceback" not in stderr and "KeyboardInterrupt" not in stderr, stderr
    assert f"unibuckle: interrupted; the finished points are in {out}" in stderr
    lines = out.read_text().splitlines()
    assert len(lines) == 1 and json.loads(lines[0])["status"] == "ok"
    again = run_script("sweep", "--config", str(base), *vary, "--json", str(out), cwd=tmp_path)
    assert again.returncode == EXIT_OK, again.stderr
    assert f"1 of {points} points already in" in again.stderr


HALF_BUILT = """
import sys
from unibuckle_fenicsx import cli


class HalfBuilt:  # as dolfinx's LinearProblem: __del__ reads what __init__ sets last
    def __init__(self):
        raise KeyboardInterrupt  # Ctrl-C before self._solver is set

    def __del__(self):
        self._solver


def run(*args):
    HalfBuilt()


cli.run_command = run
sys.exit(cli.main(sys.argv[1:]))
"""


def test_an_interrupted_constructor_prints_no_traceback(tmp_path):
    """Ctrl-C inside a constructor: the one-line message, exit 130, no destructor traceback.

    The object the interrupt left half-built is destroyed after the message; a destructor
    that assumes a finished constructor (dolfinx's LinearProblem.__del__) raised, and
    Python printed "Exception ignored ... Traceback" (seen once in the SIGINT test above,
    when the signal landed in the prestress solve's set-up).
    """
    script = tmp_path / "half_built.py"
    script.write_text(HALF_BUILT)
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    proc = subprocess.run(
        [sys.executable, str(script), "solve", "--case", "c1"],
        capture_output=True, text=True, env=env, cwd=tmp_path,
    )  # fmt: skip
    assert proc.returncode == EXIT_INTERRUPTED, proc.stderr
    assert "unibuckle: interrupted; nothing written" in proc.stderr
    assert "Traceback" not in proc.stderr and "Exception ignored" not in proc.stderr, proc.stderr


def test_an_interrupt_inside_a_petsc_callback_is_an_interrupt(monkeypatch, capsys):
    """Ctrl-C while SNES calls the nonlinear path's residual: exit 130, not a PETSc error.

    petsc4py turns an exception raised in a Python callback into PETSc error 101 with
    the exception as its context; the first residual evaluation raises the interrupt
    here, as a Ctrl-C during the load path does (measured: "PETSc/SLEPc failed: error
    code 101", exit 3, before the fix).
    """
    from unibuckle_fenicsx.nonlinear.model import VonKarmanPlate

    def interrupted(self, snes, x, b):
        raise KeyboardInterrupt

    monkeypatch.setattr(VonKarmanPlate, "residual", interrupted)
    monkeypatch.setattr(sys, "unraisablehook", sys.unraisablehook)  # main() replaces it
    args = ["nonlinear", "--case", "c1", "--nx", "6", "--ny", "4", "-q"]
    assert main(args) == EXIT_INTERRUPTED
    assert "unibuckle: interrupted; nothing written" in capsys.readouterr().err


def _imports(path: Path) -> list[str]:
    """The top-level names of the modules ``path`` imports, in order (module level only)."""
    import ast

    names = []
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, ast.Import):
            names += [alias.name.split(".")[0] for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            names.append(node.module.split(".")[0])
    return names


def test_every_module_loads_mpi_before_petsc():
    """Any module of the package imports cleanly as a script's first import.

    The PyPI wheel's petsc4py finds libmpi only once mpi4py has loaded it, so every
    module that imports petsc4py, slepc4py, DOLFINx, basix or UFL must find mpi4py
    imported before, by itself or by a package above it (whose __init__ runs first).
    Before, ``from unibuckle_fenicsx.certificate.certify import certify`` as a first
    import failed ("libmpi.so.12: cannot open shared object file").
    """
    package = ROOT / "unibuckle_fenicsx"
    needs = {"petsc4py", "slepc4py", "dolfinx", "basix", "ufl"}
    for path in sorted(package.rglob("*.py")):
        above = [p / "__init__.py" for p in path.parents if p.is_relative_to(package)]
        loaded = any("mpi4py" in _imports(init) for init in above if init != path)
        for name in _imports(path):
            loaded = loaded or name == "mpi4py"
            assert loaded or name not in needs, f"{path.relative_to(package)} imports {name}"
    proc = subprocess.run(
        [sys.executable, "-c", "from unibuckle_fenicsx.certificate.certify import certify"],
        capture_output=True, text=True, env={**os.environ, "OMP_NUM_THREADS": "1"},
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr


# -- names ---------------------------------------------------------------------------------
def test_file_stem():
    assert file_stem("c1") == "c1"
    assert file_stem("../../evil/x") == "___.._evil_x"
    assert file_stem(".hidden") == "_hidden"
    assert file_stem("plate 1/2 (steel)") == "plate_1_2__steel_"
    assert file_stem("") == "plate"
    for name in ("../../evil/x", "/etc/passwd", "..", "a/../../b", "C:\\x"):
        assert "/" not in file_stem(name) and not file_stem(name).startswith(".")


def test_a_name_writes_nowhere_but_the_output_folder(tmp_path, capsys):
    config = tmp_path / "evil.toml"
    config.write_text('name = "../../evil/x"\n' + SMALL)
    work = tmp_path / "a" / "b"
    work.mkdir(parents=True)
    out = work / "out"
    assert main(["solve", "--config", str(config), "--output", str(out)]) == EXIT_OK
    assert "../../evil/x: lambda_c" in capsys.readouterr().out  # the label is kept
    written = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file())
    outside = [p for p in written if p.parts[:3] != ("a", "b", "out") and p.name != "evil.toml"]
    assert outside == [], outside
    assert (out / "___.._evil_x.pvd").is_file() and (out / "___.._evil_x_w.bp").is_dir()


# -- refused problems: a mechanism, holes, thickness ----------------------------------------
@pytest.mark.parametrize(
    ("edges", "what"),
    [
        (
            '[edges.left]\nsupport = "free"\nnormal_stress = -1.0\n'
            '[edges.right]\nsupport = "free"\nnormal_stress = -1.0\n'
            '[edges.bottom]\nsupport = "free"\n[edges.top]\nsupport = "free"\n',
            "every boundary part is free",
        ),
        (
            "[edges.left]\nnormal_stress = -1.0\n"
            '[edges.right]\nsupport = "free"\nnormal_stress = -1.0\n'
            '[edges.bottom]\nsupport = "free"\n[edges.top]\nsupport = "free"\n',
            "the only support (edges.left.support = 'simply_supported') lies on one straight",
        ),
    ],
)
def test_a_mechanism_is_refused_naming_the_supports(tmp_path, capsys, nothing_built, edges, what):
    """Every edge free (or a single simply supported one): exit 2, not exit 3 after a solve."""
    config = tmp_path / "free.toml"
    config.write_text(SMALL + edges)
    assert main(["solve", "--config", str(config)]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "edges.*.support" in err and what in err and "rigid body" in err, err


def test_supports_that_hold_the_plate_are_accepted():
    """Two supported edges, one clamped edge, or a bilateral foundation hold the plate."""
    free = {"support": "free"}
    loads = {"normal_stress": -1.0}
    for edges, extra in (
        ({"left": loads, "right": loads, "bottom": free, "top": free}, {}),
        ({"left": {**loads, "support": "clamped"}, "right": {**free, **loads}}, {}),
        (
            {"left": {**free, **loads}, "right": {**free, **loads}, "bottom": free, "top": free},
            {"obstacle": {"zone": "all", "side": "both", "foundation_stiffness": 1e9}},
        ),
    ):
        problem_from_dict({"edges": edges, **extra})
    with pytest.raises(ValueError, match=r"edges\.\*\.support: every boundary part is free"):
        problem_from_dict(
            {
                "edges": {
                    "left": {**free, **loads},
                    "right": {**free, **loads},
                    "bottom": free,
                    "top": free,
                },
                "obstacle": {"zone": "all", "foundation_stiffness": 1e9},  # tensionless
            }
        )


def _holed(center, radius, size=0.01):
    return {
        "plate": {
            "corners": [[0.0, 0.0], [0.3, 0.1]],
            "holes": [{"center": center, "radius": radius}],
        },
        "mesh": {"size": size},
    }


@pytest.mark.parametrize(
    ("center", "radius", "match"),
    [
        # Tangent to the top edge y = 0.1; in floating point its distance exceeds r by 3e-18.
        (
            [0.1, 0.1 - 0.02],
            0.02,
            r"the gap between plate\.holes\[0\] and the plate's edge is .*touches",
        ),
        ([0.1, 0.05], 1e-7, r"plate\.holes\[0\]\.radius = 1e-07 m .* below mesh\.size / 100"),
        ([0.1, 0.05], 0.04999, r"gap between plate\.holes\[0\] and the plate's edge .* mesh\.size"),
    ],
)
def test_tangent_and_tiny_holes_are_refused_before_gmsh(nothing_built, center, radius, match):
    with pytest.raises(ValueError, match=match):
        problem_from_dict(_holed(center, radius))


@serial
def test_a_plate_gmsh_cannot_mesh_names_its_features():
    """A ligament of mesh.size/50: allowed, but gmsh leaves triangles; the keys are named."""
    pytest.importorskip("gmsh")
    spec = problem_from_dict(_holed([0.1, 0.1 - 0.03 - 2e-4], 0.03))
    from unibuckle_fenicsx.model.gmsh_mesh import gmsh_plate_mesh

    with pytest.raises(ValueError) as err:
        gmsh_plate_mesh(spec.plate, spec.mesh, MPI.COMM_SELF)
    message = str(err.value)
    assert "mesh.size = 0.01 m" in message
    assert "the gap between plate.holes[0] and the plate's edge: 0.0002 m" in message
    assert "Recombine" not in message, message


def test_thickness_outside_the_plate_model(tmp_path, capsys, nothing_built):
    """t/b = 100 is refused naming plate.thickness; t/b = 0.3 gets a warning."""
    config = tmp_path / "thick.toml"
    config.write_text(SMALL.replace("thickness = 0.006", "thickness = 10.0"))
    assert main(["solve", "--config", str(config)]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "plate.thickness = 10 m is 100 times the plate's smaller side 0.1 m" in err, err
    assert f"at most {MAX_THICKNESS_RATIO:g} times it" in err


def test_moderately_thick_plate_gets_a_warning(tmp_path, capsys):
    config = tmp_path / "thick.toml"
    config.write_text(SMALL.replace("thickness = 0.006", "thickness = 0.03"))
    out = tmp_path / "thick.json"
    assert main(["solve", "--config", str(config), "--json", str(out)]) == EXIT_OK
    err = capsys.readouterr().err
    assert "unibuckle: warning: plate.thickness = 0.03 m is 0.3 times" in err, err
    assert f"up to t/b of about {THICK_PLATE_RATIO:g}" in err
    assert "0.3 times" in json.loads(out.read_text())["details"]["plate_model"]


def test_the_thick_plate_warning_is_in_the_file_s_units(tmp_path, capsys):
    """A mm-N-MPa file's warning in mm (it said 0.03 m of a file that writes 30 mm)."""
    config = tmp_path / "thick.toml"
    text = SMALL.replace("thickness = 0.006", "thickness = 30.0")
    config.write_text('units = "mm-N-MPa"\n' + text.replace("0.2, 0.1", "200.0, 100.0"))
    out = tmp_path / "thick.json"
    assert main(["solve", "--config", str(config), "--json", str(out)]) == EXIT_OK
    err = capsys.readouterr().err
    assert "plate.thickness = 30 mm is 0.3 times the plate's smaller side 100 mm" in err, err
    note = json.loads(out.read_text())["details"]["plate_model"]  # the JSON is SI
    assert "plate.thickness = 0.03 m is 0.3 times" in note, note


@pytest.mark.parametrize(
    ("mesh", "said"),
    [
        ("size = 0.5", "mesh.size = 0.5 m (2 x 2 cells, at least 2 a side): cells up to 0.1 m"),
        ("nx = 8\nny = 2", "mesh.nx = 8, mesh.ny = 2: cells up to 0.05 m"),
        ("nx = 8\nny = 4", None),
    ],
)
def test_a_mesh_too_coarse_for_the_plate_gets_a_warning(tmp_path, capsys, mesh, said):
    """Cells larger than a quarter of the smaller side b: a warning, not silence.

    ``mesh.size`` larger than the plate was rounded up to two cells a side without a
    word: the 300 x 100 x 3 mm SSSS plate at size = 500 mm gave k = 17.41 (Navier's k
    for a/b = 3 is 4, Timoshenko and Gere 9.2). The simply supported square's k on n x n
    cells, by this package's element, is 5.95, 4.70, 4.37 at n = 2, 3, 4 (+49, +18,
    +9 %): fewer than 4 cells across b draw the warning, 4 do not.
    """
    config = tmp_path / "coarse.toml"
    config.write_text(SMALL.replace("nx = 8\nny = 4", mesh))
    assert main(["solve", "--config", str(config)]) == EXIT_OK
    err = capsys.readouterr().err
    if said is None:
        assert "cells across" not in err, err
    else:
        assert f"unibuckle: warning: {said}, more than a quarter of the plate's smaller" in err
        assert "fewer than 4 cells across it" in err, err


def _kirchhoff_square_k(psi: float, terms: int = 14) -> float:
    """The simply supported square's k under sigma(y) = sigma_1 (1 - (1 - psi) y/b), by Ritz.

    w = sum sin(m pi x/b) sin(n pi y/b), m = 1..6, n = 1..terms (Kirchhoff; Gauss
    quadrature of the stress term), in units of sigma_E = pi^2 D/(t b^2), b = 1.
    """
    from scipy.linalg import eigh

    modes = [(m, n) for m in range(1, 7) for n in range(1, terms + 1)]
    stiffness = np.diag([np.pi**4 * (m * m + n * n) ** 2 / 4.0 for m, n in modes])
    s, weights = np.polynomial.legendre.leggauss(60)
    x, w1 = (s + 1.0) / 2.0, weights / 2.0
    X, Y = np.meshgrid(x, x, indexing="ij")
    weight = (np.outer(w1, w1) * (1.0 - (1.0 - psi) * Y)).ravel()
    slopes = np.array(
        [m * np.pi * np.cos(m * np.pi * X) * np.sin(n * np.pi * Y) for m, n in modes]
    ).reshape(len(modes), -1)
    geometric = (slopes * weight) @ slopes.T
    return float(1.0 / (np.pi**2 * eigh(geometric, stiffness, eigvals_only=True).max()))


@pytest.mark.parametrize(("cells", "warned"), [(8, True), (12, False)])
def test_a_mesh_too_coarse_for_a_stress_gradient_gets_a_warning(tmp_path, capsys, cells, warned):
    """Cells too coarse for the compressed width b_c = b/(1 - psi): a warning, not silence.

    Under in-plane bending the buckle lies in the compressed part of the plate (EN 1993-1-5
    Table 4.1's b_c), and the warning counted cells across b alone: the simply supported
    square 100 x 100 x 0.5 mm at psi = -2 on 8 x 8 cells (8 across b, 2.7 across b_c) gave
    k = 65.2 without a word, +20 % over Kirchhoff's 54.40 (Ritz, below; Table 4.1's
    5.98 (1 - psi)^2 = 53.8), where the uniform square's +9 % at 4 cells across is warned
    of. Now fewer than 4 cells across b_c draw the warning; 12 x 12 (4 across) do not.
    """
    config = tmp_path / "bending.toml"
    config.write_text(
        "[plate]\ncorners = [[0.0, 0.0], [0.1, 0.1]]\nthickness = 0.0005\n"
        "[material]\nE = 2.1e11\nnu = 0.3\n"
        "[edges.left]\nnormal_stress = [-1.0, 2.0]\n[edges.right]\nnormal_stress = [-1.0, 2.0]\n"
        f"[edges.bottom]\n[edges.top]\n[mesh]\nnx = {cells}\nny = {cells}\n"
    )
    out = tmp_path / "k.json"
    assert main(["solve", "--config", str(config), "--json", str(out), "-q"]) == EXIT_OK
    err = capsys.readouterr().err
    k = json.loads(out.read_text())["buckling_coefficient_k"]
    reference = _kirchhoff_square_k(-2.0)
    assert reference == pytest.approx(54.40, abs=0.01)
    if warned:
        assert k > 1.15 * reference, (k, reference)
        said = "cells up to 0.0125 m along edges.left, whose normal_stress [-1, 2] is compressive"
        assert f"unibuckle: warning: mesh.nx = 8, mesh.ny = 8: {said} over 0.0333 m" in err, err
        assert "fewer than 4 cells across the compressed width" in err, err
    else:
        assert k < 1.10 * reference, (k, reference)
        assert "unibuckle: warning" not in err, err


def test_nonlinear_warns_of_a_mesh_too_coarse_as_solve_does(tmp_path, capsys):
    """``unibuckle nonlinear`` on 8 x 2 cells of a 200 x 100 plate: solve's warning too.

    Cells of 0.05 m across b = 0.1 m are 2 across the smaller side, fewer than the 4 that
    keep the square's k within +9 % (the test above); the nonlinear command said nothing.
    """
    config = tmp_path / "coarse.toml"
    config.write_text(SMALL.replace("nx = 8\nny = 4", "nx = 8\nny = 2"))
    main(["nonlinear", "--config", str(config), "--max-load", "1.05", "-q"])
    err = capsys.readouterr().err
    said = "unibuckle: warning: mesh.nx = 8, mesh.ny = 2: cells up to 0.05 m, more than a quarter"
    assert said in err, err


def test_a_sweep_warns_once_of_its_points_too_coarse(tmp_path, capsys):
    """A sweep over the thickness on 8 x 2 cells: one warning naming the points' count.

    Every point has cells of 0.05 m across b = 0.1 m (2 across, fewer than 4): the sweep
    said nothing, as its points' solves are silenced.
    """
    config = tmp_path / "coarse.toml"
    config.write_text(SMALL.replace("nx = 8\nny = 4", "nx = 8\nny = 2"))
    out = tmp_path / "k.jsonl"
    args = ["sweep", "--config", str(config), "--vary", "plate.thickness=0.005:0.006:2"]
    assert main([*args, "--json", str(out), "-q"]) == EXIT_OK
    err = capsys.readouterr().err
    assert err.count("unibuckle: warning:") == 1, err
    assert "2 of 2 sweep points have cells too coarse; point 0" in err, err
    assert "mesh.nx = 8, mesh.ny = 2: cells up to 0.05 m" in err, err


def test_a_sweep_reads_each_of_its_points_once(tmp_path, capsys, monkeypatch):
    """Two points, two problems read: the coarse-cell warning uses the sweep's own.

    The warning read every point's problem, and the sweep read them all again.
    """
    import unibuckle_fenicsx.sweep as sweep

    read = []

    def counted(data, name):
        read.append(name)
        return spec_from_dict(data, name)

    spec_from_dict = sweep.spec_from_dict
    monkeypatch.setattr(sweep, "spec_from_dict", counted)
    config = tmp_path / "coarse.toml"
    config.write_text(SMALL.replace("nx = 8\nny = 4", "nx = 8\nny = 2"))
    out = tmp_path / "k.jsonl"
    args = ["sweep", "--config", str(config), "--vary", "plate.thickness=0.005:0.006:2"]
    assert main([*args, "--json", str(out), "-q"]) == EXIT_OK
    assert len(read) == 2, read  # the grid's two points
    assert "2 of 2 sweep points have cells too coarse" in capsys.readouterr().err


@pytest.mark.parametrize(("nu", "warned"), [(-0.2, True), (0.3, False)])
def test_solve_warns_of_a_design_poisson_s_ratio_not_a_steel_s(tmp_path, capsys, nu, warned):
    """[design] with nu = -0.2 ran without a word; EN 1993-1-1 3.2.6 gives steel nu = 0.3."""
    config = tmp_path / "nu.toml"
    config.write_text(
        SMALL
        + f"[material]\nE = 2.1e11\nnu = {nu}\n[design]\nyield_stress = 3.55e8\n"
        + "[edges.left]\nnormal_stress = -1.0\n[edges.right]\nnormal_stress = -1.0\n"
    )
    assert main(["solve", "--config", str(config)]) == EXIT_OK
    err = capsys.readouterr().err
    said = f"unibuckle: warning: design: material.nu = {nu:g} is not a steel's"
    assert (said in err) == warned, err


# -- files and flags named ------------------------------------------------------------------
def test_missing_config_names_the_option(tmp_path, capsys, nothing_built):
    missing = tmp_path / "nowhere.toml"
    sweep = ["sweep", "--vary", "plate.thickness=1,2", "--json", str(tmp_path / "k.jsonl")]
    for head in (["solve"], ["nonlinear"], sweep):
        assert main([*head, "--config", str(missing)]) == EXIT_BAD_INPUT
        err = capsys.readouterr().err
        assert f"--config {missing}: cannot read it (No such file or directory)" in err, err
        assert "[Errno" not in err


def test_sweep_file_that_is_not_a_sweep_is_refused_and_kept(tmp_path, capsys, nothing_built):
    """Bytes that are not UTF-8, or another file: named, refused, left as they were."""
    config = tmp_path / "base.toml"
    config.write_text(SMALL)
    vary = ["--vary", "plate.thickness=0.005,0.006"]
    for name, data, why in (
        ("binary.jsonl", b"\xff\xfe\x00garbage\n", "not UTF-8 text"),
        ("notes.txt", b"my notes, not a sweep\n", "not JSON"),
    ):
        path = tmp_path / name
        path.write_bytes(data)
        assert main(["sweep", "--config", str(config), *vary, "--json", str(path)]) == 2
        err = capsys.readouterr().err
        assert f"--json {path}: line " in err and why in err, err
        assert path.read_bytes() == data


def test_nonlinear_unilateral_shape_without_obstacle_names_the_flags(capsys, nothing_built):
    for args, why in (
        (["--case", "free"], "the problem has none"),
        (["--case", "c1", "--no-obstacle"], "--no-obstacle removes it"),
    ):
        assert main(["nonlinear", *args, "--shape", "unilateral"]) == EXIT_BAD_INPUT
        err = capsys.readouterr().err
        assert "--shape unilateral" in err and why in err and "obstacle = true" not in err, err


def test_versions_name_every_library_that_took_part():
    import petsc4py
    import slepc4py

    found = versions()
    for dist in ("mpi4py", "gmsh", "cvxpy", "clarabel", "fenics-dolfinx"):
        try:
            expected = version(dist)
        except PackageNotFoundError:
            assert dist not in found
        else:
            assert found[dist] == expected
    # The bindings always took part, whichever distribution installed them (the PyPI
    # wheel dolfinx-solver-real bundles them under its own name).
    assert found["petsc4py"] == petsc4py.__version__
    assert found["slepc4py"] == slepc4py.__version__


# -- an incomplete nonlinear path -----------------------------------------------------------
def test_incomplete_path_says_what_it_validated(tmp_path, capsys, monkeypatch):
    """SNES fails past the knee; both loads are read and the contact holds: say so."""
    import unibuckle_fenicsx.nonlinear
    from unibuckle_fenicsx.nonlinear import NonlinearResult

    linear = 1.4316e7
    result = NonlinearResult(
        case="c1", mesh=[20, 20], dofs=1, obstacle=True, control="load", imperfection=1e-3,
        imperfection_shape="unilateral", thickness_m=0.006, linear_critical_load_Pa=linear,
        free_load_Pa=1.276e7, linear_method="active-set", southwell_load_Pa=linear * (1 + 1.5e-4),
        southwell_points=5, inflection_load_Pa=linear * (1 - 2e-4), southwell_ratio=1 + 1.5e-4,
        inflection_ratio=1 - 2e-4, completed=False,
        path=[{"load_Pa": 1.05 * linear, "max_w_m": 1e-3, "contact_nodes": 9}],
        stop_reason="SNES diverged at the smallest step (DIVERGED_LINE_SEARCH)",
        rejected_steps=3, constrained_nodes=171, contact_check={"satisfied": True},
        options={"max_load": 1.2}, wall_time_s=1.0,
    )  # fmt: skip

    class Analysis:
        def __init__(self):
            self.result = result

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return None

    monkeypatch.setattr(unibuckle_fenicsx.nonlinear, "solve_nonlinear", lambda *a: Analysis())
    out = tmp_path / "nl.json"
    assert main(["nonlinear", "--case", "c1", "--json", str(out)]) == EXIT_NOT_CERTIFIED
    err = capsys.readouterr().err
    validated, _, missing = err.partition("Not validated:")
    assert re.search(r"Validated: the Southwell load 1\.431\d+e\+07 Pa \(\+1\.5e-04", validated)
    assert "the inflection load" in validated and "(-2.0e-04 relative)" in validated
    assert "the contact conditions at the last converged state" in validated
    assert "the path from 1.05 to --max-load 1.2 x the linear load" in missing
    assert "DIVERGED_LINE_SEARCH" in missing
    assert json.loads(out.read_text())["completed"] is False


def _too_thin_plate(tmp_path: Path) -> Path:
    """SSSS 0.2 x 0.1 m (the paper's plate, 40 x 20 cells) at t = 1e-7 m, b/t = 1e6."""
    ssss = tmp_path / "ssss.toml"
    ssss.write_text(
        SMALL.replace("thickness = 0.006", "thickness = 1e-7").replace("nx = 8", "nx = 40")
        .replace("ny = 4", "ny = 20")
    )  # fmt: skip
    return ssss


def test_a_plate_too_thin_for_double_precision_is_said_so(tmp_path, capsys):
    """b/t = 1e6 and 1e7: the stiffness keeps fewer digits than the inertia check needs.

    The rounding bound (``load_resolution``, eps |u|^T|A||u| / (lambda u^T B u)) grows as
    (b/t)^2. Above FREE_CHECK_RESOLUTION (1e-3) the free pair's inertia check refuses the
    load, whatever its count (which within rounding of the load is decided by the
    partition): SSSS 0.2 x 0.1 m at t = 1e-7 m (b/t = 1e6), and an outstand 0.5 x 0.1 m
    (bottom edge simply supported, top free, compression 1 to 0.5 across, E = 210 GPa,
    50 x 10 cells) at t = 1e-8 m. At t = 1e-5 m the outstand is solved and proven:
    k = 0.742 (docs/history/2026-12-02d-thinmpi.md, unchanged by the check).
    """
    ssss = _too_thin_plate(tmp_path)
    assert main(["solve", "--config", str(ssss), "-q"]) == EXIT_NOT_CERTIFIED
    err = capsys.readouterr().err
    assert "load_resolution" in err and "section.thickness" in err, err
    assert "plate.thickness = 1e-07 m" in err and "times thicker" in err, err
    assert "too loose" not in err, err
    outstand = """\
[plate]
corners = [[0.0, 0.0], [0.5, 0.1]]
thickness = THICKNESS
[material]
E = 2.1e11
nu = 0.3
[edges.left]
normal_stress = [-1.0, -0.5]
[edges.right]
normal_stress = [-1.0, -0.5]
[edges.top]
support = "free"
[mesh]
nx = 50
ny = 10
"""
    path = tmp_path / "outstand_1e-8.toml"
    path.write_text(outstand.replace("THICKNESS", "1e-8"))
    assert main(["solve", "--config", str(path), "-q"]) == EXIT_NOT_CERTIFIED
    err = capsys.readouterr().err
    assert "load_resolution" in err and "plate.thickness = 1e-08 m" in err, err
    path = tmp_path / "outstand_1e-5.toml"
    path.write_text(outstand.replace("THICKNESS", "1e-5"))
    out = tmp_path / "outstand_1e-5.json"
    assert main(["solve", "--config", str(path), "-q", "--json", str(out)]) == EXIT_OK
    err = capsys.readouterr().err
    assert "warning: double precision fixes the critical load" not in err, err
    result = json.loads(out.read_text())
    assert result["buckling_coefficient_k"] == pytest.approx(0.7422, abs=1e-4)


@pytest.mark.mpi
@serial
def test_a_plate_too_thin_is_refused_alike_on_two_ranks(tmp_path):
    """The b/t = 1e6 plate above: exit 3 and one message on 1 and on 2 ranks.

    The refusal is decided by the load's rounding bound (0.0046 on either partition),
    not by the inertia count, which lies within rounding of the load: the count found one
    eigenvalue below on 1 rank and none on 2, which then gave exit 0 and "proven=yes"
    (docs/history/2026-12-02c-mpihunt.md). The project's rule: results are the same on
    any number of ranks.
    """
    ssss = _too_thin_plate(tmp_path)
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    runs = {
        n: subprocess.run(
            [mpiexec(), "-n", str(n), str(SCRIPT), "solve", "--config", str(ssss), "-q"],
            capture_output=True, text=True, env=env, cwd=tmp_path,
        )
        for n in (1, 2)
    }  # fmt: skip
    assert runs[1].returncode == runs[2].returncode == EXIT_NOT_CERTIFIED, runs
    assert "load_resolution" in runs[1].stderr, runs[1].stderr
    assert runs[1].stderr == runs[2].stderr


def test_the_resolution_warning_starts_above_its_threshold():
    """The warning on a coarse load is given above RESOLUTION_WARNING (1e-2) only.

    docs/guide/results.md (``load_resolution``); the plate without obstacle that gave it
    (the outstand at t = 1e-8 m above) is now refused by the free pair's check.
    """
    assert resolution_note(None) is None
    assert resolution_note(RESOLUTION_WARNING) is None
    note = resolution_note(2 * RESOLUTION_WARNING)
    assert note is not None and "fixes the critical load only to 0.02 of it" in note


@serial
def test_output_into_a_pipe_closed_early_ends_quietly_with_141(tmp_path):
    """``unibuckle solve ... | head -1``: the reader stops early, the run ends with 141.

    128 + SIGPIPE, the status of any command a closed pipe ends (``seq 100 | head -1``
    under pipefail) and the one mpiexec gives, itself ended by the signal when it forwards
    the ranks' output. PETSc takes SIGPIPE for a crash: the run ended with "Caught signal
    number 13 Broken Pipe" and MPI_Abort (exit 59), or with 0 when only the summary met
    the closed pipe; a PETSc viewer's output (``-unibuckle_eps_view``) stopped it with
    "PETSc/SLEPc failed" and 3. The pipe is closed before anything is written (the solve
    takes tenths of a second), so the writes meet a closed pipe for certain.
    """
    box = ["--config", str(ROOT / "demos/box.toml"), "--set", "obstacle.core=false"]
    runs = (
        ["--case", "free"],
        [*box, "--set", "mesh.size=0.025"],
        ["--case", "c1", "--nx", "6", "--ny", "6", "-unibuckle_eps_view"],
    )
    for args in runs:
        proc = subprocess.Popen(
            [str(SCRIPT), "solve", *args, "-q"],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            cwd=tmp_path,
            env={**os.environ, "OMP_NUM_THREADS": "1"},
        )
        assert proc.stdout is not None and proc.stderr is not None
        proc.stdout.close()  # what head does after its lines
        err = proc.stderr.read().decode()
        assert proc.wait() == 128 + signal.SIGPIPE, (args, err)
        assert "PETSC ERROR" not in err and "Traceback" not in err, err


def test_nonlinear_warns_that_it_writes_no_design_output(tmp_path, capsys):
    """``[design]`` given to ``unibuckle nonlinear`` is said to be unused, not dropped silently.

    The load path writes no EN 1993-1-5 output; the command read the table and said nothing.
    """
    config = tmp_path / "designed.toml"
    config.write_text(SMALL + "[material]\nE = 2.1e11\nnu = 0.3\n[design]\nyield_stress = 3.55e8\n")
    main(["nonlinear", "--config", str(config), "--max-load", "1.05", "-q"])
    err = capsys.readouterr().err
    assert "unibuckle: warning: unibuckle nonlinear writes no design output" in err, err
