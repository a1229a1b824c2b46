r"""The unilateral critical state of a section over a hierarchy of meshes.

The package's active-set method (:func:`~unibuckle_fenicsx.algorithms.active_set.solve_active_set`)
runs its seeds on the coarsest section (the mesh size doubled ``levels`` times); each
finer section starts from the coarser level's contact set, carried over by
:func:`prolong_directions`, and the primal-dual iteration
(:func:`~unibuckle_fenicsx.algorithms.pdas.iterate`) polishes it, its eigen solves
shifted just below the expected load. This is the plate's multilevel route
(:mod:`~unibuckle_fenicsx.algorithms.multilevel`) for meshes that are no structured
rectangle; the answer is always a KKT point of the finest section. The polish runs
first with the plate's looser tolerances (:func:`_polish`); if they reach no KKT point,
the plain rule polishes the carried set and the seeds run again on that level, and the
lower of their KKT points is kept (either may end higher than the other). On the given
(finest) section the seeds run after a successful polish too, and the lower KKT point
is kept: a coarser section that ranks its arrangements otherwise carries a contact set
whose polished KKT point can lie well above theirs (a filled tube in bending:
:doc:`/history/2026-11-30e-sections`).

That is the ``"active-set"`` route. The ``"interior-point"`` route (:func:`_interior_point`)
runs the thin plates' nested interior-point chain
(:func:`~unibuckle_fenicsx.algorithms.chain.solve_interior_point`) over the same
sections: barrier Newton from its starts on the coarsest section, the barrier point's
mode carried to each finer section
(:class:`~unibuckle_fenicsx.model.shell.prolong.SectionProlongation`) and restored
there by a few Newton steps, the contact set read on the finest and its exact
eigenpair checked against the KKT conditions. Near where a wall lifts off the core the
mode's tails make the active set's steps flip directions a few at a time, more the finer
the mesh; the barrier moves them all at once. If it reaches no KKT point, the active-set
route runs on the sections it built (the finest and the coarser ones the active set
starts on: assembled, prestressed and their free modes solved once). Where the
``levels`` asked make the chain start on a section of fewer than :data:`COARSEST_DOFS`,
its starts run once more on the coarsest section of at least that many (or the given
one), and the lower KKT point is kept (:func:`_starts_coarse_enough`): so coarse a
section can merge arrangements that the finer ones tell apart.

Which route runs is decided with the plate's method, in one place
(:func:`~.registry.choose_section_method`, ``"auto"``: the interior
point on sections of at least :data:`INTERIOR_POINT_DOFS` degrees of freedom; on
smaller ones both routes (:data:`BOTH`), the active set on the sections the interior
point built, and the lower KKT point is kept: both are KKT points, neither is proven
the lowest, and either can end above the other); :func:`solve_levels` runs the route
it is given, and each route is an entry of
:data:`~unibuckle_fenicsx.algorithms.registry.REGISTRY` (:data:`BOTH` is one of its own).

The seeds are those of :data:`SEEDS`, the plate's others (:data:`MORE_SEEDS`) only if
these reach no KKT point: a core makes every wall move outward, and the contact set is
the walls' nodes save where they lift off, which the free mode's signs seed
(:doc:`/verification/sections`, "Cost").
"""

from __future__ import annotations

import itertools
import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import replace

from mpi4py import MPI

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms import RunStatus, UnilateralSolution
from unibuckle_fenicsx.algorithms.active_set import (
    POLISH_ITERATIONS,
    SEED_NAMES,
    THRESHOLDS,
    solve_active_set,
)
from unibuckle_fenicsx.algorithms.bounds import bracket
from unibuckle_fenicsx.algorithms.chain import ChainOptions, solve_interior_point
from unibuckle_fenicsx.algorithms.pdas import iterate
from unibuckle_fenicsx.algorithms.records import (
    ActiveSetDetails,
    InteriorPointDetails,
    SectionLevel,
    SectionLevelsDetails,
)
from unibuckle_fenicsx.errors import InputError, NoKKTPointError
from unibuckle_fenicsx.model.problem import UnilateralProblem
from unibuckle_fenicsx.model.shell.core import CoreConstraints
from unibuckle_fenicsx.model.shell.geometry import grid_nodes
from unibuckle_fenicsx.model.shell.model import DOFS_PER_NODE
from unibuckle_fenicsx.model.shell.problem import CoredSectionProblem
from unibuckle_fenicsx.model.shell.prolong import SectionProlongation
from unibuckle_fenicsx.model.shell.section import Section, SectionParameters, build_section
from unibuckle_fenicsx.spec import SolverSpec
from unibuckle_fenicsx.spec.base import in_file
from unibuckle_fenicsx.spec.section import check_levels, most_levels

__all__ = [
    "BOTH",
    "CHAIN_OPTIONS",
    "CHECKED",
    "CHECK_SEEDS_DOFS",
    "COARSEST_DOFS",
    "INTERIOR_POINT_DOFS",
    "MORE_SEEDS",
    "ROUTES",
    "SEEDS",
    "estimated_dofs",
    "interior_levels",
    "prolong_directions",
    "solve_levels",
]

logger = logging.getLogger(__name__)

#: The active set's seeds on a section (of
#: :data:`~unibuckle_fenicsx.algorithms.active_set.SEED_NAMES`): the free mode's two
#: sign patterns. With a core the contact set is most of the walls, and where they lift
#: off the free mode's signs seed; the plate's other seeds (every direction in contact,
#: windows along the long side, the greedy ones) run only when neither of these reaches
#: a KKT point (:data:`MORE_SEEDS`): they cost most of the solves and found no lower KKT
#: point on the sections of :doc:`/verification/sections` ("Cost").
SEEDS = ("free+", "free-")
#: The plate's other seeds, in their order: run when :data:`SEEDS` reach no KKT point.
MORE_SEEDS = tuple(name for name in SEED_NAMES if name not in SEEDS)
#: Steps of the plain rule when the polish at looser tolerances reached no KKT point
#: (:func:`_polish`); the seeds run on the finer section too, and the lower KKT point wins.
PLAIN_POLISH_ITERATIONS = 50
#: On the given section a polished carried set's KKT point is kept over the seeds' unless
#: theirs is lower by more than this relative load (the same point reached twice agrees
#: to about 1e-13): the method and records stay the polish's.
SAME_LOAD = 1e-9
#: The route of ``"auto"`` on sections below :data:`INTERIOR_POINT_DOFS`: both routes on
#: the same sections, the lower KKT point kept (module docstring); a registry entry of
#: its own, with a section runner only.
BOTH = "both"
#: The route of ``"auto"`` on sections of :data:`INTERIOR_POINT_DOFS` and more: the
#: interior point, then the active set's seeds on its coarsest section only; where they
#: reach a KKT point below the chain's there, their contact set is carried to each finer
#: section and polished (no seeds above the coarsest), and the lower KKT point on the
#: given section is kept (:func:`_seeds_carried`). A registry entry of its own.
CHECKED = "interior-point+seeds"
#: On the route :data:`CHECKED`, the seeds run again on a finer section whose carried set
#: polishes to no KKT point only below this many DOFs: there they cost a few times the
#: interior point's route; above, the active set's route is out of reach
#: (:doc:`/verification/sections`, "Cost", holds both) and the chain's KKT
#: point stands.
CHECK_SEEDS_DOFS = 20_000
#: The routes of :func:`solve_levels` (module docstring).
ROUTES = ("interior-point", "active-set", BOTH, CHECKED)
#: "auto" takes the interior point alone on sections of at least this many DOFs
#: (estimated from the cell size: six per node), and both routes on smaller ones
#: (:data:`BOTH`): there the active set's eigen solves on small pencils cost about what
#: the interior point's starts on the coarsest section do, and either route ended at a
#: lower KKT point than the other on some sections (:doc:`/verification/sections`, "Cost").
INTERIOR_POINT_DOFS = 10_000
#: The interior point's settings on sections: only the lowest arrangement of the coarsest
#: section is carried up (``arrangements = 1``). On every section of
#: :doc:`/verification/sections` it gave the lowest KKT point on the finest, and each
#: further arrangement costs a whole run of Newton steps on the finest section. Where a
#: read of the gaps is no KKT point, the predicted contact set is read too
#: (``read_predicted``): where a wall lies almost flat on the core its gaps stay above
#: the tolerance, and only the predicted set holds them
#: (:doc:`/verification/sections_finest`). The release of the nodes that pull at a read
#: (``release_steps``, :doc:`/verification/fine_level_release`) is off here: on sections
#: it saved next to nothing (:doc:`/verification/sections_full_cost`).
CHAIN_OPTIONS = ChainOptions(arrangements=1, read_predicted=True, release_steps=0)
#: The interior point starts on a section at least this coarse: the cell size doubled
#: while the coarser section keeps this many DOFs (more if ``levels`` asks). The
#: starts take a few hundred Newton steps there; on the sections of
#: :doc:`/verification/sections` ("Cost") a coarsest section of 1 000 to 2 500 DOFs
#: ranked their arrangements as the finest did. Where ``levels`` makes the chain start
#: on a coarser one, the starts run on such a section too (:func:`_starts_coarse_enough`).
COARSEST_DOFS = 1_000


def prolong_directions(
    active: npt.NDArray[np.int64], coarse: CoreConstraints, fine: CoreConstraints
) -> npt.NDArray[np.int64]:
    """The contact set ``active`` of a coarse section on a finer section's directions.

    Each fine direction takes the status of the nearest coarse direction with the same
    normal (unrolled coordinates x, s): in contact when that one is. Written by hand
    (a nearest-neighbour search per normal): the meshes need not be nested.
    """
    from scipy.spatial import cKDTree

    mask = np.zeros(coarse.size, dtype=bool)
    mask[active] = True
    out = np.zeros(fine.size, dtype=bool)
    # Group directions by their normal (faces of a box; a tube's normals all differ,
    # so there the group is by the normal's angle: nearest in (x, s) alone).
    key_c = np.round(coarse.normals, 6)
    key_f = np.round(fine.normals, 6)
    if np.unique(key_f, axis=0).shape[0] > 8:  # a curved wall: one group
        key_c = np.zeros_like(key_c)
        key_f = np.zeros_like(key_f)
    for key in np.unique(key_f, axis=0):
        cf = np.flatnonzero(np.all(key_f == key, axis=1))
        cc = np.flatnonzero(np.all(key_c == key, axis=1))
        if not cc.size:
            continue
        tree = cKDTree(coarse.unrolled[cc])
        _, nearest = tree.query(fine.unrolled[cf])
        out[cf] = mask[cc[nearest]]
    return np.flatnonzero(out).astype(np.int64)


def solve_levels(
    parameters: SectionParameters,
    *,
    route: str,
    levels: int = 2,
    comm: MPI.Comm = MPI.COMM_WORLD,
    solver: SolverSpec | None = None,
    max_iterations: int = 100,
) -> tuple[Section, UnilateralSolution]:
    """Unilateral critical state of a section with a core, coarse to fine.

    Args:
        parameters: The section, with ``core = True``.
        levels: Coarser sections (each with twice the mesh size) to start on, >= 0; 0
            runs on the section itself. The interior point takes more while the
            coarsest keeps :data:`COARSEST_DOFS`.
        comm: Communicator.
        solver: Solver options.
        route: One of :data:`ROUTES` (module docstring): "interior-point" (the active
            set on its sections if it reaches no KKT point) or "active-set";
            :func:`~.registry.choose_section_method` chooses it for
            :func:`~unibuckle_fenicsx.section_analysis.solve_section`.
        max_iterations: Iterates per seed on the coarsest level, >= 1.

    Returns:
        The finest section (the caller destroys it) and the solution on it.

    Note:
        Collective on ``comm``.
    """
    if not parameters.core:
        raise InputError("solve_levels needs a section with core = true")
    if int(levels) != levels or levels < 0:
        raise InputError(f"levels must be an integer >= 0, got {levels!r}")
    if route not in ROUTES:
        raise InputError(f"route must be one of {ROUTES}, got {route!r}")
    check_levels(parameters.mesh_size, parameters.length, levels)
    if route in ("interior-point", BOTH, CHECKED):
        more = interior_levels(parameters, levels)
        return _interior_point(parameters, more, comm, solver, levels, max_iterations, route=route)
    return _active_set(parameters, levels, comm, solver, max_iterations)


def estimated_dofs(parameters: SectionParameters) -> int:
    """The section's DOFs before it is meshed: six per node of its (x, s) grid."""
    p = parameters
    across = (p.diameter, p.diameter) if p.shape == "tube" else (p.width, p.depth)
    widths = (float(across[0] or 0.0), float(across[1] or 0.0))
    around, along = grid_nodes(p.shape, widths, p.length, p.mesh_size, p.corner_cell)
    return DOFS_PER_NODE * around * along


def interior_levels(parameters: SectionParameters, levels: int) -> int:
    """The interior point's coarser sections: ``levels``, or more.

    More while the coarsest keeps :data:`COARSEST_DOFS` (estimated: :func:`estimated_dofs`).
    """
    k, most = 0, most_levels(parameters.mesh_size, parameters.length)
    while k < most and estimated_dofs(_at(parameters, 2.0 ** (k + 1))) >= COARSEST_DOFS:
        k += 1
    return max(levels, k)


def _sizes(parameters: SectionParameters, levels: int) -> list[float]:
    """The sections' cell sizes, coarsest first."""
    return [parameters.mesh_size * 2.0**k for k in range(levels, -1, -1)]


def _build(
    parameters: SectionParameters, size: float, comm: MPI.Comm, solver: SolverSpec | None
) -> Section:
    """The section on cells of ``size`` (a box's corner cells graded in proportion)."""
    return build_section(_at(parameters, size / parameters.mesh_size), comm, solver)


def _at(parameters: SectionParameters, factor: float) -> SectionParameters:
    """``parameters`` with cells ``factor`` times as large (corner cells too)."""
    corner = parameters.corner_cell
    return replace(
        parameters,
        mesh_size=parameters.mesh_size * factor,
        corner_cell=None if corner is None else corner * factor,
    )


def _interior_point(
    parameters: SectionParameters,
    levels: int,
    comm: MPI.Comm,
    solver: SolverSpec | None,
    asked: int,
    max_iterations: int,
    route: str = "interior-point",
) -> tuple[Section, UnilateralSolution]:
    """The nested interior-point chain over the sections (module docstring).

    ``levels``: the coarser sections (:func:`interior_levels`), ``asked`` of them the
    caller's: a coarser section that cannot be built (its core covers no free node) ends
    the added ones, and is refused among the asked ones. If the chain reaches no KKT
    point, the active-set route (``max_iterations`` per seed) runs on the finest section
    and the ``asked`` coarser ones, as built here. ``route`` :data:`BOTH`: the
    active-set route runs on them after a KKT point of the chain too, and the lower KKT
    point is kept (the chain's where they agree to :data:`SAME_LOAD`); :data:`CHECKED`:
    the active set's seeds on the coarsest section and their contact set carried up
    (:func:`_seeds_carried`), the lower kept likewise. The solution's
    ``eigensolves`` counts every eigen solve on every section but the finest's free solve
    (the result adds that one).
    """
    fell_back = False
    penalty = 0  # the active set's penalty continuations (their own eigen solvers)

    def active_set(problem: UnilateralProblem) -> UnilateralSolution:
        nonlocal fell_back, penalty
        fell_back = True
        _, solution = _active_set(
            parameters, asked, comm, solver, max_iterations, built=sections[-(asked + 1) :]
        )
        if isinstance(solution.details, SectionLevelsDetails):
            penalty += sum(level.penalty_eigensolves for level in solution.details.levels)
        return solution

    sections: list[Section] = []
    try:
        _build_all(parameters, levels, asked, comm, solver, sections)
        problems = [section.cored for section in sections]
        solution = _chain(sections, active_set)
        if route == BOTH and not fell_back:
            solution = _lower(solution, active_set(problems[-1]))
        elif route == CHECKED and not fell_back:
            carried, seeds_penalty = _seeds_carried(sections, solution, max_iterations)
            penalty += seeds_penalty
            if carried is not None:
                solution = _lower(solution, carried)
        solution = _starts_coarse_enough(sections, solution)
        # Every section's solves, the chain's, the active set's and its penalty
        # continuations' (the finest's free solve is the result's own).
        total = sum(p.eigensolver.solves for p in problems) - problems[-1].free_solves + penalty
        solution = replace(solution, eigensolves=total)
    except BaseException:
        for section in sections:
            section.destroy()
        raise
    for section in sections[:-1]:
        section.destroy()
    return sections[-1], solution


def _build_all(
    parameters: SectionParameters,
    levels: int,
    asked: int,
    comm: MPI.Comm,
    solver: SolverSpec | None,
    sections: list[Section],
) -> None:
    """Build the interior point's sections into ``sections``, coarsest first.

    The finest first; a coarser section that cannot be built ends the ones
    :func:`interior_levels` added, and is refused among the ``asked`` ones. The caller
    destroys ``sections`` (those built before an error too).
    """
    for k, size in enumerate(_sizes(parameters, levels)[::-1]):  # finest first
        try:
            sections.insert(0, _build(parameters, size, comm, solver))
        except InputError as err:
            if k == 0:  # the given cells' own error
                raise
            if k > asked:  # a level added by interior_levels: fewer of them
                break
            cells, unit = in_file(size, "m")
            raise InputError(
                f"mesh.levels = {asked}: the coarser section of cells {cells:g} {unit} "
                f"(mesh.size doubled): {err}; lower mesh.levels (0: the search starts "
                "on the given cells)"
            ) from None


def _seeds_carried(
    sections: Sequence[Section], chain: UnilateralSolution, max_iterations: int
) -> tuple[UnilateralSolution | None, int]:
    """The active set's seeds on the coarsest section, carried up: a check of the chain.

    The interior point's starts settle in one arrangement of the lift-off on the
    coarsest section, and it is carried up; the active set's seeds (:data:`SEEDS`, the
    free mode's sign patterns) can reach another, lower one (:doc:`/verification/sections`,
    "Cost"). They run on ``sections[0]`` (``max_iterations`` each, as a check: where they
    stall, no fallback runs, and the chain's answer stands); where their KKT point
    lies below the chain's lowest there by more than :data:`SAME_LOAD`, their contact set
    is carried to each finer section and polished (:func:`_polish`, the looser
    tolerances, then the plain rule), and where neither reaches a KKT point the seeds run
    on that section (as on the active-set route) if it has fewer than
    :data:`CHECK_SEEDS_DOFS`: the lower arrangement the seeds found may polish into no
    KKT point on a finer section, and the seeds there find it. With
    one section the seeds' KKT point is the candidate itself. Returns the candidate on
    the finest section as a solution of the chain's record (None: the seeds found no
    lower KKT point, or no KKT point on a finer section) and the seeds' penalty
    continuations' eigen solves. Collective.
    """
    coarse = sections[0].cored
    seeded = solve_active_set(
        coarse,
        multilevel=False,
        max_iterations=max_iterations,
        bound_budget=0,
        seeds=SEEDS,
        check=True,
    )
    penalty = 0
    if isinstance(seeded.details, ActiveSetDetails):
        penalty = seeded.details.penalty_eigensolves
    if not seeded.candidate.kkt:
        return None, penalty
    best = seeded
    logger.info("section: the seeds on the coarsest section %.10g (KKT)", seeded.load)
    if len(sections) > 1:
        details = chain.details
        loads = details.coarse_kkt_loads if isinstance(details, InteriorPointDetails) else []
        if loads and seeded.load >= min(loads) * (1.0 - SAME_LOAD):
            return None, penalty  # the chain's arrangement there is as low
        for prev, section in itertools.pairwise(sections):
            if prev.constraints is None or section.constraints is None:
                raise RuntimeError("solve_levels: a core section without constraints")
            z = prolong_directions(best.active, prev.constraints, section.constraints)
            polished, _ = _polish(section.cored, z, best.load, THRESHOLDS, 0)
            if polished is None:
                budget = min(max_iterations, PLAIN_POLISH_ITERATIONS)
                polished, _ = _polish(section.cored, z, best.load, (), POLISH_ITERATIONS, budget)
            logger.info(
                "section: the seeds' contact set carried and polished: %s",
                "no KKT point" if polished is None else f"{polished.load:.10g}",
            )
            if polished is None and section.model.num_dofs >= CHECK_SEEDS_DOFS:
                return None, penalty  # the seeds' cost there is the active set's route's
            if polished is None:  # as the active-set route does: the seeds on this section
                polished = solve_active_set(
                    section.cored, multilevel=False, max_iterations=max_iterations,
                    bound_budget=0, seeds=SEEDS, check=True,
                )  # fmt: skip
                if isinstance(polished.details, ActiveSetDetails):
                    penalty += polished.details.penalty_eigensolves
                logger.info("section: the seeds on it %.10g", polished.load)
                if not polished.candidate.kkt:
                    return None, penalty
            best = polished
    found = replace(
        chain,
        candidate=best.candidate,
        method="active-set (section levels)",
        route=[*chain.route, "active-set"],
        kkt_points=[best.candidate, chain.candidate],
        lower_bound=best.lower_bound,
        global_optimum_proven=best.global_optimum_proven,
        upper_bound=best.load,
        lower_bound_by=best.lower_bound_by,
    )
    return found, penalty


def _starts_coarse_enough(
    sections: Sequence[Section], solution: UnilateralSolution
) -> UnilateralSolution:
    """The chain's starts again on the coarsest section of :data:`COARSEST_DOFS` or more.

    The ``levels`` asked may make the chain start on a section of fewer DOFs than
    :data:`COARSEST_DOFS`, where the starts merge arrangements the finer sections tell
    apart: a rectangular filled box's coarser section (2 cells across its narrower face)
    gave one KKT point, carried up to a higher one than the starts on the given section
    reach (:doc:`/history/2026-12-01a-coreroute`). There the chain runs once more from
    the first section (coarsest first) of at least :data:`COARSEST_DOFS`, or the given
    one, and its KKT point is kept where it is lower than ``solution``'s by more than
    :data:`SAME_LOAD`. ``solution`` is returned otherwise, also when that chain reaches
    no KKT point (no fallback runs for it). Collective.
    """
    dofs = [section.model.num_dofs for section in sections]
    first = next((k for k, n in enumerate(dofs) if n >= COARSEST_DOFS), len(sections) - 1)
    if first == 0:  # the chain started there
        return solution

    def no_fallback(_: UnilateralProblem) -> UnilateralSolution:
        raise NoKKTPointError

    try:
        again = _chain(sections[first:], no_fallback)
    except NoKKTPointError:
        logger.info("section: the starts on %d DOFs reach no KKT point", dofs[first])
        return solution
    logger.info(
        "section: the starts on %d DOFs %.10g (KKT %s), the route's %.10g: the lower kept",
        dofs[first], again.load, again.candidate.kkt, solution.load,
    )  # fmt: skip
    lower = not solution.candidate.kkt or again.load < solution.load * (1.0 - SAME_LOAD)
    return again if again.candidate.kkt and lower else solution


def _chain(
    sections: Sequence[Section], fallback: Callable[[UnilateralProblem], UnilateralSolution]
) -> UnilateralSolution:
    """The interior point's chain from ``sections[0]`` to ``sections[-1]`` (coarsest first).

    ``fallback`` solves the finest when the chain reaches no KKT point. Collective.
    """
    problems = [section.cored for section in sections]
    solution = solve_interior_point(
        problems[-1],
        CHAIN_OPTIONS,
        coarser=problems[:-1],
        carrier=SectionProlongation,
        fallback=fallback,
    )
    solution.method = "interior-point (section levels)"
    return solution


def _lower(chain: UnilateralSolution, other: UnilateralSolution) -> UnilateralSolution:
    """The lower of two KKT points of the same section: the chain's unless ``other`` is lower.

    ``other`` (the active-set route's) is kept only when it is a KKT point below the
    chain's by more than :data:`SAME_LOAD` (the same point reached twice agrees to
    about 1e-13).
    """
    logger.info(
        "section: interior point %.10g, active set %.10g (KKT %s): the lower kept",
        chain.load, other.load, other.candidate.kkt,
    )  # fmt: skip
    if other.candidate.kkt and other.load < chain.load * (1.0 - SAME_LOAD):
        return other
    return chain


def _active_set(
    parameters: SectionParameters,
    levels: int,
    comm: MPI.Comm,
    solver: SolverSpec | None,
    max_iterations: int,
    built: Sequence[Section] = (),
) -> tuple[Section, UnilateralSolution]:
    """The active-set route (module docstring).

    ``built``: the ``levels + 1`` sections, coarsest first, built already (the interior
    point's, which stay the caller's); empty: each built here, and destroyed once the
    next finer one is solved.
    """
    t0 = time.perf_counter()
    sizes = _sizes(parameters, levels)
    log: list[SectionLevel] = []
    prev: Section | None = None
    best: UnilateralSolution | None = None
    polish_iterations: int | None = None
    for k, size in enumerate(sizes):
        try:
            section, polished, polish_iterations, level = _level(
                parameters, size, prev, best, comm, solver, max_iterations,
                built[k] if built else None, finest=k == len(sizes) - 1,
            )  # fmt: skip
        except BaseException as err:
            if prev is not None and not built:
                prev.destroy()
            if isinstance(err, InputError) and size != sizes[-1]:  # a coarser section's
                cells, unit = in_file(size, "m")
                raise InputError(
                    f"mesh.levels = {levels}: the coarser section of cells {cells:g} {unit} "
                    f"(mesh.size doubled): {err}; lower mesh.levels (0: the seeds run on "
                    "the given cells)"
                ) from None
            raise
        log.append(level)
        if prev is not None and not built:
            prev.destroy()
        prev, best = section, polished
    if prev is None or best is None:
        raise RuntimeError("solve_levels: no level ran")
    details = SectionLevelsDetails(
        free_load=prev.problem.solve_free().load,
        levels=log,
        coarse_eigensolves=sum(level.eigensolves for level in log[:-1]),
        wall_time_s=time.perf_counter() - t0,
    )
    if polish_iterations is not None:
        details.polish_iterations = polish_iterations
    elif isinstance(best.details, ActiveSetDetails):
        details.active_set = best.details
    # Every level's solves, the polish's and the seeds' (kept or not); the finest's free
    # solve is the result's own.
    total = sum(level.eigensolves for level in log) - prev.problem.free_solves
    return prev, replace(best, details=details, eigensolves=total)


def _level(
    parameters: SectionParameters,
    size: float,
    prev: Section | None,
    best: UnilateralSolution | None,
    comm: MPI.Comm,
    solver: SolverSpec | None,
    max_iterations: int,
    built: Section | None = None,
    finest: bool = False,
) -> tuple[Section, UnilateralSolution, int | None, SectionLevel]:
    """One level: the section on cells of ``size``, solved from the coarser one's ``best``.

    ``built``: that section, built already (the caller's); None: built here. ``finest``:
    the given section, where the seeds run after a polish too and the lower KKT point is
    kept. Returns the section (the caller destroys it), its solution, the polish's
    iterations (None: the seeds' KKT point was kept) and the level's record (its eigen
    solves: this level's own).
    """
    tl = time.perf_counter()
    section = _build(parameters, size, comm, solver) if built is None else built
    problem = section.problem
    if not isinstance(problem, CoredSectionProblem) or section.constraints is None:
        if built is None:
            section.destroy()
        raise RuntimeError("solve_levels: a core section without constraints")
    solves0 = problem.eigensolver.solves
    polished, polish_iterations, seeded_steps = None, None, None
    penalty = 0  # the seeds' penalty continuation has its own eigen solver
    try:
        plain: tuple[UnilateralSolution | None, int | None] = (None, None)
        if prev is not None and best is not None and prev.constraints is not None:
            z = prolong_directions(best.active, prev.constraints, section.constraints)
            polished, polish_iterations = _polish(problem, z, best.load, THRESHOLDS, 0)
            if polished is None:
                budget = min(max_iterations, PLAIN_POLISH_ITERATIONS)
                plain = _polish(problem, z, best.load, (), POLISH_ITERATIONS, budget)
        # On the given section the seeds run even where the carried set polished: the
        # coarser section may rank its arrangements otherwise, and the carried set's KKT
        # point be a higher one than theirs (module docstring).
        carried = polished if finest else None
        if polished is None or carried is not None:
            seeded = solve_active_set(
                problem,
                multilevel=False,
                max_iterations=max_iterations,
                bound_budget=0,
                seeds=SEEDS,
                more_seeds=MORE_SEEDS,
            )
            runs, penalty = [], 0
            if isinstance(seeded.details, ActiveSetDetails):
                runs, penalty = seeded.details.runs, seeded.details.penalty_eigensolves
            seeded_steps = sum(r.iterations for r in runs)
            solves = problem.eigensolver.solves
            kept, plain_iterations = plain
            if carried is not None and carried.load <= seeded.load * (1.0 + SAME_LOAD):
                polished = replace(carried, eigensolves=solves)
            elif kept is not None and kept.load < seeded.load:
                polished, polish_iterations = replace(kept, eigensolves=solves), plain_iterations
            else:
                polished, polish_iterations = seeded, None
    except BaseException:
        if built is None:
            section.destroy()
        raise
    level = SectionLevel(
        mesh_size=size,
        dofs=section.model.num_dofs,
        constrained=section.constraints.size,
        load=polished.load,
        kkt=polished.candidate.kkt,
        eigensolves=problem.eigensolver.solves - solves0 + penalty,
        penalty_eigensolves=penalty,
        steps=(polish_iterations or 0) + (seeded_steps or 0),
        seeded=seeded_steps is not None,
        wall_time_s=time.perf_counter() - tl,
    )
    return section, polished, polish_iterations, level


def _polish(
    problem: CoredSectionProblem,
    z: npt.NDArray[np.int64],
    estimate: float,
    thresholds: tuple[float, ...],
    before: int,
    budget: int = POLISH_ITERATIONS,
) -> tuple[UnilateralSolution | None, int | None]:
    """The active set from the contact set ``z`` carried from the coarser section.

    Returns the solution and its iterations (``before`` of an earlier polish included)
    when they reach a KKT point, else (None, None). ``estimate``: the coarser section's
    load (the eigen solves shift near it). ``thresholds``: the looser tolerances
    (:data:`THRESHOLDS`: on thin walls the mode's tails flip sign from one contact set
    to the next, as on thin plates), or none (the plain rule at ``tau``); ``budget``:
    the steps allowed.
    """
    run = iterate(problem, "prolonged", z, None, budget, thresholds=thresholds, near=estimate)
    if run.status is not RunStatus.KKT or run.final is None:
        return None, None
    iterations = before + run.iterations
    # Interlacing closes the bracket when the load is the free one (the free mode
    # admissible: |Z| = 0), as the active set's own bracket says (no lattice search).
    closed = bracket(problem, problem.solve_free().load, run.final, 0, "active-set")
    solution = UnilateralSolution(
        candidate=run.final,
        method="active-set (section levels)",
        eigensolves=problem.eigensolver.solves,
        lower_bound=closed.lower,
        global_optimum_proven=closed.proven,
        upper_bound=run.final.load,
        kkt_points=[run.final],
        lower_bound_by="interlacing",
    )
    return solution, iterations
