r"""Problem description: frozen dataclasses and the TOML loader.

The computation is in SI units (m, N, Pa). The load is *one* scalar :math:`\lambda`: the
membrane traction on a loaded edge is :math:`\lambda\, t\, (\sigma_n n + \tau_s s)` with
:math:`(\sigma_n, \tau_s)` the edge stress per unit load given here, so that
:math:`\lambda` is a stress in Pa (for the paper's plate, the compressive stress). A TOML
file may be written in another consistent system (``units``, :data:`UNITS`); it is
converted to SI when read, and results are printed in its stress unit.

Validation happens in ``__post_init__``: a bad value (wrong type included) raises
``ValueError`` naming the parameter and the allowed range before any mesh or matrix is
built.
"""

from __future__ import annotations

import json
import math
import tomllib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.checks import check_features, check_supports, check_thickness
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.geometry import (
    circle_points,
    distance_to_polygon,
    is_simple,
    points_in_circle,
    points_in_polygon,
    polygon_area,
    polygon_inside,
    polygons_disjoint,
)
from unibuckle_fenicsx.laminate import laminate

__all__ = [
    "BENDING_SUPPORTS",
    "EDGE_NAMES",
    "HOLES",
    "INPLANE_SUPPORTS",
    "METHODS",
    "POINT_KINDS",
    "SIDES",
    "UNITS",
    "Circle",
    "DesignSpec",
    "EdgeSpec",
    "LoadSpec",
    "Material",
    "MeshSpec",
    "ObstacleSpec",
    "PlateSpec",
    "Ply",
    "PointSpec",
    "Polygon",
    "ProblemSpec",
    "SolverSpec",
    "load_problem",
    "load_toml",
    "problem_from_dict",
    "problem_to_dict",
    "stress_ends",
    "stress_value",
    "temperature_field",
]

#: Edge names of a rectangular plate, in facet-tag order 1..4.
EDGE_NAMES = ("left", "right", "bottom", "top")
#: Transverse (bending) conditions. "simply_supported" is the *hard* support of a
#: Reissner-Mindlin plate (w = 0 and tangential rotation = 0); "soft" fixes w only.
BENDING_SUPPORTS = ("simply_supported", "simply_supported_soft", "clamped", "free")
#: In-plane conditions for the prestress solve.
INPLANE_SUPPORTS = ("free", "clamped", "roller")
#: Unilateral solution methods.
METHODS = ("auto", "enumerate", "interior-point", "active-set", "penalty")
#: Unit systems of a problem file: name -> (metres per length unit, pascals per stress
#: unit, stress unit's name). Forces follow (N for both).
UNITS: dict[str, tuple[float, float, str]] = {
    "SI": (1.0, 1.0, "Pa"),
    "mm-N-MPa": (1e-3, 1e6, "MPa"),
}

Predicate = Callable[[npt.NDArray[np.float64]], npt.NDArray[np.bool_]]


def _number(name: str, value: Any) -> float:
    """``value`` as a finite float; a string, a boolean or NaN/inf is refused."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise InputError(f"{name} must be a number, got {value!r} ({type(value).__name__})")
    value = float(value)
    if not math.isfinite(value):
        raise InputError(f"{name} must be a finite number, got {value!r}")
    return value


def _integer(name: str, value: Any, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < minimum:
        raise InputError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def _boolean(name: str, value: Any) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise InputError(f"{name} must be true or false, got {value!r} ({type(value).__name__})")
    return bool(value)


def _stress(name: str, value: Any) -> float | tuple[float, float]:
    """An edge stress: a number, or a pair ``[start, end]`` of numbers (linear along the edge)."""
    if isinstance(value, list | tuple):
        if len(value) != 2:
            raise InputError(
                f"{name} must be a number or a pair [start, end] (linear along the edge), "
                f"got {value!r}"
            )
        return (_number(name, value[0]), _number(name, value[1]))
    return _number(name, value)


def stress_ends(value: float | tuple[float, float]) -> tuple[float, float]:
    """(start, end) of an edge stress: the pair itself, or the number twice."""
    if isinstance(value, tuple):
        return value
    return (value, value)


def _choice(name: str, value: Any, choices: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value not in choices:
        raise InputError(f"{name} must be one of {choices}, got {value!r}")
    return value


@dataclass(frozen=True)
class Ply:
    r"""One orthotropic ply of a laminate (:mod:`~unibuckle_fenicsx.laminate`).

    Args:
        thickness: Ply thickness (m), > 0.
        angle: Fibre angle from the x axis, counter-clockwise (degrees).
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


@dataclass(frozen=True)
class Circle:
    """A circular zone: the closed disc of ``radius`` about ``center`` (m)."""

    center: tuple[float, float]
    radius: float

    def __post_init__(self) -> None:
        try:
            cx, cy = self.center
        except (TypeError, ValueError):
            raise InputError(f"circle.center must be [x, y], got {self.center!r}") from None
        object.__setattr__(
            self, "center", (_number("circle.center", cx), _number("circle.center", cy))
        )
        if not _number("circle.radius", self.radius) > 0.0:
            raise InputError(f"circle.radius must be > 0 m, got {self.radius!r}")
        object.__setattr__(self, "radius", float(self.radius))


@dataclass(frozen=True)
class Polygon:
    """A polygonal zone: the closed simple polygon of ``vertices`` (m), at least three."""

    vertices: tuple[tuple[float, float], ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "vertices", _polygon("polygon", self.vertices))


def _polygon(name: str, value: Any) -> tuple[tuple[float, float], ...]:
    """A simple polygon of at least three vertices [[x, y], ...] with a non-zero area."""
    if not isinstance(value, list | tuple) or len(value) < 3:
        raise InputError(f"{name} must be a list of at least 3 points [[x, y], ...], got {value!r}")
    vertices = []
    for point in value:
        if not isinstance(point, list | tuple) or len(point) != 2:
            raise InputError(f"{name}: each vertex must be a point [x, y], got {point!r}")
        vertices.append((_number(name, point[0]), _number(name, point[1])))
    if not is_simple(vertices):
        raise InputError(
            f"{name} must be a simple polygon (no repeated vertex, no self-intersection), "
            f"got {value!r}"
        )
    size = float(np.ptp(np.asarray(vertices), axis=0).max())
    if abs(polygon_area(vertices)) <= 1e-12 * size * size:
        raise InputError(f"{name} has no area (collinear vertices), got {value!r}")
    return tuple(vertices)


@dataclass(frozen=True)
class EdgeSpec:
    r"""Conditions on one edge part.

    Args:
        name: Edge name; for the rectangle one of :data:`EDGE_NAMES`.
        support: Transverse condition, one of :data:`BENDING_SUPPORTS`.
        inplane: In-plane condition for the prestress, one of :data:`INPLANE_SUPPORTS`
            ("roller" fixes the normal displacement only).
        normal_stress: Normal edge stress per unit load (Pa/Pa), tension positive;
            the paper's compressed edges have -1. A pair ``(start, end)`` varies
            linearly along the edge (:func:`~unibuckle_fenicsx.mesh.edge_lines` gives
            the direction): in-plane bending is ``(1, -1)``, the stress-gradient ratio
            of design codes is :math:`\psi` = end/start.
        shear_stress: Tangential edge stress per unit load (Pa/Pa), along the
            counter-clockwise tangent; a number or a pair, as ``normal_stress``.
        tag: Facet tag of this edge in a user-supplied mesh; ``None`` for the
            rectangle (tags 1..4 in :data:`EDGE_NAMES` order).
        segments: The outline segments forming this boundary part (segment k runs from
            vertex k to vertex k + 1), for a plate given by its ``outline``.
        rotational_stiffness: Elastic restraint of the rotation about the edge,
            :math:`k_r` (N m per m per rad, i.e. N), >= 0: the energy
            :math:`\tfrac12\int k_r (\theta\cdot n)^2\,ds`, on an edge whose support leaves
            that rotation free (not "clamped"). 0: none; :math:`k_r \to \infty`: clamped.
        translational_stiffness: Elastic support of the deflection along the edge,
            :math:`k_t` (N/m per m, i.e. N/m^2), >= 0: :math:`\tfrac12\int k_t w^2\,ds`,
            on an edge whose support leaves w free ("free"). :math:`k_t \to \infty`:
            the soft simple support.
        fixed_normal_stress: Normal edge stress (Pa) applied as is, not scaled by the
            load factor (the fixed part of the load, :class:`LoadSpec`); a number or a
            pair, as ``normal_stress``.
        fixed_shear_stress: Tangential edge stress (Pa) applied as is.
    """

    name: str
    support: str = "simply_supported"
    inplane: str = "free"
    normal_stress: float | tuple[float, float] = 0.0
    shear_stress: float | tuple[float, float] = 0.0
    tag: int | None = None
    segments: tuple[int, ...] | None = None
    rotational_stiffness: float = 0.0
    translational_stiffness: float = 0.0
    fixed_normal_stress: float | tuple[float, float] = 0.0
    fixed_shear_stress: float | tuple[float, float] = 0.0

    def __post_init__(self) -> None:
        where = f"edges.{self.name}"
        if not isinstance(self.name, str) or not self.name:
            raise InputError(f"edge names must be non-empty strings, got {self.name!r}")
        _choice(f"{where}.support", self.support, BENDING_SUPPORTS)
        _choice(f"{where}.inplane", self.inplane, INPLANE_SUPPORTS)
        for name in ("normal_stress", "shear_stress", "fixed_normal_stress", "fixed_shear_stress"):
            object.__setattr__(self, name, _stress(f"{where}.{name}", getattr(self, name)))
        if self.tag is not None:
            _integer(f"{where}.tag", self.tag, 0)
        if self.segments is not None:
            if not isinstance(self.segments, list | tuple) or not self.segments:
                raise InputError(
                    f"{where}.segments must be a non-empty list of outline segment numbers "
                    f"[k, ...], got {self.segments!r}"
                )
            segments = tuple(_integer(f"{where}.segments", k, 0) for k in self.segments)
            if len(set(segments)) != len(segments):
                raise InputError(f"{where}.segments repeats a segment: {list(segments)}")
            object.__setattr__(self, "segments", segments)
        self._check_springs(where)

    def _check_springs(self, where: str) -> None:
        """The edge springs: finite, >= 0, on DOFs the support leaves free."""
        for name in ("rotational_stiffness", "translational_stiffness"):
            if not _number(f"{where}.{name}", getattr(self, name)) >= 0.0:
                raise InputError(
                    f"{where}.{name} must be >= 0 (0: no spring), got {getattr(self, name)!r}"
                )
            object.__setattr__(self, name, float(getattr(self, name)))
        if self.rotational_stiffness > 0.0 and self.support == "clamped":
            raise InputError(
                f'{where}.rotational_stiffness: support = "clamped" fixes the rotation '
                "already; a rotational spring needs a support that leaves it free "
                '("simply_supported", "simply_supported_soft" or "free")'
            )
        if self.translational_stiffness > 0.0 and self.support != "free":
            raise InputError(
                f'{where}.translational_stiffness: support = "{self.support}" fixes the '
                'deflection already; an elastically supported edge has support = "free"'
            )

    @property
    def springs(self) -> bool:
        """Whether the edge carries a rotational or a translational spring."""
        return self.rotational_stiffness > 0.0 or self.translational_stiffness > 0.0

    @property
    def loaded(self) -> bool:
        r"""Whether this edge carries a traction (belongs to :math:`\gamma_1`)."""
        return any(v != 0.0 for v in (*self.normal_ends, *self.shear_ends))

    @property
    def fixed_loaded(self) -> bool:
        """Whether the edge carries a fixed traction."""
        ends = (*stress_ends(self.fixed_normal_stress), *stress_ends(self.fixed_shear_stress))
        return any(v != 0.0 for v in ends)

    def fixed_part(self) -> EdgeSpec:
        """This edge with its fixed stresses as the stresses (and no fixed part)."""
        return replace(
            self,
            normal_stress=self.fixed_normal_stress,
            shear_stress=self.fixed_shear_stress,
            fixed_normal_stress=0.0,
            fixed_shear_stress=0.0,
        )

    @property
    def normal_ends(self) -> tuple[float, float]:
        """Normal stress per unit load at the start and the end of the edge."""
        return stress_ends(self.normal_stress)

    @property
    def shear_ends(self) -> tuple[float, float]:
        """Shear stress per unit load at the start and the end of the edge."""
        return stress_ends(self.shear_stress)

    @property
    def uniform(self) -> bool:
        """Whether both stresses are constant along the edge."""
        return all(a == b for a, b in (self.normal_ends, self.shear_ends))

    def max_stress(self) -> float:
        """The largest absolute edge stress per unit load (normal or shear, either end)."""
        return max(abs(v) for v in (*self.normal_ends, *self.shear_ends))


def paper_edges() -> tuple[EdgeSpec, ...]:
    """Simply supported on the whole edge, unit compression on the short edges x = const."""
    return (
        EdgeSpec("left", normal_stress=-1.0),
        EdgeSpec("right", normal_stress=-1.0),
        EdgeSpec("bottom"),
        EdgeSpec("top"),
    )


@dataclass(frozen=True)
class PlateSpec:
    """Geometry and edge conditions of the plate.

    The plate is the rectangle of ``corners`` (a structured mesh), or, meshed by gmsh
    with quadrilaterals, the polygon ``outline``, the rectangle or the outline with
    ``holes``, or the plate of a gmsh ``file``.

    Args:
        corners: Opposite corners ``((x0, y0), (x1, y1))`` of the rectangle (m); for an
            outline, its bounding box (set from it); for a file, its bounding box once
            meshed.
        thickness: Plate thickness t = 2 epsilon (m), > 0.
        edges: One :class:`EdgeSpec` per edge part: the rectangle's are named as in
            :data:`EDGE_NAMES`, an outline's parts by their ``segments``, a file's by
            its physical groups of dimension 1; the part ``holes`` is the holes'
            boundary. Boundary parts not named are free.
        outline: A simple polygon [(x, y), ...] (m), at least three vertices; segment k
            runs from vertex k to vertex k + 1 (the last back to the first).
        holes: :class:`Circle` or :class:`Polygon` holes inside the plate, disjoint.
        file: A gmsh ``.geo`` (meshed with quadrilaterals) or ``.msh`` (its
            quadrilaterals) file with a physical surface and named physical curves.
    """

    corners: tuple[tuple[float, float], tuple[float, float]] = ((-0.1, -0.05), (0.1, 0.05))
    thickness: float = 0.006
    edges: tuple[EdgeSpec, ...] = field(default_factory=paper_edges)
    outline: tuple[tuple[float, float], ...] | None = None
    holes: tuple[Circle | Polygon, ...] = ()
    file: str | None = None

    def __post_init__(self) -> None:
        if not _number("plate.thickness", self.thickness) > 0.0:
            raise InputError(f"plate.thickness must be > 0 m, got {self.thickness!r}")
        object.__setattr__(self, "thickness", float(self.thickness))
        if self.outline is not None:
            outline = _polygon("plate.outline", self.outline)
            object.__setattr__(self, "outline", outline)
            v = np.asarray(outline)
            lo, hi = v.min(axis=0), v.max(axis=0)
            object.__setattr__(
                self, "corners", ((float(lo[0]), float(lo[1])), (float(hi[0]), float(hi[1])))
            )
        try:
            (x0, y0), (x1, y1) = self.corners
        except (TypeError, ValueError):
            raise InputError(
                f"plate.corners must be [[x0, y0], [x1, y1]], got {self.corners!r}"
            ) from None
        corners = (
            (_number("plate.corners", x0), _number("plate.corners", y0)),
            (_number("plate.corners", x1), _number("plate.corners", y1)),
        )
        object.__setattr__(self, "corners", corners)
        if not (corners[1][0] > corners[0][0] and corners[1][1] > corners[0][1]):
            raise InputError(
                "plate.corners must satisfy x1 > x0 and y1 > y0 (a non-degenerate "
                f"rectangle), got {self.corners!r}"
            )
        object.__setattr__(self, "edges", tuple(self.edges))
        names = [e.name for e in self.edges]
        if len(set(names)) != len(names):
            raise InputError(f"plate.edges: duplicate edge names {names}")
        self._check_file()
        self._check_holes()
        self._check_edges()
        check_thickness(self)

    def _check_file(self) -> None:
        if self.file is None:
            return
        if not isinstance(self.file, str) or Path(self.file).suffix.lower() not in (
            ".geo",
            ".msh",
        ):
            raise InputError(f"plate.file must be a gmsh .geo or .msh file, got {self.file!r}")
        if self.outline is not None or self.holes:
            raise InputError("plate.file: give a file, or an outline and holes, not both")
        if not Path(self.file).is_file():
            raise InputError(f"plate.file: no such file {self.file!r}")

    def _check_holes(self) -> None:
        holes = tuple(self.holes)
        object.__setattr__(self, "holes", holes)
        outer = self.boundary
        for k, hole in enumerate(holes):
            where = f"plate.holes[{k}]"
            if isinstance(hole, Circle):
                center = np.array([hole.center])
                inside = (
                    bool(points_in_polygon(center, outer)[0])
                    and float(distance_to_polygon(center, outer)[0]) > hole.radius
                )
            elif isinstance(hole, Polygon):
                inside = polygon_inside(hole.vertices, outer)
            else:
                raise InputError(f"{where} must be a Circle or a Polygon, got {hole!r}")
            if not inside:
                raise InputError(f"{where} must lie inside the plate, without touching its edge")
            for j in range(k):
                if not _disjoint(holes[j], hole):
                    raise InputError(f"plate.holes[{j}] and {where} overlap or touch")
        check_features(self, None)  # touching within rounding (a tangent hole)

    def _check_edges(self) -> None:
        count = len(self.outline) if self.outline is not None else 0
        used: dict[int, str] = {}
        for e in self.edges:
            where = f"edges.{e.name}"
            if e.name == HOLES and e.tag is None:
                if not self.holes:
                    raise InputError(f"{where}: the plate has no holes (plate.holes)")
                if e.segments is not None:
                    raise InputError(f"{where}: the holes' boundary takes no segments")
                if not e.uniform:
                    raise InputError(
                        f"{where}: a linear [start, end] stress needs a straight edge; give "
                        "the holes a number"
                    )
                continue
            if e.segments is not None:
                if self.outline is None:
                    raise InputError(
                        f"{where}.segments names segments of plate.outline, which this "
                        "plate does not have"
                    )
                for k in e.segments:
                    if k >= count:
                        raise InputError(
                            f"{where}.segments: {k} is not a segment of the outline (0 to "
                            f"{count - 1}: segment k runs from vertex k to vertex k + 1)"
                        )
                    if k in used:
                        raise InputError(
                            f"{where}.segments: segment {k} is already in edges.{used[k]}"
                        )
                    used[k] = e.name
            elif self.outline is not None and e.tag is None:
                raise InputError(
                    f"{where}: a plate given by its outline names its boundary parts by "
                    f"segments = [k, ...] (outline segments 0 to {count - 1}), or "
                    f"{HOLES!r} for the holes"
                )

    @property
    def meshed_by_gmsh(self) -> bool:
        """Whether gmsh meshes the plate (an outline, holes or a file)."""
        return self.outline is not None or bool(self.holes) or self.file is not None

    @property
    def boundary(self) -> tuple[tuple[float, float], ...]:
        """The outer boundary as a polygon: the outline, or the rectangle's four corners.

        For a file, the bounding box.
        """
        if self.outline is not None:
            return self.outline
        (x0, y0), (x1, y1) = self.corners
        return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))

    @property
    def area(self) -> float:
        """The plate's area (m^2): the outer boundary's less the holes' (a file: its box)."""
        total = abs(polygon_area(self.boundary))
        for hole in self.holes:
            if isinstance(hole, Circle):
                total -= math.pi * hole.radius**2
            else:
                total -= abs(polygon_area(hole.vertices))
        return total

    @property
    def length(self) -> float:
        """Extent in x (m)."""
        return self.corners[1][0] - self.corners[0][0]

    @property
    def width(self) -> float:
        """Extent in y (m)."""
        return self.corners[1][1] - self.corners[0][1]

    def fixed_part(self) -> PlateSpec:
        """The plate with its edges' fixed stresses as the stresses (for the fixed prestress)."""
        return replace(self, edges=tuple(e.fixed_part() for e in self.edges))

    @property
    def fixed_loaded(self) -> bool:
        """Whether an edge carries a fixed stress."""
        return any(e.fixed_loaded for e in self.edges)

    def contains(self, points: npt.NDArray[np.float64], tol: float) -> npt.NDArray[np.bool_]:
        """Mask of the points (n, 2) in the closed plate (within ``tol``), not in a hole.

        For a file, its bounding box (the mesh is not known yet).
        """
        inside = points_in_polygon(points, self.boundary, tol)
        for hole in self.holes:
            if isinstance(hole, Circle):
                inside &= ~points_in_circle(points, hole.center, hole.radius, -tol)
            else:
                inside &= ~points_in_polygon(points, hole.vertices) | (
                    distance_to_polygon(points, hole.vertices) <= tol
                )
        return inside

    def edge(self, name: str) -> EdgeSpec:
        """The edge called ``name``."""
        for e in self.edges:
            if e.name == name:
                return e
        raise KeyError(f"plate has no edge {name!r}; edges: {[e.name for e in self.edges]}")


@dataclass(frozen=True)
class MeshSpec:
    """Structured quadrilateral mesh of the rectangle.

    Args:
        nx: Cells along x, >= 2 (one cell cannot carry a buckle).
        ny: Cells along y, >= 2.
        size: The cell size the file asked for (m), or None when it gave nx and ny;
            nx and ny are then :meth:`cells_for` of the plate (recorded so that a file
            written back, e.g. a sweep point, keeps asking for the size).
    """

    nx: int = 20
    ny: int = 20
    size: float | None = None

    def __post_init__(self) -> None:
        for name in ("nx", "ny"):
            object.__setattr__(self, name, _integer(f"mesh.{name}", getattr(self, name), 2))
        if self.size is not None:
            if not _number("mesh.size", self.size) > 0.0:
                raise InputError(f"mesh.size must be > 0 m, got {self.size!r}")
            object.__setattr__(self, "size", float(self.size))

    @staticmethod
    def cells_for(length: float, width: float, size: float) -> tuple[int, int]:
        """Cells (nx, ny) of side at most ``size`` on a ``length`` x ``width`` plate (>= 2)."""
        if not _number("mesh.size", size) > 0.0:
            raise InputError(f"mesh.size must be > 0 m, got {size!r}")
        # 1e-9: a size that divides the side exactly gives that many cells, not one more.
        return tuple(  # type: ignore[return-value]
            max(2, math.ceil(side / size * (1.0 - 1e-9))) for side in (length, width)
        )

    @property
    def num_dofs(self) -> int:
        """DOFs of (w, theta) on this mesh: 3 per node."""
        return 3 * (self.nx + 1) * (self.ny + 1)


def _disjoint(a: Circle | Polygon, b: Circle | Polygon) -> bool:
    """Whether two holes neither overlap nor touch (a circle as a 256-gon, to 1e-4 r)."""
    if isinstance(a, Circle) and isinstance(b, Circle):
        return math.dist(a.center, b.center) > a.radius + b.radius
    pa, pb = (_hole_polygon(h) for h in (a, b))
    return polygons_disjoint(pa, pb)


def _hole_polygon(hole: Circle | Polygon) -> npt.NDArray[np.float64]:
    if isinstance(hole, Circle):
        return circle_points(hole.center, hole.radius, 256)
    return np.asarray(hole.vertices, dtype=float)


#: Name of the holes' boundary part in ``[edges.*]``.
HOLES = "holes"


#: Sides of an obstacle: "above" (on the +w side: w <= 0 in its zone), "below" (w >= 0);
#: "both" only for a foundation (a bilateral Winkler foundation, springs everywhere).
SIDES = ("above", "below", "both")

Box = tuple[tuple[float, float], tuple[float, float]]


def _box(name: str, value: Any) -> Box:
    """A box [[xmin, xmax], [ymin, ymax]] of finite numbers, min <= max."""
    try:
        (x0, x1), (y0, y1) = value
    except (TypeError, ValueError):
        raise InputError(f"{name} must be [[xmin, xmax], [ymin, ymax]], got {value!r}") from None
    box = ((_number(name, x0), _number(name, x1)), (_number(name, y0), _number(name, y1)))
    if box[0][0] > box[0][1] or box[1][0] > box[1][1]:
        raise InputError(f"{name} needs xmin <= xmax and ymin <= ymax, got {value!r}")
    return box


@dataclass(frozen=True)
class ObstacleSpec:
    r"""Rigid flat obstacle, or Winkler foundation, on one side of the plate over a zone.

    With ``side = "above"`` the deflection must satisfy w <= 0 at every mesh node of the
    closed zone; with ``"below"``, w >= 0. With a ``foundation_stiffness`` :math:`k_f`
    the obstacle is a tensionless (compression-only) Winkler foundation instead: the
    plate may press into it, against a pressure :math:`k_f w` (above; :math:`-k_f w`
    below), and lift off it freely; :math:`k_f \to \infty` is the rigid obstacle.
    ``side = "both"`` is then a bilateral foundation (springs in tension too).

    Args:
        zone: ``"all"`` (the whole closed plate), a box ``((xmin, xmax), (ymin, ymax))``,
            a :class:`Polygon`, a :class:`Circle`, or a predicate ``f(x) -> bool array``
            on coordinates of shape (3, n).
        tolerance: Geometric tolerance (m) for a node to count as inside a box, polygon
            or circle; ``None`` uses 1e-8 times the plate size.
        side: One of :data:`SIDES`: where the obstacle lies (w, the deflection, is
            positive towards "above"); "both" only with a foundation.
        foundation_stiffness: Winkler modulus :math:`k_f` (N/m^3, Pa/m), > 0; ``None``
            for a rigid obstacle. The springs are lumped at the zone's nodes: node k
            carries :math:`k_f \int \varphi_k\,dx` (its tributary area).
        gap: Clearance g (m) >= 0 between the flat plate and a rigid obstacle: w <= g
            (above), w >= -g (below). The nonlinear analysis follows the plate onto it;
            the linear critical state ignores an obstacle with a gap (an infinitesimal
            buckle does not reach it).
    """

    zone: Literal["all"] | Box | Polygon | Circle | Predicate = "all"
    tolerance: float | None = None
    side: str = "above"
    foundation_stiffness: float | None = None
    gap: float = 0.0

    def __post_init__(self) -> None:
        if isinstance(self.zone, str):
            if self.zone != "all":
                raise InputError(
                    f'obstacle.zone must be "all", [[xmin, xmax], [ymin, ymax]] or a '
                    f"callable, got {self.zone!r}"
                )
        elif isinstance(self.zone, Polygon | Circle):
            pass
        elif not callable(self.zone):
            object.__setattr__(self, "zone", _box("obstacle.zone", self.zone))
        if self.tolerance is not None and not _number("obstacle.tolerance", self.tolerance) >= 0:
            raise InputError(f"obstacle.tolerance must be >= 0 m, got {self.tolerance!r}")
        if self.foundation_stiffness is not None:
            if not _number("obstacle.foundation_stiffness", self.foundation_stiffness) > 0.0:
                raise InputError(
                    "obstacle.foundation_stiffness (Winkler modulus) must be > 0 N/m^3, got "
                    f"{self.foundation_stiffness!r}; leave it out for a rigid obstacle"
                )
            object.__setattr__(self, "foundation_stiffness", float(self.foundation_stiffness))
        if self.side == "both" and self.foundation_stiffness is None:
            raise InputError(
                'obstacle.side = "both": a rigid obstacle on both sides of the plate is a '
                "bilateral support (w = 0 in the zone), not an obstacle; give an edge its "
                '[edges.NAME] support (e.g. support = "simply_supported"), or one side '
                '("above" or "below"); "both" is for a foundation (foundation_stiffness)'
            )
        _choice("obstacle.side", self.side, SIDES)
        gap = _number("obstacle.gap", self.gap)
        if not gap >= 0.0:
            raise InputError(f"obstacle.gap must be >= 0 m, got {gap!r}")
        if gap and self.foundation_stiffness is not None:
            raise InputError(
                "obstacle.gap: a gap is modelled for rigid obstacles only, not for a "
                "foundation (foundation_stiffness)"
            )
        object.__setattr__(self, "gap", gap)

    @property
    def sign(self) -> float:
        """+1 for an obstacle above (w <= 0 admissible), -1 below (w >= 0), 0 for both."""
        return {"above": 1.0, "below": -1.0}.get(self.side, 0.0)

    @property
    def kind(self) -> str:
        """Kind: "rigid", "tensionless" (one-sided foundation) or "bilateral" (foundation)."""
        if self.foundation_stiffness is None:
            return "rigid"
        return "bilateral" if self.side == "both" else "tensionless"

    def describe(self) -> str:
        """Short human-readable description of the zone."""
        if isinstance(self.zone, str):
            return "whole plate"
        if isinstance(self.zone, Polygon):
            return f"polygon of {len(self.zone.vertices)} vertices"
        if isinstance(self.zone, Circle):
            (cx, cy), r = self.zone.center, self.zone.radius
            return f"circle about ({cx:g}, {cy:g}) of radius {r:g}"
        if callable(self.zone):
            return f"predicate {getattr(self.zone, '__name__', 'zone')}"
        (x0, x1), (y0, y1) = self.zone
        return f"[{x0:g}, {x1:g}] x [{y0:g}, {y1:g}]"

    def contains(self, x: npt.NDArray[np.float64], size: float) -> npt.NDArray[np.bool_]:
        """Mask of the points ``x`` (shape (3, n)) in the closed zone.

        Args:
            x: Point coordinates, shape (3, n).
            size: Plate size, scales the default tolerance.
        """
        if isinstance(self.zone, str):
            return np.ones(x.shape[1], dtype=bool)
        tol = 1e-8 * size if self.tolerance is None else self.tolerance
        if isinstance(self.zone, Polygon):
            return points_in_polygon(x[:2].T, self.zone.vertices, tol)
        if isinstance(self.zone, Circle):
            return points_in_circle(x[:2].T, self.zone.center, self.zone.radius, tol)
        if callable(self.zone):
            return np.asarray(self.zone(x), dtype=bool)
        (x0, x1), (y0, y1) = self.zone
        return (x[0] >= x0 - tol) & (x[0] <= x1 + tol) & (x[1] >= y0 - tol) & (x[1] <= y1 + tol)

    def same_zone(self, other: ObstacleSpec) -> bool:
        """Whether ``other`` has the same zone (a predicate only when it is the same one)."""
        return self.zone is other.zone or (not callable(self.zone) and self.zone == other.zone)


Temperature = float | tuple[float, float, float]


def _temperature(name: str, value: Any) -> Temperature:
    """A temperature rise: a number (K), or [T0, dT/dx, dT/dy] (K, K/m) for a linear field."""
    if isinstance(value, list | tuple):
        if len(value) != 3:
            raise InputError(
                f"{name} must be a number (a uniform rise, K) or [T0, dT/dx, dT/dy] (the "
                f"linear field T0 + dT/dx x + dT/dy y, K and K/m), got {value!r}"
            )
        return (_number(name, value[0]), _number(name, value[1]), _number(name, value[2]))
    return _number(name, value)


def temperature_field(value: Temperature) -> tuple[float, float, float]:
    """(T0, dT/dx, dT/dy) of a temperature rise."""
    return value if isinstance(value, tuple) else (value, 0.0, 0.0)


@dataclass(frozen=True)
class LoadSpec:
    r"""The load besides the edge stresses: temperature rises, scaled and fixed.

    The prestress is :math:`N = N_{fixed} + \lambda N_{scaled}`: the scaled part is the
    edges' ``normal_stress`` and ``shear_stress`` (per unit load) with ``temperature``;
    the fixed part, applied as is, the edges' ``fixed_normal_stress`` and
    ``fixed_shear_stress`` (Pa) with ``fixed_temperature``, times ``fixed_factor``. A
    temperature rise :math:`\Delta T` gives the free thermal strain
    :math:`\alpha\Delta T I` (``[material] thermal_expansion``), which the edges'
    in-plane conditions turn into a prestress. The buckling pencil is
    :math:`(A - B_{fixed}, B_{scaled})`.

    Args:
        temperature: The rise per unit load factor: a number (K, uniform) or
            ``(T0, dTdx, dTdy)``, the linear field :math:`T_0 + T_{,x} x + T_{,y} y` (K, K/m).
        fixed_temperature: A rise applied as is, the same forms.
        fixed_factor: A factor on the whole fixed part (the fixed edge stresses and
            ``fixed_temperature``), 1 by default: a sweep over it draws an interaction
            curve with one ``--vary``; 0 switches the fixed part off.
    """

    temperature: Temperature = 0.0
    fixed_temperature: Temperature = 0.0
    fixed_factor: float = 1.0

    def __post_init__(self) -> None:
        for name in ("temperature", "fixed_temperature"):
            object.__setattr__(self, name, _temperature(f"load.{name}", getattr(self, name)))
        object.__setattr__(self, "fixed_factor", _number("load.fixed_factor", self.fixed_factor))

    @property
    def thermal(self) -> bool:
        """Whether the scaled part has a temperature rise."""
        return any(temperature_field(self.temperature))

    @property
    def fixed_thermal(self) -> bool:
        """Whether the fixed part has a temperature rise."""
        return any(temperature_field(self.fixed_temperature))


@dataclass(frozen=True)
class DesignSpec:
    r"""Design output by EN 1993-1-5 (:mod:`~unibuckle_fenicsx.design`).

    Args:
        yield_stress: :math:`f_y` (Pa), > 0.
        partial_factor: :math:`\gamma_{M1}`, > 0 (1.0, the recommended value of
            EN 1993-1-1, 6.1).
    """

    yield_stress: float
    partial_factor: float = 1.0

    def __post_init__(self) -> None:
        for name, unit in (("yield_stress", " Pa"), ("partial_factor", "")):
            value = _number(f"design.{name}", getattr(self, name))
            if not value > 0.0:
                raise InputError(f"design.{name} must be > 0{unit}, got {value!r}")
            object.__setattr__(self, name, value)


#: Kinds of point restraint: w = 0, the obstacle's cone at the point, or a spring.
POINT_KINDS = ("bilateral", "one-sided", "spring")


def _pair(name: str, value: Any) -> tuple[float, float]:
    """A pair [a, b] of finite numbers."""
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise InputError(f"{name} must be a pair [x, y] of numbers, got {value!r}")
    return (_number(name, value[0]), _number(name, value[1]))


@dataclass(frozen=True)
class PointSpec:
    r"""Point restraints: one point, or a grid of them (bolts, tie bars, studs).

    Each point acts on the mesh node nearest to it (the snap distance is reported).

    Args:
        at: One point (x, y) (m); or None for a grid.
        spacing: The grid's spacing (sx, sy) (m), > 0 (a number: the same in x and y).
        offset: A point of the grid (m); default the region's lower-left corner.
        region: The box ((xmin, xmax), (ymin, ymax)) (m) holding the grid's points (a
            degenerate side gives a line); default the plate's bounding box. Points
            outside the plate (or in a hole) are left out.
        kind: One of :data:`POINT_KINDS`: "bilateral" (w = 0), "one-sided" (the
            obstacle's cone at the point: w <= 0 with ``side`` "above", w >= 0
            "below"), "spring" (a spring of ``stiffness`` N/m to w = 0).
        stiffness: The spring's stiffness (N/m), > 0, for ``kind = "spring"`` only.
        side: "above" or "below", for ``kind = "one-sided"`` only.
    """

    at: tuple[float, float] | None = None
    spacing: tuple[float, float] | None = None
    offset: tuple[float, float] | None = None
    region: Box | None = None
    kind: str = "bilateral"
    stiffness: float | None = None
    side: str = "above"

    def __post_init__(self) -> None:
        where = "points"
        _choice(f"{where}.kind", self.kind, POINT_KINDS)
        if (self.at is None) == (self.spacing is None):
            raise InputError(
                "[[points]] needs at = [x, y] (one point) or spacing = s or [sx, sy] (a "
                "grid, with optional offset and region): exactly one of them"
            )
        if self.at is not None:
            object.__setattr__(self, "at", _pair(f"{where}.at", self.at))
            for name in ("offset", "region"):
                if getattr(self, name) is not None:
                    raise InputError(f"{where}.{name} belongs to a grid (spacing), not to at")
        else:
            spacing: Any = self.spacing
            if not isinstance(spacing, list | tuple):
                spacing = (spacing, spacing)
            pair = _pair(f"{where}.spacing", spacing)
            if min(pair) <= 0.0:
                raise InputError(f"{where}.spacing must be > 0 m, got {self.spacing!r}")
            object.__setattr__(self, "spacing", pair)
            if self.offset is not None:
                object.__setattr__(self, "offset", _pair(f"{where}.offset", self.offset))
            if self.region is not None:
                object.__setattr__(self, "region", _box(f"{where}.region", self.region))
        if self.kind == "spring":
            if self.stiffness is None or not _number(f"{where}.stiffness", self.stiffness) > 0:
                raise InputError(
                    f'{where}.stiffness: kind = "spring" needs a stiffness > 0 N/m, got '
                    f"{self.stiffness!r}"
                )
            object.__setattr__(self, "stiffness", float(self.stiffness))
        elif self.stiffness is not None:
            raise InputError(f'{where}.stiffness belongs to kind = "spring", not "{self.kind}"')
        _choice(f"{where}.side", self.side, ("above", "below"))
        if self.side != "above" and self.kind != "one-sided":
            raise InputError(f'{where}.side belongs to kind = "one-sided", not "{self.kind}"')

    @property
    def sign(self) -> float:
        """+1 for a one-sided point above (w <= 0 admissible), -1 below."""
        return 1.0 if self.side == "above" else -1.0

    def locations(self, plate: PlateSpec) -> npt.NDArray[np.float64]:
        """The points (n, 2) (m): ``at``, or the grid's points inside the plate.

        Raises:
            ValueError: ``at`` outside the plate, or a grid with no point in it.
        """
        size = max(plate.length, plate.width)
        tol = 1e-9 * size
        if self.at is not None:
            points = np.array([self.at])
        else:
            assert self.spacing is not None
            region = self.region if self.region is not None else tuple(zip(*plate.corners))
            offset = self.offset if self.offset is not None else (region[0][0], region[1][0])
            axes = []
            for (lo, hi), step, start in zip(region, self.spacing, offset, strict=True):
                first = math.ceil((lo - start - tol) / step)
                last = math.floor((hi - start + tol) / step)
                if last - first > 100_000:
                    raise InputError(
                        f"points.spacing {self.spacing} gives more than 100000 points per row"
                    )
                axes.append(start + step * np.arange(first, last + 1))
            gx, gy = np.meshgrid(*axes, indexing="ij")
            points = np.column_stack([gx.ravel(), gy.ravel()])
        inside = plate.contains(points, tol) if plate.file is None else np.ones(len(points), bool)
        if self.at is not None and not inside.all():
            raise InputError(f"points.at {list(self.at)} lies outside the plate (or in a hole)")
        points = points[inside]
        if not len(points):
            raise InputError(
                f"points: the grid of spacing {list(self.spacing or ())} holds no point of "
                "the plate; check spacing, offset and region"
            )
        return points

    def describe(self) -> str:
        """Short description (for messages and the summary)."""
        what = self.kind if self.kind != "spring" else f"spring {self.stiffness:g} N/m"
        if self.kind == "one-sided":
            what += f" ({self.side})"
        if self.at is not None:
            return f"{what} at ({self.at[0]:g}, {self.at[1]:g}) m"
        assert self.spacing is not None
        return f"{what} grid of spacing {self.spacing[0]:g} x {self.spacing[1]:g} m"


@dataclass(frozen=True)
class SolverSpec:
    """Solver options.

    Args:
        method: One of :data:`METHODS`; "auto" enumerates (with ``until_proven``) when
            the candidate count 2^i is at most ``max_candidates`` and the estimated
            enumeration time is within ``enumeration_budget_s``; otherwise it runs the
            nested interior-point method on thin plates (thickness below
            :data:`~unibuckle_fenicsx.algorithms.chain.THIN_PLATE` of the shorter side)
            and the multilevel active-set method on the others.
        tau: Relative feasibility/contact tolerance (README, "The problem"), in (0, 1e-2].
        eps_tol: SLEPc convergence tolerance, in (0, 1e-4].
        max_candidates: Largest candidate count the enumeration accepts, >= 1.
        enumeration_budget_s: "auto" enumerates only if the estimate (2^i times the
            time of one eigen solve) is at most this many seconds, > 0.
        complete: Enumerate every subset instead of stopping after the first
            feasible size p (to check the paper's monotonicity).
        until_proven: Enumerate past the paper's stopping size p* until the
            interlacing bound proves the best feasible set optimal (exact; the
            paper's rule is not, see the README).
        max_iterations: Active-set iterates per seed and mesh level, >= 1 (the feasible
            descent, the chain's last link, may use ten times as many solves).
        bound_budget: Eigen solves allowed for the active set's lattice lower bound,
            >= 0 (it runs when the budget covers the i singletons).
        certify: Verify the result's global optimality (README, "Proving the global
            minimum"); off for speed studies.
        bracket: Also try the low-rank verified bracket when two or more pencil
            eigenvalues lie below the load (README, "Proving the global minimum"): tens of
            free solves' time on a thin plate of 90x30 cells, so off by default.
        penalty: Penalty stiffness rho for ``method="penalty"`` (relative to the
            largest diagonal entry of A), > 0.
        prestress_degree: Lagrange degree of the in-plane displacement, >= 1.
        shear: "mitc" (MacNeal/MITC4, locking-free) or "full" (plain full
            integration, locks; for comparison only).
    """

    method: str = "auto"
    tau: float = 1e-8
    eps_tol: float = 1e-10
    max_candidates: int = 100_000
    enumeration_budget_s: float = 60.0
    complete: bool = False
    until_proven: bool = False
    max_iterations: int = 100
    bound_budget: int = 64
    certify: bool = True
    bracket: bool = False
    penalty: float = 1e3
    prestress_degree: int = 1
    shear: str = "mitc"

    def __post_init__(self) -> None:
        _choice("solver.method", self.method, METHODS)
        _choice("solver.shear", self.shear, ("mitc", "full"))
        if not 0.0 < _number("solver.tau", self.tau) <= 1e-2:
            raise InputError(f"solver.tau must lie in (0, 1e-2], got {self.tau!r}")
        if not 0.0 < _number("solver.eps_tol", self.eps_tol) <= 1e-4:
            raise InputError(f"solver.eps_tol must lie in (0, 1e-4], got {self.eps_tol!r}")
        if not _number("solver.enumeration_budget_s", self.enumeration_budget_s) > 0.0:
            raise InputError(
                f"solver.enumeration_budget_s must be > 0 s, got {self.enumeration_budget_s!r}"
            )
        if not _number("solver.penalty", self.penalty) > 0.0:
            raise InputError(f"solver.penalty must be > 0, got {self.penalty!r}")
        for name, minimum in (
            ("max_candidates", 1),
            ("max_iterations", 1),
            ("bound_budget", 0),
            ("prestress_degree", 1),
        ):
            object.__setattr__(self, name, _integer(f"solver.{name}", getattr(self, name), minimum))
        for name in ("complete", "until_proven", "certify", "bracket"):
            object.__setattr__(self, name, _boolean(f"solver.{name}", getattr(self, name)))
        for name in ("tau", "eps_tol", "enumeration_budget_s", "penalty"):
            object.__setattr__(self, name, float(getattr(self, name)))


@dataclass(frozen=True)
class ProblemSpec:
    """A complete unilateral buckling problem (in SI units).

    Args:
        name: Label used in output.
        plate: Geometry, thickness and edge conditions.
        material: Elastic constants.
        mesh: Mesh resolution.
        obstacle: Obstacle zone, or ``None`` for the free (bilateral) plate.
        solver: Solver options.
        units: The unit system results are printed in (one of :data:`UNITS`; the
            numbers here are SI whatever it is).
        obstacles: Several obstacles (the file's ``[[obstacles]]`` tables), instead of
            ``obstacle``; their constrained nodes are the union of their zones'.
        points: Point restraints (the file's ``[[points]]`` tables).
        load: Temperature rises, scaled and fixed (the ``[load]`` table).
        design: The EN 1993-1-5 design output's data (``[design]``), or None.
    """

    name: str = "plate"
    plate: PlateSpec = field(default_factory=PlateSpec)
    material: Material = field(default_factory=lambda: Material(E=1.0e9, nu=0.3))
    mesh: MeshSpec = field(default_factory=MeshSpec)
    obstacle: ObstacleSpec | None = None
    solver: SolverSpec = field(default_factory=SolverSpec)
    units: str = "SI"
    obstacles: tuple[ObstacleSpec, ...] = ()
    points: tuple[PointSpec, ...] = ()
    load: LoadSpec = field(default_factory=LoadSpec)
    design: DesignSpec | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise InputError(f"name must be a string, got {self.name!r}")
        _choice("units", self.units, tuple(UNITS))
        object.__setattr__(self, "obstacles", tuple(self.obstacles))
        plate = self.plate
        if plate.meshed_by_gmsh and self.mesh.size is None:
            if plate.file is None:
                raise InputError(
                    "mesh.size: a plate meshed by gmsh (outline or holes) needs [mesh] size = "
                    "h, the characteristic cell size (m)"
                )
        if plate.file is not None and plate.file.lower().endswith(".msh") and self.mesh.size:
            raise InputError("mesh.size: a .msh file is meshed already; leave size out")
        if plate.meshed_by_gmsh:
            check_features(plate, self.mesh.size)
        if self.obstacle is not None and self.obstacles:
            raise InputError("give one [obstacle] table or several [[obstacles]] tables, not both")
        for k, o in enumerate(self.obstacles):
            if not isinstance(o, ObstacleSpec):
                raise InputError(f"obstacles[{k}] must be an ObstacleSpec, got {o!r}")
        if self.material.plies:
            total = sum(ply.thickness for ply in self.material.plies)
            if not math.isclose(plate.thickness, total, rel_tol=1e-9):
                raise InputError(
                    f"plate.thickness = {plate.thickness!r} m differs from the plies' total "
                    f"{total!r} m"
                )
        self._check_load()
        self._check_design()
        object.__setattr__(self, "points", tuple(self.points))
        for k, point in enumerate(self.points):
            if not isinstance(point, PointSpec):
                raise InputError(f"points[{k}] must be a PointSpec, got {point!r}")
            if plate.file is not None:
                continue  # the plate's extent is known once the file is meshed
            try:
                point.locations(plate)
            except ValueError as err:
                raise InputError(f"points[{k}]{str(err)[len('points') :]}") from None
        found = self.all_obstacles
        check_supports(self)
        kinds = {o.kind for o in found}
        if self.one_sided_points and "tensionless" in kinds:
            raise InputError(
                'points: one-sided points (kind = "one-sided") join a rigid obstacle\'s cone; '
                'with a tensionless foundation give them a stiffness (kind = "spring") or '
                "make the foundation rigid"
            )
        if {"rigid", "tensionless"} <= kinds:
            raise InputError(
                "rigid obstacles and tensionless foundations in one problem are not "
                "supported: give every one-sided obstacle a foundation_stiffness, or none "
                '(a bilateral foundation, side = "both", goes with either)'
            )
        if "tensionless" in kinds and self.solver.method != "auto":
            raise InputError(
                f'solver.method = "{self.solver.method}": a tensionless foundation is solved '
                'by its own spring-set iteration; use method = "auto"'
            )
        for j, first in enumerate(found):
            for k in range(j + 1, len(found)):
                second = found[k]
                if not (
                    first.same_zone(second) and {first.side, second.side} == {"above", "below"}
                ):
                    continue
                label = f"{self.obstacle_label(j)} and {self.obstacle_label(k)}"
                if first.kind == second.kind == "tensionless":
                    raise InputError(
                        f"{label} give the same foundation zone on both sides of the plate: "
                        'write it once with side = "both" (a bilateral foundation)'
                    )
                raise InputError(
                    f"{label} give the same zone on both sides of the plate: that is a "
                    "bilateral support (w = 0 there), not an obstacle; give an edge its "
                    '[edges.NAME] support (e.g. support = "simply_supported"), or keep one '
                    "side"
                )

    def _check_load(self) -> None:
        """Temperatures need a thermal expansion and an edge held in its plane."""
        load = self.load
        if (load.thermal or load.fixed_thermal) and not self.material.thermal_expansion:
            which = "load.temperature" if load.thermal else "load.fixed_temperature"
            raise InputError(
                f"{which}: a temperature rise needs [material] thermal_expansion > 0 (1/K)"
            )
        held = any(e.inplane != "free" for e in self.plate.edges)
        for name, on in (("temperature", load.thermal), ("fixed_temperature", load.fixed_thermal)):
            if on and not held:
                raise InputError(
                    f"load.{name}: the temperature rise leaves the plate stress-free (a "
                    "uniform or linear rise expands a plate free in its plane without "
                    'stress): hold an edge in its plane (inplane = "clamped" or "roller")'
                )

    def _check_design(self) -> None:
        """The design output needs a compressive normal edge stress (its sigma_cr)."""
        if self.design is None:
            return
        if not isinstance(self.design, DesignSpec):
            raise InputError(f"design must be a DesignSpec, got {self.design!r}")
        compressed = any(
            min(*stress_ends(e.normal_stress), *stress_ends(e.fixed_normal_stress)) < 0.0
            for e in self.plate.edges
        )
        if not compressed:
            raise InputError(
                "design: the EN 1993-1-5 output takes sigma_cr as a compressive normal edge "
                "stress, and this load has none (give a loaded edge normal_stress < 0)"
            )

    def check_scaled_load(self) -> None:
        """Refuse a problem with nothing for lambda to scale (a fixed part alone)."""
        if not self.load.thermal and not any(e.loaded for e in self.plate.edges):
            raise InputError(
                "no load to scale: give an edge a non-zero normal_stress or shear_stress (per "
                "unit load), or [load] temperature (a rise per unit load factor)"
                + (
                    "; the fixed part (fixed_normal_stress, fixed_shear_stress, "
                    "fixed_temperature) is applied as is, not scaled"
                    if self.has_fixed_load
                    else ""
                )
            )

    @property
    def has_fixed_load(self) -> bool:
        """Whether the load has a fixed part (edge stresses or a temperature rise)."""
        return bool(self.load.fixed_factor) and (self.plate.fixed_loaded or self.load.fixed_thermal)

    @property
    def one_sided_points(self) -> tuple[PointSpec, ...]:
        """The point restraints that join the obstacle's cone."""
        return tuple(p for p in self.points if p.kind == "one-sided")

    @property
    def unilateral_obstacles(self) -> tuple[ObstacleSpec, ...]:
        """The one-sided obstacles (rigid or tensionless foundations): the contact nodes'.

        Without those with a gap: an infinitesimal buckle does not reach them.
        """
        return tuple(o for o in self.all_obstacles if o.kind != "bilateral" and not o.gap)

    @property
    def gapped_obstacles(self) -> tuple[ObstacleSpec, ...]:
        """The obstacles with a gap (the nonlinear analysis' only)."""
        return tuple(o for o in self.all_obstacles if o.gap)

    @property
    def bilateral_foundations(self) -> tuple[ObstacleSpec, ...]:
        """The bilateral foundations (``side = "both"``): springs added to the stiffness."""
        return tuple(o for o in self.all_obstacles if o.kind == "bilateral")

    @property
    def tensionless(self) -> bool:
        """Whether the one-sided obstacles are tensionless foundations."""
        return any(o.kind == "tensionless" for o in self.all_obstacles)

    @property
    def all_obstacles(self) -> tuple[ObstacleSpec, ...]:
        """Every obstacle: ``(obstacle,)`` or ``obstacles`` (empty for the free plate)."""
        return (self.obstacle,) if self.obstacle is not None else self.obstacles

    def obstacle_label(self, k: int) -> str:
        """How the file names obstacle k of :attr:`all_obstacles` (for messages)."""
        return "obstacle" if self.obstacle is not None else f"obstacles[{k}]"

    def without_obstacles(self) -> ProblemSpec:
        """Copy of the free plate (no obstacle)."""
        return replace(self, obstacle=None, obstacles=())

    def with_mesh(self, nx: int, ny: int) -> ProblemSpec:
        """Copy with another mesh resolution (the structured rectangle only)."""
        if self.plate.meshed_by_gmsh:
            raise InputError(
                "nx, ny (--nx, --ny) set the structured rectangle's cells; a plate meshed by "
                "gmsh takes [mesh] size = h"
            )
        return replace(self, mesh=MeshSpec(nx, ny))

    def with_solver(self, **changes: Any) -> ProblemSpec:
        """Copy with changed solver options."""
        return replace(self, solver=replace(self.solver, **changes))

    @property
    def stress_unit(self) -> tuple[float, str]:
        """(pascals per unit, name) of the stress unit results are printed in."""
        _, stress, name = UNITS[self.units]
        return stress, name


def _take(table: Mapping[str, Any], allowed: tuple[str, ...], where: str) -> dict[str, Any]:
    if not isinstance(table, Mapping):
        raise InputError(f"[{where}] must be a table, got {table!r}")
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        raise InputError(f"unknown key(s) {unknown} in [{where}]; allowed: {list(allowed)}")
    return dict(table)


def _names(cls: type) -> tuple[str, ...]:
    return tuple(f.name for f in fields(cls))


def _scaled(value: Any, factor: float, name: str) -> Any:
    """``value`` (a number or nested lists of numbers) times ``factor``, types checked."""
    if isinstance(value, list | tuple):
        return [_scaled(v, factor, name) for v in value]
    return _number(name, value) * factor


#: Keys converted to SI by a file's ``units``: (table, key) -> powers of (length, stress).
_DIMENSIONS: dict[tuple[str, str], tuple[int, int]] = {
    ("plate", "corners"): (1, 0),
    ("plate", "thickness"): (1, 0),
    ("material", "E"): (0, 1),
    ("material", "membrane_voigt"): (1, 1),  # N/m = Pa m
    ("material", "bending_voigt"): (3, 1),  # N m = Pa m^3
    ("mesh", "size"): (1, 0),
    ("design", "yield_stress"): (0, 1),
}


def _to_si(top: dict[str, Any], units: str, inverse: bool = False) -> dict[str, Any]:
    """Convert the dimensional values of a TOML-shaped mapping between ``units`` and SI.

    From ``units`` to SI, or from SI to ``units`` with ``inverse``.
    """
    length, stress, _ = UNITS[units]
    if units == "SI":
        return top
    sign = -1 if inverse else 1
    out = {k: dict(v) if isinstance(v, Mapping) else v for k, v in top.items()}
    for (table, key), (pl, ps) in _DIMENSIONS.items():
        if isinstance(out.get(table), dict) and key in out[table]:
            factor = (length**pl * stress**ps) ** sign
            out[table][key] = _scaled(out[table][key], factor, f"{table}.{key}")
    load = out.get("load")
    if isinstance(load, dict):
        for key in ("temperature", "fixed_temperature"):
            value = load.get(key)
            if isinstance(value, list) and len(value) == 3:  # K, K/m, K/m
                load[key] = [value[0], *_scaled(value[1:], length**-sign, f"load.{key}")]
    material = out.get("material")
    if isinstance(material, dict) and isinstance(material.get("plies"), list):
        material["plies"] = [
            {
                k: _scaled(
                    v, length**sign if k == "thickness" else stress**sign, f"material.plies.{k}"
                )
                if k in ("thickness", "E1", "E2", "G12", "G13", "G23")
                else v
                for k, v in ply.items()
            }
            if isinstance(ply, Mapping)
            else ply
            for ply in material["plies"]
        ]
    edges = out.get("edges")
    if isinstance(edges, dict):
        out["edges"] = {
            name: _edge_to_si(table, f"edges.{name}", length, stress, sign)
            if isinstance(table, Mapping)
            else table
            for name, table in edges.items()
        }
    plate = out.get("plate")
    if isinstance(plate, dict):
        if "outline" in plate:
            plate["outline"] = _scaled(plate["outline"], length**sign, "plate.outline")
        if isinstance(plate.get("holes"), list):
            plate["holes"] = [
                {
                    k: _scaled(v, length**sign, f"plate.holes[{j}].{k}")
                    if k in ("center", "radius", "outline")
                    else v
                    for k, v in hole.items()
                }
                if isinstance(hole, Mapping)
                else hole
                for j, hole in enumerate(plate["holes"])
            ]
    if isinstance(out.get("obstacle"), dict):
        out["obstacle"] = _obstacle_to_si(out["obstacle"], "obstacle", length**sign, stress**sign)
    for key, convert in (("points", _point_to_si), ("obstacles", _obstacle_to_si)):
        if isinstance(out.get(key), list):
            out[key] = [
                convert(t, f"{key}[{k}]", length**sign, stress**sign)
                if isinstance(t, Mapping)
                else t
                for k, t in enumerate(out[key])
            ]
    return out


#: Keys of an ``[edges.NAME]`` table converted by a file's ``units``: key -> powers of
#: (length, stress).
_EDGE_DIMENSIONS: dict[str, tuple[int, int]] = {
    "translational_stiffness": (0, 1),  # N/m^2 = Pa; rotational_stiffness is N in both
    "fixed_normal_stress": (0, 1),  # Pa (normal_stress is per unit load: no unit)
    "fixed_shear_stress": (0, 1),
}


def _edge_to_si(
    table: Mapping[str, Any], where: str, length: float, stress: float, sign: int
) -> dict[str, Any]:
    """An edge table with its dimensional values converted (see :func:`_to_si`)."""
    out = dict(table)
    for key, (pl, ps) in _EDGE_DIMENSIONS.items():
        if key in out:
            out[key] = _scaled(out[key], (length**pl * stress**ps) ** sign, f"{where}.{key}")
    return out


def _point_to_si(
    table: Mapping[str, Any], where: str, length: float, stress: float
) -> dict[str, Any]:
    """A points table with its lengths times ``length``, its stiffness (N/m) converted."""
    out = dict(table)
    for key in ("at", "spacing", "offset", "region"):
        if key in out:
            out[key] = _scaled(out[key], length, f"{where}.{key}")
    if "stiffness" in out:  # N/m = Pa m
        out["stiffness"] = _scaled(out["stiffness"], stress * length, f"{where}.stiffness")
    return out


def _obstacle_to_si(
    table: Mapping[str, Any], where: str, length: float, stress: float
) -> dict[str, Any]:
    """An obstacle table with its lengths times ``length`` and stresses times ``stress``."""
    out = dict(table)
    for key in ("polygon", "tolerance", "gap"):
        if key in out:
            out[key] = _scaled(out[key], length, f"{where}.{key}")
    if "foundation_stiffness" in out:  # N/m^3 = Pa/m
        out["foundation_stiffness"] = _scaled(
            out["foundation_stiffness"], stress / length, f"{where}.foundation_stiffness"
        )
    if isinstance(out.get("zone"), list):
        out["zone"] = _scaled(out["zone"], length, f"{where}.zone")
    if isinstance(out.get("circle"), Mapping):
        circle = dict(out["circle"])
        for key in ("center", "radius"):
            if key in circle:
                circle[key] = _scaled(circle[key], length, f"{where}.circle.{key}")
        out["circle"] = circle
    return out


#: Keys of an ``[obstacle]`` or ``[[obstacles]]`` table.
OBSTACLE_KEYS = ("zone", "polygon", "circle", "side", "foundation_stiffness", "tolerance", "gap")


def _holes(tables: Any) -> tuple[Circle | Polygon, ...]:
    """``[[plate.holes]]`` tables: center and radius (a circle) or outline (a polygon)."""
    if not isinstance(tables, list):
        raise InputError(f"plate.holes must be a list of tables ([[plate.holes]]), got {tables!r}")
    holes: list[Circle | Polygon] = []
    for k, table in enumerate(tables):
        where = f"plate.holes[{k}]"
        kw = _take(table, ("center", "radius", "outline"), where)
        if set(kw) == {"outline"}:
            holes.append(Polygon(_polygon(f"{where}.outline", kw["outline"])))
        elif set(kw) == {"center", "radius"}:
            try:
                holes.append(Circle(kw["center"], kw["radius"]))
            except ValueError as err:
                # Circle's messages name circle.center/radius; the file's keys are these.
                raise InputError(f"{where}.{str(err).removeprefix('circle.')}") from None
        else:
            raise InputError(
                f"[{where}] needs center = [x, y] and radius = r (a circle), or outline = "
                f"[[x, y], ...] (a polygon); got {sorted(kw)}"
            )
    return tuple(holes)


def _obstacle_from_table(table: Any, where: str) -> ObstacleSpec:
    """An :class:`ObstacleSpec` from its table; messages name ``where`` (e.g. obstacles[1])."""
    kw = _take(table, OBSTACLE_KEYS, where)
    given = [key for key in ("zone", "polygon", "circle") if key in kw]
    if len(given) != 1:
        raise InputError(
            f'[{where}] needs zone = "all" (the whole plate) or [[xmin, xmax], [ymin, ymax]], '
            "or polygon = [[x, y], ...], or circle = {center = [x, y], radius = r}: exactly "
            f"one of them; got {given or 'none'}"
        )
    try:
        if "polygon" in kw:
            kw["zone"] = Polygon(_polygon(f"{where}.polygon", kw.pop("polygon")))
        elif "circle" in kw:
            circle = _take(kw.pop("circle"), ("center", "radius"), f"{where}.circle")
            if set(circle) != {"center", "radius"}:
                raise InputError(f"{where}.circle needs center = [x, y] and radius = r")
            kw["zone"] = Circle(**circle)
        return ObstacleSpec(**kw)
    except ValueError as err:
        message = str(err)
        if message.startswith("obstacle."):
            message = where + message[len("obstacle") :]
        elif message.startswith("circle."):
            message = f"{where}.{message}"
        raise InputError(message) from None


def _plate_table(plate: PlateSpec) -> dict[str, Any]:
    """The file form of the plate."""
    out: dict[str, Any] = {"thickness": plate.thickness}
    if plate.file is not None:
        out["file"] = plate.file
    elif plate.outline is not None:
        out["outline"] = [list(v) for v in plate.outline]
    else:
        out["corners"] = [list(c) for c in plate.corners]
    holes: list[dict[str, Any]] = []
    for hole in plate.holes:
        if isinstance(hole, Circle):
            holes.append({"center": list(hole.center), "radius": hole.radius})
        else:
            holes.append({"outline": [list(v) for v in hole.vertices]})
    if holes:
        out["holes"] = holes
    return out


def _obstacle_table(obstacle: ObstacleSpec) -> dict[str, Any]:
    """The file form of an obstacle (every key with the value used)."""
    zone = obstacle.zone
    out: dict[str, Any] = {}
    if isinstance(zone, Polygon):
        out["polygon"] = [list(v) for v in zone.vertices]
    elif isinstance(zone, Circle):
        out["circle"] = {"center": list(zone.center), "radius": zone.radius}
    elif callable(zone):
        raise InputError("problem_to_dict: a predicate obstacle zone cannot be written")
    else:
        out["zone"] = zone if isinstance(zone, str) else [list(z) for z in zone]
    out["side"] = obstacle.side
    if obstacle.foundation_stiffness is not None:
        out["foundation_stiffness"] = obstacle.foundation_stiffness
    if obstacle.tolerance is not None:
        out["tolerance"] = obstacle.tolerance
    out["gap"] = obstacle.gap
    return out


def problem_from_dict(data: Mapping[str, Any], name: str = "plate") -> ProblemSpec:
    """Build a :class:`ProblemSpec` from a TOML-shaped mapping (schema: README).

    Tables: ``[plate]`` (corners, or outline, or file; thickness; ``[[plate.holes]]``
    with center and radius, or outline), ``[material]`` (E, nu, shear_correction,
    membrane_voigt, bending_voigt), ``[edges.<name>]`` (support, inplane,
    normal_stress, shear_stress, segments), ``[mesh]`` (nx, ny; or size, a cell size),
    ``[obstacle]`` (zone, polygon or circle, side, foundation_stiffness, tolerance;
    absent = free plate) or several ``[[obstacles]]``
    with the same keys, ``[solver]`` (the :class:`SolverSpec` fields);
    top-level ``name`` and ``units``. Unknown tables or keys raise ``ValueError``.

    Missing values take the paper's, with one exception for the load: if any edge table
    gives ``normal_stress``, ``shear_stress`` or a fixed stress, or the file has a
    ``[load]`` table, the edges that give no stress carry no load (the paper's unit
    compression of the short edges applies only to a file that sets no load at all).
    """
    top = _take(
        data,
        (
            "name",
            "units",
            "plate",
            "material",
            "edges",
            "mesh",
            "obstacle",
            "obstacles",
            "points",
            "load",
            "design",
            "solver",
        ),
        "top",
    )
    units = _choice("units", top.get("units", "SI"), tuple(UNITS))
    top = _to_si(top, units)
    plate_kw = _take(
        top.get("plate", {}), ("corners", "thickness", "outline", "holes", "file"), "plate"
    )
    gmsh_plate = any(key in plate_kw for key in ("outline", "file"))
    if gmsh_plate and "corners" in plate_kw:
        raise InputError(
            "[plate]: give corners (a rectangle), or outline (a polygon) or file (a gmsh "
            "file), not both"
        )
    if "holes" in plate_kw:
        plate_kw["holes"] = _holes(plate_kw["holes"])
    given = top.get("edges", {})
    if gmsh_plate:  # a file's or an outline's part names are checked by PlateSpec
        names = tuple(given) if isinstance(given, Mapping) else ()
    else:
        names = (*EDGE_NAMES, HOLES) if "holes" in plate_kw else EDGE_NAMES
    edge_tables = _take(given, names, "edges")
    edges = {} if gmsh_plate else {e.name: e for e in paper_edges()}
    load_keys = ("normal_stress", "shear_stress", "fixed_normal_stress", "fixed_shear_stress")
    loads_given = any(
        key in table for table in edge_tables.values() if isinstance(table, Mapping)
        for key in load_keys
    ) or (isinstance(top.get("load"), Mapping) and bool(top["load"]))  # fmt: skip
    if loads_given:
        edges = {n: replace(e, normal_stress=0.0, shear_stress=0.0) for n, e in edges.items()}
    edge_keys = (
        "support",
        "inplane",
        "normal_stress",
        "shear_stress",
        "segments",
        "rotational_stiffness",
        "translational_stiffness",
        "fixed_normal_stress",
        "fixed_shear_stress",
    )
    for edge_name, edge_table in edge_tables.items():
        kw = _take(edge_table, edge_keys, f"edges.{edge_name}")
        edge = edges.get(edge_name, EdgeSpec(edge_name))
        edges[edge_name] = replace(edge, **kw)
    plate = PlateSpec(**plate_kw, edges=tuple(edges.values()))
    material = _material(top.get("material", {"E": 1.0e9, "nu": 0.3}))
    if material.plies:
        total = sum(ply.thickness for ply in material.plies)
        if "thickness" not in plate_kw:
            plate = replace(plate, thickness=total)
        elif not math.isclose(plate.thickness, total, rel_tol=1e-9):
            raise InputError(
                f"plate.thickness = {plate.thickness!r} m differs from the plies' total "
                f"{total!r} m: leave plate.thickness out for a laminate (it is the plies')"
            )
    mesh_kw = _take(top.get("mesh", {}), _names(MeshSpec), "mesh")
    if plate.meshed_by_gmsh:
        if "nx" in mesh_kw or "ny" in mesh_kw:
            raise InputError(
                "[mesh]: a plate meshed by gmsh (outline, holes or file) takes size = h (the "
                "characteristic cell size), not nx and ny"
            )
    elif "size" in mesh_kw:
        if "nx" in mesh_kw or "ny" in mesh_kw:
            raise InputError("[mesh]: give size (a cell size) or nx and ny, not both")
        mesh_kw["nx"], mesh_kw["ny"] = MeshSpec.cells_for(
            plate.length, plate.width, mesh_kw["size"]
        )
    mesh = MeshSpec(**mesh_kw)
    obstacle = None
    if "obstacle" in top:
        obstacle = _obstacle_from_table(top["obstacle"], "obstacle")
    obstacles: list[ObstacleSpec] = []
    if "obstacles" in top:
        tables = top["obstacles"]
        if not isinstance(tables, list) or not tables:
            raise InputError(
                "obstacles must be a list of tables ([[obstacles]] in TOML), at least one, "
                f"got {tables!r}"
            )
        if obstacle is not None:
            raise InputError("give one [obstacle] table or several [[obstacles]] tables, not both")
        obstacles = [_obstacle_from_table(t, f"obstacles[{k}]") for k, t in enumerate(tables)]
    points = _points(top["points"]) if "points" in top else ()
    load = LoadSpec(**_take(top.get("load", {}), _names(LoadSpec), "load"))
    design = None
    if "design" in top:
        design_kw = _take(top["design"], _names(DesignSpec), "design")
        if "yield_stress" not in design_kw:
            raise InputError("[design] needs yield_stress (f_y)")
        design = DesignSpec(**design_kw)
    solver = SolverSpec(**_take(top.get("solver", {}), _names(SolverSpec), "solver"))
    label = top.get("name", name)
    if not isinstance(label, str):
        raise InputError(f"name must be a string, got {label!r}")
    return ProblemSpec(
        name=label,
        plate=plate,
        material=material,
        mesh=mesh,
        obstacle=obstacle,
        solver=solver,
        units=units,
        obstacles=tuple(obstacles),
        points=points,
        load=load,
        design=design,
    )


#: Keys of a ``[[material.plies]]`` table.
PLY_KEYS = ("thickness", "angle", "E1", "E2", "G12", "nu12", "G13", "G23")


def _material(table: Any) -> Material:
    """``[material]``: E and nu, or ``[[material.plies]]`` (a laminate)."""
    kw = _take(table, _names(Material), "material")
    if "plies" not in kw:
        for key in ("E", "nu"):
            if key not in kw:
                raise InputError(f"[material] needs {key!r} (or [[material.plies]])")
        return Material(**kw)
    other = sorted(set(kw) - {"plies", "shear_correction", "thermal_expansion"})
    if other:
        raise InputError(
            f"[material] with plies takes shear_correction only besides them, not {other}: "
            "a laminate's stiffness (and its E_x, nu_xy) comes from its plies"
        )
    tables = kw.pop("plies")
    if not isinstance(tables, list) or not tables:
        raise InputError(
            "material.plies must be a list of tables ([[material.plies]] in TOML), at least "
            f"one, got {tables!r}"
        )
    plies = []
    for k, ply in enumerate(tables):
        where = f"material.plies[{k}]"
        ply_kw = _take(ply, PLY_KEYS, where)
        missing = [key for key in PLY_KEYS if key not in ply_kw]
        if missing:
            raise InputError(f"[{where}] needs {missing} (keys: {list(PLY_KEYS)})")
        try:
            plies.append(Ply(**ply_kw))
        except ValueError as err:
            raise InputError(str(err).replace("material.plies.", f"{where}.")) from None
    if kw.pop("thermal_expansion", 0.0):
        Material(E=1.0, nu=0.0, thermal_expansion=1.0, plies=tuple(plies))  # raises
    return Material.from_plies(plies, **kw)


def _points(tables: Any) -> tuple[PointSpec, ...]:
    """``[[points]]`` tables; messages name ``points[k]``."""
    if not isinstance(tables, list) or not tables:
        raise InputError(
            f"points must be a list of tables ([[points]] in TOML), at least one, got {tables!r}"
        )
    out = []
    for k, table in enumerate(tables):
        kw = _take(table, _names(PointSpec), f"points[{k}]")
        try:
            out.append(PointSpec(**kw))
        except ValueError as err:
            message = str(err)
            if message.startswith("points"):
                message = f"points[{k}]" + message[len("points") :]
            raise InputError(message) from None
    return tuple(out)


def _material_table(material: Material) -> dict[str, Any]:
    """The file form of the material (a laminate: its plies, not E and nu)."""
    if material.plies:
        return {
            "shear_correction": material.shear_correction,
            "plies": [dict(vars(ply)) for ply in material.plies],
            "thermal_expansion": material.thermal_expansion,
        }
    out: dict[str, Any] = {
        k: v for k, v in vars(material).items() if v is not None and k != "plies"
    }
    for key in ("membrane_voigt", "bending_voigt"):
        if key in out:
            out[key] = [list(row) for row in out[key]]
    return out


def _point_table(point: PointSpec) -> dict[str, Any]:
    """The file form of a point restraint (every key with the value used)."""
    out: dict[str, Any] = {"kind": point.kind}
    if point.at is not None:
        out["at"] = list(point.at)
    else:
        assert point.spacing is not None
        sx, sy = point.spacing
        out["spacing"] = sx if sx == sy else [sx, sy]
        if point.offset is not None:
            out["offset"] = list(point.offset)
        if point.region is not None:
            out["region"] = [list(r) for r in point.region]
    if point.stiffness is not None:
        out["stiffness"] = point.stiffness
    if point.kind == "one-sided":
        out["side"] = point.side
    return out


def problem_to_dict(spec: ProblemSpec, units: str = "SI") -> dict[str, Any]:
    """The TOML-shaped mapping of ``spec``, every key with the value used.

    ``problem_from_dict(problem_to_dict(spec)) == spec`` for a spec with a box or
    "all" zone on the rectangle (a predicate zone cannot be written; it raises).

    Args:
        spec: The problem.
        units: Unit system of the numbers written (one of :data:`UNITS`); the mapping's
            ``units`` key says which.
    """
    _choice("units", units, tuple(UNITS))
    plate = spec.plate
    mesh = spec.mesh
    out: dict[str, Any] = {
        "name": spec.name,
        "units": "SI",
        "plate": _plate_table(plate),
        "material": _material_table(spec.material),
        "edges": {
            e.name: {
                "support": e.support,
                "inplane": e.inplane,
                "normal_stress": stress_value(e.normal_stress),
                "shear_stress": stress_value(e.shear_stress),
                "rotational_stiffness": e.rotational_stiffness,
                "translational_stiffness": e.translational_stiffness,
                "fixed_normal_stress": stress_value(e.fixed_normal_stress),
                "fixed_shear_stress": stress_value(e.fixed_shear_stress),
            }
            | ({} if e.segments is None else {"segments": list(e.segments)})
            for e in plate.edges
        },
        "mesh": (
            {"size": mesh.size}
            if mesh.size is not None
            else {}
            if plate.meshed_by_gmsh
            else {"nx": mesh.nx, "ny": mesh.ny}
        ),
        "solver": dict(vars(spec.solver)),
    }
    if spec.obstacle is not None:
        out["obstacle"] = _obstacle_table(spec.obstacle)
    if spec.obstacles:
        out["obstacles"] = [_obstacle_table(o) for o in spec.obstacles]
    if spec.points:
        out["points"] = [_point_table(p) for p in spec.points]
    out["load"] = {
        key: list(value) if isinstance(value, tuple) else value
        for key, value in vars(spec.load).items()
    }
    if spec.design is not None:
        out["design"] = dict(vars(spec.design))
    if units != "SI":
        out = _to_si(out, units, inverse=True)
        out["units"] = units
    return out


def stress_value(value: float | tuple[float, float]) -> float | list[float]:
    """An edge stress as written in a file: a number or ``[start, end]``."""
    return list(value) if isinstance(value, tuple) else value


def load_toml(path: str | Path) -> ProblemSpec:
    """Read a :class:`ProblemSpec` from a TOML file (schema: :func:`problem_from_dict`).

    Raises:
        ValueError: The file is not UTF-8 TOML, or describes an invalid problem; the
            message names the file.
        OSError: The file cannot be read.
    """
    path = Path(path)
    try:
        data = tomllib.loads(path.read_bytes().decode("utf-8"))
    except UnicodeDecodeError as err:
        raise InputError(
            f"{path}: not a UTF-8 text file ({err.reason} at byte {err.start})"
        ) from None
    except tomllib.TOMLDecodeError as err:
        raise InputError(f"{path}: invalid TOML: {err}") from None
    plate = data.get("plate")
    if isinstance(plate, dict) and isinstance(plate.get("file"), str):
        # A gmsh file is found next to the problem file.
        plate["file"] = str((path.parent / plate["file"]).resolve())
    try:
        return problem_from_dict(data, name=path.stem)
    except ValueError as err:
        raise InputError(f"{path}: {err}") from None


def load_problem(path: str | Path) -> ProblemSpec:
    """A problem file: TOML, or the JSON of a result (its ``input``, which re-runs it).

    Raises:
        ValueError: An invalid file or problem; the message names the file.
        OSError: The file cannot be read.
    """
    path = Path(path)
    if path.suffix.lower() != ".json":
        return load_toml(path)
    try:
        data = json.loads(path.read_bytes().decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise InputError(f"{path}: not a JSON result or problem file: {err}") from None
    if isinstance(data, dict) and "input" in data:
        data = data["input"]
        if data is None:
            raise InputError(f"{path}: this result's problem has no file form (a predicate zone)")
    try:
        return problem_from_dict(data, name=path.stem)
    except ValueError as err:
        raise InputError(f"{path}: {err}") from None
