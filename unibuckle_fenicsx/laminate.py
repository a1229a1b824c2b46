r"""Laminate stiffness by classical lamination theory with first-order transverse shear.

A stack of orthotropic plies, listed from the bottom face (z = -t/2) to the top, each
with its thickness, fibre angle :math:`\theta` (degrees, from the x axis, counter-
clockwise) and elastic constants :math:`E_1, E_2, G_{12}, \nu_{12}, G_{13}, G_{23}`
(1: along the fibres). Each ply's reduced stiffness (plane stress) in its axes,

.. math::

    Q = \frac{1}{1-\nu_{12}\nu_{21}}\begin{bmatrix} E_1 & \nu_{12}E_2 & 0\\
        \nu_{12}E_2 & E_2 & 0\\ 0 & 0 & (1-\nu_{12}\nu_{21})G_{12}\end{bmatrix},
    \qquad \nu_{21} = \nu_{12}E_2/E_1,

turns into the plate axes as :math:`\bar Q = T^T Q T` with T the transformation of the
engineering strains :math:`(\varepsilon_{x}, \varepsilon_{y}, \gamma_{xy})` into the
ply axes, and the transverse shear stiffness :math:`\bar Q_s = R^T \mathrm{diag}(G_{13},
G_{23}) R` with R the rotation of :math:`(\gamma_{xz}, \gamma_{yz})`. Then (Jones,
*Mechanics of Composite Materials*, 2nd ed., 1999, section 4.2; Reddy, *Mechanics of
Laminated Composite Plates and Shells*, 2nd ed., 2004, sections 3.3 and 3.4)

.. math::

    (A, B, D) = \sum_k \bar Q_k \left(z_k - z_{k-1},\ \tfrac12(z_k^2 - z_{k-1}^2),\
    \tfrac13(z_k^3 - z_{k-1}^3)\right), \qquad
    H = \kappa_s \sum_k \bar Q_{s,k} (z_k - z_{k-1}),

with the first-order shear deformation theory's shear correction factor
:math:`\kappa_s` (5/6). A, D and H are the package's ``membrane_voigt``,
``bending_voigt`` and transverse shear stiffness; B (bending–membrane coupling) must
vanish: the prestress and the buckling pencil here are those of a plate whose mid-plane
stays flat under in-plane load, which an unsymmetric stack does not. Hand-written: the
few lines of the textbook formulas, which no package of the environment provides.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Protocol

import numpy as np
import numpy.typing as npt

__all__ = ["Laminate", "PlyLike", "laminate", "ply_reduced_stiffness"]


class PlyLike(Protocol):
    """What :func:`laminate` needs of a ply (:class:`~unibuckle_fenicsx.spec.Ply`)."""

    @property
    def thickness(self) -> float:
        """Ply thickness (m)."""
        ...

    @property
    def angle(self) -> float:
        """Fibre angle from x (degrees)."""
        ...

    @property
    def E1(self) -> float:
        """Modulus along the fibres (Pa)."""
        ...

    @property
    def E2(self) -> float:
        """Modulus across the fibres (Pa)."""
        ...

    @property
    def G12(self) -> float:
        """In-plane shear modulus (Pa)."""
        ...

    @property
    def nu12(self) -> float:
        """Major Poisson's ratio."""
        ...

    @property
    def G13(self) -> float:
        """Transverse shear modulus, 1-3 (Pa)."""
        ...

    @property
    def G23(self) -> float:
        """Transverse shear modulus, 2-3 (Pa)."""
        ...


def ply_reduced_stiffness(ply: PlyLike) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    r"""(:math:`\bar Q`, :math:`\bar Q_s`) of one ply in the plate axes (Pa)."""
    nu21 = ply.nu12 * ply.E2 / ply.E1
    d = 1.0 - ply.nu12 * nu21
    Q = np.array(
        [
            [ply.E1 / d, ply.nu12 * ply.E2 / d, 0.0],
            [ply.nu12 * ply.E2 / d, ply.E2 / d, 0.0],
            [0.0, 0.0, ply.G12],
        ]
    )
    theta = math.radians(ply.angle)
    c, s = math.cos(theta), math.sin(theta)
    T = np.array(
        [[c * c, s * s, c * s], [s * s, c * c, -c * s], [-2 * c * s, 2 * c * s, c * c - s * s]]
    )
    R = np.array([[c, s], [-s, c]])
    return T.T @ Q @ T, R.T @ np.diag([ply.G13, ply.G23]) @ R


class Laminate:
    """A, B, D (3x3 Voigt on engineering strains/curvatures) and H (2x2) of a stack.

    Attributes:
        A: Membrane stiffness (N/m).
        B: Bending-membrane coupling (N).
        D: Bending stiffness (N m).
        H: Transverse shear stiffness (N/m), the shear correction factor included.
        thickness: Total thickness (m).
    """

    def __init__(
        self,
        A: npt.NDArray[np.float64],
        B: npt.NDArray[np.float64],
        D: npt.NDArray[np.float64],
        H: npt.NDArray[np.float64],
        thickness: float,
    ) -> None:
        self.A, self.B, self.D, self.H, self.thickness = A, B, D, H, thickness

    @property
    def coupling(self) -> float:
        r"""The largest :math:`|B_{ij}|` relative to :math:`\max|A_{ij}|\,t` (0: symmetric)."""
        return float(np.abs(self.B).max() / (np.abs(self.A).max() * self.thickness))

    def engineering_constants(self) -> tuple[float, float]:
        r"""In-plane :math:`E_x = 1/(t a_{11})` and :math:`\nu_{xy} = -a_{12}/a_{11}`, a = A⁻¹."""
        a = np.linalg.inv(self.A)
        return float(1.0 / (self.thickness * a[0, 0])), float(-a[0, 1] / a[0, 0])


def laminate(plies: Sequence[PlyLike], shear_correction: float = 5.0 / 6.0) -> Laminate:
    """The stiffness of the stack ``plies`` (bottom to top), see the module docstring."""
    total = float(sum(p.thickness for p in plies))
    z = -0.5 * total
    A, B, D = (np.zeros((3, 3)) for _ in range(3))
    H = np.zeros((2, 2))
    for ply in plies:
        Qb, Qs = ply_reduced_stiffness(ply)
        top = z + ply.thickness
        A += Qb * (top - z)
        B += Qb * (top**2 - z**2) / 2.0
        D += Qb * (top**3 - z**3) / 3.0
        H += Qs * (top - z)
        z = top

    def symmetric(m: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        return 0.5 * (m + m.T)

    return Laminate(
        symmetric(A), symmetric(B), symmetric(D), shear_correction * symmetric(H), total
    )
