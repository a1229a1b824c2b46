r"""Python entry point for sections: :func:`solve_section` a box or a tube, with or without a core.

The section counterpart of :func:`~unibuckle_fenicsx.analysis.solve`: a
:class:`~unibuckle_fenicsx.model.shell.section.SectionParameters` (shape, walls, ends,
load, whether a rigid core fills the section) in, a :class:`SectionAnalysis` out, whose
:class:`SectionResult` is the plate's :class:`~unibuckle_fenicsx.results.records.BucklingResult`
with the section's reference stress. The obstacle is the core: at every node of the walls
it covers, the wall may only move away from it (:mod:`~unibuckle_fenicsx.model.shell.core`).

- Without a core the critical load is the pencil's smallest eigenvalue, verified the
  smallest by the inertia of :math:`A - \sigma B` (as a plate without obstacle).
- With a core the free load is the hollow section's; the unilateral critical state is
  found by the method :func:`~unibuckle_fenicsx.algorithms.registry.choose_section_method` chooses,
  run through the registry (:data:`~unibuckle_fenicsx.algorithms.registry.REGISTRY`):
  with a rigid core coarse to fine
  (:func:`~unibuckle_fenicsx.algorithms.section_levels.solve_levels`: the interior
  point's starts on a coarser section, the mode carried to the finer one;
  or the active set's seeds and carried contact set), with an elastic core by the
  spring-set iteration; it is certified
  (:func:`~unibuckle_fenicsx.certificate.certify.certify`) on the finest.

The critical load is the factor on the stresses per unit load: the compressive stress in
Pa when ``axial_stress = -1`` without bending. A box's ``buckling_coefficient_k`` uses its
widest face, :math:`k = \sigma t b^2/(\pi^2 D)` with :math:`\sigma` the face's largest
compressive stress at that load (with bending, the extreme fibre's); a
tube has none (its reference is :math:`\sigma_{cl} = E t/(R\sqrt{3(1-\nu^2)})`,
``classical_stress_Pa``).
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time
from dataclasses import dataclass

from mpi4py import MPI

import dolfinx

import msgspec
import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms import UnilateralSolution
from unibuckle_fenicsx.algorithms.registry import choose_section_method, entry
from unibuckle_fenicsx.algorithms.section_levels import estimated_dofs
from unibuckle_fenicsx.certificate.certify import Certificate, certify, certify_foundation
from unibuckle_fenicsx.en1993 import (
    check_steel_modulus,
    check_steel_yield_stress,
    steel_poisson_note,
    yield_stress_note,
)
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.la.ownership import Owner
from unibuckle_fenicsx.model.problem import Mode
from unibuckle_fenicsx.model.resources import check_section_memory
from unibuckle_fenicsx.model.shell.geometry import cell_length, face_cell_width, tube_facet_width
from unibuckle_fenicsx.model.shell.section import (
    Section,
    SectionFigureData,
    SectionParameters,
    build_section,
    figure_data,
    section_parameters,
)
from unibuckle_fenicsx.progress import warn_once
from unibuckle_fenicsx.results.assemble import record_contact, versions
from unibuckle_fenicsx.results.records import BucklingResult, ResultDetails, coefficient_text
from unibuckle_fenicsx.section_design import (
    SectionDesignRecord,
    at_lower_bound,
    design_line,
    face_compressions,
    face_width,
    section_design,
)
from unibuckle_fenicsx.spec import (
    UNITS,
    DesignSpec,
    SectionProblemSpec,
    SolverSpec,
    problem_to_dict,
)
from unibuckle_fenicsx.spec.base import FILE_UNITS, file_units, in_file
from unibuckle_fenicsx.spec.plate import THICK_PLATE_RATIO
from unibuckle_fenicsx.spec.section import (
    DEFAULT_LEVELS,
    check_core_options,
    check_section_mesh,
    check_section_solver,
    narrowest_face,
)

__all__ = [
    "COLUMN_FRACTION",
    "LONG_TUBE_HALF_WAVES",
    "MAX_CALIBRATED_RADIUS_RATIO",
    "MIN_ALONG_CELLS",
    "MIN_FACE_CELLS",
    "MIN_HALF_WAVE_CELLS",
    "MIN_HALF_WAVE_CELLS_LONG",
    "SHORT_TUBE_HALF_WAVES",
    "SectionAnalysis",
    "SectionResult",
    "buckle_length",
    "coarse_mesh_note",
    "column_note",
    "half_wave",
    "mesh_cell_counts",
    "min_half_wave_cells",
    "solve_section",
    "thick_wall_note",
]

logger = logging.getLogger(__name__)


class SectionResult(BucklingResult, kw_only=True):
    r"""Critical state of a section: a :class:`~unibuckle_fenicsx.results.records.BucklingResult`.

    The fields keep the plate's meaning, with the section's words:
    ``critical_load_Pa`` is the critical load factor on the stresses per unit load (the
    filled section's with a core), ``free_load_Pa`` the hollow section's: with
    ``axial_stress = -1`` and no bending, the compressive stress in Pa;
    ``buckling_coefficient_k`` uses a box's widest face and its largest compressive
    stress at the critical load, so it is the classical k whatever the stress gradient
    (None for a tube); ``mesh`` is [cells along, cells around]; ``dofs`` counts the
    six components of every node; ``constrained_nodes`` counts the core's constrained
    *directions* (a box's corner node has two), ``contact_coordinates`` their unrolled
    (x, s) (m along the member, m around the mid-line), ``contact_indices`` their numbers
    (ordered by (x, s), the same on any number of ranks); ``contact_dofs`` are the
    rows of the rotated pencil in DOLFINx's numbering of the distributed mesh, which
    depends on the number of MPI ranks (its partition): compare runs by
    ``contact_indices`` or ``contact_coordinates``, not by them; ``input`` is the section's
    problem file (:func:`~unibuckle_fenicsx.spec.problem_to_dict`) when one was solved,
    else ``{"section": the parameters}``; ``critical_force_N_per_m`` is the extreme
    fibre's :math:`t\sigma` (``compression_Pa``); ``design``, with a ``[design]`` table, is a
    :class:`~unibuckle_fenicsx.section_design.SectionDesignRecord` (EN 1993-1-5 per face of
    a box, EN 1994-1-1's wall limits with a core).

    Attributes:
        classical_stress_Pa: The section's reference stress (Pa): a box's k = 4 load
            :math:`4\pi^2 D/(t b^2)`, a tube's :math:`E t/(R\sqrt{3(1-\nu^2)})`.
        compression_Pa: The largest compressive stress at the critical load (Pa), the
            extreme fibre's: ``critical_load_Pa`` times the largest compression per unit
            load (``SectionParameters.compression()``), equal to it with
            ``axial_stress = -1`` and no bending.
        faces: A box's faces at the critical load (empty for a tube): each face's name
            (``right``, ``top``, ``left``, ``bottom``: y = +b/2, z = +d/2, y = -b/2,
            z = -d/2), its width (m), its largest compressive stress ``compression_Pa``
            (Pa, <= 0: none), its own buckling coefficient :math:`\sigma t w^2/(\pi^2 D)`
            with that stress (NaN, null in JSON, without compression), its constrained
            directions and those in contact with the core (pressing a foundation).
        warnings: The warnings the solve logged, in its order: a thick wall, cells too
            coarse (or a tube thinner than the cell rule's range), a design's Poisson's
            ratio not a steel's, the member's column mode near its load (kept here
            for a sweep's points, whose solves print none).
    """

    classical_stress_Pa: float = math.nan
    compression_Pa: float = math.nan
    faces: list[dict[str, str | float]] = msgspec.field(default_factory=list)
    warnings: list[str] = msgspec.field(default_factory=list)

    def _bending(self) -> float:
        """The input's ``bending_stress`` (0 by default in a file's ``[load]``); NaN unknown."""
        for key in ("load", "section"):  # a file's echo; solve_section's parameters
            table = self.input.get(key) if isinstance(self.input, dict) else None
            if isinstance(table, dict) and (key == "load" or "bending_stress" in table):
                return float(table.get("bending_stress", 0.0))
        return math.nan

    def summary(self) -> str:
        """Lines for the terminal: the critical stress, the hollow one, the reference.

        Stresses in the file's unit system (``units``: Pa, or MPa for mm-N-MPa).
        """
        scale, unit = UNITS[self.units][1:]
        k_value = self.buckling_coefficient_k
        k = "" if k_value is None else f", k = {coefficient_text(k_value)}"
        sigma = self.compression_Pa  # the stresses printed are the extreme fibre's
        if math.isnan(sigma):  # a result written before the field: the load factor
            sigma = self.critical_load_Pa
        where = " (uniform)" if self._bending() == 0.0 else " at the extreme fibre"
        factor = (
            ""
            if sigma == self.critical_load_Pa
            else f"{where}, load factor {self.critical_load_Pa / scale:.6e} {unit}"
        )
        hollow = self.free_load_Pa * (sigma / self.critical_load_Pa)  # its extreme fibre's
        head = (
            f"{self.case}: sigma_cr = {sigma / scale:.6e} {unit}{factor} "
            f"({self.ratio_to_free:.4f} x hollow {hollow / scale:.6e} {unit}){k}, "
            f"{sigma / self.classical_stress_Pa:.4f} x classical "
            f"{self.classical_stress_Pa / scale:.6e} {unit} "
            # What "classical" is: a box's widest face as a long hinged plate, a tube's
            # sigma_cl (the chart's and the figures' reference, docs/guide/sections.md).
            + (
                "(sigma_cl = E t/(R sqrt(3(1 - nu^2))))"
                if k_value is None
                else "(the widest face's k = 4)"
            )
        )
        lines = [
            f"{head}, method {self.method}, {self.eigensolves} eigensolves, "
            f"{self.wall_time_s:.2f} s"
        ]
        cert, lower = self.certificate, self.lower_bound_Pa
        if cert is not None:
            # The bound in the same stress as sigma_cr (the extreme fibre's).
            bound = (
                "none"
                if lower is None
                else f"{lower * (sigma / self.critical_load_Pa) / scale:.6e} {unit}"
            )
            lines.append(
                f"core: {self.constrained_nodes} constrained directions, |Z| = "
                f"{self.contact_nodes}, KKT = {'yes' if cert.kkt else 'NO'}, "
                f"certificate {cert.status} (lower bound {bound} by {cert.proven_by})"
            )
            bracket = self._bound_line(
                scale,
                unit,
                what="critical stress",
                free="the hollow section's",
                ratio=sigma / self.critical_load_Pa,
                bracket=False,  # solver.bracket is a plate's option: a section refuses it
            )
            if bracket:
                lines.append(bracket)
        if isinstance(self.design, SectionDesignRecord):
            length = UNITS[self.units][0]
            lines.append(
                design_line(self.design, scale, unit, (length, "m" if self.units == "SI" else "mm"))
            )
        return "\n  ".join(lines)


@dataclass
class SectionAnalysis(Owner):
    """What :func:`solve_section` returns: the result, the section, the mode.

    Attributes:
        result: JSON-ready numbers (:class:`SectionResult`).
        section: The finest section (mesh, shell model, the core's constraints, problem).
        solution: The unilateral solution (None without a core).
        certificate: Its certificate (None without a core).

    Note:
        :meth:`destroy` (or leaving a ``with`` block) is collective.
    """

    result: SectionResult
    section: Section
    solution: UnilateralSolution | None = None
    certificate: Certificate | None = None

    @property
    def mode(self) -> dolfinx.fem.Function:
        """The critical mode in global components (u, omega), max |u| = 1 (collective)."""
        if self.solution is not None:
            return self.section.problem.global_mode(self.solution.candidate.mode)
        return self.free_mode

    @property
    def free_mode(self) -> dolfinx.fem.Function:
        """The hollow section's mode in global components (collective)."""
        free = self.section.problem.free
        if free is None:
            raise RuntimeError("free_mode: the section's free mode was not solved")
        return self.section.problem.global_mode(free.function, name="free mode")

    def figure_data(self, free: bool = False) -> SectionFigureData:
        """The arrays of the 3-D figure of the critical mode (``free``: the hollow one).

        Serial only (:func:`~unibuckle_fenicsx.model.shell.section.figure_data`); draw them
        with :func:`~unibuckle_fenicsx.viz.section.plot_section_mode_3d`.
        """
        problem = self.section.problem
        if free or self.solution is None:
            if problem.free is None:
                raise RuntimeError("figure_data: the section's free mode was not solved")
            return figure_data(self.section, mode=problem.free.function)
        return figure_data(self.section, self.solution.candidate)

    def destroy(self) -> None:
        """Destroy the section's PETSc/SLEPc objects (collective)."""
        self.section.destroy()


def solve_section(
    parameters: SectionParameters | SectionProblemSpec,
    comm: MPI.Comm = MPI.COMM_WORLD,
    *,
    levels: int = DEFAULT_LEVELS,
    solver: SolverSpec | None = None,
    design: DesignSpec | None = None,
) -> SectionAnalysis:
    """Critical axial stress and mode of a box or tube section; with a core, certified.

    Args:
        parameters: The section (:class:`~unibuckle_fenicsx.model.shell.section.SectionParameters`,
            checked when built: bad keys raise :class:`~unibuckle_fenicsx.errors.InputError`),
            or a section's problem file
            (:class:`~unibuckle_fenicsx.spec.section.SectionProblemSpec`: its
            ``mesh.levels``, ``[solver]`` and ``[design]`` are solved, and ``levels``,
            ``solver`` and ``design`` given beside it refused; the result's ``case`` is
            the file's ``name`` and its ``input`` the file, which re-runs it).
        comm: Communicator; the mesh is distributed over it.
        levels: With a core, coarser sections (each with twice the mesh size) the search
            starts on, >= 0 (:func:`~unibuckle_fenicsx.algorithms.section_levels.solve_levels`:
            the interior point's starts, or the active set's seeds). 1 by default: the
            starts' many steps on a section of a quarter of the DOFs, a few on the given one.
            Without a core, refused (as the file's ``mesh.levels``) if not the default.
        solver: Solver options (the method, one of
            :data:`~unibuckle_fenicsx.spec.section.SECTION_METHODS`, chosen by
            :func:`~unibuckle_fenicsx.algorithms.registry.choose_section_method`; tolerances, the
            feasibility tolerance tau); the package's defaults when None.
        design: The yield stress and partial factor of the design output
            (:mod:`~unibuckle_fenicsx.section_design`); None: none.

    Returns:
        The analysis; the caller destroys it (or uses ``with``).

    Raises:
        TypeError: ``parameters`` is not a SectionParameters.
        InputError: ``levels`` out of range (its coarsest section without 2 cells
            along, or a core's span without a free node on it), a core on a box whose
            narrowest face gets fewer than 4 cells (``mesh_size``, the file's
            ``mesh.size``: :func:`~unibuckle_fenicsx.spec.section.check_core_face_cells`),
            a method no section runs
            (``solver.method``), or what the problem file refuses: a core's search
            options (``levels``, ``solver.tau``, ``solver.max_iterations``) given to a
            section without a core, a plate's solver option; all before any mesh.
        NumericalError: An eigen solve did not converge.

    Note:
        Collective on ``comm``. On an error every PETSc/SLEPc object built here is
        destroyed before the error propagates.
    """
    units = parameters.units if isinstance(parameters, SectionProblemSpec) else "SI"
    with file_units(units):  # every refusal, warning and note of the run speaks the file's
        return _solve_section(parameters, comm, levels, solver, design)


def _solve_section(
    parameters: SectionParameters | SectionProblemSpec,
    comm: MPI.Comm,
    levels: int,
    solver: SolverSpec | None,
    design: DesignSpec | None,
) -> SectionAnalysis:
    """:func:`solve_section` in its file's units (set by the caller: ``file_units``)."""
    t0 = time.perf_counter()
    echo: dict[str, object] | None = None
    units, name = "SI", None
    if isinstance(parameters, SectionProblemSpec):
        _file_holds_them(parameters, levels, solver, design)
        echo, name = problem_to_dict(parameters), parameters.name
        levels, solver, design = parameters.mesh.levels, parameters.solver, parameters.design
        units = parameters.units
        parameters = section_parameters(parameters)
    if not isinstance(parameters, SectionParameters):
        raise TypeError(
            f"solve_section: parameters must be a SectionParameters or a SectionProblemSpec, "
            f"got {type(parameters).__name__}"
        )
    solver = solver or SolverSpec()
    warnings = _check(parameters, levels, solver, design, comm)
    certificate: Certificate | None = None
    method, reason = choose_section_method(parameters, solver)
    logger.info("section: method %s (%s)", method, reason)
    section, solution = _solve(parameters, int(levels), comm, method, solver)
    try:
        problem = section.problem
        t1 = time.perf_counter()
        free = problem.solve_free()
        problem.timings["free_solve_s"] = time.perf_counter() - t1
        if solution is None:
            t1 = time.perf_counter()
            problem.verify_free()
            problem.timings["free_check_s"] = time.perf_counter() - t1
        else:
            t1 = time.perf_counter()
            cored = section.cored
            certificate = (
                certify_foundation(cored, solution)
                if cored.tensionless
                else certify(cored, solution)
            )
            problem.timings["certify_s"] = time.perf_counter() - t1
            if certificate.status == "not-kkt":
                warn_once(
                    logger,
                    comm,
                    "the section's result fails its certificate: %s",
                    "; ".join(certificate.notes) or certificate.status,
                )
        result = _result(section, free, solution, certificate, time.perf_counter() - t0, reason)
        if echo is not None:  # a file's run: its name, its input
            result.case, result.input, result.units = str(name), echo, units
        column = column_note(parameters, result.critical_load_Pa, solution is not None)
        if column is not None:
            warn_once(logger, comm, "%s", column)
        result.warnings = [*warnings, *([] if column is None else [column])]
        if design is not None:
            result.design = _design(parameters, design, result, certificate, column)
    except BaseException:
        section.destroy()
        raise
    return SectionAnalysis(result, section, solution, certificate)


def _file_holds_them(
    spec: SectionProblemSpec, levels: int, solver: SolverSpec | None, design: DesignSpec | None
) -> None:
    """Refuse ``levels``, ``solver`` or ``design`` given beside a problem file, which holds them.

    The file's ``mesh.levels``, ``[solver]`` and ``[design]`` are the ones solved; an
    argument beside it was ignored.
    """
    given = {  # argument: (its key in the file, the spec's field, given)
        "levels": ("mesh.levels", "mesh", levels != DEFAULT_LEVELS),
        "solver": ("[solver]", "solver", solver is not None),
        "design": ("[design]", "design", design is not None),
    }
    for argument, (key, field, set_) in given.items():
        if set_:
            value = (
                f"msgspec.structs.replace(spec.mesh, levels={levels!r})"
                if argument == "levels"
                else argument
            )
            raise InputError(
                f"solve_section: {argument} is given with a problem file "
                f"(SectionProblemSpec), whose {key} is the one solved: set it in the file "
                f"(msgspec.structs.replace(spec, {field}={value}))"
            )


#: Fewer cells than this across a box's narrowest face draw a warning: there the hollow
#: box's load is already more than about 5 % above its converged value, and a core's
#: shorter buckles make it worse (:doc:`/guide/sections`, "Cell size"); a core on fewer
#: than :data:`~unibuckle_fenicsx.spec.section.MIN_CORE_FACE_CELLS` is refused.
MIN_FACE_CELLS = 5
#: Fewer cells than this along a tube's axisymmetric half-wave
#: :math:`\pi\sqrt{Rt}/(12(1-\nu^2))^{1/4}` draw a warning between clamped ends, and
#: between simply supported ends up to :data:`SHORT_TUBE_HALF_WAVES` half-waves long: the
#: hollow tube's error on n cells is about C/n\ :sup:`2`, C up to 81 % over R/t = 12.5 to
#: 800, so 4 cells keep it to about 5 % (:doc:`/verification/tube_cells`).
MIN_HALF_WAVE_CELLS = 4.0
#: ... and this many along a simply supported tube at least :data:`LONG_TUBE_HALF_WAVES`
#: half-waves long (C up to 23 %; the count asked falls linearly in between).
MIN_HALF_WAVE_CELLS_LONG = 2.5
#: The simply supported tube's lengths (in half-waves) between which the cells asked fall.
SHORT_TUBE_HALF_WAVES = 5.0
#: See :data:`SHORT_TUBE_HALF_WAVES`.
LONG_TUBE_HALF_WAVES = 8.0
#: The largest R/t the rule on the half-wave is calibrated at: thinner tubes draw a warning
#: whatever their cells (:func:`coarse_mesh_note`).
MAX_CALIBRATED_RADIUS_RATIO = 800.0
#: Fewer cells than this along the longest buckle the ends allow (:func:`buckle_length`)
#: draw a warning, by the same measure: a short section buckles in one wave as long as
#: the member, whatever its walls' own buckles: the count that keeps short boxes and
#: tubes to the guide's accuracy (:doc:`/guide/sections`, "Cell size", holds the
#: calibration).
MIN_ALONG_CELLS = 6


def _check(
    parameters: SectionParameters,
    levels: int,
    solver: SolverSpec,
    design: DesignSpec | None,
    comm: MPI.Comm,
) -> list[str]:
    """Refuse what no solve should start with, and warn of walls or cells out of range.

    Returns the warnings logged (the result's ``warnings``).

    Raises:
        InputError: ``levels`` not an integer >= 0; a hollow section given a core's
            search options (``levels``, ``solver.tau``, ``solver.max_iterations``:
            :func:`~unibuckle_fenicsx.spec.section.check_core_options`) or any section a
            plate's solver option; cells or levels the section cannot have (a core on a
            box: 4 cells across its narrowest face at least), or a core's
            span holding no free node of a section the search runs on
            (:func:`~unibuckle_fenicsx.spec.section.check_section_mesh`); a design output
            asked of a wall whose E is not a steel's
            (:func:`~unibuckle_fenicsx.en1993.check_steel_modulus`); cells whose DOFs,
            estimated before meshing, need more memory than the ranks have
            (:func:`~unibuckle_fenicsx.model.resources.check_section_memory`). Collective.
    """
    if isinstance(levels, bool) or int(levels) != levels or levels < 0:
        raise InputError(f"levels must be an integer >= 0, got {levels!r}")
    p = parameters
    # The file's own checks (its reader ran them already): a core's options on a hollow
    # section, a plate's options, the cells, levels and span.
    check_core_options(p.core, int(levels), solver, {"mesh.levels": "levels"})
    check_section_solver(solver)
    check_section_mesh(
        size=p.mesh_size, length=p.length, levels=int(levels), core=p.core,
        elastic=p.foundation_stiffness is not None, span=p.core_span,
        across=max(float(v or 0.0) for v in (p.width, p.depth, p.diameter)),
        narrowest=narrowest_face(p.shape, p.width, p.depth),
    )  # fmt: skip
    check_section_memory(estimated_dofs(p), p.mesh_size, comm)
    notes = [thick_wall_note(parameters), coarse_mesh_note(parameters)]
    if design is not None:
        stress = UNITS[FILE_UNITS.get()][1:]
        check_steel_modulus(parameters.E, *stress)
        check_steel_yield_stress(design.yield_stress, *stress)
        notes.append(steel_poisson_note(parameters.nu))
        notes.append(
            yield_stress_note(design.yield_stress, parameters.thickness, "section.thickness")
        )
    found = [note for note in notes if note is not None]
    for note in found:
        warn_once(logger, comm, "%s", note)
    return found


def _design(
    parameters: SectionParameters,
    design: DesignSpec,
    result: SectionResult,
    certificate: Certificate | None,
    column: str | None,
) -> SectionDesignRecord:
    """The design output of ``result``, at the verified lower bound too if not proven.

    ``column``: the warning of a column's mode (:func:`column_note`), a note of it.
    """
    record = section_design(parameters, design, result.critical_load_Pa)
    if column is not None:
        record.notes.append(column)
    lower = result.lower_bound_Pa
    if certificate is not None and not certificate.global_optimum_proven and lower:
        at_lower_bound(record, parameters, design, lower)
    return record


#: A member whose critical axial stress reaches this fraction of its Euler stress draws
#: a warning. Hollow: its mode is the column's, or coupled with it (the shell's column
#: has shear deformation and comes out up to a few % below Euler's load). With a core:
#: the core keeps the walls off the column's mode, so the result says nothing of it.
COLUMN_FRACTION = 0.8


def column_note(parameters: SectionParameters, load: float, cored: bool) -> str | None:
    """A warning when the member's Euler stress is near or below its critical one, else None.

    Its uniform axial stress at ``load`` at or above :data:`COLUMN_FRACTION` of the
    Euler stress (:meth:`SectionParameters.euler_stress`, the walls' section alone).
    Hollow: k and EN 1993-1-5's face values are the walls' quantities, not a column's.
    With a core (``cored``): the model holds the walls off the column's mode (a rigid
    core lets them move only outward, an elastic one resists with springs fixed in
    space), while a real core moves with the member; the critical stress is the walls'
    local one, and the member's flexural buckling is not checked (EN 1994-1-1, 6.7.3).
    Stresses in the units of the file solved (:func:`~unibuckle_fenicsx.spec.base.file_units`).
    """
    p = parameters
    axial = -load * p.axial_stress
    euler = p.euler_stress()
    if axial < COLUMN_FRACTION * euler:
        return None
    _, scale, unit = UNITS[FILE_UNITS.get()]
    stresses = (
        f"the critical axial stress {axial / scale:.4g} {unit} is {axial / euler:.3g} times "
        f"the member's Euler stress {euler / scale:.4g} {unit}"
    )
    if cored:
        return (
            f"{stresses} (its walls' section alone): the core holds the walls off the "
            "member's column mode here, so sigma_cr is the walls' local critical stress "
            "and says nothing of the member's flexural buckling, to be checked on its own "
            "(EN 1994-1-1, 6.7.3, with the infill's stiffness; EN 1993-1-1, 6.3.1 without)"
        )
    return (
        f"{stresses}: the mode is the column's "
        "(or coupled with it), and k and the EN 1993-1-5 face values are the walls' "
        "quantities, not the column's (EN 1993-1-1, 6.3.1)"
    )


def coarse_mesh_note(parameters: SectionParameters) -> str | None:
    """A warning when the cells are too coarse for the walls' buckles, else None.

    The rule (:data:`MIN_FACE_CELLS` across a box's face, :func:`min_half_wave_cells`
    along a tube's half-wave, :data:`MIN_ALONG_CELLS` along :func:`buckle_length`; the
    note names the one that asks for the finest cells) is a priori, from the section's
    dimensions and the cells its mesh will have (:func:`mesh_cell_counts`): on cells too
    coarse for the buckles the shell's critical stress is too high (it falls as the cells
    are refined), and so are k and the design values. A tube thinner than
    :data:`MAX_CALIBRATED_RADIUS_RATIO` draws a warning whatever its cells: the rule is
    not calibrated there. Lengths in the units of the file solved
    (:func:`~unibuckle_fenicsx.spec.base.file_units`).
    """
    p = parameters
    width, across = _buckle_width(p)
    length, along = buckle_length(p)
    need_across = MIN_FACE_CELLS if p.shape == "box" else min_half_wave_cells(p)
    cells_across, cells_along = mesh_cell_counts(p)
    checks = [
        # a box's buckle spans its face; a tube's half-wave runs along the axis
        (cells_across, width, need_across, f"{'across' if p.shape == 'box' else 'along'} {across}"),
        (cells_along, length, MIN_ALONG_CELLS, f"along {along}"),
    ]
    # A whole number of cells within rounding (5 cells of L/5 over L) counts as that many.
    short = [c for c in checks if c[0] * (1.0 + 1e-9) < c[2]]
    if not short:
        return _thin_tube_note(p)
    cells, span, need, where = min(short, key=lambda c: c[0] / c[2])  # the finest asked
    (size, finer, width), unit = in_file((p.mesh_size, span / need, span), "m")
    return (
        f"mesh.size = {size:.3g} {unit} gives {cells:.2g} cells {where} "
        f"({width:.3g} {unit}), fewer than {need:g}: on cells this coarse the "
        "critical stress, k and the design values come out too high (refine mesh.size to "
        f'{finer:.3g} {unit} or less; docs/guide/sections.md, "Cell size")'
    )


def min_half_wave_cells(parameters: SectionParameters) -> float:
    """The cells a tube's mesh needs along its axisymmetric half-wave (:func:`half_wave`).

    :data:`MIN_HALF_WAVE_CELLS` between clamped ends and along a simply supported tube
    of up to :data:`SHORT_TUBE_HALF_WAVES` half-waves, :data:`MIN_HALF_WAVE_CELLS_LONG`
    from :data:`LONG_TUBE_HALF_WAVES` on, linear in the length in between (rounded up
    to a tenth).
    """
    p = parameters
    if p.ends == "clamped":
        return MIN_HALF_WAVE_CELLS
    waves = p.length / half_wave(p)
    cells = np.interp(
        waves,
        (SHORT_TUBE_HALF_WAVES, LONG_TUBE_HALF_WAVES),
        (MIN_HALF_WAVE_CELLS, MIN_HALF_WAVE_CELLS_LONG),
    )
    return math.ceil(10.0 * float(cells) - 1e-9) / 10.0  # up to a tenth of a cell


def _thin_tube_note(parameters: SectionParameters) -> str | None:
    """The warning of :func:`coarse_mesh_note` for a tube thinner than the rule's range."""
    p = parameters
    if p.shape != "tube":
        return None
    ratio = 0.5 * float(p.diameter or 0.0) / p.thickness
    if ratio <= MAX_CALIBRATED_RADIUS_RATIO:
        return None
    return (
        f"R/t = {ratio:.4g} is above {MAX_CALIBRATED_RADIUS_RATIO:g}, the thinnest tube "
        "the rule on the cells along the half-wave is calibrated at: the critical stress, k "
        "and the design values may come out too high on these cells (compare with a "
        'solve on a finer mesh.size; docs/guide/sections.md, "Cell size")'
    )


def mesh_cell_counts(parameters: SectionParameters) -> tuple[float, float]:
    """The cells the mesh puts across the walls' buckles and along the member's.

    What the mesh of ``mesh.size`` has (:mod:`~unibuckle_fenicsx.model.shell.geometry`
    rounds the cells up: an even number across a box's face, ceil(L/size) along):
    a box's narrowest face over its widest cell across (uniform faces: their number of
    cells); a tube's axisymmetric half-wave (:func:`half_wave`) over the larger of its
    cells' length and its facets' width; and :func:`buckle_length` over the cells'
    length.
    """
    p = parameters
    along = cell_length(p.length, p.mesh_size)
    width, _ = _buckle_width(p)
    if p.shape == "box":
        across = width / face_cell_width(width, p.mesh_size, p.corner_cell)
    else:
        across = width / max(along, tube_facet_width(float(p.diameter or 0.0), p.mesh_size))
    return across, buckle_length(p)[0] / along


def buckle_length(parameters: SectionParameters) -> tuple[float, str]:
    r"""The longest buckle the loaded ends allow along the member (m), and its name.

    The length L between simply supported ends (one half-wave :math:`\sin(\pi x/L)`),
    L/2 between clamped ones (the one-wave mode :math:`1 - \cos(2\pi x/L)` bends in
    half-waves of L/2). On a long member the walls' own buckles are shorter and
    :func:`coarse_mesh_note` checks those; on a short one this length is the buckle's.
    """
    p = parameters
    if p.ends == "clamped":
        return 0.5 * p.length, "half the length between the clamped ends"
    return p.length, "the length between the simply supported ends"


def half_wave(parameters: SectionParameters) -> float:
    r"""A tube's axisymmetric buckling half-wave :math:`\pi\sqrt{Rt}/(12(1-\nu^2))^{1/4}` (m)."""
    p = parameters
    radius = 0.5 * float(p.diameter or 0.0)
    return math.pi * math.sqrt(radius * p.thickness) / (12.0 * (1.0 - p.nu**2)) ** 0.25


def _buckle_width(parameters: SectionParameters) -> tuple[float, str]:
    """The width of the walls' buckles (m) and its name.

    A box's narrowest face; a tube's axisymmetric half-wave (:func:`half_wave`).
    """
    p = parameters
    if p.shape == "box":
        return min(float(p.width or 0.0), float(p.depth or 0.0)), "the narrowest face"
    return half_wave(p), "the tube's axisymmetric half-wave"


def thick_wall_note(parameters: SectionParameters) -> str | None:
    """A warning when the wall is thick for the shell model, else None.

    The plate's rule (:func:`~unibuckle_fenicsx.spec.checks.plate_model_note`): the
    shell's Reissner-Mindlin kinematics model walls up to about
    :data:`~unibuckle_fenicsx.spec.plate.THICK_PLATE_RATIO` times the width of their
    buckles (:func:`_buckle_width`). Lengths in the units of the file solved
    (:func:`~unibuckle_fenicsx.spec.base.file_units`).
    """
    p = parameters
    span, what = _buckle_width(p)
    ratio = p.thickness / span
    if ratio <= THICK_PLATE_RATIO:
        return None
    (t, width), unit = in_file((p.thickness, span), "m")
    return (
        f"section.thickness = {t:g} {unit} is {ratio:.3g} times {what} "
        f"({width:.3g} {unit}): "
        "the shell (transverse shear, no thickness stretch) is a model of walls up to about "
        f"{THICK_PLATE_RATIO:g} times the width of their buckles; beyond, compare with a "
        "3-D solid model"
    )


#: A box's faces: name, the axis of their normal (1: y, 2: z) and its inward sign.
_FACES = (("right", 1, -1.0), ("top", 2, -1.0), ("left", 1, 1.0), ("bottom", 2, 1.0))


def _faces(
    section: Section, load: float, active: npt.NDArray[np.int64] | None
) -> list[dict[str, str | float]]:
    """Each face of a box at the load ``load``, with the contact set ``active``."""
    p = section.parameters
    if p.shape != "box" or p.width is None or p.depth is None:
        return []
    D = p.bending_stiffness
    normals = np.zeros((0, 3)) if section.constraints is None else section.constraints.normals
    touching = np.zeros(len(normals), dtype=bool)
    if active is not None:
        touching[active] = True
    out: list[dict[str, str | float]] = []
    compressions = face_compressions(p)
    for name, axis, sign in _FACES:
        width = face_width(p, name)
        on = normals[:, axis] * sign > 0.5
        sigma = load * max(compressions[name]) + 0.0  # its largest compression (no -0.0)
        out.append(
            {
                "face": name,
                "width_m": width,
                "compression_Pa": sigma,
                "buckling_coefficient_k": sigma * p.thickness * width**2 / (math.pi**2 * D)
                if sigma > 0.0
                else math.nan,
                "constrained": int(on.sum()),
                "in_contact": int((on & touching).sum()),
            }
        )
    return out


def _solve(
    parameters: SectionParameters, levels: int, comm: MPI.Comm, method: str, solver: SolverSpec
) -> tuple[Section, UnilateralSolution | None]:
    """The section and, with a core, its solution by ``method`` (a registry key)."""
    if not parameters.core:  # the hollow section's free load is the answer
        return build_section(parameters, comm, solver), None
    return entry(method).solve_section(parameters, levels, comm, solver)


def _result(
    section: Section,
    free: Mode,
    solution: UnilateralSolution | None,
    certificate: Certificate | None,
    wall_time_s: float,
    method_chosen_by: str,
) -> SectionResult:
    """The :class:`SectionResult` of a solved section (collective: gathers the contact rows).

    ``method_chosen_by``: why its method ran
    (:func:`~unibuckle_fenicsx.algorithms.registry.choose_section_method`).
    """
    p = section.parameters
    problem = section.problem
    load = free.load if solution is None else solution.load
    k = section.buckling_coefficient(load)
    mode = free.function if solution is None else solution.candidate.mode
    result = SectionResult(
        case=f"section-{p.shape}",
        method="free" if solution is None else solution.method,
        route=["free"] if solution is None else list(solution.route),
        critical_load_Pa=load,
        free_load_Pa=free.load,
        ratio_to_free=load / free.load,
        critical_force_N_per_m=p.thickness * load * p.compression(),
        buckling_coefficient_k=None if math.isnan(k) else k,
        dofs=section.model.num_dofs,
        mesh=[section.mesh.cells_along, section.mesh.cells_around],
        eigensolves=problem.free_solves + (0 if solution is None else solution.eigensolves),
        wall_time_s=wall_time_s,
        load_resolution=problem.load_resolution(mode.x.petsc_vec, load),
        timings={**problem.timings, "total_s": wall_time_s},
        mpi_size=problem.comm.size,
        method_chosen_by=method_chosen_by,
        details=ResultDetails(
            free_eigen_error=free.eigen.error, free_eigen_iterations=free.eigen.iterations
        ),
        input={"section": dataclasses.asdict(p)},
        versions=versions(),
        classical_stress_Pa=section.classical_stress(),
        compression_Pa=load * p.compression(),
        faces=_faces(section, load, None if solution is None else solution.active),
    )
    if solution is None or certificate is None:
        result.lower_bound_Pa = result.upper_bound_Pa = free.load
        return result
    record_contact(result, problem, solution, certificate)
    return result
