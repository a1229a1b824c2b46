"""The free solve shifted near a coarse-mesh estimate, on a distributed mesh.

``mpiexec -n P python tests/mpi/free_estimate.py`` prints, on rank 0, the paper's free
load at 48x24 (its estimate made at 12x6: the threshold is lowered to this small mesh)
and the number of shifts its proof took; ``tests/unit/la/test_free_solve.py`` compares 1 and 2
ranks.
"""

from __future__ import annotations

from mpi4py import MPI

import unibuckle_fenicsx.model.build as build_module
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.spec.cases import paper_case

build_module.FREE_ESTIMATE_DOFS = 0
with build_problem(paper_case("free", 48, 24), MPI.COMM_WORLD) as problem:
    load = problem.solve_free().load
    proof = problem.free_proof
    assert proof is not None
    if MPI.COMM_WORLD.rank == 0:
        print(f"{load!r} {len(proof.shifts)}")
