r"""Metamorphic relations: answers of related problems, in the order their definitions force.

The relations and why each holds: ``tests/support/metamorphic.py``. Two kinds of checks:

- tensionless foundations found by the random sweep (``bench/bench_metamorphic.py``,
  ``bench/bench_metamorphic.py --foundations``) to end above a stiffer foundation's load
  and above the rigid obstacle's, which the minimum of the quotient
  :math:`(a(v,v) + \sum_k \rho_k \max(0, s_k v_k)^2)/b(v,v)` cannot exceed (it grows
  pointwise with :math:`k_f`, and equals a/b on the rigid obstacle's admissible modes;
  docs/methods/foundations.md). The expected loads are the minimum over every spring
  set by dense linear algebra (``tests/support/exhaustive.py``, no code of the
  package's iteration);
- a few problems of the sweep with a fixed seed, every relation checked.
"""

from __future__ import annotations

import copy
import math

from mpi4py import MPI

import numpy as np
import pytest

from support.exhaustive import RTOL, exhaustive_tensionless
from support.metamorphic import NOTES, check_problem, random_problem
from unibuckle_fenicsx import problem_from_dict
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.materials import bending_stiffness

serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense reference is serial")

#: A thin plate (t/b = 0.01), the loaded edges clamped and simply supported (soft), a
#: foundation under a strip along the simply supported long edge (the sweep's problem 3
#: of its first seed): its free and bilateral starts ended 0.54 % above the minimum at
#: K = 100, and 1.3 % above the rigid obstacle's load at K = 3000.
STRIP = {
    "name": "strip_foundation",
    "plate": {"corners": [[0.0, 0.0], [0.3, 0.1]], "thickness": 0.001},
    "material": {"E": 1.0e9, "nu": 0.3},
    "edges": {
        "left": {"support": "clamped", "normal_stress": -1.0},
        "right": {"support": "simply_supported_soft", "normal_stress": -1.0},
        "bottom": {"support": "simply_supported"},
        "top": {"support": "clamped"},
    },
    "mesh": {"nx": 15, "ny": 5},
    "obstacle": {"zone": [[0.14, 0.26], [0.0, 0.04]], "side": "below"},
}

#: A long plate (a/b = 3) with its loaded edges clamped on a whole-face foundation, one
#: row of free nodes: at K = 10 (a soft foundation, two starts) it ended 4.9 % above
#: the minimum, at K = 300 6.4 %.
ROW = {
    "name": "row_foundation",
    "plate": {"corners": [[0.0, 0.0], [0.3, 0.1]], "thickness": 0.001},
    "material": {"E": 1.0e9, "nu": 0.3},
    "edges": {
        "left": {"support": "clamped", "normal_stress": -1.0},
        "right": {"support": "clamped", "normal_stress": -1.0},
        "bottom": {"support": "simply_supported"},
        "top": {"support": "simply_supported"},
    },
    "mesh": {"nx": 9, "ny": 2},
    "obstacle": {"zone": "all", "side": "above"},
}


def on_foundation(data: dict, K: float) -> dict:
    """``data`` with its obstacle a tensionless foundation of K = k_f b^4/(pi^4 D)."""
    d = copy.deepcopy(data)
    D = bending_stiffness(1.0e9, 0.3, d["plate"]["thickness"])
    b = d["plate"]["corners"][1][1] - d["plate"]["corners"][0][1]
    d["obstacle"]["foundation_stiffness"] = K * math.pi**4 * D / b**4
    return d


def load_and_minimum(data: dict) -> tuple[float, float]:
    """The package's load of ``data`` and the dense minimum over every spring set."""
    spec = problem_from_dict(data)
    with solve(spec, MPI.COMM_WORLD) as analysis:
        load = analysis.result.critical_load_Pa
    with build_problem(spec, MPI.COMM_WORLD) as problem:
        return load, exhaustive_tensionless(problem)


def test_a_foundation_stays_below_the_rigid_obstacle_and_a_stiffer_foundation():
    """lambda(K = 100) <= lambda(K = 3000) <= lambda_rigid (the relation alone: 2^14 sets).

    The rigid obstacle by the interior point (its answer, 620 818.57 Pa, is proven the
    minimum; "auto" would enumerate the 2^14 sets to the same load).
    """
    rigid = {**STRIP, "solver": {"method": "interior-point"}}
    loads = []
    for data in (on_foundation(STRIP, 100.0), on_foundation(STRIP, 3000.0), rigid):
        with solve(problem_from_dict(data), MPI.COMM_WORLD) as analysis:
            loads.append(analysis.result.critical_load_Pa)
    soft, stiff, rigid = loads
    assert soft <= stiff * (1 + RTOL)
    assert stiff <= rigid * (1 + RTOL)


@serial
@pytest.mark.parametrize("K", [10.0, 300.0])
def test_a_foundation_reaches_the_minimum_over_every_spring_set(K):
    """One row of free nodes: the dense minimum (before: 4.9 % and 6.4 % above it)."""
    with solve(problem_from_dict(ROW), MPI.COMM_WORLD) as analysis:
        rigid = analysis.result.critical_load_Pa
    load, minimum = load_and_minimum(on_foundation(ROW, K))
    assert load == pytest.approx(minimum, rel=RTOL)
    assert load <= rigid * (1 + RTOL)


#: (seed, n) of sweep problems that run in seconds: compression with a strip zone,
#: shear, in-plane bending (psi = -0.5), a temperature rise.
FIXED = ((2, 1), (2, 2), (2, 3))


@serial
@pytest.mark.parametrize(("seed", "n"), FIXED, ids=[f"mm{s}_{n}" for s, n in FIXED])
def test_relations_of_a_random_plate(seed, n):
    """Ordering, agreement of the methods, mirror, load scaling, zone and edge springs."""
    rng = np.random.default_rng([seed, n])
    data = random_problem(rng, f"mm{seed}_{n}")
    record, violations = check_problem(data, rng, full=False)
    assert "load" in record["auto"], record["auto"]
    assert [v for v in violations if v["relation"] not in NOTES] == []
