"""The log of the node sets an iteration visits: the one cycle test of the set iterations.

The primal-dual active-set iteration (:mod:`.pdas`, contact sets) and the spring-set
iteration of the penalty method and the foundation (:mod:`.penalty`) both move from one
node set to the next and stop when a set comes back: here is where they remember the sets
and measure the cycle.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

__all__ = ["SetLog"]


class SetLog:
    """The sets visited, each with the iteration at which it was last visited."""

    def __init__(self) -> None:
        self._seen: dict[bytes, int] = {}

    @staticmethod
    def _key(nodes: npt.ArrayLike) -> bytes:
        return np.asarray(nodes, dtype=np.int64).tobytes()

    def visit(self, nodes: npt.ArrayLike, iteration: int) -> None:
        """Record ``nodes`` (sorted node numbers) as visited at ``iteration``."""
        self._seen[self._key(nodes)] = iteration

    def __contains__(self, nodes: npt.ArrayLike) -> bool:
        return self._key(nodes) in self._seen

    def cycle_length(self, nodes: npt.ArrayLike, iteration: int) -> int:
        """Iterations since ``nodes`` was visited, were it visited next (0: never)."""
        last = self._seen.get(self._key(nodes))
        return 0 if last is None else iteration + 1 - last

    def clear(self) -> None:
        """Forget every set (a new phase of the iteration starts)."""
        self._seen.clear()
