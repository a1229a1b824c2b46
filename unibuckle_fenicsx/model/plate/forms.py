r"""Reissner-Mindlin kinematics and the bilinear forms of the buckling pencil.

Energies (the factor 1/2 written out; the forms below are their second variations):

.. math::

    \tfrac12 a(u,u) = \tfrac12\int_\omega M(\theta):\kappa(\theta)\,dx
                     + \tfrac12\int_\omega \kappa_s G t\, |\gamma|^2\,dx, \qquad
    \tfrac12 b(u,u) = -\tfrac12\int_\omega N^0 \nabla w\cdot\nabla w\,dx,

with :math:`\kappa = \mathrm{sym}\nabla\theta`, :math:`M = D[(1-\nu)\kappa +
\nu\,\mathrm{tr}\kappa\, I]` (or a general Voigt :math:`D_{\alpha\beta\nu\mu}`)
and :math:`\gamma = \nabla w - \theta`. b is positive for compression (N^0 < 0).
"""

from __future__ import annotations

import ufl

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.model.prestress import material_constant, voigt_to_ufl

__all__ = [
    "bending_form",
    "bending_moment",
    "curvature",
    "geometric_form",
    "shear_force",
    "shear_form",
    "shear_strain",
]


def curvature(theta: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
    r""":math:`\kappa(\theta) = \mathrm{sym}\,\nabla\theta`."""
    return ufl.sym(ufl.grad(theta))


def shear_strain(w: ufl.core.expr.Expr, theta: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
    r""":math:`\gamma = \nabla w - \theta` (before MITC interpolation)."""
    return ufl.grad(w) - theta


def bending_moment(
    theta: ufl.core.expr.Expr, D_voigt: npt.NDArray[np.float64]
) -> ufl.core.expr.Expr:
    r""":math:`M = D\,\kappa(\theta)` with the 3x3 Voigt bending stiffness (N m)."""
    return voigt_to_ufl(D_voigt, curvature(theta))


def shear_force(
    gamma: ufl.core.expr.Expr, shear_stiffness: float | npt.NDArray[np.float64]
) -> ufl.core.expr.Expr:
    r""":math:`Q = \kappa_s G t\, \gamma`, or :math:`H\gamma` with a 2x2 H (N/m)."""
    H = material_constant(shear_stiffness, gamma)
    return ufl.dot(H, gamma) if isinstance(shear_stiffness, np.ndarray) else H * gamma


def bending_form(u: ufl.Argument, v: ufl.Argument, D_voigt: npt.NDArray[np.float64]) -> ufl.Form:
    r""":math:`\int M(\theta):\kappa(\eta)` for u = (w, theta), v = (v, eta)."""
    _, theta = ufl.split(u)
    _, eta = ufl.split(v)
    return ufl.inner(bending_moment(theta, D_voigt), curvature(eta)) * ufl.dx


def shear_form(
    u: ufl.Argument, v: ufl.Argument, shear_stiffness: float | npt.NDArray[np.float64]
) -> ufl.Form:
    r"""Fully integrated shear energy :math:`\int \kappa_s G t\,\gamma(u)\cdot\gamma(v)`.

    Locks as t -> 0 on bilinear elements; kept for comparison with the MITC shear.
    """
    w, theta = ufl.split(u)
    z, eta = ufl.split(v)
    return (
        ufl.inner(shear_force(shear_strain(w, theta), shear_stiffness), shear_strain(z, eta))
        * ufl.dx
    )


def geometric_form(u: ufl.Argument, v: ufl.Argument, N0: ufl.core.expr.Expr) -> ufl.Form:
    r""":math:`b(u, v) = -\int N^0 \nabla w\cdot\nabla z` (positive for compression)."""
    w, _ = ufl.split(u)
    z, _ = ufl.split(v)
    return -ufl.inner(N0 * ufl.grad(w), ufl.grad(z)) * ufl.dx
