"""Benchmark: where the route's wall time goes as the mesh grows (cProfile, phases, memory).

For each mesh, a fresh process solves the benchmark plate of ``bench_plates.py``
(0.3 x 0.1 m, t = 0.1 mm, obstacle over the whole face) under ``cProfile`` (process
time: on a shared machine it moves far less than the wall time), with the exclusive phase
timers of ``bench_stages.py --phases`` on the wall clock and on the process time, and reads
its peak resident memory (``ru_maxrss``); another fresh process does the same for the
plate without obstacle (the free run). It prints

- per mesh: the whole run's and the free run's wall seconds, their ratio and peak memory;
- per phase (fine level; the coarser levels summed): wall and process seconds, calls, microseconds
  per DOF of the mesh the phase ran on, and the growth exponent p of t ~ DOFs^p from the
  mesh before (1 is linear; a sparse LDL^T of a 2D mesh costs DOFs^1.5);
- per function (cProfile's exclusive process time, ``tottime``, of the functions above
  0.2 % of the largest run's process time): seconds, calls and p, the functions whose
  p exceeds the free run's by more than 0.15 marked.

Usage: python bench/bench_profile.py [--meshes 180x60,360x120,500x166] [--case ssss]
[--top 40] [--json FILE]; with ``--load FILE`` it prints the tables of the runs stored in
FILE instead of running.
"""

from __future__ import annotations

import argparse
import cProfile
import importlib.util
import json
import math
import pstats
import resource
import subprocess
import sys
import time
import types
from collections import defaultdict
from pathlib import Path
from typing import Any

from _results import append_rows, print_header

STAGES_FILE = Path(__file__).with_name("bench_stages.py")

#: A function's time counts as growing faster than the free run where its exponent
#: exceeds the free run's by this much (the seconds of a shared machine move p by ~0.1).
MARGIN = 0.15


def _name(key: tuple[str, int, str]) -> str:
    """``file:function`` of a cProfile key, the file relative to the package or site."""
    path, line, func = key
    for anchor in ("unibuckle_fenicsx/", "site-packages/", "bench/"):
        if anchor in path:
            path = anchor.split("/")[0] + "/" + path.split(anchor, 1)[1]
            break
    return f"{path}:{line}({func})" if line else func


def worker(case: str, nx: int, ny: int, free: bool) -> None:
    """One solve in this process under cProfile; print a JSON line."""
    from mpi4py import MPI
    from petsc4py import PETSc

    from bench_plates import _spec
    from msgspec.structs import replace

    from unibuckle_fenicsx.analysis import solve

    PETSc.Log.begin()
    # The exclusive phase timers of bench_stages.py twice, each from its own copy of the
    # module: one on the wall clock, one on the process time (wrapped around the first).
    accs: dict[str, dict[tuple[str, int], list[float]]] = {}
    for clock, timer in (("phases", time.perf_counter), ("cpu_phases", time.process_time)):
        spec_ = importlib.util.spec_from_file_location(f"_stages_{clock}", STAGES_FILE)
        assert spec_ is not None and spec_.loader is not None
        stages = importlib.util.module_from_spec(spec_)
        spec_.loader.exec_module(stages)
        stages.time = types.SimpleNamespace(process_time=timer)  # type: ignore[attr-defined]
        accs[clock] = defaultdict(lambda: [0.0, 0, 0, 0])
        stages._install_phases(accs[clock])
    spec = _spec(case, nx, ny)
    if free:
        spec = replace(spec, obstacle=None)
    profile = cProfile.Profile(time.process_time)
    w0 = time.perf_counter()
    profile.enable()
    with solve(spec, MPI.COMM_WORLD) as run:
        result, solution = run.result, run.solution
        levels = [] if solution is None else getattr(solution.details, "levels", [])
        row: dict[str, Any] = {
            "dofs": result.dofs,
            "load_Pa": result.critical_load_Pa,
            "method": result.method,
            "route": list(getattr(result, "route", ()) or ()),
            "eigensolves": result.eigensolves,
            "kkt": None if run.certificate is None else run.certificate.kkt,
            "smallest": None if run.certificate is None else run.certificate.smallest_of_reduced,
            "levels": [
                [lv.mesh, lv.newton_steps, lv.factorizations, lv.eigensolves] for lv in levels
            ],
        }
    profile.disable()
    row["wall"] = time.perf_counter() - w0
    usage = resource.getrusage(resource.RUSAGE_SELF)
    row["cpu"] = usage.ru_utime + usage.ru_stime
    row["maxrss_kib"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    for clock, acc in accs.items():
        row[clock] = [[phase, n, *values] for (phase, n), values in acc.items()]
    stats = pstats.Stats(profile).stats  # type: ignore[attr-defined]
    row["functions"] = [
        [_name(key), nc, tt, ct]
        for key, (_, nc, tt, ct, _) in stats.items()
        if tt > 1e-3 or ct > 1e-2
    ]
    print(json.dumps(row))


def _run(case: str, nx: int, ny: int, free: bool) -> dict[str, Any]:
    cmd = [sys.executable, __file__, "--worker", case, str(nx), str(ny)]
    cmd += ["--free"] if free else []
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    w0 = time.perf_counter()
    out = subprocess.run(cmd, check=True, capture_output=True)
    wall = time.perf_counter() - w0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    row = dict(json.loads(out.stdout.decode().strip().splitlines()[-1]))
    row["process_wall"] = wall
    row["process_cpu"] = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    return row


def _p(t0: float, t1: float, n0: int, n1: int) -> str:
    if t0 <= 0 or t1 <= 0:
        return ""
    return f"{math.log(t1 / t0) / math.log(n1 / n0):.2f}"


def _phase_table(runs: list[dict[str, Any]], key: str = "phases") -> list[dict[str, Any]]:
    """Per mesh and phase: fine level's and coarser levels' seconds and calls."""
    rows = []
    for r in runs:
        n = r["dofs"]
        table: dict[str, list[float]] = defaultdict(lambda: [0.0, 0, 0.0, 0])
        for phase, k, seconds, calls, *_ in r.get(key, []):
            at = 0 if (k == n or k == 0) else 2
            table[phase][at] += seconds
            table[phase][at + 1] += calls
        rows.append({"dofs": n, "mesh": r["mesh"], "phases": dict(table)})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default="180x60,360x120,500x166")
    parser.add_argument("--case", default="ssss", help="a case of bench_plates.py")
    parser.add_argument("--top", type=int, default=40, help="functions listed, by fine time")
    parser.add_argument("--json", help="append one JSON line per mesh and run to this file")
    parser.add_argument("--load", help="read the runs from this JSON lines file instead")
    parser.add_argument("--worker", nargs=3, metavar=("CASE", "NX", "NY"), help=argparse.SUPPRESS)
    parser.add_argument("--free", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args.worker[0], int(args.worker[1]), int(args.worker[2]), args.free)
        return
    meshes = [tuple(int(v) for v in m.split("x")) for m in args.meshes.split(",")]
    runs: list[dict[str, Any]] = []
    frees: list[dict[str, Any]] = []
    if args.load:
        stored = [json.loads(x) for x in Path(args.load).read_text().splitlines() if x.strip()]
        for nx, ny in meshes:
            mesh = f"{nx}x{ny}"
            got = [s for s in stored if s["mesh"] == mesh and s["case"] == args.case]
            runs.append(next(s for s in got if not s["free"]))
            frees.append(next(s for s in got if s["free"]))
    else:
        for nx, ny in meshes:
            for free, into in ((False, runs), (True, frees)):
                r = _run(args.case, nx, ny, free)
                r.update(case=args.case, mesh=f"{nx}x{ny}", free=free)
                into.append(r)
                append_rows(args.json, [r])
    _print(args.case, runs, frees, args.top)


def _print(case: str, runs: list[dict[str, Any]], frees: list[dict[str, Any]], top: int) -> None:
    _print_runs(case, runs, frees)
    _print_phases(case, runs, frees)
    _print_functions(case, runs, frees, top)


def _print_runs(case: str, runs: list[dict[str, Any]], frees: list[dict[str, Any]]) -> None:
    print_header(
        f"{case}: whole run and free run (wall and CPU seconds, peak resident memory)",
        ["mesh", "DOFs", "solve wall (s)", "free (s)", "ratio", "process wall (s)", "free (s)",
         "ratio", "process CPU (s)", "free (s)", "ratio", "run (GiB)", "free (GiB)", "ratio",
         "load (Pa)", "route", "levels: steps / factorisations / eigen solves"],
    )  # fmt: skip
    for r, f in zip(runs, frees, strict=True):
        levels = " · ".join(f"{'x'.join(map(str, m))}: {s}/{fa}/{e}" for m, s, fa, e in r["levels"])
        cells = [r["mesh"], r["dofs"]]
        for key in ("wall", "process_wall", "process_cpu"):
            cells += [f"{r[key]:.1f}", f"{f[key]:.1f}", f"{r[key] / f[key]:.2f}"]
        gb = r["maxrss_kib"] / 2**20, f["maxrss_kib"] / 2**20
        cells += [f"{gb[0]:.2f}", f"{gb[1]:.2f}", f"{gb[0] / gb[1]:.2f}"]
        cells += [f"{r['load_Pa']:.6f}", " + ".join(r.get("route") or [r["method"]]), levels]
        print("| " + " | ".join(map(str, cells)) + " |")
    print()


def _print_phases(case: str, runs: list[dict[str, Any]], frees: list[dict[str, Any]]) -> None:
    for key, clock in (("phases", "wall"), ("cpu_phases", "process")):
        table = _phase_table(runs, key)
        if not any(r["phases"] for r in table):
            continue
        head = ["phase"] + [f"{r['mesh']}: s / calls / µs per DOF (p)" for r in table]
        print_header(
            f"{case}: exclusive {clock} seconds per phase, fine level (coarser levels)", head
        )
        phases = sorted({ph for r in table for ph in r["phases"]})
        for ph in phases:
            cells = []
            for k, r in enumerate(table):
                fs, fc, cs, cc = r["phases"].get(ph, [0.0, 0, 0.0, 0])
                cell = f"{fs:.2f} / {fc} / {1e6 * fs / r['dofs']:.1f}"
                if k:
                    b = table[k - 1]
                    p = _p(b["phases"].get(ph, [0.0])[0], fs, b["dofs"], r["dofs"])
                    cell += f" ({p})" if p else ""
                if cs:
                    cell += f"; coarser {cs:.2f} / {cc}"
                cells.append(cell)
            print(f"| {ph} | " + " | ".join(cells) + " |")
        total = "wall" if clock == "wall" else "cpu"
        for label, src in (("whole run", runs), ("free run", frees)):
            cells = []
            for k, r in enumerate(src):
                cell = f"{r[total]:.2f} / 1 / {1e6 * r[total] / r['dofs']:.1f}"
                if k:
                    b = src[k - 1]
                    cell += f" ({_p(b[total], r[total], b['dofs'], r['dofs'])})"
                cells.append(cell)
            print(f"| {label} | " + " | ".join(cells) + " |")
        print()
    ftable = _phase_table(frees, "cpu_phases")
    free_phase = [r["phases"].get("free solve", [0.0])[0] for r in ftable]
    print(f"(free run's free solve, process time: {', '.join(f'{t:.2f}' for t in free_phase)} s)")
    print()


def _print_functions(
    case: str, runs: list[dict[str, Any]], frees: list[dict[str, Any]], top: int
) -> None:
    # Functions: exclusive time in the largest run, all meshes' numbers beside it.
    funcs = [{name: (nc, tt, ct) for name, nc, tt, ct in r["functions"]} for r in runs]
    p_free = [
        math.log(frees[k]["cpu"] / frees[k - 1]["cpu"])
        / math.log(frees[k]["dofs"] / frees[k - 1]["dofs"])
        for k in range(1, len(frees))
    ]
    last = funcs[-1]
    floor = 2e-3 * runs[-1]["cpu"]
    names = sorted((n for n in last if last[n][1] > floor), key=lambda n: -last[n][1])[:top]
    exponents = ", ".join(f"{p:.2f}" for p in p_free)
    print_header(
        f"{case}: functions by exclusive process seconds (cProfile tottime) in the largest "
        f"run; * = p above the free run's CPU time's ({exponents}) by > {MARGIN}",
        ["function"] + [f"{r['mesh']}: s / calls (p)" for r in runs],
    )
    for name in names:
        cells = []
        flag = ""
        for k, f in enumerate(funcs):
            nc, tt, _ = f.get(name, (0, 0.0, 0.0))
            cell = f"{tt:.2f} / {nc}"
            if k:
                before = funcs[k - 1].get(name, (0, 0.0, 0.0))[1]
                p = _p(before, tt, runs[k - 1]["dofs"], runs[k]["dofs"])
                if p:
                    cell += f" ({p})"
                    if float(p) > p_free[k - 1] + MARGIN and tt > floor:
                        flag = " *"
            cells.append(cell)
        print(f"| {name}{flag} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
