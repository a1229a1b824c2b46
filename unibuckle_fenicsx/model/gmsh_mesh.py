"""Plates meshed by gmsh: a polygon outline with circular or polygonal holes, or a file.

Quadrilaterals for the MITC element: gmsh's Frontal-Delaunay for quads (``Mesh.Algorithm =
8``) with the Blossom full-quad recombination (``Mesh.RecombinationAlgorithm = 3``), which
leaves no triangle; the model is read by :func:`dolfinx.io.gmsh.model_to_mesh` on rank 0
and distributed over the communicator.

Boundary parts are gmsh physical curves: outline segment k has the tag
:func:`segment_tag` (k + 1, named ``segment_k``); a rectangle with holes keeps the
rectangle's tags 1..4 (left, right, bottom, top); the holes' boundary is :data:`HOLES_TAG`
(named ``holes``). A file brings its own physical curves, matched to ``[edges.NAME]``
by name.

**Obstacle zones are mesh lines.** The edges of box, polygon and circle zones (a
degenerate box: a line or a point) are cut into the plate with OpenCASCADE's
``fragment``, so that mesh nodes lie on them and the discrete zone is the zone given
(a circle: the polygon of at least :data:`ZONE_CIRCLE_SEGMENTS` cell edges its nodes
inscribe). Without such a zone the plate is built by gmsh's own kernel, as before.
**Parallelogram patches are structured**: a surface bounded by four straight curves in
two parallel pairs of equal length (the rectangle, the bands a zone cuts from it) gets a
transfinite grid with ceil(side / size) cells a side, the structured mesh's rule, so
the gmsh rectangle is the structured grid wherever it lies. Where gmsh cannot mesh the
plate so, it retries without the structured patches, then without the zone lines (a
warning); a plate it cannot mesh at all is refused with its smallest features named.

gmsh is an optional dependency (the ``gmsh`` extra); it is imported when a plate needs it.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from typing import Any

from mpi4py import MPI

import dolfinx
import dolfinx.io.gmsh

import numpy as np

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.geometry import distance_to_polygon
from unibuckle_fenicsx.spec import EDGE_NAMES, Circle, MeshSpec, ObstacleSpec, PlateSpec, Polygon
from unibuckle_fenicsx.spec.base import in_file, unit_name
from unibuckle_fenicsx.spec.checks import FEATURE_RATIO, plate_features
from unibuckle_fenicsx.tolerances import GEOMETRY_RTOL

__all__ = [
    "HOLES_TAG",
    "SURFACE_TAG",
    "ZONE_CIRCLE_SEGMENTS",
    "gmsh_plate_mesh",
    "import_gmsh",
    "segment_tag",
    "zone_curves",
]

logger = logging.getLogger(__name__)

#: Physical tag of the holes' boundary.
HOLES_TAG = 10000
#: Physical tag of the plate's surface.
SURFACE_TAG = 1
#: Circles get at least this many cell edges, whatever the cell size.
CIRCLE_SEGMENTS = 16
#: Circular zones get at least this many: the inscribed 32-gon has n sin(2 pi/n)/(2 pi)
#: = 99.36 % of the disc's area.
ZONE_CIRCLE_SEGMENTS = 32
#: gmsh options of the quadrilateral mesh.
GMSH_OPTIONS: dict[str, float] = {
    "General.Terminal": 0,
    "Mesh.Algorithm": 8,  # Frontal-Delaunay for quads
    "Mesh.RecombineAll": 1,
    "Mesh.RecombinationAlgorithm": 3,  # Blossom full-quad: no triangle left
    "Mesh.ElementOrder": 1,
}


def segment_tag(k: int) -> int:
    """Physical tag of outline segment k."""
    return k + 1


def import_gmsh() -> Any:
    """The gmsh module, or an ImportError naming the extra that installs it."""
    try:
        import gmsh
    except ImportError as err:
        raise ImportError(
            "plates with an outline, holes or a gmsh file are meshed by gmsh, which is not "
            f"installed ({err}): pip install 'unibuckle_fenicsx[gmsh]'"
        ) from None
    return gmsh


def _outline_parts(plate: PlateSpec) -> list[int]:
    """Physical tag of each segment of the outer boundary."""
    if plate.outline is not None:
        return [segment_tag(k) for k in range(len(plate.outline))]
    # The rectangle (x0, y0) -> (x1, y0) -> (x1, y1) -> (x0, y1): bottom, right, top, left.
    return [EDGE_NAMES.index(name) + 1 for name in ("bottom", "right", "top", "left")]


def _build(gmsh: Any, plate: PlateSpec, size: float) -> None:
    """The plate's geometry and physical groups in the current gmsh model."""
    geo = gmsh.model.geo
    outline = plate.boundary
    points = [geo.addPoint(x, y, 0.0, size) for x, y in outline]
    lines = [geo.addLine(points[k], points[(k + 1) % len(points)]) for k in range(len(points))]
    loops = [geo.addCurveLoop(lines)]
    hole_curves: list[int] = []
    for hole in plate.holes:
        if isinstance(hole, Circle):
            (cx, cy), r = hole.center, hole.radius
            h = min(size, 2.0 * np.pi * r / CIRCLE_SEGMENTS)
            center = geo.addPoint(cx, cy, 0.0, h)
            ring = [
                geo.addPoint(cx + r * np.cos(a), cy + r * np.sin(a), 0.0, h)
                for a in 0.5 * np.pi * np.arange(4)
            ]
            curves = [geo.addCircleArc(ring[k], center, ring[(k + 1) % 4]) for k in range(4)]
        else:
            hp = [geo.addPoint(x, y, 0.0, size) for x, y in hole.vertices]
            curves = [geo.addLine(hp[k], hp[(k + 1) % len(hp)]) for k in range(len(hp))]
        loops.append(geo.addCurveLoop(curves))
        hole_curves += curves
    surface = geo.addPlaneSurface(loops)
    geo.synchronize()
    parts = _outline_parts(plate)
    for line, tag in zip(lines, parts, strict=True):
        name = f"segment_{tag - 1}" if plate.outline is not None else EDGE_NAMES[tag - 1]
        gmsh.model.addPhysicalGroup(1, [line], tag, name=name)
    if hole_curves:
        gmsh.model.addPhysicalGroup(1, hole_curves, HOLES_TAG, name="holes")
    gmsh.model.addPhysicalGroup(2, [surface], SURFACE_TAG, name="plate")


#: A zone's curve for the mesh: ("polyline", vertices, closed, from a box), ("circle",
#: center, radius) or ("point", (x, y)).
Curve = tuple[Any, ...]


def zone_curves(obstacles: Sequence[ObstacleSpec], size: float) -> list[Curve]:
    """The curves of the obstacles' zones that become mesh lines.

    Boxes (a degenerate box: a segment or a point), polygons and circles; "all" and
    predicates have none, and a circle smaller than ``size /`` :data:`FEATURE_RATIO`
    (which gmsh cannot resolve) is left out.
    """
    curves: list[Curve] = []
    for obstacle in obstacles:
        zone = obstacle.zone
        if isinstance(zone, Circle):
            if 2.0 * zone.radius >= size / FEATURE_RATIO:
                curves.append(("circle", zone.center, zone.radius))
        elif isinstance(zone, Polygon):
            curves.append(("polyline", zone.vertices, True, False))
        elif isinstance(zone, tuple):
            (x0, x1), (y0, y1) = zone
            if x0 == x1 and y0 == y1:
                curves.append(("point", (x0, y0)))
            elif x0 == x1 or y0 == y1:
                curves.append(("polyline", ((x0, y0), (x1, y1)), False, True))
            else:
                box = ((x0, y0), (x1, y0), (x1, y1), (x0, y1))
                curves.append(("polyline", box, True, True))
    return curves


def _grid_lines(plate: PlateSpec, curves: list[Curve]) -> list[Curve]:
    """On a rectangle without holes: the lines of the zones' box edges across the plate.

    They cut the plate into rectangles (structured patches), so that a zone whose edges
    lie on the structured grid's lines gives the structured grid itself.
    """
    if plate.holes:
        return []
    (x0, y0), (x1, y1) = plate.corners
    if plate.outline is not None and set(plate.outline) != {(x0, y0), (x1, y0), (x1, y1), (x0, y1)}:
        return []
    xs: set[float] = set()
    ys: set[float] = set()
    for curve in curves:
        if curve[0] == "point":
            xs.add(curve[1][0])
            ys.add(curve[1][1])
        elif curve[0] == "polyline" and curve[3]:
            xs.update(float(v[0]) for v in curve[1])
            ys.update(float(v[1]) for v in curve[1])
    lines: list[Curve] = [
        ("polyline", ((x, y0), (x, y1)), False) for x in sorted(xs) if x0 < x < x1
    ]
    lines += [("polyline", ((x0, y), (x1, y)), False) for y in sorted(ys) if y0 < y < y1]
    return lines


def _build_occ(gmsh: Any, plate: PlateSpec, size: float, curves: list[Curve]) -> None:
    """The plate with the zone curves cut into it (OpenCASCADE), and its physical groups."""
    occ = gmsh.model.occ

    def loop(vertices: Sequence[Sequence[float]]) -> int:
        points = [occ.addPoint(x, y, 0.0) for x, y in vertices]
        n = len(points)
        return occ.addCurveLoop([occ.addLine(points[k], points[(k + 1) % n]) for k in range(n)])

    body = [(2, occ.addPlaneSurface([loop(plate.boundary)]))]
    cutters = []
    for hole in plate.holes:
        if isinstance(hole, Circle):
            (cx, cy), r = hole.center, hole.radius
            cutters.append((2, occ.addDisk(cx, cy, 0.0, r, r)))
        else:
            cutters.append((2, occ.addPlaneSurface([loop(hole.vertices)])))
    if cutters:
        body, _ = occ.cut(body, cutters)
    tools = []
    for curve in curves:
        if curve[0] == "circle":
            (cx, cy), r = curve[1], curve[2]
            tools.append((1, occ.addCircle(cx, cy, 0.0, r)))
        elif curve[0] == "point":
            tools.append((0, occ.addPoint(*curve[1], 0.0)))
        else:
            vertices, closed = curve[1], curve[2]
            points = [occ.addPoint(x, y, 0.0) for x, y in vertices]
            n = len(points)
            for k in range(n if closed else n - 1):
                tools.append((1, occ.addLine(points[k], points[(k + 1) % n])))
    occ.fragment(body, tools)
    occ.synchronize()
    _drop_outside(gmsh)
    circles = [(h.center, h.radius, CIRCLE_SEGMENTS) for h in plate.holes if isinstance(h, Circle)]
    circles += [(c[1], c[2], ZONE_CIRCLE_SEGMENTS) for c in curves if c[0] == "circle"]
    _point_sizes(gmsh, size, circles)
    _groups_by_position(gmsh, plate)


def _drop_outside(gmsh: Any) -> None:
    """Remove the zone curves and points that ``fragment`` left outside the plate."""
    keep: dict[int, set[int]] = {1: set(), 0: set()}
    for _, s in gmsh.model.getEntities(2):
        for dim, tag in gmsh.model.getBoundary([(2, s)], combined=False, oriented=False):
            keep[dim].add(tag)
        for dim, tag in gmsh.model.mesh.getEmbedded(2, s):
            keep[dim].add(tag)
    for c in list(keep[1]):
        for _, tag in gmsh.model.getBoundary([(1, c)], combined=False, oriented=False):
            keep[0].add(tag)
    drop = [(1, t) for _, t in gmsh.model.getEntities(1) if t not in keep[1]]
    drop += [(0, t) for _, t in gmsh.model.getEntities(0) if t not in keep[0]]
    if drop:
        gmsh.model.occ.remove(drop)
        gmsh.model.occ.synchronize()


def _point_sizes(
    gmsh: Any, size: float, circles: list[tuple[tuple[float, float], float, int]]
) -> None:
    """Mesh size ``size`` at every point, smaller on circles (n cell edges at least)."""
    for _, p in gmsh.model.getEntities(0):
        x, y, _ = gmsh.model.getValue(0, p, [])
        h = size
        for (cx, cy), r, n in circles:
            if abs(math.hypot(x - cx, y - cy) - r) <= GEOMETRY_RTOL * max(r, size):
                h = min(h, 2.0 * math.pi * r / n)
        gmsh.model.mesh.setSize([(0, p)], h)


def _groups_by_position(gmsh: Any, plate: PlateSpec) -> None:
    """Physical groups: each boundary curve goes to the outline segment or hole it lies on."""
    outline = np.asarray(plate.boundary, dtype=float)
    parts = _outline_parts(plate)
    tol = 1e-7 * max(plate.length, plate.width)
    groups: dict[int, list[int]] = {}
    for _, c in gmsh.model.getEntities(1):
        lo, hi = gmsh.model.getParametrizationBounds(1, c)
        mid = np.asarray(gmsh.model.getValue(1, c, [0.5 * (lo[0] + hi[0])]))[:2]
        n = len(outline)
        for k in range(n):
            segment = np.array([outline[k], outline[(k + 1) % n]])
            if distance_to_polygon(mid[None, :], segment)[0] <= tol:
                groups.setdefault(parts[k], []).append(c)
                break
        else:
            for hole in plate.holes:
                if isinstance(hole, Circle):
                    on = abs(math.dist(mid, hole.center) - hole.radius) <= tol
                else:
                    on = bool(distance_to_polygon(mid[None, :], hole.vertices)[0] <= tol)
                if on:
                    groups.setdefault(HOLES_TAG, []).append(c)
                    break
    for tag, curves in sorted(groups.items()):
        if tag == HOLES_TAG:
            name = "holes"
        elif plate.outline is not None:
            name = f"segment_{tag - 1}"
        else:
            name = EDGE_NAMES[tag - 1]
        gmsh.model.addPhysicalGroup(1, curves, tag, name=name)
    surfaces = [s for _, s in gmsh.model.getEntities(2)]
    gmsh.model.addPhysicalGroup(2, surfaces, SURFACE_TAG, name="plate")


def _structure_parallelograms(gmsh: Any, size: float) -> int:
    """Transfinite grids on the parallelogram surfaces; returns how many."""
    count = 0
    for _, s in gmsh.model.getEntities(2):
        boundary = gmsh.model.getBoundary([(2, s)], combined=False, oriented=False)
        if len(boundary) != 4 or gmsh.model.mesh.getEmbedded(2, s):
            continue
        ends = []
        for _, c in boundary:
            if gmsh.model.getType(1, c) != "Line":
                break
            points = gmsh.model.getBoundary([(1, c)], combined=False, oriented=True)
            ends.append([np.asarray(gmsh.model.getValue(0, abs(p), []))[:2] for _, p in points])
        if len(ends) != 4:
            continue
        vectors = [b - a for a, b in ends]
        lengths = [float(np.linalg.norm(v)) for v in vectors]
        paired: set[int] = set()
        for j in range(4):
            for k in range(j + 1, 4):
                cross = vectors[j][0] * vectors[k][1] - vectors[j][1] * vectors[k][0]
                if abs(cross) <= GEOMETRY_RTOL * lengths[j] * lengths[k] and abs(
                    lengths[j] - lengths[k]
                ) <= GEOMETRY_RTOL * max(lengths[j], lengths[k]):
                    paired.update((j, k))
        if len(paired) != 4:
            continue
        for (_, c), length in zip(boundary, lengths, strict=True):
            cells = max(1, math.ceil(length / size * (1.0 - GEOMETRY_RTOL)))
            gmsh.model.mesh.setTransfiniteCurve(c, cells + 1)
        gmsh.model.mesh.setTransfiniteSurface(s)
        gmsh.model.mesh.setRecombine(2, s)
        count += 1
    return count


def _features_text(plate: PlateSpec) -> str:
    """The plate's two smallest features, for a message."""
    features = plate_features(plate)[:2]
    return (
        "; ".join("{}: {:.3g} {}".format(what, *in_file(length, "m")) for length, what in features)
        or "none"
    )


def _quadrilaterals_only(gmsh: Any, hint: str = "") -> None:
    kinds = {
        gmsh.model.mesh.getElementProperties(t)[0]: len(tags)
        for t, tags in zip(*gmsh.model.mesh.getElements(2)[:2], strict=True)
    }
    others = {k: n for k, n in kinds.items() if not k.startswith("Quadrilateral 4")}
    if others or not kinds:
        raise InputError(
            f"the gmsh mesh must consist of bilinear quadrilaterals (the MITC element), got "
            f"{kinds or 'no 2-D cells'}{hint}"
        )


def gmsh_plate_mesh(
    plate: PlateSpec,
    spec: MeshSpec,
    comm: MPI.Comm = MPI.COMM_WORLD,
    obstacles: Sequence[ObstacleSpec] = (),
) -> tuple[dolfinx.mesh.Mesh, dolfinx.mesh.MeshTags, dict[str, int]]:
    """Quadrilateral mesh of ``plate`` by gmsh, distributed over ``comm``.

    Args:
        plate: An outline or a rectangle with holes (built here), or a file.
        spec: ``size``, gmsh's characteristic cell size (m); for a ``.geo`` file, the
            largest cell size if given.
        comm: Communicator (gmsh runs on its rank 0).
        obstacles: Obstacles whose zones' edges become mesh lines (:func:`zone_curves`;
            not in a file's mesh).

    Returns:
        The mesh, its facet tags (physical curves) and the physical curves' tags by name.

    Raises:
        ImportError: gmsh is not installed (the message names the extra).
        ValueError: A mesh that is not made of quadrilaterals (for a plate built here,
            the message names its smallest features and mesh.size), or a file without
            a physical surface.

    Note:
        Collective.
    """
    gmsh = _import_on_root(comm)
    error = _mesh_on_root(gmsh, plate, spec, obstacles) if comm.rank == 0 else None
    error = comm.bcast(error, root=0)
    if error is not None:
        raise InputError(error)
    try:
        model = gmsh.model if gmsh is not None else None
        data = dolfinx.io.gmsh.model_to_mesh(model, comm, 0, gdim=2)
    finally:
        if comm.rank == 0:
            if gmsh is None:
                raise RuntimeError(
                    "gmsh_plate_mesh: expected gmsh is not None (an internal invariant)"
                )
            gmsh.finalize()
    msh = data.mesh
    tags = data.facet_tags
    if tags is None:
        fdim = msh.topology.dim - 1
        empty = np.empty(0, dtype=np.int32)
        tags = dolfinx.mesh.meshtags(msh, fdim, empty, empty)
    groups = {name: int(g.tag) for name, g in data.physical_groups.items() if g.dim == 1}
    return msh, tags, groups


def _import_on_root(comm: MPI.Comm) -> Any:
    """Gmsh on rank 0 (None on the others); an ImportError on every rank if it is missing.

    Collective.
    """
    error: str | None = None
    gmsh = None
    if comm.rank == 0:
        try:
            gmsh = import_gmsh()
        except ImportError as err:
            error = str(err)
    error = comm.bcast(error, root=0)
    if error is not None:
        raise ImportError(error)
    return gmsh


def _mesh_on_root(
    gmsh: Any, plate: PlateSpec, spec: MeshSpec, obstacles: Sequence[ObstacleSpec]
) -> str | None:
    """Mesh the plate in a new gmsh session (rank 0); why it failed, or None.

    On a failure the session is closed; on success it stays open for the mesh to be
    distributed.
    """
    if gmsh is None:
        raise RuntimeError("gmsh_plate_mesh: expected gmsh is not None (an internal invariant)")
    if plate.file is None and spec.size is None:
        raise RuntimeError(
            "gmsh_plate_mesh: expected spec.size is not None (an internal invariant)"
        )
    gmsh.initialize(interruptible=False)
    error: str | None = None
    try:
        for key, value in GMSH_OPTIONS.items():
            gmsh.option.setNumber(key, value)
        if plate.file is not None:
            _mesh_file(gmsh, plate, spec)
        else:
            size = float(spec.size or 0.0)  # checked above
            _mesh_built(gmsh, plate, size, zone_curves(obstacles, size))
    except ValueError as err:
        error = str(err) if plate.file is None else f"plate.file {plate.file}: {err}"
    except Exception as err:  # gmsh raises plain Exceptions
        error = f"gmsh failed to mesh the plate: {err}"
    if error is not None:
        gmsh.finalize()
    return error


def _mesh_file(gmsh: Any, plate: PlateSpec, spec: MeshSpec) -> None:
    """Open (and mesh, for a .geo) the plate's file in the current gmsh session."""
    if plate.file is None:
        raise RuntimeError("_mesh_file: expected plate.file is not None (an internal invariant)")
    gmsh.open(plate.file)
    if not plate.file.lower().endswith(".msh"):
        if spec.size is not None:
            gmsh.option.setNumber("Mesh.MeshSizeMax", spec.size)
        gmsh.model.mesh.generate(2)
    if not gmsh.model.getPhysicalGroups(2):
        raise InputError(
            "no physical surface (Physical Surface(...) = {...}): gmsh's cells "
            "reach DOLFINx through physical groups"
        )
    _quadrilaterals_only(
        gmsh, "; recombine the mesh (Recombine Surface{...}, Mesh.RecombineAll = 1)"
    )


def _mesh_built(gmsh: Any, plate: PlateSpec, size: float, curves: list[Curve]) -> None:
    """Build and mesh the plate: structured patches and zone lines, dropped if need be.

    Raises:
        ValueError: No attempt gave a mesh of quadrilaterals; the message names the
            plate's smallest features and mesh.size.
    """
    attempts: list[tuple[list[Curve], bool]] = []
    if curves:
        attempts += [(curves + _grid_lines(plate, curves), True), (curves, False)]
    attempts += [([], True), ([], False)]
    failures = []
    for zone_lines, structured in attempts:
        gmsh.clear()
        gmsh.model.add("plate")
        try:
            if zone_lines:
                _build_occ(gmsh, plate, size, zone_lines)
            else:
                _build(gmsh, plate, size)
            if structured and not _structure_parallelograms(gmsh, size):
                continue  # nothing to structure: the next attempt is the same mesh
            gmsh.model.mesh.generate(2)
            _quadrilaterals_only(gmsh)
        except Exception as err:  # gmsh raises plain Exceptions
            failures.append(str(err).splitlines()[0])
            continue
        if curves and not zone_lines:
            logger.warning(
                "gmsh could not mesh the plate with the obstacle zones' edges as mesh lines "
                "(%s): they are not; the discrete zones differ from the zones given "
                "(obstacle_zones in the result)",
                failures[0],
            )
        return
    raise InputError(
        f"gmsh could not mesh the plate with quadrilaterals only at mesh.size = "
        f"{in_file(size, 'm')[0]:g} {unit_name('m')} "
        f"({failures[-1]}); the plate's smallest features: {_features_text(plate)}: give a "
        "smaller mesh.size, or enlarge them"
    )
