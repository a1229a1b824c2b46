r"""Independent thin-plate references for simply supported rectangles (no FEniCSx).

Two discretisations of the Kirchhoff plate :math:`a(w,w) = D\int(\Delta w)^2` (the
Gaussian-curvature term integrates to zero on a simply supported rectangle), under the
prestress :math:`\sigma_x(y)` (tension positive, per unit load) of the loaded edges
x = 0, a, :math:`b(w,w) = -t\int \sigma_x w_{,x}^2`, nothing here shared with the
package:

- :func:`ritz_k`: Ritz with the double sine series
  :math:`w = \sin(m\pi x/a)\sum_n c_n \sin(n\pi y/b)` (exact boundary conditions; the
  modes of different m decouple because :math:`\sigma_x` does not depend on x). This is
  the method of Timoshenko and Gere, *Theory of Elastic Stability*, 1961, section 9.6,
  for in-plane bending; it reproduces their table.
- :func:`fd_unilateral_k`: finite differences (five-point Laplacian with w = 0 on the
  edge, which is the simple support's odd reflection) and a unilateral constraint
  :math:`w \le 0` at every interior node, solved by its own primal-dual active-set loop
  on the reduced pencils (scipy), for the plate against a whole-plate obstacle.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg


def ritz_k(aspect: float, start: float, end: float, terms: int = 40, m_max: int = 8) -> float:
    r"""Buckling coefficient :math:`k = \sigma_{cr} t b^2/(\pi^2 D)` by the sine series.

    Args:
        aspect: a/b.
        start: :math:`\sigma_x` per unit load at y = 0 (tension positive).
        end: :math:`\sigma_x` at y = b.
        terms: Sine terms in y.
        m_max: Half-waves in x tried.
    """
    y, wq = np.polynomial.legendre.leggauss(4 * terms + 40)
    y, wq = 0.5 * (y + 1.0), 0.5 * wq  # b = 1
    sigma = start + (end - start) * y
    n = np.arange(1, terms + 1)
    S = np.sin(np.pi * np.outer(n, y))
    M = (S * sigma * wq) @ S.T  # int sigma sin(n pi y) sin(p pi y) dy
    best = math.inf
    for m in range(1, m_max + 1):
        K = np.diag(aspect / 4.0 * np.pi**4 * ((m / aspect) ** 2 + n.astype(float) ** 2) ** 2)
        G = -((m * np.pi / aspect) ** 2) * (aspect / 2.0) * M  # D = t = 1
        theta = scipy.linalg.eigh(G, K, eigvals_only=True)[-1]
        if theta > 0:
            best = min(best, 1.0 / theta)
    return best / np.pi**2


def _fd_pencil(aspect: float, start: float, end: float, ny: int) -> tuple[sp.csr_matrix, ...]:
    """A, B on the interior nodes of an nx x ny grid of the a x 1 plate (D = t = 1)."""
    nx = round(ny * aspect)
    hx, hy = aspect / nx, 1.0 / ny

    def second(n: int, h: float) -> sp.csr_matrix:
        return sp.diags([1.0, -2.0, 1.0], [-1, 0, 1], shape=(n - 1, n - 1)) / h**2

    Ix, Iy = sp.identity(nx - 1), sp.identity(ny - 1)
    L = sp.kron(Iy, second(nx, hx)) + sp.kron(second(ny, hy), Ix)  # node (i, j) -> j*(nx-1)+i
    A = (hx * hy) * (L.T @ L)
    # Forward differences in x on the nx edges of each row (w = 0 at both ends).
    Dx = sp.diags([-1.0, 1.0], [-1, 0], shape=(nx, nx - 1)) / hx
    y = hy * np.arange(1, ny)
    sigma = start + (end - start) * y
    B = -(hx * hy) * sp.kron(sp.diags(sigma), Dx.T @ Dx)
    return sp.csr_matrix(A), sp.csr_matrix(B)


def _smallest(A: sp.csr_matrix, B: sp.csr_matrix, keep: np.ndarray) -> tuple[float, np.ndarray]:
    Ak, Bk = A[keep][:, keep], B[keep][:, keep]
    # Largest theta of B x = theta A x (B is indefinite under bending): lambda = 1/theta.
    theta, x = scipy.sparse.linalg.eigsh(Bk, k=1, M=Ak.tocsc(), which="LA", tol=1e-12)
    return 1.0 / theta[0], x[:, 0]


def fd_unilateral_k(
    aspect: float, start: float, end: float, ny: int, max_iterations: int = 200
) -> tuple[float, float]:
    r"""(k without obstacle, k with :math:`w \le 0` at every node) by finite differences.

    The active-set loop: remove the contact set Z, take the smallest eigenpair of the
    reduced pencil oriented so that its largest entry off Z is smallest, add the nodes
    where :math:`w_k > 0`, release the nodes of Z where :math:`(Aw - \lambda Bw)_k > 0`
    (the obstacle would pull), until Z repeats (a KKT point).
    """
    A, B = _fd_pencil(aspect, start, end, ny)
    n = A.shape[0]
    free_load, w = _smallest(A, B, np.arange(n))
    tol = 1e-9
    w = w if -w.min() >= w.max() else -w
    active = np.flatnonzero(w > tol * np.abs(w).max())
    seen = set()
    for _ in range(max_iterations):
        keep = np.setdiff1d(np.arange(n), active)
        load, x = _smallest(A, B, keep)
        u = np.zeros(n)
        u[keep] = x
        u = u if u.max() <= -u.min() else -u
        u /= np.abs(u).max()
        r = A @ u - load * (B @ u)
        scale = np.abs(A @ u).max()
        add = keep[u[keep] > tol]
        release = active[r[active] > tol * scale]
        if not add.size and not release.size:
            return free_load / np.pi**2, load / np.pi**2
        key = active.tobytes()
        if key in seen:
            raise RuntimeError("fd_unilateral_k: the active set cycles")
        seen.add(key)
        active = np.union1d(np.setdiff1d(active, release), add)
    raise RuntimeError("fd_unilateral_k: no KKT point within max_iterations")
