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
from dataclasses import dataclass, field, replace

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
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem
from unibuckle_fenicsx.tolerances import ROUNDING_RTOL

__all__ = [
    "MeshLevel",
    "Reader",
    "critical_state",
    "descend_from",
    "newton_link",
    "polish",
    "read_contact",
    "resolved",
    "run_from",
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
    fine: bool = False,
) -> Candidate:
    """The exact critical state of the contact set ``active`` read off ``point``.

    Default: the nodes at the tolerance (:meth:`~.newton.InteriorPointNewton.contact_set`).
    ``fine``: on the fine mesh, a state that is no KKT point at ``tau`` is tried as one
    within the load's resolution (:func:`resolved`).
    """
    t0 = time.perf_counter()
    solves0 = problem.eigensolver.solves
    active = newton.contact_set(point) if active is None else active
    cand = problem.evaluate(active, initial=point.mode.x.petsc_vec, near=point.load)
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
    if fine and not cand.kkt:
        return resolved(problem, cand, level, label) or cand
    return cand


def penetration(cand: Candidate) -> float:
    """The largest value of ``cand``'s mode on I, relative to max|w| (feasible: at most tau)."""
    return float(cand.values.max(initial=-math.inf))


def violation(cand: Candidate) -> float:
    """The largest value of ``cand``'s mode on I and force on Z (relative; KKT: at most tau)."""
    return max(penetration(cand), cand.max_force)


def resolved(
    problem: UnilateralProblem, cand: Candidate, level: MeshLevel, label: str
) -> Candidate | None:
    r"""``cand`` as a KKT point within the load's resolution, or None.

    The resolution :math:`\eta` is the relative accuracy of any load of this mesh: the
    larger of the eigen solver's tolerance and
    :meth:`~unibuckle_fenicsx.model.problem.Problem.load_resolution` (double precision
    on the mode; 1e-9 to 1e-8 on thin plates). The state (Z, lambda, u) breaks the KKT
    conditions at ``tau``: some node off Z lies above the obstacle (:math:`u_k > \tau`,
    relative to max|w|) or some node of Z pulls it (:math:`r_k > \tau`, relative to
    :math:`\|Au\|_\infty`). Flipping those nodes,
    :math:`Z' = Z \cup \{k \notin Z: u_k > \tau\} \setminus \{k \in Z: r_k > \tau\}`,
    changes the load by a quantity of second order in the violations (the load is
    stationary in the mode). Where one eigen solve finds
    :math:`|\lambda(Z') - \lambda(Z)| \le \eta\lambda`, the two states are one critical
    state as far as double precision can tell, and the lower of the two is returned as a
    KKT point at the tolerance of its own largest violation (its ``tau``; a Z' that is a
    KKT point at ``tau`` is returned as it is). A penetration :math:`\epsilon` costs a
    load of order :math:`\epsilon^2` (a node's stiffness is of the order of the load
    when the mode is scaled to max|w| = 1), so states that penetrate by more than
    :math:`\sqrt\eta` are not tried (no solve is spent); a pull is measured against
    :math:`\|Au\|_\infty`, which the shear stiffness dominates on a thin plate, so its
    size bounds nothing and every pulling state is tried (one eigen solve a read).

    Note:
        Collective.
    """
    if not math.isfinite(cand.load) or violation(cand) <= cand.tau:
        return None
    rounding = problem.load_resolution(cand.mode.x.petsc_vec, cand.load)
    eta = max(problem.spec.solver.eps_tol, rounding)
    if not penetration(cand) <= math.sqrt(eta):
        return None
    t0 = time.perf_counter()
    solves0 = problem.eigensolver.solves
    active = np.zeros(problem.num_constrained, dtype=bool)
    active[cand.active] = True
    flipped = (~active & (cand.values > cand.tau)) | (active & (cand.forces > cand.tau))
    other = problem.evaluate(
        np.flatnonzero(active ^ flipped), initial=cand.mode.x.petsc_vec, near=cand.load
    )
    level.offer(other)
    found: Candidate | None = None
    if other.kkt:
        found = other
    elif math.isfinite(other.load) and abs(other.load - cand.load) <= eta * cand.load:
        tried = [c for c in (cand, other) if penetration(c) <= math.sqrt(eta)]
        best = min(tried, key=lambda c: c.load)
        tol = max(best.tau, violation(best))
        found = replace(best, tau=tol, feasible=True)
    level.links.append(
        LinkRecord(
            "evaluate",
            label + " (flipped)",
            "kkt" if found is not None else "not-kkt",
            eigensolves=problem.eigensolver.solves - solves0,
            seconds=time.perf_counter() - t0,
            load=other.load if math.isfinite(other.load) else None,
            contact_nodes=len(other.active),
            kkt=found is not None,
            tolerance=None if found is None else found.tau,
        )
    )
    return found


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
        cand = read_contact(self.problem, self.newton, point, self.level, label, active, True)
        if not cand.kkt:
            return None
        self.armed, self.found = False, cand
        return NewtonStatus.READ


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
) -> tuple[Candidate | None, BarrierPoint]:
    """Read the contact set off ``point``; escape a saddle, drive the barrier lower, polish.

    Returns the KKT point (or None) and the barrier point it belongs to (recomputed
    after a polish only when ``carry``: it goes on to a finer mesh). ``quick``: a
    short polish and no descent (a second try follows). Saddles are escaped on every
    try: an escape costs less than a second try from the coarsest mesh.
    """
    fine = reader is not None
    cand = read_contact(problem, newton, point, level, label, fine=fine)
    if cand.kkt:
        return cand, point
    for attempt in range(options.escapes):
        saddle = not cand.feasible and cand.load < point.load * (1.0 - ROUNDING_RTOL)
        if not (saddle and newton.escape(point, cand.mode.x.petsc_vec)):
            break
        tag = f"{label} (escape {attempt + 1})"
        point, _ = run_from(
            newton, point, level, tag, options, keep_push=False,
            mu=max(point.mu, options.escape_mu), mu_min=max(point.mu, options.fine_mu_min),
        )  # fmt: skip
        cand = read_contact(problem, newton, point, level, tag, fine=fine)
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
        cand = read_contact(problem, newton, point, level, tag, fine=fine)
        if cand.kkt:
            return cand, point
    if math.isfinite(cand.load):
        budget = options.quick_polish_iterations if quick else options.polish_iterations
        polished = polish(problem, cand, level, label, budget)
        if polished is not None and polished.feasible and not polished.kkt and not quick:
            polished = descend_from(problem, polished, level, label, options.descent_steps)
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
