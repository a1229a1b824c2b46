"""The paper's enumeration (section 5.3) against an independent dense brute force.

Expected values come from a dense numpy computation over *all* 2^i contact sets, written
here independently of SLEPc, ``UnilateralProblem.evaluate`` and the enumeration module:
Cholesky of the reduced A, symmetric eigensolve of L^-1 B L^-T, feasibility of the
largest-mu eigenvector in both orientations. Tolerance on loads 1e-9 relative: the
SLEPc pairs are converged to eps_tol = 1e-10 (relative residual, which bounds the
relative eigenvalue error of this symmetric-definite pencil) and LAPACK is accurate to
~1e-13 here.
"""

from __future__ import annotations

import itertools
import json
import math
import subprocess
import sys
from pathlib import Path

from mpi4py import MPI

import numpy as np
import pytest
from msgspec.structs import replace

from support.paths import MPI_SCRIPTS
from support.processes import run_mpi
from unibuckle_fenicsx.algorithms.enumeration import enumerate_contact_sets
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.certificate.certify import certify
from unibuckle_fenicsx.errors import EmptyZoneError
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.problem import UnilateralProblem
from unibuckle_fenicsx.spec import ObstacleSpec, ProblemSpec
from unibuckle_fenicsx.spec.cases import paper_case
from unibuckle_fenicsx.tolerances import LOAD_TIE_RTOL

RTOL = 1e-9
BIG = 10**12  # max_candidates that never refuses

# Small problems (i <= 10): the paper's zones on coarse meshes, an off-centre zone and a
# zone touching the right and bottom edges (its edge nodes are fixed, not counted).
OFF_CENTRE = ObstacleSpec(zone=((0.02, 0.08), (-0.03, 0.03)))
AT_EDGE = ObstacleSpec(zone=((0.04, 0.1), (-0.05, 0.0)))
CASES = {
    "c1-8x4": (paper_case("c1", 8, 4), 9),
    "c2-8x4": (paper_case("c2", 8, 4), 3),
    "c2-8x6": (paper_case("c2", 8, 6), 9),
    "c3-6x3": (paper_case("c3", 6, 3), 10),
    "off-centre-8x4": (replace(paper_case("c1", 8, 4), name="off", obstacle=OFF_CENTRE), 9),
    "at-edge-12x6": (replace(paper_case("c1", 12, 6), name="edge", obstacle=AT_EDGE), 9),
}


def _pick(entries: list[tuple[float, tuple[int, ...]]]) -> tuple[float, tuple[int, ...]]:
    """Smallest load; among loads within LOAD_TIE_RTOL of it, the lexicographically first set."""
    best = min(load for load, _ in entries)
    return min(((s, load) for load, s in entries if load <= best * (1 + LOAD_TIE_RTOL)))[::-1]


def dense_brute_force(problem: UnilateralProblem) -> dict:
    """Load and feasibility of every subset of I by dense linear algebra (serial).

    B acts on w only, so the rotations are condensed out once: S = A_ww - A_wt A_tt^-1
    A_tw on the free w-DOFs, and removing a contact set deletes rows and columns of S.
    """
    assert problem.contact is not None
    A = problem.model.A.convert("dense").getDenseArray().copy()
    B = problem.model.B.convert("dense").getDenseArray().copy()
    i, n = problem.contact.size, A.shape[0]
    w = np.setdiff1d(problem.model.w_dofs, problem.model.bc_dofs)
    t = np.setdiff1d(np.setdiff1d(np.arange(n), problem.model.w_dofs), problem.model.bc_dofs)
    S = A[np.ix_(w, w)] - A[np.ix_(w, t)] @ np.linalg.solve(A[np.ix_(t, t)], A[np.ix_(t, w)])
    Bw = B[np.ix_(w, w)]
    rows = [problem.contact.removed_rows(np.array([k]))[0] for k in range(i)]
    node = np.searchsorted(w, rows)  # position of each constrained node in w
    assert np.array_equal(w[node], rows)
    by_p: list[list[tuple[float, tuple[int, ...], bool]]] = []
    for p in range(i + 1):
        level = []
        for Z in itertools.combinations(range(i), p):
            keep = np.setdiff1d(np.arange(w.size), node[list(Z)])
            if keep.size == 0:
                level.append((math.inf, Z, False))
                continue
            L = np.linalg.cholesky(S[np.ix_(keep, keep)])
            C = np.linalg.solve(L, np.linalg.solve(L, Bw[np.ix_(keep, keep)]).T)
            mu, V = np.linalg.eigh(C)
            if mu[-1] <= 0.0:
                level.append((math.inf, Z, False))
                continue
            x = np.zeros(w.size)
            x[keep] = np.linalg.solve(L.T, V[:, -1])
            x /= np.abs(x).max()
            v = x[node[np.setdiff1d(np.arange(i), Z)]]
            feasible = v.size == 0 or v.max() <= problem.tau or -v.min() <= problem.tau
            level.append((1.0 / mu[-1], Z, bool(feasible)))
        by_p.append(level)
    feasible = [(load, Z) for level in by_p for load, Z, ok in level if ok]
    per_p = [[(load, Z) for load, Z, ok in level if ok] for level in by_p]
    p_star = next(p for p, f in enumerate(per_p) if f)
    best_by_p = [_pick(f)[0] if f else None for f in per_p]
    known = [x for x in best_by_p if x is not None]
    return {
        "optimum": _pick(feasible),
        "p_star": p_star,
        "paper": _pick(per_p[p_star]),
        "monotone": all(a <= b * (1 + LOAD_TIE_RTOL) for a, b in itertools.combinations(known, 2)),
        "all_removed": by_p[i][0][0],
    }


@pytest.fixture(scope="module")
def solved() -> dict:
    """Each case: problem results of the three stopping rules and the dense reference."""
    out = {}
    for name, (spec, i) in CASES.items():
        problem = build_problem(spec, MPI.COMM_SELF)
        assert problem.num_constrained == i
        free = problem.solve_free().load
        runs = {}
        for mode in ("paper", "proven", "complete"):
            sol = enumerate_contact_sets(
                problem,
                complete=mode == "complete",
                until_proven=mode == "proven",
                max_candidates=BIG,
            )
            cert = certify(problem, sol)
            runs[mode] = (sol, cert)
        out[name] = (free, runs, dense_brute_force(problem))
        problem.destroy()
    return out


@pytest.mark.parametrize("name", list(CASES))
def test_exact_modes_match_brute_force(solved, name):
    """Modes complete and until_proven give the minimum over all 2^i feasible sets, certified."""
    _, runs, ref = solved[name]
    load_ref, set_ref = ref["optimum"]
    for mode in ("proven", "complete"):
        sol, cert = runs[mode]
        assert sol.load == pytest.approx(load_ref, rel=RTOL), mode
        assert tuple(sol.active) == set_ref, mode
        assert sol.global_optimum_proven and sol.lower_bound == pytest.approx(sol.load, rel=RTOL)
        assert cert.kkt, (mode, cert)
    assert runs["complete"][0].details.monotone is ref["monotone"]
    assert runs["proven"][0].eigensolves <= runs["complete"][0].eigensolves


@pytest.mark.parametrize("name", list(CASES))
def test_paper_rule_and_its_bracket(solved, name):
    """The paper's rule stops at the dense p*, picks the best set there; bound is valid.

    When it claims optimality it matches the brute force exactly (set and load).
    """
    _, runs, ref = solved[name]
    sol, cert = runs["paper"]
    load_ref, set_ref = ref["optimum"]
    assert sol.p_star == ref["p_star"]
    assert sol.load == pytest.approx(ref["paper"][0], rel=RTOL)
    assert tuple(sol.active) == ref["paper"][1]
    assert cert.feasible
    assert sol.lower_bound <= load_ref * (1 + RTOL)
    assert sol.load >= load_ref * (1 - RTOL)
    if sol.global_optimum_proven:
        assert tuple(sol.active) == set_ref
        assert sol.load == pytest.approx(load_ref, rel=RTOL)
        assert cert.kkt, cert
    if ref["monotone"]:
        # The paper's observation holds here, so its rule finds the optimum.
        assert tuple(sol.active) == set_ref


@pytest.mark.parametrize("name", list(CASES))
def test_interlacing_bracket(solved, name):
    """lambda_free <= lambda_unilateral <= lambda(all of I removed) (interlacing)."""
    free, runs, ref = solved[name]
    for sol, _ in runs.values():
        assert free * (1 - RTOL) <= sol.lower_bound <= sol.load <= ref["all_removed"] * (1 + RTOL)


def test_paper_rule_not_exact_on_c1_8x4(solved):
    """Counterexample to the paper's monotonicity (dense: lambda(2) > lambda(3)).

    c1 on 8 x 4: no single node gives a feasible mode; the best pair (two opposite corners
    of the zone) gives 17.44 MPa, but the column x = -0.025 (3 nodes) gives 14.94 MPa.
    The paper's rule returns the former and must say it is not proven.
    """
    _, runs, ref = solved["c1-8x4"]
    sol, _ = runs["paper"]
    assert not ref["monotone"]
    assert sol.p_star == 2 and not sol.global_optimum_proven
    assert sol.load > 1.15 * ref["optimum"][0]
    assert runs["complete"][0].details.monotone is False
    assert list(runs["proven"][0].active) == [0, 3, 6]


def test_refuses_above_max_candidates():
    """Zone c1 on 12 x 6 has i = 25: 2^25 candidate sets, refused before any solve."""
    problem = build_problem(paper_case("c1", 12, 6), MPI.COMM_SELF)
    assert problem.num_constrained == 25
    solves = problem.eigensolver.solves
    with pytest.raises(ValueError, match=r"33554432.*i = 25.*active-set"):
        enumerate_contact_sets(problem)
    with pytest.raises(ValueError, match="max_candidates"):
        enumerate_contact_sets(problem, max_candidates=0)
    assert problem.eigensolver.solves == solves
    problem.destroy()


def test_needs_an_obstacle():
    problem = build_problem(paper_case("free", 4, 2), MPI.COMM_SELF)
    with pytest.raises(ValueError, match="obstacle"):
        enumerate_contact_sets(problem)
    problem.destroy()


@pytest.mark.parametrize(
    ("zone", "message"),
    [
        (((0.01, 0.02), (0.01, 0.02)), r"\[0.01, 0.02\] x \[0.01, 0.02\] holds no free mesh node"),
        (((0.1, 0.1), (-0.05, 0.05)), r"5 zone nodes are held by supports: edges or bilateral"),
    ],
)
def test_empty_zone(zone, message):
    """A zone between nodes (8 x 4: spacing 0.025 m), or on a supported edge only."""
    spec: ProblemSpec = replace(paper_case("c1", 8, 4), obstacle=ObstacleSpec(zone=zone))
    with pytest.raises(EmptyZoneError, match=message):
        build_problem(spec, MPI.COMM_SELF)


@pytest.mark.mpi
def test_candidate_parallel_matches_serial():
    """Under mpiexec -n 2 the candidate-parallel runs agree with the serial one.

    (The mesh-distributed enumeration, ``--distributed``, agrees too but is slow on a
    loaded 2-core machine: one collective eigen solve per candidate.)
    """
    cases = {"c1:8:4:1": ("c1", 8, 4, True), "c3:6:3:0": ("c3", 6, 3, False)}
    out = json.loads(
        run_mpi(MPI_SCRIPTS / "enum_candidate_parallel.py", 2, *cases).splitlines()[-1]
    )
    for key, (case, nx, ny, complete) in cases.items():
        spec = paper_case(case, nx, ny).with_solver(method="enumerate", complete=complete)
        with solve(spec, MPI.COMM_SELF) as analysis:
            serial = analysis.result
        for mode, par in out[key].items():
            assert par["active"] == serial.contact_indices, (key, mode)
            assert par["same_active_on_ranks"] and par["mode_spread"] < 1e-10, (key, mode)
            assert par["load"] == pytest.approx(serial.critical_load_Pa, rel=1e-10), (key, mode)
            assert par["p_star"] == serial.p_star
        assert out[key]["candidate"]["ranks"] == 2
        # Each candidate solved once over both ranks (the winner's mode is broadcast).
        assert out[key]["candidate"]["eigensolves"] == serial.eigensolves


def test_cli_enumerate_json(tmp_path: Path):
    """`unibuckle solve --case c2 --nx 8 --ny 4 --method enumerate --json out.json`."""
    out = tmp_path / "out.json"
    exe = Path(sys.executable).parent / "unibuckle"
    cmd = [str(exe), "solve", "--case", "c2", "--nx", "8", "--ny", "4"]
    cmd += ["--method", "enumerate", "--json", str(out)]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    # c2 on 8 x 4: i = 3 nodes (x = -0.025, 0, 0.025 on y = 0); the dense brute force
    # (test above) gives p* = 1, Z = {node 0}, proven (monotone case).
    assert data["constrained_nodes"] == 3
    assert data["contact_nodes"] == 1 and data["p_star"] == 1
    cert = data["certificate"]
    assert cert["feasible"] and cert["global_optimum_proven"]
    assert cert["max_contact_force"] <= cert["tolerance"]
    assert cert["relative_residual"] < 1e-8
    assert data["critical_load_Pa"] > data["free_load_Pa"]
    assert data["contact_coordinates"] == [[pytest.approx(-0.025), pytest.approx(0.0, abs=1e-12)]]
