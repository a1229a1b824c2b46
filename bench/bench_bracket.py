"""Benchmark: the verified bracket on thin long plates, and its cost against one free solve.

The thin plates of ``bench_plates.py`` (0.3 x 0.1 m, t = 1e-4 m, the obstacle over the
whole plate), where two to four pencil eigenvalues lie below the load and the split
route (:mod:`unibuckle_fenicsx.certificate.copositivity_split`) gives the bracket. For
each case and mesh, ``solve`` runs in one process (cold free solve, the route, the
certificate and, where the certificate refutes the answer, the descent from its refuting
mode and a new certificate); the table gives

- the load returned, the verified lower bound and the relative gap, the status (proven,
  bracketed, KKT only) and m, the pencil eigenvalues below the load;
- the split route's distances tried (verified or why not), its columns r, pieces and
  right-hand sides solved (batched), and its estimated cost in free solves (from counts:
  the rule that turns it on by default, at most 3);
- ``certificate / free``: the certificate's time (continuations included) over the cold
  free solve's, in one process, the median of ``--repeat`` runs (their values in the
  JSON row's ``ratios``); ``route / free``: the global bound's routes alone (the split
  route and the rank-2 attempts before it), the same run's;
- ``continued``: the loads of the refuting modes the solve continued from.

With ``--bracket`` the certificate runs as asked for (``solver.bracket``: distances down
to 1e-6, larger budgets, no cost limit); without, as by default.

Usage: python bench/bench_bracket.py [--meshes 90x30,180x60] [--cases ssss,cs,sc,cccc,shear]
[--bracket] [--repeat N] [--json FILE]
"""

from __future__ import annotations

import argparse
import statistics

from mpi4py import MPI

from _results import append_rows, parse_plates, print_header
from bench_plates import CASES, _spec

from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.certificate.records import SplitRecord


def _attempts(split: SplitRecord | None) -> str:
    """Each distance tried: verified, or why not (shortened)."""
    out = []
    for a in split.attempts if split is not None else []:
        out.append(f"{a.delta:g} " + ("ok" if a.proven else a.why.split(":")[0]))
    return "; ".join(out)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default="90x30,180x60")
    parser.add_argument("--cases", default=",".join(CASES))
    parser.add_argument("--bracket", action="store_true", help="solver.bracket (as asked for)")
    parser.add_argument("--repeat", type=int, default=1, help="runs per plate (median ratio)")
    parser.add_argument("--json", help="append one JSON line per row to this file")
    args, meshes = parse_plates(parser)
    comm = MPI.COMM_WORLD
    if comm.rank == 0:
        print_header(
            f"MPI ranks: {comm.size}; bracket asked for: {args.bracket}",
            ("case", "mesh", "m", "lambda_c (Pa)", "lower bound (Pa)", "gap", "status",
             "distances", "r", "pieces", "rhs", "estimated cost", "certificate / free",
             "route / free", "continued"),
        )  # fmt: skip
    for nx, ny in meshes:
        for name in args.cases.split(","):
            spec = _spec(name, nx, ny, "above")
            if args.bracket:
                spec = spec.with_solver(bracket=True)
            ratios, routes = [], []
            for _ in range(args.repeat):
                with solve(spec, comm) as analysis:
                    r, cert, sol = analysis.result, analysis.certificate, analysis.solution
                    assert cert is not None and sol is not None
                    t = analysis.problem.timings
                    ratios.append(t["certify_s"] / t["free_solve_s"])
                    record = cert.copositivity
                    route_s = 0.0 if record is None else record.time_s
                    routes.append(route_s / t["free_solve_s"])
            split = None if cert.copositivity is None else cert.copositivity.split
            row = {
                "case": name,
                "edges": CASES[name][2],
                "mesh": f"{nx}x{ny}",
                "bracket": args.bracket,
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
                "estimated_cost": None if split is None else split.estimated_cost,
                "free_solve_s": t["free_solve_s"],
                "certify_ratio": statistics.median(ratios),
                "ratios": ratios,
                "route_ratio": statistics.median(routes),
                "continued": [c.from_load for c in sol.continued],
            }
            if comm.rank == 0:
                print(
                    "| {case} | {mesh} | {m} | {load_Pa:.6f} | {lower_bound_Pa:.6f} | "
                    "{relative_gap:.1e} | {status} | {distances} | {r} | {pieces} | {rhs} | "
                    "{est} | **{certify_ratio:.2f}** | {route_ratio:.2f} | {continued} |".format(
                        **row,
                        est="-" if row["estimated_cost"] is None
                        else f"{row['estimated_cost']:.2f}",
                    ),
                    flush=True,
                )  # fmt: skip
                append_rows(args.json, [row])


if __name__ == "__main__":
    main()
