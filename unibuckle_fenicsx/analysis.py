"""High-level entry point: :func:`solve` a :class:`~unibuckle_fenicsx.spec.ProblemSpec`.

Set-up, method, certificate, result. The method is chosen by the registry
(:func:`~unibuckle_fenicsx.algorithms.registry.choose_method`, once the mesh is built and
the free eigen solve timed), which runs it; the reason a result records as
``method_chosen_by``. A tensionless foundation's start from the rigid obstacle is its
rigid twin solved here as a whole problem (:func:`solve`).
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

from mpi4py import MPI

import dolfinx

import numpy as np
import numpy.typing as npt
from msgspec.structs import replace

from unibuckle_fenicsx.algorithms import UnilateralSolution
from unibuckle_fenicsx.algorithms.registry import (
    FREE,
    PlateContext,
    choose_method,
    entry,
    method_without_enumeration,
)
from unibuckle_fenicsx.certificate.certify import Certificate, certify, certify_foundation
from unibuckle_fenicsx.errors import InputError, NoAdmissibleModeError
from unibuckle_fenicsx.la.ownership import Owner
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.problem import Problem, UnilateralProblem
from unibuckle_fenicsx.progress import warn_once
from unibuckle_fenicsx.results.assemble import assemble_result
from unibuckle_fenicsx.results.records import BucklingResult
from unibuckle_fenicsx.spec import ObstacleSpec, ProblemSpec

__all__ = ["Analysis", "solve"]
logger = logging.getLogger(__name__)


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


def _rigid_twin(problem: UnilateralProblem) -> tuple[npt.NDArray[np.int64], int]:
    """The contact set of the rigid twin's answer, as the foundation's nodes; its solves.

    The twin is ``problem.spec`` with every tensionless foundation made rigid, solved by
    :func:`solve` (certified, continued from a refuting mode) with the method "auto"
    runs on its plate besides the enumeration
    (:func:`~unibuckle_fenicsx.algorithms.registry.method_without_enumeration`): the
    enumeration's cost would be paid again at every stiffness. On the problem's own mesh
    when it is the user's. A contact node is matched to the foundation's node at the same
    coordinates (a twin's zone node on no whole cell of the zone carries no spring and is
    left out). Without an admissible rigid mode, the empty set (the free start's).
    Collective.
    """
    spec = problem.spec

    def rigid(o: ObstacleSpec) -> ObstacleSpec:
        return replace(o, foundation_stiffness=None) if o.kind == "tensionless" else o

    if spec.obstacle is not None:
        spec = replace(spec, obstacle=rigid(spec.obstacle))
    else:
        spec = replace(spec, obstacles=tuple(rigid(o) for o in spec.obstacles))
    method, _ = method_without_enumeration(spec)
    spec = replace(spec, solver=replace(spec.solver, method=method))
    own = problem.custom_mesh
    mesh, tags = (problem.mesh, problem.facet_tags) if own else (None, None)
    try:
        twin = solve(spec, problem.comm, mesh=mesh, facet_tags=tags)
    except NoAdmissibleModeError:  # the rigid obstacle leaves no mode: no start from it
        logger.info("foundation: the rigid obstacle has no admissible mode; no rigid start")
        return np.empty(0, np.int64), 0
    with twin:
        solution = twin.solution
        if not isinstance(twin.problem, UnilateralProblem) or solution is None:
            raise RuntimeError(
                "_rigid_twin: expected the rigid twin to have an obstacle (an internal invariant)"
            )
        coordinates = twin.problem.contact.coordinates[solution.candidate.active]
        load, solves = solution.load, twin.result.eigensolves
    logger.info("foundation: the rigid obstacle's load %.10g starts a run", load)
    index = {tuple(c): k for k, c in enumerate(problem.contact.coordinates)}
    active = sorted(index[tuple(c)] for c in coordinates if tuple(c) in index)
    return np.asarray(active, dtype=np.int64), solves


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
        context = PlateContext(
            candidate_comm=comm if candidate_parallel else None,
            rigid_start=(lambda: _rigid_twin(problem)) if problem.tensionless else None,
        )
        solution = entry(method).solve(problem, context)
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
            warn_once(
                logger, comm, "the %s result fails its certificate: %s",
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
