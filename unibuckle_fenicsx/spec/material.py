"""The material: isotropic, general Voigt matrices, or a laminate of plies."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.laminate import laminate
from unibuckle_fenicsx.spec.values import (
    _number,
)

#: The largest fibre angle magnitude accepted (degrees): one turn.
MAX_PLY_ANGLE = 360.0


@dataclass(frozen=True)
class Ply:
    r"""One orthotropic ply of a laminate (:mod:`~unibuckle_fenicsx.laminate`).

    Args:
        thickness: Ply thickness (m), > 0.
        angle: Fibre angle from the x axis, counter-clockwise (degrees), in [-360, 360]:
            one turn either way covers every angle; a larger value is a typing error (a
            ply at 1e300 degrees has no meaningful cosine).
        E1: Young's modulus along the fibres (Pa), > 0.
        E2: Young's modulus across the fibres (Pa), > 0.
        G12: In-plane shear modulus (Pa), > 0.
        nu12: Major Poisson's ratio, :math:`|\nu_{12}| < \sqrt{E_1/E_2}` (a positive
            definite ply).
        G13: Transverse shear modulus in the 1-3 plane (Pa), > 0.
        G23: Transverse shear modulus in the 2-3 plane (Pa), > 0.
    """

    thickness: float
    angle: float
    E1: float
    E2: float
    G12: float
    nu12: float
    G13: float
    G23: float

    def __post_init__(self) -> None:
        for name in ("thickness", "E1", "E2", "G12", "G13", "G23"):
            value = _number(f"material.plies.{name}", getattr(self, name))
            if not value > 0.0:
                unit = "m" if name == "thickness" else "Pa"
                raise InputError(f"material.plies.{name} must be > 0 {unit}, got {value!r}")
            object.__setattr__(self, name, value)
        for name in ("angle", "nu12"):
            object.__setattr__(self, name, _number(f"material.plies.{name}", getattr(self, name)))
        if not abs(self.angle) <= MAX_PLY_ANGLE:
            raise InputError(
                f"material.plies.angle must lie in [-{MAX_PLY_ANGLE:g}, {MAX_PLY_ANGLE:g}] "
                f"degrees, got {self.angle!r}"
            )
        if not abs(self.nu12) < math.sqrt(self.E1 / self.E2):
            raise InputError(
                f"material.plies.nu12 must satisfy |nu12| < sqrt(E1/E2) = "
                f"{math.sqrt(self.E1 / self.E2):.4g} (a positive definite ply), got {self.nu12!r}"
            )


@dataclass(frozen=True)
class Material:
    r"""Linear elastic material.

    Args:
        E: Young's modulus (Pa), > 0.
        nu: Poisson's ratio, in (-1, 0.5).
        shear_correction: Reissner-Mindlin shear correction factor, > 0 (5/6).
        membrane_voigt: Optional general membrane stiffness (the paper's
            :math:`E_{\alpha\beta\nu\mu}` integrated over the thickness), a
            symmetric positive definite 3x3 Voigt matrix (N/m) acting on
            :math:`(\varepsilon_{11}, \varepsilon_{22}, 2\varepsilon_{12})`.
            ``None``: isotropic plane stress, :math:`t\,E/(1-\nu^2)\,[\ldots]`.
        bending_voigt: Optional general bending stiffness
            :math:`D_{\alpha\beta\nu\mu}`, 3x3 Voigt (N m) acting on
            :math:`(\kappa_{11}, \kappa_{22}, 2\kappa_{12})`. ``None``: isotropic
            :math:`D = E t^3/(12(1-\nu^2))`.
        plies: A laminate, bottom ply first (:class:`Ply`): its membrane, bending and
            transverse shear stiffness by classical lamination theory with first-order
            shear (:mod:`~unibuckle_fenicsx.laminate`, ``shear_correction`` the factor
            on the shear); symmetric stacks only (no bending-membrane coupling). E and
            nu are then the laminate's in-plane constants :math:`E_x, \nu_{xy}`: build
            it with :meth:`from_plies`.
        thermal_expansion: Coefficient of thermal expansion :math:`\alpha` (1/K), >= 0,
            the same in every direction (the free thermal strain :math:`\alpha\Delta T I`);
            not for a laminate, whose plies expand differently.
    """

    E: float
    nu: float
    shear_correction: float = 5.0 / 6.0
    membrane_voigt: tuple[tuple[float, ...], ...] | None = None
    bending_voigt: tuple[tuple[float, ...], ...] | None = None
    plies: tuple[Ply, ...] = ()
    thermal_expansion: float = 0.0

    @classmethod
    def from_plies(cls, plies: Any, shear_correction: float = 5.0 / 6.0) -> Material:
        """The laminate of ``plies`` (bottom first), E and nu its in-plane constants."""
        if not isinstance(plies, list | tuple) or not plies:
            raise InputError(
                "material.plies must be a list of tables ([[material.plies]] in TOML), at "
                f"least one, got {plies!r}"
            )
        for k, ply in enumerate(plies):
            if not isinstance(ply, Ply):
                raise InputError(f"material.plies[{k}] must be a Ply, got {ply!r}")
        E, nu = laminate(plies).engineering_constants()
        return cls(E=E, nu=nu, shear_correction=shear_correction, plies=tuple(plies))

    def __post_init__(self) -> None:
        object.__setattr__(self, "plies", tuple(self.plies))
        alpha = _number("material.thermal_expansion", self.thermal_expansion)
        if not alpha >= 0.0:
            raise InputError(f"material.thermal_expansion must be >= 0 1/K, got {alpha!r}")
        object.__setattr__(self, "thermal_expansion", alpha)
        if alpha and self.plies:
            raise InputError(
                "material.thermal_expansion: a laminate's plies expand differently (their "
                "own coefficients along and across the fibres), which is not modelled; a "
                "thermal load needs an isotropic material or Voigt matrices"
            )
        if self.plies:
            self._check_laminate()
            return
        if not _number("material.E", self.E) > 0.0:
            raise InputError(f"material.E (Young's modulus) must be > 0 Pa, got {self.E!r}")
        if not -1.0 < _number("material.nu", self.nu) < 0.5:
            raise InputError(
                f"material.nu (Poisson's ratio) must lie in (-1, 0.5), got {self.nu!r}"
            )
        if not _number("material.shear_correction", self.shear_correction) > 0.0:
            raise InputError(
                f"material.shear_correction must be > 0, got {self.shear_correction!r}"
            )
        for name in ("membrane_voigt", "bending_voigt"):
            value = getattr(self, name)
            if value is None:
                continue
            try:
                mat = np.array(
                    [[_number(f"material.{name}", c) for c in row] for row in value], dtype=float
                )
            except TypeError:
                raise InputError(f"material.{name} must be a 3x3 matrix, got {value!r}") from None
            if mat.shape != (3, 3):
                raise InputError(f"material.{name} must be a finite 3x3 matrix, got {value!r}")
            if not np.allclose(mat, mat.T, rtol=1e-12, atol=0.0):
                raise InputError(f"material.{name} must be symmetric")
            if np.linalg.eigvalsh(mat).min() <= 0.0:
                raise InputError(f"material.{name} must be positive definite")
            object.__setattr__(self, name, tuple(tuple(float(c) for c in row) for row in mat))
        for name in ("E", "nu", "shear_correction"):
            object.__setattr__(self, name, float(getattr(self, name)))

    def _check_laminate(self) -> None:
        """A symmetric stack of plies; E and nu its in-plane constants."""
        if self.membrane_voigt is not None or self.bending_voigt is not None:
            raise InputError(
                "material.plies: a laminate's stiffness comes from its plies; give plies, or "
                "membrane_voigt and bending_voigt, not both"
            )
        if not _number("material.shear_correction", self.shear_correction) > 0.0:
            raise InputError(
                f"material.shear_correction must be > 0, got {self.shear_correction!r}"
            )
        stack = laminate(self.plies, self.shear_correction)
        if stack.coupling > 1e-10:
            raise InputError(
                "material.plies: the stack is not symmetric about its mid-plane (bending-"
                f"membrane coupling: largest |B_ij| = {np.abs(stack.B).max():.4g} N, "
                f"{stack.coupling:.2g} of max|A_ij| t); unsymmetric laminates bend under "
                "in-plane load and are not modelled: give a stack symmetric about its "
                "mid-plane (same thickness, angle and material at equal distances)"
            )
        E, nu = stack.engineering_constants()
        if not (math.isclose(self.E, E, rel_tol=1e-9) and math.isclose(self.nu, nu, rel_tol=1e-9)):
            raise InputError(
                f"material.E and material.nu of a laminate are its in-plane constants E_x = "
                f"{E:.6g} Pa and nu_xy = {nu:.6g} from the plies (got {self.E!r}, {self.nu!r}): "
                "leave them out (Material.from_plies)"
            )
        object.__setattr__(self, "shear_correction", float(self.shear_correction))
