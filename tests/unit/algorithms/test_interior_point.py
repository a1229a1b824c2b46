r"""The nested interior-point Newton method (README, "The fast route on thin plates").

- The Newton direction solves the linearised optimality conditions
  :math:`F_u = Au - \lambda Bu + E\nu`, :math:`F_c = \nu\circ g - \mu`,
  :math:`F_n = \frac12(u^TBu - 1)` (g = -E^T u): compared with a dense Newton solve of
  the full Jacobian, written here with numpy from the assembled matrices, with the
  obstacle on either side.
- Interpolation between nested meshes is exact for Q1 functions (a linear field).
- The route on problems of the random stress family agrees with the exhaustive minimum
  over all 2^i contact sets (dense linear algebra, ``tests/support/exhaustive.py``) wherever the
  active-set method does (sample here, the whole family with ``-m stress``).
- A thin plate (t/b = 1e-3) against a whole-plate obstacle: the route answers with a
  certified KKT point that is the smallest eigenvalue of its reduced pencil, and the mode
  vanishes on the contact set; two ranks give the serial answer; the obstacle below gives
  the load of the obstacle above (the mirror image w -> -w).
- Starts that meet on one central path on the coarsest mesh stop there, with the answer
  of every start taken to the end. The second free mode's starts are the second
  eigenpair of a dense solve; with them a clamped plate's route ends no higher than the
  active set's (at its two-buckle state).
- The predicted contact set is the set of nodes that the dense affine-scaling Newton
  step (the direction for a zero barrier parameter) closes by more than half their gap;
  read inside a run it leaves the run unchanged; the fine mesh read early gives the
  load of the mesh read at the end, in fewer Newton steps, and a set predicted at two
  steps in a row the load of the set read where the barrier problem is solved; where
  the gaps' set at a barrier point is no KKT point, ``read_predicted`` reads the
  predicted set there, the KKT point the gaps give at a smaller parameter; with
  ``quick_descent`` the first try's short polish that ends short of a KKT point goes on
  by the feasible descent to one (dense numpy's KKT check, LAPACK's load).
- Near a saddle of the barrier problem, the direction of most negative curvature read
  off the regularised factorisation is that of a dense reference (the Schur complement
  onto the DOFs with geometric stiffness, on the tangent space), and the step along it
  lowers the barrier objective; with a few Krylov vectors two ranks find the serial value.
- An option under the prefix ``unibuckle_ipm_`` reaches the factorisation.
"""

from __future__ import annotations

import json
from dataclasses import replace
from types import SimpleNamespace

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx

import numpy as np
import pytest
import scipy.linalg
from msgspec import structs

from support.exhaustive import dense, dense_reduced_load, satisfies_kkt
from support.newton import at_saddle
from support.paths import MPI_SCRIPTS
from support.processes import run_mpi
from support.stress import FAMILY, check
from unibuckle_fenicsx.algorithms.chain import ChainOptions, solve_interior_point
from unibuckle_fenicsx.algorithms.interior_point import (
    BarrierPoint,
    InteriorPointNewton,
    NewtonOptions,
    NewtonStatus,
)
from unibuckle_fenicsx.algorithms.interior_point.explore import second_free_mode
from unibuckle_fenicsx.algorithms.interior_point.links import (
    MeshLevel,
    Reader,
    critical_state,
    read_contact,
    released,
    saddle_read,
)
from unibuckle_fenicsx.algorithms.interior_point.newton import StallWatch
from unibuckle_fenicsx.algorithms.interior_point.options import PUSH_MARGIN
from unibuckle_fenicsx.algorithms.multilevel import Prolongation
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.problem import UnilateralProblem
from unibuckle_fenicsx.results.records import jsonable
from unibuckle_fenicsx.spec import ObstacleSpec, problem_from_dict, problem_to_dict
from unibuckle_fenicsx.spec.cases import paper_case, plate_case
from unibuckle_fenicsx.tolerances import ROUNDING_RTOL

serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense reference is serial")
PARALLEL = MPI_SCRIPTS / "interior_point_parallel.py"
#: Problems of the stress family run through the interior-point route by default.
SAMPLE = 12
#: Problems of the stress family where the interior-point route returns a genuine KKT
#: point above the exhaustive minimum (never claimed proven): none. stress37 (5x3 mesh,
#: whole-plate obstacle, clamped / simply supported edges under pure shear, i = 8), one
#: of the active set's two, was one for the route too until its coarsest mesh started
#: from the parts of the free plate's second mode (ChainOptions.seeds); stress166, the
#: active set's other, it solves.
KNOWN_LOCAL_MINIMA: set[str] = set()


def _load_rounding(problem: UnilateralProblem, cand) -> float:
    r"""Relative resolution of a critical load in double precision.

    A backward-stable solve perturbs A by :math:`|E| \le \epsilon |A|`, which moves the
    eigenvalue by up to :math:`\epsilon\,|u|^T|A||u| / u^TBu` (first-order perturbation
    of a generalised eigenvalue). On a thin plate :math:`|A||u| \gg |Au|` (the shear
    stiffness), so this is 1e-9 of the load, not 1e-16: two solves of one contact set
    at different shifts agree to it, not to the last bit.
    """
    A, B = problem.model.A, problem.model.B
    u = cand.mode.x.petsc_vec
    ai, aj, av = A.getValuesCSR()
    abs_u = np.abs(u.array_r)
    abs_a = np.abs(av)
    rows = np.repeat(np.arange(ai.size - 1), np.diff(ai))
    au = np.bincount(rows, weights=abs_a * abs_u[aj], minlength=ai.size - 1)
    bu = B.createVecLeft()
    B.mult(u, bu)
    ubu = u.dot(bu)
    bu.destroy()
    return float(np.finfo(float).eps * abs_u @ au / ubu / cand.load)


def _dense_newton_step(A, B, E, x, lam, nu, mu_abs):
    """Newton's step on (u, nu, lambda) from the full dense Jacobian (reference)."""
    n, m = x.size, nu.size
    gap = -E.T @ x
    F = np.concatenate(
        [A @ x - lam * (B @ x) + E @ nu, nu * gap - mu_abs, [0.5 * (x @ B @ x - 1.0)]]
    )
    J = np.zeros((n + m + 1, n + m + 1))
    J[:n, :n] = A - lam * B
    J[:n, n : n + m] = E
    J[:n, -1] = -(B @ x)
    J[n : n + m, :n] = -nu[:, None] * E.T
    J[n : n + m, n : n + m] = np.diag(gap)
    J[-1, :n] = B @ x
    return np.linalg.solve(J, -F)


@serial
@pytest.mark.parametrize("side", ["above", "below"])
def test_newton_direction_solves_the_linearised_conditions(side, thin_plate):
    r"""The obstacle on either side.

    The barrier's Hessian :math:`E\,diag(\nu/g)E^T` has the entries
    :math:`s_k^2\nu_k/g_k = \nu_k/g_k` whatever the sign :math:`s_k` of the side.
    """
    spec = thin_plate(nx=6, ny=3)
    spec = structs.replace(spec, obstacle=structs.replace(spec.obstacle, side=side))
    problem = build_problem(spec, MPI.COMM_SELF)
    with InteriorPointNewton(problem) as newton:
        u = newton.starts.pressure_mode()  # strictly inside the cone
        vec = u.x.petsc_vec
        vec.scale(0.7)  # not normalised: F_n != 0
        A, B = dense(problem.model.A), dense(problem.model.B)
        x = vec.array.copy()
        n = x.size
        rows = newton.kernel.dofs
        E = np.zeros((n, rows.size))
        E[rows, np.arange(rows.size)] = newton.kernel.signs
        gap = -E.T @ x
        assert gap.min() > 0
        rng = np.random.default_rng(7)
        nu = rng.uniform(0.5, 2.0, rows.size) * np.abs(A @ x).max() * 1e-3
        lam = 0.5 * problem.solve_free().load  # K positive definite: no regularisation
        mu_abs = float(np.mean(nu * gap))
        problem.model.A.mult(vec, newton.kernel.Au)
        problem.model.B.mult(vec, newton.kernel.Bu)
        newton.kernel.Au.copy(newton.kernel.Fu)
        newton.kernel.Fu.axpy(-lam, newton.kernel.Bu)
        newton.kernel.add_zone(newton.kernel.Fu, nu)
        step = newton.kernel.direction(vec, lam, nu, gap, mu_abs)
        assert step is not None
        dlam, dz, dnu = step
        du = newton.kernel.du.array.copy()
    problem.destroy()
    delta = _dense_newton_step(A, B, E, x, lam, nu, mu_abs)
    scale = np.abs(delta[:n]).max()
    assert np.abs(du - delta[:n]).max() <= 1e-8 * scale
    assert np.allclose(dz, E.T @ delta[:n], rtol=0, atol=1e-8 * scale)
    assert abs(dlam - delta[-1]) <= 1e-8 * max(abs(delta[-1]), lam)
    assert np.allclose(dnu, delta[n:-1], rtol=1e-6, atol=1e-8 * np.abs(delta[n:-1]).max())


@serial
def test_a_line_search_that_backtracks_to_its_end_returns_the_step_it_applied(thin_plate):
    """The load moves by the returned step times dlambda, the mode by the step applied.

    A direction pointing out of the cone (every trial's barrier objective infinite) with
    a descending slope backtracks ``max_backtracks`` times: the mode then is the
    normalised u0 + alpha du of the last trial, and the returned alpha must be that one
    (it was one backtrack factor smaller).
    """
    spec = thin_plate(nx=6, ny=3)
    problem = build_problem(spec, MPI.COMM_SELF)
    options = NewtonOptions(max_backtracks=3, backtrack=0.5)
    with InteriorPointNewton(problem, options) as newton:
        kernel = newton.kernel
        u = newton.starts.pressure_mode()  # strictly inside the cone
        vec = u.x.petsc_vec
        kernel.normalize(vec)
        u0 = vec.array.copy()
        gap = -kernel.oriented(vec)
        assert gap.min() > 0
        kernel.du.set(0.0)
        kernel.add_zone(kernel.du, -1e3 * np.abs(u0).max() * np.ones(gap.size))  # outward
        du = kernel.du.array.copy()
        kernel.A.mult(vec, kernel.Au)
        energy_slope = abs(kernel.Au.dot(kernel.du))
        mu_abs = 1e-3
        # A descending slope Au.du + mu sum(dz/g) < 0: the search does not stop at once.
        dz = -gap * (1.0 + 10.0 * energy_slope / (mu_abs * gap.size))
        alpha = kernel.line_search(vec, mu_abs, 1.0, dz, gap, e_u=1.0)
        applied = vec.array.copy()
    problem.destroy()
    assert alpha == pytest.approx(0.25, rel=1e-15)  # 1, 0.5, 0.25: three trials
    trial = u0 + alpha * du
    assert np.allclose(applied / np.abs(applied).max(), trial / np.abs(trial).max(), atol=1e-12)


@serial
def test_negative_curvature_is_the_lowest_curvature_on_the_tangent_space(thin_plate):
    r"""At a load above the second free one, K has a negative direction on the tangent space.

    Reference: the smallest eigenvalue of the dense pencil
    :math:`(Q^TSQ, Q^TM_{PP}Q)`, where P are the DOFs on which the regularisation's
    diagonal M (the row sums of :math:`\lambda|B|`) is nonzero, S the Schur complement
    of K onto them (the other DOFs, the rotations, carry no geometric stiffness and
    are eliminated at their minimum) and Q a basis of the tangent space
    :math:`(Bu)^Tv = 0`. With as many Krylov vectors as that space has dimensions the
    Rayleigh–Ritz value is that eigenvalue (to the rounding of the thin plate's solves,
    measured 1e-11 of it); the step along the direction lowers the barrier objective.
    """
    problem = build_problem(thin_plate(nx=6, ny=3), MPI.COMM_SELF)
    A, B = dense(problem.model.A), dense(problem.model.B)
    D = np.abs(B).sum(axis=1)
    P, R = np.flatnonzero(D > 0.0), np.flatnonzero(D == 0.0)
    # As many Krylov vectors as the tangent space on P has dimensions (one more would
    # be rounding only, with rotations that are not at their least energy).
    options = replace(NewtonOptions(), curvature_vectors=P.size - 1)
    second = np.sort(np.linalg.eigvals(np.linalg.solve(A, B)).real)[-2]
    lam = 1.3 / second  # between the second and third free loads
    with InteriorPointNewton(problem, options) as newton:
        u, gap, nu, mu_abs = at_saddle(newton, lam)
        vec = u.x.petsc_vec
        x = vec.array.copy()
        assert newton.kernel.last_correction > 0.0  # the unmodified K had the wrong inertia
        du = newton.kernel.du.array.copy()
        found = newton.curvature.find(vec, lam)
        assert found is not None
        theta, d, curvature = found[0], found[1].array.copy(), found[2]
        assert np.array_equal(newton.kernel.du.array, du)  # the Newton direction is kept
        phi0 = newton.kernel.merit(vec, mu_abs)
        assert newton.curvature.step(vec, lam, gap, mu_abs) is not None
        phi1 = newton.kernel.merit(vec, mu_abs)
        sigma = np.zeros(x.size)
        sigma[newton.kernel.dofs] = nu / gap
    problem.destroy()
    K = A - lam * B + np.diag(sigma)
    S = K[np.ix_(P, P)] - K[np.ix_(P, R)] @ np.linalg.solve(K[np.ix_(R, R)], K[np.ix_(R, P)])
    Q = np.linalg.svd((B @ x)[P][None, :])[2][1:].T  # orthonormal basis of the tangent space
    M = lam * np.diag(D[P])
    L = np.linalg.cholesky(Q.T @ M @ Q)
    reference = np.linalg.eigvalsh(np.linalg.solve(L, np.linalg.solve(L, Q.T @ S @ Q).T))[0]
    assert reference < -1e-4  # a saddle, as the test intends
    assert theta == pytest.approx(reference, rel=1e-8)
    assert abs((B @ x) @ d) <= 1e-10 * np.abs(B @ x).max() * np.abs(d).max()
    assert (d @ K @ d) / (d @ (lam * D * d)) == pytest.approx(reference, rel=1e-8)
    assert curvature == pytest.approx(d @ K @ d, rel=1e-8)
    assert phi1 < phi0


@serial
def test_negative_curvature_is_the_same_on_two_ranks(tmp_path, thin_plate):
    """Three Krylov vectors: a Ritz value that depends on the start.

    The start is a function of the DOFs' coordinates, not of their numbers, so two ranks
    find the serial value (to the rounding of the solves, 1e-9 relative on this thin plate).
    """
    spec = thin_plate(nx=12, ny=4)
    problem = build_problem(spec, MPI.COMM_SELF)
    A, B = dense(problem.model.A), dense(problem.model.B)
    lam = 1.3 / np.sort(np.linalg.eigvals(np.linalg.solve(A, B)).real)[-2]
    with InteriorPointNewton(problem, replace(NewtonOptions(), curvature_vectors=3)) as newton:
        u, *_ = at_saddle(newton, lam)
        found = newton.curvature.find(u.x.petsc_vec, lam)
        assert found is not None
    problem.destroy()
    path = tmp_path / "plate.json"
    path.write_text(json.dumps({"input": problem_to_dict(spec)}))
    script = PARALLEL.parent / "negative_curvature_parallel.py"
    out = run_mpi(script, 2, str(path), repr(float(lam)), "3")
    report = json.loads(out.strip().splitlines()[-1])
    assert found[0] < -1e-4
    assert report["theta"] == pytest.approx(found[0], rel=1e-9)


@serial
def test_prolongation_is_exact_for_q1(thin_plate):
    coarse = build_problem(thin_plate(nx=4, ny=2), MPI.COMM_SELF)
    fine = build_problem(thin_plate(nx=8, ny=4), MPI.COMM_SELF)
    carry = Prolongation(coarse, fine)
    u = coarse.new_mode()
    u.sub(0).interpolate(lambda x: 1.0 + 2.0 * x[0] - 3.0 * x[1])
    u.x.scatter_forward()
    v = carry.mode(u)
    w = dolfinx.fem.Function(fine.model.Vw)
    w.interpolate(lambda x: 1.0 + 2.0 * x[0] - 3.0 * x[1])
    assert np.allclose(v.x.array[fine.model.w_dofs], w.x.array, atol=1e-12)
    for p in (coarse, fine):
        p.destroy()


@serial
def test_lift_is_the_least_energy_correction(thin_plate):
    """``lift`` moves every node off the obstacle by the correction of least energy.

    A coarse clamped plate's free mode, carried to a finer mesh and relaxed, crosses
    the obstacle on half the plate. The correction c = lifted - start gives every such
    node its prescribed gap, and among all corrections with those nodal deflections
    (the nodal clip's is one) it has the least energy a(c, c) (the minimum-energy
    extension of prescribed values): checked against the clip's correction.
    """
    coarse = build_problem(thin_plate("cs", nx=12, ny=4), MPI.COMM_SELF)
    fine = build_problem(thin_plate("cs", nx=24, ny=8), MPI.COMM_SELF)
    margin = 1e-3
    with InteriorPointNewton(fine) as newton:
        start = Prolongation(coarse, fine).mode(coarse.solve_free().function)
        newton.starts.relax(start.x.petsc_vec, "deflection")
        newton.starts.relax(start.x.petsc_vec, "rotations")
        amplitude = fine.max_abs_w(start.x.petsc_vec)
        lifted, clipped = fine.new_mode(), fine.new_mode()
        for target in (lifted, clipped):
            target.x.array[:] = start.x.array
        moved = newton.starts.lift(lifted, margin)
        assert moved > 0
        # The clip at the same (fixed) limit as the lift's first correction.
        z0 = newton.kernel.oriented(start.x.petsc_vec)
        near = z0 > -margin * amplitude
        vec = clipped.x.petsc_vec
        vec.array[newton.kernel.dofs[near]] = newton.kernel.signs[near] * (-margin * amplitude)
        gap = -newton.kernel.oriented(lifted.x.petsc_vec)
        assert gap.min() >= margin * fine.max_abs_w(lifted.x.petsc_vec) * (1 - 1e-9)

        def energy(c):
            out = c.duplicate()
            fine.model.A.mult(c, out)
            return c.dot(out)

        c_lift = lifted.x.petsc_vec.copy()
        c_lift.axpy(-1.0, start.x.petsc_vec)
        c_clip = clipped.x.petsc_vec.copy()
        c_clip.axpy(-1.0, start.x.petsc_vec)
        assert energy(c_lift) <= energy(c_clip)
    for p in (coarse, fine):
        p.destroy()


@serial
@pytest.mark.parametrize(
    ("spec", "kind", "i"), FAMILY[:SAMPLE], ids=[s.name for s, *_ in FAMILY[:SAMPLE]]
)
def test_route_equals_exhaustive_minimum_sample(spec, kind, i):
    route = structs.replace(spec, solver=structs.replace(spec.solver, method="interior-point"))
    check(route, kind, i, KNOWN_LOCAL_MINIMA)


@serial
@pytest.mark.stress
@pytest.mark.parametrize(
    ("spec", "kind", "i"), FAMILY[SAMPLE:], ids=[s.name for s, *_ in FAMILY[SAMPLE:]]
)
def test_route_equals_exhaustive_minimum_family(spec, kind, i):
    route = structs.replace(spec, solver=structs.replace(spec.solver, method="interior-point"))
    check(route, kind, i, KNOWN_LOCAL_MINIMA)


def _route(spec) -> dict:
    with solve(spec, MPI.COMM_WORLD) as analysis:
        sol, cert = analysis.solution, analysis.certificate
        assert sol is not None and cert is not None
        problem = analysis.problem
        assert problem.contact is not None
        values = problem.contact.values(sol.candidate.mode.x.petsc_vec)
        return {
            "method": analysis.result.method,
            "load": sol.load,
            "coordinates": problem.contact.coordinates[sol.active].tolist(),
            "kkt": cert.kkt,
            "smallest": cert.smallest_of_reduced,
            "on_contact": float(np.abs(values[sol.active]).max(initial=0.0)),
            "levels": jsonable(sol.details).get("levels", []),
        }


@serial
def test_thin_plate_route_is_certified(thin_plate):
    """SSSS, loaded edges clamped: 45x15 cells, t/b = 1e-3, whole-plate obstacle."""
    for name in ("ssss", "cs"):
        report = _route(thin_plate(name, nx=45, ny=15))
        assert report["method"].startswith("interior-point"), report["method"]
        assert report["kkt"] and report["smallest"], report
        assert report["on_contact"] == 0.0  # removed DOFs of the reduced pencil
        meshes = [lv["mesh"] for lv in report["levels"]]
        assert meshes == [[22, 7], [45, 15]], meshes
        assert all(lv["newton_steps"] > 0 for lv in report["levels"])


@serial
def test_obstacle_below_is_the_mirror_image(thin_plate):
    """The plate against an obstacle below is the mirror image (w -> -w) of the one above.

    A thin SSSS plate under shear (nearly equal arrangements of the buckle): the same
    load, contact set and Newton steps, by the same route. Before the barrier's Hessian
    was fixed the route failed on every start below and the slow active-set chain
    answered; before the starts were oriented by the obstacle, the mirrored plate ended
    at another contact set of equal load.
    """
    spec = thin_plate("shear", nx=24, ny=8, load="shear")
    below = structs.replace(spec, obstacle=structs.replace(spec.obstacle, side="below"))
    above, under = _route(spec), _route(below)
    for report in (above, under):
        assert report["method"] == "interior-point", report["method"]
        assert report["kkt"] and report["smallest"], report
    assert under["load"] == pytest.approx(above["load"], rel=1e-9)
    assert under["coordinates"] == above["coordinates"]
    # The starts are oriented by the obstacle, not by the free mode's arbitrary sign: the
    # same Newton steps on every level.
    steps = [[lv["newton_steps"] for lv in r["levels"]] for r in (above, under)]
    assert steps[0] == steps[1], steps


def _twisted(nx: int, ny: int, method: str = "interior-point"):
    """Two zones on opposite sides of a plate with a free edge (t/b = 1e-2).

    Left edge simply supported, right clamped (both loaded), bottom free, top simply
    supported; w <= 0 on the left 45 %, w >= 0 on the right 45 %.
    """
    data = {
        "plate": {"corners": [[0.0, 0.0], [0.15, 0.1]], "thickness": 1e-3},
        "material": {"E": 2.1e11, "nu": 0.3},
        "edges": {
            "left": {"support": "simply_supported", "normal_stress": -1.0},
            "right": {"support": "clamped", "normal_stress": -1.0},
            "bottom": {"support": "free"},
            "top": {"support": "simply_supported"},
        },
        "mesh": {"nx": nx, "ny": ny},
        "obstacles": [
            {"zone": [[0.0, 0.0675], [0.0, 0.1]], "side": "above"},
            {"zone": [[0.0825, 0.15], [0.0, 0.1]], "side": "below"},
        ],
        "solver": {"method": method},
    }
    return problem_from_dict(data)


@serial
def test_pressure_deflection_is_lifted_into_the_cone():
    """A pressure deflection that crosses an obstacle is lifted back into the cone.

    The two pushes twist the plate about its free edge across an obstacle; the start is
    moved back to a gap of at least PUSH_MARGIN max|w| at every constrained node.
    """
    problem = build_problem(_twisted(9, 6), MPI.COMM_SELF)
    with InteriorPointNewton(problem) as newton:
        plain = problem.new_mode("plain")
        newton.kernel.factor(0.0, None)
        newton.kernel.rhs.zeroEntries()
        newton.kernel.add_zone(newton.kernel.rhs, -np.ones(newton.kernel.contact.size))
        newton.kernel.ksp.solve(newton.kernel.rhs, plain.x.petsc_vec)
        assert newton.kernel.oriented(plain.x.petsc_vec).max() > 0.0  # crosses an obstacle
        push = newton.starts.pressure_mode()
        vec = push.x.petsc_vec
        gap = -newton.kernel.oriented(vec)
        assert gap.min() >= PUSH_MARGIN * problem.max_abs_w(vec) * (1 - 1e-12)
    problem.destroy()


@serial
def test_obstacles_on_opposite_sides_with_a_free_edge():
    """The interior-point route answers, with the active-set route's load.

    Before the lift no start existed on the coarsest mesh and the active-set chain
    answered after the interior point.
    """
    route = _route(_twisted(36, 24))
    assert route["method"] == "interior-point", route["method"]
    assert route["kkt"] and route["smallest"], route
    other = _route(_twisted(36, 24, "active-set"))
    assert other["method"] == "active-set" and other["kkt"]
    assert route["load"] == pytest.approx(other["load"], rel=1e-9)


@pytest.mark.mpi
@serial
def test_two_ranks_give_the_serial_answer(tmp_path, thin_plate):
    spec = thin_plate("cs", nx=45, ny=15)
    serial_report = _route(spec)
    path = tmp_path / "plate.json"
    path.write_text(json.dumps({"input": problem_to_dict(spec)}))
    report = json.loads(run_mpi(PARALLEL, 2, str(path)).strip().splitlines()[-1])
    assert report["kkt"] and report["smallest"]
    assert abs(report["load"] - serial_report["load"]) <= 1e-8 * serial_report["load"]
    assert report["coordinates"] == serial_report["coordinates"]


@serial
def test_option_under_the_prefix_reaches_the_factorisation(thin_plate):
    """A command-line MUMPS control under the prefix, and the inertia controls, are in effect.

    The Newton matrix is factorised by the mesh's shared LDL^T (prefix ``unibuckle_ldl_``).
    Construction does not factorise; the controls are read at the first factorisation.
    """
    problem = build_problem(thin_plate(nx=6, ny=3), MPI.COMM_SELF)
    prefix = f"{problem.eigensolver.prefix}ldl_"
    assert prefix == "unibuckle_ldl_"
    opts = PETSc.Options()
    opts[f"{prefix}mat_mumps_icntl_14"] = 57
    try:
        with InteriorPointNewton(problem) as newton:
            assert newton.kernel.factorizations == 0
            newton.starts.pressure_mode()  # one factorisation of A
            factor = newton.kernel.ksp.getPC().getFactorMatrix()
            assert factor.getMumpsIcntl(14) == 57
            assert (factor.getMumpsIcntl(13), factor.getMumpsIcntl(24)) == (1, 1)
            assert factor.getInertia()[0] == 0  # A is positive definite
    finally:
        del opts[f"{prefix}mat_mumps_icntl_14"]
        problem.destroy()


def test_stall_watch_counts_steps_without_halving():
    """The run stops after ``stall_steps`` steps in which the residual did not halve."""
    watch = StallWatch(3)
    # 1.0 sets the best; 0.6, 0.9, 0.51 do not halve it: the third of them stalls.
    assert [watch.stalled(r) for r in (1.0, 0.6, 0.9, 0.51)] == [False, False, False, True]
    watch = StallWatch(3)
    # Halving (0.5, then 0.2) resets the count.
    assert not any(watch.stalled(r) for r in (1.0, 0.8, 0.5, 0.45, 0.2, 0.15, 0.19))
    assert not any(StallWatch(0).stalled(1.0) for _ in range(50))


@serial
def test_starts_on_one_central_path_are_not_taken_further(thin_plate):
    """A start on the central path of an arrangement met before stops there.

    Thin SSSS plate, 45x15 (coarsest mesh 22x7): several starts reach one arrangement;
    the lowest critical state is the one found when every start is taken to the end
    (``twin_rtol = path_rtol = 0``: only bit-identical loads compare equal, whatever the
    deflections), in fewer Newton steps on the coarsest mesh.
    """
    problem = build_problem(thin_plate("ssss", nx=45, ny=15), MPI.COMM_SELF)
    short = solve_interior_point(problem, ChainOptions())
    full = solve_interior_point(problem, ChainOptions(twin_rtol=0.0, path_rtol=0.0))
    coarse = [jsonable(sol.details.levels[0]) for sol in (short, full)]
    assert "met before" in [link["status"] for link in coarse[0]["links"]]
    assert "met before" not in [link["status"] for link in coarse[1]["links"]]
    assert coarse[0]["newton_steps"] < coarse[1]["newton_steps"]
    assert short.method == full.method == "interior-point"
    assert np.array_equal(short.candidate.active, full.candidate.active)
    # One contact set, its eigen solve shifted below two barrier loads: equal to the
    # resolution of the load in double precision.
    resolution = _load_rounding(problem, full.candidate)
    assert short.load == pytest.approx(full.load, rel=resolution)
    assert short.candidate.kkt
    problem.destroy()


@serial
def test_second_free_mode_is_the_pencils_second_eigenpair(thin_plate):
    """The starts "free2-" and "free2+" are the parts of the free plate's second mode.

    Reference: a dense solve of B x = theta A x (scipy.linalg.eigh) on the assembled
    matrices of a thin SSSS plate (6x3); the mode's Rayleigh quotient a(u, u)/b(u, u) is
    the second smallest positive load 1/theta. Tolerance: dense and SLEPc solves of these
    plates agree to a few 1e-8 (cond(A) ~ 1e11, ``tests/support/stress.py``).
    """
    problem = build_problem(thin_plate("ssss", nx=6, ny=3), MPI.COMM_SELF)
    A, B = dense(problem.model.A), dense(problem.model.B)
    theta = scipy.linalg.eigh(B, A, eigvals_only=True)
    loads = np.sort(1.0 / theta[theta > 0.0])
    assert loads[1] > loads[0] * (1.0 + 1e-3)  # a simple second eigenvalue
    vec = second_free_mode(problem)
    assert vec is not None
    x = vec.array.copy()
    vec.destroy()
    assert x @ A @ x / (x @ B @ x) == pytest.approx(loads[1], rel=1e-6)
    problem.destroy()


@serial
@pytest.mark.parametrize("thickness", [1e-3, 2e-3])
def test_clamped_plate_reaches_its_two_buckle_state(thickness):
    """A clamped 0.3 x 0.1 m plate against a whole face (t = 1, 2 mm; 45x15).

    The starts from the free plate's first mode and from pressures all end at three
    buckles along the plate; two buckles in the middle lie lower, and the parts of the
    second mode reach them. Reference: the active-set route (another algorithm, from its
    own starts), whose load the route's must not exceed beyond the load's resolution in
    double precision (1e-9). Before the second mode's starts the route ended 5.7e-3
    (1 mm) and 5.0e-4 (2 mm) above it.
    """
    spec = plate_case(
        "cccc",
        length=0.3,
        width=0.1,
        thickness=thickness,
        supports="clamped",
        nx=45,
        ny=15,
        zone=ObstacleSpec(zone="all"),
    )
    loads = {}
    for method in ("interior-point", "active-set"):
        with solve(spec.with_solver(method=method, certify=False), MPI.COMM_SELF) as analysis:
            assert analysis.result.method.startswith(method)
            assert analysis.solution is not None and analysis.solution.candidate.kkt
            loads[method] = analysis.result.critical_load_Pa
    assert loads["interior-point"] <= loads["active-set"] * (1.0 + 1e-9), loads


@serial
def test_predicted_contact_set_is_the_affine_step_indicator(thin_plate):
    r"""Z = {k : \delta z_k > g_k/2} for the dense Newton step at :math:`\mu = 0`.

    The affine-scaling step moves a gap g to :math:`g - \delta z` and a push
    :math:`\nu` to :math:`\nu\,\delta z/g`; the gap falls by a larger fraction than
    the push exactly when :math:`\delta z > g/2` (the Tapia indicator: El-Bakry, Tapia &
    Zhang, SIAM Rev. 36, 1994). Reference: a dense solve of the full Jacobian, as in
    :func:`test_newton_direction_solves_the_linearised_conditions`, with pushes that
    make some gaps close and others open.
    """
    problem = build_problem(thin_plate(nx=6, ny=3), MPI.COMM_SELF)
    with InteriorPointNewton(problem) as newton:
        u = newton.starts.pressure_mode()
        newton.kernel.normalize(u.x.petsc_vec)
        x = u.x.petsc_vec.array.copy()
        A, B = dense(problem.model.A), dense(problem.model.B)
        n, rows = x.size, newton.kernel.dofs
        E = np.zeros((n, rows.size))
        E[rows, np.arange(rows.size)] = newton.kernel.signs
        gap = -E.T @ x
        rng = np.random.default_rng(3)
        nu = rng.uniform(0.01, 3.0, rows.size) * np.abs(A @ x).max() * 1e-2
        lam = 0.5 * problem.solve_free().load  # K positive definite: no regularisation
        active = newton.predicted_contact_set(BarrierPoint(u, lam, nu, 1e-9))
        positions = newton.kernel.contact.owned_positions
    problem.destroy()
    dz = E.T @ _dense_newton_step(A, B, E, x, lam, nu, 0.0)[:n]
    ratio = dz / gap
    assert (np.abs(ratio - 0.5) > 1e-6).all()  # no node on the fence
    expected = np.sort(positions[(ratio > 0.5) | (gap - dz <= problem.tau * np.abs(x).max())])
    assert 0 < expected.size < rows.size  # both kinds present
    assert np.array_equal(active, expected)


@serial
def test_predicted_contact_set_read_inside_a_run_leaves_it_unchanged(thin_plate):
    """Read from the ``on_solved`` hook, the set costs no factorisation and no change.

    Thin SSSS plate, 22x7, from the pressure deflection: the run with the hook takes the
    same steps, factorisations and loads (bit for bit) as the run without it, and the
    set read inside equals the one computed afresh from a copy of the same point.
    """
    problem = build_problem(thin_plate(nx=22, ny=7), MPI.COMM_SELF)
    runs, inside, copies = [], [], []

    def hook(point):
        inside.append(newton.predicted_contact_set(point))
        mode = problem.new_mode("copy")
        point.mode.x.petsc_vec.copy(mode.x.petsc_vec)
        copies.append(BarrierPoint(mode, point.load, point.push.copy(), point.mu))
        return None

    with InteriorPointNewton(problem) as newton:
        for on_solved in (None, hook):
            newton.kernel.forget_corrections()
            _, record = newton.solve(newton.starts.pressure_mode(), mu=1e-2, mu_min=1e-12,
                                     on_solved=on_solved)  # fmt: skip
            runs.append(record)
        fresh = [newton.predicted_contact_set(point) for point in copies]
    problem.destroy()
    plain, hooked = runs
    assert plain.status is hooked.status is NewtonStatus.CONVERGED
    assert (plain.steps, plain.factorizations) == (hooked.steps, hooked.factorizations)
    assert plain.history == hooked.history
    assert len(inside) >= 2
    assert all(np.array_equal(a, b) for a, b in zip(inside, fresh, strict=True))


@serial
def test_a_state_read_off_the_gaps_short_of_kkt_reads_the_predicted_set_too(thin_plate):
    """With ``read_predicted`` the predicted set is read where the gaps' set fails.

    Thin SSSS plate, 45x15, a run from the pressure deflection to the barrier problem at
    1e-9: there the gaps at the tolerance hold part of the contact set only (no KKT
    point), while the predicted set is the one the gaps give where the barrier problem
    at 1e-10 is solved, a KKT point (reference: that read, by the gaps alone). By
    default :func:`~.links.critical_state` goes on from the gaps' set (a further run);
    with ``read_predicted`` it returns the predicted set's KKT point at once.
    """
    problem = build_problem(thin_plate("ssss", nx=45, ny=15), MPI.COMM_SELF)
    options = ChainOptions(read_predicted=True)
    with InteriorPointNewton(problem) as newton:
        newton.kernel.forget_corrections()
        reference, _ = newton.solve(newton.starts.pressure_mode(), mu=1e-2, mu_min=1e-10)
        at_reference = newton.contact_set(reference)
        expected = read_contact(problem, newton, reference, MeshLevel([45, 15], 0), "ref")
        states = {}
        for read_predicted in (False, True):
            newton.kernel.forget_corrections()
            point, _ = newton.solve(newton.starts.pressure_mode(), mu=1e-2, mu_min=1e-9)
            gaps = newton.contact_set(point)
            level = MeshLevel([45, 15], problem.num_constrained)
            chosen = replace(options, read_predicted=read_predicted)
            cand, _ = critical_state(problem, newton, point, level, "test", chosen, carry=False)
            states[read_predicted] = (cand, level.links)
    problem.destroy()
    assert expected.kkt and not np.array_equal(gaps, at_reference)
    cand, links = states[True]
    assert cand is not None and cand.kkt
    assert np.array_equal(cand.active, at_reference)
    assert [(link.link, link.kkt) for link in links] == [("evaluate", False), ("evaluate", True)]
    assert links[1].seed == "test (predicted)"
    _, default_links = states[False]
    assert "interior-point" in [link.link for link in default_links]  # ran on


def test_the_saddle_escaped_is_the_kept_read_first():
    """:func:`~.links.saddle_read`: the first read that crosses the obstacle below the point.

    ``critical_state`` passes the read it kept first (then, with ``escape_either``, the
    other): a kept saddle is escaped even where the other lies lower; a kept read that
    is admissible, or crosses at or above the point's load (to rounding), leaves the
    other's. Hand-made reads (load, admissible) at a point of load 100.
    """
    point = SimpleNamespace(load=100.0)
    read = {
        name: SimpleNamespace(load=load, feasible=feasible)
        for name, load, feasible in (
            ("crossing low", 60.0, False),
            ("crossing", 90.0, False),
            ("admissible", 95.0, True),
            ("crossing above", 101.0, False),
            ("crossing at", 100.0 * (1.0 - 0.1 * ROUNDING_RTOL), False),
        )
    }
    assert saddle_read(point, [read["crossing"], read["crossing low"]]) is read["crossing"]
    assert saddle_read(point, [read["admissible"], read["crossing"]]) is read["crossing"]
    assert saddle_read(point, [read["crossing above"], read["crossing"]]) is read["crossing"]
    assert saddle_read(point, [read["crossing at"], read["admissible"]]) is None
    assert saddle_read(point, [read["admissible"]]) is None


@serial
def test_the_first_tries_short_polish_descends_with_quick_descent(thin_plate):
    """``quick_descent``: the first try's short polish, short of a KKT point, descends.

    Where that polish ends at an admissible mode short of a KKT point, the feasible
    descent runs from it and ends at one. Thin SSSS plate, 45x15, a run from the
    pressure deflection to the barrier problem at 1e-6; :func:`~.links.critical_state`
    as on the fine mesh's first try (``quick``), no escape, no lower barrier, a polish
    of 2 iterates, which ends at an admissible mode that is no KKT point (measured). By
    default the try ends there (no state: the chain carries again); with
    ``quick_descent`` the descent's KKT point is returned, its load at most the
    polish's, and checked with dense numpy (KKT conditions on the assembled matrices;
    LAPACK's load of its contact set).
    """
    problem = build_problem(thin_plate("ssss", nx=45, ny=15), MPI.COMM_SELF)
    options = ChainOptions(escapes=0, last_mu_min=1.0, quick_polish_iterations=2)
    states = {}
    for quick_descent in (False, True):
        with InteriorPointNewton(problem) as newton:
            newton.kernel.forget_corrections()
            point, _ = newton.solve(newton.starts.pressure_mode(), mu=1e-2, mu_min=1e-6)
            level = MeshLevel([45, 15], problem.num_constrained)
            chosen = replace(options, quick_descent=quick_descent)
            cand, _ = critical_state(
                problem, newton, point, level, "test", chosen, carry=False, quick=True
            )
            states[quick_descent] = (cand, level.links)
    cand, links = states[False]
    polished = links[-1]
    assert cand is None and polished.link == "active-set polish" and not polished.kkt
    assert polished.load is not None  # an admissible mode short of a KKT point
    cand, links = states[True]
    assert [link.link for link in links[-2:]] == ["active-set polish", "feasible descent"]
    assert cand is not None and cand.kkt and cand.load <= polished.load
    A, B = dense(problem.model.A), dense(problem.model.B)
    x = cand.mode.x.petsc_vec.array.copy()
    assert satisfies_kkt(problem, A, B, x, cand.load, cand.active)
    reference = dense_reduced_load(problem, tuple(int(k) for k in cand.active))
    assert cand.load == pytest.approx(reference, rel=_load_rounding(problem, cand))
    problem.destroy()


def test_result_reports_the_load_resolution(thin_plate):
    """The result's ``load_resolution`` is the first-order rounding bound of the load.

    Reference: ``_load_rounding`` above (numpy on A's CSR rows), from the returned mode.
    On the thin plate (t/b = 1e-3) it is far above the 1e-16 of a well-conditioned
    eigenvalue (the shear stiffness: |A||u| >> |Au|; measured 2.8e-10 at 12x4, 3e-9 for
    SSSS at 45x15), on the paper's plate (t/b = 0.06) three orders below (8.5e-14).
    """
    with solve(thin_plate("ssss", nx=12, ny=4), MPI.COMM_SELF) as analysis:
        assert analysis.solution is not None
        reference = _load_rounding(analysis.problem, analysis.solution.candidate)
        reported = analysis.result.load_resolution
    assert reported == pytest.approx(reference, rel=1e-10)
    assert 1e-12 < reported < 1e-6
    with solve(paper_case("c1", 8, 4), MPI.COMM_SELF) as analysis:
        thick = analysis.result.load_resolution
    assert thick is not None and thick < 1e-3 * reported


@serial
def test_a_set_predicted_twice_in_a_row_is_read_before_the_barrier_problem_is_solved(thin_plate):
    """The same critical state as the read where the barrier problem at 1e-9 is solved.

    Thin SSSS plate, 60x20, whole-plate obstacle: by default (``read_stable``) the
    predicted set is evaluated as soon as two Newton steps predict the same one; without,
    where the barrier problem at 1e-9 is solved. The same contact set, its load to the
    rounding of two solves at different shifts, in fewer fine-mesh steps.
    """
    problem = build_problem(thin_plate("ssss", nx=60, ny=20), MPI.COMM_SELF)
    stable = solve_interior_point(problem, ChainOptions())
    solved = solve_interior_point(problem, ChainOptions(read_stable=False))
    fine = [jsonable(sol.details.levels[-1]) for sol in (stable, solved)]
    labels = [[link["seed"] for link in level["links"]] for level in fine]
    assert any("(stable at 1e-09)" in label for label in labels[0])
    assert not any("stable" in label for label in labels[1])
    assert fine[0]["newton_steps"] < fine[1]["newton_steps"]
    assert stable.candidate.kkt and solved.candidate.kkt
    assert np.array_equal(stable.candidate.active, solved.candidate.active)
    assert stable.load == pytest.approx(solved.load, rel=_load_rounding(problem, solved.candidate))
    problem.destroy()


@serial
def test_fine_mesh_read_early_gives_the_load_read_at_the_end(thin_plate):
    """The fine mesh's contact set read at 1e-9: the same critical state, fewer steps.

    Thin SSSS plate, 45x15, whole-plate obstacle: with ``read_mu = 0`` the contact set is
    read off the gaps at the end (``fine_mu_min``); by default the predicted set read
    where the barrier problem at 1e-9 is solved is a KKT point, and the run stops there.
    """
    problem = build_problem(thin_plate("ssss", nx=45, ny=15), MPI.COMM_SELF)
    early = solve_interior_point(problem, ChainOptions())
    late = solve_interior_point(problem, ChainOptions(read_mu=0.0))
    fine = [jsonable(sol.details.levels[-1]) for sol in (early, late)]
    assert "read" in [link["status"] for link in fine[0]["links"]]
    assert "read" not in [link["status"] for link in fine[1]["links"]]
    assert fine[0]["newton_steps"] < fine[1]["newton_steps"]
    assert early.method == late.method == "interior-point"
    assert early.candidate.kkt and late.candidate.kkt
    assert np.array_equal(early.candidate.active, late.candidate.active)
    # The same contact set, solved at shifts below two barrier loads (1e-9 and 1e-14).
    assert early.load == pytest.approx(late.load, rel=_load_rounding(problem, late.candidate))
    problem.destroy()


def _dense_forces(problem: UnilateralProblem, A, B, active) -> np.ndarray:
    r"""Forces of the smallest reduced eigenpair at the constrained nodes, by LAPACK.

    :math:`r = Au - \lambda Bu` relative to :math:`\|Au\|_\infty`, of the pencil reduced
    on ``active`` (``scipy.linalg.eigh``), the mode oriented to stay off the obstacle.
    """
    removed = np.union1d(problem.model.bc_dofs, problem.contact.removed_rows(active))
    keep = np.setdiff1d(np.arange(A.shape[0]), removed)
    theta, vecs = scipy.linalg.eigh(B[np.ix_(keep, keep)], A[np.ix_(keep, keep)])
    u = np.zeros(A.shape[0])
    u[keep] = vecs[:, -1]
    u /= np.abs(u[problem.model.w_dofs]).max()
    rows, signs = problem.contact.global_rows(), problem.contact.signs
    if (signs * u[rows]).max() > problem.tau:
        u = -u  # the admissible side
    assert (signs * u[rows]).max() <= problem.tau
    r = A @ u - (B @ u) / theta[-1]
    return signs * r[rows] / np.abs(A @ u).max()


@serial
def test_a_read_pulled_at_nodes_of_its_set_is_released_to_a_kkt_point(thin_plate):
    """``release_steps``: the nodes where the obstacle pulls are dropped and the set read again.

    Thin SSSS plate, 12x4: the route's KKT set with the two nodes nearest to the obstacle
    off it added gives an admissible mode that the obstacle pulls at exactly those two
    nodes (reference: the reduced pencil's smallest eigenpair by LAPACK, its forces
    r = Au - lambda Bu). Read from a barrier point near the KKT state, that set is no
    KKT point; with one release step the reader drops the pulled nodes, and the set it
    reads is a KKT point (checked on the dense matrices) whose load is LAPACK's for that
    set; with none (``release_steps = 0``) the read ends nothing.
    """
    problem = build_problem(thin_plate("ssss", nx=12, ny=4), MPI.COMM_SELF)
    kkt = solve_interior_point(problem, ChainOptions()).candidate
    off = np.setdiff1d(np.arange(problem.contact.size), kkt.active)
    extra = np.sort(off[np.argsort(-kkt.values[off])][:2])
    pulled_set = np.union1d(kkt.active, extra)
    A, B = dense(problem.model.A), dense(problem.model.B)
    forces = _dense_forces(problem, A, B, pulled_set)
    expected = pulled_set[forces[pulled_set] <= problem.tau]
    assert np.array_equal(np.setdiff1d(pulled_set, expected), extra)  # pulled at the two only
    cand = problem.evaluate(pulled_set, initial=kkt.mode.x.petsc_vec, near=kkt.load)
    assert cand.feasible and not cand.kkt
    kept = released(cand)
    assert kept is not None and np.array_equal(kept, expected)
    results = {}
    with InteriorPointNewton(problem) as newton:
        for steps in (0, 1):
            point = newton.starts.from_candidate(kkt, 1e-9)
            level = MeshLevel([12, 4], problem.num_constrained)
            reader = Reader(problem, newton, level, ChainOptions(release_steps=steps))
            status = reader.arm("test")._read(point, pulled_set, "given")
            results[steps] = (status, reader.found, [link.seed for link in level.links])
    assert results[0] == (None, None, ["test (given at 1e-09)"])
    status, found, seeds = results[1]
    assert status is NewtonStatus.READ and found is not None
    assert seeds == ["test (given at 1e-09)", "test (given at 1e-09) (release 1)"]
    assert np.array_equal(found.active, expected)
    x = found.mode.x.petsc_vec.array.copy()
    assert satisfies_kkt(problem, A, B, x, found.load, found.active)
    reference = dense_reduced_load(problem, tuple(expected))
    assert found.load == pytest.approx(reference, rel=_load_rounding(problem, found))
    problem.destroy()


def test_a_tensionless_foundation_is_refused_naming_its_route(thin_plate):
    # The interior point solves rigid obstacles; a foundation's route is solve_foundation
    # (as solve_foundation refuses a rigid obstacle), refused before any solve.
    foundation = ObstacleSpec("all", foundation_stiffness=1.0e3)
    spec = structs.replace(thin_plate(), obstacle=foundation)
    with build_problem(spec, MPI.COMM_SELF) as problem:
        with pytest.raises(InputError, match="solve_foundation"):
            solve_interior_point(problem)
        assert problem.eigensolver.solves == 0
