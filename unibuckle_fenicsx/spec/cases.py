"""The paper's test problem (Ayadi, section 6) as data, and rectangular plates in general."""

from __future__ import annotations

from collections.abc import Mapping

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.spec.material import Material
from unibuckle_fenicsx.spec.obstacles import ObstacleSpec
from unibuckle_fenicsx.spec.plate import EDGE_NAMES, EdgeSpec, MeshSpec, PlateSpec, Support
from unibuckle_fenicsx.spec.problem import ProblemSpec
from unibuckle_fenicsx.spec.solver import SolverSpec

__all__ = ["CASES", "LOADS", "paper_case", "plate_case"]

#: Edge stresses per unit load of the loads :func:`plate_case` knows, in
#: :data:`~unibuckle_fenicsx.spec.plate.EDGE_NAMES` order, as (normal, shear) pairs: uniaxial
#: compression along x; pure shear (a uniform sigma_xy = 1 state: the shear stress along
#: the counter-clockwise tangent is +1 on x = const and -1 on y = const); and both.
LOADS: dict[str, tuple[tuple[float, float], ...]] = {
    "uniaxial": ((-1.0, 0.0), (-1.0, 0.0), (0.0, 0.0), (0.0, 0.0)),
    "shear": ((0.0, 1.0), (0.0, 1.0), (0.0, -1.0), (0.0, -1.0)),
    "compression+shear": ((-1.0, 1.0), (-1.0, 1.0), (0.0, -1.0), (0.0, -1.0)),
}

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
        raise InputError(f"case must be one of {list(CASES)}, got {name!r}")
    return ProblemSpec(
        name=name,
        plate=PlateSpec(),
        material=Material(E=1.0e9, nu=0.3),
        mesh=MeshSpec(nx, ny),
        obstacle=CASES[name],
        solver=solver if solver is not None else SolverSpec(),
    )


def plate_case(
    name: str,
    *,
    length: float,
    width: float,
    thickness: float,
    supports: Support | Mapping[str, Support] = "simply_supported",
    load: str = "uniaxial",
    nx: int,
    ny: int,
    zone: ObstacleSpec | None = None,
    material: Material | None = None,
    solver: SolverSpec | None = None,
) -> ProblemSpec:
    """A rectangular plate [0, length] x [0, width] under one of :data:`LOADS`.

    Args:
        name: Label.
        length: Extent in x (m); the uniaxial load acts along x.
        width: Extent in y (m).
        thickness: t (m).
        supports: One support for every edge, or one per edge name (left, right, bottom,
            top; missing edges are simply supported).
        load: A key of :data:`LOADS`.
        nx: Cells along x.
        ny: Cells along y.
        zone: The obstacle (None: the free plate).
        material: Default: E = 1 GPa, nu = 0.3 (the paper's).
        solver: Default options.
    """
    if load not in LOADS:
        raise InputError(f"load must be one of {list(LOADS)}, got {load!r}")
    per_edge = dict.fromkeys(EDGE_NAMES, supports) if isinstance(supports, str) else dict(supports)
    unknown = set(per_edge) - set(EDGE_NAMES)
    if unknown:
        raise InputError(f"supports: unknown edge(s) {sorted(unknown)}; edges: {EDGE_NAMES}")
    edges = tuple(
        EdgeSpec(
            edge,
            support=per_edge.get(edge, "simply_supported"),
            normal_stress=normal,
            shear_stress=shear,
        )
        for edge, (normal, shear) in zip(EDGE_NAMES, LOADS[load], strict=True)
    )
    return ProblemSpec(
        name=name,
        plate=PlateSpec(corners=((0.0, 0.0), (length, width)), thickness=thickness, edges=edges),
        material=material if material is not None else Material(E=1.0e9, nu=0.3),
        mesh=MeshSpec(nx, ny),
        obstacle=zone,
        solver=solver if solver is not None else SolverSpec(),
    )
