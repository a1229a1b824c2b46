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

gmsh is an optional dependency (the ``gmsh`` extra); it is imported when a plate needs it.
"""

from __future__ import annotations

from typing import Any

from mpi4py import MPI

import dolfinx
import dolfinx.io.gmsh

import numpy as np

from unibuckle_fenicsx.config import EDGE_NAMES, Circle, MeshSpec, PlateSpec

__all__ = ["HOLES_TAG", "SURFACE_TAG", "gmsh_plate_mesh", "import_gmsh", "segment_tag"]

#: Physical tag of the holes' boundary.
HOLES_TAG = 10000
#: Physical tag of the plate's surface.
SURFACE_TAG = 1
#: Circles get at least this many cell edges, whatever the cell size.
CIRCLE_SEGMENTS = 16
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


def _quadrilaterals_only(gmsh: Any) -> None:
    kinds = {
        gmsh.model.mesh.getElementProperties(t)[0]: len(tags)
        for t, tags in zip(*gmsh.model.mesh.getElements(2)[:2], strict=True)
    }
    others = {k: n for k, n in kinds.items() if not k.startswith("Quadrilateral 4")}
    if others or not kinds:
        raise ValueError(
            f"the gmsh mesh must consist of bilinear quadrilaterals (the MITC element), got "
            f"{kinds or 'no 2-D cells'}; recombine the mesh (Recombine Surface{{...}}, "
            "Mesh.RecombineAll = 1)"
        )


def gmsh_plate_mesh(
    plate: PlateSpec, spec: MeshSpec, comm: MPI.Comm = MPI.COMM_WORLD
) -> tuple[dolfinx.mesh.Mesh, dolfinx.mesh.MeshTags, dict[str, int]]:
    """Quadrilateral mesh of ``plate`` by gmsh, distributed over ``comm``.

    Args:
        plate: An outline or a rectangle with holes (built here), or a file.
        spec: ``size``, gmsh's characteristic cell size (m); for a ``.geo`` file, the
            largest cell size if given.
        comm: Communicator (gmsh runs on its rank 0).

    Returns:
        The mesh, its facet tags (physical curves) and the physical curves' tags by name.

    Raises:
        ImportError: gmsh is not installed (the message names the extra).
        ValueError: A mesh that is not made of quadrilaterals, or a file without a
            physical surface.

    Note:
        Collective.
    """
    error: str | None = None
    gmsh = None
    if comm.rank == 0:
        try:
            gmsh = import_gmsh()
        except ImportError as err:
            error = f"ImportError: {err}"
    error = comm.bcast(error, root=0)
    if error is not None:
        raise ImportError(error.removeprefix("ImportError: "))
    if comm.rank == 0:
        assert gmsh is not None
        gmsh.initialize(interruptible=False)
        try:
            for key, value in GMSH_OPTIONS.items():
                gmsh.option.setNumber(key, value)
            if plate.file is not None:
                gmsh.open(plate.file)
                if not plate.file.lower().endswith(".msh"):
                    if spec.size is not None:
                        gmsh.option.setNumber("Mesh.MeshSizeMax", spec.size)
                    gmsh.model.mesh.generate(2)
                if not gmsh.model.getPhysicalGroups(2):
                    raise ValueError(
                        "no physical surface (Physical Surface(...) = {...}): gmsh's cells "
                        "reach DOLFINx through physical groups"
                    )
            else:
                assert spec.size is not None
                gmsh.model.add("plate")
                _build(gmsh, plate, spec.size)
                gmsh.model.mesh.generate(2)
            _quadrilaterals_only(gmsh)
        except ValueError as err:
            error = str(err) if plate.file is None else f"plate.file {plate.file}: {err}"
        except Exception as err:  # gmsh raises plain Exceptions
            error = f"gmsh failed to mesh the plate: {err}"
        if error is not None:
            gmsh.finalize()
    error = comm.bcast(error, root=0)
    if error is not None:
        raise ValueError(error)
    try:
        model = gmsh.model if gmsh is not None else None
        data = dolfinx.io.gmsh.model_to_mesh(model, comm, 0, gdim=2)
    finally:
        if comm.rank == 0:
            assert gmsh is not None
            gmsh.finalize()
    msh = data.mesh
    tags = data.facet_tags
    if tags is None:
        fdim = msh.topology.dim - 1
        empty = np.empty(0, dtype=np.int32)
        tags = dolfinx.mesh.meshtags(msh, fdim, empty, empty)
    groups = {name: int(g.tag) for name, g in data.physical_groups.items() if g.dim == 1}
    return msh, tags, groups
