r"""The primal-dual active-set iteration on the contact set.

From a seed :math:`Z_0`, repeat: solve the reduced pencil
(:meth:`~unibuckle_fenicsx.model.problem.UnilateralProblem.evaluate`, warm-started from the
previous mode; the candidate comes back oriented away from the obstacle), add the nodes of
:math:`I \setminus Z` where the mode violates the obstacle (:math:`u_k > \tau`) and release
the nodes of Z whose multiplier pulls (:math:`r_k > \tau \|Au\|_\infty`). It stops at a
KKT point when neither set is empty. A contact set met twice is a cycle: the iteration then
switches to a damped rule (add only the most violated node(s), release only from a feasible
mode) and, if that cycles too, stops and says so. Every feasible reduced mode is an
admissible mode, so its load is an upper bound whatever the iteration does. With
``thresholds``, the same rule runs first with looser tolerances in place of
:math:`\tau`, each until the point is KKT at it; the end is KKT at :math:`\tau`.

Note:
    All decisions use values reduced over the ranks, so every rank takes the same path;
    collective on the problem's communicator.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from petsc4py import PETSc

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms import RunStatus
from unibuckle_fenicsx.algorithms.records import RunSummary
from unibuckle_fenicsx.algorithms.sets import SetLog
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem
from unibuckle_fenicsx.tolerances import ROUNDING_RTOL

__all__ = ["Run", "iterate"]


@dataclass
class Run:
    """A primal-dual active-set run from one seed.

    Attributes:
        seed: Name of the seed.
        status: KKT, CYCLE, MAX_ITERATIONS or NO_FINITE_LOAD.
        iterations: Eigen solves used.
        final: The last candidate.
        best_feasible: The feasible candidate with the smallest load met (an upper bound).
        history: (|Z|, load, feasible) per iterate.
    """

    seed: str
    status: RunStatus = RunStatus.MAX_ITERATIONS
    iterations: int = 0
    final: Candidate | None = None
    best_feasible: Candidate | None = None
    history: list[tuple[int, float, bool]] = field(default_factory=list)

    def record(self, size: int, cand: Candidate) -> None:
        """Count one more iterate: ``cand``, on a contact set of ``size`` nodes."""
        self.iterations += 1
        self.final = cand
        self.history.append((size, cand.load, cand.feasible))

    def summary(self) -> RunSummary:
        """The run's record."""
        final = self.final
        return RunSummary(
            seed=self.seed,
            status=str(self.status),
            iterations=self.iterations,
            load=None if final is None or not math.isfinite(final.load) else final.load,
            contact_nodes=None if final is None else len(final.active),
            kkt=bool(final is not None and final.kkt),
        )


def _mask(n: int, active: npt.NDArray[np.int64]) -> npt.NDArray[np.bool_]:
    m = np.zeros(n, dtype=bool)
    m[active] = True
    return m


def _changes(
    cand: Candidate, inz: npt.NDArray[np.bool_], stages: list[float], stage: int
) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_], int]:
    """The nodes to add and to release at the first threshold from ``stage`` that has any.

    A point that is KKT at a threshold moves on to the next (tighter) one; the last is
    the tolerance itself. Returns (add, release, the threshold's stage).
    """
    while True:
        level = stages[stage]
        add = ~inz & (cand.values > level)
        release = inz & (cand.forces > level)
        if add.any() or release.any() or stage == len(stages) - 1:
            return add, release, stage
        stage += 1


def _restrict(
    cand: Candidate,
    add: npt.NDArray[np.bool_],
    release: npt.NDArray[np.bool_],
    most_violated: bool,
    damped: bool,
) -> None:
    """Narrow the changes in place (the greedy and the damped rules).

    With ``most_violated`` add only the most violated node(s); while ``damped`` and adding,
    release none.
    """
    if most_violated and add.any():
        add &= cand.values >= cand.values[add].max() * (1.0 - ROUNDING_RTOL)
    if damped and add.any():
        release[:] = False


def iterate(
    problem: UnilateralProblem,
    seed: str,
    start: npt.NDArray[np.int64],
    initial: PETSc.Vec | None,
    max_iterations: int,
    greedy: bool = False,
    thresholds: tuple[float, ...] = (),
    near: float | None = None,
) -> Run:
    """Primal-dual active-set iteration from the contact set ``start``.

    Args:
        problem: The problem (with an obstacle).
        seed: Name recorded in the run.
        start: Initial contact set.
        initial: Start vector of the first eigen solve (later ones start from the
            previous mode).
        max_iterations: Eigen solves allowed, >= 1.
        greedy: Add only the most violated node(s) per iterate (the paper's idea that
            small contact sets come first), instead of every violated node.
        thresholds: Looser tolerances (decreasing, each above ``problem.tau``) to
            converge with first: the iteration ignores violations and pulls below the
            current threshold, and moves to the next one at a point that is KKT at this
            one, warm-started (:doc:`/methods/active_set`).
        near: An estimate of the first set's load: each eigen solve then shifts just
            below the previous iterate's load (or this estimate), the inertia proving
            that the pair is the smallest
            (:meth:`~unibuckle_fenicsx.model.problem.UnilateralProblem.evaluate`).
            Without it every solve is at 0.

    Note:
        Collective.
    """
    n = problem.contact.size
    tau = problem.tau
    run = Run(seed)
    active = np.unique(np.asarray(start, dtype=np.int64))
    stages = [t for t in thresholds if t > tau] + [tau]
    stage = 0
    seen = SetLog()
    damped = False
    vec = initial
    for it in range(max_iterations):
        seen.visit(active, it)
        cand = problem.evaluate(active, initial=vec, near=near)
        vec = cand.mode.x.petsc_vec
        if near is not None and math.isfinite(cand.load):
            near = cand.load
        run.record(len(active), cand)
        if not math.isfinite(cand.load):
            run.status = RunStatus.NO_FINITE_LOAD
            break
        if cand.feasible and (run.best_feasible is None or cand.load < run.best_feasible.load):
            run.best_feasible = cand
        if cand.kkt:
            run.status = RunStatus.KKT
            break
        inz = _mask(n, active)
        add, release, tighter = _changes(cand, inz, stages, stage)
        if tighter != stage:
            # KKT at the looser thresholds: tightened (same contact set and mode).
            stage, damped = tighter, False
            seen.clear()
        _restrict(cand, add, release, greedy or damped, damped)
        new = (inz & ~release) | add
        nxt = np.flatnonzero(new).astype(np.int64)
        if nxt in seen:
            if damped:
                run.status = RunStatus.CYCLE
                break
            # Switch to the damped rule and forget the cycle.
            damped = True
            seen.clear()
            new = inz | add if add.any() else inz & ~release
            nxt = np.flatnonzero(new).astype(np.int64)
        active = nxt
    return run
