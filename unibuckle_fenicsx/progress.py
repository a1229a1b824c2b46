"""Progress of long runs, as ``logging`` lines on the logger ``unibuckle_fenicsx.progress``.

The command line shows them on stderr (``-q`` hides them). :class:`Progress` rate-limits
the lines of a loop and estimates the time left from the rate so far; asked for a bar
(the sweep), it draws one with tqdm (the ``progress`` extra) instead of the lines, and
falls back to the lines, saying so, when tqdm is not installed. :func:`warn_once` logs a
warning that every rank computes on one rank only.
"""

from __future__ import annotations

import logging
import time
from typing import Any

__all__ = ["LOGGER", "Progress", "warn_once"]

#: The progress logger (INFO lines; the CLI shows them unless ``-q``).
LOGGER = logging.getLogger("unibuckle_fenicsx.progress")


def warn_once(logger: logging.Logger, comm: Any, message: str, *args: object) -> None:
    """``logger.warning(message, *args)`` on rank 0 of ``comm`` only.

    For a warning every rank computes alike (from values reduced over the ranks): a
    script's logging, unlike the command line's, shows every rank's records, and would
    show it once per rank. Not collective.
    """
    if comm.rank == 0:
        logger.warning(message, *args)


class Progress:
    """Counts of a loop, logged at most every ``interval`` seconds with the time left.

    Args:
        label: What is being counted, e.g. "enumeration p = 3".
        total: Items in the loop.
        interval: Seconds between lines.
        enabled: Log at all (e.g. only on rank 0).
        logger: Where to log (default :data:`LOGGER`).
        bar: Draw a tqdm bar instead of lines (if tqdm is installed).
        initial: Items already done before this run (a resumed loop): the bar starts
            there; ``done`` in :meth:`update` counts this run's items only.
        unit: What an item is, for the bar.
    """

    def __init__(
        self,
        label: str,
        total: int,
        interval: float = 5.0,
        enabled: bool = True,
        logger: logging.Logger = LOGGER,
        *,
        bar: bool = False,
        initial: int = 0,
        unit: str = "it",
    ) -> None:
        self.logger = logger
        self.label = label
        self.total = total
        self.interval = interval
        self.enabled = enabled
        self.start = time.perf_counter()
        self._last = self.start
        self.initial = initial
        self._bar = (
            _tqdm(label, total + initial, initial, unit, logger) if enabled and bar else None
        )

    def update(self, done: int, note: str = "") -> None:
        """Report ``done`` items out of ``total`` if ``interval`` has passed."""
        if self._bar is not None:
            self._bar.update(self.initial + done - self._bar.n)
            return
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

    def close(self) -> None:
        """Finish the bar (if any)."""
        if self._bar is not None:
            self._bar.update(self._bar.total - self._bar.n)
            self._bar.close()
            self._bar = None


def _tqdm(label: str, total: int, initial: int, unit: str, logger: logging.Logger) -> Any:
    """A tqdm bar, or None (with a line naming the extra) if tqdm is not installed."""
    try:
        from tqdm import tqdm
    except ImportError:
        logger.info(
            "%s: install the 'progress' extra (pip install 'unibuckle_fenicsx[progress]') "
            "for a progress bar; progress lines follow instead",
            label,
        )
        return None
    return tqdm(total=total, initial=initial, unit=unit, desc=label, dynamic_ncols=True)
