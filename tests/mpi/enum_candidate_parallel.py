"""Enumeration under mpiexec: candidate-parallel and distributed-mesh runs of the same cases.

Usage: ``mpiexec -n P python enum_candidate_parallel.py [--distributed] CASE:NX:NY:COMPLETE ...``.
Prints one JSON line on rank 0: per case and mode ("candidate"; with ``--distributed``
also the mesh-distributed serial enumeration), the load, the contact set, p*, the eigen
solve count, and the largest difference between ranks of the returned mode at I.
"""

from __future__ import annotations

import json
import sys

from mpi4py import MPI

import numpy as np

from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.spec.cases import paper_case


def run(case: str, nx: int, ny: int, complete: bool, candidate_parallel: bool) -> dict:
    comm = MPI.COMM_WORLD
    spec = paper_case(case, nx, ny).with_solver(method="enumerate", complete=complete)
    with solve(spec, comm, candidate_parallel=candidate_parallel) as analysis:
        result = analysis.result
        assert analysis.solution is not None
        values = analysis.solution.candidate.values
    spread = max(float(np.abs(v - values).max()) for v in comm.allgather(values))
    actives = comm.allgather(list(result.contact_indices))
    return {
        "load": result.critical_load_Pa,
        "active": result.contact_indices,
        "same_active_on_ranks": all(a == actives[0] for a in actives),
        "p_star": result.p_star,
        "eigensolves": result.eigensolves,
        "mode_spread": spread,
        "kkt": result.certificate["kkt"],
        "ranks": result.details["candidate_ranks"],
    }


def main() -> None:
    args = sys.argv[1:]
    distributed = "--distributed" in args
    out = {}
    for arg in (a for a in args if a != "--distributed"):
        case, nx, ny, complete = arg.split(":")
        key = f"{case}:{nx}:{ny}:{complete}"
        out[key] = {"candidate": run(case, int(nx), int(ny), complete == "1", True)}
        if distributed:
            out[key]["distributed"] = run(case, int(nx), int(ny), complete == "1", False)
    if MPI.COMM_WORLD.rank == 0:
        print(json.dumps(out))


if __name__ == "__main__":
    main()
