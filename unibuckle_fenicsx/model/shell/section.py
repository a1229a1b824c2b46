r"""A section's buckling problem from plain parameters: the public surface of the shell model.

:func:`build_section` takes what a ``[section]`` table will hold (shape, width, depth or
diameter, thickness, length, ends, E, nu, the axial stress per unit load and its part
varying over the depth, whether a core fills the section, the mesh size) and returns a
:class:`Section`: the mesh, the shell model (A, B in global components), the prestress,
and with a core the rotated pencil (A', B') with the constrained rows (one per
constrained direction, sign +1: :math:`n_{in}\cdot u \le 0`) and each constrained node's
frame, set up as a :class:`~unibuckle_fenicsx.model.shell.problem.SectionProblem` for
the package's unilateral algorithms and certificate. :func:`figure_data` gathers what the
3-D figure of a mode needs (:func:`~unibuckle_fenicsx.viz.section.plot_section_mode_3d`).

The critical load :math:`\lambda` is the compressive stress in Pa when
``axial_stress = -1`` without bending (the prestress is :math:`\lambda` times the unit
one). A box's buckling coefficient uses its widest face, :math:`k = \sigma t b^2/(\pi^2 D)`
with :math:`\sigma` that face's largest compressive stress at the load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from mpi4py import MPI

import dolfinx

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.la.ownership import Owner
from unibuckle_fenicsx.model.materials import bending_stiffness
from unibuckle_fenicsx.model.problem import Candidate
from unibuckle_fenicsx.model.shell.core import (
    CoreConstraints,
    axis_turns,
    change_of_basis,
    core_constraints,
    core_springs,
    quarter_turns,
)
from unibuckle_fenicsx.model.shell.forms import DRILLING_FACTOR
from unibuckle_fenicsx.model.shell.geometry import SectionMesh, section_mesh
from unibuckle_fenicsx.model.shell.model import ENDS, ShellModel, end_supports
from unibuckle_fenicsx.model.shell.prestress import SectionPrestress, solve_section_prestress
from unibuckle_fenicsx.model.shell.problem import (
    CoredSectionProblem,
    SectionProblem,
    section_problem,
)
from unibuckle_fenicsx.spec import Material, SectionProblemSpec, SolverSpec
from unibuckle_fenicsx.spec.section import check_cells_along, tension_everywhere

__all__ = [
    "GEOMETRIC",
    "Section",
    "SectionFigureData",
    "SectionParameters",
    "build_section",
    "figure_data",
    "outward_component",
    "section_parameters",
]

#: Displacement components in the geometric stiffness b: "full" (all three: the axial
#: stress's work on the wall's rotation in its own plane as well as out of it, the
#: consistent term of the shell's stiffness, as in Flügge's and Sanders' stability
#: equations) or "donnell" (the normal deflection only, the plate model's b). Donnell's
#: leaves out the in-plane part, which a column's mode and a tube's modes of few
#: circumferential waves carry: with this stiffness it puts a tube's n-wave mode about
#: 1 + 1/n² too high and a column's load at twice Euler's; a box's walls' modes carry
#: none of it (:doc:`/verification/sections_geometric`).
GEOMETRIC = ("full", "donnell")


@dataclass(frozen=True)
class SectionParameters:
    r"""A section's description, checked before any mesh is made.

    Args:
        shape: "box" (rectangular hollow section) or "tube" (circular hollow section).
        thickness: Wall thickness t (m), > 0 and < half the smallest dimension across.
        length: Length L between the loaded ends (m), > 0.
        E: Young's modulus (Pa), > 0.
        nu: Poisson's ratio, in (-1, 0.5).
        mesh_size: Target cell size (m), a file's ``mesh.size``: > 0 and below ``length``
            (at least 2 cells along; a box's faces get an even number of cells; a box
            with a core, :func:`~unibuckle_fenicsx.section_analysis.solve_section` asks
            for at least 4 across its narrowest face).
        width: Box: mid-line width b along y (m).
        depth: Box: mid-line depth d along z (m).
        diameter: Tube: mid-surface diameter 2R (m).
        ends: The loaded ends: "clamped" or "simply_supported"
            (:func:`~unibuckle_fenicsx.model.shell.model.end_supports`).
        axial_stress: Uniform axial stress per unit load (Pa/Pa; compression < 0); -1
            makes the critical load the compressive stress in Pa.
        bending_stress: Part of the axial stress varying linearly over the depth, its
            value at z = +d/2 (box) or +R (tube) per unit load (an axial force with
            bending), 0 by default.
        core: A rigid core fills the section: the walls may only move outward.
        core_span: The core's extent (x0, x1) along the member (m), a file's
            ``obstacle.span``; None: the whole length.
        foundation_stiffness: The core as a tensionless Winkler foundation of this
            modulus (N/m^3), > 0 (:func:`~unibuckle_fenicsx.model.shell.core.core_springs`);
            None: a rigid core.
        geometric: Components in b (:data:`GEOMETRIC`); "full" by default, the term
            consistent with the shell's stiffness (Sanders' and Flügge's equations);
            "donnell" only to compare with Donnell's shallow-shell theory.
        drilling: Drilling stiffness relative to Gt
            (:data:`~unibuckle_fenicsx.model.shell.forms.DRILLING_FACTOR`).
        corner_cell: A box's faces graded to cells this wide (m) at the corners
            (:func:`~unibuckle_fenicsx.model.shell.geometry.box_mesh`), > 0 and below
            ``mesh_size``; None: uniform. Not for a tube.
    """

    shape: str
    thickness: float
    length: float
    E: float
    nu: float
    mesh_size: float
    width: float | None = None
    depth: float | None = None
    diameter: float | None = None
    ends: str = "clamped"
    axial_stress: float = -1.0
    bending_stress: float = 0.0
    core: bool = False
    core_span: tuple[float, float] | None = None
    foundation_stiffness: float | None = None
    geometric: str = "full"
    drilling: float = DRILLING_FACTOR
    corner_cell: float | None = None

    def __post_init__(self) -> None:
        across = self._check_shape()
        t = _positive("thickness", self.thickness)
        if t >= 0.5 * across:
            raise InputError(
                f"section.thickness = {t:g} m must be < half the smallest dimension across "
                f"({0.5 * across:g} m): the walls would meet"
            )
        _positive("length", self.length)
        _positive("size", self.mesh_size, "mesh")
        check_cells_along(self.mesh_size, self.length)
        if self.corner_cell is not None:
            if self.shape != "box":
                raise InputError(
                    f"corner_cell = {self.corner_cell!r} grades a box's faces at its corners; "
                    "a tube has no corners (its facets are uniform): leave it None"
                )
            cell = self.corner_cell
            if not (isinstance(cell, int | float) and math.isfinite(cell) and cell > 0.0):
                # Not a file key (a section's [mesh] has none): named as the argument it is.
                raise InputError(
                    "corner_cell (an argument of SectionParameters, not a file key) must be "
                    f"a finite number > 0 (m), got {cell!r}"
                )
            if self.corner_cell >= self.mesh_size:
                raise InputError(
                    f"corner_cell = {self.corner_cell:g} m must be < mesh_size = "
                    f"{self.mesh_size:g} m (cells no finer at the corners are the uniform "
                    "mesh's): leave it None for uniform cells"
                )
        if not (isinstance(self.E, int | float) and math.isfinite(self.E) and self.E > 0):
            raise InputError(f"material.E must be a finite number > 0 (Pa), got {self.E!r}")
        if not (isinstance(self.nu, int | float) and -1.0 < self.nu < 0.5):
            raise InputError(f"material.nu must lie in (-1, 0.5), got {self.nu!r}")
        if self.ends not in ENDS:
            raise InputError(f"section.ends must be one of {ENDS}, got {self.ends!r}")
        if self.geometric not in GEOMETRIC:
            raise InputError(f"geometric must be one of {GEOMETRIC}, got {self.geometric!r}")
        if not (math.isfinite(self.drilling) and self.drilling > 0.0):
            raise InputError(f"drilling must be a finite number > 0, got {self.drilling!r}")
        self._check_load()

    def _check_shape(self) -> float:
        """The shape's keys; returns the smallest dimension across (m)."""
        if self.shape not in ("box", "tube"):
            raise InputError(f"section.shape must be one of ('box', 'tube'), got {self.shape!r}")
        if self.shape == "box":
            if self.diameter is not None:
                raise InputError("section.diameter is for a tube; a box has width and depth")
            return min(_positive("width", self.width), _positive("depth", self.depth))
        for key in ("width", "depth"):
            if getattr(self, key) is not None:
                raise InputError(f"section.{key} is for a box; a tube has diameter")
        return _positive("diameter", self.diameter)

    def _check_load(self) -> None:
        """The stresses and the core's span."""
        for key in ("axial_stress", "bending_stress"):
            if not math.isfinite(getattr(self, key)):
                raise InputError(
                    f"load.{key} must be a finite number (Pa), got {getattr(self, key)!r}"
                )
        if self.axial_stress == 0.0 and self.bending_stress == 0.0:
            raise InputError("load.axial_stress and load.bending_stress are both 0: no load")
        tension = tension_everywhere(self.axial_stress, self.bending_stress)
        if tension:
            raise InputError(f"load.axial_stress{tension}")
        if self.foundation_stiffness is not None:
            if not self.core:
                raise InputError("obstacle.foundation_stiffness needs core = true")
            _positive("foundation_stiffness", self.foundation_stiffness, "obstacle", "N/m^3")
        if self.core_span is not None:
            if not self.core:
                raise InputError("obstacle.span (core_span) needs core = true")
            x0, x1 = self.core_span
            if not (0.0 <= x0 < x1 <= self.length):
                raise InputError(
                    f"obstacle.span (core_span) must satisfy 0 <= x0 < x1 <= length = "
                    f"{self.length:g} m, got {self.core_span}"
                )

    def compression(self) -> float:
        r"""The largest compressive stress per unit load (Pa/Pa), the extreme fibre's.

        The axial stress is :math:`\sigma_a + \sigma_b\zeta` (``axial_stress``,
        ``bending_stress``), :math:`\zeta` from -1 to 1 over the depth; the result is
        :math:`|\sigma_b| - \sigma_a`, <= 0 when no fibre is in compression.
        """
        return abs(self.bending_stress) - self.axial_stress

    @property
    def bending_stiffness(self) -> float:
        """The walls' flexural rigidity D (N m)."""
        return bending_stiffness(self.E, self.nu, self.thickness)

    def classical_stress(self) -> float:
        r"""The walls' reference stress (Pa): a box's k = 4 load, a tube's classical one.

        Box: :math:`4\pi^2 D/(t b^2)`, b the widest face; tube:
        :math:`E t / (R\sqrt{3(1-\nu^2)})`.
        """
        t = self.thickness
        if self.shape == "tube":
            return self.E * t / (0.5 * self.widest * math.sqrt(3.0 * (1.0 - self.nu**2)))
        return 4.0 * math.pi**2 * self.bending_stiffness / (t * self.widest**2)

    def euler_stress(self) -> float:
        r"""The member's Euler stress :math:`\pi^2 E r^2/L_e^2` (Pa), as a column.

        :math:`r^2 = I/A` of the thin-walled mid-line about the weaker axis: a box's
        :math:`\min(d^2(d + 3b), b^2(b + 3d))/(12(b + d))`, a tube's :math:`R^2/2`;
        :math:`L_e` the length between simply supported ends, half of it between
        clamped ones.
        """
        if self.shape == "box":
            b, d = float(self.width or 0.0), float(self.depth or 0.0)
            r2 = min(d * d * (d + 3.0 * b), b * b * (b + 3.0 * d)) / (12.0 * (b + d))
        else:
            r2 = 0.125 * float(self.diameter or 0.0) ** 2
        effective = self.length if self.ends == "simply_supported" else 0.5 * self.length
        return math.pi**2 * self.E * r2 / effective**2

    def donnell(self) -> bool:
        """Whether the geometric stiffness is Donnell's (the normal deflection only)."""
        return self.geometric == "donnell"

    @property
    def widest(self) -> float:
        """The widest face b of a box (m), the buckling coefficient's width; a tube's 2R."""
        if self.shape == "box":
            return max(float(self.width or 0.0), float(self.depth or 0.0))
        return float(self.diameter or 0.0)


def section_parameters(spec: SectionProblemSpec) -> SectionParameters:
    """The :class:`SectionParameters` of a section's problem file (checked already).

    Its cells and levels were checked when it was read
    (:func:`~unibuckle_fenicsx.spec.section.check_section_mesh`).
    """
    s, core = spec.section, spec.obstacle
    return SectionParameters(
        s.shape, thickness=s.thickness, length=s.length, E=spec.material.E,
        nu=spec.material.nu, mesh_size=spec.mesh.size, width=s.width, depth=s.depth,
        diameter=s.diameter, ends=s.ends, axial_stress=spec.load.axial_stress,
        bending_stress=spec.load.bending_stress, core=core.core, core_span=core.span,
        foundation_stiffness=core.foundation_stiffness,
    )  # fmt: skip


def _positive(key: str, value: float | None, table: str = "section", unit: str = "m") -> float:
    """``value`` as a float, or an :class:`InputError` naming ``table.key``."""
    if value is None or not (isinstance(value, int | float) and math.isfinite(value)):
        raise InputError(f"{table}.{key} must be a finite number > 0 ({unit}), got {value!r}")
    if value <= 0.0:
        raise InputError(f"{table}.{key} must be > 0 ({unit}), got {value!r}")
    return float(value)


class Section(Owner):
    """A section's buckling problem, built by :func:`build_section`.

    Attributes:
        parameters: The description.
        mesh: The section's mesh and tags.
        prestress: The prestress per unit load.
        model: The shell model: A, B in global components, with the end supports.
        constraints: The core's constrained directions (None without a core).
        problem: The pencil as a :class:`~unibuckle_fenicsx.model.shell.problem.SectionProblem`
            (with a core: a :class:`~unibuckle_fenicsx.model.shell.problem.CoredSectionProblem`,
            rotated, with the contact manager; without: A, B as they are).

    Note:
        :meth:`destroy` is collective; the section is a context manager.
    """

    def __init__(
        self,
        parameters: SectionParameters,
        mesh: SectionMesh,
        prestress: SectionPrestress,
        model: ShellModel,
        constraints: CoreConstraints | None,
        problem: SectionProblem,
    ) -> None:
        self.parameters = parameters
        self.mesh = mesh
        self.prestress = prestress
        self.model = model
        self.constraints = constraints
        self.problem = problem

    @property
    def cored(self) -> CoredSectionProblem:
        """The problem with the core's contact manager.

        Raises:
            RuntimeError: The section has no core (an internal invariant of its caller).
        """
        if not isinstance(self.problem, CoredSectionProblem) or self.constraints is None:
            raise RuntimeError("a section without a core has no contact manager")
        return self.problem

    @property
    def rows(self) -> npt.NDArray[np.int64]:
        """Global rows of (A', B') of the constrained directions, numbered 0..i-1 (collective)."""
        if not isinstance(self.problem, CoredSectionProblem):
            return np.empty(0, np.int64)
        return self.problem.contact.global_rows()

    @property
    def signs(self) -> npt.NDArray[np.float64]:
        r"""Sign of each constrained row: +1 (:math:`n_{in}\cdot u = u'_k \le 0`)."""
        return np.ones(0 if self.constraints is None else self.constraints.size)

    def buckling_coefficient(self, load: float) -> float:
        r""":math:`k = \sigma t b^2/(\pi^2 D)` of a box's widest face b; NaN for a tube.

        :math:`\sigma` is the load ``load`` times ``SectionParameters.compression()``, the
        largest compression, which the widest faces reach: the classical coefficient
        whatever the stress per unit load and its gradient (:math:`\psi = -1`: a web's
        23.9 when hinged); NaN without compression
        (:meth:`.SectionProblem.buckling_coefficient`).
        """
        return self.problem.buckling_coefficient(load)

    def classical_stress(self) -> float:
        r"""Reference stress (Pa): a box's k = 4 load, a tube's classical one.

        Box: :math:`4\pi^2 D/(t b^2)`; tube: :math:`E t / (R\sqrt{3(1-\nu^2)})`.
        """
        return self.parameters.classical_stress()

    def destroy(self) -> None:
        """Destroy the problem and the model (collective)."""
        for name in ("problem", "model"):
            owner = self.__dict__.get(name)
            if owner is not None:
                owner.destroy()

    def __del__(self) -> None:
        self.destroy()


def build_section(
    parameters: SectionParameters,
    comm: MPI.Comm = MPI.COMM_WORLD,
    solver: SolverSpec | None = None,
) -> Section:
    """Mesh, prestress, pencil and (with a core) the rotated pencil of a section.

    Args:
        parameters: The section (checked already: :class:`SectionParameters`).
        comm: Communicator of the mesh.
        solver: Solver options of the problem (tolerances, certificate).

    Returns:
        The :class:`Section`; the caller destroys it.

    Note:
        Collective on ``comm``.
    """
    p = parameters
    msh = section_mesh(
        p.shape, width=p.width, depth=p.depth, diameter=p.diameter, length=p.length,
        size=p.mesh_size, comm=comm, corner_cell=p.corner_cell,
    )  # fmt: skip
    material = Material(E=p.E, nu=p.nu)
    prestress = solve_section_prestress(
        msh, material, p.thickness, p.axial_stress, p.bending_stress
    )
    model = ShellModel(
        msh, material, p.thickness, prestress.N0, end_supports(msh, p.ends),
        drilling=p.drilling, donnell=p.donnell(),
    )  # fmt: skip
    constraints = core_constraints(model, p.core_span) if p.core else None
    T = change_of_basis(model, constraints) if constraints is not None else None
    springs = None
    if constraints is not None and p.foundation_stiffness is not None:
        springs = core_springs(model, constraints, p.foundation_stiffness, p.core_span)
    problem = section_problem(
        model, prestress, constraints, T, material, solver, springs=springs,
        compression=p.compression(),
        symmetries=_symmetries(p, constraints, springs, msh.cells_around),
    )  # fmt: skip
    return Section(p, msh, prestress, model, constraints, problem)


def _symmetries(
    p: SectionParameters,
    constraints: CoreConstraints | None,
    springs: npt.NDArray[np.float64] | None,
    cells_around: int,
) -> tuple[npt.NDArray[np.int64], ...]:
    """The turns about its axis under which the section's pencil and core are invariant.

    A square box (width = depth) under a load the same on every face (no bending
    stress): its walls, supports, core span and prestress are the same after a quarter
    turn about its axis, and so are its pencil's eigenvalues and the normal components of
    its modes. A tube under a load the same all around (no bending stress) likewise
    after a turn by a whole number of its ``cells_around`` facets: its mesh is that
    polygon swept along the axis, the core's span runs along the axis, and the supports
    of its ends are the same all around (a simply supported end's one node held along
    the axis holds the rigid axial motion only, which neither energy sees). The turns
    that map the mesh's constrained directions onto themselves
    (:func:`~unibuckle_fenicsx.model.shell.core.quarter_turns`,
    :func:`~unibuckle_fenicsx.model.shell.core.axis_turns`) and a foundation's springs
    onto equal springs; none for any other section (a bending stress varies around it,
    and a turn changes it).
    """
    if constraints is None or p.bending_stress != 0.0:
        return ()
    if p.shape == "box" and p.width == p.depth:
        turns = quarter_turns(constraints)
    elif p.shape == "tube":
        turns = axis_turns(constraints, cells_around)
    else:
        return ()
    if springs is not None:
        turns = tuple(t for t in turns if np.allclose(springs[t], springs, rtol=1e-12, atol=0.0))
    return turns


@dataclass(frozen=True)
class SectionFigureData:
    """What the section's figure needs, on one rank.

    Attributes:
        points: (n, 3) mesh nodes (m).
        quads: (c, 4) cells as node indices, in VTK's counter-clockwise order.
        displacement: (n, 3) the mode's displacement, global components, max |u| = 1.
        outward: (n,) its component along the outward normal (a corner node: the larger
            in magnitude of its two), max |u| = 1.
        pressing: (p, 3) nodes where the wall presses on the core (contact force > 0).
        touching: (q, 3) other nodes of the contact set (on the core, no force).
        shape: "box", "tube" or "flat".
        size: (length, width, depth) of the section (m).
    """

    points: npt.NDArray[np.float64]
    quads: npt.NDArray[np.int64]
    displacement: npt.NDArray[np.float64]
    outward: npt.NDArray[np.float64]
    pressing: npt.NDArray[np.float64]
    touching: npt.NDArray[np.float64]
    shape: str
    size: tuple[float, float, float]


def outward_component(
    section: Section, points: npt.NDArray[np.float64], displacement: npt.NDArray[np.float64]
) -> npt.NDArray[np.float64]:
    """The component (n,) of each node's ``displacement`` (n, 3) along the outward normal.

    ``points`` (n, 3): the nodes. A box's corner node has two normals: the larger in
    magnitude of its two components is kept.
    """
    normals = section.mesh.inward_normals(np.asarray(points, dtype=float).T)
    return np.array(
        [max((-(n @ d) for n in ns), key=abs) for ns, d in zip(normals, displacement, strict=True)],
        dtype=float,
    )


def figure_data(
    section: Section, candidate: Candidate | None = None, mode: dolfinx.fem.Function | None = None
) -> SectionFigureData:
    """The arrays of the 3-D figure of a mode (serial sections only).

    Args:
        section: The section.
        candidate: A unilateral critical state (its mode, contact set and forces), or
        mode: A mode in the problem's basis (e.g. the free mode).

    Note:
        Serial (``comm.size == 1``), as :func:`~unibuckle_fenicsx.viz.plotting.plot_mode_3d`.
    """
    import dolfinx.plot

    problem = section.problem
    if problem.comm.size != 1:
        raise RuntimeError("figure_data gathers serial sections only (comm.size == 1)")
    if candidate is not None:
        mode = candidate.mode
    if mode is None:
        raise ValueError("figure_data needs a candidate or a mode")
    u = problem.global_mode(mode)
    V = section.model.W
    topology, _, x = dolfinx.plot.vtk_mesh(V)  # type: ignore[arg-type]
    quads = np.asarray(topology, dtype=np.int64).reshape(-1, 5)[:, 1:]
    disp = u.x.array.reshape(-1, 6)[:, :3]
    scale = float(np.abs(disp).max()) or 1.0
    disp = disp / scale
    outward = outward_component(section, np.asarray(x), disp)
    pressing = touching = np.zeros((0, 3))
    if candidate is not None and section.constraints is not None and candidate.active.size:
        active = candidate.active
        pts = section.constraints.coordinates[active]
        push = candidate.forces[active] < -candidate.tau
        pressing, touching = pts[push], pts[~push]
    m = section.mesh
    return SectionFigureData(
        np.asarray(x, dtype=float), quads, disp, outward, pressing, touching, m.shape,
        (m.length, m.width, m.depth),
    )  # fmt: skip
