"""Benchmark: CPU time of each stage of ``solve`` on a thin plate as the mesh grows.

Finds the stage whose time grows faster than the mesh. For each mesh, a fresh process
solves the benchmark plate of ``bench_plates.py`` (0.3 x 0.1 m, t = 0.1 mm, obstacle
over the whole face) and, in another fresh process, the same plate without obstacle
(the free run). Stage timers wrap the route's functions and add up their process time
(``time.process_time``: on a machine shared with other jobs it moves far less than the
wall time, which waits for a core); a stage called inside another is counted in both.
The table gives, per mesh, the seconds of

- ``setup``: every mesh's problem (mesh, prestress, assembly, contact data);
- ``free solve``: the fine mesh's free eigen solve inside the run;
- ``coarse levels``: the interior point on every mesh below the fine one;
- ``fine IP``: the interior point on the fine mesh;
- ``fine LDL``: the numeric factorisations of the fine mesh's shared LDL^T (count and
  seconds each): the interior point's (most of ``fine IP``) and the certificate's;
- ``fine eigen``: the reduced eigen solves on the fine mesh (the free one excluded);
- ``certificate``: the global-optimality certificate;
- ``total`` and ``free run`` (the whole free run), and ``ratio`` = total / free run;

and, for each stage, the growth exponent p of t ~ DOFs^p between consecutive meshes:
1 is linear; a sparse LDL^T of a 2D mesh (nested dissection) costs DOFs^1.5.

It also counts, independent of the machine's load, per mesh level of the route: Newton
steps / numeric factorisations / solves with a factorisation / eigen solves (the
factorisations and solves are PETSc's ``MatCholFctrNum`` and ``MatSolve`` events inside
the level's runs, eigen solves' included), and the whole run's factorisations and
solves against the free run's.

Usage: python bench/bench_stages.py [--meshes 90x30,180x60,360x120] [--case ssss]
[--repeat N] [--json FILE]

With ``--repeat N`` each process is run N times and every stage keeps its minimum.

With ``--phases`` it also prints, per mesh and per level of the route, the *exclusive*
process seconds of each phase (a phase called inside another is charged to the inner
one only, so a level's phases add up to its time): ``setup`` (mesh, prestress,
assembly), ``kernel`` (a Newton kernel's matrices, once per mesh), ``prolong`` (the
carried mode's interpolation), ``relax`` (its block solves into the mesh's Kirchhoff
kernel), ``lift`` (the least-energy correction: one factorisation), ``LDL`` (numeric
factorisations of the shared LDL^T), ``Newton`` (the steps' vector work and bookkeeping),
``sets`` (reading contact sets off barrier points), ``eigen`` (reduced eigen solves, their
factorisations included), ``other`` (the rest of the level's code); the fine level, the
free solve and the certificate in rows of their own.
"""

from __future__ import annotations

import argparse
import functools
import json
import math
import subprocess
import sys
import time
from collections import defaultdict
from collections.abc import Callable
from typing import Any

from _results import append_rows, print_header
from msgspec.structs import replace

STAGES = (
    "setup", "free solve", "coarse levels", "fine IP", "fine LDL", "fine eigen",
    "certificate", "total", "free run",
)  # fmt: skip
STAGE_EVENTS = ("coarsest", "level")  # the stages whose counts make the levels' table


#: PETSc's log events counted: numeric factorisations (MUMPS LDL^T) and solves with one.
EVENTS = ("MatCholFctrNum", "MatSolve")


def _counts() -> tuple[int, ...]:
    from petsc4py import PETSc

    return tuple(int(PETSc.Log.Event(e).getPerfInfo()["count"]) for e in EVENTS)


def _install_timers(acc: dict[tuple[str, int], list[float]]) -> None:
    """Wrap the route's functions: ``acc[(stage, DOFs)] = [process seconds, calls, *counts]``.

    ``counts``: the :data:`EVENTS` inside the calls.
    """
    from unibuckle_fenicsx import analysis
    from unibuckle_fenicsx.algorithms import chain
    from unibuckle_fenicsx.algorithms.interior_point import explore, newton
    from unibuckle_fenicsx.certificate import certify
    from unibuckle_fenicsx.la import factor
    from unibuckle_fenicsx.model import build, problem

    def wrap(owner: Any, name: str, stage: str, dofs: Callable[..., int]) -> None:
        inner = getattr(owner, name)

        @functools.wraps(inner)
        def timed(*args: Any, **kwargs: Any) -> Any:
            c0, n0 = time.process_time(), _counts()
            try:
                return inner(*args, **kwargs)
            finally:
                entry = acc[(stage, dofs(*args))]
                entry[0] += time.process_time() - c0
                entry[1] += 1
                for j, (a, b) in enumerate(zip(n0, _counts(), strict=True)):
                    entry[2 + j] += b - a

        setattr(owner, name, timed)

    def size(mat: Any) -> int:
        return int(mat.getSize()[0])

    wrap(build, "build_problem", "setup", lambda *a, **k: 0)
    wrap(problem.Problem, "solve_free", "free solve", lambda p: size(p.model.A))
    wrap(problem.UnilateralProblem, "evaluate", "eigen", lambda p, *a, **k: size(p.model.A))
    wrap(newton.InteriorPointNewton, "solve", "IP", lambda n, *a, **k: size(n.kernel.A))
    wrap(factor.SharedFactorization, "factor", "LDL", lambda f, *a: size(f.matrix))
    wrap(explore, "explore", "coarsest", lambda p, *a, **k: size(p.model.A))
    wrap(chain, "_carry", "level", lambda ps, k, *a, **kw: size(ps[k].model.A))
    wrap(certify, "certify", "certificate", lambda *a, **k: 0)
    # The names imported elsewhere, bound before the wrapping.
    analysis.certify, analysis.build_problem = certify.certify, build.build_problem
    chain.explore = explore.explore


#: Exclusive phases (``--phases``): (module, owner, attribute, phase, DOFs of the call).
PHASES = (
    "setup", "kernel", "prolong", "relax", "lift", "LDL", "Newton", "sets", "eigen", "other",
)  # fmt: skip


def _install_phases(acc: dict[tuple[str, int], list[float]]) -> None:
    """Wrap the route's functions: ``acc[(phase, DOFs)] = [exclusive seconds, calls, *counts]``.

    Exclusive: the process time and :data:`EVENTS` of the wrapped calls made inside a
    call are charged to theirs only.
    """
    from unibuckle_fenicsx import analysis
    from unibuckle_fenicsx.algorithms import chain, multilevel
    from unibuckle_fenicsx.algorithms.interior_point import explore, kernel, newton, starts
    from unibuckle_fenicsx.certificate import certify
    from unibuckle_fenicsx.la import factor
    from unibuckle_fenicsx.model import build, problem

    inner: list[list[float]] = []  # per open call: [seconds, *counts] of its wrapped callees

    def wrap(owner: Any, name: str, phase: str, dofs: Callable[..., int]) -> None:
        wrapped = getattr(owner, name)

        @functools.wraps(wrapped)
        def timed(*args: Any, **kwargs: Any) -> Any:
            c0, n0 = time.process_time(), _counts()
            inner.append([0.0] * (1 + len(EVENTS)))
            result = None
            try:
                result = wrapped(*args, **kwargs)
                return result
            finally:
                counts = (b - a for a, b in zip(n0, _counts(), strict=True))
                spent = [time.process_time() - c0, *counts]
                callees = inner.pop()
                if inner:
                    inner[-1] = [x + y for x, y in zip(inner[-1], spent, strict=True)]
                entry = acc[(phase, dofs(result, *args))]
                entry[0] += spent[0] - callees[0]
                entry[1] += 1
                for j in range(len(EVENTS)):
                    entry[2 + j] += spent[1 + j] - callees[1 + j]

        setattr(owner, name, timed)

    def size(mat: Any) -> int:
        return int(mat.getSize()[0])

    def of_problem(r: Any, p: Any, *a: Any, **k: Any) -> int:
        return size(p.model.A)

    wrap(build, "build_problem", "setup", lambda r, *a, **k: size(r.model.A))
    wrap(build, "build_unilateral_problem", "setup", lambda r, *a, **k: size(r.model.A))
    wrap(problem.Problem, "solve_free", "free solve", of_problem)
    wrap(problem.UnilateralProblem, "evaluate", "eigen", of_problem)
    wrap(kernel.NewtonKernel, "__init__", "kernel", lambda r, k, p, *a, **kw: size(p.model.A))
    wrap(newton.InteriorPointNewton, "solve", "Newton", lambda r, n, *a, **k: size(n.kernel.A))
    for name in ("predicted_contact_set", "contact_set"):
        wrap(newton.InteriorPointNewton, name, "sets", lambda r, n, *a, **k: size(n.kernel.A))
    wrap(factor.SharedFactorization, "factor", "LDL", lambda r, f, *a: size(f.matrix))
    wrap(multilevel.Prolongation, "__init__", "prolong", lambda r, c, co, f: size(f.model.A))
    wrap(multilevel.Prolongation, "mode", "prolong", lambda r, c, *a: size(c.fine.model.A))
    for name in ("relax", "lift"):
        wrap(starts.Starts, name, name, lambda r, s, *a, **k: size(s.kernel.A))
    wrap(explore, "explore", "other", of_problem)
    wrap(chain, "_carry", "other", lambda r, ps, k, *a, **kw: size(ps[k].model.A))
    wrap(certify, "certify", "certificate", lambda *a, **k: 0)
    # The names imported elsewhere, bound before the wrapping.
    analysis.certify, analysis.build_problem = certify.certify, build.build_problem
    chain.explore, chain.build_unilateral_problem = explore.explore, build.build_unilateral_problem
    chain.Prolongation = multilevel.Prolongation


def worker(case: str, nx: int, ny: int, free: bool, phases: bool = False) -> None:
    """One solve in this process; print a JSON line of its stage times."""
    from mpi4py import MPI
    from petsc4py import PETSc

    from bench_plates import _spec

    from unibuckle_fenicsx.analysis import solve

    PETSc.Log.begin()
    acc: dict[tuple[str, int], list[float]] = defaultdict(lambda: [0.0, 0, 0, 0])
    (_install_phases if phases else _install_timers)(acc)
    spec = _spec(case, nx, ny)
    if free:
        spec = replace(spec, obstacle=None)
    c0, n0 = time.process_time(), _counts()
    with solve(spec, MPI.COMM_WORLD) as run:
        result, solution = run.result, run.solution
        levels = [] if solution is None else getattr(solution.details, "levels", [])
        cert = run.certificate
        row: dict[str, Any] = {
            "dofs": result.dofs,
            "load_Pa": result.critical_load_Pa,
            "kkt": None if cert is None else cert.kkt,
            "tolerance": None if cert is None else cert.tolerance,
            "levels": [
                [lv.mesh, lv.newton_steps, lv.factorizations, lv.eigensolves] for lv in levels
            ],
        }
    row["total"] = time.process_time() - c0
    row["factorisations"], row["solves"] = (b - a for a, b in zip(n0, _counts(), strict=True))
    key = "phases" if phases else "stages"
    row[key] = [[stage, n, *values] for (stage, n), values in acc.items()]
    print(json.dumps(row))


def _run(case: str, nx: int, ny: int, free: bool, phases: bool = False) -> dict[str, Any]:
    cmd = [sys.executable, __file__, "--worker", case, str(nx), str(ny)]
    cmd += (["--free"] if free else []) + (["--phases"] if phases else [])
    out = subprocess.run(cmd, check=True, capture_output=True)
    return dict(json.loads(out.stdout.decode().strip().splitlines()[-1]))


def _phase_rows(
    case: str, mesh: str, run: dict[str, Any], free_run: dict[str, Any]
) -> list[dict[str, Any]]:
    """One row per level of ``run`` (coarsest first): its exclusive phase seconds.

    The fine level's row also holds the free solve, the certificate, the whole run's
    and the free run's process seconds and their ratio.
    """
    got: dict[tuple[str, int], list[float]] = {(s, k): v for s, k, *v in run["phases"]}
    sizes = sorted({k for ph, k in got if ph in PHASES})
    rows = []
    for n, (level, steps, _, eigensolves) in zip(sizes, run["levels"], strict=True):
        here = {ph: v for (ph, k), v in got.items() if k == n and ph in PHASES}
        rows.append(
            {
                "case": case, "mesh": mesh, "level": "x".join(map(str, level)), "dofs": n,
                "steps": steps, "eigensolves": eigensolves,
                "factorisations": int(sum(v[2] for v in here.values())),
                "solves": int(sum(v[3] for v in here.values())),
                "LDL calls": int(here.get("LDL", [0.0, 0])[1]),
                **{ph: here.get(ph, [0.0])[0] for ph in PHASES},
                "level total": sum(v[0] for v in here.values()),
            }
        )  # fmt: skip
    fine = rows[-1]
    fine["free solve"] = got.get(("free solve", fine["dofs"]), [0.0])[0]
    fine["certificate"] = got.get(("certificate", 0), [0.0])[0]
    fine["total"], fine["free run"] = run["total"], free_run["total"]
    fine["ratio"] = run["total"] / free_run["total"]
    fine["load_Pa"], fine["kkt"] = run["load_Pa"], run.get("kkt")
    return rows


def _stages(run: dict[str, Any], free_run: dict[str, Any]) -> dict[str, Any]:
    """The table's stages of one mesh from a run and its free run."""
    n = run["dofs"]
    got: dict[tuple[str, int], tuple[float, int]] = {
        (s, k): (t, c) for s, k, t, c, *_ in run["stages"]
    }

    def seconds(stage: str, fine: bool | None = None) -> float:
        return sum(
            t for (s, k), (t, _) in got.items() if s == stage and (fine is None or (k == n) == fine)
        )

    factorisations = got.get(("LDL", n), (0.0, 0))[1]
    coarsest = {k for s, k in got if s == "coarsest"}  # its IP runs inside _explore
    intermediate = sum(
        t for (s, k), (t, _) in got.items() if s == "IP" and k != n and k not in coarsest
    )
    return {
        "setup": seconds("setup"),
        "free solve": seconds("free solve", True),
        "coarse levels": seconds("coarsest") + intermediate,
        "fine IP": seconds("IP", True),
        "fine LDL": seconds("LDL", True),
        "fine LDL calls": factorisations,
        "fine eigen": seconds("eigen", True),
        "certificate": seconds("certificate"),
        "total": run["total"],
        "free run": free_run["total"],
    }


def _per_level(run: dict[str, Any]) -> str:
    """Per level: mesh: Newton steps / factorisations / solves / eigen solves.

    The factorisations and solves are the PETSc events counted inside the level's runs
    (its eigen solves' included); the levels' runs, keyed by their DOFs, in the order of
    the route's level records (coarsest first).
    """
    counted = sorted((row[1], row[4], row[5]) for row in run["stages"] if row[0] in STAGE_EVENTS)
    cells = []
    for lv, (_, factorisations, solves) in zip(run["levels"], counted, strict=False):
        mesh, steps, _, eigensolves = lv
        name = "x".join(str(m) for m in mesh)
        cells.append(f"{name}: {steps}/{factorisations}/{solves}/{eigensolves}")
    return " · ".join(cells)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default="90x30,180x60,360x120")
    parser.add_argument("--case", default="ssss", help="a case of bench_plates.py")
    parser.add_argument("--repeat", type=int, default=1, help="runs per process; minimum kept")
    parser.add_argument("--json", help="append one JSON line per mesh to this file")
    parser.add_argument("--worker", nargs=3, metavar=("CASE", "NX", "NY"), help=argparse.SUPPRESS)
    parser.add_argument("--free", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument(
        "--phases", action="store_true", help="exclusive seconds per level and phase instead"
    )
    args = parser.parse_args()
    if args.worker:
        worker(args.worker[0], int(args.worker[1]), int(args.worker[2]), args.free, args.phases)
        return
    if args.repeat < 1:
        parser.error(f"--repeat must be at least 1, got {args.repeat}")
    meshes = [tuple(int(v) for v in m.split("x")) for m in args.meshes.split(",")]
    if args.phases:
        _phases_main(args.case, meshes, args.json)
        return
    rows: list[dict[str, Any]] = []
    for nx, ny in meshes:
        best: dict[str, Any] | None = None
        for _ in range(args.repeat):
            run, free_run = _run(args.case, nx, ny, False), _run(args.case, nx, ny, True)
            stages = _stages(run, free_run)
            if best is None:
                best = {"run": run, "free": free_run, "stages": stages}
            else:
                best["stages"] = {k: min(v, stages[k]) for k, v in best["stages"].items()}
        assert best is not None
        run = best["run"]
        rows.append(
            {
                "case": args.case,
                "mesh": f"{nx}x{ny}",
                "dofs": run["dofs"],
                "load_Pa": run["load_Pa"],
                "kkt": run.get("kkt"),
                "tolerance": run.get("tolerance"),
                "levels": run["levels"],
                "per_level": _per_level(run),
                "factorisations": run["factorisations"],
                "solves": run["solves"],
                "free_factorisations": best["free"]["factorisations"],
                "free_solves": best["free"]["solves"],
                **best["stages"],
                "ratio": best["stages"]["total"] / best["stages"]["free run"],
            }
        )
    print_header(
        f"{args.case}: process seconds per stage (growth exponent p, t ~ DOFs^p, "
        "from the mesh before)",
        ["stage"] + [f"{r['mesh']} ({r['dofs']} DOFs)" for r in rows],
    )
    for stage in STAGES:
        cells = []
        for k, r in enumerate(rows):
            cell = f"{r[stage]:.2f}"
            if stage == "fine LDL":
                calls = r["fine LDL calls"]
                cell = f"{r[stage]:.2f} ({calls} x {r[stage] / max(calls, 1):.3f})"
            before = rows[k - 1] if k else None
            if before is not None and before[stage] > 0 and r[stage] > 0:
                p = math.log(r[stage] / before[stage]) / math.log(r["dofs"] / before["dofs"])
                cell += f" (p {p:.2f})"
            cells.append(cell)
        print(f"| {stage} | " + " | ".join(cells) + " |")
    ratios = " | ".join(f"{r['total'] / r['free run']:.2f}" for r in rows)
    print(f"| ratio total / free run | {ratios} |")
    for r in rows:
        print(
            f"{r['mesh']}: load {r['load_Pa']!r} Pa, KKT {r['kkt']} at tolerance "
            f"{r['tolerance']}; whole run {r['factorisations']} factorisations, "
            f"{r['solves']} solves (free run {r['free_factorisations']}, {r['free_solves']})"
        )
        print(f"  per level, steps / factorisations / solves / eigen solves: {r['per_level']}")
    append_rows(args.json, rows)


def _phases_main(case: str, meshes: list[tuple[int, ...]], path: str | None) -> None:
    """``--phases``: one run and one free run per mesh; a row per level and phase."""
    tail = ("free solve", "certificate", "total", "free run", "ratio")
    print_header(
        f"{case}: exclusive process seconds per level and phase (LDL: count x seconds each)",
        ["mesh", "level", "DOFs", "steps / factorisations / solves / eigen solves", *PHASES,
         "level", *tail],
    )  # fmt: skip
    for nx, ny in meshes:
        mesh = f"{nx}x{ny}"
        rows = _phase_rows(case, mesh, _run(case, nx, ny, False, True), _run(case, nx, ny, True))
        for r in rows:
            cells = [f"{r[ph]:.2f}" for ph in PHASES]
            calls = r["LDL calls"]
            cells[PHASES.index("LDL")] = f"{calls} x {r['LDL'] / max(calls, 1):.3f}"
            cells += [f"{r['level total']:.2f}"] + [f"{r[k]:.2f}" if k in r else "" for k in tail]
            counts = f"{r['steps']}/{r['factorisations']}/{r['solves']}/{r['eigensolves']}"
            print(f"| {mesh} | {r['level']} | {r['dofs']} | {counts} | " + " | ".join(cells) + " |")
        append_rows(path, rows)


if __name__ == "__main__":
    main()
