"""Soundness of a bracket route against the exhaustive minimum (shared by its tests).

The route is run on the KKT points of a small problem (the active set's answer, every
other KKT point it met) and on the exhaustive minimiser claimed at raised loads (a wrong
claim that no sound route may verify); every verified lower bound must lie below the
exhaustive minimum (:func:`support.exhaustive.exhaustive_minimum`), every refuting mode be
admissible with a load between the minimum and the claimed load.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any

from mpi4py import MPI

import numpy as np

from support.exhaustive import RTOL, exhaustive_minimum
from unibuckle_fenicsx.algorithms.active_set import solve_active_set
from unibuckle_fenicsx.certificate.shifted import ShiftedMatrix
from unibuckle_fenicsx.model.build import build_problem

#: route(problem, matrix, candidate, others) -> outcomes with ``value`` and ``refuting``.
Route = Callable[..., list[Any]]


def check_soundness(spec, i: int, route: Route, raised=(1e-4, 1e-3)) -> dict:
    """Run ``route`` where two or more pencil eigenvalues lie below; assert; a report."""
    report = {"m": 0, "verified": 0, "refuted": 0, "tried": 0, "wrong": 0}
    with build_problem(spec, MPI.COMM_SELF) as problem:
        best, minimisers, _ = exhaustive_minimum(problem)
        if not math.isfinite(best):
            return report
        sol = solve_active_set(problem, bound_budget=0)
        exact = problem.evaluate(np.asarray(minimisers[0], dtype=np.int64))
        points = [("returned", sol.candidate)]
        points += [(f"kkt{k}", c) for k, c in enumerate(sol.kkt_points) if c.kkt]
        points += [(f"claimed+{e:g}", replace(exact, load=exact.load * (1 + e))) for e in raised]
        matrix = ShiftedMatrix(problem.model.A, problem.model.B)
        try:
            for name, cand in points:
                neg, _, _ = matrix.factor(cand.load * (1 - 1e-3))
                if neg < 2:
                    continue
                report["m"] = max(report["m"], neg)
                report["tried"] += 1
                report["wrong"] += cand.load > best * (1 + 1e-6)
                others = [c for c in sol.kkt_points if c.key() != cand.key()]
                for out in route(problem, matrix, cand, others):
                    where = (spec.name, i, name, cand.load, best, out.attempts)
                    if out.value is not None:
                        report["verified"] += 1
                        assert out.value <= best * (1 + RTOL), where
                    if out.refuting is not None:
                        report["refuted"] += 1
                        assert best * (1 - RTOL) <= out.refuting.load < cand.load, where
                        assert out.refuting.values.max() <= problem.tau, where
        finally:
            matrix.destroy()
    return report
