"""Benchmark: the free solve's coarse estimate and first shift on random plates.

The free solve shifts to 1 % above the lowest load of the plate on a mesh four times
coarser (at most a third of the way to its second load) and proves the pair the smallest
by the inertia of that one factorisation when exactly one eigenvalue lies below the
shift and the pair found does too; otherwise it factorises again (a check just below
the pair, or lower shifts). This script draws seeded random plates (aspect 0.5 to 5,
t/b 1e-4 to 0.1, each edge simply supported (S), clamped (C) or soft (s), compression, shear or
both, and plates with one edge clamped in plane, in tension somewhere: the swapped
pencil) on meshes of ``--cells`` cells across and reports per plate:

- ``coarse_error``: the coarse mesh's lowest load over the fine one's, less 1;
- ``gap``: the fine second load over the first, less 1;
- ``first_below``: eigenvalues below the first shift (1: proven by one factorisation);
- ``factorisations``: numeric factorisations the proof took (-1: none proved it, the
  solve at target 0 answered);
- ``agrees``: the load equals the one of the solve at target 0 checked by its inertia
  (the previous method) within 1e-9 relative (thin plates: within the load's
  resolution).

Usage: python bench/bench_free_estimates.py [--count 40] [--cells 24] [--seed N] [--json FILE]
"""

from __future__ import annotations

import argparse
import math

from mpi4py import MPI

import numpy as np
from _results import append_rows, print_header
from msgspec.structs import replace

import unibuckle_fenicsx.model.problem as problem_module
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.model.problem import BucklingProblem
from unibuckle_fenicsx.spec import PlateSpec
from unibuckle_fenicsx.spec.cases import LOADS, plate_case

SUPPORTS = ("simply_supported", "clamped", "simply_supported_soft")
SHORT = {"simply_supported": "S", "clamped": "C", "simply_supported_soft": "s"}


def _plates(count: int, cells: int, seed: int):
    """``count`` seeded random plates: (spec, description)."""
    rng = np.random.default_rng(seed)
    for k in range(count):
        aspect = float(np.exp(rng.uniform(np.log(0.5), np.log(5.0))))
        width = 0.1
        thickness = width * float(10 ** rng.uniform(-4.0, -1.0))
        supports = {e: str(rng.choice(SUPPORTS)) for e in ("left", "right", "bottom", "top")}
        load = str(rng.choice(list(LOADS)))
        ny = cells if aspect >= 1 else max(4, round(cells * aspect))
        nx = max(4, round(cells * aspect)) if aspect >= 1 else cells
        size = {"length": aspect * width, "width": width, "thickness": thickness}
        spec = plate_case(f"plate{k}", **size, supports=supports, load=load, nx=nx, ny=ny)
        tension = rng.random() < 0.2
        if tension:  # the left edge held in plane, the right one compressed
            change = {
                "left": {"inplane": "clamped", "normal_stress": 0.0, "shear_stress": 0.0},
                "right": {"normal_stress": -1.0},
            }
            edges = tuple(replace(e, **change.get(e.name, {})) for e in spec.plate.edges)
            spec = replace(spec, plate=PlateSpec(spec.plate.corners, thickness, edges))
        what = (
            f"a/b {aspect:.2f}, t/b {thickness / min(width, aspect * width):.1e}, "
            f"{'/'.join(SHORT[s] for s in supports.values())}, {load}"
            + (", left clamped in plane" if tension else "")
        )
        yield spec, what, tension


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=40)
    parser.add_argument("--cells", type=int, default=24, help="cells across the shorter side")
    parser.add_argument("--seed", type=int, default=20261201)
    parser.add_argument("--json", help="append one JSON line per row to this file")
    args, _ = parser.parse_known_args()
    comm = MPI.COMM_WORLD
    problem_module.FREE_ESTIMATE_DOFS = 0  # every plate gets its estimate
    if comm.rank == 0:
        print_header(
            f"MPI ranks: {comm.size}; {args.count} random plates, {args.cells} cells across",
            (
                "plate", "mesh", "dofs", "indefinite B", "coarse error", "gap", "first below",
                "factorisations", "agrees", "load (Pa)",
            ),
        )  # fmt: skip
    for spec, what, _ in _plates(args.count, args.cells, args.seed):
        try:
            problem = BucklingProblem(spec, comm)
        except InputError as err:  # no buckling load on this mesh
            if comm.rank == 0:
                print(f"| {what} | refused: {err} |")
            continue
        with problem:
            estimate = problem._free_estimate()
            pair, proof = problem.eigensolver.smallest(estimate=estimate)
            reference = problem.eigensolver.solve()  # target 0, as before
            below = problem.eigensolver.count_below(reference.value * (1 - 1e-7))
            resolution = 1e-9
            if math.isfinite(reference.value):
                u = problem.new_mode()
                problem.eigensolver.solve(out=u.x.petsc_vec)
                resolution = max(1e-9, problem.load_resolution(u.x.petsc_vec, reference.value))
            first = (
                problem.eigensolver.count_below(proof.shifts[0]) if proof else None
            )  # recount: the proof record keeps the last shift's count
            row = {
                "plate": what,
                "seed": args.seed,
                "cells": args.cells,
                "mesh": f"{spec.mesh.nx}x{spec.mesh.ny}",
                "dofs": int(problem.model.A.getSize()[0]),
                "indefinite": problem.prestress.indefinite,
                "coarse_error": (estimate[0] / pair.value - 1.0) if estimate else None,
                "gap": (estimate[1] / estimate[0] - 1.0) if len(estimate) > 1 else None,
                "first_below": first,
                "factorisations": len(proof.shifts) if proof else -1,
                "agrees": below == 0 and abs(pair.value / reference.value - 1.0) <= resolution,
                "load_Pa": pair.value,
            }
        if comm.rank == 0:
            print(
                "| {plate} | {mesh} | {dofs} | {indefinite} | {ce} | {g} | {first_below} "
                "| {factorisations} | {agrees} | {load_Pa:.8g} |".format(
                    **row,
                    ce="-" if row["coarse_error"] is None else f"{row['coarse_error']:.2e}",
                    g="-" if row["gap"] is None else f"{row['gap']:.3f}",
                ),
                flush=True,
            )
            append_rows(args.json, [row])


if __name__ == "__main__":
    main()
