r"""Obstacles with a gap: w <= g (above) in the nonlinear analysis, left out of the linear one.

Expected values:

- the linear critical state of a plate with an obstacle at a gap is the free plate's
  (an infinitesimal buckle does not reach it);
- until the plate reaches the obstacle, the load path is that of the plate without it
  (the bounds are inactive): the same loads and deflections, step by step; the paper's
  plate buckles in the antisymmetric mode (m = 2: one lobe up, one down, equal by the
  symmetry x -> -x, w -> -w), so its largest upward deflection is max |w|, and the plate
  reaches a whole-plate obstacle above at gap g at the first step where the free path's
  max |w| reaches g;
- at the end, w <= g at every zone node and the obstacle only pushes (contact check);
- the knee of the gapped path lies between the free load (the linear state's) and the
  linear unilateral load with the gap closed, computed here by a separate linear solve
  of the same plate with ``gap = 0``: the obstacle stiffens the plate only once reached.
  With a gap no linear load is the answer, so the verdict validates none; a load 8 %
  above the linear one (a small gap's run) is never called validated.
"""

from __future__ import annotations

import json

from mpi4py import MPI

import pytest

from support.paths import ROOT
from support.processes import run_mpi
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.spec import ObstacleSpec, problem_from_dict, problem_to_dict

CLI = ROOT / "unibuckle_fenicsx" / "cli" / "__main__.py"
GAP = 0.003  # m: half the paper plate's thickness
DATA = {"mesh": {"nx": 8, "ny": 8}, "obstacle": {"zone": "all", "gap": GAP}}


def test_gap_is_read_converted_and_written_back():
    spec = problem_from_dict({"units": "mm-N-MPa", "obstacle": {"zone": "all", "gap": 3.0}})
    assert spec.obstacle.gap == pytest.approx(GAP)
    assert problem_from_dict(problem_to_dict(spec, units="mm-N-MPa")) == spec
    assert spec.gapped_obstacles == (spec.obstacle,) and spec.unilateral_obstacles == ()
    with pytest.raises(ValueError, match=r"obstacle\.gap must be >= 0 m"):
        ObstacleSpec(gap=-1e-3)
    with pytest.raises(ValueError, match=r"obstacle\.gap: a gap is modelled for rigid obstacles"):
        ObstacleSpec(gap=1e-3, foundation_stiffness=1e6)


def test_the_linear_critical_state_leaves_a_gapped_obstacle_out():
    spec = problem_from_dict(DATA)
    free = problem_from_dict({"mesh": DATA["mesh"]})
    with solve(spec, MPI.COMM_WORLD) as a, solve(free, MPI.COMM_WORLD) as b:
        assert a.result.critical_load_Pa == b.result.critical_load_Pa
        assert a.result.method == "free" and "with a gap" in a.result.details.gapped_obstacles


def _paths():
    from unibuckle_fenicsx.nonlinear import NonlinearOptions, solve_nonlinear

    spec = problem_from_dict(DATA)
    out = []
    for obstacle in (True, False):
        options = NonlinearOptions(obstacle=obstacle, max_load=1.15)
        with solve_nonlinear(spec, options, MPI.COMM_WORLD) as analysis:
            out.append(analysis.result)
    return out


def test_the_path_reaches_the_obstacle_across_its_gap():
    gapped, free = _paths()
    k = next(i for i, q in enumerate(gapped.path) if q["contact_nodes"])
    assert gapped.contact_load_Pa == gapped.path[k]["load_Pa"]
    for q, r in zip(gapped.path[:k], free.path[:k], strict=True):
        assert q["load_Pa"] == r["load_Pa"]
        assert q["max_w_m"] == pytest.approx(r["max_w_m"], rel=1e-8)
    # The free plate passes max |w| = g at step k (same load), the gapped one stops there.
    assert free.path[k]["load_Pa"] == gapped.path[k]["load_Pa"]
    assert free.path[k - 1]["max_w_m"] < GAP <= free.path[k]["max_w_m"]
    assert gapped.path[k]["max_w_m"] <= free.path[k]["max_w_m"]
    assert 1.0 < gapped.contact_load_Pa / gapped.linear_critical_load_Pa < 1.15
    check = gapped.contact_check
    assert check["satisfied"] and check["max_zone_w_m"] <= 0.0 and check["contact_nodes"] > 0
    assert gapped.path[-1]["max_w_m"] < free.path[-1]["max_w_m"]  # the obstacle holds it
    assert "the plate reaches the obstacle at lambda" in gapped.summary()


def test_the_gapped_knee_lies_between_the_free_and_the_gap_closed_loads():
    gapped, free = _paths()
    closed_data = {**DATA, "obstacle": {"zone": "all", "gap": 0.0}}
    with solve(problem_from_dict(closed_data), MPI.COMM_WORLD) as analysis:
        closed = analysis.result.critical_load_Pa
    assert gapped.gapped and not free.gapped
    assert gapped.unilateral_load_Pa == pytest.approx(closed, rel=1e-10)
    assert gapped.linear_critical_load_Pa == free.linear_critical_load_Pa < closed
    for load in (gapped.southwell_load_Pa, gapped.inflection_load_Pa):
        assert gapped.linear_critical_load_Pa * 0.99 <= load <= closed * 1.01
    assert gapped.certified and "with a gap the knee lies between the free load" in gapped.verdict
    assert "no linear load is validated" in gapped.summary()
    assert "x free" in gapped.summary() and "gaps closed" in gapped.summary()


def _hand_result(southwell, inflection, *, gap=False, closed=None, linear=1.5e4):
    """A complete path with these loads read off it (a NonlinearResult by hand)."""
    from unibuckle_fenicsx.nonlinear import NonlinearResult

    return NonlinearResult(
        case="plate", mesh=[12, 6], dofs=1, obstacle=True, control="load", imperfection=1e-3,
        imperfection_shape="unilateral", thickness_m=2e-4, linear_critical_load_Pa=linear,
        free_load_Pa=linear, linear_method="free", southwell_load_Pa=southwell,
        southwell_points=5, inflection_load_Pa=inflection, southwell_ratio=southwell / linear,
        inflection_ratio=inflection / linear, completed=True,
        path=[{"load_Pa": 0.0, "max_w_m": 2e-7, "contact_nodes": 0, "end_shortening_m": 0.0},
              {"load_Pa": 1.2 * linear, "max_w_m": 1e-4, "contact_nodes": 6,
               "end_shortening_m": 1e-6}],
        stop_reason="reached 1.2 x the linear critical load", rejected_steps=0,
        constrained_nodes=91, contact_check={"satisfied": True}, options={"max_load": 1.2},
        wall_time_s=1.0, gapped=gap, unilateral_load_Pa=closed,
    )  # fmt: skip


def test_a_load_8_percent_away_is_never_validated(capsys):
    """The issue's run (gap 4e-6 m = 0.02 t): Southwell 8.6 %, inflection 13.6 % above.

    Without the gap known, those loads were compared with the free load alone and the
    run exited 0; a path whose loads lie 8 % from the linear load validates nothing.
    """
    linear = 1.503291e4
    plain = _hand_result(1.632729e4, 1.707346e4, linear=linear)
    assert not plain.certified
    text = plain.shortfall()
    validated, _, missing = text.partition("Not validated:")
    assert "Validated: the contact conditions" in validated and "Southwell" not in validated
    assert "the Southwell load 1.632729e+04 Pa (+8.6e-02 relative): more than 1% from" in missing
    # With the gap known: between the free load and the gap-closed one, consistent.
    gapped = _hand_result(1.632729e4, 1.707346e4, gap=True, closed=1.70949e4, linear=linear)
    assert gapped.certified
    summary = gapped.summary()
    assert "no linear load is validated" in summary and "validated:" not in summary
    # Above the gap-closed load: not consistent, exit 3's message says so.
    above = _hand_result(1.632729e4, 1.25 * linear, gap=True, closed=1.70949e4, linear=linear)
    assert not above.certified
    assert "Not consistent: the inflection load" in above.shortfall()


@pytest.mark.mpi
@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="launches mpiexec itself")
def test_the_gapped_path_on_two_ranks_is_the_serial_one(tmp_path):
    """``unibuckle nonlinear`` under mpiexec -n 2: the serial path and contact load."""
    from unibuckle_fenicsx.cli import main

    problem = tmp_path / "gap.toml"
    problem.write_text(f'[mesh]\nnx = 6\nny = 6\n[obstacle]\nzone = "all"\ngap = {GAP}\n')
    args = ["nonlinear", "--config", str(problem), "--max-load", "1.1", "-q", "--json"]
    assert main([*args, str(tmp_path / "serial.json")]) == 0
    run_mpi(CLI, 2, *args, str(tmp_path / "parallel.json"))
    serial, parallel = (
        json.loads((tmp_path / f"{n}.json").read_text()) for n in ("serial", "parallel")
    )
    assert parallel["mpi_size"] == 2 and len(parallel["path"]) == len(serial["path"])
    assert serial["contact_load_Pa"] is not None
    assert parallel["contact_load_Pa"] == pytest.approx(serial["contact_load_Pa"], rel=1e-8)
    for p, s in zip(parallel["path"], serial["path"], strict=True):
        assert p["load_Pa"] == pytest.approx(s["load_Pa"], rel=1e-8)
        assert p["max_w_m"] == pytest.approx(s["max_w_m"], rel=1e-6)
        assert p["contact_nodes"] == s["contact_nodes"]
