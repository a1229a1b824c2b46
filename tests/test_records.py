"""Records for version control: the same on any machine, and ``make demo`` leaves the tree.

A result's JSON from two machines differs where rounding decides: loads in their last
digits (1e-13 relative on the paper's plate), round-off diagnostics (residuals, margins,
the certificate's gap), the algorithm's path (eigen-solve counts: 76 against 81 on the
same plate in a user's run; the contact sets visited), times and versions. A record
keeps what the problem fixes, at eight digits: two results that differ only there give
the same record. ``make demo`` writes under ``output/`` (ignored by git) and compares its
records with the repository's ``figures/``.
"""

from __future__ import annotations

import copy
import importlib.util
import json
from pathlib import Path

from mpi4py import MPI

import pytest

from unibuckle_fenicsx.results import record

ROOT = Path(__file__).resolve().parents[1]


def _run_all():
    spec = importlib.util.spec_from_file_location("run_all", ROOT / "demos" / "run_all.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _jitter(data, scale=1 + 3e-13):
    """``data`` with every float moved by 3e-13 relative (rounding between machines)."""
    if isinstance(data, dict):
        return {k: _jitter(v, scale) for k, v in data.items()}
    if isinstance(data, list):
        return [_jitter(v, scale) for v in data]
    return data * scale if isinstance(data, float) else data


@pytest.fixture(scope="module")
def c1():
    from unibuckle_fenicsx import paper_case
    from unibuckle_fenicsx.analysis import solve

    with solve(paper_case("c1", 8, 8), MPI.COMM_SELF) as analysis:
        return analysis.result.as_dict(timings=False)


def test_results_that_differ_in_rounding_and_path_give_one_record(c1):
    other = _jitter(copy.deepcopy(c1))
    other["eigensolves"] += 5  # the path: counts and visited sets
    other["details"]["free_eigen_iterations"] += 1
    other["certificate"]["relative_residual"] *= 1.5  # round-off diagnostics
    other["versions"]["numpy"] = "another"
    other["mpi_size"] = 2
    other["contact_dofs"] = other["contact_dofs"][::-1]  # the partition's numbering
    assert record(other) == record(c1)
    assert json.dumps(record(other)) == json.dumps(record(c1))


def test_a_record_keeps_what_the_problem_fixes(c1):
    kept = record(c1)
    for key in ("critical_load_Pa", "free_load_Pa", "buckling_coefficient_k", "mesh", "input"):
        assert key in kept
    assert kept["critical_load_Pa"] == pytest.approx(c1["critical_load_Pa"], rel=1e-7)
    assert kept["contact_coordinates"] == [
        [round(x, 9), round(y, 9)] for x, y in c1["contact_coordinates"]
    ]
    assert set(kept["certificate"]) <= {
        "feasible", "kkt", "smallest_of_reduced", "global_optimum_proven", "proven_by",
        "status", "negative_eigenvalues", "tolerance",
    }  # fmt: skip
    for key in ("eigensolves", "details", "versions", "mpi_size", "contact_dofs"):
        assert key not in kept
    assert "contact_coordinates" not in record(c1, contact=False)
    # A coordinate's rounding beside the plate's size is zero: -0.09999999999999999 and
    # 2.8e-19 in a section are -0.1 and 0.0.
    assert record([-0.09999999999999999, 2.77555756156289e-19, 0.1]) == [-0.1, 0.0, 0.1]


def test_make_demo_writes_outside_the_repository_s_figures(tmp_path):
    """run_all writes under output/ (git ignores it) and lists records that differ."""
    run_all = _run_all()
    assert run_all.parser().parse_args([]).figures == ROOT / "output" / "figures"
    assert "output/" in (ROOT / ".gitignore").read_text().split()
    figures = tmp_path / "figures"
    (figures / "c1").mkdir(parents=True)
    stored = tmp_path / "stored"
    (stored / "c1").mkdir(parents=True)
    data = {"case": "c1", "results": [{"critical_load_Pa": 14445630.0, "method": "active-set"}]}
    (stored / "c1" / "results.json").write_text(json.dumps(data))
    (figures / "c1" / "results.json").write_text(json.dumps(data))
    assert run_all.compare_records(figures, stored) == []
    data["results"][0]["critical_load_Pa"] = 14445630.0 * (1 + 1e-7)  # within eight digits
    (figures / "c1" / "results.json").write_text(json.dumps(data))
    assert run_all.compare_records(figures, stored) == []
    data["results"][0]["critical_load_Pa"] = 14.4e6
    (figures / "c1" / "results.json").write_text(json.dumps(data))
    (differ,) = run_all.compare_records(figures, stored)
    assert "1 difference(s): .results[0].critical_load_Pa: 14400000.0 against 14445630.0" in differ
