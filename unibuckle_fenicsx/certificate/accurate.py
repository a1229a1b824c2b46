r"""Residuals in twice the working precision, with rigorous error bounds.

Each entry is :math:`G_{ab} = u_a^Tx_b + x_a^T\rho_b + \rho_a^TK^{-1}\rho_b`
with :math:`x_b` the computed (refined) solution and :math:`\rho_b = u_b - Kx_b` its exact
residual. On thin plates :math:`|K||x| \gg |Kx|` (shear stiffness against bending: at
t/b = 1e-3 the rounding bound of a double-precision residual is a million times that
of the one below; :doc:`/verification/index`), so
:math:`\rho` is computed in twice the working precision: Dot2 of T. Ogita, S. M. Rump and
S. Oishi, "Accurate sum and dot product", SIAM J. Sci. Comput. 26 (2005) 1955-1988
(TwoSum of D. E. Knuth, TwoProduct of T. J. Dekker with Veltkamp's splitting), with
their error bound :math:`|res - x^Ty| \le u|x^Ty| + \gamma_n^2|x|^T|y|`. NumPy has no
double-double type and PETSc's MatMult none either, so the transformation is written here,
vectorised over the rows of K (stored row by row, padded to the longest row). The dot
products :math:`u_a^Tx_b` are summed exactly rounded by :func:`math.fsum` over the
error-free products. The second-order term is estimated by
:math:`2\|K^{-1}\hat\rho_a\|\,\|\,|\hat\rho_b| + e_b\|` (a solve; not bounded rigorously,
as in the rank-2 route; it is about :math:`u^2` of the others after refinement).

Note:
    :class:`AccurateResidual` is collective on the matrix's communicator.
"""

from __future__ import annotations

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import numpy.typing as npt

__all__ = ["AccurateResidual", "U", "gamma", "two_product", "two_sum"]

#: Unit roundoff of IEEE double (Ogita-Rump-Oishi's eps).
U = 2.0**-53
_SPLITTER = 2.0**27 + 1.0  # Veltkamp's splitting constant for 53-bit mantissas


def gamma(n: int) -> float:
    r"""Higham's :math:`\gamma_n = nu/(1 - nu)`, the bound on n roundings."""
    return n * U / (1.0 - n * U)


def two_sum(
    a: npt.NDArray[np.float64], b: npt.NDArray[np.float64]
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Knuth's TwoSum: s + e = a + b exactly, s = fl(a + b) (elementwise)."""
    s = a + b
    z = s - a
    return s, (a - (s - z)) + (b - z)


def _split(a: npt.NDArray[np.float64]) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Veltkamp's splitting: a = hi + lo, each with at most 26 significant bits."""
    c = _SPLITTER * a
    hi = c - (c - a)
    return hi, a - hi


def two_product(
    a: npt.NDArray[np.float64],
    b: npt.NDArray[np.float64],
    a_parts: tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]] | None = None,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Dekker's TwoProduct: p + e = a b exactly, p = fl(a b) (no underflow; elementwise)."""
    p = a * b
    ah, al = a_parts if a_parts is not None else _split(a)
    bh, bl = _split(b)
    return p, al * bl - (((p - ah * bh) - al * bh) - ah * bl)


class AccurateResidual:
    r""":math:`\rho = w - Kx` in twice the working precision, with a componentwise bound.

    K's local rows (``getValuesCSR``) are padded to the longest row and stored by
    position in the row; the x values of their columns come through one PETSc scatter
    (ghost values in parallel). Dot2 of every row at once, one position at a time, for
    a batch of vectors; the work arrays are allocated once per call (fresh temporaries of
    this size cost page faults).

    Args:
        K: The assembled symmetric matrix (AIJ); its values are read now.

    Note:
        Collective (construction and calls). The owner must :meth:`destroy` it.
    """

    def __init__(self, K: PETSc.Mat) -> None:
        ai, aj, av = K.getValuesCSR()
        lens = np.diff(ai)
        n = len(lens)
        length = int(lens.max()) if n else 0
        rows = np.repeat(np.arange(n), lens)
        pos = np.arange(len(aj)) - ai[rows]
        needed, inverse = np.unique(aj, return_inverse=True)
        cols = np.zeros((length, n), dtype=np.int64)
        cols[pos, rows] = inverse
        vals = np.zeros((length, n))
        vals[pos, rows] = -av
        if not np.isfinite(vals).all() or np.abs(vals).max(initial=0.0) > 2.0**995:
            raise ValueError("AccurateResidual: K has entries too large for TwoProduct")
        self.cols, self.vals = cols, vals
        self.hi, self.lo = _split(vals)
        self.abs_vals = np.abs(vals)
        comm = K.getComm().tompi4py()
        self.terms = int(comm.allreduce(length, op=MPI.MAX)) + 1
        x = K.createVecRight()
        self._local = PETSc.Vec().createSeq(len(needed), comm=PETSc.COMM_SELF)
        index = PETSc.IS().createGeneral(needed.astype(PETSc.IntType), comm=PETSc.COMM_SELF)  # type: ignore[arg-type]
        self._scatter = PETSc.Scatter().create(x, index, self._local, None)  # type: ignore[arg-type]
        index.destroy()
        x.destroy()

    def _gather(self, xs: list[PETSc.Vec]) -> npt.NDArray[np.float64]:
        out = np.empty((self._local.getSize(), len(xs)))
        for j, x in enumerate(xs):
            self._scatter.scatter(
                x,
                self._local,
                PETSc.InsertMode.INSERT,  # type: ignore[arg-type]
                PETSc.ScatterMode.FORWARD,  # type: ignore[arg-type]
            )
            out[:, j] = self._local.array_r
        return out

    def __call__(
        self, ws: list[PETSc.Vec], xs: list[PETSc.Vec]
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        r"""(:math:`\hat\rho`, e), (owned rows, vectors): :math:`|\rho - \hat\rho| \le e`."""
        X = self._gather(xs)
        n, r = self.cols.shape[1], len(xs)
        sh = np.column_stack([w.array_r for w in ws]) if r else np.zeros((n, 0))
        sl = np.zeros((n, r))
        total = np.abs(sh)
        xk, p, c, t, xh, xl, e, s2, z = (np.empty((n, r)) for _ in range(9))
        for k in range(self.cols.shape[0]):
            np.take(X, self.cols[k], axis=0, out=xk)
            a, ah, al = self.vals[k][:, None], self.hi[k][:, None], self.lo[k][:, None]
            # TwoProduct (Dekker, Veltkamp's split of xk): p + e = a xk exactly.
            np.multiply(a, xk, out=p)
            np.multiply(xk, _SPLITTER, out=c)
            np.subtract(c, xk, out=t)
            np.subtract(c, t, out=xh)
            np.subtract(xk, xh, out=xl)
            np.multiply(ah, xh, out=t)
            np.subtract(p, t, out=e)
            np.multiply(al, xh, out=t)
            np.subtract(e, t, out=e)
            np.multiply(ah, xl, out=t)
            np.subtract(e, t, out=e)
            np.multiply(al, xl, out=t)
            np.subtract(t, e, out=e)
            # TwoSum (Knuth): s2 + q = sh + p exactly; Dot2: sl = sl + (q + e).
            np.add(sh, p, out=s2)
            np.subtract(s2, sh, out=z)
            np.subtract(s2, z, out=t)
            np.subtract(sh, t, out=t)
            np.subtract(p, z, out=c)
            np.add(t, c, out=t)
            np.add(t, e, out=t)
            np.add(sl, t, out=sl)
            sh, s2 = s2, sh
            np.abs(xk, out=t)
            np.multiply(self.abs_vals[k][:, None], t, out=t)
            np.add(total, t, out=total)
        rho = sh + sl
        # Ogita-Rump-Oishi (Dot2): |res - exact| <= u |exact| + gamma_n^2 sum |terms|; the
        # computed sum of |terms| is itself rounded (a factor 1 + gamma_n covers it).
        m = self.terms
        err = (U * np.abs(rho) + gamma(m) ** 2 * total * (1 + gamma(m + 1))) / (1.0 - U)
        return np.asarray(rho, dtype=np.float64), np.asarray(err, dtype=np.float64)

    def destroy(self) -> None:
        """Destroy the scatter and its work vector."""
        for name in ("_scatter", "_local"):
            obj = getattr(self, name, None)
            if obj is not None:
                obj.destroy()
                setattr(self, name, None)

    def __del__(self) -> None:
        self.destroy()
