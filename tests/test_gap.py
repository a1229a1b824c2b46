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
- at the end, w <= g at every zone node and the obstacle only pushes (contact check).
"""

from __future__ import annotations

import json
from pathlib import Path

from mpi4py import MPI

import pytest
from conftest import run_mpi

from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.spec import ObstacleSpec, problem_from_dict, problem_to_dict

CLI = Path(__file__).resolve().parents[1] / "unibuckle_fenicsx" / "cli.py"
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
        assert a.result.method == "free" and "with a gap" in a.result.details["gapped_obstacles"]


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
