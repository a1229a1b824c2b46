"""Progress of long runs, as ``logging`` lines on the logger ``unibuckle_fenicsx.progress``.

The command line shows them on stderr (``-q`` hides them). :class:`Progress` rate-limits
the lines of a loop and estimates the time left from the measured rate.
"""

from __future__ import annotations

import logging
import time

__all__ = ["LOGGER", "Progress"]

#: The progress logger (INFO lines; the CLI shows them unless ``-q``).
LOGGER = logging.getLogger("unibuckle_fenicsx.progress")


class Progress:
    """Counts of a loop, logged at most every ``interval`` seconds with the time left.

    Args:
        label: What is being counted, e.g. "enumeration p = 3".
        total: Items in the loop.
        interval: Seconds between lines.
        enabled: Log at all (e.g. only on rank 0).
        logger: Where to log (default :data:`LOGGER`).
    """

    def __init__(
        self,
        label: str,
        total: int,
        interval: float = 5.0,
        enabled: bool = True,
        logger: logging.Logger = LOGGER,
    ) -> None:
        self.logger = logger
        self.label = label
        self.total = total
        self.interval = interval
        self.enabled = enabled
        self.start = time.perf_counter()
        self._last = self.start

    def update(self, done: int, note: str = "") -> None:
        """Report ``done`` items out of ``total`` if ``interval`` has passed."""
        now = time.perf_counter()
        if not self.enabled or now - self._last < self.interval or done <= 0:
            return
        self._last = now
        elapsed = now - self.start
        left = elapsed * (self.total - done) / done
        self.logger.info(
            "%s: %d/%d (%.0f %%), %.0f s elapsed, about %.0f s left%s",
            self.label,
            done,
            self.total,
            100.0 * done / self.total,
            elapsed,
            left,
            f"; {note}" if note else "",
        )
