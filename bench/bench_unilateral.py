"""Benchmark: unilateral (active-set) solve time over one free buckling solve.

For the paper's plate with the zones c1 and c3, on each mesh: set the problem up, time
one free buckling solve (cold: first solve on the problem, LU included), then time
:func:`~unibuckle_fenicsx.algorithms.active_set.solve_active_set` on the same problem
(coarse levels and their set-up included). Prints a table; peak memory is the process
maximum resident set size so far (``resource.getrusage``), i.e. cumulative. With
``--json FILE`` each row is also appended to FILE as one JSON line.

Usage: python bench/bench_unilateral.py [--meshes 160x80,320x160] [--cases c1,c3]
[--json FILE]
"""

from __future__ import annotations

import argparse
import resource
import time

from mpi4py import MPI

from _results import append_rows

from unibuckle_fenicsx.algorithms.active_set import solve_active_set
from unibuckle_fenicsx.model.problem import BucklingProblem
from unibuckle_fenicsx.spec.cases import paper_case


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default="160x80,320x160")
    parser.add_argument("--cases", default="c1,c3")
    parser.add_argument("--json", help="append one JSON line per row to this file")
    args, _ = parser.parse_known_args()
    comm = MPI.COMM_WORLD
    meshes = [tuple(int(v) for v in m.split("x")) for m in args.meshes.split(",")]
    header = (
        f"{'case':5} {'mesh':>8} {'dofs':>7} {'free [s]':>9} {'unilat. [s]':>11} "
        f"{'ratio':>6} {'solves':>11} {'peak MB':>8} {'load [Pa]':>14} {'|Z|':>5} kkt"
    )
    if comm.rank == 0:
        print(f"MPI ranks: {comm.size}")
        print(header)
    for nx, ny in meshes:
        for case in args.cases.split(","):
            problem = BucklingProblem(paper_case(case, nx, ny), comm)
            comm.Barrier()
            t0 = time.perf_counter()
            problem.solve_free()
            t_free = time.perf_counter() - t0
            comm.Barrier()
            t0 = time.perf_counter()
            sol = solve_active_set(problem)
            t_uni = time.perf_counter() - t0
            peak = comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, op=MPI.MAX)
            d = sol.details
            solves = f"{d['fine_eigensolves']}+{d['coarse_eigensolves']}c"
            if comm.rank == 0:
                print(
                    f"{case:5} {f'{nx}x{ny}':>8} {problem.model.num_dofs:7d} {t_free:9.2f} "
                    f"{t_uni:11.2f} {t_uni / t_free:6.2f} {solves:>11} {peak / 1024:8.0f} "
                    f"{sol.load:14.6f} {len(sol.active):5d} {sol.candidate.kkt}",
                    flush=True,
                )
                row = {
                    "case": case,
                    "mesh": f"{nx}x{ny}",
                    "ranks": comm.size,
                    "dofs": problem.model.num_dofs,
                    "free_solve_s": t_free,
                    "unilateral_s": t_uni,
                    "ratio": t_uni / t_free,
                    "fine_eigensolves": d["fine_eigensolves"],
                    "coarse_eigensolves": d["coarse_eigensolves"],
                    "peak_MB": peak / 1024,
                    "load_Pa": sol.load,
                    "contact_nodes": len(sol.active),
                    "kkt": bool(sol.candidate.kkt),
                }
                append_rows(args.json, [row])
            problem.destroy()


if __name__ == "__main__":
    main()
