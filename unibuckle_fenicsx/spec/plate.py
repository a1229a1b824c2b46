"""The plate: rectangle, outline, holes or gmsh file; its edges and its mesh.

The geometry rules (a simple outline, holes inside and disjoint, segments named once)
are checked here by hand: no schema library knows them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.geometry import (
    circle_points,
    distance_to_polygon,
    is_simple,
    points_in_circle,
    points_in_polygon,
    polygon_area,
    polygon_inside,
    polygons_disjoint,
)
from unibuckle_fenicsx.spec.checks import check_features, check_thickness
from unibuckle_fenicsx.spec.values import (
    BENDING_SUPPORTS,
    HOLES,
    INPLANE_SUPPORTS,
    _choice,
    _integer,
    _number,
    _stress,
    stress_ends,
)


@dataclass(frozen=True)
class Circle:
    """A circular zone: the closed disc of ``radius`` about ``center`` (m)."""

    center: tuple[float, float]
    radius: float

    def __post_init__(self) -> None:
        try:
            cx, cy = self.center
        except (TypeError, ValueError):
            raise InputError(f"circle.center must be [x, y], got {self.center!r}") from None
        object.__setattr__(
            self, "center", (_number("circle.center", cx), _number("circle.center", cy))
        )
        if not _number("circle.radius", self.radius) > 0.0:
            raise InputError(f"circle.radius must be > 0 m, got {self.radius!r}")
        object.__setattr__(self, "radius", float(self.radius))


@dataclass(frozen=True)
class Polygon:
    """A polygonal zone: the closed simple polygon of ``vertices`` (m), at least three."""

    vertices: tuple[tuple[float, float], ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "vertices", _polygon("polygon", self.vertices))


def _polygon(name: str, value: Any) -> tuple[tuple[float, float], ...]:
    """A simple polygon of at least three vertices [[x, y], ...] with a non-zero area."""
    if not isinstance(value, list | tuple) or len(value) < 3:
        raise InputError(f"{name} must be a list of at least 3 points [[x, y], ...], got {value!r}")
    vertices = []
    for point in value:
        if not isinstance(point, list | tuple) or len(point) != 2:
            raise InputError(f"{name}: each vertex must be a point [x, y], got {point!r}")
        vertices.append((_number(name, point[0]), _number(name, point[1])))
    if not is_simple(vertices):
        raise InputError(
            f"{name} must be a simple polygon (no repeated vertex, no self-intersection), "
            f"got {value!r}"
        )
    size = float(np.ptp(np.asarray(vertices), axis=0).max())
    if abs(polygon_area(vertices)) <= 1e-12 * size * size:
        raise InputError(f"{name} has no area (collinear vertices), got {value!r}")
    return tuple(vertices)


@dataclass(frozen=True)
class EdgeSpec:
    r"""Conditions on one edge part.

    Args:
        name: Edge name; for the rectangle one of :data:`EDGE_NAMES`.
        support: Transverse condition, one of :data:`BENDING_SUPPORTS`.
        inplane: In-plane condition for the prestress, one of :data:`INPLANE_SUPPORTS`
            ("roller" fixes the normal displacement only).
        normal_stress: Normal edge stress per unit load (Pa/Pa), tension positive;
            the paper's compressed edges have -1. A pair ``(start, end)`` varies
            linearly along the edge (:func:`~unibuckle_fenicsx.model.mesh.edge_line` gives
            the direction): in-plane bending is ``(1, -1)``, the stress-gradient ratio
            of design codes is :math:`\psi` = end/start.
        shear_stress: Tangential edge stress per unit load (Pa/Pa), along the
            counter-clockwise tangent; a number or a pair, as ``normal_stress``.
        tag: Facet tag of this edge in a user-supplied mesh; ``None`` for the
            rectangle (tags 1..4 in :data:`EDGE_NAMES` order).
        segments: The outline segments forming this boundary part (segment k runs from
            vertex k to vertex k + 1), for a plate given by its ``outline``.
        rotational_stiffness: Elastic restraint of the rotation about the edge,
            :math:`k_r` (N m per m per rad, i.e. N), >= 0: the energy
            :math:`\tfrac12\int k_r (\theta\cdot n)^2\,ds`, on an edge whose support leaves
            that rotation free (not "clamped"). 0: none; :math:`k_r \to \infty`: clamped.
        translational_stiffness: Elastic support of the deflection along the edge,
            :math:`k_t` (N/m per m, i.e. N/m^2), >= 0: :math:`\tfrac12\int k_t w^2\,ds`,
            on an edge whose support leaves w free ("free"). :math:`k_t \to \infty`:
            the soft simple support.
        fixed_normal_stress: Normal edge stress (Pa) applied as is, not scaled by the
            load factor (the fixed part of the load, :class:`LoadSpec`); a number or a
            pair, as ``normal_stress``.
        fixed_shear_stress: Tangential edge stress (Pa) applied as is.
    """

    name: str
    support: str = "simply_supported"
    inplane: str = "free"
    normal_stress: float | tuple[float, float] = 0.0
    shear_stress: float | tuple[float, float] = 0.0
    tag: int | None = None
    segments: tuple[int, ...] | None = None
    rotational_stiffness: float = 0.0
    translational_stiffness: float = 0.0
    fixed_normal_stress: float | tuple[float, float] = 0.0
    fixed_shear_stress: float | tuple[float, float] = 0.0

    def __post_init__(self) -> None:
        where = f"edges.{self.name}"
        if not isinstance(self.name, str) or not self.name:
            raise InputError(f"edge names must be non-empty strings, got {self.name!r}")
        _choice(f"{where}.support", self.support, BENDING_SUPPORTS)
        _choice(f"{where}.inplane", self.inplane, INPLANE_SUPPORTS)
        for name in ("normal_stress", "shear_stress", "fixed_normal_stress", "fixed_shear_stress"):
            object.__setattr__(self, name, _stress(f"{where}.{name}", getattr(self, name)))
        if self.tag is not None:
            _integer(f"{where}.tag", self.tag, 0)
        if self.segments is not None:
            if not isinstance(self.segments, list | tuple) or not self.segments:
                raise InputError(
                    f"{where}.segments must be a non-empty list of outline segment numbers "
                    f"[k, ...], got {self.segments!r}"
                )
            segments = tuple(_integer(f"{where}.segments", k, 0) for k in self.segments)
            if len(set(segments)) != len(segments):
                raise InputError(f"{where}.segments repeats a segment: {list(segments)}")
            object.__setattr__(self, "segments", segments)
        self._check_springs(where)

    def _check_springs(self, where: str) -> None:
        """The edge springs: finite, >= 0, on DOFs the support leaves free."""
        for name in ("rotational_stiffness", "translational_stiffness"):
            if not _number(f"{where}.{name}", getattr(self, name)) >= 0.0:
                raise InputError(
                    f"{where}.{name} must be >= 0 (0: no spring), got {getattr(self, name)!r}"
                )
            object.__setattr__(self, name, float(getattr(self, name)))
        if self.rotational_stiffness > 0.0 and self.support == "clamped":
            raise InputError(
                f'{where}.rotational_stiffness: support = "clamped" fixes the rotation '
                "already; a rotational spring needs a support that leaves it free "
                '("simply_supported", "simply_supported_soft" or "free")'
            )
        if self.translational_stiffness > 0.0 and self.support != "free":
            raise InputError(
                f'{where}.translational_stiffness: support = "{self.support}" fixes the '
                'deflection already; an elastically supported edge has support = "free"'
            )

    @property
    def springs(self) -> bool:
        """Whether the edge carries a rotational or a translational spring."""
        return self.rotational_stiffness > 0.0 or self.translational_stiffness > 0.0

    @property
    def loaded(self) -> bool:
        r"""Whether this edge carries a traction (belongs to :math:`\gamma_1`)."""
        return any(v != 0.0 for v in (*self.normal_ends, *self.shear_ends))

    @property
    def fixed_loaded(self) -> bool:
        """Whether the edge carries a fixed traction."""
        ends = (*stress_ends(self.fixed_normal_stress), *stress_ends(self.fixed_shear_stress))
        return any(v != 0.0 for v in ends)

    def fixed_part(self) -> EdgeSpec:
        """This edge with its fixed stresses as the stresses (and no fixed part)."""
        return replace(
            self,
            normal_stress=self.fixed_normal_stress,
            shear_stress=self.fixed_shear_stress,
            fixed_normal_stress=0.0,
            fixed_shear_stress=0.0,
        )

    @property
    def normal_ends(self) -> tuple[float, float]:
        """Normal stress per unit load at the start and the end of the edge."""
        return stress_ends(self.normal_stress)

    @property
    def shear_ends(self) -> tuple[float, float]:
        """Shear stress per unit load at the start and the end of the edge."""
        return stress_ends(self.shear_stress)

    @property
    def uniform(self) -> bool:
        """Whether both stresses are constant along the edge."""
        return all(a == b for a, b in (self.normal_ends, self.shear_ends))

    def max_stress(self) -> float:
        """The largest absolute edge stress per unit load (normal or shear, either end)."""
        return max(abs(v) for v in (*self.normal_ends, *self.shear_ends))


def paper_edges() -> tuple[EdgeSpec, ...]:
    """Simply supported on the whole edge, unit compression on the short edges x = const."""
    return (
        EdgeSpec("left", normal_stress=-1.0),
        EdgeSpec("right", normal_stress=-1.0),
        EdgeSpec("bottom"),
        EdgeSpec("top"),
    )


@dataclass(frozen=True)
class PlateSpec:
    """Geometry and edge conditions of the plate.

    The plate is the rectangle of ``corners`` (a structured mesh), or, meshed by gmsh
    with quadrilaterals, the polygon ``outline``, the rectangle or the outline with
    ``holes``, or the plate of a gmsh ``file``.

    Args:
        corners: Opposite corners ``((x0, y0), (x1, y1))`` of the rectangle (m); for an
            outline, its bounding box (set from it); for a file, its bounding box once
            meshed.
        thickness: Plate thickness t = 2 epsilon (m), > 0.
        edges: One :class:`EdgeSpec` per edge part: the rectangle's are named as in
            :data:`EDGE_NAMES`, an outline's parts by their ``segments``, a file's by
            its physical groups of dimension 1; the part ``holes`` is the holes'
            boundary. Boundary parts not named are free.
        outline: A simple polygon [(x, y), ...] (m), at least three vertices; segment k
            runs from vertex k to vertex k + 1 (the last back to the first).
        holes: :class:`Circle` or :class:`Polygon` holes inside the plate, disjoint.
        file: A gmsh ``.geo`` (meshed with quadrilaterals) or ``.msh`` (its
            quadrilaterals) file with a physical surface and named physical curves.
    """

    corners: tuple[tuple[float, float], tuple[float, float]] = ((-0.1, -0.05), (0.1, 0.05))
    thickness: float = 0.006
    edges: tuple[EdgeSpec, ...] = field(default_factory=paper_edges)
    outline: tuple[tuple[float, float], ...] | None = None
    holes: tuple[Circle | Polygon, ...] = ()
    file: str | None = None

    def __post_init__(self) -> None:
        if not _number("plate.thickness", self.thickness) > 0.0:
            raise InputError(f"plate.thickness must be > 0 m, got {self.thickness!r}")
        object.__setattr__(self, "thickness", float(self.thickness))
        if self.outline is not None:
            outline = _polygon("plate.outline", self.outline)
            object.__setattr__(self, "outline", outline)
            v = np.asarray(outline)
            lo, hi = v.min(axis=0), v.max(axis=0)
            object.__setattr__(
                self, "corners", ((float(lo[0]), float(lo[1])), (float(hi[0]), float(hi[1])))
            )
        try:
            (x0, y0), (x1, y1) = self.corners
        except (TypeError, ValueError):
            raise InputError(
                f"plate.corners must be [[x0, y0], [x1, y1]], got {self.corners!r}"
            ) from None
        corners = (
            (_number("plate.corners", x0), _number("plate.corners", y0)),
            (_number("plate.corners", x1), _number("plate.corners", y1)),
        )
        object.__setattr__(self, "corners", corners)
        if not (corners[1][0] > corners[0][0] and corners[1][1] > corners[0][1]):
            raise InputError(
                "plate.corners must satisfy x1 > x0 and y1 > y0 (a non-degenerate "
                f"rectangle), got {self.corners!r}"
            )
        object.__setattr__(self, "edges", tuple(self.edges))
        names = [e.name for e in self.edges]
        if len(set(names)) != len(names):
            raise InputError(f"plate.edges: duplicate edge names {names}")
        self._check_file()
        self._check_holes()
        self._check_edges()
        check_thickness(self)

    def _check_file(self) -> None:
        if self.file is None:
            return
        if not isinstance(self.file, str) or Path(self.file).suffix.lower() not in (
            ".geo",
            ".msh",
        ):
            raise InputError(f"plate.file must be a gmsh .geo or .msh file, got {self.file!r}")
        if self.outline is not None or self.holes:
            raise InputError("plate.file: give a file, or an outline and holes, not both")
        if not Path(self.file).is_file():
            raise InputError(f"plate.file: no such file {self.file!r}")

    def _check_holes(self) -> None:
        holes = tuple(self.holes)
        object.__setattr__(self, "holes", holes)
        outer = self.boundary
        for k, hole in enumerate(holes):
            where = f"plate.holes[{k}]"
            if isinstance(hole, Circle):
                center = np.array([hole.center])
                inside = (
                    bool(points_in_polygon(center, outer)[0])
                    and float(distance_to_polygon(center, outer)[0]) > hole.radius
                )
            elif isinstance(hole, Polygon):
                inside = polygon_inside(hole.vertices, outer)
            else:
                raise InputError(f"{where} must be a Circle or a Polygon, got {hole!r}")
            if not inside:
                raise InputError(f"{where} must lie inside the plate, without touching its edge")
            for j in range(k):
                if not _disjoint(holes[j], hole):
                    raise InputError(f"plate.holes[{j}] and {where} overlap or touch")
        check_features(self, None)  # touching within rounding (a tangent hole)

    def _check_edges(self) -> None:
        count = len(self.outline) if self.outline is not None else 0
        used: dict[int, str] = {}
        for e in self.edges:
            where = f"edges.{e.name}"
            if e.name == HOLES and e.tag is None:
                if not self.holes:
                    raise InputError(f"{where}: the plate has no holes (plate.holes)")
                if e.segments is not None:
                    raise InputError(f"{where}: the holes' boundary takes no segments")
                if not e.uniform:
                    raise InputError(
                        f"{where}: a linear [start, end] stress needs a straight edge; give "
                        "the holes a number"
                    )
                continue
            if e.segments is not None:
                if self.outline is None:
                    raise InputError(
                        f"{where}.segments names segments of plate.outline, which this "
                        "plate does not have"
                    )
                for k in e.segments:
                    if k >= count:
                        raise InputError(
                            f"{where}.segments: {k} is not a segment of the outline (0 to "
                            f"{count - 1}: segment k runs from vertex k to vertex k + 1)"
                        )
                    if k in used:
                        raise InputError(
                            f"{where}.segments: segment {k} is already in edges.{used[k]}"
                        )
                    used[k] = e.name
            elif self.outline is not None and e.tag is None:
                raise InputError(
                    f"{where}: a plate given by its outline names its boundary parts by "
                    f"segments = [k, ...] (outline segments 0 to {count - 1}), or "
                    f"{HOLES!r} for the holes"
                )

    @property
    def meshed_by_gmsh(self) -> bool:
        """Whether gmsh meshes the plate (an outline, holes or a file)."""
        return self.outline is not None or bool(self.holes) or self.file is not None

    @property
    def boundary(self) -> tuple[tuple[float, float], ...]:
        """The outer boundary as a polygon: the outline, or the rectangle's four corners.

        For a file, the bounding box.
        """
        if self.outline is not None:
            return self.outline
        (x0, y0), (x1, y1) = self.corners
        return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))

    @property
    def area(self) -> float:
        """The plate's area (m^2): the outer boundary's less the holes' (a file: its box)."""
        total = abs(polygon_area(self.boundary))
        for hole in self.holes:
            if isinstance(hole, Circle):
                total -= math.pi * hole.radius**2
            else:
                total -= abs(polygon_area(hole.vertices))
        return total

    @property
    def length(self) -> float:
        """Extent in x (m)."""
        return self.corners[1][0] - self.corners[0][0]

    @property
    def width(self) -> float:
        """Extent in y (m)."""
        return self.corners[1][1] - self.corners[0][1]

    def fixed_part(self) -> PlateSpec:
        """The plate with its edges' fixed stresses as the stresses (for the fixed prestress)."""
        return replace(self, edges=tuple(e.fixed_part() for e in self.edges))

    @property
    def loaded(self) -> bool:
        """Whether an edge carries a stress per unit load (scaled by lambda)."""
        return any(e.loaded for e in self.edges)

    @property
    def fixed_loaded(self) -> bool:
        """Whether an edge carries a fixed stress."""
        return any(e.fixed_loaded for e in self.edges)

    def contains(self, points: npt.NDArray[np.float64], tol: float) -> npt.NDArray[np.bool_]:
        """Mask of the points (n, 2) in the closed plate (within ``tol``), not in a hole.

        For a file, its bounding box (the mesh is not known yet).
        """
        inside = points_in_polygon(points, self.boundary, tol)
        for hole in self.holes:
            if isinstance(hole, Circle):
                inside &= ~points_in_circle(points, hole.center, hole.radius, -tol)
            else:
                inside &= ~points_in_polygon(points, hole.vertices) | (
                    distance_to_polygon(points, hole.vertices) <= tol
                )
        return inside

    def edge(self, name: str) -> EdgeSpec:
        """The edge called ``name``."""
        for e in self.edges:
            if e.name == name:
                return e
        raise KeyError(f"plate has no edge {name!r}; edges: {[e.name for e in self.edges]}")


@dataclass(frozen=True)
class MeshSpec:
    """Structured quadrilateral mesh of the rectangle.

    Args:
        nx: Cells along x, >= 2 (one cell cannot carry a buckle).
        ny: Cells along y, >= 2.
        size: The cell size the file asked for (m), or None when it gave nx and ny;
            nx and ny are then :meth:`cells_for` of the plate (recorded so that a file
            written back, e.g. a sweep point, keeps asking for the size).
    """

    nx: int = 20
    ny: int = 20
    size: float | None = None

    def __post_init__(self) -> None:
        for name in ("nx", "ny"):
            object.__setattr__(self, name, _integer(f"mesh.{name}", getattr(self, name), 2))
        if self.size is not None:
            if not _number("mesh.size", self.size) > 0.0:
                raise InputError(f"mesh.size must be > 0 m, got {self.size!r}")
            object.__setattr__(self, "size", float(self.size))

    @staticmethod
    def cells_for(length: float, width: float, size: float) -> tuple[int, int]:
        """Cells (nx, ny) of side at most ``size`` on a ``length`` x ``width`` plate (>= 2)."""
        if not _number("mesh.size", size) > 0.0:
            raise InputError(f"mesh.size must be > 0 m, got {size!r}")
        # 1e-9: a size that divides the side exactly gives that many cells, not one more.
        return tuple(  # type: ignore[return-value]
            max(2, math.ceil(side / size * (1.0 - 1e-9))) for side in (length, width)
        )

    @property
    def num_dofs(self) -> int:
        """DOFs of (w, theta) on this mesh: 3 per node."""
        return 3 * (self.nx + 1) * (self.ny + 1)


def _disjoint(a: Circle | Polygon, b: Circle | Polygon) -> bool:
    """Whether two holes neither overlap nor touch (a circle as a 256-gon, to 1e-4 r)."""
    if isinstance(a, Circle) and isinstance(b, Circle):
        return math.dist(a.center, b.center) > a.radius + b.radius
    pa, pb = (_hole_polygon(h) for h in (a, b))
    return polygons_disjoint(pa, pb)


def _hole_polygon(hole: Circle | Polygon) -> npt.NDArray[np.float64]:
    if isinstance(hole, Circle):
        return circle_points(hole.center, hole.radius, 256)
    return np.asarray(hole.vertices, dtype=float)
