"""The solver options and the whole problem (with the edge-load rule)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.spec.checks import check_features, check_supports, design_element
from unibuckle_fenicsx.spec.material import Material
from unibuckle_fenicsx.spec.obstacles import DesignSpec, LoadSpec, ObstacleSpec, PointSpec
from unibuckle_fenicsx.spec.plate import (
    MeshSpec,
    PlateSpec,
)
from unibuckle_fenicsx.spec.values import (
    METHODS,
    UNITS,
    _boolean,
    _choice,
    _integer,
    _number,
    stress_ends,
)


@dataclass(frozen=True)
class SolverSpec:
    """Solver options.

    Args:
        method: One of :data:`METHODS`; "auto" enumerates (with ``until_proven``) when
            the candidate count 2^i is at most ``max_candidates`` and the estimated
            enumeration time is within ``enumeration_budget_s``; otherwise it runs the
            nested interior-point method on thin plates (thickness below
            :data:`~unibuckle_fenicsx.algorithms.chain.THIN_PLATE` of the shorter side)
            and the multilevel active-set method on the others.
        tau: Relative feasibility/contact tolerance :doc:`/methods/problem`, in (0, 1e-2].
        eps_tol: SLEPc convergence tolerance, in (0, 1e-4].
        max_candidates: Largest candidate count the enumeration accepts, >= 1.
        enumeration_budget_s: "auto" enumerates only if the estimate (2^i times the
            time of one eigen solve) is at most this many seconds, > 0.
        complete: Enumerate every subset instead of stopping after the first
            feasible size p (to check the paper's monotonicity).
        until_proven: Enumerate past the paper's stopping size p* until the
            interlacing bound proves the best feasible set optimal (exact; the
            paper's rule is not, see :doc:`/methods/enumeration`).
        max_iterations: Active-set iterates per seed and mesh level, >= 1 (the feasible
            descent, the chain's last link, may use as many solves again).
        bound_budget: Eigen solves allowed for the active set's lattice lower bound,
            >= 0 (it runs when the budget covers the i singletons).
        certify: Verify the result's global optimality (:doc:`/methods/certificates`);
            off for speed studies.
        bracket: Also try the low-rank verified bracket when two or more pencil
            eigenvalues lie below the load (:doc:`/methods/certificates`): tens of
            free solves' time on a thin plate of 90x30 cells, so off by default.
        penalty: Penalty stiffness rho for ``method="penalty"`` (relative to the
            largest diagonal entry of A), > 0.
        prestress_degree: Lagrange degree of the in-plane displacement, >= 1.
        shear: "mitc" (MacNeal/MITC4, locking-free) or "full" (plain full
            integration, locks; for comparison only).
    """

    method: str = "auto"
    tau: float = 1e-8
    eps_tol: float = 1e-10
    max_candidates: int = 100_000
    enumeration_budget_s: float = 60.0
    complete: bool = False
    until_proven: bool = False
    max_iterations: int = 100
    bound_budget: int = 64
    certify: bool = True
    bracket: bool = False
    penalty: float = 1e3
    prestress_degree: int = 1
    shear: str = "mitc"

    def __post_init__(self) -> None:
        _choice("solver.method", self.method, METHODS)
        _choice("solver.shear", self.shear, ("mitc", "full"))
        if not 0.0 < _number("solver.tau", self.tau) <= 1e-2:
            raise InputError(f"solver.tau must lie in (0, 1e-2], got {self.tau!r}")
        if not 0.0 < _number("solver.eps_tol", self.eps_tol) <= 1e-4:
            raise InputError(f"solver.eps_tol must lie in (0, 1e-4], got {self.eps_tol!r}")
        if not _number("solver.enumeration_budget_s", self.enumeration_budget_s) > 0.0:
            raise InputError(
                f"solver.enumeration_budget_s must be > 0 s, got {self.enumeration_budget_s!r}"
            )
        if not _number("solver.penalty", self.penalty) > 0.0:
            raise InputError(f"solver.penalty must be > 0, got {self.penalty!r}")
        for name, minimum in (
            ("max_candidates", 1),
            ("max_iterations", 1),
            ("bound_budget", 0),
            ("prestress_degree", 1),
        ):
            object.__setattr__(self, name, _integer(f"solver.{name}", getattr(self, name), minimum))
        for name in ("complete", "until_proven", "certify", "bracket"):
            object.__setattr__(self, name, _boolean(f"solver.{name}", getattr(self, name)))
        for name in ("tau", "eps_tol", "enumeration_budget_s", "penalty"):
            object.__setattr__(self, name, float(getattr(self, name)))


@dataclass(frozen=True)
class ProblemSpec:
    """A complete unilateral buckling problem (in SI units).

    Args:
        name: Label used in output.
        plate: Geometry, thickness and edge conditions.
        material: Elastic constants.
        mesh: Mesh resolution.
        obstacle: Obstacle zone, or ``None`` for the free (bilateral) plate.
        solver: Solver options.
        units: The unit system results are printed in (one of :data:`UNITS`; the
            numbers here are SI whatever it is).
        obstacles: Several obstacles (the file's ``[[obstacles]]`` tables), instead of
            ``obstacle``; their constrained nodes are the union of their zones'.
        points: Point restraints (the file's ``[[points]]`` tables).
        load: Temperature rises, scaled and fixed (the ``[load]`` table).
        design: The EN 1993-1-5 design output's data (``[design]``), or None.
    """

    name: str = "plate"
    plate: PlateSpec = field(default_factory=PlateSpec)
    material: Material = field(default_factory=lambda: Material(E=1.0e9, nu=0.3))
    mesh: MeshSpec = field(default_factory=MeshSpec)
    obstacle: ObstacleSpec | None = None
    solver: SolverSpec = field(default_factory=SolverSpec)
    units: str = "SI"
    obstacles: tuple[ObstacleSpec, ...] = ()
    points: tuple[PointSpec, ...] = ()
    load: LoadSpec = field(default_factory=LoadSpec)
    design: DesignSpec | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise InputError(f"name must be a string, got {self.name!r}")
        _choice("units", self.units, tuple(UNITS))
        object.__setattr__(self, "obstacles", tuple(self.obstacles))
        plate = self.plate
        if plate.meshed_by_gmsh and self.mesh.size is None:
            if plate.file is None:
                raise InputError(
                    "mesh.size: a plate meshed by gmsh (outline or holes) needs [mesh] size = "
                    "h, the characteristic cell size (m)"
                )
        if plate.file is not None and plate.file.lower().endswith(".msh") and self.mesh.size:
            raise InputError("mesh.size: a .msh file is meshed already; leave size out")
        if plate.meshed_by_gmsh:
            check_features(plate, self.mesh.size)
        if self.obstacle is not None and self.obstacles:
            raise InputError("give one [obstacle] table or several [[obstacles]] tables, not both")
        for k, o in enumerate(self.obstacles):
            if not isinstance(o, ObstacleSpec):
                raise InputError(f"obstacles[{k}] must be an ObstacleSpec, got {o!r}")
        if self.material.plies:
            total = sum(ply.thickness for ply in self.material.plies)
            if not math.isclose(plate.thickness, total, rel_tol=1e-9):
                raise InputError(
                    f"plate.thickness = {plate.thickness!r} m differs from the plies' total "
                    f"{total!r} m"
                )
        self._check_load()
        self._check_design()
        object.__setattr__(self, "points", tuple(self.points))
        for k, point in enumerate(self.points):
            if not isinstance(point, PointSpec):
                raise InputError(f"points[{k}] must be a PointSpec, got {point!r}")
            if plate.file is not None:
                continue  # the plate's extent is known once the file is meshed
            try:
                point.locations(plate)
            except ValueError as err:
                raise InputError(f"points[{k}]{str(err)[len('points') :]}") from None
        found = self.all_obstacles
        check_supports(self)
        kinds = {o.kind for o in found}
        if self.one_sided_points and "tensionless" in kinds:
            raise InputError(
                'points: one-sided points (kind = "one-sided") join a rigid obstacle\'s cone; '
                'with a tensionless foundation give them a stiffness (kind = "spring") or '
                "make the foundation rigid"
            )
        if {"rigid", "tensionless"} <= kinds:
            raise InputError(
                "rigid obstacles and tensionless foundations in one problem are not "
                "supported: give every one-sided obstacle a foundation_stiffness, or none "
                '(a bilateral foundation, side = "both", goes with either)'
            )
        if "tensionless" in kinds and self.solver.method != "auto":
            raise InputError(
                f'solver.method = "{self.solver.method}": a tensionless foundation is solved '
                'by its own spring-set iteration; use method = "auto"'
            )
        for j, first in enumerate(found):
            for k in range(j + 1, len(found)):
                second = found[k]
                if not (
                    first.same_zone(second) and {first.side, second.side} == {"above", "below"}
                ):
                    continue
                label = f"{self.obstacle_label(j)} and {self.obstacle_label(k)}"
                if first.kind == second.kind == "tensionless":
                    raise InputError(
                        f"{label} give the same foundation zone on both sides of the plate: "
                        'write it once with side = "both" (a bilateral foundation)'
                    )
                raise InputError(
                    f"{label} give the same zone on both sides of the plate: that is a "
                    "bilateral support (w = 0 there), not an obstacle; give an edge its "
                    '[edges.NAME] support (e.g. support = "simply_supported"), or keep one '
                    "side"
                )

    def _check_load(self) -> None:
        """Temperatures need a thermal expansion and an edge held in its plane."""
        load = self.load
        if (load.thermal or load.fixed_thermal) and not self.material.thermal_expansion:
            which = "load.temperature" if load.thermal else "load.fixed_temperature"
            raise InputError(
                f"{which}: a temperature rise needs [material] thermal_expansion > 0 (1/K)"
            )
        held = any(e.inplane != "free" for e in self.plate.edges)
        for name, on in (("temperature", load.thermal), ("fixed_temperature", load.fixed_thermal)):
            if on and not held:
                raise InputError(
                    f"load.{name}: the temperature rise leaves the plate stress-free (a "
                    "uniform or linear rise expands a plate free in its plane without "
                    'stress): hold an edge in its plane (inplane = "clamped" or "roller")'
                )

    def _check_design(self) -> None:
        """The design output needs a compressive normal edge stress (its sigma_cr).

        And a plate that EN 1993-1-5 4.4 describes: an internal or an outstand element
        (:func:`~unibuckle_fenicsx.spec.checks.design_element` says which, or refuses).
        """
        if self.design is None:
            return
        if not isinstance(self.design, DesignSpec):
            raise InputError(f"design must be a DesignSpec, got {self.design!r}")
        compressed = any(
            min(*stress_ends(e.normal_stress), *stress_ends(e.fixed_normal_stress)) < 0.0
            for e in self.plate.edges
        )
        if not compressed:
            raise InputError(
                "design: the EN 1993-1-5 output takes sigma_cr as a compressive normal edge "
                "stress, and this load has none (give a loaded edge normal_stress < 0)"
            )
        design_element(self)

    def check_scaled_load(self) -> None:
        """Refuse a problem with nothing for lambda to scale (a fixed part alone)."""
        if not self.load.thermal and not self.plate.loaded:
            raise InputError(
                "no load to scale: give an edge a non-zero normal_stress or shear_stress (per "
                "unit load), or [load] temperature (a rise per unit load factor)"
                + (
                    "; the fixed part (fixed_normal_stress, fixed_shear_stress, "
                    "fixed_temperature) is applied as is, not scaled"
                    if self.has_fixed_load
                    else ""
                )
            )

    @property
    def has_fixed_load(self) -> bool:
        """Whether the load has a fixed part (edge stresses or a temperature rise)."""
        return bool(self.load.fixed_factor) and (self.plate.fixed_loaded or self.load.fixed_thermal)

    @property
    def one_sided_points(self) -> tuple[PointSpec, ...]:
        """The point restraints that join the obstacle's cone."""
        return tuple(p for p in self.points if p.kind == "one-sided")

    @property
    def unilateral_obstacles(self) -> tuple[ObstacleSpec, ...]:
        """The one-sided obstacles (rigid or tensionless foundations): the contact nodes'.

        Without those with a gap: an infinitesimal buckle does not reach them.
        """
        return tuple(o for o in self.all_obstacles if o.kind != "bilateral" and not o.gap)

    @property
    def gapped_obstacles(self) -> tuple[ObstacleSpec, ...]:
        """The obstacles with a gap (the nonlinear analysis' only)."""
        return tuple(o for o in self.all_obstacles if o.gap)

    @property
    def bilateral_foundations(self) -> tuple[ObstacleSpec, ...]:
        """The bilateral foundations (``side = "both"``): springs added to the stiffness."""
        return tuple(o for o in self.all_obstacles if o.kind == "bilateral")

    @property
    def tensionless(self) -> bool:
        """Whether the one-sided obstacles are tensionless foundations."""
        return any(o.kind == "tensionless" for o in self.all_obstacles)

    @property
    def all_obstacles(self) -> tuple[ObstacleSpec, ...]:
        """Every obstacle: ``(obstacle,)`` or ``obstacles`` (empty for the free plate)."""
        return (self.obstacle,) if self.obstacle is not None else self.obstacles

    def obstacle_label(self, k: int) -> str:
        """How the file names obstacle k of :attr:`all_obstacles` (for messages)."""
        return "obstacle" if self.obstacle is not None else f"obstacles[{k}]"

    def without_obstacles(self) -> ProblemSpec:
        """Copy of the free plate (no obstacle)."""
        return replace(self, obstacle=None, obstacles=())

    def with_mesh(self, nx: int, ny: int) -> ProblemSpec:
        """Copy with another mesh resolution (the structured rectangle only)."""
        if self.plate.meshed_by_gmsh:
            raise InputError(
                "nx, ny (--nx, --ny) set the structured rectangle's cells; a plate meshed by "
                "gmsh takes [mesh] size = h"
            )
        return replace(self, mesh=MeshSpec(nx, ny))

    def with_solver(self, **changes: Any) -> ProblemSpec:
        """Copy with changed solver options."""
        return replace(self, solver=replace(self.solver, **changes))

    @property
    def stress_unit(self) -> tuple[float, str]:
        """(pascals per unit, name) of the stress unit results are printed in."""
        _, stress, name = UNITS[self.units]
        return stress, name
