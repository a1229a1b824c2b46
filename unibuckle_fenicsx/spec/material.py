"""The material: isotropic, general Voigt matrices, or a laminate of plies."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Annotated, ClassVar

import numpy as np
from msgspec import Meta

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.laminate import laminate
from unibuckle_fenicsx.spec.base import Matrix3, Table, in_file, unit

#: Elastic moduli (Pa) accepted: from three decades below the softest elastomers'
#: (about 1e6 Pa) to ten times diamond's (1.2e12 Pa). The buckling load is proportional
#: to E, so nothing physical lies outside; far outside (1e200, 1e-300 Pa) the stiffness
#: matrices overflow or underflow in double precision and SLEPc fails in the solve.
MIN_MODULUS, MAX_MODULUS = 1.0e3, 1.0e13
Modulus = Annotated[float, unit("Pa", ge=MIN_MODULUS, le=MAX_MODULUS)]
#: Below this modulus (Pa) no structural material lies (polymers about 3e9 Pa, timber
#: about 1e10 Pa): an E accepted by the range but below it is most likely in another unit
#: (210000, steel's E in MPa, in an SI file), and draws a warning (:func:`modulus_note`).
STRUCTURAL_MODULUS = 1.0e8


def modulus_note(E: float, units: str = "SI") -> str | None:
    """A warning when ``E`` (Pa) lies below :data:`STRUCTURAL_MODULUS`, else None.

    The buckling load is proportional to E, so a modulus in MPa in an SI file gives every
    stress in MPa printed as Pa. ``units``: the file's unit system, in which the message
    writes E and says what to change.
    """
    if E >= STRUCTURAL_MODULUS:
        return None
    (given, low), name = in_file((E, STRUCTURAL_MODULUS), "Pa", units)
    if units == "SI":
        fix = (
            'if it is in MPa and the lengths in mm, put units = "mm-N-MPa" at the top of the '
            "file (as given, the stresses printed in Pa are in the unit of E)"
        )
    else:
        fix = f"give it in {name} (steel: 210000 {name})"
    return (
        f"material.E = {given:g} {name} is below any structural material's modulus "
        f"({low:g} {name}; polymers about 3 GPa, steel 210 GPa): {fix}"
    )


#: Shear correction factors accepted. kappa_s G t is the shear stiffness of the section
#: (energy-equivalent to its shear stress tau(z)): kappa_s = (int tau dz)^2 /
#: (G_mean t int tau^2/G dz) <= 1 by the Cauchy-Schwarz inequality, for any layering;
#: 5/6 for a homogeneous plate, pi^2/12 Mindlin's, down to about 1e-3 for a sandwich
#: plate with a soft core written with its faces' mean modulus. Above 1 the shear
#: stiffness exceeds any section's and aggravates the rounding of thin plates (kappa_s
#: = 10 on an outstand with t/b = 2.5e-4 failed the inertia check that 5/6 and 1 pass);
#: far outside (1e30, 1e-300) the solve fails. A plate nearly rigid in shear
#: (Kirchhoff's) is a thin plate, not a large factor.
MIN_SHEAR_CORRECTION, MAX_SHEAR_CORRECTION = 1.0e-3, 1.0

#: The largest fibre angle magnitude accepted (degrees): one turn.
MAX_PLY_ANGLE = 360.0


class Ply(Table, frozen=True):
    r"""One orthotropic ply of a laminate (:mod:`~unibuckle_fenicsx.laminate`).

    Args:
        thickness: Ply thickness (m), > 0.
        angle: Fibre angle from the x axis, counter-clockwise (degrees), in [-360, 360]:
            one turn either way covers every angle; a larger value is a typing error (a
            ply at 1e300 degrees has no meaningful cosine).
        E1: Young's modulus along the fibres (Pa), in [1e3, 1e13] (:data:`MIN_MODULUS`,
            :data:`MAX_MODULUS`: from far below the softest elastomer to ten times diamond).
        E2: Young's modulus across the fibres (Pa), in [1e3, 1e13].
        G12: In-plane shear modulus (Pa), in [1e3, 1e13].
        nu12: Major Poisson's ratio, :math:`|\nu_{12}| < \sqrt{E_1/E_2}` (a positive
            definite ply).
        G13: Transverse shear modulus in the 1-3 plane (Pa), in [1e3, 1e13].
        G23: Transverse shear modulus in the 2-3 plane (Pa), in [1e3, 1e13].
    """

    KEY: ClassVar[str] = "material.plies"
    thickness: Annotated[float, unit("m", gt=0)]
    angle: Annotated[float, unit("degrees", ge=-MAX_PLY_ANGLE, le=MAX_PLY_ANGLE)]
    E1: Modulus
    E2: Modulus
    G12: Modulus
    nu12: float
    G13: Modulus
    G23: Modulus

    def check(self) -> None:
        """The rules between this table's fields."""
        bound = math.sqrt(self.E1 / self.E2)
        if not abs(self.nu12) < bound:
            raise self.error(
                "nu12",
                f" must satisfy |nu12| < sqrt(E1/E2) = {bound:.4g} (a positive definite ply), "
                f"got {self.nu12!r}",
            )


class Material(Table, frozen=True):
    r"""Linear elastic material (the file's ``[material]``).

    Args:
        E: Young's modulus (Pa), in [1e3, 1e13] (:data:`MIN_MODULUS`,
            :data:`MAX_MODULUS`): from far below the softest elastomer (1e6 Pa) to ten
            times diamond (1.2e12 Pa); beyond, the stiffness overflows double precision.
        nu: Poisson's ratio, in (-1, 0.5).
        shear_correction: Reissner-Mindlin shear correction factor, in [0.001, 1]
            (:data:`MIN_SHEAR_CORRECTION`, :data:`MAX_SHEAR_CORRECTION`): no section's
            factor exceeds 1 (Cauchy-Schwarz on its shear stress), a sandwich plate's with
            a soft core reaches about 1e-3; 5/6, the value of a homogeneous plate
            (parabolic shear stress across the thickness). A plate nearly rigid in shear
            is a thin plate, not a large factor.
        membrane_voigt: Optional general membrane stiffness (the paper's
            :math:`E_{\alpha\beta\nu\mu}` integrated over the thickness), a symmetric
            positive definite 3x3 Voigt matrix (N/m) acting on
            :math:`(\varepsilon_{11}, \varepsilon_{22}, 2\varepsilon_{12})`. ``None``:
            isotropic plane stress, :math:`t\,E/(1-\nu^2)\,[\ldots]`.
        bending_voigt: Optional general bending stiffness :math:`D_{\alpha\beta\nu\mu}`,
            3x3 Voigt (N m) acting on :math:`(\kappa_{11}, \kappa_{22}, 2\kappa_{12})`.
            ``None``: isotropic :math:`D = E t^3/(12(1-\nu^2))`.
        plies: A laminate, bottom ply first (:class:`Ply`): its stiffness by classical
            lamination theory with first-order shear (:mod:`~unibuckle_fenicsx.laminate`,
            ``shear_correction`` the factor on the shear); symmetric stacks only. E and nu
            are then the laminate's in-plane constants :math:`E_x, \nu_{xy}` (a file leaves
            them out; in code: :meth:`from_plies`); :math:`\nu_{xy}` may lie outside
            (-1, 0.5) (0.51 for a balanced +-45 glass stack).
        thermal_expansion: Coefficient of thermal expansion :math:`\alpha` (1/K), >= 0,
            the same in every direction; not for a laminate, whose plies expand differently.
    """

    KEY: ClassVar[str] = "material"
    E: Modulus
    nu: float  # in (-1, 0.5) but for a laminate (check); the schema has the file's range
    shear_correction: Annotated[float, Meta(ge=MIN_SHEAR_CORRECTION, le=MAX_SHEAR_CORRECTION)] = (
        5.0 / 6.0
    )
    membrane_voigt: Annotated[Matrix3, unit("N/m")] | None = None
    bending_voigt: Annotated[Matrix3, unit("N m")] | None = None
    plies: tuple[Ply, ...] = ()
    thermal_expansion: Annotated[float, unit("1/K", ge=0)] = 0.0

    @classmethod
    def from_plies(cls, plies: Sequence[Ply], shear_correction: float = 5.0 / 6.0) -> Material:
        """The laminate of ``plies`` (bottom first), E and nu its in-plane constants."""
        if not plies:
            raise InputError(
                f"material.plies must be a list of tables, at least one, got {plies!r}"
            )
        E, nu = laminate(plies).engineering_constants()
        return cls(E=E, nu=nu, shear_correction=shear_correction, plies=tuple(plies))

    def check(self) -> None:
        """The rules between this table's fields."""
        if self.thermal_expansion and self.plies:
            raise self.error(
                "thermal_expansion",
                ": a laminate's plies expand differently (their own coefficients along and "
                "across the fibres), which is not modelled; a thermal load needs an isotropic "
                "material or Voigt matrices",
            )
        if self.plies:
            self._check_laminate()
        elif not -1.0 < self.nu < 0.5:  # an isotropic material's; a laminate's nu_xy is not
            raise self.error("nu", f" must lie in (-1, 0.5), got {self.nu!r}")
        for name in ("membrane_voigt", "bending_voigt"):
            mat = np.array(getattr(self, name) or np.eye(3), dtype=float)
            if not np.allclose(mat, mat.T, rtol=1e-12, atol=0.0):
                raise self.error(name, " must be symmetric")
            if np.linalg.eigvalsh(mat).min() <= 0.0:
                raise self.error(name, " must be positive definite")

    def _check_laminate(self) -> None:
        """A symmetric stack of plies; E and nu its in-plane constants; no Voigt matrices."""
        if self.membrane_voigt is not None or self.bending_voigt is not None:
            raise self.error(
                "plies",
                ": a laminate's stiffness comes from its plies; give plies, or membrane_voigt "
                "and bending_voigt, not both",
            )
        stack = laminate(self.plies, self.shear_correction)
        if stack.coupling > 1e-10:
            raise self.error(
                "plies",
                ": the stack is not symmetric about its mid-plane (bending-membrane coupling: "
                f"largest |B_ij| = {np.abs(stack.B).max():.4g} N, {stack.coupling:.2g} of "
                "max|A_ij| t); unsymmetric laminates bend under in-plane load and are not "
                "modelled: give a stack symmetric about its mid-plane (same thickness, angle "
                "and material at equal distances)",
            )
        E, nu = stack.engineering_constants()
        if not (math.isclose(self.E, E, rel_tol=1e-9) and math.isclose(self.nu, nu, rel_tol=1e-9)):
            (E, name), (given, _) = in_file(E, "Pa"), in_file(self.E, "Pa")
            raise self.error(
                "E",
                f" and material.nu of a laminate are its in-plane constants E_x = {E:.6g} "
                f"{name} and nu_xy = {nu:.6g} from the plies (got {given!r}, {self.nu!r}): leave "
                "them out (Material.from_plies)",
            )
