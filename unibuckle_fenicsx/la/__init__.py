"""Linear algebra on PETSc and SLEPc: options, ownership, the eigen solver, factorisations.

- :mod:`.options`: the table of options prefixes (:class:`~.options.Prefix`) and the one
  place that touches PETSc's options database (push defaults under a prefix, pop them);
- :mod:`.ownership`: :class:`~.ownership.Owner` (a holder of PETSc objects that
  destroys them) and :func:`~.ownership.release`;
- :mod:`.eigen`: the buckling pencil's smallest eigenpair (:class:`~.eigen.GEPSolver`),
  the swapped pencil's extreme pairs, a symmetric matrix's extreme eigenvalues;
- :mod:`.factor`: MUMPS :math:`LDL^T` with inertia, alone or shared by the users of one
  mesh's stiffness pattern.

Every object here is collective on its matrices' communicator; ``destroy()`` is
collective.
"""

# mpi4py first: it loads the MPI library petsc4py links to (with the PyPI wheel,
# petsc4py alone fails to find libmpi).
from mpi4py import MPI  # noqa: F401

try:
    import petsc4py  # noqa: F401
    import slepc4py  # noqa: F401
except ImportError as err:  # pragma: no cover
    raise ImportError(
        "unibuckle_fenicsx.la needs petsc4py and slepc4py (real scalars); install the "
        "'fenics' extra: pip install 'unibuckle_fenicsx[fenics]'"
    ) from err
