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

from mpi4py import MPI

import pytest

from support.paths import ROOT
from unibuckle_fenicsx.results import record


def _run_all():
    spec = importlib.util.spec_from_file_location("run_all", ROOT / "demos" / "run_all.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _jitter(data, scale=1 + 3e-13):
    """``data`` with every computed float moved by 3e-13 relative (rounding between machines).

    The input is the problem a user gave: the same on every machine.
    """
    if isinstance(data, dict):
        return {k: v if k == "input" else _jitter(v, scale) for k, v in data.items()}
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
    # A normalised mode's largest value is 1 within rounding: 0.9999999999997 on one
    # machine, 1.0000000000002 on another (c2's section in the second environment was
    # kept to eight decimals, 0.01464486, against seven, 0.0146449, before).
    low, high = (record([0.014644861, -0.9999999999997]), record([0.014644861, -1.0000000000002]))
    assert low == high == [0.0146449, -1.0]


def test_a_record_keeps_its_input_exact_so_that_a_re_run_meshes_the_same(tmp_path):
    """A record's results are rounded, its input not: re-running it is the same problem.

    b/12 at eight digits is 0.083333333, and 1/0.083333333 = 12.00000005 rounds up to
    13 cells across (the garland demo's records re-ran on 25 x 13 cells, not 24 x 12).
    """
    from unibuckle_fenicsx.spec import load_problem, paper_case, problem_to_dict

    spec = paper_case("c1", 24, 12)  # 0.2 x 0.1 m
    problem = problem_to_dict(spec, units=spec.units)
    problem["mesh"] = {"size": 0.1 / 12}  # 24 x 12 cells of 8.33 mm
    data = {"critical_load_Pa": 1 / 3, "point": {"mesh.size": 0.1 / 12}, "input": problem}
    kept = record(data)
    assert kept["critical_load_Pa"] == 0.33333333  # a result: eight digits
    assert kept["point"] == {"mesh.size": 0.1 / 12}
    assert kept["input"]["mesh"]["size"] == 0.1 / 12
    assert kept["input"]["material"]["shear_correction"] == 5 / 6
    path = tmp_path / "record.json"
    path.write_text(json.dumps(kept))
    again = load_problem(path)  # as unibuckle solve --config record.json reads it
    assert (again.mesh.nx, again.mesh.ny) == (24, 12)


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


#: Section A of the free mode of the paper's plate (20 x 20) from two runs of the same
#: code on this machine: OpenBLAS's default kernel on one thread (W_A), its Sandybridge
#: kernel on two (W_B). They differ by 1e-13 at most; the PNGs drawn from them differed
#: in 49 pixels (matplotlib's path simplification drops a nearly collinear vertex or not).
X = [
    -0.1,
    -0.09000000000000001,
    -0.08,
    -0.07,
    -0.060000000000000005,
    -0.05,
    -0.04000000000000001,
    -0.03,
    -0.020000000000000004,
    -0.010000000000000009,
    5.55111512312578e-19,
    0.009999999999999997,
    0.01999999999999999,
    0.030000000000000002,
    0.04000000000000001,
    0.04999999999999999,
    0.060000000000000005,
    0.07,
    0.07999999999999999,
    0.09,
    0.1,
]
W_A = [
    0.0,
    -0.3090169943768054,
    -0.587785252293067,
    -0.8090169943744233,
    -0.9510565162950946,
    -1.0,
    -0.9510565162953614,
    -0.8090169943751331,
    -0.5877852522926099,
    -0.3090169943743379,
    9.106129127009649e-13,
    0.30901699437512675,
    0.5877852522922695,
    0.8090169943752222,
    0.9510565162962542,
    0.9999999999997384,
    0.9510565162931756,
    0.8090169943741848,
    0.5877852522934043,
    0.3090169943765128,
    0.0,
]
W_B = [
    0.0,
    -0.30901699437680985,
    -0.5877852522930749,
    -0.8090169943744318,
    -0.9510565162950995,
    -1.0,
    -0.9510565162953559,
    -0.8090169943751245,
    -0.5877852522926027,
    -0.3090169943743366,
    8.996004112207978e-13,
    0.30901699437509783,
    0.5877852522922191,
    0.8090169943751497,
    0.9510565162961631,
    0.9999999999996346,
    0.9510565162930698,
    0.8090169943740895,
    0.587785252293332,
    0.3090169943764742,
    0.0,
]


def test_a_figure_of_numbers_that_differ_in_rounding_is_the_same_file(tmp_path):
    """Section A drawn from W_A and from W_B: the same PNG (the data at eight digits)."""
    pytest.importorskip("matplotlib")
    from unibuckle_fenicsx.viz.plotting import plot_section

    assert max(abs(a - b) for a, b in zip(W_A, W_B, strict=True)) < 2e-13
    paths = [
        plot_section(tmp_path / f"{k}.png", X, w, X, w, zone_x=(-0.04, 0.04))
        for k, w in enumerate((W_A, W_B))
    ]
    assert paths[0].read_bytes() == paths[1].read_bytes()
