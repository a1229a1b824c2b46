r"""Section meshes: a box, a circular tube and one flat face, as quadrilateral surfaces in 3-D.

The member's axis is x, from the loaded end x = 0 to the loaded end x = L; the section
lies in the (y, z) plane, centred on the axis. Each mesh is a DOLFINx mesh of
quadrilaterals of topological dimension 2 and geometric dimension 3, made from numpy
arrays by ``dolfinx.mesh.create_mesh`` (no gmsh: the surfaces are structured).
Every cell is a rectangle: its first reference direction runs along x, its second
around the section (counter-clockwise seen from +x), so its normal
:math:`e_x \times t_s` points into the section (toward a core). The shell element
(:mod:`~unibuckle_fenicsx.model.shell.forms`) relies on rectangular cells: its assumed
shear strain is MITC4's on them.

- **Box** (rectangular hollow section): mid-line width b (along y), depth d (along z);
  the four faces share their corner nodes (a folded plate). Faces are tagged
  1 (y = +b/2), 2 (z = +d/2), 3 (y = -b/2), 4 (z = -d/2).
- **Tube** (circular hollow section): mid-surface radius R; the wall is the polygon of
  its nodes (flat facets, a faceted approximation whose error is :math:`O(h^2)`).
- **Flat face**: one rectangle [0, L] x [0, b] in the plane z = 0 (normal +z), the
  plate of :mod:`~unibuckle_fenicsx.model.plate` embedded in 3-D; edges tagged like the
  plate's (1 left x = 0, 2 right x = L, 3 bottom y = 0, 4 top y = b).

Facet tags of the loaded ends: :data:`END_START` (x = 0) and :data:`END_FINISH` (x = L).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from mpi4py import MPI

import basix.ufl
import dolfinx
import ufl

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.spec.section import cells_along, face_cells

__all__ = [
    "END_FINISH",
    "END_START",
    "SHAPES",
    "SectionMesh",
    "box_mesh",
    "cell_length",
    "face_cell_width",
    "flat_face_mesh",
    "grid_nodes",
    "section_mesh",
    "tube_facet_width",
    "tube_mesh",
]

#: Facet tag of the loaded end x = 0 (and of a flat face's left edge).
END_START = 1
#: Facet tag of the loaded end x = L (and of a flat face's right edge).
END_FINISH = 2
#: Facet tags of a flat face's unloaded edges y = 0 and y = b.
FLAT_BOTTOM, FLAT_TOP = 3, 4
#: The section shapes.
SHAPES = ("box", "tube", "flat")


@dataclass(frozen=True)
class SectionMesh:
    """A section's surface mesh with its tags and the geometry that defines it.

    Attributes:
        mesh: Quadrilateral mesh, topological dimension 2, geometric dimension 3.
        facet_tags: :data:`END_START`, :data:`END_FINISH` (a flat face also 3, 4).
        cell_tags: Face number of each cell (box 1..4; tube and flat face 1).
        shape: "box", "tube" or "flat".
        length: L (m), along x.
        width: Box: mid-line width b (y); flat face: its width b (y); tube: 2R.
        depth: Box: mid-line depth d (z); tube: 2R; flat face: 0.
        cells_around: Cells around the section (flat face: across its width).
        cells_along: Cells along x.
    """

    mesh: dolfinx.mesh.Mesh
    facet_tags: dolfinx.mesh.MeshTags
    cell_tags: dolfinx.mesh.MeshTags
    shape: str
    length: float
    width: float
    depth: float
    cells_around: int
    cells_along: int

    @property
    def radius(self) -> float:
        """Mid-surface radius R of a tube (m)."""
        return 0.5 * self.width

    @property
    def perimeter(self) -> float:
        """Length of the mid-line around the section (a flat face: its width) (m)."""
        if self.shape == "box":
            return 2.0 * (self.width + self.depth)
        if self.shape == "tube":
            return math.pi * self.width
        return self.width

    @property
    def tolerance(self) -> float:
        """Absolute distance below which two points coincide (m)."""
        return 1e-9 * max(self.length, self.width, self.depth)

    def inward_normals(self, x: npt.NDArray[np.float64]) -> list[npt.NDArray[np.float64]]:
        r"""The unit normals toward the core at the points ``x`` (3, n), per point.

        A box's face node has its face's normal, a corner node both faces' (orthogonal),
        a tube's node :math:`-(0, y, z)/R` (it turns with the node), a flat face's node
        +z (the side of the plate model's obstacle "above": w = u_z <= 0).

        Returns:
            A list of n arrays of shape (k, 3), k = 1 or 2.
        """
        tol = self.tolerance
        out: list[npt.NDArray[np.float64]] = []
        for y, z in zip(x[1], x[2], strict=True):
            if self.shape == "flat":
                out.append(np.array([[0.0, 0.0, 1.0]]))
            elif self.shape == "tube":
                r = math.hypot(y, z)
                out.append(np.array([[0.0, -y / r, -z / r]]))
            else:
                normals = []
                if abs(abs(y) - 0.5 * self.width) < tol:
                    normals.append([0.0, -math.copysign(1.0, y), 0.0])
                if abs(abs(z) - 0.5 * self.depth) < tol:
                    normals.append([0.0, 0.0, -math.copysign(1.0, z)])
                out.append(np.array(normals))
        return out


def _cells_along(length: float, size: float) -> int:
    """Cells along x of every section mesh: ceil(L/size), at least one.

    :func:`~unibuckle_fenicsx.spec.section.cells_along`: the problem file's checks count
    them the same way before any mesh is made.
    """
    return cells_along(length, size)


def _facets(diameter: float, size: float) -> int:
    """A tube's facets around: an even number of chords of about ``size``, at least 8."""
    return face_cells(math.pi * diameter, size, least=8)


#: Growth ratio of neighbouring cells across a graded face (:func:`_face_fractions`).
GRADING_RATIO = 1.3


def _face_fractions(extent: float, size: float, first: float | None) -> npt.NDArray[np.float64]:
    """Node positions across a face as fractions of its width, corner to corner.

    Uniform (an even number of cells of about ``size``) without ``first``; with it, the
    cells at both corners are ``first`` wide and grow by :data:`GRADING_RATIO` up to
    ``size``, symmetrically, with an even number of cells in the uniform middle part
    (a node at the middle of the face).
    """
    widths, n_mid, middle = _face_grading(extent, size, first)
    if first is None or first >= size:
        return np.arange(n_mid + 1) / n_mid
    cells = widths + [middle / n_mid] * n_mid + widths[::-1]
    edges = np.concatenate([[0.0], np.cumsum(cells)])
    return edges / edges[-1]


def _face_grading(
    extent: float, size: float, first: float | None
) -> tuple[list[float], int, float]:
    """A face's graded cells at one corner, its middle part's cell count and width (m).

    :func:`_face_fractions`'s cells without their arrays (uniform: no graded cells).
    """
    widths: list[float] = []
    if first is not None and first < size:
        w = first
        while w < size and 2.0 * (sum(widths) + w) < extent - 2.0 * size:
            widths.append(w)
            w *= GRADING_RATIO
    middle = extent - 2.0 * sum(widths)
    return widths, face_cells(middle, size), middle


def _surface(
    comm: MPI.Comm,
    ring: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int32],
    length: float,
    nx: int,
    closed: bool,
) -> tuple[dolfinx.mesh.Mesh, npt.NDArray[np.float64], npt.NDArray[np.int32]]:
    """Mesh of the ring of section points (m, 2) swept along x in nx cells.

    ``faces[j]`` tags the cell between ring points j and j + 1 (closed: j + 1 mod m).
    Returns the mesh, and the cells' midpoints and face tags in input order (rank 0).
    """
    m = ring.shape[0]
    nseg = m if closed else m - 1
    if comm.rank == 0:
        xs = np.linspace(0.0, length, nx + 1)
        x = np.zeros(((nx + 1) * m, 3))
        x[:, 0] = np.repeat(xs, m)
        x[:, 1] = np.tile(ring[:, 0], nx + 1)
        x[:, 2] = np.tile(ring[:, 1], nx + 1)
        ii, jj = np.meshgrid(np.arange(nx), np.arange(nseg), indexing="ij")
        i, j = ii.ravel(), jj.ravel()
        j1 = (j + 1) % m
        # Tensor-product vertex order: reference X0 along x, X1 around the section.
        cells = np.stack([i * m + j, (i + 1) * m + j, i * m + j1, (i + 1) * m + j1], axis=1)
        tags = np.asarray(faces, dtype=np.int32)[j]
    else:
        x = np.zeros((0, 3))
        cells = np.zeros((0, 4), dtype=np.int64)
        tags = np.zeros(0, dtype=np.int32)
    element = ufl.Mesh(basix.ufl.element("Lagrange", "quadrilateral", 1, shape=(3,)))
    msh = dolfinx.mesh.create_mesh(comm, cells.astype(np.int64), element, x)
    return msh, x, tags


def _tags(
    sm_mesh: dolfinx.mesh.Mesh,
    input_tags: npt.NDArray[np.int32],
    markers: dict[int, object],
) -> tuple[dolfinx.mesh.MeshTags, dolfinx.mesh.MeshTags]:
    """Cell tags from the input cells' face numbers, facet tags from marker functions."""
    msh = sm_mesh
    tdim = msh.topology.dim
    # Cell tags: the input cells' numbers travel with the cells (original_cell_index).
    n_local = msh.topology.index_map(tdim).size_local
    original = np.asarray(msh.topology.original_cell_index, dtype=np.int64)[:n_local]
    all_tags = msh.comm.bcast(input_tags, root=0)
    cells = np.arange(n_local, dtype=np.int32)
    cell_tags = dolfinx.mesh.meshtags(msh, tdim, cells, all_tags[original].astype(np.int32))
    msh.topology.create_connectivity(tdim - 1, tdim)
    facets, values = [], []
    for tag, marker in markers.items():
        f = dolfinx.mesh.locate_entities_boundary(msh, tdim - 1, marker)  # type: ignore[arg-type]
        facets.append(f)
        values.append(np.full(f.size, tag, dtype=np.int32))
    facet = np.concatenate(facets)
    order = np.argsort(facet)
    facet_tags = dolfinx.mesh.meshtags(
        msh, tdim - 1, facet[order].astype(np.int32), np.concatenate(values)[order]
    )
    return facet_tags, cell_tags


def _end_markers(length: float, tol: float) -> dict[int, object]:
    return {
        END_START: lambda x: np.isclose(x[0], 0.0, rtol=0.0, atol=tol),
        END_FINISH: lambda x: np.isclose(x[0], length, rtol=0.0, atol=tol),
    }


def box_mesh(
    width: float,
    depth: float,
    length: float,
    size: float,
    comm: MPI.Comm = MPI.COMM_WORLD,
    *,
    corner_cell: float | None = None,
) -> SectionMesh:
    """Rectangular hollow section: four flat faces sharing their corner nodes.

    Args:
        width: Mid-line width b (m) along y, > 0.
        depth: Mid-line depth d (m) along z, > 0.
        length: Length L (m) between the loaded ends, > 0.
        size: Target cell size (m), > 0: each face gets an even number (at least 2) of
            cells across, so that a node lies at the middle of every face (the prestress
            solve pins its rigid motions there), and ceil(L/size) cells along.
        comm: Communicator of the mesh.
        corner_cell: Width (m) of the cells next to the corners, the faces graded from
            it up to ``size`` (:data:`GRADING_RATIO`); None: uniform faces. A core makes
            a corner's rotation cost a transverse-shear boundary layer about t wide on
            the face lying on it; cells of about t there resolve it.

    Note:
        Collective on ``comm``.
    """
    _positive(width=width, depth=depth, length=length, size=size)
    if corner_cell is not None:
        _positive(corner_cell=corner_cell)
    nx = _cells_along(length, size)
    hb, hd = 0.5 * width, 0.5 * depth
    # Counter-clockwise from the corner (+b/2, -d/2); face tags 1..4.
    corners = [(hb, -hd), (hb, hd), (-hb, hd), (-hb, -hd)]
    extents = [depth, width, depth, width]
    points, faces = [], []
    for k in range(4):
        p, q = np.array(corners[k]), np.array(corners[(k + 1) % 4])
        s = _face_fractions(extents[k], size, corner_cell)[:-1]
        points.append(p[None, :] + s[:, None] * (q - p)[None, :])
        faces.extend([k + 1] * s.size)
    ring = np.vstack(points)
    msh, _, tags = _surface(comm, ring, np.array(faces, dtype=np.int32), length, nx, True)
    tol = 1e-9 * max(length, width, depth)
    facet_tags, cell_tags = _tags(msh, tags, _end_markers(length, tol))
    return SectionMesh(msh, facet_tags, cell_tags, "box", length, width, depth, ring.shape[0], nx)


def tube_mesh(
    diameter: float,
    length: float,
    size: float,
    comm: MPI.Comm = MPI.COMM_WORLD,
    *,
    cells_around: int | None = None,
) -> SectionMesh:
    """Circular hollow section: the polygon of its nodes swept along x (flat facets).

    Args:
        diameter: Mid-surface diameter 2R (m), > 0.
        length: Length L (m) between the loaded ends, > 0.
        size: Target cell size (m), > 0, along x and around (the facet's chord).
        comm: Communicator of the mesh.
        cells_around: Cells around the section instead of the one from ``size``
            (even, >= 8: nodes at y = +-R on z = 0, where the prestress solve pins).

    Note:
        Collective on ``comm``.
    """
    _positive(diameter=diameter, length=length, size=size)
    R = 0.5 * diameter
    nc = _facets(diameter, size) if cells_around is None else cells_around
    if nc < 8 or nc % 2:
        raise InputError(f"cells_around must be an even integer >= 8, got {nc}")
    nx = _cells_along(length, size)
    phi = 2.0 * math.pi * np.arange(nc) / nc
    ring = np.stack([R * np.cos(phi), R * np.sin(phi)], axis=1)
    msh, _, tags = _surface(comm, ring, np.ones(nc, dtype=np.int32), length, nx, True)
    tol = 1e-9 * max(length, diameter)
    facet_tags, cell_tags = _tags(msh, tags, _end_markers(length, tol))
    return SectionMesh(msh, facet_tags, cell_tags, "tube", length, diameter, diameter, nc, nx)


def flat_face_mesh(
    width: float,
    length: float,
    size: float | None = None,
    comm: MPI.Comm = MPI.COMM_WORLD,
    *,
    cells: tuple[int, int] | None = None,
) -> SectionMesh:
    """One flat face [0, L] x [0, b] in the plane z = 0: the plate, embedded in 3-D.

    Args:
        width: Width b (m) along y, > 0.
        length: Length L (m) along x, > 0.
        size: Target cell size (m), or
        cells: (cells along x, cells across y), as the plate's ``mesh.nx, mesh.ny``.
        comm: Communicator of the mesh.

    Note:
        Collective on ``comm``.
    """
    _positive(width=width, length=length)
    if cells is None:
        if size is None:
            raise InputError("flat_face_mesh needs size or cells")
        _positive(size=size)
        nx, ny = _cells_along(length, size), face_cells(width, size, False, 1)
    else:
        nx, ny = cells
    ring = np.stack([np.linspace(0.0, width, ny + 1), np.zeros(ny + 1)], axis=1)
    msh, _, tags = _surface(comm, ring, np.ones(ny, dtype=np.int32), length, nx, False)
    tol = 1e-9 * max(length, width)
    markers = _end_markers(length, tol)
    markers[FLAT_BOTTOM] = lambda x: np.isclose(x[1], 0.0, rtol=0.0, atol=tol)
    markers[FLAT_TOP] = lambda x: np.isclose(x[1], width, rtol=0.0, atol=tol)
    facet_tags, cell_tags = _tags(msh, tags, markers)
    return SectionMesh(msh, facet_tags, cell_tags, "flat", length, width, 0.0, ny, nx)


def grid_nodes(
    shape: str, across: tuple[float, float], length: float, size: float, corner: float | None
) -> tuple[int, int]:
    """(nodes around, nodes along) of the mesh :func:`section_mesh` would make, without it.

    ``across``: a box's (width, depth), a tube's (diameter, diameter), a flat face's
    (width, 0); ``corner``: a box's ``corner_cell``. No input is checked here.
    """
    along = _cells_along(length, size) + 1
    if shape == "tube":
        return _facets(across[0], size), along
    if shape == "flat":
        return face_cells(across[0], size, even=False, least=1) + 1, along
    b, d = across
    return sum(_face_cells(e, size, corner) for e in (d, b, d, b)), along


def _face_cells(extent: float, size: float, first: float | None) -> int:
    """The cells :func:`_face_fractions` puts across a face, counted without its arrays."""
    widths, n_mid, _ = _face_grading(extent, size, first)
    return 2 * len(widths) + n_mid


def cell_length(length: float, size: float) -> float:
    """The length along x (m) of the cells :func:`section_mesh` makes: L/ceil(L/size)."""
    return length / _cells_along(length, size)


def face_cell_width(extent: float, size: float, corner: float | None = None) -> float:
    """The widest cell (m) across a box's face of width ``extent`` (:func:`box_mesh`).

    An even number of cells of at most ``size``; graded at the corners (``corner``), the
    uniform middle part's.
    """
    widths, n_mid, middle = _face_grading(extent, size, corner)
    return max([middle / n_mid, *widths])


def tube_facet_width(diameter: float, size: float) -> float:
    """The width (m) of a tube's facets (:func:`tube_mesh`): the chord 2R sin(pi/n)."""
    return diameter * math.sin(math.pi / _facets(diameter, size))


def section_mesh(
    shape: str,
    *,
    width: float | None = None,
    depth: float | None = None,
    diameter: float | None = None,
    length: float,
    size: float,
    comm: MPI.Comm = MPI.COMM_WORLD,
    corner_cell: float | None = None,
) -> SectionMesh:
    """The mesh of a section named by ``shape`` ("box", "tube" or "flat").

    Note:
        Collective on ``comm``.
    """
    if shape == "box":
        if width is None or depth is None:
            raise InputError("a box needs width and depth")
        return box_mesh(width, depth, length, size, comm, corner_cell=corner_cell)
    if shape == "tube":
        if diameter is None:
            raise InputError("a tube needs diameter")
        return tube_mesh(diameter, length, size, comm)
    if shape == "flat":
        if width is None:
            raise InputError("a flat face needs width")
        return flat_face_mesh(width, length, size, comm)
    raise InputError(f"shape must be one of {SHAPES}, got {shape!r}")


def _positive(**values: float) -> None:
    for name, v in values.items():
        if not (math.isfinite(v) and v > 0.0):
            raise InputError(f"{name} must be a finite number > 0 (m), got {v!r}")
