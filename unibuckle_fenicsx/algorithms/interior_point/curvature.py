r"""The negative-curvature step of the interior-point method: leaving a saddle.

Where the barrier problem is nearly solved but the unmodified Newton matrix K still has
the wrong inertia, the iterate is near a saddle of the barrier problem, to which the
regularised steps converge; a step along the direction of most negative curvature of K
on the tangent space leaves it instead (Moré & Sorensen, *On the use of directions of
negative curvature in a modified Newton method*, Math. Program. 16, 1979). The direction
comes from the factorisation already made: with :math:`K_\delta = K + \delta M` positive
definite on the tangent space (M the regularisation's diagonal),
:math:`K_\delta^{-1}M` has the eigenvalues :math:`1/(\theta + \delta)` for those
:math:`\theta` of the pencil (K, M), so the most negative :math:`\theta` dominates a few
Krylov vectors (Rayleigh–Ritz on them; one triangular solve each, no factorisation).

Note:
    Every method is collective on the problem's communicator.
"""

from __future__ import annotations

import logging
import math

from petsc4py import PETSc

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms.interior_point.kernel import NewtonKernel, dot
from unibuckle_fenicsx.la.ownership import Owner
from unibuckle_fenicsx.tolerances import EXHAUSTED_NORM

__all__ = ["PROBE_HASH", "NegativeCurvature"]

logger = logging.getLogger(__name__)

#: The Krylov space's start, a fixed pseudo-random field of the DOFs' coordinates (x, y)
#: on a plate of length L: frac(sin(a x/L + b y/L + shift) c) with (a, b, c) these, the
#: classic one-line hash of shader programs. Any field without the plate's symmetries
#: serves; this one is cheap, reproducible and the same on any number of ranks.
PROBE_HASH = (12.9898, 78.233, 4.3e4)


class NegativeCurvature(Owner):
    """The direction of most negative curvature of the kernel's K, and the step along it.

    Args:
        kernel: The Newton kernel whose last factorisation is used.

    Note:
        Owns its Krylov vectors (made on first use); :meth:`destroy` is collective.
    """

    def __init__(self, kernel: NewtonKernel) -> None:
        self.kernel = kernel
        self.options = kernel.options
        self._krylov: list[PETSc.Vec] = []

    def _probe(self) -> PETSc.Vec:
        """Start of the negative-curvature Krylov space: a fixed pseudo-random field.

        A function of each DOF's coordinates (not of its number), so that the same
        direction is found on any number of ranks; not symmetric, so that it sees
        antisymmetric directions on a symmetric plate.
        """
        length = self.kernel.problem.spec.plate.length

        a, b, c = PROBE_HASH

        def noise(x: npt.NDArray[np.float64], shift: float) -> npt.NDArray[np.float64]:
            return np.modf(np.sin(a * x[0] / length + b * x[1] / length + shift) * c)[0]

        f = self.kernel.problem.new_mode("probe")
        bs = f.function_space.dofmap.index_map_bs
        if bs > 1:  # a blocked space (a section's six components per node)
            f.interpolate(lambda x: np.vstack([noise(x, float(k)) for k in range(bs)]))
        else:  # the plate's (w, theta)
            f.sub(0).interpolate(lambda x: noise(x, 0.0))
            f.sub(1).interpolate(lambda x: np.vstack([noise(x, 1.0), noise(x, 2.0)]))
        f.x.scatter_forward()
        return f.x.petsc_vec.copy()

    def find(self, u: PETSc.Vec, lam: float) -> tuple[float, PETSc.Vec, float] | None:
        r"""The direction of most negative curvature of K on the tangent space.

        Uses the last factorisation, :math:`K_\delta = K + \delta M` with
        :math:`\delta` the last step's correction (the kernel's direction, which also
        left :math:`Bu` in its ``Bu`` and :math:`y_2 = K_\delta^{-1}Bu` in its ``y2``).
        Rayleigh–Ritz on the Krylov space of :math:`K_\delta^{-1} M` (``curvature_vectors``
        vectors, one triangular solve each), M-orthonormal and projected on the tangent
        space :math:`(Bu)^Tv = 0` along :math:`y_2`: since :math:`K_\delta^{-1}M` has the
        eigenvalues :math:`1/(\theta + \delta)` for the eigenvalues :math:`\theta` of
        (K, M) on the tangent space, the most negative :math:`\theta` dominates.

        Returns:
            :math:`\theta = \min v^TKv / v^TMv` over the Krylov space, its direction
            v (scaled to :math:`v^TBv = 1`; a work vector, valid until the next call)
            and :math:`v^TKv`;
            None when the last step needed no correction (``delta = 0``), no vector
            was wanted, or v carries no geometric stiffness (:math:`v^TBv \le 0`,
            possible under shear). The kernel's Newton direction ``du`` is left as it was.
        """
        kernel = self.kernel
        opts = self.options
        delta = kernel.last_correction
        if not (opts.curvature_vectors and delta > 0.0):
            return None
        if not self._krylov:
            extra = opts.curvature_vectors + 3  # the metric, work, direction, basis
            self._krylov = [self._probe()] + [u.duplicate() for _ in range(extra)]
        probe, metric, work, d, *basis = self._krylov
        kernel.reg.copy(metric)  # M: the diagonal whose multiple delta M regularises K
        if opts.metric == "geometric":
            metric.scale(lam)
        # Projected on the tangent space along y2 = K_delta^{-1} Bu, which keeps every
        # vector in the range of K_delta^{-1} on the DOFs that M weighs (the rotations,
        # which carry no geometric stiffness, stay at their least energy).
        by2 = dot(kernel.Bu, kernel.y2)
        if by2 == 0.0:
            return None
        size = self._basis(probe, metric, work, basis, by2)
        if size == 0:
            return None
        # The projected pencil (V^T K V, V^T M V), with K v = K_delta v - delta M v.
        H, G = np.empty((size, size)), np.empty((size, size))
        for j, vj in enumerate(basis[:size]):
            kernel.K.mult(vj, kernel.trial)
            work.pointwiseMult(metric, vj)
            kernel.trial.axpy(-delta, work)
            for i, vi in enumerate(basis[:size]):
                H[i, j] = dot(vi, kernel.trial)
                G[i, j] = dot(vi, work)
        try:
            L = np.linalg.cholesky(0.5 * (G + G.T))
        except np.linalg.LinAlgError:
            return None  # (the basis is M-orthonormal: G is the identity up to rounding)
        theta, Y = np.linalg.eigh(np.linalg.solve(L, np.linalg.solve(L, 0.5 * (H + H.T)).T))
        coef = np.linalg.solve(L.T, Y[:, 0])
        d.zeroEntries()
        for c, v in zip(coef, basis[:size], strict=True):
            d.axpy(float(c), v)
        d.axpy(-dot(kernel.Bu, d) / by2, kernel.y2)  # tangent again (rounding)
        kernel.B.mult(d, work)
        norm2 = dot(d, work)
        if not norm2 > 0.0:  # (B is indefinite under shear)
            return None
        d.scale(1.0 / math.sqrt(norm2))
        kernel.K.mult(d, kernel.trial)  # K v = K_delta v - delta M v
        work.pointwiseMult(metric, d)
        curvature = dot(d, kernel.trial) - delta * dot(d, work)
        return float(theta[0]), d, curvature

    def _basis(
        self,
        probe: PETSc.Vec,
        metric: PETSc.Vec,
        work: PETSc.Vec,
        basis: list[PETSc.Vec],
        by2: float,
    ) -> int:
        r"""The M-orthonormal Krylov basis of :math:`K_\delta^{-1}M` on the tangent space.

        Started from ``probe``; returns its size (it stops where the space is exhausted).
        """
        kernel = self.kernel
        source, size = probe, 0
        for v in basis:
            work.pointwiseMult(metric, source)
            kernel.ksp.solve(work, v)
            v.axpy(-dot(kernel.Bu, v) / by2, kernel.y2)  # tangent
            work.pointwiseMult(metric, v)
            before = dot(work, v)
            for w in basis[:size]:  # M-orthogonal to the previous vectors
                work.pointwiseMult(metric, w)
                v.axpy(-dot(work, v), w)
            work.pointwiseMult(metric, v)
            norm2 = dot(work, v)
            if not norm2 > EXHAUSTED_NORM * before:  # the space is exhausted: rounding only
                break
            v.scale(1.0 / math.sqrt(norm2))
            source, size = v, size + 1
        return size

    def step(
        self, u: PETSc.Vec, lam: float, gap: npt.NDArray[np.float64], mu_abs: float
    ) -> float | None:
        r"""A step along the direction of most negative curvature (in place).

        Taken when :meth:`find` finds :math:`\theta <
        -` ``saddle_curvature``; the step goes along :math:`\pm v` (downhill on the
        barrier objective) up to the fraction to the boundary, and backtracks to a
        decrease of at least ``armijo`` of the quadratic model's.

        Returns:
            The Rayleigh quotient of the new (normalised) iterate, or None (``u``
            unchanged) when no curvature below the threshold or no decrease was found.
        """
        kernel = self.kernel
        opts = self.options
        found = self.find(u, lam)
        if found is None or not found[0] < -opts.saddle_curvature:
            return None
        theta, d, curvature = found
        dz = kernel.oriented(d)
        kernel.A.mult(u, kernel.Au)
        slope = dot(kernel.Au, d) + mu_abs * kernel.sum((dz / gap).sum())
        sign = -1.0 if slope > 0.0 else 1.0
        closing = sign * dz > 0.0
        t = min(1.0, opts.fraction * kernel.min(gap[closing] / (sign * dz[closing])))
        phi0 = kernel.merit(u, mu_abs)
        for _ in range(opts.max_backtracks):
            u.copy(kernel.trial)
            kernel.trial.axpy(sign * t, d)
            model = t * sign * slope + 0.5 * t * t * curvature
            try:
                kernel.normalize(kernel.trial)
            except FloatingPointError:  # b(u, u) <= 0 there (shear): shorter
                t *= opts.backtrack
                continue
            if kernel.merit(kernel.trial, mu_abs) <= phi0 + opts.armijo * model:
                break
            t *= opts.backtrack
        else:
            return None
        logger.debug("ipm curvature step: theta %.3g, step %.3g", theta, t)
        kernel.trial.copy(u)
        kernel.A.mult(u, kernel.Au)
        return dot(u, kernel.Au)

    def destroy(self) -> None:
        """Destroy the Krylov vectors (collective)."""
        for vec in getattr(self, "_krylov", []):
            vec.destroy()
        self._krylov = []

    def __del__(self) -> None:
        self.destroy()
