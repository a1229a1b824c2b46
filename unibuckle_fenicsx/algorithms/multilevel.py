"""A hierarchy of coarser structured meshes; modes and contact sets carried up it.

The unilateral solvers start on a coarse copy of the plate and carry what they found
to the next finer mesh: the interior-point method its mode (:class:`Prolongation`), the
active-set iteration its contact set (:func:`prolong_contact_set`).
"""

from __future__ import annotations

import dolfinx

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.model.mesh import collapsed
from unibuckle_fenicsx.model.problem import UnilateralProblem

__all__ = [
    "Prolongation",
    "mesh_levels",
    "prolong",
    "prolong_contact_set",
]


class Prolongation:
    """Interpolation from a coarse problem's spaces to a fine one's (any two meshes).

    Q1 functions are interpolated at the fine nodes (exact on nested meshes). From a
    structured rectangle (the chain's coarser copies of a structured plate) the
    bilinear weights of every fine node are computed once from the grid spacing and
    the coarse values are gathered on every rank; from any other mesh dolfinx's
    non-matching interpolation does it (its point-ownership data computed once and
    shared by w and theta). Hand-written because that general route locates every
    fine node in the coarse mesh's cells, a hundred times slower
    (:doc:`/verification/tuning`).

    Args:
        coarse: The coarse problem.
        fine: The fine problem (the same plate).

    Note:
        Construction and every method are collective.
    """

    def __init__(self, coarse: UnilateralProblem, fine: UnilateralProblem) -> None:
        self.coarse, self.fine = coarse, fine
        self._subs = [
            (collapsed(coarse.model.W, sub)[1:], collapsed(fine.model.W, sub)[1:]) for sub in (0, 1)
        ]
        self._grid: list[_BilinearWeights] | None = None
        if coarse.structured:
            self._grid = [_BilinearWeights(coarse, Vc, Vf) for (Vc, _), (Vf, _) in self._subs]
            return
        Vf = fine.model.Vw
        topology = Vf.mesh.topology
        index_map = topology.index_map(topology.dim)
        self._cells = np.arange(index_map.size_local + index_map.num_ghosts, dtype=np.int32)
        self._data = dolfinx.fem.create_interpolation_data(Vf, coarse.model.Vw, self._cells)

    def mode(self, u: dolfinx.fem.Function) -> dolfinx.fem.Function:
        """The coarse (w, theta) function ``u`` interpolated on the fine space."""
        out = self.fine.new_mode("prolonged")
        for sub, ((Vc, map_c), (Vf, map_f)) in enumerate(self._subs):
            coarse_values = u.x.array[map_c]
            if self._grid is not None:
                fine_values = self._grid[sub].apply(coarse_values)
            else:
                fc = dolfinx.fem.Function(Vc)
                fc.x.array[:] = coarse_values
                ff = dolfinx.fem.Function(Vf)
                ff.interpolate_nonmatching(fc, self._cells, self._data)
                fine_values = np.asarray(ff.x.array, dtype=np.float64)
            out.x.array[map_f] = fine_values
        out.x.scatter_forward()
        return out


class _BilinearWeights:
    """Bilinear interpolation from a structured rectangle's Q1 space ``Vc`` at ``Vf``'s nodes.

    Every rank gathers the coarse nodal values (by grid position) and evaluates its fine
    nodes, ghosts included: no further communication.
    """

    def __init__(
        self,
        coarse: UnilateralProblem,
        Vc: dolfinx.fem.FunctionSpace,
        Vf: dolfinx.fem.FunctionSpace,
    ) -> None:
        (x0, y0), (x1, y1) = coarse.spec.plate.corners
        nx, ny = coarse.spec.mesh.nx, coarse.spec.mesh.ny
        hx, hy = (x1 - x0) / nx, (y1 - y0) / ny
        self.bs = Vc.dofmap.index_map_bs
        self.comm = Vc.mesh.comm
        owned = Vc.dofmap.index_map.size_local
        xy = Vc.tabulate_dof_coordinates()[:owned, :2]
        ix = np.rint((xy[:, 0] - x0) / hx).astype(np.int64)
        iy = np.rint((xy[:, 1] - y0) / hy).astype(np.int64)
        self._owned = owned
        self._slots = np.concatenate(self.comm.allgather(ix * (ny + 1) + iy))
        if self._slots.size != (nx + 1) * (ny + 1):
            raise RuntimeError("Prolongation: the coarse mesh is not the expected rectangle")
        fine_xy = Vf.tabulate_dof_coordinates()
        fx = (fine_xy[:, 0] - x0) / hx
        fy = (fine_xy[:, 1] - y0) / hy
        cx = np.clip(np.floor(fx), 0, nx - 1).astype(np.int64)
        cy = np.clip(np.floor(fy), 0, ny - 1).astype(np.int64)
        sx, sy = fx - cx, fy - cy
        self._index = np.stack(
            [cx * (ny + 1) + cy, (cx + 1) * (ny + 1) + cy, cx * (ny + 1) + cy + 1,
             (cx + 1) * (ny + 1) + cy + 1], axis=1,
        )  # fmt: skip
        self._weight = np.stack(
            [(1 - sx) * (1 - sy), sx * (1 - sy), (1 - sx) * sy, sx * sy], axis=1
        )

    def apply(self, coarse_values: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """Fine nodal values (unrolled blocks) from the coarse ones (unrolled, ghosts too)."""
        mine = coarse_values.reshape(-1, self.bs)[: self._owned]
        grid = np.empty((self._slots.size, self.bs))
        grid[self._slots] = np.concatenate(self.comm.allgather(mine))
        fine = np.einsum("nk,nkb->nb", self._weight, grid[self._index])
        return fine.reshape(-1)


def mesh_levels(nx: int, ny: int, coarse_min_cells: int) -> list[tuple[int, int]]:
    """Coarser meshes (coarsest first) obtained by halving while both sides stay large."""
    levels: list[tuple[int, int]] = []
    while min(nx, ny) // 2 >= coarse_min_cells:
        nx, ny = nx // 2, ny // 2
        levels.append((nx, ny))
    return levels[::-1]


def prolong_contact_set(
    active: npt.NDArray[np.int64],
    coarse_xy: npt.NDArray[np.float64],
    fine_xy: npt.NDArray[np.float64],
    origin: tuple[float, float],
    spacing: tuple[float, float],
    cells: tuple[int, int],
) -> npt.NDArray[np.int64]:
    """Contact set on a finer structured mesh from one on a coarser mesh.

    The coarse nodes within 0.51 coarse cell widths of a fine node (in x and in y; one,
    two or four of them) vote: a fine node is in contact when at least one of them is a
    coarse contact node and none is a coarse node outside the contact set (nodes on the
    plate's edge abstain). So coinciding nodes and nodes midway between two contact nodes
    are in contact, and the contact set does not grow by a fine layer.

    Args:
        active: Coarse contact set (node numbers into ``coarse_xy``).
        coarse_xy: (ic, 2) coarse constrained-node coordinates.
        fine_xy: (i, 2) fine constrained-node coordinates.
        origin: Lower-left corner of the plate.
        spacing: Coarse cell widths (hx, hy).
        cells: Coarse cells along x and y.

    Returns:
        Sorted fine node numbers.
    """
    hx, hy = spacing
    nx, ny = cells[0] + 1, cells[1] + 1
    grid = np.zeros((nx, ny), dtype=bool)
    ix = np.rint((coarse_xy[active, 0] - origin[0]) / hx).astype(np.int64)
    iy = np.rint((coarse_xy[active, 1] - origin[1]) / hy).astype(np.int64)
    grid[np.clip(ix, 0, nx - 1), np.clip(iy, 0, ny - 1)] = True
    fx = (fine_xy[:, 0] - origin[0]) / hx
    fy = (fine_xy[:, 1] - origin[1]) / hy
    yes = np.zeros(fine_xy.shape[0], dtype=bool)
    no = np.zeros(fine_xy.shape[0], dtype=bool)
    for cx in {0: np.floor(fx), 1: np.ceil(fx)}.values():
        for cy in {0: np.floor(fy), 1: np.ceil(fy)}.values():
            gx, gy = cx.astype(np.int64), cy.astype(np.int64)
            near = (np.abs(fx - cx) <= 0.51) & (np.abs(fy - cy) <= 0.51)
            inner = near & (gx > 0) & (gx < nx - 1) & (gy > 0) & (gy < ny - 1)
            hit = np.zeros_like(inner)
            hit[inner] = grid[gx[inner], gy[inner]]
            yes |= hit
            no |= inner & ~hit
    return np.flatnonzero(yes & ~no).astype(np.int64)


def prolong(
    coarse: UnilateralProblem,
    fine: UnilateralProblem,
    active: npt.NDArray[np.int64],
) -> npt.NDArray[np.int64]:
    """Contact set ``active`` of the structured ``coarse`` problem, on ``fine``'s nodes."""
    plate = fine.spec.plate
    nx, ny = coarse.spec.mesh.nx, coarse.spec.mesh.ny
    return prolong_contact_set(
        active,
        coarse.contact.coordinates,
        fine.contact.coordinates,
        plate.corners[0],
        (plate.length / nx, plate.width / ny),
        (nx, ny),
    )
