"""High-level entry point: :func:`solve` a :class:`~unibuckle_fenicsx.config.ProblemSpec`."""

from __future__ import annotations

import logging
import math
import time
from pathlib import Path

from mpi4py import MPI

import dolfinx
import dolfinx.io

import numpy as np

from unibuckle_fenicsx.algorithms import UnilateralSolution
from unibuckle_fenicsx.config import ProblemSpec
from unibuckle_fenicsx.problem import BucklingProblem
from unibuckle_fenicsx.results import BucklingResult

__all__ = ["candidate_count", "choose_method", "solve", "write_vtx"]

logger = logging.getLogger(__name__)


def candidate_count(i: int) -> int:
    r"""Subsets the paper's enumeration may visit: :math:`\sum_p C(i, p) = 2^i`."""
    return 2**i


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


def solve(
    spec: ProblemSpec,
    comm: MPI.Comm = MPI.COMM_WORLD,
    *,
    candidate_parallel: bool = False,
    eps_options: dict[str, str | float | int] | None = None,
    mesh: dolfinx.mesh.Mesh | None = None,
    facet_tags: dolfinx.mesh.MeshTags | None = None,
) -> tuple[BucklingResult, BucklingProblem]:
    """Critical load and mode of ``spec``.

    Args:
        spec: The problem.
        comm: Communicator. By default the mesh is distributed over it.
        candidate_parallel: Instead, give every rank a serial copy of the problem and
            split the enumeration's candidate sets over ``comm`` (method "enumerate").
        mesh: Optional quadrilateral mesh replacing ``spec.mesh`` (with ``facet_tags``;
            see :class:`~unibuckle_fenicsx.problem.BucklingProblem`).
        facet_tags: Edge markers of ``mesh``.
        eps_options: Extra EPS options under the prefix ``unibuckle_`` (so ``eps_view``
            is ``-unibuckle_eps_view``).

    Returns:
        The result and the set-up problem (holding the mode in ``problem.u``; the
        caller should ``destroy()`` it).

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
    i = problem.num_constrained
    method = "free"
    solution: UnilateralSolution | None = None
    if problem.contact is not None:
        method = choose_method(spec, i)
        if candidate_parallel and method != "enumerate":
            raise ValueError(
                'candidate_parallel runs need method "enumerate"; distribute the mesh '
                "for the other methods"
            )
        logger.info("i = %d constrained nodes; method %s", i, method)
        solution = _run_method(method, problem, comm if candidate_parallel else None)
    wall = time.perf_counter() - t0
    load = free.value if solution is None else solution.load
    t = spec.plate.thickness
    result = BucklingResult(
        case=spec.name,
        method=method,
        critical_load_Pa=load,
        free_load_Pa=free.value,
        ratio_to_free=load / free.value,
        critical_force_N_per_m=t * load,
        buckling_coefficient_k=problem.buckling_coefficient(load),
        dofs=problem.model.num_dofs,
        mesh=(
            [problem.mesh.topology.index_map(2).size_global]
            if problem.custom_mesh
            else [spec.mesh.nx, spec.mesh.ny]
        ),
        eigensolves=1 + (0 if solution is None else solution.eigensolves),
        wall_time_s=wall,
        timings={**problem.timings, "total_s": wall},
        mpi_size=comm.size,
        details={"free_eigen_error": free.error, "free_eigen_iterations": free.iterations},
    )
    if solution is not None:
        assert problem.contact is not None
        cert = problem.certify(
            solution.load,
            solution.active,
            global_optimum_proven=solution.global_optimum_proven,
        )
        if not cert.kkt:
            logger.warning("the %s result fails its certificate: %s", method, cert)
        result.constrained_nodes = i
        result.contact_nodes = len(solution.active)
        result.p_star = solution.p_star
        result.contact_indices = [int(k) for k in solution.active]
        result.contact_coordinates = problem.contact.coordinates[solution.active].tolist()
        rows = problem.contact.removed_rows(solution.active)
        result.contact_dofs = sorted(
            int(r) for part in problem.comm.allgather(rows.tolist()) for r in part
        )
        result.lower_bound_Pa = solution.lower_bound
        result.upper_bound_Pa = solution.load
        result.certificate = cert.as_dict()
        result.details.update(solution.details)
    else:
        result.lower_bound_Pa = result.upper_bound_Pa = free.value
    if math.isinf(load):
        raise RuntimeError(f"{spec.name}: no finite critical load was found")
    return result, problem


def write_vtx(
    problem: BucklingProblem, result: BucklingResult, directory: str | Path
) -> list[Path]:
    """Write the mode, the free mode, the obstacle zone and the contact set as VTX (.bp).

    Files: ``<case>_w.bp`` (w, free w, obstacle indicator, contact indicator on the Q1
    space) and ``<case>_theta.bp`` (rotation). Open them in ParaView (ADIOS2VTXReader).

    Note:
        Collective on the mesh communicator.
    """
    directory = Path(directory)
    if problem.comm.rank == 0:
        directory.mkdir(parents=True, exist_ok=True)
    problem.comm.barrier()
    w, theta = problem.model.split(problem.u)
    fields = [w]
    if problem.free_mode is not None:
        w_free, _ = problem.model.split(problem.free_mode)
        w_free.name = "w_free"
        fields.append(w_free)
    if problem.contact is not None:
        fields.append(problem.contact.indicator())
        fields.append(
            problem.contact.node_function(np.asarray(result.contact_indices, dtype=np.int64))
        )
    paths = [directory / f"{result.case}_w.bp", directory / f"{result.case}_theta.bp"]
    for path, funcs in ((paths[0], fields), (paths[1], [theta])):
        with dolfinx.io.VTXWriter(problem.comm, path, funcs, engine="BP4") as writer:
            writer.write(0.0)
    return paths
