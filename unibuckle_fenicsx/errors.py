"""One error hierarchy: what went wrong decides the exit status.

- :class:`InputError`: the user's input is wrong (a problem file, a keyword argument, a
  command-line flag). The message names the key and the allowed range; it is raised before
  any solve. The command line exits with status 2, the sweep records the point "refused".
- :class:`NumericalError`: a solve that did not converge or found nothing admissible. The
  command line exits with status 3 and writes the bracket or the partial result when there
  is one; the sweep records the point "failed" (or a more precise status).
- Anything else is a bug: the command line exits with status 1, prints the traceback and
  asks for a report.

Both classes keep the built-in class they replace as a base (``ValueError``,
``RuntimeError``), so code that catches those still works.
"""

from __future__ import annotations

__all__ = ["InputError", "NumericalError", "UnibuckleError"]


class UnibuckleError(Exception):
    """Base of the package's errors."""


class InputError(UnibuckleError, ValueError):
    """The input is wrong; the message names the key and the allowed range."""


class NumericalError(UnibuckleError, RuntimeError):
    """A solve did not converge, or found no admissible state."""
