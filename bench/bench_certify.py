"""Benchmark: the global-optimality certificate's cost against one free eigen solve.

For each case and mesh: ``solve`` (free solve, unilateral algorithm, certificate, all in
one process), then the certificate's time over the free solve's (cold: LU included),
its route, the verified gap, and its factorisations and solves. Target: at most one free
solve.

With ``--json FILE`` each row is also appended to FILE as one JSON line (the
documentation renders ``bench/results/certify.jsonl`` as a table).

Usage: python bench/bench_certify.py [--meshes 160x80,320x160] [--cases c1,c3] [--json FILE]
"""

from __future__ import annotations

import argparse

from mpi4py import MPI

from _results import append_rows

from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.spec.cases import paper_case

#: The JSON keys of a row, in the table's order.
JSON_KEYS = (
    "case",
    "mesh",
    "dofs",
    "i",
    "contact_nodes",
    "free_solve_s",
    "certificate_s",
    "ratio",
    "proven_by",
    "relative_gap",
    "factorisations",
    "solves",
    "load_Pa",
    "lower_bound_Pa",
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default="160x80,320x160")
    parser.add_argument("--cases", default="c1,c3")
    parser.add_argument("--json", help="append one JSON line per row to this file")
    args, _ = parser.parse_known_args()
    comm = MPI.COMM_WORLD
    meshes = [tuple(int(v) for v in m.split("x")) for m in args.meshes.split(",")]
    rows = []
    for nx, ny in meshes:
        for case in args.cases.split(","):
            with solve(paper_case(case, nx, ny), comm) as analysis:
                r, cert = analysis.result, analysis.certificate
            assert cert is not None
            t = r.timings
            record = cert.copositivity or {}
            rows.append(
                (
                    case,
                    f"{nx}x{ny}",
                    r.dofs,
                    r.constrained_nodes,
                    r.contact_nodes,
                    t["free_solve_s"],
                    t["certify_s"],
                    t["certify_s"] / t["free_solve_s"],
                    cert.proven_by,
                    cert.relative_gap,
                    record.get("factorisations", 0),
                    record.get("solves", 0),
                    r.critical_load_Pa,
                    cert.lower_bound,
                )
            )
    if comm.rank == 0:
        print(f"MPI ranks: {comm.size}")
        print(
            "| case | mesh | DOFs | i | \\|Z\\| | free solve (s) | certificate (s) | ratio "
            "| proven by | gap | LDL^T | solves | lambda_c (Pa) | lower bound (Pa) |"
        )
        print("|" + "---|" * 14)
        for row in rows:
            print(
                "| {} | {} | {} | {} | {} | {:.2f} | {:.2f} | **{:.2f}** | {} | {:.0e} | {} "
                "| {} | {:.2f} | {:.2f} |".format(*row)
            )
        append_rows(args.json, (dict(zip(JSON_KEYS, row, strict=True)) for row in rows))


if __name__ == "__main__":
    main()
