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

With ``--cli`` the row also keeps the processes' CPU seconds (user + system, of the
process and the ones it waited for): ``cli_cpu_ratios`` (each pair's ratio;
``cli_cpu_ratio`` their median), ``cli_cpu_s`` and ``free_cli_cpu_s`` (the minima). On
a machine shared with other jobs the wall time waits for a core; the CPU time moves far
less.

With ``--cli --baseline PYTHON`` the same two commands of the package installed for
another interpreter (an older version) are timed after them, and their ratios kept
(``baseline_cli_ratios``, ``baseline_cli_cpu_ratios``): the change of a ratio measured
on the same machine at the same time.

With ``--repeat N`` each plate is solved N times (and each CLI pair run N times) and the
ratios are the medians (all of them in the JSON row's ``ratios`` and ``cli_ratios``): on
a shared machine one free solve of a 90×30 plate took 0.17 to 0.35 s within an hour,
and a single run's ratio moved by as much. The Newton steps and loads are the same in
every repetition.

With ``--bracket`` the certificate's bracket runs as asked for (``solver.bracket``:
distances down to 1e-6, no cost limit; by default it runs where its estimated cost is
at most 3 free solves; ``bench_bracket.py`` measures it).

With ``--thickness T`` the plates are T thick (m; default 1e-4): 1e-3 is the filled
box's face of ``bench_sections.py`` (b/t = 100) scaled by one half.

With ``--side below`` the face lies below the plate (w >= 0): the mirror image, the same
loads (w -> -w), by the same route.

The cases ``c1``, ``c2``, ``c3`` are the paper's plate (0.2 x 0.1 m, t = 6 mm) with its
obstacle zones (:func:`~unibuckle_fenicsx.spec.cases.paper_case`), solved and timed the
same way (``--side`` does not apply to them).

Usage: python bench/bench_plates.py [--meshes 90x30,180x60] [--cases ssss,cs,sc,cccc,shear,c1,c3]
[--side above|below] [--thickness T] [--cli] [--baseline PYTHON] [--bracket] [--repeat N]
[--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mpi4py import MPI

from _results import append_rows, parse_plates, print_header
from msgspec.structs import replace

from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.certificate.certify import Certificate
from unibuckle_fenicsx.certificate.records import LowRankRecord
from unibuckle_fenicsx.results.records import jsonable
from unibuckle_fenicsx.spec import ObstacleSpec, problem_to_dict
from unibuckle_fenicsx.spec.cases import CASES as PAPER_CASES
from unibuckle_fenicsx.spec.cases import paper_case, plate_case

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
    if name in PAPER_CASES:
        return paper_case(name, nx, ny)
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
    record = _bracket(cert)
    return f"KKT only: {'; '.join(cert.notes) if record is None else record.why}"


def _bracket(cert: Certificate) -> LowRankRecord | None:
    """The bracket route's record: the split route's, else the low-rank route's, or None."""
    record = cert.copositivity
    if record is None:
        return None
    return record.split or record.lowrank


def _lowrank(cert: Certificate) -> tuple[object, object]:
    """(r, pieces) of the bracket route, or dashes."""
    record = _bracket(cert)
    return ("-", "-") if record is None else (record.r, record.pieces)


def _times(timings: dict[str, float]) -> tuple[float, float, float]:
    """Free solve (s), (unilateral + certificate) / free, certificate / free."""
    free, certify = timings["free_solve_s"], timings["certify_s"]
    return free, (timings["unilateral_s"] + certify) / free, certify / free


def _cli_seconds(spec, python: str = sys.executable) -> tuple[float, float]:
    """Wall time and CPU time (user + system) of ``unibuckle solve`` on ``spec``.

    ``python``: the interpreter whose installation of the package runs it.
    """
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "plate.json"
        path.write_text(json.dumps({"input": problem_to_dict(spec)}))
        cmd = [python, "-m", "unibuckle_fenicsx.cli", "solve", "--config", str(path)]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        # cwd: python -m puts it first on sys.path (a checkout there would shadow the
        # installation of ``python``).
        subprocess.run(cmd, check=True, capture_output=True, env={**os.environ}, cwd=tmp)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
        return wall, cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default="90x30,180x60")
    parser.add_argument("--cases", default=",".join(CASES))
    parser.add_argument("--cli", action="store_true", help="also time whole CLI processes")
    parser.add_argument("--json", help="append one JSON line per row to this file")
    parser.add_argument(
        "--bracket", action="store_true", help="the bracket as asked for (solver.bracket)"
    )
    parser.add_argument(
        "--side", choices=("above", "below"), default="above", help="where the face lies"
    )
    parser.add_argument(
        "--repeat", type=int, default=1, help="solves per plate; the ratios are the medians"
    )
    parser.add_argument(
        "--baseline", metavar="PYTHON", help="with --cli: also time another installation"
    )
    parser.add_argument(
        "--thickness", type=float, default=THICKNESS, help="plate thickness (m), > 0"
    )
    args, meshes = parse_plates(parser)
    if not args.thickness > 0.0:
        parser.error(f"--thickness must be > 0, got {args.thickness}")
    comm = MPI.COMM_WORLD
    if comm.rank == 0:
        print_header(
            f"MPI ranks: {comm.size}; plate {LENGTH} x {WIDTH} m, t = {args.thickness} m, "
            f"zone all, face {args.side} (c1, c2, c3: the paper's plate and zones)",
            (
                "case", "mesh", "i", "\\|Z\\|", "levels: steps / factorisations / eigen solves",
                "route", "free solve (s)", "ratio", "CLI ratio", "KKT", "smallest",
                "certificate", "m", "r", "pieces", "certificate / free", "k", "lambda_c (Pa)",
            ),
        )  # fmt: skip
    for nx, ny in meshes:
        for name in args.cases.split(","):
            spec = _spec(name, nx, ny, args.side, args.thickness)
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
                levels = jsonable(sol.details).get("levels", [])
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
                    "edges": CASES[name][2] if name in CASES else "paper",
                    "mesh": f"{nx}x{ny}",
                    "thickness": args.thickness,
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
                pairs = [(_cli_seconds(spec), _cli_seconds(free)) for _ in range(args.repeat)]
                cli = [full[0] / bare[0] for full, bare in pairs]
                cli_ratio = statistics.median(cli)
                row["cli_ratios"] = cli
                row["cli_cpu_ratios"] = [full[1] / bare[1] for full, bare in pairs]
                row["cli_cpu_ratio"] = statistics.median(row["cli_cpu_ratios"])
                row["cli_cpu_s"] = min(full[1] for full, _ in pairs)
                row["free_cli_cpu_s"] = min(bare[1] for _, bare in pairs)
                if args.baseline:
                    pairs = [
                        (_cli_seconds(spec, args.baseline), _cli_seconds(free, args.baseline))
                        for _ in range(args.repeat)
                    ]
                    row["baseline_cli_ratios"] = [full[0] / bare[0] for full, bare in pairs]
                    row["baseline_cli_cpu_ratios"] = [full[1] / bare[1] for full, bare in pairs]
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
