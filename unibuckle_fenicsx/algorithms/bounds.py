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
from unibuckle_fenicsx.errors import EigenSolveError
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem
from unibuckle_fenicsx.tolerances import PROOF_RTOL, SMALLEST_RTOL_FACTOR

__all__ = ["Bracket", "bounded_below", "bracket", "lattice_bound"]


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
    chosen, lower, again = bounded_below(problem, chosen, lower, free_load, route)
    if again:
        warning = again if warning is None else f"{warning}; {again}"
    # Only an admissible mode's load bounds the critical load from above.
    proven = bool(chosen.feasible and lower >= chosen.load * (1 - PROOF_RTOL))
    return Bracket(chosen, lower, proven, evaluations, complete, warning)


def _floor(cand: Candidate, lower: float, free_load: float) -> float:
    """The least load ``cand`` can have: ``lower`` if admissible, the free load if an eigenpair."""
    if cand.feasible:
        return lower  # an admissible mode's quotient bounds the critical load from above
    return free_load if cand.eigen is not None else -math.inf  # interlacing


def bounded_below(
    problem: UnilateralProblem, chosen: Candidate, lower: float, free_load: float, route: str
) -> tuple[Candidate, float, str | None]:
    r"""``chosen`` and the proven lower bound ``lower`` beside it, which it cannot lie below.

    An admissible mode's load is at least the critical load, so at least ``lower`` (the
    free load by interlacing, or the lattice's bound); any eigenpair of a reduced pencil
    lies at or above the free load. A load below its floor by more than the eigen
    solver's accuracy (:data:`~unibuckle_fenicsx.tolerances.SMALLEST_RTOL_FACTOR` times
    ``eps_tol``) is a contradiction, never a lower bound: the free pair is verified the
    smallest (inertia), the contact set solved again from SLEPc's own start, and if the
    load still lies below, :class:`~unibuckle_fenicsx.errors.EigenSolveError` says the
    pair is not an eigenpair. Within that accuracy the two agree, and the bound is
    lowered to an admissible load (the bracket is not inverted by rounding).

    Returns:
        (the candidate, solved again if it had to be; the lower bound; what was done, in
        words, or None).

    Note:
        Collective.
    """
    agree = 1.0 - SMALLEST_RTOL_FACTOR * problem.spec.solver.eps_tol
    message = None
    if chosen.load < _floor(chosen, lower, free_load) * agree:
        problem.verify_free()  # raises if the free pair, not this one, is the wrong one
        again = problem.evaluate(chosen.active)
        message = (
            f"the {route} critical state's load {chosen.load:.10g} lay below the proven "
            f"lower bound {lower:.10g}: no eigenpair; its contact set solved again gave "
            f"{again.load:.10g}"
        )
        if again.load < _floor(again, lower, free_load) * agree:
            raise EigenSolveError(
                f"{message}, still below: the eigen solver returns a pair that is not an "
                f"eigenpair of the pencil with |Z| = {again.active.size} removed; try a "
                f"larger -{problem.eigensolver.prefix}eps_ncv"
            )
        chosen = again
    if chosen.feasible and chosen.load < lower:
        lower = chosen.load  # equal within the eigen solver's accuracy
    return chosen, lower, message
