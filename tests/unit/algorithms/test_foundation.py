r"""Winkler foundations: bilateral (springs everywhere) and tensionless (compression only).

A foundation of modulus :math:`k_f` (N/m^3) is lumped at the zone's nodes
(:math:`k_f\int\varphi_k`). Expected values:

- bilateral, simply supported strip of width b: with :math:`w = \sin(\pi x/l)\sin(\pi
  y/b)` the thin-plate coefficient is :math:`k(\varphi) = 1/\varphi^2 + 2 +
  \varphi^2(1 + K)`, :math:`\varphi = l/b`, :math:`K = k_f b^4/(\pi^4 D)`; its minimum
  over :math:`\varphi` is :math:`2 + 2\sqrt{1 + K}` (the long strip), reached at
  :math:`\varphi = (1 + K)^{-1/4}` (the plate analogue of the bar on an elastic
  foundation, Timoshenko and Gere, *Theory of Elastic Stability*, 1961, chapter 2: the
  same computation with a sine across the width);
- tensionless: the quotient grows with :math:`k_f` (pointwise), lies between the free
  plate (:math:`k_f = 0`) and the rigid obstacle (:math:`k_f \to \infty`, whose spring
  term vanishes on every admissible mode), and tends to the rigid value: for a long
  plate with clamped loaded edges and simply supported long edges the thin-plate limit is
  16/3 (an interior buckle between two touch-down lines, README "Every plate the schema
  describes"), for simply supported loaded edges 9/2 (a buckle against the loaded edge).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

from mpi4py import MPI

import numpy as np
import pytest
from msgspec import structs

from unibuckle_fenicsx.algorithms import RunStatus
from unibuckle_fenicsx.algorithms.foundation import solve_foundation
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.certificate.certify import certify_foundation
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.contact import (
    ContactSetManager,
    foundation_springs,
    tributary_areas,
)
from unibuckle_fenicsx.model.materials import bending_stiffness
from unibuckle_fenicsx.spec import (
    Circle,
    Material,
    ObstacleSpec,
    problem_from_dict,
    problem_to_dict,
)
from unibuckle_fenicsx.spec.cases import paper_case, plate_case

THICKNESS = 1e-3  # b = 1 m: t/b = 1e-3, the thin limit
D = bending_stiffness(1.0e9, 0.3, THICKNESS)


def modulus(K):
    """k_f (N/m^3) of the non-dimensional foundation stiffness K = k_f b^4/(pi^4 D), b = 1."""
    return K * math.pi**4 * D


def strip_k(aspect, K):
    """Thin-plate k of the simply supported a x 1 plate on a bilateral foundation."""
    return min(1 / p**2 + 2 + p**2 * (1 + K) for p in (aspect / m for m in range(1, 60)))


def strip(aspect, ny, zone=None, supports="simply_supported"):
    return plate_case(
        "strip",
        length=aspect,
        width=1.0,
        thickness=THICKNESS,
        nx=round(aspect * ny),
        ny=ny,
        zone=zone,
        supports=supports,
    )


# -- schema ------------------------------------------------------------------------------
def test_foundation_keys_are_read_checked_and_written_back():
    data = {"obstacle": {"zone": "all", "foundation_stiffness": 2.0e6, "side": "below"}}
    spec = problem_from_dict(data)
    assert spec.obstacle.kind == "tensionless" and spec.tensionless
    assert problem_from_dict(problem_to_dict(spec)) == spec
    both = problem_from_dict(
        {"obstacle": {"zone": "all", "foundation_stiffness": 1.0, "side": "both"}}
    )
    assert both.obstacle.kind == "bilateral" and not both.tensionless
    assert both.bilateral_foundations == (both.obstacle,) and both.unilateral_obstacles == ()
    # N/mm^3 in a mm-N-MPa file: 1 N/mm^3 = 1e9 N/m^3.
    mm = problem_from_dict(
        {"units": "mm-N-MPa", "obstacle": {"zone": "all", "foundation_stiffness": 0.002}}
    )
    assert mm.obstacle.foundation_stiffness == pytest.approx(2.0e6, rel=1e-15)
    assert problem_to_dict(mm, units="mm-N-MPa")["obstacle"][
        "foundation_stiffness"
    ] == pytest.approx(0.002)


@pytest.mark.parametrize(
    "data, match",
    [
        (
            {"obstacle": {"zone": "all", "foundation_stiffness": 0.0}},
            r"obstacle\.foundation_stiffness must be > 0 N/m\^3",
        ),
        (
            {"obstacle": {"zone": "all", "foundation_stiffness": "stiff"}},
            r"obstacle\.foundation_stiffness must be a number",
        ),
        (
            {"obstacle": {"zone": "all", "side": "both"}},
            r"bilateral support.*support.*foundation_stiffness",
        ),
        (
            {
                "obstacles": [
                    {"zone": "all", "foundation_stiffness": 1.0},
                    {"zone": [[0, 0.1], [0, 0.1]]},
                ]
            },
            r"rigid obstacles and tensionless foundations in one problem are not supported",
        ),
        (
            {
                "obstacle": {"zone": "all", "foundation_stiffness": 1.0},
                "solver": {"method": "active-set"},
            },
            r'solver\.method = "active-set": a tensionless foundation .* use method = "auto"',
        ),
        (
            {
                "obstacles": [
                    {"zone": "all", "foundation_stiffness": 1.0},
                    {"zone": "all", "foundation_stiffness": 1.0, "side": "below"},
                ]
            },
            r'same foundation zone on both sides .* side = "both"',
        ),
    ],
)
def test_bad_foundations_name_the_parameter(data, match):
    with pytest.raises(ValueError, match=match):
        problem_from_dict(data)


def test_a_bilateral_foundation_goes_with_a_rigid_obstacle():
    data = {
        "obstacles": [
            {"zone": "all", "foundation_stiffness": 1.0e3, "side": "both"},
            {"zone": [[-0.04, 0.04], [-0.05, 0.05]]},
        ]
    }
    spec = problem_from_dict(data).with_mesh(12, 6)
    with solve(spec) as analysis:
        assert analysis.result.method != "foundation" and analysis.result.certificate.kkt


# -- the spring term ---------------------------------------------------------------------
def test_a_bad_iteration_count_is_refused_before_any_solve():
    # max_iterations is the [solver] key's (an integer >= 1): refused naming it, no eigen solve.
    spec = strip(1.5, 6, ObstacleSpec("all", foundation_stiffness=1.0))
    with build_problem(spec, MPI.COMM_WORLD) as problem:
        for bad in (0, 2.5, True):
            with pytest.raises(ValueError, match=r"max_iterations must be an integer >= 1"):
                solve_foundation(problem, max_iterations=bad)
        assert problem.eigensolver.solves == 0


def test_tributary_areas_sum_to_the_plate_area():
    spec = strip(1.5, 6, ObstacleSpec("all", foundation_stiffness=1.0))
    with build_problem(spec, MPI.COMM_WORLD) as problem:
        areas = tributary_areas(problem.model)
        n = problem.model.Vw.dofmap.index_map.size_local
        total = MPI.COMM_WORLD.allreduce(float(areas.array[:n].sum()), op=MPI.SUM)
        # Interior nodes of a uniform grid carry one cell: h^2.
        assert problem.contact.stiffness.max() == pytest.approx((1.5 / 9) * (1.0 / 6), rel=1e-12)
    assert total == pytest.approx(1.5, rel=1e-13)


def _hat_integral(x, lo, hi, h):
    """Exact 1-D integral over [lo, hi] of the hat function of spacing h at x (on the grid)."""
    left = np.clip(np.minimum(x, hi) - np.maximum(x - h, lo), 0.0, None)  # rising half
    right = np.clip(np.minimum(x + h, hi) - np.maximum(x, lo), 0.0, None)  # falling half
    # The rising half of the hat over [x - h, x] covers [a, b] with weight
    # ((b - (x - h))^2 - (a - (x - h))^2) / (2 h); likewise the falling half.
    a, b = np.maximum(x - h, lo), np.minimum(x, hi)
    rise = np.where(left > 0, ((b - x + h) ** 2 - (a - x + h) ** 2) / (2 * h), 0.0)
    a, b = np.maximum(x, lo), np.minimum(x + h, hi)
    fall = np.where(right > 0, ((x + h - a) ** 2 - (x + h - b) ** 2) / (2 * h), 0.0)
    return rise + fall


def test_foundation_springs_are_the_zone_integral_of_the_hat_functions():
    """Node k of a foundation carries k_f times the integral of its hat function over the zone.

    1.5 x 1 m plate, 9 x 6 cells (h = 1/6), zone [0.5, 1] x [1/3, 1] on grid lines. The
    Q1 hat function is a product of 1-D hats, so its integral over the box is the product
    of the 1-D integrals over [0.5, 1] and [1/3, 1] (computed in closed form here): h on
    a node inside, h/2 on the zone's edge, 0 outside. The zone's nodes on its edges
    carried their whole area h^2 before (the springs overstated the foundation). The sum
    is the zone's area, 1/3 m^2. A bilateral foundation's springs and a tensionless one's
    are the same numbers.
    """
    h = 1.0 / 6
    zone = ((0.5, 1.0), (1.0 / 3, 1.0))
    kf = 2.0e3
    spec = strip(1.5, 6)
    with build_problem(spec, MPI.COMM_WORLD) as problem:
        model = problem.model
        owned = model.Vw.dofmap.index_map.size_local
        xy = model.Vw.tabulate_dof_coordinates()[:owned, :2]
        areas = tributary_areas(model, ObstacleSpec(zone, foundation_stiffness=kf)).array[:owned]
        exact = _hat_integral(xy[:, 0], 0.5, 1.0, h) * _hat_integral(xy[:, 1], 1 / 3, 1.0, h)
        np.testing.assert_allclose(areas, exact, rtol=1e-12, atol=1e-15)
        total = MPI.COMM_WORLD.allreduce(float(areas.sum()), op=MPI.SUM)
        contact = ContactSetManager(model, ObstacleSpec(zone, foundation_stiffness=kf))
        xc = contact.coordinates
        expected = kf * _hat_integral(xc[:, 0], 0.5, 1.0, h) * _hat_integral(xc[:, 1], 1 / 3, 1, h)
        # The manager's coordinates are rounded to 1e-12 m: rtol 1e-9 on h/2 = 0.08 m.
        np.testing.assert_allclose(contact.stiffness, expected, rtol=1e-9)
        _, springs = foundation_springs(
            model, [ObstacleSpec(zone, foundation_stiffness=kf, side="both")]
        )
        gathered = np.sort(np.concatenate(MPI.COMM_WORLD.allgather(springs)))
        np.testing.assert_allclose(gathered, np.sort(contact.stiffness), rtol=1e-12)
    assert total == pytest.approx(0.5 * (2.0 / 3.0), rel=1e-13)
    assert contact.stiffness.max() == pytest.approx(kf * h * h, rel=1e-12)
    assert contact.stiffness.min() == pytest.approx(kf * h * h / 4, rel=1e-12)  # its corners


def test_a_zone_node_on_no_covered_cell_carries_no_tensionless_spring():
    """A circle's nodes that lie on no cell inside it carry no foundation, and no spring.

    1.5 x 1 m plate, 9 x 6 cells (h = 1/6), circle of radius 0.34 m about the node (0.5,
    0.5): 13 nodes lie in it (offsets (i, j) h with i^2 + j^2 <= 4), but only the four
    cells about the centre have all their nodes in it (their far corners at 0.236 m;
    the next cells' at 0.373 m). The foundation is those cells, 4 h^2, carried by their
    9 nodes; the 4 nodes at 2h lie on no such cell. Before, the 13 nodes carried their
    whole areas (13 h^2); a node with no area would be a tensionless spring of zero
    stiffness, which the spring-set iteration refuses.
    """
    h = 1.0 / 6
    zone = ObstacleSpec(Circle((0.5, 0.5), 0.34), foundation_stiffness=1.0)
    with build_problem(strip(1.5, 6, zone), MPI.COMM_WORLD) as problem:
        contact = problem.contact
        assert contact.size == 9
        assert contact.stiffness.sum() == pytest.approx(4 * h * h, rel=1e-12)
        assert np.abs(contact.coordinates - 0.5).max() == pytest.approx(h, rel=1e-9)
    with solve(strip(1.5, 6, zone)) as analysis:
        assert analysis.result.method == "foundation"


def test_a_foundation_split_in_two_zones_is_the_whole_foundation():
    """Zones [0, 0.75] and [0.75, 2] of a 2 x 1 plate together are the whole-plate foundation.

    The integral over the plate is the sum of the integrals over the two parts, so the
    loads agree to rounding. Before, the line x = 0.75 carried both zones' whole areas (a
    strip of width h counted twice): 16 x 8 cells, K = 15, 3.2 % too high.
    """
    kf = modulus(15.0)
    halves = tuple(
        ObstacleSpec(z, foundation_stiffness=kf, side="both")
        for z in (((0.0, 0.75), (0.0, 1.0)), ((0.75, 2.0), (0.0, 1.0)))
    )
    whole = ObstacleSpec("all", foundation_stiffness=kf, side="both")
    loads = []
    for obstacles in (halves, (whole,)):
        with solve(structs.replace(strip(2.0, 8), obstacles=obstacles)) as analysis:
            loads.append(analysis.result.critical_load_Pa)
    assert loads[0] == pytest.approx(loads[1], rel=1e-10)


def test_a_partial_foundation_converges_at_the_element_rate():
    """A bilateral foundation on [0.5, 1.5] x [0, 1] of a 2 x 1 plate: loads converge at h^2.

    The element converges at rate 2 (MITC4); springs whose zone-edge nodes take their
    whole area add an O(h) error (a strip h/2 wide along each zone edge), and the
    successive differences on b/12, b/24, b/48 then shrink by 2.6 (rate 1.4) instead
    of 4.
    """
    zone = ObstacleSpec(((0.5, 1.5), (0.0, 1.0)), foundation_stiffness=modulus(15.0), side="both")
    loads = []
    for ny in (12, 24, 48):
        with solve(strip(2.0, ny, zone)) as analysis:
            loads.append(analysis.result.critical_load_Pa)
    rate = math.log2((loads[0] - loads[1]) / (loads[1] - loads[2]))
    assert 1.8 < rate < 2.2, (rate, loads)


@pytest.mark.parametrize("aspect, K", [(2.0, 15.0), (3.0, 3.0)])
def test_bilateral_foundation_against_the_strip_formula(aspect, K):
    """Bilateral foundation: k = min over the half-waves of 1/phi^2 + 2 + phi^2 (1 + K).

    (2, 15): four half-waves of b/2, exactly the long strip's 2 + 2 sqrt(1 + K) = 10;
    (3, 3): four half-waves of 0.75 b, 6.028, 0.5 % above the long strip's 6. Meshes of
    b/16 and b/32: the finer within 1 % of the formula, Richardson (rate 2) within 1e-3.
    """
    zone = ObstacleSpec("all", foundation_stiffness=modulus(K), side="both")
    ks = []
    for ny in (16, 32):
        with solve(strip(aspect, ny, zone)) as analysis:
            assert analysis.result.method == "free"  # the springs are part of A
            ks.append(analysis.result.buckling_coefficient_k)
    exact = strip_k(aspect, K)
    assert ks[1] == pytest.approx(exact, rel=1e-2)
    assert ks[1] + (ks[1] - ks[0]) / 3 == pytest.approx(exact, rel=1e-3)
    assert exact == pytest.approx(2 + 2 * math.sqrt(1 + K), rel=5e-3)


# -- tensionless ---------------------------------------------------------------------------
def test_foundation_the_free_mode_turns_away_from_is_proven_inactive():
    """A foundation the free mode turns away from is inactive, proven.

    A square plate's first mode is one-signed: turned away from a whole-plate foundation
    it presses nothing, so the load is the free one and the bracket closes.
    """
    spec = strip(1.0, 8, ObstacleSpec("all", foundation_stiffness=modulus(100.0)))
    with solve(spec) as analysis:
        result = analysis.result
    assert result.method == "foundation" and result.contact_nodes == 0
    assert result.critical_load_Pa == pytest.approx(result.free_load_Pa, rel=1e-10)
    assert result.certificate.kkt and result.certificate.global_optimum_proven


@pytest.mark.parametrize(("stiffness", "proven"), [(1e-300, True), (modulus(1.0), False)])
def test_a_foundation_is_proven_when_its_bracket_closes(stiffness, proven):
    """The bracket [lambda_free, lambda] proves the answer when it closes, nodes pressing.

    a/b = 3 on 12 x 4 cells, simply supported: the free mode has three half-waves and
    presses the whole-plate foundation which way it turns. Springs of 1e-300 N/m^3 add
    nothing a double can hold, so the expected load is the free plate's (the same plate
    solved without an obstacle) and the bracket closes: proven (before: ``kkt-only``,
    "between L and L"). At K = 1 the springs raise the load (the strip formula's
    bilateral k = 2 + 2 sqrt(2) bounds it above, k = 4 of the free plate below): a gap,
    never proven.

    The springs of 1e-300 stop after the free start: its spring-set iteration reaches a
    fixed point (a KKT point) at the free load, which no other start can lower (every
    quotient is at least lambda_free). Expected eigen solves, by the route: the free
    plate's one, then the free start's two (no springs; the set that mode presses, which
    repeats): 3. Before, every start ran and the rigid twin was solved: 70. (The free
    load is the expected value, not Navier's k = 4: on 12 x 4 cells it is k = 4.37.)
    """
    base = strip(3.0, 4)
    with solve(base) as analysis:
        free = analysis.result.critical_load_Pa
    spec = structs.replace(base, obstacle=ObstacleSpec("all", foundation_stiffness=stiffness))
    with solve(spec) as analysis:
        result = analysis.result
    assert result.method == "foundation" and result.contact_nodes > 0
    assert result.certificate.kkt
    starts = result.details.run.foundation_iterations
    if proven:
        assert result.critical_load_Pa == pytest.approx(free, rel=1e-9)  # eigen tolerance
        assert starts == {"free": 2} and result.eigensolves == 3
    else:
        assert result.critical_load_Pa > free * (1 + 1e-3)
        assert {"free", "bilateral", "rigid"} <= set(starts)
    assert result.certificate.global_optimum_proven is proven


def test_the_foundation_certificate_reads_the_typed_status_never_a_default():
    """The certificate takes the spring-set status from ``solution.status``.

    A solution without one is refused (before, a missing "foundation_status" key read as
    "converged" and certified); an unconverged status is not KKT. The status reaches the
    JSON under its old key and spelling.
    """
    spec = strip(1.0, 8, ObstacleSpec("all", foundation_stiffness=modulus(100.0)))
    with solve(spec) as analysis:
        solution = analysis.solution
        assert solution is not None and solution.status is RunStatus.CONVERGED
        assert analysis.result.details.run.foundation_status == "converged"
        with pytest.raises(ValueError, match=r"solution\.status"):
            certify_foundation(analysis.problem, replace(solution, status=None))
        stalled = certify_foundation(
            analysis.problem, replace(solution, status=RunStatus.MAX_ITERATIONS)
        )
        assert not stalled.kkt


@pytest.mark.parametrize("supports", ["simply_supported", "loaded_clamped"])
def test_tensionless_foundation_lies_between_free_and_rigid_and_grows(supports):
    """a/b = 3, 24x8 cells, t/b = 1e-3, whole-plate foundation, K = 1 ... 1e4.

    k(K) increases strictly, stays between the free plate's and the rigid obstacle's k
    on the same mesh, and at K = 1e4 is within 2e-4 of the rigid value. Every result is
    a stationary point of the spring quotient (certificate: residual, and the smallest
    eigenvalue of its pencil).
    """
    edges = (
        "simply_supported"
        if supports == "simply_supported"
        else {"left": "clamped", "right": "clamped"}
    )
    base = strip(3.0, 8, supports=edges)
    with solve(base) as analysis:
        free = analysis.result.buckling_coefficient_k
    with solve(structs.replace(base, obstacle=ObstacleSpec("all"))) as analysis:
        rigid = analysis.result.buckling_coefficient_k
        assert analysis.result.certificate.kkt
    ks = []
    for K in (1.0, 10.0, 100.0, 1e3, 1e4):
        with solve(
            structs.replace(base, obstacle=ObstacleSpec("all", foundation_stiffness=modulus(K)))
        ) as analysis:
            result = analysis.result
        assert result.method == "foundation"
        cert = result.certificate
        assert cert.kkt and cert.smallest_of_reduced, (K, cert)
        assert cert.relative_residual < 1e-6
        ks.append(result.buckling_coefficient_k)
    assert free < ks[0], (free, ks)
    assert all(x < y for x, y in itertools.pairwise(ks)), ks
    assert ks[-1] <= rigid * (1 + 1e-8), (ks, rigid)
    assert ks[-1] == pytest.approx(rigid, rel=2e-4)


def test_foundation_below_is_the_mirror_of_above():
    base = strip(3.0, 8, supports={"left": "clamped", "right": "clamped"})
    loads = []
    for side in ("above", "below"):
        zone = ObstacleSpec("all", foundation_stiffness=modulus(10.0), side=side)
        with solve(structs.replace(base, obstacle=zone)) as analysis:
            loads.append(analysis.result.critical_load_Pa)
            coordinates = analysis.result.contact_coordinates
            if side == "above":
                first = coordinates
    assert loads[1] == pytest.approx(loads[0], rel=1e-9)
    assert sorted(map(tuple, coordinates)) == sorted(map(tuple, first))


@pytest.mark.convergence
def test_tensionless_limit_tends_to_sixteen_thirds():
    """Loaded edges clamped, a/b = 3: K = 1e4 tends to the rigid obstacle, both to 16/3.

    36x12 and 72x24 cells: the foundation's k lies below the rigid obstacle's by the
    foundation's own (mesh-independent) compliance, measured 1.0e-4 and 2.3e-4; the rigid
    value converges to the thin long-plate limit 16/3 at rate 2 (error ratio about 4).
    """
    base = {ny: strip(3.0, ny, supports={"left": "clamped", "right": "clamped"}) for ny in (12, 24)}
    rigid, soft = [], []
    for spec in base.values():
        with solve(structs.replace(spec, obstacle=ObstacleSpec("all"))) as analysis:
            rigid.append(analysis.result.buckling_coefficient_k)
        zone = ObstacleSpec("all", foundation_stiffness=modulus(1e4))
        with solve(structs.replace(spec, obstacle=zone)) as analysis:
            assert analysis.result.certificate.kkt
            soft.append(analysis.result.buckling_coefficient_k)
    for s, r in zip(soft, rigid, strict=True):
        assert s <= r * (1 + 1e-8) and s == pytest.approx(r, rel=1e-3)
    errors = np.array(rigid) - 16 / 3
    assert errors[0] > errors[1] > 0
    assert 3.0 < errors[0] / errors[1] < 5.0, errors


def test_nonlinear_analysis_refuses_a_foundation():
    from unibuckle_fenicsx.nonlinear import solve_nonlinear

    spec = strip(3.0, 6, ObstacleSpec("all", foundation_stiffness=modulus(10.0)))
    with pytest.raises(ValueError, match=r"rigid obstacles only, not Winkler foundations"):
        solve_nonlinear(spec)


# -- stiff foundations: the rigid obstacle is the limit and the bound ---------------------
def _gap_to_rigid(spec, Ks):
    """The rigid obstacle's load, and each K's load and certificate, on one mesh."""
    with solve(spec) as analysis:
        rigid = analysis.result.critical_load_Pa
    b = min(spec.plate.length, spec.plate.width)
    D12 = spec.material.E * spec.plate.thickness**3 / 12.0  # the input check's D
    loads = []
    for K in Ks:
        zone = structs.replace(spec.obstacle, foundation_stiffness=K * math.pi**4 * D12 / b**4)
        with solve(structs.replace(spec, obstacle=zone)) as analysis:
            result = analysis.result
            assert result.method == "foundation" and result.certificate.kkt, (K, result)
            loads.append(result.critical_load_Pa)
    return rigid, loads


def test_a_thin_liner_on_concrete_is_answered_below_the_rigid_obstacle():
    """A 4 x 2 m, 1 mm steel liner on concrete, k_f = 1e11 N/m^3 (K = 9.4e8).

    Refused before (K above 1e8); past the refusal the spring-set iteration ended 1.8e-4
    above the rigid obstacle's load at K = 1e9, not KKT, where no foundation's load can
    exceed it (the rigid obstacle's mode presses no spring: its quotient is its load).
    Expected: the rigid obstacle's load on the same mesh, from below, within 1e-7 (the
    gap measured 1.1e-9).
    """
    spec = plate_case(
        "liner", length=4.0, width=2.0, thickness=1e-3, nx=16, ny=8,
        supports={"left": "clamped", "right": "clamped"},
        zone=ObstacleSpec("all", foundation_stiffness=1e11),
        material=Material(E=2.1e11, nu=0.3),
    )  # fmt: skip
    with solve(spec) as analysis:
        load = analysis.result.critical_load_Pa
        assert analysis.result.certificate.kkt
    with solve(structs.replace(spec, obstacle=ObstacleSpec("all"))) as analysis:
        rigid = analysis.result.critical_load_Pa
    assert rigid * (1 - 1e-7) <= load <= rigid * (1 + 1e-12), (load, rigid)


def test_a_stiff_foundation_tends_to_the_rigid_obstacle_as_one_over_K():
    """The paper's plate, zone omega_c1 (the mode presses it), 40 x 20 cells.

    K = 1e6, 1e9, 1e11: the load grows with K, stays below the rigid obstacle's load,
    and the gap falls as 1/K (the Winkler boundary layer below one cell: the springs of
    the touch-down nodes act as a penalty). Before, K > 1e8 was refused, and past the
    refusal, on zone omega_c2, K = 1e10 ended 1.1e-5 above the rigid obstacle's load,
    not KKT. Expected: the rigid obstacle's load and the rate 1/K.
    """
    rigid, loads = _gap_to_rigid(paper_case("c1", 40, 20), (1e6, 1e9, 1e11))
    assert all(x < y for x, y in itertools.pairwise(loads)), loads
    assert loads[-1] <= rigid * (1 + 1e-12), (loads, rigid)
    scaled = [(rigid - x) / rigid * K for x, K in zip(loads, (1e6, 1e9, 1e11), strict=True)]
    assert scaled[0] == pytest.approx(scaled[1], rel=0.05), scaled
    assert scaled[1] == pytest.approx(scaled[2], rel=0.1), scaled
