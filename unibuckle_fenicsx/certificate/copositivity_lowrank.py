r"""Low-rank copositivity certificate: a verified bracket when several pencil eigenvalues lie below.

Let :math:`K = K(\lambda) = A - \lambda B` have m negative eigenvalues (one sparse
:math:`LDL^T`, :class:`~unibuckle_fenicsx.certificate.copositivity.ShiftedMatrix`), and let
:math:`U = [u_1 \dots u_r]` hold r columns that vanish off the constrained nodes I and
are nonnegative there (in oriented values). With :math:`G = U^TK^{-1}U` (r solves):

1. if G is nonsingular with exactly m negative eigenvalues, K is positive definite on
   :math:`\ker U^T`, and then :math:`\min\{u^TKu : U^Tu = y\} = y^TSy`,
   :math:`S = G^{-1}`;
2. if S is copositive, every u of the cone :math:`\{u_I \le 0\}` (so :math:`y = U^Tu \le
   0`) has :math:`u^TKu \ge y^TSy \ge 0`: no admissible mode has a load below
   :math:`\lambda`, a verified lower bound.

Copositivity of S is proven piecewise: the orthant is split into simplicial cones
cone(V) (a star split at the piece's local minimiser, exact as checked in rational
arithmetic, else edge bisection, whose midpoints are exact in binary) and on each one
:math:`V^TSV - N \succ 0` with :math:`N \ge 0` (entrywise; an r x r semidefinite program,
Clarabel called directly, the ``sdp`` extra) proves :math:`y^TSy \ge 0` there (SPN). Nothing the
SDP returns is trusted: N is clipped to :math:`N \ge 0` and checked through the bordered
matrix :math:`M = [[-G, V], [V^T, -N]]`, :math:`\mathrm{In}(M) = \mathrm{In}(-G) +
\mathrm{In}(V^TSV - N)` (Haynsworth), so no inverse of G is needed: M must have exactly
r - m negative eigenvalues and none near zero. Both inertia counts (of G and of M) use
Weyl's theorem with the rigorous bound E on the error of the computed G plus the
backward error of LAPACK's symmetric eigensolver (taken as :math:`4 n u \|M\|_F`).

**Columns**: the contact reaction of the KKT point (the route is tight when the reaction
of the true minimiser is a column), its mirror images, the reactions of the other KKT
points met, the positive and negative parts on I of the free mode and, if G then has
fewer than m negative eigenvalues, of approximate pencil modes below :math:`\lambda`
(block inverse iteration with the factorised K); on zones of at most
``unit_columns`` nodes, U = I instead (the exact relaxation). Columns that leave G
nearly singular are not used (an ill-conditioned S defeats the SDP). Then **cuts**:
a :math:`y \ge 0` with :math:`y^TSy < 0` gives :math:`u = -K^{-1}USy` (the minimiser of
:math:`u^TKu` on :math:`U^Tu = -y`, with :math:`u^TKu = y^TSy < 0`); the positive part of
u on I becomes a new column (it cuts u off), and if it is empty, u is an admissible mode
with a load below :math:`\lambda`: the KKT point is *refuted*, and u is handed back.
Budgets bound the columns, cuts, pieces (and, optionally, time); the relative distances
:math:`\delta` below the load are tried from 1e-3 down while they are verified (else
1e-2), one factorisation each: the result is the smallest verified gap.

**Rounding.** Each entry of G is :math:`u_a^Tx_b + x_a^T\rho_b + \rho_a^TK^{-1}\rho_b`, its
residual :math:`\rho_b` computed in twice the working precision
(:mod:`~unibuckle_fenicsx.certificate.accurate`).

The module is about 900 lines: the column set, the piecewise split of the orthant and the
cuts share one state (:class:`_Columns`) and one set of budgets (:class:`LowRankOptions`)
within one attempt; split across modules they would pass that state back and forth.

Note:
    Collective on the problem's communicator. The dense programs run on every rank with
    identical data.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import numpy.typing as npt
from msgspec import UNSET

from unibuckle_fenicsx.certificate.accurate import (
    AccurateResidual,
    U,
    gamma,
    two_product,
)
from unibuckle_fenicsx.certificate.records import LowRankAttempt, LowRankRecord, Refuting
from unibuckle_fenicsx.certificate.shifted import ShiftedMatrix, mirror_maps, rayleigh
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem

__all__ = [
    "LowRankOptions",
    "LowRankOutcome",
    "factor_at",
    "lowrank_certificate",
    "search_deltas",
]


@dataclass(frozen=True)
class LowRankOptions:
    """Budgets and tolerances of the low-rank route.

    Attributes:
        deltas: Relative distances below the load tried in this order while they are
            verified (one factorisation each): the gap reported is the last verified.
        fallback: Tried in this order when the first of ``deltas`` fails.
        max_columns: Columns of U at most.
        max_cuts: Cuts (new columns from a negative direction of S) per delta.
        max_pieces: Simplicial pieces of the orthant per delta.
        time_budget: Wall time allowed, in free eigen solves
            (``problem.timings["free_solve_s"]``; None, the default: no limit, so that
            the answer depends on the counts above only, the same on every machine and
            partition). Checked between pieces and cuts, by all ranks together; the
            search then stops with what is verified.
        min_time_s: ... but at least this many seconds (on coarse meshes the dense
            programs, not the solves, set the time).
        mode_iterations: Block inverse iterations for the pencil-mode columns (used when
            the first columns see fewer than m negative directions).
        unit_cuts: When a cut's positive part cannot be added, the unit vectors of up to
            this many of its most violated nodes are tried instead.
        unit_columns: With at most this many constrained nodes, U = I (their unit vectors).
        prune_condition: Older columns that leave the scaled G's condition number above
            this are dropped (0: never); an ill-conditioned S defeats the SDP.
        near: A piece whose minimum (scaled to a unit diagonal) lies below this is first
            tightened by a cut at its minimiser, if that mode is not admissible.
        refinements: Refinement steps of each solve (double-double residuals).
        margin_factor: The inertia counts need every eigenvalue this many times beyond
            the error bound.
        select_margin: A column is used only if G keeps every eigenvalue this many
            times beyond that (a nearly singular G proves nothing), and if its condition
            number stays below ``max_condition`` (the SDP solver's accuracy).
    """

    deltas: tuple[float, ...] = (1e-3, 1e-4, 1e-5, 1e-6)
    fallback: tuple[float, ...] = (1e-2,)
    max_columns: int = 48
    max_cuts: int = 24
    max_pieces: int = 64
    refinements: int = 1
    margin_factor: float = 2.0
    select_margin: float = 8.0
    max_condition: float = 1e12
    near: float = 1e-4
    prune_condition: float = 1e6
    mode_iterations: int = 6
    unit_cuts: int = 4
    unit_columns: int = 24
    time_budget: float | None = None
    min_time_s: float = 2.0


@dataclass
class LowRankOutcome:
    """What the low-rank route found.

    Attributes:
        value: Verified lower bound (None if no delta was certified).
        delta: Its relative distance below the load.
        m: Negative eigenvalues of K at the last delta tried (pencil eigenvalues below).
        r: Columns at the end.
        pieces: Simplicial pieces of the certified (or last) attempt.
        margin: Smallest verified eigenvalue margin of the pieces (or the best SDP
            margin reached when it failed).
        attempts: Per delta: columns, cuts, pieces, what stopped it.
        why: Why it failed, in words ("" when certified).
        refuting: An admissible mode with a load below the KKT point's, if one was met
            (its load, oriented values at I and the W-vector's owned entries).
        solves: Triangular solve pairs used.
    """

    value: float | None = None
    delta: float | None = None
    m: int = 0
    r: int = 0
    pieces: int = 0
    margin: float = -math.inf
    attempts: list[LowRankAttempt] = field(default_factory=list)
    why: str = ""
    refuting: Refuting | None = None
    solves: int = 0
    _deadline: tuple[float, MPI.Comm] | None = None

    def out_of_time(self) -> bool:
        """Past the time budget, by the slowest rank's clock (collective)."""
        if self._deadline is None:
            return False
        end, comm = self._deadline
        return bool(comm.allreduce(time.perf_counter() > end, op=MPI.LOR))

    def record(self) -> LowRankRecord:
        """The route's record (without the refuting mode's vector)."""
        return LowRankRecord(
            value=self.value,
            delta=self.delta,
            m=self.m,
            r=self.r,
            pieces=self.pieces,
            margin=self.margin,
            why=self.why,
            attempts=self.attempts,
            refuting_load=UNSET if self.refuting is None else self.refuting.load,
        )


class _Columns:
    """Columns of U, their refined solves and G = U^T K^-1 U with an error bound."""

    def __init__(
        self, problem: UnilateralProblem, matrix: ShiftedMatrix, refinements: int, max_columns: int
    ):
        if matrix.K is None:
            raise RuntimeError("__init__: expected matrix.K is not None (an internal invariant)")
        self.problem, self.matrix, self.refinements = problem, matrix, refinements
        self.max_columns = max_columns
        self.contact = problem.contact
        self.residual = AccurateResidual(matrix.K)
        self.names: list[str] = []
        self.values: list[npt.NDArray[np.float64]] = []
        self.w: list[PETSc.Vec] = []
        self.x: list[PETSc.Vec] = []
        self.rho: list[npt.NDArray[np.float64]] = []
        self.err: list[npt.NDArray[np.float64]] = []
        self.xI: list[npt.NDArray[np.float64]] = []
        self.d_norm: list[float] = []
        self._G: dict[tuple[int, int], tuple[float, float]] = {}
        self.dropped: set[int] = set()
        self.comm = problem.comm

    @property
    def r(self) -> int:
        return len(self.names)

    def add(self, items: list[tuple[str, npt.NDArray[np.float64]]]) -> int:
        """Add columns (oriented values on I, >= 0), skipping zeros and repeats; how many.

        Each is solved, refined once with a double-double residual, and its final
        residual computed in double-double with its bound (batched).
        """
        new: list[tuple[str, npt.NDArray[np.float64]]] = []
        for name, values in items:
            v = np.maximum(values, 0.0)
            top = float(v.max()) if v.size else 0.0
            if not top > 0.0 or len(self.values) + len(new) >= self.max_columns:
                continue
            v = v / top
            if any(
                float(np.abs(o - v).max()) <= 1e-6 for o in [*self.values, *(q for _, q in new)]
            ):
                continue
            new.append((name, v))
        if not new:
            return 0
        ws = [self.contact.scatter(v, self.problem.model.A.createVecRight()) for _, v in new]
        xs = [w.duplicate() for w in ws]
        d, rv = ws[0].duplicate(), ws[0].duplicate()
        for w, x in zip(ws, xs, strict=True):
            self.matrix.solve(w, x)
        for _ in range(self.refinements):
            rho, _ = self.residual(ws, xs)
            for j, x in enumerate(xs):
                rv.array[:] = rho[:, j]
                self.matrix.solve(rv, d)
                x.axpy(1.0, d)
        rho, err = self.residual(ws, xs)
        for j, ((name, v), w, x) in enumerate(zip(new, ws, xs, strict=True)):
            rv.array[:] = rho[:, j]
            self.matrix.solve(rv, d)
            self.d_norm.append(float(d.norm()))  # type: ignore[arg-type]
            self.names.append(name)
            self.values.append(v)
            self.w.append(w)
            self.x.append(x)
            self.rho.append(rho[:, j].copy())
            self.err.append(err[:, j].copy())
            self.xI.append(self.contact.values(x))
        d.destroy()
        rv.destroy()
        return len(new)

    def _entry(self, a: int, b: int) -> tuple[float, float]:
        key = (min(a, b), max(a, b))
        if key in self._G:
            return self._G[key]
        a, b = key
        va, xb = self.values[a], self.xI[b]
        nz = np.flatnonzero(va)
        p, e = two_product(va[nz], xb[nz])
        t1 = math.fsum(np.concatenate([p, e]).tolist())  # exactly rounded
        xa = self.x[a].array_r
        rb, eb = self.rho[b], self.err[b]
        local = np.array(
            [
                float(xa @ rb),
                float(np.abs(xa) @ np.abs(rb)),
                float(np.abs(xa) @ eb),
                float((np.abs(rb) + eb) @ (np.abs(rb) + eb)),
            ]
        )
        t2, abs2, ea, rb2 = self.comm.allreduce(local, op=MPI.SUM)
        n = self.x[a].getSize()
        value = t1 + t2
        bound = (
            2 * U * abs(t1)
            + gamma(n) * abs2 * (1 + gamma(n))
            + ea * (1 + gamma(n))
            + 2.0 * self.d_norm[a] * math.sqrt(rb2)
            + U * abs(value)
        )
        self._G[key] = (value, bound)
        return value, bound

    def gram(
        self, use: list[int] | None = None
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(G, E) of the columns ``use`` (default all): computed G and a bound of its error."""
        use = list(range(self.r)) if use is None else use
        r = len(use)
        G, E = np.empty((r, r)), np.empty((r, r))
        for i, a in enumerate(use):
            for j in range(i, r):
                G[i, j], E[i, j] = self._entry(a, use[j])
                G[j, i], E[j, i] = G[i, j], E[i, j]
        return G, E

    def gram_negative(self, opts: LowRankOptions) -> int:
        """Negative eigenvalues of the scaled G of the well-conditioned columns."""
        use = _select(self, [], opts)
        G, E = self.gram(use)
        dg = 1.0 / _pow2(np.sqrt(np.maximum(np.abs(np.diag(G)), np.diag(E))))
        return int((np.linalg.eigvalsh(G * dg[:, None] * dg[None, :]) < 0).sum())

    def combination(self, coef: npt.NDArray[np.float64]) -> PETSc.Vec:
        """sum_a coef_a x_a (a new vector; the caller destroys it)."""
        u = self.x[0].duplicate()
        u.zeroEntries()
        u.maxpy(coef.tolist(), self.x)
        return u

    def destroy(self) -> None:
        for v in (*self.w, *self.x):
            v.destroy()
        self.w, self.x = [], []
        self.residual.destroy()


def _eig_error(M: npt.NDArray[np.float64], E: npt.NDArray[np.float64]) -> float:
    """Weyl bound on the eigenvalue error: ||E||_F plus LAPACK's backward error."""
    n = M.shape[0]
    return float(np.linalg.norm(E)) + 4 * n * U * float(np.linalg.norm(M))


def _inertia(
    M: npt.NDArray[np.float64], E: npt.NDArray[np.float64], factor: float
) -> tuple[int, int, float]:
    """(negative count, positive count, margin) of the exact matrix within E of M.

    margin = smallest |eigenvalue| over factor times the error bound; the counts are
    proven when margin > 1.
    """
    eig = np.linalg.eigvalsh(0.5 * (M + M.T))
    err = _eig_error(M, E) * factor
    margin = float(np.abs(eig).min() / err) if err > 0 else math.inf
    return int((eig < 0).sum()), int((eig > 0).sum()), margin


#: Clarabel's settings for the SPN programs (tight: the margin scales like delta).
SPN_SETTINGS: dict[str, bool | float | int] = {
    "verbose": False,
    "tol_gap_abs": 1e-12,
    "tol_gap_rel": 1e-12,
    "tol_feas": 1e-12,
    "tol_ktratio": 1e-10,
    "max_iter": 200,
}


def _spn(P: npt.NDArray[np.float64]) -> tuple[float, npt.NDArray[np.float64], Any]:
    """Max t: N >= 0 (zero diagonal), P - N >= t I, t <= 1; (t, N clipped, dual Y or None).

    Clarabel directly (its import costs milliseconds, cvxpy's seconds): variables
    x = (t, N_ab for a < b); the PSD cone on the upper triangle by columns with the
    off-diagonal entries scaled by sqrt(2) (Clarabel's convention).
    """
    import clarabel
    import scipy.sparse as sp

    n = P.shape[0]
    iu, ju = np.triu_indices(n, 1)
    p = len(iu)
    # svec order: (i, j), i <= j, column by column.
    jj, ii = np.nonzero(np.tril(np.ones((n, n), dtype=bool)))  # jj >= ii, by columns
    order = np.lexsort((ii, jj))
    ii, jj = ii[order], jj[order]
    k = len(ii)
    diag = ii == jj
    scale = np.where(diag, 1.0, math.sqrt(2.0))
    pair = {(int(a), int(b)): q for q, (a, b) in enumerate(zip(iu, ju, strict=True))}
    # t on the diagonal, N_ab (scaled) off it
    cols = [0 if diag[row] else 1 + pair[(int(ii[row]), int(jj[row]))] for row in range(k)]
    rows, vals = list(range(k)), scale.tolist()
    A_psd = sp.csc_matrix((vals, (rows, cols)), shape=(k, 1 + p))
    A_nn = sp.hstack([sp.csc_matrix((p, 1)), -sp.identity(p, format="csc")])
    A_t = sp.csc_matrix(([1.0], ([0], [0])), shape=(1, 1 + p))
    A = sp.vstack([A_nn, A_t, A_psd]).tocsc()
    b = np.concatenate([np.zeros(p), [1.0], scale * P[ii, jj]])
    q = np.zeros(1 + p)
    q[0] = -1.0
    cones = [clarabel.NonnegativeConeT(p + 1), clarabel.PSDTriangleConeT(n)]
    settings = clarabel.DefaultSettings()
    for key, value in SPN_SETTINGS.items():
        setattr(settings, key, value)
    solver = clarabel.DefaultSolver(sp.csc_matrix((1 + p, 1 + p)), q, A, b, cones, settings)
    sol = solver.solve()
    x = np.asarray(sol.x)
    if not np.isfinite(x).all() or str(sol.status) not in ("Solved", "AlmostSolved"):
        return -math.inf, np.zeros((n, n)), None
    N = np.zeros((n, n))
    N[iu, ju] = np.maximum(x[1:], 0.0)
    N = N + N.T
    z = np.asarray(sol.z)[p + 1 :]
    Y = np.zeros((n, n))
    Y[ii, jj] = z / scale
    Y = Y + np.triu(Y, 1).T
    return float(x[0]), N, Y


def _simplex_min(
    P: npt.NDArray[np.float64], starts: list[npt.NDArray[np.float64]], iterations: int = 100
) -> tuple[float, npt.NDArray[np.float64]]:
    """Local minima of z'Pz on the simplex {z >= 0, sum z = 1} from ``starts``; the best.

    Frank-Wolfe with exact line search (a quadratic), all starts at once.
    """
    n = P.shape[0]
    Z = np.array([np.maximum(z, 0.0) for z in starts if np.maximum(z, 0.0).sum() > 0])
    if not len(Z):
        Z = np.full((1, n), 1.0 / n)
    Z = Z / Z.sum(axis=1, keepdims=True)
    rows = np.arange(len(Z))
    for _ in range(iterations):
        G = Z @ P
        k = np.argmin(G, axis=1)
        D = -Z
        D[rows, k] += 1.0
        slope = np.einsum("ij,ij->i", G, D)
        curv = np.einsum("ij,ij->i", D @ P, D)
        active = slope < -1e-15 * np.maximum(1.0, np.abs(np.einsum("ij,ij->i", Z, G)))
        if not active.any():
            break
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(curv > 0, np.minimum(1.0, -slope / curv), 1.0)
        Z = Z + np.where(active, step, 0.0)[:, None] * D
    f = np.einsum("ij,ij->i", Z @ P, Z)
    best = int(np.argmin(f))
    return float(f[best]), Z[best]


def _starts(P: npt.NDArray[np.float64], dual: Any) -> list[npt.NDArray[np.float64]]:
    n = P.shape[0]
    out = [np.eye(n)[k] for k in np.argsort(P.sum(axis=1))[:4]]
    if dual is not None:
        Y = 0.5 * (np.asarray(dual) + np.asarray(dual).T)
        _, vec = np.linalg.eigh(Y)
        out.insert(0, np.abs(vec[:, -1]))
    low = np.unravel_index(np.argmin(P - np.diag(np.diag(P)) * 2), P.shape)
    z = np.zeros(n)
    z[list(low)] = 1.0
    out.insert(0, z)
    return out


def _conditioning(cols: _Columns, use: list[int]) -> tuple[float, npt.NDArray[np.float64]]:
    """(min|eig| / max|eig| of the scaled G of ``use``, the eigenvector of min|eig|)."""
    G, E = cols.gram(use)
    dg = 1.0 / _pow2(np.sqrt(np.maximum(np.abs(np.diag(G)), np.diag(E))))
    w, V = np.linalg.eigh(G * dg[:, None] * dg[None, :])
    k = int(np.argmin(np.abs(w)))
    return float(abs(w[k]) / np.abs(w).max()), V[:, k]


def _prune(cols: _Columns, use: list[int], opts: LowRankOptions) -> list[int]:
    """Drop older columns that nearly repeat newer ones (in the K^-1 metric).

    While the scaled G's condition number exceeds ``prune_condition``, the column of the
    smallest eigenvector's support (not the first) whose removal helps most is dropped,
    if that improves the conditioning tenfold. Ill-conditioned S defeats the SDP.
    """
    out = list(use)
    while len(out) > 2:
        ratio, v = _conditioning(cols, out)
        if ratio * opts.prune_condition >= 1.0:
            break
        best: tuple[float, int] | None = None
        for pos in np.flatnonzero(np.abs(v) > 0.1):
            if pos == 0:
                continue
            trial = out[:pos] + out[pos + 1 :]
            r_trial, _ = _conditioning(cols, trial)
            if best is None or r_trial > best[0]:
                best = (r_trial, int(pos))
        if best is None or best[0] < 10 * ratio:
            break
        cols.dropped.add(out.pop(best[1]))
    return out


def _select(cols: _Columns, use: list[int], opts: LowRankOptions) -> list[int]:
    """``use`` and then each further column in turn, kept if G stays well conditioned.

    A column is kept when every eigenvalue of the scaled G is ``select_margin`` times
    beyond its error bound (a G near singular can prove nothing).
    """
    out = list(use)
    for a in range(cols.r):
        if a in out or a in cols.dropped:
            continue
        trial = [*out, a]
        G, E = cols.gram(trial)
        dg = 1.0 / _pow2(np.sqrt(np.maximum(np.abs(np.diag(G)), np.diag(E))))
        Gs = G * dg[:, None] * dg[None, :]
        _, _, margin = _inertia(Gs, E * dg[:, None] * dg[None, :], opts.margin_factor)
        eig = np.abs(np.linalg.eigvalsh(Gs))
        if margin > opts.select_margin and eig.min() * opts.max_condition > eig.max():
            out.append(a)
    return _prune(cols, out, opts) if opts.prune_condition else out


def _pow2(d: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """The powers of two nearest d (scalings by them are exact)."""
    return np.exp2(np.round(np.log2(np.maximum(d, 1e-300))))


def _check_piece(
    Gs: npt.NDArray[np.float64],
    Es: npt.NDArray[np.float64],
    V: npt.NDArray[np.float64],
    N: npt.NDArray[np.float64],
    m: int,
    factor: float,
) -> float:
    """Margin of the bordered check [[-G, V], [V^T, -N]]: > 1 proves V^TSV - N > 0."""
    r = Gs.shape[0]
    M = np.block([[-Gs, V], [V.T, -N]])
    E = np.zeros_like(M)
    E[:r, :r] = Es
    neg, _, margin = _inertia(M, E, factor)
    return margin if neg == r - m else -margin


def _split_piece(
    V: npt.NDArray[np.float64],
    Vn: npt.NDArray[np.float64],
    Ps: npt.NDArray[np.float64],
    z: npt.NDArray[np.float64],
) -> list[npt.NDArray[np.float64]]:
    """Sub-cones covering cone(V): a star split at the piece's local minimiser z, or a bisection.

    The star split replaces, one at a time, each vertex in the support of z by v = V c
    (c = z in V's scaling, rounded to multiples of 1/256): the new cones cover cone(V)
    exactly when v is computed exactly, which is checked in rational arithmetic. At the
    minimiser the new vertex's row of the piece's matrix is nonnegative (the simplex
    optimality condition), which is what an SPN split needs. Otherwise the edge with the
    most negative scaled entry is bisected (the midpoint of dyadic vertices is exact).
    """
    from fractions import Fraction

    r = V.shape[0]
    c = z * (Vn[0] / V[0] if False else 1.0)
    scale = np.array([Vn[:, k].max() / V[:, k].max() for k in range(r)])  # powers of two
    c = z * scale
    c = np.round(c / c.max() * 256.0) / 256.0
    support = np.flatnonzero(c > 0)
    if support.size >= 2:
        v = V @ c
        exact = all(
            sum(Fraction(float(V[i, k])) * Fraction(float(c[k])) for k in support)
            == Fraction(float(v[i]))
            for i in range(r)
        )
        if exact:
            pieces = []
            for k in support:
                W = V.copy()
                W[:, k] = v
                pieces.append(W)
            return pieces
    a, b = np.unravel_index(np.argmin(Ps + np.eye(r) * 1e300), Ps.shape)
    return _halves(V, int(a), int(b))


def _halves(V: npt.NDArray[np.float64], a: int, b: int) -> list[npt.NDArray[np.float64]]:
    """The two halves of the cone piece V (columns: generators) cut at the middle of a, b."""
    mid = 0.5 * (V[:, a] + V[:, b])
    pieces = []
    for k in (a, b):
        W = V.copy()
        W[:, k] = mid
        pieces.append(W)
    return pieces


@dataclass
class _OrthantStats:
    """What :func:`_orthant` met: pieces, margins, the best SDP margin, why it stopped."""

    best_t: float | None = None
    margin: float | None = None
    pieces: int = 0
    f: float | None = None
    stopped: str | None = None


def _orthant(
    Gs: npt.NDArray[np.float64],
    Es: npt.NDArray[np.float64],
    m: int,
    opts: LowRankOptions,
    stats: _OrthantStats,
    near: float,
    out_of_time: Any,
) -> tuple[bool, npt.NDArray[np.float64] | None]:
    """Copositivity of S = Gs^-1 on the orthant, piece by piece.

    Returns (proven, y): y >= 0 with y'Sy < near (on a piece scaled to a unit
    diagonal; a cut, or with near > 0 a point where the relaxation is nearly tight) when
    one is found before the proof.
    """
    r = Gs.shape[0]
    S = np.linalg.inv(Gs)
    S = 0.5 * (S + S.T)
    if (np.diag(S) < 0).any():
        return False, np.eye(r)[int(np.argmin(np.diag(S)))]
    queue = [np.eye(r)]  # dyadic vertices: midpoints stay exact
    done = 0
    stats.best_t = math.inf
    while queue:
        V = queue.pop()
        # Columns scaled by powers of two (exact: the piece is the same cone).
        Vn = V / _pow2(np.sqrt(np.abs(np.diag(V.T @ S @ V))))
        Ps = Vn.T @ S @ Vn
        Ps = 0.5 * (Ps + Ps.T)
        t, N, dual = _spn(Ps)
        ok = False
        if math.isfinite(t) and t > 0:
            margin = _check_piece(Gs, Es, Vn, N, m, opts.margin_factor)
            ok = margin > 1.0
            if ok:
                stats.margin = min(math.inf if stats.margin is None else stats.margin, margin)
        stats.best_t = min(stats.best_t, t)
        if ok:
            done += 1
            stats.pieces = done + len(queue)
            continue
        f, z = _simplex_min(Ps, _starts(Ps, dual))
        stats.f = f
        if f < near:
            return False, Vn @ z
        if done + len(queue) + 2 > opts.max_pieces or out_of_time():
            stats.pieces = done + len(queue) + 1
            stats.stopped = "time" if out_of_time() else "pieces"
            return False, None
        queue += _split_piece(V, Vn, Ps, z)
    stats.pieces = done
    return True, None


def _pencil_modes(
    problem: UnilateralProblem,
    matrix: ShiftedMatrix,
    cols: _Columns,
    lam: float,
    m: int,
    iterations: int,
) -> list[tuple[str, npt.NDArray[np.float64]]]:
    r"""Positive and negative parts on I of approximate pencil modes below ``lam``.

    Block inverse iteration :math:`V \leftarrow K^{-1}BV` with the factorised K (block
    m + 3, started from the free mode and the last columns' solutions, orthogonalised),
    then Rayleigh-Ritz on (A, B); the Ritz
    vectors with a value below ``lam`` (heuristics only: the certificate checks whatever
    columns it gets).
    """
    k = min(m + 3, cols.r + 1)
    V = [problem.solve_free().function.x.petsc_vec.copy()]
    V += [x.copy() for x in cols.x[-(k - 1) :]]
    work = V[0].duplicate()
    for _ in range(iterations):
        for j, v in enumerate(V):
            problem.model.B.mult(v, work)
            matrix.solve(work, v)
            for q in V[:j]:  # modified Gram-Schmidt: keep the block independent
                v.axpy(-v.dot(q).real, q)
            v.scale(1.0 / float(v.norm()))
    AV = [problem.model.A.createVecLeft() for _ in V]
    BV = [problem.model.B.createVecLeft() for _ in V]
    for v, a, b in zip(V, AV, BV, strict=True):
        problem.model.A.mult(v, a)
        problem.model.B.mult(v, b)
    Am = np.array([[v.dot(a).real for a in AV] for v in V])
    Bm = np.array([[v.dot(b).real for b in BV] for v in V])
    out: list[tuple[str, npt.NDArray[np.float64]]] = []
    try:
        import scipy.linalg

        theta, Y = scipy.linalg.eigh(0.5 * (Bm + Bm.T), 0.5 * (Am + Am.T))
    except (np.linalg.LinAlgError, ValueError):
        theta, Y = np.zeros(0), np.zeros((k, 0))
    for j in range(len(theta)):
        if theta[j] > 0 and 1.0 / theta[j] < lam:
            work.zeroEntries()
            work.maxpy(Y[:, j].tolist(), V)
            values = problem.contact.values(work)
            out += [(f"mode{j}+", np.maximum(values, 0.0)), (f"mode{j}-", np.maximum(-values, 0.0))]
    for v in (*V, *AV, *BV, work):
        v.destroy()
    return out


def _reaction(candidate: Candidate) -> npt.NDArray[np.float64]:
    return np.maximum(0.0, -candidate.forces)


def _sources(
    problem: UnilateralProblem, candidate: Candidate, others: list[Candidate], units: int
) -> list[tuple[str, npt.NDArray[np.float64]]]:
    """The first columns (oriented values on I), in order of use.

    With at most ``units`` constrained nodes, their unit vectors (U = I: the relaxation is
    exact, the route is the full copositivity test of the Schur complement).
    """
    i = problem.num_constrained
    if i <= units:
        return [(f"node{k}", np.eye(1, i, k)[0]) for k in range(i)]
    w_plus = _reaction(candidate)
    sources = [("reaction", w_plus)]
    mirrors = mirror_maps(problem)
    sources += [(f"mirror-{name}", w_plus[perm]) for name, perm in mirrors.items()]
    for k, other in enumerate(others):
        w = _reaction(other)
        sources.append((f"kkt{k}", w))
        sources += [(f"kkt{k}-mirror-{name}", w[perm]) for name, perm in mirrors.items()]
    phi = problem.contact.values(problem.solve_free().function.x.petsc_vec)
    return [*sources, ("free+", np.maximum(phi, 0.0)), ("free-", np.maximum(-phi, 0.0))]


def lowrank_certificate(
    problem: UnilateralProblem,
    matrix: ShiftedMatrix,
    candidate: Candidate,
    others: list[Candidate],
    opts: LowRankOptions | None = None,
) -> LowRankOutcome:
    r"""The smallest verified :math:`\delta` of ``opts.deltas`` (a verified bracket).

    The deltas are tried in the order given; after a success the next (smaller) one
    is tried, after a failure the search stops if something is verified, and otherwise
    goes on with ``opts.fallback`` (larger deltas). The columns of one attempt (cuts
    included) seed the next. A refuting mode ends the search.

    Args:
        problem: The problem.
        matrix: :math:`K(\lambda)`, refactorised per delta.
        candidate: The KKT point.
        others: Other KKT points (their reactions become columns).
        opts: Deltas and budgets.

    Note:
        Collective.
    """
    opts = opts or LowRankOptions()
    out = LowRankOutcome()
    free_s = problem.timings.get("free_solve_s")
    if opts.time_budget is not None and free_s:
        budget = max(opts.time_budget * free_s, opts.min_time_s)
        out._deadline = (time.perf_counter() + budget, problem.comm)
    sources = _sources(problem, candidate, others, opts.unit_columns)

    def attempt(delta: float) -> LowRankAttempt:
        nonlocal sources
        record, sources = _attempt(problem, matrix, candidate, delta, sources, opts, out)
        return record

    search_deltas(out, candidate.load, opts.deltas, opts.fallback, attempt, out.out_of_time)
    out.solves = matrix.solves
    return out


def _scaled_gram(
    cols: _Columns, use: list[int]
) -> tuple[
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
]:
    """G of the columns ``use``, its scaling D (powers of two: exact), D G D and D E D.

    E is G's error bound.
    """
    G, E = cols.gram(use)
    dg = 1.0 / _pow2(np.sqrt(np.maximum(np.abs(np.diag(G)), np.diag(E))))
    return G, dg, G * dg[:, None] * dg[None, :], E * dg[:, None] * dg[None, :]


def _cut(
    problem: UnilateralProblem,
    cols: _Columns,
    use: list[int],
    coef: npt.NDArray[np.float64],
    candidate: Candidate,
    lam: float,
    stats: _OrthantStats,
    opts: LowRankOptions,
    out: LowRankOutcome,
    cuts: int,
) -> tuple[str | None, bool]:
    """The mode :math:`u = -K^{-1}USy` of a point y the pieces could not prove: a cut.

    An admissible u with a lower quotient refutes the KKT point (``out.refuting``); else
    its positive part (or, if that repeats a column or leaves G singular, the unit
    vectors of its most violated nodes: all of them, the full SDP) becomes a column.

    Returns:
        Why the attempt stops (refuted, out of time), or None; and whether a column was
        added.
    """
    u = cols.combination(coef)  # -K^-1 U S y
    scale = problem.max_abs_w(u)
    values = problem.contact.values(u) / scale
    admissible = bool(values.max() <= problem.tau)
    if admissible and (-1.0 if stats.f is None else stats.f) < 0.0:
        refuting = _refuting(problem, u, values)
        if refuting is not None and refuting.load < candidate.load:
            out.refuting = refuting
    u.destroy()
    if out.refuting is not None:
        return (
            f"refuted: an admissible mode has the load {out.refuting.load:.10g} < {lam:.10g}"
        ), False
    if out.out_of_time():
        return f"the time budget ({cuts} cuts)", False
    if admissible or cuts >= opts.max_cuts:
        return None, False
    order = np.argsort(-values)[: opts.unit_cuts]
    units = [(f"cut{cuts}-node{k}", np.eye(1, len(values), k)[0])
             for k in order if values[k] > 0]  # fmt: skip
    for item in [(f"cut{cuts}", values), *units]:
        if cols.add([item]) and _select(cols, use, opts) != use:
            return None, True
    return None, False


def _attempt(
    problem: UnilateralProblem,
    matrix: ShiftedMatrix,
    candidate: Candidate,
    delta: float,
    sources: list[tuple[str, npt.NDArray[np.float64]]],
    opts: LowRankOptions,
    out: LowRankOutcome,
) -> tuple[LowRankAttempt, list[tuple[str, npt.NDArray[np.float64]]]]:
    """One delta: factorise, columns, cuts, pieces. Returns (record, columns to reuse)."""
    attempt, lam = factor_at(matrix, candidate.load, delta, out, LowRankAttempt)
    neg = attempt.m
    if attempt.why:
        return attempt, sources
    cols = _Columns(problem, matrix, opts.refinements, opts.max_columns)
    try:
        cols.add(sources)
        if _select(cols, [], opts) and cols.gram_negative(opts) < neg:
            cols.add(_pencil_modes(problem, matrix, cols, lam, neg, opts.mode_iterations))
        cuts = 0
        use: list[int] = []
        near = opts.near
        while True:
            use = _select(cols, use, opts)
            G, dg, Gs, Es = _scaled_gram(cols, use)
            gneg, _, gmargin = _inertia(Gs, Es, opts.margin_factor)
            attempt.r, attempt.columns, attempt.cuts = len(use), cols.r, cuts
            attempt.G_negative, attempt.G_margin = gneg, gmargin
            if gneg != neg or gmargin <= 1.0:
                attempt.why = (
                    f"G has {gneg} negative eigenvalues, K {neg}: K is not positive "
                    "definite on ker U^T (the columns miss a negative direction)"
                )
                break
            stats = _OrthantStats()
            proven, ys = _orthant(Gs, Es, neg, opts, stats, near, out.out_of_time)
            attempt.pieces, attempt.best_t = stats.pieces, stats.best_t
            if proven:
                attempt.proven = True
                attempt.margin = math.inf if stats.margin is None else stats.margin
                attempt.why = ""
                break
            if ys is None:
                budget = (
                    "the time budget" if stats.stopped == "time" else f"{opts.max_pieces} pieces"
                )
                best_t = -math.inf if stats.best_t is None else stats.best_t
                attempt.why = (
                    f"S is not proven copositive within {budget} (best SDP margin "
                    f"{best_t:.3g}, {cuts} cuts)"
                )
                break
            coef = np.zeros(cols.r)
            coef[use] = -np.linalg.solve(G, ys / dg)  # G_s = D G D, S_s = D^-1 S D^-1
            why, grown = _cut(problem, cols, use, coef, candidate, lam, stats, opts, out, cuts)
            if why is not None:
                attempt.why = why
                break
            if not grown:
                if near > 0.0:
                    near = 0.0  # no tightening cut there: partition instead
                    continue
                attempt.why = (
                    f"budget: {cuts} cuts"
                    if cuts >= opts.max_cuts
                    else "a cut repeats a column or leaves G nearly singular"
                )
                break
            cuts += 1
            near = opts.near
        return attempt, list(zip(cols.names, cols.values, strict=True))
    finally:
        cols.destroy()


def factor_at[A: LowRankAttempt](
    matrix: ShiftedMatrix, load: float, delta: float, out: LowRankOutcome, kind: type[A]
) -> tuple[A, float]:
    """K factorised at ``load (1 - delta)``: the attempt's record (of type ``kind``) and the shift.

    The record's ``why`` says when no bracket route applies there (K singular, or fewer
    than two negative eigenvalues); ``out.m`` is the negative eigenvalues (both routes).
    """
    lam = load * (1.0 - delta)
    neg, zero, _ = matrix.factor(lam)
    out.m = neg
    attempt = kind(delta=delta, m=neg)
    if zero:
        attempt.why = "K is singular at this shift"
    elif neg < 2:
        attempt.why = f"K has {neg} negative eigenvalue(s): the other routes apply"
    return attempt, lam


def _refuting(
    problem: UnilateralProblem, u: PETSc.Vec, values: npt.NDArray[np.float64]
) -> Refuting | None:
    """The admissible mode u as a record (load = its Rayleigh quotient), if b(u, u) > 0."""
    load = rayleigh(problem, u)
    if load is None:
        return None
    return Refuting(load=load, values=values, vector=np.array(u.array_r, dtype=np.float64))


def search_deltas(
    out: LowRankOutcome,
    load: float,
    deltas: tuple[float, ...],
    fallback: tuple[float, ...],
    attempt: Callable[[float], LowRankAttempt],
    stop: Callable[[], bool] | None = None,
    proceed: Callable[[LowRankAttempt], bool] | None = None,
) -> None:
    """Relative distances below ``load`` tried in order while verified (both bracket routes).

    After a success the next (smaller) delta is tried (if ``proceed(record)`` says so);
    after a failure the search stops if something is verified, else goes on with
    ``fallback`` (larger deltas). A refuting mode (``out.refuting``) ends it. Fills
    ``out``'s value, delta, pieces, margin, r, why and attempts from the records
    ``attempt(delta)`` returns (the split route.s
    :class:`~unibuckle_fenicsx.certificate.records.SplitAttempt` among them).
    """
    queue, rest = list(deltas), list(fallback)
    while queue and not (stop is not None and stop()):
        delta = queue.pop(0)
        record = attempt(delta)
        out.attempts.append(record)
        if out.refuting is not None:
            out.why = record.why
            break
        if record.proven:
            out.value, out.delta = load * (1.0 - delta), delta
            out.pieces, out.margin, out.r = record.pieces, record.margin, record.r
            rest = []
            if proceed is not None and not proceed(record):
                break
        elif out.value is not None:
            break  # the previous (larger) delta stands
        else:
            queue, rest = rest, []  # nothing verified: larger deltas
    if out.value is None and out.refuting is None:
        out.why = "no delta tried"
        if out.attempts:
            last = out.attempts[-1]
            best_t = last.best_t if isinstance(last.best_t, float) else None
            out.why, out.r, out.pieces = last.why, last.r, last.pieces
            out.margin = float(best_t or -math.inf)
