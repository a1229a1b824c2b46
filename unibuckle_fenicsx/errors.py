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

__all__ = ["FieldError", "InputError", "NumericalError", "UnibuckleError"]


class UnibuckleError(Exception):
    """Base of the package's errors."""


class InputError(UnibuckleError, ValueError):
    """The input is wrong; the message names the key and the allowed range."""


class FieldError(InputError):
    """A rule between the fields of one table of a problem, broken at ``field`` ("": the table).

    The message names the field by the table's key in code (``obstacle.gap``); the loader
    of a file, which knows where the table lies, names it there (``obstacles[1].gap``).
    """

    def __init__(self, table: str, field: str, text: str) -> None:
        self.field, self.text = field, text
        where = f"[{table}]" if not field else f"{table}.{field}" if table else field
        super().__init__(where + text)


class NumericalError(UnibuckleError, RuntimeError):
    """A solve did not converge, or found no admissible state."""
