"""High-level entry point: :func:`solve` a :class:`~unibuckle_fenicsx.spec.ProblemSpec`.

The method of every unilateral problem is decided here: a plate's by :func:`choose_method`
(once its mesh is built and its free eigen solve timed), a section's by
:func:`choose_section_method` (before any mesh). Each returns a key of
:data:`~unibuckle_fenicsx.algorithms.registry.REGISTRY`, through which the method runs,
and the reason a result records as ``method_chosen_by``.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

from mpi4py import MPI

import dolfinx

from unibuckle_fenicsx.algorithms import UnilateralSolution, candidate_count
from unibuckle_fenicsx.algorithms.chain import THIN_PLATE, thin_plate
from unibuckle_fenicsx.algorithms.registry import FOUNDATION, entry
from unibuckle_fenicsx.algorithms.section_levels import (
    BOTH,
    CHECKED,
    INTERIOR_POINT_DOFS,
    estimated_dofs,
)
from unibuckle_fenicsx.certificate.certify import Certificate, certify, certify_foundation
from unibuckle_fenicsx.errors import InputError, NoAdmissibleModeError
from unibuckle_fenicsx.la.ownership import Owner
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.problem import Problem, UnilateralProblem
from unibuckle_fenicsx.model.shell.section import SectionParameters
from unibuckle_fenicsx.results.assemble import assemble_result
from unibuckle_fenicsx.results.records import BucklingResult
from unibuckle_fenicsx.spec import Method, ProblemSpec, SolverSpec
from unibuckle_fenicsx.spec.section import check_section_method

__all__ = [
    "FREE",
    "Analysis",
    "choose_method",
    "choose_section_method",
    "method_without_enumeration",
    "solve",
]

#: The "method" of a problem without obstacle (a section without core): its free load.
FREE = "free"

logger = logging.getLogger(__name__)


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


#: Times a refuted answer is continued from its refuting mode (each time certified again).
MAX_CONTINUATIONS = 3


def _continue(
    problem: UnilateralProblem, solution: UnilateralSolution, certificate: Certificate
) -> tuple[UnilateralSolution, Certificate]:
    """While the certificate refutes the answer, continue the solve from its refuting mode.

    A refuting mode is admissible with a load below the answer's: the feasible descent
    from it (:func:`~unibuckle_fenicsx.algorithms.descent.continue_from`) never raises
    the load, so the answer never ends above it; the new answer is certified again.
    """
    from unibuckle_fenicsx.algorithms.descent import continue_from

    for _ in range(MAX_CONTINUATIONS):
        start = certificate.refuting_mode
        if start is None:
            break
        logger.info(
            "the certificate refutes the load %.10g (an admissible mode has %.10g): "
            "continuing from that mode", solution.load, start.load,
        )  # fmt: skip
        solution = continue_from(problem, solution, start, problem.spec.solver.max_iterations)
        certificate = certify(problem, solution)
    return solution, certificate


@dataclass
class Analysis(Owner):
    """What :func:`solve` returns: the result, the critical mode and the set-up problem.

    Attributes:
        result: The result's records (:class:`~unibuckle_fenicsx.results.records.BucklingResult`).
        problem: The set-up problem (mesh, pencil, contact manager, free mode).
        solution: The unilateral algorithm's solution (None without obstacle).
        certificate: Its certificate (None without obstacle).

    Note:
        :meth:`destroy` (or leaving a ``with`` block) is collective.
    """

    result: BucklingResult
    problem: Problem
    solution: UnilateralSolution | None = None
    certificate: Certificate | None = None

    @property
    def mode(self) -> dolfinx.fem.Function:
        """The critical mode (w, theta), max |w| = 1 (the free mode without obstacle)."""
        if self.solution is not None:
            return self.solution.candidate.mode
        return self.free_mode

    @property
    def free_mode(self) -> dolfinx.fem.Function:
        """The mode without obstacle, max |w| = 1."""
        if self.problem.free is None:
            raise RuntimeError(
                "free_mode: expected self.problem.free is not None (an internal invariant)"
            )
        return self.problem.free.function

    def destroy(self) -> None:
        """Destroy the problem's PETSc/SLEPc objects (collective)."""
        self.problem.destroy()


def solve(
    spec: ProblemSpec,
    comm: MPI.Comm = MPI.COMM_WORLD,
    *,
    candidate_parallel: bool = False,
    eps_options: dict[str, str | float | int] | None = None,
    mesh: dolfinx.mesh.Mesh | None = None,
    facet_tags: dolfinx.mesh.MeshTags | None = None,
) -> Analysis:
    """Critical load and mode of ``spec``, certified.

    Args:
        spec: The problem.
        comm: Communicator. By default the mesh is distributed over it.
        candidate_parallel: Instead, give every rank a serial copy of the problem and
            split the enumeration's candidate sets over ``comm`` (method "enumerate").
        eps_options: Extra EPS options under the prefix ``unibuckle_`` (so ``eps_view``
            is ``-unibuckle_eps_view``).
        mesh: Optional quadrilateral mesh replacing ``spec.mesh`` (with ``facet_tags``;
            see :func:`~unibuckle_fenicsx.model.build.build_problem`).
        facet_tags: Edge markers of ``mesh``.

    Returns:
        The analysis (result, mode, problem); the caller destroys it (or uses ``with``).

    Raises:
        TypeError: ``spec`` is not a :class:`~unibuckle_fenicsx.spec.ProblemSpec` or
            ``comm`` not an MPI communicator.
        InputError: The problem is refused (before any solve, or once its mesh exists).
        NumericalError: A solve did not converge, or no admissible mode was found.

    Note:
        Collective on ``comm``. On an error, every PETSc/SLEPc object built here is
        destroyed before the error propagates (collectively: every rank raises).
    """
    t0 = time.perf_counter()
    if not isinstance(spec, ProblemSpec):
        raise TypeError(
            f"solve: spec must be a ProblemSpec (paper_case(...), load_toml(path), "
            f"problem_from_dict(data)), got {type(spec).__name__}"
        )
    if not isinstance(comm, MPI.Comm):
        raise TypeError(
            f"solve: comm must be an MPI communicator (MPI.COMM_WORLD), got {type(comm).__name__}"
        )
    if mesh is not None and candidate_parallel:
        raise InputError("candidate_parallel builds its own serial meshes: pass no mesh")
    problem = build_problem(
        spec,
        MPI.COMM_SELF if candidate_parallel else comm,
        eps_options,
        mesh=mesh,
        facet_tags=facet_tags,
    )
    try:
        return _analyse(spec, problem, comm, candidate_parallel, t0)
    except BaseException:
        # A failed solve (or Ctrl-C) must not leave the problem's PETSc objects to the
        # garbage collector, whose order differs between ranks: the caller may go on
        # collectively (the sweep's next point).
        problem.destroy()
        raise


def _analyse(
    spec: ProblemSpec,
    problem: Problem,
    comm: MPI.Comm,
    candidate_parallel: bool,
    t0: float,
) -> Analysis:
    """The solves of :func:`solve` on ``problem``, set up from ``spec`` (collective)."""
    t_free = time.perf_counter()
    free = problem.solve_free()
    t_free = comm.allreduce(time.perf_counter() - t_free, op=MPI.MAX)
    problem.timings["free_solve_s"] = t_free
    solution: UnilateralSolution | None = None
    certificate: Certificate | None = None
    method, reason = FREE, "no obstacle"
    if not isinstance(problem, UnilateralProblem):
        # The free load is the answer: verified the smallest (one LDL^T's inertia).
        t1 = time.perf_counter()
        problem.verify_free()
        problem.timings["free_check_s"] = time.perf_counter() - t1
    else:
        method, reason = choose_method(
            spec, problem.num_constrained, t_free, candidate_parallel=candidate_parallel
        )
        logger.info(
            "i = %d constrained nodes; method %s (%s)", problem.num_constrained, method, reason
        )
        t1 = time.perf_counter()
        solution = entry(method).solve(problem, comm if candidate_parallel else None)
        problem.timings["unilateral_s"] = time.perf_counter() - t1
        if not math.isfinite(solution.load):
            raise NoAdmissibleModeError(
                f"{spec.name}: no admissible mode with a finite load was found; lower bound "
                f"lambda_free = {free.load!r} Pa"
            )
        t1 = time.perf_counter()
        if problem.tensionless:  # springs, not obstacles: their own certificate
            certificate = certify_foundation(problem, solution)
        else:
            certificate = certify(problem, solution)
            solution, certificate = _continue(problem, solution, certificate)
        problem.timings["certify_s"] = time.perf_counter() - t1
        if certificate.status == "not-kkt":
            logger.warning(
                "the %s result fails its certificate: %s",
                method, "; ".join(certificate.notes) or certificate.status,
            )  # fmt: skip
    result = assemble_result(
        problem,
        free,
        solution,
        certificate,
        wall_time_s=time.perf_counter() - t0,
        mpi_size=comm.size,
        method_chosen_by=reason,
    )
    return Analysis(result, problem, solution, certificate)
