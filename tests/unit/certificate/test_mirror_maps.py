"""The constrained nodes' permutations under the plate's mirror symmetries.

Expected values by brute force: for every node, the node nearest its mirror image (a
dense distance table), which must lie within a thousandth of the node spacing.
"""

from __future__ import annotations

from mpi4py import MPI

import numpy as np
import pytest

from unibuckle_fenicsx.certificate.shifted import mirror_maps
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.spec import ObstacleSpec
from unibuckle_fenicsx.spec.cases import plate_case


def _spec(zone):
    return plate_case(
        "mirror", length=0.3, width=0.1, thickness=1e-3, nx=12, ny=4, zone=ObstacleSpec(zone)
    )


def _brute_force(xy, centre, signs):
    image = centre + signs * (xy - centre)
    dist = np.linalg.norm(image[:, None, :] - xy[None, :, :], axis=2)
    nearest = dist.argmin(axis=1)
    found = dist[np.arange(len(xy)), nearest] < 1e-3 * 0.025
    return nearest if found.all() else None


@pytest.mark.parametrize(
    "zone, expected",
    [
        ("all", {"x", "y", "xy"}),
        (((0.0, 0.1), (0.0, 0.1)), {"y"}),  # the left third, across the whole width
        (((0.0, 0.1), (0.0, 0.05)), set()),
    ],
)
def test_mirror_maps_against_brute_force(zone, expected):
    with build_problem(_spec(zone), MPI.COMM_WORLD) as problem:
        xy = problem.contact.coordinates
        maps = mirror_maps(problem)
    assert set(maps) == expected
    centre = np.array([0.15, 0.05])
    for name, signs in {"x": (-1, 1), "y": (1, -1), "xy": (-1, -1)}.items():
        reference = _brute_force(xy, centre, np.array(signs, dtype=float))
        if name in maps:
            np.testing.assert_array_equal(maps[name], reference)
        else:
            assert reference is None
