"""BucklingResult: what a solve returns and its JSON form (files: :mod:`unibuckle_fenicsx.io`)."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.model.zones import zone_report
from unibuckle_fenicsx.spec import (
    UNITS,
    PointSpec,
    ProblemSpec,
    problem_to_dict,
    stress_value,
    temperature_field,
)
from unibuckle_fenicsx.spec.checks import plate_model_note

if TYPE_CHECKING:  # pragma: no cover
    from unibuckle_fenicsx.algorithms import UnilateralSolution
    from unibuckle_fenicsx.certificate.certify import Certificate
    from unibuckle_fenicsx.model.problem import BucklingProblem, Mode

__all__ = ["RECORD_DIGITS", "BucklingResult", "record", "rounded", "versions"]

#: Significant digits of the numbers a record keeps (:func:`record`): the loads carry
#: about ten (the eigen solver's tolerance, 1e-10) and double precision fixes them to
#: 1e-13 on the paper's plate, 1e-9 to 1e-8 on thin ones (``load_resolution``); mode
#: values about eight. Eight keeps what every quantity carries and drops its rounding.
RECORD_DIGITS = 8
#: What a record leaves out: what depends on the machine (its BLAS kernels and threads,
#: the rank count, the clock), not on the problem. The algorithm's path (counts of eigen
#: solves and factorisations, the sets and loads it visited: on symmetric or thin
#: plates rounding decides between contact sets of equal load), round-off diagnostics
#: (residuals, margins, the load's resolution), times, versions, the rank count and the
#: partition's DOF numbering.
RUN_DEPENDENT = frozenset(
    {
        "eigensolves", "details", "timings", "wall_time_s", "method_chosen_by", "versions",
        "mpi_size", "contact_dofs", "load_resolution", "rejected_steps", "solves_cold",
        "solves_warm", "max_free_residual", "max_complementarity", "max_zone_w_m",
        "free_eigen_error", "free_eigen_iterations",
    }
)  # fmt: skip
#: Of a certificate, the verdict (its margins and residuals are round-off).
CERTIFICATE_VERDICT = (
    "feasible", "kkt", "smallest_of_reduced", "global_optimum_proven", "proven_by", "status",
    "negative_eigenvalues", "tolerance",
)  # fmt: skip
#: The contact set's keys, left out of a record with ``contact=False`` (the contact
#: force lists its pushes in the order of the set).
CONTACT_KEYS = ("contact_nodes", "contact_coordinates", "contact_indices", "contact_force")


def record(data: Any, *, contact: bool = True) -> Any:
    """``data`` (a result's JSON mapping, or any JSON value) as a record for version control.

    The same on every machine up to its last digit: the keys of :data:`RUN_DEPENDENT`
    left out at any depth, a certificate reduced to its verdict
    (:data:`CERTIFICATE_VERDICT`), every number rounded to :data:`RECORD_DIGITS`
    significant digits, those of a list of numbers to the digits of its largest (a
    coordinate's rounding, 3e-19 beside 0.1, is then 0). A number that lies within its
    noise of a rounding boundary may still change its last digit between machines.

    Args:
        data: A JSON value (``BucklingResult.as_dict()``, a sweep's line, a demo's summary).
        contact: Keep the contact set; on thin plates nodes with both a zero deflection
            and a zero contact force (DESIGN: degenerate complementarity) fall in or out
            of it with rounding, at the same load: ``False`` leaves it out.
    """
    if isinstance(data, dict):
        out = {}
        for key, value in data.items():
            if key in RUN_DEPENDENT or (not contact and key in CONTACT_KEYS):
                continue
            if key == "certificate" and isinstance(value, dict):
                value = {k: value[k] for k in CERTIFICATE_VERDICT if k in value}
            out[key] = record(value, contact=contact)
        return out
    if isinstance(data, list | tuple):
        numbers = [v for v in data if isinstance(v, float)]
        if numbers and len(numbers) == len(data):
            return [_rounded(v, max(abs(x) for x in numbers)) for v in numbers]
        return [record(v, contact=contact) for v in data]
    if isinstance(data, float):
        return _rounded(data, abs(data))
    return data


def rounded(values: Any) -> npt.NDArray[np.float64]:
    """``values`` (an array) to :data:`RECORD_DIGITS` significant digits of the largest.

    What a figure draws: an antialiased line moves a pixel's shade for a change of
    1e-13 in its data, so a figure of the full numbers differs between machines where
    one of the rounded numbers does not.
    """
    array = np.asarray(values, dtype=float)
    finite = np.abs(array[np.isfinite(array)])
    scale = float(finite.max()) if finite.size else 0.0
    if scale == 0.0:
        return array
    return np.round(array, _decimals(scale)) + 0.0


def _decimals(scale: float) -> int:
    """Decimals that keep :data:`RECORD_DIGITS` significant digits of ``scale`` (> 0).

    Of ``scale`` itself at those digits: a normalised mode's largest value is 1 within
    rounding, 0.9999999999997 on one machine and 1.0000000000002 on another, and both
    must give the same decimals.
    """
    return RECORD_DIGITS - 1 - math.floor(math.log10(float(f"{scale:.{RECORD_DIGITS - 1}e}")))


def _rounded(value: float, scale: float) -> float:
    """``value`` to :data:`RECORD_DIGITS` significant digits of ``scale`` (0.0 for -0.0)."""
    if not math.isfinite(value) or scale == 0.0:
        return value
    return round(value, _decimals(scale)) + 0.0


@dataclass
class BucklingResult:
    """Critical state of one problem (JSON-ready fields only).

    Attributes:
        case: Problem name.
        method: Algorithm used ("free", "enumerate", "active-set", "penalty").
        critical_load_Pa: lambda, the critical compressive stress (Pa).
        free_load_Pa: lambda without obstacle (Pa).
        ratio_to_free: critical / free.
        critical_force_N_per_m: N = t lambda.
        buckling_coefficient_k: k = N b^2 / (pi^2 D), b = plate width; None when the
            scaled load is a temperature rise alone (lambda is then a factor on it).
        dofs: Global DOF count of (w, theta).
        mesh: [nx, ny] (a user-supplied or gmsh mesh: [number of cells]).
        eigensolves: Linear eigen solves, including the free one.
        wall_time_s: Wall time of the whole solve (set-up included).
        constrained_nodes: i, nodes in the closed obstacle zone with free deflection.
        contact_nodes: |Z|.
        p_star: Enumeration: the contact-set size where it stopped.
        contact_coordinates: Coordinates of Z, (|Z|, 2).
        contact_indices: Node numbers of Z (lexicographic (y, x) order of the zone).
        contact_dofs: Global W DOF indices of Z (partition-dependent numbering).
        load_resolution: How closely double precision fixes the critical load, relative
            to it (:meth:`~unibuckle_fenicsx.model.problem.BucklingProblem.load_resolution`:
            1e-9 to 1e-8 on thin plates, where the shear stiffness dominates; digits beyond
            it are rounding). None for a tensionless foundation (the springs' stiffness is
            not counted).
        lower_bound_Pa: Verified lower bound of the critical load (Pa): no admissible
            mode has a lower load.
        upper_bound_Pa: The load of an admissible mode (Pa), so an upper bound of the
            critical load; None if the method found none.
        certificate: :class:`~unibuckle_fenicsx.certificate.certify.Certificate` as a dict.
        details: Method-specific information.
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
        design: With ``[design]``: the relative slenderness and the reduction factor of
            EN 1993-1-5 from this sigma_cr (:func:`~unibuckle_fenicsx.design.design_output`).
        units: The unit system the summary prints in (the numbers here are SI).
        input: The problem solved, every key with the value used, in SI
            (:func:`~unibuckle_fenicsx.spec.problem_to_dict`; None for a predicate zone).
        versions: Versions of the package and of the libraries that computed the result
            (:func:`versions`).
        obstacle_zones: Per obstacle, the zone's area on the plate against the discrete
            zone's and its node count (:func:`~unibuckle_fenicsx.model.zones.zone_report`).
        contact_force: The obstacle's push on the plate at each contact node, in the
            order of ``contact_indices``: ``{"unit": "N/m", "push": [...],
            "resolution": r}``. A linear buckling mode has no amplitude: the push is that
            of the mode scaled to max |w| = 1 m (the nodal force ``-(A u - lambda B u)_k``,
            in N per metre of the largest deflection). ``resolution``: the push double
            precision cannot tell from zero (``load_resolution`` times the largest nodal
            force of A u, N/m); a node whose push exceeds it *presses* the obstacle, the
            others only *touch* it (zero deflection, no force). None without a rigid
            obstacle (a tensionless foundation's springs are not contact forces).
    """

    case: str
    method: str
    critical_load_Pa: float
    free_load_Pa: float
    ratio_to_free: float
    critical_force_N_per_m: float
    buckling_coefficient_k: float | None
    dofs: int
    mesh: list[int]
    eigensolves: int
    wall_time_s: float
    constrained_nodes: int = 0
    contact_nodes: int = 0
    p_star: int | None = None
    contact_coordinates: list[list[float]] = field(default_factory=list)
    contact_indices: list[int] = field(default_factory=list)
    contact_dofs: list[int] = field(default_factory=list)
    load_resolution: float | None = None
    lower_bound_Pa: float | None = None
    upper_bound_Pa: float | None = None
    certificate: dict[str, Any] | None = None
    details: dict[str, Any] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)
    mpi_size: int = 1
    method_chosen_by: str = ""
    edge_loads: dict[str, dict[str, Any]] = field(default_factory=dict)
    critical_load_factor: float | None = None
    critical_temperature_K: float | None = None
    critical_total_temperature_K: float | None = None
    design: dict[str, Any] | None = None
    units: str = "SI"
    input: dict[str, Any] | None = None
    versions: dict[str, str] = field(default_factory=dict)
    obstacle_zones: list[dict[str, Any]] = field(default_factory=list)
    contact_force: dict[str, Any] | None = None

    @classmethod
    def from_solution(
        cls,
        problem: BucklingProblem,
        free: Mode,
        solution: UnilateralSolution | None,
        certificate: Certificate | None,
        *,
        method: str,
        wall_time_s: float,
        mpi_size: int,
    ) -> BucklingResult:
        """Assemble the result of ``problem``'s free mode and unilateral ``solution``.

        Note:
            Collective on the problem's communicator (gathers the contact DOFs).
        """
        spec = problem.spec
        load = free.load if solution is None else solution.load
        result = cls(
            case=spec.name,
            method=method,
            critical_load_Pa=load,
            free_load_Pa=free.load,
            ratio_to_free=load / free.load,
            critical_force_N_per_m=spec.plate.thickness * load,
            # k is a buckling coefficient of edge loads: none for a rise alone.
            buckling_coefficient_k=(
                problem.buckling_coefficient(load) if spec.plate.loaded else None
            ),
            dofs=problem.model.num_dofs,
            mesh=(
                [problem.mesh.topology.index_map(2).size_global]
                if not problem.structured
                else [spec.mesh.nx, spec.mesh.ny]
            ),
            eigensolves=1 + (0 if solution is None else solution.eigensolves),
            wall_time_s=wall_time_s,
            timings={**problem.timings, "total_s": wall_time_s},
            mpi_size=mpi_size,
            details={
                "free_eigen_error": free.eigen.error,
                "free_eigen_iterations": free.eigen.iterations,
            },
            edge_loads={
                e.name: {
                    "normal_stress": stress_value(e.normal_stress),
                    "shear_stress": stress_value(e.shear_stress),
                }
                | (
                    {
                        "fixed_normal_stress": stress_value(e.fixed_normal_stress),
                        "fixed_shear_stress": stress_value(e.fixed_shear_stress),
                    }
                    if e.fixed_loaded
                    else {}
                )
                for e in spec.plate.edges
            },
            critical_load_factor=load,
            critical_temperature_K=_critical_temperature(spec, load),
            critical_total_temperature_K=_total_temperature(spec, load),
            units=spec.units,
            input=_input(spec),
            versions=versions(),
        )
        if not problem.tensionless:
            mode = free.function if solution is None else solution.candidate.mode
            result.load_resolution = problem.load_resolution(mode.x.petsc_vec, load)
        if problem.model.points:
            result.details["point_restraints"] = [g.report() for g in problem.model.points]
        if spec.gapped_obstacles:
            result.details["gapped_obstacles"] = (
                f"{len(spec.gapped_obstacles)} obstacle(s) with a gap left out of the linear "
                "critical state (an infinitesimal buckle does not reach them); unibuckle "
                "nonlinear follows the plate onto them"
            )
        if spec.design is not None:
            from unibuckle_fenicsx.design import design_output

            result.design = design_output(spec, spec.design, load)
        note = plate_model_note(spec.plate)
        if note is not None:
            result.details["plate_model"] = note
        if spec.all_obstacles:
            labels = [spec.obstacle_label(k) for k in range(len(spec.all_obstacles))]
            result.obstacle_zones = zone_report(
                problem.mesh, spec.all_obstacles, spec.plate, labels
            )
        if solution is None or certificate is None:
            result.lower_bound_Pa = result.upper_bound_Pa = free.load
            return result
        result.record_contact(problem, solution, certificate)
        return result

    def record_contact(
        self, problem: BucklingProblem, solution: UnilateralSolution, certificate: Certificate
    ) -> None:
        """Fill in the contact set, the bracket, the certificate and the contact forces.

        Note:
            Collective on the problem's communicator (gathers the contact DOFs).
        """
        contact = problem.contact
        if contact is None:
            raise ValueError(
                "record_contact: the problem has no obstacle (this needs an obstacle zone)"
            )
        active = solution.active
        rows = contact.removed_rows(active)
        self.constrained_nodes = problem.num_constrained
        self.contact_nodes = len(active)
        self.p_star = solution.p_star
        self.contact_indices = [int(k) for k in active]
        self.contact_coordinates = contact.coordinates[active].tolist()
        self.contact_dofs = sorted(
            int(r) for part in problem.comm.allgather(rows.tolist()) for r in part
        )
        self.lower_bound_Pa = certificate.lower_bound
        self.upper_bound_Pa = (
            certificate.upper_bound if math.isfinite(certificate.upper_bound) else None
        )
        self.certificate = certificate.as_dict()
        self.details.update(solution.report())
        if not problem.tensionless:
            self.contact_force = _contact_force(problem, solution, self.load_resolution)

    def as_dict(self, timings: bool = True) -> dict[str, Any]:
        """JSON-ready mapping (non-finite floats become ``null``: JSON has no infinity).

        Args:
            timings: Keep the wall times (``*_s`` and ``seconds`` keys, the latter in
                the interior point's level records; ``timings``) and the "auto" rule's
                reason, which quotes a measured time; without them the mapping is the same
                on every run (for files kept under version control).
        """
        data = _jsonable(asdict(self))
        return data if timings else _without_timings(data)

    def summary(self) -> str:
        """Lines for the terminal: the result, the load it is a multiple of, the model."""
        scale, unit = UNITS[self.units][1:]
        z = ""
        if self.constrained_nodes:
            cert = self.certificate or {}
            z = (
                f"  i={self.constrained_nodes} |Z|={self.contact_nodes}"
                f"  KKT={'yes' if cert.get('kkt') else 'NO'}  {_verified(cert)}"
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
                f"k = {self.buckling_coefficient_k:.4f}"
            )
            second = f"\n  edge stress per unit lambda (tension > 0): {'; '.join(loaded)}"
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

    def _bound_line(self, scale: float, unit: str) -> str:
        """Where the critical load lies when it is not proven: the verified bracket.

        The printed load is that of an admissible mode, so the critical load is at most
        it; the verified lower bound is the safe value (the free plate's load when nothing
        closer was verified; ``--bracket`` may raise it). Empty when proven.
        """
        cert = self.certificate or {}
        if not self.constrained_nodes or cert.get("global_optimum_proven"):
            return ""
        lower, upper = self.lower_bound_Pa, self.upper_bound_Pa
        if lower is None:
            return ""
        by = cert.get("proven_by")
        how = "the free plate's, by interlacing" if by == "interlacing" else f"by {by}"
        high = "no admissible mode" if upper is None else f"{upper / scale:.6e} {unit}"
        # Two or more pencil eigenvalues below: only the low-rank bracket may do better.
        m = cert.get("negative_eigenvalues")
        hint = ""
        if by == "interlacing" and m is not None and m >= 2:
            tried = (self.input or {}).get("solver", {}).get("bracket")
            hint = "; --bracket verified no higher bound" if tried else "; --bracket may raise it"
        return (
            f"not proven: the critical load lies between {lower / scale:.6e} {unit} "
            f"(verified lower bound, {how}) and {high}{hint}"
        )

    def _model_lines(self) -> list[str]:
        """Summary lines of what the model holds beyond plate, edges and obstacle."""
        length, scale, unit = UNITS[self.units]
        lines = []
        if "gapped_obstacles" in self.details:
            lines.append(self.details["gapped_obstacles"])
        load = (self.input or {}).get("load", {})
        if self.critical_temperature_K is not None:
            lines.append(
                f"temperature rise per unit lambda {load.get('temperature')}: critical rise "
                f"{self.critical_temperature_K:.6g} K"
            )
        fixed = [
            f"{name} {_load_text(edge, 'fixed_', scale, ' ' + unit)}"
            for name, edge in self.edge_loads.items()
            if "fixed_normal_stress" in edge
        ]
        if load.get("fixed_temperature"):
            fixed.append(f"temperature rise {load['fixed_temperature']} K")
        if self.critical_total_temperature_K is not None:
            lines.append(
                "total temperature rise at the critical state (the fixed rise and lambda "
                f"times the scaled one): {self.critical_total_temperature_K:.6g} K"
            )
        if self.design is not None:
            d = self.design
            rho = d["reduction_factor"]
            lines.append(
                f"EN 1993-1-5: sigma_cr = {d['sigma_cr_Pa'] / scale:.4g} {unit} ({d['edge']}), "
                f"psi = {d['psi']:.3g}, slenderness {d['relative_slenderness']:.4g}, rho = "
                + (
                    f"{rho:.4g}, rho f_y/gamma_M1 = {d['reduced_design_stress_Pa'] / scale:.4g} "
                    f"{unit}"
                    if rho is not None
                    else f"none (psi outside {d['table']})"
                )
                + f"; {d['element']} element"
                + (f" (free edge {d['free_edge']})" if d.get("free_edge") else "")
                + ", 4.4(2) calibrated on bilateral plates"
            )
        factor = load.get("fixed_factor", 1.0)
        if fixed and factor:
            times = "" if factor == 1.0 else f"{factor:g} x "
            lines.append(f"fixed load (applied as is): {times}{'; '.join(fixed)}")
        reports = self.details.get("point_restraints", [])
        name = "m" if self.units == "SI" else "mm"
        for p, restraint in zip(reports, self._point_restraints(reports), strict=True):
            idle = p.get("restraining_nothing", [])
            shown = ", ".join(f"({x / length:g}, {y / length:g})" for x, y in idle[:3])
            lines.append(
                f"points: {restraint}: {p['points']} points on {p['nodes']} nodes, "
                f"largest snap distance {p['max_snap_distance_m'] / length:.3g} {name}"
                + (
                    f"; {len(idle)} on a node held already (by an edge support or a "
                    f"bilateral point), restraining nothing: {shown}"
                    + (", ..." if len(idle) > 3 else "")
                    + f" {name}"
                    if idle
                    else ""
                )
            )
        return lines

    def _point_restraints(self, reports: list[dict[str, Any]]) -> list[str]:
        """Each point restraint described in the summary's units (the JSON's are SI)."""
        tables = (self.input or {}).get("points", [])
        if self.units == "SI" or len(tables) != len(reports):
            return [p["restraint"] for p in reports]
        return [PointSpec(**table).describe(self.units) for table in tables]


def _contact_force(
    problem: BucklingProblem, solution: UnilateralSolution, resolution: float | None
) -> dict[str, Any]:
    """The obstacle's push at each contact node of the returned mode (N/m; collective).

    The mode is scaled to max |w| = 1 and oriented away from the obstacle, so the
    residual ``r = A u - lambda B u`` at a contact node is the obstacle's reaction on it
    with the sign of a pull: the push is ``-s_k r_k`` (``s_k`` the node's obstacle side).
    """
    if problem.contact is None:  # pragma: no cover (from_solution checked it)
        raise ValueError("_contact_force: the problem has no obstacle")
    r, au_inf, _ = problem.residual(solution.load, solution.candidate.mode.x.petsc_vec)
    push = -problem.contact.values(r)[solution.active]
    return {
        "unit": "N/m",
        "push": [float(f) for f in push],
        "resolution": None if resolution is None else float(resolution * au_inf),
    }


def _gap_text(gap: float) -> str:
    """The relative gap rounded up to one significant digit: 8.1e-05 -> "9e-05"."""
    if gap <= 0:
        return "0"
    exponent = math.floor(math.log10(gap))
    digit = math.ceil(round(gap / 10.0**exponent, 9))
    if digit >= 10:
        digit, exponent = 1, exponent + 1
    return f"{digit}e{exponent:+03d}"


def _verified(cert: dict[str, Any]) -> str:
    """What the certificate verified, for the summary line."""
    m = cert.get("negative_eigenvalues")
    below = f", m={m}" if m is not None else ""
    status = cert.get("status")
    gap = cert.get("relative_gap")
    if cert.get("global_optimum_proven"):
        return f"proven=yes ({cert.get('proven_by')}, gap {float(gap or 0):.1e}{below})"
    if status == "bracketed" and isinstance(gap, float):
        return f"proven=no, bracketed to {_gap_text(gap)} ({cert.get('proven_by')}{below})"
    refuted = cert.get("refuting_load_Pa")
    if isinstance(refuted, float):
        return f"proven=no, refuted: an admissible mode has {refuted:.6e} Pa"
    return f"proven=no (KKT only{below})"


def _zone_text(zone: dict[str, Any]) -> str:
    """A line on a discrete zone that differs from its zone by more than 1e-6, or ''."""
    area, discrete = zone.get("area_m2"), zone["discrete_area_m2"]
    if area is None or area <= 0.0 or abs(discrete - area) <= 1e-6 * area:
        return ""
    return (
        f"{zone['obstacle']} zone on the mesh: the cells with every node in it cover "
        f"{discrete / area:.2%} of its area ({zone['nodes']} nodes); the obstacle acts on "
        "the mesh nodes in the zone"
    )


def _load_text(load: dict[str, Any], prefix: str = "", scale: float = 1.0, unit: str = "") -> str:
    """The edge stresses of ``load`` (``prefix`` "fixed_": the fixed ones, in ``unit``)."""
    parts = []
    for key in ("normal", "shear"):
        value = load[f"{prefix}{key}_stress"]
        if isinstance(value, list | tuple):
            if any(value):
                parts.append(f"{key} {value[0] / scale:g} to {value[1] / scale:g}{unit} (linear)")
        elif value:
            parts.append(f"{key} {value / scale:g}{unit}")
    return ", ".join(parts)


def _critical_temperature(spec: ProblemSpec, load: float) -> float | None:
    """The critical rise: lambda times the scaled field's largest rise over the plate.

    The largest signed rise (the field is linear: its largest value lies on the
    boundary's vertices): where part of the plate cools, the heated part buckles it.
    """
    if not spec.load.thermal:
        return None
    T0, gx, gy = temperature_field(spec.load.temperature)
    rises = [T0 + gx * x + gy * y for x, y in spec.plate.boundary]
    return load * max(rises)


def _total_temperature(spec: ProblemSpec, load: float) -> float | None:
    """With a fixed rise: the largest total rise at the critical state (K), else None.

    ``fixed_factor`` times the fixed field plus lambda times the scaled one: a linear
    field, largest on a vertex of the boundary.
    """
    if not (spec.load.fixed_thermal and spec.load.fixed_factor):
        return None
    fixed = temperature_field(spec.load.fixed_temperature)
    scaled = temperature_field(spec.load.temperature)
    factor = spec.load.fixed_factor
    return max(
        factor * (fixed[0] + fixed[1] * x + fixed[2] * y)
        + load * (scaled[0] + scaled[1] * x + scaled[2] * y)
        for x, y in spec.plate.boundary
    )


def _input(spec: ProblemSpec) -> dict[str, Any] | None:
    try:
        return problem_to_dict(spec)
    except ValueError:  # a predicate zone
        return None


def versions() -> dict[str, str]:
    """Versions of the package and of the libraries that computed the result."""
    import platform
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": platform.python_version(), "numpy": np.__version__}
    # Distributions that can take part in a result (installed ones only): meshing (gmsh),
    # MPI, the SDP certificate (cvxpy, clarabel), the dense references (scipy).
    dists = (
        "unibuckle_fenicsx",
        "fenics-dolfinx",
        "petsc4py",
        "slepc4py",
        "fenics-basix",
        "mpi4py",
        "gmsh",
        "cvxpy",
        "clarabel",
        "scipy",
    )
    for dist in dists:
        try:
            out[dist] = version(dist)
        except PackageNotFoundError:
            pass
    try:
        import petsc4py
        import slepc4py
        from petsc4py import PETSc
        from slepc4py import SLEPc

        import dolfinx

        # The bindings' own versions: the PyPI wheel (dolfinx-solver-real) bundles them
        # under its own distribution name, where the loop above finds none.
        out.setdefault("petsc4py", petsc4py.__version__)
        out.setdefault("slepc4py", slepc4py.__version__)
        out["dolfinx"] = dolfinx.__version__
        out["PETSc"] = ".".join(str(v) for v in PETSc.Sys.getVersion())
        out["SLEPc"] = ".".join(str(v) for v in SLEPc.Sys.getVersion())
    except ImportError:  # pragma: no cover
        pass
    return out


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


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, float | np.floating):
        # No finite value (a contact force with no contact node, an upper bound with no
        # admissible mode): null, as the top-level upper_bound_Pa has always been,
        # rather than a string where a reader expects a number.
        value = float(obj)
        return value if np.isfinite(value) else None
    return obj
