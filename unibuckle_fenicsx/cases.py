"""The paper's test problem (Ayadi, section 6) as data."""

from __future__ import annotations

from unibuckle_fenicsx.config import (
    Material,
    MeshSpec,
    ObstacleSpec,
    PlateSpec,
    ProblemSpec,
    SolverSpec,
)

__all__ = ["CASES", "paper_case"]

#: Obstacle zone of each case; ``None`` is the free plate.
CASES: dict[str, ObstacleSpec | None] = {
    "free": None,
    "c1": ObstacleSpec(zone=((-0.04, 0.04), (-0.05, 0.05))),
    "c2": ObstacleSpec(zone=((-0.04, 0.04), (-0.02, 0.02))),
    "c3": ObstacleSpec(zone="all"),
}


def paper_case(
    name: str, nx: int = 20, ny: int = 20, solver: SolverSpec | None = None
) -> ProblemSpec:
    """The paper's plate with obstacle case ``name`` (one of :data:`CASES`).

    Plate ]-0.1, 0.1[ x ]-0.05, 0.05[ m, t = 0.006 m, E = 1e9 Pa, nu = 0.3, simply
    supported (hard) on the whole edge, unit compression on the short edges x = +-0.1,
    free lateral expansion. Default mesh: the paper's 20 x 20 quadrilaterals.
    """
    if name not in CASES:
        raise ValueError(f"case must be one of {list(CASES)}, got {name!r}")
    return ProblemSpec(
        name=name,
        plate=PlateSpec(),
        material=Material(E=1.0e9, nu=0.3),
        mesh=MeshSpec(nx, ny),
        obstacle=CASES[name],
        solver=solver if solver is not None else SolverSpec(),
    )
