r"""Independent thin-plate reference: Kirchhoff plates on bicubic Hermite elements (no FEniCSx).

A rectangle :math:`[0, a] \times [0, b]` on a uniform grid of Bogner–Fox–Schmit elements
(the tensor product of the cubic Hermite beam element: DOFs :math:`w, w_{,x}, w_{,y},
w_{,xy}` at each node; C¹, so it is a conforming Kirchhoff element and its eigenvalues
converge at rate :math:`h^4`). With :math:`w = \sum c_{IJ} \phi_I(x) \psi_J(y)` every
integral over the rectangle is a Kronecker product of one-dimensional Hermite matrices
:math:`X_{pq} = \int \phi_I^{(p)} \phi_K^{(q)}\,dx`:

.. math::

    a(w,w) = D_{11}\int w_{,xx}^2 + 2D_{12}\int w_{,xx}w_{,yy} + D_{22}\int w_{,yy}^2
           + 4D_{66}\int w_{,xy}^2 + \sum_{edges}\int k_r w_{,n}^2 + k_t w^2
           + \sum_{points} k_p w(p)^2 - \int N^{fix}_{\alpha\beta} w_{,\alpha} w_{,\beta},

    b(w,w) = -\int N_{\alpha\beta} w_{,\alpha} w_{,\beta}

(specially orthotropic bending; isotropic :math:`D_{11} = D_{22} = D`, :math:`D_{12} = \nu
D`, :math:`D_{66} = (1-\nu)D/2`; uniform membrane forces). A simple support removes the
value DOFs of the edge (w = 0 along it implies :math:`w_{,s} = 0`), a clamped edge also
the normal slope; "free" removes nothing. Point restraints act on the nodal value DOF.
The obstacle :math:`w \le 0` (or :math:`\ge 0`) holds at the grid nodes of a mask, on
the nodal values, which are DOFs. The unilateral critical load is found by a primal–dual
active-set loop on the reduced pencils (scipy) started from the free mode; each result
is checked to be a KKT point. Nothing here is shared with the package (its element is
Reissner–Mindlin MITC4 on Q1; this one is Kirchhoff, C¹ cubic): for t/b = 1e-3 the two
models differ by about 1e-5 relative.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg

EDGES = ("left", "right", "bottom", "top")


def _hermite(n: int, length: float) -> dict[tuple[int, int], sp.csr_matrix]:
    """Global 1-D matrices X_pq = int phi^(p) phi^(q), p, q in 0..2, of n cubic elements.

    DOFs (value, slope) at nodes 0..n, ordered 2 k (value), 2 k + 1 (slope).
    """
    h = length / n
    xi, wq = np.polynomial.legendre.leggauss(5)
    xi, wq = 0.5 * (xi + 1.0), 0.5 * wq * h

    def shapes(s: np.ndarray) -> list[np.ndarray]:
        # derivative order 0, 1, 2 with respect to x of the four cubic Hermite functions
        n0 = [
            1 - 3 * s**2 + 2 * s**3,
            h * (s - 2 * s**2 + s**3),
            3 * s**2 - 2 * s**3,
            h * (s**3 - s**2),
        ]
        n1 = [
            (-6 * s + 6 * s**2) / h,
            1 - 4 * s + 3 * s**2,
            (6 * s - 6 * s**2) / h,
            3 * s**2 - 2 * s,
        ]
        n2 = [(-6 + 12 * s) / h**2, (-4 + 6 * s) / h, (6 - 12 * s) / h**2, (6 * s - 2) / h]
        return [np.array(n0), np.array(n1), np.array(n2)]

    f = shapes(xi)
    out = {}
    size = 2 * (n + 1)
    for p in range(3):
        for q in range(3):
            local = (f[p] * wq) @ f[q].T
            M = sp.lil_matrix((size, size))
            for e in range(n):
                dofs = np.arange(2 * e, 2 * e + 4)
                M[np.ix_(dofs, dofs)] += local
            out[p, q] = M.tocsr()
    return out


@dataclass
class HermitePlate:
    r"""A Kirchhoff plate a x b on nx x ny Bogner–Fox–Schmit elements.

    Args:
        a, b: Sides (x, y).
        nx, ny: Elements.
        bending: (D11, D12, D22, D66) in N m.
        supports: Edge -> "ss", "clamped" or "free" (missing: "ss").
        rotational: Edge -> k_r (N) on the normal slope.
        translational: Edge -> k_t (N/m^2).
        membrane: Uniform (N_xx, N_yy, N_xy) per unit load (N/m, tension > 0): b's.
        fixed: Uniform (N_xx, N_yy, N_xy) applied as is (N/m): moved into a.
    """

    a: float
    b: float
    nx: int
    ny: int
    bending: tuple[float, float, float, float]
    supports: dict[str, str] = field(default_factory=dict)
    rotational: dict[str, float] = field(default_factory=dict)
    translational: dict[str, float] = field(default_factory=dict)
    membrane: tuple[float, float, float] = (-1.0, 0.0, 0.0)
    fixed: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        X, Y = _hermite(self.nx, self.a), _hermite(self.ny, self.b)
        D11, D12, D22, D66 = self.bending
        kron = sp.kron
        A = (
            D11 * kron(X[2, 2], Y[0, 0])
            + D12 * (kron(X[2, 0], Y[0, 2]) + kron(X[0, 2], Y[2, 0]))
            + D22 * kron(X[0, 0], Y[2, 2])
            + 4 * D66 * kron(X[1, 1], Y[1, 1])
        )

        def geometric(N: tuple[float, float, float]) -> sp.csr_matrix:
            Nxx, Nyy, Nxy = N
            return -(
                Nxx * kron(X[1, 1], Y[0, 0])
                + Nyy * kron(X[0, 0], Y[1, 1])
                + Nxy * (kron(X[1, 0], Y[0, 1]) + kron(X[0, 1], Y[1, 0]))
            )

        self.ndx, self.ndy = 2 * (self.nx + 1), 2 * (self.ny + 1)
        ex = {"left": 0, "right": 2 * self.nx}  # value DOF of the edge node in x
        ey = {"bottom": 0, "top": 2 * self.ny}
        for edge in EDGES:
            for k, value in (
                (1, self.rotational.get(edge, 0.0)),
                (0, self.translational.get(edge, 0.0)),
            ):
                if not value:
                    continue
                # k = 1: the normal slope DOF of the edge node; 0: its value DOF.
                if edge in ex:
                    e = sp.csr_matrix(
                        ([1.0], ([ex[edge] + k], [ex[edge] + k])), shape=(self.ndx,) * 2
                    )
                    A = A + value * kron(e, Y[0, 0])
                else:
                    e = sp.csr_matrix(
                        ([1.0], ([ey[edge] + k], [ey[edge] + k])), shape=(self.ndy,) * 2
                    )
                    A = A + value * kron(X[0, 0], e)
        self.A = sp.csr_matrix(A + geometric(self.fixed))
        self.B = sp.csr_matrix(geometric(self.membrane))
        removed = set()
        for edge in EDGES:
            support = self.supports.get(edge, "ss")
            slopes = (0,) if support == "ss" else (0, 1) if support == "clamped" else ()
            for k in slopes:
                if edge in ex:
                    removed |= {self.index(ex[edge] + k, j) for j in range(self.ndy)}
                else:
                    removed |= {self.index(i, ey[edge] + k) for i in range(self.ndx)}
        self.keep = np.setdiff1d(np.arange(self.ndx * self.ndy), sorted(removed))

    def index(self, i: int, j: int) -> int:
        """Global DOF of x-DOF i and y-DOF j."""
        return i * self.ndy + j

    def node_dof(self, p: int, q: int) -> int:
        """The value DOF of grid node (p, q) (x_p = p a/nx, y_q = q b/ny)."""
        return self.index(2 * p, 2 * q)

    def add_point_springs(self, nodes: list[tuple[int, int]], stiffness: float) -> None:
        """Springs k_p w(p)^2 at grid nodes."""
        d = np.zeros(self.A.shape[0])
        for p, q in nodes:
            d[self.node_dof(p, q)] += stiffness
        self.A = sp.csr_matrix(self.A + sp.diags(d))

    def fix_points(self, nodes: list[tuple[int, int]]) -> None:
        """Fix w = 0 at grid nodes (bilateral point restraints)."""
        self.keep = np.setdiff1d(self.keep, [self.node_dof(p, q) for p, q in nodes])

    def free_load(self) -> float:
        """Smallest positive load factor without obstacle."""
        return _smallest(self.A, self.B, self.keep)[0]

    def unilateral_load(
        self,
        mask: np.ndarray | None = None,
        sign: float = 1.0,
        tol: float = 1e-9,
        max_iterations: int = 400,
    ) -> tuple[float, np.ndarray]:
        r"""(load, contact nodes) with :math:`s\,w \le 0` at the nodes of ``mask`` ((nx+1, ny+1)).

        Default mask: every node with a free value DOF. A primal-dual active set: remove
        Z, orient the reduced mode to violate least, add the violating nodes, release the
        nodes where the obstacle pulls (:math:`s(Aw - \lambda Bw)_k > 0`), until Z
        repeats; once a set recurs (a cycle), only the most pulling node is released per
        step. The answer is checked to be a KKT point.
        """
        grid = np.array(
            [[self.node_dof(p, q) for q in range(self.ny + 1)] for p in range(self.nx + 1)]
        )
        if mask is None:
            mask = np.ones(grid.shape, dtype=bool)
        nodes = np.intersect1d(grid[mask], self.keep)
        n = self.A.shape[0]
        free_load, w = _smallest(self.A, self.B, self.keep)
        u = np.zeros(n)
        u[self.keep] = w
        z = sign * u[nodes]
        z = z if z.max() <= -z.min() else -z
        active = nodes[z > tol * np.abs(z).max()]
        seen: set[bytes] = set()
        cautious = False
        for _ in range(max_iterations):
            keep = np.setdiff1d(self.keep, active)
            load, x = _smallest(self.A, self.B, keep, below=free_load)
            u = np.zeros(n)
            u[keep] = x
            z = sign * u[nodes]
            if z.max() > -z.min():
                u, z = -u, -z
            u /= np.abs(u).max()
            z = sign * u[nodes]
            r = sign * (self.A @ u - load * (self.B @ u))
            scale = np.abs(self.A @ u).max()
            free = np.setdiff1d(nodes, active)
            add = free[sign * u[free] > tol]
            release = active[r[active] > tol * scale]
            if not add.size and not release.size:
                assert np.all(z <= tol) and np.all(r[active] <= tol * scale)
                return load, active
            key = np.sort(active).tobytes()
            if key in seen:
                if cautious:
                    raise RuntimeError("HermitePlate.unilateral_load: the active set cycles")
                cautious, seen = True, set()  # from now on release one node per step
            seen.add(key)
            if cautious and release.size:
                release = release[[np.argmax(r[release])]]
            active = np.union1d(np.setdiff1d(active, release), add)
        raise RuntimeError("HermitePlate.unilateral_load: no KKT point within max_iterations")


def _smallest(
    A: sp.csr_matrix, B: sp.csr_matrix, keep: np.ndarray, below: float | None = None
) -> tuple[float, np.ndarray]:
    """Smallest positive lambda of A x = lambda B x on the DOFs ``keep`` (A SPD there).

    ``below``: a load known to lie below it (interlacing: the free load), used as the
    shift of ARPACK's buckling mode; otherwise the largest theta of B x = theta A x.
    """
    Ak, Bk = A[keep][:, keep].tocsc(), B[keep][:, keep].tocsc()
    if below is None:
        theta, x = scipy.sparse.linalg.eigsh(Bk, k=1, M=Ak, which="LA", tol=1e-13, ncv=20)
        return 1.0 / theta[0], x[:, 0]
    # Buckling mode: nu = lambda/(lambda - sigma); with sigma below every positive
    # lambda the largest nu is the smallest lambda above sigma.
    lam, x = scipy.sparse.linalg.eigsh(
        Ak, k=1, M=Bk, sigma=0.95 * below, mode="buckling", which="LA", tol=1e-13, ncv=20
    )
    return float(lam[0]), x[:, 0]


def isotropic(E: float, nu: float, t: float) -> tuple[float, float, float, float]:
    """(D11, D12, D22, D66) of an isotropic plate."""
    D = E * t**3 / (12 * (1 - nu**2))
    return (D, nu * D, D, (1 - nu) * D / 2)
