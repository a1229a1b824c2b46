r"""Certificates of a unilateral critical state: local (KKT) and global (lower bound).

Local. A candidate (:math:`\lambda`, u, Z) is a critical state of the discrete problem
when (:doc:`/methods/problem`; paper, Lemma 5.1)

- :math:`r = Au - \lambda Bu` vanishes off Z (relative residual below :math:`\sqrt\tau`),
- :math:`u_k \le \tau \max|w|` on I (the mode does not cross the obstacle),
- :math:`r_k \le \tau \|Au\|_\infty` on Z (the obstacle only pushes),
- :math:`\lambda` is the smallest eigenvalue of the pencil with Z removed: checked by the
  inertia of :math:`A_Z - \lambda(1 - \delta) B_Z` (Sylvester: its negative eigenvalues
  count the reduced pencil's eigenvalues in :math:`(0, \lambda(1-\delta))`), with
  :math:`\delta = 10^3` ``eps_tol`` (one sparse :math:`LDL^T`).

Global. The algorithms bracket the critical load: any admissible mode's load is an upper
bound; interlacing, the lattice search and exhaustive enumeration give lower bounds, and
:mod:`unibuckle_fenicsx.certificate.copositivity` proves one just below a KKT point's load when
:math:`A - \lambda B` is copositive on the cone there (a rank-2 certificate that costs one
sparse :math:`LDL^T`, or a semidefinite program for small i), or, when several pencil
eigenvalues lie below the load, a slightly lower one by the low-rank route
(:mod:`unibuckle_fenicsx.certificate.copositivity_lowrank`). The result is a *verified
bracket*: *proven* globally optimal when it closes to
:data:`~unibuckle_fenicsx.tolerances.PROOF_GAP`, *bracketed* when its verified relative gap is
at most :data:`~unibuckle_fenicsx.tolerances.BRACKET_GAP` (the load is then known to that
accuracy: no admissible mode has a load below the lower bound), otherwise "KKT only".
The smallest-eigenvalue check runs on every route, proven or not. When the low-rank
route meets an admissible mode with a lower load than the KKT point's, the point is
refuted: the certificate hands that mode back (``Certificate.refuting_mode``) and its
load becomes the upper bound.

Every check here is collective on the problem's communicator.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

from petsc4py import PETSc

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms import RunStatus, UnilateralSolution
from unibuckle_fenicsx.algorithms.foundation import pressing_nodes
from unibuckle_fenicsx.algorithms.penalty import held_nodes
from unibuckle_fenicsx.certificate.copositivity import BoundOptions, copositivity_bound
from unibuckle_fenicsx.certificate.records import CopositivityRecord, Refuting
from unibuckle_fenicsx.certificate.shifted import ShiftedMatrix, rayleigh
from unibuckle_fenicsx.errors import EigenSolveError, InputError
from unibuckle_fenicsx.la.factor import SymmetricFactorization
from unibuckle_fenicsx.la.options import Prefix
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem
from unibuckle_fenicsx.tolerances import (
    BRACKET_GAP,
    PRESSING_RTOL,
    PROOF_GAP,
    ROUNDING_RTOL,
    SMALLEST_RTOL_FACTOR,
)

__all__ = [
    "BRACKET_GAP",
    "PROOF_GAP",
    "Certificate",
    "certify",
    "certify_foundation",
    "pencil_inertia",
    "reduced_inertia",
    "spring_inertia",
]

logger = logging.getLogger(__name__)


def _within(gap: float, limit: float) -> bool:
    """Whether the relative gap is at most ``limit``, up to the rounding of the gap.

    A bound verified at lambda (1 - limit) gives the gap ``limit`` to its last bits, on
    either side of it (:data:`~unibuckle_fenicsx.tolerances.ROUNDING_RTOL`).
    """
    return gap <= limit * (1 + ROUNDING_RTOL)


@dataclass(frozen=True)
class Certificate:
    r"""What was verified about a returned critical state.

    Attributes:
        feasible: :math:`u_k \le \tau \max|w|` on every constrained node.
        feasibility_margin: :math:`\max_{I \setminus Z} u_k / \max|w|` (negative: strictly
            below the obstacle; ``-inf`` when Z = I).
        max_contact_force: :math:`\max_Z r_k / \|Au\|_\infty` (``-inf`` when Z is empty).
        max_contact_value: :math:`\max_Z |u_k| / \max|w|` (0 for an eigenvector of the
            reduced pencil; checked, not assumed).
        relative_residual: :math:`\|r\ \text{off}\ Z\|_2 / \|Au\|_2`.
        tolerance: :math:`\tau`.
        kkt: Feasible, forces at most :math:`\tau`, residual at most :math:`\sqrt\tau`.
        smallest_of_reduced: :math:`\lambda` is the smallest eigenvalue of the reduced
            pencil (inertia check, on every route); ``None`` when not checked
            (certification off, or a mode not computed by an eigen solve).
        lower_bound: Verified lower bound on the critical load.
        upper_bound: Load of an admissible mode (``inf`` if the mode is not admissible).
        relative_gap: (upper - lower) / upper.
        global_optimum_proven: The gap is at most :data:`~unibuckle_fenicsx.tolerances.PROOF_GAP`
            (up to the rounding of the gap, :data:`~unibuckle_fenicsx.tolerances.ROUNDING_RTOL`).
        proven_by: What gave the lower bound: "interlacing" (the free load),
            "lattice", "enumeration", or a copositivity route ("rank2-spn", "sdp-spn",
            "sdp-sectors", "lowrank-spn", "psd").
        copositivity: The copositivity certificate's record (route, delta, verified
            margins, m, factorisations, solves, seconds, the low-rank route's record),
            or None if it did not run.
        notes: Anything that failed or was skipped, in words.
        refuting_mode: An admissible mode with a lower load than the returned one, found
            by the low-rank route (the returned KKT point is then not the global
            minimum): a :class:`~unibuckle_fenicsx.model.problem.Candidate` (its ``eigen`` is
            None: a Rayleigh quotient, not an eigenpair) from which a solver can
            continue. Not in ``as_dict`` (its load is: ``refuting_load_Pa``).
    """

    feasible: bool
    feasibility_margin: float
    max_contact_force: float
    relative_residual: float
    tolerance: float
    kkt: bool
    smallest_of_reduced: bool | None
    lower_bound: float
    upper_bound: float
    relative_gap: float
    global_optimum_proven: bool
    proven_by: str
    copositivity: CopositivityRecord | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)
    max_contact_value: float = 0.0
    refuting_mode: Candidate | None = None

    @property
    def status(self) -> str:
        """One of proven, bracketed (verified gap <= BRACKET_GAP), kkt-only, not-kkt.

        "kkt-only" says a critical state: the load must also be its reduced pencil's
        smallest eigenvalue (paper, Lemma 5.1). A pair checked and found not to be
        (``smallest_of_reduced`` False) is "not-kkt" unless its verified bracket closes
        (proven, bracketed): an admissible load above a verified bound stands on its own.
        """
        if not self.kkt:
            return "not-kkt"
        if self.global_optimum_proven:
            return "proven"
        if self.proven_by != "interlacing" and _within(self.relative_gap, BRACKET_GAP):
            return "bracketed"
        if self.smallest_of_reduced is False:
            return "not-kkt"
        return "kkt-only"

    @property
    def negative_eigenvalues(self) -> int | None:
        """m: pencil eigenvalues below the shifts tried (None if no factorisation ran)."""
        if self.copositivity is None:
            return None
        m = self.copositivity.negative_eigenvalues
        return None if m is None else int(m)


def reduced_inertia(
    problem: UnilateralProblem,
    active: npt.NDArray[np.int64],
    sigma: float,
    matrix: ShiftedMatrix | None = None,
) -> tuple[int, int, int]:
    r"""Inertia of :math:`A_Z - \sigma B_Z`, the pencil with the contact set Z removed.

    Its negative count is the number of eigenvalues of the reduced pencil in
    :math:`(0, \sigma)` (Sylvester's law of inertia, A SPD). With ``matrix`` (a
    :class:`~.shifted.ShiftedMatrix` of the same pencil, already factorised) its
    symbolic analysis is reused: one numeric factorisation.

    Note:
        Collective.
    """
    rows = problem.contact.removed_rows(active)
    if matrix is not None:
        return matrix.factor_reduced(rows, sigma)
    A_Z, B_Z = problem.eigensolver.reduced(rows)
    return pencil_inertia(A_Z, B_Z, sigma)


def pencil_inertia(
    A: PETSc.Mat, B: PETSc.Mat, sigma: float, diagonal: PETSc.Vec | None = None
) -> tuple[int, int, int]:
    r"""Inertia (negative, zero, positive) of :math:`A + \mathrm{diag}(d) - \sigma B`.

    One MUMPS :math:`LDL^T` under the prefix ``unibuckle_certify_``; A and B are not
    modified, ``diagonal`` (d) is optional.

    Note:
        Collective.
    """
    K = A.duplicate(copy=True)
    try:
        if diagonal is not None:
            K.setDiagonal(diagonal, addv=PETSc.InsertMode.ADD_VALUES)  # type: ignore[arg-type]
        K.axpy(-sigma, B, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)  # type: ignore[arg-type]
        factor = SymmetricFactorization(K, Prefix.CERTIFY)
        try:
            return factor.inertia()
        finally:
            factor.destroy()
    finally:
        K.destroy()


def _residual_off_contact(problem: UnilateralProblem, candidate: Candidate) -> float:
    r""":math:`\|r\|_2 / \|Au\|_2` with the rows of Z left out."""
    r, _, au_2 = problem.residual(candidate.load, candidate.mode.x.petsc_vec)
    rows = problem.contact.removed_rows(candidate.active)
    r.setValues(rows.astype(PETSc.IntType), np.zeros(len(rows)))  # type: ignore[arg-type]
    r.assemble()
    return float(r.norm()) / au_2  # type: ignore[arg-type]


def _as_solution(
    problem: UnilateralProblem, solution: UnilateralSolution | Candidate
) -> UnilateralSolution:
    """A bare candidate as a solution with the interlacing bracket [lambda_free, lambda]."""
    if not isinstance(solution, Candidate):
        return solution
    return UnilateralSolution(
        candidate=solution,
        method="candidate",
        eigensolves=0,
        lower_bound=problem.solve_free().load,
        global_optimum_proven=False,
        upper_bound=solution.load if solution.feasible else math.inf,
    )


def certify(
    problem: UnilateralProblem,
    solution: UnilateralSolution | Candidate,
    *,
    global_bound: bool | None = None,
    check_smallest: bool = True,
    options: BoundOptions | None = None,
) -> Certificate:
    r"""Certify ``solution`` (its candidate and its bracket) on ``problem``.

    Args:
        problem: The problem the solution was computed on.
        solution: An algorithm's result, or a bare candidate (whose bracket is then
            :math:`[\lambda_{free}, \lambda]`, by interlacing).
        global_bound: Try the copositivity certificate of global optimality (default:
            ``problem.spec.solver.certify``), unless the algorithm proved it already.
        check_smallest: When the optimum is not proven, verify by inertia that the load
            is the smallest eigenvalue of the reduced pencil (one sparse factorisation).
        options: Settings of the copositivity certificate.

    Note:
        Collective.
    """
    solution = _as_solution(problem, solution)
    if global_bound is None:
        global_bound = problem.spec.solver.certify
    cand = solution.candidate
    if not math.isfinite(cand.load):
        raise ValueError("certify: the candidate has no finite load")
    notes: list[str] = []
    kkt, residual, on_contact = _local(problem, cand, notes)
    br = _Bracket.of(solution, notes, SMALLEST_RTOL_FACTOR * problem.spec.solver.eps_tol)
    algorithm_proof = solution.global_optimum_proven
    smallest: bool | None = None
    # One matrix for the copositivity attempt and the smallest-eigenvalue check, both
    # factorised through the mesh's shared LDL^T (its symbolic analysis done once).
    matrix = ShiftedMatrix(
        problem.model.A, problem.model.B, shared=problem.eigensolver.factorization
    )
    try:
        if not algorithm_proof and global_bound and kkt and cand.eigen is not None:
            _copositivity(problem, solution, options, matrix, br)
        elif not algorithm_proof and not global_bound:
            br.notes.append("global certification skipped (solver.certify = false)")
        if check_smallest and global_bound and cand.eigen is not None:
            smallest = _smallest(problem, cand, matrix, br.notes)
        elif cand.eigen is None:
            br.notes.append("the mode is not an eigenvector of a reduced pencil (not checked)")
    finally:
        matrix.destroy()
    gap = (br.upper - br.lower) / br.upper if math.isfinite(br.upper) else math.inf
    closed = _within(gap, PROOF_GAP)
    proven = bool(kkt and closed and (algorithm_proof or br.proven_by != "interlacing"))
    # The free load is the lower bound (interlacing), or lies above the returned load,
    # which no smallest eigenvalue can: it is verified the pencil's smallest (one LDL^T).
    free = problem.solve_free().load
    below_free = cand.feasible and cand.load < free * (1.0 - ROUNDING_RTOL)
    if global_bound and (br.proven_by == "interlacing" or below_free):
        problem.verify_free()
    return Certificate(
        feasible=cand.feasible,
        feasibility_margin=cand.margin,
        max_contact_force=cand.max_force,
        max_contact_value=on_contact,
        relative_residual=residual,
        tolerance=problem.tau,
        kkt=bool(kkt),
        smallest_of_reduced=smallest,
        lower_bound=br.lower,
        upper_bound=br.upper,
        relative_gap=gap,
        global_optimum_proven=proven,
        proven_by=br.proven_by,
        copositivity=br.record,
        notes=tuple(br.notes),
        refuting_mode=br.refuting,
    )


@dataclass
class _Bracket:
    """The bracket of a certificate as it is built, with what proves its lower end."""

    lower: float
    upper: float
    proven_by: str
    notes: list[str]
    record: CopositivityRecord | None = None
    refuting: Candidate | None = None
    agree: float = 0.0

    def closed_within(self) -> None:
        """The lower end at most the upper, or an error: never a bound clipped to a load.

        A proven lower bound above an admissible load by more than ``agree`` (relative:
        the eigen solver's accuracy) is a contradiction: the bound is none, or the load
        is no mode's. Raises :class:`~unibuckle_fenicsx.errors.EigenSolveError` then;
        within it the two agree and the lower end is the upper.
        """
        _ordered(self.lower, self.upper, self.proven_by, self.agree)
        self.lower = min(self.lower, self.upper)

    @classmethod
    def of(cls, solution: UnilateralSolution, notes: list[str], agree: float) -> _Bracket:
        """The algorithm's bracket, the candidate's load its upper end if it may be.

        An upper end below the proven lower end by more than ``agree`` (relative: the
        eigen solver's accuracy) is a contradiction, not a bracket: raises
        :class:`~unibuckle_fenicsx.errors.EigenSolveError` (the mode is no eigenvector
        of its reduced pencil, or the lower bound no bound). Within it they agree, and
        the lower end is the upper.
        """
        cand = solution.candidate
        # Only the eigenvalue of a reduced pencil whose mode is admissible bounds the
        # critical load from above (a penalised quotient lies below it).
        upper = solution.upper_bound
        if cand.eigen is not None and cand.feasible:
            upper = min(upper, cand.load)
        elif not cand.feasible:
            notes.append("the mode crosses the obstacle: its load is not an upper bound")
        # No stated proof: the lower bound is the free load, by interlacing.
        proven_by = solution.lower_bound_by or "interlacing"
        br = cls(solution.lower_bound, upper, proven_by, notes, agree=agree)
        br.closed_within()
        return br


def _ordered(lower: float, upper: float, proven_by: str, agree: float) -> None:
    """Raise :class:`EigenSolveError` if the admissible load ``upper`` lies below ``lower``.

    Beyond the relative accuracy ``agree``: a load below a proven bound is an error,
    never the bound.
    """
    if upper < lower * (1.0 - agree):
        raise EigenSolveError(
            f"the admissible load {upper!r} lies below the proven lower bound {lower!r} "
            f"(by {proven_by}): the mode is not an eigenvector of its pencil, or the "
            "bound is none, and no bracket holds"
        )


def _local(
    problem: UnilateralProblem, cand: Candidate, notes: list[str]
) -> tuple[bool, float, float]:
    """The KKT conditions of ``cand``: (kkt, residual off Z, largest value on Z)."""
    tau = problem.tau
    residual = _residual_off_contact(problem, cand)
    # The mode must vanish on Z (checked, not assumed: a mode from elsewhere than an
    # eigen solve of the reduced pencil need not).
    on_contact = float(np.abs(cand.values[cand.active]).max(initial=0.0))
    kkt = (
        cand.feasible and cand.max_force <= tau and residual <= math.sqrt(tau) and on_contact <= tau
    )
    if on_contact > tau:
        notes.append(f"the mode does not vanish on the contact set (max |u_Z| = {on_contact:.3g})")
    return bool(kkt), residual, on_contact


def _copositivity(
    problem: UnilateralProblem,
    solution: UnilateralSolution,
    options: BoundOptions | None,
    matrix: ShiftedMatrix,
    br: _Bracket,
) -> None:
    """The copositivity certificate's bound (and refuting mode) into the bracket ``br``."""
    cand = solution.candidate
    if options is None:
        options = _bound_options(problem.spec.solver.bracket)
    bound = copositivity_bound(problem, cand, solution.kkt_points, options, matrix)
    br.record = CopositivityRecord(
        method=bound.method,
        delta=bound.delta,
        margins=bound.margins,
        negative_eigenvalues=bound.negative_eigenvalues,
        factorisations=int(bound.timings["factorisations"]),
        solves=int(bound.timings["solves"]),
        time_s=bound.timings["total_s"],
        free_solve_s=problem.timings.get("free_solve_s"),
        split=bound.split,
        lowrank=bound.lowrank,
    )
    br.notes += list(bound.notes)
    if bound.refuting is not None:
        refuting = _refuting_candidate(problem, bound.refuting)
        if refuting.feasible and refuting.load < cand.load:
            br.refuting = refuting
            br.upper = min(br.upper, refuting.load)
            br.notes.append(
                f"refuted: an admissible mode has the load {refuting.load!r} < "
                f"{cand.load!r} (Certificate.refuting_mode)"
            )
    if bound.value is not None and bound.value > br.lower:
        br.lower, br.proven_by = bound.value, bound.method
    br.closed_within()  # a bound above a refuting mode's or the candidate's load: an error


def _smallest(
    problem: UnilateralProblem, cand: Candidate, matrix: ShiftedMatrix, notes: list[str]
) -> bool:
    """Whether the load is the reduced pencil's smallest eigenvalue (inertia)."""
    sigma = cand.load * (1.0 - SMALLEST_RTOL_FACTOR * problem.spec.solver.eps_tol)
    neg, _, _ = reduced_inertia(problem, cand.active, sigma, matrix)
    if neg:
        notes.append(
            f"the reduced pencil has {neg} eigenvalue(s) below the returned load: "
            "not its smallest eigenpair"
        )
    return neg == 0


def _bound_options(bracket: bool) -> BoundOptions:
    """By default the split route within its cost limit; on request, thorough, then low rank."""
    from unibuckle_fenicsx.certificate.copositivity_split import SplitOptions

    if bracket:
        return BoundOptions(split=SplitOptions.thorough())
    return BoundOptions(lowrank=None)


def _refuting_candidate(problem: UnilateralProblem, refuting: Refuting) -> Candidate:
    """The route's refuting mode as a :class:`Candidate` (contact set: its zeros).

    The mode is set to exactly zero at the nodes within tau of the obstacle (its contact
    set), so that it lies in that set's subspace (a start for the feasible descent), and
    its load is its Rayleigh quotient after that.
    """
    u = problem.new_mode("refuting_mode")
    vec = u.x.petsc_vec
    vec.array[:] = refuting.vector
    values = problem.contact.values(vec) / problem.max_abs_w(vec)
    active = np.flatnonzero(values >= -problem.tau).astype(np.int64)
    rows = problem.contact.removed_rows(active)
    vec.setValues(rows.astype(PETSc.IntType), np.zeros(len(rows)))
    vec.assemble()
    u.x.scatter_forward()
    load = rayleigh(problem, vec)
    return problem.candidate(u, math.inf if load is None else load, active, sign=1.0)


def certify_foundation(problem: UnilateralProblem, solution: UnilateralSolution) -> Certificate:
    r"""Certify a critical state on a tensionless foundation (:mod:`.algorithms.foundation`).

    With :math:`z_k = s_k u_k` the oriented mode at the foundation's nodes and
    :math:`S = \{k: z_k > \epsilon \max|w|\}` the nodes pressing it (ε =
    :data:`~unibuckle_fenicsx.tolerances.PRESSING_RTOL`, as the solver counts them), the
    quotient
    :math:`R_f = (a + \sum \rho_k \max(0, z_k)^2)/b` is stationary at u when

    - :math:`r_f = Au + \sum_k \rho_k \max(0, z_k) s_k e_k - \lambda Bu` vanishes
      (relative residual :math:`\|r_f\|_2/\|Au\|_2 \le \sqrt\tau`: ``kkt``);
    - and :math:`\lambda` is the smallest eigenvalue of the pencil
      :math:`(A + \sum_{k\in S}\rho_k e_k e_k^T, B)` (inertia, ``smallest_of_reduced``).

    Every mode is admissible on a foundation (``feasible``); ``feasibility_margin`` is
    the largest :math:`z_k/\max|w|` (how deep the plate presses the springs) and springs
    cannot pull (``max_contact_force`` = -inf). Bracket: :math:`[\lambda_{free}, \lambda]`;
    proven only when it closes.

    Note:
        Collective.
    """
    contact = problem.contact
    if contact.stiffness is None:
        raise InputError(
            "certify_foundation needs a problem with a tensionless foundation "
            "(obstacle.foundation_stiffness); this one has rigid obstacles: certify"
        )
    problem.verify_free()  # the bracket's lower end
    cand = solution.candidate
    tau = problem.tau
    notes: list[str] = []
    if not math.isfinite(cand.load):
        raise ValueError("certify_foundation: the candidate has no finite load")
    z, residual = _spring_residual(problem, cand)
    # As the solver counts them: beyond PRESSING_RTOL of max|w|, or (stiff springs) a node
    # of the returned set whose spring force is beyond PRESSING_RTOL of the largest.
    held = held_nodes(z, contact.stiffness, cand.active, PRESSING_RTOL)
    pressing = np.union1d(pressing_nodes(z, 1.0), held).astype(np.int64)
    kkt = _spring_kkt(solution, residual, tau, notes)
    # The springs only stiffen: no eigenvalue of the pencil with them lies below the
    # free load (the lower end), so a load below it is no eigenpair's, never the bound.
    agree = SMALLEST_RTOL_FACTOR * problem.spec.solver.eps_tol
    _ordered(solution.lower_bound, cand.load, "interlacing", agree)
    lower = min(solution.lower_bound, cand.load)  # equal within the solver's accuracy
    upper = cand.load
    gap = (upper - lower) / upper
    proven = bool(kkt and solution.global_optimum_proven and _within(gap, PROOF_GAP))
    smallest = _spring_smallest(problem, cand, pressing, notes)
    if not proven:
        notes.append(
            f"tensionless foundation: {pressing.size} of {contact.size} nodes press it; a "
            "stationary point of the spring quotient, global optimality not proven"
        )
    return Certificate(
        feasible=True,
        feasibility_margin=float(z.max()),
        max_contact_force=-math.inf,
        relative_residual=residual,
        tolerance=tau,
        kkt=bool(kkt),
        smallest_of_reduced=smallest,
        lower_bound=lower,
        upper_bound=upper,
        relative_gap=gap,
        global_optimum_proven=proven,
        proven_by="interlacing",
        notes=tuple(notes),
    )


def _spring_kkt(
    solution: UnilateralSolution, residual: float, tau: float, notes: list[str]
) -> bool:
    """Whether the spring quotient is stationary: ``residual`` within sqrt(tau), converged.

    Raises:
        ValueError: ``solution`` carries no spring-set status (not from solve_foundation).
    """
    status = solution.status
    if status is None:
        raise ValueError(
            "certify_foundation: the solution carries no spring-set status (solution.status); "
            "it needs one from solve_foundation"
        )
    if status is not RunStatus.CONVERGED:
        notes.append(f"the spring-set iteration did not converge ({status})")
    return residual <= math.sqrt(tau) and status is RunStatus.CONVERGED


def _spring_smallest(
    problem: UnilateralProblem,
    cand: Candidate,
    pressing: npt.NDArray[np.int64],
    notes: list[str],
) -> bool:
    """Whether the load is the smallest eigenvalue with the springs of ``pressing`` (inertia).

    Collective.
    """
    sigma = cand.load * (1.0 - SMALLEST_RTOL_FACTOR * problem.spec.solver.eps_tol)
    neg, _, _ = spring_inertia(problem, pressing, sigma)
    if neg:
        notes.append(
            f"the pencil with the springs of the pressing nodes has {neg} eigenvalue(s) "
            "below the returned load"
        )
    return neg == 0


def _spring_residual(
    problem: UnilateralProblem, cand: Candidate
) -> tuple[npt.NDArray[np.float64], float]:
    r"""The oriented values (max|w| = 1) and :math:`\|r_f\|_2/\|Au\|_2` of the spring quotient.

    Collective.
    """
    contact = problem.contact
    assert contact.stiffness is not None
    u = cand.mode.x.petsc_vec
    scale = problem.max_abs_w(u)
    z = contact.values(u) / scale
    r, _, au_2 = problem.residual(cand.load, u)
    spring = u.duplicate()
    try:
        contact.scatter(contact.stiffness * np.maximum(z, 0.0) * scale, spring)
        r.axpy(1.0, spring)
    finally:
        spring.destroy()
    return z, float(r.norm()) / au_2  # type: ignore[arg-type]


def spring_inertia(
    problem: UnilateralProblem, pressing: npt.NDArray[np.int64], sigma: float
) -> tuple[int, int, int]:
    r"""Inertia of :math:`A + \sum_{k \in S} \rho_k e_k e_k^T - \sigma B`.

    The foundation's pencil with the springs :math:`\rho_k` of the nodes S = ``pressing``
    (contact indices): its negative count is the number of its eigenvalues in
    :math:`(0, \sigma)` (Sylvester's law of inertia), as :func:`reduced_inertia`'s for a
    rigid obstacle.

    Raises:
        InputError: The problem has rigid obstacles, no foundation.

    Note:
        Collective.
    """
    contact = problem.contact
    if contact.stiffness is None:
        raise InputError(
            "spring_inertia needs a problem with a tensionless foundation "
            "(obstacle.foundation_stiffness); this one has rigid obstacles"
        )
    diag = problem.model.A.createVecLeft()
    try:
        rows, nodes = contact.node_rows(pressing)
        diag.setValues(rows.astype(PETSc.IntType), contact.stiffness[nodes])
        diag.assemble()
        return pencil_inertia(problem.model.A, problem.model.B, sigma, diag)
    finally:
        diag.destroy()
