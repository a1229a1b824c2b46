"""The shifted and the free eigen solves never return a pair that is no eigenpair.

The filled tube of ``test_spurious_pair.py`` (D = 0.1 m, t = 1 mm, L = 0.1 m, 10 mm
cells, every core direction removed; B semidefinite, most of its rank lost). The
solve shifted below an estimate (``near``), started from the free mode, returned
7.993e10 Pa on the starting code: 0.75 % below the pencil's least load 8.0533e10
(scipy), with its vector's Rayleigh quotient at 8.113e10; the two lowest pairs of
the same shifted solve (``lowest_pairs``) were -1.519e11 and 5.175e10, "proven the
smallest". The references need no eigen solver of the package: scipy's dense
``eigh`` of the swapped pencil (A SPD).
"""

from __future__ import annotations

from mpi4py import MPI

import numpy as np
import pytest
import scipy.linalg

from support.exhaustive import dense
from support.tubes import filled_tube
from unibuckle_fenicsx.la import eigen
from unibuckle_fenicsx.la.eigen import SmallestSearch
from unibuckle_fenicsx.model.shell.section import build_section

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial")


@pytest.fixture(scope="module")
def tube():
    section = build_section(filled_tube(), MPI.COMM_SELF)
    yield section.problem
    section.destroy()


def _least_loads(A, B, removed, count):
    """The ``count`` least loads of the pencil without ``removed`` (scipy, dense)."""
    keep = np.setdiff1d(np.arange(A.getSize()[0]), removed)
    a = dense(A)[np.ix_(keep, keep)]
    b = dense(B)[np.ix_(keep, keep)]
    mu = scipy.linalg.eigh(b, a, eigvals_only=True)
    return np.sort(1.0 / mu[mu > 0.0])[:count]


def _quotient(A, B, x):
    ax, bx = A.createVecLeft(), B.createVecLeft()
    A.mult(x, ax)
    B.mult(x, bx)
    try:
        return x.dot(ax) / x.dot(bx)
    finally:
        ax.destroy()
        bx.destroy()


def test_the_shifted_solve_returns_no_pair_below_the_least_load(tube):
    solver = tube.eigensolver
    free = tube.solve_free()
    rows = tube.contact.removed_rows(np.arange(tube.contact.size))
    start = free.function.x.petsc_vec  # nonzero on the removed rows, as the last mode
    out = start.duplicate()
    try:
        pair = solver.solve(rows, out=out, initial=start, near=free.load)
        A, B = solver.reduced(rows)
        least = _least_loads(A, B, rows, 1)[0]  # 8.0533462e10 Pa
        assert pair.value == pytest.approx(least, rel=1e-8)
        assert _quotient(A, B, out) == pytest.approx(pair.value, rel=1e-10)
    finally:
        out.destroy()


def test_the_lowest_pairs_are_eigenpairs_or_none(tube):
    solver = tube.eigensolver
    free = tube.solve_free()
    rows = tube.contact.removed_rows(np.arange(tube.contact.size))
    pairs = solver.lowest_pairs(rows, free.load, 2, initial=free.function.x.petsc_vec)
    try:
        A, B = solver.reduced(rows)
        least = _least_loads(A, B, rows, 2)  # 8.0533462e10, 8.0535185e10 Pa
        assert len(pairs) in (0, 2)  # none (nothing proven), or the two least
        for (pair, vec), load in zip(pairs, least, strict=False):
            assert pair.value == pytest.approx(load, rel=1e-8)
            assert _quotient(A, B, vec) == pytest.approx(pair.value, rel=1e-8)
    finally:
        for _, vec in pairs:
            vec.destroy()


def test_a_free_pair_that_is_none_is_not_proven_the_smallest(tube, monkeypatch):
    """A pair of the free solve that fails the check leaves it to the solve at 0, unproven.

    No free solve was seen to return a pair that is none; the check is made to flag
    every pair of the free solve's EPS, and the proof must then be withheld.
    """
    solver = tube.eigensolver
    checked = eigen.spurious_pair
    flagged = []

    def flag_free(eps, index=0):
        if eps is solver.shifted.free_eps():
            flagged.append(index)
            return True
        return checked(eps, index)

    monkeypatch.setattr(eigen, "spurious_pair", flag_free)
    out = solver.A.createVecRight()
    try:
        least = _least_loads(solver.A, solver.B, np.empty(0, np.int64), 1)[0]  # 2.6009e9 Pa
        pair, proof = SmallestSearch(solver, (least,)).run(out)
        assert flagged
        assert proof is None
        assert pair.value == pytest.approx(least, rel=1e-8)
    finally:
        out.destroy()


def test_pairs_that_are_none_in_every_subspace_leave_it_to_the_swapped_pencil(tube, monkeypatch):
    """A pair that is none at 0 and in the widest subspace: the swapped pencil's, checked.

    Seen on one machine's rounding (the filled short tube of the section anchors): the
    solve at 0 and its retry with 64 Krylov vectors both returned a pair whose residual
    was 3.7e-4, and the run stopped with an error. The check is made to flag every pair
    of the solve at 0 here; the swapped pencil B x = theta A x (A in the inner-product
    slot) must then give the least load, with a vector whose Rayleigh quotient is it.
    The reference: scipy's dense ``eigh`` of the reduced pencil.
    """
    solver = tube.eigensolver
    checked = eigen.spurious_pair
    flagged = []

    def flag_at_zero(eps, index=0):
        if eps is solver.eps:
            flagged.append(index)
            return True
        return checked(eps, index)

    monkeypatch.setattr(eigen, "spurious_pair", flag_at_zero)
    rows = tube.contact.removed_rows(np.arange(tube.contact.size))
    out = solver.A.createVecRight()
    try:
        pair = solver.solve(rows, out=out)
        A, B = solver.reduced(rows)
        least = _least_loads(A, B, rows, 1)[0]  # 8.0533462e10 Pa
        assert len(flagged) == 2  # the solve at 0, then the widest subspace
        assert pair.value == pytest.approx(least, rel=1e-8)
        assert _quotient(A, B, out) == pytest.approx(pair.value, rel=1e-10)
        assert pair.error < 1e-6
    finally:
        out.destroy()
