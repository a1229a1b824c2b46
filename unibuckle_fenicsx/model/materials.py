"""Pure functions of the elastic constants (no FEniCSx imports)."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.laminate import laminate
from unibuckle_fenicsx.spec import Material

__all__ = [
    "bending_stiffness",
    "bending_voigt",
    "membrane_voigt",
    "navier_load_kirchhoff",
    "navier_load_mindlin",
    "reference_bending_stiffness",
    "shear_modulus",
    "shear_stiffness",
    "transverse_shear",
]


def bending_stiffness(E: float, nu: float, thickness: float) -> float:
    r"""Flexural rigidity :math:`D = E t^3 / (12 (1 - \nu^2))` (N m)."""
    return E * thickness**3 / (12.0 * (1.0 - nu**2))


def shear_modulus(E: float, nu: float) -> float:
    r""":math:`G = E / (2 (1 + \nu))` (Pa)."""
    return E / (2.0 * (1.0 + nu))


def shear_stiffness(material: Material, thickness: float) -> float:
    r"""Transverse shear stiffness :math:`\kappa_s G t` (N/m)."""
    return material.shear_correction * shear_modulus(material.E, material.nu) * thickness


def _isotropic_voigt(nu: float) -> npt.NDArray[np.float64]:
    return np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, (1.0 - nu) / 2.0]])


def transverse_shear(material: Material, thickness: float) -> float | npt.NDArray[np.float64]:
    r"""Transverse shear stiffness (N/m): :math:`\kappa_s G t`, or a laminate's 2x2 H."""
    if material.plies:
        return laminate(material.plies, material.shear_correction).H
    return shear_stiffness(material, thickness)


def reference_bending_stiffness(material: Material, thickness: float) -> float:
    r""":math:`\sqrt{D_{11} D_{22}}` (N m), the scale of the buckling coefficient k.

    An isotropic plate's D; for an orthotropic plate the usual normalisation of k.
    """
    D = bending_voigt(material, thickness)
    return float(np.sqrt(D[0, 0] * D[1, 1]))


def membrane_voigt(material: Material, thickness: float) -> npt.NDArray[np.float64]:
    r"""Membrane stiffness (N/m), 3x3 Voigt on :math:`(\varepsilon_{11}, \varepsilon_{22}, 2\varepsilon_{12})`."""  # noqa: E501
    if material.plies:
        return laminate(material.plies).A
    if material.membrane_voigt is not None:
        return np.asarray(material.membrane_voigt, dtype=float)
    return material.E * thickness / (1.0 - material.nu**2) * _isotropic_voigt(material.nu)


def bending_voigt(material: Material, thickness: float) -> npt.NDArray[np.float64]:
    r"""Bending stiffness, 3x3 Voigt on :math:`(\kappa_{11}, \kappa_{22}, 2\kappa_{12})` (N m)."""
    if material.plies:
        return laminate(material.plies).D
    if material.bending_voigt is not None:
        return np.asarray(material.bending_voigt, dtype=float)
    D = bending_stiffness(material.E, material.nu, thickness)
    return D * _isotropic_voigt(material.nu)


def navier_load_kirchhoff(
    E: float, nu: float, thickness: float, a: float, b: float, m_max: int = 20
) -> tuple[float, int]:
    r"""Kirchhoff critical stress of a simply supported plate under uniaxial compression.

    :math:`\sigma = k \pi^2 D / (t b^2)` with :math:`k = \min_m (m b/a + a/(m b))^2`
    (Timoshenko), load along the side of length ``a``.

    Returns:
        The critical stress (Pa) and the number m of half-waves along ``a``.
    """
    D = bending_stiffness(E, nu, thickness)
    ks = [(m * b / a + a / (m * b)) ** 2 for m in range(1, m_max + 1)]
    m = int(np.argmin(ks)) + 1
    return ks[m - 1] * math.pi**2 * D / (thickness * b**2), m


def navier_load_mindlin(
    E: float,
    nu: float,
    thickness: float,
    a: float,
    b: float,
    kappa: float = 5.0 / 6.0,
    m_max: int = 20,
) -> tuple[float, int]:
    r"""Reissner-Mindlin critical stress, hard simple support (Navier series, n = 1).

    :math:`\sigma_m = \sigma_K(m) / (1 + \pi^2 D (m^2/a^2 + 1/b^2)/(\kappa G t))`,
    minimised over m (hard simple support: w = 0 and tangential rotation = 0).

    Returns:
        The critical stress (Pa) and the minimising m.
    """
    D = bending_stiffness(E, nu, thickness)
    G = shear_modulus(E, nu)
    loads = []
    for m in range(1, m_max + 1):
        k = (m * b / a + a / (m * b)) ** 2
        sigma_k = k * math.pi**2 * D / (thickness * b**2)
        loads.append(
            sigma_k / (1.0 + math.pi**2 * D * (m**2 / a**2 + 1.0 / b**2) / (kappa * G * thickness))
        )
    m = int(np.argmin(loads)) + 1
    return loads[m - 1], m
