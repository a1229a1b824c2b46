"""Plane geometry of outlines, holes and obstacle zones: polygons and circles (numpy only).

Hand-written (a few dozen lines each: point in polygon, distances, convex clipping, ear
clipping) so that the package needs no geometry library for its checks and its zone
areas; gmsh, which would do the clipping, is an optional extra.

Polygons are sequences of vertices (x, y), closed implicitly (the last vertex joins the
first); segment k runs from vertex k to vertex k + 1.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

__all__ = [
    "circle_points",
    "clip_polygon",
    "collinear",
    "disc_polygon",
    "distance_to_polygon",
    "intersection_area",
    "is_convex",
    "is_simple",
    "narrowest_neck",
    "narrowest_width",
    "points_in_circle",
    "points_in_polygon",
    "polygon_area",
    "polygon_inside",
    "polygons_disjoint",
    "segment_lengths",
    "shape_gap",
    "triangulate",
]

#: A polygon's vertices (m), in order: a sequence of (x, y) pairs or an (n, 2) array.
Vertices = Sequence[Sequence[float]] | npt.NDArray[np.float64]
#: A circle (center, radius), or a polygon's vertices (n, 2).
Shape = tuple[Sequence[float], float] | npt.NDArray[np.float64]


def polygon_area(vertices: Vertices) -> float:
    """Signed area (positive for counter-clockwise vertices), by the shoelace formula."""
    v = np.asarray(vertices, dtype=float)
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _segments_cross(
    p: npt.NDArray[np.float64],
    q: npt.NDArray[np.float64],
    r: npt.NDArray[np.float64],
    s: npt.NDArray[np.float64],
    tol: float,
) -> bool:
    """Whether the closed segments pq and rs share a point (within ``tol``)."""

    def orient(
        a: npt.NDArray[np.float64], b: npt.NDArray[np.float64], c: npt.NDArray[np.float64]
    ) -> float:
        return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    # Orientations are areas: their tolerance is tol times the longer segment.
    length = float(max(np.linalg.norm(q - p), np.linalg.norm(s - r)))
    area = tol * length
    d1, d2 = orient(r, s, p), orient(r, s, q)
    d3, d4 = orient(p, q, r), orient(p, q, s)
    if ((d1 > area and d2 < -area) or (d1 < -area and d2 > area)) and (
        (d3 > area and d4 < -area) or (d3 < -area and d4 > area)
    ):
        return True
    # Touching or collinear overlap: a point of one segment on the other.
    for a, b, c in ((r, s, p), (r, s, q), (p, q, r), (p, q, s)):
        if _point_segment_distance(c, a, b) <= tol:
            return True
    return False


def _point_segment_distance(
    c: npt.NDArray[np.float64], a: npt.NDArray[np.float64], b: npt.NDArray[np.float64]
) -> float:
    d = b - a
    t = float(np.clip(np.dot(c - a, d) / max(float(np.dot(d, d)), 1e-300), 0.0, 1.0))
    return float(np.linalg.norm(c - (a + t * d)))


def is_simple(vertices: Vertices) -> bool:
    """Whether the closed polygon has no repeated vertex and no self-intersection."""
    v = np.asarray(vertices, dtype=float)
    n = len(v)
    size = float(np.ptp(v, axis=0).max())
    tol = 1e-12 * size
    for k in range(n):
        for j in range(k + 1, n):
            if np.linalg.norm(v[k] - v[j]) <= tol:
                return False
    for k in range(n):
        for j in range(k + 1, n):
            if j == k + 1 or (k == 0 and j == n - 1):
                continue  # adjacent segments share a vertex
            if _segments_cross(v[k], v[(k + 1) % n], v[j], v[(j + 1) % n], tol):
                return False
    return True


def distance_to_polygon(
    points: npt.NDArray[np.float64], vertices: Vertices
) -> npt.NDArray[np.float64]:
    """Distance of each point (n, 2) to the polygon's boundary."""
    v = np.asarray(vertices, dtype=float)
    p = np.asarray(points, dtype=float)[:, :2]
    a, b = v, np.roll(v, -1, axis=0)
    d = b - a  # (m, 2)
    rel = p[:, None, :] - a[None, :, :]  # (n, m, 2)
    t = np.clip(
        np.einsum("nmk,mk->nm", rel, d) / np.maximum(np.einsum("mk,mk->m", d, d), 1e-300), 0.0, 1.0
    )
    nearest = a[None, :, :] + t[..., None] * d[None, :, :]
    return np.linalg.norm(p[:, None, :] - nearest, axis=2).min(axis=1)


def points_in_polygon(
    points: npt.NDArray[np.float64], vertices: Vertices, tol: float = 0.0
) -> npt.NDArray[np.bool_]:
    """Mask of the points (n, 2 or more columns) in the closed polygon, or within ``tol`` of it.

    Even-odd ray casting for the interior; the boundary counts as inside through the
    distance test, so a node on an edge of the zone is in the zone.
    """
    v = np.asarray(vertices, dtype=float)
    p = np.asarray(points, dtype=float)
    x, y = p[:, 0], p[:, 1]
    inside = np.zeros(len(p), dtype=bool)
    for (x0, y0), (x1, y1) in zip(v, np.roll(v, -1, axis=0), strict=True):
        crosses = (y0 > y) != (y1 > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            xc = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
        inside ^= crosses & (x < xc)
    return inside | (distance_to_polygon(p, v) <= tol)


def points_in_circle(
    points: npt.NDArray[np.float64], center: Sequence[float], radius: float, tol: float = 0.0
) -> npt.NDArray[np.bool_]:
    """Mask of the points (n, 2 or more columns) in the closed disc, or within ``tol`` of it."""
    p = np.asarray(points, dtype=float)
    return np.hypot(p[:, 0] - center[0], p[:, 1] - center[1]) <= radius + tol


def polygon_inside(inner: Vertices, outer: Vertices) -> bool:
    """Whether the polygon ``inner`` lies strictly inside ``outer`` (vertices and no crossing)."""
    a, b = np.asarray(inner, dtype=float), np.asarray(outer, dtype=float)
    if not points_in_polygon(a, b).all() or (distance_to_polygon(a, b) == 0.0).any():
        return False
    size = float(np.ptp(b, axis=0).max())
    for k in range(len(a)):
        for j in range(len(b)):
            if _segments_cross(a[k], a[(k + 1) % len(a)], b[j], b[(j + 1) % len(b)], 1e-12 * size):
                return False
    return True


def circle_points(center: Sequence[float], radius: float, n: int = 96) -> npt.NDArray[np.float64]:
    """``n`` points on the circle (counter-clockwise), for drawing."""
    phi = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return np.column_stack([center[0] + radius * np.cos(phi), center[1] + radius * np.sin(phi)])


def polygons_disjoint(a: Vertices, b: Vertices) -> bool:
    """Whether two polygons neither overlap, nor touch, nor contain one another."""
    pa, pb = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    size = float(max(np.ptp(pa, axis=0).max(), np.ptp(pb, axis=0).max()))
    if points_in_polygon(pa, pb).any() or points_in_polygon(pb, pa).any():
        return False
    for k in range(len(pa)):
        for j in range(len(pb)):
            if _segments_cross(
                pa[k], pa[(k + 1) % len(pa)], pb[j], pb[(j + 1) % len(pb)], 1e-12 * size
            ):
                return False
    return True


def _counter_clockwise(v: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    return v if polygon_area(v) >= 0.0 else v[::-1]


def is_convex(vertices: Vertices) -> bool:
    """Whether the simple polygon is convex (no reflex vertex; collinear ones allowed)."""
    v = np.asarray(vertices, dtype=float)
    d = np.roll(v, -1, axis=0) - v
    cross = d[:, 0] * np.roll(d[:, 1], -1) - d[:, 1] * np.roll(d[:, 0], -1)
    scale = float(np.abs(d).max()) ** 2
    return bool((cross >= -1e-12 * scale).all() or (cross <= 1e-12 * scale).all())


def clip_polygon(subject: Vertices, convex: Vertices) -> npt.NDArray[np.float64]:
    """The part of ``subject`` inside the convex polygon ``convex`` (Sutherland-Hodgman).

    ``subject`` may be any simple polygon: the result may then hold zero-width bridges,
    which add nothing to its area (use it for :func:`polygon_area`).
    """
    out = np.asarray(subject, dtype=float).reshape(-1, 2)
    c = _counter_clockwise(np.asarray(convex, dtype=float))
    for a, b in zip(c, np.roll(c, -1, axis=0), strict=True):
        if len(out) == 0:
            break
        edge = b - a
        side = edge[0] * (out[:, 1] - a[1]) - edge[1] * (out[:, 0] - a[0])  # >= 0: inside
        inside = side >= 0.0
        prev, side_prev = np.roll(out, 1, axis=0), np.roll(side, 1)
        crossing = inside != np.roll(inside, 1)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(crossing, side_prev / (side_prev - side), 0.0)
        cut = prev + (out - prev) * t[:, None]
        # Vertex k of the result: the crossing into (or out of) edge k, then vertex k.
        points = np.stack([cut, out], axis=1).reshape(-1, 2)
        out = points[np.stack([crossing, inside], axis=1).reshape(-1)]
    return out


def triangulate(vertices: Vertices) -> list[npt.NDArray[np.float64]]:
    """Triangles covering the simple polygon (ear clipping, O(n^3): small polygons)."""
    v = list(_counter_clockwise(np.asarray(vertices, dtype=float)))
    triangles = []
    while len(v) > 3:
        for k in range(len(v)):
            a, b, c = v[k - 1], v[k], v[(k + 1) % len(v)]
            if polygon_area([a, b, c]) <= 0.0:
                continue  # reflex (or flat) corner
            others = [p for p in v if not any(p is q for q in (a, b, c))]
            if others and points_in_polygon(np.array(others), [a, b, c]).any():
                continue
            triangles.append(np.array([a, b, c]))
            del v[k]
            break
        else:  # only flat corners left
            break
    triangles.append(np.array(v[:3]))
    return triangles


def intersection_area(a: Vertices, b: Vertices) -> float:
    """Area of the intersection of two simple polygons.

    One is clipped by the other when that one is convex (:func:`clip_polygon`), the
    cheaper way round; otherwise by each triangle of the polygon with fewer vertices.
    """
    pa, pb = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if len(pa) < len(pb):
        pa, pb = pb, pa  # pb: the one with fewer vertices, the clipper if it can be
    if is_convex(pb):
        return abs(polygon_area(clip_polygon(pa, pb)))
    if is_convex(pa) and len(pa) <= 3 * (len(pb) - 2):
        return abs(polygon_area(clip_polygon(pb, pa)))
    return sum(abs(polygon_area(clip_polygon(pa, t))) for t in triangulate(pb))


def disc_polygon(center: Sequence[float], radius: float, n: int = 4096) -> npt.NDArray[np.float64]:
    """A regular n-gon with the disc's area (its radius enlarged by the n-gon's deficit).

    Clipped by a polygon, it gives the area of the disc's part to O(n^-2).
    """
    scale = np.sqrt(2.0 * np.pi / (n * np.sin(2.0 * np.pi / n)))
    return circle_points(center, radius * scale, n)


def collinear(points: npt.NDArray[np.float64], size: float) -> bool:
    """Whether the points (n, 2) lie on one straight line (within 1e-9 of ``size``)."""
    if len(points) < 3:
        return True
    s = np.linalg.svd(points - points[0], compute_uv=False)
    return bool(s.size < 2 or s[1] <= 1e-9 * size * math.sqrt(len(points)))


def segment_lengths(vertices: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """The lengths of the polygon's segments (segment k from vertex k to k + 1)."""
    return np.linalg.norm(np.roll(vertices, -1, axis=0) - vertices, axis=1)


def narrowest_neck(v: npt.NDArray[np.float64]) -> float:
    """Smallest distance of a vertex to a segment not adjacent to it (a narrow neck)."""
    n = len(v)
    best = math.inf
    for k in range(n):
        for j in (j for j in range(n) if j not in (k, (k - 1) % n)):
            segment = np.array([v[j], v[(j + 1) % n]])
            best = min(best, float(distance_to_polygon(v[k : k + 1], segment)[0]))
    return best


def narrowest_width(vertices: Vertices) -> float:
    """The polygon's narrowest width: the shortest way across it from a side's midpoint.

    From the midpoint of each segment along its inward normal to the first other segment
    it meets; the smallest of these lengths. A rectangle's smaller side, a parallelogram's
    smaller height, the width of an L-shape's arm, however the polygon is rotated (a
    slot cut into it is not the plate's width: the normal from its walls runs into the
    plate).
    """
    v = np.asarray(vertices, dtype=float)
    a, b = v, np.roll(v, -1, axis=0)
    d = b - a
    size = float(np.ptp(v, axis=0).max())
    turn = 1.0 if polygon_area(v) > 0 else -1.0  # inward normal: left of a counter-clockwise side
    best = math.inf
    for j in range(len(v)):
        start = 0.5 * (a[j] + b[j])
        normal = turn * np.array([-d[j][1], d[j][0]]) / np.linalg.norm(d[j])
        for k in range(len(v)):
            if k == j:
                continue
            # start + s normal = a_k + u d_k, solved for (s, u)
            matrix = np.column_stack([normal, -d[k]])
            if abs(np.linalg.det(matrix)) <= 1e-12 * np.linalg.norm(d[k]):
                continue  # parallel to the normal
            s, u = np.linalg.solve(matrix, a[k] - start)
            if s > 1e-9 * size and -1e-9 <= u <= 1.0 + 1e-9:
                best = min(best, float(s))
    return best


def shape_gap(a: Shape, b: Shape) -> float:
    """Distance between the boundaries of two disjoint shapes (circles or polygons)."""
    if isinstance(a, tuple) and isinstance(b, tuple):
        return math.dist(a[0], b[0]) - a[1] - b[1]
    if isinstance(b, tuple):
        return shape_gap(b, a)
    if isinstance(a, tuple):
        return float(distance_to_polygon(np.array([a[0]]), b)[0]) - a[1]
    return float(min(distance_to_polygon(a, b).min(), distance_to_polygon(b, a).min()))
