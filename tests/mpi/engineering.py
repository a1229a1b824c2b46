"""Solve problem files on a mesh distributed over the ranks; JSON of the results on rank 0.

Usage: ``mpiexec -n 2 python engineering.py PROBLEMS.json``: a JSON list of TOML-shaped
problem mappings; prints one JSON list of :func:`summary` per problem.
"""

from __future__ import annotations

import json
import sys
from typing import Any

from mpi4py import MPI

from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.spec import problem_from_dict

#: Result keys compared between serial and parallel runs (those present).
KEYS = (
    "critical_load_Pa",
    "free_load_Pa",
    "contact_coordinates",
    "critical_load_factor",
    "critical_temperature_K",
    "design",
)


def summary(data: dict[str, Any], comm: MPI.Comm) -> dict[str, Any]:
    """The compared numbers of one problem's solve."""
    with solve(problem_from_dict(data), comm) as analysis:
        out = analysis.result.as_dict(timings=False)
    picked = {key: out[key] for key in KEYS if key in out}
    picked["kkt"] = (out.get("certificate") or {}).get("kkt")
    picked["point_restraints"] = out["details"].get("point_restraints")
    return picked


def main() -> None:
    problems = json.loads(open(sys.argv[1]).read())
    results = [summary(data, MPI.COMM_WORLD) for data in problems]
    if MPI.COMM_WORLD.rank == 0:
        print(json.dumps(results))


if __name__ == "__main__":
    main()
