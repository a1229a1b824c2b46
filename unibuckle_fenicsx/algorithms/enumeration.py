r"""The paper's direct method (Ayadi, section 5.3): enumerate the contact sets by size.

For p = 0, 1, ..., i (i = number of constrained nodes) and every subset Z of I with
|Z| = p, in the lexicographic order of :func:`itertools.combinations`, compute the
smallest eigenpair of the pencil with the w-DOFs of Z removed
(:meth:`~unibuckle_fenicsx.model.problem.UnilateralProblem.evaluate`). The mode is *feasible*
when, suitably oriented, it is negative on :math:`I \setminus Z` (tolerance tau). Keep
the smallest feasible load and stop after the first p that produced a feasible mode
(:math:`p^*`), or visit every p (``complete=True``) to check the paper's observation
that :math:`\lambda(p) \le \lambda(q)` for :math:`p \le q`, with :math:`\lambda(p)` the
smallest feasible load among the sets of size p.

That observation does not hold in general (e.g. the zone c1 on the 8 x 4 mesh:
:math:`\lambda(2) > \lambda(3)`, the optimum being a full column of contact nodes), and
then the paper's stopping rule returns an admissible mode whose load is above the
critical one. Every result therefore carries a proven lower bound:

Optimality. The critical state's contact set Z has a feasible reduced first mode
(Lemma 5.1), so it is one of the feasible sets. Removing more DOFs never lowers the
smallest eigenvalue (interlacing, :doc:`/methods/problem`), so a set Z with :math:`|Z| > q`
has :math:`\lambda(Z) \ge \max_{S \subset Z, |S| = q} \lambda(S)`, a maximum over at
least q + 1 distinct sets of size q; it is therefore at least :math:`\mu_q`, the
(q+1)-th smallest :math:`\lambda(S)` over *all* sets of size q (feasible or not). After
visiting the sizes 0..q the critical load is bounded below by the smaller of
:math:`\mu_q` and the best feasible load found; the result is proven optimal when the
two agree. (The cruder bound :math:`\min_{|S| = p^*} \lambda(S)` is also reported.)
``until_proven=True`` keeps enumerating past :math:`p^*` until the bound proves the
best feasible load optimal (exact, usually far fewer sets than ``complete``). The
complete mode is exhaustive. These arguments assume, as the paper does, that the
reduced first eigenvalue is simple.

Ties (mirror-symmetric sets have equal loads up to rounding) are broken
deterministically: the smallest load, and among loads within
:data:`~unibuckle_fenicsx.tolerances.LOAD_TIE_RTOL` of it the lexicographically smallest
set. Every candidate solve starts from the same
pseudo-random vector (seeded, indexed by global DOF), so that a set's load does not
depend on which sets were solved before on the same rank.

Candidate-parallel runs (``candidate_comm``): every rank holds its own serial copy of
the problem and evaluates the candidates of each p round-robin; the per-p results are
reduced on all ranks, which therefore stop at the same p and pick the same set; the
rank that evaluated the winning set broadcasts its mode.
"""

from __future__ import annotations

import itertools
import logging
import math
import time
from dataclasses import dataclass

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np

from unibuckle_fenicsx.algorithms import UnilateralSolution, candidate_count
from unibuckle_fenicsx.algorithms.records import EnumerationDetails
from unibuckle_fenicsx.errors import InputError, NoAdmissibleModeError
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem, require_obstacle
from unibuckle_fenicsx.progress import LOGGER as PROGRESS
from unibuckle_fenicsx.progress import Progress
from unibuckle_fenicsx.spec.solver import EnumerateOptions
from unibuckle_fenicsx.tolerances import LOAD_TIE_RTOL, PROOF_RTOL

__all__ = ["LevelSummary", "enumerate_contact_sets"]

logger = logging.getLogger(__name__)

#: Seed of the start vector shared by all candidate solves.
START_SEED = 20240503


@dataclass(frozen=True)
class LevelSummary:
    """Reduced (over candidate ranks) results for one contact-set size p.

    Attributes:
        p: Contact-set size.
        candidates: C(i, p), the sets evaluated.
        feasible: Number of sets with a feasible mode.
        load_min: Smallest load over all sets of size p (feasible or not).
        load_kth: The (p+1)-th smallest load over all sets of size p (``inf`` if fewer).
        best_load: Smallest feasible load (``inf`` if none).
        best_set: The set giving it (ties: lexicographically smallest), or None.
        wall_s: Wall time of this level (max over ranks).
    """

    p: int
    candidates: int
    feasible: int
    load_min: float
    load_kth: float
    best_load: float
    best_set: tuple[int, ...] | None
    wall_s: float


def _start_vector(problem: UnilateralProblem) -> PETSc.Vec:
    """Seeded pseudo-random vector of the W layout, partition independent (caller destroys)."""
    vec = problem.model.A.createVecRight()
    lo, hi = vec.getOwnershipRange()
    rng = np.random.default_rng(START_SEED)
    vec.array_w[:] = rng.standard_normal(vec.getSize())[lo:hi]
    vec.assemble()
    return vec


def _pick(entries: list[tuple[float, tuple[int, ...]]]) -> tuple[float, tuple[int, ...] | None]:
    """Smallest load, then lexicographically smallest set among loads within LOAD_TIE_RTOL."""
    if not entries:
        return math.inf, None
    best = min(load for load, _ in entries)
    ties = [(s, load) for load, s in entries if load <= best * (1.0 + LOAD_TIE_RTOL)]
    s, load = min(ties)
    return load, s


def _reduce_level(
    p: int,
    n: int,
    loads: list[float],
    feasible: list[tuple[float, tuple[int, ...]]],
    wall: float,
    comm: MPI.Comm,
) -> LevelSummary:
    """Combine the candidate ranks' results for size p (collective on ``comm``)."""
    k = p + 1
    smallest = sorted(loads)[:k]
    merged = sorted(x for part in comm.allgather(smallest) for x in part)
    load_kth = merged[k - 1] if len(merged) >= k else math.inf
    load_min = merged[0] if merged else math.inf
    n_feasible = comm.allreduce(len(feasible), op=MPI.SUM)
    # Global minimum first, then each rank offers its lexicographic pick within the ties.
    local_min = min((load for load, _ in feasible), default=math.inf)
    global_min = comm.allreduce(local_min, op=MPI.MIN)
    offers = [(load, s) for load, s in feasible if load <= global_min * (1.0 + LOAD_TIE_RTOL)]
    local_offer = min(offers, key=lambda e: e[1]) if offers else None
    picks = [e for e in comm.allgather(local_offer) if e is not None]
    best_load, best_set = _pick(picks)
    return LevelSummary(
        p=p,
        candidates=n,
        feasible=int(n_feasible),
        load_min=float(load_min),
        load_kth=float(load_kth),
        best_load=float(best_load),
        best_set=best_set,
        wall_s=float(comm.allreduce(wall, op=MPI.MAX)),
    )


def _monotonicity(levels: list[LevelSummary]) -> tuple[bool, list[list[int]]]:
    r"""Check :math:`\lambda(p) \le \lambda(q)` for p <= q over the sizes with a feasible mode."""
    feasible = [lv for lv in levels if lv.best_set is not None]
    violations = [
        [a.p, b.p]
        for a, b in itertools.combinations(feasible, 2)
        if a.best_load > b.best_load * (1.0 + LOAD_TIE_RTOL)
    ]
    return not violations, violations


def _keep_ties(ties: list[Candidate], cand: Candidate) -> list[Candidate]:
    """Add ``cand`` to the feasible candidates within LOAD_TIE_RTOL of the smallest load."""
    best = min([c.load for c in ties] + [cand.load])
    return [c for c in [*ties, cand] if c.load <= best * (1.0 + LOAD_TIE_RTOL)]


def _share(problem: UnilateralProblem, mine: Candidate | None, ccomm: MPI.Comm) -> Candidate:
    """The winning candidate on every candidate rank: its evaluator broadcasts the mode.

    Every rank holds a serial copy of the same mesh, so the DOF layouts agree.
    """
    owner = ccomm.allreduce(ccomm.rank if mine is not None else ccomm.size, op=MPI.MIN)
    if ccomm.size == 1:
        if mine is None:
            raise RuntimeError("_share: expected mine is not None (an internal invariant)")
        return mine
    payload = None
    if ccomm.rank == owner:
        if mine is None:
            raise RuntimeError("_share: expected mine is not None (an internal invariant)")
        payload = (mine.mode.x.array.copy(), mine.load, mine.active, mine.eigen)
    array, load, active, eigen = ccomm.bcast(payload, root=owner)
    if ccomm.rank == owner:
        if mine is None:
            raise RuntimeError("_share: expected mine is not None (an internal invariant)")
        return mine
    u = problem.new_mode()
    u.x.array[:] = array
    return problem.candidate(u, load, active, eigen=eigen)


def _finite_or_none(value: float) -> float | None:
    return value if math.isfinite(value) else None


def _check(problem: UnilateralProblem, max_candidates: int, ccomm: MPI.Comm) -> None:
    """Refuse a bad ``max_candidates``, too many candidate sets, or a distributed copy."""
    if (
        isinstance(max_candidates, bool)
        or int(max_candidates) != max_candidates
        or max_candidates < 1
    ):
        raise InputError(f"max_candidates must be an integer >= 1, got {max_candidates!r}")
    if ccomm.size > 1 and problem.comm.size > 1:
        raise InputError(
            "candidate_comm needs a serial copy of the problem on every rank "
            f"(problem.comm has {problem.comm.size} ranks): build it on MPI.COMM_SELF, "
            "e.g. analysis.solve(..., candidate_parallel=True)"
        )
    i = problem.contact.size
    count = candidate_count(i)
    if count > max_candidates:
        raise InputError(
            f"enumeration may need {count} candidate sets (2^{i}, i = {i} constrained "
            f"nodes), above max_candidates = {max_candidates}: use --method active-set "
            "(or a coarser mesh, a smaller zone, or a larger --max-candidates)"
        )


def _level(
    problem: UnilateralProblem, p: int, start: PETSc.Vec, ccomm: MPI.Comm, talk: bool
) -> tuple[LevelSummary, Candidate | None]:
    """Every contact set of size ``p`` (this rank's share): the level, this rank's best.

    Collective on ``problem.comm`` and ``ccomm``.
    """
    i = problem.contact.size
    t0 = time.perf_counter()
    loads: list[float] = []
    feasible: list[tuple[float, tuple[int, ...]]] = []
    ties: list[Candidate] = []  # feasible candidates within LOAD_TIE_RTOL of the best
    n = 0
    progress = Progress(f"enumeration p = {p}", math.comb(i, p), enabled=talk)
    for j, combo in enumerate(itertools.combinations(range(i), p)):
        n += 1
        progress.update(j)
        if j % ccomm.size != ccomm.rank:
            continue
        cand = problem.evaluate(np.asarray(combo, dtype=np.int64), initial=start)
        loads.append(cand.load)
        if cand.feasible:
            feasible.append((cand.load, combo))
            ties = _keep_ties(ties, cand)
    level = _reduce_level(p, n, loads, feasible, time.perf_counter() - t0, ccomm)
    mine = (
        next((c for c in ties if tuple(c.active) == level.best_set), None)
        if level.best_set is not None
        else None
    )
    return level, mine


def _stop(levels: list[LevelSummary], complete: bool, until_proven: bool) -> bool:
    """Whether the enumeration stops after the last level (section 5.3; module docstring)."""
    level = levels[-1]
    if complete:
        return False
    if until_proven:
        found = min((lv.best_load for lv in levels), default=math.inf)
        return math.isfinite(found) and level.load_kth >= found * (1.0 - PROOF_RTOL)
    return level.best_set is not None


def _details(
    levels: list[LevelSummary],
    nodes: int,
    p_optimum: int,
    complete: bool,
    until_proven: bool,
    ranks: int,
    t_start: float,
) -> EnumerationDetails:
    """The enumeration's record: per size visited its best and least loads, counts and times."""
    monotone, violations = _monotonicity(levels) if complete else (None, [])
    first = next(lv for lv in levels if lv.best_set is not None)
    return EnumerationDetails(
        constrained_nodes=nodes,
        candidate_count=candidate_count(nodes),
        candidates_evaluated=sum(lv.candidates for lv in levels),
        candidate_ranks=ranks,
        complete=complete,
        until_proven=until_proven,
        p_optimum=p_optimum,
        lambda_by_p=[_finite_or_none(lv.best_load) for lv in levels],
        feasible_by_p=[lv.feasible for lv in levels],
        candidates_by_p=[lv.candidates for lv in levels],
        lambda_min_by_p=[_finite_or_none(lv.load_min) for lv in levels],
        wall_by_p_s=[lv.wall_s for lv in levels],
        monotone=monotone,
        monotone_violations=violations,
        lower_bound_interlacing=first.load_min,
        enumeration_wall_s=time.perf_counter() - t_start,
    )


def _solution(
    problem: UnilateralProblem,
    levels: list[LevelSummary],
    kept: list[Candidate | None],
    ccomm: MPI.Comm,
    complete: bool,
    until_proven: bool,
    t_start: float,
    solves0: int,
) -> UnilateralSolution:
    """The best admissible set over the sizes visited, its bound and the record.

    Raises:
        NoAdmissibleModeError: No size had a set with an admissible mode.

    Note:
        Collective on ``problem.comm`` and ``ccomm``.
    """
    i = problem.contact.size
    rank, size = ccomm.rank, ccomm.size
    with_feasible = [lv for lv in levels if lv.best_set is not None]
    if not with_feasible:
        raise NoAdmissibleModeError(
            f"no admissible mode with a finite load: no contact set of the {i} constrained "
            f"nodes gives a feasible mode (tau = {problem.tau:g}), so the obstacle prevents "
            f"buckling on this mesh; lower bound lambda_free = {problem.solve_free().load!r} Pa"
        )
    p_star = with_feasible[0].p
    load, chosen = _pick([(lv.best_load, lv.best_set) for lv in with_feasible])  # type: ignore[misc]
    if chosen is None:
        raise RuntimeError(
            "enumerate_contact_sets: expected chosen is not None (an internal invariant)"
        )
    last = levels[-1]
    # Sets larger than the last size visited: >= its (p+1)-th smallest load.
    lower = load if last.p == i else min(load, last.load_kth)
    proven = lower >= load * (1.0 - PROOF_RTOL)
    level_of = next(k for k, lv in enumerate(levels) if lv.best_set == chosen)
    candidate = _share(problem, kept[level_of], ccomm)
    eigensolves = int(ccomm.allreduce(problem.eigensolver.solves - solves0, op=MPI.SUM))

    details = _details(levels, i, len(chosen), complete, until_proven, size, t_start)
    if problem.comm.rank == 0 and rank == 0:
        logger.info(
            "enumeration: lambda = %.9e, |Z| = %d, p* = %d, lower bound %.9e (%s), %d eigen solves",
            load,
            len(chosen),
            p_star,
            lower,
            "proven" if proven else "not proven",
            eigensolves,
        )
    return UnilateralSolution(
        candidate=candidate,
        method="enumerate",
        eigensolves=eigensolves,
        lower_bound=float(lower),
        global_optimum_proven=bool(proven),
        upper_bound=float(load),
        p_star=p_star,
        lower_bound_by="enumeration",
        details=details,
    )


def enumerate_contact_sets(
    problem: UnilateralProblem,
    *,
    complete: bool = False,
    max_candidates: int = 100_000,
    candidate_comm: MPI.Comm | None = None,
    until_proven: bool = False,
) -> UnilateralSolution:
    r"""Critical load by the paper's enumeration of contact sets (section 5.3).

    Args:
        problem: A set-up problem with an obstacle.
        complete: Visit every size p = 0..i instead of stopping after the first p with
            a feasible mode; reports :math:`\lambda(p)` per p and whether it is
            monotone, and proves the global optimum.
        max_candidates: Refuse (``ValueError``, before any solve) when the number of
            candidate sets that may be visited, :math:`2^i`, exceeds this.
        candidate_comm: Split the candidate sets of each p round-robin over this
            communicator's ranks; every rank must hold its own serial copy of the
            problem (``problem.comm`` of size 1). ``None``: evaluate every candidate
            on ``problem.comm`` (which may distribute the mesh).
        until_proven: Do not stop at :math:`p^*` (the paper's rule) but after the first
            size q at which the interlacing bound proves the best feasible load found
            globally optimal (see the module docstring).

    Returns:
        The solution, its candidate on every rank. ``eigensolves`` counts the solves of
        all candidate ranks. ``details`` holds, per visited p, the candidates, the feasible
        count, :math:`\lambda(p)` (``lambda_by_p``) and the smallest load of any set
        (``lambda_min_by_p``); ``monotone`` (complete mode; ``None`` otherwise).

    Raises:
        ValueError: No obstacle, bad ``max_candidates``, too many candidates, or a
            distributed problem with ``candidate_comm``.
        NoAdmissibleModeError: No contact set gives a feasible mode.

    Note:
        Collective on ``problem.comm`` and on ``candidate_comm``.
    """
    require_obstacle(problem, "enumerate_contact_sets")
    EnumerateOptions(max_candidates=max_candidates)  # the [solver] key's range
    ccomm = MPI.COMM_SELF if candidate_comm is None else candidate_comm
    _check(problem, max_candidates, ccomm)
    i = problem.contact.size
    count = candidate_count(i)
    t_start = time.perf_counter()
    solves0 = problem.eigensolver.solves
    start = _start_vector(problem)
    levels: list[LevelSummary] = []
    kept: list[Candidate | None] = []  # per level: this rank's candidate of its best set
    talk = ccomm.rank == 0 and problem.comm.rank == 0
    try:
        for p in range(i + 1):
            level, mine = _level(problem, p, start, ccomm, talk)
            levels.append(level)
            kept.append(mine)
            if talk:
                PROGRESS.info(
                    "enumeration p = %d done: %d sets, %d feasible, lambda(p) = %.9e, "
                    "min lambda = %.9e (%.2f s); %d of %d sets visited",
                    p,
                    level.candidates,
                    level.feasible,
                    level.best_load,
                    level.load_min,
                    level.wall_s,
                    sum(lv.candidates for lv in levels),
                    count,
                )
            if _stop(levels, complete, until_proven):
                break
    finally:
        start.destroy()

    return _solution(problem, levels, kept, ccomm, complete, until_proven, t_start, solves0)
