"""Benchmark: the verified bracket on thin long plates, and its cost against one free solve.

The thin plates of ``bench_plates.py`` (0.3 x 0.1 m, t = 1e-4 m, the obstacle over the
whole plate), where two to four pencil eigenvalues lie below the load and the split
route (:mod:`unibuckle_fenicsx.certificate.copositivity_split`) gives the bracket. For
each case and mesh, ``solve`` runs in one process (cold free solve, the route, the
certificate and, where the certificate refutes the answer, the descent from its refuting
mode and a new certificate); the table gives

- the load returned, the verified lower bound and the relative gap, the status (proven,
  bracketed, KKT only) and m, the pencil eigenvalues below the load;
- the split route's distances tried (verified or why not), its columns r, pieces
  proven, right-hand sides solved (batched), pieces examined, factorisations (one per
  distance), and its estimated cost in free solves (from counts: the rule that turns it
  on by default, at most 3);
- ``certificate / free``: the certificate's time (continuations included) over the cold
  free solve's, in one process, the least of ``--repeat`` runs (their values in the
  JSON row's ``ratios``: the least is the one least disturbed by other work on the
  machine); ``route / free``: the global bound's routes alone (the split route and the
  rank-2 attempts before it), the least of the runs;
- ``continued``: the loads of the refuting modes the solve continued from.

With ``--bracket`` the certificate runs as asked for (``solver.bracket``: distances down
to 1e-6, larger budgets, no cost limit); without, as by default. With ``--uncapped`` the
default solve is certified once more in the same process with the default's distances
and budgets but no cost limit (``SplitOptions(max_cost=None)``): the run the estimate
predicts, so that ``route / free`` is the measured cost the estimate is compared with.
With ``--compare`` each plate's default solve is bounded twice in one process, without
and with the interpolated multipliers (``SplitOptions(interpolate=False)``, the pieces as
before them, then the default), with the default's budgets, or with ``--bracket``'s
(``SplitOptions.thorough()``), no cost limit; the table gives both, "without -> with"
(rows in ``bench/results/bracket_compare.jsonl``, docs/verification/bracket_cost.md).
The rows also give the counts the cost model (``COST_MODEL``) is fitted to: DOFs,
factorisations (attempts) and pieces examined; ``--fit`` fits its unit costs to the
``--uncapped`` rows of a results file (non-negative least squares on the route's time
in free solves) and prints them with the estimate against the measured cost per plate.

Usage: python bench/bench_bracket.py [--meshes 90x30,180x60] [--cases ssss,cs,sc,cccc,shear]
[--bracket | --uncapped] [--compare] [--repeat N] [--json FILE] [--fit FILE]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
from pathlib import Path
from typing import Any

from mpi4py import MPI

from _results import append_rows, parse_plates, print_header
from bench_plates import CASES, _spec

from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.certificate.copositivity import BoundOptions, copositivity_bound
from unibuckle_fenicsx.certificate.copositivity_split import SplitOptions
from unibuckle_fenicsx.certificate.records import SplitRecord


def _attempts(split: SplitRecord | None) -> str:
    """Each distance tried: verified, or why not (shortened)."""
    out = []
    for a in split.attempts if split is not None else []:
        out.append(f"{a.delta:g} " + ("ok" if a.proven else a.why.split(":")[0]))
    return "; ".join(out)


def _number(value: float | None, spec: str) -> str:
    return "-" if value is None else format(value, spec)


def _predicted(analysis: Any, m: int) -> dict[str, Any]:
    """The counts the default's estimate prices (no solve), and the DOFs."""
    from unibuckle_fenicsx.certificate.copositivity_split import column_sources, estimate_counts

    opts, sol = SplitOptions(), analysis.solution
    sources = column_sources(analysis.problem, sol.candidate, sol.kkt_points, opts)
    counts = estimate_counts(analysis.problem, sources, m, opts)
    predicted = {"attempts": counts.attempts, "rhs": counts.rhs, "pieces": counts.pieces,
                 "size": counts.size}  # fmt: skip
    return {"dofs": int(analysis.problem.model.A.getSize()[0]), "predicted": predicted}


def _run(spec: Any, comm: Any, uncapped: bool) -> dict[str, Any]:
    """One solve in this process: result, certificate, solution, counts, the ratios.

    With ``uncapped``, the default solve's point is bounded once more with the default's
    budgets and no cost limit (:func:`copositivity_bound`, as the certificate calls it):
    its time split into factorisations, solves and the rest (the pieces' dense work).
    """
    with solve(spec, comm) as analysis:
        r, cert, sol = analysis.result, analysis.certificate, analysis.solution
        assert cert is not None and sol is not None
        free_s = analysis.problem.timings["free_solve_s"]
        out = {"result": r, "cert": cert, "solution": sol, "free_solve_s": free_s,
               "ratio": analysis.problem.timings["certify_s"] / free_s,
               "route": 0.0 if cert.copositivity is None
               else cert.copositivity.time_s / free_s}  # fmt: skip
        out.update(_predicted(analysis, cert.negative_eigenvalues))
        # The default solve's own certificate and route (with the cost limit), kept apart
        # from the uncapped bound's below.
        out.update(default_ratio=out["ratio"], default_route=out["route"],
                   default_status=cert.status)  # fmt: skip
        if uncapped:
            options = BoundOptions(lowrank=None, split=SplitOptions(max_cost=None))
            bound = copositivity_bound(analysis.problem, sol.candidate, sol.kkt_points, options)
            t = bound.timings
            out.update(bound=bound, route=t["total_s"] / free_s, ratio=t["total_s"] / free_s,
                       factor=t["factor_s"] / free_s, solve=t["solve_s"] / free_s)  # fmt: skip
        return out


def _row(name: str, mesh: str, args: Any, runs: list[dict[str, Any]]) -> dict[str, Any]:
    run = runs[-1]
    r, cert, sol = run["result"], run["cert"], run["solution"]
    bound = run.get("bound")
    split = bound.split if bound is not None else (
        None if cert.copositivity is None else cert.copositivity.split)  # fmt: skip
    attempts = [] if split is None else split.attempts
    row = {
        "case": name,
        "edges": CASES[name][2],
        "mesh": mesh,
        "bracket": args.bracket,
        "uncapped": args.uncapped,
        "repeat": args.repeat,
        "dofs": run["dofs"],
        "m": cert.negative_eigenvalues,
        "load_Pa": r.critical_load_Pa,
        "lower_bound_Pa": cert.lower_bound,
        "relative_gap": cert.relative_gap,
        "status": cert.status,
        "proven_by": cert.proven_by,
        "distances": _attempts(split) or "; ".join(cert.notes)[:80],
        "r": None if split is None else split.r,
        "pieces": None if split is None else split.pieces,
        "rhs": None if split is None else split.solves,
        "factorisations": len(attempts),
        "examined": sum(a.examined or 0 for a in attempts),
        "estimated_cost": None if split is None else split.estimated_cost,
        "predicted": run["predicted"],
        "free_solve_s": min(x["free_solve_s"] for x in runs),
        "certify_ratio": min(x["ratio"] for x in runs),
        "ratios": [x["ratio"] for x in runs],
        "route_ratio": min(x["route"] for x in runs),
        "routes": [x["route"] for x in runs],
        "continued": [c.from_load for c in sol.continued],
        "default_status": run["default_status"],
        "default_certify_ratio": min(x["default_ratio"] for x in runs),
        "default_route_ratio": min(x["default_route"] for x in runs),
    }
    if bound is not None:
        # The bound found without the cost limit (not the certificate's status: the
        # default solve's certificate ran with it).
        value = bound.value
        row.update(
            lower_bound_Pa=value,
            relative_gap=None if value is None else 1.0 - value / sol.candidate.load,
            status="bound" if value is not None else "none",
            proven_by=bound.method,
            factor_ratio=min(x["factor"] for x in runs),
            solve_ratio=min(x["solve"] for x in runs),
        )  # fmt: skip
    return row


def _units(row: dict[str, Any]) -> tuple[float, float, float]:
    """(factorisation, right-hand sides per free solve, piece) of one ``--uncapped`` row."""
    rest = row["route_ratio"] - row["factor_ratio"] - row["solve_ratio"]
    return (row["factor_ratio"] / max(row["factorisations"], 1),
            row["rhs"] / row["solve_ratio"],
            max(rest, 0.0) / max(row["examined"], 1))  # fmt: skip


def fit(path: str) -> dict[str, float]:
    """:data:`COST_MODEL`'s unit costs from the ``--uncapped`` rows of ``path``; print them.

    Per row, in free solves (the least of the repeats, each in one process): one
    factorisation (``factor_ratio`` over the factorisations), the right-hand sides per
    free solve (their count over ``solve_ratio``) and one piece's work (the rest of the
    route's time over the pieces examined). Plates with m <= 3 whose route found a
    bound only: with m = 4 a piece costs about three times more (the SPN programs of the
    deeper pieces), and their estimate exceeds the limit many times over by the pieces
    alone; a route that stops on an uncovered direction after a few pieces leaves the
    Gram products of all its columns to those few (their rows are printed, not
    fitted). Per mesh the largest factorisation and piece
    and the fewest right-hand sides (the estimate serves a rule that says "at most");
    between the smallest and the largest mesh, each unit's growth with the DOFs (a
    two-point fit; with one mesh the model's growth is kept). The pieces expected per
    attempt: the most examined per attempt by a fitted plate with m = 2, and the ratio
    of m = 3's to it as the growth per further negative eigenvalue. Then, per plate, the
    estimate by the model at run time, by the fitted one (one attempt, as the rule
    prices it), the route's own counts (its attempts, right-hand sides and pieces) priced
    by the fitted units, and the measured cost (all its attempts).
    """
    from unibuckle_fenicsx.certificate.copositivity_split import (
        COST_MODEL,
        CostCounts,
        price,
        unit_costs,
    )

    every = [row for row in map(json.loads, Path(path).read_text().splitlines())
             if row.get("uncapped") and row.get("factor_ratio") is not None]  # fmt: skip
    rows = [row for row in every if row["m"] <= 3 and row["lower_bound_Pa"] is not None]
    units = []
    for row in rows:
        units.append(_units(row))
    sizes = sorted({row["dofs"] for row in rows})
    pick = (max, min, max)
    at = {n: [pick[k](u[k] for u, row in zip(units, rows, strict=True) if row["dofs"] == n)
              for k in range(3)] for n in sizes}  # fmt: skip
    model = dict(COST_MODEL)
    ref = model["reference_dofs"]
    keys = (("factorisation", "factor_growth", 1), ("rhs_per_solve", "rhs_growth", -1),
            ("piece", "piece_growth", 1))  # fmt: skip
    for k, (name, growth, sign) in enumerate(keys):
        lo, hi = at[sizes[0]][k], at[sizes[-1]][k]
        if len(sizes) > 1:
            model[growth] = sign * math.log(hi / lo) / math.log(sizes[-1] / sizes[0])
        model[name] = lo / (sizes[0] / ref) ** (sign * model[growth])
    # Pieces expected per attempt: the most examined by one attempt of a plate with m = 2
    # (its first attempt's share: the pieces over the attempts), and the growth to m = 3.
    per_attempt = {m: max((row["examined"] / max(row["factorisations"], 1) for row in rows
                           if row["m"] == m), default=None) for m in (2, 3)}  # fmt: skip
    if per_attempt[2]:
        model["pieces"] = per_attempt[2]
        if per_attempt[3]:
            model["growth"] = per_attempt[3] / per_attempt[2]
    print("fitted:", {k: round(v, 4) for k, v in model.items()})
    print_header(
        f"{len(rows)} rows of {path}",
        ("case", "mesh", "m", "factorisation / free", "rhs per free solve", "piece / free",
         "factorisations", "rhs", "examined", "pieces expected", "estimate (run time)",
         "estimate (fitted)", "its counts (fitted)", "measured"),
    )  # fmt: skip
    for row in every:
        u = units[rows.index(row)] if row in rows else _units(row)
        p = row["predicted"]
        m = row["m"]
        pieces = min(model["pieces"] * model["growth"] ** max(m - 2, 0), 400.0)
        counts = CostCounts(1, p["rhs"], pieces, p["size"])
        factor, per_rhs, piece = unit_costs(p["size"], model)
        spent = (row["factorisations"] * factor + row["rhs"] * per_rhs
                 + row["examined"] * piece)  # fmt: skip
        print(f"| {row['case']} | {row['mesh']} | {m} | {u[0]:.3f} | {u[1]:.0f} | "
              f"{u[2]:.4f} | {row['factorisations']} | {row['rhs']} | {row['examined']} | "
              f"{pieces:g} | {row['estimated_cost']:.2f} | "
              f"{price(counts, model):.2f} | {spent:.2f} | {row['route_ratio']:.2f} |")  # fmt: skip
    return model


def _compare(spec: Any, comm: Any, thorough: bool, repeat: int) -> dict[str, Any]:
    """Without and with the interpolated multipliers, from one solve, in one process.

    Per variant (keys ending ``_without`` and ``_with``): the bound of the last run and
    the least of ``repeat`` times over the free solve's (all of them in ``routes_*``).
    """
    with solve(spec, comm) as analysis:
        sol, free_s = analysis.solution, analysis.problem.timings["free_solve_s"]
        assert sol is not None
        load = sol.candidate.load
        row: dict[str, Any] = {"load_Pa": load, "free_solve_s": free_s}
        for interpolate, tag in ((False, "without"), (True, "with")):
            base = SplitOptions.thorough() if thorough else SplitOptions(max_cost=None)
            split = dataclasses.replace(base, interpolate=interpolate)
            options = BoundOptions(lowrank=None, split=split)
            times = []
            for _ in range(repeat):
                bound = copositivity_bound(analysis.problem, sol.candidate, sol.kkt_points, options)
                times.append(bound.timings["total_s"] / free_s)
            record = bound.split
            attempts = [] if record is None else record.attempts
            row["m"] = None if record is None else record.m
            row.update({
                f"gap_{tag}": None if bound.value is None else 1.0 - bound.value / load,
                f"lower_bound_Pa_{tag}": bound.value,
                f"factorisations_{tag}": len(attempts),
                f"rhs_{tag}": None if record is None else record.solves,
                f"examined_{tag}": sum(a.examined or 0 for a in attempts),
                f"pieces_{tag}": None if record is None else record.pieces,
                f"route_ratio_{tag}": min(times),
                f"routes_{tag}": times,
            })  # fmt: skip
        return row


def _print_compare(name: str, mesh: str, budgets: str, row: dict[str, Any]) -> None:
    def pair(key: str, spec: str = "") -> str:
        values = (row[f"{key}_{tag}"] for tag in ("without", "with"))
        return " -> ".join("-" if x is None else format(x, spec) for x in values)

    print(f"| {name} | {mesh} | {row['m']} | {budgets} | {pair('gap', '.0e')} | "
          f"{pair('factorisations')} | {pair('rhs')} | {pair('examined')} | "
          f"{pair('pieces')} | {pair('route_ratio', '.2f')} |", flush=True)  # fmt: skip


def _compare_all(args: Any, meshes: list[tuple[int, int]], comm: Any) -> None:
    """``--compare``: the table "without -> with" per plate and mesh, and its JSON rows."""
    budgets = "--bracket" if args.bracket else "default"
    if comm.rank == 0:
        print_header(
            f"MPI ranks: {comm.size}; without -> with the interpolated multipliers",
            ("case", "mesh", "m", "budgets", "gap", "factorisations", "rhs", "examined",
             "pieces proven", "route / free"),
        )  # fmt: skip
    for nx, ny in meshes:
        for name in args.cases.split(","):
            row = _compare(_spec(name, nx, ny, "above"), comm, args.bracket, args.repeat)
            if comm.rank == 0:
                _print_compare(name, f"{nx}x{ny}", budgets, row)
                row.update(case=name, mesh=f"{nx}x{ny}", bracket=args.bracket, repeat=args.repeat)
                append_rows(args.json, [row])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default="90x30,180x60")
    parser.add_argument("--cases", default=",".join(CASES))
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--bracket", action="store_true", help="solver.bracket (as asked for)")
    mode.add_argument("--uncapped", action="store_true", help="default budgets, no cost limit")
    parser.add_argument(
        "--compare", action="store_true", help="without and with the interpolated multipliers"
    )
    parser.add_argument("--repeat", type=int, default=1, help="runs per plate (least ratio)")
    parser.add_argument("--json", help="append one JSON line per row to this file")
    parser.add_argument("--fit", help="fit COST_MODEL's unit costs to this file's rows; no run")
    args, meshes = parse_plates(parser)
    comm = MPI.COMM_WORLD
    if args.fit:
        if comm.rank == 0:
            fit(args.fit)
        return
    if args.compare:
        _compare_all(args, meshes, comm)
        return
    if comm.rank == 0:
        print_header(
            f"MPI ranks: {comm.size}; bracket asked for: {args.bracket}; "
            f"uncapped: {args.uncapped}",
            ("case", "mesh", "m", "lambda_c (Pa)", "lower bound (Pa)", "gap", "status",
             "distances", "r", "pieces", "rhs", "examined", "factorisations", "estimated cost",
             "certificate / free", "route / free", "continued"),
        )  # fmt: skip
    for nx, ny in meshes:
        for name in args.cases.split(","):
            spec = _spec(name, nx, ny, "above")
            if args.bracket:
                spec = spec.with_solver(bracket=True)
            runs = [_run(spec, comm, args.uncapped) for _ in range(args.repeat)]
            row = _row(name, f"{nx}x{ny}", args, runs)
            if comm.rank == 0:
                print(
                    "| {case} | {mesh} | {m} | {load_Pa:.6f} | {lower} | "
                    "{gap} | {status} | {distances} | {r} | {pieces} | {rhs} | "
                    "{examined} | {factorisations} | {est} | **{certify_ratio:.2f}** | "
                    "{route_ratio:.2f} | "
                    "{continued} |".format(
                        **row,
                        lower=_number(row["lower_bound_Pa"], ".6f"),
                        gap=_number(row["relative_gap"], ".1e"),
                        est="-" if row["estimated_cost"] is None
                        else f"{row['estimated_cost']:.2f}",
                    ),
                    flush=True,
                )  # fmt: skip
                append_rows(args.json, [row])


if __name__ == "__main__":
    main()
