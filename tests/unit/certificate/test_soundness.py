r"""Soundness of the whole certificate on long plates, against the exhaustive minimum.

The route tests (``test_split.py``, ``test_lowrank.py``) check one route each. Here the
certificate as a user gets it: every route in turn (rank 2, the semidefinite programs on
these small zones, the split route, the low-rank route), with the default's settings and
with ``--bracket``'s, and the whole solve (the algorithm, the certificate, the
continuation from a refuting mode, the certificate again).

The reference is independent of the certificate: the exhaustive minimum over all 2^i
contact sets by dense LAPACK (``tests/support/exhaustive.py``: the paper's enumeration,
Section 5, without its stopping rule), on problems small enough for it (i <= 14). The
problems are long plates (``tests/support/families.py``: :func:`long_plate_family`,
a/b 2.5-4.5, four support cases, compression or shear, t/b 1e-3 to 3e-2, whole face or a
strip, above or below) and very long plates with one row of free nodes whose buckles
slide along it (:func:`translated_family`, a/b 4-7): families of nearly equal critical
states translated along the plate. Seeds differ from the route tests': fresh problems.

Asserted on each: no verified lower bound above the exhaustive minimum (relative 1e-8,
the references' agreement, :data:`support.exhaustive.RTOL`), for the active set's KKT
point, every other KKT point it met (wrong ones included) and the true minimiser claimed
at loads raised by 1e-4, 1e-3 and 1e-2 (a claim no sound route may bracket); every
refuting mode admissible with a load between the minimum and the claimed load; and, for
the whole solve (active set by default, interior point with ``--bracket``), the
certificate's lower bound at most the minimum, the answer at least the minimum. The
family counts only problems where two or more pencil eigenvalues lie below the load
(the low-rank and split routes' domain; rank 2 cannot apply there). A sample runs by
default, the whole family (>= 200 such problems) under ``-m stress``.
"""

from __future__ import annotations

import math

from mpi4py import MPI

import pytest

from support.brackets import check_soundness
from support.exhaustive import RTOL, exhaustive_minimum
from support.families import long_plate_family, translated_family
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.certificate.copositivity import BoundOptions, copositivity_bound
from unibuckle_fenicsx.certificate.copositivity_split import SplitOptions
from unibuckle_fenicsx.model.build import build_problem

pytest.importorskip("clarabel")
serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense reference is serial")

#: Fresh long plates and sliding buckles (seeds apart from the route tests').
FAMILY = [
    *long_plate_family(170, seed=20261130),
    *translated_family(100, seed=20261131),
]
SAMPLE = 3
#: The certificate's settings: the default's (split route within its cost limit, no
#: low-rank route) and ``--bracket``'s (the split route's thorough budgets, then low rank).
SETTINGS = {
    "default": BoundOptions(lowrank=None),
    "bracket": BoundOptions(split=SplitOptions.thorough()),
}


def _routes(problem, matrix, cand, others):
    """The whole copositivity certificate at both settings, on one KKT point."""
    return [
        copositivity_bound(problem, cand, others, options, matrix) for options in SETTINGS.values()
    ]


def _whole_solve(spec, best: float) -> dict:
    """The solve as a user runs it, at both settings: bound <= minimum <= answer."""
    report = {"bracketed": 0, "continued": 0}
    for bracket, method in ((False, "active-set"), (True, "interior-point")):
        with solve(spec.with_solver(method=method, bracket=bracket), MPI.COMM_SELF) as analysis:
            cert = analysis.certificate
            load = analysis.result.critical_load_Pa
            where = (spec.name, method, bracket, cert.lower_bound, best, load, cert.proven_by)
            assert cert.lower_bound <= best * (1 + RTOL), where
            assert load >= best * (1 - RTOL), where
            report["bracketed"] += cert.status in ("proven", "bracketed")
            report["continued"] += len(analysis.solution.continued)
    return report


def _check(spec, i) -> dict:
    report = check_soundness(spec, i, _routes, raised=(1e-4, 1e-3, 1e-2))
    if report["tried"]:
        with build_problem(spec, MPI.COMM_SELF) as problem:
            best, _, _ = exhaustive_minimum(problem)
        assert math.isfinite(best)
        report |= _whole_solve(spec, best)
    return report


@serial
@pytest.mark.parametrize(("spec", "i"), FAMILY[:SAMPLE], ids=[s.name for s, _ in FAMILY[:SAMPLE]])
def test_certificate_is_sound_sample(spec, i):
    """The first long plates of the family: no lower bound above the exhaustive minimum."""
    _check(spec, i)


@serial
@pytest.mark.stress
def test_certificate_is_sound_on_the_families():
    """>= 200 problems with m >= 2 (long plates, sliding buckles), none unsound.

    Asserted inside :func:`_check`; here: the family is not vacuous (bounds verified,
    wrong KKT points met and refuted, sliding buckles among the problems tried).
    """
    reports = [(spec.name, _check(spec, i)) for spec, i in FAMILY]
    tried = [r for _, r in reports if r["tried"]]
    assert len(tried) >= 200, len(tried)
    assert sum(1 for name, r in reports if r["tried"] and name.startswith("slide")) >= 50
    assert sum(r["verified"] for r in tried) >= 100
    assert sum(r["wrong"] for r in tried) >= 20
    assert sum(r["refuted"] for r in tried) >= 20
    assert sum(r["bracketed"] for r in tried) >= 100
