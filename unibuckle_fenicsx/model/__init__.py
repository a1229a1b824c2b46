"""The plate problem: mesh, prestress, Reissner-Mindlin plate, obstacle contact, pencil."""

from __future__ import annotations

# Before any module of this package imports petsc4py or DOLFINx: mpi4py loads the MPI
# library they link to (with the PyPI wheel, petsc4py alone fails to find libmpi).
from mpi4py import MPI  # noqa: F401
