"""The interior-point Newton step's state at a saddle (a test set-up run serially and on MPI).

Used by the negative-curvature tests (``tests/unit/algorithms/test_interior_point.py``)
and by ``tests/mpi/negative_curvature_parallel.py``.
"""

from __future__ import annotations

from petsc4py import PETSc

from unibuckle_fenicsx.algorithms.interior_point import InteriorPointNewton


def at_saddle(newton: InteriorPointNewton, lam: float) -> tuple:
    """The pressure deflection at ``lam``, with the Newton step's factorisation made there.

    ``lam`` above the second free load: the unmodified K has a negative direction on the
    tangent space, so the factorisation is regularised (:meth:`direction`). Returns the
    normalised iterate (a function: its vector lives as long as it), its gaps, pushes
    (mu/g) and absolute barrier parameter. Collective (also used by
    ``tests/mpi/negative_curvature_parallel.py``).
    """
    u = newton.starts.pressure_mode()  # strictly inside the cone
    vec = u.x.petsc_vec
    newton.kernel.normalize(vec)  # leaves Bu in newton.kernel.Bu
    gap = -newton.kernel.oriented(vec)
    w_max = float(vec.norm(PETSc.NormType.INFINITY))
    mu_abs = 1e-6 * lam * float(newton.kernel.Bu.norm(PETSc.NormType.INFINITY)) * w_max
    nu = mu_abs / gap
    newton.kernel.residual(vec, lam, nu)
    assert newton.kernel.direction(vec, lam, nu, gap, mu_abs) is not None
    return u, gap, nu, mu_abs
