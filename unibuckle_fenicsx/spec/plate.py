"""The plate: rectangle, outline, holes or gmsh file; its edges and its mesh."""

from __future__ import annotations

import math
import typing
from pathlib import Path
from typing import Annotated, ClassVar, Literal

import msgspec
import numpy as np
import numpy.typing as npt
from msgspec import Meta
from msgspec.structs import force_setattr, replace

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.geometry import (
    circle_points,
    distance_to_polygon,
    is_simple,
    narrowest_width,
    points_in_circle,
    points_in_polygon,
    polygon_area,
    polygon_inside,
    polygons_disjoint,
)
from unibuckle_fenicsx.spec.base import (
    Point,
    Stress,
    Table,
    in_file,
    plain,
    stress_ends,
    unit,
    unknown_keys,
)

#: Edge names of a rectangular plate, in facet-tag order 1..4.
EDGE_NAMES = ("left", "right", "bottom", "top")
#: Name of the holes' boundary part in ``[edges.*]``.
HOLES = "holes"
Support = Literal["simply_supported", "simply_supported_soft", "clamped", "free"]
Inplane = Literal["free", "clamped", "roller"]
#: Transverse (bending) conditions. "simply_supported" is the *hard* support of a
#: Reissner-Mindlin plate (w = 0 and tangential rotation = 0); "soft" fixes w only.
BENDING_SUPPORTS: tuple[str, ...] = typing.get_args(Support)
#: In-plane conditions for the prestress solve ("roller": the normal displacement only).
INPLANE_SUPPORTS: tuple[str, ...] = typing.get_args(Inplane)
#: Above this thickness over the plate's smaller side (an outline's narrowest width,
#: :attr:`PlateSpec.narrowest`), a warning: Reissner-Mindlin theory (transverse shear,
#: plane sections, no thickness stretch) is the usual model of moderately thick plates
#: up to t/b of about 0.2.
THICK_PLATE_RATIO = 0.2
#: Above this thickness over the plate's smaller side (as above) the body is not a plate:
#: refused.
MAX_THICKNESS_RATIO = 0.5
#: Below this thickness over the plate's smaller side, refused: the bending stiffness
#: (:math:`\propto t^3`) against the shear stiffness (:math:`\propto t`) of the same
#: deflection is about :math:`(t/b)^2`, which at 1e-8 lies below the double precision's
#: unit round-off (1.1e-16): no digit of the load is left (SLEPc returned a negative
#: load at t/b = 1e-8). Between this and about 1e-5 the load is computed with the
#: digits it keeps (the ``load_resolution`` warning says how many), or refused where
#: the free pair's check cannot resolve it (``FREE_CHECK_RESOLUTION``).
MIN_THICKNESS_RATIO = 1e-7
#: Plate sides and corner coordinates accepted (m): from a micro-machined membrane to
#: far beyond a bridge deck; beyond, lengths to the fourth power (the bending stiffness
#: against the geometric stiffness) leave double precision (a plate of 1e300 m failed
#: in MUMPS), and coordinates far from the origin keep few digits of the cells.
MIN_SIDE, MAX_COORDINATE = 1e-6, 1e6

Length = Annotated[float, unit("m", gt=0)]
Vertices = Annotated[
    tuple[Point, ...], Meta(min_length=3, extra={"unit": "m", "form": "[[x, y], ...] (3 or more)"})
]


class Circle(Table, frozen=True, tag_field="shape", tag="circle"):
    """A circular zone: the closed disc of ``radius`` about ``center``.

    Args:
        center: The centre [x, y] (m).
        radius: The radius (m), > 0.
    """

    KEY: ClassVar[str] = "circle"
    center: Annotated[Point, unit("m")]
    radius: Length


class Polygon(Table, frozen=True, tag_field="shape", tag="polygon"):
    """A polygonal zone: the closed simple polygon of ``vertices``.

    Args:
        vertices: The vertices [[x, y], ...] (m), at least three, of a simple polygon.
    """

    KEY: ClassVar[str] = "polygon"
    vertices: Vertices

    def check(self) -> None:
        """The rules between this table's fields."""
        if (why := polygon_fault(self.vertices)) is not None:
            raise self.error("vertices", why)


def polygon_fault(vertices: tuple[Point, ...]) -> str | None:
    """Why ``vertices`` are not a simple polygon with an area, or None."""
    if not is_simple(vertices):
        return " must be a simple polygon (no repeated vertex, no self-intersection)"
    size = float(np.ptp(np.asarray(vertices), axis=0).max())
    if abs(polygon_area(vertices)) <= 1e-12 * size * size:
        return " has no area (collinear vertices)"
    return None


Segments = Annotated[
    tuple[Annotated[int, Meta(ge=0)], ...],
    Meta(min_length=1, extra={"form": "a list of outline segments [k, ...]"}),
]


#: The edge stresses that an edge held in its plane does not take (the prestress solve's
#: Dirichlet condition replaces the traction): "roller" holds the normal displacement,
#: Largest magnitude of an edge stress (Pa, or Pa per unit load): a hundred times the
#: strength of the strongest structural materials (about 1e10 Pa), the modulus of
#: diamond. Far beyond (1e300) the membrane forces overflow double precision and the
#: solve fails; a stress per unit load only scales the load factor, so nothing is lost.
MAX_EDGE_STRESS = 1e12
#: "clamped" both.
HELD_STRESSES = {
    "roller": ("normal_stress", "fixed_normal_stress"),
    "clamped": ("normal_stress", "fixed_normal_stress", "shear_stress", "fixed_shear_stress"),
}


class EdgeSpec(Table, frozen=True):
    r"""Conditions on one edge part (the file's ``[edges.NAME]``).

    Args:
        name: Edge name; for the rectangle one of :data:`EDGE_NAMES`.
        support: Transverse condition, one of :data:`BENDING_SUPPORTS`.
        inplane: In-plane condition for the prestress, one of :data:`INPLANE_SUPPORTS`;
            the stress on a held edge is its support's reaction, so a stress given in a
            held direction (:data:`HELD_STRESSES`) is refused.
        normal_stress: Normal edge stress per unit load (Pa/Pa), tension positive; the
            paper's compressed edges have -1. Every edge stress (this, the shear and the
            fixed ones) lies in [-1e12, 1e12] (:data:`MAX_EDGE_STRESS`: a hundred times the
            strength of any structural material; beyond, double precision overflows). A
            pair ``(start, end)`` varies linearly along the edge
            (:func:`~unibuckle_fenicsx.model.mesh.edge_line` gives the direction):
            in-plane bending is ``(1, -1)``, the stress-gradient ratio of design codes is
            :math:`\psi` = end/start.
        shear_stress: Tangential edge stress per unit load (Pa/Pa), along the
            counter-clockwise tangent; a number or a pair, as ``normal_stress``.
        rotational_stiffness: Elastic restraint of the rotation about the edge, :math:`k_r`
            (N m per m per rad, i.e. N), >= 0: the energy :math:`\tfrac12\int k_r
            (\theta\cdot n)^2\,ds` on an edge whose support leaves that rotation free (not
            "clamped"). 0: none; :math:`k_r \to \infty`: clamped.
        translational_stiffness: Elastic support of the deflection along the edge,
            :math:`k_t` (N/m per m, i.e. N/m^2), >= 0: :math:`\tfrac12\int k_t w^2\,ds` on
            an edge whose support is "free". :math:`k_t \to \infty`: the soft simple support.
        fixed_normal_stress: Normal edge stress (Pa) applied as is, not scaled by the load
            factor (the fixed part of the load, :class:`LoadSpec`); a number or a pair.
        fixed_shear_stress: Tangential edge stress (Pa) applied as is.
        segments: The outline segments forming this boundary part (segment k runs from
            vertex k to vertex k + 1), for a plate given by its ``outline``.
        tag: Facet tag of this edge in a user-supplied mesh (the Python API only); ``None``
            for the rectangle (tags 1..4 in :data:`EDGE_NAMES` order).
    """

    CODE_ONLY: ClassVar[tuple[str, ...]] = ("name", "tag")
    name: Annotated[str, Meta(min_length=1)]
    support: Support = "simply_supported"
    inplane: Inplane = "free"
    normal_stress: Stress = 0.0
    shear_stress: Stress = 0.0
    rotational_stiffness: Annotated[float, unit("N", ge=0)] = 0.0  # N in every system
    translational_stiffness: Annotated[float, unit("N/m^2", ge=0)] = 0.0
    fixed_normal_stress: Annotated[Stress, unit("Pa")] = 0.0
    fixed_shear_stress: Annotated[Stress, unit("Pa")] = 0.0
    segments: Segments | None = None
    tag: Annotated[int, Meta(ge=0)] | None = None

    def key(self) -> str:
        """``edges.NAME``."""
        return f"edges.{self.name}" if self.name else "edges"

    def check(self) -> None:
        """The rules between this table's fields."""
        if self.segments is not None and len(set(self.segments)) != len(self.segments):
            raise self.error("segments", f" repeats a segment: {list(self.segments)}")
        if self.rotational_stiffness > 0.0 and self.support == "clamped":
            raise self.error(
                "rotational_stiffness",
                ': support = "clamped" fixes the rotation already; a rotational spring '
                'needs a support that leaves it free ("simply_supported", '
                '"simply_supported_soft" or "free")',
            )
        if self.translational_stiffness > 0.0 and self.support != "free":
            raise self.error(
                "translational_stiffness",
                f': support = "{self.support}" fixes the deflection already; an elastically '
                'supported edge has support = "free"',
            )
        for name in ("normal_stress", "shear_stress", "fixed_normal_stress", "fixed_shear_stress"):
            value = getattr(self, name)
            if max(abs(v) for v in stress_ends(value)) > MAX_EDGE_STRESS:
                fixed = name.startswith("fixed_")
                given, unit_text = in_file(plain(value), "Pa") if fixed else (value, "")
                bound = in_file(MAX_EDGE_STRESS, "Pa")[0] if fixed else MAX_EDGE_STRESS
                raise self.error(
                    name,
                    f" = {plain(given)!r} must lie in [-{bound:g}, {bound:g}]"
                    + (f" {unit_text}" if fixed else " (Pa per unit load)")
                    + ": a hundred times the strength of any structural material"
                    + (
                        ""
                        if fixed
                        else " (give the load's pattern, e.g. -1, and read the load factor "
                        "as the stress)"
                    ),
                )
        for name in HELD_STRESSES.get(self.inplane, ()):
            if any(stress_ends(getattr(self, name))):
                raise self.error(
                    name,
                    f" = {plain(getattr(self, name))!r} is not applied: inplane = "
                    f'"{self.inplane}" holds the edge in its plane, and the support\'s reaction '
                    "is the stress there (the other edges' loads reach it); leave "
                    f'{name} out on this edge, or give it inplane = "free"',
                )

    @property
    def springs(self) -> bool:
        """Whether the edge carries a rotational or a translational spring."""
        return self.rotational_stiffness > 0.0 or self.translational_stiffness > 0.0

    @property
    def normal_ends(self) -> tuple[float, float]:
        """Normal stress per unit load at the start and the end of the edge."""
        return stress_ends(self.normal_stress)

    @property
    def shear_ends(self) -> tuple[float, float]:
        """Shear stress per unit load at the start and the end of the edge."""
        return stress_ends(self.shear_stress)

    @property
    def loaded(self) -> bool:
        r"""Whether this edge carries a traction (belongs to :math:`\gamma_1`)."""
        return any(v != 0.0 for v in (*self.normal_ends, *self.shear_ends))

    @property
    def fixed_loaded(self) -> bool:
        """Whether the edge carries a fixed traction."""
        ends = (*stress_ends(self.fixed_normal_stress), *stress_ends(self.fixed_shear_stress))
        return any(v != 0.0 for v in ends)

    @property
    def uniform(self) -> bool:
        """Whether both stresses are constant along the edge."""
        return all(a == b for a, b in (self.normal_ends, self.shear_ends))

    def max_stress(self) -> float:
        """The largest absolute edge stress per unit load (normal or shear, either end)."""
        return max(abs(v) for v in (*self.normal_ends, *self.shear_ends))

    def fixed_part(self) -> EdgeSpec:
        """This edge with its fixed stresses as the stresses (and no fixed part)."""
        return replace(
            self,
            normal_stress=self.fixed_normal_stress,
            shear_stress=self.fixed_shear_stress,
            fixed_normal_stress=0.0,
            fixed_shear_stress=0.0,
        )


def reference_edge(
    normal: typing.Sequence[typing.Sequence[float]], shear: typing.Sequence[typing.Sequence[float]]
) -> tuple[int, float, Literal["compressive", "shear"]]:
    """The loaded edge whose stress per unit load is k's reference, its stress and kind.

    ``normal``, ``shear``: each loaded edge's normal and shear stresses per unit load
    at its ends (tension > 0), in the edges' order (at least one edge). The largest
    compressive normal stress (positive); without one, the largest absolute shear
    stress; edges in tension alone, neither sheared: the least tensile stress,
    negative. Ties: the first edge. :meth:`PlateSpec.reference_load` and the result's
    summary take it so.
    """
    compression = [max(-v for v in ends) for ends in normal]
    sheared = [max(abs(v) for v in ends) for ends in shear]
    is_normal = max(compression) > 0.0 or max(sheared) == 0.0
    values = compression if is_normal else sheared
    k = int(np.argmax(values))  # the first of equal values
    return k, values[k], "compressive" if is_normal else "shear"


def paper_edges() -> tuple[EdgeSpec, ...]:
    """Simply supported on the whole edge, unit compression on the short edges x = const."""
    return (
        EdgeSpec("left", normal_stress=-1.0),
        EdgeSpec("right", normal_stress=-1.0),
        EdgeSpec("bottom"),
        EdgeSpec("top"),
    )


class PlateSpec(Table, frozen=True):
    """Geometry and edge conditions of the plate (the file's ``[plate]`` and ``[edges.*]``).

    The plate is the rectangle of ``corners`` (a structured mesh), or, meshed by gmsh
    with quadrilaterals, the polygon ``outline``, the rectangle or the outline with
    ``holes``, or the plate of a gmsh ``file``.

    Args:
        corners: Opposite corners ``((x0, y0), (x1, y1))`` of the rectangle (m); for an
            outline, its bounding box (set from it); for a file, its bounding box once
            meshed. Coordinates within +-1e6 m and sides of at least 1e-6 m
            (:data:`MAX_COORDINATE`, :data:`MIN_SIDE`): beyond, double precision fails.
        thickness: Plate thickness t = 2 epsilon (m), > 0, from
            :data:`MIN_THICKNESS_RATIO` (1e-7: below, double precision keeps no digit of
            the bending stiffness beside the shear stiffness) to
            :data:`MAX_THICKNESS_RATIO` (0.5: above, not a plate) times the smaller side
            (an outline's narrowest width: :attr:`narrowest`).
        edges: One :class:`EdgeSpec` per edge part: the rectangle's are named as in
            :data:`EDGE_NAMES`, an outline's parts by their ``segments``, a file's by its
            physical groups of dimension 1; the part ``holes`` is the holes' boundary.
            Boundary parts not named are free.
        outline: A simple polygon [(x, y), ...] (m), at least three vertices; segment k
            runs from vertex k to vertex k + 1 (the last back to the first).
        holes: :class:`Circle` or :class:`Polygon` holes inside the plate, disjoint (in a
            file a table with center and radius, or with outline).
        file: A gmsh ``.geo`` (meshed with quadrilaterals) or ``.msh`` (its
            quadrilaterals) file with a physical surface and named physical curves.
    """

    KEY: ClassVar[str] = "plate"
    CODE_ONLY: ClassVar[tuple[str, ...]] = ("edges",)
    thickness: Length = 0.006
    corners: Annotated[
        tuple[Point, Point], Meta(extra={"unit": "m", "form": "[[x0, y0], [x1, y1]]"})
    ] = ((-0.1, -0.05), (0.1, 0.05))
    outline: Vertices | None = None
    file: str | None = None
    holes: tuple[Circle | Polygon, ...] = ()
    edges: tuple[EdgeSpec, ...] = msgspec.field(default_factory=paper_edges)

    def check(self) -> None:
        """The rules between this table's fields."""
        if self.outline is not None:
            if (why := polygon_fault(self.outline)) is not None:
                raise self.error("outline", why)
            v = np.asarray(self.outline)
            lo, hi = v.min(axis=0).tolist(), v.max(axis=0).tolist()
            force_setattr(self, "corners", ((lo[0], lo[1]), (hi[0], hi[1])))
        (x0, y0), (x1, y1) = self.corners
        if not (x1 > x0 and y1 > y0):
            raise self.error(
                "corners",
                " must satisfy x1 > x0 and y1 > y0 (a non-degenerate rectangle), got "
                f"{in_file(self.corners, 'm')[0]!r}",
            )
        names = [e.name for e in self.edges]
        if len(set(names)) != len(names):
            raise self.error("edges", f": duplicate edge names {names}")
        self._check_file()
        self._check_holes()
        self._check_edges()
        self._check_extent()
        b, side_name = self.narrowest
        ratio = self.thickness / b
        if self.file is None and not MIN_THICKNESS_RATIO <= ratio <= MAX_THICKNESS_RATIO:
            (t, name), (side, _) = in_file(self.thickness, "m"), in_file(b, "m")
            why = (
                f"plate.thickness must be at least {MIN_THICKNESS_RATIO:g} times it (t/b in "
                f"[{MIN_THICKNESS_RATIO:g}, {MAX_THICKNESS_RATIO:g}]): below, the bending "
                "stiffness (t^3) is lost in the rounding of the shear stiffness (t) in double "
                "precision and no digit of the load is left"
                if ratio < MIN_THICKNESS_RATIO
                else f"not a plate; plate.thickness must be at most {MAX_THICKNESS_RATIO:g} "
                "times it (Reissner-Mindlin theory is a model of plates up to t/b of about "
                f"{THICK_PLATE_RATIO:g})"
            )
            raise self.error(
                "thickness",
                f" = {t:g} {name} is {ratio:.3g} times {side_name} {side:g} {name}: {why}",
            )

    def _check_extent(self) -> None:
        """Sides and coordinates within :data:`MIN_SIDE` and :data:`MAX_COORDINATE`."""
        if self.file is not None:
            return
        far = max(abs(c) for corner in self.corners for c in corner)
        side = min(self.length, self.width)
        if far <= MAX_COORDINATE and side >= MIN_SIDE:
            return
        (far, side, low, high), name = in_file([far, side, MIN_SIDE, MAX_COORDINATE], "m")
        raise self.error(
            "outline" if self.outline is not None else "corners",
            f" has a coordinate of magnitude {far:g} {name} and a smaller side of {side:g} "
            f"{name}: coordinates must lie in [-{high:g}, {high:g}] {name} (put the origin "
            f"on the plate) and the sides be at least {low:g} {name}",
        )

    def _check_file(self) -> None:
        if self.file is None:
            return
        if Path(self.file).suffix.lower() not in (".geo", ".msh"):
            raise self.error("file", f" must be a gmsh .geo or .msh file, got {self.file!r}")
        if self.outline is not None or self.holes:
            raise self.error("file", ": give a file, or an outline and holes, not both")
        if not Path(self.file).is_file():
            raise self.error("file", f": no such file {self.file!r}")

    def _check_holes(self) -> None:
        outer = self.boundary
        for k, hole in enumerate(self.holes):
            if isinstance(hole, Circle):
                center = np.array([hole.center])
                room = float(distance_to_polygon(center, outer)[0])
                within = bool(points_in_polygon(center, outer)[0])
                inside = within and room > hole.radius
                (r, free, c), name = in_file([hole.radius, room, list(hole.center)], "m")
                why = (
                    f": its radius must be below its centre's distance to the plate's edge, "
                    f"{free:g} {name}, got radius = {r:g} {name}"
                    if within
                    else f": its centre [{c[0]:g}, {c[1]:g}] {name} lies outside the plate"
                )
            else:
                inside = polygon_inside(hole.vertices, outer)
                why = ": every vertex of its outline inside the plate's boundary"
            if not inside:
                raise self.error(
                    f"holes[{k}]",
                    f" must lie inside the plate, without touching its edge{why}",
                )
            for j in range(k):
                if not _disjoint(self.holes[j], hole):
                    raise self.error(f"holes[{j}]", f" and plate.holes[{k}] overlap or touch")

    def _check_edges(self) -> None:
        """Each edge part's name or segments belong to this plate."""
        used: dict[int, str] = {}
        count = len(self.outline) if self.outline is not None else 0
        for e in self.edges:
            if e.tag is not None or self.file is not None:
                continue
            where = f"edges.{e.name}"
            allowed = [*EDGE_NAMES, HOLES] if self.holes else list(EDGE_NAMES)
            if self.outline is None and e.name not in allowed:
                raise InputError(unknown_keys([e.name], "[edges]", allowed))
            if e.name == HOLES:
                _check_holes_edge(e, bool(self.holes))
            elif (self.outline is None) != (e.segments is None):
                raise InputError(
                    f"{where}.segments names segments of plate.outline, which this plate does "
                    "not have"
                    if self.outline is None
                    else f"{where}: a plate given by its outline names its boundary parts by "
                    f"segments = [k, ...] (outline segments 0 to {count - 1}), or {HOLES!r} for "
                    "the holes"
                )
            for k in e.segments or ():
                if k >= count:
                    raise InputError(
                        f"{where}.segments: {k} is not a segment of the outline (0 to "
                        f"{count - 1}: segment k runs from vertex k to vertex k + 1)"
                    )
                if k in used:
                    raise InputError(f"{where}.segments: segment {k} is already in edges.{used[k]}")
                used[k] = e.name

    @property
    def meshed_by_gmsh(self) -> bool:
        """Whether gmsh meshes the plate (an outline, holes or a file)."""
        return self.outline is not None or bool(self.holes) or self.file is not None

    @property
    def boundary(self) -> tuple[Point, ...]:
        """The outer boundary as a polygon: the outline, or the rectangle's (a file's box)."""
        if self.outline is not None:
            return self.outline
        (x0, y0), (x1, y1) = self.corners
        return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))

    @property
    def narrowest(self) -> tuple[float, str]:
        """The width b of the plate's rules on t/b and on its cells (m), and its name.

        The rectangle's smaller side; for a plate given by its outline, the smaller of its
        bounding box's sides and its narrowest width
        (:func:`~unibuckle_fenicsx.geometry.narrowest_width`: a rotated rectangle's smaller
        side, an L-shape's arm), which the bounding box is not. The name is the one the
        messages give it ("the plate's smaller side", "the plate's narrowest width").
        """
        b = min(self.length, self.width)
        if self.outline is None:
            return b, "the plate's smaller side"
        return min(b, narrowest_width(self.outline)), "the plate's narrowest width"

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

    @property
    def loaded(self) -> bool:
        """Whether an edge carries a stress per unit load (scaled by lambda)."""
        return any(e.loaded for e in self.edges)

    @property
    def fixed_loaded(self) -> bool:
        """Whether an edge carries a fixed stress."""
        return any(e.fixed_loaded for e in self.edges)

    def reference_load(self) -> tuple[float, float]:
        r"""(sigma, b): the reference edge stress per unit load and the width it acts across.

        The largest compressive normal edge stress per unit load (Pa/Pa, positive), and b
        (m) the length of the loaded edge: for the rectangle the y extent (left, right) or
        the x extent (bottom, top); for an outline, the extent of the part's segments on
        the line of its longest one (a rotated rectangle's side; a skew plate's loaded
        end, not the plate's extent along it, which takes in the offset of the opposite
        end). Without a compressive normal stress, the largest absolute shear stress per
        unit load, and b the smaller of the sheared edge's length (as above) and the
        plate's extent across it (for the rectangle its shorter side, the b of
        :math:`k_\tau = 5.34 + 4(b/a)^2`). An edge whose direction the plate does not give
        (a file's or a mesh's part, the holes): b the y extent, or for shear the smaller
        of the x and y extents. Ties: the first edge listed. Edges in tension alone: the
        least tensile stress, negative. The fixed
        stresses are not in it: (0, y extent) when no edge is loaded.
        """
        edges = [e for e in self.edges if e.loaded]
        if not edges:
            return 0.0, self.width
        normal, shear = [e.normal_ends for e in edges], [e.shear_ends for e in edges]
        k, value, kind = reference_edge(normal, shear)
        along, across = self._edge_extents(edges[k])
        length = self._edge_length(edges[k], along)
        return value, length if kind == "compressive" else min(length, across)

    def _edge_length(self, edge: EdgeSpec, along: float) -> float:
        """The length (m) of a loaded outline part: its segments on its longest one's line.

        ``along``, the plate's extent along the edge, for a part that is not an
        outline's (the rectangle's edge, whose extent it is).
        """
        if self.outline is None or edge.segments is None:
            return along
        v = np.asarray(self.outline, dtype=float)
        ends = [(v[k], v[(k + 1) % len(v)]) for k in edge.segments]
        start, end = max(ends, key=lambda pair: float(np.hypot(*(pair[1] - pair[0]))))
        t = (end - start) / np.hypot(*(end - start))
        normal = np.array([-t[1], t[0]])
        off = 1e-9 * max(self.length, self.width)  # on the line, up to rounding
        points = np.array([q for pair in ends for q in pair if abs((q - start) @ normal) <= off])
        return float(np.ptp(points @ t))

    def _edge_extents(self, edge: EdgeSpec) -> tuple[float, float]:
        """The plate's extents (m) along and across ``edge`` (see :meth:`reference_load`)."""
        if self.outline is not None and edge.segments is not None:
            v = np.asarray(self.outline, dtype=float)
            ends = [(v[k], v[(k + 1) % len(v)]) for k in edge.segments]
            start, end = max(ends, key=lambda pair: float(np.hypot(*(pair[1] - pair[0]))))
            d = end - start
            t = d / np.hypot(d[0], d[1])
            along = v[:, 0] * t[0] + v[:, 1] * t[1]
            across = v[:, 1] * t[0] - v[:, 0] * t[1]
            return float(along.max() - along.min()), float(across.max() - across.min())
        if edge.tag is None and self.file is None and edge.name in ("bottom", "top"):
            return self.length, self.width
        return self.width, self.length  # left, right, or an edge of unknown direction

    def fixed_part(self) -> PlateSpec:
        """The plate with its edges' fixed stresses as the stresses (for the fixed prestress)."""
        return replace(self, edges=tuple(e.fixed_part() for e in self.edges))

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


def _check_holes_edge(e: EdgeSpec, holes: bool) -> None:
    """The holes' boundary part: the plate has holes, no segments, a uniform stress."""
    where = f"edges.{e.name}"
    if not holes:
        raise InputError(f"{where}: the plate has no holes (plate.holes)")
    if e.segments is not None:
        raise InputError(f"{where}: the holes' boundary takes no segments")
    if not e.uniform:
        raise InputError(
            f"{where}: a linear [start, end] stress needs a straight edge; give the holes a number"
        )


class MeshSpec(Table, frozen=True):
    """Structured quadrilateral mesh of the rectangle, or the cell size of gmsh's.

    Args:
        nx: Cells along x, >= 2 (one cell cannot carry a buckle).
        ny: Cells along y, >= 2.
        size: The cell size (m), > 0, or None. A rectangle's nx and ny are then
            :meth:`cells_for` of the plate (set by :class:`ProblemSpec`); a plate meshed by
            gmsh needs it (its characteristic length), but for a ``.msh`` file.
    """

    KEY: ClassVar[str] = "mesh"
    nx: Annotated[int, Meta(ge=2)] = 20
    ny: Annotated[int, Meta(ge=2)] = 20
    size: Length | None = None

    @staticmethod
    def cells_for(length: float, width: float, size: float) -> tuple[int, int]:
        """Cells (nx, ny) of side at most ``size`` on a ``length`` x ``width`` plate (>= 2)."""
        # 1e-9: a size that divides the side exactly gives that many cells, not one more.
        nx, ny = (max(2, math.ceil(side / size * (1.0 - 1e-9))) for side in (length, width))
        return nx, ny

    @property
    def num_dofs(self) -> int:
        """DOFs of (w, theta) on this mesh: 3 per node."""
        return 3 * (self.nx + 1) * (self.ny + 1)


def _disjoint(a: Circle | Polygon, b: Circle | Polygon) -> bool:
    """Whether two holes neither overlap nor touch (a circle as a 256-gon, to 1e-4 r)."""
    if isinstance(a, Circle) and isinstance(b, Circle):
        return math.dist(a.center, b.center) > a.radius + b.radius
    pa, pb = (
        circle_points(h.center, h.radius, 256)
        if isinstance(h, Circle)
        else np.asarray(h.vertices, dtype=float)
        for h in (a, b)
    )
    return polygons_disjoint(pa, pb)
