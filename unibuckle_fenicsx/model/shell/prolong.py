r"""A section's mode carried from one section mesh to another of the same section.

The interior-point chain (:func:`~unibuckle_fenicsx.algorithms.chain.solve_interior_point`)
carries a barrier point's mode from a coarse section to the next finer one
(:func:`~unibuckle_fenicsx.algorithms.section_levels.solve_levels`). Every section mesh is a
tensor product (:mod:`~unibuckle_fenicsx.model.shell.geometry`): a ring of nodes around
the section swept along x. In the unrolled coordinates (x, s), s the arc length around
the mid-line (:func:`~unibuckle_fenicsx.model.shell.core.perimeter_coordinate`), each
mesh is a rectangular grid, periodic in s on a closed section, so bilinear weights in
(x, s) interpolate any two of them (nested or not: the numbers of cells are rounded up
from the sizes, and a box graded at its corners has uneven rings). The six components
of each node are interpolated in the section's frame: global on a box's flat faces
(the faces' corner nodes are shared, so no face-local frame exists there), rotated
with the node's angle around the axis on a tube (radial, tangential; on the faceted
tube global components would mix the normal deflection with the hoop displacement).

Written by hand rather than with dolfinx's ``Function.interpolate_nonmatching``: that
locates the fine nodes in the coarse cells in 3-D, whereas the faceted tubes of two
sizes are different surfaces (a fine node lies up to :math:`R(1-\cos(\pi/n))` off the
coarse facets), and it would interpolate the rotated basis's components, which turn
from node to node; the grid's weights are exact and need no search. The plate's
structured prolongation (:class:`~unibuckle_fenicsx.algorithms.multilevel.Prolongation`)
reads a plate's (w, theta) spaces and its rectangle, neither of which a section has.
"""

from __future__ import annotations

from typing import cast

import dolfinx

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.model.problem import UnilateralProblem
from unibuckle_fenicsx.model.shell.core import perimeter_coordinate
from unibuckle_fenicsx.model.shell.geometry import SectionMesh
from unibuckle_fenicsx.model.shell.model import DOFS_PER_NODE
from unibuckle_fenicsx.model.shell.problem import RotatedPencil, SectionProblem

__all__ = ["SectionProlongation"]


class SectionProlongation:
    """Bilinear interpolation in (x, s) of a section's modes, from ``coarse`` to ``fine``.

    Every rank gathers the coarse nodal values (in the section's frame, module
    docstring) and evaluates its own fine nodes; the fine mode is then turned into the
    fine pencil's basis (:meth:`~unibuckle_fenicsx.model.shell.problem.RotatedPencil.to_rotated`).

    Args:
        coarse: The section on the coarser mesh (a
            :class:`~unibuckle_fenicsx.model.shell.problem.SectionProblem`).
        fine: The same section on a finer mesh.

    Raises:
        TypeError: Either is no section problem.
        ValueError: The two are not meshes of one section (shape, length, perimeter).

    Note:
        Construction and :meth:`mode` are collective.
    """

    def __init__(self, coarse: UnilateralProblem, fine: UnilateralProblem) -> None:
        if not isinstance(coarse, SectionProblem) or not isinstance(fine, SectionProblem):
            raise TypeError("SectionProlongation carries modes between section problems")
        self.coarse: UnilateralProblem = coarse
        self.fine: UnilateralProblem = fine
        pc, pf = cast(RotatedPencil, coarse.pencil), cast(RotatedPencil, fine.pencil)
        sc, sf = pc.shell.section, pf.shell.section
        same = (sc.shape, sc.length, sc.perimeter) == (sf.shape, sf.length, sf.perimeter)
        if not same:
            raise ValueError("SectionProlongation: the two meshes are not of one section")
        self.section = sf
        self.comm = sf.mesh.comm
        self._closed = sf.shape != "flat"
        xc, phic = _nodes(sc, pc.W)
        self._owned_c = xc.shape[0]
        self._phi_c = phic
        xg, sg, ix, js = self._grid(xc)
        self._shape = (xg.size, sg.size)
        self._slots = np.concatenate(self.comm.allgather(ix * sg.size + js))
        if self._slots.size != xg.size * sg.size or np.unique(self._slots).size != self._slots.size:
            raise RuntimeError("SectionProlongation: the coarse nodes are no (x, s) grid")
        xf, self._phi_f = _nodes(sf, pf.W)
        self._index, self._weight = self._weights(xg, sg, xf)

    def _grid(
        self, x: npt.NDArray[np.float64]
    ) -> tuple[
        npt.NDArray[np.float64],
        npt.NDArray[np.float64],
        npt.NDArray[np.int64],
        npt.NDArray[np.int64],
    ]:
        """The coarse grid's lines (x and s, sorted) and the owned nodes' places on them."""
        tol = self.section.tolerance
        keys = np.round(x / tol).astype(np.int64)
        every = np.concatenate(self.comm.allgather(keys))
        values = np.concatenate(self.comm.allgather(x))
        xk, xi = np.unique(every[:, 0], return_index=True)
        sk, si = np.unique(every[:, 1], return_index=True)
        ix = np.searchsorted(xk, keys[:, 0]).astype(np.int64)
        js = np.searchsorted(sk, keys[:, 1]).astype(np.int64)
        return values[xi, 0], values[si, 1], ix, js

    def _weights(
        self, xg: npt.NDArray[np.float64], sg: npt.NDArray[np.float64], xf: npt.NDArray[np.float64]
    ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.float64]]:
        """Each fine node's four coarse grid slots and their bilinear weights."""
        nxg, nsg = xg.size, sg.size
        i = np.clip(np.searchsorted(xg, xf[:, 0], side="right") - 1, 0, nxg - 2)
        sx = np.clip((xf[:, 0] - xg[i]) / (xg[i + 1] - xg[i]), 0.0, 1.0)
        if self._closed:  # the ring's last segment closes on its first node
            ends = np.append(sg, self.section.perimeter)
            j = np.clip(np.searchsorted(ends, xf[:, 1], side="right") - 1, 0, nsg - 1)
            j1 = (j + 1) % nsg
            sy = np.clip((xf[:, 1] - ends[j]) / (ends[j + 1] - ends[j]), 0.0, 1.0)
        else:
            j = np.clip(np.searchsorted(sg, xf[:, 1], side="right") - 1, 0, nsg - 2)
            j1 = j + 1
            sy = np.clip((xf[:, 1] - sg[j]) / (sg[j1] - sg[j]), 0.0, 1.0)
        index = np.stack([i * nsg + j, (i + 1) * nsg + j, i * nsg + j1, (i + 1) * nsg + j1], axis=1)
        weight = np.stack([(1 - sx) * (1 - sy), sx * (1 - sy), (1 - sx) * sy, sx * sy], axis=1)
        return index, weight

    def mode(self, u: dolfinx.fem.Function) -> dolfinx.fem.Function:
        """The coarse mode ``u`` (the coarse pencil's basis) on the fine section (its basis)."""
        pc = cast(RotatedPencil, cast(SectionProblem, self.coarse).pencil)
        pf = cast(RotatedPencil, cast(SectionProblem, self.fine).pencil)
        g = dolfinx.fem.Function(pc.W)
        pc.to_global(u.x.petsc_vec, g.x.petsc_vec)
        owned = np.asarray(g.x.array[: self._owned_c * DOFS_PER_NODE], dtype=np.float64)
        mine = _to_frame(owned.reshape(-1, DOFS_PER_NODE), self._phi_c, 1.0)
        grid = np.empty((self._slots.size, DOFS_PER_NODE))
        grid[self._slots] = np.concatenate(self.comm.allgather(mine))
        values = np.einsum("nk,nkb->nb", self._weight, grid[self._index])
        values = _to_frame(values, self._phi_f, -1.0)
        fine_global = dolfinx.fem.Function(pf.W)
        n = values.shape[0] * DOFS_PER_NODE
        fine_global.x.array[:n] = values.reshape(-1)
        out = self.fine.new_mode("prolonged")
        pf.to_rotated(fine_global.x.petsc_vec, out.x.petsc_vec)
        out.x.scatter_forward()
        return out


def _nodes(
    section: SectionMesh, W: dolfinx.fem.FunctionSpace
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64] | None]:
    """The owned nodes' unrolled (x, s), s wrapped to [0, perimeter), and a tube's angles."""
    owned = W.dofmap.index_map.size_local
    X = W.tabulate_dof_coordinates()[:owned]
    s = perimeter_coordinate(section, X.T)
    if section.shape != "flat":
        s = np.where(s > section.perimeter - section.tolerance, 0.0, s)
    phi = np.arctan2(X[:, 2], X[:, 1]) if section.shape == "tube" else None
    return np.stack([X[:, 0], s], axis=1), phi


def _to_frame(
    values: npt.NDArray[np.float64], phi: npt.NDArray[np.float64] | None, sign: float
) -> npt.NDArray[np.float64]:
    """Nodal (n, 6) components turned about x by ``-sign * phi``.

    Global to a tube's frame for sign 1, back for -1; unchanged without angles (a box,
    a flat face).
    """
    if phi is None:
        return values
    c, s = np.cos(phi), sign * np.sin(phi)
    out = values.copy()
    for k in (0, 3):  # the translations and the rotations
        y, z = values[:, k + 1], values[:, k + 2]
        out[:, k + 1] = c * y + s * z
        out[:, k + 2] = -s * y + c * z
    return out
