"""Plate meshes and edge markers."""

from __future__ import annotations

from mpi4py import MPI

import dolfinx

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.config import EDGE_NAMES, EdgeSpec, MeshSpec, PlateSpec

__all__ = ["create_plate_mesh", "edge_line", "edge_normal_axis", "edge_tag"]


def create_plate_mesh(
    plate: PlateSpec, spec: MeshSpec, comm: MPI.Comm = MPI.COMM_WORLD
) -> tuple[dolfinx.mesh.Mesh, dolfinx.mesh.MeshTags]:
    """Structured quadrilateral mesh of the rectangle with tagged edges.

    Args:
        plate: Geometry; edges named as in :data:`EDGE_NAMES`.
        spec: Cells along x and y.
        comm: Communicator (``MPI.COMM_SELF`` for a serial copy per rank).

    Returns:
        The mesh and facet tags 1..4 for left, right, bottom, top.

    Note:
        Collective on ``comm``.
    """
    (x0, y0), (x1, y1) = plate.corners
    msh = dolfinx.mesh.create_rectangle(
        comm,
        [np.array([x0, y0]), np.array([x1, y1])],
        [spec.nx, spec.ny],
        dolfinx.mesh.CellType.quadrilateral,
    )
    # Absolute tolerance from the plate's size and the coordinates' magnitude (rounding
    # of x0 + i h); no relative tolerance, which would grow with the distance to 0.
    tol = 1e-10 * max(plate.length, plate.width) + 64 * np.finfo(float).eps * max(
        abs(x0), abs(x1), abs(y0), abs(y1)
    )
    markers = (
        lambda x: np.isclose(x[0], x0, rtol=0.0, atol=tol),
        lambda x: np.isclose(x[0], x1, rtol=0.0, atol=tol),
        lambda x: np.isclose(x[1], y0, rtol=0.0, atol=tol),
        lambda x: np.isclose(x[1], y1, rtol=0.0, atol=tol),
    )
    fdim = msh.topology.dim - 1
    facets, values = [], []
    for tag, marker in enumerate(markers, start=1):
        f = dolfinx.mesh.locate_entities_boundary(msh, fdim, marker)
        facets.append(f)
        values.append(np.full_like(f, tag))
    order_facets = np.concatenate(facets)
    order = np.argsort(order_facets, kind="stable")
    tags = dolfinx.mesh.meshtags(
        msh,
        fdim,
        order_facets[order].astype(np.int32),
        np.concatenate(values)[order].astype(np.int32),
    )
    assert len(EDGE_NAMES) == 4
    return msh, tags


def edge_tag(plate: PlateSpec, edge: EdgeSpec) -> int:
    """Facet tag of ``edge``: its ``tag`` if set, else its position in :data:`EDGE_NAMES` + 1."""
    if edge.tag is not None:
        return edge.tag
    if edge.name not in EDGE_NAMES:
        raise ValueError(f"edge {edge.name!r} has no tag; rectangle edges are named {EDGE_NAMES}")
    return EDGE_NAMES.index(edge.name) + 1


def edge_normal_axis(
    msh: dolfinx.mesh.Mesh, facet_tags: dolfinx.mesh.MeshTags, tag: int, name: str
) -> int:
    """Axis (0: x, 1: y) normal to the straight, axis-aligned edge with facet tag ``tag``.

    Raises ``ValueError`` for an edge that is not parallel to a coordinate axis, where
    a tangential/normal condition would need a rotated constraint.

    Note:
        Collective.
    """
    fdim = msh.topology.dim - 1
    facets = facet_tags.find(tag)
    msh.topology.create_connectivity(fdim, 0)
    vertices = np.unique(dolfinx.mesh.entities_to_geometry(msh, fdim, facets).ravel())
    x = msh.geometry.x[vertices, :2]
    lo = np.min(msh.comm.allgather(x.min(axis=0) if vertices.size else np.full(2, np.inf)), axis=0)
    hi = np.max(msh.comm.allgather(x.max(axis=0) if vertices.size else np.full(2, -np.inf)), axis=0)
    if not np.all(np.isfinite(lo)):
        raise ValueError(f"edge {name!r} (facet tag {tag}) holds no facet of the mesh")
    extent = hi - lo
    if extent[0] <= 1e-10 * extent.max():
        return 0
    if extent[1] <= 1e-10 * extent.max():
        return 1
    raise ValueError(
        f"edge {name!r} is not parallel to a coordinate axis: hard simple support and "
        "in-plane rollers need axis-aligned edges"
    )


def edge_line(
    msh: dolfinx.mesh.Mesh, facet_tags: dolfinx.mesh.MeshTags, plate: PlateSpec, edge: EdgeSpec
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Start and end point of a straight edge: the direction of a linearly varying stress.

    A rectangle edge runs from its end with the smaller coordinate to the larger (y for
    left and right, x for bottom and top). An edge given by a facet tag of a user mesh
    runs the same way along the coordinate in which it extends most (its extreme mesh
    nodes along that coordinate).

    Note:
        Collective (for an edge given by a tag).
    """
    if edge.tag is None and edge.name in EDGE_NAMES:
        (x0, y0), (x1, y1) = plate.corners
        ends = {
            "left": ((x0, y0), (x0, y1)),
            "right": ((x1, y0), (x1, y1)),
            "bottom": ((x0, y0), (x1, y0)),
            "top": ((x0, y1), (x1, y1)),
        }[edge.name]
        return np.array(ends[0], dtype=float), np.array(ends[1], dtype=float)
    tag = edge_tag(plate, edge)
    fdim = msh.topology.dim - 1
    msh.topology.create_connectivity(fdim, 0)
    facets = facet_tags.find(tag)
    nodes = np.unique(dolfinx.mesh.entities_to_geometry(msh, fdim, facets).ravel())
    x = msh.geometry.x[nodes, :2]
    lo = np.min(msh.comm.allgather(x.min(axis=0) if nodes.size else np.full(2, np.inf)), axis=0)
    hi = np.max(msh.comm.allgather(x.max(axis=0) if nodes.size else np.full(2, -np.inf)), axis=0)
    if not np.all(np.isfinite(lo)):
        raise ValueError(f"edge {edge.name!r} (facet tag {tag}) holds no facet of the mesh")
    axis = int(np.argmax(hi - lo))
    # The extreme nodes along that axis (same on every rank).
    candidates = []
    for pick, better in ((np.argmin, np.less), (np.argmax, np.greater)):
        k = int(pick(x[:, axis])) if nodes.size else -1
        local = x[k] if nodes.size else None
        points = [p for p in msh.comm.allgather(local) if p is not None]
        best = points[0]
        for p in points[1:]:
            if better(p[axis], best[axis]):
                best = p
        candidates.append(np.asarray(best, dtype=float))
    return candidates[0], candidates[1]
