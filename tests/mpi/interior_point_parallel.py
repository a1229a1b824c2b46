"""The interior-point route on a mesh distributed over the ranks; JSON on rank 0.

Usage: mpiexec -n 2 python interior_point_parallel.py PROBLEM.json
"""

from __future__ import annotations

import json
import sys

from mpi4py import MPI

import numpy as np

from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.spec import load_problem

spec = load_problem(sys.argv[1])
with solve(spec, MPI.COMM_WORLD) as analysis:
    sol, cert = analysis.solution, analysis.certificate
    assert sol is not None and cert is not None
    problem = analysis.problem
    assert problem.contact is not None
    active = sol.active.tolist()
    # Every rank must hold the same answer.
    assert MPI.COMM_WORLD.allgather(active).count(active) == MPI.COMM_WORLD.size
    values = problem.contact.values(sol.candidate.mode.x.petsc_vec)
    report = {
        "method": analysis.result.method,
        "load": sol.load,
        "coordinates": problem.contact.coordinates[sol.active].tolist(),
        "kkt": cert.kkt,
        "smallest": cert.smallest_of_reduced,
        "on_contact": float(np.abs(values[sol.active]).max(initial=0.0)),
    }
if MPI.COMM_WORLD.rank == 0:
    print(json.dumps(report))
