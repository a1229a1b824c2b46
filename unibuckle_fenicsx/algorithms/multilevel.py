"""A hierarchy of coarser structured meshes, and contact sets carried up it.

On a fine mesh the active-set iteration moves the contact zone by about one node layer
per iterate (one sparse LU each), so the seeds run on a coarser copy of the plate and
their best contact sets are prolonged level by level (:func:`prolong_contact_set`),
where a couple of iterates polish them.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.problem import BucklingProblem

__all__ = ["mesh_levels", "prolong", "prolong_contact_set"]


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
    coarse: BucklingProblem,
    fine: BucklingProblem,
    active: npt.NDArray[np.int64],
) -> npt.NDArray[np.int64]:
    """Contact set ``active`` of the structured ``coarse`` problem, on ``fine``'s nodes."""
    assert coarse.contact is not None and fine.contact is not None
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
