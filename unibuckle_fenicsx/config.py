r"""Problem description: frozen dataclasses and the TOML loader.

Every quantity is in SI units. The load is *one* scalar :math:`\lambda`: the
membrane traction on a loaded edge is :math:`\lambda\, t\, (\sigma_n n + \tau_s s)`
with :math:`(\sigma_n, \tau_s)` the edge stress per unit load given here, so that
:math:`\lambda` is a stress in Pa (for the paper's plate, the compressive stress).

Validation happens in ``__post_init__``: a bad value raises ``ValueError`` naming
the parameter and the allowed range before any mesh or matrix is built.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

__all__ = [
    "BENDING_SUPPORTS",
    "EDGE_NAMES",
    "INPLANE_SUPPORTS",
    "METHODS",
    "EdgeSpec",
    "Material",
    "MeshSpec",
    "ObstacleSpec",
    "PlateSpec",
    "ProblemSpec",
    "SolverSpec",
    "load_toml",
    "problem_from_dict",
]

#: Edge names of a rectangular plate, in facet-tag order 1..4.
EDGE_NAMES = ("left", "right", "bottom", "top")
#: Transverse (bending) conditions. "simply_supported" is the *hard* support of a
#: Reissner-Mindlin plate (w = 0 and tangential rotation = 0); "soft" fixes w only.
BENDING_SUPPORTS = ("simply_supported", "simply_supported_soft", "clamped", "free")
#: In-plane conditions for the prestress solve.
INPLANE_SUPPORTS = ("free", "clamped", "roller")
#: Unilateral solution methods.
METHODS = ("auto", "enumerate", "active-set", "penalty")

Predicate = Callable[[npt.NDArray[np.float64]], npt.NDArray[np.bool_]]


def _finite(name: str, value: float) -> float:
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return value


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
    """

    E: float
    nu: float
    shear_correction: float = 5.0 / 6.0
    membrane_voigt: tuple[tuple[float, ...], ...] | None = None
    bending_voigt: tuple[tuple[float, ...], ...] | None = None

    def __post_init__(self) -> None:
        if not _finite("material.E", self.E) > 0.0:
            raise ValueError(f"material.E (Young's modulus) must be > 0 Pa, got {self.E!r}")
        if not -1.0 < _finite("material.nu", self.nu) < 0.5:
            raise ValueError(
                f"material.nu (Poisson's ratio) must lie in (-1, 0.5), got {self.nu!r}"
            )
        if not _finite("material.shear_correction", self.shear_correction) > 0.0:
            raise ValueError(
                f"material.shear_correction must be > 0, got {self.shear_correction!r}"
            )
        for name in ("membrane_voigt", "bending_voigt"):
            value = getattr(self, name)
            if value is None:
                continue
            mat = np.asarray(value, dtype=float)
            if mat.shape != (3, 3) or not np.all(np.isfinite(mat)):
                raise ValueError(f"material.{name} must be a finite 3x3 matrix, got {value!r}")
            if not np.allclose(mat, mat.T, rtol=1e-12, atol=0.0):
                raise ValueError(f"material.{name} must be symmetric")
            if np.linalg.eigvalsh(mat).min() <= 0.0:
                raise ValueError(f"material.{name} must be positive definite")
            object.__setattr__(self, name, tuple(tuple(float(c) for c in row) for row in mat))


@dataclass(frozen=True)
class EdgeSpec:
    """Conditions on one edge part.

    Args:
        name: Edge name; for the rectangle one of :data:`EDGE_NAMES`.
        support: Transverse condition, one of :data:`BENDING_SUPPORTS`.
        inplane: In-plane condition for the prestress, one of :data:`INPLANE_SUPPORTS`
            ("roller" fixes the normal displacement only).
        normal_stress: Normal edge stress per unit load (Pa/Pa), tension positive;
            the paper's compressed edges have -1.
        shear_stress: Tangential edge stress per unit load (Pa/Pa), along the
            counter-clockwise tangent.
        tag: Facet tag of this edge in a user-supplied mesh; ``None`` for the
            rectangle (tags 1..4 in :data:`EDGE_NAMES` order).
    """

    name: str
    support: str = "simply_supported"
    inplane: str = "free"
    normal_stress: float = 0.0
    shear_stress: float = 0.0
    tag: int | None = None

    def __post_init__(self) -> None:
        if self.support not in BENDING_SUPPORTS:
            raise ValueError(
                f"edges.{self.name}.support must be one of {BENDING_SUPPORTS}, got {self.support!r}"
            )
        if self.inplane not in INPLANE_SUPPORTS:
            raise ValueError(
                f"edges.{self.name}.inplane must be one of {INPLANE_SUPPORTS}, got {self.inplane!r}"
            )
        _finite(f"edges.{self.name}.normal_stress", self.normal_stress)
        _finite(f"edges.{self.name}.shear_stress", self.shear_stress)

    @property
    def loaded(self) -> bool:
        r"""Whether this edge carries a traction (belongs to :math:`\gamma_1`)."""
        return self.normal_stress != 0.0 or self.shear_stress != 0.0


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

    Args:
        corners: Opposite corners ``((x0, y0), (x1, y1))`` of the rectangle (m).
        thickness: Plate thickness t = 2 epsilon (m), > 0.
        edges: One :class:`EdgeSpec` per edge part.
    """

    corners: tuple[tuple[float, float], tuple[float, float]] = ((-0.1, -0.05), (0.1, 0.05))
    thickness: float = 0.006
    edges: tuple[EdgeSpec, ...] = field(default_factory=paper_edges)

    def __post_init__(self) -> None:
        if not _finite("plate.thickness", self.thickness) > 0.0:
            raise ValueError(f"plate.thickness must be > 0 m, got {self.thickness!r}")
        try:
            (x0, y0), (x1, y1) = self.corners
            corners = (
                (_finite("plate.corners", x0), _finite("plate.corners", y0)),
                (_finite("plate.corners", x1), _finite("plate.corners", y1)),
            )
        except (TypeError, ValueError) as err:
            raise ValueError(
                f"plate.corners must be [[x0, y0], [x1, y1]] with finite numbers: {err}"
            ) from None
        object.__setattr__(self, "corners", corners)
        if not (corners[1][0] > corners[0][0] and corners[1][1] > corners[0][1]):
            raise ValueError(
                "plate.corners must satisfy x1 > x0 and y1 > y0 (a non-degenerate "
                f"rectangle), got {self.corners!r}"
            )
        object.__setattr__(self, "edges", tuple(self.edges))
        names = [e.name for e in self.edges]
        if len(set(names)) != len(names):
            raise ValueError(f"plate.edges: duplicate edge names {names}")

    @property
    def length(self) -> float:
        """Extent in x (m)."""
        return self.corners[1][0] - self.corners[0][0]

    @property
    def width(self) -> float:
        """Extent in y (m)."""
        return self.corners[1][1] - self.corners[0][1]

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
        nx: Cells along x, >= 1.
        ny: Cells along y, >= 1.
    """

    nx: int = 20
    ny: int = 20

    def __post_init__(self) -> None:
        for name in ("nx", "ny"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
                raise ValueError(f"mesh.{name} must be an integer >= 1, got {value!r}")


@dataclass(frozen=True)
class ObstacleSpec:
    """Rigid flat obstacle just above the plate over a contact zone.

    The deflection must satisfy w <= 0 at every mesh node of the closed zone.

    Args:
        zone: ``"all"`` (the whole closed plate), a box
            ``((xmin, xmax), (ymin, ymax))``, or a predicate
            ``f(x) -> bool array`` on coordinates of shape (3, n).
        tolerance: Geometric tolerance (m) for a node to count as inside a box;
            ``None`` uses 1e-8 times the plate size.
    """

    zone: Literal["all"] | tuple[tuple[float, float], tuple[float, float]] | Predicate = "all"
    tolerance: float | None = None

    def __post_init__(self) -> None:
        if isinstance(self.zone, str):
            if self.zone != "all":
                raise ValueError(
                    f'obstacle.zone must be "all", [[xmin, xmax], [ymin, ymax]] or a '
                    f"callable, got {self.zone!r}"
                )
        elif not callable(self.zone):
            try:
                (x0, x1), (y0, y1) = self.zone
                box = ((float(x0), float(x1)), (float(y0), float(y1)))
            except (TypeError, ValueError):
                raise ValueError(
                    f"obstacle.zone must be [[xmin, xmax], [ymin, ymax]], got {self.zone!r}"
                ) from None
            if not all(math.isfinite(c) for pair in box for c in pair):
                raise ValueError(f"obstacle.zone must hold finite numbers, got {self.zone!r}")
            if box[0][0] > box[0][1] or box[1][0] > box[1][1]:
                raise ValueError(
                    f"obstacle.zone needs xmin <= xmax and ymin <= ymax, got {self.zone!r}"
                )
            object.__setattr__(self, "zone", box)
        if self.tolerance is not None and not _finite("obstacle.tolerance", self.tolerance) >= 0:
            raise ValueError(f"obstacle.tolerance must be >= 0 m, got {self.tolerance!r}")

    def describe(self) -> str:
        """Short human-readable description of the zone."""
        if isinstance(self.zone, str):
            return "whole plate"
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
        if callable(self.zone):
            return np.asarray(self.zone(x), dtype=bool)
        tol = 1e-8 * size if self.tolerance is None else self.tolerance
        (x0, x1), (y0, y1) = self.zone
        return (x[0] >= x0 - tol) & (x[0] <= x1 + tol) & (x[1] >= y0 - tol) & (x[1] <= y1 + tol)


@dataclass(frozen=True)
class SolverSpec:
    """Solver options.

    Args:
        method: One of :data:`METHODS`; "auto" enumerates (with ``until_proven``) when
            the candidate count 2^i is at most ``max_candidates`` and uses the
            active-set method otherwise.
        tau: Relative feasibility/contact tolerance (README, "The problem"), in (0, 1e-2].
        eps_tol: SLEPc convergence tolerance, in (0, 1e-4].
        max_candidates: Largest candidate count the enumeration accepts, >= 1.
        complete: Enumerate every subset instead of stopping after the first
            feasible size p (to check the paper's monotonicity).
        until_proven: Enumerate past the paper's stopping size p* until the
            interlacing bound proves the best feasible set optimal (exact; the
            paper's rule is not, see the README).
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
    complete: bool = False
    until_proven: bool = False
    penalty: float = 1e3
    prestress_degree: int = 1
    shear: str = "mitc"

    def __post_init__(self) -> None:
        if self.method not in METHODS:
            raise ValueError(f"solver.method must be one of {METHODS}, got {self.method!r}")
        if not 0.0 < _finite("solver.tau", self.tau) <= 1e-2:
            raise ValueError(f"solver.tau must lie in (0, 1e-2], got {self.tau!r}")
        if not 0.0 < _finite("solver.eps_tol", self.eps_tol) <= 1e-4:
            raise ValueError(f"solver.eps_tol must lie in (0, 1e-4], got {self.eps_tol!r}")
        if int(self.max_candidates) != self.max_candidates or self.max_candidates < 1:
            raise ValueError(
                f"solver.max_candidates must be an integer >= 1, got {self.max_candidates!r}"
            )
        if not _finite("solver.penalty", self.penalty) > 0.0:
            raise ValueError(f"solver.penalty must be > 0, got {self.penalty!r}")
        if int(self.prestress_degree) != self.prestress_degree or self.prestress_degree < 1:
            raise ValueError(
                f"solver.prestress_degree must be an integer >= 1, got {self.prestress_degree!r}"
            )
        if self.shear not in ("mitc", "full"):
            raise ValueError(f'solver.shear must be "mitc" or "full", got {self.shear!r}')


@dataclass(frozen=True)
class ProblemSpec:
    """A complete unilateral buckling problem.

    Args:
        name: Label used in output.
        plate: Geometry, thickness and edge conditions.
        material: Elastic constants.
        mesh: Mesh resolution.
        obstacle: Obstacle zone, or ``None`` for the free (bilateral) plate.
        solver: Solver options.
    """

    name: str = "plate"
    plate: PlateSpec = field(default_factory=PlateSpec)
    material: Material = field(default_factory=lambda: Material(E=1.0e9, nu=0.3))
    mesh: MeshSpec = field(default_factory=MeshSpec)
    obstacle: ObstacleSpec | None = None
    solver: SolverSpec = field(default_factory=SolverSpec)

    def with_mesh(self, nx: int, ny: int) -> ProblemSpec:
        """Copy with another mesh resolution."""
        return replace(self, mesh=MeshSpec(nx, ny))

    def with_solver(self, **changes: Any) -> ProblemSpec:
        """Copy with changed solver options."""
        return replace(self, solver=replace(self.solver, **changes))


def _take(table: Mapping[str, Any], allowed: tuple[str, ...], where: str) -> dict[str, Any]:
    if not isinstance(table, Mapping):
        raise ValueError(f"[{where}] must be a table, got {table!r}")
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        raise ValueError(f"unknown key(s) {unknown} in [{where}]; allowed: {list(allowed)}")
    return dict(table)


def _names(cls: type) -> tuple[str, ...]:
    return tuple(f.name for f in fields(cls))


def problem_from_dict(data: Mapping[str, Any], name: str = "plate") -> ProblemSpec:
    """Build a :class:`ProblemSpec` from a TOML-shaped mapping.

    Tables: ``[plate]`` (corners, thickness), ``[material]`` (E, nu, shear_correction,
    membrane_voigt, bending_voigt), ``[edges.<name>]`` (support, inplane,
    normal_stress, shear_stress), ``[mesh]`` (nx, ny), ``[obstacle]`` (zone,
    tolerance; absent = free plate), ``[solver]`` (the :class:`SolverSpec` fields).
    Unknown tables or keys raise ``ValueError``. Missing values take the paper's.
    """
    top = _take(data, ("name", "plate", "material", "edges", "mesh", "obstacle", "solver"), "top")
    plate_kw = _take(top.get("plate", {}), ("corners", "thickness"), "plate")
    edges = {e.name: e for e in paper_edges()}
    for edge_name, edge_table in _take(top.get("edges", {}), EDGE_NAMES, "edges").items():
        kw = _take(edge_table, _names(EdgeSpec)[1:-1], f"edges.{edge_name}")
        edges[edge_name] = replace(edges[edge_name], **kw)
    plate = PlateSpec(**plate_kw, edges=tuple(edges.values()))
    material_kw = _take(top.get("material", {"E": 1.0e9, "nu": 0.3}), _names(Material), "material")
    for key in ("E", "nu"):
        if key not in material_kw:
            raise ValueError(f"[material] needs {key!r}")
    material = Material(**material_kw)
    mesh = MeshSpec(**_take(top.get("mesh", {}), _names(MeshSpec), "mesh"))
    obstacle = None
    if "obstacle" in top:
        obstacle = ObstacleSpec(**_take(top["obstacle"], ("zone", "tolerance"), "obstacle"))
    solver = SolverSpec(**_take(top.get("solver", {}), _names(SolverSpec), "solver"))
    return ProblemSpec(
        name=str(top.get("name", name)),
        plate=plate,
        material=material,
        mesh=mesh,
        obstacle=obstacle,
        solver=solver,
    )


def load_toml(path: str | Path) -> ProblemSpec:
    """Read a :class:`ProblemSpec` from a TOML file (schema: :func:`problem_from_dict`)."""
    path = Path(path)
    with path.open("rb") as f:
        data = tomllib.load(f)
    return problem_from_dict(data, name=path.stem)
