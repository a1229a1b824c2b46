r"""The load path of the imperfect plate, and the buckling load read off it.

:func:`solve_nonlinear` validates the linear critical state by the analysis an engineer
would run in a commercial code (contact plus a path-following method): the linear
problem (:func:`~unibuckle_fenicsx.analysis.solve`) gives :math:`\lambda_c` and its mode;
the von Kármán plate (:class:`~unibuckle_fenicsx.nonlinear.model.VonKarmanPlate`) is
given the stress-free imperfection :math:`w_0 = \delta t\,\hat\phi` (max :math:`|w_0| =
\delta t`) and loaded step by step, against the obstacle; the knee of the path
max :math:`|w|` against :math:`\lambda` is read off twice, independently of the linear
eigen solve:

- **Southwell's method** (R. V. Southwell, *On the analysis of experimental observations
  in problems of elastic stability*, Proc. R. Soc. Lond. A 135, 1932, 601–616): below the
  critical load the additional deflection :math:`\delta_w = \max|w| - \delta t` of an
  imperfect structure grows as :math:`\delta_w = a\lambda/(\lambda_c - \lambda)`, i.e.
  :math:`\delta_w/\lambda = a/\lambda_c + \delta_w/\lambda_c`: a straight line in
  :math:`\delta_w` of slope :math:`1/\lambda_S`. Fitted on the path's points with
  :data:`SOUTHWELL_WINDOW` (:math:`0.5\,\lambda_i \le \lambda \le 0.95\,\lambda_i`, with
  :math:`\lambda_i` the inflection load) and :math:`\delta_w \le t/10` (small deflection:
  the relation is linear theory);
- the **inflection load** :math:`\lambda_i`: where max :math:`|w|` rises most steeply,
  the maximum of :math:`d\max|w|/d\lambda` by central differences on the path (uneven
  steps), refined by the vertex of the parabola through the largest slope and its two
  neighbours. For a stable symmetric bifurcation (plates) it tends to :math:`\lambda_c`
  as :math:`\delta \to 0`.

The imperfection is the linear free mode or the unilateral mode; with the obstacle it is
pushed strictly off it (:data:`PUSH_OFF` times the deflection under a uniform pressure,
which is negative inside the plate): a shape touching the obstacle with zero reaction
stalls the active set.
"""

from __future__ import annotations

import logging
import time
from dataclasses import asdict, dataclass, field
from typing import Any

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import dolfinx.fem.petsc
import ufl

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.analysis import Analysis
from unibuckle_fenicsx.analysis import solve as solve_linear
from unibuckle_fenicsx.config import UNITS, ProblemSpec, _boolean, _choice, _integer, _number
from unibuckle_fenicsx.eigen import Owner, set_options
from unibuckle_fenicsx.errors import InputError, NumericalError
from unibuckle_fenicsx.nonlinear.model import (
    CONTROLS,
    THETA_SUB,
    VonKarmanPlate,
    displacement_axis,
)
from unibuckle_fenicsx.problem import BucklingProblem
from unibuckle_fenicsx.progress import LOGGER
from unibuckle_fenicsx.results import versions

__all__ = [
    "PUSH_OFF",
    "SHAPES",
    "SOUTHWELL_WINDOW",
    "NonlinearAnalysis",
    "NonlinearError",
    "NonlinearOptions",
    "NonlinearResult",
    "PathPoint",
    "inflection_load",
    "solve_nonlinear",
    "southwell_load",
    "southwell_window",
]

logger = logging.getLogger(__name__)

#: Imperfection shapes: the linear free mode, the unilateral mode, or "auto" (the
#: unilateral mode with the obstacle, the free mode without).
SHAPES = ("auto", "free", "unilateral")
#: Southwell fit window: loads between these fractions of the inflection load.
SOUTHWELL_WINDOW = (0.5, 0.95)
#: ... and additional deflections up to this fraction of the thickness.
SOUTHWELL_MAX_DEFLECTION = 0.1
#: Weight of the uniform-pressure deflection added to a mode to keep the imperfection
#: strictly off the obstacle (relative, both shapes scaled to max |w| = 1).
PUSH_OFF = 1e-2
#: SNES absolute tolerance, relative to the load vector at the reference load.
ATOL = 1e-11
#: Linear solve of the push-off shape (prefix ``unibuckle_nl_shape_``).
SHAPE_LU: dict[str, str | float | int | bool] = {
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
    "ksp_error_if_not_converged": True,
}


class NonlinearError(NumericalError):
    """The nonlinear solve failed before any load step converged."""


@dataclass(frozen=True)
class NonlinearOptions:
    r"""Options of the nonlinear analysis.

    Args:
        imperfection: :math:`\delta`, the imperfection's amplitude max :math:`|w_0|`
            relative to the thickness, in (0, 1].
        shape: Imperfection shape, one of :data:`SHAPES`.
        control: "load" (edge traction :math:`\lambda`, adaptive steps) or
            "displacement" (end shortening of the loaded edges; :math:`\lambda` from the
            edge reactions; a uniaxial compression only).
        obstacle: Keep the problem's obstacle (False: the same plate without it).
        max_load: Stop the path at this multiple of the linear critical load, in (0, 5].
        max_step: Largest step, relative to the linear critical load (or to the flat
            plate's end shortening under it), in (0, 1].
        min_step: Smallest step before giving up, relative as ``max_step``, in
            (0, max_step].
        deflection_step: Target relative change of max |w| per step, in (0, 1].
        max_steps: Largest number of accepted steps, >= 1.
        degree: Lagrange degree of the in-plane displacement (1 or 2); None: the
            problem's ``solver.prestress_degree``.
    """

    imperfection: float = 1e-3
    shape: str = "auto"
    control: str = "load"
    obstacle: bool = True
    max_load: float = 1.2
    max_step: float = 0.05
    min_step: float = 1e-5
    deflection_step: float = 0.1
    max_steps: int = 400
    degree: int | None = None

    def __post_init__(self) -> None:
        if not 0.0 < _number("imperfection", self.imperfection) <= 1.0:
            raise InputError(
                "imperfection (delta: max |w0| / thickness) must lie in (0, 1], got "
                f"{self.imperfection!r}"
            )
        _choice("shape", self.shape, SHAPES)
        _choice("control", self.control, CONTROLS)
        _boolean("obstacle", self.obstacle)
        if not 0.0 < _number("max_load", self.max_load) <= 5.0:
            raise InputError(
                "max_load (a multiple of the linear critical load) must lie in (0, 5], got "
                f"{self.max_load!r}"
            )
        if not 0.0 < _number("max_step", self.max_step) <= 1.0:
            raise InputError(f"max_step must lie in (0, 1], got {self.max_step!r}")
        if not 0.0 < _number("min_step", self.min_step) <= self.max_step:
            raise InputError(
                f"min_step must lie in (0, max_step = {self.max_step}], got {self.min_step!r}"
            )
        if not 0.0 < _number("deflection_step", self.deflection_step) <= 1.0:
            raise InputError(f"deflection_step must lie in (0, 1], got {self.deflection_step!r}")
        _integer("max_steps", self.max_steps, 1)
        if self.degree is not None and (isinstance(self.degree, bool) or self.degree not in (1, 2)):
            raise InputError(f"degree (in-plane displacement) must be 1 or 2, got {self.degree!r}")


@dataclass(frozen=True)
class PathPoint:
    r"""One converged state of the path.

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


def southwell_window(
    loads: npt.ArrayLike,
    max_w: npt.ArrayLike,
    initial: float,
    knee: float,
    thickness: float,
) -> npt.NDArray[np.bool_]:
    r"""The path points Southwell's fit uses.

    Those with :math:`\lambda` within :data:`SOUTHWELL_WINDOW` times ``knee`` and an
    additional deflection :math:`0 < \delta_w = \max|w| - w_0 \le`
    :data:`SOUTHWELL_MAX_DEFLECTION` t.
    """
    lam = np.asarray(loads, dtype=float)
    dw = np.asarray(max_w, dtype=float) - initial
    lo, hi = SOUTHWELL_WINDOW
    mask = (lam >= lo * knee) & (lam <= hi * knee) & (dw > 0.0)
    return np.asarray(mask & (dw <= SOUTHWELL_MAX_DEFLECTION * thickness), dtype=bool)


def southwell_load(
    loads: npt.ArrayLike,
    max_w: npt.ArrayLike,
    initial: float,
    knee: float,
    thickness: float,
) -> tuple[float | None, int]:
    r"""Southwell's estimate of the critical load from a path below its knee.

    Fits :math:`\delta_w/\lambda = a + \delta_w/\lambda_S` (least squares) on the
    points of :func:`southwell_window`, where :math:`\delta_w = \max|w| - w_0`.

    Args:
        loads: :math:`\lambda` along the path.
        max_w: max :math:`|w|` along the path.
        initial: max :math:`|w_0|`, the imperfection.
        knee: The load the window is relative to (the inflection load).
        thickness: t.

    Returns:
        :math:`\lambda_S` (None with fewer than three points in the window or a
        non-positive slope) and the number of points fitted.
    """
    lam = np.asarray(loads, dtype=float)
    dw = np.asarray(max_w, dtype=float) - initial
    mask = southwell_window(lam, max_w, initial, knee, thickness)
    count = int(mask.sum())
    if count < 3:
        return None, count
    slope, _ = np.polyfit(dw[mask], dw[mask] / lam[mask], 1)
    return (float(1.0 / slope) if slope > 0.0 else None), count


def inflection_load(loads: npt.ArrayLike, max_w: npt.ArrayLike) -> float | None:
    r"""The load where max :math:`|w|` rises most steeply along the path.

    Central differences on uneven steps (second order) at the interior points; the
    largest slope and its two neighbours define a parabola whose vertex is returned
    (kept within the neighbours' loads).

    Returns:
        The inflection load, or None if the steepest slope is at the path's first or
        last interior point (the path does not pass the knee).
    """
    lam = np.asarray(loads, dtype=float)
    w = np.asarray(max_w, dtype=float)
    if lam.size < 5 or np.any(np.diff(lam) <= 0.0):
        keep = np.concatenate([[True], np.diff(lam) > 0.0]) if lam.size else lam.astype(bool)
        lam, w = lam[keep], w[keep]
        if lam.size < 5:
            return None
    h0 = lam[1:-1] - lam[:-2]
    h1 = lam[2:] - lam[1:-1]
    slope = (
        -h1 / (h0 * (h0 + h1)) * w[:-2]
        + (h1 - h0) / (h0 * h1) * w[1:-1]
        + h0 / (h1 * (h0 + h1)) * w[2:]
    )
    k = int(np.argmax(slope))
    if k == 0 or k == slope.size - 1:
        return None
    x = lam[k : k + 3]  # interior points k-1, k, k+1 of slope <-> lam[k], lam[k+1], lam[k+2]
    y = slope[k - 1 : k + 2]
    a, b, _ = np.polyfit(x - x[1], y, 2)
    vertex = x[1] - b / (2 * a) if a < 0.0 else x[1]
    return float(np.clip(vertex, x[0], x[2]))


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
        contact_check: The contact conditions at the last state (see
            :meth:`NonlinearAnalysis.contact_check`).
        options: The options used.
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
    path: list[dict[str, Any]]
    completed: bool
    stop_reason: str
    rejected_steps: int
    constrained_nodes: int
    contact_check: dict[str, Any]
    options: dict[str, Any]
    wall_time_s: float
    contact_load_Pa: float | None = None
    timings: dict[str, float] = field(default_factory=dict)
    mpi_size: int = 1
    units: str = "SI"
    versions: dict[str, str] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        """The path is complete, both loads were read off it, the contact holds."""
        return (
            self.completed
            and self.southwell_load_Pa is not None
            and self.inflection_load_Pa is not None
            and bool(self.contact_check.get("satisfied", True))
        )

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready mapping."""
        return asdict(self)

    def summary(self) -> str:
        """Two lines for the terminal."""
        scale, unit = UNITS[self.units][1:]

        def load(value: float | None, ratio: float | None) -> str:
            if value is None or ratio is None:
                return "not found"
            return f"{value / scale:.6e} {unit} ({ratio:.4f} x linear)"

        last = self.path[-1]
        where = "with obstacle" if self.obstacle else "without obstacle"
        return (
            f"{self.case} ({where}, delta/t = {self.imperfection:g}, {self.control} control): "
            f"Southwell {load(self.southwell_load_Pa, self.southwell_ratio)}, inflection "
            f"{load(self.inflection_load_Pa, self.inflection_ratio)}; linear "
            f"{self.linear_critical_load_Pa / scale:.6e} {unit}\n"
            f"  path: {len(self.path) - 1} steps ({self.rejected_steps} rejected) to "
            f"lambda = {last['load_Pa'] / scale:.6e} {unit}, max|w|/t = "
            f"{last['max_w_m'] / self.thickness_m:.4g}, {last['contact_nodes']} contact "
            f"nodes; {self.stop_reason}; {self.wall_time_s:.2f} s"
            + (
                f"\n  the plate reaches the obstacle at lambda = "
                f"{self.contact_load_Pa / scale:.6e} {unit} "
                f"({self.contact_load_Pa / self.linear_critical_load_Pa:.4f} x linear)"
                if self.contact_load_Pa is not None and self.obstacle
                else ""
            )
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


def to_linear_space(
    plate: VonKarmanPlate, x: dolfinx.fem.Function, problem: BucklingProblem
) -> dolfinx.fem.Function:
    """(w, theta) of the scaled state ``x`` in physical units on the linear (w, theta) space."""
    W = problem.model.W
    out = dolfinx.fem.Function(W, name="deflection")
    t = plate.thickness
    for sub_x, sub_w, factor in ((1, 0, t), (THETA_SUB, 1, 1.0)):
        source = x.sub(sub_x).collapse()
        Vt, dofs = W.sub(sub_w).collapse()
        target = dolfinx.fem.Function(Vt)
        target.interpolate(source)
        out.x.array[dofs[0]] = factor * target.x.array
    out.x.scatter_forward()
    return out


def _embed(
    plate: VonKarmanPlate, shape: dolfinx.fem.Function, problem: BucklingProblem, amplitude: float
) -> None:
    """x0 = (0, amplitude * w / t, amplitude * theta) from a linear (w, theta) shape."""
    x0 = plate.x0
    x0.x.array[:] = 0.0
    for sub_w, sub_x, factor in ((0, 1, amplitude / plate.thickness), (1, THETA_SUB, amplitude)):
        source = shape.sub(sub_w).collapse()
        Vt, dofs = plate.W.sub(sub_x).collapse()
        target = dolfinx.fem.Function(Vt)
        target.interpolate(source)
        x0.x.array[dofs[0]] = factor * target.x.array
    x0.x.scatter_forward()


def _pressure_shape(problem: BucklingProblem, sign: float = 1.0) -> dolfinx.fem.Function:
    """Deflection under a uniform pressure away from the obstacles (linear plate), max |w| = 1.

    ``sign`` = +1 (obstacles above): downward, w <= 0; -1 (below): upward.
    """
    model = problem.model
    z, _ = ufl.split(ufl.TestFunction(model.W))
    f = dolfinx.fem.petsc.assemble_vector(dolfinx.fem.form(-sign * z * ufl.dx))
    f.ghostUpdate(addv=True, mode="reverse")  # ADD_VALUES, SCATTER_REVERSE
    dolfinx.fem.petsc.set_bc(f, model.bcs)
    ksp = PETSc.KSP().create(problem.comm)  # type: ignore[arg-type]
    ksp.setOperators(model.A)
    set_options(ksp, "unibuckle_nl_shape_", SHAPE_LU)
    p = dolfinx.fem.Function(model.W, name="pressure_shape")
    try:
        ksp.solve(f, p.x.petsc_vec)
    finally:
        ksp.destroy()
        f.destroy()
    p.x.scatter_forward()
    p.x.petsc_vec.scale(1.0 / problem.max_abs_w(p.x.petsc_vec))
    p.x.scatter_forward()
    return p


def _orientation(problem: BucklingProblem, mode: dolfinx.fem.Function) -> float:
    """A partition-independent sign: that of the integral of w times an asymmetric weight."""
    (x0, y0), (x1, y1) = problem.spec.plate.corners
    xs = ufl.SpatialCoordinate(problem.mesh)
    weight = 1.0 + (xs[0] - x0) / (x1 - x0) + 0.37 * (xs[1] - y0) / (y1 - y0)
    w, _ = ufl.split(mode)
    value = dolfinx.fem.assemble_scalar(dolfinx.fem.form(weight * w * ufl.dx))
    value = problem.comm.allreduce(value, op=MPI.SUM)
    return -1.0 if value > 0.0 else 1.0  # mostly downward


def imperfection_shape(
    linear: Analysis, shape: str, obstacle: bool
) -> tuple[dolfinx.fem.Function, str]:
    """The imperfection's (w, theta) on the linear space, max |w| = 1, and its name.

    With the obstacle: w < 0 at every zone node (pushed off by :data:`PUSH_OFF` times the
    uniform-pressure deflection).

    Raises:
        ValueError: "unilateral" without an obstacle; "free" with an obstacle when the
            free mode crosses it whichever its sign.

    Note:
        Collective.
    """
    problem = linear.problem
    contact = problem.contact if obstacle else None
    name = shape if shape != "auto" else ("unilateral" if contact is not None else "free")
    if name == "unilateral" and (contact is None or linear.solution is None):
        raise InputError('shape = "unilateral" needs a problem with its obstacle')
    out = dolfinx.fem.Function(problem.model.W, name="imperfection_shape")
    if name == "unilateral":
        out.x.array[:] = linear.mode.x.array  # oriented: w <= 0 in the zone
    else:
        out.x.array[:] = linear.free_mode.x.array
        if contact is not None:
            values = contact.values(out.x.petsc_vec)
            if -values.min() < values.max():  # the sign with the lower max over the zone
                out.x.array[:] *= -1.0
                values = -values
            if values.max() > 0.0:
                raise InputError(
                    'shape = "free": the free mode crosses the obstacle whichever its sign '
                    f"(w > 0 at {int((values > 0).sum())} of the {contact.size} zone nodes); "
                    'use shape = "unilateral"'
                )
        else:
            out.x.array[:] *= _orientation(problem, out)
    if contact is not None:
        sides = {float(v) for v in contact.signs}
        if len(sides) != 1:
            raise InputError(
                "the nonlinear analysis pushes the imperfection off the obstacles by a uniform "
                "pressure: it needs every obstacle on one side of the plate (all above or all "
                "below)"
            )
        p = _pressure_shape(problem, sides.pop())
        out.x.petsc_vec.axpy(PUSH_OFF, p.x.petsc_vec)
        out.x.scatter_forward()
        out.x.petsc_vec.scale(1.0 / problem.max_abs_w(out.x.petsc_vec))
        out.x.scatter_forward()
        worst = float(contact.values(out.x.petsc_vec).max())
        if worst >= 0.0:
            raise InputError(
                f'the imperfection shape "{name}" touches the obstacle (w = {worst:.3g} '
                "max|w| at a zone node after the push-off)"
            )
    return out, name


def _check_gaps(plate: VonKarmanPlate, imperfection: float) -> None:
    """Refuse an imperfection that reaches an obstacle across its gap (collective)."""
    if plate.contact is None or not plate.contact.gaps.any():
        return
    clearance = plate.zone_clearance(plate.x0)
    gapped = plate.contact.gaps > 0
    if clearance[gapped].max() >= 0.0:
        raise InputError(
            f"obstacle.gap: the imperfection (delta = {imperfection:g}, max |w0| = "
            f"{imperfection * plate.thickness:.3g} m) reaches an obstacle across its gap "
            f"(smallest gap {plate.contact.gaps[gapped].min():.3g} m): lower the "
            "imperfection or widen the gap"
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

    def measure(iterations: int) -> PathPoint:
        lam = plate.load.value.item() if load_control else plate.edge_reaction_load()
        return PathPoint(
            float(lam),
            plate.max_abs_w(),
            int(plate.contact_nodes().size),
            plate.end_shortening(),
            iterations,
        )

    plate.set_control(0.0)
    plate.x.x.array[:] = plate.x0.x.array
    path = [measure(0)]
    p, p_prev = 0.0, None
    x_prev: npt.NDArray[np.floating] | None = None
    step = options.max_step * unit
    rejected = 0
    while True:
        if path[-1].load_Pa >= stop_load * (1 - 1e-12) or p >= p_max * (1 - 1e-12):
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
        point = measure(report.iterations) if report.converged else None
        jump = (
            abs(point.max_w_m - path[-1].max_w_m) / path[-1].max_w_m if point is not None else 0.0
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
                    f"{path[-1].load_Pa:.6e} Pa"
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
                point.load_Pa,
                point.load_Pa / reference,
                point.max_w_m / t,
                point.contact_nodes,
                report.iterations,
            )


def contact_check(plate: VonKarmanPlate, rtol: float = 1e-8) -> dict[str, Any]:
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
    out: dict[str, Any] = {"force_scale": scale, "rtol": rtol}
    ok = True
    if plate.contact is not None:
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
        out.update(
            max_zone_w_m=float(w.max()),
            contact_nodes=int(on.sum()),
            max_contact_force=float(forces[on].max()) if on.any() else None,
            min_contact_force=float(forces[on].min()) if on.any() else None,
            max_complementarity=float(np.abs(w * forces).max() / plate.thickness),
        )
        ok = out["max_zone_w_m"] <= 0.0
        if out["max_contact_force"] is not None:
            ok = ok and out["max_contact_force"] <= rtol
    free = float(np.abs(F.array[~skip]).max(initial=0.0)) / scale
    out["max_free_residual"] = float(plate.comm.allreduce(free, op=MPI.MAX))
    out["satisfied"] = bool(ok and out["max_free_residual"] <= rtol)
    return out


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
        if obstacle and linear.problem.contact is None:
            raise InputError(
                "linear: the analysis given was solved without the obstacle; pass one of "
                "the problem with its obstacle (or obstacle = false)"
            )
        if linear.problem.spec.mesh != spec.mesh or linear.problem.spec.plate != spec.plate:
            raise InputError("linear: the analysis given is of another plate or mesh")
    owns_linear = linear is None
    if linear is None:
        linear = solve_linear(spec if obstacle else spec.without_obstacles(), comm)
    timings = {"linear_s": time.perf_counter() - t0}
    result = linear.result
    reference = result.critical_load_Pa if obstacle else result.free_load_Pa
    certificate = result.certificate or {}
    how = "free" if not obstacle else result.method
    if obstacle:
        how += ", KKT" if certificate.get("kkt") else ", NOT certified"
    label = f"{spec.name} delta/t={options.imperfection:g}"
    plate = None
    try:
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
        opts = PETSc.Options()
        if not opts.hasName("unibuckle_nl_snes_atol"):
            assert plate.snes is not None
            plate.snes.setTolerances(atol=ATOL * plate.unit_load_norm * reference)
        shape, shape_name = imperfection_shape(linear, options.shape, obstacle)
        _embed(plate, shape, linear.problem, options.imperfection * spec.plate.thickness)
        _check_gaps(plate, options.imperfection)
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
    loads = np.array([q.load_Pa for q in path])
    max_w = np.array([q.max_w_m for q in path])
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
        imperfection_shape=shape_name,
        thickness_m=spec.plate.thickness,
        linear_critical_load_Pa=reference,
        free_load_Pa=result.free_load_Pa,
        linear_method=how,
        southwell_load_Pa=southwell,
        southwell_points=count,
        inflection_load_Pa=knee,
        southwell_ratio=None if southwell is None else southwell / reference,
        inflection_ratio=None if knee is None else knee / reference,
        path=[asdict(q) for q in path],
        completed=completed,
        stop_reason=why,
        rejected_steps=rejected,
        constrained_nodes=0 if plate.contact is None else plate.contact.size,
        contact_load_Pa=next((q.load_Pa for q in path if q.contact_nodes), None),
        contact_check=check,
        options={**asdict(options), "degree": degree},
        wall_time_s=time.perf_counter() - t0,
        timings=timings,
        mpi_size=comm.size,
        units=spec.units,
        versions=versions(),
    )
    return NonlinearAnalysis(nl, plate, linear, owns_linear)
