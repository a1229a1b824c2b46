"""``unibuckle`` with an error forced on one rank: ``python one_rank_fails.py KIND RANK ARGS``.

KIND "input" raises an InputError, "bug" a RuntimeError, on rank RANK (-1: every rank)
where the free eigen solve starts; the other ranks enter that solve, a collective call
the failed rank never makes. ARGS are the command line of ``unibuckle``.
"""

from __future__ import annotations

import sys

from mpi4py import MPI

import unibuckle_fenicsx.model.problem as problem_module
from unibuckle_fenicsx import cli
from unibuckle_fenicsx.errors import InputError

kind, rank = sys.argv[1], int(sys.argv[2])
original = problem_module.BucklingProblem.solve_free


def solve_free(self):
    here = MPI.COMM_WORLD.rank
    if rank in (-1, here):
        if kind == "input":
            raise InputError(f"an error forced on rank {here}")
        raise RuntimeError(f"a bug forced on rank {here}")
    return original(self)


problem_module.BucklingProblem.solve_free = solve_free
sys.exit(cli.main(sys.argv[3:]))
