r"""A verified lower bound on the unilateral critical load: copositivity on the cone.

Let :math:`K(\lambda) = A - \lambda B` (edge-constrained rows decoupled) and C the cone
:math:`\{u : u_I \le 0\}`. If an i x i matrix :math:`N \ge 0` (entrywise) satisfies
:math:`K(\lambda) - N_{pad} \succeq 0` (N padded with zeros outside :math:`I \times I`),
then every :math:`u \in C` has :math:`u^T K u \ge u_I^T N u_I \ge 0`, so no admissible
mode has a Rayleigh quotient below :math:`\lambda`: :math:`\lambda \le \lambda_c`. The
certificate tries :math:`\lambda_{lb} = \lambda(1 - \delta)` below the load found, for
:math:`\delta` on a 1-2-5 grid from the smallest the rounding allows (predicted from
matrix-vector products), one sparse :math:`LDL^T` of :math:`K(\lambda_{lb})` each.

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
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from mpi4py import MPI

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.certificate.shifted import (
    EPS,
    ShiftedMatrix,
    absdot,
    mirror_maps,
    norm2,
)
from unibuckle_fenicsx.model.problem import BucklingProblem, Candidate

if TYPE_CHECKING:  # pragma: no cover
    from unibuckle_fenicsx.certificate.copositivity_lowrank import LowRankOptions

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
        lowrank: Budgets of the low-rank route (two or more negative eigenvalues, any
            i; :mod:`unibuckle_fenicsx.certificate.copositivity_lowrank`); None skips it.
    """

    deltas: tuple[float, ...] = (1e-9, 2e-9, 5e-9, 1e-8, 2e-8, 5e-8, 1e-7, 2e-7, 5e-7, 1e-6)
    slack: float = 1.25
    safety: float = 4.0
    rel_margin: float = 1e-12
    search_iterations: int = 100
    sdp_max_constrained: int = 60
    sectors: tuple[int, ...] = (3, 4, 8)
    lowrank: LowRankOptions | None = field(default_factory=lambda: _lowrank_options())


def _lowrank_options() -> LowRankOptions:
    from unibuckle_fenicsx.certificate.copositivity_lowrank import LowRankOptions

    return LowRankOptions()


@dataclass(frozen=True)
class LowerBound:
    """The outcome of :func:`copositivity_bound`.

    Attributes:
        value: The verified lower bound (None if no route succeeded).
        method: "psd", "rank2-spn", "sdp-spn", "sdp-sectors", "lowrank-spn", or "none".
        delta: Relative distance of ``value`` below the load.
        margins: The verified quantities (alpha, beta, gamma and their error bounds, or
            the SDP's smallest eigenvalue).
        attempts: Per delta tried: the inertia of K and what each route found.
        notes: What failed, in words.
        timings: Seconds and counts (factorisations, solves).
        negative_eigenvalues: m, the pencil eigenvalues below the first shift tried (the
            negative eigenvalues of K there).
        lowrank: The low-rank route's record (None if it did not run).
        refuting: An admissible mode with a lower load than the KKT point's, met by the
            low-rank route (load, oriented values at I, owned entries of the W-vector),
            or None.
    """

    value: float | None
    method: str
    delta: float | None
    margins: dict[str, Any] = field(default_factory=dict)
    attempts: tuple[dict[str, Any], ...] = ()
    notes: tuple[str, ...] = ()
    timings: dict[str, float] = field(default_factory=dict)
    negative_eigenvalues: int | None = None
    lowrank: dict[str, Any] | None = None
    refuting: dict[str, Any] | None = None


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
    problem: BucklingProblem, matrix: ShiftedMatrix, a: npt.NDArray[np.float64], iterations: int
) -> tuple[npt.NDArray[np.float64], float, int]:
    r"""Maximise :math:`f(w) = -w^TK^{-1}w` on :math:`\{w \ge 0, a^Tw = 1\}` (concave there).

    Projected gradient with Barzilai-Borwein steps and exact line search, one solve per
    iterate; stops at the first :math:`f > 0`. Returns (best w, its f, iterations).
    """
    if problem.contact is None:
        raise ValueError(
            "_search_other_nappe: the problem has no obstacle (this needs an obstacle zone)"
        )
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


def _predict_delta(problem: BucklingProblem, matrix: ShiftedMatrix, candidate: Candidate,
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
    problem: BucklingProblem,
    matrix: ShiftedMatrix,
    w_plus: npt.NDArray[np.float64],
    candidates: list[tuple[str, npt.NDArray[np.float64]]],
    options: BoundOptions,
) -> tuple[dict[str, Any], dict[str, Any] | None]:
    """Alpha for w+, then beta and gamma for each w- candidate; the first that certifies."""
    if problem.contact is None:
        raise ValueError("_rank2: the problem has no obstacle (this needs an obstacle zone)")
    contact = problem.contact
    vec = problem.model.A.createVecRight()
    sp = matrix.refined(contact.scatter(w_plus, vec.duplicate()))
    a_val, alpha_err = ShiftedMatrix.bilinear(sp, sp)
    alpha = -a_val
    scale_p = norm2(sp.x) * norm2(sp.w)
    record: dict[str, Any] = {"alpha": alpha, "alpha_err": alpha_err}
    record["alpha_ok"] = bool(
        alpha > options.safety * alpha_err and alpha > options.rel_margin * scale_p
    )
    record["tried"] = []
    found = None
    if record["alpha_ok"]:
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
            entry = {"w_minus": name, "beta": beta, "beta_err": beta_err, "gamma": gamma,
                     "gamma_err": gamma_err, "ok": bool(ok)}  # fmt: skip
            record["tried"].append(entry)
            if ok:
                found = {"alpha": alpha, "alpha_err": alpha_err, **entry, "c": 1.0 / gamma}
                break
    sp.destroy()
    vec.destroy()
    return record, found


def copositivity_bound(  # noqa: C901 - the delta grid with its three routes (rank 2, SDP, low rank)
    problem: BucklingProblem,
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
    if problem.contact is None:
        raise ValueError(
            "copositivity_bound: the problem has no obstacle (this needs an obstacle zone)"
        )
    opts = options or BoundOptions()
    t0 = time.perf_counter()
    notes: list[str] = []
    attempts: list[dict[str, Any]] = []
    phi = problem.contact.values(problem.solve_free().function.x.petsc_vec)
    w_plus = _reaction(candidate)
    sigma = float(phi @ w_plus)
    w_minus: list[tuple[str, npt.NDArray[np.float64]]] = []
    for k, other in enumerate(others or []):
        w = _reaction(other)
        if w.max() > 0 and float(phi @ w) * sigma < 0:
            w_minus.append((f"kkt{k} ({other.load:.10g})", w))
    for name, perm in mirror_maps(problem).items():
        image = w_plus[perm]
        if float(phi @ image) * sigma < 0:
            w_minus.append((f"mirror-{name}", image))
    a = -np.sign(sigma) * phi  # normalisation a'w = 1 of the other nappe
    own = matrix is None
    if matrix is None:
        matrix = ShiftedMatrix(
            problem.model.A, problem.model.B, shared=problem.eigensolver.factorization
        )
    factorisations0, solves0 = matrix.factorisations, matrix.solves
    factor_s0, solve_s0 = matrix.factor_s, matrix.solve_s
    result: LowerBound | None = None
    m: int | None = None
    several = False  # two or more pencil eigenvalues below some shift tried
    lowrank: dict[str, Any] | None = None
    refuting: dict[str, Any] | None = None
    try:
        if not w_plus.max() > 0:
            notes.append("the KKT point has no contact force (w+ = 0)")
        predicted = _predict_delta(problem, matrix, candidate, opts.safety)
        deltas = [d for d in opts.deltas if d >= opts.slack * predicted] or [opts.deltas[-1]]
        for delta in deltas:
            lam = candidate.load * (1.0 - delta)
            neg, zero, pos = matrix.factor(lam)
            attempt: dict[str, Any] = {"delta": delta, "inertia": [neg, zero, pos]}
            attempts.append(attempt)
            m = neg if m is None else m
            several |= neg >= 2
            if zero:
                attempt["why"] = "K(lambda_lb) is singular"
                continue
            if neg == 0:
                result = LowerBound(lam, "psd", delta, {"inertia": [neg, zero, pos]})
                notes.append("A - lambda_lb B is positive definite: the obstacle is inactive")
                break
            if neg == 1 and w_plus.max() > 0:
                record, found = _rank2(problem, matrix, w_plus, w_minus, opts)
                attempt["rank2"] = record
                if found is None and record["alpha_ok"] and (a > 0).any():
                    w, f, its = _search_other_nappe(problem, matrix, a, opts.search_iterations)
                    attempt["search"] = {"iterations": its, "f": f}
                    if f > 0:
                        record, found = _rank2(problem, matrix, w_plus, [("search", w)], opts)
                        attempt["rank2_search"] = record
                if found is not None:
                    result = LowerBound(lam, "rank2-spn", delta, found)
                    break
                continue
            if neg >= 2:
                route = _sdp(problem, matrix, lam, neg, opts, notes)
                attempt["sdp"] = route
                if route.get("ok"):
                    method = route.pop("method")
                    result = LowerBound(lam, method, delta, route)
                    break
                if route.get("unavailable") or route.get("too_large"):
                    break
        if result is None and several and opts.lowrank is not None:
            outcome = _lowrank(problem, matrix, candidate, others or [], opts.lowrank, notes)
            if outcome is not None:
                lowrank, refuting = outcome.record(), outcome.refuting
                if outcome.value is not None:
                    margins = {"r": outcome.r, "pieces": outcome.pieces,
                               "margin": outcome.margin, "m": outcome.m}  # fmt: skip
                    result = LowerBound(outcome.value, "lowrank-spn", outcome.delta, margins)
    finally:
        timings = {  # the slowest rank's, so that the record is the same on every rank
            "total_s": problem.comm.allreduce(time.perf_counter() - t0, op=MPI.MAX),
            "factor_s": problem.comm.allreduce(matrix.factor_s - factor_s0, op=MPI.MAX),
            "solve_s": problem.comm.allreduce(matrix.solve_s - solve_s0, op=MPI.MAX),
            "factorisations": matrix.factorisations - factorisations0,
            "solves": matrix.solves - solves0,
        }
        if own:
            matrix.destroy()
    if result is None:
        notes.append(
            "no certificate at any delta tried "
            f"({', '.join(f'{d:g}' for d in deltas)}): the lower bound stays at the "
            "algorithm's"
        )
        result = LowerBound(None, "none", None)
    return LowerBound(
        result.value,
        result.method,
        result.delta,
        result.margins,
        tuple(attempts),
        tuple(notes),
        timings,
        m,
        lowrank,
        refuting,
    )


def _lowrank(
    problem: BucklingProblem,
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
    problem: BucklingProblem,
    matrix: ShiftedMatrix,
    lam: float,
    neg: int,
    opts: BoundOptions,
    notes: list[str],
) -> dict[str, Any]:
    """The SDP routes for two or more negative eigenvalues (optional extra "sdp")."""
    i = problem.num_constrained
    if i > opts.sdp_max_constrained:
        notes.append(
            f"{neg} pencil eigenvalues lie below the load: the rank-2 certificate does not "
            f"apply, and the full SDP route is limited to i <= {opts.sdp_max_constrained} "
            f"constrained nodes (here {i})"
            + (
                ": the low-rank route runs"
                if opts.lowrank is not None
                else ": the low-rank bracket runs on request (solver.bracket = true, --bracket)"
            )
        )
        return {"too_large": True}
    try:
        from unibuckle_fenicsx.certificate import copositivity_sdp
    except ImportError as err:
        notes.append(
            f"{neg} pencil eigenvalues lie below the load: the SDP route needs the 'sdp' "
            f"extra (pip install 'unibuckle_fenicsx[sdp]'): {err}"
        )
        return {"unavailable": True}
    route = copositivity_sdp.spn_certificate(problem, matrix, lam)
    if not route.get("ok") and neg == 2 and route.get("neg_S") == 2:
        sectors = copositivity_sdp.sector_certificate(problem, matrix, lam, opts.sectors)
        route = {**route, "sectors": sectors}
        if sectors.get("ok"):
            return {"ok": True, "method": "sdp-sectors", **sectors}
    if route.get("ok"):
        route["method"] = "sdp-spn"
    return route
