r"""The plane span{u, d} in an A-orthonormal basis, and the forms of B on it.

The feasible descent (:mod:`.descent`, u the iterate and d an eigenvector or a gradient)
moves on the unit A-circle of a plane, :math:`x(\varphi) = \cos\varphi\, e_1 +
\sin\varphi\, e_2` with :math:`e_1 = u/\|u\|_A` and :math:`e_2` the A-orthogonal part of
d, normalised. (The foundation's arc descent, :mod:`.foundation`, builds the same plane
in its own basis: moved onto this one, a certified foundation result on a 24 x 8 plate
lost its certificate, so it keeps its own until that is understood.) On that
circle :math:`a(x, x) = 1` and :math:`b(x, x) = b_{11}\cos^2\varphi + 2 b_{12}\cos\varphi
\sin\varphi + b_{22}\sin^2\varphi`, so the Rayleigh quotient is :math:`1/b`.

Note:
    Collective on the vectors' communicator.
"""

from __future__ import annotations

import math

from petsc4py import PETSc

from unibuckle_fenicsx.tolerances import SAME_DIRECTION

__all__ = ["ArcPlane"]


def _form(M: PETSc.Mat, x: PETSc.Vec, y: PETSc.Vec, work: PETSc.Vec) -> float:
    """x^T M y (collective)."""
    M.mult(y, work)
    return float(x.dot(work).real)


class ArcPlane:
    """span{u, d}: the A-orthonormal basis (e1, e2) and the 2x2 form of B on it.

    Args:
        A: The SPD stiffness.
        B: The geometric stiffness.
        u: The first direction (e1 is u, A-normalised).
        d: The second direction.

    Attributes:
        e1: The basis's first vector (new, owned).
        e2: Its second (new, owned); None when d lies within
            :data:`~unibuckle_fenicsx.tolerances.SAME_DIRECTION` of u (no plane).
        b11: :math:`b(e_1, e_1)`.
        b12: :math:`b(e_1, e_2)` (0 without a plane).
        b22: :math:`b(e_2, e_2)` (0 without a plane).

    Note:
        Collective; :meth:`destroy` frees the basis.
    """

    def __init__(self, A: PETSc.Mat, B: PETSc.Mat, u: PETSc.Vec, d: PETSc.Vec) -> None:
        work = u.duplicate()
        try:
            self.e1 = u.copy()
            self.e1.scale(1.0 / math.sqrt(_form(A, u, u, work)))
            e2 = d.copy()
            e2.axpy(-_form(A, d, self.e1, work), self.e1)
            s = math.sqrt(max(_form(A, e2, e2, work), 0.0))
            self.e2: PETSc.Vec | None = None
            self.b11 = self.b12 = self.b22 = 0.0
            if s > SAME_DIRECTION * math.sqrt(_form(A, d, d, work)):
                e2.scale(1.0 / s)
                self.e2 = e2
                self.b11 = _form(B, self.e1, self.e1, work)
                self.b12 = _form(B, self.e1, e2, work)
                self.b22 = _form(B, e2, e2, work)
            else:
                e2.destroy()
        finally:
            work.destroy()

    def flip(self) -> None:
        """e2 -> -e2 (b12 changes sign)."""
        if self.e2 is not None:
            self.e2.scale(-1.0)
            self.b12 = -self.b12

    def point(self, phi: float) -> PETSc.Vec:
        """x(phi) = cos(phi) e1 + sin(phi) e2, a new vector."""
        x = self.e1.copy()
        x.scale(math.cos(phi))
        if self.e2 is not None:
            x.axpy(math.sin(phi), self.e2)
        return x

    def destroy(self) -> None:
        """Destroy the basis vectors."""
        self.e1.destroy()
        if self.e2 is not None:
            self.e2.destroy()
            self.e2 = None
