r"""A lower bound on the critical load by best-first search over the subset lattice.

Every contact set's load bounds the loads of its supersets from below (interlacing:
removing more DOFs never lowers the smallest eigenvalue). The search keeps a frontier of
sets whose subtrees :math:`\{Z \cup S : \min S > \max Z\}` are unexplored; the smallest
load on the frontier is a lower bound of every unexplored set, a feasible set closes its
subtree (its supersets cannot do better), and the bracket closes when the frontier's
minimum reaches the best feasible load. The cost is one eigen solve per visited set, so
this suits small i only (the budget decides).
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass

import numpy as np

from unibuckle_fenicsx.algorithms.descent import descend
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem
from unibuckle_fenicsx.tolerances import PROOF_RTOL

__all__ = ["Bracket", "bracket", "lattice_bound"]


def lattice_bound(
    problem: UnilateralProblem, free_load: float, upper: float, budget: int
) -> tuple[float, int, Candidate | None, bool]:
    r"""Best-first branch and bound over the subset lattice (see the module docstring).

    Args:
        problem: The problem (with an obstacle).
        free_load: :math:`\lambda_{free}`, the load of the empty set.
        upper: Best feasible load known.
        budget: Eigen solves allowed; the search runs only if it covers the i singletons.

    Returns:
        (lower bound, evaluations, a feasible candidate with a lower load than ``upper``
        or None, whether the search completed).

    Note:
        Collective.
    """
    n = problem.contact.size
    if budget < n:
        return free_load, 0, None, False
    better: Candidate | None = None
    frontier: list[tuple[float, tuple[int, ...]]] = [(free_load, ())]
    evaluations = 0
    while frontier:
        load, z = frontier[0]
        if load >= upper * (1.0 - PROOF_RTOL):
            break
        first = (z[-1] + 1) if z else 0
        if evaluations + (n - first) > budget:
            break
        heapq.heappop(frontier)
        for k in range(first, n):
            cand = problem.evaluate(np.array((*z, k), dtype=np.int64))
            evaluations += 1
            if not math.isfinite(cand.load):
                continue
            if cand.feasible:
                if cand.load < upper * (1.0 - PROOF_RTOL):
                    upper = cand.load
                    better = cand
                continue
            if cand.load < upper:
                heapq.heappush(frontier, (cand.load, (*z, k)))
    lower = min(frontier[0][0], upper) if frontier else upper
    complete = not frontier or frontier[0][0] >= upper * (1 - PROOF_RTOL)
    return lower, evaluations, better, complete


@dataclass(frozen=True)
class Bracket:
    """The critical state after the lattice search, with its verified bracket.

    Attributes:
        chosen: The returned critical state (the search's lower feasible one if found).
        lower: Lower bound, at least the free load.
        proven: The bracket closes (relative :data:`~unibuckle_fenicsx.tolerances.PROOF_RTOL`).
        evaluations: Eigen solves of the search.
        complete: The search completed.
        warning: What the search changed, in words (None if nothing).
    """

    chosen: Candidate
    lower: float
    proven: bool
    evaluations: int
    complete: bool
    warning: str | None


def bracket(
    problem: UnilateralProblem, free_load: float, chosen: Candidate, budget: int, route: str
) -> Bracket:
    """Close the bracket of ``chosen`` by :func:`lattice_bound` (small zones) and interlacing.

    Note:
        Collective.
    """
    lower, evaluations, better, complete = lattice_bound(problem, free_load, chosen.load, budget)
    warning = None
    if better is not None:
        warning = (
            f"the lattice search found a lower feasible load {better.load:.10g} than the "
            f"{route} critical state {chosen.load:.10g}"
        )
        if not better.kkt:
            # An admissible mode, not yet a critical state: the feasible descent (it
            # cannot cycle, and R does not increase) takes it to one.
            run, _ = descend(problem, better, max(10 * problem.num_constrained, 50))
            if run.final is not None and run.status == "kkt":
                better = run.final
            evaluations += run.iterations
        chosen = better
    lower = max(lower, free_load)
    proven = bool(lower >= chosen.load * (1 - PROOF_RTOL))
    return Bracket(chosen, lower, proven, evaluations, complete, warning)
