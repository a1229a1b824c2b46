"""Who destroys a PETSc/SLEPc object: its owner, collectively, once.

Every class that holds PETSc or SLEPc objects derives from :class:`Owner`: it has
``destroy()`` (collective) and is a context manager that calls it on exit. A function
that returns a PETSc object says in its docstring that the caller destroys it.
"""

from __future__ import annotations

from types import TracebackType
from typing import Any

__all__ = ["Owner", "release"]


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
        self.destroy()
