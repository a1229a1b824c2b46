r"""Primal-dual active-set method for the unilateral critical state, with bounds.

The discrete problem (:doc:`/methods/problem`): the smallest :math:`\lambda` and
:math:`u \neq 0` with :math:`u_k \le 0` on the constrained nodes I and

- :math:`r = A u - \lambda B u` zero off the contact set :math:`Z = \{k: u_k = 0\}`,
- :math:`u_k < 0` on :math:`I \setminus Z`, :math:`r_k \le 0` on Z,
- :math:`\lambda` the smallest eigenvalue of the pencil with Z removed.

**Iteration** (:mod:`.pdas`). From a seed :math:`Z_0`, repeat: solve the reduced
pencil, add the nodes of :math:`I \setminus Z` where the mode violates the obstacle and
release the nodes of Z whose multiplier pulls, until a KKT point (with a damped rule
after a cycle). Every feasible reduced mode is an admissible mode, so its load is an
upper bound whatever the iteration does.

**Seeds.** The conditions above have several solutions (e.g. a buckle against one
loaded edge and one between two touch-down lines; mirror images with equal loads),
so the iteration runs from several seeds: the free mode's violation set for both
signs, every constrained node fixed, buckles seeded at either end and the middle
of the long axis (Z = I outside a window of half the plate's length), and two greedy
runs (start from the free mode's most violated node for either sign, add only the
most violated node per iterate: small contact sets first, as in the paper; at most
:data:`GREEDY_ITERATIONS` iterates when another seed has reached a KKT point).
The damped rule used after a cycle is also greedy. The smallest
KKT load is kept; the distinct KKT points and equal-load twins are reported.

**Multilevel** (:mod:`.multilevel`, speed). The cost is one sparse factorisation per iterate, and
on a fine mesh the contact zone moves by one node layer per iterate. So on a fine
structured mesh the seeds run on a hierarchy of coarser meshes (halved until the shorter
side has fewer than ``coarse_min_cells`` cells); the best KKT sets (within
``refine_margin`` of the best load, one per group of twins) are prolonged level by level
and polished by the same iteration, which then needs a couple of iterates per level.
When no prolonged set reaches a KKT point, the best one is polished again converging
with looser tolerances first (:data:`THRESHOLDS`, then ``solver.tau``), so that it
places the contact lines before it chases the sign of the mode's tails. The answer is
always a KKT point of the *fine* problem.

**Fallbacks.** When the finest level reaches no KKT point (or only the one with every
constrained node in contact while other seeds stalled): penalty continuation
(:mod:`.continuation`), then, if that stalls too, the feasible descent
(:mod:`.descent`), which cannot cycle, from the best admissible mode met.

**Bounds** (:mod:`.bounds`). Upper: the returned feasible load. Lower:
:math:`\lambda_{free}`, and, when the budget allows (``bound_budget`` evaluations, at
least i), the best-first search over the subset lattice, which closes the bracket
(``global_optimum_proven``) on small problems. If it finds a lower feasible load, the
answer is replaced and the replacement is reported.

Note:
    All decisions use values reduced over the ranks
    (:meth:`~unibuckle_fenicsx.model.contact.ContactSetManager.values`), so every rank takes
    the same path; the function is collective on ``problem.comm``.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
from msgspec import UNSET, UnsetType

from unibuckle_fenicsx.algorithms import RunStatus, UnilateralSolution
from unibuckle_fenicsx.algorithms.bounds import Bracket, bracket
from unibuckle_fenicsx.algorithms.continuation import penalty_continuation
from unibuckle_fenicsx.algorithms.descent import admissible_start, descend
from unibuckle_fenicsx.algorithms.multilevel import mesh_levels, prolong
from unibuckle_fenicsx.algorithms.pdas import Run, iterate
from unibuckle_fenicsx.algorithms.records import (
    ActiveSetDetails,
    ActiveSetLevel,
    DescentRecord,
    Fallback,
    KktPoint,
)
from unibuckle_fenicsx.errors import (
    EmptyZoneError,
    InputError,
    NoAdmissibleModeError,
    NoLoadError,
)
from unibuckle_fenicsx.model.build import build_unilateral_problem
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem, require_obstacle
from unibuckle_fenicsx.progress import LOGGER as PROGRESS
from unibuckle_fenicsx.spec.solver import ActiveSetOptions
from unibuckle_fenicsx.tolerances import PROOF_RTOL, ROUNDING_RTOL, TWIN_RTOL

__all__ = ["SEED_NAMES", "reached_kkt", "solve_active_set"]

logger = logging.getLogger(__name__)

#: Iterates allowed when polishing a prolonged contact set (it needs one to three when
#: the coarser level predicts the fine one; more means it stalls: the fallback takes over).
POLISH_ITERATIONS = 25
#: Eigen solves allowed to the feasible descent, per ``max_iterations``.
DESCENT_BUDGET = 10
#: Eigen solves allowed to each penalty of the penalty continuation, per
#: ``max_iterations`` (a spring-set iteration per penalty, from a soft start).
PENALTY_BUDGET = 2
#: Looser tolerances the iteration converges with first (:doc:`/methods/active_set`):
#: on thin plates the mode's tails, 1e-3 to 1e-8 of the buckle, flip sign from one
#: contact set to the next, and chasing them at the final tolerance at once moves the
#: contact lines a node per iterate.
THRESHOLDS = (1e-2, 1e-3, 1e-4, 1e-6)
#: Iterates allowed to a greedy seed when another seed has reached a KKT point (it adds
#: one node per iterate and is there for small contact sets: on the paper's plate it ends
#: in 5-13, on the thin plates of the changelog's active-set table it was still adding
#: nodes after 100 on the 45x15 level). When no other seed has, it gets
#: ``max_iterations``: its best admissible mode may then be the feasible descent's start
#: (on the long clamped plate of the descent table of :doc:`/verification/thin_plates`,
#: at b/6, it gives k = 5.6673 where a capped run gives 5.7015).
GREEDY_ITERATIONS = 25
#: Seeds run on the coarsest level, in this order.
SEED_NAMES = ("free+", "free-", "all", "end-low", "middle", "end-high", "greedy+", "greedy-")


def _seeds(
    problem: UnilateralProblem,
    free_values: npt.NDArray[np.float64],
    tau: float,
    names: tuple[str, ...] = SEED_NAMES,
) -> list[tuple[str, npt.NDArray[np.int64], str | None]]:
    """Seed contact sets (deduplicated, in the order of ``names``, a part of :data:`SEED_NAMES`).

    Each as (name, set, image_of). A seed whose set is the image of an earlier one's
    under a symmetry of the problem (``problem.contact.symmetries``: a square box's
    quarter turns, a tube's turns about its axis, where the free mode's two sign
    patterns are such images) has that one's name as ``image_of`` (else None): its run
    is that one's image, and its KKT point has the same load, so it runs only where that
    one reaches no KKT point (:func:`multi_seed`). Only up to rounding: a tie may break
    otherwise in either run, which then ends at another image of the same load, or
    stalls where the other does not (:doc:`/verification/sections_cost_symmetry`).
    """
    xy = problem.contact.coordinates
    plate = problem.spec.plate
    (x0, y0), (x1, y1) = plate.corners
    axis = 0 if plate.length >= plate.width else 1
    lo, hi = (x0, x1) if axis == 0 else (y0, y1)
    half = 0.5 * (hi - lo)
    windows = {
        "end-low": (lo, lo + half),
        "middle": (lo + 0.5 * half, hi - 0.5 * half),
        "end-high": (hi - half, hi),
    }
    n = problem.num_constrained
    scale = np.abs(free_values).max() if free_values.size else 1.0
    images = problem.contact.symmetries
    out: list[tuple[str, npt.NDArray[np.int64], str | None]] = []
    seen: set[bytes] = set()
    for name in names:
        if name == "free+":
            z = np.flatnonzero(free_values > tau * scale)
        elif name == "free-":
            z = np.flatnonzero(-free_values > tau * scale)
        elif name == "all":
            z = np.arange(n)
        elif name in ("greedy+", "greedy-"):
            v = free_values if name == "greedy+" else -free_values
            z = (
                np.flatnonzero(v >= v.max() * (1.0 - ROUNDING_RTOL))
                if v.max() > tau * scale
                else np.empty(0, np.intp)
            )
        else:
            a, b = windows[name]
            c = xy[:, axis]
            z = np.flatnonzero((c < a - 1e-12 * half) | (c > b + 1e-12 * half))
        z = z.astype(np.int64)
        if z.tobytes() in seen:
            continue
        seen.add(z.tobytes())
        image = next(
            (
                e
                for e, y, of in out
                if of is None
                for p in images
                if np.array_equal(np.sort(p[y]), z)
            ),
            None,
        )
        out.append((name, z, image))
    return out


def multi_seed(
    problem: UnilateralProblem,
    max_iterations: int,
    seeds: tuple[str, ...] = SEED_NAMES,
    more_seeds: tuple[str, ...] = (),
) -> list[Run]:
    """Run the iteration from every seed of ``seeds``, starting from the free mode.

    The seeds of ``more_seeds`` run after them only if none of theirs reached a KKT point.
    A seed whose set is the image of an earlier seed's under a symmetry of the problem
    (:func:`_seeds`) runs only if that seed's run reached no KKT point.
    """
    free = problem.solve_free().function.x.petsc_vec
    values = problem.contact.values(free)
    runs: list[Run] = []
    # The greedy seeds come last.
    for name, z, image_of in _seeds(problem, values, problem.tau, seeds + more_seeds):
        if name in more_seeds and any(r.status is RunStatus.KKT for r in runs if r.seed in seeds):
            break
        if image_of is not None and any(
            r.status is RunStatus.KKT for r in runs if r.seed == image_of
        ):
            logger.info("active set: seed %s, the image of %s by symmetry: not run", name, image_of)
            continue
        greedy = name.startswith("greedy")
        capped = greedy and any(r.status is RunStatus.KKT for r in runs)
        budget = min(max_iterations, GREEDY_ITERATIONS) if capped else max_iterations
        runs.append(iterate(problem, name, z, free, budget, greedy=greedy))
    return runs


def _polish(
    problem: UnilateralProblem,
    coarse: UnilateralProblem,
    candidates: list[Candidate],
    budget: int,
    bests: list[float],
) -> list[Run]:
    """Prolong the coarser level's KKT contact sets to ``problem``'s mesh and iterate.

    With a load estimate (:func:`_estimates`) the first eigen solve shifts just below it,
    later ones below the previous iterate's load, the inertia proving each pair the
    smallest (:meth:`~unibuckle_fenicsx.model.problem.UnilateralProblem.evaluate`): a
    shifted solve converges in a few restarts (:doc:`/verification/tuning`).

    If no prolonged set reaches a KKT point, the best one (the first) is iterated once
    more from its prolongation with the looser :data:`THRESHOLDS` first.
    """
    estimates = _estimates(candidates, bests)
    runs = [
        iterate(problem, f"candidate{k}", prolong(coarse, problem, c.active), None, budget, near=e)
        for k, (c, e) in enumerate(zip(candidates, estimates, strict=True))
    ]
    if candidates and not any(r.status is RunStatus.KKT for r in runs):
        z = prolong(coarse, problem, candidates[0].active)
        runs.append(
            iterate(problem, "candidate0-thresholds", z, None, budget, thresholds=THRESHOLDS)
        )
    return runs


def _estimates(candidates: list[Candidate], bests: list[float]) -> list[float | None]:
    r"""The loads expected on the next finer mesh of the coarse KKT points ``candidates``.

    ``bests``: the lowest load of each coarser level, the last one that of the
    candidates' level. The step from the level before is extrapolated (h² convergence,
    halved cells: the next step a third of the last), only downwards: each load becomes
    :math:`\lambda\,(1 - \max(0, \lambda_{2h}/\lambda_h - 1)/3)`. None with a single
    level (the paper's plate loses 1.3 % from 20×10 to 40×20, far more than the
    shift's margin). A wrong estimate costs time, never the answer: the eigen solve
    checks the inertia at its shift.
    """
    if len(bests) < 2:
        return [None] * len(candidates)
    drop = max(0.0, bests[-2] / bests[-1] - 1.0) / 3.0
    return [c.load * (1.0 - drop) for c in candidates]


def _twin_groups(points: list[Candidate]) -> list[list[Candidate]]:
    """Group KKT points (sorted by load) whose loads agree within TWIN_RTOL (relative).

    (:data:`~unibuckle_fenicsx.tolerances.TWIN_RTOL`.)

    Each group is ordered by contact-set size, then lexicographically, so that its
    first member does not depend on rounding (e.g. on the number of ranks).
    """
    groups: list[list[Candidate]] = []
    for p in points:
        if groups and abs(p.load - groups[-1][0].load) <= TWIN_RTOL * abs(p.load):
            groups[-1].append(p)
        else:
            groups.append([p])
    return [sorted(g, key=lambda s: (len(s.active), tuple(s.active))) for g in groups]


def distinct_kkt(runs: list[Run]) -> list[Candidate]:
    """Distinct KKT end points of ``runs``, sorted by load then lexicographically."""
    found: dict[bytes, Candidate] = {}
    for run in runs:
        if run.status is RunStatus.KKT and run.final is not None:
            found.setdefault(run.final.key(), run.final)
    return sorted(found.values(), key=lambda s: (s.load, len(s.active), tuple(s.active)))


def _least_violating(runs: list[Run]) -> Candidate | None:
    """The final state with a finite load that crosses the obstacle least (or None)."""
    finals = [r.final for r in runs if r.final is not None and math.isfinite(r.final.load)]
    return min(finals, key=lambda c: c.margin) if finals else None


def _descent(
    problem: UnilateralProblem, runs: list[Run], max_steps: int
) -> tuple[Run | None, dict[str, int]]:
    """Feasible descent from the best admissible mode of ``runs`` (or one made admissible).

    Returns (None, {}) when no admissible mode with a finite load can be made.
    """
    feasible = [r.best_feasible for r in runs if r.best_feasible is not None]
    if feasible:
        start: Candidate | None = min(feasible, key=lambda s: s.load)
        used = 0
    else:
        attempt = _least_violating(runs)
        if attempt is None:
            return None, {}
        start, used = admissible_start(problem, attempt, max_steps)
    if start is None:
        return None, {}
    run, steps = descend(problem, start, max(max_steps - used, 1))
    run.iterations += used
    return run, steps


def _prune(problem: UnilateralProblem, cand: Candidate) -> Candidate:
    """Release the contact nodes with (near) zero multiplier if the KKT point stays."""
    slack = cand.forces[cand.active] >= -problem.tau
    if not slack.any():
        return cand
    trial = problem.evaluate(cand.active[~slack], initial=cand.mode.x.petsc_vec, near=cand.load)
    if trial.kkt and trial.load <= cand.load * (1.0 + PROOF_RTOL):
        return trial
    return cand


@dataclass
class _Coarse:
    """What the coarser levels leave for the fine one (:func:`_coarse_levels`)."""

    candidates: list[Candidate] | None = None
    bests: list[float] = field(default_factory=list)  # lowest KKT load per level
    kkt: list[Candidate] = field(default_factory=list)
    last: UnilateralProblem | None = None  # the finest coarse problem (the caller's)
    runs: list[Run] = field(default_factory=list)  # the seeded level's
    log: list[ActiveSetLevel] = field(default_factory=list)
    solves: int = 0


def _has_load(cp: UnilateralProblem) -> bool:
    """Whether the coarse problem ``cp`` has a free load, which the seeds start from.

    A level whose cells cannot resolve a steep stress gradient's compressed strip (a
    cell across) has none, where the fine mesh has one. Collective.
    """
    try:
        cp.solve_free()
    except NoLoadError:
        return False
    return True


def _coarse_levels(
    problem: UnilateralProblem,
    levels: list[tuple[int, int]],
    max_iterations: int,
    refine_margin: float,
    seeds: tuple[str, ...] = SEED_NAMES,
    more_seeds: tuple[str, ...] = (),
) -> _Coarse:
    """Seeds on the coarsest level, then the best contact sets polished level by level.

    A level the seeds would run on is skipped where it has no positive load
    (:func:`_has_load`); they run on the next finer one (the fine mesh, if none).
    The finest coarse problem is left alive in the result (:attr:`_Coarse.last`, for
    the fine level's polish); the caller destroys it. Collective.
    """
    coarse = _Coarse()
    for nx, ny in levels:
        tl = time.perf_counter()
        try:
            cp = build_unilateral_problem(problem.spec.with_mesh(nx, ny), problem.comm)
        except EmptyZoneError:
            continue
        except NoLoadError:  # its geometric stiffness is round-off
            _skip(coarse, problem, [nx, ny], None, tl)
            continue
        tl = time.perf_counter()
        if coarse.candidates is None and not _has_load(cp):
            _skip(coarse, problem, [nx, ny], cp, tl)
            cp.destroy()
            continue
        if coarse.candidates is None:
            coarse.runs = multi_seed(cp, max_iterations, seeds, more_seeds)
            runs = coarse.runs
        else:
            if coarse.last is None:
                raise RuntimeError("_coarse_levels: a polish without a coarser level")
            budget = min(max_iterations, POLISH_ITERATIONS)
            runs = _polish(cp, coarse.last, coarse.candidates, budget, coarse.bests)
        kkt = distinct_kkt(runs)
        groups = _twin_groups(kkt)
        if groups:
            best = groups[0][0].load
            coarse.candidates = [g[0] for g in groups if g[0].load <= best * (1 + refine_margin)]
            coarse.bests.append(best)
            coarse.kkt = kkt
        coarse.log.append(
            ActiveSetLevel(
                mesh=[nx, ny],
                constrained_nodes=cp.num_constrained,
                eigensolves=cp.eigensolver.solves,
                wall_time_s=time.perf_counter() - tl,
                runs=[r.summary() for r in runs],
                kkt_loads=[s.load for s in kkt],
            )
        )
        if problem.comm.rank == 0:
            PROGRESS.info(
                "active set, level %dx%d (i = %d): %d runs, %d KKT point(s)%s, %d eigen solves, "
                "%.2f s",
                nx, ny, cp.num_constrained, len(runs), len(kkt),
                f", best lambda = {kkt[0].load:.9e}" if kkt else "",
                cp.eigensolver.solves, time.perf_counter() - tl,
            )  # fmt: skip
        coarse.solves += cp.eigensolver.solves
        if coarse.last is not None:
            coarse.last.destroy()
        coarse.last = cp
        if not groups:
            # Nothing to refine: fall back to seeding on the fine level.
            coarse.candidates = None
            coarse.bests.clear()
    return coarse


def _skip(
    coarse: _Coarse,
    problem: UnilateralProblem,
    mesh: list[int],
    cp: UnilateralProblem | None,
    since: float,
) -> None:
    """Record the coarse level ``mesh`` (``cp``, None if refused) as skipped: no load."""
    why = "no positive buckling load on this mesh"
    solves = cp.eigensolver.solves if cp is not None else 0
    coarse.solves += solves
    coarse.log.append(
        ActiveSetLevel(
            mesh=mesh,
            constrained_nodes=cp.num_constrained if cp is not None else 0,
            eigensolves=solves,
            wall_time_s=time.perf_counter() - since,
            runs=[],
            kkt_loads=[],
            skipped=why,
        )
    )
    if problem.comm.rank == 0:
        PROGRESS.info("active set, level %dx%d skipped: %s", *mesh, why)


@dataclass
class _Fallbacks:
    """What ran when the fine level's iteration stalled (:func:`_fall_back`)."""

    record: Fallback | UnsetType = UNSET
    penalty_solves: int = 0  # the penalty solver has its own eigen solver
    route: list[str] = field(default_factory=list)


#: How a run ends when it gave up before a KKT point (:func:`reached_kkt`).
_STALLS = (RunStatus.CYCLE, RunStatus.MAX_ITERATIONS, RunStatus.STALLED)


def _pinned(problem: UnilateralProblem, run: Run) -> bool:
    """Whether ``run`` ended at a KKT point with every constrained node in contact."""
    final = run.final
    return (
        run.status is RunStatus.KKT
        and final is not None
        and final.active.size == problem.num_constrained
    )


def reached_kkt(problem: UnilateralProblem, runs: list[Run]) -> bool:
    """Whether ``runs`` reached a KKT point the fallbacks need not look below.

    The rule :func:`solve_active_set` asks before each fallback (:func:`_fall_back`): a
    KKT point other than the all-contact one, or that one while no run stalled.
    """
    kkt = [r for r in runs if r.status is RunStatus.KKT and r.final is not None]
    stalled = any(r.status in _STALLS for r in runs)
    return any(not _pinned(problem, r) for r in kkt) or (bool(kkt) and not stalled)


def _fall_back(
    problem: UnilateralProblem, runs: list[Run], max_iterations: int, warnings: list[str]
) -> _Fallbacks:
    """The penalty continuation, then the feasible descent, while no run is at a KKT point.

    A KKT point with every constrained node in contact (the "all" seed's at once) counts
    as none while another run stalled: its mode stays off the obstacle everywhere, which
    on a filled section leaves only the walls' stretching (a filled tube's load of
    thousands of times the hollow one's), while the stalled runs met lower modes.

    Their runs are appended to ``runs``, what they did to ``warnings``. Collective.
    """
    out = _Fallbacks()
    if reached_kkt(problem, runs):
        return out
    # The iteration stalled on this mesh: penalty continuation, started from the free
    # plate (on thin plates a stalled contact set is a poorer start).
    run, out.penalty_solves = penalty_continuation(
        problem, None, max_iterations=PENALTY_BUDGET * max_iterations
    )
    runs.append(run)
    out.route.append("penalty-continuation")
    out.record = record = Fallback(
        method="penalty continuation", penalty_eigensolves=out.penalty_solves, status=run.status
    )
    warnings.append(
        f"the active-set iteration stalled; penalty continuation ({out.penalty_solves} "
        f"eigen solves) ended {'at a KKT point' if run.status == 'kkt' else run.status}"
    )
    if reached_kkt(problem, runs):
        return out
    # Both stalled: the feasible descent cannot cycle (docs: methods/active_set); not
    # from the all-contact point, a KKT point it cannot leave.
    starts = [r for r in runs if not _pinned(problem, r)]
    last, steps = _descent(problem, starts, DESCENT_BUDGET * max_iterations)
    if last is not None:
        runs.append(last)
        out.route.append("feasible-descent")
        record.descent = DescentRecord(eigensolves=last.iterations, status=last.status, steps=steps)
        warnings.append(
            f"feasible descent ({last.iterations} eigen solves) ended "
            f"{'at a KKT point' if last.status == 'kkt' else last.status}"
        )
    return out


def _choose(
    problem: UnilateralProblem, runs: list[Run], kkt: list[Candidate], warnings: list[str]
) -> Candidate:
    """The lowest KKT point, unless a feasible mode lies lower; else the best there is.

    Raises:
        NoAdmissibleModeError: No run met a mode with a finite load.
    """
    feasible = [r.best_feasible for r in runs if r.best_feasible is not None]
    if kkt:
        chosen = _twin_groups(kkt)[0][0]
        best_feasible = min(feasible, key=lambda s: s.load)
        # Lower by more than rounding: on a thin plate double precision fixes a load to
        # its resolution only (1e-9 to 1e-8), and two solves of nested contact sets can
        # come out in the wrong order below it.
        rounding = problem.load_resolution(chosen.mode.x.petsc_vec, chosen.load)
        if best_feasible.load < chosen.load * (1 - max(PROOF_RTOL, rounding)):
            warnings.append(
                f"a feasible non-KKT mode has a lower load ({best_feasible.load:.10g}) "
                f"than the best KKT point ({chosen.load:.10g}); a lower KKT point was missed"
            )
            chosen = best_feasible
    elif feasible:
        chosen = min(feasible, key=lambda s: s.load)
        warnings.append("no seed reached a KKT point; returning the best feasible mode")
    else:
        attempt = _least_violating(runs)
        if attempt is None:
            raise NoAdmissibleModeError(
                "no admissible mode with a finite load was found (the load grows without "
                "bound as the obstacle is enforced: it may prevent buckling on this mesh; "
                f"refine it); lower bound lambda_free = {problem.solve_free().load!r} Pa"
            )
        chosen = attempt
        warnings.append(
            "no admissible mode was found; returning the least violating one (no upper bound)"
        )
    return _prune(problem, chosen) if chosen.kkt else chosen


def _fine_level(
    problem: UnilateralProblem,
    coarse: _Coarse,
    max_iterations: int,
    seeds: tuple[str, ...] = SEED_NAMES,
    more_seeds: tuple[str, ...] = (),
) -> tuple[list[Run], list[int] | str]:
    """The fine mesh's runs: the coarse sets polished, or the seeds; and what seeded them.

    Destroys the finest coarse problem. Collective.
    """
    spec = problem.spec
    seeded_on: list[int] | str
    if coarse.candidates is not None and coarse.last is not None:
        budget = min(max_iterations, POLISH_ITERATIONS)
        runs = _polish(problem, coarse.last, coarse.candidates, budget, coarse.bests)
        seeded_on = [coarse.last.spec.mesh.nx, coarse.last.spec.mesh.ny]
    else:
        runs = multi_seed(problem, max_iterations, seeds, more_seeds)
        seeded_on = [spec.mesh.nx, spec.mesh.ny] if problem.structured else "fine"
    if coarse.last is not None:
        coarse.last.destroy()
    return runs, seeded_on


def _details(
    problem: UnilateralProblem,
    free_load: float,
    seeded_on: list[int] | str,
    coarse: _Coarse,
    fallbacks: _Fallbacks,
    runs: list[Run],
    kkt: list[Candidate],
    closed: Bracket,
) -> ActiveSetDetails:
    """The run's record (its fine eigen solves, time and warning filled in by the caller)."""
    groups = _twin_groups(kkt)
    return ActiveSetDetails(
        free_load=free_load,
        seeded_on=seeded_on,
        fallback=fallbacks.record,
        levels=coarse.log,
        runs=[r.summary() for r in runs],
        kkt_points=[KktPoint(load=s.load, contact_nodes=len(s.active)) for s in kkt],
        twins=[[[int(k) for k in s.active] for s in g] for g in groups if len(g) > 1],
        coarse_kkt_loads=[s.load for s in coarse.kkt],
        fine_eigensolves=0,
        coarse_eigensolves=coarse.solves,
        penalty_eigensolves=fallbacks.penalty_solves,
        bound_evaluations=closed.evaluations,
        bound_search_complete=closed.complete,
        wall_time_s=0.0,
    )


def _check_options(
    max_iterations: int,
    coarse_min_cells: int,
    refine_margin: float,
    bound_budget: int,
    seeds: tuple[str, ...] = SEED_NAMES,
    more_seeds: tuple[str, ...] = (),
) -> None:
    """Refuse settings out of range, naming them."""
    unknown = [name for name in seeds + more_seeds if name not in SEED_NAMES]
    if unknown or not seeds or set(seeds) & set(more_seeds):
        raise InputError(
            f"seeds and more_seeds must be some of {SEED_NAMES}, seeds not empty and none "
            f"in both, got {seeds!r} and {more_seeds!r}"
        )
    # The [solver] keys' ranges, from their one description:
    ActiveSetOptions(max_iterations=max_iterations, bound_budget=bound_budget)
    if int(coarse_min_cells) != coarse_min_cells or coarse_min_cells < 2:
        raise InputError(f"coarse_min_cells must be an integer >= 2, got {coarse_min_cells!r}")
    if not (math.isfinite(refine_margin) and refine_margin >= 0):
        raise InputError(f"refine_margin must be a finite number >= 0, got {refine_margin!r}")


def solve_active_set(
    problem: UnilateralProblem,
    *,
    max_iterations: int = 100,
    multilevel: bool = True,
    coarse_min_cells: int = 8,
    refine_margin: float = 0.02,
    bound_budget: int = 64,
    seeds: tuple[str, ...] = SEED_NAMES,
    more_seeds: tuple[str, ...] = (),
    check: bool = False,
) -> UnilateralSolution:
    """Unilateral critical load by a multi-seed primal-dual active-set method.

    Args:
        problem: A set-up problem with an obstacle (its free mode is computed if absent).
        max_iterations: Iterates per seed and level, >= 1.
        multilevel: Run the seeds on coarser meshes and polish the best contact sets
            level by level (only for the structured plate mesh, when a coarser level
            with at least ``coarse_min_cells`` cells across exists).
        coarse_min_cells: Fewest cells along the shorter side of the coarsest level, >= 2.
        refine_margin: Coarse KKT points within this relative load of the best are
            refined, >= 0.
        bound_budget: Evaluations allowed for the lattice lower bound, >= 0 (the search
            runs only if the budget covers at least the i singletons).
        seeds: The seeds run on the coarsest level, some of :data:`SEED_NAMES` in their
            order; all of them by default (a plate's buckle may sit at either end or in
            the middle, and small contact sets come first on plates).
        more_seeds: Seeds run after ``seeds`` (on the same level) only if none of those
            reached a KKT point; none by default.
        check: The run checks another route's answer, which stands if the seeds find
            nothing: where they stall, no fallback runs (the penalty continuation and the
            feasible descent), and what the run did is logged as information, not as
            warnings.

    Returns:
        The best KKT point found (or, flagged in the record's ``warning``, the best
        feasible mode), with its bracket.

    Raises:
        NoAdmissibleModeError: No seed produced a mode with a finite load.

    Note:
        Collective on ``problem.comm``.
    """
    require_obstacle(problem, "solve_active_set")
    _check_options(max_iterations, coarse_min_cells, refine_margin, bound_budget, seeds, more_seeds)
    t0 = time.perf_counter()
    solves0 = problem.eigensolver.solves
    free_load = problem.solve_free().load
    spec = problem.spec
    structured = multilevel and problem.structured  # coarse copies need spec.mesh
    levels = mesh_levels(spec.mesh.nx, spec.mesh.ny, coarse_min_cells) if structured else []
    coarse = _coarse_levels(problem, levels, max_iterations, refine_margin, seeds, more_seeds)
    runs, seeded_on = _fine_level(problem, coarse, max_iterations, seeds, more_seeds)
    warnings: list[str] = []
    fallbacks = _Fallbacks() if check else _fall_back(problem, runs, max_iterations, warnings)
    kkt = distinct_kkt(runs)
    cycles = [r.seed for r in runs + coarse.runs if r.status is RunStatus.CYCLE]
    if cycles:
        warnings.append(f"active-set iteration cycled from seed(s) {cycles}")
    chosen = _choose(problem, runs, kkt, warnings)
    # -- bounds ---------------------------------------------------------------------
    closed = bracket(problem, free_load, chosen, bound_budget, "active-set")
    if closed.warning:
        warnings.append(closed.warning)
    for w in warnings:
        logger.log(logging.INFO if check else logging.WARNING, "active-set: %s", w)
    details = _details(problem, free_load, seeded_on, coarse, fallbacks, runs, kkt, closed)
    details.fine_eigensolves = problem.eigensolver.solves - solves0
    details.wall_time_s = time.perf_counter() - t0
    details.warning = "; ".join(warnings) if warnings else UNSET
    extra = coarse.solves + fallbacks.penalty_solves
    return _solution(closed, kkt, details, extra, fallbacks.route)


def _solution(
    closed: Bracket,
    kkt: list[Candidate],
    details: ActiveSetDetails,
    other_solves: int,
    fallback_route: list[str],
) -> UnilateralSolution:
    """The answer ``closed.chosen`` with its bracket and record.

    Its eigen solves: the fine mesh's (``details``) and ``other_solves`` (the coarse
    levels' and the penalty continuation's, which have their own eigen solvers).
    """
    chosen = closed.chosen
    return UnilateralSolution(
        candidate=chosen,
        method="active-set",
        eigensolves=details.fine_eigensolves + other_solves,
        lower_bound=closed.lower,
        global_optimum_proven=closed.proven,
        upper_bound=chosen.load if chosen.feasible else math.inf,
        kkt_points=kkt,
        lower_bound_by="lattice" if closed.evaluations else "interlacing",
        details=details,
        route=["active-set", *fallback_route],
    )
