"""Benchmarks of the paper's enumeration (``--method enumerate``), through the CLI.

Two studies, each printing a Markdown table:

- ``scan``: for each of the paper's zones, meshes of aspect 2:1 of increasing size; the
  constrained-node count i, p*, the candidate sets evaluated and the wall time, until a
  run exceeds the time budget (default 60 s). The refusal limit ``--max-candidates`` is
  lifted (the worst-case count 2^i is far above it); the paper's stopping rule applies.
- ``parallel``: one case with a few thousand candidate sets (default c1 on 8 x 5 with
  ``--complete``: 2^12 = 4096 sets), serial versus ``mpiexec -n 2 --candidate-parallel``.

Usage::

    python bench/bench_enumeration.py scan [--budget 60] [--zones c1 c2 c3] [--json FILE]
    python bench/bench_enumeration.py parallel [--case c1 --nx 8 --ny 5] [--repeat 3]
        [--json FILE]

Timings depend on the machine's load; the table header prints the load average. With
``--json FILE`` each row is also appended to FILE as one JSON line.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _results import append_rows

BIN = Path(sys.executable).parent
MESHES = {
    "c1": [(8, 4), (10, 5), (12, 6), (14, 7), (16, 8), (18, 9), (20, 10)],
    "c2": [(8, 4), (12, 6), (16, 8), (20, 10), (24, 12), (28, 14), (32, 16)],
    "c3": [(4, 2), (6, 3), (8, 4), (10, 5), (12, 6)],
}


def run_cli(
    case: str, nx: int, ny: int, extra: list[str], nprocs: int = 1, timeout: float = 600
) -> tuple[dict | None, float]:
    """Run ``unibuckle solve`` (under mpiexec if nprocs > 1); (JSON or None on timeout, wall)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out.json"
        cmd = [str(BIN / "unibuckle"), "solve", "--case", case, "--nx", str(nx), "--ny", str(ny)]
        cmd += ["--method", "enumerate", "--max-candidates", str(10**30), "--json", str(out)]
        cmd += extra
        if nprocs > 1:
            cmd = [str(BIN / "mpiexec"), "-n", str(nprocs), *cmd]
        env = {**os.environ, "OMP_NUM_THREADS": "1"}
        t0 = time.perf_counter()
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env)
        except subprocess.TimeoutExpired:
            return None, time.perf_counter() - t0
        wall = time.perf_counter() - t0
        if proc.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)} failed:\n{proc.stderr}")
        return json.loads(out.read_text()), wall


def scan(zones: list[str], budget: float, json_path: str | None) -> None:
    print(f"load average before: {os.getloadavg()[0]:.2f} (2 cores, shared)\n")
    print("| zone | mesh | i | p* | sets evaluated | lambda_c (MPa) | proven | solve wall (s) |")
    print("|---|---|---|---|---|---|---|---|")
    for zone in zones:
        for nx, ny in MESHES[zone]:
            data, _ = run_cli(zone, nx, ny, [], timeout=budget)
            if data is None:
                print(f"| {zone} | {nx}x{ny} | | | | | | > {budget:.0f} (stopped) |", flush=True)
                break
            d = data["details"]
            print(
                f"| {zone} | {nx}x{ny} | {data['constrained_nodes']} | {data['p_star']} "
                f"| {d['candidates_evaluated']} | {data['critical_load_Pa'] / 1e6:.4f} "
                f"| {'yes' if data['certificate']['global_optimum_proven'] else 'no'} "
                f"| {data['wall_time_s']:.1f} |",
                flush=True,
            )
            row = {
                "study": "scan",
                "zone": zone,
                "mesh": f"{nx}x{ny}",
                "constrained_nodes": data["constrained_nodes"],
                "p_star": data["p_star"],
                "candidates_evaluated": d["candidates_evaluated"],
                "critical_load_Pa": data["critical_load_Pa"],
                "proven": data["certificate"]["global_optimum_proven"],
                "wall_time_s": data["wall_time_s"],
            }
            append_rows(json_path, [row])


def parallel(
    case: str, nx: int, ny: int, complete: bool, repeat: int, json_path: str | None
) -> None:
    extra = ["--complete"] if complete else []
    print(f"load average before: {os.getloadavg()[0]:.2f} (2 cores, shared)\n")
    print("| ranks | sets | enumeration wall (s), best of runs | total wall (s) | speed-up |")
    print("|---|---|---|---|---|")
    base = None
    for nprocs in (1, 2):
        best, total, sets = float("inf"), float("inf"), 0
        results = []
        for _ in range(repeat):
            flags = extra + (["--candidate-parallel"] if nprocs > 1 else [])
            data, wall = run_cli(case, nx, ny, flags, nprocs)
            assert data is not None
            results.append((data["critical_load_Pa"], data["contact_indices"]))
            best = min(best, data["details"]["enumeration_wall_s"])
            total = min(total, wall)
            sets = data["details"]["candidates_evaluated"]
        base = base or best
        assert all(r == results[0] for r in results)
        print(f"| {nprocs} | {sets} | {best:.2f} | {total:.2f} | {base / best:.2f} |", flush=True)
        row = {
            "study": "parallel",
            "case": case,
            "mesh": f"{nx}x{ny}",
            "complete": complete,
            "ranks": nprocs,
            "sets": sets,
            "enumeration_wall_s": best,
            "total_wall_s": total,
            "speed_up": base / best,
        }
        append_rows(json_path, [row])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="study", required=True)
    s = sub.add_parser("scan")
    s.add_argument("--zones", nargs="+", default=list(MESHES), choices=list(MESHES))
    s.add_argument("--budget", type=float, default=60.0, help="seconds per run")
    p = sub.add_parser("parallel")
    p.add_argument("--case", default="c1")
    p.add_argument("--nx", type=int, default=8)
    p.add_argument("--ny", type=int, default=5)
    p.add_argument("--no-complete", action="store_true", help="paper's stopping rule")
    p.add_argument("--repeat", type=int, default=3)
    for study in (s, p):
        study.add_argument("--json", help="append one JSON line per row to this file")
    args = parser.parse_args()
    if args.study == "scan":
        scan(args.zones, args.budget, args.json)
    else:
        parallel(args.case, args.nx, args.ny, not args.no_complete, args.repeat, args.json)


if __name__ == "__main__":
    main()
