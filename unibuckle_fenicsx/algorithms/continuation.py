r"""Penalty continuation: a robust route to a KKT point when the active-set iteration stalls.

On thin plates and long plates with clamped edges the critical mode has several lobes
separated by contact lines, and on a fine mesh the primal-dual active-set iteration
(:mod:`.pdas`) moves those lines a node at a time, or cycles, among contact sets whose
loads differ by 1e-9. The penalised problem (:mod:`.penalty`),

.. math::

    \min_v \frac{a(v,v) + \rho \sum_{k\in I}\max(0, v_k)^2}{b(v,v)},

is a smooth relaxation: its iteration on the spring set converges where the exact one
does not, and its limit as :math:`\rho \to \infty` is the critical state. So the spring
set is carried through an increasing sequence of penalties (each warm-started from the
previous one's), and the last spring set, removed exactly, is polished by the active-set
iteration into a KKT point of the exact problem (one to three eigen solves when the
penalty has found the contact set).

Note:
    Collective on the problem's communicator.
"""

from __future__ import annotations

import logging
import math

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms import RunStatus
from unibuckle_fenicsx.algorithms.pdas import Run, iterate
from unibuckle_fenicsx.algorithms.penalty import PenaltySolver
from unibuckle_fenicsx.algorithms.records import PenaltyDetails
from unibuckle_fenicsx.model.problem import UnilateralProblem

__all__ = ["COLD_PENALTIES", "WARM_PENALTIES", "penalty_continuation"]

logger = logging.getLogger(__name__)

#: Penalties (relative to max diag A) from the free mode: start soft.
COLD_PENALTIES = (1e-2, 1.0, 1e2, 1e4, 1e6)
#: Penalties from a spring set prolonged from a coarser mesh.
WARM_PENALTIES = (1.0, 1e2, 1e4, 1e6)


def penalty_continuation(
    problem: UnilateralProblem,
    start: npt.NDArray[np.int64] | None,
    *,
    penalties: tuple[float, ...] | None = None,
    max_iterations: int = 200,
    polish_iterations: int = 25,
) -> tuple[Run, int]:
    """From the spring set ``start`` (None: the free mode) to a KKT point.

    Args:
        problem: The problem (with an obstacle).
        start: Initial spring set; None starts from the free plate.
        penalties: Increasing relative penalties (default :data:`COLD_PENALTIES` from
            the free plate, :data:`WARM_PENALTIES` from a given set).
        max_iterations: Eigen solves allowed per penalty.
        polish_iterations: Active-set iterates allowed for the final, exact polish.

    Returns:
        The polishing run (its ``final`` candidate is a KKT point when its status is
        "kkt") and the eigen solves of the penalty stage.

    Note:
        Collective.
    """
    if penalties is None:
        penalties = COLD_PENALTIES if start is None else WARM_PENALTIES
    lower = problem.solve_free().load
    springs = None if start is None else np.asarray(start, dtype=np.int64)
    solves = 0
    with PenaltySolver(problem) as pen:
        for rho in penalties:
            sol = pen.solve(
                rho, initial_active=springs, max_iterations=max_iterations, lower_bound=lower
            )
            solves += sol.eigensolves
            springs = sol.active
            status = sol.details.penalty_status if isinstance(sol.details, PenaltyDetails) else ""
            logger.debug(
                "penalty continuation rho=%g: %s, %d solves, R = %.10g, |S| = %d",
                rho, status, sol.eigensolves, sol.load, len(springs),
            )  # fmt: skip
        if springs is None:
            raise ValueError("penalties must not be empty")
        mode = sol.candidate.mode.x.petsc_vec
        run = iterate(problem, "penalty", springs, mode, polish_iterations)
    if run.final is not None and not math.isfinite(run.final.load):
        run.status = RunStatus.NO_FINITE_LOAD
    return run, solves
