"""Data of a solved problem for figures: nodal deflections, sections, the zone's box.

Kept apart from :mod:`unibuckle_fenicsx.viz.plotting` (which only draws): the functions that
read a mode are collective on the mesh communicator and return the same arrays on every
rank, so that drawing can happen on rank 0 alone.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.tolerances import GEOMETRY_RTOL

if TYPE_CHECKING:  # pragma: no cover
    import dolfinx

    from unibuckle_fenicsx.model.problem import BucklingProblem
    from unibuckle_fenicsx.results import BucklingResult
    from unibuckle_fenicsx.spec import ProblemSpec

__all__ = [
    "mesh_triangles",
    "mirror_to_match",
    "nodal_deflection",
    "pressing",
    "problem_zone",
    "section",
    "zone_box",
    "zone_outlines",
]


def zone_box(
    spec: ProblemSpec, constrained: npt.NDArray[np.float64] | None = None
) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """Obstacle zone of ``spec`` as ``((xmin, xmax), (ymin, ymax))``; ``None`` without one.

    A polygon or circle gives its bounding box; several obstacles the box around all.

    Args:
        spec: The problem.
        constrained: Coordinates of the constrained nodes (needed for a predicate
            zone, whose bounding box is returned).
    """
    outlines = zone_outlines(spec)
    if not outlines:
        if spec.all_obstacles and constrained is not None and len(constrained):
            lo, hi = constrained.min(axis=0), constrained.max(axis=0)
            return (float(lo[0]), float(hi[0])), (float(lo[1]), float(hi[1]))
        return None
    points = np.vstack([xy for xy, _ in outlines])
    lo, hi = points.min(axis=0), points.max(axis=0)
    return (float(lo[0]), float(hi[0])), (float(lo[1]), float(hi[1]))


def zone_outlines(spec: ProblemSpec) -> list[tuple[npt.NDArray[np.float64], str]]:
    """Outline (n, 2), closed implicitly, and side of every obstacle zone, for drawing.

    "all" gives the plate's outer boundary (its outline, or its bounding box), a circle
    96 points; a predicate zone has no outline and is left out.
    """
    from unibuckle_fenicsx.geometry import circle_points
    from unibuckle_fenicsx.spec import Circle, Polygon

    out: list[tuple[npt.NDArray[np.float64], str]] = []
    for obstacle in spec.all_obstacles:
        zone = obstacle.zone
        if isinstance(zone, str):
            xy = np.asarray(spec.plate.boundary, dtype=float)
        elif isinstance(zone, Polygon):
            xy = np.asarray(zone.vertices, dtype=float)
        elif isinstance(zone, Circle):
            xy = circle_points(zone.center, zone.radius)
        elif callable(zone):
            continue
        else:
            (x0, x1), (y0, y1) = zone
            xy = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float)
        out.append((xy, obstacle.side))
    return out


def problem_zone(
    problem: BucklingProblem,
) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """:func:`zone_box` of a set-up problem (a predicate zone: its nodes' bounding box)."""
    coords = problem.contact.coordinates if problem.contact is not None else None
    return zone_box(problem.spec, coords)


def nodal_deflection(
    problem: BucklingProblem, u: dolfinx.fem.Function
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Node coordinates (n, 2) and deflection w (n,) of the mode ``u``.

    Gathered over the mesh communicator (owned w-DOFs of every rank), same on all ranks,
    in the order of the nodes' (y, x) (quantised as the contact sets'): the same on
    every partition, so that a figure drawn from them is too.

    Note:
        Collective.
    """
    w, _ = problem.model.split(u)
    Vw = w.function_space
    n_owned = Vw.dofmap.index_map.size_local
    xy = Vw.tabulate_dof_coordinates()[:n_owned, :2]
    values = w.x.array[:n_owned].real
    comm = problem.comm
    all_xy = np.vstack(comm.allgather(xy))
    all_w = np.concatenate(comm.allgather(values))
    scale = max(problem.spec.plate.length, problem.spec.plate.width)
    keys = np.round(all_xy / (GEOMETRY_RTOL * scale)).astype(np.int64)
    order = np.lexsort((keys[:, 0], keys[:, 1]))
    return all_xy[order], all_w[order]


def section(
    problem: BucklingProblem,
    u: dolfinx.fem.Function,
    y: float = 0.0,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Section of the deflection along the line y = ``y`` ("section A" for y = 0).

    Returns the nodal values when the line is a row of mesh nodes, and the values at
    the nodes' x positions interpolated linearly between the two nearest rows otherwise
    (exact for the bilinear element).

    Returns:
        x (sorted) and w at those points.

    Note:
        Collective.
    """
    xy, w = nodal_deflection(problem, u)
    scale = max(problem.spec.plate.length, problem.spec.plate.width)
    keys = np.round(xy / (GEOMETRY_RTOL * scale)).astype(np.int64)
    _, first = np.unique(keys, axis=0, return_index=True)
    xy, w = xy[first], w[first]  # drop duplicates (none in serial)
    rows = np.unique(np.round(xy[:, 1] / (GEOMETRY_RTOL * scale))) * GEOMETRY_RTOL * scale
    if y < rows[0] - GEOMETRY_RTOL * scale or y > rows[-1] + GEOMETRY_RTOL * scale:
        raise InputError(f"section: y = {y} lies outside the plate [{rows[0]}, {rows[-1]}]")
    below = rows[rows <= y + GEOMETRY_RTOL * scale].max()
    above = rows[rows >= y - GEOMETRY_RTOL * scale].min()

    def row(yr: float) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        mask = np.abs(xy[:, 1] - yr) <= GEOMETRY_RTOL * scale
        order = np.argsort(xy[mask, 0])
        return xy[mask, 0][order], w[mask][order]

    x0, w0 = row(below)
    if above - below <= GEOMETRY_RTOL * scale:
        return x0, w0
    x1, w1 = row(above)
    s = (y - below) / (above - below)
    return x0, (1 - s) * w0 + s * np.interp(x0, x1, w1)


def mirror_to_match(
    x_ref: npt.ArrayLike,
    w_ref: npt.ArrayLike,
    x: npt.ArrayLike,
    w: npt.ArrayLike,
    center: float = 0.0,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], bool]:
    """Reflect a section about x = ``center`` if its mirror image matches ``w_ref`` better.

    The paper's plate and zones are symmetric about x = 0, so a mode and its mirror
    image have the same load; solvers may return either. Drawing twins on the same side
    makes sections comparable.

    Returns:
        The (possibly reflected, re-sorted) abscissae and values, and whether it was
        reflected.
    """
    x_ref, w_ref = np.asarray(x_ref, dtype=float), np.asarray(w_ref, dtype=float)
    x, w = np.asarray(x, dtype=float), np.asarray(w, dtype=float)
    direct = np.dot(np.interp(x_ref, x, w), w_ref)
    xm = 2 * center - x[::-1]
    wm = w[::-1]
    mirrored = np.dot(np.interp(x_ref, xm, wm), w_ref)
    if mirrored > direct:
        return xm, wm, True
    return x, w, False


def mesh_triangles(
    problem: BucklingProblem, u: dolfinx.fem.Function
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.int32]]:
    """Node coordinates (n, 2), deflection (n,) and triangles (2 per quadrilateral, (m, 3)).

    The plate's own cells, split along a diagonal, for contour plots that leave holes and
    re-entrant corners empty (a triangulation of the nodes alone would fill them).
    Serial problems only (``comm.size == 1``).
    """
    if problem.comm.size != 1:
        raise RuntimeError("mesh_triangles draws serial problems only (comm.size == 1)")
    w, _ = problem.model.split(u)
    Vw = w.function_space
    xy = Vw.tabulate_dof_coordinates()[:, :2]
    cells = Vw.dofmap.list  # Q1 on quadrilaterals: DOLFINx's tensor order 0, 1, 2, 3
    quads = cells[:, [0, 1, 3, 2]]  # counter-clockwise
    triangles = np.vstack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]]).astype(np.int32)
    return xy, w.x.array.real.copy(), triangles


def pressing(result: BucklingResult) -> npt.NDArray[np.bool_] | None:
    """Whether each contact node presses the obstacle, in the order of the contact set.

    A node presses when the obstacle's push on it exceeds the push double precision can
    tell from zero (``result.contact_force["resolution"]``); the others only touch it:
    zero deflection and no force (on thin plates against a whole face, most of them).
    None when the result has no contact force (no rigid obstacle).
    """
    force = result.contact_force
    if force is None or force.get("resolution") is None:
        return None
    return np.asarray(force["push"], dtype=float) > float(force["resolution"])
