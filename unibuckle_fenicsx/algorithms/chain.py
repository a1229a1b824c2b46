r"""Which route answers a unilateral problem, and in what order: the solver chain.

For a rigid obstacle (any side, several zones) the chain is

1. **Nested interior-point Newton** (:mod:`.interior_point`). On the coarsest mesh (a
   structured plate's cells halved, a gmsh plate's cell size doubled, while the shorter
   side keeps ``explore_min_cells`` cells; a user's mesh has one level) the method runs
   from a few starts (the parts of the free plate's first two modes on either side of
   the obstacle, the deflection under a pressure on the whole zone, on either end and in
   the middle): the buckle may sit
   almost anywhere at nearly the same load, and each start finds one arrangement (a
   start that joins the central path of one met before stops there). The
   lowest critical state is carried to the next finer mesh by interpolating its mode (a
   point of the central path: the push there is μ/g node by node and the load the mode's
   quotient, so neither needs carrying); there a few Newton steps restore the barrier
   problem, and so on to the fine mesh.
2. **Contact set and exact eigenpair.** The fine barrier solution gives the contact set
   Z: first where the barrier problem at ``read_mu`` is solved, the nodes that the
   Newton step for a zero barrier parameter closes by more than half their gap
   (:meth:`~.interior_point.InteriorPointNewton.predicted_contact_set`), which ends the
   run if it is a KKT point; else, at the end, the nodes whose gap is at the tolerance
   ``tau``. The smallest eigenpair of the
   pencil with Z removed (:meth:`~unibuckle_fenicsx.model.problem.BucklingProblem.evaluate`)
   is the returned critical state, checked against the KKT conditions. If it fails, a
   saddle is escaped (the lower reduced mode shows the way), the barrier is driven
   lower and the active-set iteration (:mod:`.pdas`) polishes Z; if that fails too, the
   coarse state is carried once more at a small barrier parameter (flat parts stay
   flat), with a longer polish and the feasible descent (:mod:`.descent`).
3. **Fallbacks.** The feasible descent from the lowest admissible mode met (it cannot
   cycle); then the multilevel active-set method (:mod:`.active_set`, with its penalty
   continuation) from scratch.

Tensionless foundations run their spring-set iteration (:mod:`.foundation`); small
zones are enumerated (:mod:`.enumeration`; :func:`~unibuckle_fenicsx.analysis.choose_method`
decides).

Every link leaves a typed record (:class:`LinkRecord`); the solution's ``method`` names
the route that answered.

Note:
    Collective on the problem's communicator.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from slepc4py import SLEPc

import numpy as np
import numpy.typing as npt
from msgspec.structs import replace

from unibuckle_fenicsx.algorithms import NoAdmissibleModeError, RunStatus, UnilateralSolution
from unibuckle_fenicsx.algorithms.bounds import bracket
from unibuckle_fenicsx.algorithms.descent import descend
from unibuckle_fenicsx.algorithms.interior_point import (
    BarrierPoint,
    InteriorPointNewton,
    NewtonOptions,
    NewtonRecord,
    NewtonStatus,
)
from unibuckle_fenicsx.algorithms.multilevel import Prolongation, mesh_levels
from unibuckle_fenicsx.algorithms.pdas import iterate
from unibuckle_fenicsx.eigen import Owner, release, swapped_eigenpairs
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.model.contact import EmptyZoneError
from unibuckle_fenicsx.model.problem import BucklingProblem, Candidate
from unibuckle_fenicsx.progress import LOGGER as PROGRESS
from unibuckle_fenicsx.spec import ProblemSpec
from unibuckle_fenicsx.tolerances import ROUNDING_RTOL

__all__ = ["THIN_PLATE", "ChainOptions", "LevelRecord", "LinkRecord", "solve_unilateral"]

logger = logging.getLogger(__name__)

#: "auto" runs the interior-point route on plates whose thickness is below this fraction
#: of the shorter side, the multilevel active set on thicker ones. Measured: at t/b = 1e-3
#: the active set needs hundreds of eigen solves on a whole-face obstacle; on the paper's
#: plate (t/b = 0.06, a/b = 2) the active set costs 1.7–2.5 free solves at 160×80 and the
#: interior point 3.9–4.6. On long plates against a whole face the interior point is
#: usually the faster above 0.02 too (``bench/bench_routes.py``: 0.3 × 0.1 m, t/b =
#: 0.02–0.06, five edge and load cases: the faster on 18 of 20, median 4.1×; the active
#: set needs 212–1133 eigen solves), but the two routes end at different critical
#: states on some of them, either one lower; the threshold stays where the answers of
#: ``auto`` have been (the documentation's benchmarks page, "Which route").
THIN_PLATE = 0.02


@dataclass(frozen=True)
class ChainOptions:
    """Settings of the chain.

    Attributes:
        explore_min_cells: Fewest cells along the shorter side of the coarsest mesh, where
            the starts are explored (the active set's multilevel has its own,
            ``coarse_min_cells`` of :func:`~.active_set.solve_active_set`).
            Measured on the five thin plates of ``bench/bench_plates.py`` at 90×30
            (coarsest 22×7 at 4–7): at 3 (an 11×3 exploration mesh) SSSS took 3.9 free
            solves instead of 5.5, but loaded edges clamped and CCCC ended at higher
            critical states (9.2e-6 and 1.8e-4 above): 11×3 cells rank the
            arrangements wrongly; at 8 (exploring on 45×15) every plate was slower
            (SSSS 7.5, shear 44.9 free solves) and CCCC ended higher.
        seeds: Starts of the interior-point method on the coarsest mesh: "free-" and
            "free+" (the free mode's parts on either side of the obstacle), "pressure"
            (the deflection under a pressure on the whole zone), "end-low", "middle",
            "end-high" (a pressure on a third of the plate's longer side), "free2-" and
            "free2+" (the parts of the free plate's second mode). The three pressures
            on a third cost up to 57 % of the coarsest mesh's Newton steps (unloaded
            edges clamped at 90×30: 324 against 140 without them) and found no lower
            critical state on 191 random plates, but without them the design chart's
            thin plate with clamped loaded edges at a/b = 2.75 (cells of b/12) ends
            6.8e-5 higher. The second mode's parts reach an arrangement no other start
            does (on a clamped 0.3 × 0.1 m plate against a whole face: two buckles in
            the middle, the ends flat or with a small buckle, where the other starts end
            at three buckles): at 90×30 its critical state lies 2.1e-5 (t = 0.1 mm),
            1.8e-4 (1 mm) and 9.2e-5 (2 mm) below theirs, and 2.3e-6 at 180×60 (0.1
            mm); both arrangements are then carried to the fine mesh, which doubles
            the time on those plates (``bench/bench_plates.py``).
        compare_mu: Barrier parameter at which the starts are compared.
        explore_mu_min: Barrier parameter at which the starts' contact sets are read.
        twin_rtol: Starts whose barrier solutions' loads at ``compare_mu``, or at a
            barrier parameter passed on the way to ``explore_mu_min``, agree to this
            (relative) lead to the same arrangement.
        path_rtol: ... or agree to this and their deflections on the zone (scaled
            to a largest value of 1) to ``path_shape_tol``: a barrier problem solved to
            a residual of about ten times its parameter fixes the load to only about
            that (measured on the coarsest mesh of a thin plate with clamped unloaded
            edges at 1e-6: starts on one central path 1e-8 to 2.5e-6 apart in load and
            1e-5 to 2e-4 in deflection, two arrangements 3e-4 and 0.9).
        path_shape_tol: See ``path_rtol``.
        level_mu: Barrier parameter of the central-path point carried from one mesh to
            the next.
        flat_mu: ... and of the second try when the first ends at no KKT point.
        fine_mu_min: ... and the fine mesh, before its contact set is read.
        read_mu: On the fine mesh, the contact set is first read when the barrier
            problem at this parameter (or the first one below it) is solved, from the
            predicted gaps and pushes
            (:meth:`~.interior_point.InteriorPointNewton.predicted_contact_set`); a
            KKT point there ends the run (0: read only at ``fine_mu_min``).
        read_stable: ... and, below ``read_mu``, as soon as two Newton steps in a row
            predict the same set (each prediction one more solve with the next step's
            factorisation). Measured on the five thin plates of
            ``bench/bench_plates.py`` (fine-mesh steps / factorisations / eigen
            solves): SSSS 7/9/1 → 6/8/1 at 90×30 and 10/12/1 → 8/10/1 at 180×60,
            loaded edges clamped 26/35/2 → 22/31/2 at 90×30, shear 82/121/5 →
            78/117/5 at 90×30; a set predicted twice that is not the answer costs one
            eigen solve (CCCC 28/36/1 → 28/36/2 at 90×30). The robustness sweep (350
            plates): the same routes and contact sets, 22701 → 22533 factorisations,
            10272 → 10283 eigen solves, the loads within each plate's resolution.
        last_mu_min: ... once more when that contact set is not a KKT point.
        clip_margin: Smallest gap (relative to max|w|) of an interpolated mode's nodes
            (the least-energy correction lifts those closer to the obstacle to it).
            Measured, 1e-6 → 1e-5 (fine-mesh steps on the five thin plates of
            ``bench/bench_plates.py``): CCCC 28 → 26 and 33 → 30, shear 78 → 56 and
            79 → 61, unloaded edges clamped at 180×60 38 → 33, none longer; but the
            robustness sweep took 0.35 % more factorisations (43 plates more, 20 fewer)
            and the sheared column face of ``demos/demo_column.py`` fell back to the
            active-set chain (3.9 → 4.9 s, the same load): not adopted. 1e-4: better at
            90×30, worse at 180×60 (shear 79 → 135 fine steps).
        max_steps: Newton steps per run.
        escapes: Saddle escapes allowed per run.
        escape_mu: Barrier parameter the run restarts with after an escape (small: a
            larger one would lift the flattened buckle again).
        carry_margin: Critical states within this (relative) of the lowest on a mesh
            are carried to the next (the active set's ``refine_margin`` is its own).
        arrangements: ... at most this many.
        polish_iterations: Active-set iterates allowed to polish a contact set.
        quick_polish_iterations: ... on the first try of the fine mesh.
        descent_steps: Eigen solves allowed to the feasible descent after a polish that
            ends at an admissible mode short of a KKT point.
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
    clip_margin: float = 1e-6
    max_steps: int = 100
    escapes: int = 3
    escape_mu: float = 1e-10
    carry_margin: float = 2e-3
    arrangements: int = 3
    polish_iterations: int = 25
    quick_polish_iterations: int = 5
    descent_steps: int = 50
    descent_budget: int = 1
    max_iterations: int = 100
    bound_budget: int = 64


@dataclass
class LinkRecord:
    """One run of one link of the chain.

    Attributes:
        link: "interior-point", "evaluate", "active-set polish", "fallback".
        seed: The start (or level) it ran from.
        status: How it ended.
        steps: Newton steps or active-set iterates.
        factorizations: Numeric factorisations (interior point).
        eigensolves: Eigen solves.
        seconds: Wall time.
        load: The load it ended with (None if none).
        contact_nodes: |Z| (None if no contact set was read).
        kkt: It ended at a KKT point.
    """

    link: str
    seed: str
    status: str
    steps: int = 0
    factorizations: int = 0
    eigensolves: int = 0
    seconds: float = 0.0
    load: float | None = None
    contact_nodes: int | None = None
    kkt: bool = False


@dataclass
class LevelRecord:
    """What the chain did on one mesh.

    Attributes:
        mesh: [nx, ny] (structured), ["h=<cell size>"] (meshed by gmsh) or ["fine"] (a
            user's mesh or a mesh file).
        constrained_nodes: i on this mesh.
        links: The runs on it.
        seconds: Wall time on it (set-up included).
    """

    mesh: list[Any]
    constrained_nodes: int
    links: list[LinkRecord] = field(default_factory=list)
    seconds: float = 0.0
    #: The admissible mode with the lowest load met on this mesh (not in the record).
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

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready mapping."""
        return {
            "mesh": self.mesh,
            "constrained_nodes": self.constrained_nodes,
            "newton_steps": self.newton_steps,
            "factorizations": self.factorizations,
            "eigensolves": self.eigensolves,
            "seconds": self.seconds,
            "links": [vars(r) for r in self.links],
        }


#: Newton settings of the coarsest mesh's starts (see :func:`_explore`).
EXPLORE = NewtonOptions(plain_first=False, metric="stiffness", stall_steps=0)


def _newton_link(seed: str, record: NewtonRecord) -> LinkRecord:
    return LinkRecord(
        "interior-point",
        seed,
        record.status.value,
        steps=record.steps,
        factorizations=record.factorizations,
        seconds=record.seconds,
        load=record.load,
    )


def _run(
    newton: InteriorPointNewton,
    point: BarrierPoint,
    level: LevelRecord,
    label: str,
    options: ChainOptions,
    *,
    mu: float,
    mu_min: float,
    keep_push: bool = True,
    on_solved: Callable[[BarrierPoint], NewtonStatus | None] | None = None,
    on_step: Callable[[BarrierPoint], NewtonStatus | None] | None = None,
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
    level.links.append(_newton_link(label, rec))
    return new, rec


def _canonical_sign(problem: BucklingProblem, vec: Any) -> float:
    """+1 or -1: the sign that gives ``vec`` a negative oriented value at its largest node.

    The largest |oriented value| (to 1e-6 of it; ties to the lowest node number) decides,
    so that the eigen solver's arbitrary sign of the free mode does not, and a plate with
    the obstacle below starts as the mirror image of the one above (measured: under
    shear at 90x30 the face below took 92 fine Newton steps instead of 48, the free-mode
    starts being taken in the other order; now the same steps on every mesh). Unlike
    :func:`~unibuckle_fenicsx.model.contact.orientation`, which compares the largest
    violations on either side, a near tie (an antisymmetric mode) is not decided by
    rounding, which differs with the number of ranks. Collective.
    """
    assert problem.contact is not None
    z = problem.contact.values(vec)  # the same on every rank
    size = np.abs(z)
    first = int(np.flatnonzero(size >= size.max() * (1.0 - 1e-6))[0])
    return 1.0 if z[first] < 0.0 else -1.0


def _second_free_mode(problem: BucklingProblem) -> Any:
    """The free plate's second buckling mode (PETSc vector; the caller destroys it).

    The two lowest pairs of the swapped pencil B x = theta A x (theta = 1/lambda, so that
    an indefinite B is handled as everywhere else); None when SLEPc converges fewer.
    Collective.
    """
    pairs = swapped_eigenpairs(
        problem.model.A,
        problem.model.B,
        "unibuckle_ipm_free2_",
        which=SLEPc.EPS.Which.LARGEST_REAL,
        nev=2,
        tol=1e-8,
        vectors=True,
    )
    second = None
    for k, (theta, vec) in enumerate(pairs):
        if k == 1 and theta > 0.0:
            second = vec
        elif vec is not None:
            vec.destroy()
    return second


class _SecondMode(Owner):
    """The free plate's second mode (:func:`_second_free_mode`) if ``wanted``; owns it."""

    def __init__(self, problem: BucklingProblem, wanted: bool) -> None:
        self.second = _second_free_mode(problem) if wanted else None

    def destroy(self) -> None:
        """Destroy the mode (collective)."""
        release(self, "second")


def _start(newton: InteriorPointNewton, seed: str, push: Any, second: Any = None) -> Any:
    """The start ``seed`` on ``newton``'s problem, strictly inside the cone.

    ``second``: the free plate's second mode (:func:`_second_free_mode`), for the seeds
    "free2-" and "free2+".
    """
    problem = newton.problem
    assert problem.contact is not None
    if seed in ("free-", "free+", "free2-", "free2+"):
        if seed.startswith("free2"):
            if second is None:
                raise ValueError(
                    "no second free mode (SLEPc converged fewer than two positive loads)"
                )
            mode = second
        else:
            mode = problem.solve_free().function.x.petsc_vec
        sign = _canonical_sign(problem, mode)
        u = newton.negative_part(mode, sign if seed.endswith("-") else -sign)
        return newton.make_interior(u, push=push)
    if seed == "pressure":
        u = problem.new_mode("start")
        push.x.petsc_vec.copy(u.x.petsc_vec)
        u.x.scatter_forward()
        return u
    xy = problem.contact.coordinates
    (x0, y0), (x1, y1) = problem.spec.plate.corners
    axis = 0 if x1 - x0 >= y1 - y0 else 1
    lo, hi = (x0, x1) if axis == 0 else (y0, y1)
    c = (xy[:, axis] - lo) / (hi - lo)
    windows = {"end-low": (0.0, 1 / 3), "middle": (1 / 3, 2 / 3), "end-high": (2 / 3, 1.0)}
    if seed not in windows:
        raise ValueError(f"unknown interior-point start {seed!r}")
    a, b = windows[seed]
    weights = np.where((c >= a) & (c <= b), 1.0, 0.01)
    return newton.pressure_mode(weights)


def _read_contact(
    problem: BucklingProblem,
    newton: InteriorPointNewton,
    point: BarrierPoint,
    level: LevelRecord,
    label: str,
    active: npt.NDArray[np.int64] | None = None,
) -> Candidate:
    """The exact critical state of the contact set ``active`` read off ``point``.

    Default: the nodes at the tolerance (:meth:`~.interior_point.InteriorPointNewton.contact_set`).
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
    return cand


@dataclass
class _Reader:
    """Reads the fine mesh's critical state before its runs reach ``fine_mu_min``.

    Called by a run each time it has solved a barrier problem (``on_solved``); once per
    run (:meth:`arm`), at the first parameter at or below ``read_mu``, it evaluates the
    predicted contact set and ends the run when that is a KKT point. With
    ``read_stable`` it is also called at the steps in between (:meth:`step`, ``on_step``
    of the run), and evaluates the predicted set as soon as two steps in a row predict
    the same one. No set is evaluated twice. Measured on the five
    thin plates of ``bench/bench_plates.py`` (fine-mesh Newton steps / factorisations /
    eigen solves): SSSS 11/12/1 → 7/9/1 at 90×30 and 15/16/1 → 10/12/1 at 180×60,
    loaded edges clamped 42/67/3 → 39/65/3 and 33/35/2 → 21/25/2, CCCC 34/41/1 →
    28/36/1 at 90×30; where the set read at 1e-9 is not a KKT point (the runs that end
    by an escape or a polish: unloaded edges clamped, shear, CCCC at 180×60) the run goes
    on unchanged, and the read cost one eigen solve. Loads equal to 6e-15.
    """

    problem: BucklingProblem
    newton: InteriorPointNewton
    level: LevelRecord
    options: ChainOptions
    label: str = ""
    armed: bool = False
    found: Candidate | None = None
    #: The set predicted at the run's previous step (:meth:`step`), and the sets evaluated.
    previous: npt.NDArray[np.int64] | None = None
    tried: list[npt.NDArray[np.int64]] = field(default_factory=list)

    def arm(self, label: str) -> _Reader:
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
        cand = _read_contact(self.problem, self.newton, point, self.level, label, active)
        if not cand.kkt:
            return None
        self.armed, self.found = False, cand
        return NewtonStatus.READ


def _polish(
    problem: BucklingProblem, cand: Candidate, level: LevelRecord, label: str, budget: int
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


def _descend(
    problem: BucklingProblem, start: Candidate, level: LevelRecord, label: str, budget: int
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


def _critical_state(
    problem: BucklingProblem,
    newton: InteriorPointNewton,
    point: BarrierPoint,
    level: LevelRecord,
    label: str,
    options: ChainOptions,
    carry: bool = True,
    quick: bool = False,
    reader: _Reader | None = None,
) -> tuple[Candidate | None, BarrierPoint]:
    """Read the contact set off ``point``; escape a saddle, drive the barrier lower, polish.

    Returns the KKT point (or None) and the barrier point it belongs to (recomputed
    after a polish only when ``carry``: it goes on to a finer mesh). ``quick``: a
    short polish and no descent (a second try follows). Saddles are escaped on every
    try: measured, the escape answers the fine mesh's first try where a second try
    from the coarsest mesh cost more (clamped unloaded edges at 90×30: 47 fine steps
    and 11 eigen solves, plus 55 steps at 45×15, against 42 and 6; the same load to
    6e-11, lower).
    """
    cand = _read_contact(problem, newton, point, level, label)
    if cand.kkt:
        return cand, point
    for attempt in range(options.escapes):
        saddle = not cand.feasible and cand.load < point.load * (1.0 - ROUNDING_RTOL)
        if not (saddle and newton.escape(point, cand.mode.x.petsc_vec)):
            break
        tag = f"{label} (escape {attempt + 1})"
        point, _ = _run(
            newton, point, level, tag, options, keep_push=False,
            mu=max(point.mu, options.escape_mu), mu_min=max(point.mu, options.fine_mu_min),
        )  # fmt: skip
        cand = _read_contact(problem, newton, point, level, tag)
        if cand.kkt:
            return cand, point
    if point.mu > options.last_mu_min:
        tag = label + " (lower barrier)"
        point, _ = _run(
            newton, point, level, tag, options, mu=point.mu, mu_min=options.last_mu_min,
            on_solved=None if reader is None else reader.arm(tag),
            on_step=None if reader is None else reader.step,
        )  # fmt: skip
        if reader is not None and reader.found is not None:
            return reader.found, point
        cand = _read_contact(problem, newton, point, level, tag)
        if cand.kkt:
            return cand, point
    if math.isfinite(cand.load):
        budget = options.quick_polish_iterations if quick else options.polish_iterations
        polished = _polish(problem, cand, level, label, budget)
        if polished is not None and polished.feasible and not polished.kkt and not quick:
            polished = _descend(problem, polished, level, label, options.descent_steps)
        if polished is not None and polished.kkt and not carry:
            return polished, point
        if polished is not None and polished.kkt:
            # The barrier point that goes with it, for the next mesh.
            fresh = newton.from_candidate(polished, options.level_mu)
            fresh, _ = _run(
                newton, fresh, level, label + " (after polish)", options,
                mu=fresh.mu, mu_min=point.mu,
            )  # fmt: skip
            return polished, fresh
    return None, point


@dataclass
class _Arrangement:
    """A critical state being carried up the meshes: its barrier points and load."""

    load: float
    point: BarrierPoint  # on the central path at level_mu
    flat: BarrierPoint  # on the coarsest mesh, at flat_mu


@dataclass
class _Paths:
    """The barrier solutions the starts met, by barrier parameter (see :func:`_explore`)."""

    problem: BucklingProblem
    options: ChainOptions
    #: By barrier parameter: (load, oriented values on the zone scaled to max 1) of each.
    met: dict[float, list[tuple[float, npt.NDArray[np.float64]]]] = field(default_factory=dict)

    def met_before(self, mu: float, point: BarrierPoint) -> bool:
        """Whether a start met ``point`` (solved at ``mu``) before (else it is remembered).

        Collective (the values are gathered on every rank).
        """
        assert self.problem.contact is not None
        z = self.problem.contact.values(point.mode.x.petsc_vec)  # the same on every rank
        z = z / np.abs(z).max()
        seen = self.met.setdefault(mu, [])
        for load, other in seen:
            if math.isclose(point.load, load, rel_tol=self.options.twin_rtol):
                return True
            if math.isclose(point.load, load, rel_tol=self.options.path_rtol):
                if np.abs(z - other).max() <= self.options.path_shape_tol:
                    return True
        seen.append((point.load, z))
        return False


def _explore(
    problem: BucklingProblem, level: LevelRecord, options: ChainOptions, carry: bool = True
) -> tuple[list[Candidate], list[_Arrangement]]:
    """Run the starts on ``problem``: its KKT points, and the arrangements to carry up.

    The distinct KKT points within ``carry_margin`` of the lowest (at most
    ``arrangements``) are carried, each as its barrier point on the central path at
    ``level_mu`` and at ``flat_mu`` (see :func:`_levels`). Without ``carry`` (``problem``
    is the only mesh) no barrier point is made for a finer mesh: measured on a plate
    meshed by gmsh (i = 3430), those runs took 230 of the 560 Newton steps.

    A start whose barrier solution at ``compare_mu``, or at a barrier parameter passed
    on the way down to ``explore_mu_min`` (every start passes the same ones), has the
    load of one met before (relative ``twin_rtol``), or its load to ``path_rtol`` and
    its deflection on the zone to ``path_shape_tol``, is on the central path of the
    same arrangement and is not taken further. Measured on the five plates of
    ``bench/bench_plates.py`` at 90×30: the loads alone, 2–30 % fewer Newton steps on
    the coarsest mesh (SSSS 223 → 156, unloaded edges clamped 376 → 324); with the
    deflections, starts stop at the first parameter below ``compare_mu`` instead of
    up to 56 steps later (SSSS 157 → 139, loaded edges clamped 161 → 127, unloaded
    edges clamped 324 → 184, CCCC 123 → 105); the same fine steps, loads within the
    thin plates' rounding (1e-9).
    """
    found: list[tuple[Candidate, BarrierPoint]] = []
    paths = _Paths(problem, options)

    def on_solved(point: BarrierPoint) -> NewtonStatus | None:
        return NewtonStatus.MET_BEFORE if paths.met_before(point.mu, point) else None

    # Damped steps (a stiffness-scaled correction that decays from step to step) keep
    # each start near its own arrangement: measured, with the finer meshes' settings a
    # start jumped past the lowest (CCCC at 90x30 ended 1.8e-4 higher).
    wanted = any(seed.startswith("free2") for seed in options.seeds)
    with InteriorPointNewton(problem, EXPLORE) as newton, _SecondMode(problem, wanted) as modes:
        push = newton.pressure_mode()
        for seed in options.seeds:
            try:
                start = _start(newton, seed, push, modes.second)
                point, rec = newton.solve(
                    start, mu=1e-2, mu_min=options.compare_mu, max_steps=options.max_steps
                )
            except (ValueError, FloatingPointError) as err:
                level.links.append(LinkRecord("interior-point", seed, f"no start: {err}"))
                continue
            level.links.append(_newton_link(seed, rec))
            if rec.status is not NewtonStatus.CONVERGED:
                continue
            if paths.met_before(options.compare_mu, point):
                level.links.append(LinkRecord("interior-point", seed, "same as a previous start"))
                continue
            point, rec = _run(
                newton, point, level, seed, options,
                mu=point.mu, mu_min=options.explore_mu_min,
                on_solved=on_solved,
            )  # fmt: skip
            if rec.status is not NewtonStatus.CONVERGED:
                continue
            if paths.met_before(point.mu, point):
                level.links.append(LinkRecord("interior-point", seed, "same as a previous start"))
                continue
            cand, point = _critical_state(problem, newton, point, level, seed, options, carry)
            if point.mu == options.explore_mu_min:
                paths.met_before(point.mu, point)  # where an escape ended
            if cand is not None:
                found.append((cand, point))
        found.sort(key=lambda cp: cp[0].load)
        carried: list[_Arrangement] = []
        for cand, point in found if carry else []:
            far = cand.load > found[0][0].load * (1.0 + options.carry_margin)
            twin = any(math.isclose(cand.load, a.load, rel_tol=options.twin_rtol) for a in carried)
            if far or twin or len(carried) == options.arrangements:
                continue
            tag = f"{cand.load:.10g}"
            flat = _central(newton, point, level, options, f"{tag}, kept flat", options.flat_mu)
            lifted = _central(newton, point, level, options, f"{tag}, lifted", options.level_mu)
            carried.append(_Arrangement(cand.load, lifted, flat))
    return [c for c, _ in found], carried


def _central(
    newton: InteriorPointNewton,
    point: BarrierPoint,
    level: LevelRecord,
    options: ChainOptions,
    label: str,
    mu: float,
) -> BarrierPoint:
    r"""The point of the central path at ``mu`` near ``point`` (what is carried up).

    On the central path the push is :math:`\mu/g` node by node, so a finer mesh can
    start from the interpolated mode alone, at the same barrier parameter. The mode is
    copied: ``point`` is left as it was.
    """
    start = BarrierPoint(newton.problem.new_mode("central"), point.load, point.push, point.mu)
    point.mode.x.petsc_vec.copy(start.mode.x.petsc_vec)
    start.mode.x.scatter_forward()
    lifted, _ = _run(newton, start, level, label, options, mu=mu, mu_min=mu)
    return lifted


def _refine(
    carry: Prolongation,
    point: BarrierPoint,
    level: LevelRecord,
    options: ChainOptions,
    last: bool,
    mu: float,
    label: str,
    quick: bool,
    newton: InteriorPointNewton,
) -> tuple[Candidate | None, BarrierPoint | None]:
    """Carry ``point`` to the finer mesh (``carry``) and solve the barrier problem there.

    The interpolated mode is relaxed into the fine mesh's discrete Kirchhoff kernel
    (:meth:`~.interior_point.InteriorPointNewton.relax`), the nodes it brings too close
    to the obstacle are moved back by the least-energy correction
    (:meth:`~.interior_point.InteriorPointNewton.lift`), then the method runs from
    the barrier parameter ``mu``: to ``mu`` on an intermediate mesh, to ``fine_mu_min``
    on the fine one, whose critical state is read. ``newton``: the method on ``fine``
    (the caller's, kept for the level's other arrangements: its factorisation's symbolic
    analysis is done once per mesh).
    """
    fine = carry.fine
    mode = carry.mode(point.mode)
    newton.forget_corrections()
    try:
        newton.relax(mode.x.petsc_vec, "deflection")
        newton.relax(mode.x.petsc_vec, "rotations")
        newton.lift(mode, options.clip_margin)
        reader = _Reader(fine, newton, level, options) if last else None
        new, rec = newton.solve(
            mode,
            mu=mu,
            mu_min=options.fine_mu_min if last else mu,
            max_steps=options.max_steps,
            on_solved=None if reader is None else reader.arm(label),
            on_step=None if reader is None else reader.step,
        )
    except (ValueError, FloatingPointError) as err:
        level.links.append(LinkRecord("interior-point", label, f"failed: {err}"))
        return None, None
    level.links.append(_newton_link(label, rec))
    if not last:
        return None, new
    assert reader is not None
    if reader.found is not None:
        return reader.found, new
    cand, new = _critical_state(
        fine, newton, new, level, label, options, carry=False, quick=quick, reader=reader
    )
    return cand, new


def _level_record(problem: BucklingProblem) -> LevelRecord:
    spec = problem.spec
    mesh: list[Any] = [spec.mesh.nx, spec.mesh.ny] if problem.structured else ["fine"]
    if _gmsh_levels(problem):
        mesh = [f"h={spec.mesh.size:.3g}"]
    return LevelRecord(mesh, problem.num_constrained)


def _gmsh_levels(problem: BucklingProblem) -> bool:
    """Whether coarser copies of ``problem`` are meshed by gmsh at larger cell sizes."""
    spec = problem.spec
    return (
        not problem.custom_mesh
        and spec.plate.meshed_by_gmsh
        and spec.plate.file is None
        and spec.mesh.size is not None
    )


def _coarser(problem: BucklingProblem, options: ChainOptions) -> list[ProblemSpec]:
    """The problem on coarser meshes, coarsest first.

    Coarser while the shorter side keeps ``explore_min_cells`` cells. A structured
    rectangle's cells are halved (:func:`~.multilevel.mesh_levels`); a plate meshed by
    gmsh (outline, holes) is meshed again at twice the cell size, and again (the meshes
    are not nested: :class:`~.multilevel.Prolongation` interpolates between any two). A
    size at which gmsh cannot resolve a hole or an outline ends the levels. A user's
    mesh or a mesh file has no coarser copy.
    """
    spec = problem.spec
    if problem.structured:
        levels = mesh_levels(spec.mesh.nx, spec.mesh.ny, options.explore_min_cells)
        return [spec.with_mesh(nx, ny) for nx, ny in levels]
    if not _gmsh_levels(problem):
        return []
    assert spec.mesh.size is not None
    side, size = min(spec.plate.length, spec.plate.width), spec.mesh.size
    specs: list[ProblemSpec] = []
    while side / (2.0 * size) >= options.explore_min_cells:
        size *= 2.0
        try:
            specs.append(replace(spec, mesh=replace(spec.mesh, size=size)))
        except InputError:  # a feature below size / FEATURE_RATIO
            break
    return specs[::-1]


def _report(problem: BucklingProblem, level: LevelRecord) -> None:
    if problem.comm.rank == 0:
        PROGRESS.info(
            "interior point, mesh %s (i = %d): %d Newton steps, %d factorisations, "
            "%d eigen solves, %.2f s",
            "x".join(map(str, level.mesh)), level.constrained_nodes, level.newton_steps,
            level.factorizations, level.eigensolves, level.seconds,
        )  # fmt: skip


def _carry(
    problems: list[BucklingProblem],
    k: int,
    points: list[BarrierPoint],
    level: LevelRecord,
    options: ChainOptions,
    mu: float,
    label: str,
    quick: bool,
    newtons: dict[int, InteriorPointNewton],
) -> tuple[list[Candidate], list[BarrierPoint]]:
    """Carry every point from ``problems[k - 1]`` to ``problems[k]``.

    On an intermediate mesh the points whose loads lie more than ``carry_margin`` above
    the lowest are dropped (the meshes rank the arrangements better as they get finer);
    on the finest, the KKT points met are returned. ``newtons``: the method on each mesh
    (created here when missing), shared by the arrangements and tries.
    """
    tl = time.perf_counter()
    last = k == len(problems) - 1
    found: list[Candidate] = []
    carried: list[BarrierPoint] = []
    if k not in newtons:
        newtons[k] = InteriorPointNewton(problems[k])
    carry = Prolongation(problems[k - 1], problems[k])
    for j, point in enumerate(points):
        tag = label if len(points) == 1 else f"{label} {j + 1}"
        cand, new = _refine(carry, point, level, options, last, mu, tag, quick, newtons[k])
        if cand is not None and cand.kkt:
            found.append(cand)
        if new is not None and not last:
            carried.append(new)
    if carried:
        lowest = min(p.load for p in carried)
        carried = [p for p in carried if p.load <= lowest * (1.0 + options.carry_margin)]
    level.seconds += time.perf_counter() - tl
    _report(problems[k], level)
    return found, carried


def _ascend(
    problems: list[BucklingProblem],
    points: list[BarrierPoint],
    levels: list[LevelRecord],
    options: ChainOptions,
    mu: float,
    label: str,
    quick: bool,
    newtons: dict[int, InteriorPointNewton],
) -> Candidate | None:
    """Carry ``points`` from ``problems[0]`` to the fine mesh; the lowest KKT point there."""
    for k in range(1, len(problems)):
        found, points = _carry(problems, k, points, levels[k], options, mu, label, quick, newtons)
        if k == len(problems) - 1:
            return min(found, key=lambda c: c.load) if found else None
        if not points:
            return None
    return None


def _levels(
    problems: list[BucklingProblem], options: ChainOptions
) -> tuple[list[LevelRecord], list[Candidate], Candidate | None]:
    """Explore the coarsest mesh and carry its best critical states up to the finest.

    The states are carried on the central path at ``level_mu``, where the contact lines
    still move freely. If the fine mesh then ends at no KKT point (typically at a saddle
    where buckles that the barrier keeps apart have almost equal loads), the lowest is
    carried once more at ``flat_mu``, which keeps the parts lying on the obstacle flat.
    """
    levels = [_level_record(p) for p in problems]
    tl = time.perf_counter()
    explored, carried = _explore(problems[0], levels[0], options, carry=len(problems) > 1)
    levels[0].seconds = time.perf_counter() - tl
    _report(problems[0], levels[0])
    if len(problems) == 1 or not carried:
        return levels, explored, (explored[0] if explored else None)
    points = [a.point for a in carried]
    newtons: dict[int, InteriorPointNewton] = {}  # one per mesh: one symbolic analysis
    try:
        chosen = _ascend(
            problems, points, levels, options, options.level_mu, "prolonged", True, newtons
        )
        if chosen is None:
            flat = [carried[0].flat]
            chosen = _ascend(
                problems, flat, levels, options, options.flat_mu, "prolonged flat", False, newtons
            )
    finally:
        for newton in newtons.values():
            newton.destroy()
    return levels, explored, chosen


def _fallback(problem: BucklingProblem, options: ChainOptions) -> UnilateralSolution:
    from unibuckle_fenicsx.algorithms.active_set import solve_active_set

    return solve_active_set(
        problem, max_iterations=options.max_iterations, bound_budget=options.bound_budget
    )


def solve_unilateral(
    problem: BucklingProblem, options: ChainOptions | None = None
) -> UnilateralSolution:
    """Critical state of ``problem`` (rigid obstacles) by the chain of the module docstring.

    Args:
        problem: A set-up problem with a rigid obstacle.
        options: Settings (default :class:`ChainOptions`).

    Returns:
        The critical state with its bracket and the per-mesh records in
        ``details["levels"]``.

    Raises:
        NoAdmissibleModeError: No route produced an admissible mode.

    Note:
        Collective on ``problem.comm``.
    """
    options = options or ChainOptions()
    if problem.contact is None or problem.tensionless:
        raise ValueError("solve_unilateral needs a problem with a rigid obstacle")
    t0 = time.perf_counter()
    solves0 = problem.eigensolver.solves
    free_load = problem.solve_free().load
    problems: list[BucklingProblem] = []
    for coarse in _coarser(problem, options):
        try:
            problems.append(BucklingProblem(coarse, problem.comm))
        except EmptyZoneError:
            continue
    problems.append(problem)
    try:
        levels, explored, chosen = _levels(problems, options)
    finally:
        other_solves = sum(p.eigensolver.solves for p in problems[:-1])
        for p in problems[:-1]:
            p.destroy()

    if (chosen is None or not chosen.kkt) and levels and levels[-1].best_admissible is not None:
        # The lowest admissible mode met, taken to a critical state by the feasible
        # descent (monotone: it cannot cycle), before anything starts afresh.
        budget = options.descent_budget * options.max_iterations
        final = _descend(problem, levels[-1].best_admissible, levels[-1], "fallback", budget)
        if final.kkt:
            chosen = final
    if chosen is None or not chosen.kkt:
        logger.warning("interior point: no KKT point on the fine mesh; the active-set chain runs")
        solution = _fallback(problem, options)
        solution.details["interior_point_levels"] = [lv.as_dict() for lv in levels]
        solution.method = "active-set (after interior point)"
        solution.eigensolves += other_solves
        return solution

    closed = bracket(problem, free_load, chosen, options.bound_budget, "interior-point")
    chosen, lower, proven = closed.chosen, closed.lower, closed.proven
    route = "interior-point"
    for link in ("active-set polish", "feasible descent"):
        if any(r.link == link and r.kkt for r in levels[-1].links):
            route += f" + {link}"
    details: dict[str, Any] = {
        "free_load": free_load,
        "route": route,
        "levels": [lv.as_dict() for lv in levels],
        "coarse_kkt_loads": sorted(c.load for c in explored),
        "fine_eigensolves": problem.eigensolver.solves - solves0,
        "coarse_eigensolves": other_solves,
        "bound_evaluations": closed.evaluations,
        "bound_search_complete": closed.complete,
        "lower_bound_by": "lattice" if closed.evaluations else "interlacing",
        "wall_time_s": time.perf_counter() - t0,
    }
    if closed.warning:
        details["warning"] = closed.warning
    if not math.isfinite(chosen.load):
        raise NoAdmissibleModeError("the interior-point route ended without a finite load")
    return UnilateralSolution(
        candidate=chosen,
        method=route,
        eigensolves=problem.eigensolver.solves - solves0 + other_solves,
        lower_bound=min(lower, chosen.load),
        global_optimum_proven=proven,
        upper_bound=chosen.load if chosen.feasible else math.inf,
        kkt_points=[chosen],
        details=details,
    )
