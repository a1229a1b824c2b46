r"""The penalty method (for comparison with the paper's direct method).

The unilateral condition :math:`w_k \le 0` on the constrained nodes I is relaxed into
a spring of stiffness :math:`\rho` at every node that penetrates the obstacle:

.. math::

    \lambda(\rho) = \min_{v \ne 0} R_\rho(v), \qquad
    R_\rho(v) = \frac{a(v, v) + \rho \sum_{k \in I} \max(0, v_k)^2}{b(v, v)}.

For v in the cone the penalty term vanishes, so :math:`\lambda(\rho) \le \lambda_c`;
:math:`R_\rho` grows pointwise with :math:`\rho`, so :math:`\lambda(\rho)` is
non-decreasing, and :math:`\lambda(\rho) \to \lambda_c` as :math:`\rho \to \infty`.

:math:`R_\rho` is piecewise quadratic. On the set S of penetrating nodes it is the
Rayleigh quotient of :math:`A_S = A + \rho \sum_{k \in S} e_k e_k^T`, so the method
iterates on S (a semismooth Newton step): solve the smallest eigenpair of
:math:`(A_S, B)`, orient the mode (its sign is free) to minimise the penetration, and
take as the next S the nodes with :math:`v_k > 0` (when both orientations penetrate
alike, as the antisymmetric free mode of the paper's symmetric plate does, the tie is
broken deterministically, see :data:`~unibuckle_fenicsx.tolerances.ENERGY_TIE_RTOL`). A
fixed point (S repeats) is a stationary point of :math:`R_\rho`; a set that reappears after
more than one step is a cycle, which is reported (the iterate with the smallest
:math:`R_\rho` is returned).

The stationary point found is not proven to be the global minimum of :math:`R_\rho`,
and its mode penetrates the obstacle by :math:`O(1/\rho)`: the result is neither a
proven bound nor an admissible mode, so it gives no upper bound (only the load of an
admissible mode is one). The lower bound reported is :math:`\lambda_{free}`
(interlacing). ``rho`` is given relative to the largest diagonal entry of A:
:math:`\rho_{abs} = \rho \max_j A_{jj}`.

A is assembled once (by :class:`~unibuckle_fenicsx.model.plate.model.PlateModel`); the
springs are added on the diagonal of a private copy :math:`A_{pen}`, which has its
own :class:`~unibuckle_fenicsx.la.eigen.GEPSolver` with the options prefix
``unibuckle_penalty_``.

Note:
    Everything here is collective on the problem's communicator.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

from petsc4py import PETSc

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms import RunStatus, UnilateralSolution
from unibuckle_fenicsx.algorithms.records import PenaltyDetails
from unibuckle_fenicsx.algorithms.sets import SetLog
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.la.eigen import (
    EIGEN_OPTIONS,
    EXTREME_OPTIONS,
    GEPSolver,
    extreme_eigenvalues,
)
from unibuckle_fenicsx.la.options import Prefix
from unibuckle_fenicsx.la.ownership import Owner, release
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem, require_obstacle
from unibuckle_fenicsx.progress import warn_once
from unibuckle_fenicsx.tolerances import ENERGY_TIE_RTOL

__all__ = [
    "PenaltySolver",
    "PenaltyStep",
    "SpringIteration",
    "solve_penalty",
]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class PenaltyStep:
    r"""One eigen solve of the iteration on the penetrating set.

    Attributes:
        springs: Sorted node numbers carrying a spring in this solve (the set S).
        load: Smallest eigenvalue :math:`\lambda_S` of :math:`(A_S, B)`.
        quotient: :math:`R_\rho` of the oriented mode (equals ``load`` at a fixed point).
        penetration: Largest oriented :math:`w_k/\max|w|` over I (0 if none penetrates).
        penetrating: Sorted node numbers with :math:`w_k` above the threshold: the next S.
    """

    springs: npt.NDArray[np.int64]
    load: float
    quotient: float
    penetration: float
    penetrating: npt.NDArray[np.int64]


@dataclass(frozen=True)
class SpringIteration:
    r"""How :meth:`PenaltySolver.iterate_springs` ended.

    Attributes:
        candidate: The returned mode (the iterate with the smallest quotient), its load
            the quotient and its ``active`` set the nodes pressing the springs.
        steps: Every eigen solve.
        step: The returned iterate's step.
        status: CONVERGED (a fixed point), CYCLE, MAX_ITERATIONS or NO_FINITE_LOAD.
        cycle_length: Length of the cycle (0 if none).
        ties: Orientation ties broken by the deterministic rule.
        lower_bound: :math:`\lambda_{free}`.
    """

    candidate: Candidate
    steps: list[PenaltyStep]
    step: PenaltyStep
    status: RunStatus
    cycle_length: int
    ties: int
    lower_bound: float


def _key(nodes: npt.NDArray[np.int64]) -> tuple[int, ...]:
    return tuple(int(k) for k in nodes)


@dataclass
class _Iteration:
    """The state of one spring-set iteration (:meth:`PenaltySolver.iterate_springs`)."""

    weights: npt.NDArray[np.float64]
    active: npt.NDArray[np.int64]
    lower_bound: float | None
    best: PETSc.Vec | None = None
    best_q: float = math.inf
    best_step: int = -1
    previous: PETSc.Vec | None = None
    seen: SetLog = field(default_factory=SetLog)
    steps: list[PenaltyStep] = field(default_factory=list)
    status: RunStatus = RunStatus.MAX_ITERATIONS
    cycle_length: int = 0
    ties: int = 0
    hold_pressed: bool = False


def held_nodes(
    values: npt.NDArray[np.float64],
    weights: npt.NDArray[np.float64],
    active: npt.NDArray[np.int64],
    threshold: float,
) -> npt.NDArray[np.int64]:
    r"""The nodes of ``active`` whose spring force exceeds ``threshold`` of the largest.

    A stiff spring lets its node press by only :math:`f_k/\rho_k`, below any threshold
    on the values once :math:`\rho_k` is large; its force :math:`f_k = \rho_k v_k` is
    what says it presses. ``values`` are oriented, scaled by max|w|.
    """
    if not active.size:
        return active
    force = weights[active] * values[active]
    scale = float(force.max())
    if not scale > 0.0:
        return active[:0]
    return active[force > threshold * scale].astype(np.int64)


def _orientation(
    vals: npt.NDArray[np.float64],
    weights: npt.NDArray[np.float64],
    tie_rtol: float,
    threshold: float,
) -> tuple[float, bool]:
    """The sign that penetrates less (spring energy), and whether the two tied.

    On a tie (e.g. the antisymmetric free mode under a zone symmetric about x = 0: both
    orientations penetrate alike, and the two unilateral modes are mirror images with
    equal loads) rounding would decide, and the choice would flip with tiny changes of
    rho; the lexicographically smaller penetrating set is taken instead (the
    enumeration's tie rule).
    """
    up = float(np.sum(weights * np.maximum(vals, 0.0) ** 2))
    down = float(np.sum(weights * np.maximum(-vals, 0.0) ** 2))
    if abs(up - down) > tie_rtol * (up + down):
        return (1.0 if up < down else -1.0), False
    plus = _key(np.flatnonzero(vals > threshold))
    minus = _key(np.flatnonzero(-vals > threshold))
    return (1.0 if plus <= minus else -1.0), True


class PenaltySolver(Owner):
    r"""Penalised pencil :math:`(A + \rho_{abs} \sum_{k\in S} e_k e_k^T, B)` of a problem.

    Args:
        problem: A :class:`~unibuckle_fenicsx.model.problem.UnilateralProblem` with an obstacle.
        prefix: Options prefix of the eigen solver (``-<prefix>eps_view`` etc. apply).
        eps_options: Extra EPS options under ``prefix`` (merged into
            :data:`~unibuckle_fenicsx.la.eigen.EIGEN_OPTIONS`).

    Attributes:
        max_diag: :math:`\max_j A_{jj}`, the unit of the relative penalty.
        solves: Eigen solves performed by this object (the condition estimates excluded).

    Note:
        Construction, every method and :meth:`destroy` are collective. The caller owns
        the object and must :meth:`destroy` it.
    """

    def __init__(
        self,
        problem: UnilateralProblem,
        prefix: str = Prefix.PENALTY,
        eps_options: dict[str, str | float | int] | None = None,
    ) -> None:
        require_obstacle(problem, "the penalty method")
        self.problem = problem
        A = problem.model.A
        diag = A.getDiagonal()
        self.max_diag = float(diag.max()[1])
        diag.destroy()
        self.A_pen = A.duplicate(copy=True)
        self._springs = A.createVecLeft()
        self._work = A.createVecLeft()
        self._Av = A.createVecLeft()
        self._Bv = A.createVecLeft()
        self._active = np.empty(0, dtype=np.int64)
        options = {**EIGEN_OPTIONS, **(eps_options or {})}
        self.gep = GEPSolver(
            self.A_pen,
            problem.model.B,
            indefinite=problem.prestress.indefinite,
            prefix=prefix,
            tol=problem.spec.solver.eps_tol,
            options=options,
        )
        self.solves = 0

    # -- the penalised operator ---------------------------------------------------------
    def set_springs(
        self, rho_abs: float | npt.NDArray[np.float64], active: npt.NDArray[np.int64]
    ) -> None:
        r""":math:`A_{pen} = A + \sum_{k \in S} \rho_k e_k e_k^T` (S = ``active``), in place.

        Args:
            rho_abs: The spring stiffness :math:`\rho_k`: one value for every node, or
                one per constrained node (i,).
            active: The spring set S (node numbers).
        """
        same = PETSc.Mat.Structure.SAME_NONZERO_PATTERN
        self.problem.model.A.copy(self.A_pen, structure=same)
        self._springs.zeroEntries()
        rows, nodes = self.problem.contact.node_rows(active)
        values = np.broadcast_to(np.asarray(rho_abs, dtype=float), (self.problem.contact.size,))
        self._springs.setValues(rows.astype(PETSc.IntType), values[nodes])
        self._springs.assemble()
        self.A_pen.setDiagonal(self._springs, addv=PETSc.InsertMode.ADD_VALUES)
        self.gep.operators_changed()
        self._active = np.asarray(active, dtype=np.int64)

    def quotient(self, vec: PETSc.Vec, rho_abs: float | npt.NDArray[np.float64]) -> float:
        r""":math:`R_\rho(v) = (v^TAv + \sum_I \rho_k \max(0, v_k)^2) / v^TBv`.

        ``rho_abs``: one stiffness for every node, or one per constrained node; v_k are the
        oriented values at the constrained nodes.
        """
        self.problem.model.A.mult(vec, self._Av)
        self.problem.model.B.mult(vec, self._Bv)
        vals = self.problem.contact.values(vec)
        num = float(np.real(vec.dot(self._Av))) + float(
            np.sum(np.asarray(rho_abs) * np.maximum(vals, 0.0) ** 2)
        )
        den = float(np.real(vec.dot(self._Bv)))
        return float(num / den) if den > 0.0 else math.inf

    def condition_number(self) -> tuple[float, float]:
        r"""Extreme eigenvalues of the current :math:`A_{pen}` restricted to the free DOFs.

        The edge-constrained rows (diagonal 1, decoupled) are left out, so this is the
        spectrum of the operator that actually carries the physics; the 2-norm condition
        number of this SPD matrix is the ratio of the two values
        (:func:`~unibuckle_fenicsx.la.eigen.extreme_eigenvalues`, options prefix
        ``unibuckle_penalty_cond_``).

        Returns:
            (smallest, largest) eigenvalue.
        """
        model = self.problem.model
        n_owned = model.num_owned_dofs
        owned_bc = model.bc_dofs[model.bc_dofs < n_owned]
        keep = np.setdiff1d(np.arange(n_owned, dtype=np.int32), owned_bc)
        rows = model.global_dofs(keep).astype(PETSc.IntType)
        iset = PETSc.IS().createGeneral(rows, comm=self.A_pen.comm)  # type: ignore[arg-type]
        sub = self.A_pen.createSubMatrix(iset, iset)
        iset.destroy()
        try:
            return extreme_eigenvalues(sub, Prefix.PENALTY_CONDITION, EXTREME_OPTIONS)
        finally:
            sub.destroy()

    # -- the iteration ----------------------------------------------------------------
    def solve(
        self,
        rho: float,
        *,
        initial_active: npt.NDArray[np.int64] | None = None,
        max_iterations: int = 100,
        threshold: float = 0.0,
        condition: bool = False,
        lower_bound: float | None = None,
        tie_rtol: float = ENERGY_TIE_RTOL,
    ) -> UnilateralSolution:
        r"""Iterate on the penetrating set for one penalty.

        Args:
            rho: Penalty relative to :math:`\max_j A_{jj}`, finite and > 0.
            initial_active: Starting spring set S_0 (node numbers; default empty, whose
                first solve is the free plate). For a sequence of penalties, pass the
                previous penalty's set (continuation).
            max_iterations: Eigen solves allowed, >= 1.
            threshold: A node penetrates when :math:`w_k` above the threshold * max|w|; in
                [0, 1e-2].
            condition: Also estimate the condition number of the final :math:`A_{pen}`
                (:meth:`condition_number`, two extra SLEPc solves).
            lower_bound: :math:`\lambda_{free}` if known; else taken from the first solve
                when S_0 is empty, or computed with one extra solve.
            tie_rtol: The two orientations of a mode tie when their penalty energies
                :math:`\sum \max(0, \pm v_k)^2` differ by at most this, relatively; a
                tie is broken by the lexicographically smaller penetrating set. In
                [0, 1); 0 leaves ties to rounding (for studying its effect).

        Returns:
            The solution; its candidate's ``load`` is :math:`R_\rho` of the returned mode
            (a stationary value of the penalised quotient; <= the critical load if it is
            the global minimum, which is not proven), its ``active`` set the penetrating
            set (where the springs act); ``lower_bound`` = :math:`\lambda_{free}`,
            ``upper_bound`` = inf (the mode penetrates), ``global_optimum_proven``
            False, and ``details`` (see the code).
        """
        if not (isinstance(rho, int | float) and math.isfinite(rho) and rho > 0.0):
            raise InputError(f"rho (relative penalty) must be finite and > 0, got {rho!r}")
        rho_abs = float(rho) * self.max_diag
        solves0 = self.solves
        it = self.iterate_springs(
            rho_abs,
            initial_active=initial_active,
            max_iterations=max_iterations,
            threshold=threshold,
            lower_bound=lower_bound,
            tie_rtol=tie_rtol,
            label=f"penalty rho={rho:.3g}",
        )
        step = it.step
        details = PenaltyDetails(
            penalty_rho=float(rho),
            penalty_rho_abs=rho_abs,
            penalty_max_diag_A=self.max_diag,
            penalty_status=it.status,
            penalty_cycle_length=it.cycle_length,
            penalty_iterations=len(it.steps),
            penalty_orientation_ties=it.ties,
            penalty_max_penetration=step.penetration,
            penalty_penetrating_set=[int(k) for k in step.penetrating],
            penalty_springs=[int(k) for k in step.springs],
            penalty_eigenvalue=step.load,
            penalty_history=[s.quotient for s in it.steps],
        )
        if condition:
            lo, hi = self.condition_number()
            details.penalty_eig_min_A_pen = lo
            details.penalty_eig_max_A_pen = hi
            details.penalty_condition_number = hi / lo
        return UnilateralSolution(
            candidate=it.candidate,
            method="penalty",
            eigensolves=self.solves - solves0,
            lower_bound=float(it.lower_bound),
            global_optimum_proven=False,
            upper_bound=math.inf,
            details=details,
        )

    def iterate_springs(
        self,
        rho_abs: float | npt.NDArray[np.float64],
        *,
        initial_active: npt.NDArray[np.int64] | None = None,
        max_iterations: int = 100,
        threshold: float = 0.0,
        lower_bound: float | None = None,
        tie_rtol: float = ENERGY_TIE_RTOL,
        label: str = "springs",
        hold_pressed: bool = False,
    ) -> SpringIteration:
        r"""The iteration on the spring set S for the springs ``rho_abs`` (N/m).

        Minimises :math:`(a(v,v) + \sum_{k\in I}\rho_k\max(0, v_k)^2)/b(v,v)` (see the
        module docstring): the penalty method with one stiffness for every node, or a
        tensionless Winkler foundation with its physical nodal springs.

        Args:
            rho_abs: Absolute spring stiffness: one value, or one per constrained node.
            initial_active: Starting spring set S_0 (default empty: the free plate).
            max_iterations: Eigen solves allowed, >= 1.
            threshold: A node penetrates when :math:`v_k >` threshold * max|w|, in
                [0, 1e-2].
            lower_bound: :math:`\lambda_{free}` if known (see :meth:`solve`).
            tie_rtol: Tie tolerance of the two orientations' spring energies, in [0, 1).
            label: Name in log messages.
            hold_pressed: A node of S also presses while its spring force
                :math:`\rho_k v_k` exceeds ``threshold`` times the largest force of S,
                however small :math:`v_k` (:func:`held_nodes`): stiff springs press
                deep below ``threshold`` * max|w|.

        Returns:
            The iteration (the returned candidate, every step, how it ended).

        Note:
            Collective.
        """
        weights, active = self._check_iteration(
            rho_abs, initial_active, max_iterations, threshold, tie_rtol
        )
        run = _Iteration(weights, active, lower_bound, hold_pressed=hold_pressed)
        for it in range(int(max_iterations)):
            if self._spring_step(run, it, threshold, tie_rtol, label):
                break
        if run.status is RunStatus.MAX_ITERATIONS:
            warn_once(
                logger, self.problem.comm,
                "%s: no fixed point after %d solves (-max_iterations)", label, max_iterations,
            )  # fmt: skip
        return self._spring_result(run)

    def _check_iteration(
        self,
        rho_abs: float | npt.NDArray[np.float64],
        initial_active: npt.NDArray[np.int64] | None,
        max_iterations: int,
        threshold: float,
        tie_rtol: float,
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
        """The nodal springs and the first spring set; settings out of range refused."""
        contact = self.problem.contact
        weights = np.broadcast_to(np.asarray(rho_abs, dtype=float), (contact.size,))
        if not (np.all(np.isfinite(weights)) and np.all(weights > 0.0)):
            raise InputError("rho_abs (spring stiffness) must be finite and > 0 at every node")
        if int(max_iterations) != max_iterations or max_iterations < 1:
            raise InputError(f"max_iterations must be an integer >= 1, got {max_iterations!r}")
        if not 0.0 <= tie_rtol < 1.0:
            raise InputError(f"tie_rtol must lie in [0, 1), got {tie_rtol!r}")
        if not 0.0 <= threshold <= 1e-2:
            raise InputError(f"threshold must lie in [0, 1e-2], got {threshold!r}")
        i = contact.size
        active = np.unique(np.asarray([] if initial_active is None else initial_active, np.int64))
        if active.size and (active.min() < 0 or active.max() >= i):
            raise InputError(f"initial_active must hold node numbers in [0, {i}), got {active}")
        return weights, active

    def _spring_step(
        self, run: _Iteration, it: int, threshold: float, tie_rtol: float, label: str
    ) -> bool:
        """One eigen solve with the springs of ``run.active``; whether the iteration ends."""
        problem, vec = self.problem, self._work
        run.seen.visit(run.active, it)
        self.set_springs(run.weights, run.active)
        pair = self.gep.solve(out=vec, initial=run.previous)
        self.solves += 1
        if run.lower_bound is None and not run.active.size:
            run.lower_bound = pair.value
        # A mode without deflection (w = 0: b(v, v) = 0, an infinite load) is not scaled.
        wmax = problem.max_abs_w(vec) or 1.0
        vals = problem.contact.values(vec) / wmax
        sign, tie = _orientation(vals, run.weights, tie_rtol, threshold)
        run.ties += tie
        vec.scale(sign / wmax)
        vals = sign * vals
        q = self.quotient(vec, run.weights)
        penetrating = np.flatnonzero(vals > threshold).astype(np.int64)
        if run.hold_pressed:
            penetrating = np.union1d(
                penetrating, held_nodes(vals, run.weights, run.active, threshold)
            )
        run.steps.append(
            PenaltyStep(run.active, pair.value, q, max(float(vals.max()), 0.0), penetrating)
        )
        logger.debug(
            "%s it %d: |S|=%d lambda_S=%.10g R=%.10g penetration %.3g",
            label, it, run.active.size, pair.value, q, run.steps[-1].penetration,
        )  # fmt: skip
        if q < run.best_q:
            run.best_q, run.best_step = q, it
            if run.best is None:
                run.best = vec.copy()
            else:
                vec.copy(run.best)
        if run.previous is None:
            run.previous = vec.copy()
        else:
            vec.copy(run.previous)
        if np.array_equal(penetrating, run.active):
            run.status = RunStatus.CONVERGED
            return True
        if penetrating in run.seen:
            run.status = RunStatus.CYCLE
            run.cycle_length = run.seen.cycle_length(penetrating, it)
            warn_once(
                logger, self.problem.comm,
                "%s: the penetrating set cycles (length %d) after %d solves; "
                "returning the iterate with the smallest penalised quotient",
                label, run.cycle_length, it + 1,
            )  # fmt: skip
            return True
        run.active = penetrating
        return False

    def _spring_result(self, run: _Iteration) -> SpringIteration:
        """The iterate with the smallest quotient as the result; the work vectors freed."""
        problem = self.problem
        if run.best is None:
            # Every iterate had b(v, v) <= 0 (an infinite penalised quotient): the load
            # grows without bound with rho, no admissible mode buckles. Keep the last.
            run.best, run.best_step = self._work.copy(), len(run.steps) - 1
            run.status = RunStatus.NO_FINITE_LOAD
        if run.previous is not None:
            run.previous.destroy()
        u = problem.new_mode()
        run.best.copy(u.x.petsc_vec)
        u.x.scatter_forward()
        run.best.destroy()
        step = run.steps[run.best_step]
        # Oriented and scaled above: the iteration's own orientation minimises R_rho.
        candidate = problem.candidate(u, step.quotient, step.penetrating, sign=1.0)
        if run.status is not RunStatus.CONVERGED:
            # Leave A_pen with the springs of the returned mode, for condition().
            self.set_springs(run.weights, step.springs)
        lower_bound = run.lower_bound
        if lower_bound is None:
            fresh = problem.free is None
            lower_bound = problem.solve_free().load
            self.solves += int(fresh)
        return SpringIteration(
            candidate, run.steps, step, run.status, run.cycle_length, run.ties, float(lower_bound)
        )

    def destroy(self) -> None:
        """Destroy the eigen solver, A_pen and the work vectors (collective)."""
        release(self, "gep", "A_pen", "_springs", "_work", "_Av", "_Bv")

    def __del__(self) -> None:
        self.destroy()


def solve_penalty(
    problem: UnilateralProblem,
    rho: float,
    *,
    initial_active: npt.NDArray[np.int64] | None = None,
    max_iterations: int = 100,
    threshold: float = 0.0,
    condition: bool = False,
    tie_rtol: float = ENERGY_TIE_RTOL,
    eps_options: dict[str, str | float | int] | None = None,
) -> UnilateralSolution:
    r"""Penalty method for one relative penalty ``rho`` (see the module docstring).

    Args:
        problem: A :class:`~unibuckle_fenicsx.model.problem.UnilateralProblem` with an obstacle.
        rho: Penalty relative to the largest diagonal entry of A, finite and > 0.
        initial_active: Starting spring set (default empty).
        max_iterations: Eigen solves allowed, >= 1.
        threshold: Relative penetration that counts, in [0, 1e-2].
        condition: Also estimate the condition number of the penalised operator.
        tie_rtol: Tie tolerance of the two orientations (see :meth:`PenaltySolver.solve`).
        eps_options: Extra options under ``unibuckle_penalty_``.

    Returns:
        The solution; see :meth:`PenaltySolver.solve`.

    Note:
        Collective.
    """
    if not (isinstance(rho, int | float) and math.isfinite(rho) and rho > 0.0):
        raise InputError(f"rho (relative penalty) must be finite and > 0, got {rho!r}")
    solver = PenaltySolver(problem, eps_options=eps_options)
    try:
        return solver.solve(
            rho,
            initial_active=initial_active,
            max_iterations=max_iterations,
            threshold=threshold,
            condition=condition,
            tie_rtol=tie_rtol,
        )
    finally:
        solver.destroy()
