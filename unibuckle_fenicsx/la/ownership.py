"""Who destroys a PETSc/SLEPc object: its owner, collectively, once.

Every class that holds PETSc or SLEPc objects derives from :class:`Owner`: it has
``destroy()`` (collective) and is a context manager that calls it on exit. A function
that returns a PETSc object says in its docstring that the caller destroys it.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager
from types import TracebackType
from typing import Any

__all__ = ["Owner", "destroyed_after", "release"]

logger = logging.getLogger(__name__)


def _destroy_after_error(obj: Any, error: BaseException) -> None:
    """Destroy ``obj`` while ``error`` propagates, never letting a second error mask it.

    A SLEPc solve that fails mid-iteration can leave a work matrix checked out, and the
    EPS's destroy then fails too ("Need to call MatDenseRestoreSubMatrix() first"); that
    second error would replace the first, the one that says what went wrong. It is
    logged instead (the object may leak: the run is ending with ``error``).
    """
    try:
        obj.destroy()
    except Exception as second:
        logger.debug(
            "%s.destroy() failed after %s: %s", type(obj).__name__, type(error).__name__, second
        )


@contextmanager
def destroyed_after(obj: Any) -> Iterator[Any]:
    """Destroy ``obj`` on leaving the ``with`` block, never masking the block's error.

    ``with destroyed_after(SLEPc.EPS().create(comm)) as eps: ...``. If the block
    raises, its error propagates even when ``destroy()`` fails too
    (:func:`_destroy_after_error`). Collective (``destroy()`` is).
    """
    try:
        yield obj
    except BaseException as error:
        _destroy_after_error(obj, error)
        raise
    obj.destroy()


def release(owner: object, *names: str) -> None:
    """Destroy the PETSc/SLEPc objects held in ``owner``'s attributes ``names`` (collective).

    Each is set to None afterwards, so a second call (or ``__del__`` after ``destroy``)
    does nothing.
    """
    for name in names:
        obj = getattr(owner, name, None)
        if obj is not None:
            obj.destroy()
            setattr(owner, name, None)


class Owner:
    """A holder of PETSc/SLEPc objects: ``destroy()`` them, or use it in a ``with`` block."""

    def destroy(self) -> None:
        """Destroy the objects held (collective)."""
        raise NotImplementedError

    def __enter__(self) -> Any:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if exc is not None:  # the block's error, not a failure of destroy, reaches the user
            _destroy_after_error(self, exc)
        else:
            self.destroy()
