"""The nonlinear load path under mpiexec: the mesh distributed over the ranks.

``mpiexec -n P python tests/mpi/nonlinear_path.py NX NY DELTA`` runs
:func:`unibuckle_fenicsx.nonlinear.solve_nonlinear` on the paper's case c1 and prints on
rank 0 one JSON line: the path (load, max |w|, contact nodes, end shortening per step),
the Southwell and inflection loads, the linear load and the contact check.
"""

from __future__ import annotations

import json
import sys

from mpi4py import MPI

from unibuckle_fenicsx import paper_case
from unibuckle_fenicsx.nonlinear import NonlinearOptions, solve_nonlinear


def collect(comm: MPI.Comm, nx: int, ny: int, delta: float) -> dict:
    """The path of c1 on an nx x ny mesh with imperfection delta (collective)."""
    options = NonlinearOptions(imperfection=delta)
    with solve_nonlinear(paper_case("c1", nx, ny), options, comm) as analysis:
        result = analysis.result
        return {
            "ranks": comm.size,
            "path": result.path,
            "southwell": result.southwell_load_Pa,
            "inflection": result.inflection_load_Pa,
            "linear": result.linear_critical_load_Pa,
            "contact_check": result.contact_check,
            "dofs": result.dofs,
        }


if __name__ == "__main__":
    nx, ny, delta = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])
    report = collect(MPI.COMM_WORLD, nx, ny, delta)
    if MPI.COMM_WORLD.rank == 0:
        print(json.dumps(report))
