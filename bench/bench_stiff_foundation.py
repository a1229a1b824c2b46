"""lambda(K) of a tensionless foundation against the rigid obstacle (stiff foundations).

Prints one row per (plate, K): the load, its gap to the rigid obstacle's load on the same
mesh, the spring-set status, the certificate, the eigen solves and seconds. K =
k_f b^4/(pi^4 D), D = E t^3/12, b the smaller side (the problem file's check).

    OMP_NUM_THREADS=1 python bench/bench_stiff_foundation.py [plate ...] [--K 1e2,1e4]
"""

from __future__ import annotations

import argparse
import json
import math
import time

from mpi4py import MPI

from msgspec import structs

import unibuckle_fenicsx.spec.problem as spec_problem
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.spec import Material, ObstacleSpec
from unibuckle_fenicsx.spec.cases import paper_case, plate_case

STEEL = Material(E=2.1e11, nu=0.3)


def plates():
    """Name -> (spec with a rigid obstacle, b, D)."""
    d_paper = 1.0e9 * 0.006**3 / 12
    out = {}
    for case in ("c1", "c2"):
        out[f"paper-{case}-40x20"] = (paper_case(case, 40, 20), 0.1, d_paper)
    out["paper-c1-80x40"] = (paper_case("c1", 80, 40), 0.1, d_paper)
    clamped = {"left": "clamped", "right": "clamped"}
    for ny in (8, 16):
        out[f"long3-clampedload-whole-{3 * ny}x{ny}"] = (
            plate_case("long", length=3.0, width=1.0, thickness=1e-3, supports=clamped,
                       nx=3 * ny, ny=ny, zone=ObstacleSpec("all")),
            1.0, 1.0e9 * 1e-9 / 12,
        )  # fmt: skip
    for ny in (8, 16):
        out[f"long3-SSSS-middle-{3 * ny}x{ny}"] = (
            plate_case("long", length=3.0, width=1.0, thickness=1e-3, nx=3 * ny, ny=ny,
                       zone=ObstacleSpec(((1.0, 2.0), (0.0, 1.0)))),
            1.0, 1.0e9 * 1e-9 / 12,
        )  # fmt: skip
    for ny in (8, 16):
        out[f"liner-4x2-{2 * ny}x{ny}"] = (
            plate_case("liner", length=4.0, width=2.0, thickness=1e-3, nx=2 * ny, ny=ny,
                       supports=clamped, zone=ObstacleSpec("all"), material=STEEL),
            2.0, 2.1e11 * 1e-9 / 12,
        )  # fmt: skip
    return out


def run(spec):
    t0 = time.perf_counter()
    with solve(spec, MPI.COMM_WORLD) as analysis:
        r = analysis.result
        cert = r.certificate
        return {
            "load": r.critical_load_Pa,
            "k": r.buckling_coefficient_k,
            "method": r.method,
            "kkt": bool(cert.kkt) if cert is not None else None,
            "status": None if cert is None else str(cert.status),
            "solves": r.eigensolves,
            "contact": r.contact_nodes,
            "seconds": time.perf_counter() - t0,
        }


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("plates", nargs="*")
    parser.add_argument("--K", default="1e2,1e3,1e4,1e5,1e6,1e7,1e8")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    spec_problem.MAX_FOUNDATION_K = math.inf  # measure past the input bound too
    table = plates()
    names = args.plates or list(table)
    Ks = [float(x) for x in args.K.split(",")]
    for name in names:
        spec, b, D = table[name]
        rigid = run(spec)
        print(json.dumps({"plate": name, "K": "rigid", **rigid}), flush=True)
        free = run(structs.replace(spec, obstacle=None))
        print(json.dumps({"plate": name, "K": 0, **free}), flush=True)
        for K in Ks:
            kf = K * math.pi**4 * D / b**4
            zone = structs.replace(spec.obstacle, foundation_stiffness=kf)
            try:
                row = run(structs.replace(spec, obstacle=zone))
            except Exception as exc:
                row = {"error": f"{type(exc).__name__}: {exc}"[:200]}
            gap = (rigid["load"] - row["load"]) / rigid["load"] if "load" in row else None
            line = {"plate": name, "K": K, "k_f": kf, "gap": gap, **row}
            print(json.dumps(line), flush=True)
            if args.out:
                with open(args.out, "a") as f:
                    f.write(json.dumps(line) + "\n")


if __name__ == "__main__":
    main()
