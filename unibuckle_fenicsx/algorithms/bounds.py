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

import numpy as np

from unibuckle_fenicsx.problem import BucklingProblem, Candidate

__all__ = ["PROOF_RTOL", "lattice_bound"]

#: Relative tolerance for "the bracket is closed".
PROOF_RTOL = 1e-10


def lattice_bound(
    problem: BucklingProblem, free_load: float, upper: float, budget: int
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
    assert problem.contact is not None
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
