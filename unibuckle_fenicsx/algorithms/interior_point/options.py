r"""The interior-point method's settings, iterates and records.

Every number the Newton kernel decides with is a field of :class:`NewtonOptions` (a
setting of the method) or a tolerance of :mod:`unibuckle_fenicsx.tolerances` (a
rounding level); the measurements that chose the defaults are on
:doc:`/verification/tuning`.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field

import dolfinx

import numpy as np
import numpy.typing as npt

__all__ = [
    "EXPLORE",
    "PUSH_MARGIN",
    "RELAX_OPTIONS",
    "BarrierPoint",
    "ChainOptions",
    "NewtonOptions",
    "NewtonRecord",
    "NewtonStatus",
]

#: Smallest gap (relative to max|w|) of a pressure deflection that had to be lifted off
#: the obstacle; the margin of
#: :meth:`~unibuckle_fenicsx.algorithms.interior_point.starts.Starts.make_interior`:
#: one per cent keeps a start well inside the cone, where the barrier is smooth.
PUSH_MARGIN = 1e-2

#: Solver of the relaxation's block of A (the deflection's, or the rotations': symmetric
#: positive definite), options prefix ``<prefix>relax_w_`` or ``<prefix>relax_theta_``:
#: conjugate gradients with an incomplete Cholesky preconditioner (block Jacobi across
#: ranks), made once per mesh; a tenth of the cost of factorising the whole matrix
#: (:doc:`/verification/tuning`).
RELAX_OPTIONS: dict[str, str | float | int | bool] = {
    "ksp_type": "cg",
    "pc_type": "bjacobi",
    "sub_pc_type": "icc",
    "ksp_rtol": 1e-12,
    "ksp_atol": 0.0,
    "ksp_max_it": 5000,
}


class NewtonStatus(enum.Enum):
    """How a run of :meth:`~.newton.InteriorPointNewton.solve` ended."""

    CONVERGED = "converged"
    MAX_STEPS = "max-steps"
    INERTIA = "inertia-correction-failed"
    STALLED = "stalled"
    BREAKDOWN = "breakdown"
    MET_BEFORE = "met before"
    READ = "read"


@dataclass(frozen=True)
class NewtonOptions:
    r"""Settings of the interior-point Newton method (scaled quantities).

    Attributes:
        keep_mu_until: The barrier parameter is not decreased while
            :math:`\|F_u\|_2/\|Au\|_2` exceeds this (in (0, 1)): the iterate first
            reaches the neighbourhood of the central path.
        kappa_eps: The barrier problem counts as solved when its scaled residuals are
            at most ``kappa_eps`` times :math:`\mu` (> 0; IPOPT's 10).
        kappa_mu: Linear factor of the decrease of :math:`\mu` (in (0, 1); IPOPT's 0.2).
        theta_mu: Superlinear exponent of the decrease of :math:`\mu` (in (1, 2);
            IPOPT's 1.5).
        residual_floor: Scaled residual of :math:`F_u` that counts as zero (its
            rounding on thin plates: :math:`|A||u| \gg |Au|`).
        fraction: Fraction to the boundary (in (0, 1); IPOPT's 0.995): a step keeps
            this fraction of each gap; the push keeps ``1 - fraction`` of its value.
        local_residual: Below this scaled residual, full steps are taken (no line
            search): near the solution the objective's changes are below its rounding.
        delta_first: First regularisation :math:`\delta` (in the units of ``metric``).
        delta_max: Largest regularisation before giving up (with the geometric
            metric the matrix is positive definite at 1, which is the cap).
        correction_decay: A remembered correction is retried divided by this (> 1).
        correction_growth: A correction is multiplied by this until the inertia is
            right (> 1), ...
        correction_growth_remembered: ... and by this when it started from a
            remembered one (closer to the right one: a smaller growth).
        forgotten_correction: A correction below this is not remembered (damped
            steps only: it has decayed to nothing).
        plain_first: After a full step or one that needed no correction, try the
            unmodified matrix first (IPOPT's rule; fast local convergence). Off, the
            correction decays by ``correction_decay`` per step (damped steps that stay
            near the start: the exploration of the coarsest mesh uses this).
        metric: The matrix of the regularisation. "geometric": :math:`\lambda D`
            with D the row sums of :math:`|B|`, so that :math:`\delta` is the fraction
            of the geometric stiffness given back (:math:`D - B` is diagonally
            dominant, hence :math:`K + \lambda D \succeq A + E\Sigma E^T \succ 0`).
            "stiffness": diag(A), whose shear part on a thin plate is about
            :math:`(b/t)^2` times the bending stiffness, so that even a small
            :math:`\delta` damps the bending steps heavily.
        curvature_vectors: Krylov vectors of the negative-curvature step (0: none).
            The step is taken instead of the Newton step when the unmodified matrix
            was tried first and had the wrong inertia while the scaled residual is at
            most ``local_residual`` (near a stationary point: a saddle of the barrier
            problem).
        saddle_curvature: The step is taken when the curvature found,
            :math:`\theta = v^TKv / v^TMv` (in units of the regularisation: a fraction
            of the geometric stiffness), is below minus this: shallower curvatures
            are those of nearly degenerate plates, whose steps only move the path.
        stall_steps: In a run that lowers the barrier parameter (not one held at a
            single parameter), the run stops (status "stalled") when the residual of
            :math:`F_u` has not halved in this many steps (0: never), whatever
            parameter it has reached; the caller reads the contact set there as at
            convergence and goes on from it (saddle escape, lower barrier, polish).
        push_floor: At the first step, a given push is raised to this fraction of
            :math:`\mu/g` node by node (in (0, 1)): a push of zero is off the path.
        max_load_step: A step changes the load by at most this fraction of it.
        armijo: Sufficient decrease of the backtracking line searches, relative to
            the model's (Nocedal & Wright's :math:`c_1`, 1e-4).
        backtrack: Factor of a step length per backtrack (in (0, 1): halving).
        max_backtracks: Trials of a line search before it gives up (>= 1; the last is applied).
        held_stiffness: A DOF held fixed by a diagonal entry gets this times the largest
            diagonal entry of A: it moves by its inverse (1e-8) of the correction.
        interior_margin: The gap, relative to max|w|, of a barrier point made from an
            exact critical state (:meth:`~.starts.Starts.from_candidate`): small, so
            that the point is near the state, and positive, so that it is inside.
        escape_fraction: A saddle escape goes this fraction of the way to the first
            node that would touch the obstacle (in (0, 1): the node stays off it).
        max_escape_step: The largest step of a saddle escape, relative to the
            (B-normalised) mode, when no node limits it.
    """

    keep_mu_until: float = 1e-2
    kappa_eps: float = 10.0
    kappa_mu: float = 0.2
    theta_mu: float = 1.5
    residual_floor: float = 1e-8
    fraction: float = 0.995
    local_residual: float = 1e-2
    delta_first: float = 1e-4
    delta_max: float = 1e6
    correction_decay: float = 3.0
    correction_growth: float = 100.0
    correction_growth_remembered: float = 8.0
    forgotten_correction: float = 1e-11
    plain_first: bool = True
    metric: str = "geometric"
    curvature_vectors: int = 8
    saddle_curvature: float = 1e-4
    stall_steps: int = 10
    push_floor: float = 1e-3
    max_load_step: float = 0.5
    armijo: float = 1e-4
    backtrack: float = 0.5
    max_backtracks: int = 30
    held_stiffness: float = 1e8
    interior_margin: float = 1e-6
    escape_fraction: float = 0.99
    max_escape_step: float = 1e3


@dataclass
class BarrierPoint:
    r"""An iterate of the interior-point method.

    Attributes:
        mode: u = (w, theta), :math:`u^TBu = 1`, strictly inside the cone.
        load: :math:`\lambda`.
        push: :math:`\nu > 0` at the constrained nodes owned by this rank, in the
            order of :meth:`~unibuckle_fenicsx.model.contact.ContactSetManager.owned_positions`.
        mu: Scaled barrier parameter.
    """

    mode: dolfinx.fem.Function
    load: float
    push: npt.NDArray[np.float64]
    mu: float


@dataclass
class NewtonRecord:
    r"""What one run of the method did.

    Attributes:
        status: How it ended.
        steps: Newton steps taken.
        factorizations: Numeric factorisations (steps plus inertia corrections).
        curvature_steps: Of the steps, those along a direction of negative curvature.
        seconds: Wall time.
        load: Final :math:`\\lambda`.
        mu: Final scaled barrier parameter.
        history: (load, mu, scaled residual of F_u, scaled complementarity) per step.
    """

    status: NewtonStatus = NewtonStatus.MAX_STEPS
    steps: int = 0
    factorizations: int = 0
    curvature_steps: int = 0
    seconds: float = 0.0
    load: float = math.nan
    mu: float = math.nan
    history: list[tuple[float, float, float, float]] = field(default_factory=list)


@dataclass(frozen=True)
class ChainOptions:
    """Settings of the interior point's nested route (:mod:`unibuckle_fenicsx.algorithms.chain`).

    The measurements behind the defaults are on :doc:`/verification/tuning`.

    Attributes:
        explore_min_cells: Fewest cells along the shorter side of the coarsest mesh, where
            the starts are explored (>= 2): fewer rank the arrangements of the buckles
            wrongly, more make the exploration slow (the active set's multilevel has its
            own, ``coarse_min_cells`` of :func:`~.active_set.solve_active_set`).
        seeds: Starts of the interior-point method on the coarsest mesh: "free-" and
            "free+" (the free mode's parts on either side of the obstacle), "pressure"
            (the deflection under a pressure on the whole zone), "end-low", "middle",
            "end-high" (a pressure on a third of the plate's longer side), "free2-" and
            "free2+" (the parts of the free plate's second mode): each reaches
            arrangements of the buckles the others may miss.
        start_mu: Barrier parameter the starts begin with (large: the start lies well
            inside the cone, where the barrier is smooth).
        compare_mu: Barrier parameter at which the starts are compared.
        explore_mu_min: Barrier parameter at which the starts' contact sets are read.
        twin_rtol: Starts whose barrier solutions' loads at ``compare_mu``, or at a
            barrier parameter passed on the way to ``explore_mu_min``, agree to this
            (relative) lead to the same arrangement.
        path_rtol: ... or agree to this and their deflections on the zone (scaled
            to a largest value of 1) to ``path_shape_tol``: a barrier problem solved to
            a residual of about ten times its parameter fixes the load to only about
            that.
        path_shape_tol: See ``path_rtol``.
        level_mu: Barrier parameter of the central-path point carried from one mesh to
            the next.
        flat_mu: ... and of the second try when the first ends at no KKT point.
        fine_mu_min: ... and the fine mesh, before its contact set is read.
        read_mu: On the fine mesh, the contact set is first read when the barrier
            problem at this parameter (or the first one below it) is solved, from the
            predicted gaps and pushes
            (:meth:`~.newton.InteriorPointNewton.predicted_contact_set`); a KKT point
            there ends the run (0: read only at ``fine_mu_min``).
        read_stable: ... and, below ``read_mu``, as soon as two Newton steps in a row
            predict the same set (each prediction one more solve with the next step's
            factorisation).
        last_mu_min: ... once more when that contact set is not a KKT point.
        read_predicted: Where the contact set read off the gaps at the end of a run
            (:func:`~.links.critical_state`) is no KKT point, read the predicted set
            there too and go on from the one nearer to a KKT point. Off by default:
            the plates' runs end where the gaps' set is the predicted one or a saddle's;
            on sections with a core, where a wall lies almost flat on the core, the
            gaps there stay above ``tau`` at every parameter reached, and only the
            predicted set holds them (:doc:`/verification/sections_finest`).
        double_push: On the fine mesh, a contact set read at the barrier point's load
            whose mode crosses the obstacle by more than this (relative to its largest
            deflection) is checked for a double eigenvalue
            (:func:`~.links.double_read`: one more eigen solve). The sign changes of
            the degenerate nodes stay below a thousandth of the buckle; a second
            buckle of the same load crosses by a good part of its own.
        release_steps: On the fine mesh, where a contact set read at or below
            ``read_mu`` gives an admissible mode that the obstacle pulls at nodes of
            the set, those nodes are released and the smaller set read (one eigen
            solve each, :func:`~.links.released`), at most this many times in a row
            (0: never); a KKT point met so ends the run
            (:doc:`/verification/fine_level_release`).
        clip_margin: Smallest gap (relative to max|w|) of an interpolated mode's nodes
            (the least-energy correction lifts those closer to the obstacle to it).
        max_steps: Newton steps per run.
        escapes: Saddle escapes allowed per run.
        escape_either: With ``read_predicted``, where the set kept at a barrier point
            is no saddle's (its mode crosses no node, or lies above the point's load),
            a saddle is escaped along the other set read, if that one's is.
        escape_mu: Barrier parameter the run restarts with after an escape (small: a
            larger one would lift the flattened buckle again).
        carry_margin: Critical states within this (relative) of the lowest on a mesh
            are carried to the next (the active set's ``refine_margin`` is its own).
        arrangements: ... at most this many.
        polish_iterations: Active-set iterates allowed to polish a contact set.
        quick_polish_iterations: ... on the first try of the fine mesh.
        descent_steps: Eigen solves allowed to the feasible descent after a polish that
            ends at an admissible mode short of a KKT point.
        quick_descent: Where the short polish of the first try ends at no KKT point,
            the feasible descent runs from the lowest admissible mode met on the mesh
            (the polish's or a read's) with ``descent_steps`` eigen solves (else the
            descent runs on the second try only).
        descent_budget: Eigen solves (per ``max_iterations``) of the last descent, from
            the lowest admissible mode met, when the fine mesh ended at no KKT point.
        max_iterations: Iterates per seed of the fallback active-set method.
        bound_budget: Eigen solves of the lattice lower bound (small zones).
    """

    explore_min_cells: int = 6
    seeds: tuple[str, ...] = (
        "free-",
        "free+",
        "pressure",
        "end-low",
        "middle",
        "end-high",
        "free2-",
        "free2+",
    )
    start_mu: float = 1e-2
    compare_mu: float = 1e-4
    explore_mu_min: float = 1e-14
    twin_rtol: float = 1e-7
    path_rtol: float = 1e-4
    path_shape_tol: float = 1e-2
    level_mu: float = 1e-6
    flat_mu: float = 1e-10
    fine_mu_min: float = 1e-14
    read_mu: float = 1e-9
    read_stable: bool = True
    last_mu_min: float = 1e-14
    read_predicted: bool = False
    double_push: float = 1e-2
    release_steps: int = 8
    clip_margin: float = 1e-6
    max_steps: int = 100
    escapes: int = 3
    escape_either: bool = False
    escape_mu: float = 1e-10
    carry_margin: float = 2e-3
    arrangements: int = 3
    polish_iterations: int = 25
    quick_polish_iterations: int = 5
    descent_steps: int = 50
    quick_descent: bool = False
    descent_budget: int = 1
    max_iterations: int = 100
    bound_budget: int = 64


#: Newton settings of the coarsest mesh's starts: damped steps (a stiffness-scaled
#: correction that decays from step to step) keep each start near its own arrangement,
#: and a start is never stopped as stalled (:func:`~.explore.explore`).
EXPLORE = NewtonOptions(plain_first=False, metric="stiffness", stall_steps=0)
