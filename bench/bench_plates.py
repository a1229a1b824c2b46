"""Benchmark: the unilateral solve on thin plates against one free solve of the same plate.

Thin plates (0.3 x 0.1 m, t = 1e-4 m, t/b = 1e-3) with the obstacle over the whole
plate (a steel face against concrete), under every edge condition and under shear: the
plates on which most constrained nodes lie flat on the obstacle with no contact force.
For each case and mesh, ``solve`` runs the whole process in one process (free solve,
unilateral route, certificate); the table gives

- ``ratio``: (unilateral + certificate time) / (cold free solve time), in one process;
- per mesh level of the route: Newton steps / numeric factorisations / eigen solves;
- the route that answered, whether the result is KKT and the smallest eigenvalue of its
  reduced pencil, what its certificate verified (proven, bracketed with its gap, or KKT
  only; README, "Proving the global minimum") with m (pencil eigenvalues below the
  load), the low-rank route's columns r and pieces and the certificate's time over the
  free solve's, and the buckling coefficient k = lambda b^2 t / (pi^2 D).

With ``--cli`` it also times what a user waits: ``unibuckle solve`` on the plate, over
``unibuckle solve`` on the same plate without obstacle (whole processes, start-up and
JIT cache included).

With ``--repeat N`` each plate is solved N times (and each CLI pair run N times) and the
ratios are the medians (all of them in the JSON row's ``ratios`` and ``cli_ratios``): on
a shared machine one free solve of a 90×30 plate took 0.17 to 0.35 s within an hour,
and a single run's ratio moved by as much. The Newton steps and loads are the same in
every repetition.

With ``--bracket`` the certificate also runs the low-rank verified bracket
(``solver.bracket``; off by default: it costs tens of free solves on these plates).

With ``--side below`` the face lies below the plate (w >= 0): the mirror image, the same
loads (w -> -w), by the same route.

Usage: python bench/bench_plates.py [--meshes 90x30,180x60] [--cases ssss,cs,sc,cccc,shear]
[--side above|below] [--cli] [--bracket] [--repeat N] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mpi4py import MPI

from _results import append_rows, print_header
from msgspec.structs import replace

from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.certificate.certify import Certificate
from unibuckle_fenicsx.spec import ObstacleSpec, problem_to_dict
from unibuckle_fenicsx.spec.cases import plate_case

#: name -> (edge supports, load, description of the edges)
CASES = {
    "ssss": ("simply_supported", "uniaxial", "SSSS"),
    "cs": ({"left": "clamped", "right": "clamped"}, "uniaxial", "loaded edges clamped"),
    "sc": ({"bottom": "clamped", "top": "clamped"}, "uniaxial", "unloaded edges clamped"),
    "cccc": ("clamped", "uniaxial", "CCCC"),
    "shear": ("simply_supported", "shear", "SSSS, shear"),
}
LENGTH, WIDTH, THICKNESS = 0.3, 0.1, 1e-4


def _spec(
    name: str,
    nx: int,
    ny: int,
    side: str = "above",
    thickness: float = THICKNESS,
    length: float = LENGTH,
):
    supports, load, _ = CASES[name]
    return plate_case(
        name,
        length=length,
        width=WIDTH,
        thickness=thickness,
        supports=supports,
        load=load,
        nx=nx,
        ny=ny,
        zone=ObstacleSpec(zone="all", side=side),
    )


def _verified(cert: Certificate) -> str:
    """Proven (route), bracketed (gap, route), refuted, or KKT only (why)."""
    if cert.global_optimum_proven:
        return f"proven ({cert.proven_by})"
    if cert.status == "bracketed":
        return f"bracketed {cert.relative_gap:.0e} ({cert.proven_by})"
    if cert.refuting_mode is not None:
        return f"refuted ({cert.refuting_mode.load:.6f})"
    lowrank = (cert.copositivity or {}).get("lowrank") or {}
    return f"KKT only: {lowrank.get('why', '; '.join(cert.notes))}"


def _lowrank(cert: Certificate) -> tuple[object, object]:
    """(r, pieces) of the low-rank route, or dashes."""
    lowrank = (cert.copositivity or {}).get("lowrank") or {}
    return lowrank.get("r", "-"), lowrank.get("pieces", "-")


def _times(timings: dict[str, float]) -> tuple[float, float, float]:
    """Free solve (s), (unilateral + certificate) / free, certificate / free."""
    free, certify = timings["free_solve_s"], timings["certify_s"]
    return free, (timings["unilateral_s"] + certify) / free, certify / free


def _cli_seconds(spec) -> float:
    """Wall time of ``unibuckle solve`` on ``spec`` (a whole process)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "plate.json"
        path.write_text(json.dumps({"input": problem_to_dict(spec)}))
        cmd = [sys.executable, "-m", "unibuckle_fenicsx.cli", "solve", "--config", str(path)]
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True, env={**os.environ})
        return time.perf_counter() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default="90x30,180x60")
    parser.add_argument("--cases", default=",".join(CASES))
    parser.add_argument("--cli", action="store_true", help="also time whole CLI processes")
    parser.add_argument("--json", help="append one JSON line per row to this file")
    parser.add_argument(
        "--bracket", action="store_true", help="also run the low-rank bracket (solver.bracket)"
    )
    parser.add_argument(
        "--side", choices=("above", "below"), default="above", help="where the face lies"
    )
    parser.add_argument(
        "--repeat", type=int, default=1, help="solves per plate; the ratios are the medians"
    )
    args, _ = parser.parse_known_args()
    if args.repeat < 1:
        parser.error(f"--repeat must be at least 1, got {args.repeat}")
    comm = MPI.COMM_WORLD
    meshes = [tuple(int(v) for v in m.split("x")) for m in args.meshes.split(",")]
    if comm.rank == 0:
        print_header(
            f"MPI ranks: {comm.size}; plate {LENGTH} x {WIDTH} m, t = {THICKNESS} m, "
            f"zone all, face {args.side}",
            (
                "case", "mesh", "i", "\\|Z\\|", "levels: steps / factorisations / eigen solves",
                "route", "free solve (s)", "ratio", "CLI ratio", "KKT", "smallest",
                "certificate", "m", "r", "pieces", "certificate / free", "k", "lambda_c (Pa)",
            ),
        )  # fmt: skip
    for nx, ny in meshes:
        for name in args.cases.split(","):
            spec = _spec(name, nx, ny, args.side)
            if args.bracket:
                spec = spec.with_solver(bracket=True)
            runs = []  # (free solve s, ratio, certificate / free) of each repetition
            for _ in range(args.repeat - 1):
                with solve(spec, comm) as analysis:
                    t = analysis.result.timings
                    runs.append(_times(t))
            with solve(spec, comm) as analysis:
                r, sol, cert = analysis.result, analysis.solution, analysis.certificate
                assert sol is not None and cert is not None
                runs.append(_times(r.timings))
                free_s, ratio, certify_ratio = (
                    statistics.median(column) for column in zip(*runs, strict=True)
                )
                levels = sol.details.get("levels", [])
                per_level = ", ".join(
                    f"{'x'.join(map(str, lv['mesh']))}: {lv['newton_steps']}/"
                    f"{lv['factorizations']}/{lv['eigensolves']}"
                    for lv in levels
                    if "newton_steps" in lv
                )
                row = {
                    "case": name,
                    "side": args.side,
                    "bracket": args.bracket,
                    "edges": CASES[name][2],
                    "mesh": f"{nx}x{ny}",
                    "i": r.constrained_nodes,
                    "contact_nodes": r.contact_nodes,
                    "levels": per_level or f"{r.eigensolves} eigen solves",
                    "route": r.method,
                    "free_solve_s": free_s,
                    "ratio": ratio,
                    "ratios": [run[1] for run in runs],
                    "kkt": cert.kkt,
                    "smallest": cert.smallest_of_reduced,
                    "certificate": _verified(cert),
                    "m": cert.negative_eigenvalues,
                    "r": _lowrank(cert)[0],
                    "pieces": _lowrank(cert)[1],
                    "certify_ratio": certify_ratio,
                    "k": analysis.problem.buckling_coefficient(r.critical_load_Pa),
                    "load_Pa": r.critical_load_Pa,
                    "level_records": levels,
                }
            cli_ratio = None
            if args.cli and comm.size == 1:
                free = replace(spec, obstacle=None)
                cli = [_cli_seconds(spec) / _cli_seconds(free) for _ in range(args.repeat)]
                cli_ratio = statistics.median(cli)
                row["cli_ratios"] = cli
            row["cli_ratio"] = cli_ratio
            if comm.rank == 0:  # one row at a time: a long run shows its progress
                print(
                    "| {case} | {mesh} | {i} | {contact_nodes} | {levels} | {route} "
                    "| {free_solve_s:.2f} | **{ratio:.1f}** | {cli} | {kkt} | {smallest} "
                    "| {certificate} | {m} | {r} | {pieces} | {certify_ratio:.1f} | {k:.4f} "
                    "| {load_Pa:.6f} |".format(
                        **row, cli="-" if cli_ratio is None else f"{cli_ratio:.1f}"
                    ),
                    flush=True,
                )
                append_rows(args.json, [row])


if __name__ == "__main__":
    main()
