"""Active-set solve on a mesh distributed over the ranks; JSON on rank 0.

Usage: mpiexec -n 2 python active_parallel.py CASE NX NY   (a paper case: c1, c2, c3)
       mpiexec -n 2 python active_parallel.py PROBLEM.json  (any problem file)
"""

from __future__ import annotations

import json
import sys

from mpi4py import MPI

from unibuckle_fenicsx.algorithms.active_set import solve_active_set
from unibuckle_fenicsx.model.problem import BucklingProblem
from unibuckle_fenicsx.spec import load_problem
from unibuckle_fenicsx.spec.cases import paper_case

if sys.argv[1].endswith((".json", ".toml")):
    spec = load_problem(sys.argv[1])
else:
    spec = paper_case(sys.argv[1], int(sys.argv[2]), int(sys.argv[3]))
problem = BucklingProblem(spec, MPI.COMM_WORLD)
sol = solve_active_set(problem)
assert problem.contact is not None
coords = problem.contact.coordinates[sol.active].tolist()
# Every rank must hold the same answer.
assert (
    MPI.COMM_WORLD.allgather(sol.active.tolist()).count(sol.active.tolist()) == MPI.COMM_WORLD.size
)
if MPI.COMM_WORLD.rank == 0:
    print(
        json.dumps(
            {
                "load": sol.load,
                "coordinates": coords,
                "kkt": sol.candidate.kkt,
                "fallback": sol.details.get("fallback"),
            }
        )
    )
problem.destroy()
