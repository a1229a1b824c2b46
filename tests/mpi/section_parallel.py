"""A section solved on the ranks of ``mpiexec``: its loads, printed as one JSON line on rank 0.

``mpiexec -n P python tests/mpi/section_parallel.py`` solves :data:`SECTIONS` (a small box
hollow, with a rigid core and with an elastic one) with
:func:`~unibuckle_fenicsx.section_analysis.solve_section` on ``COMM_WORLD`` and prints
``{name: [critical load, free load, contact directions, KKT]}`` (and the rigid core's
``contact_indices`` and ``contact_dofs``); :func:`collect` is the
same on any communicator (the serial run of ``tests/test_mpi.py``).
"""

from __future__ import annotations

import json
from typing import Any

from mpi4py import MPI

from unibuckle_fenicsx import SectionParameters, solve_section

BOX = {
    "width": 0.1, "depth": 0.1, "thickness": 0.002, "length": 0.2, "E": 2.1e11, "nu": 0.3,
    "mesh_size": 0.025, "ends": "simply_supported",
}  # fmt: skip
SECTIONS = {
    "hollow": {},
    "rigid core": {"core": True},
    "elastic core": {"core": True, "foundation_stiffness": 1e9},
}


def collect(comm: MPI.Comm) -> dict[str, Any]:
    """Each section's [critical load, free load, contact directions, KKT] on ``comm``."""
    out = {}
    for name, changes in SECTIONS.items():
        params = SectionParameters("box", **BOX, **changes)
        levels = {"levels": 0} if params.core else {}  # a hollow section takes none
        with solve_section(params, comm, **levels) as analysis:
            r = analysis.result
            kkt = None if r.certificate is None else r.certificate.kkt
            out[name] = [r.critical_load_Pa, r.free_load_Pa, r.contact_nodes, kkt]
            if name == "rigid core":
                out["rigid core's contact"] = [r.contact_indices, r.contact_dofs]
    return out


if __name__ == "__main__":
    found = collect(MPI.COMM_WORLD)
    if MPI.COMM_WORLD.rank == 0:
        print(json.dumps(found))
