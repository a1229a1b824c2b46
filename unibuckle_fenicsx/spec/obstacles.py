"""Obstacles (rigid or foundations), point restraints, the load and the design data."""

from __future__ import annotations

import math
import typing
from collections.abc import Callable
from typing import TYPE_CHECKING, Annotated, ClassVar, Literal

import numpy as np
import numpy.typing as npt
from msgspec import Meta
from msgspec.structs import force_setattr

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.geometry import points_in_circle, points_in_polygon
from unibuckle_fenicsx.spec.base import (
    UNITS,
    Box,
    Point,
    Table,
    Temperature,
    in_file,
    plain,
    temperature_field,
    unit,
    unit_name,
)
from unibuckle_fenicsx.spec.plate import Circle, PlateSpec, Polygon

Side = Literal["above", "below", "both"]
#: Sides of an obstacle: "above" (on the +w side: w <= 0 in its zone), "below" (w >= 0);
#: "both" only for a foundation (a bilateral Winkler foundation, springs everywhere).
SIDES: tuple[str, ...] = typing.get_args(Side)
Kind = Literal["bilateral", "one-sided", "spring"]
#: Kinds of point restraint: w = 0, the obstacle's cone at the point, or a spring.
POINT_KINDS: tuple[str, ...] = typing.get_args(Kind)
Predicate = Callable[[npt.NDArray[np.float64]], npt.NDArray[np.bool_]]
if TYPE_CHECKING:  # a predicate zone (code only); a grid's spacing once built: a pair
    Zone = Literal["all"] | Box | Polygon | Circle | Predicate
    Spacing = tuple[float, float]
else:
    Zone = Literal["all"] | Box | Polygon | Circle
    Spacing = float | tuple[float, float]
Boxed = Annotated[Box, Meta(extra={"unit": "m"})]


class ObstacleSpec(Table, frozen=True):
    r"""Rigid flat obstacle, or Winkler foundation, on one side of the plate over a zone.

    With ``side = "above"`` the deflection must satisfy w <= 0 at every mesh node of the
    closed zone; with ``"below"``, w >= 0. With a ``foundation_stiffness`` :math:`k_f` the
    obstacle is a tensionless (compression-only) Winkler foundation instead: the plate may
    press into it, against a pressure :math:`k_f w` (above; :math:`-k_f w` below), and
    lift off it freely; :math:`k_f \to \infty` is the rigid obstacle. ``side = "both"``
    is then a bilateral foundation (springs in tension too).

    Args:
        zone: ``"all"`` (the whole closed plate), a box ``((xmin, xmax), (ymin, ymax))``
            (m), a :class:`Polygon` (the file's ``polygon = [[x, y], ...]``), a
            :class:`Circle` (``circle = {center, radius}``), or in code a predicate
            ``f(x) -> bool array`` on coordinates of shape (3, n).
        side: One of :data:`SIDES`: where the obstacle lies (w, the deflection, is
            positive towards "above"); "both" only with a foundation.
        foundation_stiffness: Winkler modulus :math:`k_f` (N/m^3, Pa/m), > 0; ``None`` for
            a rigid obstacle. A tensionless one at most :math:`K = k_f b^4/(\pi^4 D) \le
            10^8` (b the smaller side, :math:`D = E t^3/12`): stiffer, it is the rigid
            obstacle to the load's 1e-8, and its springs swamp the plate in double
            precision. The springs are lumped at the zone's nodes: node k carries
            :math:`k_f \int_{\omega_h} \varphi_k\,dx`, the part of its tributary area in
            the discrete zone :math:`\omega_h` (the cells whose nodes all lie in the zone:
            half the area on the zone's edge).
        tolerance: Geometric tolerance (m), >= 0, for a node to count as inside a box,
            polygon or circle; ``None`` uses 1e-8 times the plate size. At most a tenth
            of the mesh's smallest cell side (refused above, before any solve): it
            catches nodes on the zone's edge up to rounding, it does not widen the zone.
        gap: Clearance g (m) >= 0 between the flat plate and a rigid obstacle: w <= g
            (above), w >= -g (below). The nonlinear analysis follows the plate onto it; the
            linear critical state ignores an obstacle with a gap (an infinitesimal buckle
            does not reach it).
    """

    KEY: ClassVar[str] = "obstacle"
    CALLABLE: ClassVar[tuple[str, ...]] = ("zone",)
    zone: Annotated[
        Zone, Meta(extra={"unit": "m", "form": '"all" or [[xmin, xmax], [ymin, ymax]]'})
    ] = "all"
    side: Side = "above"
    foundation_stiffness: Annotated[float, unit("N/m^3", gt=0)] | None = None
    tolerance: Annotated[float, unit("m", ge=0)] | None = None
    gap: Annotated[float, unit("m", ge=0)] = 0.0

    def check(self) -> None:
        """The rules between this table's fields."""
        if isinstance(self.zone, tuple) and any(lo > hi for lo, hi in self.zone):
            zone = in_file(self.zone, "m")[0]
            raise self.error("zone", f" needs xmin <= xmax and ymin <= ymax, got {zone!r}")
        if self.side == "both" and self.foundation_stiffness is None:
            raise self.error(
                "side",
                ' = "both": a rigid obstacle on both sides of the plate is a bilateral support '
                "(w = 0 in the zone), not an obstacle; give an edge its [edges.NAME] support "
                '(e.g. support = "simply_supported"), or one side ("above" or "below"); "both" '
                "is for a foundation (foundation_stiffness)",
            )
        if self.gap and self.foundation_stiffness is not None:
            raise self.error(
                "gap",
                ": a gap is modelled for rigid obstacles only, not for a foundation "
                "(foundation_stiffness)",
            )

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
        return self.zone.KEY if isinstance(self.zone, Polygon | Circle) else "zone"

    def describe(self, units: str | None = "SI") -> str:
        """Short human-readable description of the zone.

        ``units``: "SI" (the result's), or None for a message: the lengths in the units
        of the file being read or solved (:data:`~unibuckle_fenicsx.spec.base.FILE_UNITS`),
        with the unit's name.
        """
        zone = self.zone
        if isinstance(zone, str):
            return "whole plate"
        if isinstance(zone, Polygon):
            return f"polygon of {len(zone.vertices)} vertices"
        if callable(zone):
            return f"predicate {getattr(zone, '__name__', 'zone')}"
        values = (*zone.center, zone.radius) if isinstance(zone, Circle) else (*zone[0], *zone[1])
        (a, b, c, *d), name = in_file(values, "m", units)
        named = "" if name == "m" else f" {name}"  # SI's messages as they were
        if isinstance(zone, Circle):
            return f"circle about ({a:g}, {b:g}) of radius {c:g}{named}"
        return f"[{a:g}, {b:g}] x [{c:g}, {d[0]:g}]{named}"

    def contains(self, x: npt.NDArray[np.float64], size: float) -> npt.NDArray[np.bool_]:
        """Mask of the points ``x`` (shape (3, n)) in the closed zone.

        Args:
            x: Point coordinates, shape (3, n).
            size: Plate size (m), scales the default tolerance.
        """
        zone = self.zone
        if isinstance(zone, str):
            return np.ones(x.shape[1], dtype=bool)
        tol = 1e-8 * size if self.tolerance is None else self.tolerance
        if isinstance(zone, Polygon):
            return points_in_polygon(x[:2].T, zone.vertices, tol)
        if isinstance(zone, Circle):
            return points_in_circle(x[:2].T, zone.center, zone.radius, tol)
        if callable(zone):
            return np.asarray(zone(x), dtype=bool)
        (x0, x1), (y0, y1) = zone
        return (x[0] >= x0 - tol) & (x[0] <= x1 + tol) & (x[1] >= y0 - tol) & (x[1] <= y1 + tol)

    def same_zone(self, other: ObstacleSpec) -> bool:
        """Whether ``other`` has the same zone (a predicate only when it is the same one)."""
        return self.zone is other.zone or (not callable(self.zone) and self.zone == other.zone)


class LoadSpec(Table, frozen=True):
    r"""The load besides the edge stresses: temperature rises, scaled and fixed (``[load]``).

    The prestress is :math:`N = N_{fixed} + \lambda N_{scaled}`: the scaled part is the
    edges' ``normal_stress`` and ``shear_stress`` (per unit load) with ``temperature``;
    the fixed part, applied as is, the edges' ``fixed_normal_stress`` and
    ``fixed_shear_stress`` (Pa) with ``fixed_temperature``, times ``fixed_factor``. A
    rise :math:`\Delta T` gives the free thermal strain :math:`\alpha\Delta T I`
    (``[material] thermal_expansion``), which the edges' in-plane conditions turn into a
    prestress. The buckling pencil is :math:`(A - B_{fixed}, B_{scaled})`.

    Args:
        temperature: The rise per unit load factor: a number (K, uniform) or
            ``(T0, dTdx, dTdy)``, the linear field :math:`T_0 + T_{,x} x + T_{,y} y` (K, K/m).
        fixed_temperature: A rise applied as is, the same forms.
        fixed_factor: A factor on the whole fixed part, 1 by default (the fixed part as
            given): a sweep over it draws an interaction curve; 0 switches it off.
    """

    KEY: ClassVar[str] = "load"
    temperature: Annotated[Temperature, Meta(extra={"unit": "K, K/m"})] = 0.0
    fixed_temperature: Annotated[Temperature, Meta(extra={"unit": "K, K/m"})] = 0.0
    fixed_factor: float = 1.0

    @property
    def thermal(self) -> bool:
        """Whether the scaled part has a temperature rise."""
        return any(temperature_field(self.temperature))

    @property
    def fixed_thermal(self) -> bool:
        """Whether the fixed part has a temperature rise."""
        return any(temperature_field(self.fixed_temperature))


class DesignSpec(Table, frozen=True):
    r"""Design output by EN 1993-1-5 (:mod:`~unibuckle_fenicsx.design`; ``[design]``).

    Args:
        yield_stress: :math:`f_y` (Pa), > 0: a steel's, 1.5e8 to 1e9 Pa
            (:data:`~unibuckle_fenicsx.en1993.STEEL_YIELD_STRESS`), else refused.
        partial_factor: :math:`\gamma_M`, >= 1, of the stress limit :math:`\rho
            f_y/\gamma_M`: :math:`\gamma_{M0}` at :math:`\psi = 1` (EN 1993-1-5 4.6(1),
            the effective cross-section, :math:`f_y A_{eff}/\gamma_{M0}`) and in the
            tension-yield check (EN 1993-1-1 6.2.1(5)); :math:`\gamma_{M1}` at
            :math:`\psi < 1` (EN 1993-1-5 section 10, the reduced stress method); the
            output names which (``partial_factor_name``). 1.0, the recommended value of
            both (EN 1993-1-1, 6.1; a resistance factor below 1 would put the design
            stress above the reduced characteristic one, rho f_y).
    """

    KEY: ClassVar[str] = "design"
    yield_stress: Annotated[float, unit("Pa", gt=0)]
    partial_factor: Annotated[float, Meta(ge=1.0)] = 1.0


class PointSpec(Table, frozen=True):
    r"""Point restraints: one point, or a grid of them (bolts, tie bars, studs; ``[[points]]``).

    Each point acts on the mesh node nearest to it (the snap distance is reported).

    Args:
        at: One point (x, y) (m); or None for a grid.
        spacing: The grid's spacing (sx, sy) (m), > 0 (a number: the same in x and y).
        offset: A point of the grid (m); default the region's lower-left corner.
        region: The box ((xmin, xmax), (ymin, ymax)) (m) holding the grid's points (a
            degenerate side gives a line); default the plate's bounding box. Points outside
            the plate (or in a hole) are left out.
        kind: One of :data:`POINT_KINDS`: "bilateral" (w = 0), "one-sided" (the obstacle's
            cone at the point: w <= 0 with ``side`` "above", w >= 0 "below"), "spring" (a
            spring of ``stiffness`` N/m to w = 0).
        stiffness: The spring's stiffness (N/m), > 0, for ``kind = "spring"`` only.
        side: "above" (w <= 0 at the point) or "below" (w >= 0), for ``kind =
            "one-sided"`` only, where it is required: the side decides which half of the
            plate's deflections the point forbids, and no default is sound for both a
            stud under the plate and a bolt head over it.
    """

    KEY: ClassVar[str] = "points"
    kind: Kind = "bilateral"
    at: Annotated[Point, unit("m")] | None = None
    spacing: (
        Annotated[Spacing, Meta(extra={"unit": "m", "form": "a number or [sx, sy]"})] | None
    ) = None
    offset: Annotated[Point, unit("m")] | None = None
    region: Boxed | None = None
    stiffness: Annotated[float, unit("N/m", gt=0)] | None = None
    side: Literal["above", "below"] | None = None

    def check(self) -> None:
        """The rules between this table's fields."""
        if (self.at is None) == (self.spacing is None):
            raise self.error(
                "",
                " needs at = [x, y] (one point) or spacing = s or [sx, sy] (a grid, with "
                "optional offset and region): exactly one of them",
            )
        if self.at is not None and (self.offset, self.region) != (None, None):
            name = "offset" if self.offset is not None else "region"
            raise self.error(name, " belongs to a grid (spacing), not to at")
        if isinstance(self.spacing, float | int):  # the same in x and y
            force_setattr(self, "spacing", (self.spacing, self.spacing))
        if self.spacing is not None and min(self.spacing) <= 0.0:
            spacing, name = in_file(plain(self.spacing), "m")
            raise self.error("spacing", f" must be > 0 {name}, got {spacing!r}")
        if (self.kind == "spring") != (self.stiffness is not None):
            raise self.error(
                "stiffness",
                f': kind = "spring" needs a stiffness > 0 {unit_name("N/m")}, got '
                f"{self.stiffness!r}"
                if self.kind == "spring"
                else f' belongs to kind = "spring", not "{self.kind}"',
            )
        if self.kind == "one-sided" and self.side is None:
            raise self.error(
                "side",
                ': kind = "one-sided" needs side = "above" (the point holds the plate from '
                'above: w <= 0) or "below" (from below: w >= 0)',
            )
        if self.side is not None and self.kind != "one-sided":
            raise self.error("side", f' belongs to kind = "one-sided", not "{self.kind}"')

    @property
    def sign(self) -> float:
        """+1 for a one-sided point above (w <= 0 admissible), -1 below, 0 for other kinds."""
        return {"above": 1.0, "below": -1.0}.get(self.side or "", 0.0)

    def locations(self, plate: PlateSpec) -> npt.NDArray[np.float64]:
        """The points (n, 2) (m): ``at``, or the grid's points inside the plate.

        Raises:
            InputError: ``at`` outside the plate, or a grid with no point in it.
        """
        tol = 1e-9 * max(plate.length, plate.width)
        if self.at is not None:
            points = np.array([self.at])
        else:
            assert self.spacing is not None
            region = self.region or tuple(zip(*plate.corners, strict=True))
            offset = self.offset or (region[0][0], region[1][0])
            axes = []
            for (lo, hi), step, start in zip(region, self.spacing, offset, strict=True):
                first = math.ceil((lo - start - tol) / step)
                last = math.floor((hi - start + tol) / step)
                if last - first > 100_000:
                    spacing, name = in_file(list(self.spacing), "m")
                    raise InputError(
                        f"points.spacing {spacing} {name} gives more than 100000 points per row"
                    )
                axes.append(start + step * np.arange(first, last + 1))
            gx, gy = np.meshgrid(*axes, indexing="ij")
            points = np.column_stack([gx.ravel(), gy.ravel()])
        inside = plate.contains(points, tol) if plate.file is None else np.ones(len(points), bool)
        if self.at is not None and not inside.all():
            at, name = in_file(list(self.at), "m")
            named = "" if name == "m" else f" {name}"  # SI's messages as they were
            raise InputError(f"points.at {at}{named} lies outside the plate (or in a hole)")
        if not inside.any():
            spacing, name = in_file(list(self.spacing or ()), "m")
            named = "" if name == "m" else f" {name}"
            raise InputError(
                f"points: the grid of spacing {spacing}{named} holds no point of the "
                "plate; check spacing, offset and region"
            )
        return points[inside]

    def describe(self, units: str = "SI") -> str:
        """Short description (for messages and the summary), in ``units`` (:data:`UNITS`)."""
        metres = UNITS[units][0]  # metres per length unit
        length = "m" if metres == 1.0 else "mm"
        what: str = self.kind
        if self.kind == "spring":
            what = f"spring {self.stiffness * metres:g} N/{length}"  # type: ignore[operator]
        if self.kind == "one-sided":
            what += f" ({self.side})"
        if self.at is not None:
            return f"{what} at ({self.at[0] / metres:g}, {self.at[1] / metres:g}) {length}"
        assert self.spacing is not None
        sx, sy = (v / metres for v in self.spacing)
        return f"{what} grid of spacing {sx:g} x {sy:g} {length}"
