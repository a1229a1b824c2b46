r"""Flat-facet shell kinematics and the bilinear forms of the section's buckling pencil.

Unknowns (6 per node, global components): the displacement :math:`u \in (Q_1)^3` and
the rotation vector :math:`\omega \in (Q_1)^3`, in one blocked space of shape (6,).
Each cell is a flat rectangle with the orthonormal frame :math:`(e_1, e_2, n)`,
:math:`e_1` along its first reference direction, :math:`n = e_1 \times e_2`
(:func:`cell_frame`, from the Jacobian: constant on a parallelogram). In it, the wall's
membrane displacement is :math:`u_\alpha = u\cdot e_\alpha`, its deflection
:math:`w = u\cdot n`, and the rotation of its normal fibre
:math:`\beta_\alpha = (n\times\omega)\cdot e_\alpha` (the plate model's
:math:`\theta`: Kirchhoff's constraint is :math:`\beta = \nabla w`). With the frame
constant on a cell, derivatives act on u and :math:`\omega` only:

.. math::

    \varepsilon_{\alpha\beta} = \mathrm{sym}\,(e_\alpha\cdot\partial_\beta u), \qquad
    \kappa_{\alpha\beta} = \mathrm{sym}\,\partial_\beta\beta_\alpha, \qquad
    \gamma_\alpha = \partial_\alpha w - \beta_\alpha .

Energies (the factor 1/2 written out; the forms are their second variations):

.. math::

    \tfrac12 a(U,U) = \tfrac12\int N(\varepsilon):\varepsilon
      + \tfrac12\int M(\kappa):\kappa
      + \tfrac12\int \kappa_s G t\,|\gamma^{MITC}|^2
      + \tfrac12\int \alpha_d G t\,(\omega\cdot n - \tfrac12(\partial_1 u_2 - \partial_2 u_1))^2,

.. math::

    \tfrac12 b(U,U) = -\tfrac12\int N^0_{\alpha\beta}\,\partial_\alpha u\cdot\partial_\beta u
    \quad\text{(all three components; Donnell's: } -\tfrac12\int N^0 \nabla w\cdot\nabla w).

**Assumed shear (MITC4).** Bathe & Dvorkin (Int. J. Numer. Meth. Engng 21, 1985) tie
the covariant shear :math:`\gamma_1` to its values at the midpoints of the two edges
along :math:`e_1` and interpolate linearly across; on a rectangle :math:`\gamma_1` is then
its value on the line :math:`X_0 = 1/2`, and its energy is exactly the two-point Gauss
rule on that line (and :math:`\gamma_2` on :math:`X_1 = 1/2`): :func:`shear_form` is that
quadrature, element by element. It is the plate model's N1curl interpolation
(:mod:`~unibuckle_fenicsx.model.plate.spaces`) on rectangles, but local to each cell:
at a fold the tangential shear on a shared edge differs between the two cells' planes,
so a conforming N1curl field across the fold would be wrong.

**Drilling.** The rotation about the normal has no stiffness of its own; the term of
Hughes & Brezzi (Comput. Methods Appl. Mech. Engrg 72, 1989) ties it to the membrane's
rotation, vanishes on rigid motions and on the exact solution, and with a small
:math:`\alpha_d` leaves the loads unchanged (:data:`DRILLING_FACTOR`).
"""

from __future__ import annotations

import math

import dolfinx
import ufl

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.model.prestress import material_constant, voigt_to_ufl

__all__ = [
    "DRILLING_FACTOR",
    "ShellFields",
    "bending_form",
    "cell_frame",
    "curvature",
    "drilling_form",
    "drilling_strain",
    "fibre_rotation",
    "geometric_form",
    "membrane_force",
    "membrane_form",
    "membrane_strain",
    "shear_form",
    "shear_strain",
    "split",
]

#: Drilling stiffness :math:`\alpha_d G t` relative to the membrane shear stiffness
#: :math:`G t`. Small: it only removes the singular drilling rotation (A must be
#: positive definite); the loads do not depend on it over several decades
#: (:doc:`/verification/sections`).
DRILLING_FACTOR = 1e-3

#: Quadrature of the membrane, bending, drilling and geometric forms: 2x2 Gauss points,
#: exact for the products of bilinear fields' derivatives on a rectangle. (UFL's estimate
#: from the frame's square roots is far higher, at no gain on a flat rectangle.)
GAUSS_2X2 = {"quadrature_degree": 2}


def split(U: ufl.core.expr.Expr) -> tuple[ufl.core.expr.Expr, ufl.core.expr.Expr]:
    """Displacement u and rotation vector omega of a 6-vector of the section space."""
    return ufl.as_vector([U[0], U[1], U[2]]), ufl.as_vector([U[3], U[4], U[5]])


def cell_frame(
    msh: dolfinx.mesh.Mesh,
) -> tuple[ufl.core.expr.Expr, ufl.core.expr.Expr, ufl.core.expr.Expr]:
    r"""Orthonormal frame :math:`(e_1, e_2, n)` of each cell, from its Jacobian.

    :math:`e_1` along the first reference direction, :math:`e_2` the second made
    orthogonal to it, :math:`n = e_1\times e_2`; constant on a parallelogram cell.
    """
    J = ufl.Jacobian(msh)
    g1 = ufl.as_vector([J[i, 0] for i in range(3)])
    g2 = ufl.as_vector([J[i, 1] for i in range(3)])
    e1 = g1 / ufl.sqrt(ufl.dot(g1, g1))
    h2 = g2 - ufl.dot(g2, e1) * e1
    e2 = h2 / ufl.sqrt(ufl.dot(h2, h2))
    return e1, e2, ufl.cross(e1, e2)


class ShellFields:
    """The frame of a mesh's cells and the local strains of a 6-vector field on them."""

    def __init__(self, msh: dolfinx.mesh.Mesh) -> None:
        self.mesh = msh
        self.e1, self.e2, self.n = cell_frame(msh)
        self.frame = (self.e1, self.e2)


def _d(f: ufl.core.expr.Expr, e: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
    """Derivative of the field f along the (cellwise constant) direction e."""
    return ufl.dot(ufl.grad(f), e)


def membrane_strain(U: ufl.core.expr.Expr, f: ShellFields) -> ufl.core.expr.Expr:
    r""":math:`\varepsilon_{\alpha\beta} = \mathrm{sym}(e_\alpha\cdot\partial_\beta u)` (2x2)."""
    u, _ = split(U)
    g = ufl.as_matrix([[ufl.dot(a, _d(u, b)) for b in f.frame] for a in f.frame])
    return ufl.sym(g)


def fibre_rotation(U: ufl.core.expr.Expr, f: ShellFields) -> ufl.core.expr.Expr:
    r"""Rotation of the normal fibre :math:`\beta_\alpha = (n\times\omega)\cdot e_\alpha`."""
    _, omega = split(U)
    return ufl.as_vector([ufl.dot(ufl.cross(f.n, omega), a) for a in f.frame])


def curvature(U: ufl.core.expr.Expr, f: ShellFields) -> ufl.core.expr.Expr:
    r""":math:`\kappa_{\alpha\beta} = \mathrm{sym}\,\partial_\beta\beta_\alpha` (2x2, 1/m)."""
    _, omega = split(U)
    g = ufl.as_matrix(
        [[ufl.dot(ufl.cross(f.n, _d(omega, b)), a) for b in f.frame] for a in f.frame]
    )
    return ufl.sym(g)


def shear_strain(U: ufl.core.expr.Expr, f: ShellFields) -> ufl.core.expr.Expr:
    r""":math:`\gamma_\alpha = \partial_\alpha w - \beta_\alpha` (before the MITC tying)."""
    u, _ = split(U)
    beta = fibre_rotation(U, f)
    return ufl.as_vector([ufl.dot(f.n, _d(u, a)) - beta[k] for k, a in enumerate(f.frame)])


def drilling_strain(U: ufl.core.expr.Expr, f: ShellFields) -> ufl.core.expr.Expr:
    r""":math:`\omega\cdot n - \tfrac12(\partial_1 u_2 - \partial_2 u_1)`."""
    u, omega = split(U)
    rot = ufl.dot(f.e2, _d(u, f.e1)) - ufl.dot(f.e1, _d(u, f.e2))
    return ufl.dot(omega, f.n) - 0.5 * rot


def membrane_force(
    U: ufl.core.expr.Expr, f: ShellFields, C: npt.NDArray[np.float64]
) -> ufl.core.expr.Expr:
    r"""Membrane stress resultant :math:`N = C_m\varepsilon` (N/m), 2x2 in the cell frame."""
    return voigt_to_ufl(C, membrane_strain(U, f))


def _dx() -> ufl.Measure:
    return ufl.Measure("dx", metadata=GAUSS_2X2)


def membrane_form(
    U: ufl.core.expr.Expr, V: ufl.core.expr.Expr, f: ShellFields, C: npt.NDArray[np.float64]
) -> ufl.Form:
    r""":math:`\int N(\varepsilon(u)):\varepsilon(v)` with the 3x3 Voigt :math:`C_m` (N/m)."""
    return ufl.inner(membrane_force(U, f, C), membrane_strain(V, f)) * _dx()


def bending_form(
    U: ufl.core.expr.Expr, V: ufl.core.expr.Expr, f: ShellFields, D: npt.NDArray[np.float64]
) -> ufl.Form:
    r""":math:`\int M(\kappa(u)):\kappa(v)` with the 3x3 Voigt D (N m)."""
    return ufl.inner(voigt_to_ufl(D, curvature(U, f)), curvature(V, f)) * _dx()


def _tying_measure(direction: int) -> ufl.Measure:
    """Two-point Gauss rule on the reference line through the centre across ``direction``."""
    g = 0.5 / math.sqrt(3.0)
    line = np.array([0.5 - g, 0.5 + g])
    points = np.zeros((2, 2))
    points[:, direction] = 0.5
    points[:, 1 - direction] = line
    metadata = {
        "quadrature_rule": "custom",
        "quadrature_points": points,
        "quadrature_weights": np.array([0.5, 0.5]),
    }
    return ufl.Measure("dx", metadata=metadata)


def shear_form(U: ufl.core.expr.Expr, V: ufl.core.expr.Expr, f: ShellFields, ks: float) -> ufl.Form:
    r"""MITC4 shear energy :math:`\int \kappa_s G t\, \gamma^{MITC}(u)\cdot\gamma^{MITC}(v)`.

    Each covariant component on its tying line (module docstring); rectangular cells.
    """
    k = material_constant(ks, f.n)
    gu, gv = shear_strain(U, f), shear_strain(V, f)
    return k * gu[0] * gv[0] * _tying_measure(0) + k * gu[1] * gv[1] * _tying_measure(1)


def drilling_form(
    U: ufl.core.expr.Expr, V: ufl.core.expr.Expr, f: ShellFields, kd: float
) -> ufl.Form:
    r""":math:`\int k_d\,\delta(u)\delta(v)` with the drilling strain :math:`\delta`, kd in N/m."""
    return material_constant(kd, f.n) * drilling_strain(U, f) * drilling_strain(V, f) * _dx()


def geometric_form(
    U: ufl.core.expr.Expr,
    V: ufl.core.expr.Expr,
    f: ShellFields,
    N0: ufl.core.expr.Expr,
    *,
    donnell: bool = False,
) -> ufl.Form:
    r""":math:`b(u,v) = -\int N^0_{\alpha\beta}\,\partial_\alpha u\cdot\partial_\beta v`.

    Positive for compression (:math:`N^0` negative). All three displacement components
    (the membrane stress's work on the wall's rotation of every line element: a flat
    face's in-plane motion then buckles as a column in its plane, far above its
    plate modes); ``donnell``: the normal deflection w only, the plate model's b.

    Args:
        U: Trial function (or a state) of the section space.
        V: Test function (or a state).
        f: The cells' frames.
        N0: Membrane force per unit load, 2x2 in the cell frame (N/m).
        donnell: The normal deflection only (else all three components).
    """
    u, _ = split(U)
    v, _ = split(V)
    if donnell:
        du = [ufl.dot(f.n, _d(u, a)) for a in f.frame]
        dv = [ufl.dot(f.n, _d(v, a)) for a in f.frame]
        return -sum(N0[i, j] * du[i] * dv[j] for i in range(2) for j in range(2)) * _dx()
    du3 = [_d(u, a) for a in f.frame]
    dv3 = [_d(v, a) for a in f.frame]
    return -sum(N0[i, j] * ufl.dot(du3[i], dv3[j]) for i in range(2) for j in range(2)) * _dx()
