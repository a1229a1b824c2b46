"""Low-rank certificate of one contact set of a thin long plate, on the ranks given.

Usage: python lowrank_parallel.py NX NY NODES (comma-separated contact nodes). Prints one
JSON line on rank 0: the load, the verified bound, the route and the low-rank record.
"""

from __future__ import annotations

import json
import sys

from mpi4py import MPI

import numpy as np

from unibuckle_fenicsx.certificate.copositivity import BoundOptions, copositivity_bound
from unibuckle_fenicsx.certificate.copositivity_lowrank import LowRankOptions
from unibuckle_fenicsx.model.problem import BucklingProblem
from unibuckle_fenicsx.spec import ObstacleSpec
from unibuckle_fenicsx.spec.cases import plate_case

#: One delta, no time budget: the same work on every partition.
OPTIONS = BoundOptions(lowrank=LowRankOptions(deltas=(1e-3,), fallback=(), time_budget=None))


def certificate(comm: MPI.Comm, nx: int, ny: int, active: np.ndarray) -> dict:
    """The low-rank certificate of the contact set ``active`` (a thin SSSS plate)."""
    spec = plate_case("thin", length=0.3, width=0.1, thickness=1e-4, nx=nx, ny=ny,
                      zone=ObstacleSpec(zone="all"))  # fmt: skip
    with BucklingProblem(spec, comm) as problem:
        problem.solve_free()
        cand = problem.evaluate(active)
        bound = copositivity_bound(problem, cand, [], OPTIONS)
        lowrank = bound.lowrank or {}
        return {
            "load": cand.load,
            "value": bound.value,
            "method": bound.method,
            "m": bound.negative_eigenvalues,
            "r": lowrank.get("r"),
            "pieces": lowrank.get("pieces"),
        }


if __name__ == "__main__":
    nx, ny = int(sys.argv[1]), int(sys.argv[2])
    nodes = np.array([int(k) for k in sys.argv[3].split(",")], dtype=np.int64)
    out = certificate(MPI.COMM_WORLD, nx, ny, nodes)
    if MPI.COMM_WORLD.rank == 0:
        print(json.dumps(out))
