"""Plate meshes and edge markers."""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

from mpi4py import MPI

import dolfinx

import numpy as np
import numpy.typing as npt
from msgspec.structs import replace

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.model.gmsh_mesh import HOLES_TAG, gmsh_plate_mesh, segment_tag
from unibuckle_fenicsx.spec import (
    EDGE_NAMES,
    HOLES,
    EdgeSpec,
    MeshSpec,
    ObstacleSpec,
    PlateSpec,
)

__all__ = [
    "Collapsed",
    "build_plate_mesh",
    "check_user_mesh",
    "collapsed",
    "create_plate_mesh",
    "edge_facets",
    "edge_line",
    "edge_normal_axis",
    "edge_tag",
    "edge_tags",
]


class Collapsed(NamedTuple):
    """A sub-space of a function space, collapsed (:func:`collapsed`)."""

    #: The sub-space (a view into the parent's DOFs, for boundary conditions).
    sub: dolfinx.fem.FunctionSpace
    #: Its collapsed copy (a space of its own).
    space: dolfinx.fem.FunctionSpace
    #: The parent's local DOF of each local DOF of ``space``.
    dofs: npt.NDArray[np.int32]


#: Attribute of a function space that holds its collapsed sub-spaces, by path.
_COLLAPSED = "_unibuckle_collapsed"


def collapsed(V: dolfinx.fem.FunctionSpace, *path: int) -> Collapsed:
    """The sub-space of ``V`` at ``path`` (``V.sub(i).sub(j)...``), collapsed once per ``V``.

    ``FunctionSpace.collapse`` builds a new dofmap each time it is called; the supports'
    boundary conditions, the MITC operator, the prolongation between meshes and the
    prestress's pins all need the same few sub-spaces of one space. The result is kept
    on ``V`` (and goes with it) and is the same on every call.

    Note:
        Collective on the first call for a ``path``.
    """
    cache: dict[tuple[int, ...], Collapsed] = V.__dict__.setdefault(_COLLAPSED, {})
    if path not in cache:
        sub = V
        for i in path:
            sub = sub.sub(i)
        space, dofs = sub.collapse()
        cache[path] = Collapsed(sub, space, np.asarray(dofs[0], dtype=np.int32))
    return cache[path]


def create_plate_mesh(
    plate: PlateSpec, spec: MeshSpec, comm: MPI.Comm = MPI.COMM_WORLD
) -> tuple[dolfinx.mesh.Mesh, dolfinx.mesh.MeshTags]:
    """Structured quadrilateral mesh of the rectangle with tagged edges (or gmsh's).

    A plate meshed by gmsh (an outline, holes or a file) goes to
    :func:`build_plate_mesh`; a file's edge names are then not resolved (use
    :func:`build_plate_mesh`).

    Args:
        plate: Geometry; edges named as in :data:`EDGE_NAMES`.
        spec: Cells along x and y.
        comm: Communicator (``MPI.COMM_SELF`` for a serial copy per rank).

    Returns:
        The mesh and facet tags 1..4 for left, right, bottom, top.

    Note:
        Collective on ``comm``.
    """
    if plate.meshed_by_gmsh:
        msh, tags, _ = build_plate_mesh(plate, spec, comm)
        return msh, tags
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
    if len(EDGE_NAMES) != 4:
        raise RuntimeError(
            "create_plate_mesh: expected len(EDGE_NAMES) == 4 (an internal invariant)"
        )
    return msh, tags


def check_user_mesh(
    msh: dolfinx.mesh.Mesh, facet_tags: dolfinx.mesh.MeshTags, plate: PlateSpec
) -> None:
    """Refuse a user mesh that does not fit ``plate`` (before any solve).

    Its bounding box must be ``plate.corners`` (the zones' tolerances, the buckling
    coefficient's width and the edge loads' directions use them), and every edge's facet
    tag must mark facets: without them the edge's support and load act nowhere, and the
    loads then look like tension everywhere or an unloaded plate, which is not what went
    wrong.

    Note:
        Collective.
    """
    x = msh.geometry.x[: msh.geometry.index_map().size_local, :2]
    lo = np.min(msh.comm.allgather(x.min(axis=0) if len(x) else np.full(2, np.inf)), axis=0)
    hi = np.max(msh.comm.allgather(x.max(axis=0) if len(x) else np.full(2, -np.inf)), axis=0)
    corners = np.array(plate.corners, dtype=float)
    size = max(plate.length, plate.width)
    if not np.allclose([lo, hi], corners, rtol=0.0, atol=1e-8 * size):
        raise InputError(
            f"mesh: its bounding box {[lo.tolist(), hi.tolist()]} is not plate.corners "
            f"{corners.tolist()}: give the plate the mesh's corners (the zones, the "
            "buckling coefficient's width and the edge loads' directions use them)"
        )
    for edge in plate.edges:
        for tag in edge_tags(plate, edge):
            count = msh.comm.allreduce(len(facet_tags.find(tag)), op=MPI.SUM)
            if count == 0:
                present = sorted(
                    {int(v) for part in msh.comm.allgather(np.unique(facet_tags.values).tolist())
                     for v in part}
                )  # fmt: skip
                raise InputError(
                    f"edge {edge.name!r} (facet tag {tag}) holds no facet of the mesh "
                    f"(its facet tags: {present}); give each edge its tag (EdgeSpec.tag)"
                )


def edge_tag(plate: PlateSpec, edge: EdgeSpec) -> int:
    """The one facet tag of ``edge`` (see :func:`edge_tags`); an error if it has several."""
    tags = edge_tags(plate, edge)
    if len(tags) != 1:
        raise InputError(f"edge {edge.name!r} has several facet tags {tags}")
    return tags[0]


def edge_tags(plate: PlateSpec, edge: EdgeSpec) -> tuple[int, ...]:
    """Facet tags of ``edge``.

    Its ``tag`` if set (a user mesh, or a file's physical curve); an outline's segments'
    tags (:func:`~unibuckle_fenicsx.model.gmsh_mesh.segment_tag`); the holes'
    (:data:`~unibuckle_fenicsx.model.gmsh_mesh.HOLES_TAG`); else its position in
    :data:`EDGE_NAMES` + 1 (the rectangle, meshed by either route).
    """
    if edge.tag is not None:
        return (edge.tag,)
    if edge.segments is not None:
        return tuple(segment_tag(k) for k in edge.segments)
    if edge.name == HOLES and plate.holes:
        return (HOLES_TAG,)
    if edge.name not in EDGE_NAMES or plate.outline is not None or plate.file is not None:
        raise InputError(
            f"edge {edge.name!r} has no facet tag; rectangle edges are named {EDGE_NAMES}"
        )
    return (EDGE_NAMES.index(edge.name) + 1,)


def edge_facets(facet_tags: dolfinx.mesh.MeshTags, tags: tuple[int, ...]) -> npt.NDArray[np.int32]:
    """Local facets carrying any of ``tags``."""
    found = [facet_tags.find(tag) for tag in tags]
    return np.unique(np.concatenate(found)).astype(np.int32) if found else np.empty(0, np.int32)


def edge_normal_axis(
    msh: dolfinx.mesh.Mesh, facet_tags: dolfinx.mesh.MeshTags, tag: int, name: str
) -> int:
    """Axis (0: x, 1: y) normal to every facet with tag ``tag`` (edges parallel to an axis).

    The facets may lie on several parallel straight edges (a file's physical curve of both
    loaded ends, say). Raises ``ValueError`` for facets not all parallel to one coordinate
    axis, where a tangential/normal condition would need a rotated constraint.

    Note:
        Collective.
    """
    fdim = msh.topology.dim - 1
    facets = facet_tags.find(tag)
    msh.topology.create_connectivity(fdim, 0)
    nodes = dolfinx.mesh.entities_to_geometry(msh, fdim, facets)
    x = msh.geometry.x[:, :2]
    d = np.abs(x[nodes[:, -1]] - x[nodes[:, 0]]) if len(facets) else np.zeros((0, 2))
    length = np.linalg.norm(d, axis=1)
    # Which axis every local facet is normal to: 0 if it runs along y, 1 along x.
    along_y = bool(np.all(d[:, 0] <= 1e-10 * length))
    along_x = bool(np.all(d[:, 1] <= 1e-10 * length))
    count = msh.comm.allreduce(len(facets), op=MPI.SUM)
    along_y = msh.comm.allreduce(along_y, op=MPI.LAND)
    along_x = msh.comm.allreduce(along_x, op=MPI.LAND)
    if count == 0:
        raise InputError(f"edge {name!r} (facet tag {tag}) holds no facet of the mesh")
    if along_y:
        return 0
    if along_x:
        return 1
    raise InputError(
        f"edge {name!r} is not parallel to a coordinate axis: hard simple support and "
        "in-plane rollers need axis-aligned edges (use simply_supported_soft or clamped)"
    )


def edge_line(
    msh: dolfinx.mesh.Mesh,
    facet_tags: dolfinx.mesh.MeshTags,
    plate: PlateSpec,
    edge: EdgeSpec,
    tag: int | None = None,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Start and end point of a straight edge: the direction of a linearly varying stress.

    A rectangle edge runs from its end with the smaller coordinate to the larger (y for
    left and right, x for bottom and top); an outline segment from its vertex k to vertex
    k + 1 (``tag``: the segment's, for a part of several segments). An edge given by a
    facet tag of a user mesh or a file runs, like the rectangle's, along the coordinate
    in which it extends most (its extreme mesh nodes along that coordinate).

    Note:
        Collective (for an edge given by a tag).
    """
    if tag is None:
        tag = edge_tag(plate, edge)
    if edge.segments is not None and plate.outline is not None:
        k = tag - 1
        v = plate.outline
        return np.array(v[k], dtype=float), np.array(v[(k + 1) % len(v)], dtype=float)
    if edge.tag is None and edge.name in EDGE_NAMES:
        (x0, y0), (x1, y1) = plate.corners
        ends = {
            "left": ((x0, y0), (x0, y1)),
            "right": ((x1, y0), (x1, y1)),
            "bottom": ((x0, y0), (x1, y0)),
            "top": ((x0, y1), (x1, y1)),
        }[edge.name]
        return np.array(ends[0], dtype=float), np.array(ends[1], dtype=float)
    fdim = msh.topology.dim - 1
    msh.topology.create_connectivity(fdim, 0)
    facets = facet_tags.find(tag)
    nodes = np.unique(dolfinx.mesh.entities_to_geometry(msh, fdim, facets).ravel())
    x = msh.geometry.x[nodes, :2]
    lo = np.min(msh.comm.allgather(x.min(axis=0) if nodes.size else np.full(2, np.inf)), axis=0)
    hi = np.max(msh.comm.allgather(x.max(axis=0) if nodes.size else np.full(2, -np.inf)), axis=0)
    if not np.all(np.isfinite(lo)):
        raise InputError(f"edge {edge.name!r} (facet tag {tag}) holds no facet of the mesh")
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


def build_plate_mesh(
    plate: PlateSpec,
    spec: MeshSpec,
    comm: MPI.Comm = MPI.COMM_WORLD,
    obstacles: Sequence[ObstacleSpec] = (),
) -> tuple[dolfinx.mesh.Mesh, dolfinx.mesh.MeshTags, PlateSpec]:
    """The plate's mesh, its facet tags, and the plate with every edge's tag resolved.

    The rectangle: :func:`create_plate_mesh` (the plate unchanged). Meshed by gmsh
    (:func:`~unibuckle_fenicsx.model.gmsh_mesh.gmsh_plate_mesh`): a file's ``[edges.NAME]`` get
    the tag of the physical curve called NAME (an error listing the file's names if there
    is none), and its ``corners`` become the mesh's bounding box; the edges of the
    ``obstacles``' zones are mesh lines of a plate gmsh builds.

    Note:
        Collective on ``comm``.
    """
    if not plate.meshed_by_gmsh:
        msh, tags = create_plate_mesh(plate, spec, comm)
        return msh, tags, plate
    msh, tags, groups = gmsh_plate_mesh(plate, spec, comm, obstacles)
    if plate.file is None:
        return msh, tags, plate
    missing = [e.name for e in plate.edges if e.tag is None and e.name not in groups]
    if missing:
        raise InputError(
            f"edges.{missing[0]}: {plate.file} has no boundary part (physical curve) named "
            f"{missing[0]!r}; its boundary parts: {sorted(groups)}"
        )
    edges = tuple(e if e.tag is not None else replace(e, tag=groups[e.name]) for e in plate.edges)
    x = msh.geometry.x[:, :2]
    lo = np.min(comm.allgather(x.min(axis=0) if len(x) else np.full(2, np.inf)), axis=0)
    hi = np.max(comm.allgather(x.max(axis=0) if len(x) else np.full(2, -np.inf)), axis=0)
    corners = ((float(lo[0]), float(lo[1])), (float(hi[0]), float(hi[1])))
    return msh, tags, replace(plate, edges=edges, corners=corners)
