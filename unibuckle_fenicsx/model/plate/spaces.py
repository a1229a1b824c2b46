r"""Function spaces and the MacNeal/MITC4 assumed shear strain operator.

The deflection w and the rotation :math:`\theta` are bilinear (Q1) on quadrilaterals,
in one mixed space :math:`W = Q_1 \times Q_1^2`. The transverse shear strain is not
:math:`\nabla w - \theta` but its interpolant
:math:`\gamma_h = \Pi(\nabla w - \theta)` into the lowest-order N1curl space
(tangential components at edge midpoints: MacNeal's / Bathe-Dvorkin's assumed shear
strain; Bathe & Dvorkin, Int. J. Numer. Meth. Engng 21, 1985), which removes shear
locking without hourglass modes.
:math:`\Pi \nabla w` is exactly the discrete gradient and :math:`\Pi \theta` the
interpolation matrix, so :math:`\gamma_h = P u` with a sparse matrix P.
"""

from __future__ import annotations

from petsc4py import PETSc

import basix.ufl
import dolfinx
import dolfinx.fem.petsc

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.model.mesh import collapsed

__all__ = ["MixedDofs", "create_plate_space", "create_shear_space", "mitc_shear_operator"]


def create_plate_space(msh: dolfinx.mesh.Mesh) -> dolfinx.fem.FunctionSpace:
    r"""Mixed space :math:`W = Q_1 \times Q_1^2` for (w, theta); sub-space 0 is w."""
    cell = msh.basix_cell().name
    Q1 = basix.ufl.element("Lagrange", cell, 1)
    Q1v = basix.ufl.element("Lagrange", cell, 1, shape=(2,))
    return dolfinx.fem.functionspace(msh, basix.ufl.mixed_element([Q1, Q1v]))


def create_shear_space(msh: dolfinx.mesh.Mesh) -> dolfinx.fem.FunctionSpace:
    """Lowest-order N1curl space of the assumed shear strain."""
    return dolfinx.fem.functionspace(msh, ("N1curl", 1))


def _restriction(
    W: dolfinx.fem.FunctionSpace, Vc: dolfinx.fem.FunctionSpace, parent: npt.NDArray[np.int32]
) -> PETSc.Mat:
    """0/1 matrix R with (R u)_i = u[parent[i]], from W to its collapsed sub-space Vc."""
    imW, bsW = W.dofmap.index_map, W.dofmap.index_map_bs
    imc, bsc = Vc.dofmap.index_map, Vc.dofmap.index_map_bs
    n_rows = imc.size_local * bsc
    local = np.ascontiguousarray(parent[:n_rows], dtype=np.int32)
    cols = imW.local_to_global(local // bsW) * bsW + local % bsW
    R = PETSc.Mat().createAIJ(
        ((n_rows, None), (imW.size_local * bsW, None)),  # type: ignore[arg-type]
        csr=(  # type: ignore[arg-type]
            np.arange(n_rows + 1, dtype=PETSc.IntType),
            cols.astype(PETSc.IntType),
            np.ones(n_rows, dtype=PETSc.ScalarType),
        ),
        comm=W.mesh.comm,
    )
    R.assemble()
    return R


def mitc_shear_operator(
    W: dolfinx.fem.FunctionSpace,
    Vs: dolfinx.fem.FunctionSpace,
    *,
    w_sub: int = 0,
    theta_sub: int = 1,
) -> PETSc.Mat:
    r"""Matrix P with :math:`\gamma_h = P u = \Pi \nabla w - \Pi \theta`.

    Args:
        W: Mixed space holding w (Q1) and theta (Q1^2), e.g. the (w, theta) space of
            :func:`create_plate_space`.
        Vs: N1curl space from :func:`create_shear_space`.
        w_sub: Sub-space of W holding w.
        theta_sub: Sub-space of W holding theta.

    Returns:
        P of size dim(Vs) x dim(W). The caller must destroy it.

    Note:
        Collective.
    """
    _, Vw, map_w = collapsed(W, w_sub)
    _, Vt, map_t = collapsed(W, theta_sub)
    G = dolfinx.fem.petsc.discrete_gradient(Vw, Vs)
    G.assemble()
    I = dolfinx.fem.petsc.interpolation_matrix(Vt, Vs)  # noqa: E741
    I.assemble()
    Rw = _restriction(W, Vw, map_w)
    Rt = _restriction(W, Vt, map_t)
    P = G.matMult(Rw)
    It = I.matMult(Rt)
    P.axpy(-1.0, It, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)  # type: ignore[arg-type]
    for m in (G, I, Rw, Rt, It):
        m.destroy()
    return P


class MixedDofs:
    """DOF counts and global indices of a mixed space ``self.W`` (for the plate models)."""

    W: dolfinx.fem.FunctionSpace

    @property
    def num_owned_dofs(self) -> int:
        """Owned DOFs of W on this rank."""
        return self.W.dofmap.index_map.size_local * self.W.dofmap.index_map_bs

    @property
    def num_dofs(self) -> int:
        """Global DOF count of W."""
        return self.W.dofmap.index_map.size_global * self.W.dofmap.index_map_bs

    def global_dofs(self, local: npt.NDArray[np.int32]) -> npt.NDArray[np.int64]:
        """Global (PETSc) indices of the local W DOFs ``local``."""
        im, bs = self.W.dofmap.index_map, self.W.dofmap.index_map_bs
        local = np.ascontiguousarray(local, dtype=np.int32)
        return im.local_to_global(local // bs) * bs + local % bs
