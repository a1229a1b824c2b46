r"""The links of the interior point's route on one mesh: runs, reads, polish, descent.

A run continues the interior-point method from a barrier point (:func:`run_from`); the
contact set read off a barrier point gives an exact critical state (:func:`read_contact`,
and :class:`Reader` reads it early on the fine mesh); where that is no KKT point a
saddle is escaped, the barrier driven lower, the set polished by the active-set
iteration and the feasible descent run (:func:`critical_state`). Every link leaves a
:class:`~unibuckle_fenicsx.algorithms.records.LinkRecord` in its mesh's
:class:`MeshLevel`.

Note:
    Collective on the problem's communicator.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

from petsc4py import PETSc

import dolfinx

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms import RunStatus
from unibuckle_fenicsx.algorithms.descent import descend
from unibuckle_fenicsx.algorithms.interior_point.newton import Hook, InteriorPointNewton
from unibuckle_fenicsx.algorithms.interior_point.options import (
    BarrierPoint,
    ChainOptions,
    NewtonRecord,
    NewtonStatus,
)
from unibuckle_fenicsx.algorithms.pdas import iterate
from unibuckle_fenicsx.algorithms.records import LevelRecord, LinkRecord
from unibuckle_fenicsx.la.eigen import EigenPair
from unibuckle_fenicsx.model.problem import Candidate, Problem, UnilateralProblem
from unibuckle_fenicsx.tolerances import ROUNDING_RTOL, SMALLEST_RTOL_FACTOR

__all__ = [
    "MeshLevel",
    "Reader",
    "critical_state",
    "descend_from",
    "double_read",
    "newton_link",
    "polish",
    "project_on_pairs",
    "read_contact",
    "released",
    "run_from",
    "saddle_read",
]


@dataclass
class MeshLevel:
    """What the chain does on one mesh, as it goes (its record: :meth:`record`).

    Attributes:
        mesh: [nx, ny] (structured), ["h=<cell size>"] (meshed by gmsh) or ["fine"] (a
            user's mesh or a mesh file).
        constrained_nodes: i on this mesh.
        links: The runs on it.
        seconds: Wall time on it (set-up included).
        best_admissible: The admissible mode with the lowest load met on this mesh (not
            in the record).
    """

    mesh: list[int | str]
    constrained_nodes: int
    links: list[LinkRecord] = field(default_factory=list)
    seconds: float = 0.0
    best_admissible: Candidate | None = field(default=None, repr=False)

    def offer(self, cand: Candidate | None) -> None:
        """Keep ``cand`` if it is admissible with a lower load than the best so far."""
        if cand is None or not cand.feasible or not math.isfinite(cand.load):
            return
        if self.best_admissible is None or cand.load < self.best_admissible.load:
            self.best_admissible = cand

    @property
    def newton_steps(self) -> int:
        """Interior-point Newton steps on this mesh."""
        return sum(r.steps for r in self.links if r.link == "interior-point")

    @property
    def factorizations(self) -> int:
        """Numeric factorisations on this mesh."""
        return sum(r.factorizations for r in self.links)

    @property
    def eigensolves(self) -> int:
        """Eigen solves on this mesh."""
        return sum(r.eigensolves for r in self.links)

    def record(self) -> LevelRecord:
        """The level's record."""
        return LevelRecord(
            mesh=self.mesh,
            constrained_nodes=self.constrained_nodes,
            newton_steps=self.newton_steps,
            factorizations=self.factorizations,
            eigensolves=self.eigensolves,
            seconds=self.seconds,
            links=self.links,
        )


def newton_link(seed: str, record: NewtonRecord) -> LinkRecord:
    """The link record of an interior-point run from ``seed``."""
    return LinkRecord(
        "interior-point",
        seed,
        record.status.value,
        steps=record.steps,
        factorizations=record.factorizations,
        seconds=record.seconds,
        load=record.load,
    )


def run_from(
    newton: InteriorPointNewton,
    point: BarrierPoint,
    level: MeshLevel,
    label: str,
    options: ChainOptions,
    *,
    mu: float,
    mu_min: float,
    keep_push: bool = True,
    on_solved: Hook | None = None,
    on_step: Hook | None = None,
) -> tuple[BarrierPoint, NewtonRecord]:
    """Continue the method from ``point`` (updated in place) and record the run."""
    new, rec = newton.solve(
        point.mode,
        load=point.load,
        push=point.push if keep_push else None,
        mu=mu,
        mu_min=mu_min,
        max_steps=options.max_steps,
        on_solved=on_solved,
        on_step=on_step,
    )
    level.links.append(newton_link(label, rec))
    return new, rec


def read_contact(
    problem: UnilateralProblem,
    newton: InteriorPointNewton,
    point: BarrierPoint,
    level: MeshLevel,
    label: str,
    active: npt.NDArray[np.int64] | None = None,
    double: float | None = None,
) -> Candidate:
    """The exact critical state of the contact set ``active`` read off ``point``.

    Default: the nodes at the tolerance (:meth:`~.newton.InteriorPointNewton.contact_set`).
    ``double``: where the reduced mode crosses the obstacle by more than this at the
    barrier point's load, look for a double eigenvalue (:func:`double_read`).
    """
    t0 = time.perf_counter()
    solves0 = problem.eigensolver.solves
    active = newton.contact_set(point) if active is None else active
    cand = problem.evaluate(active, initial=point.mode.x.petsc_vec, near=point.load)
    if double is not None and not cand.kkt:
        cand = double_read(problem, point, cand, double) or cand
    level.offer(cand)
    level.links.append(
        LinkRecord(
            "evaluate",
            label,
            "kkt" if cand.kkt else "not-kkt",
            eigensolves=problem.eigensolver.solves - solves0,
            seconds=time.perf_counter() - t0,
            load=cand.load if math.isfinite(cand.load) else None,
            contact_nodes=len(active),
            kkt=cand.kkt,
        )
    )
    return cand


def double_read(
    problem: UnilateralProblem, point: BarrierPoint, cand: Candidate, push: float
) -> Candidate | None:
    r"""The critical state of ``cand``'s contact set on a double eigenvalue, or None.

    Where two buckles of the same load are weakly coupled, the pencil reduced on the
    contact set Z read off the barrier point can have two eigenvalues closer than the
    smallest-eigenvalue check resolves (:data:`~unibuckle_fenicsx.tolerances.SMALLEST_RTOL_FACTOR`
    eigen tolerances), and the eigen solver then returns an arbitrary mode of their
    plane: typically one that lifts one buckle and pushes the other into the obstacle.
    Every mode of that plane is an eigenvector to that resolution; the one taken is the
    barrier point's mode projected on the plane (:func:`project_on_pairs`), its load
    its Rayleigh quotient, which lies between the two eigenvalues, so that the inertia
    check of the smallest eigenvalue holds. Tried only where ``cand`` crosses the
    obstacle by more than ``push`` of its largest deflection and its load is the
    barrier point's to that resolution (one eigen solve for the two lowest pairs);
    returned only if it is a KKT point.
    """
    resolution = SMALLEST_RTOL_FACTOR * problem.spec.solver.eps_tol
    if not cand.active.size or not math.isfinite(cand.load) or cand.values.max() <= push:
        return None
    if abs(cand.load - point.load) > resolution * point.load:
        return None
    rows = problem.contact.removed_rows(cand.active)
    u = point.mode.x.petsc_vec
    pairs = problem.eigensolver.lowest_pairs(rows, cand.load, 2, initial=u)
    try:
        if len(pairs) < 2 or pairs[1][0].value > pairs[0][0].value * (1.0 + resolution):
            return None
        projected = project_on_pairs(problem, u, [vec for _, vec in pairs])
    finally:
        for _, vec in pairs:
            vec.destroy()
    if projected is None:
        return None
    mode, load = projected
    first = pairs[0][0]
    eigen = EigenPair(load, first.error, first.iterations, first.converged)
    double = problem.candidate(mode, load, cand.active, eigen=eigen)
    return double if double.kkt else None


def project_on_pairs(
    problem: Problem, u: PETSc.Vec, vecs: list[PETSc.Vec]
) -> tuple[dolfinx.fem.Function, float] | None:
    r"""``u`` projected on the span of ``vecs``, and its Rayleigh quotient :math:`a/b`.

    The projection is :math:`A`-orthogonal (A is positive definite, B need not be);
    None when :math:`b \le 0` there. Collective.
    """
    A, B = problem.model.A, problem.model.B
    Av = [A.createVecLeft() for _ in vecs]
    try:
        for vec, out in zip(vecs, Av, strict=True):
            A.mult(vec, out)
        gram = np.array([[out.dot(vec) for vec in vecs] for out in Av])
        coef = np.linalg.solve(gram, np.array([out.dot(u) for out in Av]))
        mode = problem.new_mode("projected")
        x = mode.x.petsc_vec
        x.set(0.0)
        for c, vec in zip(coef, vecs, strict=True):
            x.axpy(float(c), vec)
        mode.x.scatter_forward()
        A.mult(x, Av[0])
        B.mult(x, Av[1])
        a, b = float(x.dot(Av[0])), float(x.dot(Av[1]))
    finally:
        for out in Av:
            out.destroy()
    return (mode, a / b) if b > 0.0 else None


@dataclass
class Reader:
    """Reads the fine mesh's critical state before its runs reach ``fine_mu_min``.

    Called by a run each time it has solved a barrier problem (``on_solved``); once per
    run (:meth:`arm`), at the first parameter at or below ``read_mu``, it evaluates the
    predicted contact set and ends the run when that is a KKT point. With
    ``read_stable`` it is also called at the steps in between (:meth:`step`, ``on_step``
    of the run), and evaluates the predicted set as soon as two steps in a row predict
    the same one. No set is evaluated twice; where the set read is not a KKT point the
    run goes on unchanged, at the cost of one eigen solve.
    """

    problem: UnilateralProblem
    newton: InteriorPointNewton
    level: MeshLevel
    options: ChainOptions
    label: str = ""
    armed: bool = False
    found: Candidate | None = None
    #: The set predicted at the run's previous step (:meth:`step`), and the sets evaluated.
    previous: npt.NDArray[np.int64] | None = None
    tried: list[npt.NDArray[np.int64]] = field(default_factory=list)

    def arm(self, label: str) -> Reader:
        """Ready for the next run (labelled ``label``); returns itself, the hook."""
        self.label, self.armed = label, self.options.read_mu > 0.0
        self.previous = None
        return self

    def __call__(self, point: BarrierPoint) -> NewtonStatus | None:
        """Where the run has solved a barrier problem (``on_solved``)."""
        if not self.armed or point.mu > self.options.read_mu:
            return None
        self.armed = False
        return self._read(point, self.newton.predicted_contact_set(point), "predicted")

    def step(self, point: BarrierPoint) -> NewtonStatus | None:
        """At a step in between (``on_step``): read a set predicted twice in a row."""
        if not (self.armed and self.options.read_stable) or point.mu > self.options.read_mu:
            return None
        active, self.previous = self.previous, self.newton.predicted_contact_set(point)
        if active is None or not np.array_equal(active, self.previous):
            return None
        return self._read(point, active, "stable")

    def _read(
        self, point: BarrierPoint, active: npt.NDArray[np.int64], how: str
    ) -> NewtonStatus | None:
        if any(np.array_equal(active, other) for other in self.tried):
            return None
        self.tried.append(active)
        label = f"{self.label} ({how} at {point.mu:.0e})"
        cand = read_contact(
            self.problem,
            self.newton,
            point,
            self.level,
            label,
            active,
            double=self.options.double_push,
        )
        for step in range(self.options.release_steps):
            kept = released(cand)
            if kept is None or any(np.array_equal(kept, other) for other in self.tried):
                break
            self.tried.append(kept)
            cand = read_contact(
                self.problem,
                self.newton,
                point,
                self.level,
                f"{label} (release {step + 1})",
                kept,
                double=self.options.double_push,
            )
        if not cand.kkt:
            return None
        self.armed, self.found = False, cand
        return NewtonStatus.READ


def released(cand: Candidate) -> npt.NDArray[np.int64] | None:
    r"""``cand``'s contact set without the nodes that pull, or None.

    For a critical state that fails the KKT conditions only by the obstacle's pull
    (admissible: :math:`u_k \le \tau` on every node, with :math:`r_k > \tau` at some
    nodes of Z, :math:`r = Au - \lambda Bu` relative to :math:`\|Au\|_\infty`), the
    release step of the active-set iteration
    (:mod:`~unibuckle_fenicsx.algorithms.pdas`): Z without those nodes.
    None when ``cand`` is a KKT point, crosses the obstacle, has no finite load, or no
    node of Z pulls.
    """
    if cand.kkt or not cand.feasible or not math.isfinite(cand.load):
        return None
    pulls = cand.forces[cand.active] > cand.tau
    if not pulls.any():
        return None
    return cand.active[~pulls]


def polish(
    problem: UnilateralProblem, cand: Candidate, level: MeshLevel, label: str, budget: int
) -> Candidate | None:
    """Active-set iteration from ``cand``'s contact set; its KKT point or best feasible."""
    t0 = time.perf_counter()
    solves0 = problem.eigensolver.solves
    run = iterate(problem, label, cand.active, cand.mode.x.petsc_vec, budget, near=cand.load)
    final = run.final if run.status is RunStatus.KKT else run.best_feasible
    level.offer(final)
    level.links.append(
        LinkRecord(
            "active-set polish",
            label,
            run.status,
            steps=run.iterations,
            eigensolves=problem.eigensolver.solves - solves0,
            seconds=time.perf_counter() - t0,
            load=None if final is None else final.load,
            contact_nodes=None if final is None else len(final.active),
            kkt=final is not None and final.kkt,
        )
    )
    return final


def descend_from(
    problem: UnilateralProblem, start: Candidate, level: MeshLevel, label: str, budget: int
) -> Candidate:
    """Feasible descent (:mod:`.descent`) from the admissible ``start``: it cannot cycle."""
    t0 = time.perf_counter()
    solves0 = problem.eigensolver.solves
    run, _ = descend(problem, start, budget)
    final = run.final if run.status is RunStatus.KKT else run.best_feasible
    assert final is not None
    level.offer(final)
    level.links.append(
        LinkRecord(
            "feasible descent",
            label,
            run.status,
            steps=run.iterations,
            eigensolves=problem.eigensolver.solves - solves0,
            seconds=time.perf_counter() - t0,
            load=final.load,
            contact_nodes=len(final.active),
            kkt=final.kkt,
        )
    )
    return final


def _read_state(
    newton: InteriorPointNewton,
    point: BarrierPoint,
    level: MeshLevel,
    label: str,
    predicted: bool,
    double: float | None = None,
) -> tuple[Candidate, list[Candidate]]:
    """The critical state read off ``point`` by :func:`critical_state`, and the reads.

    The gaps' set (:func:`read_contact`); with ``predicted``
    (``ChainOptions.read_predicted``), where that is no KKT point, the predicted set too
    (:meth:`~.newton.InteriorPointNewton.predicted_contact_set`: one more factorisation
    and eigen solve), and the one nearer to a KKT point (:func:`_violation`) is kept.
    ``double``: as :func:`read_contact`'s. Returns the state kept and the states read,
    the kept one first.
    """
    problem = newton.problem
    cand = read_contact(problem, newton, point, level, label, double=double)
    if cand.kkt or not predicted:
        return cand, [cand]
    active = newton.predicted_contact_set(point)
    if np.array_equal(active, cand.active):
        return cand, [cand]
    other = read_contact(
        problem, newton, point, level, f"{label} (predicted)", active, double=double
    )
    if other.kkt or _violation(other) < _violation(cand):
        return other, [other, cand]
    return cand, [cand, other]


def saddle_read(point: BarrierPoint, reads: list[Candidate]) -> Candidate | None:
    """The first of ``reads`` that crosses the obstacle below ``point``'s load, or None."""
    for cand in reads:
        if not cand.feasible and cand.load < point.load * (1.0 - ROUNDING_RTOL):
            return cand
    return None


def _violation(cand: Candidate) -> float:
    """How far ``cand`` is from a KKT point: its largest value, or largest force on Z."""
    largest = float(cand.values.max()) if cand.values.size else -math.inf
    return max(largest, cand.max_force)


def _polish_descend(
    problem: UnilateralProblem,
    cand: Candidate,
    level: MeshLevel,
    label: str,
    options: ChainOptions,
    quick: bool,
) -> Candidate | None:
    """The polish of ``cand``'s set, and where it ends short of a KKT point the descent.

    The descent runs from the polish's admissible mode; on the ``quick`` try only with
    ``quick_descent``, and from the lowest admissible mode met on the mesh.
    """
    budget = options.quick_polish_iterations if quick else options.polish_iterations
    polished = polish(problem, cand, level, label, budget)
    if polished is not None and polished.kkt:
        return polished
    if not quick:
        if polished is not None and polished.feasible:
            polished = descend_from(problem, polished, level, label, options.descent_steps)
        return polished
    start = level.best_admissible  # the polish's, or a read's
    if options.quick_descent and start is not None:
        return descend_from(problem, start, level, label, options.descent_steps)
    return polished


def critical_state(
    problem: UnilateralProblem,
    newton: InteriorPointNewton,
    point: BarrierPoint,
    level: MeshLevel,
    label: str,
    options: ChainOptions,
    carry: bool = True,
    quick: bool = False,
    reader: Reader | None = None,
    double: bool = False,
) -> tuple[Candidate | None, BarrierPoint]:
    """Read the contact set off ``point``; escape a saddle, drive the barrier lower, polish.

    Returns the KKT point (or None) and the barrier point it belongs to (recomputed
    after a polish only when ``carry``: it goes on to a finer mesh). ``quick``: a
    short polish and no descent (a second try follows). Saddles are escaped on every
    try: an escape costs less than a second try from the coarsest mesh. ``double``:
    read double eigenvalues (:func:`double_read`; on the fine mesh).
    """
    push = options.double_push if double else None
    cand, reads = _read_state(newton, point, level, label, options.read_predicted, push)
    if cand.kkt:
        return cand, point
    for attempt in range(options.escapes):
        saddle = saddle_read(point, reads if options.escape_either else [cand])
        if saddle is None or not newton.escape(point, saddle.mode.x.petsc_vec):
            break
        tag = f"{label} (escape {attempt + 1})"
        point, _ = run_from(
            newton, point, level, tag, options, keep_push=False,
            mu=max(point.mu, options.escape_mu), mu_min=max(point.mu, options.fine_mu_min),
        )  # fmt: skip
        cand, reads = _read_state(newton, point, level, tag, options.read_predicted, push)
        if cand.kkt:
            return cand, point
    if point.mu > options.last_mu_min:
        tag = label + " (lower barrier)"
        point, _ = run_from(
            newton, point, level, tag, options, mu=point.mu, mu_min=options.last_mu_min,
            on_solved=None if reader is None else reader.arm(tag),
            on_step=None if reader is None else reader.step,
        )  # fmt: skip
        if reader is not None and reader.found is not None:
            return reader.found, point
        cand, _ = _read_state(newton, point, level, tag, options.read_predicted, push)
        if cand.kkt:
            return cand, point
    if math.isfinite(cand.load):
        polished = _polish_descend(problem, cand, level, label, options, quick)
        if polished is not None and polished.kkt and not carry:
            return polished, point
        if polished is not None and polished.kkt:
            # The barrier point that goes with it, for the next mesh.
            fresh = newton.starts.from_candidate(polished, options.level_mu)
            fresh, _ = run_from(
                newton, fresh, level, label + " (after polish)", options,
                mu=fresh.mu, mu_min=point.mu,
            )  # fmt: skip
            return polished, fresh
    return None, point
