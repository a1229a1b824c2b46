"""Checks of a whole problem that no single key can make: supports and gmsh's features.

Run by :class:`~unibuckle_fenicsx.spec.ProblemSpec` when it is built, before any mesh:
each raises :class:`~unibuckle_fenicsx.errors.InputError` naming the keys
(:func:`plate_model_note` returns a warning instead).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from unibuckle_fenicsx.en1993 import INTERNAL, OUTSTAND, psi_range, table_row
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.geometry import Shape, collinear, narrowest_neck, segment_lengths, shape_gap
from unibuckle_fenicsx.spec.base import stress_ends
from unibuckle_fenicsx.spec.obstacles import LoadSpec
from unibuckle_fenicsx.spec.plate import (
    EDGE_NAMES,
    HOLES,
    MAX_THICKNESS_RATIO,
    THICK_PLATE_RATIO,
    Circle,
    PlateSpec,
    Polygon,
)

__all__ = [
    "FEATURE_RATIO",
    "MAX_THICKNESS_RATIO",
    "THICK_PLATE_RATIO",
    "TOUCH_TOLERANCE",
    "DesignElement",
    "check_features",
    "check_supports",
    "design_element",
    "plate_features",
    "plate_model_note",
]

#: Gmsh plates: a hole, a ligament or an outline segment shorter than mesh.size over
#: this is refused (gmsh's quadrilaterals cannot be graded down to it reliably: a hole of
#: radius 1e-4 m or a ligament of 2e-4 m at mesh.size = 0.01 m leave triangles).
FEATURE_RATIO = 100.0
#: Gaps below this times the plate's size are a contact (tangent holes, say): refused.
TOUCH_TOLERANCE = 1e-9


def plate_model_note(plate: PlateSpec) -> str | None:
    """A warning when t/b exceeds :data:`THICK_PLATE_RATIO`, else None."""
    if plate.file is not None:
        return None
    b = min(plate.length, plate.width)
    ratio = plate.thickness / b
    if ratio <= THICK_PLATE_RATIO:
        return None
    return (
        f"plate.thickness = {plate.thickness:g} m is {ratio:.3g} times the plate's smaller "
        f"side {b:g} m: Reissner-Mindlin theory (transverse shear, no thickness stretch) is "
        f"a model of plates up to t/b of about {THICK_PLATE_RATIO:g}; beyond, compare with a "
        "3-D solid model"
    )


def check_supports(plate: PlateSpec, foundation: bool) -> None:
    """Refuse supports that leave a rigid-body motion of the deflection (a mechanism).

    With no clamped edge, the supported boundary must not lie on one straight line
    (a plate held on one line turns about it): every edge free, or a single simply
    supported edge, is refused. A bilateral foundation (springs everywhere) holds the
    plate, an obstacle or a tensionless foundation does not (the plate lifts off it).
    An edge given by a facet tag of a user mesh is taken to hold the plate; for a gmsh
    file only "every part free" is checked (its geometry is known once meshed).

    Args:
        plate: The plate and its edges.
        foundation: Whether a bilateral foundation holds the plate.

    Raises:
        InputError: Naming ``edges.*.support``.
    """
    if foundation:
        return
    held = [e for e in plate.edges if e.support != "free"]
    if any(e.support == "clamped" for e in held):
        return
    if held and (plate.file is not None or any(e.tag is not None for e in held)):
        return  # a file's or a user mesh's parts: their geometry is known once meshed
    size = max(plate.length, plate.width)
    points: list[tuple[float, float]] = []
    for e in held:
        if e.name == HOLES and plate.holes:
            if any(isinstance(h, Circle) for h in plate.holes):
                return
            points += [v for h in plate.holes if isinstance(h, Polygon) for v in h.vertices]
        elif e.segments is not None and plate.outline is not None:
            v = plate.outline
            points += [v[k] for k in e.segments] + [v[(k + 1) % len(v)] for k in e.segments]
        elif e.name in EDGE_NAMES:
            (x0, y0), (x1, y1) = plate.corners
            points += {
                "left": [(x0, y0), (x0, y1)],
                "right": [(x1, y0), (x1, y1)],
                "bottom": [(x0, y0), (x1, y0)],
                "top": [(x0, y1), (x1, y1)],
            }[e.name]
    if held and not collinear(np.asarray(points, dtype=float), size):
        return
    if not held:
        what = "every boundary part is free"
    else:
        names = ", ".join(f"edges.{e.name}.support = {e.support!r}" for e in held)
        what = f"the only support ({names}) lies on one straight line"
    raise InputError(
        f"edges.*.support: {what}: the plate can move as a rigid body (a mechanism, no "
        "buckling load); support edges that are not all in line (e.g. simply_supported "
        'on two opposite edges), clamp one, or add a bilateral foundation (side = "both")'
    )


def plate_features(plate: PlateSpec) -> list[tuple[float, str]]:
    """The smallest lengths gmsh must resolve, each with the keys it comes from.

    Hole diameters and shortest hole segments, the gaps between a hole and the plate's
    edge and between two holes, the outline's shortest segment and narrowest neck.
    Sorted, smallest first.
    """
    outer = np.asarray(plate.boundary, dtype=float)
    out: list[tuple[float, str]] = []
    if plate.outline is not None:
        k = int(np.argmin(segment_lengths(outer)))
        out.append((float(segment_lengths(outer)[k]), f"plate.outline segment {k}"))
        if len(outer) > 3:
            out.append((narrowest_neck(outer), "plate.outline (its narrowest neck)"))
    shapes: list[tuple[str, Shape]] = []
    for k, hole in enumerate(plate.holes):
        where = f"plate.holes[{k}]"
        shape: Shape
        if isinstance(hole, Circle):
            shape = (hole.center, hole.radius)
            out.append((2.0 * hole.radius, f"{where}.radius = {hole.radius:g} m (its diameter)"))
        else:
            shape = np.asarray(hole.vertices, dtype=float)
            j = int(np.argmin(segment_lengths(shape)))
            out.append((float(segment_lengths(shape)[j]), f"{where}.outline segment {j}"))
        out.append((shape_gap(shape, outer), f"the gap between {where} and the plate's edge"))
        out += [
            (shape_gap(other, shape), f"the gap between {w} and {where}") for w, other in shapes
        ]
        shapes.append((where, shape))
    return sorted(out, key=lambda item: item[0])


def check_features(plate: PlateSpec, mesh_size: float | None) -> None:
    """Refuse holes that touch, and features gmsh cannot resolve at ``mesh_size``.

    A gap below :data:`TOUCH_TOLERANCE` times the plate's size is a contact; with a mesh
    size (a plate meshed here by gmsh), every length of :func:`plate_features` must be
    at least ``mesh_size /`` :data:`FEATURE_RATIO`.

    Raises:
        ValueError: Naming the hole or outline, and ``mesh.size``.
    """
    if not plate.holes and plate.outline is None:
        return
    size = max(plate.length, plate.width)
    features = plate_features(plate)
    for length, what in features:
        if what.startswith("the gap") and length <= TOUCH_TOLERANCE * size:
            raise InputError(
                f"{what} is {length:.3g} m: the hole touches it; holes must lie inside the "
                "plate without touching its edge or each other"
            )
    if mesh_size is None or plate.file is not None:
        return
    limit = mesh_size / FEATURE_RATIO
    for length, what in features:
        if length < limit:
            raise InputError(
                f"{what} is {length:.3g} m, below mesh.size / {FEATURE_RATIO:g} = {limit:.3g} "
                "m: gmsh cannot grade its quadrilaterals from mesh.size down to it; give a "
                "smaller mesh.size or a larger feature"
            )


#: The rectangle's edges in pairs of opposite edges, and the coordinate each pair's edges
#: run along (a [start, end] stress runs from the smaller coordinate to the larger).
_PAIRS = {("left", "right"): ("bottom", "top"), ("bottom", "top"): ("left", "right")}


@dataclass(frozen=True)
class DesignElement:
    """The plate as a compression element of EN 1993-1-5 4.4 (:mod:`unibuckle_fenicsx.en1993`).

    Attributes:
        kind: "internal" (both unloaded edges supported) or "outstand" (one free).
        loaded: The two opposite edges across which the direct stress acts.
        unloaded: The two edges parallel to it.
        free_edge: The free unloaded edge of an outstand, else None.
    """

    kind: str
    loaded: tuple[str, str]
    unloaded: tuple[str, str]
    free_edge: str | None = None

    @property
    def free_end(self) -> int | None:
        """Which end (0 start, 1 end) of a loaded edge lies on the free edge, or None.

        A loaded edge runs from its end with the smaller coordinate to the larger, so its
        start lies on the first edge of ``unloaded`` (bottom, or left).
        """
        if self.free_edge is None:
            return None
        return self.unloaded.index(self.free_edge)


@dataclass(frozen=True)
class _Edge:
    """What the design check reads of an edge (an edge the plate does not name is free)."""

    name: str
    support: str = "free"
    inplane: str = "free"
    translational_stiffness: float = 0.0
    normal: tuple[float, float] = (0.0, 0.0)
    fixed_normal: tuple[float, float] = (0.0, 0.0)


def _edge(plate: PlateSpec, name: str) -> _Edge:
    for e in plate.edges:
        if e.name == name:
            return _Edge(
                name,
                e.support,
                e.inplane,
                e.translational_stiffness,
                stress_ends(e.normal_stress),
                stress_ends(e.fixed_normal_stress),
            )
    return _Edge(name)


class _Problem(Protocol):
    """What :func:`design_element` reads of a :class:`~unibuckle_fenicsx.spec.ProblemSpec`.

    (``spec.problem`` imports this module: a protocol, not an import of it.)
    """

    @property
    def plate(self) -> PlateSpec: ...

    @property
    def load(self) -> LoadSpec: ...


def design_element(spec: _Problem) -> DesignElement:
    """Classify the plate for the design output (EN 1993-1-5 4.4(2)), or refuse it.

    The direct stress acts across the edges given a normal stress (scaled or fixed); the
    other two edges are the unloaded ones: both supported, an internal element (Table
    4.1); one free (``support = "free"``, no translational spring), an outstand (Table
    4.2). A stress ratio outside the element's table is refused here when the scaled
    stresses alone fix it (no fixed normal stress); with a fixed part it depends on the
    load and the output says so.

    Raises:
        InputError: What clause 4.4 does not describe, naming the keys: a plate that is
            not a rectangle (outline, file), a temperature rise, normal stress in
            both directions (biaxial), both unloaded edges free, a free edge on springs,
            an unloaded edge held in its plane (a transverse stress), a stress ratio
            outside the table.
    """
    plate, load = spec.plate, spec.load
    why = (
        "is given by its outline"
        if plate.outline is not None
        else "is a gmsh file"
        if plate.file is not None
        else ""
    )
    if why:
        raise InputError(
            f"design: EN 1993-1-5 4.4 describes a rectangular plate element by its two "
            f"unloaded edges; this plate {why} (plate.outline, plate.file): leave [design] "
            "out, or give the rectangle's plate.corners"
        )
    thermal = load.thermal or (load.fixed_thermal and load.fixed_factor != 0.0)
    if thermal:
        key = "load.temperature" if load.thermal else "load.fixed_temperature"
        raise InputError(
            f"design: {key}: a temperature rise adds a membrane stress (set by the in-plane "
            "supports) that the edge stresses, from which the design output takes sigma_cr "
            "and psi, do not show: leave [design] or the temperature out"
        )
    fixed = load.fixed_factor != 0.0
    sides = {name: _edge(plate, name) for name in EDGE_NAMES}
    stressed = [f"edges.{name}.normal_stress" for name, e in sides.items() if any(e.normal)]
    stressed += [
        f"edges.{name}.fixed_normal_stress"
        for name, e in sides.items()
        if fixed and any(e.fixed_normal)
    ]
    pairs = [pair for pair in _PAIRS if any(key.split(".")[1] in pair for key in stressed)]
    if len(pairs) != 1:
        given = ", ".join(stressed)
        raise InputError(
            f"design: {given} give normal stress in both directions (biaxial): EN 1993-1-5 "
            "4.4 describes direct stress in one direction (section 10 combines biaxial "
            "stresses, which is not done here); leave [design] out"
        )
    loaded = pairs[0]
    unloaded = _PAIRS[loaded]
    edges = [sides[name] for name in unloaded]
    for e in edges:
        if e.inplane != "free":
            raise InputError(
                f'design: edges.{e.name}.inplane = "{e.inplane}" holds an unloaded edge in '
                "its plane, which adds a transverse stress (Poisson's ratio times the direct "
                "stress) that EN 1993-1-5 4.4 does not describe: leave the unloaded edges "
                'free in their plane (inplane = "free") or [design] out'
            )
        if e.support == "free" and e.translational_stiffness > 0.0:
            raise InputError(
                f"design: edges.{e.name}.translational_stiffness: an unloaded edge on springs "
                "is neither supported (an internal element, EN 1993-1-5 Table 4.1) nor free "
                '(an outstand, Table 4.2): give it support = "simply_supported" or no springs'
            )
    free = [e.name for e in edges if e.support == "free"]
    if len(free) == 2:
        raise InputError(
            f'design: edges.{unloaded[0]}.support and edges.{unloaded[1]}.support are both "free": '
            "with both unloaded edges free the plate is a strut (column-like buckling), "
            "neither an internal nor an outstand element of EN 1993-1-5 4.4; leave [design] "
            "out or support an unloaded edge"
        )
    element = DesignElement(
        OUTSTAND if free else INTERNAL, loaded, unloaded, free[0] if free else None
    )
    if not (fixed and any(any(sides[name].fixed_normal) for name in loaded)):
        _check_stress_ratio([sides[name] for name in loaded], element)
    return element


def _check_stress_ratio(loaded: list[_Edge], element: DesignElement) -> None:
    """Refuse a stress ratio psi (of the scaled stresses alone) outside the element's table."""
    best: tuple[float, float, int, str] = (0.0, 0.0, 0, "")
    for e in loaded:
        ends = [-v for v in e.normal]  # compression positive
        for k in (0, 1):
            if ends[k] > best[0]:
                best = (ends[k], ends[1 - k], k, e.name)
    sigma1, sigma2, k, name = best
    if sigma1 <= 0.0:
        return  # no scaled compression: the compression check says so
    psi = sigma2 / sigma1
    at_free = element.free_end is None or k == element.free_end or psi == 1.0
    low, _ = psi_range(element.kind, at_free)
    if psi < low:
        raise InputError(
            f"design: edges.{name}.normal_stress gives the stress ratio psi = sigma_2/sigma_1 "
            f"= {psi:.4g}, outside EN 1993-1-5 {table_row(element.kind, at_free)}, which "
            f"covers 1 >= psi >= {low:g}: leave [design] out or change the stress gradient"
        )
