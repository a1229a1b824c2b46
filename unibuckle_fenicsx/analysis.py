"""High-level entry point: :func:`solve` a :class:`~unibuckle_fenicsx.config.ProblemSpec`."""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

from mpi4py import MPI

import dolfinx

from unibuckle_fenicsx.algorithms import UnilateralSolution, candidate_count
from unibuckle_fenicsx.certify import Certificate, certify
from unibuckle_fenicsx.config import ProblemSpec
from unibuckle_fenicsx.eigen import Owner
from unibuckle_fenicsx.problem import BucklingProblem
from unibuckle_fenicsx.results import BucklingResult

__all__ = ["Analysis", "choose_method", "solve"]

logger = logging.getLogger(__name__)


def choose_method(spec: ProblemSpec, i: int) -> str:
    """The method "auto" resolves to: enumeration when 2^i <= max_candidates.

    "auto" enumerates with ``until_proven`` (exact), "enumerate" alone follows the
    paper's stopping rule.
    """
    if spec.solver.method != "auto":
        return spec.solver.method
    return "enumerate" if candidate_count(i) <= spec.solver.max_candidates else "active-set"


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
            # "auto" must be exact: the paper's stopping rule is not (README).
            until_proven=options.until_proven or options.method == "auto",
        )
    if method == "active-set":
        from unibuckle_fenicsx.algorithms.active_set import solve_active_set

        return solve_active_set(problem)
    if method == "penalty":
        from unibuckle_fenicsx.algorithms.penalty import solve_penalty

        return solve_penalty(problem, problem.spec.solver.penalty)
    raise ValueError(f"unknown method {method!r}")


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
        assert self.problem.free is not None
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
            see :class:`~unibuckle_fenicsx.problem.BucklingProblem`).
        facet_tags: Edge markers of ``mesh``.

    Returns:
        The analysis (result, mode, problem); the caller destroys it (or uses ``with``).

    Note:
        Collective on ``comm``.
    """
    t0 = time.perf_counter()
    if mesh is not None and candidate_parallel:
        raise ValueError("candidate_parallel builds its own serial meshes: pass no mesh")
    problem = BucklingProblem(
        spec,
        MPI.COMM_SELF if candidate_parallel else comm,
        eps_options,
        mesh=mesh,
        facet_tags=facet_tags,
    )
    free = problem.solve_free()
    solution: UnilateralSolution | None = None
    certificate: Certificate | None = None
    method = "free"
    if problem.contact is not None:
        method = choose_method(spec, problem.num_constrained)
        if candidate_parallel and method != "enumerate":
            raise ValueError(
                'candidate_parallel runs need method "enumerate"; distribute the mesh '
                "for the other methods"
            )
        logger.info("i = %d constrained nodes; method %s", problem.num_constrained, method)
        solution = _run_method(method, problem, comm if candidate_parallel else None)
        if not math.isfinite(solution.load):
            raise RuntimeError(f"{spec.name}: no finite critical load was found")
        certificate = certify(problem, solution)
        if not certificate.kkt:
            logger.warning("the %s result fails its certificate: %s", method, certificate)
    result = BucklingResult.from_solution(
        problem,
        free,
        solution,
        certificate,
        method=method,
        wall_time_s=time.perf_counter() - t0,
        mpi_size=comm.size,
    )
    return Analysis(result, problem, solution, certificate)
