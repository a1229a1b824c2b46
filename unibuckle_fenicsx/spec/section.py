r"""A section's problem file: ``[section]``, ``[material]``, ``[load]``, ``[obstacle]``, ``[mesh]``.

A file with a ``[section]`` table describes a box or a tube whose walls are the shell
model's (:mod:`~unibuckle_fenicsx.model.shell`), not a plate: its tables are these, each
checked as the plate's are (:mod:`~unibuckle_fenicsx.spec.base`). The critical load is
the compressive axial stress in Pa when ``axial_stress = -1``.
"""

from __future__ import annotations

import math
from typing import Annotated, ClassVar, Literal

import msgspec
from msgspec import Meta

from unibuckle_fenicsx.en1993 import check_steel_modulus, check_steel_yield_stress
from unibuckle_fenicsx.errors import FieldError, InputError
from unibuckle_fenicsx.spec.base import UNITS, Table, Units, in_file, unit
from unibuckle_fenicsx.spec.obstacles import DesignSpec
from unibuckle_fenicsx.spec.solver import Method, SolverSpec, default

Length = Annotated[float, unit("m", gt=0)]
#: The default of ``mesh.levels``: the search's many steps on a quarter of the DOFs.
DEFAULT_LEVELS = 1
#: The ``[solver]`` options a section uses (the others are the plate's methods').
SOLVER_KEYS = ("method", "tau", "eps_tol", "max_iterations")
#: The methods a section with a rigid core may name (``[solver] method``, ``--method``):
#: "auto" chooses between the other two by the section's size
#: (:func:`~unibuckle_fenicsx.algorithms.registry.choose_section_method`). The enumeration's 2^i
#: candidate sets are out of reach with a core's hundreds of directions, and the penalty
#: was never verified on a shell.
SECTION_METHODS: tuple[Method, ...] = (Method.AUTO, Method.INTERIOR_POINT, Method.ACTIVE_SET)


def check_section_method(method: str, core: bool = True, elastic: bool = False) -> None:
    """Refuse a ``[solver] method`` no section runs, or one this section would not run.

    One of :data:`SECTION_METHODS` runs a rigid core's search; a hollow section
    (``core`` false: the free solve) and an elastic core (``elastic``: the spring-set
    iteration) have one route each, so only "auto" is taken there (a method named for
    them would be ignored).

    Raises:
        FieldError: ``method`` is not one of :data:`SECTION_METHODS`, or is not "auto"
            without a rigid core (an :class:`~unibuckle_fenicsx.errors.InputError`
            naming ``solver.method``).
    """
    if method not in SECTION_METHODS:
        allowed = ", ".join(f'"{m}"' for m in SECTION_METHODS)
        raise FieldError(
            "", "solver.method", f" must be one of {allowed} for a section, got {str(method)!r}"
        )
    if method != Method.AUTO and (not core or elastic):
        which = (
            "a section without a core (its free solve)"
            if not core
            else "an elastic core (obstacle.foundation_stiffness: its spring-set iteration)"
        )
        raise FieldError(
            "",
            "solver.method",
            f" = {str(method)!r} chooses a rigid core's route; {which} has one route: "
            'leave it out or give "auto"',
        )


#: The options only a core's search reads (a rigid core's route: its coarser sections,
#: its KKT tolerance, its iterates per seed), with what each sets.
SEARCH_OPTIONS = {
    "mesh.levels": "the core's search's coarser sections",
    "solver.tau": "the core's contact tolerance (its KKT test)",
    "solver.max_iterations": "the core's search's iterates per seed",
}


def check_core_options(
    core: bool, levels: int, solver: SolverSpec, names: dict[str, str] | None = None
) -> None:
    """Refuse a search option given (other than its default) to a section without a core.

    Such a section is its free solve: none of :data:`SEARCH_OPTIONS` applies. A default
    value is taken, as a result's echoed ``input`` holds every key. The same table and
    message for a file and for :func:`~unibuckle_fenicsx.section_analysis.solve_section`'s
    arguments (``names``: a key's argument, named after it, e.g. ``levels``).

    Raises:
        FieldError: Such an option given (an :class:`~unibuckle_fenicsx.errors.InputError`
            naming it and saying why).
    """
    if core:
        return
    given = {  # each option: (its value, its default)
        "mesh.levels": (levels, DEFAULT_LEVELS),
        "solver.tau": (solver.tau, default("tau")),
        "solver.max_iterations": (solver.max_iterations, default("max_iterations")),
    }
    for key, what in SEARCH_OPTIONS.items():
        value, unset = given[key]
        if value != unset:
            argument = (names or {}).get(key)
            raise FieldError(
                "",
                key,
                f" = {value!r}{f' ({argument})' if argument else ''} sets {what}; a section "
                "without a core (obstacle.core = false) is its free solve: leave it out",
            )


def check_section_solver(solver: SolverSpec) -> None:
    """Refuse a plate's ``[solver]`` option (one not of :data:`SOLVER_KEYS`) given to a section.

    Raises:
        FieldError: Such an option other than its default (naming ``solver.KEY``).
    """
    plate_default = SolverSpec()
    for key in SolverSpec.__struct_fields__:
        if key not in SOLVER_KEYS and getattr(solver, key) != getattr(plate_default, key):
            takes = ", ".join(f"solver.{k}" for k in SOLVER_KEYS)
            raise FieldError("", f"solver.{key}", f" is a plate's option; a section takes {takes}")


#: Relative rounding of the mesh's arithmetic: L/h within it of a whole number n gives n
#: cells along, and a node within it (of the section's size) of a span's end lies in it.
_ROUNDING = 1e-9


def cells_along(length: float, size: float) -> int:
    """The cells of ``size`` (m) a section's mesh puts along its ``length``: ceil(L/h), >= 1.

    :mod:`~unibuckle_fenicsx.model.shell.geometry` meshes with it; the checks of a file's
    ``[mesh]`` read it before any mesh is made.
    """
    return max(1, math.ceil(length / size - _ROUNDING))


def face_cells(extent: float, size: float, even: bool = True, least: int = 2) -> int:
    """The cells of about ``size`` (m) across a width ``extent`` (m) of a section's mesh.

    ceil(extent/size), at least ``least``, made even if ``even`` (a box's face: a node at
    its middle; a tube's facets, at least 8). :mod:`~unibuckle_fenicsx.model.shell.geometry`
    meshes with it; the checks of a file's ``[mesh]`` read it before any mesh is made.
    """
    n = max(least, math.ceil(extent / size - _ROUNDING))
    return n + n % 2 if even else n


#: The fewest cells across a box's narrowest face a core (rigid or elastic) is solved on.
#: With the core every face's buckle must lie on one side of it between the corners,
#: where the adjacent faces' turning meets it: 2 cells (one node inside the face) cannot
#: hold such a buckle, and the critical stress comes out many times too high
#: (:doc:`/guide/sections`, "Cell size").
MIN_CORE_FACE_CELLS = 4


def check_core_face_cells(size: float, narrowest: float, units: str | None = None) -> None:
    """Refuse a box with a core whose narrowest face gets too few cells.

    At least :data:`MIN_CORE_FACE_CELLS` cells (:func:`face_cells`) across the narrowest
    face of width ``narrowest`` (m): ``size`` below narrowest/2, from where the even
    count is 4. The message in ``units`` (None: those of the file read or solved).

    Raises:
        InputError: Naming ``mesh.size`` and its range here.
    """
    cells = face_cells(narrowest, size)
    if cells >= MIN_CORE_FACE_CELLS:
        return
    (h, name), (w, _) = in_file(size, "m", units), in_file(narrowest, "m", units)
    bound, _ = in_file(narrowest / (MIN_CORE_FACE_CELLS - 2), "m", units)
    raise InputError(
        f"mesh.size = {h:g} {name} gives {cells} cells across the box's narrowest face "
        f"({w:g} {name}); with a core (obstacle.core) a face needs at least "
        f"{MIN_CORE_FACE_CELLS}, or its buckle cannot lie on one side of the core between "
        f"the corners and the critical stress comes out many times too high: mesh.size "
        f"must be < {bound:g} {name} here (a face's cells are ceil(width/mesh.size) made "
        'even; docs/guide/sections.md, "Cell size")'
    )


def check_cells_along(size: float, length: float, units: str | None = None) -> None:
    """Refuse a cell size ``size`` not below ``length`` (m): 2 cells along at least.

    The message in ``units`` (None: those of the file read or solved,
    :func:`~unibuckle_fenicsx.spec.base.file_units`).

    Raises:
        InputError: Naming ``mesh.size`` and its range.
    """
    if size * (1.0 + _ROUNDING) >= length:  # cells_along: ceil(L/h)
        (h, name), (L, _) = in_file(size, "m", units), in_file(length, "m", units)
        raise InputError(
            f"mesh.size = {h:g} {name} must be below section.length = {L:g} {name}: the "
            "section needs at least 2 cells along its length (the nodes of its loaded ends "
            "are supported)"
        )


def most_levels(size: float, length: float) -> int:
    """The most coarser sections (cells of ``size`` doubled) keeping 2 cells along ``length``."""
    most = 0
    while size * 2.0 ** (most + 1) * (1.0 + _ROUNDING) < length:
        most += 1
    return most


def check_levels(size: float, length: float, levels: int, units: str | None = None) -> None:
    """Refuse ``levels`` whose coarsest section has fewer than 2 cells along the member.

    The message in ``units`` (None: those of the file read or solved).

    Raises:
        InputError: Naming ``mesh.levels`` and its range here (<= :func:`most_levels`).
    """
    most = most_levels(size, length)
    if levels > most:
        coarsest, name = in_file(size * 2.0**levels, "m", units)
        L, _ = in_file(length, "m", units)
        raise InputError(
            f"mesh.levels = {levels}: the coarsest section's cells, mesh.size x 2^{levels} = "
            f"{coarsest:g} {name}, are not below section.length = "
            f"{L:g} {name} (at least 2 cells along): mesh.levels <= {most} here"
        )


def check_span_nodes(
    span: tuple[float, float],
    length: float,
    size: float,
    levels: int,
    across: float,
    units: str | None = None,
) -> None:
    """Refuse a core's ``span`` holding no free node of the section or of a coarser one.

    The nodes along the member lie at :math:`x_i = iL/n`, n = :func:`cells_along`; those
    of the loaded ends (i = 0, n) are held by the end supports (their normal motion, at
    both kinds of ends), so the span needs some :math:`0 < i < n` within it (to the
    mesh's tolerance, :data:`_ROUNDING` of the section's largest dimension, ``across``
    or ``length``), on the given cells and on each of the ``levels`` coarser sections
    a rigid core's search starts on (each with twice the cells' size).

    Raises:
        InputError: Naming ``obstacle.span`` (and ``mesh.levels`` when a coarser section
            has no node in it), with what to change.
    """
    x0, x1 = span
    tol = _ROUNDING * max(length, across)
    (a, b), unit = in_file((x0, x1), "m", units)
    for k in range(levels + 1):
        n = cells_along(length, size * 2.0**k)

        def first(least: int, n: int = n) -> int:
            """The first node i >= least at or past x0 (n + 1: none): O(1), any n."""
            i = max(least, math.floor((x0 - tol) * n / length))
            while i <= n and i * length / n < x0 - tol:
                i += 1
            return i

        interior, any_node = first(1), first(0)
        if interior < n and interior * length / n <= x1 + tol:
            continue
        held = any_node <= n and any_node * length / n <= x1 + tol
        what = "only nodes held by the end supports" if held else "no node of the mesh"
        cells, _ = in_file(size * 2.0**k, "m", units)
        where = (
            f"the cells of mesh.size = {cells:g} {unit}"
            if k == 0
            else f"the coarser section of mesh.levels = {levels} with cells {cells:g} {unit} "
            f"(mesh.size doubled {k} time{'s' if k > 1 else ''})"
        )
        change = "lengthen obstacle.span or refine mesh.size" + (
            f", or lower mesh.levels to {k - 1}{' or less' if k > 1 else ''}" if k else ""
        )
        raise InputError(
            f"obstacle.span = [{a:g}, {b:g}] {unit}: the core covers no free node: its span "
            f"(obstacle.span) holds {what} on {where}; {change}"
        )


def check_section_mesh(
    *,
    size: float,
    length: float,
    levels: int,
    core: bool,
    elastic: bool,
    span: tuple[float, float] | None,
    across: float,
    narrowest: float | None = None,
    units: str | None = None,
) -> None:
    """What a section's cells and ``mesh.levels`` must allow, checked before any mesh.

    2 cells along (:func:`check_cells_along`); with a rigid core, ``levels`` coarser
    sections of 2 cells along (:func:`check_levels`), each with a free node in the core's
    ``span`` (:func:`check_span_nodes`); with a core (rigid or elastic) on a box,
    :data:`MIN_CORE_FACE_CELLS` across its ``narrowest`` face (m; None: a tube,
    :func:`check_core_face_cells`). An elastic core's rigid start takes the default
    levels as far as the section allows them, so only levels given other than the default
    are checked, and its span on the given cells only (its start falls back on them). The
    problem file's :meth:`SectionProblemSpec.check` and
    :func:`~unibuckle_fenicsx.section_analysis.solve_section` call it.

    Raises:
        InputError: Naming ``mesh.size``, ``mesh.levels`` or ``obstacle.span`` and the
            range allowed.
    """
    check_cells_along(size, length, units)
    if core and (not elastic or levels != DEFAULT_LEVELS):
        check_levels(size, length, levels, units)
    if core and span is not None:
        check_span_nodes(span, length, size, 0 if elastic else levels, across, units)
    if core and narrowest is not None:
        check_core_face_cells(size, narrowest, units)


def narrowest_face(shape: str, width: float | None, depth: float | None) -> float | None:
    """A box's narrowest face (m), the smaller of ``width`` and ``depth``; None: a tube."""
    if shape != "box" or width is None or depth is None:
        return None
    return min(width, depth)


class SectionSpec(Table, frozen=True):
    """A box or tube section (the file's ``[section]``).

    Args:
        shape: "box" (rectangular hollow section) or "tube" (circular hollow section).
        width: Box: mid-line width b of the faces along y (m), > 0; not for a tube.
        depth: Box: mid-line depth d along z (m), > 0; not for a tube.
        diameter: Tube: mid-surface diameter 2R (m), > 0; not for a box.
        thickness: Wall thickness t (m), > 0 and below half the smallest dimension
            across (the walls would meet).
        length: Length L between the loaded ends (m), > 0.
        ends: The loaded ends: "clamped" or "simply_supported" (the section's ends held
            against moving off the member's axis; clamped ends also against turning).
    """

    KEY: ClassVar[str] = "section"
    shape: Literal["box", "tube"]
    thickness: Length
    length: Length
    width: Length | None = None
    depth: Length | None = None
    diameter: Length | None = None
    ends: Literal["clamped", "simply_supported"] = "clamped"

    def check(self) -> None:
        """A box has width and depth, a tube a diameter; the walls do not meet."""
        keys = ("width", "depth") if self.shape == "box" else ("diameter",)
        for other in ("width", "depth", "diameter"):
            given = getattr(self, other) is not None
            if other in keys and not given:
                raise self.error(other, f" is needed by a {self.shape} (m, > 0)")
            if other not in keys and given:
                raise self.error(
                    other, f" is not a key of a {self.shape}: it has {' and '.join(keys)}"
                )
        across = min(getattr(self, k) for k in keys)
        if self.thickness >= 0.5 * across:
            (half, name), (t, _) = in_file(0.5 * across, "m"), in_file(self.thickness, "m")
            raise self.error(
                "thickness",
                f" must be < half of {' and '.join(keys)} ({half:g} {name}): the walls "
                f"would meet, got {t!r}",
            )


class WallMaterial(Table, frozen=True):
    """The walls' isotropic material (a section file's ``[material]``).

    Args:
        E: Young's modulus (Pa), > 0.
        nu: Poisson's ratio, in (-1, 0.5).
    """

    KEY: ClassVar[str] = "material"
    E: Annotated[float, unit("Pa", gt=0)]
    nu: Annotated[float, Meta(gt=-1.0, lt=0.5)]


class AxialLoad(Table, frozen=True):
    """The end load per unit load factor (a section file's ``[load]``).

    Args:
        axial_stress: Uniform axial stress per unit load (Pa per Pa; compression < 0);
            -1 makes the critical load the compressive stress in Pa.
        bending_stress: The part varying linearly over the depth, its value at
            z = +d/2 (box) or +R (tube) per unit load (an axial force with bending); 0.
    """

    KEY: ClassVar[str] = "load"
    axial_stress: float = -1.0
    bending_stress: float = 0.0

    def check(self) -> None:
        """Some load, and some fibre in compression under it."""
        if self.axial_stress == 0.0 and self.bending_stress == 0.0:
            raise self.error("axial_stress", " and load.bending_stress are 0: no load")
        tension = tension_everywhere(self.axial_stress, self.bending_stress)
        if tension:
            raise self.error("axial_stress", tension)


def tension_everywhere(axial_stress: float, bending_stress: float) -> str:
    r"""Why these end stresses put every wall fibre in tension ("" when some is compressed).

    The axial stress is :math:`\sigma_a + \sigma_b\zeta`, :math:`\zeta` from -1 to 1 over
    the depth: the extreme fibre's compression per unit load is
    :math:`|\sigma_b| - \sigma_a`. The text follows ``load.axial_stress`` in a refusal.
    """
    if abs(bending_stress) - axial_stress > 0.0:
        return ""
    return (
        f" = {axial_stress!r} with load.bending_stress = {bending_stress!r} puts the walls "
        "in tension everywhere (the extreme fibre's compression per unit load, "
        "|bending_stress| - axial_stress, must be > 0): no buckling under a positive load; "
        "compression is axial_stress < 0"
    )


class CoreSpec(Table, frozen=True):
    r"""The core filling the section (a section file's ``[obstacle]``).

    Args:
        core: A core fills the section: the walls may only move outward (rigid), or
            press it only as far as its foundation lets them (``foundation_stiffness``).
        span: The core's extent [x0, x1] along the member (m), 0 <= x0 < x1 <= length;
            absent: the whole length.
        foundation_stiffness: The core as a tensionless Winkler foundation of this
            modulus (N/m^3, Pa/m), > 0: the walls press it with :math:`k_f\,u_n` and leave
            it freely; absent: a rigid core. For concrete, about :math:`E_c` over the
            depth the wall's bulge strains (a few wall half-waves).
    """

    KEY: ClassVar[str] = "obstacle"
    core: bool = False
    span: (
        Annotated[
            tuple[float, float],
            Meta(extra={"unit": "m", "form": "a pair [x0, x1] (from x0 to x1 along the member)"}),
        ]
        | None
    ) = None
    foundation_stiffness: Annotated[float, unit("N/m^3", gt=0)] | None = None

    def check(self) -> None:
        """A span or a stiffness belongs to a core."""
        for key in ("span", "foundation_stiffness"):
            if getattr(self, key) is not None and not self.core:
                raise self.error(key, " is the core's: it needs core = true")


class SectionMeshSpec(Table, frozen=True):
    """The section's cells (a section file's ``[mesh]``).

    Args:
        size: Target cell size (m), > 0 and below the section's length (2 cells along at
            least); a box's faces get an even number of cells, with a core at least 4
            across the narrowest face (size below half its width).
        levels: With a rigid core, coarser sections (each with twice the cell size) the
            search starts on, >= 0, as long as the coarsest keeps 2 cells along; 1: its
            many steps on a quarter of the DOFs, a few on the given cells. An elastic core:
            those of its start from the rigid core's contact set. Refused
            without a core (:func:`check_core_options`).
    """

    KEY: ClassVar[str] = "mesh"
    size: Length
    levels: Annotated[int, Meta(ge=0)] = DEFAULT_LEVELS


class SectionProblemSpec(Table, frozen=True):
    """A section problem (a file with a ``[section]`` table), in SI units.

    Args:
        name: Label used in output (a file's stem when it gives none).
        units: The unit system the file is written in and results are printed in.
        section: The section's shape, walls and ends.
        material: The walls' material.
        load: The end load per unit load factor.
        obstacle: The core, if any.
        mesh: The cells.
        design: With ``[design]``: EN 1993-1-5 per face and EN 1994-1-1's wall limits from
            the critical state (:mod:`~unibuckle_fenicsx.section_design`).
        solver: Solver options: of :data:`SOLVER_KEYS` (the method, one of
            :data:`SECTION_METHODS`; the feasibility tolerance tau, the eigen solves'
            tolerance, the active-set iterations per seed); the plate's methods' options
            are refused.
    """

    KEY: ClassVar[str] = ""
    section: SectionSpec
    material: WallMaterial
    mesh: SectionMeshSpec
    name: str = "section"
    units: Units = "SI"
    load: AxialLoad = msgspec.field(default_factory=AxialLoad)
    obstacle: CoreSpec = msgspec.field(default_factory=CoreSpec)
    solver: SolverSpec = msgspec.field(default_factory=SolverSpec)
    design: DesignSpec | None = None

    def check(self) -> None:
        """The core's span lies on the member; the solver's options are a section's."""
        span, length = self.obstacle.span, self.section.length
        if span is not None and not 0.0 <= span[0] < span[1] <= length:
            (L, x0, x1), name = in_file((length, *span), "m", self.units)  # the file's units
            raise self.error(
                "obstacle.span",
                f" must satisfy 0 <= x0 < x1 <= section.length = {L:g} {name}, "
                f"got [{x0:g}, {x1:g}]",
            )
        elastic = self.obstacle.foundation_stiffness is not None
        check_section_method(self.solver.method, self.obstacle.core, elastic)
        check_core_options(self.obstacle.core, self.mesh.levels, self.solver)
        check_section_solver(self.solver)
        s = self.section
        check_section_mesh(
            size=self.mesh.size, length=s.length, levels=self.mesh.levels,
            core=self.obstacle.core, elastic=elastic, span=span,
            across=max(float(v or 0.0) for v in (s.width, s.depth, s.diameter)),
            narrowest=narrowest_face(s.shape, s.width, s.depth), units=self.units,
        )  # fmt: skip
        if self.design is not None:
            check_steel_modulus(self.material.E, *UNITS[self.units][1:])
            check_steel_yield_stress(self.design.yield_stress, *UNITS[self.units][1:])
