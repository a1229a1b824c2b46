"""Obstacles (rigid or foundations), point restraints, the load and the design data."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.geometry import (
    points_in_circle,
    points_in_polygon,
)
from unibuckle_fenicsx.spec.plate import (
    Circle,
    PlateSpec,
    Polygon,
)
from unibuckle_fenicsx.spec.values import (
    POINT_KINDS,
    SIDES,
    UNITS,
    Box,
    Predicate,
    Temperature,
    _box,
    _choice,
    _number,
    _pair,
    _temperature,
    temperature_field,
)


@dataclass(frozen=True)
class ObstacleSpec:
    r"""Rigid flat obstacle, or Winkler foundation, on one side of the plate over a zone.

    With ``side = "above"`` the deflection must satisfy w <= 0 at every mesh node of the
    closed zone; with ``"below"``, w >= 0. With a ``foundation_stiffness`` :math:`k_f`
    the obstacle is a tensionless (compression-only) Winkler foundation instead: the
    plate may press into it, against a pressure :math:`k_f w` (above; :math:`-k_f w`
    below), and lift off it freely; :math:`k_f \to \infty` is the rigid obstacle.
    ``side = "both"`` is then a bilateral foundation (springs in tension too).

    Args:
        zone: ``"all"`` (the whole closed plate), a box ``((xmin, xmax), (ymin, ymax))``,
            a :class:`Polygon`, a :class:`Circle`, or a predicate ``f(x) -> bool array``
            on coordinates of shape (3, n).
        tolerance: Geometric tolerance (m) for a node to count as inside a box, polygon
            or circle; ``None`` uses 1e-8 times the plate size.
        side: One of :data:`SIDES`: where the obstacle lies (w, the deflection, is
            positive towards "above"); "both" only with a foundation.
        foundation_stiffness: Winkler modulus :math:`k_f` (N/m^3, Pa/m), > 0; ``None``
            for a rigid obstacle. The springs are lumped at the zone's nodes: node k
            carries :math:`k_f \int \varphi_k\,dx` (its tributary area).
        gap: Clearance g (m) >= 0 between the flat plate and a rigid obstacle: w <= g
            (above), w >= -g (below). The nonlinear analysis follows the plate onto it;
            the linear critical state ignores an obstacle with a gap (an infinitesimal
            buckle does not reach it).
    """

    zone: Literal["all"] | Box | Polygon | Circle | Predicate = "all"
    tolerance: float | None = None
    side: str = "above"
    foundation_stiffness: float | None = None
    gap: float = 0.0

    def __post_init__(self) -> None:
        if isinstance(self.zone, str):
            if self.zone != "all":
                raise InputError(
                    f'obstacle.zone must be "all", [[xmin, xmax], [ymin, ymax]] or a '
                    f"callable, got {self.zone!r}"
                )
        elif isinstance(self.zone, Polygon | Circle):
            pass
        elif not callable(self.zone):
            object.__setattr__(self, "zone", _box("obstacle.zone", self.zone))
        if self.tolerance is not None and not _number("obstacle.tolerance", self.tolerance) >= 0:
            raise InputError(f"obstacle.tolerance must be >= 0 m, got {self.tolerance!r}")
        if self.foundation_stiffness is not None:
            if not _number("obstacle.foundation_stiffness", self.foundation_stiffness) > 0.0:
                raise InputError(
                    "obstacle.foundation_stiffness (Winkler modulus) must be > 0 N/m^3, got "
                    f"{self.foundation_stiffness!r}; leave it out for a rigid obstacle"
                )
            object.__setattr__(self, "foundation_stiffness", float(self.foundation_stiffness))
        if self.side == "both" and self.foundation_stiffness is None:
            raise InputError(
                'obstacle.side = "both": a rigid obstacle on both sides of the plate is a '
                "bilateral support (w = 0 in the zone), not an obstacle; give an edge its "
                '[edges.NAME] support (e.g. support = "simply_supported"), or one side '
                '("above" or "below"); "both" is for a foundation (foundation_stiffness)'
            )
        _choice("obstacle.side", self.side, SIDES)
        gap = _number("obstacle.gap", self.gap)
        if not gap >= 0.0:
            raise InputError(f"obstacle.gap must be >= 0 m, got {gap!r}")
        if gap and self.foundation_stiffness is not None:
            raise InputError(
                "obstacle.gap: a gap is modelled for rigid obstacles only, not for a "
                "foundation (foundation_stiffness)"
            )
        object.__setattr__(self, "gap", gap)

    @property
    def sign(self) -> float:
        """+1 for an obstacle above (w <= 0 admissible), -1 below (w >= 0), 0 for both."""
        return {"above": 1.0, "below": -1.0}.get(self.side, 0.0)

    @property
    def kind(self) -> str:
        """Kind: "rigid", "tensionless" (one-sided foundation) or "bilateral" (foundation)."""
        if self.foundation_stiffness is None:
            return "rigid"
        return "bilateral" if self.side == "both" else "tensionless"

    @property
    def zone_key(self) -> str:
        """The problem file's key of the zone: "zone", "polygon" or "circle"."""
        if isinstance(self.zone, Polygon):
            return "polygon"
        if isinstance(self.zone, Circle):
            return "circle"
        return "zone"

    def describe(self) -> str:
        """Short human-readable description of the zone."""
        if isinstance(self.zone, str):
            return "whole plate"
        if isinstance(self.zone, Polygon):
            return f"polygon of {len(self.zone.vertices)} vertices"
        if isinstance(self.zone, Circle):
            (cx, cy), r = self.zone.center, self.zone.radius
            return f"circle about ({cx:g}, {cy:g}) of radius {r:g}"
        if callable(self.zone):
            return f"predicate {getattr(self.zone, '__name__', 'zone')}"
        (x0, x1), (y0, y1) = self.zone
        return f"[{x0:g}, {x1:g}] x [{y0:g}, {y1:g}]"

    def contains(self, x: npt.NDArray[np.float64], size: float) -> npt.NDArray[np.bool_]:
        """Mask of the points ``x`` (shape (3, n)) in the closed zone.

        Args:
            x: Point coordinates, shape (3, n).
            size: Plate size, scales the default tolerance.
        """
        if isinstance(self.zone, str):
            return np.ones(x.shape[1], dtype=bool)
        tol = 1e-8 * size if self.tolerance is None else self.tolerance
        if isinstance(self.zone, Polygon):
            return points_in_polygon(x[:2].T, self.zone.vertices, tol)
        if isinstance(self.zone, Circle):
            return points_in_circle(x[:2].T, self.zone.center, self.zone.radius, tol)
        if callable(self.zone):
            return np.asarray(self.zone(x), dtype=bool)
        (x0, x1), (y0, y1) = self.zone
        return (x[0] >= x0 - tol) & (x[0] <= x1 + tol) & (x[1] >= y0 - tol) & (x[1] <= y1 + tol)

    def same_zone(self, other: ObstacleSpec) -> bool:
        """Whether ``other`` has the same zone (a predicate only when it is the same one)."""
        return self.zone is other.zone or (not callable(self.zone) and self.zone == other.zone)


@dataclass(frozen=True)
class LoadSpec:
    r"""The load besides the edge stresses: temperature rises, scaled and fixed.

    The prestress is :math:`N = N_{fixed} + \lambda N_{scaled}`: the scaled part is the
    edges' ``normal_stress`` and ``shear_stress`` (per unit load) with ``temperature``;
    the fixed part, applied as is, the edges' ``fixed_normal_stress`` and
    ``fixed_shear_stress`` (Pa) with ``fixed_temperature``, times ``fixed_factor``. A
    temperature rise :math:`\Delta T` gives the free thermal strain
    :math:`\alpha\Delta T I` (``[material] thermal_expansion``), which the edges'
    in-plane conditions turn into a prestress. The buckling pencil is
    :math:`(A - B_{fixed}, B_{scaled})`.

    Args:
        temperature: The rise per unit load factor: a number (K, uniform) or
            ``(T0, dTdx, dTdy)``, the linear field :math:`T_0 + T_{,x} x + T_{,y} y` (K, K/m).
        fixed_temperature: A rise applied as is, the same forms.
        fixed_factor: A factor on the whole fixed part (the fixed edge stresses and
            ``fixed_temperature``), 1 by default: a sweep over it draws an interaction
            curve with one ``--vary``; 0 switches the fixed part off.
    """

    temperature: Temperature = 0.0
    fixed_temperature: Temperature = 0.0
    fixed_factor: float = 1.0

    def __post_init__(self) -> None:
        for name in ("temperature", "fixed_temperature"):
            object.__setattr__(self, name, _temperature(f"load.{name}", getattr(self, name)))
        object.__setattr__(self, "fixed_factor", _number("load.fixed_factor", self.fixed_factor))

    @property
    def thermal(self) -> bool:
        """Whether the scaled part has a temperature rise."""
        return any(temperature_field(self.temperature))

    @property
    def fixed_thermal(self) -> bool:
        """Whether the fixed part has a temperature rise."""
        return any(temperature_field(self.fixed_temperature))


@dataclass(frozen=True)
class DesignSpec:
    r"""Design output by EN 1993-1-5 (:mod:`~unibuckle_fenicsx.design`).

    Args:
        yield_stress: :math:`f_y` (Pa), > 0.
        partial_factor: :math:`\gamma_{M1}`, > 0 (1.0, the recommended value of
            EN 1993-1-1, 6.1).
    """

    yield_stress: float
    partial_factor: float = 1.0

    def __post_init__(self) -> None:
        for name, unit in (("yield_stress", " Pa"), ("partial_factor", "")):
            value = _number(f"design.{name}", getattr(self, name))
            if not value > 0.0:
                raise InputError(f"design.{name} must be > 0{unit}, got {value!r}")
            object.__setattr__(self, name, value)


@dataclass(frozen=True)
class PointSpec:
    r"""Point restraints: one point, or a grid of them (bolts, tie bars, studs).

    Each point acts on the mesh node nearest to it (the snap distance is reported).

    Args:
        at: One point (x, y) (m); or None for a grid.
        spacing: The grid's spacing (sx, sy) (m), > 0 (a number: the same in x and y).
        offset: A point of the grid (m); default the region's lower-left corner.
        region: The box ((xmin, xmax), (ymin, ymax)) (m) holding the grid's points (a
            degenerate side gives a line); default the plate's bounding box. Points
            outside the plate (or in a hole) are left out.
        kind: One of :data:`POINT_KINDS`: "bilateral" (w = 0), "one-sided" (the
            obstacle's cone at the point: w <= 0 with ``side`` "above", w >= 0
            "below"), "spring" (a spring of ``stiffness`` N/m to w = 0).
        stiffness: The spring's stiffness (N/m), > 0, for ``kind = "spring"`` only.
        side: "above" (w <= 0 at the point) or "below" (w >= 0), for ``kind =
            "one-sided"`` only, where it is required: the side decides which half of the
            plate's deflections the point forbids, and no default is sound for both a
            stud under the plate and a bolt head over it.
    """

    at: tuple[float, float] | None = None
    spacing: tuple[float, float] | None = None
    offset: tuple[float, float] | None = None
    region: Box | None = None
    kind: str = "bilateral"
    stiffness: float | None = None
    side: str | None = None

    def __post_init__(self) -> None:
        where = "points"
        _choice(f"{where}.kind", self.kind, POINT_KINDS)
        if (self.at is None) == (self.spacing is None):
            raise InputError(
                "[[points]] needs at = [x, y] (one point) or spacing = s or [sx, sy] (a "
                "grid, with optional offset and region): exactly one of them"
            )
        if self.at is not None:
            object.__setattr__(self, "at", _pair(f"{where}.at", self.at))
            for name in ("offset", "region"):
                if getattr(self, name) is not None:
                    raise InputError(f"{where}.{name} belongs to a grid (spacing), not to at")
        else:
            spacing: Any = self.spacing
            if not isinstance(spacing, list | tuple):
                spacing = (spacing, spacing)
            pair = _pair(f"{where}.spacing", spacing)
            if min(pair) <= 0.0:
                raise InputError(f"{where}.spacing must be > 0 m, got {self.spacing!r}")
            object.__setattr__(self, "spacing", pair)
            if self.offset is not None:
                object.__setattr__(self, "offset", _pair(f"{where}.offset", self.offset))
            if self.region is not None:
                object.__setattr__(self, "region", _box(f"{where}.region", self.region))
        if self.kind == "spring":
            if self.stiffness is None or not _number(f"{where}.stiffness", self.stiffness) > 0:
                raise InputError(
                    f'{where}.stiffness: kind = "spring" needs a stiffness > 0 N/m, got '
                    f"{self.stiffness!r}"
                )
            object.__setattr__(self, "stiffness", float(self.stiffness))
        elif self.stiffness is not None:
            raise InputError(f'{where}.stiffness belongs to kind = "spring", not "{self.kind}"')
        if self.kind == "one-sided" and self.side is None:
            raise InputError(
                f'{where}.side: kind = "one-sided" needs side = "above" (the point holds the '
                'plate from above: w <= 0) or "below" (from below: w >= 0)'
            )
        if self.side is not None:
            _choice(f"{where}.side", self.side, ("above", "below"))
            if self.kind != "one-sided":
                raise InputError(f'{where}.side belongs to kind = "one-sided", not "{self.kind}"')

    @property
    def sign(self) -> float:
        """+1 for a one-sided point above (w <= 0 admissible), -1 below, 0 for other kinds."""
        return {"above": 1.0, "below": -1.0}.get(self.side or "", 0.0)

    def locations(self, plate: PlateSpec) -> npt.NDArray[np.float64]:
        """The points (n, 2) (m): ``at``, or the grid's points inside the plate.

        Raises:
            ValueError: ``at`` outside the plate, or a grid with no point in it.
        """
        size = max(plate.length, plate.width)
        tol = 1e-9 * size
        if self.at is not None:
            points = np.array([self.at])
        else:
            assert self.spacing is not None
            region = (
                self.region if self.region is not None else tuple(zip(*plate.corners, strict=True))
            )
            offset = self.offset if self.offset is not None else (region[0][0], region[1][0])
            axes = []
            for (lo, hi), step, start in zip(region, self.spacing, offset, strict=True):
                first = math.ceil((lo - start - tol) / step)
                last = math.floor((hi - start + tol) / step)
                if last - first > 100_000:
                    raise InputError(
                        f"points.spacing {self.spacing} gives more than 100000 points per row"
                    )
                axes.append(start + step * np.arange(first, last + 1))
            gx, gy = np.meshgrid(*axes, indexing="ij")
            points = np.column_stack([gx.ravel(), gy.ravel()])
        inside = plate.contains(points, tol) if plate.file is None else np.ones(len(points), bool)
        if self.at is not None and not inside.all():
            raise InputError(f"points.at {list(self.at)} lies outside the plate (or in a hole)")
        points = points[inside]
        if not len(points):
            raise InputError(
                f"points: the grid of spacing {list(self.spacing or ())} holds no point of "
                "the plate; check spacing, offset and region"
            )
        return points

    def describe(self, units: str = "SI") -> str:
        """Short description (for messages and the summary), in ``units`` (:data:`UNITS`)."""
        metres = UNITS[units][0]  # metres per length unit
        length = "m" if metres == 1.0 else "mm"
        what = self.kind
        if self.kind == "spring":
            what = f"spring {self.stiffness * metres:g} N/{length}"  # type: ignore[operator]
        if self.kind == "one-sided":
            what += f" ({self.side})"
        if self.at is not None:
            return f"{what} at ({self.at[0] / metres:g}, {self.at[1] / metres:g}) {length}"
        assert self.spacing is not None
        sx, sy = (v / metres for v in self.spacing)
        return f"{what} grid of spacing {sx:g} x {sy:g} {length}"
