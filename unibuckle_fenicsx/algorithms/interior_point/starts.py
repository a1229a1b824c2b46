r"""Starts of the interior-point method: points strictly inside the cone.

The method needs a mode strictly inside the cone :math:`\{u: s_k u_k < 0, k \in I\}`:
the deflection under a pressure pushing the plate off the obstacle
(:meth:`Starts.pressure_mode`), the part of a mode on the admissible side
(:meth:`Starts.negative_part`) pushed inside by that deflection
(:meth:`Starts.make_interior`), a mode carried from a coarser mesh relaxed into this
mesh's discrete Kirchhoff kernel (:meth:`Starts.relax`) and lifted off the obstacle by
the least-energy correction (:meth:`Starts.lift`), or a barrier point near an exact
critical state (:meth:`Starts.from_candidate`).

Note:
    Every method is collective on the problem's communicator.
"""

from __future__ import annotations

import logging

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms.interior_point.kernel import NewtonKernel
from unibuckle_fenicsx.algorithms.interior_point.options import (
    PUSH_MARGIN,
    RELAX_OPTIONS,
    BarrierPoint,
)
from unibuckle_fenicsx.la.options import Prefix, set_options
from unibuckle_fenicsx.la.ownership import Owner
from unibuckle_fenicsx.model.problem import Candidate

__all__ = ["Starts"]

logger = logging.getLogger(__name__)


class Starts(Owner):
    """Starts strictly inside the cone, made with the kernel's matrix and solves.

    Args:
        kernel: The Newton kernel of the mesh.
        prefix: Options prefix of the relaxation's solvers (:data:`~.options.RELAX_OPTIONS`).

    Note:
        Owns the relaxation's block solvers (made on first use); :meth:`destroy` is
        collective.
    """

    def __init__(self, kernel: NewtonKernel, prefix: str = Prefix.IPM) -> None:
        self.kernel = kernel
        self.prefix = prefix
        # relax(): the solvers of A's deflection and rotation blocks, made on first use.
        self._blocks: dict[str, tuple[npt.NDArray[np.int64], PETSc.KSP, PETSc.Vec, PETSc.Vec]] = {}

    def pressure_mode(self, weights: npt.NDArray[np.float64] | None = None) -> dolfinx.fem.Function:
        r"""Deflection under nodal forces ``weights`` pushing the plate off the obstacle.

        :math:`A u = -E\,\omega` (one factorisation of A): for positive weights a
        deflection strictly inside the cone on simply supported and clamped plates, with
        rotations consistent with it. Where it is not (obstacles on both sides of a
        plate with a free edge: the two pushes twist it across an obstacle), the nodes
        closer to the obstacle than ``margin`` max|w| are moved back by :meth:`lift`.

        Args:
            weights: (i,) nonnegative weights of the constrained nodes (default all 1).
        """
        kernel = self.kernel
        n = kernel.contact.size
        weights = np.ones(n) if weights is None else np.asarray(weights, dtype=float)
        kernel.factor(0.0, None)
        kernel.rhs.zeroEntries()
        kernel.add_zone(kernel.rhs, -weights[kernel.contact.owned_positions])
        u = kernel.problem.new_mode("start")
        kernel.ksp.solve(kernel.rhs, u.x.petsc_vec)
        u.x.scatter_forward()
        if not kernel.min(-kernel.oriented(u.x.petsc_vec)) > 0.0:
            self.lift(u, PUSH_MARGIN)
        return u

    def relax(self, vec: PETSc.Vec, free: str = "rotations") -> None:
        r"""Minimise :math:`a(u, u)` over the rotations (or the deflection) of ``vec``.

        A mode interpolated from another mesh, or built from nodal deflections, is not
        in this mesh's discrete Kirchhoff kernel: its assumed shear strain is not small
        and, on a thin plate, its quotient is orders of magnitude off. Minimising the
        energy over w with the rotations held (a Poisson-like problem: w integrates the
        rotations along the edges), then over the rotations with w held, restores it
        while keeping the shape. Each is a solve with a block of A (the free DOFs'
        rows and columns; :data:`~.options.RELAX_OPTIONS`). Should that solver not converge,
        the whole matrix is factorised with the held DOFs given a stiff diagonal
        (:meth:`~.kernel.NewtonKernel.held_diagonal`).

        Args:
            vec: The W-vector, changed in place.
            free: "rotations" or "deflection": the DOFs that move.
        """
        kernel = self.kernel
        if free not in ("rotations", "deflection"):
            raise ValueError(f'free must be "rotations" or "deflection", got {free!r}')
        kernel.A.mult(vec, kernel.rhs)
        kernel.rhs.scale(-1.0)
        local, ksp, rhs, step = self._block(free)
        rhs.array[:] = kernel.rhs.array_r[local]
        ksp.solve(rhs, step)
        if int(ksp.getConvergedReason()) > 0:  # type: ignore[call-overload]
            vec.array[local] += np.asarray(step.array_r, dtype=np.float64)
            return
        logger.debug("relax: the %s block's solver did not converge; factorising", free)
        held = np.zeros(vec.getLocalSize(), dtype=bool)
        held[kernel.problem.owned_w_dofs] = True
        if free == "deflection":
            held = ~held
        kernel.factor(0.0, None, stiff=(held, kernel.held_diagonal()))
        kernel.rhs.array[held] = 0.0
        kernel.ksp.solve(kernel.rhs, kernel.y1)
        kernel.y1.array[held] = 0.0
        vec.axpy(1.0, kernel.y1)

    def _block(self, free: str) -> tuple[npt.NDArray[np.int64], PETSc.KSP, PETSc.Vec, PETSc.Vec]:
        """``free``'s owned DOFs (local numbers), the solver of A's block there, work vectors."""
        kernel = self.kernel
        if free not in self._blocks:
            mine = np.zeros(kernel.A.getLocalSize()[0], dtype=bool)
            mine[kernel.problem.owned_w_dofs] = True
            if free == "rotations":
                mine = ~mine
            local = np.flatnonzero(mine)
            start = kernel.A.getOwnershipRange()[0]
            rows = PETSc.IS().createGeneral(
                (start + local).astype(PETSc.IntType), comm=kernel.A.comm
            )
            block = kernel.A.createSubMatrix(rows, rows)
            rows.destroy()
            block.setOption(PETSc.Mat.Option.SPD, True)
            ksp = PETSc.KSP().create(kernel.A.comm)
            ksp.setOperators(block)
            tag = "w" if free == "deflection" else "theta"
            set_options(ksp, f"{self.prefix}relax_{tag}_", RELAX_OPTIONS)
            step, rhs = block.createVecs()
            block.destroy()  # the KSP holds a reference
            self._blocks[free] = (local, ksp, rhs, step)
        return self._blocks[free]

    def relax_rotations(self, vec: PETSc.Vec) -> None:
        """:meth:`relax` over the rotations."""
        self.relax(vec, "rotations")

    def clip(self, u: dolfinx.fem.Function, margin: float) -> int:
        """Move the deflection of the nodes closer to the obstacle than ``margin`` max|w| back.

        Each such node gets the gap ``margin`` max|w| exactly (its rotations are left;
        call :meth:`relax` after). For a mode interpolated from a coarser mesh the
        nodes are few and the changes of the order of the interpolation error.

        Returns:
            The number of nodes moved (over all ranks).
        """
        kernel = self.kernel
        vec = u.x.petsc_vec
        limit = -margin * kernel.problem.max_abs_w(vec)
        z = kernel.oriented(vec)
        moved = z > limit
        vec.array[kernel.dofs[moved]] = kernel.signs[moved] * limit
        u.x.scatter_forward()
        return int(kernel.comm.allreduce(int(moved.sum()), op=MPI.SUM))

    def lift(self, u: dolfinx.fem.Function, margin: float) -> int:
        r"""Move the nodes closer to the obstacle than ``margin`` max|w| back, smoothly.

        The correction :math:`c` is the deformation of least energy :math:`a(c, c)` that
        gives each such node the gap ``margin`` max|w| exactly (its deflection held by a
        stiff diagonal, as in :meth:`relax`; one factorisation). Unlike moving the nodes
        alone (:meth:`clip`), it keeps the mode in the discrete Kirchhoff kernel: on a
        thin clamped plate a mode carried from a coarser mesh keeps its quotient within
        a few per cent instead of gaining a third. Nodes that the correction still
        leaves too close are then clipped.

        Returns:
            The number of nodes moved by the correction (over all ranks).
        """
        kernel = self.kernel
        vec = u.x.petsc_vec
        limit = -margin * kernel.problem.max_abs_w(vec)
        z = kernel.oriented(vec)
        moved = z > limit
        count = int(kernel.comm.allreduce(int(moved.sum()), op=MPI.SUM))
        if count:
            held = np.zeros(vec.getLocalSize(), dtype=bool)
            held[kernel.dofs[moved]] = True
            big = kernel.held_diagonal()
            kernel.factor(0.0, None, stiff=(held, big))
            kernel.rhs.zeroEntries()
            kernel.rhs.array[kernel.dofs[moved]] = big * kernel.signs[moved] * (limit - z[moved])
            kernel.ksp.solve(kernel.rhs, kernel.y1)
            vec.axpy(1.0, kernel.y1)
            u.x.scatter_forward()
        self.clip(u, margin)
        return count

    def negative_part(self, vec: PETSc.Vec, sign: float = 1.0) -> dolfinx.fem.Function:
        """The mode ``sign * vec`` with its deflection set to 0 where it crosses the obstacle.

        The rotations are relaxed (:meth:`relax_rotations`); the result is not yet
        strictly inside the cone (see :meth:`make_interior`).
        """
        kernel = self.kernel
        u = kernel.problem.new_mode("start")
        u.x.petsc_vec.array[:] = sign * vec.array_r
        z = kernel.oriented(u.x.petsc_vec)
        u.x.petsc_vec.array[kernel.dofs[z > 0.0]] = 0.0
        self.relax_rotations(u.x.petsc_vec)
        u.x.scatter_forward()
        return u

    def make_interior(
        self,
        u: dolfinx.fem.Function,
        margin: float = PUSH_MARGIN,
        push: dolfinx.fem.Function | None = None,
    ) -> dolfinx.fem.Function:
        """Add the pressure deflection to ``u`` so that it lies strictly inside the cone.

        The deflection ``push`` (default :meth:`pressure_mode` with unit weights) is
        added with the smallest amplitude that gives every constrained node a gap of at
        least ``margin`` max|w(u)| (node by node: a node next to a clamped edge, where
        the pressure deflection is small, asks for much only if u crosses there).
        """
        kernel = self.kernel
        push = push if push is not None else self.pressure_mode()
        gap_push = -kernel.oriented(push.x.petsc_vec)
        if not kernel.min(gap_push) > 0.0:
            raise ValueError("the pressure deflection does not lie inside the cone")
        need = kernel.oriented(u.x.petsc_vec) + margin * kernel.problem.max_abs_w(u.x.petsc_vec)
        short = need > 0.0
        amount = max(kernel.max(need[short] / gap_push[short]), 0.0)
        if amount > 0.0:
            u.x.petsc_vec.axpy(amount, push.x.petsc_vec)
            u.x.scatter_forward()
        return u

    def reaction_push(
        self, mode: dolfinx.fem.Function, load: float, mu: float
    ) -> npt.NDArray[np.float64]:
        r"""Push estimate at ``mode``: the reaction :math:`-z(Au - \lambda Bu)`.

        At least :math:`\mu/g` at every node. ``mode`` must lie strictly inside the
        cone; it is normalised in place.
        """
        kernel = self.kernel
        vec = mode.x.petsc_vec
        kernel.normalize(vec)
        kernel.residual(vec, load)
        f_scale = load * float(kernel.Bu.norm(PETSc.NormType.INFINITY))
        gap = -kernel.oriented(vec)
        mu_abs = mu * f_scale * kernel.problem.max_abs_w(vec)
        return np.maximum(-kernel.oriented(kernel.Fu), mu_abs / gap)

    def from_candidate(self, cand: Candidate, mu: float) -> BarrierPoint:
        r"""A barrier point near an exact critical state ``cand`` (a :class:`Candidate`).

        The mode is pushed strictly inside the cone (by ``interior_margin`` of its
        amplitude); the push is :meth:`reaction_push`.
        """
        u = self.kernel.problem.new_mode("barrier")
        cand.mode.x.petsc_vec.copy(u.x.petsc_vec)
        u.x.scatter_forward()
        self.make_interior(u, margin=self.kernel.options.interior_margin)
        push = self.reaction_push(u, float(cand.load), mu)
        return BarrierPoint(u, float(cand.load), push, mu)

    def destroy(self) -> None:
        """Destroy the relaxation's solvers and vectors (collective)."""
        for _, ksp, rhs, step in getattr(self, "_blocks", {}).values():
            for obj in (ksp, rhs, step):
                obj.destroy()
        self._blocks = {}

    def __del__(self) -> None:
        self.destroy()
