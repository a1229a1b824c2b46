"""The obstacle's push at each contact node: in the JSON (N/m) and in the ParaView output.

Expected values are not taken from the code that writes them:

- the push is recomputed here from the assembled matrices, ``-(A u - lambda B u)`` at each
  contact node's deflection row, for the returned mode (scaled to max |w| = 1);
- a stiffer material gives proportionally larger forces for the same mode: with E
  doubled the load doubles, the mode is the same, and every push doubles (A and B scale
  with E and with 1 respectively, lambda with E);
- the obstacle only pushes (KKT): no push below minus its resolution, and the pushes
  add up to a positive total on the paper's case c1;
- the field ``contact_force`` of the ``.pvd`` output, read back with pyvista, holds the
  same numbers at the contact nodes and zero elsewhere.
"""

from __future__ import annotations

from mpi4py import MPI

import numpy as np
import pytest
from msgspec.structs import replace

from unibuckle_fenicsx import paper_case, solve
from unibuckle_fenicsx.results.files import write_fields

serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial comparison")


def _recomputed_push(analysis) -> np.ndarray:
    problem = analysis.problem
    u = analysis.mode.x.petsc_vec
    au, bu = u.duplicate(), u.duplicate()
    problem.model.A.mult(u, au)
    problem.model.B.mult(u, bu)
    rows, nodes = problem.contact.node_rows(analysis.solution.active)
    start = u.getOwnershipRange()[0]
    r = au.array_r[rows - start] - analysis.result.critical_load_Pa * bu.array_r[rows - start]
    au.destroy()
    bu.destroy()
    order = np.argsort(nodes)  # contact_indices are sorted node numbers
    return -problem.contact.signs[nodes[order]] * r[order]


@serial
def test_contact_force_is_the_obstacle_s_push(tmp_path):
    spec = paper_case("c1", 20, 20)
    with solve(spec, MPI.COMM_SELF) as analysis:
        force = analysis.result.contact_force
        push = np.array(force.push)
        expected = _recomputed_push(analysis)
        paths = write_fields(analysis, tmp_path)
        indices = np.array(analysis.result.contact_indices)
        coordinates = np.array(analysis.result.contact_coordinates)
    assert force.unit == "N/m"
    assert len(push) == len(indices) == analysis.result.contact_nodes
    np.testing.assert_allclose(push, expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())
    assert push.min() >= -force.resolution and push.sum() > 0
    data = analysis.result.as_dict()
    assert data["contact_force"]["push"] == pytest.approx(list(push))

    pv = pytest.importorskip("pyvista")
    mesh = pv.read(str(paths[-1]))
    if isinstance(mesh, pv.MultiBlock):
        mesh = mesh.combine()
    field = np.asarray(mesh.point_data["contact_force"])
    points = np.asarray(mesh.points)[:, :2]
    at_contact = np.zeros(len(points), dtype=bool)
    for (x, y), f in zip(coordinates, push, strict=True):
        near = np.hypot(points[:, 0] - x, points[:, 1] - y) < 1e-9
        assert near.any()
        np.testing.assert_allclose(field[near], f, rtol=1e-12)
        at_contact |= near
    assert np.all(field[~at_contact] == 0.0)


@serial
def test_contact_force_scales_with_the_stiffness():
    spec = paper_case("c1", 12, 12)
    stiffer = replace(spec, material=replace(spec.material, E=2 * spec.material.E))
    pushes, loads = [], []
    for s in (spec, stiffer):
        with solve(s, MPI.COMM_SELF) as analysis:
            pushes.append(np.array(analysis.result.contact_force.push))
            loads.append(analysis.result.critical_load_Pa)
    assert loads[1] == pytest.approx(2 * loads[0], rel=1e-8)
    np.testing.assert_allclose(pushes[1], 2 * pushes[0], rtol=1e-6, atol=1e-9 * pushes[0].max())
