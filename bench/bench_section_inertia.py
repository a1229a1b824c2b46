r"""Benchmark: how many eigenvalues of the pencil lie below the critical load, section and plate.

The interior point's Newton matrix :math:`K = A - \lambda B + E\,\Sigma\,E^T` must have
one negative eigenvalue on the central path (with the normalisation's border: the
inertia test of :mod:`~unibuckle_fenicsx.algorithms.interior_point.kernel`). Without the
obstacle, :math:`A - \lambda_c B` has as many negative eigenvalues as the free pencil has
eigenvalues below :math:`\lambda_c`; all but one of them the barrier's curvature
:math:`\Sigma` on the contact directions must lift. This script counts them: the free
load (one eigen solve), then the inertia of :math:`A - \lambda B` at the given load
(MUMPS :math:`LDL^T`, one factorisation), i.e. the number of pencil eigenvalues below it
(Sylvester's law of inertia).

Problems: ``box:SIZE@LOAD`` (the filled box of ``bench_sections.py`` on cells of SIZE m)
and ``CASE:NXxNY:T@LOAD`` (a plate of ``bench_plates.py``, e.g. ``sc:330x110:1e-3``), LOAD
in Pa: the critical load to count below (the page that uses the rows says where each
comes from).

Usage: python bench/bench_section_inertia.py --problems box:0.0105@146593361.83
[--json FILE]
"""

from __future__ import annotations

import argparse

from _results import append_rows, print_header
from bench_step_cost import _newton_matrix, _problem

from unibuckle_fenicsx.la.factor import SymmetricFactorization

COLUMNS = ("problem", "rows", "free_load_Pa", "load_Pa", "load/free", "below")


def count(name: str, load: float) -> dict[str, object]:
    """The row of ``name``: its free load and the pencil's eigenvalues below ``load``."""
    problem, owner = _problem(name)
    try:
        free = problem.solve_free().load
        K = _newton_matrix(problem.model.A, problem.model.B, load)
        ldl = SymmetricFactorization(K, "bench_inertia_")
        try:
            below = ldl.inertia()[0]
        finally:
            ldl.destroy()
            K.destroy()
        return {
            "problem": name,
            "rows": problem.model.A.getSize()[0],
            "free_load_Pa": free,
            "load_Pa": load,
            "load/free": load / free,
            "below": below,
        }
    finally:
        owner.destroy()


def main() -> None:
    """Parse the options, count, print the rows."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--problems", required=True, help="comma-separated NAME@LOAD (module docstring)"
    )
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    items = []
    for item in args.problems.split(","):
        name, sep, load = item.rpartition("@")
        if not sep or not name or not float(load) > 0.0:
            parser.error(f"--problems: {item!r} is not NAME@LOAD with LOAD > 0 (Pa)")
        items.append((name, float(load)))
    print_header("Pencil eigenvalues below the critical load (MUMPS inertia)", COLUMNS)
    rows = []
    for name, load in items:
        row = count(name, load)
        rows.append(row)
        cells = [f"{row[c]:.6g}" if isinstance(row[c], float) else str(row[c]) for c in COLUMNS]
        print("| " + " | ".join(cells) + " |", flush=True)
    append_rows(args.json, rows)


if __name__ == "__main__":
    main()
