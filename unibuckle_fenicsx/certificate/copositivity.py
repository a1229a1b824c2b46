r"""A verified lower bound on the unilateral critical load: copositivity on the cone.

Let :math:`K(\lambda) = A - \lambda B` (edge-constrained rows decoupled) and C the cone
:math:`\{u : u_I \le 0\}`. If an i x i matrix :math:`N \ge 0` (entrywise) satisfies
:math:`K(\lambda) - N_{pad} \succeq 0` (N padded with zeros outside :math:`I \times I`),
then every :math:`u \in C` has :math:`u^T K u \ge u_I^T N u_I \ge 0`, so no admissible
mode has a Rayleigh quotient below :math:`\lambda`: :math:`\lambda \le \lambda_c`. The
certificate tries :math:`\lambda_{lb} = \lambda(1 - \delta)` below the load found, for
:math:`\delta` on a 1-2-5 grid from the smallest the rounding allows (predicted from
matrix-vector products), one sparse :math:`LDL^T` of :math:`K(\lambda_{lb})` each:
upward until one certifies, or, once a dense SDP route (below) has failed at one, by
bisection of the grid above it (the smallest that certifies, if success grows with
:math:`\delta`; an SDP costs far more than a factorisation).

**Rank-2 route** (exactly one pencil eigenvalue below :math:`\lambda_{lb}`, i.e. one
negative eigenvalue of K). With :math:`N = c(w_+w_-^T + w_-w_+^T)`, :math:`w_\pm \ge 0`
on I, Haynsworth's inertia additivity on :math:`[[K, U], [U^T, C^{-1}]]`,
:math:`U = [w_+\ w_-]`, :math:`C = c[[0,1],[1,0]]`, gives
:math:`\mathrm{neg}(K - N) = \mathrm{neg}(K) + \mathrm{neg}(T) - 1` with
:math:`T = [[\alpha, 1/c - \gamma], [1/c - \gamma, \beta]]`, :math:`\alpha = -w_+^T K^{-1}
w_+`, :math:`\beta = -w_-^T K^{-1} w_-`, :math:`\gamma = w_+^T K^{-1} w_-`. Choosing
:math:`1/c` = the computed :math:`\gamma`, :math:`K - N \succ 0` follows from
:math:`\alpha, \beta > 0` and :math:`\alpha\beta > e_\gamma^2` (the error of
:math:`\gamma`), all checked with rigorous floating-point bounds on the two solves
(residuals refined once; :func:`ShiftedMatrix.bilinear`). :math:`w_+` is the contact
reaction :math:`-r` of the KKT point (:math:`\alpha = 0` at its load and grows as
:math:`\lambda_{lb}` decreases, :math:`d\alpha/d\lambda = -u^TBu`); :math:`w_-` is a
nonnegative vector in the other *nappe* of :math:`\{v: v^TK^{-1}v < 0\}`: the reaction of
another KKT point on the other side (told by the sign of :math:`\varphi_1^T w`,
:math:`\varphi_1` the free mode), the mirror image of :math:`w_+` when the constrained
nodes are symmetric, or the maximiser of the concave :math:`-w^TK^{-1}w` over
:math:`\{w \ge 0, a^Tw = 1\}` in that nappe (projected gradient, one solve per step).
Below the second pencil eigenvalue such a :math:`w_-` exists whenever
:math:`\lambda_{lb} < \lambda_c` (a KKT point below :math:`\lambda_2` is the minimum of
its nappe), so the route is complete there; only finding :math:`w_-` can fail.

**PSD**: no negative eigenvalue at all (:math:`\lambda_{lb}` below the free load: an
inactive obstacle).

**SDP routes** (two or more pencil eigenvalues below, small i; the ``sdp`` extra):
:mod:`unibuckle_fenicsx.certificate.copositivity_sdp`.

What is certified is the stored, symmetrised matrix fl(A - lambda B); the rounding of the
products lambda B_ij (1e-16 relative) is far below the gaps used (>= 1e-9).

Note:
    Collective on the problem's communicator. Options prefix ``unibuckle_certify_``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

from mpi4py import MPI

import msgspec
import numpy as np
import numpy.typing as npt
from msgspec import UnsetType

from unibuckle_fenicsx.certificate.records import (
    AttemptRecord,
    LowRankMargins,
    LowRankRecord,
    Margins,
    NoMargins,
    PsdMargins,
    Rank2Margins,
    Rank2Record,
    Rank2Try,
    Refuting,
    SdpRecord,
    SearchRecord,
    SectorRecord,
    SplitRecord,
)
from unibuckle_fenicsx.certificate.shifted import (
    EPS,
    ShiftedMatrix,
    absdot,
    mirror_maps,
    norm2,
)
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem

if TYPE_CHECKING:  # pragma: no cover
    from unibuckle_fenicsx.certificate.copositivity_lowrank import LowRankOptions, LowRankOutcome
    from unibuckle_fenicsx.certificate.copositivity_split import SplitOptions, SplitOutcome

__all__ = ["BoundOptions", "LowerBound", "copositivity_bound"]


@dataclass(frozen=True)
class BoundOptions:
    """Settings of the copositivity certificate.

    Attributes:
        deltas: Relative distances below the load to try (one factorisation each); the
            first tried is the first at least ``slack`` times the predicted smallest.
        slack: See ``deltas``.
        safety: alpha, beta, gamma must exceed this many times their error bounds.
        rel_margin: ... and this fraction of ||w|| ||K^-1 w|| (against backward error).
        search_iterations: Solves allowed for the search of w- in the other nappe.
        sdp_max_constrained: The SDP routes run when i is at most this (dense i x i
            semidefinite programs: seconds at i = 50, inaccurate beyond about 80).
        sectors: Sector counts tried by the sector SDP route (two negative eigenvalues).
        split: Budgets of the split route (two or more negative eigenvalues, any i;
            :mod:`unibuckle_fenicsx.certificate.copositivity_split`); None skips it.
        lowrank: Budgets of the low-rank route, tried when the split route proves nothing
            and refutes nothing (:mod:`unibuckle_fenicsx.certificate.copositivity_lowrank`);
            None skips it.
    """

    deltas: tuple[float, ...] = (1e-9, 2e-9, 5e-9, 1e-8, 2e-8, 5e-8, 1e-7, 2e-7, 5e-7, 1e-6)
    slack: float = 1.25
    safety: float = 4.0
    rel_margin: float = 1e-12
    search_iterations: int = 100
    sdp_max_constrained: int = 60
    sectors: tuple[int, ...] = (3, 4, 8)
    split: SplitOptions | None = field(default_factory=lambda: _split_options())
    lowrank: LowRankOptions | None = field(default_factory=lambda: _lowrank_options())


def _lowrank_options() -> LowRankOptions:
    from unibuckle_fenicsx.certificate.copositivity_lowrank import LowRankOptions

    return LowRankOptions()


def _split_options() -> SplitOptions:
    from unibuckle_fenicsx.certificate.copositivity_split import SplitOptions

    return SplitOptions()


@dataclass(frozen=True)
class LowerBound:
    """The outcome of :func:`copositivity_bound`.

    Attributes:
        value: The verified lower bound (None if no route succeeded).
        method: "psd", "rank2-spn", "sdp-spn", "sdp-sectors", "split-spn", "lowrank-spn",
            or "none".
        delta: Relative distance of ``value`` below the load.
        margins: The verified quantities (alpha, beta, gamma and their error bounds, or
            the SDP's smallest eigenvalue).
        attempts: Per delta tried: the inertia of K and what each route found.
        notes: What failed, in words.
        timings: Seconds and counts (factorisations, solves).
        negative_eigenvalues: m, the pencil eigenvalues below the first shift tried (the
            negative eigenvalues of K there).
        lowrank: The low-rank route's record (None if it did not run).
        split: The split route's record (None if it did not run).
        refuting: An admissible mode with a lower load than the KKT point's, met by the
            split or low-rank route, or None.
    """

    value: float | None
    method: str
    delta: float | None
    margins: Margins = field(default_factory=NoMargins)
    attempts: tuple[AttemptRecord, ...] = ()
    notes: tuple[str, ...] = ()
    timings: dict[str, float] = field(default_factory=dict)
    negative_eigenvalues: int | None = None
    lowrank: LowRankRecord | None = None
    refuting: Refuting | None = None
    split: SplitRecord | None = None


def _reaction(candidate: Candidate) -> npt.NDArray[np.float64]:
    """The contact reaction max(0, -r) at I of a KKT point, scaled to max 1."""
    w = np.maximum(0.0, -candidate.forces)
    return w / w.max() if w.max() > 0 else w


def _project(z: npt.NDArray[np.float64], a: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Euclidean projection of z onto {w >= 0, a'w = 1} (a has a positive entry)."""

    def g(nu: float) -> float:
        return float(a @ np.maximum(0.0, z + nu * a)) - 1.0

    lo, hi = -1.0, 1.0
    while g(lo) > 0:
        lo *= 2
    while g(hi) < 0:
        hi *= 2
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if g(mid) < 0 else (lo, mid)
        if hi - lo <= 1e-15 * max(1.0, abs(hi)):
            break
    w = np.maximum(0.0, z + hi * a)
    return w / (a @ w)


def _search_other_nappe(
    problem: UnilateralProblem, matrix: ShiftedMatrix, a: npt.NDArray[np.float64], iterations: int
) -> tuple[npt.NDArray[np.float64], float, int]:
    r"""Maximise :math:`f(w) = -w^TK^{-1}w` on :math:`\{w \ge 0, a^Tw = 1\}` (concave there).

    Projected gradient with Barzilai-Borwein steps and exact line search, one solve per
    iterate; stops at the first :math:`f > 0`. Returns (best w, its f, iterations).
    """
    contact = problem.contact
    vec = problem.model.A.createVecRight()
    x = vec.duplicate()

    def minus_inverse(v: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        matrix.solve(contact.scatter(v, vec), x)
        return -contact.values(x)

    w = _project(np.maximum(a, 0.0), a)
    y = minus_inverse(w)
    f = float(w @ y)
    best = (w.copy(), f)
    step = 1.0 / max(float(np.abs(y).max()), 1e-300)
    w_prev = g_prev = None
    it = 0
    for _ in range(iterations):
        it += 1
        g = 2 * y
        if w_prev is not None and g_prev is not None:
            s, dg = w - w_prev, g - g_prev
            sy = float(s @ dg)
            if sy < 0:  # concave: s'dg < 0
                step = float(s @ s) / (-sy)
        d = _project(w + step * g, a) - w
        if np.abs(d).max() <= 1e-14 * np.abs(w).max():
            break
        Qd = minus_inverse(d)
        dQd, dQw = float(d @ Qd), float(d @ y)
        t = 1.0 if dQd >= 0 else min(1.0, max(0.0, -dQw / dQd))
        if t == 0.0:
            break
        w_prev, g_prev = w, g
        w, y = w + t * d, y + t * Qd
        f = float(w @ y)
        if f > best[1]:
            best = (w.copy(), f)
        if f > 0:
            break
    vec.destroy()
    x.destroy()
    return best[0], best[1], it


def _predict_delta(problem: UnilateralProblem, matrix: ShiftedMatrix, candidate: Candidate,
                   safety: float) -> float:  # fmt: skip
    r"""Smallest delta at which alpha should clear ``safety`` times its rounding bound.

    :math:`\alpha(\lambda_c(1-\delta)) \approx \delta\lambda_c u^TBu / s^2` against a bound
    :math:`\approx \gamma_m(|u|^T|r| + |u|^T|K||u|)/s^2` (s = max w): no factorisation.
    """
    u = candidate.mode.x.petsc_vec
    matrix.build(candidate.load)
    if matrix.Kabs is None:
        raise RuntimeError(
            "_predict_delta: expected matrix.Kabs is not None (an internal invariant)"
        )
    r, _, _ = problem.residual(candidate.load, u)
    ua, Ku, Bu = u.duplicate(), u.duplicate(), u.duplicate()
    ua.array[:] = np.abs(u.array_r)
    matrix.Kabs.mult(ua, Ku)
    problem.model.B.mult(u, Bu)
    m = matrix.row_length + 1
    num = m * EPS * (absdot(u, r) + float(ua.dot(Ku)))
    den = candidate.load * float(u.dot(Bu))
    for v in (ua, Ku, Bu):
        v.destroy()
    return safety * num / den


def _rank2(
    problem: UnilateralProblem,
    matrix: ShiftedMatrix,
    w_plus: npt.NDArray[np.float64],
    candidates: list[tuple[str, npt.NDArray[np.float64]]],
    options: BoundOptions,
) -> tuple[Rank2Record, Rank2Margins | None]:
    """Alpha for w+, then beta and gamma for each w- candidate; the first that certifies."""
    contact = problem.contact
    vec = problem.model.A.createVecRight()
    sp = matrix.refined(contact.scatter(w_plus, vec.duplicate()))
    a_val, alpha_err = ShiftedMatrix.bilinear(sp, sp)
    alpha = -a_val
    scale_p = norm2(sp.x) * norm2(sp.w)
    alpha_ok = bool(alpha > options.safety * alpha_err and alpha > options.rel_margin * scale_p)
    record = Rank2Record(alpha=alpha, alpha_err=alpha_err, alpha_ok=alpha_ok, tried=[])
    found = None
    if alpha_ok:
        for name, w_minus in candidates:
            sm = matrix.refined(contact.scatter(w_minus, vec.duplicate()))
            b_val, beta_err = ShiftedMatrix.bilinear(sm, sm)
            gamma, gamma_err = ShiftedMatrix.bilinear(sp, sm)
            beta = -b_val
            scale_m = norm2(sm.x) * norm2(sm.w)
            sm.destroy()
            ok = (
                beta > options.safety * beta_err
                and beta > options.rel_margin * scale_m
                and gamma > options.safety * gamma_err
                and (alpha - alpha_err) * (beta - beta_err) > gamma_err**2
            )
            entry = Rank2Try(w_minus=name, beta=beta, beta_err=beta_err, gamma=gamma,
                             gamma_err=gamma_err, ok=bool(ok))  # fmt: skip
            record.tried.append(entry)
            if ok:
                found = Rank2Margins(
                    alpha=alpha, alpha_err=alpha_err, **msgspec.structs.asdict(entry), c=1.0 / gamma
                )
                break
    sp.destroy()
    vec.destroy()
    return record, found


def copositivity_bound(
    problem: UnilateralProblem,
    candidate: Candidate,
    others: list[Candidate] | None = None,
    options: BoundOptions | None = None,
    matrix: ShiftedMatrix | None = None,
) -> LowerBound:
    r"""Verified lower bound on the critical load near the KKT point ``candidate``.

    Args:
        problem: The problem (with an obstacle); its free mode is computed if absent.
        candidate: The returned KKT point (feasible, forces pushing).
        others: Further KKT points, candidates for the other nappe's :math:`w_-`.
        options: :class:`BoundOptions`.
        matrix: The :class:`~.shifted.ShiftedMatrix` of the problem's pencil to factorise
            (the caller's, left alive: its symbolic analysis serves the caller's further
            factorisations); default a new one, destroyed here.

    Returns:
        The bound, with the route and margins that verified it, or ``value=None``.

    Note:
        Collective.
    """
    opts = options or BoundOptions()
    t0 = time.perf_counter()
    notes: list[str] = []
    attempts: list[AttemptRecord] = []
    nappes = _Nappes.of(problem, candidate, others or [])
    own = matrix is None
    if matrix is None:
        matrix = ShiftedMatrix(
            problem.model.A, problem.model.B, shared=problem.eigensolver.factorization
        )
    start = (matrix.factorisations, matrix.solves, matrix.factor_s, matrix.solve_s)
    lowrank: LowRankRecord | None = None
    split: SplitRecord | None = None
    refuting: Refuting | None = None
    try:
        if not nappes.w_plus.max() > 0:
            notes.append("the KKT point has no contact force (w+ = 0)")
        predicted = _predict_delta(problem, matrix, candidate, opts.safety)
        deltas = [d for d in opts.deltas if d >= opts.slack * predicted] or [opts.deltas[-1]]
        result = _search_shifts(problem, matrix, nappes, candidate, deltas, opts, attempts, notes)
        # Two or more pencil eigenvalues below some shift tried: the rank-2 route cannot.
        several = any(a.inertia[0] >= 2 for a in attempts)
        if result is None and several:
            routes = _split_routes(problem, matrix, candidate, others or [], opts, notes)
            result, split, lowrank, refuting = routes
    finally:
        timings = _timings(problem, matrix, t0, start)
        if own:
            matrix.destroy()
    if result is None:
        notes.append(
            "no certificate at any delta tried "
            f"({', '.join(f'{d:g}' for d in deltas)}): the lower bound stays at the "
            "algorithm's"
        )
        result = LowerBound(None, "none", None)
    return replace(
        result,
        attempts=tuple(attempts),
        notes=tuple(notes),
        timings=timings,
        negative_eigenvalues=attempts[0].inertia[0] if attempts else None,
        lowrank=lowrank,
        refuting=refuting,
        split=split,
    )


def _search_shifts(
    problem: UnilateralProblem,
    matrix: ShiftedMatrix,
    nappes: _Nappes,
    candidate: Candidate,
    deltas: list[float],
    opts: BoundOptions,
    attempts: list[AttemptRecord],
    notes: list[str],
) -> LowerBound | None:
    r"""The smallest shift :math:`\lambda(1 - \delta)` of ``deltas`` :func:`_at_shift` verifies.

    Upward from the smallest while a shift costs one factorisation; once a dense SDP has
    failed (seconds each), by bisection of what is left. Each shift tried is appended to
    ``attempts``. Returns the bound, or None. Collective.
    """
    result: LowerBound | None = None
    untried, bisect = list(deltas), False
    while untried:
        index = len(untried) // 2 if bisect else 0
        delta = untried[index]
        lam = candidate.load * (1.0 - delta)
        neg, zero, pos = matrix.factor(lam)
        attempt = AttemptRecord(delta=delta, inertia=[neg, zero, pos])
        attempts.append(attempt)
        found, stop = _at_shift(problem, matrix, nappes, lam, attempt, opts, notes)
        if found is not None:
            result = found  # smaller than any earlier success: it is tried below them
            if not bisect:
                break
            untried = untried[:index]
        elif stop:
            break
        else:
            untried = untried[index + 1 :]
            bisect |= not isinstance(attempt.sdp, UnsetType)
    return result


def _split_routes(
    problem: UnilateralProblem,
    matrix: ShiftedMatrix,
    candidate: Candidate,
    others: list[Candidate],
    opts: BoundOptions,
    notes: list[str],
) -> tuple[LowerBound | None, SplitRecord | None, LowRankRecord | None, Refuting | None]:
    """The routes for two or more pencil eigenvalues below the shift.

    The split route, then the low-rank one unless the split found a bound or an admissible
    mode below the load.

    Returns:
        The bound (or None), the split's and the low-rank route's records (None where a
        route did not run) and the refuting mode (or None).

    Note:
        Collective.
    """
    result: LowerBound | None = None
    split: SplitRecord | None = None
    lowrank: LowRankRecord | None = None
    refuting: Refuting | None = None
    if opts.split is not None:
        found = _split(problem, matrix, candidate, others, opts.split, notes)
        split, refuting = found.record(), found.refuting
        result = _route_bound(found, "split-spn")
    if result is None and refuting is None and opts.lowrank is not None:
        outcome = _lowrank(problem, matrix, candidate, others, opts.lowrank, notes)
        if outcome is not None:
            lowrank, refuting = outcome.record(), outcome.refuting
            result = _route_bound(outcome, "lowrank-spn")
    return result, split, lowrank, refuting


def _route_bound(outcome: LowRankOutcome, method: str) -> LowerBound | None:
    """The split or low-rank route's verified bound (``method``), if it found one."""
    if outcome.value is None:
        return None
    margins = LowRankMargins(r=outcome.r, pieces=outcome.pieces, margin=outcome.margin, m=outcome.m)
    return LowerBound(outcome.value, method, outcome.delta, margins)


def _timings(
    problem: UnilateralProblem,
    matrix: ShiftedMatrix,
    t0: float,
    start: tuple[int, int, float, float],
) -> dict[str, float]:
    """Seconds and counts since ``start``: the slowest rank's, the same on every rank."""
    factorisations0, solves0, factor_s0, solve_s0 = start
    return {
        "total_s": problem.comm.allreduce(time.perf_counter() - t0, op=MPI.MAX),
        "factor_s": problem.comm.allreduce(matrix.factor_s - factor_s0, op=MPI.MAX),
        "solve_s": problem.comm.allreduce(matrix.solve_s - solve_s0, op=MPI.MAX),
        "factorisations": matrix.factorisations - factorisations0,
        "solves": matrix.solves - solves0,
    }


@dataclass(frozen=True)
class _Nappes:
    r"""The cone's two nappes as the certificate sees them.

    Attributes:
        w_plus: The KKT point's reaction (scaled to max 1).
        w_minus: Candidates for the other nappe: other KKT points' reactions and the
            mirror images of ``w_plus`` that lie there.
        a: The other nappe's normalisation :math:`a^Tw = 1`.
    """

    w_plus: npt.NDArray[np.float64]
    w_minus: list[tuple[str, npt.NDArray[np.float64]]]
    a: npt.NDArray[np.float64]

    @classmethod
    def of(
        cls, problem: UnilateralProblem, candidate: Candidate, others: list[Candidate]
    ) -> _Nappes:
        """The nappes of ``candidate``, with the free mode telling them apart."""
        phi = problem.contact.values(problem.solve_free().function.x.petsc_vec)
        w_plus = _reaction(candidate)
        sigma = float(phi @ w_plus)
        w_minus: list[tuple[str, npt.NDArray[np.float64]]] = []
        for k, other in enumerate(others):
            w = _reaction(other)
            if w.max() > 0 and float(phi @ w) * sigma < 0:
                w_minus.append((f"kkt{k} ({other.load:.10g})", w))
        for name, perm in mirror_maps(problem).items():
            image = w_plus[perm]
            if float(phi @ image) * sigma < 0:
                w_minus.append((f"mirror-{name}", image))
        return cls(w_plus, w_minus, -np.sign(sigma) * phi)


def _at_shift(
    problem: UnilateralProblem,
    matrix: ShiftedMatrix,
    nappes: _Nappes,
    lam: float,
    attempt: AttemptRecord,
    opts: BoundOptions,
    notes: list[str],
) -> tuple[LowerBound | None, bool]:
    """The routes at the shift ``lam`` (K factorised there): a bound, and whether to stop.

    The inertia decides: K positive definite proves the bound; one negative eigenvalue
    the rank-2 route (with the other nappe searched when no w- certifies); two or more
    the SDP routes. What each found goes into ``attempt``.
    """
    delta = attempt.delta
    neg, zero, pos = attempt.inertia
    w_plus, a = nappes.w_plus, nappes.a
    if zero:
        attempt.why = "K(lambda_lb) is singular"
        return None, False
    if neg == 0:
        notes.append("A - lambda_lb B is positive definite: the obstacle is inactive")
        return LowerBound(lam, "psd", delta, PsdMargins(inertia=[neg, zero, pos])), True
    if neg == 1 and w_plus.max() > 0:
        record, found = _rank2(problem, matrix, w_plus, nappes.w_minus, opts)
        attempt.rank2 = record
        if found is None and record.alpha_ok and (a > 0).any():
            w, f, its = _search_other_nappe(problem, matrix, a, opts.search_iterations)
            attempt.search = SearchRecord(iterations=its, f=f)
            if f > 0:
                record, found = _rank2(problem, matrix, w_plus, [("search", w)], opts)
                attempt.rank2_search = record
        if found is not None:
            return LowerBound(lam, "rank2-spn", delta, found), True
        return None, False
    if neg >= 2:
        route = _sdp(problem, matrix, lam, neg, opts, notes)
        attempt.sdp = route
        sectors = route.sectors
        if route.ok:
            return LowerBound(lam, "sdp-spn", delta, route), True
        if isinstance(sectors, SectorRecord) and sectors.ok:
            return LowerBound(lam, "sdp-sectors", delta, sectors), True
        return None, route.unavailable is True or route.too_large is True
    return None, False


def _split(
    problem: UnilateralProblem,
    matrix: ShiftedMatrix,
    candidate: Candidate,
    others: list[Candidate],
    options: SplitOptions,
    notes: list[str],
) -> SplitOutcome:
    """The split route, unless its estimated cost exceeds ``options.max_cost``.

    Then its outcome says so (``skipped``, the estimate and why), with no attempt.
    """
    from unibuckle_fenicsx.certificate.copositivity_split import (
        SplitOutcome,
        column_sources,
        estimate_cost,
        split_certificate,
    )

    m = matrix.inertia()[0]
    sources = column_sources(problem, candidate, others, options)
    cost = estimate_cost(problem, sources, m, options)
    if options.max_cost is not None and cost > options.max_cost:
        why = (
            f"the split bracket's estimated cost ({cost:.1f} free solves) exceeds "
            f"{options.max_cost:g}: it runs on request only (solver.bracket = true, --bracket)"
        )
        notes.append(f"{m} pencil eigenvalues lie below the load: {why}")
        skipped = SplitOutcome(m=m, why=why, estimated_cost=cost, cost_limit=options.max_cost)
        skipped.skipped = True
        return skipped
    outcome = split_certificate(problem, matrix, candidate, others, options, sources)
    outcome.estimated_cost, outcome.cost_limit = cost, options.max_cost
    if outcome.value is None:
        notes.append(
            f"split certificate: no verified bound (m = {outcome.m} pencil eigenvalues "
            f"below, {outcome.r} columns, {outcome.pieces} pieces): {outcome.why}"
        )
    elif outcome.why:
        notes.append(f"split certificate: {outcome.why}")
    return outcome


def _lowrank(
    problem: UnilateralProblem,
    matrix: ShiftedMatrix,
    candidate: Candidate,
    others: list[Candidate],
    options: LowRankOptions,
    notes: list[str],
) -> Any:
    """The low-rank route (needs Clarabel and SciPy, the ``sdp`` extra); None without them."""
    try:
        from unibuckle_fenicsx.certificate.copositivity_lowrank import lowrank_certificate
    except ImportError as err:
        notes.append(
            "several pencil eigenvalues lie below the load: the low-rank certificate needs "
            f"the 'sdp' extra (pip install 'unibuckle_fenicsx[sdp]'): {err}"
        )
        return None
    outcome = lowrank_certificate(problem, matrix, candidate, others, options)
    if outcome.value is None:
        notes.append(
            f"low-rank certificate: no verified bound (m = {outcome.m} pencil eigenvalues "
            f"below, r = {outcome.r} columns, {outcome.pieces} pieces, best SDP margin "
            f"{outcome.margin:.3g}): {outcome.why}"
        )
    elif outcome.why:
        notes.append(f"low-rank certificate: {outcome.why}")
    return outcome


def _sdp(
    problem: UnilateralProblem,
    matrix: ShiftedMatrix,
    lam: float,
    neg: int,
    opts: BoundOptions,
    notes: list[str],
) -> SdpRecord:
    """The SDP routes for two or more negative eigenvalues (optional extra "sdp")."""
    i = problem.num_constrained
    if i > opts.sdp_max_constrained:
        notes.append(
            f"{neg} pencil eigenvalues lie below the load: the rank-2 certificate does not "
            f"apply, and the full SDP route is limited to i <= {opts.sdp_max_constrained} "
            f"constrained nodes (here {i})"
            + (
                ": the split (or low-rank) route applies"
                if opts.split is not None or opts.lowrank is not None
                else ": the split bracket runs on request (solver.bracket = true, --bracket)"
            )
        )
        return SdpRecord(too_large=True)
    try:
        from unibuckle_fenicsx.certificate import copositivity_sdp
    except ImportError as err:
        notes.append(
            f"{neg} pencil eigenvalues lie below the load: the SDP route needs the 'sdp' "
            f"extra (pip install 'unibuckle_fenicsx[sdp]'): {err}"
        )
        return SdpRecord(unavailable=True)
    route = copositivity_sdp.spn_certificate(problem, matrix, lam)
    if not route.ok and neg == 2 and route.neg_S == 2:
        route.sectors = copositivity_sdp.sector_certificate(problem, matrix, lam, opts.sectors)
    return route
