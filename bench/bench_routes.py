"""Benchmark: which route on which plate, the interior point against the active set across t/b.

``auto`` runs the interior-point route on plates thinner than ``THIN_PLATE`` (t/b < 0.02)
and the multilevel active set on thicker ones. This script solves the plates of
``bench_plates.py`` (0.3 x 0.1 m, the obstacle over the whole plate, face above) at
several thicknesses by both routes (``solver.method``) and prints, for each, the route
``auto`` would take, each route's in-process ratio ((unilateral + certificate time) / one
cold free solve, as in ``bench_plates.py``), its eigen solves and critical load, and the
relative difference of the two loads (active set minus interior point: negative when the
active set ended at a lower critical state). Both answers are certified KKT points; which
of them is the global minimum is not proven on these plates (several pencil eigenvalues
lie below the load).

Usage: python bench/bench_routes.py [--meshes 90x30] [--cases ssss,cs,sc,cccc,shear]
[--thicknesses 0.001,0.002,0.003,0.004,0.006] [--length 0.3] [--json FILE]
"""

from __future__ import annotations

import argparse

from mpi4py import MPI

from _results import append_rows, print_header
from bench_plates import CASES, LENGTH, WIDTH, _spec, _times

from unibuckle_fenicsx.algorithms.registry import choose_method
from unibuckle_fenicsx.analysis import solve

METHODS = ("interior-point", "active-set")


def _run(spec, comm) -> dict[str, object]:
    """One solve of ``spec``: ratio, eigen solves, load, route, KKT."""
    with solve(spec, comm) as analysis:
        r, cert = analysis.result, analysis.certificate
        assert cert is not None
        free_s, ratio, _ = _times(r.timings)
        return {
            "ratio": ratio,
            "free_solve_s": free_s,
            "eigensolves": r.eigensolves,
            "load_Pa": r.critical_load_Pa,
            "route": r.method,
            "kkt": cert.kkt,
            "i": r.constrained_nodes,
        }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default="90x30")
    parser.add_argument("--cases", default=",".join(CASES))
    parser.add_argument("--thicknesses", default="0.001,0.002,0.003,0.004,0.006")
    parser.add_argument("--length", type=float, default=LENGTH, help="plate length a (m)")
    parser.add_argument("--json", help="append one JSON line per row to this file")
    args, _ = parser.parse_known_args()
    comm = MPI.COMM_WORLD
    meshes = [tuple(int(v) for v in m.split("x")) for m in args.meshes.split(",")]
    thicknesses = [float(v) for v in args.thicknesses.split(",")]
    cases = args.cases.split(",")
    unknown = set(cases) - set(CASES)
    if unknown:
        parser.error(f"--cases: unknown {sorted(unknown)}; known: {list(CASES)}")
    # The JIT of the forms and MUMPS's first use, outside every timing below.
    _run(_spec(cases[0], *meshes[0], length=args.length).with_solver(method=METHODS[0]), comm)
    if comm.rank == 0:
        print_header(
            f"MPI ranks: {comm.size}; plate {args.length} x {WIDTH} m, zone all, face above",
            (
                "case", "mesh", "t (mm)", "t/b", "auto", "interior point: ratio",
                "eigen solves", "lambda_c (Pa)", "active set: ratio", "eigen solves",
                "lambda_c (Pa)", "(active set - interior point) / interior point",
            ),
        )  # fmt: skip
    for nx, ny in meshes:
        for name in cases:
            for thickness in thicknesses:
                spec = _spec(name, nx, ny, thickness=thickness, length=args.length)
                runs = {m: _run(spec.with_solver(method=m), comm) for m in METHODS}
                ip, act = runs["interior-point"], runs["active-set"]
                auto, _ = choose_method(spec, int(ip["i"]), float(ip["free_solve_s"]))
                row = {
                    "case": name,
                    "edges": CASES[name][2],
                    "mesh": f"{nx}x{ny}",
                    "length_m": args.length,
                    "thickness_m": thickness,
                    "t_over_b": thickness / min(args.length, WIDTH),
                    "auto": auto,
                    **{f"ip_{k}": v for k, v in ip.items() if k != "i"},
                    **{f"as_{k}": v for k, v in act.items() if k != "i"},
                    "load_difference": (act["load_Pa"] - ip["load_Pa"]) / ip["load_Pa"],
                }
                if comm.rank == 0:
                    print(
                        "| {case} | {mesh} | {t:g} | {t_over_b:.3g} | {auto} | **{ip_ratio:.1f}** "
                        "| {ip_eigensolves} | {ip_load_Pa:.6f} | **{as_ratio:.1f}** "
                        "| {as_eigensolves} | {as_load_Pa:.6f} | {load_difference:.1e} |".format(
                            t=thickness * 1e3, **row
                        ),
                        flush=True,
                    )
                    append_rows(args.json, [row])


if __name__ == "__main__":
    main()
