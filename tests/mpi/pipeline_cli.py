"""The command line under mpiexec: JSON written once (rank 0), VTX written collectively.

``mpiexec -n P python tests/mpi/pipeline_cli.py OUTDIR -- CLI ARGS...`` runs
``unibuckle solve CLI ARGS --json OUTDIR/result.json --output OUTDIR/vtx`` with
:func:`unibuckle_fenicsx.results.files.write_json` and
:func:`unibuckle_fenicsx.results.files.write_fields`
wrapped to count their calls per rank, and prints on rank 0 a JSON line
``{"status": [...], "json_writes": [...], "vtx_calls": [...]}`` (one entry per rank).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from mpi4py import MPI

import unibuckle_fenicsx.results.files as results
from unibuckle_fenicsx.cli import main as cli_main


def main() -> None:
    outdir = Path(sys.argv[1])
    args = sys.argv[sys.argv.index("--") + 1 :]
    comm = MPI.COMM_WORLD
    counts = {"json": 0, "vtx": 0}
    write_json, write_fields = results.write_json, results.write_fields

    def counting_json(*a, **k):
        counts["json"] += 1
        return write_json(*a, **k)

    def counting_vtx(*a, **k):
        counts["vtx"] += 1
        return write_fields(*a, **k)

    results.write_json = counting_json
    results.write_fields = counting_vtx
    if comm.rank == 0:  # the folder of --json must exist
        outdir.mkdir(parents=True, exist_ok=True)
    comm.Barrier()
    status = cli_main(
        ["solve", *args, "--json", str(outdir / "result.json"), "--output", str(outdir / "vtx")]
    )
    sys.stdout.flush()
    report = {
        "status": comm.allgather(status),
        "json_writes": comm.allgather(counts["json"]),
        "vtx_calls": comm.allgather(counts["vtx"]),
    }
    if comm.rank == 0:
        print(json.dumps(report))


if __name__ == "__main__":
    main()
