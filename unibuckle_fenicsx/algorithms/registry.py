"""Each unilateral method once: what runs it, the options it reads, the links it may take.

:class:`~unibuckle_fenicsx.spec.Method` names the methods a problem file and the command
line may choose, and :data:`~unibuckle_fenicsx.spec.OPTIONS` gives each its options
Struct, the ``[solver]`` keys it reads: the schema's choices, the command line's
``--method`` choices and the flags that apply to each method are made from them (the
command line reads them there, so that building its parser imports no PETSc).
:data:`REGISTRY` adds what the problem's description cannot hold without importing the
algorithms: the function that runs each method on a
:class:`~unibuckle_fenicsx.model.problem.UnilateralProblem`, and the links its route may
take (a result's ``route`` starts with the method and takes only those).
:func:`unibuckle_fenicsx.analysis.solve` runs a plate's method through it
(:meth:`MethodEntry.solve`). An entry that runs on a box or tube with a core has a
``section`` runner: it builds the section (with its coarser sections) from its
parameters and solves it; :func:`unibuckle_fenicsx.section_analysis.solve_section` runs
it (:meth:`MethodEntry.solve_section`). An entry without one of the two refuses that
kind of problem, naming ``solver.method``.

The method of every unilateral problem is decided here, once: "auto" chooses among the
entries (:func:`choose_method` for a plate, once its mesh is built and its free eigen
solve timed; :func:`choose_section_method` for a section, before any mesh), each
returning a key of :data:`REGISTRY` and the reason a result records as
``method_chosen_by``; "auto" runs nothing of its own. Two entries are chosen, never
named in a file, and are no :class:`~unibuckle_fenicsx.spec.Method`: a tensionless
foundation's spring-set iteration (:data:`FOUNDATION`, chosen by the problem) and, on a
section of fewer than
:data:`~unibuckle_fenicsx.algorithms.section_levels.INTERIOR_POINT_DOFS` degrees of
freedom, "auto"'s route :data:`~unibuckle_fenicsx.algorithms.section_levels.BOTH` (the
interior point and the active set on the same sections, the lower KKT point kept), and
on larger ones :data:`~unibuckle_fenicsx.algorithms.section_levels.CHECKED` (the interior
point, checked by the active set's seeds on its coarsest section), which have a section
runner only.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

from mpi4py import MPI

import msgspec
import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms import UnilateralSolution, candidate_count
from unibuckle_fenicsx.algorithms.active_set import solve_active_set
from unibuckle_fenicsx.algorithms.chain import THIN_PLATE, solve_interior_point, thin_plate
from unibuckle_fenicsx.algorithms.enumeration import enumerate_contact_sets
from unibuckle_fenicsx.algorithms.foundation import solve_foundation
from unibuckle_fenicsx.algorithms.interior_point.options import ChainOptions
from unibuckle_fenicsx.algorithms.penalty import solve_penalty
from unibuckle_fenicsx.algorithms.section_levels import (
    BOTH,
    CHECKED,
    INTERIOR_POINT_DOFS,
    estimated_dofs,
    prolong_directions,
    solve_levels,
)
from unibuckle_fenicsx.errors import FieldError, InputError
from unibuckle_fenicsx.model.problem import UnilateralProblem
from unibuckle_fenicsx.model.shell.section import Section, SectionParameters, build_section
from unibuckle_fenicsx.spec import OPTIONS, FoundationOptions, Method, ProblemSpec, SolverSpec
from unibuckle_fenicsx.spec.base import Table
from unibuckle_fenicsx.spec.section import check_section_method, most_levels
from unibuckle_fenicsx.spec.solver import (
    ActiveSetOptions,
    EnumerateOptions,
    InteriorPointOptions,
    PenaltyOptions,
)

__all__ = [
    "FOUNDATION",
    "FREE",
    "REGISTRY",
    "MethodEntry",
    "PlateContext",
    "PlateRun",
    "RigidStart",
    "SectionRun",
    "choose_method",
    "choose_section_method",
    "entry",
    "method_without_enumeration",
]

#: The name of a tensionless foundation's spring-set iteration (a result's ``method``).
FOUNDATION = "foundation"
#: The "method" of a problem without obstacle (a section without core): its free load.
FREE = "free"

#: Gives the rigid obstacle's contact set on a tensionless foundation's contact nodes and
#: the eigen solves it took: the start of :func:`.foundation.solve_foundation` from it.
RigidStart = Callable[[], tuple[npt.NDArray[np.int64], int]]


@dataclass(frozen=True)
class PlateContext:
    """What a plate's run takes besides its problem and options.

    Attributes:
        candidate_comm: The communicator over which the enumeration splits its candidate
            sets (None: each rank holds a part of the mesh; the other methods take None
            only).
        rigid_start: A tensionless foundation's start from the rigid obstacle
            (:data:`RigidStart`; None: :func:`.foundation.solve_foundation`'s own). The
            caller that can solve the rigid twin as a whole problem passes it
            (:func:`unibuckle_fenicsx.analysis.solve`).
    """

    candidate_comm: MPI.Comm | None = None
    rigid_start: RigidStart | None = None


#: Runs a method on a plate's problem: the problem, the method's options and the
#: :class:`PlateContext` in, the solution out. Collective.
PlateRun = Callable[[UnilateralProblem, Any, PlateContext], UnilateralSolution]

#: Runs a method on a section with a core: its parameters, its coarser sections (``mesh.levels``,
#: >= 0), the communicator and the ``[solver]`` table in; the finest section (the caller
#: destroys it) and the solution on it out. Collective.
SectionRun = Callable[
    [SectionParameters, int, MPI.Comm, SolverSpec], tuple[Section, UnilateralSolution]
]


@dataclass(frozen=True)
class MethodEntry:
    """One method of the registry.

    Attributes:
        name: The method's name: a :class:`Method` value, :data:`FOUNDATION` or
            :data:`~unibuckle_fenicsx.algorithms.section_levels.BOTH` (the name a choice
            returns; a result's ``method`` is that of the route that answered).
        options: Its options Struct: the ``[solver]`` keys it reads, with their defaults.
        run: Runs it on a plate with those options (:data:`PlateRun`); None: it runs on
            sections only.
        links: The links a plate's route may take (the first is the method itself, with
            which every such route starts).
        section: Runs it on a box or tube with a core (:data:`SectionRun`); None: it runs
            on plates only.
    """

    name: str
    options: type[Table]
    run: PlateRun | None
    links: tuple[str, ...]
    section: SectionRun | None = None

    def options_of(self, solver: SolverSpec) -> Any:
        """This method's options as ``solver`` (the problem's ``[solver]``) sets them."""
        return msgspec.convert(solver, self.options, from_attributes=True)

    def solve(
        self, problem: UnilateralProblem, context: PlateContext | None = None
    ) -> UnilateralSolution:
        """Run this method on ``problem`` with the options of its ``[solver]`` table.

        ``context`` (:class:`PlateContext`) gives the enumeration's candidate
        communicator and a foundation's rigid start; None: neither.

        Raises:
            FieldError: This entry runs on sections only (naming ``solver.method``).

        Note:
            Collective on ``problem``'s communicator.
        """
        if self.run is None:
            raise FieldError("", "solver.method", self._refusal("a plate", "run"))
        return self.run(problem, self.options_of(problem.spec.solver), context or PlateContext())

    def _refusal(self, what: str, runner: str) -> str:
        """A :class:`FieldError`'s text at ``solver.method``: no ``runner`` for ``what``."""
        runs = [name for name, e in REGISTRY.items() if getattr(e, runner) is not None]
        return f" = {str(self.name)!r} does not run on {what}: {', '.join(runs)} do"

    def solve_section(
        self, parameters: SectionParameters, levels: int, comm: MPI.Comm, solver: SolverSpec
    ) -> tuple[Section, UnilateralSolution]:
        """Run this method on the section ``parameters`` with a core (:data:`SectionRun`).

        Returns:
            The finest section (the caller destroys it) and the solution on it.

        Raises:
            FieldError: This entry runs on plates only (naming ``solver.method``).

        Note:
            Collective on ``comm``.
        """
        if self.section is None:
            raise FieldError("", "solver.method", self._refusal("a section", "section"))
        return self.section(parameters, levels, comm, solver)


def _enumerate(
    problem: UnilateralProblem, options: EnumerateOptions, context: PlateContext
) -> UnilateralSolution:
    return enumerate_contact_sets(
        problem,
        complete=options.complete,
        max_candidates=options.max_candidates,
        candidate_comm=context.candidate_comm,
        # "auto" must be exact: the paper's stopping rule is not (docs: methods/enumeration).
        until_proven=options.until_proven or problem.spec.solver.method == Method.AUTO,
    )


def _interior_point(
    problem: UnilateralProblem, options: InteriorPointOptions, _: PlateContext
) -> UnilateralSolution:
    chain = ChainOptions(max_iterations=options.max_iterations, bound_budget=options.bound_budget)
    return solve_interior_point(problem, chain)


def _active_set(
    problem: UnilateralProblem, options: ActiveSetOptions, _: PlateContext
) -> UnilateralSolution:
    return solve_active_set(
        problem, max_iterations=options.max_iterations, bound_budget=options.bound_budget
    )


def _penalty(
    problem: UnilateralProblem, options: PenaltyOptions, _: PlateContext
) -> UnilateralSolution:
    return solve_penalty(problem, options.penalty)


def _foundation(
    problem: UnilateralProblem, options: FoundationOptions, context: PlateContext
) -> UnilateralSolution:
    return solve_foundation(
        problem, max_iterations=options.max_iterations, rigid_set=context.rigid_start
    )


def _section_levels(route: str) -> SectionRun:
    """The section runner of ``route``: that route over the section's coarser sections."""

    def run(
        parameters: SectionParameters, levels: int, comm: MPI.Comm, solver: SolverSpec
    ) -> tuple[Section, UnilateralSolution]:
        return solve_levels(
            parameters,
            levels=levels,
            comm=comm,
            solver=solver,
            max_iterations=solver.max_iterations,
            route=route,
        )

    return run


def _section_foundation(
    parameters: SectionParameters, levels: int, comm: MPI.Comm, solver: SolverSpec
) -> tuple[Section, UnilateralSolution]:
    """An elastic core: the spring-set iteration on the section itself (no coarser ones).

    Its start from the rigid core's contact set takes the rigid core's route
    (:func:`_rigid_core_set`, ``levels`` as far as the rigid core allows them).
    """
    section = build_section(parameters, comm, solver)
    try:
        solution = solve_foundation(
            section.cored,
            max_iterations=solver.max_iterations,
            rigid_set=lambda: _rigid_core_set(parameters, section, levels, comm, solver),
        )
    except BaseException:
        section.destroy()
        raise
    return section, solution


def _rigid_core_set(
    parameters: SectionParameters,
    section: Section,
    levels: int,
    comm: MPI.Comm,
    solver: SolverSpec,
) -> tuple[npt.NDArray[np.int64], int]:
    """The rigid core's contact set on the elastic core's ``section``, and its eigen solves.

    The route "auto" takes for the same section with a rigid core
    (:func:`~unibuckle_fenicsx.algorithms.registry.choose_section_method`), on ``levels`` coarser
    sections or as many as it allows
    (:func:`~unibuckle_fenicsx.spec.section.most_levels`), none if a coarser section
    cannot be built (the elastic core asks no levels); its contact
    set is carried to ``section``'s directions (the same mesh:
    :func:`~.section_levels.prolong_directions` maps each direction to itself). The
    active set on the elastic core's own problem can end at a higher KKT point than the
    rigid core's route, and the elastic core then above the rigid core's load, which no
    foundation exceeds (:doc:`/history/2026-12-01a-coreroute`). Collective.
    """
    rigid = replace(parameters, foundation_stiffness=None)
    method, _ = choose_section_method(rigid, solver)  # an elastic core's method is auto
    runner = entry(method).solve_section
    if runner is None or section.constraints is None:
        raise RuntimeError("the rigid core's route has no section runner")
    levels = min(levels, most_levels(rigid.mesh_size, rigid.length))
    try:
        rigid_section, solution = runner(rigid, levels, comm, solver)
    except InputError:  # a coarser section the core covers no node of: the given one's
        if levels == 0:
            raise
        rigid_section, solution = runner(rigid, 0, comm, solver)
    try:
        if rigid_section.constraints is None:
            raise RuntimeError("a core section without constraints")
        active = prolong_directions(solution.active, rigid_section.constraints, section.constraints)
        solves = solution.eigensolves + rigid_section.problem.free_solves
    finally:
        rigid_section.destroy()
    return active, solves


#: Every method that runs, by name (``auto`` is a choice among them, not one of them):
#: adding a method is adding its entry here.
REGISTRY: dict[str, MethodEntry] = {
    e.name: e
    for e in (
        MethodEntry(Method.ENUMERATE, OPTIONS[Method.ENUMERATE], _enumerate, ("enumerate",)),
        MethodEntry(
            Method.INTERIOR_POINT,
            OPTIONS[Method.INTERIOR_POINT],
            _interior_point,
            # A polish or a descent after it, or the active set's route when it fails.
            (
                "interior-point",
                "active-set-polish",
                "feasible-descent",
                "active-set",
                "penalty-continuation",
            ),
            _section_levels(Method.INTERIOR_POINT),
        ),
        MethodEntry(
            Method.ACTIVE_SET,
            OPTIONS[Method.ACTIVE_SET],
            _active_set,
            # Its fallbacks (:func:`.active_set.solve_active_set`) after it.
            ("active-set", "penalty-continuation", "feasible-descent"),
            _section_levels(Method.ACTIVE_SET),
        ),
        MethodEntry(Method.PENALTY, OPTIONS[Method.PENALTY], _penalty, ("penalty",)),
        MethodEntry(
            FOUNDATION,
            FoundationOptions,
            _foundation,
            ("foundation", "arc-descent"),
            _section_foundation,
        ),
        # "auto" on a small section: both section routes, the lower KKT point kept (its
        # solution's method and route are those of the route kept).
        MethodEntry(
            BOTH,
            OPTIONS[Method.INTERIOR_POINT],
            None,
            ("interior-point", "active-set", "penalty-continuation", "feasible-descent"),
            _section_levels(BOTH),
        ),
        # "auto" on a large section: the interior point, checked by the active set's
        # seeds on its coarsest section, carried up where they rank lower there.
        MethodEntry(
            CHECKED,
            OPTIONS[Method.INTERIOR_POINT],
            None,
            ("interior-point", "active-set", "penalty-continuation", "feasible-descent"),
            _section_levels(CHECKED),
        ),
    )
}


def entry(name: str) -> MethodEntry:
    """The registry's entry of the method ``name``.

    Raises:
        InputError: ``name`` is no method that runs ("auto" chooses one first).
    """
    try:
        return REGISTRY[name]
    except KeyError:
        raise InputError(f"unknown method {name!r}: one of {', '.join(REGISTRY)} runs") from None


def choose_method(
    spec: ProblemSpec, i: int, solve_time_s: float, *, candidate_parallel: bool = False
) -> tuple[str, str]:
    """The method to run, and why ("auto" decides by estimated cost).

    "auto" enumerates (with ``until_proven``: exact) when the 2^i candidate sets are at
    most ``max_candidates`` and their estimated time, 2^i times ``solve_time_s`` (the
    timed free eigen solve), is at most ``enumeration_budget_s``; otherwise it runs
    the interior-point method on thin plates (thickness below ``THIN_PLATE`` of the
    shorter side) and the active-set method on the others. "enumerate" alone follows
    the paper's stopping rule. A tensionless foundation runs its spring-set iteration
    (:data:`~.algorithms.registry.FOUNDATION`). The name returned is a key of
    :data:`~.algorithms.registry.REGISTRY`.

    Raises:
        InputError: ``candidate_parallel`` with a method other than enumeration, or with
            more candidate sets than ``max_candidates``.
    """
    options = spec.solver
    if spec.tensionless:
        if candidate_parallel:
            raise InputError(
                "--candidate-parallel splits the enumeration's candidate sets; a tensionless "
                "foundation is solved by its spring-set iteration: drop --candidate-parallel"
            )
        return FOUNDATION, "tensionless foundation: spring-set iteration"
    count = candidate_count(i)
    # 2^i in words a reader can take in (2^2581 has 777 digits).
    shown = str(count) if i <= 64 else f"10^{int(i * math.log10(2))}"
    estimate = math.inf if i > 1000 else count * solve_time_s
    if candidate_parallel:
        if options.method not in (Method.AUTO, Method.ENUMERATE):
            raise InputError(
                f"--candidate-parallel splits the enumeration's candidate sets: it needs "
                f'method "enumerate" or "auto", not \'{options.method}\''
            )
        if count > options.max_candidates:
            raise InputError(
                f"--candidate-parallel runs the enumeration, but i = {i} constrained nodes "
                f"give 2^{i} = {shown} candidate sets, above max_candidates = "
                f"{options.max_candidates}: drop --candidate-parallel (the active-set "
                "method distributes the mesh instead)"
            )
        return Method.ENUMERATE, f"--candidate-parallel: 2^{i} = {shown} candidate sets"
    if options.method != Method.AUTO:
        return options.method, "given"
    local, why = method_without_enumeration(spec)
    if count > options.max_candidates:
        return local, (
            f"auto: 2^{i} = {shown} candidate sets exceed max_candidates = "
            f"{options.max_candidates}; {why}"
        )
    if estimate > options.enumeration_budget_s:
        return local, (
            f"auto: enumerating 2^{i} = {shown} sets would take about {estimate:.3g} s "
            f"({solve_time_s:.3g} s per eigen solve), above enumeration_budget_s = "
            f"{options.enumeration_budget_s:g}; {why}"
        )
    return Method.ENUMERATE, (
        f"auto: 2^{i} = {shown} candidate sets, about {estimate:.3g} s "
        f"({solve_time_s:.3g} s per eigen solve), within enumeration_budget_s = "
        f"{options.enumeration_budget_s:g}"
    )


def method_without_enumeration(spec: ProblemSpec) -> tuple[str, str]:
    """The method "auto" runs on ``spec``'s plate when it does not enumerate, and why.

    The interior point on a thin plate (thickness below ``THIN_PLATE`` of the shorter
    side), the active set on the others.
    """
    plate = spec.plate
    slenderness = plate.thickness / min(plate.length, plate.width)
    thin = thin_plate(spec)
    method = Method.INTERIOR_POINT if thin else Method.ACTIVE_SET
    return method, f"t/b = {slenderness:.3g} {'<' if thin else '>='} {THIN_PLATE:g}"


def choose_section_method(parameters: SectionParameters, solver: SolverSpec) -> tuple[str, str]:
    """The method to run on a section, and why ("auto" decides by the section's size).

    Without a core, :data:`FREE` (the hollow section's smallest eigenvalue); an elastic
    core runs the spring-set iteration (:data:`~.algorithms.registry.FOUNDATION`), as a
    plate's tensionless foundation does. A rigid core runs the ``[solver] method`` given,
    one of :data:`~unibuckle_fenicsx.spec.section.SECTION_METHODS`; "auto" runs the
    interior point, checked by the active set's seeds on its coarsest section
    (:data:`~unibuckle_fenicsx.algorithms.section_levels.CHECKED`), on sections of at least
    :data:`~unibuckle_fenicsx.algorithms.section_levels.INTERIOR_POINT_DOFS` degrees of
    freedom, estimated before meshing
    (:func:`~unibuckle_fenicsx.algorithms.section_levels.estimated_dofs`), and on smaller
    ones both routes on the same sections, the lower KKT point kept
    (:data:`~unibuckle_fenicsx.algorithms.section_levels.BOTH`: either alone can end
    above the other). The interior point falls back on the active set when it reaches no
    KKT point (its route then takes the link "active-set").

    Raises:
        InputError: A method no section runs, or one other than "auto" without a rigid
            core (``solver.method``, the allowed named).
    """
    check_section_method(
        solver.method, parameters.core, parameters.foundation_stiffness is not None
    )
    if not parameters.core:
        return FREE, "no core"
    if parameters.foundation_stiffness is not None:
        return FOUNDATION, "elastic core: spring-set iteration"
    if solver.method != Method.AUTO:
        return solver.method, "given"
    dofs = estimated_dofs(parameters)
    if dofs >= INTERIOR_POINT_DOFS:
        return CHECKED, (
            f"auto: about {dofs} DOFs (estimated before meshing) >= "
            f"INTERIOR_POINT_DOFS = {INTERIOR_POINT_DOFS}: the interior point, checked by "
            "the active set's seeds on its coarsest section, the lower KKT point kept"
        )
    return BOTH, (
        f"auto: about {dofs} DOFs (estimated before meshing) < INTERIOR_POINT_DOFS = "
        f"{INTERIOR_POINT_DOFS}: the interior point and the active set, the lower KKT "
        "point kept"
    )
