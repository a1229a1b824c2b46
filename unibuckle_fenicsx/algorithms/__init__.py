"""Unilateral critical-state algorithms.

Each takes a :class:`~unibuckle_fenicsx.model.problem.UnilateralProblem` with an obstacle and
returns a :class:`UnilateralSolution` holding the chosen
:class:`~unibuckle_fenicsx.model.problem.Candidate` (load, contact set and its own mode):

- :mod:`.enumeration`: the paper's direct method (section 5.3), 2^i candidate sets;
- :mod:`.active_set`: primal-dual active-set iteration from several seeds
  (:mod:`.multilevel` carries it over a mesh hierarchy, :mod:`.bounds` brackets it);
- :mod:`.penalty`: the penalty method the paper rejects, for comparison.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum
from typing import TYPE_CHECKING

# Before any module of this package imports petsc4py or DOLFINx: mpi4py loads the MPI
# library they link to (with the PyPI wheel, petsc4py alone fails to find libmpi).
from mpi4py import MPI  # noqa: F401

import numpy as np
import numpy.typing as npt

if TYPE_CHECKING:  # pragma: no cover
    from unibuckle_fenicsx.algorithms.records import ContinuedRecord, MethodDetails
    from unibuckle_fenicsx.model.problem import Candidate

__all__ = ["RunStatus", "UnilateralSolution", "candidate_count"]


class RunStatus(StrEnum):
    """How an iteration ended (its value is what the JSON output shows).

    The active-set and descent runs end at a KKT point (``KKT``); the spring-set
    iterations of the penalty method and the foundation at a fixed point
    (``CONVERGED``); any of them may cycle, run out of iterations, stall (no admissible
    step) or meet a set without a finite load.
    """

    KKT = "kkt"
    CONVERGED = "converged"
    CYCLE = "cycle"
    MAX_ITERATIONS = "max_iterations"
    STALLED = "stalled"
    NO_FINITE_LOAD = "no-finite-load"


def candidate_count(i: int) -> int:
    r"""Contact sets the paper's enumeration may visit: :math:`\sum_{p=0}^{i} C(i, p) = 2^i`.

    Early stopping cannot know the stopping size in advance, so the worst case is the count.
    """
    return 2**i


@dataclass
class UnilateralSolution:
    """What an algorithm found.

    Attributes:
        candidate: The returned critical state: load, contact set Z and mode.
        method: Name of the algorithm.
        eigensolves: Linear eigen solves performed (all levels; for candidate-parallel
            runs summed over ranks).
        lower_bound: A lower bound on the critical load proven by the algorithm
            (interlacing, lattice search), at least the free load.
        global_optimum_proven: ``lower_bound`` reaches the load (within the algorithm's
            tolerance), or the search was exhaustive.
        upper_bound: The load of an admissible mode (``inf`` if the method found none,
            e.g. the penalty method, whose modes penetrate).
        details: The algorithm's record of its run (None for a bare candidate).
        route: The links that answered, in order (the method alone when it answered by
            itself; the interior point's polish or descent, or its active-set fallback,
            after it).
        kkt_points: Other KKT points met (distinct contact sets), for the certificate.
        p_star: Size of the contact set at which enumeration stopped (None otherwise).
        lower_bound_by: What proves ``lower_bound``: "enumeration", "lattice", or None when
            it is the free load (interlacing: the obstacle never lowers the load).
        status: How the method's iteration ended, for methods whose certificate depends on
            it (the foundation's spring-set iteration); None for the others.
        continued: The continuations from refuting modes
            (:func:`~unibuckle_fenicsx.algorithms.descent.continue_from`), in order.
    """

    candidate: Candidate
    method: str
    eigensolves: int
    lower_bound: float
    global_optimum_proven: bool
    upper_bound: float
    details: MethodDetails | None = None
    route: list[str] = field(default_factory=list)
    kkt_points: list[Candidate] = field(default_factory=list)
    p_star: int | None = None
    lower_bound_by: str | None = None
    status: RunStatus | None = None
    continued: list[ContinuedRecord] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not self.route:
            self.route = [self.method]

    @property
    def load(self) -> float:
        """The returned load."""
        return self.candidate.load

    @property
    def active(self) -> npt.NDArray[np.int64]:
        """The returned contact set."""
        return self.candidate.active
