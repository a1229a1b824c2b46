r"""How the mesh sees each obstacle zone: the discrete zone against the zone given.

The obstacle acts at the mesh nodes of the closed zone (:doc:`/methods/problem`): the
bilinear deflection is then :math:`\le 0` on every cell whose four nodes are in the zone,
and only there. So the *discrete zone* is the union of those cells; its area, next to the
area of the zone given (its part on the plate), says how far the mesh follows the zone.
On a gmsh plate the zone's edges are mesh lines
(:func:`~unibuckle_fenicsx.model.gmsh_mesh.gmsh_plate_mesh`) and the two agree, up to the
polygon a circle's cells inscribe; on the structured rectangle they agree when the grid
has lines on the zone's edges; a gmsh file's plate is known by its cells, on which the
zone's area is computed (:func:`meshed_zone_area`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from mpi4py import MPI

import dolfinx

import numpy as np
import numpy.typing as npt
from msgspec import Struct

from unibuckle_fenicsx.geometry import disc_polygon, intersection_area, is_convex, polygon_area
from unibuckle_fenicsx.spec import Circle, ObstacleSpec, PlateSpec, Polygon

__all__ = ["ZoneReport", "cell_areas", "meshed_zone_area", "zone_area", "zone_report"]


class ZoneReport(Struct, kw_only=True):
    """An obstacle's zone on the plate against its discrete zone on the mesh.

    Attributes:
        obstacle: The obstacle's label in the problem file.
        zone: The zone, described.
        area_m2: The zone's part on the plate (a gmsh file's: on its cells; None if
            unknown: a predicate zone).
        discrete_area_m2: The cells with every node in the closed zone.
        nodes: Mesh nodes in the closed zone, edge nodes included.
    """

    obstacle: str
    zone: str
    area_m2: float | None
    discrete_area_m2: float
    nodes: int


def _shape(zone: Any) -> npt.NDArray[np.float64] | None:
    """The zone as a polygon (a circle: an n-gon of its area), None if it has none."""
    if isinstance(zone, Polygon):
        return np.asarray(zone.vertices, dtype=float)
    if isinstance(zone, Circle):
        return disc_polygon(zone.center, zone.radius)
    if isinstance(zone, tuple):
        (x0, x1), (y0, y1) = zone
        return np.array([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], dtype=float)
    return None


def zone_area(obstacle: ObstacleSpec, plate: PlateSpec) -> float | None:
    """Area (m^2) of the obstacle's zone on the plate; None for a predicate or a gmsh file.

    Exact for boxes and polygons; a circle's to about 1e-6 (a 4096-gon of its area).
    """
    if plate.file is not None or callable(obstacle.zone):
        return None
    if obstacle.zone == "all":
        return plate.area
    shape = _shape(obstacle.zone)
    if shape is None or abs(polygon_area(shape)) == 0.0:
        return 0.0
    area = intersection_area(shape, plate.boundary)
    for hole in plate.holes:
        hole_shape = _shape(hole)
        if hole_shape is None:
            raise RuntimeError("zone_area: expected hole_shape is not None (an internal invariant)")
        area -= intersection_area(shape, hole_shape)
    return max(area, 0.0)


def meshed_zone_area(msh: dolfinx.mesh.Mesh, obstacle: ObstacleSpec, size: float) -> float:
    """Area (m^2) of the zone's part on the owned cells: a gmsh file's plate. Not collective.

    The plate of a file is known only by its cells, so the zone is intersected with each
    of them (:func:`~unibuckle_fenicsx.geometry.intersection_area`); cells off the zone's
    bounding box add nothing, and the cells with every node in a convex zone their area.
    (A predicate zone has no area: :func:`zone_report` gives None.)
    """
    areas, nodes = cell_areas(msh)
    if obstacle.zone == "all":
        return float(areas.sum())
    shape = _shape(obstacle.zone)
    if shape is None or abs(polygon_area(shape)) == 0.0:
        return 0.0
    ring = msh.geometry.x[:, :2][nodes[:, [0, 1, 3, 2]]]  # (cells, 4, 2), in order round
    low, high = shape.min(axis=0), shape.max(axis=0)
    near = (ring.max(axis=1) >= low).all(axis=1) & (ring.min(axis=1) <= high).all(axis=1)
    whole = obstacle.contains(msh.geometry.x.T, size)[nodes].all(axis=1) & is_convex(shape)
    area = float(areas[near & whole].sum())
    for cell in np.flatnonzero(near & ~whole):
        area += intersection_area(shape, ring[cell])
    return area


def cell_areas(msh: dolfinx.mesh.Mesh) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int32]]:
    """Areas of the owned quadrilaterals and their geometry nodes (n, 4)."""
    n = msh.topology.index_map(2).size_local
    nodes = msh.geometry.dofmaps[0][:n]
    x = msh.geometry.x[:, :2]
    ring = x[nodes[:, [0, 1, 3, 2]]]  # DOLFINx quadrilateral: tensor-product order
    xs, ys = ring[..., 0], ring[..., 1]
    areas = 0.5 * np.abs(
        np.sum(xs * np.roll(ys, -1, axis=1) - np.roll(xs, -1, axis=1) * ys, axis=1)
    )
    return areas, nodes


def discrete_zone(
    msh: dolfinx.mesh.Mesh, obstacle: ObstacleSpec, size: float
) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.float64]]:
    """The obstacle's *discrete zone*: which owned cells have every node in the zone.

    ``size``: the plate's larger side (the zone's tolerance scale). Returns the mask over
    the owned cells and their areas. Not collective.
    """
    areas, nodes = cell_areas(msh)
    inside = obstacle.contains(msh.geometry.x.T, size)
    return inside[nodes].all(axis=1), areas


def zone_report(
    msh: dolfinx.mesh.Mesh,
    obstacles: Sequence[ObstacleSpec],
    plate: PlateSpec,
    labels: Sequence[str],
) -> list[ZoneReport]:
    """Per obstacle: the zone's area, the discrete zone's area and its mesh nodes.

    Returns:
        One report per obstacle.

    Note:
        Collective.
    """
    size = max(plate.length, plate.width)
    comm = msh.comm
    x = msh.geometry.x
    n_owned = msh.geometry.index_map().size_local
    report = []
    for label, obstacle in zip(labels, obstacles, strict=True):
        inside = obstacle.contains(x[:n_owned].T, size)
        whole, areas = discrete_zone(msh, obstacle, size)
        report.append(
            ZoneReport(
                obstacle=label,
                zone=obstacle.describe(),
                area_m2=zone_area(obstacle, plate)
                if plate.file is None or callable(obstacle.zone)
                else comm.allreduce(meshed_zone_area(msh, obstacle, size), op=MPI.SUM),
                discrete_area_m2=comm.allreduce(float(areas[whole].sum()), op=MPI.SUM),
                nodes=comm.allreduce(int(np.count_nonzero(inside)), op=MPI.SUM),
            )
        )
    return report
