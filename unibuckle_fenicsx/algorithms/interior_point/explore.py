r"""The interior point's coarsest mesh: its starts, and the arrangements carried up.

On the coarsest mesh the method runs from a few starts (the parts of the free plate's
first two modes on either side of the obstacle, the deflection under a pressure on the
whole zone, on either end and in the middle: ``ChainOptions.seeds``): the
buckle may sit almost anywhere at nearly the same load, and each start finds one
arrangement (a start that joins the central path of one met before stops there,
:class:`Paths`). The lowest critical states are carried to the next finer mesh as points
of their central paths (:func:`central`, :class:`Arrangement`).

Note:
    Collective on the problem's communicator.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from slepc4py import SLEPc

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.algorithms.interior_point.links import (
    MeshLevel,
    critical_state,
    newton_link,
    run_from,
)
from unibuckle_fenicsx.algorithms.interior_point.newton import InteriorPointNewton
from unibuckle_fenicsx.algorithms.interior_point.options import (
    EXPLORE,
    BarrierPoint,
    ChainOptions,
    NewtonStatus,
)
from unibuckle_fenicsx.algorithms.records import LinkRecord
from unibuckle_fenicsx.la.eigen import swapped_eigenpairs
from unibuckle_fenicsx.la.options import Prefix
from unibuckle_fenicsx.la.ownership import Owner, release
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem

__all__ = [
    "Arrangement",
    "Paths",
    "SecondMode",
    "canonical_sign",
    "central",
    "explore",
    "second_free_mode",
    "seed_start",
]


def canonical_sign(problem: UnilateralProblem, vec: Any) -> float:
    """+1 or -1: the sign that gives ``vec`` a negative oriented value at its largest node.

    The largest absolute oriented value (to 1e-6 of it; ties to the lowest node number) decides,
    so that the eigen solver's arbitrary sign of the free mode does not, and a plate with
    the obstacle below starts as the mirror image of the one above (the starts are taken
    in the same order: :doc:`/verification/tuning`). Unlike
    :func:`~unibuckle_fenicsx.model.contact.orientation`, which compares the largest
    violations on either side, a near tie (an antisymmetric mode) is not decided by
    rounding, which differs with the number of ranks. Collective.
    """
    z = problem.contact.values(vec)  # the same on every rank
    size = np.abs(z)
    first = int(np.flatnonzero(size >= size.max() * (1.0 - 1e-6))[0])
    return 1.0 if z[first] < 0.0 else -1.0


def second_free_mode(problem: UnilateralProblem) -> Any:
    """The free plate's second buckling mode (PETSc vector; the caller destroys it).

    The two lowest pairs of the swapped pencil B x = theta A x (theta = 1/lambda, so that
    an indefinite B is handled as everywhere else); None when SLEPc converges fewer.
    Collective.
    """
    pairs = swapped_eigenpairs(
        problem.model.A,
        problem.model.B,
        Prefix.IPM_SECOND_MODE,
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


class SecondMode(Owner):
    """The free plate's second mode (:func:`second_free_mode`) if ``wanted``; owns it."""

    def __init__(self, problem: UnilateralProblem, wanted: bool) -> None:
        self.second = second_free_mode(problem) if wanted else None

    def destroy(self) -> None:
        """Destroy the mode (collective)."""
        release(self, "second")


def seed_start(newton: InteriorPointNewton, seed: str, push: Any, second: Any = None) -> Any:
    """The start ``seed`` on ``newton``'s problem, strictly inside the cone.

    ``second``: the free plate's second mode (:func:`second_free_mode`), for the seeds
    "free2-" and "free2+".
    """
    problem = newton.problem
    if seed in ("free-", "free+", "free2-", "free2+"):
        if seed.startswith("free2"):
            if second is None:
                raise ValueError(
                    "no second free mode (SLEPc converged fewer than two positive loads)"
                )
            mode = second
        else:
            mode = problem.solve_free().function.x.petsc_vec
        sign = canonical_sign(problem, mode)
        u = newton.starts.negative_part(mode, sign if seed.endswith("-") else -sign)
        return newton.starts.make_interior(u, push=push)
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
    return newton.starts.pressure_mode(weights)


@dataclass
class Arrangement:
    """A critical state being carried up the meshes: its barrier points and load."""

    load: float
    point: BarrierPoint  # on the central path at level_mu
    flat: BarrierPoint  # on the coarsest mesh, at flat_mu


@dataclass
class Paths:
    """The barrier solutions the starts met, by barrier parameter (see :func:`explore`)."""

    problem: UnilateralProblem
    options: ChainOptions
    #: By barrier parameter: (load, oriented values on the zone scaled to max 1) of each.
    met: dict[float, list[tuple[float, npt.NDArray[np.float64]]]] = field(default_factory=dict)

    def met_before(self, mu: float, point: BarrierPoint) -> bool:
        """Whether a start met ``point`` (solved at ``mu``) before (else it is remembered).

        Collective (the values are gathered on every rank).
        """
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


def explore(
    problem: UnilateralProblem, level: MeshLevel, options: ChainOptions, carry: bool = True
) -> tuple[list[Candidate], list[Arrangement]]:
    """Run the starts on ``problem``: its KKT points, and the arrangements to carry up.

    The distinct KKT points within ``carry_margin`` of the lowest (at most
    ``arrangements``) are carried, each as its barrier point on the central path at
    ``level_mu`` and at ``flat_mu`` (see :mod:`unibuckle_fenicsx.algorithms.chain`).
    Without ``carry`` (``problem`` is the only mesh) no barrier point is made for a finer
    mesh.

    A start whose barrier solution at ``compare_mu``, or at a barrier parameter passed
    on the way down to ``explore_mu_min`` (every start passes the same ones), has the
    load of one met before (relative ``twin_rtol``), or its load to ``path_rtol`` and
    its deflection on the zone to ``path_shape_tol``, is on the central path of the
    same arrangement and is not taken further (:doc:`/verification/tuning`).
    """
    found: list[tuple[Candidate, BarrierPoint]] = []
    paths = Paths(problem, options)

    def on_solved(point: BarrierPoint) -> NewtonStatus | None:
        return NewtonStatus.MET_BEFORE if paths.met_before(point.mu, point) else None

    # Damped steps (a stiffness-scaled correction that decays from step to step) keep
    # each start near its own arrangement (EXPLORE).
    wanted = any(seed.startswith("free2") for seed in options.seeds)
    with InteriorPointNewton(problem, EXPLORE) as newton, SecondMode(problem, wanted) as modes:
        push = newton.starts.pressure_mode()
        for seed in options.seeds:
            try:
                start = seed_start(newton, seed, push, modes.second)
                point, rec = newton.solve(
                    start,
                    mu=options.start_mu,
                    mu_min=options.compare_mu,
                    max_steps=options.max_steps,
                )
            except (ValueError, FloatingPointError) as err:
                level.links.append(LinkRecord("interior-point", seed, f"no start: {err}"))
                continue
            level.links.append(newton_link(seed, rec))
            if rec.status is not NewtonStatus.CONVERGED:
                continue
            if paths.met_before(options.compare_mu, point):
                level.links.append(LinkRecord("interior-point", seed, "same as a previous start"))
                continue
            point, rec = run_from(
                newton, point, level, seed, options,
                mu=point.mu, mu_min=options.explore_mu_min,
                on_solved=on_solved,
            )  # fmt: skip
            if rec.status is not NewtonStatus.CONVERGED:
                continue
            if paths.met_before(point.mu, point):
                level.links.append(LinkRecord("interior-point", seed, "same as a previous start"))
                continue
            cand, point = critical_state(problem, newton, point, level, seed, options, carry)
            if point.mu == options.explore_mu_min:
                paths.met_before(point.mu, point)  # where an escape ended
            if cand is not None:
                found.append((cand, point))
        found.sort(key=lambda cp: cp[0].load)
        carried: list[Arrangement] = []
        for cand, point in found if carry else []:
            far = cand.load > found[0][0].load * (1.0 + options.carry_margin)
            twin = any(math.isclose(cand.load, a.load, rel_tol=options.twin_rtol) for a in carried)
            if far or twin or len(carried) == options.arrangements:
                continue
            tag = f"{cand.load:.10g}"
            flat = central(newton, point, level, options, f"{tag}, kept flat", options.flat_mu)
            lifted = central(newton, point, level, options, f"{tag}, lifted", options.level_mu)
            carried.append(Arrangement(cand.load, lifted, flat))
    return [c for c, _ in found], carried


def central(
    newton: InteriorPointNewton,
    point: BarrierPoint,
    level: MeshLevel,
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
    lifted, _ = run_from(newton, start, level, label, options, mu=mu, mu_min=mu)
    return lifted
