"""How a run ended: one vocabulary for the command line, the sweep and the JSON.

:meth:`Outcome.of` reads it off a result (certified or not) or off the exception a run
raised; :attr:`Outcome.exit_status` is the command line's exit status for it, and its
value the ``status`` of a sweep's JSON line. The command line and the sweep both use it,
so that a run ends the same way whichever of them ran it.

Raised by the package: :class:`~unibuckle_fenicsx.errors.InputError` (refused),
:class:`~unibuckle_fenicsx.errors.NumericalError` and its subclasses; a PETSc/SLEPc error
(raised by petsc4py, possibly as the cause of another) is refused input when an object
was reading its options, a numerical failure otherwise; an ``ImportError`` is a missing
extra (gmsh, matplotlib: refused, the message names the extra); Ctrl-C, possibly inside a
PETSc callback, is an interrupt; anything else is a bug.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from enum import StrEnum
from typing import Protocol

from unibuckle_fenicsx.errors import (
    EigenSolveError,
    InputError,
    NoAdmissibleModeError,
    NumericalError,
)

__all__ = ["Certified", "Outcome", "PetscFailure", "in_chain", "petsc_failure"]


class Certified(Protocol):
    """A result that says whether its critical state (or path) is certified."""

    @property
    def certified(self) -> bool:
        """The result satisfies its certificate (KKT), or its path validated everything."""
        ...


class Outcome(StrEnum):
    """How a run ended (its value is a sweep line's ``status``)."""

    #: A certified critical state (or a validated load path).
    OK = "ok"
    #: A result that fails its certificate; the JSON holds the bracket found.
    NOT_CERTIFIED = "not-certified"
    #: The input was refused (the message names the parameter); nothing was solved.
    REFUSED = "refused"
    #: No admissible mode with a finite load was found.
    NO_ADMISSIBLE_MODE = "no-admissible-mode"
    #: An eigen solve did not converge.
    EIGEN_FAILURE = "eigen-failure"
    #: Another numerical failure.
    FAILED = "failed"
    #: Interrupted (Ctrl-C).
    INTERRUPTED = "interrupted"
    #: An internal error: a bug.
    BUG = "bug"

    @property
    def exit_status(self) -> int:
        """The command line's exit status: 0, 2 (refused), 3 (numerical), 1 (bug), 130."""
        return _EXIT[self]

    @property
    def solved(self) -> bool:
        """The run produced a result (certified or not)."""
        return self in (Outcome.OK, Outcome.NOT_CERTIFIED)

    @classmethod
    def of(cls, ended: Certified | BaseException) -> Outcome:
        """The outcome of a run that returned the result ``ended`` or raised it."""
        if not isinstance(ended, BaseException):
            return cls.OK if ended.certified else cls.NOT_CERTIFIED
        if in_chain(ended, KeyboardInterrupt) is not None:
            # Ctrl-C inside a Python callback of PETSc (the nonlinear path's SNES residual)
            # comes back as PETSc error 101 with the interrupt as its context.
            return cls.INTERRUPTED
        for kind, outcome in _RAISED:
            if isinstance(ended, kind):
                return outcome
        failure = petsc_failure(ended)
        if failure is not None:
            return cls.REFUSED if failure.refused_option else cls.FAILED
        return cls.BUG


_EXIT = {
    Outcome.OK: 0,
    Outcome.NOT_CERTIFIED: 3,
    Outcome.REFUSED: 2,
    Outcome.NO_ADMISSIBLE_MODE: 3,
    Outcome.EIGEN_FAILURE: 3,
    Outcome.FAILED: 3,
    Outcome.INTERRUPTED: 130,
    Outcome.BUG: 1,
}

#: The package's errors, most specific first; ImportError: a missing extra.
_RAISED: tuple[tuple[type[BaseException], Outcome], ...] = (
    (InputError, Outcome.REFUSED),
    (ImportError, Outcome.REFUSED),
    (NoAdmissibleModeError, Outcome.NO_ADMISSIBLE_MODE),
    (EigenSolveError, Outcome.EIGEN_FAILURE),
    (NumericalError, Outcome.FAILED),
)


def in_chain(err: BaseException, kind: type[BaseException]) -> BaseException | None:
    """``err`` or the first of its causes or contexts (8 deep at most) that is a ``kind``."""
    found: BaseException | None = err
    for _ in range(8):
        if found is None or isinstance(found, kind):
            return found
        found = found.__cause__ or found.__context__
    return None


@dataclass(frozen=True)
class PetscFailure:
    """A PETSc/SLEPc error found in an exception's chain.

    Attributes:
        reason: PETSc's message lines joined (its traceback lines left out).
        first_line: Its first line (the error code).
        refused_option: Raised while an object read its options (``*SetFromOptions``):
            a bad command-line option.
    """

    reason: str
    first_line: str
    refused_option: bool


def petsc_failure(err: BaseException) -> PetscFailure | None:
    """The PETSc/SLEPc error in ``err`` or its causes, or None.

    petsc4py reports an error inside a Cython call as a SystemError whose cause is the
    ``PETSc.Error``: the chain is searched. Nothing is imported: without petsc4py loaded
    no PETSc error can have been raised.
    """
    petsc = sys.modules.get("petsc4py.PETSc")
    if petsc is None:
        return None
    found = in_chain(err, petsc.Error)
    if found is None:
        return None
    lines = [line.removeprefix("[0] ").strip() for line in str(found).splitlines()]
    reason = "; ".join(line for line in lines[1:] if line and "() at " not in line)
    return PetscFailure(
        reason=reason or lines[0],
        first_line=lines[0],
        refused_option=any("SetFromOptions()" in line for line in lines),
    )
