"""Benchmark: a sweep in one process and under mpiexec, the speed-up, the same lines.

The SSSS plate of the garland demo (b = 1 m, t/b = 1e-3, cells of b/12, whole-plate
obstacle) swept over a/b; ``unibuckle sweep`` runs once serially and once under
``mpiexec -n P`` (one point per rank), each from an empty file, and the table gives the
wall times, the speed-up and whether the two files are identical. With ``--json FILE``
each row is also appended to FILE as one JSON line.

Usage: python bench/bench_sweep.py [--ranks 2] [--vary plate.length=0.5:2.25:8] [--json FILE]
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _results import append_rows

BASE = """\
name = "ssss"
[plate]
corners = [[0.0, 0.0], [1.0, 1.0]]
thickness = 0.001
[material]
E = 1.0e9
nu = 0.3
[edges.left]
normal_stress = -1.0
[edges.right]
normal_stress = -1.0
[mesh]
size = 0.08333333333333333
[obstacle]
zone = "all"
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ranks", type=int, default=2)
    parser.add_argument("--vary", default="plate.length=0.5:2.25:8")
    parser.add_argument("--json", help="append one JSON line per row to this file")
    args = parser.parse_args()
    bindir = Path(sys.executable).parent
    mpiexec = shutil.which("mpiexec", path=str(bindir)) or "mpiexec"
    cli = Path(__file__).resolve().parents[1] / "unibuckle_fenicsx" / "cli.py"
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp) / "base.toml"
        base.write_text(BASE)
        times, files = {}, {}
        for ranks in (1, args.ranks):
            out = Path(tmp) / f"n{ranks}.jsonl"
            cmd = [sys.executable, str(cli), "sweep", "--config", str(base), "--vary", args.vary]
            cmd += ["--json", str(out), "-q"]
            if ranks > 1:
                cmd = [mpiexec, "-n", str(ranks), *cmd]
            t0 = time.perf_counter()
            subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL)
            times[ranks] = time.perf_counter() - t0
            files[ranks] = out.read_text()
        points = files[1].count("\n")
    same = "yes" if files[1] == files[args.ranks] else "NO"
    print(f"sweep {args.vary} ({points} points), SSSS a/b, whole-plate obstacle, h = b/12")
    print("| ranks | points | wall time (s) | s per point | speed-up | same lines as serial |")
    print("|---|---|---|---|---|---|")
    for ranks in (1, args.ranks):
        print(
            f"| {ranks} | {points} | {times[ranks]:.1f} | {times[ranks] / points:.2f} | "
            f"{times[1] / times[ranks]:.2f} | {'-' if ranks == 1 else same} |"
        )
    rows = [
        {
            "vary": args.vary,
            "ranks": ranks,
            "points": points,
            "wall_s": times[ranks],
            "s_per_point": times[ranks] / points,
            "speed_up": times[1] / times[ranks],
            "same_lines_as_serial": None if ranks == 1 else same == "yes",
        }
        for ranks in (1, args.ranks)
    ]
    append_rows(args.json, rows)


if __name__ == "__main__":
    main()
