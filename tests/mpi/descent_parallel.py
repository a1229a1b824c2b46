"""Feasible descent on a mesh distributed over the ranks; JSON on rank 0.

Usage: mpiexec -n 2 python descent_parallel.py PROBLEM.json

From the left half of the (4 m long) plate in contact, made admissible, as
tests/unit/algorithms/test_descent.py does serially, then the descent; prints the load, the contact
set's coordinates and the number of steps.
"""

from __future__ import annotations

import json
import sys

from mpi4py import MPI

import numpy as np

from unibuckle_fenicsx.algorithms.descent import admissible_start, descend
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.spec import load_problem

problem = build_problem(load_problem(sys.argv[1]), MPI.COMM_WORLD)
assert problem.contact is not None
left = np.flatnonzero(problem.contact.coordinates[:, 0] <= 2.0)
start, _ = admissible_start(problem, problem.evaluate(left), 100)
assert start is not None
run, steps = descend(problem, start, 300)
assert run.final is not None
active = run.final.active.tolist()
# Every rank must hold the same answer.
assert MPI.COMM_WORLD.allgather(active).count(active) == MPI.COMM_WORLD.size
if MPI.COMM_WORLD.rank == 0:
    print(
        json.dumps(
            {
                "status": run.status,
                "load": run.final.load,
                "coordinates": problem.contact.coordinates[run.final.active].tolist(),
                "steps": steps,
            }
        )
    )
problem.destroy()
