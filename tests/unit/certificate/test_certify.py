r"""The global-optimality certificate (copositivity of A - lambda B on the cone).

Soundness is checked against independent exhaustive minima (dense numpy over all 2^i
contact sets, ``tests/support/exhaustive.py``): a verified lower bound may never
exceed the true critical load, and a KKT point that is not the global minimum may never
be proven. Completeness where the theory says so: below the second pencil eigenvalue the
rank-2 certificate exists (README, "Proving the global minimum"), so the paper's cases are
proven.
"""

from __future__ import annotations

import json
from dataclasses import replace

from mpi4py import MPI

import numpy as np
import pytest
from msgspec import structs

from support.exhaustive import exhaustive_minimum
from unibuckle_fenicsx.algorithms.active_set import solve_active_set
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.certificate.certify import certify, reduced_inertia
from unibuckle_fenicsx.certificate.copositivity import copositivity_bound
from unibuckle_fenicsx.certificate.shifted import ShiftedMatrix
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.spec import (
    EdgeSpec,
    Material,
    MeshSpec,
    ObstacleSpec,
    PlateSpec,
    ProblemSpec,
    SolverSpec,
)
from unibuckle_fenicsx.spec.cases import paper_case
from unibuckle_fenicsx.tolerances import PROOF_GAP

serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense reference is serial")


@pytest.mark.parametrize("case", ["c1", "c2", "c3"])
def test_paper_cases_are_proven(case):
    """The paper's mesh: proven by the rank-2 certificate, gap at most 1e-6 (one LDL^T)."""
    with solve(paper_case(case, 20, 20)) as analysis:
        cert = analysis.certificate
        assert cert is not None and cert.kkt
        assert cert.global_optimum_proven, cert
        assert cert.proven_by == "rank2-spn"
        assert cert.relative_gap <= PROOF_GAP
        assert cert.lower_bound <= analysis.result.critical_load_Pa <= cert.upper_bound
        assert cert.copositivity.factorisations == 1
        assert cert.smallest_of_reduced is True  # checked on every route, proven or not


@pytest.mark.slow
@serial
def test_lower_bound_never_exceeds_the_exhaustive_minimum(active_specs):
    """50 random small problems: the verified bound <= the dense exhaustive minimum.

    And every proof is right: a proven load is the exhaustive minimum (to 1e-8).
    """
    family = active_specs
    proven = 0
    for spec in family:
        with build_problem(spec, MPI.COMM_SELF) as problem:
            sol = solve_active_set(problem, bound_budget=0)
            cert = certify(problem, sol)
            best, _, _ = exhaustive_minimum(problem)
        assert cert.lower_bound <= best * (1 + 1e-12), (spec.name, cert.lower_bound, best)
        if cert.global_optimum_proven:
            proven += 1
            assert sol.load == pytest.approx(best, rel=1e-8), spec.name
    # random29 stops at a non-global KKT point above the second pencil eigenvalue; the
    # others lie below it and are proven (or need the SDP route).
    assert proven >= 45, proven


@serial
def test_a_wrong_kkt_point_is_never_proven(active_specs):
    """random29: every seed stops at the KKT point 23.646 MPa, the minimum is 23.142 MPa.

    Its certificate is not proven, its lower bound stays below the minimum, and a
    refuting mode, if the low-rank route finds one, is admissible and lies between the
    minimum and the returned load.

    Also a claimed load slightly above the true minimum (the true KKT point with its load
    raised by 1e-6 and 1e-4 relative) is never proven.
    """
    family = active_specs
    spec = next(s for s in family if s.name == "random29")
    with build_problem(spec, MPI.COMM_SELF) as problem:
        sol = solve_active_set(problem, bound_budget=0)
        best, _, _ = exhaustive_minimum(problem)
        assert sol.load > best * (1 + 1e-3)  # the iteration misses the global minimum
        cert = certify(problem, sol)
        assert not cert.global_optimum_proven and cert.lower_bound <= best
        assert cert.status != "proven"
        if cert.refuting_mode is not None:  # the low-rank route met a lower admissible mode
            assert cert.refuting_mode.feasible
            assert best * (1 - 1e-8) <= cert.refuting_mode.load < sol.load
            assert cert.upper_bound == cert.refuting_mode.load
        exact = solve_active_set(problem, bound_budget=2**problem.num_constrained)
        assert exact.load == pytest.approx(best, rel=1e-8)
        for excess in (1e-6, 1e-4):
            claimed = replace(exact.candidate, load=exact.load * (1 + excess))
            bound = copositivity_bound(problem, claimed)
            assert bound.value is None or bound.value <= best * (1 + 1e-12), (excess, bound)


def _long_ssss(t: float, nx: int, ny: int) -> ProblemSpec:
    """a/b = 3, all edges simply supported, uniaxial compression, whole-plate obstacle."""
    edges = (
        EdgeSpec("left", normal_stress=-1.0),
        EdgeSpec("right", normal_stress=-1.0),
        EdgeSpec("bottom"),
        EdgeSpec("top"),
    )
    return ProblemSpec(
        name="long",
        plate=PlateSpec(corners=((0.0, 0.0), (0.3, 0.1)), thickness=t, edges=edges),
        material=Material(E=1.0e9, nu=0.3),
        mesh=MeshSpec(nx, ny),
        obstacle=ObstacleSpec(zone="all"),
        solver=SolverSpec(method="active-set"),
    )


def test_two_eigenvalues_below_needs_the_sdp_route():
    """a/b = 3 with the whole-plate obstacle: two pencil eigenvalues lie below lambda_c.

    The rank-2 certificate cannot apply (K has two negative eigenvalues); on a 12 x 4 mesh
    (i = 33) the PSD + nonnegative SDP proves the active set's load.
    """
    with solve(_long_ssss(0.006, 12, 4)) as analysis:
        cert = analysis.certificate
        assert cert.copositivity is not None
        inertia = analysis.certificate.copositivity
        assert cert.global_optimum_proven, cert
        assert cert.proven_by in ("sdp-spn", "sdp-sectors"), cert
        assert cert.relative_gap <= PROOF_GAP
        assert inertia.method == cert.proven_by


def test_no_certify_skips_the_proof():
    """Unproven, the summary prints the verified bracket: [free load, returned load].

    Interlacing makes the free load a lower bound, the returned mode's load (admissible)
    an upper one; the screen says so, not only the JSON.
    """
    spec = paper_case("c1", 20, 20).with_solver(certify=False)
    with solve(spec) as analysis:
        cert = analysis.certificate
        result = analysis.result
    assert cert.kkt and not cert.global_optimum_proven
    assert cert.copositivity is None and cert.smallest_of_reduced is None
    assert any("skipped" in note for note in cert.notes)
    assert cert.lower_bound == pytest.approx(result.free_load_Pa)
    line = result.summary().splitlines()[1]
    assert line == (
        f"  not proven: the critical load lies between {result.free_load_Pa:.6e} Pa "
        "(verified lower bound, the free plate's, by interlacing) and "
        f"{result.critical_load_Pa:.6e} Pa"
    ), result.summary()


def test_inactive_obstacle_is_proven():
    """A zone where the free mode is one-signed: lambda_c = lambda_free, proven.

    The free mode is admissible, so its load is an upper bound, and interlacing makes it
    a lower bound too.
    """
    spec = structs.replace(
        paper_case("c1", 20, 20), obstacle=ObstacleSpec(zone=((0.02, 0.08), (-0.03, 0.03)))
    )
    with solve(spec) as analysis:
        cert = analysis.certificate
        result = analysis.result
    assert result.critical_load_Pa == pytest.approx(result.free_load_Pa, rel=1e-9)
    assert cert.global_optimum_proven
    assert cert.proven_by in ("interlacing", "psd", "enumeration", "lattice")
    # No contact node: the largest contact force has no finite value, null in the JSON
    # (a number or null, never a string: results.md, "The JSON file").
    assert result.contact_nodes == 0 and cert.max_contact_force == -np.inf
    data = json.loads(json.dumps(result.as_dict(), allow_nan=False))
    assert data["certificate"]["max_contact_force"] is None


@pytest.mark.parametrize("zone", [((-0.02, 0.06), (-0.03, 0.03)), ((-0.05, 0.03), (-0.05, 0.02))])
def test_off_centre_zone_is_proven_by_the_search(zone):
    """No mirror symmetry: w- comes from the search in the other nappe."""
    spec = structs.replace(paper_case("c1", 20, 20), obstacle=ObstacleSpec(zone=zone))
    with solve(spec.with_solver(method="active-set")) as analysis:
        cert = analysis.certificate
    assert cert.global_optimum_proven, cert
    assert cert.proven_by == "rank2-spn"
    assert "mirror" not in cert.copositivity.margins.w_minus
    assert np.isfinite(cert.copositivity.margins.beta)


def test_reduced_inertia_reuses_the_copositivity_factorisation():
    """The reduced pencil factorised in the copositivity attempt's matrix: a fresh one's inertia.

    The certificate's smallest-eigenvalue check reuses the attempt's symbolic analysis.
    Reference: the same inertia from an independent LDLᵀ of A_Z - sigma B_Z
    (``reduced_inertia`` without a matrix), at shifts below and above eigenvalues of the
    reduced pencil.
    """
    problem = build_problem(paper_case("c1", 10, 10), MPI.COMM_WORLD)
    try:
        load = problem.solve_free().load
        assert problem.contact is not None
        active = np.arange(0, problem.contact.size, 2)
        matrix = ShiftedMatrix(problem.model.A, problem.model.B)
        try:
            matrix.factor(1.1 * load)  # as the copositivity attempt does first
            shared, fresh = [], []
            for sigma in (0.9 * load, 1.5 * load, 4.0 * load):
                shared.append(reduced_inertia(problem, active, sigma, matrix))
                fresh.append(reduced_inertia(problem, active, sigma))
        finally:
            matrix.destroy()
    finally:
        problem.destroy()
    assert shared == fresh
    negatives = [neg for neg, _, _ in fresh]
    assert negatives[0] == 0 and negatives[-1] > 0, negatives  # the test says something


def test_a_bound_verified_at_the_proof_gap_proves_the_optimum():
    """A lower bound verified at lambda (1 - PROOF_GAP) proves the optimum, whatever its last bit.

    README, "Proving the global minimum": the rank-2 copositivity bound is verified at
    lambda (1 - delta); at delta = PROOF_GAP the gap (upper - lower) / upper is PROOF_GAP
    up to rounding, on either side of it (on this plate 1e-6 (1 - 9e-12) in one run,
    1e-6 (1 + 7e-11) in another). A thin two-sided plate (obstacles above the left part
    and below the right part) whose bound closes there: "proven" either way, not
    "bracketed" by the last bit of the gap.
    """
    from unibuckle_fenicsx.spec import problem_from_dict

    spec = problem_from_dict(
        {
            "name": "two-sided",
            "plate": {"corners": [[0, 0], [0.15, 0.1]], "thickness": 1e-4},
            "material": {"E": 2.1e11, "nu": 0.3},
            "edges": {
                "left": {"support": "simply_supported", "normal_stress": -1.0},
                "right": {"support": "clamped", "normal_stress": -1.0},
                "bottom": {"support": "simply_supported"},
                "top": {"support": "simply_supported"},
            },
            "mesh": {"nx": 30, "ny": 20},
            "obstacles": [
                {"zone": [[0.0, 0.0675], [0.0, 0.1]], "side": "above"},
                {"zone": [[0.0825, 0.15], [0.0, 0.1]], "side": "below"},
            ],
        }
    )
    with solve(spec, MPI.COMM_SELF) as analysis:
        cert = analysis.result.certificate
    assert cert.proven_by == "rank2-spn"
    assert cert.relative_gap == pytest.approx(PROOF_GAP, rel=1e-6)
    assert cert.status == "proven" and cert.global_optimum_proven
