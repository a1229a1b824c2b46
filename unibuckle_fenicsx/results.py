"""BucklingResult: what a solve returns, its JSON form, and ParaView output."""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from unibuckle_fenicsx.algorithms import UnilateralSolution
    from unibuckle_fenicsx.analysis import Analysis
    from unibuckle_fenicsx.certify import Certificate
    from unibuckle_fenicsx.problem import BucklingProblem, Mode

__all__ = ["BucklingResult", "write_json", "write_vtx"]


@dataclass
class BucklingResult:
    """Critical state of one problem (JSON-ready fields only).

    Attributes:
        case: Problem name.
        method: Algorithm used ("free", "enumerate", "active-set", "penalty").
        critical_load_Pa: lambda, the critical compressive stress (Pa).
        free_load_Pa: lambda without obstacle (Pa).
        ratio_to_free: critical / free.
        critical_force_N_per_m: N = t lambda.
        buckling_coefficient_k: k = N b^2 / (pi^2 D), b = plate width.
        dofs: Global DOF count of (w, theta).
        mesh: [nx, ny] (a user-supplied mesh: [number of cells]).
        eigensolves: Linear eigen solves, including the free one.
        wall_time_s: Wall time of the whole solve (set-up included).
        constrained_nodes: i, nodes in the closed obstacle zone with free deflection.
        contact_nodes: |Z|.
        p_star: Enumeration: the contact-set size where it stopped.
        contact_coordinates: Coordinates of Z, (|Z|, 2).
        contact_indices: Node numbers of Z (lexicographic (y, x) order of the zone).
        contact_dofs: Global W DOF indices of Z (partition-dependent numbering).
        lower_bound_Pa / upper_bound_Pa: Verified bracket of the critical load (the upper
            bound is the load of an admissible mode; None if the method found none).
        certificate: :class:`~unibuckle_fenicsx.certify.Certificate` as a dict.
        details: Method-specific information.
        timings: Seconds per phase.
        mpi_size: Ranks used.
    """

    case: str
    method: str
    critical_load_Pa: float
    free_load_Pa: float
    ratio_to_free: float
    critical_force_N_per_m: float
    buckling_coefficient_k: float
    dofs: int
    mesh: list[int]
    eigensolves: int
    wall_time_s: float
    constrained_nodes: int = 0
    contact_nodes: int = 0
    p_star: int | None = None
    contact_coordinates: list[list[float]] = field(default_factory=list)
    contact_indices: list[int] = field(default_factory=list)
    contact_dofs: list[int] = field(default_factory=list)
    lower_bound_Pa: float | None = None
    upper_bound_Pa: float | None = None
    certificate: dict[str, Any] | None = None
    details: dict[str, Any] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)
    mpi_size: int = 1

    @classmethod
    def from_solution(
        cls,
        problem: BucklingProblem,
        free: Mode,
        solution: UnilateralSolution | None,
        certificate: Certificate | None,
        *,
        method: str,
        wall_time_s: float,
        mpi_size: int,
    ) -> BucklingResult:
        """Assemble the result of ``problem``'s free mode and unilateral ``solution``.

        Note:
            Collective on the problem's communicator (gathers the contact DOFs).
        """
        spec = problem.spec
        load = free.load if solution is None else solution.load
        result = cls(
            case=spec.name,
            method=method,
            critical_load_Pa=load,
            free_load_Pa=free.load,
            ratio_to_free=load / free.load,
            critical_force_N_per_m=spec.plate.thickness * load,
            buckling_coefficient_k=problem.buckling_coefficient(load),
            dofs=problem.model.num_dofs,
            mesh=(
                [problem.mesh.topology.index_map(2).size_global]
                if problem.custom_mesh
                else [spec.mesh.nx, spec.mesh.ny]
            ),
            eigensolves=1 + (0 if solution is None else solution.eigensolves),
            wall_time_s=wall_time_s,
            timings={**problem.timings, "total_s": wall_time_s},
            mpi_size=mpi_size,
            details={
                "free_eigen_error": free.eigen.error,
                "free_eigen_iterations": free.eigen.iterations,
            },
        )
        if solution is None or certificate is None:
            result.lower_bound_Pa = result.upper_bound_Pa = free.load
            return result
        contact = problem.contact
        assert contact is not None
        active = solution.active
        rows = contact.removed_rows(active)
        result.constrained_nodes = problem.num_constrained
        result.contact_nodes = len(active)
        result.p_star = solution.p_star
        result.contact_indices = [int(k) for k in active]
        result.contact_coordinates = contact.coordinates[active].tolist()
        result.contact_dofs = sorted(
            int(r) for part in problem.comm.allgather(rows.tolist()) for r in part
        )
        result.lower_bound_Pa = certificate.lower_bound
        result.upper_bound_Pa = (
            certificate.upper_bound if math.isfinite(certificate.upper_bound) else None
        )
        result.certificate = certificate.as_dict()
        result.details.update(solution.details)
        return result

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready mapping (non-finite floats become strings)."""
        return _jsonable(asdict(self))

    def summary(self) -> str:
        """One line for the terminal."""
        z = ""
        if self.constrained_nodes:
            cert = self.certificate or {}
            z = (
                f"  i={self.constrained_nodes} |Z|={self.contact_nodes}"
                f"  KKT={'yes' if cert.get('kkt') else 'NO'}"
                f"  proven={'yes' if cert.get('global_optimum_proven') else 'no'}"
            )
        return (
            f"{self.case}: lambda_c = {self.critical_load_Pa:.6e} Pa "
            f"({self.critical_load_Pa / self.free_load_Pa:.4f} x free {self.free_load_Pa:.6e} Pa), "
            f"k = {self.buckling_coefficient_k:.4f}, method {self.method}{z}, "
            f"{self.eigensolves} eigensolves, {self.wall_time_s:.2f} s"
        )


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, float | np.floating):
        value = float(obj)
        return value if np.isfinite(value) else str(value)
    return obj


def write_json(result: BucklingResult, path: str | Path) -> Path:
    """Write ``result`` as JSON (call on one rank only)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(result.as_dict(), indent=2) + "\n")
    return path


def write_vtx(analysis: Analysis, directory: str | Path) -> list[Path]:
    """Write the mode, the free mode, the obstacle zone and the contact set as VTX (.bp).

    Files: ``<case>_w.bp`` (w, free w, obstacle indicator, contact indicator on the Q1
    space) and ``<case>_theta.bp`` (rotation). Open them in ParaView (ADIOS2VTXReader).

    Note:
        Collective on the mesh communicator.
    """
    import dolfinx.io

    problem = analysis.problem
    directory = Path(directory)
    if problem.comm.rank == 0:
        directory.mkdir(parents=True, exist_ok=True)
    problem.comm.barrier()
    w, theta = problem.model.split(analysis.mode)
    w_free, _ = problem.model.split(analysis.free_mode)
    w_free.name = "w_free"
    fields = [w, w_free]
    if problem.contact is not None and analysis.solution is not None:
        fields.append(problem.contact.indicator())
        fields.append(problem.contact.node_function(analysis.solution.active))
    case = analysis.result.case
    paths = [directory / f"{case}_w.bp", directory / f"{case}_theta.bp"]
    for path, funcs in ((paths[0], fields), (paths[1], [theta])):
        with dolfinx.io.VTXWriter(problem.comm, path, funcs, engine="BP4") as writer:
            writer.write(0.0)
    return paths
