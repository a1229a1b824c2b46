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
lower of their KKT points is kept (either may end higher than the other).

The seeds are those of :data:`SEEDS`, the plate's others (:data:`MORE_SEEDS`) only if
these reach no KKT point: a core makes every wall move outward, and the contact set is
the walls' nodes save where they lift off, which the free mode's signs seed
(:doc:`/verification/sections`, "Cost").
"""

from __future__ import annotations

import logging
import time
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
from unibuckle_fenicsx.algorithms.pdas import iterate
from unibuckle_fenicsx.algorithms.records import (
    ActiveSetDetails,
    SectionLevel,
    SectionLevelsDetails,
)
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.model.shell.core import CoreConstraints
from unibuckle_fenicsx.model.shell.problem import CoredSectionProblem
from unibuckle_fenicsx.model.shell.section import Section, SectionParameters, build_section
from unibuckle_fenicsx.spec import SolverSpec

__all__ = ["MORE_SEEDS", "SEEDS", "prolong_directions", "solve_levels"]

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
    levels: int = 2,
    comm: MPI.Comm = MPI.COMM_WORLD,
    solver: SolverSpec | None = None,
    max_iterations: int = 100,
) -> tuple[Section, UnilateralSolution]:
    """Unilateral critical state of a section with a core, coarse to fine.

    Args:
        parameters: The section, with ``core = True``.
        levels: Coarser sections (each with twice the mesh size) to seed on, >= 0; 0
            runs the seeds on the section itself.
        comm: Communicator.
        solver: Solver options.
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
    t0 = time.perf_counter()
    sizes = [parameters.mesh_size * 2.0**k for k in range(levels, -1, -1)]
    _check_levels(parameters, levels)
    log: list[SectionLevel] = []
    prev: Section | None = None
    best: UnilateralSolution | None = None
    polish_iterations: int | None = None
    coarse_solves = 0
    for size in sizes:
        try:
            section, polished, polish_iterations, level = _level(
                parameters, size, prev, best, comm, solver, max_iterations
            )
        except BaseException as err:
            if prev is not None:
                prev.destroy()
            if isinstance(err, InputError) and size != sizes[-1]:  # a coarser section's
                raise InputError(
                    f"mesh.levels = {levels}: the coarser section of cells {size:g} m "
                    f"(mesh.size doubled): {err}; lower mesh.levels (0: the seeds run on "
                    "the given cells)"
                ) from None
            raise
        log.append(level)
        if prev is not None:
            coarse_solves += prev.problem.eigensolver.solves
            prev.destroy()
        prev, best = section, polished
    if prev is None or best is None:
        raise RuntimeError("solve_levels: no level ran")
    details = SectionLevelsDetails(
        free_load=prev.problem.solve_free().load,
        levels=log,
        coarse_eigensolves=coarse_solves,
        wall_time_s=time.perf_counter() - t0,
    )
    if polish_iterations is not None:
        details.polish_iterations = polish_iterations
    elif isinstance(best.details, ActiveSetDetails):
        details.active_set = best.details
    return prev, replace(best, details=details)


def _check_levels(parameters: SectionParameters, levels: int) -> None:
    """Refuse ``levels`` whose coarsest section has fewer than 2 cells along the member."""
    most = 0  # the coarsest level SectionParameters accepts
    while parameters.mesh_size * 2.0 ** (most + 1) * (1.0 + 1e-9) < parameters.length:
        most += 1
    if levels > most:
        raise InputError(
            f"mesh.levels = {levels}: the coarsest section's cells, mesh.size x 2^{levels} = "
            f"{parameters.mesh_size * 2.0**levels:g} m, are not below section.length = "
            f"{parameters.length:g} m (at least 2 cells along): mesh.levels <= {most} here"
        )


def _level(
    parameters: SectionParameters,
    size: float,
    prev: Section | None,
    best: UnilateralSolution | None,
    comm: MPI.Comm,
    solver: SolverSpec | None,
    max_iterations: int,
) -> tuple[Section, UnilateralSolution, int | None, SectionLevel]:
    """One level: the section on cells of ``size``, solved from the coarser one's ``best``.

    Returns the section (the caller destroys it), its solution, the polish's iterations
    (None: the seeds ran) and the level's record.
    """
    tl = time.perf_counter()
    corner = parameters.corner_cell
    graded = None if corner is None else corner * size / parameters.mesh_size
    section = build_section(replace(parameters, mesh_size=size, corner_cell=graded), comm, solver)
    problem = section.problem
    if not isinstance(problem, CoredSectionProblem) or section.constraints is None:
        section.destroy()
        raise RuntimeError("solve_levels: a core section without constraints")
    polished, polish_iterations = None, None
    try:
        plain: tuple[UnilateralSolution | None, int | None] = (None, None)
        if prev is not None and best is not None and prev.constraints is not None:
            z = prolong_directions(best.active, prev.constraints, section.constraints)
            polished, polish_iterations = _polish(problem, z, best.load, THRESHOLDS, 0)
            if polished is None:
                budget = min(max_iterations, PLAIN_POLISH_ITERATIONS)
                plain = _polish(problem, z, best.load, (), POLISH_ITERATIONS, budget)
        if polished is None:
            polished = solve_active_set(
                problem,
                multilevel=False,
                max_iterations=max_iterations,
                bound_budget=0,
                seeds=SEEDS,
                more_seeds=MORE_SEEDS,
            )
            kept, plain_iterations = plain
            if kept is not None and kept.load < polished.load:
                solves = problem.eigensolver.solves
                polished, polish_iterations = replace(kept, eigensolves=solves), plain_iterations
    except BaseException:
        section.destroy()
        raise
    details = polished.details
    seeded_steps = (
        sum(r.iterations for r in details.runs) if isinstance(details, ActiveSetDetails) else 0
    )
    level = SectionLevel(
        mesh_size=size,
        dofs=section.model.num_dofs,
        constrained=section.constraints.size,
        load=polished.load,
        kkt=polished.candidate.kkt,
        eigensolves=problem.eigensolver.solves,
        steps=seeded_steps if polish_iterations is None else polish_iterations,
        seeded=polish_iterations is None,
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
    solution = UnilateralSolution(
        candidate=run.final,
        method="active-set (section levels)",
        eigensolves=problem.eigensolver.solves,
        lower_bound=problem.solve_free().load,
        global_optimum_proven=False,
        upper_bound=run.final.load,
        kkt_points=[run.final],
        lower_bound_by="interlacing",
    )
    return solution, iterations
