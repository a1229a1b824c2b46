r"""The core as an obstacle: the change of basis, and the unilateral critical state of a section.

- The change of basis T (:mod:`unibuckle_fenicsx.model.shell.core`) is orthogonal on a box,
  leaves the pencil's eigenvalues unchanged (congruence), and its constrained DOFs are the
  normal displacements :math:`n_{in}\cdot u` (computed here from the coordinates).
- Dense reference: on sections small enough to enumerate every contact set (2^12 and 2^8),
  scipy solves each reduced pencil in the *global* basis (the constraints
  :math:`n_{in}\cdot u = 0` by a null-space basis, independent of T) and keeps the smallest
  load whose mode stays on the admissible side (the discrete critical state, paper,
  Lemma 5.1); the package's active-set method on the rotated pencil must find it.
"""

from __future__ import annotations

import itertools
import math

from mpi4py import MPI

import numpy as np
import pytest
import scipy.linalg

from unibuckle_fenicsx.algorithms.active_set import solve_active_set
from unibuckle_fenicsx.algorithms.section_levels import solve_levels
from unibuckle_fenicsx.model.shell.section import SectionParameters, build_section

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense references are serial")


def _parameters(shape, **changes):
    base = {
        "box": {"width": 0.2, "depth": 0.1, "thickness": 0.002, "length": 0.2, "mesh_size": 0.1},
        "tube": {"diameter": 0.2, "thickness": 0.002, "length": 0.2, "mesh_size": 0.1},
    }[shape]
    return SectionParameters(
        shape, E=2.1e11, nu=0.3, core=True, **{"ends": "simply_supported", **base, **changes}
    )


def _normal_rows(section):
    """(i, n) rows of the constraints n_in . u <= 0 from the node coordinates alone."""
    V = section.model.W
    X = V.tabulate_dof_coordinates()
    p = section.parameters
    rows, where = [], []
    for k, (x, y, z) in enumerate(X):
        if x < 1e-9 or x > p.length - 1e-9:
            continue  # the ends: held by the supports
        normals = []
        if p.shape == "tube":
            normals.append(np.array([0.0, -y, -z]) / math.hypot(y, z))
        else:
            if abs(abs(y) - 0.5 * p.width) < 1e-9:
                normals.append(np.array([0.0, -np.sign(y), 0.0]))
            if abs(abs(z) - 0.5 * p.depth) < 1e-9:
                normals.append(np.array([0.0, 0.0, -np.sign(z)]))
        for n in normals:
            row = np.zeros(X.shape[0] * 6)
            row[6 * k : 6 * k + 3] = n
            rows.append(row)
            where.append((x, y, z, *n))
    return np.array(rows), np.array(where)


def _dense_critical(A, B, C, tau=1e-8):
    """Smallest load over all contact sets whose reduced first mode is admissible."""
    best, best_set = math.inf, None
    i = C.shape[0]
    for size in range(i + 1):
        for Z in itertools.combinations(range(i), size):
            N = scipy.linalg.null_space(C[list(Z)]) if Z else np.eye(A.shape[0])
            mu, Y = scipy.linalg.eigh(N.T @ B @ N, N.T @ A @ N)  # A SPD: swapped pencil
            if mu[-1] <= 0.0:
                continue
            load = 1.0 / mu[-1]
            u = N @ Y[:, -1]
            values = C @ u
            scale = np.abs(values).max() or 1.0
            free = np.setdiff1d(np.arange(i), Z)
            for sign in (1.0, -1.0):
                if np.all(sign * values[free] <= tau * scale) and load < best:
                    best, best_set = load, Z
    return best, best_set


@pytest.mark.parametrize("shape", ["box", "tube"])
def test_change_of_basis_is_a_congruence(shape):
    params = _parameters(shape, mesh_size=0.05, length=0.2)
    with build_section(params, MPI.COMM_SELF) as sec:
        T = sec.problem.pencil.T
        Td = T.convert("dense").getDenseArray()
        if shape == "box":
            assert np.abs(Td.T @ Td - np.eye(Td.shape[0])).max() < 1e-15
        C, _ = _normal_rows(sec)
        u = np.random.default_rng(1).standard_normal(Td.shape[0])
        constrained = np.linalg.solve(Td, u)[sec.rows]  # u' = T^-1 u at the rows
        np.testing.assert_allclose(np.sort(constrained), np.sort(C @ u), atol=1e-12)
        A, B = (m.convert("dense").getDenseArray() for m in (sec.model.A, sec.model.B))
        Ar, Br = (
            m.convert("dense").getDenseArray() for m in (sec.problem.pencil.A, sec.problem.pencil.B)
        )
        lam = 1.0 / scipy.linalg.eigh(B, A, eigvals_only=True)[-1]
        lam_rotated = 1.0 / scipy.linalg.eigh(Br, Ar, eigvals_only=True)[-1]
        assert lam_rotated == pytest.approx(lam, rel=1e-10)


@pytest.mark.parametrize(
    ("shape", "span"), [("box", (0.05, 0.15)), ("box", None), ("tube", (0.05, 0.15))]
)
def test_change_of_basis_columns_are_the_normals_from_the_coordinates(shape, span):
    # Each constrained direction's column of T is its normal n_in at its node's
    # translations (T is orthogonal on these sections: its inverse's row is the column),
    # the normals computed here from the coordinates (_normal_rows); every other column
    # of T is a unit vector, the node's other columns orthonormal to the normals: the
    # CSR that change_of_basis assembles, checked entry by entry, with the core over
    # part of the length (nodes outside it keep the identity).
    params = _parameters(shape, mesh_size=0.025, length=0.2, core_span=span)
    with build_section(params, MPI.COMM_SELF) as sec:
        Td = sec.problem.pencil.T.convert("dense").getDenseArray()
        np.testing.assert_allclose(Td.T @ Td, np.eye(Td.shape[0]), atol=1e-14)
        C, where = _normal_rows(sec)
        x = where[:, 0]
        inside = np.ones(x.size, dtype=bool) if span is None else (x > span[0] - 1e-9)
        if span is not None:
            inside &= x < span[1] + 1e-9
        C = C[inside]
        rows = sec.rows  # the constrained directions' columns (the new basis' DOFs)
        assert rows.size == C.shape[0] > 0
        columns = Td[:, rows].T
        # The same set of columns as the normal rows (each matched to its own row).
        for column in columns:
            assert np.abs(C - column).max(axis=1).min() < 1e-14
        touched = np.unique(np.concatenate([6 * (r // 6) + np.arange(3) for r in rows]))
        others = np.setdiff1d(np.arange(Td.shape[0]), touched)
        np.testing.assert_array_equal(Td[np.ix_(others, others)], np.eye(others.size))
        assert not Td[np.ix_(others, touched)].any() and not Td[np.ix_(touched, others)].any()


@pytest.mark.parametrize(
    ("shape", "changes"), [("box", {}), ("tube", {"mesh_size": 0.08, "length": 0.16})]
)
def test_core_matches_dense_enumeration(shape, changes):
    params = _parameters(shape, **changes)
    with build_section(params, MPI.COMM_SELF) as sec:
        C, _ = _normal_rows(sec)
        assert C.shape[0] == sec.constraints.size <= 12
        A, B = (m.convert("dense").getDenseArray() for m in (sec.model.A, sec.model.B))
        expected, _ = _dense_critical(A, B, C)
        solution = solve_active_set(sec.problem, multilevel=False)
        assert solution.candidate.kkt
        free = sec.problem.solve_free().load
        assert free < expected  # the core is active on these sections
        assert solution.load == pytest.approx(expected, rel=1e-8)
    # The sections' routes on the section itself: the seeds of levels.SEEDS, and the
    # interior-point chain (its contact set read off the barrier problem, the answer the
    # reduced pencil's exact eigenpair).
    for route in ("active-set", "interior-point"):
        finest, seeded = solve_levels(params, levels=0, comm=MPI.COMM_SELF, route=route)
        with finest:
            assert seeded.candidate.kkt
            assert seeded.load == pytest.approx(expected, rel=1e-8)


def test_interior_point_over_two_sections_matches_the_active_set():
    # The nested chain: barrier Newton on the box at twice the cell size, its mode carried
    # to the finer section (SectionProlongation), polished there. Reference: the plate's
    # active set with all its seeds on the finer section (an independent algorithm).
    params = _parameters("box", mesh_size=0.05)
    with build_section(params, MPI.COMM_SELF) as sec:
        reference = solve_active_set(sec.problem, multilevel=False)
        assert reference.candidate.kkt
        assert sec.problem.solve_free().load < reference.load  # the core is active
    finest, solution = solve_levels(params, levels=1, comm=MPI.COMM_SELF, route="interior-point")
    with finest:
        assert solution.method == "interior-point (section levels)"
        assert len(solution.details.levels) == 2
        assert solution.details.levels[-1].constrained_nodes == finest.constraints.size
        assert solution.candidate.kkt
        assert solution.load == pytest.approx(reference.load, rel=1e-8)


def test_the_plates_other_seeds_run_only_when_the_sections_reach_no_kkt_point():
    # The rule of solve_active_set's more_seeds, on the small box of the dense reference.
    from unibuckle_fenicsx.algorithms.section_levels import MORE_SEEDS, SEEDS
    from unibuckle_fenicsx.errors import InputError

    with build_section(_parameters("box"), MPI.COMM_SELF) as sec:
        problem = sec.problem
        found = solve_active_set(
            problem, multilevel=False, bound_budget=0, seeds=SEEDS, more_seeds=MORE_SEEDS
        )
        runs = found.details.runs
        assert [r.seed for r in runs] == list(SEEDS)
        assert any(r.status == "kkt" for r in runs)
        # One greedy step adds one direction: no KKT point, so "all" runs after it.
        again = solve_active_set(
            problem,
            multilevel=False,
            bound_budget=0,
            max_iterations=1,
            seeds=("greedy+",),
            more_seeds=("all",),
        )
        assert again.details.runs[0].status == "max_iterations"
        assert [r.seed for r in again.details.runs][:2] == ["greedy+", "all"]
        for bad in ({"seeds": ()}, {"seeds": ("nope",)}, {"more_seeds": ("free+",)}):
            with pytest.raises(InputError, match="seeds"):
                solve_active_set(problem, multilevel=False, **bad)


def test_section_figure_is_written(tmp_path):
    pytest.importorskip("pyvista")
    from unibuckle_fenicsx.model.shell.section import figure_data
    from unibuckle_fenicsx.viz.section import plot_section_mode_3d

    with build_section(_parameters("box"), MPI.COMM_SELF) as sec:
        solution = solve_active_set(sec.problem, multilevel=False)
        data = figure_data(sec, solution.candidate)
        assert len(data.pressing) + len(data.touching) == len(solution.active)
        assert np.abs(data.displacement).max() == pytest.approx(1.0)
        path = plot_section_mode_3d(data, tmp_path / "box.png", title="box")
    assert path.stat().st_size > 10_000


def test_core_over_part_of_the_length():
    """Fewer constrained directions, a wider cone: free <= part of the length <= whole length."""
    loads = []
    for span in (None, (0.0, 0.1)):
        params = _parameters("box", mesh_size=0.05, length=0.2, core_span=span)
        with build_section(params, MPI.COMM_SELF) as sec:
            x = sec.constraints.coordinates[:, 0]
            assert (x.max() <= 0.1 + 1e-12) if span else (x.max() > 0.1)
            loads.append(solve_active_set(sec.problem, multilevel=False).load)
            free = sec.problem.solve_free().load
    whole, part = loads
    assert free <= part * (1 + 1e-9) and part <= whole * (1 + 1e-9), (free, part, whole)
    assert part < whole  # the buckle moves to the uncovered half


@pytest.mark.parametrize(
    ("shape", "changes"),
    [
        ("box", {"mesh_size": 0.05}),
        ("tube", {"mesh_size": 0.03}),
        ("box", {"width": 0.3}),
        ("box", {"mesh_size": 0.04, "corner_cell": 0.01}),
    ],
)
def test_the_dofs_auto_routes_by_are_the_sections(shape, changes):
    # "auto" decides before any mesh is made: its estimate must be the built section's DOFs.
    from unibuckle_fenicsx.algorithms.section_levels import estimated_dofs

    params = _parameters(shape, **changes)
    with build_section(params, MPI.COMM_SELF) as sec:
        assert estimated_dofs(params) == sec.model.num_dofs


def test_a_route_is_one_of_the_routes():
    from unibuckle_fenicsx.errors import InputError

    with pytest.raises(InputError, match="route must be one of"):
        solve_levels(_parameters("box"), levels=0, comm=MPI.COMM_SELF, route="simplex")


def test_a_coarser_section_without_core_nodes_ends_the_added_levels():
    # The core over 0.31..0.34 m holds the 25 mm cells' nodes at 0.325 m, none of the
    # 50 mm cells' (0.30, 0.35): the interior point's added level is dropped, a level
    # the caller asked for is refused naming mesh.levels.
    from unibuckle_fenicsx.algorithms.section_levels import interior_levels
    from unibuckle_fenicsx.errors import InputError

    params = _parameters(
        "box", width=0.2, depth=0.2, length=0.6, mesh_size=0.025, core_span=(0.31, 0.34)
    )
    assert interior_levels(params, 0) >= 1
    finest, solution = solve_levels(params, levels=0, comm=MPI.COMM_SELF, route="interior-point")
    with finest:
        assert len(solution.details.levels) == 1
        assert solution.candidate.kkt
    with pytest.raises(InputError, match=r"mesh\.levels"):
        solve_levels(params, levels=1, comm=MPI.COMM_SELF, route="interior-point")


def test_the_interior_points_fallback_takes_over_its_sections(monkeypatch):
    # When the chain reaches no KKT point (here starved: one Newton step per run, no
    # polish, no descent), the active-set route runs on the two sections the interior
    # point built: each built and its free mode solved once (before, the fallback built
    # both again: 4 and 4). Reference: the plate's active set with all its seeds on the
    # finer section (an independent algorithm), as above.
    import unibuckle_fenicsx.algorithms.section_levels as levels
    from unibuckle_fenicsx.algorithms.chain import ChainOptions
    from unibuckle_fenicsx.la.eigen import GEPSolver

    params = _parameters("box", mesh_size=0.05)
    with build_section(params, MPI.COMM_SELF) as sec:
        reference = solve_active_set(sec.problem, multilevel=False)
        assert reference.candidate.kkt
    counts = {"built": 0, "free": 0}
    build, smallest = levels.build_section, GEPSolver.smallest

    def counted_build(*args, **kwargs):
        counts["built"] += 1
        return build(*args, **kwargs)

    def counted_smallest(self, *args, **kwargs):
        counts["free"] += 1
        return smallest(self, *args, **kwargs)

    starved = ChainOptions(
        arrangements=1, max_steps=1, polish_iterations=0, quick_polish_iterations=0,
        descent_budget=0,
    )  # fmt: skip
    monkeypatch.setattr(levels, "CHAIN_OPTIONS", starved)
    monkeypatch.setattr(levels, "build_section", counted_build)
    monkeypatch.setattr(GEPSolver, "smallest", counted_smallest)
    finest, solution = solve_levels(params, levels=1, comm=MPI.COMM_SELF, route="interior-point")
    with finest:
        assert counts == {"built": 2, "free": 2}
        assert solution.route[:2] == ["interior-point", "active-set (section levels)"]
        assert len(solution.details.levels) == 2
        # The interior point's own records of its two sections are kept, as a plate's.
        assert len(solution.details.interior_point_levels) == 2
        assert solution.candidate.kkt
        assert solution.load == pytest.approx(reference.load, rel=1e-8)


def test_a_filled_tube_whose_seeds_stall_is_not_left_at_every_direction_in_contact():
    # A short filled tube (R/t = 50, L = R, 21 facets, 4 cells along): the seeds free+/-
    # and the windows stall (20 steps), and the plate's "all" seed is a KKT point at
    # once: every direction pinned, the walls only stretching, 5.7e12 Pa = 1384 x the
    # hollow tube. The fallbacks must run from the stalled seeds instead.
    # Reference, independent of the solvers: the critical load is the least Rayleigh
    # quotient over the admissible cone (paper, section 2), so the quotient of any
    # admissible vector bounds it from above. The vector: the outward axisymmetric bulge
    # u_n = -sin(pi x/L) at every constrained direction (n_in . u <= 0 is admissible),
    # on the rotated pencil, the rotations left 0. Its analytic value on the smooth
    # tube: bending, hoop stretching and the transverse shear strain w' (the rotations
    # are 0) over the work of the axial stress, D pi^2/(t L^2) + E L^2/((1 - nu^2) pi^2
    # R^2) + (5/6) G = 9.08e10 Pa (7.6e7 + 2.34e10 + 6.73e10).
    from unibuckle_fenicsx.algorithms.section_levels import MORE_SEEDS, SEEDS

    params = _parameters("tube", length=0.1, mesh_size=0.03)
    with build_section(params, MPI.COMM_SELF) as sec:
        con, pencil = sec.constraints, sec.problem.pencil
        u = pencil.A.createVecRight()
        x = con.coordinates[con.owned_positions, 0]
        u.array[con.owned_local_dofs] = -np.sin(math.pi * x / params.length)
        bulge = pencil.A(u).dot(u) / pencil.B(u).dot(u)
        u.destroy()
        E, nu, t, L, R = params.E, params.nu, params.thickness, params.length, 0.1
        D = E * t**3 / (12 * (1 - nu**2))
        G = E / (2 * (1 + nu))
        smooth = (
            D * math.pi**2 / (t * L**2) + E * L**2 / ((1 - nu**2) * math.pi**2 * R**2) + 5 / 6 * G
        )
        assert bulge == pytest.approx(smooth, rel=0.02)  # 21 facets, 4 cells along
        solution = solve_active_set(
            sec.problem,
            multilevel=False,
            max_iterations=20,
            bound_budget=0,
            seeds=SEEDS,
            more_seeds=MORE_SEEDS,
        )
        assert sec.problem.solve_free().load < solution.load <= bulge
        assert solution.candidate.kkt
        assert len(solution.active) < con.size


@pytest.mark.parametrize("span", [None, (0.08, 0.32), (0.1, 0.3)])
def test_an_elastic_core_s_springs_are_the_areas_it_covers(span):
    # A box 0.3 x 0.1 m on cells of 0.0375 and 0.025 m around (8 and 4 a face) and 0.04 m
    # along (10): each face's directions carry k_f times the face's area the core covers,
    # its width times the covered length, which leaves out the simply supported ends'
    # half cells (their nodes are held): 0.36 m of the whole 0.4 m, 0.24 m of a span
    # from node to node (0.08 to 0.32 m), 0.2 m of one from cell centre to cell centre.
    # A corner's area belongs to its faces' cells, a span's end node to the half inside.
    from unibuckle_fenicsx.model.shell.core import core_springs

    p = _parameters("box", width=0.3, depth=0.1, length=0.4, mesh_size=0.04, core_span=span)
    section = build_section(p, MPI.COMM_WORLD)
    try:
        springs = core_springs(section.model, section.constraints, 2.0, span)
        across_y = np.abs(section.constraints.normals[:, 1]) > 0.5
    finally:
        section.destroy()
    length = {None: 0.36, (0.08, 0.32): 0.24, (0.1, 0.3): 0.2}[span]
    assert springs[across_y].sum() == pytest.approx(2.0 * 2 * 0.1 * length, rel=1e-12)
    assert springs[~across_y].sum() == pytest.approx(2.0 * 2 * 0.3 * length, rel=1e-12)


@pytest.mark.parametrize("ends", ["simply_supported", "clamped"])
def test_a_square_box_s_quarter_turns_leave_its_pencil_and_seeds_alike(ends):
    # A square box with a core is the same after a quarter turn about its axis. The
    # independent check of the turns found from the mesh: the pencil's own free mode (an
    # eigen solve that knows nothing of them) is mapped onto plus or minus itself at the
    # constrained directions, its two sign patterns are images of one another, and the
    # active set run from each pattern on its own reaches a KKT point of the same load
    # and size (rounding may break a tie otherwise in one run than in the other: on the
    # clamped box the two runs take 8 and 10 iterates to sets that are each other's
    # images by a mirror). So the seeds run the first pattern only.
    from unibuckle_fenicsx.algorithms.section_levels import SEEDS

    p = _parameters("box", width=0.1, depth=0.1, length=0.2, mesh_size=0.025, ends=ends)
    sec = build_section(p, MPI.COMM_WORLD)
    try:
        turns = sec.problem.contact.symmetries
        assert len(turns) == 3
        v = sec.problem.contact.values(sec.problem.solve_free().function.x.petsc_vec)
        v = v / np.abs(v).max()
        for perm in turns:
            assert min(np.abs(v[perm] - v).max(), np.abs(v[perm] + v).max()) < 1e-8
        alone = {
            seed: solve_active_set(sec.problem, multilevel=False, bound_budget=0, seeds=(seed,))
            for seed in SEEDS
        }
        plus, minus = (alone[seed] for seed in SEEDS)
        assert any(np.array_equal(np.sort(t[v > 1e-3]), np.flatnonzero(v < -1e-3)) for t in turns)
        assert plus.candidate.kkt and minus.candidate.kkt
        assert minus.load == pytest.approx(plus.load, rel=1e-10)
        assert len(minus.active) == len(plus.active)
        both = solve_active_set(sec.problem, multilevel=False, bound_budget=0, seeds=SEEDS)
        assert [run.seed for run in both.details.runs] == [SEEDS[0]]
        assert both.load == pytest.approx(min(plus.load, minus.load), rel=1e-10)
    finally:
        sec.destroy()


@pytest.mark.parametrize(
    "changes", [{"width": 0.1, "depth": 0.08}, {"width": 0.1, "depth": 0.1, "bending_stress": 0.5}]
)
def test_a_box_that_a_quarter_turn_changes_has_no_symmetries(changes):
    # A rectangular box's faces differ, and a bending stress loads them differently: no
    # turn leaves the pencil alike, and every seed runs.
    p = _parameters("box", length=0.2, mesh_size=0.025, **changes)
    sec = build_section(p, MPI.COMM_WORLD)
    try:
        assert sec.problem.contact.symmetries == ()
    finally:
        sec.destroy()


#: Two tubes with a core (R/t = 50, 40 facets): the first's seed "free+" alone stalls
#: (the active set's iteration, then the penalty continuation) where "free-" reaches
#: a KKT point; the second's both reach one.
TUBES = [
    {"diameter": 0.1, "thickness": 0.001, "length": 0.05, "mesh_size": 0.008},
    {"diameter": 0.1, "thickness": 0.001, "length": 0.04, "mesh_size": 0.008, "ends": "clamped"},
]


@pytest.mark.parametrize("changes", TUBES)
def test_a_tube_s_turns_leave_its_pencil_alike_and_skip_a_seed_only_after_a_kkt_point(changes):
    # A tube of n equal facets with a core under uniform compression is the same after a
    # turn by 2 pi k/n about its axis: n - 1 turns. The independent check of the turns
    # found from the mesh: the pencil's free mode (an eigen solve that knows nothing of
    # them) is cos(m theta + phi) around, so the half-turn maps it onto (-1)^m times itself
    # at the constrained directions, and some turn (by pi/m) maps its one sign pattern onto
    # the other. The answer with the turns equals the answer of the same problem with
    # them dropped (every seed run): the same load to rounding, fewer eigen solves where
    # the first pattern reaches a KKT point; where it stalls, its image runs too, as with
    # the turns dropped (the same count).
    from unibuckle_fenicsx.algorithms.section_levels import SEEDS

    sec = build_section(_parameters("tube", **changes), MPI.COMM_WORLD)
    try:
        n = sec.mesh.cells_around
        turns = sec.problem.contact.symmetries
        assert n == 40 and len(turns) == n - 1
        v = sec.problem.contact.values(sec.problem.solve_free().function.x.petsc_vec)
        v = v / np.abs(v).max()
        half = turns[n // 2 - 1]
        assert min(np.abs(v[half] - v).max(), np.abs(v[half] + v).max()) < 1e-8
        plus, minus = np.flatnonzero(v > 1e-3), np.flatnonzero(v < -1e-3)
        assert any(np.array_equal(np.sort(t[plus]), minus) for t in turns)
        kept = solve_active_set(sec.problem, multilevel=False, bound_budget=0, seeds=SEEDS)
        sec.problem.contact.symmetries = ()
        every = solve_active_set(sec.problem, multilevel=False, bound_budget=0, seeds=SEEDS)
        assert kept.candidate.kkt and every.candidate.kkt
        assert kept.load == pytest.approx(every.load, rel=1e-9)
        assert [run.seed for run in every.details.runs] == list(SEEDS)
        first_kkt = every.details.runs[0].kkt
        if first_kkt:
            assert [run.seed for run in kept.details.runs] == [SEEDS[0]]
            assert kept.eigensolves < every.eigensolves
        else:
            assert [run.seed for run in kept.details.runs] == list(SEEDS)
            assert kept.eigensolves == every.eigensolves
        assert first_kkt == ("ends" in changes)  # the cases TUBES describes
    finally:
        sec.destroy()


def test_a_tube_s_route_gives_the_answer_of_every_seed_with_fewer_eigen_solves(monkeypatch):
    # The active set's whole route (its seeds on the coarser section, the set carried to
    # the given one and polished, the seeds run there too) on the clamped tube of TUBES,
    # then again with the section's turns dropped (every seed run): the same load to
    # 1e-9 relative (docs/verification/sections_cost_symmetry.md: the image's run ends at
    # the same load up to rounding), fewer eigen solves.
    from unibuckle_fenicsx.model.shell import section as section_module

    params = _parameters("tube", **TUBES[1])
    fine, kept = solve_levels(params, route="active-set", levels=1)
    fine.destroy()
    monkeypatch.setattr(section_module, "_symmetries", lambda *args: ())
    fine, every = solve_levels(params, route="active-set", levels=1)
    fine.destroy()
    assert kept.candidate.kkt and every.candidate.kkt
    assert kept.load == pytest.approx(every.load, rel=1e-9)
    assert kept.eigensolves < every.eigensolves


@pytest.mark.parametrize(
    "changes, turns",
    [({"bending_stress": 0.5}, 0), ({"core_span": (0.05, 0.15)}, 21)],
)
def test_a_tube_s_turns_keep_its_stress_and_core(changes, turns):
    # A bending stress varies around the tube, so no turn leaves its prestress alike; a
    # core over part of the length is the same after every turn (21 on 22 facets).
    sec = build_section(_parameters("tube", mesh_size=0.03, **changes), MPI.COMM_WORLD)
    try:
        assert sec.mesh.cells_around == 22
        assert len(sec.problem.contact.symmetries) == turns
    finally:
        sec.destroy()
