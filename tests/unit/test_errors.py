"""The error hierarchy: one exit status per kind of error, and clean-up after a failure.

``InputError`` exits with status 2, ``NumericalError`` with 3, anything else (a bug) with
1, a traceback and a request for a report (README, "Command line"). A sweep point that
fails numerically destroys its PETSc objects before the next point, and the other points
are the same as in a sweep without it. The expected statuses are the documented ones; the
reference sweep is the same solver run without the failing point.
"""

from __future__ import annotations

import gc
import json
from pathlib import Path

from mpi4py import MPI
from petsc4py import PETSc

import pytest

import unibuckle_fenicsx.analysis
from unibuckle_fenicsx.cli import EXIT_BAD_INPUT, EXIT_BUG, EXIT_NOT_CERTIFIED, EXIT_OK, main
from unibuckle_fenicsx.errors import InputError, NumericalError, UnibuckleError
from unibuckle_fenicsx.model.problem import Problem
from unibuckle_fenicsx.sweep import parse_variation, run_sweep

#: A small plate with a box obstacle (each point an enumeration of a few sets, ~1 s).
SMALL = {
    "name": "small",
    "plate": {"corners": [[-0.1, -0.05], [0.1, 0.05]], "thickness": 0.006},
    "material": {"E": 1.0e9, "nu": 0.3},
    "mesh": {"nx": 6, "ny": 4},
    "obstacle": {"zone": [[-0.04, 0.04], [-0.05, 0.05]]},
}
FAILING = 0.005  # the thickness of the point made to fail


def test_the_classes_keep_their_builtin_bases():
    assert issubclass(InputError, ValueError) and issubclass(InputError, UnibuckleError)
    assert issubclass(NumericalError, RuntimeError) and issubclass(NumericalError, UnibuckleError)


def test_exit_0_a_certified_solve(capsys):
    assert main(["solve", "--case", "free", "--nx", "8", "--ny", "4"]) == EXIT_OK


def test_exit_2_bad_input_names_the_key(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text("[plate]\nthickness = -0.006\n")
    assert main(["solve", "--config", str(path)]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "plate.thickness" in err and "> 0" in err and "Traceback" not in err


def test_exit_3_an_eigen_solve_that_does_not_converge(capsys):
    """One Krylov-Schur iteration to an unreachable tolerance: SLEPc converges nothing."""
    opts = PETSc.Options()
    opts["unibuckle_eps_max_it"] = 1
    opts["unibuckle_eps_tol"] = 1e-300
    try:
        status = main(["solve", "--case", "free", "--nx", "8", "--ny", "4"])
    finally:
        del opts["unibuckle_eps_max_it"]
        del opts["unibuckle_eps_tol"]
    assert status == EXIT_NOT_CERTIFIED
    err = capsys.readouterr().err
    assert "converged no eigenpair" in err and "Traceback" not in err


def test_exit_1_a_bug_prints_the_traceback_and_asks_for_a_report(monkeypatch, capsys):
    def bug(*args, **kwargs):
        raise ZeroDivisionError("a planted bug")

    monkeypatch.setattr(unibuckle_fenicsx.analysis, "solve", bug)
    assert main(["solve", "--case", "free", "--nx", "8", "--ny", "4"]) == EXIT_BUG
    err = capsys.readouterr().err
    assert "Traceback" in err and "ZeroDivisionError: a planted bug" in err
    assert "please report" in err


def _live() -> list[str]:
    """Type names of the live PETSc/SLEPc objects with a handle (not destroyed)."""
    return [type(o).__name__ for o in gc.get_objects() if isinstance(o, PETSc.Object) and o.handle]


def _results(path: Path) -> dict[float, dict]:
    lines = [json.loads(line) for line in path.read_text().splitlines()]
    return {line["point"]["plate.thickness"]: line | {"index": None} for line in lines}


def test_a_failed_sweep_point_leaves_nothing_alive_and_the_others_unchanged(tmp_path, monkeypatch):
    """The failing point's problem is kept alive here, so only its destroy() can free it."""
    comm = MPI.COMM_WORLD
    reference = tmp_path / "reference.jsonl"
    run_sweep(SMALL, [parse_variation("plate.thickness=0.004,0.006")], reference, comm)

    kept: list[Problem] = []
    solve_free = Problem.solve_free

    def fail_one(self: Problem):  # the real solve, then a numerical failure
        mode = solve_free(self)
        if self.spec.plate.thickness == FAILING:
            kept.append(self)
            raise NumericalError("a planted numerical failure")
        return mode

    monkeypatch.setattr(Problem, "solve_free", fail_one)
    gc.collect()
    before = _live()
    out = tmp_path / "with_failure.jsonl"
    run_sweep(SMALL, [parse_variation(f"plate.thickness=0.004,{FAILING},0.006")], out, comm)

    assert len(kept) == 1
    # Kept alive, its matrices and eigen solver are destroyed all the same; what is left
    # is the free mode's vector, which its dolfinx Function owns (freed with the problem).
    assert sorted(_live()) == sorted([*before, "Vec"])
    kept.clear()
    assert sorted(_live()) == sorted(before)

    lines = _results(out)
    assert lines[FAILING]["status"] == "failed"
    assert "a planted numerical failure" in lines[FAILING]["error"]
    assert {k: v for k, v in lines.items() if k != FAILING} == _results(reference)


def test_a_sweep_point_refused_by_the_solver_is_refused(tmp_path):
    """A zone between the nodes (spacing 1/30 m by 1/40 m) is found empty once the mesh exists."""
    base = SMALL | {"obstacle": {"zone": [[0.005, 0.01], [0.005, 0.01]]}}
    out = tmp_path / "refused.jsonl"
    lines = run_sweep(base, [parse_variation("plate.thickness=0.006")], out)
    assert lines[0]["status"] == "refused" and "obstacle" in lines[0]["error"]


def test_input_errors_are_value_errors_for_old_callers():
    from unibuckle_fenicsx.spec import problem_from_dict

    with pytest.raises(ValueError, match=r"plate\.thickness"):
        problem_from_dict({"plate": {"thickness": 0.0}})
