"""High-level entry point: :func:`solve` a :class:`~unibuckle_fenicsx.spec.ProblemSpec`."""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

from mpi4py import MPI

import dolfinx

from unibuckle_fenicsx.algorithms import (
    NoAdmissibleModeError,
    UnilateralSolution,
    candidate_count,
)
from unibuckle_fenicsx.algorithms.chain import THIN_PLATE
from unibuckle_fenicsx.certificate.certify import Certificate, certify, certify_foundation
from unibuckle_fenicsx.eigen import Owner
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.model.problem import BucklingProblem
from unibuckle_fenicsx.results import BucklingResult
from unibuckle_fenicsx.spec import ProblemSpec

__all__ = ["Analysis", "choose_method", "solve"]

logger = logging.getLogger(__name__)


def choose_method(
    spec: ProblemSpec, i: int, solve_time_s: float, *, candidate_parallel: bool = False
) -> tuple[str, str]:
    """The method to run, and why ("auto" decides by estimated cost).

    "auto" enumerates (with ``until_proven``: exact) when the 2^i candidate sets are at
    most ``max_candidates`` and their estimated time, 2^i times ``solve_time_s`` (the
    measured time of one eigen solve), is at most ``enumeration_budget_s``; otherwise it
    runs the active-set method. "enumerate" alone follows the paper's stopping rule.

    Raises:
        ValueError: ``candidate_parallel`` with a method other than enumeration, or with
            more candidate sets than ``max_candidates``.
    """
    options = spec.solver
    if spec.tensionless:
        if candidate_parallel:
            raise InputError(
                "--candidate-parallel splits the enumeration's candidate sets; a tensionless "
                "foundation is solved by its spring-set iteration: drop --candidate-parallel"
            )
        return "foundation", "tensionless foundation: spring-set iteration"
    count = candidate_count(i)
    # 2^i in words a reader can take in (2^2581 has 777 digits).
    shown = str(count) if i <= 64 else f"10^{int(i * math.log10(2))}"
    estimate = math.inf if i > 1000 else count * solve_time_s
    if candidate_parallel:
        if options.method not in ("auto", "enumerate"):
            raise InputError(
                f"--candidate-parallel splits the enumeration's candidate sets: it needs "
                f'method "enumerate" or "auto", not {options.method!r}'
            )
        if count > options.max_candidates:
            raise InputError(
                f"--candidate-parallel runs the enumeration, but i = {i} constrained nodes "
                f"give 2^{i} = {shown} candidate sets, above max_candidates = "
                f"{options.max_candidates}: drop --candidate-parallel (the active-set "
                "method distributes the mesh instead)"
            )
        return "enumerate", f"--candidate-parallel: 2^{i} = {shown} candidate sets"
    if options.method != "auto":
        return options.method, "given"
    plate = spec.plate
    slenderness = plate.thickness / min(plate.length, plate.width)
    local = "interior-point" if slenderness < THIN_PLATE else "active-set"
    why = f"t/b = {slenderness:.3g} {'<' if local == 'interior-point' else '>='} {THIN_PLATE:g}"
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
    return "enumerate", (
        f"auto: 2^{i} = {shown} candidate sets, about {estimate:.3g} s "
        f"({solve_time_s:.3g} s per eigen solve), within enumeration_budget_s = "
        f"{options.enumeration_budget_s:g}"
    )


def _run_method(
    method: str, problem: BucklingProblem, candidate_comm: MPI.Comm | None
) -> UnilateralSolution:
    if method == "enumerate":
        from unibuckle_fenicsx.algorithms.enumeration import enumerate_contact_sets

        options = problem.spec.solver
        return enumerate_contact_sets(
            problem,
            complete=options.complete,
            max_candidates=options.max_candidates,
            candidate_comm=candidate_comm,
            # "auto" must be exact: the paper's stopping rule is not (docs: methods/enumeration).
            until_proven=options.until_proven or options.method == "auto",
        )
    if method == "interior-point":
        from unibuckle_fenicsx.algorithms.chain import ChainOptions, solve_unilateral

        options = problem.spec.solver
        return solve_unilateral(
            problem,
            ChainOptions(max_iterations=options.max_iterations, bound_budget=options.bound_budget),
        )
    if method == "active-set":
        from unibuckle_fenicsx.algorithms.active_set import solve_active_set

        options = problem.spec.solver
        return solve_active_set(
            problem, max_iterations=options.max_iterations, bound_budget=options.bound_budget
        )
    if method == "penalty":
        from unibuckle_fenicsx.algorithms.penalty import solve_penalty

        return solve_penalty(problem, problem.spec.solver.penalty)
    if method == "foundation":
        from unibuckle_fenicsx.algorithms.foundation import solve_foundation

        return solve_foundation(problem, max_iterations=problem.spec.solver.max_iterations)
    raise InputError(f"unknown method {method!r}")


@dataclass
class Analysis(Owner):
    """What :func:`solve` returns: the result, the critical mode and the set-up problem.

    Attributes:
        result: JSON-ready numbers (:class:`~unibuckle_fenicsx.results.BucklingResult`).
        problem: The set-up problem (mesh, pencil, contact manager, free mode).
        solution: The unilateral algorithm's solution (None without obstacle).
        certificate: Its certificate (None without obstacle).

    Note:
        :meth:`destroy` (or leaving a ``with`` block) is collective.
    """

    result: BucklingResult
    problem: BucklingProblem
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
            see :class:`~unibuckle_fenicsx.model.problem.BucklingProblem`).
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
    problem = BucklingProblem(
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
    problem: BucklingProblem,
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
    method, reason = "free", "no obstacle"
    if problem.contact is None:
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
        solution = _run_method(method, problem, comm if candidate_parallel else None)
        problem.timings["unilateral_s"] = time.perf_counter() - t1
        if not math.isfinite(solution.load):
            raise NoAdmissibleModeError(
                f"{spec.name}: no admissible mode with a finite load was found; lower bound "
                f"lambda_free = {free.load!r} Pa"
            )
        t1 = time.perf_counter()
        if method == "foundation":
            certificate = certify_foundation(problem, solution)
        else:
            certificate = certify(problem, solution)
        problem.timings["certify_s"] = time.perf_counter() - t1
        if not certificate.kkt:
            logger.warning(
                "the %s result fails its certificate: %s",
                method, "; ".join(certificate.notes) or certificate.status,
            )  # fmt: skip
    result = BucklingResult.from_solution(
        problem,
        free,
        solution,
        certificate,
        method=method if solution is None else solution.method,
        wall_time_s=time.perf_counter() - t0,
        mpi_size=comm.size,
    )
    result.method_chosen_by = reason
    return Analysis(result, problem, solution, certificate)
