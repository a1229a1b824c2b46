r"""Overlapping obstacle zones merged node by node by the contact manager.

A node in two tensionless zones carries both springs, :math:`(k_1 + k_2) h^2` on the
interior nodes of a uniform grid of spacing h (a node's tributary area is one cell), and
on a zone's edge only the covered half of that area, :math:`k h^2/2` from that zone
(:math:`\int_{zone}\varphi_k`: the hat function's integral over the half cells inside);
a node in two rigid zones with gaps keeps the smaller gap. Expected values from the
grid's spacing and the zones' bounds written here.
"""

from __future__ import annotations

from mpi4py import MPI

import numpy as np
import pytest

from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.contact import ContactSetManager
from unibuckle_fenicsx.spec import ObstacleSpec
from unibuckle_fenicsx.spec.cases import plate_case

H = 1.0 / 6  # 9 x 6 cells on 1.5 x 1 m
LEFT = ((0.0, 1.0), (0.0, 1.0))
RIGHT = ((0.5, 1.5), (0.0, 1.0))


def _spec():
    return plate_case("zones", length=1.5, width=1.0, thickness=1e-3, nx=9, ny=6)


def _expected(x, left, right):
    """The merged value at abscissae x: ``left`` or ``right`` alone, or both (a pair)."""
    in_left = x <= 1.0 + 1e-9
    in_right = x >= 0.5 - 1e-9
    return [
        (left if a else None, right if b else None) for a, b in zip(in_left, in_right, strict=True)
    ]


def test_springs_of_overlapping_foundations_add_up():
    k1, k2 = 1.0e3, 3.0e3
    zones = (
        ObstacleSpec(LEFT, foundation_stiffness=k1),
        ObstacleSpec(RIGHT, foundation_stiffness=k2),
    )
    with build_problem(_spec(), MPI.COMM_WORLD) as problem:
        contact = ContactSetManager(problem.model, zones)
        x, stiffness = contact.coordinates[:, 0], contact.stiffness
    assert stiffness is not None
    assert contact.size == 8 * 5  # interior nodes: the edges are simply supported
    pairs = _expected(x, k1, k2)
    assert sum(None not in pair for pair in pairs) == 4 * 5  # x = 0.5 ... 1: in both zones
    # Covered fraction of a node's cell of area h^2: 1/2 on the zone's edge line x = 1
    # (left zone) or x = 0.5 (right zone), 1 inside (the other edges are the plate's).
    half = {0: np.isclose(x, 1.0), 1: np.isclose(x, 0.5)}
    for j, (sk, pair) in enumerate(zip(stiffness, pairs, strict=True)):
        expected = sum(
            k * (0.5 if half[z][j] else 1.0) for z, k in enumerate(pair) if k is not None
        )
        assert sk == pytest.approx(expected * H * H, rel=1e-12)


def test_overlapping_rigid_zones_keep_the_smaller_gap():
    zones = (ObstacleSpec(LEFT, gap=2.0e-3), ObstacleSpec(RIGHT, gap=1.0e-3))
    with build_problem(_spec(), MPI.COMM_WORLD) as problem:
        contact = ContactSetManager(problem.model, zones)
        x, gaps, signs = contact.coordinates[:, 0], contact.gaps, contact.signs
    for gk, pair in zip(gaps, _expected(x, 2.0e-3, 1.0e-3), strict=True):
        assert gk == min(g for g in pair if g is not None)
    np.testing.assert_array_equal(signs, np.ones(len(x)))  # both above
