r"""Benchmark: MUMPS's block low-rank (BLR) factorisation for the fine level's LDL^T.

The fine level of the interior point's route spends most of its time in numeric
:math:`LDL^T` factorisations of the mesh's shared matrix (the Newton steps', the shifted
eigen solves', the certificate's; one symbolic analysis per mesh). MUMPS can compress
the blocks of its fronts to low rank (ICNTL(35) = 2: BLR factorisation and solve;
CNTL(7) = eps, the dropping threshold; ICNTL(36) the variant), which trades exactness
for speed. Two tables for the thin SSSS benchmark plate of ``bench_plates.py``
(0.3 x 0.1 m, t = 0.1 mm, obstacle over the whole face):

- ``--part factor``: per mesh and variant, :math:`K = A - \sigma B` (sigma 0.1 % above
  the plate's load, two eigenvalues below it, as the fine level's matrices) factorised
  with the route's ordering: the analysis and the numeric factorisation (process CPU
  seconds, the minimum of ``--repeat``), the inertia, the relative error of a solve with
  a known solution, MUMPS's factor memory (INFOG(22), MB);
- ``--part route``: per mesh and variant, ``unibuckle_fenicsx.analysis.solve`` in a fresh
  process with the variant's controls on the shared factorisation of every mesh of at
  least ``--min-rows`` rows (the fine level's Newton steps, eigen solves, free solve and
  certificate use it), for the plate with its obstacle and for the free plate: the
  load and its relative change from the full-rank run, the fine level's steps /
  factorisations / eigen solves, the process CPU seconds of each whole process and
  their ratio.

Process CPU seconds (MUMPS on one thread, ``OMP_NUM_THREADS=1``): on a shared machine
the wall clock measures the other jobs too. Counts, loads and inertias are exact.

Usage: python bench/bench_mumps_blr.py [--meshes 180x60,360x120] [--part factor,route]
[--variants full,blr16,blr14,blr12] [--repeat 3] [--min-rows 100000] [--free-load PA]
[--json FILE]. A 10^6-DOF mesh
(1000x333) needs about 10 GB: run it under ``flock /tmp/unibuckle-bigmem.lock``.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time
from typing import Any

from _results import append_rows, print_header

#: MUMPS controls of each variant: ICNTL(k) by integer key, CNTL(7) by "cntl_7".
VARIANTS: dict[str, dict[str, float]] = {
    "full": {},
    "blr16": {"icntl_35": 2, "cntl_7": 1e-16},
    "blr14": {"icntl_35": 2, "cntl_7": 1e-14},
    "blr12": {"icntl_35": 2, "cntl_7": 1e-12},
    "blr10": {"icntl_35": 2, "cntl_7": 1e-10},
    "blr14ucfs": {"icntl_35": 2, "icntl_36": 1, "cntl_7": 1e-14},
}
#: sigma of --part factor, relative to the plate's load (just above it, as the route's).
ABOVE = 1.001


def _set(factor: Any, controls: dict[str, float]) -> None:
    for key, value in controls.items():
        kind, k = key.rsplit("_", 1)
        if kind == "icntl":
            factor.setMumpsIcntl(int(k), int(value))
        else:
            factor.setMumpsCntl(int(k), float(value))


def factor_rows(
    nx: int, ny: int, variants: list[str], repeat: int, free_load: float | None = None
) -> list[dict[str, Any]]:
    """The factor table's rows for one mesh (one problem, every variant).

    ``free_load``: the free plate's load (Pa) if known, else a free solve computes it.
    """
    from mpi4py import MPI
    from petsc4py import PETSc

    from bench_plates import _spec

    from unibuckle_fenicsx.la.options import mumps_ordering
    from unibuckle_fenicsx.model.build import build_problem

    rows = []
    with build_problem(_spec("ssss", nx, ny), MPI.COMM_WORLD) as problem:
        free = problem.solve_free().load if free_load is None else free_load
        load = free * 1.125  # the obstacle's load is 1.125 free loads
        K = problem.model.A.duplicate(copy=True)
        K.axpy(-ABOVE * load, problem.model.B, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        K.setOption(PETSc.Mat.Option.SPD, False)
        K.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        x0, b = K.createVecs()
        rng = PETSc.Random().create(K.comm)
        rng.setSeed(7)
        x0.setRandom(rng)
        rng.destroy()
        K.mult(x0, b)
        ordering = mumps_ordering(K.getSize()[0], reused=True)
        for name in variants:
            first, numeric = [], []
            for _ in range(repeat):
                ksp = PETSc.KSP().create(K.comm)
                ksp.setOptionsPrefix("bench_blr_")
                ksp.setOperators(K)
                ksp.setType("preonly")
                pc = ksp.getPC()
                pc.setType("cholesky")
                pc.setFactorSolverType("mumps")
                pc.setFactorSetUpSolverType()
                factor = pc.getFactorMatrix()
                _set(factor, {"icntl_7": ordering, "icntl_13": 1, "icntl_24": 1})
                _set(factor, VARIANTS[name])
                c0 = time.process_time()
                ksp.setUp()
                first.append(time.process_time() - c0)
                K.setValue(0, 0, K.getValue(0, 0))  # new values, same pattern: numeric only
                K.assemble()
                ksp.setOperators(K)
                c0 = time.process_time()
                ksp.setUp()
                numeric.append(time.process_time() - c0)
                x = x0.duplicate()
                ksp.solve(b, x)
                x.axpy(-1.0, x0)
                error = x.norm() / x0.norm()
                negative, zero, _ = factor.getInertia()
                memory = factor.getMumpsInfog(22)
                x.destroy()
                ksp.destroy()
            rows.append(
                {
                    "part": "factor",
                    "mesh": f"{nx}x{ny}",
                    "dofs": K.getSize()[0],
                    "variant": name,
                    "ordering": ordering,
                    "analysis_s": max(0.0, min(first) - min(numeric)),
                    "numeric_s": min(numeric),
                    "inertia": [int(negative), int(zero)],
                    "solve_error": error,
                    "memory_MB": memory,
                }
            )
        for obj in (x0, b, K):
            obj.destroy()
    return rows


def worker(nx: int, ny: int, name: str, free: bool, min_rows: int) -> None:
    """One whole solve in this process with the variant's controls; print a JSON line."""
    from mpi4py import MPI
    from petsc4py import PETSc

    from bench_plates import _spec
    from msgspec.structs import replace

    import unibuckle_fenicsx.la.factor as factor_module
    from unibuckle_fenicsx.analysis import solve

    original = factor_module.set_ldl_options

    def with_variant(ksp: PETSc.KSP, prefix: str, reused: bool = False) -> None:
        original(ksp, prefix, reused)
        if ksp.getOperators()[0].getSize()[0] >= min_rows:
            _set(ksp.getPC().getFactorMatrix(), VARIANTS[name])

    factor_module.set_ldl_options = with_variant  # every mesh's shared LDL^T
    spec = _spec("ssss", nx, ny)
    if free:
        spec = replace(spec, obstacle=None)
    with solve(spec, MPI.COMM_WORLD) as run:
        result, solution = run.result, run.solution
        levels = [] if solution is None else getattr(solution.details, "levels", [])
        row = {
            "dofs": result.dofs,
            "load_Pa": result.critical_load_Pa,
            "kkt": None if run.certificate is None else run.certificate.kkt,
            "levels": [
                [lv.mesh, lv.newton_steps, lv.factorizations, lv.eigensolves] for lv in levels
            ],
        }
    print(json.dumps(row))


def _run(nx: int, ny: int, name: str, free: bool, min_rows: int) -> dict[str, Any]:
    cmd = [
        sys.executable,
        __file__,
        "--worker",
        str(nx),
        str(ny),
        name,
        "--min-rows",
        str(min_rows),
    ]
    cmd += ["--free"] if free else []
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run(cmd, check=True, capture_output=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    row = dict(json.loads(out.stdout.decode().strip().splitlines()[-1]))
    row["cpu_s"] = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    row["maxrss_kib"] = after.ru_maxrss
    return row


def route_rows(nx: int, ny: int, variants: list[str], min_rows: int) -> list[dict[str, Any]]:
    """The route table's rows for one mesh: each variant's run and free run."""
    rows: list[dict[str, Any]] = []
    for name in variants:
        run, free = _run(nx, ny, name, False, min_rows), _run(nx, ny, name, True, min_rows)
        rows.append(
            {
                "part": "route",
                "mesh": f"{nx}x{ny}",
                "variant": name,
                "dofs": run["dofs"],
                "load_Pa": run["load_Pa"],
                "free_load_Pa": free["load_Pa"],
                "kkt": run["kkt"],
                "fine": run["levels"][-1][1:] if run["levels"] else [],
                "levels": len(run["levels"]),
                "min_rows": min_rows,
                "cpu_s": run["cpu_s"],
                "free_cpu_s": free["cpu_s"],
            }
        )
    return rows


def print_rows(rows: list[dict[str, Any]]) -> None:
    """The two tables (Markdown) of ``rows``."""
    factor = [r for r in rows if r["part"] == "factor"]
    if factor:
        print_header(
            "LDL^T of A - sigma B, sigma 0.1 % above the load (process CPU s, min of repeats)",
            (
                "mesh", "DOFs", "variant", "analysis (s)", "numeric (s)", "numeric / full",
                "inertia (neg, zero)", "solve error", "factor memory (MB)",
            ),
        )  # fmt: skip
        for r in factor:
            full = next(
                f["numeric_s"] for f in factor if f["mesh"] == r["mesh"] and f["variant"] == "full"
            )
            print(
                f"| {r['mesh']} | {r['dofs']} | {r['variant']} | {r['analysis_s']:.2f} | "
                f"{r['numeric_s']:.3f} | {r['numeric_s'] / full:.2f} | "
                f"{tuple(r['inertia'])} | {r['solve_error']:.1e} | {r['memory_MB']} |"
            )
    route = [r for r in rows if r["part"] == "route"]
    if route:
        print_header(
            "The route, whole process (process CPU s): the run and the free run",
            (
                "mesh", "variant", "load (Pa)", "relative to full", "free load (Pa)",
                "fine level (steps/fact./eigen)", "run CPU (s)", "free run CPU (s)", "ratio",
            ),
        )  # fmt: skip
        for r in route:
            full = next(f for f in route if f["mesh"] == r["mesh"] and f["variant"] == "full")
            rel = (r["load_Pa"] - full["load_Pa"]) / full["load_Pa"]
            print(
                f"| {r['mesh']} | {r['variant']} | {r['load_Pa']:.9f} | {rel:+.1e} | "
                f"{r['free_load_Pa']:.9f} | {'/'.join(map(str, r['fine']))} | "
                f"{r['cpu_s']:.1f} | {r['free_cpu_s']:.1f} | {r['cpu_s'] / r['free_cpu_s']:.2f} |"
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default="180x60,360x120")
    parser.add_argument("--part", default="factor,route")
    parser.add_argument("--variants", default="full,blr16,blr14,blr12")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--free-load", type=float, help="factor: the free load (Pa), if known")
    parser.add_argument(
        "--min-rows", type=int, default=100_000, help="route: BLR from this many rows on"
    )
    parser.add_argument("--json", help="append one JSON line per row to this file")
    parser.add_argument("--load", help="print the tables of the rows stored in this file")
    parser.add_argument("--worker", nargs=3, help=argparse.SUPPRESS)
    parser.add_argument("--free", action="store_true", help=argparse.SUPPRESS)
    args, _ = parser.parse_known_args()
    if args.worker:
        nx, ny, name = args.worker
        worker(int(nx), int(ny), name, args.free, args.min_rows)
        return
    if args.load:
        with open(args.load, encoding="utf-8") as f:
            print_rows([json.loads(line) for line in f if line.strip()])
        return
    variants = args.variants.split(",")
    if variants[0] != "full":
        parser.error("--variants must start with full (the reference)")
    meshes = [tuple(int(v) for v in m.split("x")) for m in args.meshes.split(",")]
    rows: list[dict[str, Any]] = []
    for nx, ny in meshes:
        if "factor" in args.part:
            new = factor_rows(nx, ny, variants, args.repeat, args.free_load)
            append_rows(args.json, new)
            rows += new
        if "route" in args.part:
            new = route_rows(nx, ny, variants, args.min_rows)
            append_rows(args.json, new)
            rows += new
    print_rows(rows)


if __name__ == "__main__":
    main()
