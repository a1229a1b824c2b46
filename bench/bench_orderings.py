r"""Benchmark: MUMPS's fill-reducing orderings (ICNTL(7)) on the package's matrices, by size.

Every direct solve of a run is a MUMPS factorisation, and MUMPS orders the matrix first
(its symbolic analysis). For each plate and mesh this script builds the package's
matrices and, for each ordering, times the analysis, one numeric factorisation and one
solve, and reads MUMPS's own counts (entries in the factors, INFOG(29); operations of
the elimination, RINFOG(3); memory, INFOG(22)):

- ``pencil_ldl``: :math:`A - \\sigma B` with :math:`\\sigma` 1 % above a coarse
  estimate of the free load, by the symmetric indefinite :math:`LDL^T` with inertia that
  the free solve, the shifted eigen solves, the interior point's Newton steps and the
  certificate share (prefix ``unibuckle_ldl_``, ``unibuckle_certify_``);
- ``stiffness_lu``: A by the LU of the eigen solves at target 0 (a contact set's pencil,
  prefix ``unibuckle_``);
- ``prestress_lu``, ``prestress_cholesky``: the membrane stiffness of the prestress
  solve (prefix ``unibuckle_prestress_``), by an LU and by MUMPS's symmetric
  factorisation (the one that solve uses).

``free_s`` = analysis + one numeric factorisation + ten solves: what an ordering costs a
free solve, which factorises the pencil once and solves about ten times. Times are CPU
seconds of the process (MUMPS on one thread, ``OMP_NUM_THREADS=1``), the minimum over
``--repeat`` runs: on a shared machine the wall clock measured the other jobs (up to
six times the CPU time at a load of 12 on 2 cores), the CPU time much less.

Usage: python bench/bench_orderings.py [--plates paper,thin] [--meshes 160x80,320x160]
[--orderings amd,amf,pord,qamd,metis,scotch] [--kinds pencil_ldl,stiffness_lu,
prestress_cholesky] [--repeat 3] [--json FILE]

``--meshes`` applies to every plate; ``--dofs 30000,150000,600000`` instead picks, per
plate, the mesh of its aspect ratio nearest each number of (w, theta) DOFs. A 10^6-DOF
mesh needs about 10 GB: run it under ``flock /tmp/unibuckle-bigmem.lock``.
"""

from __future__ import annotations

import argparse
import math
import time

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem.petsc
import ufl

from _results import append_rows, print_header
from bench_free import PLATES

from unibuckle_fenicsx.model.prestress import membrane_force
from unibuckle_fenicsx.model.problem import BucklingProblem

#: MUMPS ICNTL(7) values.
ORDERINGS = {"amd": 0, "amf": 2, "scotch": 3, "pord": 4, "metis": 5, "qamd": 6}
#: Length over width of the plates of bench_free.py.
ASPECT = {"paper": 2.0, "thin": 3.0}
KINDS = ("pencil_ldl", "stiffness_lu", "prestress_lu", "prestress_cholesky")


def _mesh_for(aspect: float, dofs: int) -> tuple[int, int]:
    """The nx x ny mesh of a plate of this aspect with about ``dofs`` (w, theta) DOFs."""
    ny = max(2, round(math.sqrt(dofs / (3.0 * aspect))))
    return round(aspect * ny), ny


def _time_factor(
    mat: PETSc.Mat, pc_type: str, ordering: int, repeat: int
) -> dict[str, float | int]:
    """Analysis, numeric factorisation and solve of ``mat`` with one MUMPS ordering.

    CPU seconds of this process (``time.process_time``; MUMPS runs on one thread here):
    a first set-up (analysis and numeric factorisation), then a second after the
    matrix's values are touched (numeric only); the analysis is the difference.
    """
    analysis, numeric, solve = [], [], []
    info: dict[str, float | int] = {}
    for _ in range(repeat):
        ksp = PETSc.KSP().create(mat.comm)
        ksp.setOptionsPrefix("bench_orderings_")
        ksp.setOperators(mat)
        ksp.setType("preonly")
        pc = ksp.getPC()
        pc.setType(pc_type)
        pc.setFactorSolverType("mumps")
        pc.setFactorSetUpSolverType()
        factor = pc.getFactorMatrix()
        factor.setMumpsIcntl(7, ordering)
        if pc_type == "cholesky":
            factor.setMumpsIcntl(13, 1)
            factor.setMumpsIcntl(24, 1)
        c0 = time.process_time()
        ksp.setUp()
        c1 = time.process_time()
        mat.setValue(0, 0, mat.getValue(0, 0))  # new values, same pattern: numeric only
        mat.assemble()
        ksp.setOperators(mat)
        ksp.setUp()
        c2 = time.process_time()
        numeric.append(c2 - c1)
        analysis.append(max(0.0, (c1 - c0) - (c2 - c1)))
        x, b = mat.createVecs()
        b.set(1.0)
        c3 = time.process_time()
        for _ in range(5):
            ksp.solve(b, x)
        solve.append((time.process_time() - c3) / 5)
        info = {
            "ordering_used": factor.getMumpsInfog(7),
            "factor_entries": factor.getMumpsInfog(29),
            "flops": factor.getMumpsRinfog(3),
            "memory_MB": factor.getMumpsInfog(22),
        }
        for obj in (x, b, ksp):
            obj.destroy()
    return {
        "analysis_s": min(analysis),
        "numeric_s": min(numeric),
        "solve_s": min(solve),
        **info,
    }


def _membrane_matrix(problem: BucklingProblem) -> PETSc.Mat:
    """The prestress solve's membrane stiffness (its edge conditions or pins)."""
    spec = problem.spec
    V = problem.prestress.displacement.function_space
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    a = ufl.inner(membrane_force(u, spec.material, spec.plate.thickness), ufl.sym(ufl.grad(v)))
    # The pins do not change the pattern: the unconstrained matrix plus a small shift
    # stands for it (positive definite like the constrained one).
    K = dolfinx.fem.petsc.assemble_matrix(dolfinx.fem.form(a * ufl.dx))
    K.assemble()
    K.shift(1e-8 * K.norm(PETSc.NormType.INFINITY))
    K.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    return K


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plates", default="paper,thin")
    parser.add_argument("--meshes", help="nx x ny meshes, e.g. 160x80,320x160")
    parser.add_argument("--dofs", default="10000,40000,150000", help="target DOF counts")
    parser.add_argument("--orderings", default=",".join(ORDERINGS))
    parser.add_argument("--kinds", default=",".join(KINDS))
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", help="append one JSON line per row to this file")
    args, _ = parser.parse_known_args()
    comm = MPI.COMM_WORLD
    if comm.rank == 0:
        print_header(
            f"MPI ranks: {comm.size}; MUMPS orderings (ICNTL(7)), min of {args.repeat}",
            (
                "plate", "mesh", "dofs", "kind", "ordering", "analysis (s)", "numeric (s)",
                "solve (ms)", "free_s", "factor entries", "flops", "memory (MB)",
            ),
        )  # fmt: skip
    for plate in args.plates.split(","):
        aspect, make = ASPECT[plate], PLATES[plate]
        if args.meshes:
            meshes = [tuple(int(v) for v in m.split("x")) for m in args.meshes.split(",")]
        else:
            meshes = [_mesh_for(aspect, int(d)) for d in args.dofs.split(",")]
        for nx, ny in meshes:
            with BucklingProblem(make(nx, ny), comm) as problem:
                with BucklingProblem(make(max(2, nx // 4), max(2, ny // 4)), comm) as coarse:
                    estimate = coarse.solve_free().load
                A, B = problem.model.A, problem.model.B
                matrices: dict[str, tuple[PETSc.Mat, str]] = {}
                kinds = args.kinds.split(",")
                if "pencil_ldl" in kinds:
                    K = A.duplicate(copy=True)
                    K.axpy(-1.01 * estimate, B, structure=PETSc.Mat.Structure.SUBSET)
                    K.setOption(PETSc.Mat.Option.SPD, False)
                    K.setOption(PETSc.Mat.Option.SYMMETRIC, True)
                    matrices["pencil_ldl"] = (K, "cholesky")
                if "stiffness_lu" in kinds:
                    matrices["stiffness_lu"] = (A, "lu")
                if {"prestress_lu", "prestress_cholesky"} & set(kinds):
                    membrane = _membrane_matrix(problem)
                    for kind, pc_type in (
                        ("prestress_lu", "lu"),
                        ("prestress_cholesky", "cholesky"),
                    ):
                        if kind in kinds:
                            matrices[kind] = (membrane, pc_type)
                for kind, (mat, pc_type) in matrices.items():
                    for name in args.orderings.split(","):
                        row = {
                            "plate": plate,
                            "mesh": f"{nx}x{ny}",
                            "dofs": mat.getSize()[0],
                            "kind": kind,
                            "ordering": name,
                            "ranks": comm.size,
                            "repeat": args.repeat,
                            **_time_factor(mat, pc_type, ORDERINGS[name], args.repeat),
                        }
                        row["free_s"] = row["analysis_s"] + row["numeric_s"] + 10 * row["solve_s"]
                        if comm.rank == 0:
                            print(
                                "| {plate} | {mesh} | {dofs} | {kind} | {ordering} "
                                "| {analysis_s:.3f} | {numeric_s:.3f} | {solve_ms:.1f} "
                                "| {free_s:.3f} | {factor_entries} | {flops:.3g} "
                                "| {memory_MB} |".format(**row, solve_ms=1e3 * row["solve_s"]),
                                flush=True,
                            )
                            append_rows(args.json, [row])
                for mat in {id(m): m for m, _ in matrices.values() if m is not A}.values():
                    mat.destroy()


if __name__ == "__main__":
    main()
