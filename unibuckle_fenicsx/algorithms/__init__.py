"""Unilateral critical-state algorithms.

Each takes a :class:`~unibuckle_fenicsx.problem.BucklingProblem` with an obstacle and
returns a :class:`UnilateralSolution`, leaving the final mode in ``problem.u``:

- :mod:`.enumeration`: the paper's direct method (section 5.3), exact, 2^i candidates;
- :mod:`.active_set`: primal-dual active-set iteration from several seeds, with bounds;
- :mod:`.penalty`: the penalty method the paper rejects, for comparison.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = ["UnilateralSolution"]


@dataclass
class UnilateralSolution:
    """What an algorithm found.

    Attributes:
        load: Critical load lambda (upper bound: the load of a feasible mode).
        active: Sorted node numbers of the contact set Z of the returned mode.
        eigensolves: Linear eigen solves performed (on this rank's share for
            candidate-parallel runs: summed over ranks).
        lower_bound: A proven lower bound on the critical load.
        global_optimum_proven: ``lower_bound`` equals ``load`` (within tolerance), or
            the method is exhaustive.
        p_star: Size of the contact set at which enumeration stopped (None otherwise).
        details: Method-specific, JSON-ready information.
    """

    load: float
    active: npt.NDArray[np.int64]
    eigensolves: int
    lower_bound: float
    global_optimum_proven: bool
    p_star: int | None = None
    details: dict[str, Any] = field(default_factory=dict)
