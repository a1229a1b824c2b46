"""PETSc's options database is global: what one test puts there, it takes back."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from mpi4py import MPI  # noqa: F401  (loads libmpi before petsc4py)
from petsc4py import PETSc


@contextmanager
def options_restored() -> Iterator[list[str]]:
    """Restore PETSc's options database on leaving the block, whatever happens in it.

    Yields a list that, on leaving, holds the names the block added or changed and did
    not take back (now removed or reset): empty when it cleaned up after itself. A test
    that sets options and then fails (a solve that does not raise where it should, and
    skips the cleanup after it) cannot change the options of the tests after it.
    """
    opts = PETSc.Options()
    before = opts.getAll()
    leaked: list[str] = []
    try:
        yield leaked
    finally:
        after = opts.getAll()
        for key in sorted(after.keys() - before.keys()):
            opts.delValue(key)
            leaked.append(key)
        for key, value in before.items():
            if after.get(key) != value:
                opts.setValue(key, value)
                leaked.append(key)
