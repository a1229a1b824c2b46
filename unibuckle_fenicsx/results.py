"""BucklingResult: what a solve returns, its JSON form, and ParaView output."""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["BucklingResult", "write_json"]


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
        lower_bound_Pa / upper_bound_Pa: Optimality bracket.
        certificate: :class:`~unibuckle_fenicsx.problem.Certificate` as a dict.
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
