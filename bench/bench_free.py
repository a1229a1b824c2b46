"""Benchmark: the package's free solve against plain SLEPc solves of the same pencil.

Every run starts with the free plate's smallest eigenpair of (A, B) and its proof (the
inertia of a shifted factorisation), so this is the floor under every other timing. For
each plate, in one process and on the package's own A and B:

- ``package_s``: :meth:`~unibuckle_fenicsx.model.problem.Problem.solve_free`
  and :meth:`~unibuckle_fenicsx.model.problem.Problem.verify_free` (the coarse
  estimate, the shifted factorisation(s), Krylov-Schur and, where needed, the check),
  with ``estimate_s`` the coarse estimate's share, its numeric factorisations
  (``factorisations``, -1: solved at target 0 and checked) and the linear solves of
  its eigen solve (``solves``, the estimate's not counted);
- ``plain_s``: plain SLEPc, no proof: Krylov-Schur at target 0 with 8 vectors, a
  MUMPS Cholesky of A ordered by AMF (ICNTL(7) = 2);
- ``plain_proof_s``: plain SLEPc with the proof: a coarse-mesh estimate (the plate at a
  quarter of the cells per side, its lowest eigenvalue), then one MUMPS LDLᵀ of
  A − σ₀B at σ₀ 3 % below it, whose inertia shows no eigenvalue below σ₀, and
  Krylov-Schur at target σ₀ with 8 vectors (AMD ordering);
- ``floor_ratio`` = package_s / plain_proof_s; the loads' relative differences to the
  package's.

Times are the minimum over ``--repeat`` runs (each a new problem; the three in turn).
With ``--cli`` it also times whole processes, ``unibuckle solve --config FILE`` of the
free plate (``cli_s``, ``total_s`` as the CLI reports it); ``--baseline PYTHON`` times the
same command of another installation in turn with it (``baseline_cli_s``,
``baseline_total_s``: e.g. the package before a change, side by side).

Usage: python bench/bench_free.py [--plates paper,thin] [--meshes paper=320x160,thin=360x120]
[--repeat 3] [--cli] [--baseline PYTHON] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mpi4py import MPI
from petsc4py import PETSc
from slepc4py import SLEPc

from _results import append_rows, print_header
from bench_plates import _spec

from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.spec import problem_to_dict
from unibuckle_fenicsx.spec.cases import paper_case

#: The plates of the floor: the paper's, and the thin plate 0.3 x 0.1 x 1e-4 m (SSSS,
#: bench_plates.py's) without its obstacle.
PLATES = {
    "paper": lambda nx, ny: paper_case("free", nx, ny),
    "thin": lambda nx, ny: _spec("ssss", nx, ny).without_obstacles(),
}
MESHES = {"paper": (320, 160), "thin": (360, 120)}
TOL = 1e-10


def _solves() -> int:
    """Linear solves so far (PETSc's log of KSPSolve)."""
    return int(PETSc.Log.Event("KSPSolve").getPerfInfo()["count"])


def _package(spec, comm) -> dict[str, float | int | str]:
    """The package's free solve and its proof, timed, on a new problem."""
    with build_problem(spec, comm) as problem:
        estimate: dict[str, float] = {"s": 0.0, "solves": 0}
        coarse = problem._free_estimate

        def timed() -> tuple[float, ...]:
            s0, t0 = _solves(), time.perf_counter()
            out = coarse()
            estimate["s"], estimate["solves"] = time.perf_counter() - t0, _solves() - s0
            return out

        problem._free_estimate = timed  # type: ignore[method-assign]
        comm.Barrier()
        s0 = _solves()
        t0 = time.perf_counter()
        free = problem.solve_free()
        problem.verify_free()
        t1 = time.perf_counter()
        proof = problem.free_proof
        return {
            "package_s": t1 - t0,
            "estimate_s": estimate["s"],
            "package_load": free.load,
            "factorisations": len(proof.shifts) if proof else -1,
            "proof": f"{proof.below} below {proof.shift:.6g}" if proof else "target 0 + check",
            "solves": _solves() - s0 - int(estimate["solves"]),
            "dofs": int(problem.model.A.getSize()[0]),
        }


def _plain(A, B, target: float, ordering: int, inertia: bool) -> tuple[float, int]:
    """Krylov-Schur (8 vectors) at ``target`` with a MUMPS factorisation: load, count below."""
    eps = SLEPc.EPS().create(A.comm)
    eps.setOptionsPrefix("bench_plain_")
    eps.setOperators(A, B)
    eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
    eps.setDimensions(1, 8)
    eps.setTolerances(TOL)
    eps.setTarget(target)
    eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_REAL)
    st = eps.getST()
    st.setType(SLEPc.ST.Type.SINVERT)
    ksp = st.getKSP()
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("cholesky")
    pc.setFactorSolverType("mumps")
    below = -1
    try:
        if inertia:
            st.setMatMode(SLEPc.ST.MatMode.COPY)
            eps.setUp()
            factor = pc.getFactorMatrix()
            below = int(factor.getInertia()[0])
        eps.solve()
        return float(eps.getEigenvalue(0).real), below
    finally:
        eps.destroy()


def _plain_runs(spec, comm, coarse_spec) -> dict[str, float | int]:
    """The two plain SLEPc configurations on a new problem's pencil, timed."""
    opts = PETSc.Options("bench_plain_")
    with build_problem(spec, comm) as problem:
        A, B = problem.model.A, problem.model.B
        opts["st_mat_mumps_icntl_7"] = 2
        t0 = time.perf_counter()
        plain, _ = _plain(A, B, 0.0, 2, False)
        t1 = time.perf_counter()
        with build_problem(coarse_spec, comm) as coarse:
            estimate, _ = _plain(coarse.model.A, coarse.model.B, 0.0, 2, False)
        t2 = time.perf_counter()
        opts["st_mat_mumps_icntl_7"] = 0
        for key in (13, 24):
            opts[f"st_mat_mumps_icntl_{key}"] = 1
        K = A.duplicate(copy=True)  # no SPD flag: MUMPS's symmetric indefinite LDL^T
        K.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        t3 = time.perf_counter()
        proof, below = _plain(K, B, 0.97 * estimate, 0, True)
        t4 = time.perf_counter()
        K.destroy()
        for key in (7, 13, 24):
            del opts[f"st_mat_mumps_icntl_{key}"]
        return {
            "plain_s": t1 - t0,
            "plain_load": plain,
            "plain_proof_s": (t2 - t1) + (t4 - t3),
            "plain_proof_estimate_s": t2 - t1,
            "plain_proof_below": below,
            "plain_proof_load": proof,
        }


def _cli(python: str, spec) -> tuple[float, float]:
    """Wall time of ``python -m unibuckle_fenicsx.cli solve`` on ``spec``; its total_s."""
    with tempfile.TemporaryDirectory() as tmp:
        path, out = Path(tmp) / "plate.json", Path(tmp) / "out.json"
        path.write_text(json.dumps({"input": problem_to_dict(spec)}))
        cmd = [python, "-m", "unibuckle_fenicsx.cli", "solve", "--config", str(path)]
        env = {**os.environ, "OMP_NUM_THREADS": "1"}
        t0 = time.perf_counter()
        # cwd: python -m puts it first on sys.path, so the checkout's package would shadow
        # the installation of ``python`` (the baseline would time this package).
        subprocess.run(
            [*cmd, "--json", str(out)], check=True, capture_output=True, env=env, cwd=tmp
        )
        wall = time.perf_counter() - t0
        return wall, float(json.loads(out.read_text())["timings"]["total_s"])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plates", default="paper,thin")
    parser.add_argument("--meshes", default="", help="per plate, e.g. paper=160x80,thin=180x60")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--cli", action="store_true", help="also time whole CLI processes")
    parser.add_argument("--baseline", help="python of another installation, timed in turn")
    parser.add_argument("--json", help="append one JSON line per row to this file")
    args, _ = parser.parse_known_args()
    if args.repeat < 1:
        parser.error(f"--repeat must be at least 1, got {args.repeat}")
    comm = MPI.COMM_WORLD
    PETSc.Log.begin()
    meshes = dict(MESHES)
    for item in filter(None, args.meshes.split(",")):
        plate, mesh = item.split("=")
        meshes[plate] = tuple(int(v) for v in mesh.split("x"))
    if comm.rank == 0:
        print_header(
            f"MPI ranks: {comm.size}; min of {args.repeat}; times in s",
            (
                "plate", "mesh", "dofs", "package", "estimate", "factorisations", "solves",
                "proof", "plain", "plain + proof", "floor ratio", "CLI", "total_s",
                "baseline CLI", "baseline total_s", "load (Pa)", "plain load",
                "plain + proof load",
            ),
        )  # fmt: skip
    # The JIT of the forms and MUMPS's first use, outside every timing below.
    _package(PLATES["paper"](8, 4), comm)
    for plate in args.plates.split(","):
        nx, ny = meshes[plate]
        spec = PLATES[plate](nx, ny)
        coarse_spec = PLATES[plate](nx // 4, ny // 4)
        package, plain, cli, baseline = [], [], [], []
        for _ in range(args.repeat):
            package.append(_package(spec, comm))
            plain.append(_plain_runs(spec, comm, coarse_spec))
            if args.cli and comm.size == 1:
                cli.append(_cli(sys.executable, spec))
                if args.baseline:
                    baseline.append(_cli(args.baseline, spec))
        best = min(package, key=lambda r: r["package_s"])
        row: dict[str, object] = {
            "plate": plate,
            "mesh": f"{nx}x{ny}",
            "repeat": args.repeat,
            **best,
            "plain_s": min(r["plain_s"] for r in plain),
            "plain_proof_s": min(r["plain_proof_s"] for r in plain),
            "plain_proof_estimate_s": min(r["plain_proof_estimate_s"] for r in plain),
            "plain_load": plain[0]["plain_load"],
            "plain_proof_load": plain[0]["plain_proof_load"],
            "plain_proof_below": plain[0]["plain_proof_below"],
            "package_runs_s": [r["package_s"] for r in package],
        }
        row["floor_ratio"] = float(row["package_s"]) / float(row["plain_proof_s"])
        row["plain_rdiff"] = row["plain_load"] / best["package_load"] - 1.0
        row["plain_proof_rdiff"] = row["plain_proof_load"] / best["package_load"] - 1.0
        row["cli_s"] = min((c[0] for c in cli), default=None)
        row["total_s"] = min((c[1] for c in cli), default=None)
        row["baseline_cli_s"] = min((c[0] for c in baseline), default=None)
        row["baseline_total_s"] = min((c[1] for c in baseline), default=None)
        row["cli_runs_s"] = [c[0] for c in cli]
        row["baseline_cli_runs_s"] = [c[0] for c in baseline]
        if comm.rank == 0:
            timed = ("cli_s", "total_s", "baseline_cli_s", "baseline_total_s")
            cell = {k: "-" if row[k] is None else f"{row[k]:.2f}" for k in timed}
            print(
                f"| {plate} | {nx}x{ny} | {row['dofs']} | {row['package_s']:.2f} "
                f"| {row['estimate_s']:.2f} | {row['factorisations']} | {row['solves']} "
                f"| {row['proof']} | {row['plain_s']:.2f} | {row['plain_proof_s']:.2f} "
                f"| **{row['floor_ratio']:.2f}** | {cell['cli_s']} | {cell['total_s']} "
                f"| {cell['baseline_cli_s']} | {cell['baseline_total_s']} "
                f"| {row['package_load']:.10g} | {row['plain_rdiff']:.1e} "
                f"| {row['plain_proof_rdiff']:.1e} |",
                flush=True,
            )
            append_rows(args.json, [row])


if __name__ == "__main__":
    main()
