r"""Tensionless (compression-only) Winkler foundation: the spring-set iteration.

A foundation of modulus :math:`k_f` (N/m^3) on one side of the plate over a zone pushes
back with the pressure :math:`k_f w` where the plate presses into it and lets go where it
lifts off. Lumped at the zone's nodes (node k carries the spring
:math:`\rho_k = k_f \int\varphi_k\,dx`, its tributary area), the critical load is the
minimum of the piecewise quadratic quotient

.. math::

    \lambda_f = \min_{v \ne 0}
    \frac{a(v, v) + \sum_{k \in I} \rho_k \max(0, s_k v_k)^2}{b(v, v)},

with :math:`s_k = +1` for a foundation above the plate and -1 below. This is the
penalised quotient of :mod:`.penalty` with physical, per-node springs instead of a
numerical penalty, so the same iteration on the spring set S (the nodes pressing the
foundation) solves it: the smallest eigenpair of :math:`(A + \sum_{k\in S}\rho_k e_k
e_k^T, B)`, oriented to press the foundation least, until S repeats. A node presses
when it moves into the foundation by more than
:data:`~unibuckle_fenicsx.tolerances.PRESSING_RTOL` of max|w|: a node within rounding of
the foundation (on a nodal line of the mode) would otherwise press or not with the number
of ranks, and the iteration would take another path. Its limits:
:math:`k_f \to 0` gives the free plate, :math:`k_f \to \infty` the rigid obstacle; springs
on both sides (a bilateral foundation, ``side = "both"``) are simply added to A.

Bounds: :math:`\lambda_{free} \le \lambda_f \le \lambda_{rigid}` (the spring term is
non-negative, and vanishes on the rigid obstacle's mode), and the returned load, a value
of the quotient, is an upper bound of :math:`\lambda_f`. The iteration starts from the
free plate (no springs), from every spring active (the bilateral foundation's mode),
from the contact set of the rigid obstacle's answer (the caller's ``rigid_set``: a
plate's rigid twin, a section's rigid core's route) and, for stiff springs
(:func:`stiffness_ratio` above :data:`CONTINUATION_RATIO`), from the set a continuation
in the stiffness ends on; the smallest quotient is returned. The free start runs first:
when its answer satisfies the KKT conditions at a load within
:data:`~unibuckle_fenicsx.tolerances.TWIN_RTOL` of :math:`\lambda_{free}`
(:func:`_free_start_suffices`: springs too soft to change the free plate's answer, or a
free mode that turns away from the foundation), no other start can lower it and none is
run, nor the rigid obstacle's contact set solved for. The rigid obstacle's mode
itself is a candidate too (:func:`_rigid_mode`): it presses no spring, so its quotient
is the rigid load, and the arc descent from it only lowers it: the answer is at or below
the rigid obstacle's load by construction. The rigid start is what keeps the answer
there, and non-decreasing in :math:`k_f`: without it, the other starts can all end at
stationary points above the minimum of every spring set, and above the rigid obstacle's
load, on plates (:doc:`/history/2026-12-01a-metamorph`) and on a section's soft cores
(:doc:`/history/2026-12-01b-schunt`).
A node of the spring set keeps pressing while its spring force exceeds
:data:`~unibuckle_fenicsx.tolerances.PRESSING_RTOL` of the largest: a stiff spring's
node presses by less than that fraction of max|w|, and would otherwise leave and return
without end. The quotient has
several local minima on long plates, and each start finds one; the arc descent (below)
runs from every start that cycles (:doc:`/verification/tuning`). The stiff springs'
starts serve a section's elastic core too: with the two first starts alone a filled
box's answer came out above a stiffer core's (which the minimum, growing with
:math:`k_f`, cannot exceed; :doc:`/history/2026-11-30h-sechunt`).

The iteration on S need not decrease the quotient, and it can cycle. When a start
reaches no fixed point, an *arc descent* takes over from its best iterate v: with S the
nodes v presses, and u the smallest mode of the pencil with S's springs, the quotient is
minimised over the circle :math:`\cos\theta\, v + \sin\theta\, u` (six inner
products and the nodal values: no solve), and the minimiser becomes the next v. The
quotient never increases, so it cannot cycle; it stops when a step gains less than
:data:`~unibuckle_fenicsx.tolerances.ARC_RTOL`.

Note:
    Collective on the problem's communicator.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms import RunStatus, UnilateralSolution
from unibuckle_fenicsx.algorithms.active_set import solve_active_set
from unibuckle_fenicsx.algorithms.penalty import PenaltySolver, SpringIteration
from unibuckle_fenicsx.algorithms.records import FoundationDetails
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.la.options import Prefix
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem, require_obstacle
from unibuckle_fenicsx.spec.solver import FoundationOptions
from unibuckle_fenicsx.tolerances import ARC_RTOL, PRESSING_RTOL, PROOF_GAP, TWIN_RTOL

__all__ = ["RIGID_MODE", "pressing_nodes", "run_from_start", "solve_foundation"]

logger = logging.getLogger(__name__)

#: Above this :func:`stiffness_ratio` a start continues in the stiffness from
#: :math:`\kappa` = 10 by tenfold steps: stiff springs have stationary points far from
#: the free plate's and the bilateral foundation's (:doc:`/verification/stiff_foundations`).
CONTINUATION_RATIO = 10.0
#: The name of the candidate :func:`_rigid_mode` (a result's ``foundation_start``).
RIGID_MODE = "rigid mode"
#: Angles sampled on the circle before the golden-section refinement.
ARC_SAMPLES = 720
#: Golden-section steps in the bracket around the best sample: 0.618^60 of a sample's
#: spacing, below the rounding of an angle.
GOLDEN_STEPS = 60


def solve_foundation(
    problem: UnilateralProblem,
    *,
    max_iterations: int = 100,
    eps_options: dict[str, str | float | int] | None = None,
    rigid_set: Callable[[], tuple[npt.NDArray[np.int64], int]] | None = None,
) -> UnilateralSolution:
    r"""Critical load of the plate on its tensionless foundation (module docstring).

    Args:
        problem: A problem whose contact nodes carry a tensionless foundation
            (``problem.tensionless``).
        max_iterations: Eigen solves allowed per start, >= 1.
        eps_options: Extra EPS options under ``unibuckle_foundation_``.
        rigid_set: Gives the rigid obstacle's contact set on the problem's contact
            directions and its eigen solves, for the start from it; None:
            :func:`_rigid_set`, the active set on the problem itself.
            :func:`~unibuckle_fenicsx.analysis.solve` passes a plate's rigid twin,
            solved as a whole problem, and a section its rigid core's route: their KKT
            points can lie below the active set's (:doc:`/history/2026-12-01a-metamorph`,
            :doc:`/history/2026-12-01a-coreroute`).

    Returns:
        The solution; its candidate's load is the quotient of the returned mode, its
        ``active`` set the nodes pressing the foundation; ``lower_bound`` =
        :math:`\lambda_{free}`, ``upper_bound`` = the load; proven optimal when the two
        bounds meet within :data:`~unibuckle_fenicsx.tolerances.PROOF_GAP` (relative),
        the gap a plate's certificate proves: the free mode turned away from the
        foundation presses nothing, or the springs are too soft to raise the load.

    Note:
        Collective.
    """
    require_obstacle(problem, "solve_foundation")
    contact = problem.contact
    if contact.stiffness is None:
        raise InputError("solve_foundation needs a problem with a tensionless foundation")
    FoundationOptions(max_iterations=max_iterations)  # the [solver] key's range
    lower = problem.solve_free().load
    springs = contact.stiffness
    ratio = stiffness_ratio(problem, springs)
    with PenaltySolver(problem, prefix=Prefix.FOUNDATION, eps_options=eps_options) as solver:
        free = run_from_start(solver, "free", np.empty(0, np.int64), lower, max_iterations)
        runs, finals = {"free": free[0]}, {"free": free[1]}
        mode, rigid_solves = None, 0
        if not _free_start_suffices(free[1], lower):
            rigid = _rigid_set(problem) if rigid_set is None else rigid_set()
            _run_starts(solver, ratio, rigid[0], lower, max_iterations, runs, finals)
            lowest = min(final.load for final, _, _ in finals.values())
            mode = _rigid_mode(solver, rigid[0], lowest, max_iterations)
            if mode is not None:
                finals[RIGID_MODE] = mode
            rigid_solves = rigid[1]
        start = _lowest_start(finals)
        candidate, status, arc_steps = finals[start]
        # The rigid set's reduced eigen solve is the problem's own eigen solver's.
        solves = solver.solves + rigid_solves + (0 if mode is None else 1)
    name = f"{start}+arc" if arc_steps and start != RIGID_MODE else start
    load = candidate.load
    # [lambda_free, load] holds the minimum whatever the springs press: the spring term
    # is >= 0, and the load is the quotient of a mode. Closed to PROOF_GAP, the plates'
    # proof, the answer is proven, pressing nodes or not (springs too soft to matter).
    proven = math.isfinite(load) and load - lower <= PROOF_GAP * load
    details = _details(runs, finals, mode, start, name, springs)
    logger.info(
        "foundation: lambda = %.10g (start %s, %s, %d pressing nodes, %d eigen solves)",
        load, name, status, candidate.active.size, solves,
    )  # fmt: skip
    return UnilateralSolution(
        candidate=candidate,
        method="foundation",
        eigensolves=solves,
        lower_bound=lower,
        global_optimum_proven=bool(proven),
        upper_bound=load if math.isfinite(load) else math.inf,
        status=status,
        details=details,
        route=["foundation", "arc-descent"] if arc_steps else ["foundation"],
    )


def _free_start_suffices(final: tuple[Candidate, RunStatus, int], lower: float) -> bool:
    r"""Whether the free start's answer is the foundation's: no other start can lower it.

    ``final``: the free start's (mode, how it ended, arc steps) (:func:`run_from_start`);
    ``lower``: :math:`\lambda_{free}`. True when its spring-set iteration reached a fixed
    point, with no arc descent, at a load :math:`\lambda` within
    :data:`~unibuckle_fenicsx.tolerances.TWIN_RTOL` of :math:`\lambda_{free}`:

    .. math::

        (A + \sum_{k \in S} \rho_k e_k e_k^T)\, v = \lambda B v, \quad
        S = \{k : s_k v_k > \epsilon \max|w|\}, \qquad
        \lambda \le \lambda_{free} (1 + \text{TWIN\_RTOL}).

    (:math:`\epsilon` = :data:`~unibuckle_fenicsx.tolerances.PRESSING_RTOL`; a node of S
    also stays while its spring force holds it, :func:`_iterate`). The first
    is the stationarity of the quotient at v with the spring set it presses (the KKT
    conditions of the foundation problem; the certificate's ``kkt``); the second
    makes it the global minimum to that tolerance, since every quotient is at least
    :math:`\lambda_{free}` (the spring term is non-negative). The other starts and the
    rigid mode then end at or above :math:`\lambda_{free}`, which
    :func:`_lowest_start` would not take over the free start (it keeps the earlier start
    within the same tolerance): they are not run, nor the rigid obstacle's set solved.
    Springs too soft to change the free answer stop here; a free mode that turns away from
    the foundation (S empty) gives :math:`\lambda = \lambda_{free}` exactly.
    """
    candidate, status, arc_steps = final
    return (
        status is RunStatus.CONVERGED
        and arc_steps == 0
        and candidate.load <= lower * (1.0 + TWIN_RTOL)
    )


def _run_starts(
    solver: PenaltySolver,
    ratio: float,
    rigid: npt.NDArray[np.int64],
    lower: float,
    max_iterations: int,
    runs: dict[str, SpringIteration],
    finals: dict[str, tuple[Candidate, RunStatus, int]],
) -> None:
    """The iteration from each start after the free plate's, each with its arc descent.

    Every spring active, the rigid obstacle's contact set ``rigid`` and, above
    :data:`CONTINUATION_RATIO` (``ratio``: :func:`stiffness_ratio`), the continuation's
    set, in that order (the module docstring; the free plate's, run first, is in
    ``runs`` and ``finals`` already). Adds to ``runs`` the runs and to ``finals``, by
    start, (mode, how it ended, arc steps) (:func:`run_from_start`). Collective.
    """
    springs = solver.problem.contact.stiffness
    assert springs is not None
    starts = {"bilateral": np.arange(solver.problem.contact.size), "rigid": rigid}
    for name, start in starts.items():
        runs[name], finals[name] = run_from_start(solver, name, start, lower, max_iterations)
    if ratio > CONTINUATION_RATIO:
        start = _continued_start(solver, springs, ratio, lower, max_iterations)
        runs["continued"], finals["continued"] = run_from_start(
            solver, "continued", start, lower, max_iterations
        )


def _lowest_start(finals: dict[str, tuple[Candidate, RunStatus, int]]) -> str:
    """The start with the smallest quotient.

    Within :data:`~unibuckle_fenicsx.tolerances.TWIN_RTOL` of it (mirror images, whose
    loads differ by rounding that changes with the ranks) the earlier start, the free
    plate first.
    """
    lowest = min(final.load for final, _, _ in finals.values())
    return next(n for n, (c, _, _) in finals.items() if c.load <= lowest * (1 + TWIN_RTOL))


def _details(
    runs: dict[str, SpringIteration],
    finals: dict[str, tuple[Candidate, RunStatus, int]],
    mode: tuple[Candidate, RunStatus, int] | None,
    start: str,
    name: str,
    springs: npt.NDArray[np.float64],
) -> FoundationDetails:
    """The run's record: every start's iteration, the rigid mode's, and the answer's.

    ``start`` is the answer's start in ``finals``, ``name`` its label (``+arc`` where an
    arc descent followed).
    """
    candidate, status, arc_steps = finals[start]
    history = [s.quotient for s in runs[start].steps] if start in runs else [candidate.load]
    return FoundationDetails(
        foundation_start=name,
        foundation_arc_steps=arc_steps,
        foundation_iterations={n: len(r.steps) for n, r in runs.items()},
        foundation_loads={n: r.candidate.load for n, r in runs.items()}
        | ({} if mode is None else {RIGID_MODE: mode[0].load}),
        foundation_statuses={n: str(r.status) for n, r in runs.items()}
        | ({} if mode is None else {RIGID_MODE: str(mode[1])}),
        foundation_pressing_nodes=int(candidate.active.size),
        foundation_max_penetration=max(float(candidate.values.max()), 0.0),
        foundation_spring_range_N_per_m=[float(springs.min()), float(springs.max())],
        foundation_history=history,
        foundation_status=str(status),
    )


def stiffness_ratio(problem: UnilateralProblem, springs: npt.NDArray[np.float64]) -> float:
    r"""The springs' energy on the free mode over its bending energy: :math:`\kappa`.

    :math:`\kappa = \sum_k \rho_k u_k^2 / a(u, u)`, u the free mode: a non-dimensional
    foundation stiffness for any structure (on a plate wholly on the foundation about
    :math:`K/k`, K = :math:`k_f b^4/(\pi^4 D)`). Collective.
    """
    u = problem.solve_free().function.x.petsc_vec
    Au = u.duplicate()
    try:
        problem.model.A.mult(u, Au)
        energy = float(u.dot(Au))
    finally:
        Au.destroy()
    z = problem.contact.values(u)
    return float(np.sum(springs * z * z)) / energy if energy > 0.0 else 0.0


def _rigid_mode(
    solver: PenaltySolver, active: npt.NDArray[np.int64], lowest: float, max_iterations: int
) -> tuple[Candidate, RunStatus, int] | None:
    r"""The rigid obstacle's mode as a candidate, when its quotient is below ``lowest``.

    The smallest eigenpair with the rigid answer's contact set ``active`` removed is the
    rigid obstacle's mode; admissible, it presses no spring (by at most the feasibility
    tolerance), so its spring quotient is the rigid load. Where that lies below
    ``lowest`` (the starts' smallest quotient), the arc descent runs from it
    (:func:`_arc_descent`, never increasing): the answer is then at or below the rigid
    obstacle's load whatever the starts did. Returns (mode, how the descent ended, its
    steps), or None (no set, or not lower: nothing run after the one eigen solve).
    Collective.
    """
    if not active.size:
        return None
    problem = solver.problem
    springs = problem.contact.stiffness
    assert springs is not None
    rigid = problem.evaluate(active)
    vec = rigid.mode.x.petsc_vec
    quotient = solver.quotient(vec, springs)
    logger.info("foundation: the rigid mode's quotient %.10g, the starts' %.10g", quotient, lowest)
    if not quotient < lowest * (1.0 - TWIN_RTOL):
        return None
    pressing = pressing_nodes(problem.contact.values(vec), problem.max_abs_w(vec))
    start = problem.candidate(rigid.mode, quotient, pressing, sign=1.0)
    return _arc_descent(problem, solver, springs, start, max_iterations)


def _rigid_set(problem: UnilateralProblem) -> tuple[npt.NDArray[np.int64], int]:
    """The rigid obstacle's contact set on the foundation's nodes, and its eigen solves.

    The active set on the problem itself, its springs made rigid (its coarse levels, no
    bracket): the start :func:`solve_foundation` takes when its caller gives none.
    Collective.
    """
    rigid = solve_active_set(problem, bound_budget=0)
    logger.info("foundation: the rigid obstacle's load %.10g starts a run", rigid.candidate.load)
    return rigid.candidate.active, rigid.eigensolves


def _continued_start(
    solver: PenaltySolver,
    springs: npt.NDArray[np.float64],
    ratio: float,
    lower: float,
    max_iterations: int,
) -> npt.NDArray[np.int64]:
    r"""The spring set reached by continuation in the stiffness, for the last stage's start.

    Springs scaled by tenfold steps from :math:`\kappa` = :data:`CONTINUATION_RATIO`
    towards the given ones, each stage started from the set the previous one ended on
    (the free plate first). Collective.
    """
    stages = math.ceil(math.log10(ratio / CONTINUATION_RATIO))
    active = np.empty(0, np.int64)
    for j in range(stages, 0, -1):
        run = _iterate(
            solver, springs * 10.0 ** (-j), active, lower, max_iterations,
            f"continuation, springs / 10^{j}",
        )  # fmt: skip
        active = run.candidate.active
    return active


def _iterate(
    solver: PenaltySolver,
    springs: npt.NDArray[np.float64],
    start: npt.NDArray[np.int64],
    lower: float,
    max_iterations: int,
    name: str,
) -> SpringIteration:
    """The foundation's spring-set iteration on ``springs`` from ``start``. Collective.

    Pressing beyond :data:`~unibuckle_fenicsx.tolerances.PRESSING_RTOL`, a node of the
    set held by its spring force (``hold_pressed``).
    """
    return solver.iterate_springs(
        springs,
        initial_active=start,
        max_iterations=max_iterations,
        lower_bound=lower,
        label=f"foundation ({name})",
        threshold=PRESSING_RTOL,
        hold_pressed=True,
    )


def run_from_start(
    solver: PenaltySolver,
    name: str,
    start: npt.NDArray[np.int64],
    lower: float,
    max_iterations: int,
) -> tuple[SpringIteration, tuple[Candidate, RunStatus, int]]:
    """The spring-set iteration from ``start``, then the arc descent if it has no fixed point.

    One start of :func:`solve_foundation` (``name``: "free", "bilateral", "rigid" or
    "continued"), which asks this function for each. Returns the iteration, and (mode,
    how it ended, arc steps). Collective.
    """
    problem = solver.problem
    springs = problem.contact.stiffness
    assert springs is not None
    run = _iterate(solver, springs, start, lower, max_iterations, f"{name} start")
    final, status, arc_steps = run.candidate, run.status, 0
    if status is not RunStatus.CONVERGED and math.isfinite(final.load):
        final, status, arc_steps = _arc_descent(problem, solver, springs, final, max_iterations)
    return run, (final, status, arc_steps)


def _arc_minimum(
    a: npt.NDArray[np.float64],
    b: npt.NDArray[np.float64],
    z_v: npt.NDArray[np.float64],
    z_u: npt.NDArray[np.float64],
    springs: npt.NDArray[np.float64],
) -> tuple[float, float]:
    r"""The angle :math:`\theta` minimising the spring quotient on the arc, and its value.

    On :math:`\cos\theta\, v + \sin\theta\, u` the quotient is a ratio of quadratic forms
    (``a``, ``b``: the 2x2 forms' entries vv, vu, uu) plus the springs of the nodes pressed
    (``z_v``, ``z_u``: the oriented values); sampled at :data:`ARC_SAMPLES` angles, then a
    golden-section search in the bracket around the best sample.
    """

    def quotient(theta: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        c, s = np.cos(theta), np.sin(theta)
        num = c * c * a[0] + 2 * c * s * a[1] + s * s * a[2]
        den = c * c * b[0] + 2 * c * s * b[1] + s * s * b[2]
        z = np.outer(c, z_v) + np.outer(s, z_u)
        num = num + (springs * np.maximum(z, 0.0) ** 2).sum(axis=1)
        return np.where(den > 0.0, num / np.where(den > 0.0, den, 1.0), np.inf)

    grid = np.linspace(0.0, 2.0 * np.pi, ARC_SAMPLES, endpoint=False)
    k = int(np.argmin(quotient(grid)))
    lo, hi = grid[k] - 2 * np.pi / ARC_SAMPLES, grid[k] + 2 * np.pi / ARC_SAMPLES
    golden = 0.5 * (np.sqrt(5.0) - 1.0)
    for _ in range(GOLDEN_STEPS):
        m1, m2 = hi - golden * (hi - lo), lo + golden * (hi - lo)
        if quotient(np.array([m1]))[0] <= quotient(np.array([m2]))[0]:
            hi = m2
        else:
            lo = m1
    theta = 0.5 * (lo + hi)
    return float(theta), float(quotient(np.array([theta]))[0])


def _arc_descent(
    problem: UnilateralProblem,
    solver: PenaltySolver,
    springs: npt.NDArray[np.float64],
    start: Candidate,
    max_iterations: int,
) -> tuple[Candidate, RunStatus, int]:
    """Monotone descent of the spring quotient along arcs (module docstring), from ``start``.

    Returns the candidate reached, CONVERGED (a step gains less than
    :data:`~unibuckle_fenicsx.tolerances.ARC_RTOL`) or MAX_ITERATIONS, and the steps taken.
    """
    contact = problem.contact
    A, B = problem.model.A, problem.model.B
    v = start.mode.x.petsc_vec.copy()
    u, Av, Au, Bv, Bu = (v.duplicate() for _ in range(5))
    q = start.load
    status = RunStatus.MAX_ITERATIONS
    steps = 0
    try:
        for _ in range(int(max_iterations)):
            steps += 1
            z_v = contact.values(v)
            pressing = pressing_nodes(z_v, problem.max_abs_w(v))
            solver.set_springs(springs, pressing)
            solver.gep.solve(out=u, initial=v)
            solver.solves += 1
            # u A-orthogonal to v, of v's A-norm: the circle is then well conditioned; a
            # u parallel to v means v is the pencil's mode, a fixed point.
            A.mult(v, Av)
            A.mult(u, Au)
            vav, uau = float(v.dot(Av)), float(u.dot(Au))
            u.axpy(-float(v.dot(Au)) / vav, v)
            A.mult(u, Au)
            rest = float(u.dot(Au))
            if rest <= 1e-16 * uau:
                status = RunStatus.CONVERGED
                break
            u.scale(float(np.sqrt(vav / rest)))
            A.mult(u, Au)
            B.mult(v, Bv)
            B.mult(u, Bu)
            a = np.array([v.dot(Av), v.dot(Au), u.dot(Au)], dtype=float)
            b = np.array([v.dot(Bv), v.dot(Bu), u.dot(Bu)], dtype=float)
            theta, q_new = _arc_minimum(a, b, z_v, contact.values(u), springs)
            if not q_new < q * (1.0 - ARC_RTOL):
                status = RunStatus.CONVERGED
                break
            v.scale(float(np.cos(theta)))
            v.axpy(float(np.sin(theta)), u)
            v.scale(1.0 / problem.max_abs_w(v))
            q = q_new
        mode = problem.new_mode()
        v.copy(mode.x.petsc_vec)
        mode.x.scatter_forward()
        z = contact.values(v)
        candidate = problem.candidate(mode, q, pressing_nodes(z, problem.max_abs_w(v)), sign=1.0)
    finally:
        for vec in (v, u, Av, Au, Bv, Bu):
            vec.destroy()
    logger.info("foundation: arc descent %s after %d steps, R = %.12g", status, steps, q)
    return candidate, status, steps


def pressing_nodes(values: npt.NDArray[np.float64], max_w: float) -> npt.NDArray[np.int64]:
    """The nodes whose values move them into the foundation by more than rounding."""
    return np.flatnonzero(values > PRESSING_RTOL * max_w).astype(np.int64)
