"""Benchmark: the unilateral solve on plates other than the paper's, against one free solve.

Thin plates (t = 1e-4 m, 0.3 x 0.1 m, t/b = 1e-3) with the obstacle over the whole plate,
under every edge condition and under shear: the cases on which a contact set with several
lobes makes the active-set iteration hard. For each case and mesh, ``solve`` runs the
whole process (free solve, unilateral algorithm, certificate) and the table gives the
unilateral and certificate time over the free solve's, the eigen solves (all levels and
links), the route that gave the answer ("+ penalty continuation" when the multilevel active
set stalled and penalty continuation took over, "+ feasible descent" when that stalled
too), whether the result is a KKT point, what its certificate verified (proven, bracketed
with its gap, or KKT only; README, "Proving the global minimum"), with m (pencil
eigenvalues below the load), the low-rank route's columns r and pieces and the
certificate's time over the free solve's, and the buckling coefficient
k = lambda b^2 t / (pi^2 D).

Usage: python bench/bench_plates.py [--meshes 90x30,180x60] [--cases ssss,cs,sc,cccc,shear]
"""

from __future__ import annotations

import argparse
import time

from mpi4py import MPI

from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.cases import plate_case
from unibuckle_fenicsx.certify import Certificate
from unibuckle_fenicsx.config import ObstacleSpec

#: name -> (edge supports, load, description of the edges)
CASES = {
    "ssss": ("simply_supported", "uniaxial", "SSSS"),
    "cs": ({"left": "clamped", "right": "clamped"}, "uniaxial", "loaded edges clamped"),
    "sc": ({"bottom": "clamped", "top": "clamped"}, "uniaxial", "unloaded edges clamped"),
    "cccc": ("clamped", "uniaxial", "CCCC"),
    "shear": ("simply_supported", "shear", "SSSS"),
}
LENGTH, WIDTH, THICKNESS = 0.3, 0.1, 1e-4


def _verified(cert: Certificate) -> str:
    """Proven (route), bracketed (gap, route), refuted, or KKT only (why)."""
    if cert.global_optimum_proven:
        return f"proven ({cert.proven_by})"
    if cert.status == "bracketed":
        return f"bracketed {cert.relative_gap:.0e} ({cert.proven_by})"
    if cert.refuting_mode is not None:
        return f"refuted ({cert.refuting_mode.load:.6f})"
    lowrank = (cert.copositivity or {}).get("lowrank") or {}
    return f"KKT only: {lowrank.get('why', '; '.join(cert.notes))}"


def _lowrank(cert: Certificate) -> tuple[object, object]:
    """(r, pieces) of the low-rank route, or dashes."""
    lowrank = (cert.copositivity or {}).get("lowrank") or {}
    return lowrank.get("r", "-"), lowrank.get("pieces", "-")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default="90x30,180x60")
    parser.add_argument("--cases", default=",".join(CASES))
    args, _ = parser.parse_known_args()
    comm = MPI.COMM_WORLD
    meshes = [tuple(int(v) for v in m.split("x")) for m in args.meshes.split(",")]
    if comm.rank == 0:
        print(f"MPI ranks: {comm.size}; plate {LENGTH} x {WIDTH} m, t = {THICKNESS} m, zone all")
        print(
            "| case | edges | load | t/b | mesh | i | \\|Z\\| | eigen solves | route "
            "| free solve (s) | ratio | total (s) | KKT | certificate | m | r | pieces "
            "| certificate / free | k | lambda_c (Pa) |"
        )
        print("|" + "---|" * 20, flush=True)
    for nx, ny in meshes:
        for name in args.cases.split(","):
            supports, load, edges = CASES[name]
            spec = plate_case(
                name,
                length=LENGTH,
                width=WIDTH,
                thickness=THICKNESS,
                supports=supports,
                load=load,
                nx=nx,
                ny=ny,
                zone=ObstacleSpec(zone="all"),
            )
            t0 = time.perf_counter()
            with solve(spec, comm) as analysis:
                total = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
                r, sol, cert = analysis.result, analysis.solution, analysis.certificate
                assert sol is not None and cert is not None
                t = r.timings
                fallback = sol.details.get("fallback")
                route = r.method
                if fallback:
                    route += " + penalty continuation"
                    if "descent" in fallback:
                        route += " + feasible descent"
                row = (
                    name,
                    edges,
                    load,
                    THICKNESS / WIDTH,
                    f"{nx}x{ny}",
                    r.constrained_nodes,
                    r.contact_nodes,
                    r.eigensolves,
                    route,
                    t["free_solve_s"],
                    (t["unilateral_s"] + t["certify_s"]) / t["free_solve_s"],
                    total,
                    "yes" if cert.kkt else "no",
                    _verified(cert),
                    cert.negative_eigenvalues,
                    *_lowrank(cert),
                    t["certify_s"] / t["free_solve_s"],
                    analysis.problem.buckling_coefficient(r.critical_load_Pa),
                    r.critical_load_Pa,
                )
            if comm.rank == 0:  # one row at a time: a long run shows its progress
                print(
                    "| {} | {} | {} | {:.0e} | {} | {} | {} | {} | {} | {:.2f} | **{:.1f}** "
                    "| {:.1f} | {} | {} | {} | {} | {} | {:.1f} | {:.4f} | {:.6f} |".format(*row),
                    flush=True,
                )


if __name__ == "__main__":
    main()
