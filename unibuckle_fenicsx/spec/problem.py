"""The whole problem, and its rules between tables."""

from __future__ import annotations

import math
from typing import Any, ClassVar, Literal

import msgspec
from msgspec.structs import force_setattr, replace

from unibuckle_fenicsx.en1993 import (
    check_steel_modulus,
    check_steel_yield_stress,
    design_element,
)
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.spec.base import UNITS, Table, in_file, stress_ends
from unibuckle_fenicsx.spec.checks import check_features, check_supports
from unibuckle_fenicsx.spec.material import Material
from unibuckle_fenicsx.spec.obstacles import DesignSpec, LoadSpec, ObstacleSpec, PointSpec
from unibuckle_fenicsx.spec.plate import MeshSpec, PlateSpec
from unibuckle_fenicsx.spec.solver import SolverSpec

#: Largest non-dimensional stiffness :math:`K = k_f b^4/(\pi^4 D)` of a tensionless
#: foundation: the largest verified (docs/verification/stiff_foundations.md). Below it the
#: spring-set iteration holds the nodes its stiff springs press by their force; above it
#: no answer is verified. The rigid obstacle's load bounds every foundation's from above.
MAX_FOUNDATION_K = 1e12


def _paper_material() -> Material:
    return Material(E=1.0e9, nu=0.3)


class ProblemSpec(Table, frozen=True):
    """A complete unilateral buckling problem (in SI units): a problem file.

    Args:
        name: Label used in output (a file's stem when it gives none).
        units: The unit system the file is written in and results are printed in (one
            of :data:`UNITS`; the numbers here are SI whatever it is).
        plate: Geometry, thickness and edge conditions.
        material: Elastic constants; the paper's E = 1 GPa, nu = 0.3 by default.
        mesh: Mesh resolution.
        solver: Solver options.
        obstacle: Obstacle zone, or ``None`` for the free (bilateral) plate.
        obstacles: Several obstacles (the file's ``[[obstacles]]`` tables), instead of
            ``obstacle``; their constrained nodes are the union of their zones'.
        points: Point restraints (the file's ``[[points]]`` tables).
        load: Temperature rises, scaled and fixed (the ``[load]`` table).
        design: The EN 1993-1-5 design output's data (``[design]``), or None.
    """

    KEY: ClassVar[str] = ""
    FILE_ONLY: ClassVar[tuple[str, ...]] = ("edges",)
    name: str = "plate"
    units: Literal["SI", "mm-N-MPa"] = "SI"
    plate: PlateSpec = msgspec.field(default_factory=PlateSpec)
    material: Material = msgspec.field(default_factory=_paper_material)
    mesh: MeshSpec = msgspec.field(default_factory=MeshSpec)
    solver: SolverSpec = msgspec.field(default_factory=SolverSpec)
    obstacle: ObstacleSpec | None = None
    obstacles: tuple[ObstacleSpec, ...] = ()
    points: tuple[PointSpec, ...] = ()
    load: LoadSpec = msgspec.field(default_factory=LoadSpec)
    design: DesignSpec | None = None

    def check(self) -> None:
        """The rules between this table's fields."""
        self._check_mesh()
        if self.obstacle is not None and self.obstacles:
            raise InputError("give one [obstacle] table or several [[obstacles]] tables, not both")
        if self.material.plies:
            total = sum(ply.thickness for ply in self.material.plies)
            if not math.isclose(self.plate.thickness, total, rel_tol=1e-9):
                (t, name), (sum_t, _) = in_file(self.plate.thickness, "m"), in_file(total, "m")
                raise InputError(
                    f"plate.thickness = {t!r} {name} differs from the plies' "
                    f"total {sum_t!r} {name}: leave plate.thickness out for a laminate (it is the "
                    "plies')"
                )
        self._check_load()
        self._check_design()
        if self.plate.file is None:  # a file's extent is known once meshed
            for k, point in enumerate(self.points):
                try:
                    point.locations(self.plate)
                except InputError as err:
                    raise InputError(f"points[{k}]{str(err)[len('points') :]}") from None
        check_supports(self.plate, bool(self.bilateral_foundations))
        self._check_obstacles()

    def _check_mesh(self) -> None:
        """A rectangle's cells from a cell size; gmsh's plates need one (not a .msh)."""
        plate, size = self.plate, self.mesh.size
        if not plate.meshed_by_gmsh:
            if size is not None:
                cells = MeshSpec.cells_for(plate.length, plate.width, size)
                force_setattr(self, "mesh", MeshSpec(*cells, size))
            return
        msh = plate.file is not None and plate.file.lower().endswith(".msh")
        if size is None and plate.file is None:
            raise InputError(
                "mesh.size: a plate meshed by gmsh (outline or holes) needs [mesh] size = h, "
                "the characteristic cell size (m)"
            )
        if msh and size:
            raise InputError("mesh.size: a .msh file is meshed already; leave size out")
        check_features(plate, size)

    def _check_foundation_stiffness(self) -> None:
        r"""A tensionless foundation's :math:`K = k_f b^4/(\pi^4 D)`: at most 1e12.

        b is :attr:`~unibuckle_fenicsx.spec.plate.PlateSpec.narrowest`, the width of the
        thickness rules: a rotated rectangle's smaller side, not its bounding box's, which
        would refuse the same plate turned at a smaller K (:math:`b^4` of a wider box).
        """
        plate = self.plate
        if plate.file is not None:  # its sides are known once meshed
            return
        b, side_name = plate.narrowest
        D = self.material.E * plate.thickness**3 / 12.0
        for k, o in enumerate(self.all_obstacles):
            if o.kind != "tensionless" or o.foundation_stiffness is None:
                continue
            K = o.foundation_stiffness * b**4 / (math.pi**4 * D)
            if K > MAX_FOUNDATION_K:
                (kf, high), name = in_file(
                    [o.foundation_stiffness, MAX_FOUNDATION_K * math.pi**4 * D / b**4], "N/m^3"
                )
                raise InputError(
                    f"{self.obstacle_label(k)}.foundation_stiffness = {kf:g} {name} is "
                    f"K = k_f b^4/(pi^4 D) = {K:.3g} times the plate's bending stiffness "
                    f"(D = E t^3/12, b {side_name}): a tensionless foundation needs "
                    f"K <= {MAX_FOUNDATION_K:g}, foundation_stiffness <= {high:.3g} {name} "
                    "here (the largest verified). The rigid obstacle's load is an upper "
                    "bound of the foundation's at any stiffness, and the gap to it falls as "
                    "1/K (the documentation's 'Stiff tensionless foundations'): leave "
                    "foundation_stiffness out for that bound (a rigid obstacle)"
                )

    def _check_obstacles(self) -> None:
        """Obstacles of one kind, their method, no zone on both sides, points they allow."""
        found = self.all_obstacles
        kinds = {o.kind for o in found}
        self._check_foundation_stiffness()
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
                if first.same_zone(second) and {first.side, second.side} == {"above", "below"}:
                    label = f"{self.obstacle_label(j)} and {self.obstacle_label(k)}"
                    raise InputError(
                        f"{label} give the same foundation zone on both sides of the plate: "
                        'write it once with side = "both" (a bilateral foundation)'
                        if first.kind == second.kind == "tensionless"
                        else f"{label} give the same zone on both sides of the plate: that is "
                        "a bilateral support (w = 0 there), not an obstacle; give an edge its "
                        '[edges.NAME] support (e.g. support = "simply_supported"), or keep '
                        "one side"
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
        (:func:`~unibuckle_fenicsx.en1993.design_element` says which, or refuses), of steel
        (not a laminate, nor another metal: :meth:`_check_steel`).
        """
        if self.design is None:
            return
        if self.material.plies:
            raise InputError(
                "design: material.plies gives a laminate, and EN 1993-1-5 (Eurocode 3) "
                "describes steel plates: its reduction factor rho (4.4(2)) is calibrated on "
                "steel plates' imperfections and residual stresses; leave [design] out"
            )
        factor = self.load.fixed_factor  # the fixed part as applied
        compressed = any(
            min(
                *stress_ends(e.normal_stress),
                *(factor * f for f in stress_ends(e.fixed_normal_stress)),
            )
            < 0.0
            for e in self.plate.edges
        )
        if not compressed:
            raise InputError(
                "design: the EN 1993-1-5 output takes sigma_cr as a compressive normal edge "
                "stress, and this load has none (give a loaded edge normal_stress < 0)"
            )
        design_element(self)
        self._check_steel()

    def _check_steel(self) -> None:
        """Refuse a general stiffness, or a Young's modulus or yield stress not a steel's.

        EN 1993-1-5 describes isotropic steel plates
        (:func:`~unibuckle_fenicsx.en1993.check_steel_modulus`).
        """
        _, stress, name = UNITS[self.units]
        general = [
            key
            for key, value in (
                ("membrane_voigt", self.material.membrane_voigt),
                ("bending_voigt", self.material.bending_voigt),
            )
            if value is not None
        ]
        if general:
            raise InputError(
                f"design: material.{general[0]} gives a general stiffness, and EN 1993-1-5 "
                "(Eurocode 3) describes isotropic steel plates; leave [design] out"
            )
        check_steel_modulus(self.material.E, stress, name)
        if self.design is not None:
            check_steel_yield_stress(self.design.yield_stress, stress, name)

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
    def all_obstacles(self) -> tuple[ObstacleSpec, ...]:
        """Every obstacle: ``(obstacle,)`` or ``obstacles`` (empty for the free plate)."""
        return (self.obstacle,) if self.obstacle is not None else self.obstacles

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
