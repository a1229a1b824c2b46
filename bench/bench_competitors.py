"""Benchmark: what the split bracket lacks on a thin plate: competitors or precision.

On the thin plates of ``bench_plates.py`` (0.3 x 0.1 m, t = 1e-4 m, the obstacle over the
whole plate) the split route (:mod:`unibuckle_fenicsx.certificate.copositivity_split`)
brackets some answers to 1e-3 and stops at smaller distances. Two explanations are
measured on one plate and mesh (default: loaded edges clamped, 90x30):

- *competitors*: the columns miss critical states of the plate. The interior point's
  answer is bounded with the other KKT points its own solve met (as the certificate
  does), then with every distinct KKT point of the interior point's and the active
  set's solves (every start's arrangement), and the lowest of them with the others;
- *precision*: the error bound of the Gram matrix G eats the margins. For each column
  basis the route built, the share of the bound's terms (the residual's rounding, the
  second-order term, the dot products), and the bound with the residuals computed in
  twice the working precision (Dot2, ``SplitOptions.accurate``) on the same columns.

Each bound is run with the default's budgets and no cost limit, with ``--bracket``'s
budgets with double-precision residuals (``--bracket`` before Dot2) and with
``--bracket``'s as they are (Dot2). The table gives the bound, its gap, each distance
(verified or why not, with the columns r, the pieces examined and proven), the
right-hand sides and the route's time over the cold free solve (indicative on a shared
machine; the counts are exact). The time of a run includes its diagnostic passes.

Usage: python bench/bench_competitors.py [--case cs] [--mesh 90x30] [--json FILE]
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from typing import Any

from mpi4py import MPI

import numpy as np
from _results import append_rows, print_header
from bench_plates import CASES, _spec

from unibuckle_fenicsx.algorithms.active_set import solve_active_set
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.certificate import copositivity_split as split
from unibuckle_fenicsx.certificate.accurate import AccurateResidual, gamma
from unibuckle_fenicsx.certificate.shifted import ShiftedMatrix

BUDGETS = {
    "default": split.SplitOptions(max_cost=None),
    "bracket, double": dataclasses.replace(split.SplitOptions.thorough(), accurate=False),
    "bracket, Dot2": split.SplitOptions.thorough(),
}


class _Recorder:
    """Keeps the column bases the route builds (for the rounding diagnostic)."""

    def __init__(self) -> None:
        self.bases: list[Any] = []
        self._init = split.Basis.__init__

    def __enter__(self) -> _Recorder:
        recorder, init = self, self._init

        def record(basis: Any, *args: Any, **kw: Any) -> None:
            init(basis, *args, **kw)
            recorder.bases.append(basis)

        split.Basis.__init__ = record  # type: ignore[method-assign]
        return self

    def __exit__(self, *exc: object) -> None:
        split.Basis.__init__ = self._init  # type: ignore[method-assign]


def _shares(problem: Any, basis: Any) -> dict[str, float]:
    """Median shares of G's error bound, and the median bound over |G| (double, Dot2)."""
    q = basis.q
    U, X, rho, err = (basis._store[name][:, :q] for name in ("U", "X", "rho", "err"))
    residual = np.abs(X).T @ err
    norms = [np.sqrt((V * V).sum(axis=0)) for V in (U, X, rho)]
    nre = np.sqrt(((np.abs(rho) + err) ** 2).sum(axis=0))
    dots = gamma(basis.n + 2) * (np.outer(norms[0], norms[1]) + np.outer(norms[1], norms[2]))
    second = np.outer(basis.dnorm, nre)
    absG = np.maximum(np.abs(basis.G), np.finfo(float).tiny)
    out = {
        "bound_over_G": float(np.median(basis.E / absG)),
        "residual_share": float(np.median(residual / basis.E)),
        "second_share": float(np.median(second / basis.E)),
        "dots_share": float(np.median(dots / basis.E)),
    }
    if basis._residual is None:  # the same columns' residuals in twice the precision
        accurate = AccurateResidual(basis.matrix.K)
        A = problem.model.A
        ws, xs = [A.createVecRight() for _ in range(q)], [A.createVecRight() for _ in range(q)]
        try:
            for j in range(q):
                ws[j].array[:], xs[j].array[:] = U[:, j], X[:, j]
            _, err2 = accurate(ws, xs)
        finally:
            accurate.destroy()
            for v in (*ws, *xs):
                v.destroy()
        tighter = basis.E - residual + np.abs(X).T @ err2
        out["bound_over_G_dot2"] = float(np.median(tighter / absG))
    return out


def _bound(problem: Any, cand: Any, others: list[Any], opts: Any) -> dict[str, Any]:
    """One split bound: its record's counts and the rounding shares of its bases."""
    matrix = ShiftedMatrix(problem.model.A, problem.model.B)
    try:
        with _Recorder() as recorder:
            t0 = time.perf_counter()
            outcome = split.split_certificate(problem, matrix, cand, others, opts)
            seconds = time.perf_counter() - t0
            shares = [_shares(problem, b) for b in recorder.bases if b.q]
    finally:
        matrix.destroy()
    record = outcome.record()
    return {
        "value": record.value,
        "gap": None if record.value is None else 1.0 - record.value / cand.load,
        "refuting": None if outcome.refuting is None else outcome.refuting.load,
        "rhs": record.solves,
        "seconds": seconds,
        "attempts": [
            dict(
                delta=a.delta,
                proven=a.proven,
                why=a.why.split(":")[0],
                r=a.r,
                examined=a.examined,
                pieces=a.pieces,
            )
            for a in record.attempts
        ],
        "shares": shares,
    }


def _distances(attempts: list[dict[str, Any]]) -> str:
    """Each distance: verified or why not, with (columns / pieces examined / proven)."""
    return "; ".join(
        f"{a['delta']:g} {'ok' if a['proven'] else a['why']} "
        f"({a['r']}/{a['examined']}/{a['pieces']})"
        for a in attempts
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", default="cs", choices=sorted(CASES))
    parser.add_argument("--mesh", default="90x30")
    parser.add_argument("--json", help="append one JSON line per row to this file")
    args, _ = parser.parse_known_args()
    nx, ny = (int(v) for v in args.mesh.split("x"))
    spec = _spec(args.case, nx, ny)
    comm = MPI.COMM_SELF
    rows = []
    with solve(spec.with_solver(method="interior-point", certify=False), comm) as analysis:
        problem, sol = analysis.problem, analysis.solution
        assert sol is not None
        free_s = problem.timings["free_solve_s"]
        active = solve_active_set(problem, bound_budget=0)
        pool: dict[Any, Any] = {}
        for c in (sol.candidate, *sol.kkt_points, active.candidate, *active.kkt_points):
            if c.kkt and c.feasible:
                pool.setdefault(c.key(), c)
        lowest = min(pool.values(), key=lambda c: c.load)
        loads = ", ".join(f"{c.load:.6f}" for c in sorted(pool.values(), key=lambda c: c.load))
        print(f"{args.case} {args.mesh}: interior point {sol.load:.6f} Pa, active set "
              f"{active.load:.6f} Pa; distinct KKT points met: {loads}")  # fmt: skip
        runs = (
            ("interior point's, its own", sol.candidate, list(sol.kkt_points)),
            ("interior point's, all", sol.candidate,
             [c for k, c in pool.items() if k != sol.candidate.key()]),
            ("lowest, all", lowest, [c for k, c in pool.items() if k != lowest.key()]),
        )  # fmt: skip
        print_header(
            "",
            ["point, other KKT points", "budgets", "load (Pa)", "lower bound (Pa)", "gap",
             "distances (r/examined/proven)", "rhs", "route / free", "bound/|G|",
             "residual share", "bound/|G| with Dot2"],
        )  # fmt: skip
        for label, cand, others in runs:
            for budgets, opts in BUDGETS.items():
                out = _bound(problem, cand, others, opts)
                shares = out["shares"]
                row = {"case": args.case, "mesh": args.mesh, "point": label,
                       "others": len(others), "budgets": budgets, "load_Pa": cand.load,
                       "free_solve_s": free_s, **out}  # fmt: skip
                rows.append(row)
                first = shares[0] if shares else {}
                nan = float("nan")
                print(
                    f"| {label} ({len(others)}) | {budgets} | {cand.load:.6f} | "
                    f"{'-' if out['value'] is None else format(out['value'], '.6f')} | "
                    f"{'-' if out['gap'] is None else format(out['gap'], '.0e')} | "
                    f"{_distances(out['attempts'])} | {out['rhs']} | "
                    f"{out['seconds'] / free_s:.1f} | {first.get('bound_over_G', nan):.1e} | "
                    f"{first.get('residual_share', nan):.3f} | "
                    f"{first.get('bound_over_G_dot2', nan):.1e} |",
                    flush=True,
                )
    append_rows(args.json, rows)


if __name__ == "__main__":
    main()
