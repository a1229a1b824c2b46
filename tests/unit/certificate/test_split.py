r"""The split copositivity certificate (two or more pencil eigenvalues below the load).

- Translations of node patterns (the columns' source) against the node coordinates.
- The Gram matrix's error bound against exact rational arithmetic (Python's
  :class:`fractions.Fraction`): on a thin plate, :math:`|G - [W, M]^TK^{-1}[W, M]| \le E`
  entrywise, K the stored matrix solved exactly.
- Soundness against independent exhaustive minima (dense numpy over all 2^i contact
  sets, ``tests/support/exhaustive.py``) on long plates on coarse meshes
  (``tests/support/families.py``: :func:`long_plate_family`, and :func:`translated_family`,
  whose buckles slide along a row of nodes): the verified lower bound never exceeds the
  exhaustive minimum, for the returned KKT point, every other KKT point met (wrong ones
  included) and the true minimiser claimed at loads raised by 1e-4, 1e-3 and 1e-2; a
  refuting mode is admissible with a load between the minimum and the claimed load. A
  sample runs by default, the whole family (>= 200 problems with m >= 2) under
  ``-m slow``.
- The solve continued from a refuting mode: on the same families the answer never ends
  above a refuting mode's load (nor below the exhaustive minimum); on the thin SSSS
  plate 0.3 x 0.1 x 1e-4 m at 45 x 15 the interior point's KKT point is refuted and the
  answer continued to a lower KKT point.
- The cost rule: by default the route runs only where its estimated cost is at most
  ``max_cost`` free solves, and the summary says when it did not; with ``--bracket`` the
  thin SSSS plate at the benchmark's meshes is bracketed to 1e-4, never above the load
  the active set reaches there.
"""

from __future__ import annotations

import math
from fractions import Fraction

from mpi4py import MPI

import numpy as np
import pytest

from support.brackets import check_soundness
from support.exhaustive import RTOL, exhaustive_minimum
from support.families import long_plate_family, translated_family
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.certificate.copositivity_split import (
    Basis,
    Patterns,
    SplitOptions,
    column_sources,
    distinct_columns,
    negative_space,
    scatter_columns,
    split_certificate,
)
from unibuckle_fenicsx.certificate.shifted import ShiftedMatrix
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.tolerances import ROUNDING_RTOL

pytest.importorskip("clarabel")
serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense reference is serial")

#: The soundness family: long plates and sliding buckles; how many run by default.
FAMILY = [*long_plate_family(150), *translated_family(90)]
SAMPLE = 3
#: Distances tried: the default's and those of ``--bracket`` (down to 1e-6).
OPTIONS = SplitOptions(deltas=(1e-4, 1e-5, 1e-6), fallback=(1e-3, 1e-2), max_cost=None)


@serial
def test_translations_follow_the_coordinates(thin_plate):
    """A pattern moved by k node spacings lands k spacings further, and back again."""
    with build_problem(thin_plate("t", 9, 3), MPI.COMM_SELF) as problem:
        patterns = Patterns(problem)
        xy = problem.contact.coordinates
        h = 0.3 / 9
        rng = np.random.default_rng(3)
        values = rng.random(len(xy))
        for k in (-3, -1, 1, 2):
            moved = patterns.translate(values, k)
            for node, (x, y) in enumerate(xy):
                source = np.flatnonzero(np.isclose(xy[:, 0], x - k * h) & np.isclose(xy[:, 1], y))
                expected = values[source[0]] if source.size else 0.0
                assert moved[node] == expected
            back = patterns.translate(moved, -k)
            kept = patterns.translate(np.ones(len(xy)), k) > 0
            home = patterns.translate(kept.astype(float), -k) > 0
            assert np.array_equal(back[home], values[home])


@serial
def test_first_columns_stop_where_the_first_basis_stops(thin_plate):
    """The first columns are kept only up to the first ``max_columns`` distinct ones.

    Thin SSSS plate, 45 x 15 (45 lines along, so the reaction's line has some 90
    translates): with ``max_columns = 7`` the columns kept are a prefix of those kept
    with no effective limit (10 000: every translate, every cluster, as before the
    limit), and the first basis (:func:`distinct_columns`, the first 7 distinct ones) is the
    same from either, name by name and value by value. A line's translates are one
    column per line, each as long as the zone: kept whole they grew as the nodes times
    the lines (some 5 GB at 10^6 DOFs).
    """
    with solve(thin_plate("ssss", 45, 15), MPI.COMM_SELF) as analysis:
        problem, sol = analysis.problem, analysis.solution
        assert sol is not None
        few = column_sources(problem, sol.candidate, [], SplitOptions(max_columns=7))
        every = column_sources(problem, sol.candidate, [], SplitOptions(max_columns=10_000))
    assert 7 <= len(few.first) < len(every.first)
    assert [n for n, _ in few.first] == [n for n, _ in every.first[: len(few.first)]]
    assert all(np.array_equal(a, b) for (_, a), (_, b) in zip(few.first, every.first, strict=False))
    basis = [distinct_columns(src.first, [], 7) for src in (few, every)]
    assert [n for n, _ in basis[0]] == [n for n, _ in basis[1]] and len(basis[0]) == 7
    assert all(np.array_equal(a, b) for (_, a), (_, b) in zip(*basis, strict=True))
    assert [n for n, _ in few.movable] == [n for n, _ in every.movable]


def _exact_solve(K, rhs):
    """K^-1 rhs in rational arithmetic (Gaussian elimination with pivoting)."""
    n = len(K)
    M = [[*row, b] for row, b in zip(K, rhs, strict=True)]
    for col in range(n):
        pivot = max(range(col, n), key=lambda r: abs(M[r][col]))
        M[col], M[pivot] = M[pivot], M[col]
        for r in range(col + 1, n):
            if M[r][col]:
                f = M[r][col] / M[col][col]
                M[r] = [a - f * b for a, b in zip(M[r], M[col], strict=True)]
    x = [Fraction(0)] * n
    for r in range(n - 1, -1, -1):
        x[r] = (M[r][n] - sum(M[r][c] * x[c] for c in range(r + 1, n))) / M[r][r]
    return x


@serial
@pytest.mark.parametrize("accurate", [False, True], ids=["double", "dot2"])
def test_gram_error_bound_holds_exactly_on_a_thin_plate(thin_plate, accurate):
    """|G - C'K^-1C| <= E for the stored K solved exactly (Fraction), t/b = 1e-3.

    C = the negative space's vectors and columns on the zone; the entries of G come from
    double-precision solves and residuals (``accurate``: residuals in twice the working
    precision, as ``--bracket`` computes them), their bounds from rounding analysis. With
    the accurate residuals the bound must also be far tighter (their point).
    """
    spec = thin_plate("thin", 6, 2)
    with build_problem(spec, MPI.COMM_SELF) as problem:
        lam = 1.2 * problem.solve_free().load
        matrix = ShiftedMatrix(problem.model.A, problem.model.B)
        m, _, _ = matrix.factor(lam)
        space = negative_space(problem, matrix, lam, m, None, 4)
        assert m >= 1 and space is not None
        psi, _, _ = space
        W = np.column_stack([problem.model.B * _vec(problem, p) for p in psi.T])
        basis = Basis(problem, matrix, m, m + 3, accurate)
        basis.add(W, [f"W{j}" for j in range(m)])
        i = problem.num_constrained
        items = [("a", np.eye(1, i, 0)[0]), ("b", np.ones(i)), ("c", np.arange(i) % 2)]
        basis.add(scatter_columns(problem, items), ["a", "b", "c"])
        ai, aj, av = matrix.K.getValuesCSR()
        n = len(ai) - 1
        K = [[Fraction(0)] * n for _ in range(n)]
        for row in range(n):
            for k in range(ai[row], ai[row + 1]):
                K[row][aj[k]] = Fraction(float(av[k]))
        U = basis._store["U"][:, : basis.q]
        X = [_exact_solve(K, [Fraction(float(v)) for v in U[:, b]]) for b in range(basis.q)]
        worst = 0.0
        for a in range(basis.q):
            for b in range(basis.q):
                exact = sum(Fraction(float(U[r, a])) * X[b][r] for r in range(n))
                gap = abs(Fraction(float(basis.G[a, b])) - exact)
                assert gap <= Fraction(float(basis.E[a, b])), (a, b, float(gap), basis.E[a, b])
                worst = max(worst, float(gap) / basis.E[a, b])
        if accurate:  # the same columns with double-precision residuals
            plain = Basis(problem, matrix, m, m + 3)
            plain.add(W, [f"W{j}" for j in range(m)])
            plain.add(scatter_columns(problem, items), ["a", "b", "c"])
            ratio = float(np.median(basis.E / plain.E))
            assert ratio < 1e-2, ratio
        basis.destroy()
        matrix.destroy()
    assert 0 < worst <= 1.0, worst


def _vec(problem, values):
    v = problem.model.A.createVecRight()
    v.array[:] = values
    return v


def _check(spec, i) -> dict:
    """Run the split route on the KKT points of ``spec`` (see :mod:`brackets`)."""

    def route(problem, matrix, cand, others):
        return [split_certificate(problem, matrix, cand, others, OPTIONS)]

    return check_soundness(spec, i, route, raised=(1e-4, 1e-3, 1e-2))


@serial
@pytest.mark.parametrize(("spec", "i"), FAMILY[:SAMPLE], ids=[s.name for s, _ in FAMILY[:SAMPLE]])
def test_split_bound_is_sound_sample(spec, i):
    """The first long plates: every verified bound <= the exhaustive minimum."""
    _check(spec, i)


@serial
def test_pieces_waiting_while_columns_are_added():
    """Long plate 10 of the family: new columns arrive while pieces wait on the stack.

    Those pieces carry their parent's combinations, shorter than the grown basis; they
    must be read with zero weight on the new columns (the route once stopped there with a
    shape error). Sound as the others (asserted in :func:`_check`).
    """
    spec, i = FAMILY[10]
    report = _check(spec, i)
    assert report["tried"] >= 1, report


@serial
@pytest.mark.slow
def test_split_bound_is_sound_on_the_families():
    """>= 200 problems with m >= 2 (long plates, sliding buckles), none unsound.

    Asserted inside :func:`_check`; here: the family is not vacuous (the route verifies
    bounds, meets wrong KKT points and refutes some).
    """
    reports = [_check(spec, i) for spec, i in FAMILY]
    tried = [r for r in reports if r["tried"]]
    assert len(tried) >= 200, len(tried)
    assert sum(r["verified"] for r in tried) >= 100
    assert sum(r["wrong"] for r in tried) >= 20
    assert sum(r["refuted"] for r in tried) >= 20


def _continued(spec, method: str) -> dict:
    """The whole solve; the answer against the refuting modes met and the minimum."""
    with build_problem(spec, MPI.COMM_SELF) as problem:
        best, _, _ = exhaustive_minimum(problem)
    if not math.isfinite(best):
        return {"continued": 0}
    with solve(spec.with_solver(method=method, bracket=True), MPI.COMM_SELF) as analysis:
        load = analysis.result.critical_load_Pa
        continued = analysis.solution.continued
    assert load >= best * (1 - RTOL), (spec.name, load, best)
    for step in continued:
        assert load <= step.from_load * (1 + ROUNDING_RTOL), (spec.name, load, continued)
        assert step.from_load < step.refuted_load, (spec.name, continued)
    return {"continued": len(continued)}


@serial
@pytest.mark.slow
def test_answer_never_ends_above_a_refuting_mode():
    """On the families, with the active set and the interior point: see :func:`_continued`."""
    counts = [_continued(spec, method)["continued"] for spec, _ in FAMILY[::3]
              for method in ("active-set", "interior-point")]  # fmt: skip
    assert sum(counts) >= 1, counts  # some answer was refuted and continued


@serial
def test_thin_ssss_plate_refuted_then_continued_and_bracketed(thin_plate):
    """0.3 x 0.1 x 1e-4 m at 45 x 15 (two pencil eigenvalues below the load), --bracket.

    The interior point stops at a KKT point that the certificate refutes (an admissible
    mode with a lower load); the solve continues from that mode to a lower KKT point,
    which is bracketed to 1e-4 at least (measured: proven, to 1e-6): the lower bound
    lies below the load and within 1e-4 of it, the answer at or below every refuting
    mode met. (On so coarse a mesh the
    free solve is quick and the bracket's estimated cost exceeds 3 free solves: it runs
    on request.)
    """
    with solve(thin_plate("ssss", 45, 15).with_solver(bracket=True), MPI.COMM_SELF) as analysis:
        cert = analysis.certificate
        load = analysis.result.critical_load_Pa
        continued = analysis.solution.continued
        text = analysis.result.summary()
    assert cert is not None and cert.kkt and cert.smallest_of_reduced
    assert cert.status in ("bracketed", "proven") and cert.proven_by == "split-spn", cert.notes
    assert cert.relative_gap <= 1e-4 * (1 + ROUNDING_RTOL)
    assert cert.lower_bound <= load <= cert.upper_bound
    assert continued and all(load <= c.from_load < c.refuted_load for c in continued)
    assert "(split-spn" in text


@serial
def test_interpolated_multipliers_prove_larger_pieces(thin_plate):
    """The thin SSSS plate at 45 x 15, the default's distances, with and without.

    A piece that no single combination's cap holds is tried with its generators'
    multipliers interpolated over it before it is split; the same distances are verified
    (the bound is lambda_c (1 - delta) either way), with fewer pieces examined (measured:
    80 without, 36 with).
    """
    with solve(thin_plate("ssss", 45, 15), MPI.COMM_SELF) as analysis:
        problem, sol = analysis.problem, analysis.solution
        matrix = ShiftedMatrix(problem.model.A, problem.model.B)
        try:
            runs = [split_certificate(problem, matrix, sol.candidate, sol.kkt_points,
                                      SplitOptions(max_cost=None, interpolate=flag))
                    for flag in (False, True)]  # fmt: skip
        finally:
            matrix.destroy()
    without, with_ = ([a.examined for a in out.attempts] for out in runs)
    assert [a.proven for a in runs[0].attempts] == [a.proven for a in runs[1].attempts]
    assert runs[0].value is not None and runs[1].value == runs[0].value
    assert sum(with_) < sum(without), (with_, without)


@serial
def test_route_skipped_by_default_where_it_costs_more(thin_plate):
    """The thin SSSS plate at 45 x 15 without ``--bracket``: the rule, and the summary.

    The route runs by default only when its estimated cost (counts only) is at most
    ``SplitOptions.max_cost``; here it is not run, its record says so with the estimate,
    the answer stays a KKT point and the summary names ``--bracket``.
    """
    with solve(thin_plate("ssss", 45, 15), MPI.COMM_SELF) as analysis:
        cert = analysis.certificate
        text = analysis.result.summary()
        record = analysis.result.certificate
    assert cert is not None and cert.kkt and cert.negative_eigenvalues >= 2
    assert cert.copositivity is not None
    split = cert.copositivity.split
    assert split is not None and split.skipped, split
    assert split.estimated_cost is not None and split.estimated_cost > SplitOptions().max_cost
    assert cert.status == "kkt-only" and cert.refuting_mode is None
    assert "not bracketed by default here" in text and "--bracket" in text
    estimate = f"estimated cost {split.estimated_cost:.1f} free solves"
    assert record.split_route == f"skipped: {estimate} > 3"
    assert record.split_route in text


@serial
@pytest.mark.slow
@pytest.mark.parametrize("mesh", [(90, 30), (180, 60)])
def test_thin_ssss_plate_is_bracketed_on_request(mesh, thin_plate):
    """SSSS 0.3 x 0.1 x 1e-4 m at the benchmark's meshes, ``--bracket``: bracketed to 1e-4.

    Never above the load the active set reaches at 90 x 30 (4075.186054 Pa, below the
    interior point's): the bound must hold for every admissible mode.
    """
    with solve(thin_plate("ssss", *mesh).with_solver(bracket=True), MPI.COMM_SELF) as analysis:
        cert = analysis.certificate
        load = analysis.result.critical_load_Pa
    assert cert is not None and cert.status in ("bracketed", "proven"), cert.notes
    assert cert.proven_by == "split-spn"
    assert cert.relative_gap <= 1e-4 * (1 + ROUNDING_RTOL)
    assert cert.lower_bound <= load
    if mesh == (90, 30):
        assert cert.lower_bound <= 4075.186054


def test_cost_estimate_of_hundreds_of_negative_eigenvalues_is_the_cap():
    """The estimate's pieces: COST_MODEL's at m = 2, growth-fold per further one, capped.

    One attempt priced.
    COST_MODEL's rule (68 pieces and a growth of 2.41), capped at ``max_pieces``. A filled
    tube (R/t = 50, L = R, 10 mm cells) has m = 576 pencil eigenvalues below its load:
    4**574 (the growth then) overflows a float, and the certificate ended in an
    OverflowError (an internal error, no result).
    """
    from types import SimpleNamespace

    from unibuckle_fenicsx.certificate.copositivity_split import estimate_counts

    opts = SplitOptions()
    matrix = SimpleNamespace(getSize=lambda: (8463, 8463))
    problem = SimpleNamespace(model=SimpleNamespace(A=matrix))
    sources = SimpleNamespace(first=[("column", None)] * 3)
    assert estimate_counts(problem, sources, 2, opts).pieces == 68.0
    assert estimate_counts(problem, sources, 3, opts).pieces == pytest.approx(68.0 * 2.41)
    assert estimate_counts(problem, sources, 2, opts).attempts == 1
    for m in (5, 576, 10**6):
        assert estimate_counts(problem, sources, m, opts).pieces == float(opts.max_pieces)


@serial
def test_cost_limit_stops_further_distances_and_pieces(thin_plate):
    """The thin SSSS plate at 45 x 15: the route held to a cost limit, priced from counts.

    Without a limit the default's distances 1e-3 and 1e-4 are both verified (two
    attempts; ``spent``: the counts up to each attempt's end, priced by the cost model).
    With a limit between the first attempt's counts and those plus one more attempt's
    estimate, the second distance is not tried: the bound is the first attempt's
    (lambda_c (1 - 1e-3)), and the record says why. With a limit of half the first
    attempt's counts, that attempt stops among its pieces, and no further distance is
    tried: no bound, fewer pieces examined.
    """
    from unibuckle_fenicsx.certificate.copositivity_split import estimate_counts, price

    with solve(thin_plate("ssss", 45, 15), MPI.COMM_SELF) as analysis:
        problem, sol = analysis.problem, analysis.solution
        matrix = ShiftedMatrix(problem.model.A, problem.model.B)
        try:

            def bound(limit):
                opts = SplitOptions(max_cost=limit)
                return split_certificate(problem, matrix, sol.candidate, sol.kkt_points, opts)

            free = bound(None)
            first = free.attempts[0]
            sources = column_sources(problem, sol.candidate, sol.kkt_points, SplitOptions())
            next_attempt = price(estimate_counts(problem, sources, first.m, SplitOptions()))
            between = bound(first.spent + 0.5 * next_attempt)
            half = bound(0.5 * first.spent)
        finally:
            matrix.destroy()
    assert [a.proven for a in free.attempts] == [True, True], free.why
    assert free.attempts[1].spent > first.spent > 0
    assert [a.delta for a in between.attempts] == [1e-3] and between.attempts[0].proven
    assert between.value == sol.candidate.load * (1 - 1e-3)
    assert "no further distance" in between.why
    assert between.attempts[0].spent == pytest.approx(first.spent, rel=1e-12)
    assert len(half.attempts) == 1 and not half.attempts[0].proven
    assert half.value is None and "cost limit" in half.attempts[0].why
    assert half.attempts[0].examined < first.examined


def test_split_route_says_what_the_bracket_did():
    """The JSON's ``certificate.split_route`` and the summary's words, from the records.

    Skipped (its estimate over the limit), ran and bracketed or proven (the bound is the
    split route's), ran without a bound; None where the route did not apply.
    """
    from unibuckle_fenicsx.certificate.records import SplitRecord
    from unibuckle_fenicsx.results.records import split_route

    def record(cost, skipped=False):
        return SplitRecord(value=None, delta=None, m=2, r=0, pieces=0, margin=-math.inf,
                           why="", attempts=[], estimated_cost=cost, skipped=skipped,
                           cost_limit=3.0)  # fmt: skip

    assert split_route("kkt-only", "interlacing", None) is None
    assert (split_route("kkt-only", "interlacing", record(4.25, True))
            == "skipped: estimated cost 4.2 free solves > 3")  # fmt: skip
    assert (split_route("bracketed", "split-spn", record(2.08))
            == "bracketed (estimated cost 2.1 free solves)")  # fmt: skip
    assert split_route("proven", "split-spn", record(2.08)).startswith("proven (")
    assert split_route("kkt-only", "interlacing", record(2.08)).startswith("not bracketed (")
    assert split_route("proven", "rank2-spn", record(2.08)).startswith("not bracketed (")
