"""What a solve returns: :class:`BucklingResult`, typed records all the way down.

The result holds numbers, names and records (the certificate's, each edge's load, the
obstacle zones', the design output, the algorithm's record of its run), never a live
object: :mod:`.assemble` reads them off a live problem, ``results.files`` writes them. Its
JSON form (:meth:`BucklingResult.as_dict`) is ``msgspec.to_builtins`` of the records, with
non-finite numbers written as ``null`` and the algorithm's record flattened into
``details``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from msgspec import UNSET, Struct, UnsetType, to_builtins

from unibuckle_fenicsx.algorithms.records import ContinuedRecord, MethodDetails
from unibuckle_fenicsx.certificate.records import CopositivityRecord, SplitRecord
from unibuckle_fenicsx.design import (
    DesignRecord,
    effective_widths_text,
    limit_clause_text,
    significant,
)
from unibuckle_fenicsx.en1993 import ratio_text
from unibuckle_fenicsx.model.points import PointReport
from unibuckle_fenicsx.model.zones import ZoneReport
from unibuckle_fenicsx.section_design import SectionDesignRecord
from unibuckle_fenicsx.spec import UNITS, PointSpec
from unibuckle_fenicsx.spec.base import in_file
from unibuckle_fenicsx.spec.plate import reference_edge
from unibuckle_fenicsx.tolerances import BRACKET_GAP

__all__ = [
    "BucklingResult",
    "CertificateRecord",
    "ContactForce",
    "EdgeLoad",
    "ResultDetails",
    "coefficient_text",
    "jsonable",
    "verified_text",
]

#: An edge stress as a problem file writes it: a number, or [start, end] (linear).
Stress = float | list[float]


def coefficient_text(k: float | None) -> str:
    """A buckling coefficient for the summary: 4 decimals, or 4 significant digits below 0.1.

    Four decimals keep the digits of the usual k (0.43 to 100); a strut's k = (b/a)^2,
    9.104e-05 on a 2000 x 20 mm plate with free long edges, would read "0.0001", its one
    digit wrong.
    """
    if k is None:
        return "none"
    return f"{k:.4f}" if abs(k) >= 0.1 else significant(k)


class EdgeLoad(Struct, kw_only=True):
    """An edge's stresses per unit load (tension > 0), and its fixed part's (Pa)."""

    normal_stress: Stress
    shear_stress: Stress
    fixed_normal_stress: Stress | UnsetType = UNSET
    fixed_shear_stress: Stress | UnsetType = UNSET


class ContactForce(Struct, kw_only=True):
    """The obstacle's push on the plate at each contact node (the JSON's ``contact_force``).

    A linear buckling mode has no amplitude: the push is that of the mode scaled to
    max |w| = 1 m (the nodal force ``-(A u - lambda B u)_k``, in N per metre of the
    largest deflection).

    Attributes:
        unit: "N/m".
        push: The push at each contact node, in the order of ``contact_indices``.
        resolution: The push double precision cannot tell from zero (``load_resolution``
            times the largest nodal force of A u, N/m); a node whose push exceeds it
            *presses* the obstacle, the others only *touch* it (zero deflection, no
            force). None when the load's resolution is unknown.
    """

    unit: str = "N/m"
    push: list[float]
    resolution: float | None


class CertificateRecord(Struct, kw_only=True):
    r"""What was verified about the returned critical state (the JSON's ``certificate``).

    The record of a :class:`~unibuckle_fenicsx.certificate.certify.Certificate`; its
    fields mean what the certificate's attributes of the same names mean.

    Attributes:
        feasible: The mode does not cross the obstacle.
        feasibility_margin: Largest value off Z, relative to max|w|.
        max_contact_force: Largest force on Z, relative to :math:`\|Au\|_\infty`.
        max_contact_value: Largest |u| on Z, relative to max|w|.
        relative_residual: :math:`\|r\ \text{off}\ Z\|_2 / \|Au\|_2`.
        tolerance: :math:`\tau`.
        kkt: The KKT conditions hold.
        smallest_of_reduced: The load is the reduced pencil's smallest eigenvalue (None
            if not checked).
        lower_bound_Pa: Verified lower bound.
        upper_bound_Pa: Load of an admissible mode (None if none).
        relative_gap: (upper - lower) / upper (None if no upper bound).
        global_optimum_proven: The gap closes.
        proven_by: What gave the lower bound.
        status: proven, bracketed, kkt-only or not-kkt.
        negative_eigenvalues: m, pencil eigenvalues below the shifts tried.
        refuting_load_Pa: An admissible mode's lower load that refutes the returned one.
        copositivity: The copositivity certificate's record (None if it did not run).
        notes: What failed or was skipped, in words.
        split_route: The split bracket (two or more pencil eigenvalues below the load):
            "proven", "bracketed" or "not bracketed" when it ran, "skipped" when its
            estimated cost exceeded the default's limit, each with the estimate
            ("skipped: estimated cost 4.2 free solves > 3"); None when it did not apply.
    """

    feasible: bool
    feasibility_margin: float
    max_contact_force: float
    max_contact_value: float
    relative_residual: float
    tolerance: float
    kkt: bool
    smallest_of_reduced: bool | None
    lower_bound_Pa: float
    upper_bound_Pa: float
    relative_gap: float
    global_optimum_proven: bool
    proven_by: str
    status: str
    negative_eigenvalues: int | None
    refuting_load_Pa: float | None
    copositivity: CopositivityRecord | None
    notes: list[str]
    split_route: str | None = None


class ResultDetails(Struct, kw_only=True):
    """The JSON's ``details``: the free solve, the model's notes, the algorithm's record.

    Attributes:
        free_eigen_error: SLEPc's relative residual of the free pair.
        free_eigen_iterations: Its Krylov-Schur restarts.
        point_restraints: The point restraints on the mesh.
        gapped_obstacles: Why obstacles with a gap were left out.
        plate_model: The plate lies outside the plate model's usual range.
        run: The algorithm's record of its run (flattened into ``details`` in the
            JSON).
        lower_bound_by: What proves the algorithm's lower bound.
        continued: The continuations from a certificate's refuting modes.
    """

    free_eigen_error: float
    free_eigen_iterations: int
    point_restraints: list[PointReport] | UnsetType = UNSET
    gapped_obstacles: str | UnsetType = UNSET
    plate_model: str | UnsetType = UNSET
    run: MethodDetails | UnsetType = UNSET
    lower_bound_by: str | UnsetType = UNSET
    continued: list[ContinuedRecord] | UnsetType = UNSET


class BucklingResult(Struct, kw_only=True):
    """Critical state of one problem.

    Attributes:
        case: Problem name.
        method: The method that ran ("free", "enumerate", "active-set",
            "interior-point", "penalty", "foundation").
        route: The links that answered, in order (the method alone, or e.g.
            ["interior-point", "active-set-polish"]).
        critical_load_Pa: lambda, the critical compressive stress (Pa).
        free_load_Pa: lambda without obstacle (Pa).
        ratio_to_free: critical / free.
        critical_force_N_per_m: N = t sigma (N/m), sigma of ``buckling_coefficient_k`` at
            lambda (with a unit edge stress, t lambda); None for a temperature rise alone.
        buckling_coefficient_k: k = sigma t b^2 / (pi^2 D), sigma = lambda times the
            largest compressive edge stress per unit load (pure shear: the largest shear
            stress) and b the width it acts across
            (``PlateSpec.reference_load``); None when
            the scaled load is a temperature rise alone (lambda is then a factor on it).
        dofs: Global DOF count of (w, theta).
        mesh: [nx, ny] (a user-supplied or gmsh mesh: [number of cells]).
        eigensolves: Linear eigen solves, including the free one.
        wall_time_s: Wall time of the whole solve (set-up included).
        constrained_nodes: i, nodes in the closed obstacle zone with free deflection.
        contact_nodes: |Z|.
        p_star: Enumeration: the contact-set size where it stopped.
        contact_coordinates: Coordinates of Z, (|Z|, 2).
        contact_indices: Node numbers of Z (lexicographic (y, x) order of the zone).
        contact_dofs: Global W DOF indices of Z, in DOLFINx's numbering of the
            distributed mesh: they depend on the number of MPI ranks (its partition);
            ``contact_indices`` and ``contact_coordinates`` do not.
        load_resolution: How closely double precision fixes the critical load, relative
            to it (:meth:`~unibuckle_fenicsx.model.problem.Problem.load_resolution`);
            digits beyond it are rounding. None for a tensionless foundation (the
            springs' stiffness is not counted).
        lower_bound_Pa: Verified lower bound of the critical load (Pa): no admissible
            mode has a lower load.
        upper_bound_Pa: The load of an admissible mode (Pa), so an upper bound of the
            critical load; None if the method found none.
        certificate: The certificate's record (None without obstacle).
        details: The free solve, the model's notes, the algorithm's record.
        timings: Seconds per phase.
        mpi_size: Ranks used.
        method_chosen_by: Why this method ran ("given", or the "auto" rule's reason).
        edge_loads: Per edge, its normal and shear stress per unit load (tension > 0).
        critical_load_factor: lambda, the factor on the scaled part of the load (the
            same number as critical_load_Pa; with a fixed part, N = N_fixed + lambda
            N_scaled).
        critical_temperature_K: With a temperature rise in the scaled load: lambda times
            its largest rise over the plate (the uniform rise's critical value).
        critical_total_temperature_K: With a fixed temperature rise: the largest total
            rise over the plate at the critical state, the fixed rise (times
            ``fixed_factor``) plus lambda times the scaled one.
        design: With ``[design]``: EN 1993-1-5's quantities of this sigma_cr.
        units: The unit system the summary prints in (the numbers here are SI).
        input: The problem solved, every key with the value used, in SI (None for a
            predicate zone).
        versions: Versions of the package and of the libraries that computed the result.
        obstacle_zones: Per obstacle, the zone's area on the plate against the discrete
            zone's and its node count.
        contact_force: The obstacle's push at each contact node (:class:`ContactForce`);
            None without a rigid obstacle (a tensionless foundation's springs are not
            contact forces).
    """

    case: str
    method: str
    route: list[str]
    critical_load_Pa: float
    free_load_Pa: float
    ratio_to_free: float
    critical_force_N_per_m: float | None
    buckling_coefficient_k: float | None
    dofs: int
    mesh: list[int]
    eigensolves: int
    wall_time_s: float
    constrained_nodes: int = 0
    contact_nodes: int = 0
    p_star: int | None = None
    contact_coordinates: list[list[float]] = []
    contact_indices: list[int] = []
    contact_dofs: list[int] = []
    load_resolution: float | None = None
    lower_bound_Pa: float | None = None
    upper_bound_Pa: float | None = None
    certificate: CertificateRecord | None = None
    details: ResultDetails
    timings: dict[str, float] = {}
    mpi_size: int = 1
    method_chosen_by: str = ""
    edge_loads: dict[str, EdgeLoad] = {}
    critical_load_factor: float | None = None
    critical_temperature_K: float | None = None
    critical_total_temperature_K: float | None = None
    design: DesignRecord | SectionDesignRecord | None = None
    units: str = "SI"
    input: dict[str, object] | None = None
    versions: dict[str, str] = {}
    obstacle_zones: list[ZoneReport] = []
    contact_force: ContactForce | None = None

    @property
    def certified(self) -> bool:
        """No certificate (the free load, verified the smallest), or one not "not-kkt".

        A KKT point whose inertia shows a lower eigenvalue of its reduced pencil is no
        critical state (``Certificate.status``).
        """
        return self.certificate is None or self.certificate.status != "not-kkt"

    def as_dict(self, timings: bool = True) -> dict[str, object]:
        """JSON-ready mapping (non-finite floats become ``null``: JSON has no infinity).

        The fields in their order, ``details`` holding the algorithm's record's fields
        after the free solve's and the model's.

        Args:
            timings: Keep the wall times (``*_s`` and ``seconds`` keys, the latter in
                the interior point's level records; ``timings``) and the "auto" rule's
                reason, which quotes a timed solve; without them the mapping is the same
                on every run (for files kept under version control).
        """
        data = jsonable(self)
        details = data["details"]
        data["details"] = {
            k: v for key, value in details.items() for k, v in _flat(key, value).items()
        }
        return data if timings else _without_timings(data)

    def summary(self) -> str:
        """Lines for the terminal: the result, the load it is a multiple of, the model."""
        scale, unit = UNITS[self.units][1:]
        z = ""
        if self.method == "free" and not self.constrained_nodes:
            # No node held: the pencil's smallest eigenpair, checked (analysis.solve).
            springs = "; free: with the bilateral foundation" if self._bilateral() else ""
            z = f"  proven=yes (the smallest eigenvalue, by an LDL^T inertia count{springs})"
        if self.constrained_nodes:
            cert = self.certificate
            z = (
                f"  i={self.constrained_nodes} |Z|={self.contact_nodes}"
                f"  KKT={'yes' if cert is not None and cert.kkt else 'NO'}  {verified_text(cert)}"
            )
        loaded = [
            f"{name} {_load_text(load)}"
            for name, load in self.edge_loads.items()
            if _load_text(load)
        ]
        bound = self._bound_line(scale, unit)
        bound = f"\n  {bound}" if bound else ""
        extra = "".join(f"\n  {line}" for line in self._model_lines())
        extra += "".join(f"\n  {text}" for text in map(_zone_text, self.obstacle_zones) if text)
        if loaded:
            head = (
                f"lambda_c = {self.critical_load_Pa / scale:.6e} {unit} "
                f"({self.critical_load_Pa / self.free_load_Pa:.4f} x free "
                f"{self.free_load_Pa / scale:.6e} {unit}), "
                f"k = {coefficient_text(self.buckling_coefficient_k)}"
            )
            if self._fixed_parts(scale, unit):  # k's sigma is lambda_c's alone
                head += " (of the scaled load alone, the fixed load not in it)"
            second = f"\n  edge stress per unit lambda (tension > 0): {'; '.join(loaded)}"
            second += self._stress_line(scale, unit)
        else:  # a temperature rise alone is scaled: lambda is a factor on it
            head = (
                f"lambda_c = {self.critical_load_Pa:.6e} (factor on the temperature rise; "
                f"{self.critical_load_Pa / self.free_load_Pa:.4f} x free "
                f"{self.free_load_Pa:.6e})"
            )
            second = ""
        return (
            f"{self.case}: {head}, method {self.method}{z}, "
            f"{self.eigensolves} eigensolves, {self.wall_time_s:.2f} s{bound}{second}{extra}"
        )

    def _bilateral(self) -> bool:
        """Whether the problem has a bilateral foundation (its springs are in the free pencil)."""
        tables = [self._input_table("obstacle")]
        listed = (self.input or {}).get("obstacles")
        tables += [t for t in listed if isinstance(t, dict)] if isinstance(listed, list) else []
        return any(t.get("foundation_stiffness") and t.get("side") == "both" for t in tables)

    def _stress_line(self, scale: float, unit: str) -> str:
        """The critical edge stress when the edge stress per unit lambda is not 1 ('' else).

        lambda_c is printed in the stress's unit because with a unit edge stress it is the
        critical stress; with an edge stress of -100 per unit lambda, lambda_c = 8.2 MPa
        means an edge stress of 820 MPa at buckling, which this line says: k's sigma,
        lambda_c times the largest compressive edge stress per unit lambda (without one,
        the largest shear stress).
        """
        reference = _reference_stress(self.edge_loads)
        if reference is None or math.isclose(reference[0], 1.0, rel_tol=1e-12):
            return ""
        value, kind = reference
        sigma = self.critical_load_Pa * value / scale
        return (
            f"\n  critical edge stress: lambda_c x {value:g} = {sigma:.6e} {unit} (the largest "
            f"{kind} edge stress at lambda_c; k's sigma)"
        )

    def _bound_line(
        self,
        scale: float,
        unit: str,
        *,
        what: str = "critical load",
        free: str = "the free plate's",
        ratio: float = 1.0,
        bracket: bool = True,
    ) -> str:
        """Where the critical load lies when it is not proven: the verified bracket.

        The printed load is that of an admissible mode, so the critical load is at most
        it; the verified lower bound is the safe value (the free plate's load when nothing
        closer was verified; ``--bracket`` may raise it). Empty when proven. ``what``,
        ``free`` and ``ratio`` (the printed stress per unit load): a section's words and
        its extreme fibre's stress; ``bracket``: whether the problem takes ``--bracket``
        (a section refuses it: no hint of it).
        """
        cert = self.certificate
        if not self.constrained_nodes or cert is None or cert.global_optimum_proven:
            return ""
        lower, upper = self.lower_bound_Pa, self.upper_bound_Pa
        if lower is None:
            return ""
        by = cert.proven_by
        how = f"{free}, by interlacing" if by == "interlacing" else f"by {by}"
        high = "no admissible mode" if upper is None else f"{upper * ratio / scale:.6e} {unit}"
        # Two or more pencil eigenvalues below: only the low-rank bracket may do better.
        m = cert.negative_eigenvalues
        hint = ""
        if bracket and by == "interlacing" and m is not None and m >= 2:
            tried = self._input_table("solver").get("bracket")
            hint = "; --bracket verified no higher bound" if tried else "; --bracket may raise it"
        return (
            f"not proven: the {what} lies between {lower * ratio / scale:.6e} {unit} "
            f"(verified lower bound, {how}) and {high}{hint}"
        )

    def _input_table(self, key: str) -> dict[str, object]:
        """The table ``key`` of the problem solved, as its file writes it (empty if absent)."""
        table = (self.input or {}).get(key)
        return table if isinstance(table, dict) else {}

    def _fixed_parts(self, scale: float, unit: str) -> list[str]:
        """The fixed load's parts applied (edges, a temperature rise), as the summary says them.

        Empty without a fixed load, or with ``load.fixed_factor = 0``: then k and the
        design's k_sigma describe the same stresses.
        """
        load = self._input_table("load")
        fixed = [
            f"{name} {_load_text(edge, True, scale, ' ' + unit)}"
            for name, edge in self.edge_loads.items()
            if not isinstance(edge.fixed_normal_stress, UnsetType)
        ]
        if load.get("fixed_temperature"):
            fixed.append(f"temperature rise {_rise_text(load['fixed_temperature'], self.units)}")
        return fixed if load.get("fixed_factor", 1.0) else []

    def _model_lines(self) -> list[str]:
        """Summary lines of what the model holds beyond plate, edges and obstacle."""
        length, scale, unit = UNITS[self.units]
        lines = []
        if isinstance(self.details.gapped_obstacles, str):
            lines.append(self.details.gapped_obstacles)
        load = self._input_table("load")
        if self.critical_temperature_K is not None:
            rise = _rise_text(load.get("temperature"), self.units)
            lines.append(
                f"temperature rise per unit lambda {rise}: critical rise "
                f"{self.critical_temperature_K:.6g} K"
            )
        fixed = self._fixed_parts(scale, unit)
        if self.critical_total_temperature_K is not None:
            lines.append(
                "total temperature rise at the critical state (the fixed rise and lambda "
                f"times the scaled one): {self.critical_total_temperature_K:.6g} K"
            )
        if isinstance(self.design, DesignRecord):
            lines.append(
                _design_line(
                    self.design,
                    scale,
                    unit,
                    (length, "m" if self.units == "SI" else "mm"),
                    fixed=bool(fixed),
                )
            )
        factor = load.get("fixed_factor", 1.0)
        if fixed:
            times = "" if factor == 1.0 else f"{factor:g} x "
            lines.append(f"fixed load (applied as is): {times}{'; '.join(fixed)}")
        reports = self.details.point_restraints
        reports = [] if isinstance(reports, UnsetType) else reports
        name = "m" if self.units == "SI" else "mm"
        for p, restraint in zip(reports, self._point_restraints(reports), strict=True):
            lines.append(
                f"points: {restraint}: {p.points} points on {p.nodes} nodes, "
                f"largest snap distance {p.max_snap_distance_m / length:.3g} {name}"
                + _idle_text(p.restraining_nothing, length, name)
            )
        return lines

    def _point_restraints(self, reports: list[PointReport]) -> list[str]:
        """Each point restraint described in the summary's units (the JSON's are SI)."""
        tables = (self.input or {}).get("points")
        if self.units == "SI" or not isinstance(tables, list) or len(tables) != len(reports):
            return [p.restraint for p in reports]
        return [PointSpec(**table).describe(self.units) for table in tables]


def _idle_text(idle: list[list[float]], length: float, name: str) -> str:
    """The summary's words on points that restrain nothing ('' if none)."""
    if not idle:
        return ""
    shown = ", ".join(f"({x / length:g}, {y / length:g})" for x, y in idle[:3])
    return (
        f"; {len(idle)} on a node held already (by an edge support or a bilateral point), "
        f"restraining nothing: {shown}" + (", ..." if len(idle) > 3 else "") + f" {name}"
    )


def _design_line(
    d: DesignRecord,
    scale: float,
    unit: str,
    lengths: tuple[float, str] = (1.0, "m"),
    fixed: bool = False,
) -> str:
    """The summary line of the design output (lengths in ``lengths[1]``, m / ``lengths[0]``).

    ``fixed``: the load has a fixed part, which sigma_cr includes and the first line's k
    does not: the line then gives k_sigma = sigma_cr/sigma_E, which includes it too.
    """
    rho = d.reduction_factor
    reduced = d.reduced_design_stress_Pa
    if d.relative_slenderness is None:  # the loaded edges in tension at the critical state
        return (
            f"EN 1993-1-5: no compression on the loaded edges at the critical state (least "
            f"tension {significant(-d.sigma_cr_Pa / scale)} {unit}, {d.edge}): no sigma_cr, "
            "slenderness or rho" + _design_lower(d, scale, unit)
        )
    column = ""
    if d.xi is not None and d.xi < 1.0:
        column = (
            f" (column-type: plate {significant(d.plate_reduction_factor)}, chi_c "
            f"{significant(d.column_reduction_factor)}, xi {ratio_text(d.xi)})"
        )
    elif d.xi is not None:
        column = f" (column-type: xi {ratio_text(d.xi)}, the plate's)"
    elif d.column_critical_stress_Pa == 0.0:
        column = " (column-type: none, the column a mechanism; the plate's)"
    return (
        f"EN 1993-1-5: sigma_cr = {significant(d.sigma_cr_Pa / scale)} {unit} ({d.edge}"
        + (
            f", the fixed load included: k_sigma = {coefficient_text(d.k_sigma)}"
            if fixed and d.k_sigma is not None
            else ""
        )
        + "), "
        f"psi = {ratio_text(d.psi)}, slenderness {significant(d.relative_slenderness)}, rho = "
        + (
            f"{significant(rho)}"
            + column
            + f", rho f_y/{d.partial_factor_name} = {significant(reduced / scale)} {unit}"
            + effective_widths_text(d, *lengths)
            if rho is not None and isinstance(reduced, float)
            else f"none (psi outside {d.table})"
        )
        + _tension_text(d, scale, unit)
        + f"; {d.element} element"
        + (f" (free edge {d.free_edge})" if d.free_edge else "")
        + f"; {_design_clauses(d)}; rho calibrated on bilateral plates"
        + _design_lower(d, scale, unit)
    )


def _tension_text(d: DesignRecord, scale: float, unit: str) -> str:
    """The design line's words when the tension edge yields before rho f_y/gamma_M ('' if not)."""
    if not d.tension_yield_first:
        return ""
    return (
        f"; the tension edge yields first (EN 1993-1-1 6.2.1(5): "
        f"{significant((d.tension_Pa or 0.0) / scale)} {unit} of tension at sigma_cr), at "
        f"sigma_1 = {significant((d.sigma_1_at_tension_yield_Pa or 0.0) / scale)} {unit}: "
        "yield governs, not rho"
    )


def _design_clauses(d: DesignRecord) -> str:
    """Where each number of the design line comes from in EN 1993-1-5 (JSON: ``clauses``)."""
    table = d.table.split(" (")[0]  # "Table 4.1 (internal compression element)"
    if d.element == "outstand":  # the row: "larger compression at the free edge"
        table += f" ({d.table.split(', ')[-1].rstrip(')')})"
    rho = "eq. (4.3)" if d.element == "outstand" else "eq. (4.2)"
    column = ", rho_c 4.5.4(1)" if d.xi is not None and d.xi < 1.0 else ""
    return (
        f"psi {table}, slenderness 4.4(2), rho 4.4(2) {rho}{column}"
        + limit_clause_text(d.partial_factor_name, d.stress_limit_clause)
        + (f", b_eff {d.effective_widths_row}" if d.effective_widths_row else "")
    )


def _design_lower(d: DesignRecord, scale: float, unit: str) -> str:
    """The design line's part at the verified lower bound, when not proven."""
    low = d.lower_bound
    if not isinstance(low, DesignRecord):
        return ""
    rho = significant(low.reduction_factor)
    if low.relative_slenderness is None:
        return "\n  EN 1993-1-5 at the verified lower bound: no compression on the loaded edges"
    reduced = low.reduced_design_stress_Pa
    limit = (
        f", rho f_y/{low.partial_factor_name} = {significant(reduced / scale)} {unit}"
        if isinstance(reduced, float)
        else ""
    )
    return (
        f"\n  EN 1993-1-5 at the verified lower bound (the safe value, sigma_cr not proven "
        f"the lowest): sigma_cr = {significant(low.sigma_cr_Pa / scale)} {unit}, slenderness "
        f"{significant(low.relative_slenderness)}, rho = {rho}{limit}"
        + _tension_text(low, scale, unit)
    )


def _gap_text(gap: float) -> str:
    """The relative gap rounded up to one significant digit: 8.1e-05 -> "9e-05"."""
    if gap <= 0:
        return "0"
    exponent = math.floor(math.log10(gap))
    digit = math.ceil(round(gap / 10.0**exponent, 9))
    if digit >= 10:
        digit, exponent = 1, exponent + 1
    return f"{digit}e{exponent:+03d}"


def verified_text(cert: CertificateRecord | None) -> str:
    """What the certificate verified, as the summary's first line says it (None: KKT only)."""
    if cert is None:
        return "proven=no (KKT only)"
    m = cert.negative_eigenvalues
    below = f", m={m}" if m is not None else ""
    gap = cert.relative_gap
    if cert.global_optimum_proven:
        return f"proven=yes ({cert.proven_by}, gap {float(gap or 0):.1e}{below})"
    if cert.status == "bracketed" and isinstance(gap, float):
        return f"proven=no, bracketed to {_gap_text(gap)} ({cert.proven_by}{below})"
    refuted = cert.refuting_load_Pa
    if refuted is not None:
        return f"proven=no, refuted: an admissible mode has {refuted:.6e} Pa"
    if cert.status == "not-kkt":  # not even a critical state: not "KKT only"
        return f"proven=no (not a KKT point{below})"
    if cert.split_route is not None and cert.split_route.startswith("skipped"):
        return (
            f"proven=no (KKT only{below}; not bracketed by default here: split bracket "
            f"{cert.split_route}, --bracket runs it)"
        )
    if cert.split_route is not None and cert.split_route.startswith("not bracketed"):
        # It ran (by default or on request): say what it verified, not only what it did not.
        if cert.proven_by == "split-spn" and isinstance(gap, float):
            return (
                f"proven=no (KKT only{below}; the split bracket verified a gap of "
                f"{gap:.1e}, above the {BRACKET_GAP:.0e} of 'bracketed')"
            )
        return f"proven=no (KKT only{below}; the split bracket verified no higher bound)"
    if cert.split_route is not None:
        return f"proven=no (KKT only{below}; split bracket {cert.split_route})"
    return f"proven=no (KKT only{below})"


def split_route(status: str, proven_by: str, split: SplitRecord | None) -> str | None:
    """What the split bracket did, with its estimated cost (None if it did not apply).

    ``status`` and ``proven_by``: the certificate's; ``split``: the route's record.
    """
    if split is None or split.estimated_cost is None:
        return None
    cost = f"estimated cost {split.estimated_cost:.1f} free solves"
    if split.skipped:
        limit = "" if split.cost_limit is None else f" > {split.cost_limit:g}"
        return f"skipped: {cost}{limit}"
    if proven_by == "split-spn" and status in ("proven", "bracketed"):
        return f"{status} ({cost})"
    return f"not bracketed ({cost})"


def _zone_text(zone: ZoneReport) -> str:
    """A line on a discrete zone that differs from its zone by more than 1e-6, or ''."""
    area, discrete = zone.area_m2, zone.discrete_area_m2
    if area is None or area <= 0.0 or abs(discrete - area) <= 1e-6 * area:
        return ""
    return (
        f"{zone.obstacle} zone on the mesh: the cells with every node in it cover "
        f"{discrete / area:.2%} of its area ({zone.nodes} nodes); the obstacle acts on "
        "the mesh nodes in the zone"
    )


def _reference_stress(loads: dict[str, EdgeLoad]) -> tuple[float, str] | None:
    """The reference stress of k per unit load and its kind (``compressive`` or ``shear``).

    :func:`~unibuckle_fenicsx.spec.plate.reference_edge` on the loaded edges; None when
    they carry no compression and no shear.
    """

    def ends(value: Stress) -> list[float]:
        return [float(v) for v in value] if isinstance(value, list | tuple) else [float(value)]

    loaded = [
        (ends(e.normal_stress), ends(e.shear_stress))
        for e in loads.values()
        if any(v != 0.0 for v in (*ends(e.normal_stress), *ends(e.shear_stress)))
    ]
    if not loaded:
        return None
    _, value, kind = reference_edge([n for n, _ in loaded], [s for _, s in loaded])
    return (value, kind) if value > 0.0 else None


def _rise_text(value: object, units: str) -> str:
    """A temperature rise of the input (SI: K, or [T0, dT/dx, dT/dy] in K, K/m) in ``units``.

    The input echoed is in SI; the summary speaks the file's units, where a gradient of
    0.01 K/mm is 10 K/m.
    """
    shown, name = in_file(value, "K, K/m", units)
    if isinstance(shown, list | tuple):
        return f"[{', '.join(f'{v:g}' for v in shown)}] ({name})"
    return f"{shown:g} K" if isinstance(shown, int | float) else f"{shown} K"


def _load_text(load: EdgeLoad, fixed: bool = False, scale: float = 1.0, unit: str = "") -> str:
    """The edge stresses of ``load`` (``fixed``: its fixed ones, in ``unit``)."""
    parts = []
    values = (
        (load.fixed_normal_stress, load.fixed_shear_stress)
        if fixed
        else (load.normal_stress, load.shear_stress)
    )
    for key, value in zip(("normal", "shear"), values, strict=True):
        if isinstance(value, list | tuple):
            if any(value):
                parts.append(f"{key} {value[0] / scale:g} to {value[1] / scale:g}{unit} (linear)")
        elif isinstance(value, float | int) and value:
            parts.append(f"{key} {value / scale:g}{unit}")
    return ", ".join(parts)


def jsonable(record: Any) -> Any:
    """A record (or any mapping or list of them) as JSON-ready builtins, null for non-finite."""
    return _finite(to_builtins(record, enc_hook=_numpy))


def _flat(key: str, value: Any) -> dict[str, object]:
    """A ``details`` entry as the JSON's keys: the algorithm's record spread out."""
    return value if key == "run" else {key: value}


def _numpy(obj: Any) -> Any:
    """NumPy scalars and arrays as Python numbers and lists (``to_builtins``'s hook)."""
    if isinstance(obj, np.generic | np.ndarray):
        return obj.tolist()
    raise NotImplementedError(f"{type(obj).__name__} has no JSON form")


def _finite(obj: Any) -> Any:
    """Non-finite floats as None: JSON has no infinity (an upper bound with no mode)."""
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_finite(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def _without_timings(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {
            k: _without_timings(v)
            for k, v in obj.items()
            if not (k.endswith("_s") or k in ("timings", "method_chosen_by", "seconds"))
        }
    if isinstance(obj, list):
        return [_without_timings(v) for v in obj]
    return obj
