"""Checks of a whole problem that no single key can make: supports and gmsh's features.

Run by :class:`~unibuckle_fenicsx.spec.ProblemSpec` when it is built, before any mesh:
each raises :class:`~unibuckle_fenicsx.errors.InputError` naming the keys
(:func:`plate_model_note` returns a warning instead).
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.geometry import (
    Shape,
    collinear,
    narrowest_neck,
    segment_lengths,
    shape_gap,
)
from unibuckle_fenicsx.spec.base import in_file
from unibuckle_fenicsx.spec.plate import (
    EDGE_NAMES,
    HOLES,
    THICK_PLATE_RATIO,
    Circle,
    EdgeSpec,
    MeshSpec,
    PlateSpec,
    Polygon,
)

#: Gmsh plates: a hole, a ligament or an outline segment shorter than mesh.size over
#: this is refused (gmsh's quadrilaterals cannot be graded down to it reliably: a hole of
#: radius 1e-4 m or a ligament of 2e-4 m at mesh.size = 0.01 m leave triangles).
FEATURE_RATIO = 100.0
#: Gaps below this times the plate's size are a contact (tangent holes, say): refused.
TOUCH_TOLERANCE = 1e-9


def plate_model_note(plate: PlateSpec, units: str = "SI") -> str | None:
    """A warning when t/b exceeds :data:`THICK_PLATE_RATIO`, else None.

    b is :attr:`~unibuckle_fenicsx.spec.plate.PlateSpec.narrowest` (an outline's narrowest
    width). Lengths in the unit system ``units`` (the file's; the JSON's are SI).
    """
    if plate.file is not None:
        return None
    b, side_name = plate.narrowest
    ratio = plate.thickness / b
    if ratio <= THICK_PLATE_RATIO:
        return None
    (t, side), name = in_file((plate.thickness, b), "m", units)
    return (
        f"plate.thickness = {t:g} {name} is {ratio:.3g} times {side_name} "
        f"{side:g} {name}: Reissner-Mindlin theory (transverse shear, no thickness "
        f"stretch) is a model of plates up to t/b of about {THICK_PLATE_RATIO:g}; beyond, "
        "compare with a 3-D solid model"
    )


#: Fewer cells than this across the plate's smaller side b (cells larger than b/4) draw a
#: warning: a buckle between supported edges has a half-wave of about b, and on fewer
#: cells across it the element's load is several per cent too high (the square's k by
#: cells across: docs/history/2026-11-30c-plates.md).
MIN_CELLS_ACROSS = 4
#: Under a scaled shear stress at least as large as the largest compression, fewer cells
#: than this across b draw the warning: the buckle's diagonal waves are shorter than b,
#: and the simply supported square in pure shear has k +78 % too high on 4 x 4 cells,
#: +14 % on 8 x 8 and +8.5 % on 10 x 10 (against 48 x 48; compression's +9 % at 4 across).
MIN_SHEAR_CELLS_ACROSS = 10
#: With two opposite edges clamped (the rectangle's, or an outline's segments facing each
#: other), fewer cells than this across b draw the warning: the buckle's half-waves
#: between clamped edges are shorter than b, and the clamped square's k is +55 % on 4 x 4
#: cells, +20 % on 6 x 6, +10 % on 8 x 8 (against 48 x 48; the simply supported square's
#: +9 % at 4 across), the same square given by its outline alike.
MIN_CLAMPED_CELLS_ACROSS = 8


def coarse_mesh_note(plate: PlateSpec, mesh: MeshSpec, units: str = "SI") -> str | None:
    """A warning when the cells are larger than the plate's width over 4, else None.

    The width is :attr:`~unibuckle_fenicsx.spec.plate.PlateSpec.narrowest` (an outline's
    narrowest width).

    Under a stress gradient into tension, the same for the compressed width of a loaded
    edge (:func:`_gradient_note`). The cells of the rectangle (``nx`` and ``ny``, or
    ``size`` rounded up to at least two cells a side, so a size larger than the plate is
    no error), or gmsh's ``size``; a gmsh file is not checked. Lengths in the unit
    system ``units`` (the file's).
    """
    if plate.file is not None:
        return None
    b, side_name = plate.narrowest
    if plate.meshed_by_gmsh:
        h = mesh.size if mesh.size is not None else 0.0
    else:
        h = max(plate.length / mesh.nx, plate.width / mesh.ny)
    if mesh.size is None:
        what = f"mesh.nx = {mesh.nx}, mesh.ny = {mesh.ny}"
    else:
        size, name = in_file(mesh.size, "m", units)
        what = f"mesh.size = {size:.3g} {name}" + (
            "" if plate.meshed_by_gmsh else f" ({mesh.nx} x {mesh.ny} cells, at least 2 a side)"
        )
    if h * MIN_CELLS_ACROSS > b * (1.0 + 1e-9):
        (cell, side, finer), name = in_file((h, b, b / MIN_CELLS_ACROSS), "m", units)
        return (
            f"{what}: cells up to {cell:.3g} {name}, more than a quarter of {side_name} "
            f"{side:.3g} {name} (fewer than {MIN_CELLS_ACROSS} cells across it): on cells "
            "this coarse the critical load, k and the design values come out too high (+18 % "
            f"at 3 cells across a simply supported square); cells of {finer:.3g} {name} or less"
        )
    for cells, why in _stricter_rules(plate):
        if h * cells > b * (1.0 + 1e-9):
            (cell, side, finer), name = in_file((h, b, b / cells), "m", units)
            return (
                f"{what}: cells up to {cell:.3g} {name}, fewer than {cells} across "
                f"{side_name} {side:.3g} {name} {why}; cells of {finer:.3g} {name} or less"
            )
    return _gradient_note(plate, mesh, what, units)


def _stricter_rules(plate: PlateSpec) -> list[tuple[int, str]]:
    """The rules above four cells across b that ``plate`` falls under: (cells, why).

    Shear at least as large as the compression (:data:`MIN_SHEAR_CELLS_ACROSS`), two
    opposite edges clamped (:data:`MIN_CLAMPED_CELLS_ACROSS`); ``why`` ends the warning.
    """
    rules = []
    if _shear_dominated(plate):
        rules.append(
            (
                MIN_SHEAR_CELLS_ACROSS,
                "under a shear stress at least as large as the compression "
                "(edges.*.shear_stress): a shear buckle's diagonal waves are shorter than the "
                "plate's width, and on cells this coarse the critical load and k come out too "
                "high (a simply supported square in shear: +78 % on 4 x 4 cells, +14 % on 8 x 8)",
            )
        )
    clamped = _opposite_clamped(plate)
    if clamped:
        rules.append(
            (
                MIN_CLAMPED_CELLS_ACROSS,
                f"with {clamped} clamped: the half-waves between clamped edges are shorter than "
                "the plate's width, and on cells this coarse the critical load, k and the design "
                "values come out too high (the clamped square: +55 % on 4 x 4 cells, +20 % on "
                "6 x 6)",
            )
        )
    return rules


def _opposite_clamped(plate: PlateSpec) -> str | None:
    """The first two opposite clamped edges, named for a message, or None.

    The rectangle's opposite edges (left, right; bottom, top); an outline's clamped
    segments that face each other (:func:`_facing`), named by their edges
    (``edges.a and edges.b``, or ``edges.a's segments 1 and 3``).
    """
    clamped = [e for e in plate.edges if e.support == "clamped" and e.tag is None]
    if plate.outline is None:
        names = {e.name for e in clamped if e.segments is None}
        for pair in (("left", "right"), ("bottom", "top")):
            if set(pair) <= names:
                return f"edges.{pair[0]} and edges.{pair[1]}"
        return None
    v = np.asarray(plate.outline, dtype=float)
    parts = [(e.name, k) for e in clamped for k in e.segments or ()]
    for i, (name_i, k) in enumerate(parts):
        for name_j, j in parts[i + 1 :]:
            if _facing(v, k, j):
                if name_i == name_j:
                    return f"edges.{name_i}'s segments {min(k, j)} and {max(k, j)}"
                return f"edges.{name_i} and edges.{name_j}"
    return None


#: Two outline segments face each other when their directions differ by more than 135
#: degrees (cosine below this) and their extents along the first overlap.
FACING_COSINE = -math.sqrt(0.5)


def _facing(v: npt.NDArray[np.float64], k: int, j: int) -> bool:
    """Whether outline segments k and j face each other across the plate (or a part).

    Antiparallel within 45 degrees (a simple polygon runs opposite sides of a strip in
    opposite directions) and overlapping in their extent along segment k, by more than
    1e-9 of it: a rectangle's opposite sides, an L's arm between its sides, a tapered
    strip's converging sides.
    """
    n = len(v)
    a0, a1, b0, b1 = v[k], v[(k + 1) % n], v[j], v[(j + 1) % n]
    da, db = a1 - a0, b1 - b0
    la, lb = float(np.linalg.norm(da)), float(np.linalg.norm(db))
    if float(da @ db) > FACING_COSINE * la * lb:
        return False
    u = da / la
    lo = max(0.0, min(float(u @ (b0 - a0)), float(u @ (b1 - a0))))
    hi = min(la, max(float(u @ (b0 - a0)), float(u @ (b1 - a0))))
    return hi - lo > 1e-9 * la


def _shear_dominated(plate: PlateSpec) -> bool:
    """Whether the largest scaled shear stress of an edge is at least its largest compression.

    The edges' stresses per unit load (the fixed part's share depends on the load); the
    holes' boundary and a file's parts count as the rectangle's edges do.
    """
    shear = max((abs(v) for e in plate.edges for v in e.shear_ends), default=0.0)
    compression = max((-v for e in plate.edges for v in e.normal_ends), default=0.0)
    return shear > 0.0 and shear >= compression


def _gradient_note(plate: PlateSpec, mesh: MeshSpec, what: str, units: str) -> str | None:
    r"""The warning of :func:`coarse_mesh_note` for an edge stress that turns into tension.

    Under a stress gradient :math:`\psi = \sigma_2/\sigma_1 < 0` the buckle lies in the
    compressed part of the plate, :math:`b_c = b/(1 - \psi)` wide (EN 1993-1-5 Table
    4.1), not b: it needs :data:`MIN_CELLS_ACROSS` cells across :math:`b_c`. The scaled
    normal stresses of the rectangle's edges are read (a fixed part's ratio depends on
    the load).
    """
    worst: tuple[float, float, EdgeSpec] | None = None  # (cells across b_c, h, edge)
    for e in plate.edges:
        if e.name not in EDGE_NAMES or e.segments is not None or e.tag is not None:
            continue
        along = plate.width if e.name in ("left", "right") else plate.length
        if plate.meshed_by_gmsh:
            h = mesh.size if mesh.size is not None else 0.0
        else:
            h = along / (mesh.ny if e.name in ("left", "right") else mesh.nx)
        high, low = (max(-v for v in e.normal_ends), min(-v for v in e.normal_ends))
        if not high > 0.0 > low or h <= 0.0:
            continue
        cells = along * high / (high - low) / h
        if worst is None or cells < worst[0]:
            worst = (cells, h, e)
    if worst is None or worst[0] * (1.0 + 1e-9) >= MIN_CELLS_ACROSS:
        return None
    cells, h, e = worst
    b_c = cells * h
    (cell, compressed, finer), name = in_file((h, b_c, b_c / MIN_CELLS_ACROSS), "m", units)
    start, end = e.normal_ends
    return (
        f"{what}: cells up to {cell:.3g} {name} along edges.{e.name}, whose normal_stress "
        f"[{start:g}, {end:g}] is compressive over {compressed:.3g} {name} of it (b_c = "
        f"b/(1 - psi), EN 1993-1-5 Table 4.1): fewer than {MIN_CELLS_ACROSS} cells across "
        "the compressed width, where the buckle lies; on cells this coarse the critical "
        "load, k and the design values come out too high (a simply supported square: +20 % "
        f"at psi = -1 on 6 x 6 cells, +19 % at psi = -2 on 8 x 8); cells of {finer:.3g} "
        f"{name} or less along it"
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
