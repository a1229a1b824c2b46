"""Sparse patterns and collapsed sub-spaces, computed once and compared without copies.

``same_pattern`` decides whether the certificate's shifted matrix may use the mesh's
shared factorisation (one symbolic analysis); ``collapsed`` keeps a space's collapsed
sub-spaces. Expected values come from the matrices' own construction (a pattern written
down here, a value changed, an entry moved) and from dolfinx's ``collapse`` called
directly.
"""

from __future__ import annotations

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx

import numpy as np
import pytest

from unibuckle_fenicsx.la.factor import same_pattern
from unibuckle_fenicsx.model.mesh import collapsed
from unibuckle_fenicsx.model.plate.spaces import create_plate_space

# A 4 x 4 pattern: rows of 2, 3, 2 and 2 entries.
INDPTR = np.array([0, 2, 5, 7, 9], dtype=PETSc.IntType)
INDICES = np.array([0, 1, 0, 1, 2, 1, 2, 2, 3], dtype=PETSc.IntType)


def _matrix(indptr, indices, values):
    return PETSc.Mat().createAIJWithArrays(  # one rank: the whole matrix is local
        (4, 4), (indptr, indices, np.asarray(values, dtype=float)), comm=MPI.COMM_SELF
    )


def test_same_pattern_reads_indices_not_values():
    a = _matrix(INDPTR, INDICES, np.arange(1.0, 10.0))
    same = _matrix(INDPTR, INDICES, np.zeros(9))  # stored zeros count as entries
    moved = INDICES.copy()
    moved[-1] = 0  # row 3: (3, 2), (3, 0) -> one entry moved, the count kept
    moved[-2:] = np.sort(moved[-2:])
    other = _matrix(INDPTR, moved, np.arange(1.0, 10.0))
    fewer = _matrix(
        np.array([0, 2, 5, 7, 8], dtype=PETSc.IntType), INDICES[:-1], np.arange(1.0, 9.0)
    )
    try:
        assert same_pattern(a, a)
        assert same_pattern(a, same)
        assert not same_pattern(a, other)
        assert not same_pattern(a, fewer)
        assert not same_pattern(fewer, a)
    finally:
        for m in (a, same, other, fewer):
            m.destroy()


@pytest.mark.parametrize("path", [(0,), (1,), (1, 0), (1, 1)])
def test_collapsed_is_dolfinx_collapse_computed_once(path):
    msh = dolfinx.mesh.create_rectangle(
        MPI.COMM_WORLD, [[0.0, 0.0], [2.0, 1.0]], [4, 2], dolfinx.mesh.CellType.quadrilateral
    )
    W = create_plate_space(msh)
    first = collapsed(W, *path)
    assert collapsed(W, *path) is first  # kept on W
    sub = W
    for i in path:
        sub = sub.sub(i)
    Vc, dofs = sub.collapse()
    np.testing.assert_array_equal(first.dofs, np.asarray(dofs[0], dtype=np.int32))
    np.testing.assert_array_equal(
        first.space.tabulate_dof_coordinates(), Vc.tabulate_dof_coordinates()
    )
    assert first.sub.component() == sub.component()
    other = create_plate_space(msh)  # another space: its own sub-spaces
    assert collapsed(other, *path) is not first
