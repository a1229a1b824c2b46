"""A section solved from Python on the ranks of ``mpiexec``, every rank's log on stderr.

``mpiexec -n P python tests/mpi/section_warnings.py`` solves the hollow column of
``test_mpi.py`` (a box 50 x 50 x 5 mm, 0.6 m long, on cells of 12.5 mm: the coarse-cells
and the column's warnings) with
:func:`~unibuckle_fenicsx.section_analysis.solve_section` on ``COMM_WORLD``, a script's
logging (``logging.basicConfig``: every rank's records on stderr, led by the rank).
"""

from __future__ import annotations

import logging

from mpi4py import MPI

from unibuckle_fenicsx import SectionParameters, solve_section

COLUMN = {
    "width": 0.05, "depth": 0.05, "thickness": 0.005, "length": 0.6, "E": 2.1e11, "nu": 0.3,
    "mesh_size": 0.0125, "ends": "simply_supported",
}  # fmt: skip

if __name__ == "__main__":
    comm = MPI.COMM_WORLD
    logging.basicConfig(format=f"rank {comm.rank} %(levelname)s %(message)s")
    with solve_section(SectionParameters("box", **COLUMN), comm) as analysis:
        warnings = analysis.result.warnings
    if comm.rank == 0:
        print(len(warnings))
