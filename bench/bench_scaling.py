"""Strong scaling of the mesh-distributed solve: 1 -> 2 ranks, wall time and peak memory.

Usage::

    .venv/bin/python bench/bench_scaling.py --nx 320 --ny 160 --ranks 1 2 --cases free c1

The driver launches ``mpiexec -n P`` on this file in worker mode for every (case, P),
keeps the fastest of ``--repeat`` runs, and prints a Markdown table: set-up (mesh,
prestress, assembly), solve (free eigen solve plus, for c1, the active-set algorithm), total
wall time, speed-up, parallel efficiency and peak resident memory per rank
(``getrusage`` max RSS, which includes the ~150 MB of the Python/DOLFINx runtime). The
loads of every run are printed too: they must not depend on P. With ``--json FILE`` each
row is also appended to FILE as one JSON line.

Note:
    Timings are only meaningful on an otherwise idle machine with at least max(P) cores.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

from _results import append_rows


def worker(case: str, nx: int, ny: int, method: str) -> None:
    """One run under mpiexec; rank 0 prints a JSON line."""
    from mpi4py import MPI

    from unibuckle_fenicsx.analysis import solve
    from unibuckle_fenicsx.spec.cases import paper_case

    comm = MPI.COMM_WORLD
    spec = paper_case(case, nx, ny)
    if case != "free":
        spec = spec.with_solver(method=method)
    comm.Barrier()
    t0 = time.perf_counter()
    with solve(spec, comm) as analysis:
        result = analysis.result
    comm.Barrier()
    total = time.perf_counter() - t0
    rss_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # Linux: KiB
    setup = result.timings.get("setup_s", float("nan"))
    report = {
        "case": case,
        "method": result.method,
        "ranks": comm.size,
        "dofs": result.dofs,
        "constrained_nodes": result.constrained_nodes,
        "load_Pa": result.critical_load_Pa,
        "free_load_Pa": result.free_load_Pa,
        "eigensolves": result.eigensolves,
        "setup_s": comm.allreduce(setup, op=MPI.MAX),
        "solve_s": total - comm.allreduce(setup, op=MPI.MAX),
        "total_s": total,
        "peak_rss_mb": comm.gather(rss_mb, root=0),
    }
    if comm.rank == 0:
        print(json.dumps(report), flush=True)


def run(case: str, nx: int, ny: int, ranks: int, method: str, timeout: float) -> dict:
    """Launch one worker under ``mpiexec -n ranks`` and parse its report."""
    mpiexec = shutil.which("mpiexec", path=str(Path(sys.executable).parent)) or "mpiexec"
    cmd = [mpiexec, "-n", str(ranks), sys.executable, __file__, "--worker"]
    cmd += ["--cases", case, "--nx", str(nx), "--ny", str(ny), "--method", method]
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{proc.stdout}\n{proc.stderr}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def table(rows: list[dict]) -> str:
    """Markdown table of the reports, speed-up relative to the 1-rank run of each case."""
    lines = [
        "| case | method | DOFs | ranks | set-up (s) | solve (s) | total (s) | speed-up "
        "| efficiency | eigensolves | peak RSS per rank (MB) | load (Pa) |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|",
    ]
    base = {r["case"]: r["total_s"] for r in rows if r["ranks"] == 1}
    for r in rows:
        speedup = base.get(r["case"], float("nan")) / r["total_s"]
        efficiency = speedup / r["ranks"]
        rss = ", ".join(f"{m:.0f}" for m in r["peak_rss_mb"])
        lines.append(
            f"| {r['case']} | {r['method']} | {r['dofs']} | {r['ranks']} | {r['setup_s']:.2f} "
            f"| {r['solve_s']:.2f} | {r['total_s']:.2f} | {speedup:.2f} | {efficiency:.2f} "
            f"| {r['eigensolves']} | {rss} | {r['load_Pa']:.6e} |"
        )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--nx", type=int, default=320, help="cells along x (default 320)")
    parser.add_argument("--ny", type=int, default=160, help="cells along y (default 160)")
    parser.add_argument("--ranks", type=int, nargs="+", default=[1, 2], help="rank counts")
    parser.add_argument(
        "--cases", nargs="+", default=["free", "c1"], help="paper cases (default free c1)"
    )
    parser.add_argument(
        "--method", default="active-set", help="unilateral method for c1..c3 (default active-set)"
    )
    parser.add_argument("--repeat", type=int, default=1, help="keep the fastest of N runs")
    parser.add_argument("--timeout", type=float, default=1800.0, help="seconds per run")
    parser.add_argument("--json", help="append one JSON line per row to this file")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args.cases[0], args.nx, args.ny, args.method)
        return

    rows = []
    for case in args.cases:
        for ranks in args.ranks:
            runs = [
                run(case, args.nx, args.ny, ranks, args.method, args.timeout)
                for _ in range(args.repeat)
            ]
            best = min(runs, key=lambda r: r["total_s"])
            rows.append(best)
            print(
                f"{case} {args.nx}x{args.ny} P={ranks}: {best['total_s']:.2f} s, "
                f"load {best['load_Pa']:.10e} Pa",
                file=sys.stderr,
                flush=True,
            )
    print(table(rows))
    loads: dict[str, list[float]] = {}
    for r in rows:
        loads.setdefault(r["case"], []).append(r["load_Pa"])
    for case, values in loads.items():
        spread = (max(values) - min(values)) / min(values)
        print(f"{case}: load spread over rank counts {spread:.1e} (relative)")
    append_rows(args.json, rows)


if __name__ == "__main__":
    main()
