r"""The low-rank copositivity certificate (several pencil eigenvalues below the load).

- The error-free transformations (TwoSum, TwoProduct) against exact rational arithmetic,
  and the double-double residual's bound against the exact residual of a thin plate's
  K(lambda) (Python's :class:`fractions.Fraction`).
- Soundness against independent exhaustive minima (dense numpy over all 2^i contact sets,
  ``tests/support/exhaustive.py``) on long plates on coarse meshes whose KKT points have two or
  more pencil eigenvalues below them (``tests/support/families.py``): the verified lower bound
  never exceeds the exhaustive minimum, for the returned KKT point, for every other KKT
  point met (wrong ones included), and for the true minimiser claimed at a load raised by
  1e-4 and 1e-3; a refuting mode is admissible with a load between the minimum and the
  claimed load. A sample runs by default, the whole family under ``-m stress``.
- On the thin SSSS plate 0.3 x 0.1 x 1e-4 m (README, "Thin plates"), whose pencil has two
  eigenvalues below lambda_c, the returned load is bracketed to at least 1e-3, and the
  wrong KKT point of the interior buckle (k near 16/3 against the end buckle's 9/2) is
  not bracketed above the end buckle's load.
"""

from __future__ import annotations

from fractions import Fraction

from mpi4py import MPI

import numpy as np
import pytest

from support.brackets import check_soundness
from support.families import long_plate_family
from unibuckle_fenicsx.algorithms.active_set import solve_active_set
from unibuckle_fenicsx.algorithms.pdas import iterate
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.certificate.accurate import AccurateResidual, two_product, two_sum
from unibuckle_fenicsx.certificate.certify import certify
from unibuckle_fenicsx.certificate.copositivity_lowrank import LowRankOptions, lowrank_certificate
from unibuckle_fenicsx.certificate.shifted import ShiftedMatrix
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.tolerances import BRACKET_GAP, ROUNDING_RTOL

pytest.importorskip("clarabel")
serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense reference is serial")

#: Problems of the family, and how many run by default.
FAMILY_SIZE = 130
SAMPLE = 4
#: Budgets for the family (coarse problems: r and the pieces stay small): with U = I on
#: these small zones (the default), and with the low-rank columns and cuts instead.
OPTIONS = (
    LowRankOptions(max_pieces=24, max_cuts=12, time_budget=None),
    LowRankOptions(max_pieces=24, max_cuts=12, time_budget=None, unit_columns=0),
)


def test_error_free_transformations_are_exact():
    """TwoSum and TwoProduct: s + e = a + b and p + e = a b exactly (rational check)."""
    rng = np.random.default_rng(1)
    a = rng.standard_normal(200) * 10.0 ** rng.integers(-20, 20, 200)
    b = rng.standard_normal(200) * 10.0 ** rng.integers(-20, 20, 200)
    s, e = two_sum(a, b)
    p, f = two_product(a, b)
    for k in range(200):
        fa, fb = Fraction(float(a[k])), Fraction(float(b[k]))
        assert Fraction(float(s[k])) + Fraction(float(e[k])) == fa + fb
        assert Fraction(float(p[k])) + Fraction(float(f[k])) == fa * fb


@serial
def test_double_double_residual_bound_holds_on_a_thin_plate(thin_plate):
    """|rho - rho_hat| <= e componentwise, with rho = w - K x exact (Fraction), t/b = 1e-3.

    Also: the bound is far below what a double-precision residual can promise (the
    rounding of |K||x|, which on this plate exceeds |Kx| by orders of magnitude).
    """
    spec = thin_plate("thin", 9, 3)
    with build_problem(spec, MPI.COMM_SELF) as problem:
        lam = 1.1 * problem.solve_free().load
        matrix = ShiftedMatrix(problem.model.A, problem.model.B)
        matrix.factor(lam)
        w = problem.contact.scatter(np.ones(problem.num_constrained), matrix.K.createVecRight())
        x = w.duplicate()
        matrix.solve(w, x)
        residual = AccurateResidual(matrix.K)
        (rho,), (err,) = (v.T for v in residual([w], [x]))
        ai, aj, av = matrix.K.getValuesCSR()
        xs, ws = x.array_r, w.array_r
        worst, dp = 0.0, 0.0
        for row in range(len(ai) - 1):
            cols = range(ai[row], ai[row + 1])
            exact = Fraction(float(ws[row])) - sum(
                Fraction(float(av[j])) * Fraction(float(xs[aj[j]])) for j in cols
            )
            gap = abs(float(exact - Fraction(float(rho[row]))))
            if err[row] == 0.0:  # a row with nothing to round (an edge DOF: x = w = 0)
                assert gap == 0.0
                continue
            worst = max(worst, gap / err[row])
            dp = max(dp, sum(abs(av[j] * xs[aj[j]]) for j in cols) * 2.0**-53 / err[row])
        residual.destroy()
        for v in (w, x):
            v.destroy()
        matrix.destroy()
    assert worst <= 1.0, worst
    assert dp > 1e6, dp  # the double-precision bound would be a million times wider


def _check_long(spec, i) -> dict:
    """Run the low-rank route (both column choices) on the KKT points of ``spec``."""

    def route(problem, matrix, cand, others):
        return [lowrank_certificate(problem, matrix, cand, others, o) for o in OPTIONS]

    return check_soundness(spec, i, route)


FAMILY = long_plate_family(FAMILY_SIZE)


@serial
@pytest.mark.parametrize(("spec", "i"), FAMILY[:SAMPLE], ids=[s.name for s, _ in FAMILY[:SAMPLE]])
def test_lowrank_bound_is_sound_sample(spec, i):
    """The first long plates: every verified bound <= the exhaustive minimum."""
    _check_long(spec, i)


@serial
@pytest.mark.stress
def test_lowrank_bound_is_sound_on_the_family():
    """All of the family: >= 100 problems with m >= 2 tried, none unsound (asserted inside)."""
    reports = [_check_long(spec, i) for spec, i in FAMILY]
    tried = [r for r in reports if r.get("tried")]
    assert len(tried) >= 100, len(tried)
    # The route is not vacuous: it verifies some bounds and meets wrong KKT points.
    assert sum(r["verified"] for r in tried) >= 20
    assert sum(r["wrong"] for r in tried) >= 10


@serial
def test_thin_ssss_plate_is_bracketed(thin_plate):
    """SSSS 0.3 x 0.1 x 1e-4 m at 45 x 15: two pencil eigenvalues below, bracketed <= 1e-3.

    The bound and the load bracket the critical load: lower <= load (the load is that
    of an admissible mode), and the gap is the verified one. The JSON has the status, m
    and the route's record (split, or low-rank when the split route fails); the summary
    says "bracketed to".
    """
    spec = thin_plate("ssss", 45, 15).with_solver(bracket=True)
    with solve(spec, MPI.COMM_SELF) as analysis:
        cert = analysis.certificate
        load = analysis.result.critical_load_Pa
        data = analysis.result.as_dict()["certificate"]
        text = analysis.result.summary()
    assert cert is not None and cert.kkt
    assert cert.negative_eigenvalues is not None and cert.negative_eigenvalues >= 2
    assert cert.status in ("bracketed", "proven"), cert
    assert cert.proven_by in ("split-spn", "lowrank-spn")
    assert cert.relative_gap <= BRACKET_GAP * (1 + ROUNDING_RTOL)  # a bound at lambda (1 - 1e-3)
    assert cert.lower_bound <= load <= cert.upper_bound
    assert data["status"] == cert.status and data["negative_eigenvalues"] >= 2
    route = "split" if cert.proven_by == "split-spn" else "lowrank"
    assert data["copositivity"][route]["r"] >= 2
    assert "bracketed to" in text or "proven=yes" in text


@serial
def test_interior_bump_on_the_thin_ssss_plate_is_not_bracketed(thin_plate):
    """A wrong KKT point of the thin SSSS plate (0.3 x 0.1 x 1e-4 m, 45 x 15) stays unproven.

    The interior buckle between two touch-downs (thin-plate k = 16/3; README, "Every
    plate the schema describes") is a KKT point of the SSSS plate too, found here by the
    active-set iteration from the contact set of the plate with clamped loaded edges; the
    end buckle (k = 9/2) has a lower load. The lower bound certified at the interior
    buckle must stay below the end buckle's load (that of an admissible mode, so an upper
    bound on the critical load), and a refuting mode, if one is found, must be admissible
    and below the interior buckle's load.
    """
    ssss = thin_plate("ssss", 45, 15).with_solver(bracket=True)
    clamped = thin_plate("cs", 45, 15).with_solver(certify=False)
    with solve(clamped, MPI.COMM_SELF) as analysis:
        start = analysis.solution.active.copy()
    with build_problem(ssss, MPI.COMM_SELF) as problem:
        end_bump = solve_active_set(problem).load
        run = iterate(problem, "interior", start, None, 200, thresholds=(1e-4, 1e-6))
        assert run.status == "kkt" and run.final is not None
        bump = run.final
        k = problem.buckling_coefficient(bump.load)
        assert abs(k - 16 / 3) < 0.1 and bump.load > end_bump * 1.1, (k, bump.load, end_bump)
        cert = certify(problem, bump)
    assert cert.kkt and cert.status == "kkt-only", cert
    assert cert.lower_bound <= end_bump
    if cert.refuting_mode is not None:
        assert cert.refuting_mode.feasible and cert.refuting_mode.load < bump.load
