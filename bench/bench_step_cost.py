r"""Benchmark: one Newton step's factorisation against one free solve, section and plate.

The multiple a unilateral solve takes of its free solve is mostly its Newton steps'
numeric LDLᵀ factorisations (:doc:`/verification/sections_cost`). This script measures
the unit: for each problem, the free eigen solve in CPU seconds (with PETSc's counts of
its numeric factorisations and solves), then :math:`K = A - 1.9\,\lambda_{free} B`
factorised as the interior point does (MUMPS LDLᵀ: the analysis, then the least of
``--repeat`` numeric factorisations of the same pattern, ``bench_section_orderings.py``'s
routine), and the ratio of the two.

Problems: ``box:SIZE`` (the filled box of ``bench_sections.py`` on cells of SIZE m) and
``CASE:NXxNY:T`` (a plate of ``bench_plates.py``, e.g. ``sc:330x110:1e-3``).

Usage: python bench/bench_step_cost.py [--problems box:0.00526,sc:330x110:1e-3]
[--orderings metis,amf] [--repeat 3] [--json FILE]

Note:
    CPU seconds of the process (``OMP_NUM_THREADS=1``): on a shared machine the wall
    clock measures the other jobs too.
"""

from __future__ import annotations

import argparse
import time

from mpi4py import MPI
from petsc4py import PETSc

from _results import append_rows, print_header
from bench_section_orderings import _factorise

from unibuckle_fenicsx.la.options import ORDERINGS

COLUMNS = (
    "problem", "rows", "free_cpu_s", "free_factorisations", "free_solves", "ordering",
    "numeric_s", "flops", "per_free_solve",
)  # fmt: skip
_EVENTS = ("MatCholFctrNum", "MatLUFactorNum", "MatSolve")


def _counts() -> dict[str, int]:
    return {name: int(PETSc.Log.Event(name).getPerfInfo()["count"]) for name in _EVENTS}


def _problem(name: str):  # type: ignore[no-untyped-def]
    """The problem ``name`` and what owns it (destroyed by the caller)."""
    parts = name.split(":")
    if parts[0] == "box":
        from bench_sections import section_parameters

        from unibuckle_fenicsx.model.shell.section import build_section

        section = build_section(section_parameters("box", float(parts[1])), MPI.COMM_SELF, None)
        return section.cored, section
    from bench_plates import _spec

    from unibuckle_fenicsx.model.build import build_problem

    nx, ny = (int(n) for n in parts[1].split("x"))
    problem = build_problem(_spec(parts[0], nx, ny, "above", float(parts[2])), MPI.COMM_SELF)
    return problem, problem


def _newton_matrix(A: PETSc.Mat, B: PETSc.Mat, load: float) -> PETSc.Mat:
    """K = A - load B on A's pattern (the caller destroys it)."""
    K = A.duplicate(copy=True)
    B_on_A = A.duplicate(copy=False)
    B_on_A.axpy(1.0, B, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
    K.axpy(-load, B_on_A, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
    B_on_A.destroy()
    K.setOption(PETSc.Mat.Option.SPD, False)
    K.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    return K


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--problems", default="box:0.00526,sc:330x110:1e-3")
    parser.add_argument("--orderings", default="metis")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    PETSc.Log.begin()
    print_header("One LDLᵀ of the Newton matrix against one free solve (CPU s)", COLUMNS)
    rows = []
    for name in args.problems.split(","):
        problem, owner = _problem(name)
        before, t0 = _counts(), time.process_time()
        free = problem.solve_free().load
        free_s = time.process_time() - t0
        after = _counts()
        K = _newton_matrix(problem.model.A, problem.model.B, 1.9 * free)
        for ordering in args.orderings.split(","):
            out = _factorise(K, ORDERINGS[ordering], args.repeat, {})
            row = {
                "problem": name,
                "rows": K.getSize()[0],
                "free_cpu_s": free_s,
                "free_factorisations": sum(
                    after[e] - before[e] for e in ("MatCholFctrNum", "MatLUFactorNum")
                ),
                "free_solves": after["MatSolve"] - before["MatSolve"],
                "ordering": ordering,
                "numeric_s": out["numeric_s"],
                "flops": out["flops"],
                "per_free_solve": out["numeric_s"] / free_s,
            }
            rows.append(row)
            cells = [f"{row[c]:.3g}" if isinstance(row[c], float) else str(row[c]) for c in COLUMNS]
            print("| " + " | ".join(cells) + " |", flush=True)
        K.destroy()
        owner.destroy()
    append_rows(args.json, rows)


if __name__ == "__main__":
    main()
