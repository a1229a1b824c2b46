r"""The load path of the imperfect plate, and the buckling load read off it.

:func:`solve_nonlinear` validates the linear critical state by the analysis an engineer
would run in a commercial code (contact plus a path-following method): the linear
problem (:func:`~unibuckle_fenicsx.analysis.solve`) gives :math:`\lambda_c` and its mode;
the von Kármán plate (:class:`~unibuckle_fenicsx.nonlinear.model.VonKarmanPlate`) is
given the stress-free imperfection :math:`w_0 = \delta t\,\hat\phi` (max :math:`|w_0| =
\delta t`) and loaded step by step, against the obstacle; the knee of the path
max :math:`|w|` against :math:`\lambda` is read off twice, independently of the linear
eigen solve (:mod:`~unibuckle_fenicsx.nonlinear.estimators`: Southwell's method and the
inflection load). The imperfection shape: :mod:`~unibuckle_fenicsx.nonlinear.imperfection`.
"""

from __future__ import annotations

import logging
import time
from dataclasses import asdict, dataclass, field
from typing import NotRequired, TypedDict

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import dolfinx.fem.petsc

import numpy as np
import numpy.typing as npt
from msgspec import structs

from unibuckle_fenicsx.analysis import Analysis
from unibuckle_fenicsx.analysis import solve as solve_linear
from unibuckle_fenicsx.errors import InputError, NonlinearError, NumericalError
from unibuckle_fenicsx.la.options import Prefix
from unibuckle_fenicsx.la.ownership import Owner
from unibuckle_fenicsx.model.contact import ContactSetManager
from unibuckle_fenicsx.model.problem import UnilateralProblem
from unibuckle_fenicsx.nonlinear.choices import SHAPES
from unibuckle_fenicsx.nonlinear.estimators import (
    inflection_load,
    southwell_load,
)
from unibuckle_fenicsx.nonlinear.imperfection import (
    check_gaps,
    embed,
    imperfection_shape,
    to_linear_space,
)
from unibuckle_fenicsx.nonlinear.model import (
    VonKarmanPlate,
    displacement_axis,
)
from unibuckle_fenicsx.nonlinear.options import NonlinearOptions
from unibuckle_fenicsx.nonlinear.verdict import judge
from unibuckle_fenicsx.progress import LOGGER, warn_once
from unibuckle_fenicsx.results.assemble import versions
from unibuckle_fenicsx.results.records import BucklingResult
from unibuckle_fenicsx.spec import UNITS, ProblemSpec
from unibuckle_fenicsx.tolerances import NONLINEAR_ATOL

__all__ = [
    "SHAPES",
    "NonlinearAnalysis",
    "NonlinearOptions",
    "NonlinearResult",
    "PathPoint",
    "solve_nonlinear",
]

logger = logging.getLogger(__name__)


class PathPoint(TypedDict):
    r"""One converged state of the path (a mapping, as the JSON's ``path`` holds it).

    Attributes:
        load_Pa: :math:`\lambda`.
        max_w_m: max |w| over the plate (imperfection included).
        contact_nodes: Zone nodes on the obstacle.
        end_shortening_m: Mean inward normal displacement of the loaded edges, summed.
        newton_iterations: Newton iterations of the step (0 for the unloaded state).
    """

    load_Pa: float
    max_w_m: float
    contact_nodes: int
    end_shortening_m: float
    newton_iterations: int


class ContactCheck(TypedDict):
    r"""The contact conditions of a state (:func:`contact_check`; the JSON's ``contact_check``).

    Attributes:
        force_scale: :math:`s = \lambda \|f\|_\infty`, the scale of the forces.
        rtol: The tolerance relative to it.
        max_zone_w_m: The largest :math:`s_k w_k - g_k` at the zone nodes (<= 0
            admissible); with the obstacle only, as the next four.
        contact_nodes: Zone nodes on the obstacle.
        max_contact_force: The largest scaled residual at a contact node (None
            without one).
        min_contact_force: The smallest (None without one).
        max_complementarity: The largest :math:`|(s w - g) F|` over the zone, per t.
        max_free_residual: The largest scaled residual at a DOF free of edge conditions
            and of contact.
        satisfied: All of the conditions hold.
    """

    force_scale: float
    rtol: float
    max_zone_w_m: NotRequired[float]
    contact_nodes: NotRequired[int]
    max_contact_force: NotRequired[float | None]
    min_contact_force: NotRequired[float | None]
    max_complementarity: NotRequired[float]
    max_free_residual: NotRequired[float]
    satisfied: NotRequired[bool]


@dataclass
class NonlinearResult:
    """The load path and the loads read off it (JSON-ready fields only).

    Attributes:
        case: Problem name.
        mesh: [nx, ny].
        dofs: Global DOFs of the mixed (u, w, theta) space.
        obstacle: Whether the obstacle was imposed.
        control: "load" or "displacement".
        imperfection: delta, max |w0| / t.
        imperfection_shape: "free" or "unilateral".
        thickness_m: t.
        linear_critical_load_Pa: The linear reference: the unilateral critical load with
            the obstacle, the free load without (same mesh, linear eigen solver).
        free_load_Pa: The linear free load.
        linear_method: How the linear load was computed, and whether it is certified.
        southwell_load_Pa: Southwell's estimate (None if the window holds < 3 points).
        southwell_points: Points fitted.
        inflection_load_Pa: The steepest rise of max |w| (None if the path stops before).
        southwell_ratio: southwell / linear.
        inflection_ratio: inflection / linear.
        path: The converged states, as :class:`PathPoint` mappings.
        completed: The path reached ``max_load``.
        stop_reason: Why the path stopped.
        rejected_steps: Steps halved after a failed solve or a too large jump.
        constrained_nodes: Zone nodes with w <= g imposed (g the obstacle's gap).
        contact_load_Pa: The load of the first state on the path with a node on the
            obstacle (None if none): with a gap, where the plate reaches the obstacle.
        gapped: An obstacle with a gap was imposed: the linear load is the free plate's
            (the linear state leaves the gapped obstacle out), and the knee lies between
            it and ``unilateral_load_Pa`` (:mod:`~unibuckle_fenicsx.nonlinear.verdict`).
        unilateral_load_Pa: With ``gapped``: the linear unilateral critical load with the
            gaps closed (same mesh); None otherwise, or if that solve failed.
        verdict: The verdict in words (:func:`~unibuckle_fenicsx.nonlinear.verdict.judge`).
        contact_check: The contact conditions at the last state (see
            :func:`contact_check`).
        options: The options used, with the in-plane degree (``degree``) and the linear
            eigen solves' tolerance (``eps_tol``: solver.eps_tol, or -unibuckle_eps_tol).
        wall_time_s: Total wall time (linear solve included).
        timings: Seconds per phase.
        mpi_size: Ranks used.
        units: Unit system the summary prints in.
        versions: Library versions.
    """

    case: str
    mesh: list[int]
    dofs: int
    obstacle: bool
    control: str
    imperfection: float
    imperfection_shape: str
    thickness_m: float
    linear_critical_load_Pa: float
    free_load_Pa: float
    linear_method: str
    southwell_load_Pa: float | None
    southwell_points: int
    inflection_load_Pa: float | None
    southwell_ratio: float | None
    inflection_ratio: float | None
    path: list[PathPoint]
    completed: bool
    stop_reason: str
    rejected_steps: int
    constrained_nodes: int
    contact_check: ContactCheck
    options: dict[str, object]
    wall_time_s: float
    contact_load_Pa: float | None = None
    gapped: bool = False
    unilateral_load_Pa: float | None = None
    verdict: str = ""
    timings: dict[str, float] = field(default_factory=dict)
    mpi_size: int = 1
    units: str = "SI"
    versions: dict[str, str] = field(default_factory=dict)

    @property
    def certified(self) -> bool:
        """The path is complete, both loads were read off it and agree, the contact holds.

        Agree: within :data:`~unibuckle_fenicsx.tolerances.KNEE_RTOL` of the linear load;
        with a gap, between the free load and the unilateral one with the gaps closed
        (:func:`~unibuckle_fenicsx.nonlinear.verdict.judge`).
        """
        return judge(self).ok

    def shortfall(self) -> str:
        """What an unsuccessful load path validated, and what it did not (one paragraph).

        For a result that is not :attr:`certified`; the path was asked to reach
        ``options["max_load"]`` times the linear critical load
        (:func:`~unibuckle_fenicsx.nonlinear.verdict.judge`).
        """
        verdict = judge(self)
        validated, missing = ", ".join(verdict.validated), ", ".join(verdict.missing)
        linear = self.linear_critical_load_Pa
        if verdict.gap:
            closed = self.unilateral_load_Pa
            return (
                f"with a gap the knee lies between the free load {linear:.6e} Pa and the "
                "unilateral load with the gaps closed "
                + ("(not computed)" if closed is None else f"{closed:.6e} Pa")
                + "; the load path is not consistent with them. Consistent: "
                f"{validated or 'nothing'}. Not consistent: {missing}"
            )
        return (
            f"the load path does not validate everything against the linear critical load "
            f"{linear:.6e} Pa. Validated: {validated or 'nothing'}. Not validated: {missing}"
        )

    def as_dict(self) -> dict[str, object]:
        """JSON-ready mapping."""
        return asdict(self)

    def summary(self) -> str:
        """Lines for the terminal: the loads, the path, the verdict."""
        scale, unit = UNITS[self.units][1:]

        def load(value: float | None, ratio: float | None) -> str:
            if value is None or ratio is None:
                return "not found"
            return f"{value / scale:.6e} {unit} ({ratio:.4f} x {reference})"

        gap = self.obstacle and self.gapped
        reference = "free" if gap else "linear"
        last = self.path[-1]
        where = "with obstacle" if self.obstacle else "without obstacle"
        linear = f"linear {self.linear_critical_load_Pa / scale:.6e} {unit}"
        if gap:
            closed = self.unilateral_load_Pa
            linear = (
                f"linear: free {self.linear_critical_load_Pa / scale:.6e} {unit} (the gapped "
                "obstacle left out), unilateral with the gaps closed "
                + ("not computed" if closed is None else f"{closed / scale:.6e} {unit}")
            )
        return (
            f"{self.case} ({where}, delta/t = {self.imperfection:g}, {self.control} control): "
            f"Southwell {load(self.southwell_load_Pa, self.southwell_ratio)}, inflection "
            f"{load(self.inflection_load_Pa, self.inflection_ratio)}; {linear}\n"
            f"  path: {len(self.path) - 1} steps ({self.rejected_steps} rejected) to "
            f"lambda = {last['load_Pa'] / scale:.6e} {unit}, max|w|/t = "
            f"{last['max_w_m'] / self.thickness_m:.4g}, {last['contact_nodes']} contact "
            f"nodes; {self.stop_reason}; {self.wall_time_s:.2f} s"
            + (
                f"\n  the plate reaches the obstacle at lambda = "
                f"{self.contact_load_Pa / scale:.6e} {unit} "
                f"({self.contact_load_Pa / self.linear_critical_load_Pa:.4f} x {reference})"
                if self.contact_load_Pa is not None and self.obstacle
                else ""
            )
            + f"\n  {judge(self).summary(self)}"
        )


@dataclass
class NonlinearAnalysis(Owner):
    """What :func:`solve_nonlinear` returns: the result, the plate and the linear analysis.

    Attributes:
        result: The JSON-ready result.
        plate: The von Kármán plate, in its last converged state.
        linear: The linear analysis (reference load and imperfection shape).

    Note:
        :meth:`destroy` (or leaving a ``with`` block) is collective.
    """

    result: NonlinearResult
    plate: VonKarmanPlate
    linear: Analysis
    owns_linear: bool = True

    def deflection(self) -> dolfinx.fem.Function:
        """The last state's (w, theta) (m, rad) on the linear model's space, for figures."""
        return to_linear_space(self.plate, self.plate.x, self.linear.problem)

    def destroy(self) -> None:
        """Destroy the plate's (and the owned linear analysis') PETSc objects."""
        self.plate.destroy()
        if self.owns_linear:
            self.linear.destroy()


def _measure(plate: VonKarmanPlate, iterations: int) -> PathPoint:
    """The current state of ``plate``, reached in ``iterations`` Newton iterations (collective)."""
    lam = plate.load.value.item() if plate.control == "load" else plate.edge_reaction_load()
    return PathPoint(
        load_Pa=float(lam),
        max_w_m=plate.max_abs_w(),
        contact_nodes=int(plate.contact_nodes().size),
        end_shortening_m=plate.end_shortening(),
        newton_iterations=iterations,
    )


def _trace(
    plate: VonKarmanPlate,
    options: NonlinearOptions,
    reference: float,
    label: str,
) -> tuple[list[PathPoint], bool, str, int]:
    """Follow the path from the unloaded imperfect state (collective)."""
    t = plate.thickness
    load_control = options.control == "load"
    unit = reference if load_control else plate.flat_shortening(reference)
    stop_load = options.max_load * reference
    # Under end shortening the post-buckled plate is softer; its load is checked instead.
    p_max = stop_load if load_control else 4.0 * options.max_load * unit

    plate.set_control(0.0)
    plate.x.x.array[:] = plate.x0.x.array
    path = [_measure(plate, 0)]
    p, p_prev = 0.0, None
    x_prev: npt.NDArray[np.floating] | None = None
    step = options.max_step * unit
    rejected = 0
    while True:
        if path[-1]["load_Pa"] >= stop_load * (1 - 1e-12) or p >= p_max * (1 - 1e-12):
            return path, True, f"reached {options.max_load:g} x the linear critical load", rejected
        if len(path) > options.max_steps:
            return path, False, f"stopped after max_steps = {options.max_steps} steps", rejected
        p_try = p + step if p + 1.25 * step < p_max else p_max  # no sliver of a last step
        x_cur = plate.x.x.array.copy()
        if x_prev is not None and p_prev is not None and p > p_prev:
            plate.x.x.array[:] = x_cur + (p_try - p) / (p - p_prev) * (x_cur - x_prev)
            plate.project()
        plate.set_control(p_try)
        report = plate.solve()
        point = _measure(plate, report.iterations) if report.converged else None
        jump = (
            abs(point["max_w_m"] - path[-1]["max_w_m"]) / path[-1]["max_w_m"]
            if point is not None
            else 0.0
        )
        if point is None or (
            jump > 2.0 * options.deflection_step and step > options.min_step * unit
        ):
            plate.x.x.array[:] = x_cur
            plate.set_control(p)
            rejected += 1
            step /= 2.0
            if step < options.min_step * unit:
                why = (
                    f"SNES did not converge at the smallest step (converged reason "
                    f"{report.reason}, {report.iterations} iterations) from lambda = "
                    f"{path[-1]['load_Pa']:.6e} Pa"
                )
                return path, False, why, rejected
            continue
        x_prev, p_prev, p = x_cur, p, p_try
        path.append(point)
        factor = 2.0 if report.iterations <= 3 else 1.3 if report.iterations <= 6 else 0.7
        if jump > 0.0:
            factor = min(factor, options.deflection_step / jump)
        step = min(max(step * factor, options.min_step * unit), options.max_step * unit)
        if plate.comm.rank == 0:
            LOGGER.info(
                "%s step %d: lambda = %.6e Pa (%.4f x linear), max|w|/t = %.4g, "
                "%d contact nodes, %d Newton iterations",
                label,
                len(path) - 1,
                point["load_Pa"],
                point["load_Pa"] / reference,
                point["max_w_m"] / t,
                point["contact_nodes"],
                report.iterations,
            )


def contact_check(plate: VonKarmanPlate, rtol: float = 1e-8) -> ContactCheck:
    r"""The contact conditions of the current state.

    With :math:`F` the residual (the gradient of the energy, scaled) and
    :math:`s = \lambda \|f\|_\infty` the scale of the edge loads' vector: w <= 0 at every
    zone node; on the contact nodes :math:`F_k \le r_{tol} s` (the obstacle pushes the
    plate down: :math:`-F_k \ge 0` is its reaction); on every other DOF free of edge
    conditions :math:`|F_k| \le r_{tol} s`.

    Note:
        Collective.
    """
    lam = plate.load.value.item() if plate.control == "load" else plate.edge_reaction_load()
    scale = abs(lam) * plate.unit_load_inf or 1.0
    F = plate.residual_vector()
    n_owned = plate.num_owned_dofs
    skip = np.zeros(F.getLocalSize(), dtype=bool)
    for bc in plate.bcs:
        dofs = bc.dof_indices()[0]
        skip[dofs[dofs < n_owned]] = True
    out = ContactCheck(force_scale=scale, rtol=rtol)
    ok = True
    if isinstance(plate.contact, ContactSetManager):
        w = plate.zone_clearance()  # s w - g: <= 0 admissible
        on = np.zeros(plate.contact.size, dtype=bool)
        on[plate.contact_nodes()] = True
        forces = plate.contact.values(F) / scale
        indicator = F.duplicate()
        try:
            plate.contact.scatter(on.astype(float), indicator)
            skip |= np.abs(indicator.array) > 0.5
        finally:
            indicator.destroy()
        out["max_zone_w_m"] = float(w.max())
        out["contact_nodes"] = int(on.sum())
        top = out["max_contact_force"] = float(forces[on].max()) if on.any() else None
        out["min_contact_force"] = float(forces[on].min()) if on.any() else None
        out["max_complementarity"] = float(np.abs(w * forces).max() / plate.thickness)
        ok = out["max_zone_w_m"] <= 0.0
        if top is not None:
            ok = ok and top <= rtol
    free = float(np.abs(F.array[~skip]).max(initial=0.0)) / scale
    out["max_free_residual"] = float(plate.comm.allreduce(free, op=MPI.MAX))
    out["satisfied"] = bool(ok and out["max_free_residual"] <= rtol)
    return out


def _default_atol(plate: VonKarmanPlate, reference: float) -> None:
    """Set SNES's absolute tolerance, unless the command line gives one.

    :data:`~unibuckle_fenicsx.tolerances.NONLINEAR_ATOL` relative to the load vector at
    ``reference``.
    """
    if PETSc.Options().hasName(f"{Prefix.NONLINEAR}snes_atol"):
        return
    if plate.snes is None:
        raise RuntimeError("_default_atol: expected plate.snes is not None (an internal invariant)")
    plate.snes.setTolerances(atol=NONLINEAR_ATOL * plate.unit_load_norm * reference)


def solve_nonlinear(
    spec: ProblemSpec,
    options: NonlinearOptions | None = None,
    comm: MPI.Comm = MPI.COMM_WORLD,
    *,
    linear: Analysis | None = None,
) -> NonlinearAnalysis:
    """Trace the load path of the imperfect plate and read its buckling load off it.

    Args:
        spec: The problem (plate, edges, loads, mesh, obstacle).
        options: The nonlinear options (default :class:`NonlinearOptions`).
        comm: Communicator of the mesh.
        linear: A linear analysis of ``spec`` on the same mesh to reuse (its unilateral
            mode and load; not destroyed with the result). Default: solved here.

    Returns:
        The analysis; the caller destroys it (or uses ``with``).

    Raises:
        ValueError: Bad options or problem (before any solve).
        NonlinearError: No load step converged, even the smallest.

    Note:
        Collective on ``comm``.
    """
    t0 = time.perf_counter()
    options = NonlinearOptions() if options is None else options
    obstacle, degree = _checked(spec, options, linear)
    owns_linear = linear is None
    if linear is None:
        linear = solve_linear(spec if obstacle else spec.without_obstacles(), comm)
    timings = {"linear_s": time.perf_counter() - t0}
    result = linear.result
    reference, how = _reference(result, obstacle)
    label = f"{spec.name} delta/t={options.imperfection:g}"
    gapped = obstacle and bool(spec.gapped_obstacles)
    plate = None
    closed: float | None = None
    try:
        if gapped:
            t1 = time.perf_counter()
            closed = _gaps_closed_load(spec, linear)
            timings["gaps_closed_s"] = time.perf_counter() - t1
        t1 = time.perf_counter()
        plate = VonKarmanPlate(
            spec,
            comm,
            control=options.control,
            obstacle=obstacle,
            degree=degree,
            mesh=linear.problem.mesh,
            facet_tags=linear.problem.facet_tags,
        )
        _default_atol(plate, reference)
        shape, shape_name = imperfection_shape(linear, options.shape, obstacle)
        embed(plate, shape, linear.problem, options.imperfection * spec.plate.thickness)
        check_gaps(plate, options.imperfection)
        timings["setup_s"] = time.perf_counter() - t1
        t1 = time.perf_counter()
        path, completed, why, rejected = _trace(plate, options, reference, label)
        timings["path_s"] = time.perf_counter() - t1
    except BaseException:
        if plate is not None:
            plate.destroy()
        if owns_linear:
            linear.destroy()
        raise
    if len(path) < 2:
        plate.destroy()
        if owns_linear:
            linear.destroy()
        raise NonlinearError(f"{spec.name}: no load step converged: {why}")
    nl = _result(
        spec, options, plate, (path, completed, why, rejected), (result, reference, how),
        obstacle=obstacle, shape=shape_name, degree=degree, gapped=gapped, closed=closed,
        timings=timings, t0=t0, comm=comm,
    )  # fmt: skip
    nl.verdict = judge(nl).summary(nl)
    return NonlinearAnalysis(nl, plate, linear, owns_linear)


def _reference(result: BucklingResult, obstacle: bool) -> tuple[float, str]:
    """The linear load the path is compared with, and how it was found.

    With the obstacle: the unilateral critical load, its method and whether it is a KKT
    point; without: the free plate's load.
    """
    if not obstacle:
        return result.free_load_Pa, "free"
    kkt = result.certificate is not None and result.certificate.kkt
    return result.critical_load_Pa, result.method + (", KKT" if kkt else ", NOT certified")


def _checked(
    spec: ProblemSpec, options: NonlinearOptions, linear: Analysis | None
) -> tuple[bool, int]:
    """Refuse what the nonlinear model does not hold (before any solve).

    Returns whether the obstacle is imposed, and the in-plane displacement's degree.
    """
    if spec.load.thermal or spec.has_fixed_load:
        raise InputError(
            "the nonlinear analysis models edge loads scaled by lambda only: temperature "
            "rises ([load]) and fixed loads (fixed_normal_stress, fixed_shear_stress) are "
            "not in its energy"
        )
    if any(o.foundation_stiffness is not None for o in spec.all_obstacles):
        raise InputError(
            "the nonlinear analysis models rigid obstacles only, not Winkler foundations "
            "(foundation_stiffness)"
        )
    obstacle = options.obstacle and bool(spec.all_obstacles)
    if obstacle and len({o.side for o in spec.all_obstacles}) > 1:
        raise InputError(
            "the nonlinear analysis needs every obstacle on one side of the plate (all "
            "above or all below): the imperfection is pushed off them by a uniform pressure"
        )
    if options.shape == "unilateral" and not obstacle:
        raise InputError(
            'shape = "unilateral" needs a problem with an obstacle (and obstacle = true)'
        )
    displacement_axis(spec.plate, options.control)
    degree = options.degree if options.degree is not None else spec.solver.prestress_degree
    if degree not in (1, 2):
        raise InputError(
            f"solver.prestress_degree = {degree} sets the in-plane displacement degree of "
            "the nonlinear model, which must be 1 or 2: give degree"
        )
    if linear is not None:
        if obstacle and not isinstance(linear.problem, UnilateralProblem):
            raise InputError(
                "linear: the analysis given was solved without the obstacle; pass one of "
                "the problem with its obstacle (or obstacle = false)"
            )
        if linear.problem.spec.mesh != spec.mesh or linear.problem.spec.plate != spec.plate:
            raise InputError("linear: the analysis given is of another plate or mesh")
    return obstacle, degree


def _result(
    spec: ProblemSpec,
    options: NonlinearOptions,
    plate: VonKarmanPlate,
    traced: tuple[list[PathPoint], bool, str, int],
    linear: tuple[BucklingResult, float, str],
    *,
    obstacle: bool,
    shape: str,
    degree: int,
    gapped: bool,
    closed: float | None,
    timings: dict[str, float],
    t0: float,
    comm: MPI.Comm,
) -> NonlinearResult:
    """The result of a traced path: its loads read off it, the contact check, the record.

    ``traced``: the path, whether it completed, why it stopped, the rejected steps;
    ``linear``: the linear result, the reference load and how it was obtained;
    ``shape``: the imperfection's shape, by name.
    Collective (the contact check).
    """
    path, completed, why, rejected = traced
    result, reference, how = linear
    loads = np.array([q["load_Pa"] for q in path])
    max_w = np.array([q["max_w_m"] for q in path])
    knee = inflection_load(loads, max_w)
    southwell, count = (
        southwell_load(loads, max_w, max_w[0], knee, spec.plate.thickness)
        if knee is not None
        else (None, 0)
    )
    check = contact_check(plate)
    nl = NonlinearResult(
        case=spec.name,
        mesh=[spec.mesh.nx, spec.mesh.ny],
        dofs=plate.num_dofs,
        obstacle=obstacle,
        control=options.control,
        imperfection=options.imperfection,
        imperfection_shape=shape,
        thickness_m=spec.plate.thickness,
        linear_critical_load_Pa=reference,
        free_load_Pa=result.free_load_Pa,
        linear_method=how,
        southwell_load_Pa=southwell,
        southwell_points=count,
        inflection_load_Pa=knee,
        southwell_ratio=None if southwell is None else southwell / reference,
        inflection_ratio=None if knee is None else knee / reference,
        path=path,
        completed=completed,
        stop_reason=why,
        rejected_steps=rejected,
        constrained_nodes=plate.contact.size,
        contact_load_Pa=next((q["load_Pa"] for q in path if q["contact_nodes"]), None),
        gapped=gapped,
        unilateral_load_Pa=closed,
        contact_check=check,
        options={**structs.asdict(options), "degree": degree, "eps_tol": spec.solver.eps_tol},
        wall_time_s=time.perf_counter() - t0,
        timings=timings,
        mpi_size=comm.size,
        units=spec.units,
        versions=versions(),
    )
    return nl


def _gaps_closed_load(spec: ProblemSpec, linear: Analysis) -> float | None:
    """The linear unilateral critical load with every gap closed (g = 0), same mesh.

    The upper end of where the knee of a plate with a gapped obstacle lies; None when
    that solve finds no certified state (the verdict then says it is unknown). Collective.
    """
    closed = structs.replace(
        spec,
        obstacle=None if spec.obstacle is None else structs.replace(spec.obstacle, gap=0.0),
        obstacles=tuple(structs.replace(o, gap=0.0) for o in spec.obstacles),
    )
    problem = linear.problem
    try:
        with solve_linear(
            closed, problem.comm, mesh=problem.mesh, facet_tags=problem.facet_tags
        ) as analysis:
            return analysis.result.critical_load_Pa
    except NumericalError as err:
        warn_once(
            logger, problem.comm, "%s: the unilateral load with the gaps closed: %s", spec.name, err
        )
        return None
