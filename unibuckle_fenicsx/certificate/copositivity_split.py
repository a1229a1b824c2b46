r"""Copositivity by splitting the cone along the pencil's negative space (m >= 2 below the load).

Let :math:`K = K(\lambda) = A - \lambda B` have m negative eigenvalues (one sparse
:math:`LDL^T`), and let W hold m vectors with :math:`G_W = W^TK^{-1}W` negative definite
(:math:`W = B\Psi`, :math:`\Psi` approximate pencil modes below :math:`\lambda`, scaled
so that :math:`G_W \approx -I`). Every mode u splits into its part in the negative space,
:math:`z = W^Tu \in \mathbb{R}^m`, and the rest. The z-space is covered by simplicial
cones (*pieces*) cone(V), starting from the :math:`2^m` orthants and bisecting edges at
dyadic midpoints (exact in binary), so that the pieces cover :math:`\mathbb{R}^m` exactly.

**One piece.** Let :math:`M\mu_1, \dots, M\mu_k` be nonnegative combinations of the
*columns* M (vectors on the constrained nodes I, nonnegative there in oriented values,
zero elsewhere), :math:`C = [W, M\mu_1 \dots M\mu_k]` and :math:`G_1 = C^TK^{-1}C`
(its entries are combinations of those of :math:`G = [W, M]^TK^{-1}[W, M]`). If
:math:`G_1` has exactly m negative eigenvalues and no zero one, K is positive definite on
:math:`\ker C^T` and :math:`\min\{u^TKu : C^Tu = (z, y)\} = (z, y)^TG_1^{-1}(z, y)`
(:mod:`~unibuckle_fenicsx.certificate.copositivity_lowrank`). An admissible mode
(:math:`u_I \le 0`) with :math:`z \in` cone(V) has :math:`z = V\alpha`, :math:`\alpha
\ge 0`, and :math:`y = (M\mu_j)^Tu \le 0`, so

.. math::

    u^TKu \ \ge\ (\alpha, -y)^T\, T^TG_1^{-1}T\, (\alpha, -y), \qquad
    T = \begin{pmatrix} V & 0 \\ 0 & -I_k \end{pmatrix},

and an SPN decomposition :math:`T^TG_1^{-1}T - N \succ 0`, :math:`N \ge 0` (an
(m + k)-sized semidefinite program), shows the right side nonnegative. The SDP's N is
clipped and checked through the bordered matrix :math:`[[-G_1, T], [T^T, -N]]`
(Haynsworth: it must have exactly k negative eigenvalues, none near zero), with Weyl's
theorem and a rigorous bound on the error of :math:`G_1`: nothing the SDP returns is
trusted, and no inverse is formed in the proof. All pieces proven: no admissible mode has
a load below :math:`\lambda`.

**Which combinations.** At a direction z, the best bound of the relaxation that keeps
:math:`M^Tu \le 0` is the dual
:math:`\max_{\mu \ge 0} z^TS_Wz + (\mu^Tc)_+^2/\mu^TH\mu` with :math:`S_W = G_W^{-1}`,
:math:`c = G_{MW}S_Wz` and :math:`H = G_{MM} - G_{MW}S_WG_{WM}` (Lawson-Hanson on the
Gram form): its :math:`\mu` is the contact reaction, made of columns, of the least-energy
mode there. A piece is tried with the :math:`\mu` of its centre, then with those of the
points where the check fails, then with its generators' :math:`\mu` and a multiplier
interpolated linearly between them (exact within one active set of the relaxation, so
the piece need not lie in one cap), else bisected. Where even the dual is negative, the
relaxed minimiser :math:`u = K^{-1}C(\ldots)` crosses the obstacle: its part that does
becomes a new column (a cut), with the translates of the reaction's pieces that best
cover it; and if u, or u with its crossing part clipped, is admissible with a load below
the KKT point's, that point is *refuted* and the mode handed back.

**Columns.** A long plate's critical modes are families of nearly equal buckles
translated along it; their contact reactions are the KKT point's reaction translated and
mirrored. The columns are: the reaction along one line of nodes across the plate, placed
on every such line (a buckle's touch-down line anywhere); the reaction, its clusters
(touch-down lines) and their mirror images; the reactions of the other KKT points met;
then cuts and translated clusters where the check asks for them. (The low-rank route,
:mod:`~unibuckle_fenicsx.certificate.copositivity_lowrank`, uses a few columns for the
whole cone and splits the r-dimensional orthant; here the split is m-dimensional, m = 2
to 4, and each piece needs only the few columns of its own buckles.)

**Rounding.** Each solve is batched (``MatMatSolve``); the residual
:math:`\rho = u - Kx` is computed in double precision with the bound
:math:`\gamma_{m}(|u| + |K||x|)`, and each entry of G is
:math:`u_a^Tx_b + x_a^T\rho_b` with the error bound of both products, plus
:math:`\|K^{-1}\rho_a\|\,\|\,|\rho_b| + e_b\|` for the second-order term (one more
batched solve; estimated, as in the other routes). On thin plates these bounds are
about 1e-6 of G, nearly all of it the residual's rounding; the pieces' margins at
relative distances :math:`\delta \ge 10^{-3}` are far larger. On request
(``SplitOptions.accurate``, with ``--bracket``) the residual is computed in twice the
working precision (:class:`~unibuckle_fenicsx.certificate.accurate.AccurateResidual`),
and the bounds fall to about 1e-9 of G.

Hand-written (no library tests copositivity of large structured matrices); the SDPs are
Clarabel's (the ``sdp`` extra), the dense algebra NumPy/SciPy's.

Note:
    Collective on the problem's communicator. The dense programs run on every rank with
    identical data.
"""

from __future__ import annotations

import hashlib
import itertools
import math
from dataclasses import dataclass, field
from typing import Any

from mpi4py import MPI

import msgspec
import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.certificate.accurate import AccurateResidual, gamma
from unibuckle_fenicsx.certificate.accurate import U as UNIT_ROUNDOFF
from unibuckle_fenicsx.certificate.copositivity_lowrank import (
    LowRankOutcome,
    _check_piece,
    _halves,
    _inertia,
    _pow2,
    _simplex_min,
    _spn,
    _starts,
    factor_at,
    search_deltas,
)
from unibuckle_fenicsx.certificate.records import (
    LowRankAttempt,
    Refuting,
    SplitAttempt,
    SplitRecord,
)
from unibuckle_fenicsx.certificate.shifted import ShiftedMatrix, mirror_maps, rayleigh
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem

__all__ = ["Sources", "SplitOptions", "SplitOutcome", "column_sources", "estimate_cost",
           "split_certificate"]  # fmt: skip

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class SplitOptions:
    r"""Budgets and tolerances of the split route.

    Attributes:
        deltas: Relative distances below the load tried in this order while they are
            verified (one factorisation each); the gap reported is the last verified.
        fallback: Tried in this order when the first of ``deltas`` fails.
        next_margin: After a verified delta the next one is tried only if every piece's
            verified margin (eigenvalue over error bound) was at least this: the margins
            shrink about as delta does, so a smaller one would fail on rounding (None:
            always try it).
        max_rounding: An attempt stops after this many pieces failed on rounding only
            (verified margin between 0 and 1: the bound on G's error, not the form, is
            what fails; a smaller piece does not help).
        max_columns: Columns (without the m negative-space vectors) at most: each costs
            two right-hand sides of a batched solve per delta.
        max_rounds: Rounds of new columns (cuts and translates) per delta.
        per_round: New columns per round at most.
        max_pieces: Pieces of the z-space examined per delta.
        max_combinations: Combinations :math:`\mu` tried on one piece before it is split.
        sdp_depth: Pieces bisected this many times get the SPN program too (Clarabel;
            larger ones are split instead: the program and its import cost more), with
            the columns of the combinations met, each on its own.
        max_individual: ... at most this many of them (the heaviest).
        mode_iterations: Block inverse iterations for the negative space (each one batched
            solve of m + 3 right-hand sides); more are run while fewer than m Ritz values lie
            below the shift.
        margin_factor: The inertia counts need every eigenvalue this many times beyond its
            error bound.
        max_cost: The route runs only when :func:`estimate_cost` (in free eigen solves,
            from counts: the answer does not depend on the machine) is at most this;
            None: always.
        line_fraction: A translate of the reaction's line is kept when it keeps this
            fraction of its weight on the zone.
        line_share: The lines are used when the reaction's heaviest line carries this
            fraction of its heaviest cluster (a straight touch-down across the plate).
        clip_fraction: ... and of a cluster, this fraction (an inclined touch-down line
            cut by the plate's end is still one).
        line_extent: Clusters spanning more lines than this along the plate are placed at
            every translation from the start (the lines do not describe them).
        interpolate: A piece no single cap holds is tried with its generators' multipliers
            interpolated linearly over it before it is split (:func:`_interpolated`): exact
            within one active set of the relaxation, so larger pieces are proven (on by
            default: fewer pieces on the plates with m >= 3).
        accurate: The residuals K x - u of the columns in twice the working precision
            (:class:`~unibuckle_fenicsx.certificate.accurate.AccurateResidual`, Dot2), as
            the low-rank route's: on thin plates the double-precision residual's rounding
            is the whole of G's error bound, and it stops the smaller distances (on by
            request, ``--bracket``: it costs about as much as the batched solves).
    """

    deltas: tuple[float, ...] = (1e-3, 1e-4)
    fallback: tuple[float, ...] = (1e-2,)
    next_margin: float | None = 20.0
    max_rounding: int = 24
    max_columns: int = 360
    max_rounds: int = 8
    per_round: int = 12
    max_pieces: int = 400
    max_combinations: int = 4
    sdp_depth: int = 6
    max_individual: int = 10
    mode_iterations: int = 4
    margin_factor: float = 2.0
    max_cost: float | None = 3.0
    line_fraction: float = 0.5
    line_share: float = 0.25
    clip_fraction: float = 0.1
    line_extent: int = 4
    interpolate: bool = True
    accurate: bool = False

    @classmethod
    def thorough(cls) -> SplitOptions:
        """On request (``solver.bracket``): down to 1e-6, larger budgets, no cost limit.

        And the residuals in twice the working precision (``accurate``).
        """
        return cls(deltas=(1e-3, 1e-4, 1e-5, 1e-6), fallback=(1e-2,), next_margin=None,
                   max_columns=480, max_rounds=16, max_pieces=1000, max_cost=None,
                   accurate=True)  # fmt: skip


@dataclass
class SplitOutcome(LowRankOutcome):
    """What the split route found.

    The low-rank route's record (value, delta, m, columns r, pieces, margin, attempts,
    why, refuting mode, right-hand sides solved), plus the estimated cost
    (:func:`estimate_cost`, when the caller computed it), whether the route was
    skipped for it (``skipped``: not run by default) and the limit it was held to
    (``cost_limit``, ``SplitOptions.max_cost``; None: none).
    """

    estimated_cost: float | None = None
    skipped: bool = False
    cost_limit: float | None = None

    def record(self) -> SplitRecord:
        """The route's record (without the refuting mode's vector)."""
        return SplitRecord(
            **msgspec.structs.asdict(super().record()),
            solves=self.solves,
            estimated_cost=self.estimated_cost,
            skipped=self.skipped,
            cost_limit=self.cost_limit,
        )


# -- the columns and their Gram matrix ----------------------------------------------------
class Basis:
    """Columns [W | M] (owned rows), their solves, and G = [W, M]^T K^-1 [W, M] with a bound.

    The first m columns are the negative-space vectors W; the others are nonnegative on
    I (oriented) and zero elsewhere. ``values`` keeps each M column's oriented values on I.
    With ``accurate`` the residuals are computed in twice the working precision (Dot2;
    the matrix must not change while the basis lives); the owner must :meth:`destroy` it.
    """

    def __init__(
        self,
        problem: UnilateralProblem,
        matrix: ShiftedMatrix,
        m: int,
        capacity: int,
        accurate: bool = False,
    ) -> None:
        self.problem, self.matrix, self.m = problem, matrix, m
        self._residual: AccurateResidual | None = None
        if accurate:
            if matrix.K is None:
                raise RuntimeError("Basis: the matrix is not factorised (an internal invariant)")
            self._residual = AccurateResidual(matrix.K)
        self.comm = problem.comm
        self.n = problem.model.A.getSize()[0]
        nloc = problem.model.A.getLocalSize()[0]
        # Column storage, allocated once (Fortran order: PETSc's dense layout).
        self._store = {
            name: np.zeros((nloc, capacity), order="F") for name in ("U", "X", "rho", "err")
        }
        self.q = 0
        self.dnorm = np.zeros(0)
        self.G = np.zeros((0, 0))
        self.E = np.zeros((0, 0))
        self._abs: Array | None = None
        self.names: list[str] = []
        self.values: list[Array] = []

    @property
    def X(self) -> Array:
        """The solves K^-1 [W, M] (owned rows)."""
        return self._store["X"][:, : self.q]

    @property
    def absG(self) -> Array:
        """|G| (kept until the columns change)."""
        if self._abs is None or self._abs.shape != self.G.shape:
            self._abs = np.abs(self.G)
        return self._abs

    @property
    def r(self) -> int:
        """Columns of M."""
        return len(self.names) - self.m

    @property
    def room(self) -> int:
        """Columns that can still be added."""
        return int(self._store["U"].shape[1]) - self.q

    def _sum(self, local: Array) -> Array:
        return np.asarray(self.comm.allreduce(local, op=MPI.SUM), dtype=np.float64)

    def add(self, columns: Array, names: list[str], values: list[Array] | None = None) -> None:
        """Solve for the new columns (owned rows) and extend G and its error bound E."""
        k = min(columns.shape[1], self.room)
        if k == 0:
            return
        new = slice(self.q, self.q + k)
        U, X, rho, err = (self._store[name] for name in ("U", "X", "rho", "err"))
        U[:, new] = columns[:, :k]
        X[:, new] = self.matrix.solve_block(U[:, new])
        if self._residual is not None:
            rho[:, new], err[:, new] = self._accurate(U[:, new], X[:, new])
        else:
            KX, KX_abs = self.matrix.multiply_block(X[:, new])
            np.subtract(U[:, new], KX, out=rho[:, new])
            rows = self.matrix.row_length + 1
            err[:, new] = (gamma(rows) * (np.abs(U[:, new]) + KX_abs) + UNIT_ROUNDOFF
                           * np.abs(rho[:, new])) * (1 + 2 * gamma(rows + 1))  # fmt: skip
            del KX, KX_abs
        D = self.matrix.solve_block(rho[:, new])
        dnorm = np.sqrt(self._sum((D * D).sum(axis=0)))
        del D
        self.q += k
        self.dnorm = np.concatenate([self.dnorm, dnorm])
        self.names += names[:k]
        if values is not None:
            self.values += values[:k]
        self._extend(k)

    def _accurate(self, U: Array, X: Array) -> tuple[Array, Array]:
        r"""(:math:`\hat\rho`, e) of columns U, solves X: :math:`|u - Kx - \hat\rho| \le e`."""
        assert self._residual is not None
        A = self.problem.model.A
        ws = [A.createVecRight() for _ in range(U.shape[1])]
        xs = [A.createVecRight() for _ in range(U.shape[1])]
        try:
            for j, (w, x) in enumerate(zip(ws, xs, strict=True)):
                w.array[:], x.array[:] = U[:, j], X[:, j]
            return self._residual(ws, xs)
        finally:
            for v in (*ws, *xs):
                v.destroy()

    def destroy(self) -> None:
        """Destroy the accurate residual's scatter (if any)."""
        if self._residual is not None:
            self._residual.destroy()
            self._residual = None

    def _extend(self, k: int) -> None:
        r"""The new k rows and columns of G and E.

        For every a and each new b, :math:`G_{ab} = u_a^Tx_b + x_a^T\rho_b` (the exact
        :math:`u_a^TK^{-1}u_b` up to the second-order term) with the bound
        :math:`|x_a|^Te_b` (the residual's rounding) +
        :math:`\|K^{-1}\rho_a\|\,\|\,|\rho_b| + e_b\|` (second order) +
        :math:`\gamma_n(\|u_a\|\|x_b\| + \|x_a\|\|\rho_b\|)` (the two dot products,
        by Cauchy-Schwarz); the exact G is symmetric, so (b, a) takes the same.
        """
        q = self.q
        old = q - k
        new = slice(old, q)
        U, X, rho, err = (self._store[name][:, :q] for name in ("U", "X", "rho", "err"))
        local = np.stack([U.T @ X[:, new] + X.T @ rho[:, new], np.abs(X).T @ err[:, new]])
        norms = np.stack([(U * U).sum(axis=0), (X * X).sum(axis=0), (rho * rho).sum(axis=0),
                          ((np.abs(rho) + err) ** 2).sum(axis=0)])  # fmt: skip
        s = self._sum(local)
        nu, nx, nr, nre = np.sqrt(self._sum(norms))
        g = gamma(self.n + 2)
        value = s[0]
        bound = (
            s[1]
            + np.outer(self.dnorm, nre[new])
            + g * (np.outer(nu, nx[new]) + np.outer(nx, nr[new]))
            + UNIT_ROUNDOFF * np.abs(value)
        ) * (1 + 4 * g)
        G = np.zeros((q, q))
        E = np.zeros((q, q))
        G[:old, :old], E[:old, :old] = self.G, self.E
        G[:, new], E[:, new] = value, bound
        G[new, :], E[new, :] = value.T, bound.T
        # new-new block: (a, b) and (b, a) were both computed; keep one of each pair
        block, eblock = value[new], bound[new]
        G[new, new] = np.triu(block) + np.triu(block, 1).T
        E[new, new] = np.triu(eblock) + np.triu(eblock, 1).T
        self.G, self.E = G, E


# -- the negative space -------------------------------------------------------------------
def _block_product(mat: Any, X: Array) -> Array:
    """Mat X for a PETSc AIJ ``mat`` and the columns of X (owned rows)."""
    dense = _dense_like(mat, X)
    try:
        out = mat.matMult(dense)
        values = np.array(out.getDenseArray(), dtype=np.float64)
        out.destroy()
        return values
    finally:
        dense.destroy()


def _dense_like(mat: Any, values: Array) -> Any:
    from petsc4py import PETSc

    dense = PETSc.Mat().createDense(
        (mat.getSizes()[0], (PETSc.DECIDE, values.shape[1])), comm=mat.getComm()
    )
    dense.setUp()
    dense.getDenseArray()[:] = values
    dense.assemble()
    return dense


def negative_space(
    problem: UnilateralProblem,
    matrix: ShiftedMatrix,
    lam: float,
    m: int,
    start: Array | None,
    iterations: int,
) -> tuple[Array, Array, Array] | None:
    r"""(Ritz vectors :math:`\Psi`, their loads, the block to restart from) below ``lam``.

    Block inverse iteration :math:`V \leftarrow K^{-1}BV` with the factorised K (block
    m + 3, from the free mode, ``start`` and seeded random vectors), orthonormalised by
    Cholesky QR, then Rayleigh-Ritz on (A, B) (A-orthonormal Ritz vectors); more
    iterations (up to three times ``iterations``; checked after the first when ``start``
    is given) while fewer than m Ritz values lie below ``lam``. None if they never do.
    Heuristic only: the certificate checks whatever W it gets.
    """
    comm = problem.comm
    A, B = problem.model.A, problem.model.B
    width = m + 3
    free = problem.solve_free().function.x.petsc_vec.array_r.copy()
    cols = [free[:, None]]
    if start is not None:
        cols.append(start)
    # Seeded per global row: the same start on every partition.
    lo, hi = A.getOwnershipRange()
    noise = np.random.default_rng(20260611).standard_normal((A.getSize()[0], width))[lo:hi]
    V = np.hstack([*cols, noise])[:, :width]

    def orthonormal(V: Array) -> Array:
        for _ in range(2):  # Cholesky QR twice: orthonormal to rounding
            gram = np.asarray(comm.allreduce(V.T @ V, op=MPI.SUM))
            gram = 0.5 * (gram + gram.T)
            w, Q = np.linalg.eigh(gram)
            keep = w > w.max() * 1e-13
            V = V @ (Q[:, keep] / np.sqrt(w[keep]))
        return V

    V = orthonormal(V)
    checked = 1 if start is not None else iterations  # a previous block is nearly there
    for it in range(3 * iterations):
        V = orthonormal(matrix.solve_block(_block_product(B, V)))
        if it + 1 < checked:
            continue
        AV, BV = _block_product(A, V), _block_product(B, V)
        Am = np.asarray(comm.allreduce(V.T @ AV, op=MPI.SUM))
        Bm = np.asarray(comm.allreduce(V.T @ BV, op=MPI.SUM))
        try:  # B V = mu A V on the block (A is positive definite): theta = 1/mu
            L = np.linalg.cholesky(0.5 * (Am + Am.T))
        except np.linalg.LinAlgError:
            return None
        Li = np.linalg.inv(L)
        mu, Yc = np.linalg.eigh(Li @ (0.5 * (Bm + Bm.T)) @ Li.T)
        Y = Li.T @ Yc  # A-orthonormal Ritz vectors
        with np.errstate(divide="ignore"):
            theta = np.where(mu > 0, 1.0 / mu, np.inf)
        below = np.flatnonzero(theta < lam)
        if below.size == m:
            return V @ Y[:, below], theta[below], V @ Y
        if below.size > m:
            return None
    return None


# -- translations of patterns on the zone --------------------------------------------------
class Patterns:
    """Constrained nodes, the plate's long axis and translations of node patterns along it.

    Nodes are keyed by their coordinates in quarter node spacings (a translation by k
    spacings maps a node onto the node whose key is k spacings further, if there is one).
    """

    def __init__(self, problem: UnilateralProblem) -> None:
        self.xy = problem.contact.coordinates
        (x0, y0), (x1, y1) = problem.spec.plate.corners
        self.axis = 0 if (x1 - x0) >= (y1 - y0) else 1
        along = np.unique(np.round(self.xy[:, self.axis], 12))
        steps = np.diff(along)
        self.h = float(np.median(steps)) if steps.size else 0.0
        unit = 0.25 * self.h if self.h > 0 else 1.0
        self.keys = np.round(self.xy / unit).astype(np.int64)
        span = self.keys.max(axis=0) - self.keys.min(axis=0) + 1 if len(self.xy) else np.ones(2)
        self._stride = int(span[1]) + 8
        code = self._code(self.keys)
        self._order = np.argsort(code)
        self._sorted = code[self._order]
        self.lines = np.round((self.xy[:, self.axis] - (along[0] if along.size else 0.0))
                              / (self.h if self.h > 0 else 1.0)).astype(np.int64)  # fmt: skip
        self.mirrors = mirror_maps(problem)

    def _code(self, keys: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
        return np.asarray(keys[:, 0] * self._stride + keys[:, 1], dtype=np.int64)

    def translate(self, values: Array, k: int) -> Array:
        """``values`` moved by k node spacings along the long axis (nodes off the zone dropped).

        Only the nonzero entries are looked up (a line across the plate, a buckle's
        touch-down): a translation costs their number, and no map of a shift is kept
        (one for every shift would grow as the nodes times the lines along the plate).
        """
        src = np.flatnonzero(values)
        keys = self.keys[src]
        keys[:, self.axis] += 4 * k
        code = self._code(keys)
        size = len(self._sorted)
        pos = np.clip(np.searchsorted(self._sorted, code), 0, max(size - 1, 0))
        ok = self._sorted[pos] == code if size else np.zeros(len(code), dtype=bool)
        out = np.zeros_like(values)
        out[self._order[pos[ok]]] = values[src[ok]]
        return out

    def shifts(self) -> range:
        """Every translation that keeps some node on the zone."""
        span = int(self.lines.max() - self.lines.min()) if self.lines.size else 0
        return range(-span, span + 1)

    def clusters(self, values: Array) -> list[Array]:
        """The connected pieces of ``values``'s support, largest first.

        Nodes within 1.5 spacings of each other (along and across the plate) are connected.
        """
        support = np.flatnonzero(values > 1e-3 * values.max(initial=0.0))
        if support.size == 0 or self.h <= 0:
            return []
        keys = self.keys[support]
        near = np.abs(keys[:, None, :] - keys[None, :, :]).max(axis=2) <= 6
        label = np.arange(support.size)
        while True:  # each node takes the least label of its neighbours, until none changes
            lowest = np.where(near, label[None, :], support.size).min(axis=1)
            if np.array_equal(lowest, label):
                break
            label = lowest
        out = []
        for lab in np.unique(label):
            part = np.zeros_like(values)
            members = support[label == lab]
            part[members] = values[members]
            out.append(part)
        out.sort(key=lambda v: -float(v.sum()))
        return out

    def extent(self, values: Array) -> int:
        """Lines across the plate that ``values``'s support spans (along the long axis)."""
        lines = self.lines[values > 0]
        return int(lines.max() - lines.min()) + 1 if lines.size else 0

    def line_profile(self, values: Array) -> Array:
        """``values`` on the line of nodes across the plate that carries most of it."""
        sums = np.bincount(self.lines - self.lines.min(), weights=values)
        best = int(np.argmax(sums)) + int(self.lines.min())
        return np.where(self.lines == best, values, 0.0)


def _reaction(candidate: Candidate) -> Array:
    w = np.maximum(0.0, -candidate.forces)
    top = float(w.max(initial=0.0))
    return w / top if top > 0 else w


def _sources(
    patterns: Patterns, candidate: Candidate, others: list[Candidate], opts: SplitOptions
) -> tuple[list[tuple[str, Array]], list[tuple[str, Array]]]:
    """(first columns, patterns to translate on demand), as oriented values on I.

    The reaction's line across the plate at every line; the reaction, its clusters and
    their mirror images; a cluster that spans more than a few lines along the plate (an
    inclined or curved touch-down) at every translation too; the other KKT points'
    reactions.
    """
    w = _reaction(candidate)
    first = _First(opts.max_columns)
    movable: list[tuple[str, Array]] = []
    if w.max(initial=0.0) > 0:
        first.add("reaction", w)
        _translates(patterns, w, opts, first)
        images = [("", w)] + [(f"mirror-{n}-", w[p]) for n, p in patterns.mirrors.items()]
        for name, image in images:
            if name:
                first.add(f"{name}reaction", image)
            for j, part in enumerate(patterns.clusters(image)):
                label = f"{name}cluster{j}"
                first.add(label, part)
                movable.append((label, part))
    for k, other in enumerate(others):
        first.add(f"kkt{k}", _reaction(other))
    return first.items, movable


def _translates(patterns: Patterns, w: Array, opts: SplitOptions, first: _First) -> None:
    """Into ``first``: the reaction's line across the plate at every line, long clusters moved."""
    clusters = patterns.clusters(w)
    line = patterns.line_profile(w)
    if line.sum() >= opts.line_share * max(float(c.sum()) for c in clusters):
        for k in patterns.shifts():
            if first.full:
                return
            moved = patterns.translate(line, k)
            if moved.sum() >= opts.line_fraction * line.sum():
                first.add(f"line@{k}", moved)
    for j, part in enumerate(clusters):
        if patterns.extent(part) > opts.line_extent:
            for k in patterns.shifts():
                if first.full:
                    return
                moved = patterns.translate(part, k)
                if k and moved.sum() >= opts.clip_fraction * part.sum():
                    first.add(f"cluster{j}@{k}", moved)


# -- the dual of the relaxation at a direction ---------------------------------------------
def _dual(H: Array, c: Array, iterations: int, start: list[int] | None = None) -> Array:
    r"""Maximise :math:`2\mu^Tc - \mu^TH\mu` over :math:`\mu \ge 0` (Lawson-Hanson, Gram form).

    H is positive semidefinite (and ill-conditioned: neighbouring columns answer alike);
    the active set stays small (a buckle's touch-down lines), so each step solves a small
    system. ``start``: an active set to begin from (a nearby direction's). Heuristic: the
    certificate checks the :math:`\mu` it gets.
    """
    r = len(c)
    mu = np.zeros(r)
    scale = max(float(np.abs(c).max(initial=0.0)), 1e-300)

    ridge = 1e-14 * float(np.abs(np.diag(H)).max(initial=0.0))

    def solve(idx: npt.NDArray[np.int64]) -> Array:
        sub = H[idx[:, None], idx]
        sub.flat[:: len(idx) + 1] += ridge
        try:
            return np.asarray(np.linalg.solve(sub, c[idx]), dtype=np.float64)
        except np.linalg.LinAlgError:
            return np.asarray(np.linalg.lstsq(sub, c[idx], rcond=None)[0], dtype=np.float64)

    active: list[int] = []
    if start:
        s = solve(np.array(start))
        active = [a for a, v in zip(start, s, strict=True) if v > 0]
        if active:
            mu[active] = solve(np.array(active)).clip(min=0.0)
            active = [a for a in active if mu[a] > 0]
    for _ in range(iterations):
        g = c - H @ mu
        g[active] = -np.inf
        k = int(np.argmax(g))
        if not g[k] > 1e-12 * scale:
            break
        active.append(k)
        for _ in range(len(active) + 1):
            idx = np.array(active)
            s = solve(idx)
            if (s > 0).all():
                mu[:] = 0.0
                mu[idx] = s
                break
            cur = mu[idx]
            neg = s <= 0
            alpha = float(np.min(cur[neg] / np.maximum(cur[neg] - s[neg], 1e-300)))
            cur = cur + alpha * (s - cur)
            mu[:] = 0.0
            mu[idx] = np.maximum(cur, 0.0)
            active = [
                a for a, v in zip(active, cur, strict=True) if v > 1e-14 * max(cur.max(), 1e-300)
            ]
            if not active:
                break
    return mu


@dataclass
class _Relaxation:
    """The dual data of the relaxation at the current columns (float, heuristic)."""

    S_W: Array  # G_W^-1
    G_MW: Array
    H: Array
    metric: Array  # -S_W: the z-space's angles
    cache: dict[bytes, tuple[float, Array, float]] = field(default_factory=dict)
    used: set[int] = field(default_factory=set)  # columns in some mu met

    @classmethod
    def of(cls, basis: Basis) -> _Relaxation:
        m = basis.m
        G = basis.G
        S_W = np.linalg.inv(G[:m, :m])
        S_W = 0.5 * (S_W + S_W.T)
        G_MW = G[m:, :m]
        H = G[m:, m:] - G_MW @ S_W @ G_MW.T
        return cls(S_W, G_MW, 0.5 * (H + H.T), -S_W)

    def bound(
        self, z: Array, iterations: int, near: Array | None = None
    ) -> tuple[float, Array, float]:
        """(relative dual bound at z, its mu, the optimal scaling t of mu).

        ``near``: the mu of a nearby direction (its support starts the active set).
        """
        norm = float(z @ self.metric @ z)
        key = np.round(z / math.sqrt(norm), 12).tobytes()  # a generator shared by pieces
        if key in self.cache:
            return self.cache[key]
        c = self.G_MW @ (self.S_W @ z)
        best: tuple[float, Array, float] | None = None
        # A nearby direction's active set first (a few steps); from scratch if that
        # leaves the bound at or below zero (the start may hold it at a poor point).
        starts = [None] if near is None else [[int(a) for a in np.flatnonzero(near > 0)], None]
        for start in starts:
            mu = _dual(self.H, c, iterations, start) if len(c) else np.zeros(0)
            num, den = float(mu @ c), float(mu @ self.H @ mu)
            t = num / den if num > 0 and den > 0 else 0.0
            value = (float(z @ self.S_W @ z) + t * num) / norm
            if best is None or value > best[0]:
                best = (value, mu, t)
            if best[0] > 0:
                break
        assert best is not None
        self.cache[key] = best
        self.used.update(int(j) for j in np.flatnonzero(best[1] > 0))
        return best


# -- one piece ------------------------------------------------------------------------------
def _combined(basis: Basis, mus: list[Array], factor: float) -> tuple[Array, Array, Array] | None:
    r"""(G1s, E1s, scaling) of C = [W, M mu_1 ... M mu_k], or None unless In(G1) = (m, 0, k).

    :math:`G_1 = C^TGC` and its bound: C is nonnegative, so
    :math:`|C^T(G + \Delta G)C - \mathrm{fl}(C^TGC)| \le C^T E C` plus the rounding of
    the product; both scaled by powers of two (exactly) to a unit diagonal.
    """
    m = basis.m
    k = len(mus)
    Mu = np.column_stack(mus)
    G, E, absG = basis.G, basis.E, basis.absG
    G1, E1 = np.empty((m + k, m + k)), np.empty((m + k, m + k))
    # C = [[I, 0], [0, Mu]] >= 0, by blocks: |C'(G + dG)C - fl(C'GC)| <= C'|dG|C plus the
    # rounding of the products (at most m + r terms each).
    for out, mat in ((G1, G), (E1, E + gamma(2 * (m + basis.r) + 2) * absG)):
        out[:m, :m] = mat[:m, :m]
        out[:m, m:] = mat[:m, m:] @ Mu
        out[m:, :m] = out[:m, m:].T
        out[m:, m:] = Mu.T @ mat[m:, m:] @ Mu
    G1 = 0.5 * (G1 + G1.T)
    E1 *= 1 + gamma(2 * (m + basis.r) + 4)
    dg = 1.0 / _pow2(np.sqrt(np.maximum(np.abs(np.diag(G1)), np.diag(E1))))
    G1s, E1s = G1 * dg[:, None] * dg[None, :], E1 * dg[:, None] * dg[None, :]
    neg, _, gmargin = _inertia(G1s, E1s, factor)
    if neg != m or gmargin <= 1.0:
        return None
    return G1s, E1s, dg


def _cone_form(G1s: Array, dg: Array, V: Array, k: int) -> tuple[Array, Array, Array] | None:
    """(Tn, Qn, S): the piece's variables in G1s's scaling and the form on them, unit diagonal.

    In the scaled coordinates :math:`(z_s, y_s) = D(z, y)`, cone(V) is cone(D_zV) and the
    orthant of y is itself (D is a positive diagonal of powers of two: exact).
    """
    m = V.shape[0]
    T = np.zeros((m + k, V.shape[1] + k))
    T[:m, : V.shape[1]] = dg[:m, None] * V
    T[m:, V.shape[1] :] = -np.eye(k)
    try:
        S = np.linalg.inv(G1s)
    except np.linalg.LinAlgError:
        return None
    S = 0.5 * (S + S.T)
    Q = T.T @ S @ T
    d = 1.0 / _pow2(np.sqrt(np.abs(np.diag(Q))))
    Tn = T * d[None, :]
    Qn = Tn.T @ S @ Tn
    return Tn, 0.5 * (Qn + Qn.T), d


def _in_cap(basis: Basis, V: Array, mu: Array, factor: float) -> tuple[bool, float, int | None]:
    r"""Whether every generator of cone(V) lies in the cap of the one column M mu (verified).

    With one column the directions z where :math:`\min_{y \le 0}` of the form is
    nonnegative are one nappe of a convex quadratic cone
    (:math:`(g^TS_Wz)^2 + h\,z^TS_Wz \ge 0`, :math:`g^TS_Wz > 0`, with :math:`S_W`
    negative definite and h > 0 since :math:`\mathrm{In}(G_1) = (m, 0, 1)`): cone(V)
    lies in it when each generator does. Each generator is a 2 x 2 piece whose SPN
    certificate is exact (N = the positive off-diagonal entry), checked as the pieces are.
    Returns (proven, least margin, the first generator that failed).
    """
    m = basis.m
    combined = _combined(basis, [mu], factor)
    if combined is None:
        return False, -math.inf, 0
    G1s, E1s, dg = combined
    least = math.inf
    order = range(V.shape[1])
    for j in order:
        form = _cone_form(G1s, dg, V[:, j : j + 1], 1)
        if form is None:
            return False, -math.inf, j
        Tn, Qn, _ = form
        N = np.zeros((2, 2))
        N[0, 1] = N[1, 0] = max(Qn[0, 1], 0.0)
        if not float(np.linalg.eigvalsh(Qn - N).min()) > 0:
            return False, -math.inf, j
        margin = _check_piece(G1s, E1s, Tn, N, m, factor)
        if not margin > 1.0:
            return False, margin, j
        least = min(least, margin)
    return True, least, None


def _piece_check(
    basis: Basis, V: Array, mus: list[Array], factor: float, sdp: bool
) -> tuple[bool, float, Array | None]:
    """(proven, margin, a point of cone(V) where the form is lowest when not proven).

    With ``sdp`` false, only the N of the Z-matrix heuristic is tried (no program).
    """
    m = basis.m
    k = len(mus)
    combined = _combined(basis, mus, factor)
    if combined is None:
        return False, -math.inf, None
    G1s, E1s, dg = combined
    form = _cone_form(G1s, dg, V, k)
    if form is None:
        return False, -math.inf, None
    Tn, Qn, d = form
    # N = the positive off-diagonal part of the form (then Q - N is a Z-matrix,
    # positive definite exactly when copositive: no program to solve); then a local
    # minimum below zero disproves the piece; else the SPN program (Clarabel).
    N = np.maximum(Qn, 0.0)
    np.fill_diagonal(N, 0.0)
    t = float(np.linalg.eigvalsh(Qn - N).min())
    if t > 0:
        margin = _check_piece(G1s, E1s, Tn, N, m, factor)
        if margin > 1.0:
            return True, margin, None
    f, w = _lowest(Qn)
    if f >= 0.0 and sdp:
        t, N, dual = _spn(Qn)
        if math.isfinite(t) and t > 0:
            margin = _check_piece(G1s, E1s, Tn, N, m, factor)
            if margin > 1.0:
                return True, margin, None
        f, w = _simplex_min(Qn, _starts(Qn, dual))
    alpha = w[:m] * d[:m]  # the generators' weights (T's first m columns carry d)
    if not alpha.max(initial=0.0) > 0:
        return False, t, None
    return False, t, V @ alpha


def _lowest(Q: Array) -> tuple[float, Array]:
    """The least value of z'Qz over the vertices and edges of the simplex, and where.

    Each edge's minimum is a one-dimensional quadratic's (closed form); a point for the
    next combination, not a proof of anything.
    """
    q = Q.shape[0]
    best, where = float(np.diag(Q).min()), np.eye(q)[int(np.argmin(np.diag(Q)))]
    i, j = np.triu_indices(q, 1)
    a = Q[i, i] - 2 * Q[i, j] + Q[j, j]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(a > 0, np.clip((Q[i, i] - Q[i, j]) / a, 0.0, 1.0), 0.0)
    f = (1 - t) ** 2 * Q[i, i] + 2 * t * (1 - t) * Q[i, j] + t**2 * Q[j, j]
    if f.size and float(f.min()) < best:
        e = int(np.argmin(f))
        where = np.zeros(q)
        where[i[e]], where[j[e]] = 1 - t[e], t[e]
        best = float(f[e])
    return best, where


def _bisect(V: Array, metric: Array) -> list[Array]:
    """The two halves of cone(V) at the dyadic midpoint of its widest edge (in the metric)."""
    m = V.shape[1]
    lengths = np.sqrt(np.einsum("ij,ik,kj->j", V, metric, V))
    Z = V / lengths
    best, pair = -1.0, (0, 1)
    for a, b in itertools.combinations(range(m), 2):
        cos = float(Z[:, a] @ metric @ Z[:, b])
        angle = math.acos(max(-1.0, min(1.0, cos)))
        if angle > best:
            best, pair = angle, (a, b)
    a, b = pair
    return _halves(V, a, b)  # dyadic vertices: the midpoint exact


def _centre(V: Array, metric: Array) -> Array:
    lengths = np.sqrt(np.einsum("ij,ik,kj->j", V, metric, V))
    return np.asarray((V / lengths).sum(axis=1), dtype=np.float64)


# -- the route --------------------------------------------------------------------------------
#: Calibration of :func:`estimate_cost` against ``bench/bench_bracket.py --uncapped`` (the
#: thin plates run with the default's budgets and no cost limit, each unit timed in free
#: solves in one process; ``--fit`` derives them; the units at 90x30, their growth
#: between 90x30 and 180x60): one
#: factorisation of K(lambda) over one free solve; right-hand sides of a batched solve
#: (with the residual products and the second solve of the rounding bound) per free
#: solve; one piece's work over a free solve (its dense programs, and the Gram products
#: and column updates that go with them); each at ``reference_dofs`` DOFs. Above it each
#: unit grows as (DOFs / ``reference_dofs``)^``*_growth`` (a two-point fit between the
#: meshes, of the largest unit, or the fewest right-hand sides, over the plates of
#: each); below it as ^``*_small`` (the free solve's fixed work dominates: a piece's
#: dense work costs more free solves on a coarse mesh, checked at 30x10); the pieces
#: one attempt examines for m = 2 (the most of the plates with m = 2, with the
#: interpolated multipliers) and their growth with each further negative eigenvalue (the
#: plates with m = 3 over it).
COST_MODEL = {"factorisation": 0.67, "factor_growth": 0.66, "factor_small": 0.0,
              "rhs_per_solve": 205.0, "rhs_growth": 0.47, "rhs_small": -0.3,
              "piece": 0.074, "piece_growth": 0.91, "piece_small": -1.3,
              "pieces": 68.0, "growth": 2.41, "reference_dofs": 8463.0}  # fmt: skip


@dataclass
class Sources:
    """The zone's patterns and the columns they give for one KKT point (see :func:`_sources`)."""

    patterns: Patterns
    first: list[tuple[str, Array]]
    movable: list[tuple[str, Array]]


@dataclass
class _State:
    """What one distance's attempt leaves to the next (:func:`split_certificate`).

    Attributes:
        columns: The columns met so far (name, oriented values on I).
        movable: The patterns translated on demand (name, oriented values on I).
        start: The negative space's block to restart the inverse iteration from.
        budget: The counts spent against the cost limit (None: no limit).
    """

    columns: list[tuple[str, Array]]
    movable: list[tuple[str, Array]]
    start: Array | None = None
    budget: _Budget | None = None


def column_sources(
    problem: UnilateralProblem, candidate: Candidate, others: list[Candidate], opts: SplitOptions
) -> Sources:
    """The first columns and the patterns translated on demand (no solve)."""
    patterns = Patterns(problem)
    first, movable = _sources(patterns, candidate, others, opts)
    return Sources(patterns, first, movable)


@dataclass(frozen=True)
class CostCounts:
    """What :func:`estimate_cost` counts: attempts, right-hand sides and pieces per attempt.

    Attributes:
        attempts: Factorisations priced: one (the first distance; a further one runs only
            within the cost limit, :class:`_Budget`).
        rhs: Right-hand sides per attempt (the negative space's block iterations, then two
            per column).
        pieces: Pieces expected per attempt (:data:`COST_MODEL`'s ``pieces`` for m = 2,
            ``growth`` times as many per further negative eigenvalue, at most
            ``opts.max_pieces``).
        size: DOFs over :data:`COST_MODEL`'s ``reference_dofs``.
    """

    attempts: int
    rhs: int
    pieces: float
    size: float


def estimate_counts(
    problem: UnilateralProblem, sources: Sources, m: int, opts: SplitOptions
) -> CostCounts:
    """The counts :func:`estimate_cost` prices (no solve)."""
    columns = min(len(sources.first), opts.max_columns)
    model = COST_MODEL
    # growth**(m - 2) overflows a float past m of about 500 (a filled tube's pencil can
    # hold that many eigenvalues below the load); the cap binds long before: compare logs.
    extra = max(m - 2, 0)
    capped = math.log(model["pieces"]) + extra * math.log(model["growth"]) >= math.log(
        opts.max_pieces
    )
    return CostCounts(
        attempts=1,
        rhs=(m + 3) * (opts.mode_iterations + 1) + 2 * (m + columns),
        pieces=float(opts.max_pieces) if capped else model["pieces"] * model["growth"] ** extra,
        size=float(problem.model.A.getSize()[0]) / model["reference_dofs"],
    )


def unit_costs(size: float, model: dict[str, float] | None = None) -> tuple[float, float, float]:
    """(one factorisation, one right-hand side, one piece) in free solves at ``size``.

    ``size``: DOFs over ``model``'s ``reference_dofs`` (default :data:`COST_MODEL`).
    """
    model = model or COST_MODEL
    regime = "growth" if size >= 1.0 else "small"

    def scale(unit: str) -> float:
        return float(size ** model[f"{unit}_{regime}"])

    return (model["factorisation"] * scale("factor"), scale("rhs") / model["rhs_per_solve"],
            model["piece"] * scale("piece"))  # fmt: skip


def price(counts: CostCounts, model: dict[str, float] | None = None) -> float:
    """The time of ``counts`` in free solves by ``model`` (default :data:`COST_MODEL`)."""
    factorisation, per_rhs, piece = unit_costs(counts.size, model)
    return counts.attempts * (factorisation + counts.rhs * per_rhs + counts.pieces * piece)


def estimate_cost(
    problem: UnilateralProblem, sources: Sources, m: int, opts: SplitOptions
) -> float:
    """The split route's first attempt's expected time in free eigen solves, from counts.

    One factorisation, the right-hand sides (the negative space's block iterations, then
    two per column) and the pieces expected for m, by :data:`COST_MODEL` (no clock: the
    same on every machine). A further attempt (the next distance, or the fallback) runs
    only while the counts spent, priced the same way, and one more attempt's estimate
    stay within ``opts.max_cost`` (:class:`_Budget`), and an attempt stops its pieces
    when the counts spent reach it: with a limit the route's cost is the limit at most,
    up to the units' error.
    """
    return price(estimate_counts(problem, sources, m, opts))


@dataclass
class _Budget:
    """The counts the route has spent, priced in free solves, against ``limit``.

    Attributes:
        limit: ``SplitOptions.max_cost`` (None: no limit, nothing is stopped).
        units: :func:`unit_costs` at the problem's size.
        matrix: The shifted matrix (its ``solves`` count the right-hand sides).
        solves0: Its count when the route began.
        next_attempt: One more attempt's estimate (:func:`estimate_cost`, from the
            first attempt's m).
        examined: Pieces examined by the finished attempts.
        stopped: Why a further attempt was not tried (empty if none was refused).
    """

    limit: float | None
    units: tuple[float, float, float]
    matrix: ShiftedMatrix
    solves0: int
    next_attempt: float | None = None
    examined: int = 0
    stopped: str = ""

    def spent(self, attempts: int, examined: int) -> float:
        """The counts so far in free solves (``examined``: the current attempt's pieces)."""
        factorisation, per_rhs, piece = self.units
        rhs = self.matrix.solves - self.solves0
        return attempts * factorisation + rhs * per_rhs + (self.examined + examined) * piece

    def over(self, attempts: int, examined: int) -> bool:
        """The counts spent exceed the limit."""
        return self.limit is not None and self.spent(attempts, examined) > self.limit

    def refuse(self, attempts: int) -> bool:
        """Another attempt would exceed the limit (after ``attempts``); say why."""
        if self.limit is None or not attempts:
            return False
        total = self.spent(attempts, 0) + (self.next_attempt or 0.0)
        if total <= self.limit:
            return False
        self.stopped = (
            f"no further distance: the counts spent ({self.spent(attempts, 0):.1f} free "
            f"solves) and one more attempt's estimate exceed the cost limit {self.limit:g}"
        )
        return True


def split_certificate(
    problem: UnilateralProblem,
    matrix: ShiftedMatrix,
    candidate: Candidate,
    others: list[Candidate],
    opts: SplitOptions | None = None,
    sources: Sources | None = None,
) -> SplitOutcome:
    r"""A verified lower bound just below ``candidate``'s load, or a refuting mode.

    The relative distances of ``opts`` are searched as by the low-rank route
    (:func:`~unibuckle_fenicsx.certificate.copositivity_lowrank.search_deltas`), one
    factorisation each; the columns met (cuts included) and the negative space's block
    carry over from one distance to the next.

    Args:
        problem: The problem (with an obstacle).
        matrix: Its shifted matrix, factorised here at each distance.
        candidate: The KKT point whose load is bracketed.
        others: Further KKT points met (their reactions become columns).
        opts: Distances and budgets (default :class:`SplitOptions`).
        sources: :func:`column_sources` for this point, if the caller has them.

    Note:
        Collective.
    """
    opts = opts or SplitOptions()
    out = SplitOutcome()
    solves0 = matrix.solves
    if sources is None:
        sources = column_sources(problem, candidate, others, opts)
    patterns = sources.patterns
    size = float(problem.model.A.getSize()[0]) / COST_MODEL["reference_dofs"]
    budget = _Budget(opts.max_cost, unit_costs(size), matrix, solves0)
    state = _State(sources.first, sources.movable, budget=budget)

    def attempt(delta: float) -> SplitAttempt:
        record = _attempt(problem, matrix, candidate, delta, patterns, state, opts, out)
        budget.examined += record.examined or 0
        record.spent = budget.spent(len(out.attempts) + 1, 0)
        if budget.next_attempt is None and record.m:
            budget.next_attempt = price(estimate_counts(problem, sources, record.m, opts))
        return record

    def proceed(record: LowRankAttempt) -> bool:
        return opts.next_margin is None or record.margin >= opts.next_margin

    def stop() -> bool:
        return out.refuting is None and budget.refuse(len(out.attempts))

    search_deltas(out, candidate.load, opts.deltas, opts.fallback, attempt, stop, proceed)
    if budget.stopped:
        out.why = f"{out.why}; {budget.stopped}" if out.why else budget.stopped
    out.solves = matrix.solves - solves0
    return out


def scatter_columns(problem: UnilateralProblem, items: list[tuple[str, Array]]) -> Array:
    """The W-vectors (owned rows) of columns given as oriented values on I."""
    vec = problem.model.A.createVecRight()
    cols = []
    for _, values in items:
        problem.contact.scatter(values, vec)
        cols.append(vec.array_r.copy())
    vec.destroy()
    nloc = problem.model.A.getLocalSize()[0]
    return np.column_stack(cols) if cols else np.zeros((nloc, 0))


def _key(v: Array) -> bytes:
    """A normalised column's identity: a digest of its values rounded to 1e-9."""
    return hashlib.blake2b(np.round(v, 9).tobytes(), digest_size=16).digest()


def _normal(values: Array) -> Array | None:
    """``values`` made nonnegative and scaled to max 1 (None if nothing is left)."""
    v = np.maximum(values, 0.0)
    top = float(v.max(initial=0.0))
    return v / top if top > 0 else None


def distinct_columns(
    items: list[tuple[str, Array]], have: list[Array], limit: int | None = None
) -> list[tuple[str, Array]]:
    """Nonnegative, scaled to max 1, without zeros and repeats (of ``have`` or each other).

    At most ``limit`` of them (the first ones), if given.
    """
    seen = {_key(v) for v in have}
    out: list[tuple[str, Array]] = []
    for name, values in items:
        if limit is not None and len(out) >= limit:
            break
        v = _normal(values)
        if v is None or _key(v) in seen:
            continue
        seen.add(_key(v))
        out.append((name, v))
    return out


class _First:
    """The first columns, kept while fewer than ``limit`` of them are distinct.

    The first basis takes the first ``limit`` distinct columns (:func:`distinct_columns`);
    the columns after them are never used, and are not kept (a line's translates alone
    would be one column per line along the plate, each as long as the zone).
    """

    def __init__(self, limit: int) -> None:
        self.items: list[tuple[str, Array]] = []
        self.limit = limit
        self._seen: set[bytes] = set()

    @property
    def full(self) -> bool:
        return len(self._seen) >= self.limit

    def add(self, name: str, values: Array) -> None:
        if self.full:
            return
        self.items.append((name, values))
        v = _normal(values)
        if v is not None:
            self._seen.add(_key(v))


def _attempt(
    problem: UnilateralProblem,
    matrix: ShiftedMatrix,
    candidate: Candidate,
    delta: float,
    patterns: Patterns,
    state: _State,
    opts: SplitOptions,
    out: SplitOutcome,
) -> SplitAttempt:
    """One delta: factorise, negative space, columns, pieces (and new columns where needed)."""
    attempt, lam = factor_at(matrix, candidate.load, delta, out, SplitAttempt)
    neg = attempt.m
    if attempt.why:
        return attempt
    basis, attempt.why = _first_basis(problem, matrix, lam, neg, state, opts)
    if basis is None:
        return attempt
    try:
        return _cover(problem, basis, candidate, patterns, state, opts, out, attempt)
    finally:
        basis.destroy()


def _cover(
    problem: UnilateralProblem,
    basis: Basis,
    candidate: Candidate,
    patterns: Patterns,
    state: _State,
    opts: SplitOptions,
    out: SplitOutcome,
    attempt: SplitAttempt,
) -> SplitAttempt:
    """The pieces of one delta's z-space, proven, bisected or given new columns."""
    neg = basis.m
    relax = _Relaxation.of(basis)
    # (generators, times bisected, the combinations its parent tried)
    pieces: list[tuple[Array, int, list[Array]]] = [(V, 0, []) for V in _orthants(neg)]
    proven_pieces, examined, rounds, rounding = 0, 0, 0, 0
    margin = math.inf
    why = ""
    while pieces:
        if examined >= opts.max_pieces:
            why = f"the z-space is not covered within {opts.max_pieces} pieces"
            break
        if state.budget is not None and state.budget.over(len(out.attempts) + 1, examined):
            why = (
                f"the cost limit ({opts.max_cost:g} free solves, counts priced by "
                f"COST_MODEL) is reached after {examined} pieces"
            )
            break
        V, level, inherited = pieces.pop()
        examined += 1
        proof = _prove_piece(basis, relax, V, level, inherited, opts)
        if proof.margin is not None:
            proven_pieces += 1
            margin = min(margin, proof.margin)
            continue
        uncovered = proof.uncovered
        rounding += proof.rounding
        if rounding >= opts.max_rounding:
            why = (
                f"rounding: {rounding} pieces failed on the error bound of G alone (their "
                "margins shrink with delta)"
            )
            break
        if uncovered is None:
            pieces += [(half, level + 1, proof.tried) for half in _bisect(V, relax.metric)]
            continue
        # The relaxation itself fails at a direction: refute, or new columns there.
        if rounds >= opts.max_rounds or basis.room == 0:
            why = (
                f"a direction of the negative space is not covered by the columns "
                f"(dual bound {min(uncovered[3], 0.0):.3g}; {rounds} rounds, {basis.r} columns)"
            )
            break
        found = _new_columns(problem, basis, relax, patterns, state, candidate, uncovered[:3], opts)
        widened, why = _widen(problem, basis, relax, state, candidate.load, found, out)
        if widened is None:
            break
        relax, rounds = widened, rounds + 1
        pieces.append((V, level, []))
    proven = not pieces and not why
    if proven:
        state.columns = _carried(basis, relax, patterns)
    attempt.proven, attempt.r, attempt.pieces, attempt.examined = (
        proven,
        basis.r,
        proven_pieces,
        examined,
    )
    attempt.rounds, attempt.why, attempt.margin = rounds, why, margin if proven else -math.inf
    return attempt


def _widen(
    problem: UnilateralProblem,
    basis: Basis,
    relax: _Relaxation,
    state: _State,
    load: float,
    found: tuple[list[tuple[str, Array]], Refuting | None],
    out: SplitOutcome,
) -> tuple[_Relaxation | None, str]:
    """The relaxation with the columns ``found`` (:func:`_new_columns`), or None and why not.

    A refuting mode found (a load below the KKT point's ``load``) goes into
    ``out.refuting``.
    """
    columns, refuting = found
    if refuting is not None:
        out.refuting = refuting
        return None, f"refuted: an admissible mode has the load {refuting.load:.10g} < {load:.10g}"
    items = columns[: basis.room]
    if not items:
        return None, "a direction of the negative space is not covered and no new column helps"
    basis.add(scatter_columns(problem, items), [n for n, _ in items], [v for _, v in items])
    state.columns = list(state.columns) + items
    widened = _Relaxation.of(basis)
    widened.used |= relax.used
    return widened, ""


def _orthants(m: int) -> list[Array]:
    """The 2^m orthants of the z-space, each as its generators (columns)."""
    return [np.diag(np.array(s)) for s in itertools.product((1.0, -1.0), repeat=m)]


def _first_basis(
    problem: UnilateralProblem,
    matrix: ShiftedMatrix,
    lam: float,
    neg: int,
    state: _State,
    opts: SplitOptions,
) -> tuple[Basis | None, str]:
    """The negative space's block W and the columns met so far, or None and why not."""
    space = negative_space(problem, matrix, lam, neg, state.start, opts.mode_iterations)
    if space is None:
        return None, f"the {neg} pencil modes below the shift were not found"
    psi, theta, state.start = space
    # A-normalised Ritz pairs: psi'B K^-1 B psi = 1/(theta (theta - lam)), so this scaling
    # makes G_W nearly -I (the z-space's angles then nearly Euclidean).
    W = _block_product(problem.model.B, psi) * np.sqrt(theta * (lam - theta))[None, :]
    items = distinct_columns(state.columns, [], opts.max_columns)
    capacity = neg + min(opts.max_columns, len(items) + opts.max_rounds * opts.per_round)
    basis = Basis(problem, matrix, neg, capacity, opts.accurate)
    basis.add(W, [f"W{j}" for j in range(neg)])
    gneg, _, gmargin = _inertia(basis.G, basis.E, opts.margin_factor)
    if gneg != neg or gmargin <= 1.0:
        basis.destroy()
        return None, "W'K^-1W is not verified negative definite"
    basis.add(scatter_columns(problem, items), [n for n, _ in items], [v for _, v in items])
    return basis, ""


def _carried(basis: Basis, relax: _Relaxation, patterns: Patterns) -> list[tuple[str, Array]]:
    """The columns the next (smaller) distance starts from, after a proof here.

    Those the duals used here and their neighbours along the plate: the others answered
    no direction.
    """
    kept = [(basis.names[basis.m + j], basis.values[j]) for j in sorted(relax.used)]
    near = [(f"{name}{sign:+d}", patterns.translate(values, sign))
            for name, values in kept for sign in (-1, 1)]  # fmt: skip
    return kept + near


@dataclass
class _Proof:
    """A piece's outcome.

    Proven (its margin), or a direction that the columns do not cover (z, mu, t, bound),
    or neither (split it); ``tried``: the combinations met.
    """

    margin: float | None = None
    uncovered: tuple[Array, Array, float, float] | None = None
    tried: list[Array] = field(default_factory=list)
    rounding: bool = False  # a check failed on its error bound only


def _prove_piece(
    basis: Basis,
    relax: _Relaxation,
    V: Array,
    level: int,
    inherited: list[Array],
    opts: SplitOptions,
) -> _Proof:
    """One column M mu whose cap holds every generator, else the combinations together.

    First the combinations the parent piece met (a half often lies in one of their caps:
    no dual to solve); then mu of the centre, then of the generators that fall outside;
    then the combinations together (Z-matrix N), and on small pieces their columns one by
    one with the SPN program.
    """
    iterations = 4 * basis.m + 40
    # A piece waiting while columns were added has its parent's shorter mu: the same
    # combinations, with zero weight on the new columns.
    inherited = [np.pad(mu, (0, basis.r - len(mu))) for mu in inherited]
    for mu in inherited[:2]:
        ok, piece_margin, _ = _in_cap(basis, V, mu, opts.margin_factor)
        if ok:
            return _Proof(margin=piece_margin, tried=inherited)
    z = _centre(V, relax.metric)
    b, mu, t = relax.bound(z, iterations, inherited[0] if inherited else None)
    if b <= 0:
        return _Proof(uncovered=(z, mu, t, b))
    mus = [mu / mu.max()] if mu.max(initial=0.0) > 0 else []
    tried = 0
    rounding = False
    while tried < len(mus) and tried < opts.max_combinations:
        ok, piece_margin, outside = _in_cap(basis, V, mus[tried], opts.margin_factor)
        tried += 1
        if ok:
            return _Proof(margin=piece_margin, tried=mus)
        rounding |= 0.0 < piece_margin <= 1.0
        if outside is None:
            continue
        bw, muw, tw = relax.bound(V[:, outside], iterations, mu)
        if bw <= 0:
            return _Proof(uncovered=(V[:, outside], muw, tw, bw))
        _add_combination(mus, muw)
    if opts.interpolate:
        margin = _interpolated(basis, relax, V, iterations, opts.margin_factor)
        if margin is not None:
            return _Proof(margin=margin, tried=mus)
    return _Proof(margin=_together(basis, V, mus, level, opts), tried=mus, rounding=rounding)


def _add_combination(mus: list[Array], mu: Array) -> None:
    """Append ``mu`` scaled to a largest entry of 1 unless zero or already in ``mus`` (to 1e-6)."""
    top = float(mu.max(initial=0.0))
    if top > 0:
        mu = mu / top
        if not any(float(np.abs(mu - q).max()) <= 1e-6 for q in mus):
            mus.append(mu)


def _interpolated(
    basis: Basis, relax: _Relaxation, V: Array, iterations: int, factor: float
) -> float | None:
    r"""The piece's margin with each generator's own multiplier interpolated over the piece.

    The combinations are the generators' :math:`\mu` (the contact reactions of their
    least-energy modes). For :math:`z = V\alpha` the multiplier
    :math:`\nu(\alpha) = \Lambda^T\alpha \ge 0` on them gives the weak-duality bound
    :math:`\min_{w \ge 0} Q(\alpha, w) \ge \alpha^TR\alpha`, with
    :math:`R = Q_{\alpha\alpha} - (Q_{\alpha w} - \Lambda)Q_{ww}^{-1}(Q_{\alpha w} - \Lambda)^T`;
    within one active set of the relaxation its optimal multiplier is linear in z, so the
    interpolation is exact there and the piece need not be small. Row i of
    :math:`\Lambda` is generator i's best (its dual on the combinations), and
    :math:`N = [[N_{\alpha\alpha}, \Lambda], [\Lambda^T, 0]]` with
    :math:`N_{\alpha\alpha}` the positive off-diagonal part of R is an SPN decomposition
    of Q when :math:`R - N_{\alpha\alpha} \succ 0`; else the SPN program on the same
    combinations (Clarabel) looks for any N. Either N is checked as every piece's is
    (bordered inertia, rigorous bound on G's error). None when unproven (a generator whose
    dual bound is not positive is left to the caps: a new column there).
    """
    mus: list[Array] = []
    for j in range(V.shape[1]):
        b, mu, t = relax.bound(V[:, j], iterations)
        top = float(mu.max(initial=0.0))
        if b <= 0 or not top > 0:  # left to the caps (a new column there) or a split
            return None
        _add_combination(mus, mu)
    combined = _combined(basis, mus, factor)
    if combined is None:
        return None
    G1s, E1s, dg = combined
    form = _cone_form(G1s, dg, V, len(mus))
    if form is None:
        return None
    Tn, Qn, _ = form
    n = V.shape[1]
    Qaa, Qaw, Qww = Qn[:n, :n], Qn[:n, n:], Qn[n:, n:]
    try:
        P = np.linalg.inv(Qww)
    except np.linalg.LinAlgError:
        return None
    P = 0.5 * (P + P.T)
    # Row i: the nonnegative row closest to Q_aw's in P's norm (its dual, Lawson-Hanson).
    Lam = np.vstack([_dual(P, P @ Qaw[i], 4 * len(mus) + 8) for i in range(n)])
    D = Qaw - Lam
    R = Qaa - D @ P @ D.T
    R = 0.5 * (R + R.T)
    Naa = np.maximum(R, 0.0)
    np.fill_diagonal(Naa, 0.0)
    if float(np.linalg.eigvalsh(R - Naa).min()) > 0:
        N = np.block([[Naa, Lam], [Lam.T, np.zeros((len(mus), len(mus)))]])
    else:  # the SPN program on the same combinations (any N, not only these rows)
        t, N, _ = _spn(Qn)
        if not (math.isfinite(t) and t > 0):
            return None
    margin = _check_piece(G1s, E1s, Tn, N, basis.m, factor)
    return margin if margin > 1.0 else None


def _together(
    basis: Basis, V: Array, mus: list[Array], level: int, opts: SplitOptions
) -> float | None:
    """The piece's margin with the combinations ``mus`` together, or None if unproven.

    All of them at once (Z-matrix N); on pieces bisected ``opts.sdp_depth`` times or
    more, the columns of every combination each on its own with the SPN program.
    """
    if len(mus) >= 2:
        ok, piece_margin, _ = _piece_check(
            basis, V, mus[: opts.max_combinations], opts.margin_factor, False
        )
        if ok:
            return piece_margin
    if mus and level >= opts.sdp_depth:
        # The columns of every combination met, each on its own (the relaxation with all
        # of them is at least as strong as any combination), and the SDP.
        weight = np.max(np.column_stack(mus), axis=1)
        support = np.argsort(-weight)[: opts.max_individual]
        support = support[weight[support] > 1e-3]
        units = [np.eye(1, basis.r, int(j))[0] for j in support]
        ok, piece_margin, _ = _piece_check(basis, V, units, opts.margin_factor, True)
        if ok:
            return piece_margin
    return None


def _new_columns(
    problem: UnilateralProblem,
    basis: Basis,
    relax: _Relaxation,
    patterns: Patterns,
    state: _State,
    candidate: Candidate,
    uncovered: tuple[Array, Array, float],
    opts: SplitOptions,
) -> tuple[list[tuple[str, Array]], Refuting | None]:
    """At an uncovered direction: new columns (cut and translates), or a refuting mode."""
    z, mu, t = uncovered
    coef = np.concatenate([relax.S_W @ z + t * (relax.S_W @ (relax.G_MW.T @ mu)), -t * mu])
    u = problem.model.A.createVecRight()
    clip = u.duplicate()
    try:
        relaxed = basis.X @ coef
        u.array[:] = relaxed
        scale = problem.max_abs_w(u)
        values = problem.contact.values(u) / scale
        # The relaxed minimiser, admissible as it is or with its crossing part at I
        # removed: one with a load below the KKT point's refutes it.
        problem.contact.scatter(np.minimum(values, 0.0) - values, clip)
        for extra in (0.0, scale):
            if extra == 0.0 and values.max() > problem.tau:
                continue
            u.array[:] = relaxed + extra * clip.array_r
            load = rayleigh(problem, u)
            if load is not None and load < candidate.load * (1.0 - 1e-12):
                vals = problem.contact.values(u) / problem.max_abs_w(u)
                vector = np.array(u.array_r, dtype=np.float64)
                return [], Refuting(load=load, values=vals, vector=vector)
        plus = np.maximum(values, 0.0)
        items: list[tuple[str, Array]] = [(f"cut{len(basis.names)}", plus)]
        scored = []
        for name, part in state.movable:
            best = None
            for k in patterns.shifts():
                moved = patterns.translate(part, k)
                if moved.sum() < opts.clip_fraction * part.sum():
                    continue
                score = float(moved @ plus) / math.sqrt(float(moved @ moved))
                if best is None or score > best[0]:
                    best = (score, k, moved)
            if best is not None and best[0] > 0:
                scored.append((best[0], f"{name}@{best[1]}", best[2]))
        scored.sort(key=lambda item: -item[0])
        items += [(name, moved) for _, name, moved in scored]
        return distinct_columns(items, basis.values)[: opts.per_round], None
    finally:
        u.destroy()
        clip.destroy()
