r"""Which route answers a unilateral problem, and in what order: the solver chain.

For a rigid obstacle (any side, several zones) the chain is

1. **Nested interior-point Newton** (:mod:`.interior_point`). On the coarsest mesh (a
   structured plate's cells halved, a gmsh plate's cell size doubled, while the shorter
   side keeps ``explore_min_cells`` cells; a user's mesh has one level) the method runs
   from a few starts (the parts of the free plate's first two modes on either side of
   the obstacle, the deflection under a pressure on the whole zone, on either end and in
   the middle): the buckle may sit
   almost anywhere at nearly the same load, and each start finds one arrangement (a
   start that joins the central path of one met before stops there). The
   lowest critical state is carried to the next finer mesh by interpolating its mode (a
   point of the central path: the push there is μ/g node by node and the load the mode's
   quotient, so neither needs carrying); there a few Newton steps restore the barrier
   problem, and so on to the fine mesh.
2. **Contact set and exact eigenpair.** The fine barrier solution gives the contact set
   Z: first where the barrier problem at ``read_mu`` is solved, the nodes that the
   Newton step for a zero barrier parameter closes by more than half their gap
   (:meth:`~.interior_point.newton.InteriorPointNewton.predicted_contact_set`), which ends the
   run if it is a KKT point; else, at the end, the nodes whose gap is at the tolerance
   ``tau``. The smallest eigenpair of the
   pencil with Z removed (:meth:`~unibuckle_fenicsx.model.problem.UnilateralProblem.evaluate`)
   is the returned critical state, checked against the KKT conditions. If it fails, a
   saddle is escaped (the lower reduced mode shows the way), the barrier is driven
   lower and the active-set iteration (:mod:`.pdas`) polishes Z; if that fails too, the
   coarse state is carried once more at a small barrier parameter (flat parts stay
   flat), with a longer polish and the feasible descent (:mod:`.descent`).
3. **Fallbacks.** The feasible descent from the lowest admissible mode met (it cannot
   cycle); then the multilevel active-set method (:mod:`.active_set`, with its penalty
   continuation) from scratch.

Tensionless foundations run their spring-set iteration (:mod:`.foundation`); small
zones are enumerated (:mod:`.enumeration`; :func:`~.registry.choose_method`
decides).

Every link leaves a typed record (:class:`~.records.LinkRecord`); the solution's
``route`` names the links that answered.

Note:
    Collective on the problem's communicator.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable, Sequence
from typing import Protocol

import dolfinx

from msgspec import UNSET
from msgspec.structs import replace

from unibuckle_fenicsx.algorithms import UnilateralSolution
from unibuckle_fenicsx.algorithms.bounds import bracket
from unibuckle_fenicsx.algorithms.interior_point.explore import explore
from unibuckle_fenicsx.algorithms.interior_point.links import (
    MeshLevel,
    Reader,
    critical_state,
    descend_from,
    newton_link,
)
from unibuckle_fenicsx.algorithms.interior_point.newton import InteriorPointNewton
from unibuckle_fenicsx.algorithms.interior_point.options import BarrierPoint, ChainOptions
from unibuckle_fenicsx.algorithms.multilevel import Prolongation, mesh_levels
from unibuckle_fenicsx.algorithms.records import (
    ActiveSetDetails,
    InteriorPointDetails,
    LinkRecord,
    SectionLevelsDetails,
)
from unibuckle_fenicsx.errors import EmptyZoneError, InputError, NoAdmissibleModeError
from unibuckle_fenicsx.model.build import build_unilateral_problem
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem, require_obstacle
from unibuckle_fenicsx.progress import LOGGER as PROGRESS
from unibuckle_fenicsx.progress import warn_once
from unibuckle_fenicsx.spec import ProblemSpec

__all__ = ["THIN_PLATE", "ChainOptions", "solve_interior_point", "thin_plate"]

logger = logging.getLogger(__name__)

#: "auto" runs the interior-point route on plates whose thickness is below this fraction
#: of the shorter side, the multilevel active set on thicker ones: on thin plates the
#: active set needs hundreds of eigen solves against a whole face, and 0.02 is where the
#: answers of "auto" have been (:doc:`/verification/tuning`, and the benchmarks' "Which
#: route").
THIN_PLATE = 0.02


def thin_plate(spec: ProblemSpec) -> bool:
    """Whether ``spec``'s plate is thinner than :data:`THIN_PLATE` of its shorter side."""
    plate = spec.plate
    return plate.thickness / min(plate.length, plate.width) < THIN_PLATE


class Carry(Protocol):
    """What carries a mode from a coarse problem to a finer one (``fine``, ``mode``)."""

    fine: UnilateralProblem

    def mode(self, u: dolfinx.fem.Function) -> dolfinx.fem.Function:
        """The coarse mode ``u`` on the fine problem's space."""
        ...


#: Makes the :class:`Carry` from ``problems[k - 1]`` to ``problems[k]``.
CarryFactory = Callable[[UnilateralProblem, UnilateralProblem], Carry]


def _refine(
    carry: Carry,
    point: BarrierPoint,
    level: MeshLevel,
    options: ChainOptions,
    last: bool,
    mu: float,
    label: str,
    quick: bool,
    newton: InteriorPointNewton,
) -> tuple[Candidate | None, BarrierPoint | None]:
    """Carry ``point`` to the finer mesh (``carry``) and solve the barrier problem there.

    The interpolated mode is relaxed into the fine mesh's discrete Kirchhoff kernel
    (:meth:`~.interior_point.starts.Starts.relax`), the nodes it brings too close
    to the obstacle are moved back by the least-energy correction
    (:meth:`~.interior_point.starts.Starts.lift`), then the method runs from
    the barrier parameter ``mu``: to ``mu`` on an intermediate mesh, to ``fine_mu_min``
    on the fine one, whose critical state is read. ``newton``: the method on ``fine``
    (the caller's, kept for the level's other arrangements: its factorisation's symbolic
    analysis is done once per mesh).
    """
    fine = carry.fine
    mode = carry.mode(point.mode)
    newton.kernel.forget_corrections()
    try:
        newton.starts.relax(mode.x.petsc_vec, "deflection")
        newton.starts.relax(mode.x.petsc_vec, "rotations")
        newton.starts.lift(mode, options.clip_margin)
        reader = Reader(fine, newton, level, options) if last else None
        new, rec = newton.solve(
            mode,
            mu=mu,
            mu_min=options.fine_mu_min if last else mu,
            max_steps=options.max_steps,
            on_solved=None if reader is None else reader.arm(label),
            on_step=None if reader is None else reader.step,
        )
    except (ValueError, FloatingPointError) as err:
        level.links.append(LinkRecord("interior-point", label, f"failed: {err}"))
        return None, None
    level.links.append(newton_link(label, rec))
    if not last:
        return None, new
    assert reader is not None
    if reader.found is not None:
        return reader.found, new
    cand, new = critical_state(
        fine,
        newton,
        new,
        level,
        label,
        options,
        carry=False,
        quick=quick,
        reader=reader,
        double=True,
    )
    return cand, new


def _level_record(problem: UnilateralProblem, cells: bool = False) -> MeshLevel:
    """The record of one mesh; ``cells``: name it by its cells even if unstructured."""
    spec = problem.spec
    named = problem.structured or cells
    mesh: list[int | str] = [spec.mesh.nx, spec.mesh.ny] if named else ["fine"]
    if _gmsh_levels(problem):
        mesh = [f"h={spec.mesh.size:.3g}"]
    return MeshLevel(mesh, problem.num_constrained)


def _gmsh_levels(problem: UnilateralProblem) -> bool:
    """Whether coarser copies of ``problem`` are meshed by gmsh at larger cell sizes."""
    spec = problem.spec
    return (
        not problem.custom_mesh
        and spec.plate.meshed_by_gmsh
        and spec.plate.file is None
        and spec.mesh.size is not None
    )


def _coarser(problem: UnilateralProblem, options: ChainOptions) -> list[ProblemSpec]:
    """The problem on coarser meshes, coarsest first.

    Coarser while the shorter side keeps ``explore_min_cells`` cells. A structured
    rectangle's cells are halved (:func:`~.multilevel.mesh_levels`); a plate meshed by
    gmsh (outline, holes) is meshed again at twice the cell size, and again (the meshes
    are not nested: :class:`~.multilevel.Prolongation` interpolates between any two). A
    size at which gmsh cannot resolve a hole or an outline ends the levels. A user's
    mesh or a mesh file has no coarser copy.
    """
    spec = problem.spec
    if problem.structured:
        levels = mesh_levels(spec.mesh.nx, spec.mesh.ny, options.explore_min_cells)
        return [spec.with_mesh(nx, ny) for nx, ny in levels]
    if not _gmsh_levels(problem):
        return []
    assert spec.mesh.size is not None
    side, size = min(spec.plate.length, spec.plate.width), spec.mesh.size
    specs: list[ProblemSpec] = []
    while side / (2.0 * size) >= options.explore_min_cells:
        size *= 2.0
        try:
            specs.append(replace(spec, mesh=replace(spec.mesh, size=size)))
        except InputError:  # a feature below size / FEATURE_RATIO
            break
    return specs[::-1]


def _report(problem: UnilateralProblem, level: MeshLevel) -> None:
    if problem.comm.rank == 0:
        PROGRESS.info(
            "interior point, mesh %s (i = %d): %d Newton steps, %d factorisations, "
            "%d eigen solves, %.2f s",
            "x".join(map(str, level.mesh)), level.constrained_nodes, level.newton_steps,
            level.factorizations, level.eigensolves, level.seconds,
        )  # fmt: skip


def _carry(
    problems: list[UnilateralProblem],
    k: int,
    points: list[BarrierPoint],
    level: MeshLevel,
    options: ChainOptions,
    mu: float,
    label: str,
    quick: bool,
    newtons: dict[int, InteriorPointNewton],
    carrier: CarryFactory,
) -> tuple[list[Candidate], list[BarrierPoint]]:
    """Carry every point from ``problems[k - 1]`` to ``problems[k]``.

    On an intermediate mesh the points whose loads lie more than ``carry_margin`` above
    the lowest are dropped (the meshes rank the arrangements better as they get finer);
    on the finest, the KKT points met are returned. ``newtons``: the method on each mesh
    (created here when missing), shared by the arrangements and tries. ``carrier``
    makes the carry between the two meshes.
    """
    tl = time.perf_counter()
    last = k == len(problems) - 1
    found: list[Candidate] = []
    carried: list[BarrierPoint] = []
    if k not in newtons:
        newtons[k] = InteriorPointNewton(problems[k])
    carry = carrier(problems[k - 1], problems[k])
    for j, point in enumerate(points):
        tag = label if len(points) == 1 else f"{label} {j + 1}"
        cand, new = _refine(carry, point, level, options, last, mu, tag, quick, newtons[k])
        if cand is not None and cand.kkt:
            found.append(cand)
        if new is not None and not last:
            carried.append(new)
    if carried:
        lowest = min(p.load for p in carried)
        carried = [p for p in carried if p.load <= lowest * (1.0 + options.carry_margin)]
    level.seconds += time.perf_counter() - tl
    _report(problems[k], level)
    return found, carried


def _ascend(
    problems: list[UnilateralProblem],
    points: list[BarrierPoint],
    levels: list[MeshLevel],
    options: ChainOptions,
    mu: float,
    label: str,
    quick: bool,
    newtons: dict[int, InteriorPointNewton],
    carrier: CarryFactory,
) -> Candidate | None:
    """Carry ``points`` from ``problems[0]`` to the fine mesh; the lowest KKT point there."""
    for k in range(1, len(problems)):
        found, points = _carry(
            problems, k, points, levels[k], options, mu, label, quick, newtons, carrier
        )
        if k == len(problems) - 1:
            return min(found, key=lambda c: c.load) if found else None
        if not points:
            return None
    return None


def _levels(
    problems: list[UnilateralProblem],
    options: ChainOptions,
    carrier: CarryFactory = Prolongation,
    cells: bool = False,
) -> tuple[list[MeshLevel], list[Candidate], Candidate | None]:
    """Explore the coarsest mesh and carry its best critical states up to the finest.

    The states are carried on the central path at ``level_mu``, where the contact lines
    still move freely. If the fine mesh then ends at no KKT point (typically at a saddle
    where buckles that the barrier keeps apart have almost equal loads), the lowest is
    carried once more at ``flat_mu``, which keeps the parts lying on the obstacle flat.
    ``carrier`` makes the carry between two meshes; ``cells``: name the meshes by cells.
    """
    levels = [_level_record(p, cells) for p in problems]
    tl = time.perf_counter()
    explored, carried = explore(problems[0], levels[0], options, carry=len(problems) > 1)
    levels[0].seconds = time.perf_counter() - tl
    _report(problems[0], levels[0])
    if len(problems) == 1 or not carried:
        return levels, explored, (explored[0] if explored else None)
    points = [a.point for a in carried]
    newtons: dict[int, InteriorPointNewton] = {}  # one per mesh: one symbolic analysis
    try:
        chosen = _ascend(
            problems, points, levels, options, options.level_mu, "prolonged", True, newtons,
            carrier,
        )  # fmt: skip
        if chosen is None:
            flat = [carried[0].flat]
            chosen = _ascend(
                problems, flat, levels, options, options.flat_mu, "prolonged flat", False,
                newtons, carrier,
            )  # fmt: skip
    finally:
        for newton in newtons.values():
            newton.destroy()
    return levels, explored, chosen


def _nested(
    problem: UnilateralProblem,
    options: ChainOptions,
    coarser: Sequence[UnilateralProblem] | None = None,
    carrier: CarryFactory = Prolongation,
) -> tuple[list[MeshLevel], list[Candidate], Candidate | None, int]:
    """The route over ``problem``'s coarser copies and itself (:func:`_levels`).

    Returns the levels, the coarsest mesh's KKT points, the fine mesh's critical state
    (or None), and the coarser meshes' eigen solves. The copies are made here and
    destroyed (a plate's) unless the caller gives them (``coarser``, coarsest first,
    carried by ``carrier``; they stay the caller's). Collective.
    """
    problems: list[UnilateralProblem] = []
    made = coarser is None
    if coarser is None:
        for coarse in _coarser(problem, options):
            try:
                problems.append(build_unilateral_problem(coarse, problem.comm))
            except EmptyZoneError:
                continue
    else:
        problems.extend(coarser)
    problems.append(problem)
    try:
        levels, explored, chosen = _levels(problems, options, carrier, cells=not made)
    finally:
        other_solves = sum(p.eigensolver.solves for p in problems[:-1])
        if made:
            for p in problems[:-1]:
                p.destroy()
    return levels, explored, chosen, other_solves


def _fallback(problem: UnilateralProblem, options: ChainOptions) -> UnilateralSolution:
    from unibuckle_fenicsx.algorithms.active_set import solve_active_set

    return solve_active_set(
        problem, max_iterations=options.max_iterations, bound_budget=options.bound_budget
    )


def _descend_to_kkt(
    problem: UnilateralProblem, options: ChainOptions, levels: list[MeshLevel]
) -> Candidate | None:
    """The fine mesh's lowest admissible mode taken to a KKT point, or None.

    The feasible descent (monotone: it cannot cycle), before anything starts afresh.
    Collective.
    """
    if not levels or levels[-1].best_admissible is None:
        return None
    budget = options.descent_budget * options.max_iterations
    final = descend_from(problem, levels[-1].best_admissible, levels[-1], "fallback", budget)
    return final if final.kkt else None


def _fallback_solution(
    problem: UnilateralProblem,
    options: ChainOptions,
    fallback: Callable[[UnilateralProblem], UnilateralSolution] | None,
    levels: list[MeshLevel],
    other_solves: int,
) -> UnilateralSolution:
    """``fallback``'s answer (the active set's by default), as the route's, with its levels.

    Collective.
    """
    note = "interior point: no KKT point on the fine mesh; the active-set chain runs"
    warn_once(logger, problem.comm, note)
    solution = _fallback(problem, options) if fallback is None else fallback(problem)
    if isinstance(solution.details, ActiveSetDetails | SectionLevelsDetails):
        solution.details.interior_point_levels = [lv.record() for lv in levels]
    solution.method = "interior-point"
    solution.route = ["interior-point", *solution.route]
    solution.eigensolves += other_solves
    return solution


def solve_interior_point(
    problem: UnilateralProblem,
    options: ChainOptions | None = None,
    *,
    coarser: Sequence[UnilateralProblem] | None = None,
    carrier: CarryFactory = Prolongation,
    fallback: Callable[[UnilateralProblem], UnilateralSolution] | None = None,
) -> UnilateralSolution:
    """Critical state of ``problem`` (rigid obstacles) by the chain of the module docstring.

    Args:
        problem: A set-up problem with a rigid obstacle.
        options: Settings (default :class:`ChainOptions`).
        coarser: The same problem on coarser meshes, coarsest first (the caller's: not
            destroyed here); None: a plate's copies, made here (:func:`_coarser`).
        carrier: Makes what carries a mode from one mesh to the next finer
            (:class:`Carry`); the plate's
            :class:`~unibuckle_fenicsx.algorithms.multilevel.Prolongation` by default.
        fallback: Solves ``problem`` when the route reaches no KKT point; None: the
            multilevel active set from scratch.

    Returns:
        The critical state with its bracket and the per-mesh records in
        ``details["levels"]``.

    Raises:
        NoAdmissibleModeError: No route produced an admissible mode.

    Note:
        Collective on ``problem.comm``.
    """
    require_obstacle(problem, "solve_interior_point")
    options = options or ChainOptions()
    if problem.tensionless:
        raise InputError(
            "solve_interior_point needs a problem with a rigid obstacle; this one has a "
            "tensionless foundation (obstacle.foundation_stiffness): solve_foundation"
        )
    t0 = time.perf_counter()
    solves0 = problem.eigensolver.solves
    free_load = problem.solve_free().load
    levels, explored, chosen, other_solves = _nested(problem, options, coarser, carrier)
    if chosen is None or not chosen.kkt:
        descended = _descend_to_kkt(problem, options, levels)
        if descended is None:
            return _fallback_solution(problem, options, fallback, levels, other_solves)
        chosen = descended
    closed = bracket(problem, free_load, chosen, options.bound_budget, "interior-point")
    chosen, lower, proven = closed.chosen, closed.lower, closed.proven
    route = ["interior-point"]
    for link in ("active-set polish", "feasible descent"):
        if any(r.link == link and r.kkt for r in levels[-1].links):
            route.append(link.replace(" ", "-"))
    details = InteriorPointDetails(
        free_load=free_load,
        levels=[lv.record() for lv in levels],
        coarse_kkt_loads=sorted(c.load for c in explored),
        fine_eigensolves=problem.eigensolver.solves - solves0,
        coarse_eigensolves=other_solves,
        bound_evaluations=closed.evaluations,
        bound_search_complete=closed.complete,
        wall_time_s=time.perf_counter() - t0,
        warning=closed.warning or UNSET,
    )
    if not math.isfinite(chosen.load):
        raise NoAdmissibleModeError("the interior-point route ended without a finite load")
    return UnilateralSolution(
        candidate=chosen,
        method="interior-point",
        eigensolves=problem.eigensolver.solves - solves0 + other_solves,
        lower_bound=lower,
        global_optimum_proven=proven,
        upper_bound=chosen.load if chosen.feasible else math.inf,
        kkt_points=[chosen],
        details=details,
        route=route,
        lower_bound_by="lattice" if closed.evaluations else "interlacing",
    )
