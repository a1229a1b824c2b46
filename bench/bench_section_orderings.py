r"""Benchmark: MUMPS's orderings on a section's interior-point Newton matrix, by size.

A filled section's route factorises its Newton matrix
:math:`K = A' - \lambda B' + E\,\Sigma E^T` (the rotated pencil of
:mod:`~unibuckle_fenicsx.model.shell.core`, the barrier's diagonal on the constrained
directions) once a Newton step, hundreds of times per section
(:doc:`/verification/sections_cost`); its symbolic analysis (the ordering) is done once
per section. For each section (the box b = d = 0.2 m, t = 2 mm, L = 3b, or the tube
R = 0.1 m, t = 1 mm, L = R of ``bench_sections.py``; simply supported ends, a rigid core)
and each ordering this script times the analysis with the first numeric factorisation,
then a numeric factorisation of the same pattern (the Newton steps'), and reads MUMPS's
counts: entries in the factors (INFOG(29)) and operations of the elimination
(RINFOG(3)). K here is :math:`A' - \lambda B'` at ``--load`` times the free load, with
:math:`\Sigma` = ``--barrier`` times diag(A') on the constrained directions (a state
inside the cone: the operations depend on the pattern, not on the values; no pivot was
delayed on these matrices, INFOG(13) = 0).

Times are CPU seconds of the process (MUMPS on one thread, ``OMP_NUM_THREADS=1``), the
minimum over ``--repeat`` numeric factorisations: on a shared machine the wall clock
measures the other jobs too.

Usage: python bench/bench_section_orderings.py [--sections box:0.05,box:0.0125,tube:0.002]
[--orderings amf,metis] [--repeat 3] [--icntl 13=0,24=0] [--json FILE]
"""

from __future__ import annotations

import argparse
import time

from mpi4py import MPI
from petsc4py import PETSc

from _results import append_rows, print_header
from bench_sections import section_parameters

from unibuckle_fenicsx.la.factor import LDL_OPTIONS
from unibuckle_fenicsx.la.options import ORDERINGS, mumps_ordering
from unibuckle_fenicsx.model.shell.section import build_section

COLUMNS = (
    "section", "cell_mm", "rows", "ordering", "package", "analysis_s", "numeric_s",
    "factor_entries", "flops",
)  # fmt: skip
_SAME = PETSc.Mat.Structure.SAME_NONZERO_PATTERN


def _newton_matrix(section, load: float, barrier: float) -> PETSc.Mat:  # type: ignore[no-untyped-def]
    r""":math:`A' - \lambda B' + \Sigma` (the caller destroys it)."""
    problem = section.cored
    A, B = problem.model.A, problem.model.B
    free = problem.solve_free().load
    K = A.duplicate(copy=True)
    B_on_A = A.duplicate(copy=False)
    B_on_A.axpy(1.0, B, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
    K.axpy(-load * free, B_on_A, structure=_SAME)
    B_on_A.destroy()
    diag = A.createVecLeft()
    A.getDiagonal(diag)
    sigma = diag.duplicate()
    sigma.zeroEntries()
    dofs = problem.contact.owned_local_dofs
    sigma.array[dofs] = barrier * diag.array[dofs]
    K.setDiagonal(sigma, addv=PETSc.InsertMode.ADD_VALUES)  # type: ignore[arg-type]
    K.setOption(PETSc.Mat.Option.SPD, False)
    K.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    diag.destroy()
    sigma.destroy()
    return K


def _factorise(K: PETSc.Mat, ordering: int, repeat: int, icntl: dict[int, int]) -> dict:
    """Analysis + first numeric factorisation, then the least of ``repeat`` numeric ones."""
    ksp = PETSc.KSP().create(K.comm)
    ksp.setOptionsPrefix("bench_section_orderings_")
    ksp.setOperators(K)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("cholesky")
    pc.setFactorSolverType("mumps")
    pc.setFactorSetUpSolverType()
    factor = pc.getFactorMatrix()
    factor.setMumpsIcntl(7, ordering)
    for key, value in LDL_OPTIONS.items():
        if key.startswith("mat_mumps_icntl_"):
            factor.setMumpsIcntl(int(key.rsplit("_", 1)[1]), int(value))
    for key, value in icntl.items():  # --icntl: over the package's controls
        factor.setMumpsIcntl(key, value)
    t0 = time.process_time()
    ksp.setUp()
    first = time.process_time() - t0
    numeric = []
    for _ in range(repeat):
        K.shift(0.0)  # a new state of the values: the next setUp is numeric only
        K.assemble()
        ksp.setOperators(K)
        t0 = time.process_time()
        ksp.setUp()
        numeric.append(time.process_time() - t0)
    factor = pc.getFactorMatrix()
    out = {
        "analysis_s": max(first - min(numeric), 0.0),
        "numeric_s": min(numeric),
        "factor_entries": int(factor.getMumpsInfog(29)),
        "flops": float(factor.getMumpsRinfog(3)),
        "delayed": int(factor.getMumpsInfog(13)),
    }
    ksp.destroy()
    return out


def main() -> None:
    """Parse the options, run, print the table."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sections", default="box:0.05,box:0.025,box:0.0125,tube:0.005")
    parser.add_argument("--orderings", default="amf,metis")
    parser.add_argument("--load", type=float, default=1.9, help="lambda over the free load")
    parser.add_argument("--barrier", type=float, default=1e-3, help="Sigma over diag(A')")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument(
        "--icntl", default="", help="MUMPS controls over LDL_OPTIONS', e.g. 13=0,24=0"
    )
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    icntl = {int(k): int(v) for k, v in (c.split("=") for c in args.icntl.split(",") if c)}
    print_header("A section's Newton matrix by ordering (one rank, CPU seconds)", COLUMNS)
    rows = []
    for item in args.sections.split(","):
        shape, size = item.split(":")
        with build_section(section_parameters(shape, float(size)), MPI.COMM_SELF) as section:
            K = _newton_matrix(section, args.load, args.barrier)
            n = int(K.getSize()[0])
            package = mumps_ordering(n, reused=True)
            for name in args.orderings.split(","):
                row = {
                    "section": shape,
                    "cell_mm": 1e3 * float(size),
                    "rows": n,
                    "ordering": name,
                    "package": "yes" if ORDERINGS[name] == package else "",
                    "load": args.load,
                    "barrier": args.barrier,
                    "repeat": args.repeat,
                    "icntl": args.icntl,
                    **_factorise(K, ORDERINGS[name], args.repeat, icntl),
                }
                rows.append(row)
                cells = [row[c] for c in COLUMNS]
                print(
                    "| "
                    + " | ".join(f"{v:.3g}" if isinstance(v, float) else str(v) for v in cells)
                    + " |",
                    flush=True,
                )
            K.destroy()
    append_rows(args.json, rows)


if __name__ == "__main__":
    main()
