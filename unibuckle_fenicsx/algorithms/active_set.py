r"""Primal-dual active-set method for the unilateral critical state, with bounds.

The discrete problem (DESIGN.md section 1): the smallest :math:`\lambda` and
:math:`u \neq 0` with :math:`u_k \le 0` on the constrained nodes I and

- :math:`r = A u - \lambda B u` zero off the contact set :math:`Z = \{k: u_k = 0\}`,
- :math:`u_k < 0` on :math:`I \setminus Z`, :math:`r_k \le 0` on Z,
- :math:`\lambda` the smallest eigenvalue of the pencil with Z removed.

**Iteration.** From a seed :math:`Z_0`, repeat: solve the reduced pencil
(:meth:`~unibuckle_fenicsx.problem.BucklingProblem.evaluate`, warm-started from the
previous mode), orient the mode away from the obstacle, add the nodes of
:math:`I \setminus Z` where it violates the obstacle (:math:`u_k > \tau`) and release
the nodes of Z whose multiplier pulls (:math:`r_k > \tau \|Au\|_\infty`). It stops at
a KKT point when neither set is empty. A contact set met twice is a cycle: the
iteration then switches to a damped rule (add violators first, release only from a
feasible mode) and, if that cycles too, stops and says so. Every feasible reduced mode
is an admissible mode, so its load is an upper bound whatever the iteration does.

**Seeds.** The conditions above have several solutions (e.g. a buckle against one
loaded edge and one between two touch-down lines; mirror images with equal loads),
so the iteration runs from several seeds: the free mode's violation set for both
signs, every constrained node fixed, buckles seeded at either end and the middle
of the long axis (Z = I outside a window of half the plate's length), and two greedy
runs (start from the free mode's most violated node for either sign, add only the
most violated node per iterate: small contact sets first, as in the paper).
The damped rule used after a cycle is also greedy. The smallest
KKT load is kept; the distinct KKT points and equal-load twins are reported.

**Multilevel (speed).** The cost is one sparse LU per iterate, and on a fine mesh the
contact zone moves by one node layer per iterate. So on a fine structured mesh the
seeds run on a hierarchy of coarser meshes (halved until the shorter side has fewer
than ``coarse_min_cells`` cells); the best KKT sets (within ``refine_margin`` of the
best load, one per group of twins) are prolonged level by level (a fine node is in
contact when a coarse contact node lies within 0.51 coarse cells in x and y) and
polished by the same iteration, which then needs a couple of iterates per level.
The answer is always a KKT point of the *fine* problem, certified there.

**Bounds.** Upper: the returned feasible load. Lower: :math:`\lambda_{free}`, and,
when the budget allows (``bound_budget`` evaluations, at least i), a best-first
branch and bound over the subset lattice: a set's subtree holds its supersets
Z ∪ {k}, k > max Z, whose loads are at least its own (interlacing), so the smallest
load on the open frontier is a lower bound, a feasible set closes its subtree, and
the bracket closes (``global_optimum_proven``) when the frontier's minimum reaches the
upper bound. If this search finds a lower feasible load, the answer is replaced and
the replacement is reported.

Note:
    All decisions use values reduced over the ranks
    (:meth:`~unibuckle_fenicsx.contact.ContactSetManager.values`), so every rank takes
    the same path; the function is collective on ``problem.comm``.
"""

from __future__ import annotations

import heapq
import logging
import math
import time
from dataclasses import dataclass, field
from typing import Any

from petsc4py import PETSc

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms import UnilateralSolution
from unibuckle_fenicsx.contact import EmptyZoneError
from unibuckle_fenicsx.problem import BucklingProblem

__all__ = ["SEED_NAMES", "TWIN_RTOL", "prolong_contact_set", "solve_active_set"]

logger = logging.getLogger(__name__)

#: Loads within this relative distance are equal-load twins.
TWIN_RTOL = 1e-8
#: Relative tolerance for "the bracket is closed".
PROOF_RTOL = 1e-10
#: Seeds run on the coarsest level, in this order.
SEED_NAMES = ("free+", "free-", "all", "end-low", "middle", "end-high", "greedy+", "greedy-")


@dataclass
class _State:
    """One evaluated contact set (values oriented as the mode in ``problem.u``)."""

    active: npt.NDArray[np.int64]
    load: float
    u: npt.NDArray[np.float64]  # mode at I, max|w| = 1, oriented
    r: npt.NDArray[np.float64]  # multiplier at I, relative to ||A u||_inf
    feasible: bool
    kkt: bool
    violation: float
    max_force: float


@dataclass
class _Run:
    """A PDAS run from one seed."""

    seed: str
    status: str = "max-iterations"
    iterations: int = 0
    final: _State | None = None
    best_feasible: _State | None = None
    history: list[tuple[int, float, bool]] = field(default_factory=list)


class _Evaluator:
    """Reduced eigen solves on one problem, with multipliers and mode snapshots.

    Owns a start vector and the saved modes; :meth:`destroy` them.
    """

    def __init__(self, problem: BucklingProblem) -> None:
        self.problem = problem
        self.tau = problem.tau
        self.n = problem.num_constrained
        vec = problem.u.x.petsc_vec
        self._start = vec.duplicate()
        self.saved: dict[bytes, PETSc.Vec] = {}
        self.calls = 0

    def mask(self, active: npt.NDArray[np.int64]) -> npt.NDArray[np.bool_]:
        m = np.zeros(self.n, dtype=bool)
        m[active] = True
        return m

    def __call__(
        self,
        active: npt.NDArray[np.int64],
        initial: PETSc.Vec | None = None,
        save: bool = True,
    ) -> _State:
        """Evaluate Z = ``active``; the oriented mode is left in ``problem.u``."""
        problem = self.problem
        start = None
        if initial is not None:
            initial.copy(self._start)
            start = self._start
        cand = problem.evaluate(active, initial=start)
        self.calls += 1
        active = cand.active
        inz = self.mask(active)
        if not math.isfinite(cand.load):
            zeros = np.zeros(self.n)
            return _State(active, math.inf, zeros, zeros, False, False, math.inf, math.inf)
        vec = problem.u.x.petsc_vec
        residual, scale, _ = problem.residual(cand.load, vec)
        assert problem.contact is not None
        r = problem.contact.values(residual) / scale
        u = np.array(cand.values)
        free_u = u[~inz]
        force = float(r[inz].max()) if inz.any() else -math.inf
        if force > self.tau and (free_u.size == 0 or np.abs(free_u).max() <= self.tau):
            # Both orientations are feasible: take the one whose contact forces push.
            if float((-r[inz]).max()) < force:
                u, r = -u, -r
                vec.scale(-1.0)
                problem.u.x.scatter_forward()
                force = float(r[inz].max())
        violation = float(u[~inz].max()) if (~inz).any() else -math.inf
        feasible = violation <= self.tau
        kkt = feasible and force <= self.tau
        state = _State(active, cand.load, u, r, feasible, kkt, violation, force)
        if save and feasible:
            key = active.tobytes()
            if key not in self.saved:
                self.saved[key] = vec.copy()
        return state

    def restore(self, active: npt.NDArray[np.int64]) -> bool:
        """Copy the saved mode of ``active`` into ``problem.u``; False if none saved."""
        saved = self.saved.get(np.asarray(active, dtype=np.int64).tobytes())
        if saved is None:
            return False
        saved.copy(self.problem.u.x.petsc_vec)
        self.problem.u.x.scatter_forward()
        return True

    def destroy(self) -> None:
        for v in (self._start, *self.saved.values()):
            v.destroy()
        self.saved = {}


def _pdas(
    ev: _Evaluator,
    seed: str,
    start: npt.NDArray[np.int64],
    initial: PETSc.Vec | None,
    max_iterations: int,
    greedy: bool = False,
) -> _Run:
    """Primal-dual active-set iteration from the contact set ``start``.

    ``greedy``: add only the most violated node(s) per iterate (the paper's idea that
    small contact sets come first), instead of every violated node.
    """
    run = _Run(seed)
    tau = ev.tau
    active = np.unique(np.asarray(start, dtype=np.int64))
    seen: set[bytes] = set()
    damped = False
    vec = ev.problem.u.x.petsc_vec
    for it in range(max_iterations):
        seen.add(active.tobytes())
        state = ev(active, initial=initial if it == 0 else vec)
        run.iterations = it + 1
        run.final = state
        run.history.append((len(active), state.load, state.feasible))
        if not math.isfinite(state.load):
            run.status = "no-finite-load"
            break
        if state.feasible and (run.best_feasible is None or state.load < run.best_feasible.load):
            run.best_feasible = state
        if state.kkt:
            run.status = "kkt"
            break
        inz = ev.mask(active)
        add = ~inz & (state.u > tau)
        if (greedy or damped) and add.any():
            add &= state.u >= state.u[add].max() * (1.0 - 1e-9)
        release = inz & (state.r > tau)
        if damped and add.any():
            release[:] = False
        new = (inz & ~release) | add
        nxt = np.flatnonzero(new).astype(np.int64)
        if nxt.tobytes() in seen:
            if damped:
                run.status = "cycle"
                break
            # Switch to the damped rule and forget the cycle.
            damped = True
            seen = set()
            new = inz | add if add.any() else inz & ~release
            nxt = np.flatnonzero(new).astype(np.int64)
        active = nxt
    return run


def _seeds(
    problem: BucklingProblem, free_values: npt.NDArray[np.float64], tau: float
) -> list[tuple[str, npt.NDArray[np.int64]]]:
    """Seed contact sets (deduplicated, in :data:`SEED_NAMES` order)."""
    assert problem.contact is not None
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
    out: list[tuple[str, npt.NDArray[np.int64]]] = []
    seen: set[bytes] = set()
    for name in SEED_NAMES:
        if name == "free+":
            z = np.flatnonzero(free_values > tau * scale)
        elif name == "free-":
            z = np.flatnonzero(-free_values > tau * scale)
        elif name == "all":
            z = np.arange(n)
        elif name in ("greedy+", "greedy-"):
            v = free_values if name == "greedy+" else -free_values
            z = (
                np.flatnonzero(v >= v.max() * (1.0 - 1e-9))
                if v.max() > tau * scale
                else np.empty(0, np.intp)
            )
        else:
            a, b = windows[name]
            c = xy[:, axis]
            z = np.flatnonzero((c < a - 1e-12 * half) | (c > b + 1e-12 * half))
        z = z.astype(np.int64)
        if z.tobytes() not in seen:
            seen.add(z.tobytes())
            out.append((name, z))
    return out


def prolong_contact_set(
    active: npt.NDArray[np.int64],
    coarse_xy: npt.NDArray[np.float64],
    fine_xy: npt.NDArray[np.float64],
    origin: tuple[float, float],
    spacing: tuple[float, float],
    cells: tuple[int, int],
) -> npt.NDArray[np.int64]:
    """Contact set on a finer structured mesh from one on a coarser mesh.

    The coarse nodes within 0.51 coarse cell widths of a fine node (in x and in y; one,
    two or four of them) vote: a fine node is in contact when at least one of them is a
    coarse contact node and none is a coarse node outside the contact set (nodes on the
    plate's edge abstain). So coinciding nodes and nodes midway between two contact nodes
    are in contact, and the contact set does not grow by a fine layer.

    Args:
        active: Coarse contact set (node numbers into ``coarse_xy``).
        coarse_xy: (ic, 2) coarse constrained-node coordinates.
        fine_xy: (i, 2) fine constrained-node coordinates.
        origin: Lower-left corner of the plate.
        spacing: Coarse cell widths (hx, hy).
        cells: Coarse cells along x and y.

    Returns:
        Sorted fine node numbers.
    """
    hx, hy = spacing
    nx, ny = cells[0] + 1, cells[1] + 1
    grid = np.zeros((nx, ny), dtype=bool)
    ix = np.rint((coarse_xy[active, 0] - origin[0]) / hx).astype(np.int64)
    iy = np.rint((coarse_xy[active, 1] - origin[1]) / hy).astype(np.int64)
    grid[np.clip(ix, 0, nx - 1), np.clip(iy, 0, ny - 1)] = True
    fx = (fine_xy[:, 0] - origin[0]) / hx
    fy = (fine_xy[:, 1] - origin[1]) / hy
    yes = np.zeros(fine_xy.shape[0], dtype=bool)
    no = np.zeros(fine_xy.shape[0], dtype=bool)
    for cx in {0: np.floor(fx), 1: np.ceil(fx)}.values():
        for cy in {0: np.floor(fy), 1: np.ceil(fy)}.values():
            gx, gy = cx.astype(np.int64), cy.astype(np.int64)
            near = (np.abs(fx - cx) <= 0.51) & (np.abs(fy - cy) <= 0.51)
            inner = near & (gx > 0) & (gx < nx - 1) & (gy > 0) & (gy < ny - 1)
            hit = np.zeros_like(inner)
            hit[inner] = grid[gx[inner], gy[inner]]
            yes |= hit
            no |= inner & ~hit
    return np.flatnonzero(yes & ~no).astype(np.int64)


def _mesh_levels(nx: int, ny: int, coarse_min_cells: int) -> list[tuple[int, int]]:
    """Coarser meshes (coarsest first) obtained by halving while both sides stay large."""
    levels: list[tuple[int, int]] = []
    while min(nx, ny) // 2 >= coarse_min_cells:
        nx, ny = nx // 2, ny // 2
        levels.append((nx, ny))
    return levels[::-1]


def _twin_groups(points: list[_State]) -> list[list[_State]]:
    """Group KKT points (sorted by load) whose loads agree within :data:`TWIN_RTOL`.

    Each group is ordered by contact-set size, then lexicographically, so that its
    first member does not depend on rounding (e.g. on the number of ranks).
    """
    groups: list[list[_State]] = []
    for p in points:
        if groups and abs(p.load - groups[-1][0].load) <= TWIN_RTOL * abs(p.load):
            groups[-1].append(p)
        else:
            groups.append([p])
    return [sorted(g, key=lambda s: (len(s.active), tuple(s.active))) for g in groups]


def _distinct_kkt(runs: list[_Run]) -> list[_State]:
    """Distinct KKT end points of ``runs``, sorted by load then lexicographically."""
    found: dict[bytes, _State] = {}
    for run in runs:
        if run.status == "kkt" and run.final is not None:
            found.setdefault(run.final.active.tobytes(), run.final)
    return sorted(found.values(), key=lambda s: (s.load, len(s.active), tuple(s.active)))


def _multi_seed(
    ev: _Evaluator,
    free_values: npt.NDArray[np.float64],
    free_vec: PETSc.Vec | None,
    max_iterations: int,
) -> list[_Run]:
    runs = []
    for name, z in _seeds(ev.problem, free_values, ev.tau):
        greedy = name.startswith("greedy")
        runs.append(_pdas(ev, name, z, free_vec, max_iterations, greedy=greedy))
    return runs


def _run_summary(run: _Run) -> dict[str, Any]:
    final = run.final
    return {
        "seed": run.seed,
        "status": run.status,
        "iterations": run.iterations,
        "load": None if final is None or not math.isfinite(final.load) else final.load,
        "contact_nodes": None if final is None else len(final.active),
        "kkt": bool(final is not None and final.kkt),
    }


def _lattice_bound(
    ev: _Evaluator, free_load: float, upper: float, budget: int
) -> tuple[float, int, _State | None, bool]:
    """Best-first branch and bound over the subset lattice (see module docstring).

    Returns:
        (lower bound, evaluations, better feasible state or None, search completed).
    """
    n = ev.n
    if budget < n:
        return free_load, 0, None, False
    better: _State | None = None
    frontier: list[tuple[float, tuple[int, ...]]] = [(free_load, ())]
    evaluations = 0
    while frontier:
        load, z = frontier[0]
        if load >= upper * (1.0 - PROOF_RTOL):
            break
        first = (z[-1] + 1) if z else 0
        if evaluations + (n - first) > budget:
            break
        heapq.heappop(frontier)
        for k in range(first, n):
            child = np.array((*z, k), dtype=np.int64)
            state = ev(child, save=True)
            evaluations += 1
            if not math.isfinite(state.load):
                continue
            if state.feasible:
                if state.load < upper * (1.0 - PROOF_RTOL):
                    upper = state.load
                    better = state
                continue
            if state.load < upper:
                heapq.heappush(frontier, (state.load, (*z, k)))
    lower = min(frontier[0][0], upper) if frontier else upper
    return lower, evaluations, better, not frontier or frontier[0][0] >= upper * (1 - PROOF_RTOL)


def _polish(
    ev: _Evaluator,
    candidates: list[npt.NDArray[np.int64]],
    prev: tuple[BucklingProblem, tuple[int, int]],
    max_iterations: int,
) -> list[_Run]:
    """Prolong the contact sets of the coarser level ``prev`` to ``ev``'s mesh; iterate."""
    coarse, (nx, ny) = prev
    target = ev.problem
    assert coarse.contact is not None and target.contact is not None
    plate = target.spec.plate
    h = (plate.length / nx, plate.width / ny)
    runs = []
    for k, z in enumerate(candidates):
        zf = prolong_contact_set(
            z, coarse.contact.coordinates, target.contact.coordinates, plate.corners[0], h, (nx, ny)
        )
        runs.append(_pdas(ev, f"candidate{k}", zf, None, max_iterations))
    return runs


def _free_load(problem: BucklingProblem) -> float:
    """Rayleigh quotient of the stored free mode (its eigenvalue to solver accuracy)."""
    assert problem.free_mode is not None
    u = problem.free_mode.x.petsc_vec
    Au, Bu = u.duplicate(), u.duplicate()
    problem.model.A.mult(u, Au)
    problem.model.B.mult(u, Bu)
    value = u.dot(Au) / u.dot(Bu)
    Au.destroy()
    Bu.destroy()
    return float(value)


def _prune(ev: _Evaluator, state: _State) -> _State:
    """Release the contact nodes with (near) zero multiplier if the KKT point stays."""
    inz = ev.mask(state.active)
    slack = inz & (state.r >= -ev.tau)
    if not slack.any():
        return state
    trial = ev(np.flatnonzero(inz & ~slack).astype(np.int64))
    if trial.kkt and trial.load <= state.load * (1.0 + PROOF_RTOL):
        return trial
    ev.restore(state.active)
    return state


def solve_active_set(
    problem: BucklingProblem,
    *,
    max_iterations: int = 100,
    multilevel: bool = True,
    coarse_min_cells: int = 8,
    refine_margin: float = 0.02,
    bound_budget: int = 64,
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

    Returns:
        The best KKT point found (or, flagged in ``details["warning"]``, the best
        feasible mode), with its bracket; the mode is left in ``problem.u``.

    Note:
        Collective on ``problem.comm``.
    """
    if problem.contact is None:
        raise ValueError("solve_active_set needs a problem with an obstacle (spec.obstacle)")
    if int(max_iterations) != max_iterations or max_iterations < 1:
        raise ValueError(f"max_iterations must be an integer >= 1, got {max_iterations!r}")
    if int(coarse_min_cells) != coarse_min_cells or coarse_min_cells < 2:
        raise ValueError(f"coarse_min_cells must be an integer >= 2, got {coarse_min_cells!r}")
    if not (math.isfinite(refine_margin) and refine_margin >= 0):
        raise ValueError(f"refine_margin must be a finite number >= 0, got {refine_margin!r}")
    if int(bound_budget) != bound_budget or bound_budget < 0:
        raise ValueError(f"bound_budget must be an integer >= 0, got {bound_budget!r}")

    t0 = time.perf_counter()
    solves0 = problem.solver.solves
    if problem.free_mode is None:
        free_load = problem.solve_free().value
    else:
        free_load = _free_load(problem)
    spec = problem.spec
    details: dict[str, Any] = {"free_load": free_load}
    structured = multilevel and not problem.custom_mesh  # coarse copies need spec.mesh
    levels = _mesh_levels(spec.mesh.nx, spec.mesh.ny, coarse_min_cells) if structured else []
    coarse_solves = 0
    level_log: list[dict[str, Any]] = []

    # -- coarse levels: seeds on the coarsest, then polish upwards --------------------
    candidates: list[npt.NDArray[np.int64]] | None = None
    coarse_kkt: list[_State] = []
    prev: tuple[BucklingProblem, tuple[int, int]] | None = None
    coarse_runs: list[_Run] = []
    for nx, ny in levels:
        try:
            cp = BucklingProblem(spec.with_mesh(nx, ny), problem.comm)
        except EmptyZoneError:
            continue
        cev = _Evaluator(cp)
        tl = time.perf_counter()
        if candidates is None:
            cp.solve_free()
            assert cp.free_mode is not None and cp.contact is not None
            fvals = cp.contact.values(cp.free_mode.x.petsc_vec)
            coarse_runs = _multi_seed(cev, fvals, cp.free_mode.x.petsc_vec, max_iterations)
            runs = coarse_runs
        else:
            assert prev is not None
            runs = _polish(cev, candidates, prev, max_iterations)
        kkt = _distinct_kkt(runs)
        groups = _twin_groups(kkt)
        if groups:
            best = groups[0][0].load
            candidates = [g[0].active for g in groups if g[0].load <= best * (1 + refine_margin)]
            coarse_kkt = kkt
        level_log.append(
            {
                "mesh": [nx, ny],
                "constrained_nodes": cp.num_constrained,
                "eigensolves": cp.solver.solves,
                "wall_time_s": time.perf_counter() - tl,
                "runs": [_run_summary(r) for r in runs],
                "kkt_loads": [s.load for s in kkt],
            }
        )
        coarse_solves += cp.solver.solves
        cev.destroy()
        if prev is not None:
            prev[0].destroy()
        prev = (cp, (nx, ny))
        if not groups:
            # Nothing to refine: fall back to seeding on the fine level.
            candidates = None
    # -- finest level -------------------------------------------------------------
    ev = _Evaluator(problem)
    assert problem.free_mode is not None
    if candidates is not None and prev is not None:
        runs = _polish(ev, candidates, prev, max_iterations)
        details["seeded_on"] = list(prev[1])
    else:
        fvals = problem.contact.values(problem.free_mode.x.petsc_vec)
        runs = _multi_seed(ev, fvals, problem.free_mode.x.petsc_vec, max_iterations)
        details["seeded_on"] = [spec.mesh.nx, spec.mesh.ny]
    if prev is not None:
        prev[0].destroy()

    kkt = _distinct_kkt(runs)
    feasible = [r.best_feasible for r in runs if r.best_feasible is not None]
    warnings: list[str] = []
    cycles = [r.seed for r in runs + coarse_runs if r.status == "cycle"]
    if cycles:
        warnings.append(f"active-set iteration cycled from seed(s) {cycles}")
    if kkt:
        chosen = _twin_groups(kkt)[0][0]
        best_feasible = min(feasible, key=lambda s: s.load)
        if best_feasible.load < chosen.load * (1 - PROOF_RTOL):
            warnings.append(
                f"a feasible non-KKT mode has a lower load ({best_feasible.load:.10g}) "
                f"than the best KKT point ({chosen.load:.10g}); a lower KKT point was missed"
            )
            chosen = best_feasible
    elif feasible:
        chosen = min(feasible, key=lambda s: s.load)
        warnings.append("no seed reached a KKT point; returning the best feasible mode")
    else:
        ev.destroy()
        raise RuntimeError(
            "active-set: no seed produced a feasible mode "
            f"(runs: {[_run_summary(r) for r in runs]})"
        )
    ev.restore(chosen.active)
    if chosen.kkt:
        chosen = _prune(ev, chosen)

    # -- bounds ---------------------------------------------------------------------
    lower, bound_evals, better, complete = _lattice_bound(ev, free_load, chosen.load, bound_budget)
    if better is not None:
        warnings.append(
            f"the lattice search found a lower feasible load {better.load:.10g} "
            f"than the active-set point {chosen.load:.10g}"
        )
        chosen = better
    ev.restore(chosen.active)
    lower = max(lower, free_load)
    proven = bool(lower >= chosen.load * (1 - PROOF_RTOL))

    cert = problem.certify(chosen.load, chosen.active, global_optimum_proven=proven)
    if not cert.kkt:
        warnings.append(f"the returned point fails its certificate: {cert.as_dict()}")
    groups = _twin_groups(kkt)
    details.update(
        {
            "levels": level_log,
            "runs": [_run_summary(r) for r in runs],
            "kkt_points": [{"load": s.load, "contact_nodes": len(s.active)} for s in kkt],
            "twins": [[[int(k) for k in s.active] for s in g] for g in groups if len(g) > 1],
            "coarse_kkt_loads": [s.load for s in coarse_kkt],
            "fine_eigensolves": problem.solver.solves - solves0,
            "coarse_eigensolves": coarse_solves,
            "bound_evaluations": bound_evals,
            "bound_search_complete": complete,
            "kkt": cert.kkt,
            "certificate": cert.as_dict(),
            "wall_time_s": time.perf_counter() - t0,
        }
    )
    if warnings:
        details["warning"] = "; ".join(warnings)
        for w in warnings:
            logger.warning("active-set: %s", w)
    ev.destroy()
    return UnilateralSolution(
        load=chosen.load,
        active=chosen.active,
        eigensolves=problem.solver.solves - solves0 + coarse_solves,
        lower_bound=min(lower, chosen.load),
        global_optimum_proven=proven,
        details=details,
    )
