"""Every error class of the package: what went wrong decides how a run ends.

- :class:`InputError`: the user's input is wrong (a problem file, a keyword argument, a
  command-line flag). The message names the key and the allowed range; it is raised before
  any solve. Its subclasses say which input: :class:`FieldError` (a rule between the
  fields of one table is broken), :class:`EmptyZoneError` (an obstacle zone holds no free
  mesh node), :class:`BilateralZoneError` (zones on both sides of the plate share a node),
  :class:`NoLoadError` (no positive buckling load on the mesh).
- :class:`NumericalError`: a solve that did not converge or found nothing admissible:
  :class:`EigenSolveError` (an eigen solve did not converge),
  :class:`NoAdmissibleModeError` (no admissible mode with a finite load),
  :class:`NonlinearError` (no load step of the nonlinear path converged).
- :class:`NoKKTPointError`: a signal inside a route, never the end of a run: a chain of
  starts asked to run without a fallback reached no KKT point, and its caller keeps the
  solution it had.
- Anything else is a bug.

How each ends a run (its exit status, a sweep line's status) is
:class:`~unibuckle_fenicsx.outcome.Outcome`'s business.

Both base classes keep the built-in class they replace as a base (``ValueError``,
``RuntimeError``), so code that catches those still works.
"""

from __future__ import annotations

__all__ = [
    "BilateralZoneError",
    "EigenSolveError",
    "EmptyZoneError",
    "FieldError",
    "InputError",
    "NoAdmissibleModeError",
    "NoKKTPointError",
    "NoLoadError",
    "NonlinearError",
    "NumericalError",
    "UnibuckleError",
]


class UnibuckleError(Exception):
    """Base of the package's errors."""


class InputError(UnibuckleError, ValueError):
    """The input is wrong; the message names the key and the allowed range."""


class EmptyZoneError(InputError):
    """The obstacle zone holds no free mesh node."""


class BilateralZoneError(InputError):
    """Obstacles on opposite sides of the plate share a mesh node."""


class NoLoadError(InputError):
    """The plate has no positive buckling load on this mesh (b(w, w) nowhere positive)."""


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


class EigenSolveError(NumericalError):
    """The eigen solve did not converge."""


class NoAdmissibleModeError(NumericalError):
    """No admissible mode with a finite load was found (the message gives the bracket)."""


class NonlinearError(NumericalError):
    """The nonlinear solve failed before any load step converged."""


class NoKKTPointError(UnibuckleError):
    """A chain of starts run without a fallback reached no KKT point (its caller catches it)."""
