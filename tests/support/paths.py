"""The repository's folders, for tests that run scripts or read files."""

from __future__ import annotations

from pathlib import Path

#: The repository's root.
ROOT = Path(__file__).resolve().parents[2]
#: The tests' folder.
TESTS = ROOT / "tests"
#: The scripts that the MPI tests run under ``mpiexec``.
MPI_SCRIPTS = TESTS / "mpi"
