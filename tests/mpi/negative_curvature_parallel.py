"""The direction of most negative curvature on a mesh distributed over the ranks.

Usage: mpiexec -n 2 python negative_curvature_parallel.py PROBLEM.json LOAD VECTORS

Prints, on rank 0, the JSON of the Rayleigh–Ritz value over ``VECTORS`` Krylov vectors
at the pressure deflection and the load ``LOAD`` (the serial test's set-up).
"""

from __future__ import annotations

import json
import sys
from dataclasses import replace
from pathlib import Path

from mpi4py import MPI

from unibuckle_fenicsx.algorithms.interior_point import InteriorPointNewton, NewtonOptions
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.spec import load_problem

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from support.newton import at_saddle

spec = load_problem(sys.argv[1])
lam, vectors = float(sys.argv[2]), int(sys.argv[3])
problem = build_problem(spec, MPI.COMM_WORLD)
with InteriorPointNewton(problem, replace(NewtonOptions(), curvature_vectors=vectors)) as newton:
    u, *_ = at_saddle(newton, lam)
    found = newton.curvature.find(u.x.petsc_vec, lam)
    assert found is not None
problem.destroy()
if MPI.COMM_WORLD.rank == 0:
    print(json.dumps({"theta": found[0]}))
