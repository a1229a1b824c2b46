r"""A section's mode carried between section meshes (:mod:`unibuckle_fenicsx.model.shell.prolong`).

Expected values are the fields themselves, evaluated at the fine nodes from their
coordinates: a field bilinear in the unrolled (x, s) on each face of a box, in global
components, and on a tube a radial displacement :math:`f(x)\,e_r(\varphi)` with f linear
(its Cartesian components are not bilinear in s, its frame components are); the carried
mode's constrained components must be :math:`n_{in}\cdot u` of that field at the fine
nodes.
"""

from __future__ import annotations

from mpi4py import MPI

import dolfinx

import numpy as np
import pytest

from unibuckle_fenicsx.model.shell.core import perimeter_coordinate
from unibuckle_fenicsx.model.shell.prolong import SectionProlongation
from unibuckle_fenicsx.model.shell.section import SectionParameters, build_section


def _params(shape, size, **changes):
    geometry = (
        {"width": 0.2, "depth": 0.1, "thickness": 0.002, "length": 0.3}
        if shape == "box"
        else {"diameter": 0.2, "thickness": 0.002, "length": 0.2}
    )
    return SectionParameters(
        shape, E=2.1e11, nu=0.3, mesh_size=size, ends="simply_supported", core=True,
        **{**geometry, **changes},
    )  # fmt: skip


def _field(section, X):
    """(n, 6) global nodal values of the test field at the points X (n, 3)."""
    x = X[:, 0]
    out = np.zeros((X.shape[0], 6))
    if section.parameters.shape == "tube":
        phi = np.arctan2(X[:, 2], X[:, 1])
        f = 1.0 + 2.0 * x
        out[:, 1], out[:, 2] = f * np.cos(phi), f * np.sin(phi)  # radial
        out[:, 0] = 0.5 - x  # axial
        out[:, 3] = 3.0 * x  # a rotation about the axis
        return out
    # Linear in s along each face (corner values 0, 1, 3, 2), bilinear in (x, s) there.
    p = section.parameters
    corners = np.cumsum([0.0, p.depth, p.width, p.depth, p.width])
    g = np.interp(perimeter_coordinate(section.mesh, X.T), corners, [0.0, 1.0, 3.0, 2.0, 0.0])
    out[:, 0] = 1.0 + x * g
    out[:, 1] = 2.0 * g - x
    out[:, 2] = x + 0.5 * g
    out[:, 4] = x * g
    return out


def _mode_of_field(section):
    """The field at the section's nodes, in its pencil's basis (a Function)."""
    W = section.problem.pencil.W
    X = W.tabulate_dof_coordinates()
    g = dolfinx.fem.Function(W)
    g.x.array[:] = _field(section, X).reshape(-1)
    u = section.problem.new_mode("u")
    section.problem.pencil.to_rotated(g.x.petsc_vec, u.x.petsc_vec)
    u.x.scatter_forward()
    return u


@pytest.mark.parametrize(
    ("shape", "coarse", "fine", "changes"),
    [
        ("box", 0.1, 0.05, {}),  # nested
        ("box", 0.06, 0.025, {}),  # not nested: 4 and 8 / 2 and 4 cells per face
        ("box", 0.1, 0.05, {"corner_cell": 0.01}),  # graded rings
        ("tube", 0.08, 0.04, {}),
        ("tube", 0.07, 0.03, {}),
    ],
)
def test_a_field_of_the_interpolants_space_is_carried_exactly(shape, coarse, fine, changes):
    comm = MPI.COMM_WORLD
    with (
        build_section(_params(shape, coarse, **changes), comm) as sc,
        build_section(_params(shape, fine, **changes), comm) as sf,
    ):
        carry = SectionProlongation(sc.problem, sf.problem)
        out = carry.mode(_mode_of_field(sc))
        expected = _mode_of_field(sf)
        scale = np.abs(expected.x.array).max()
        assert np.abs(out.x.array - expected.x.array).max() <= 1e-12 * scale
        # The constrained directions: n_in . u of the field at the fine nodes.
        rows = sf.constraints.owned_local_dofs
        X = sf.constraints.coordinates[sf.constraints.owned_positions]
        n = sf.constraints.normals[sf.constraints.owned_positions]
        want = np.einsum("ij,ij->i", n, _field(sf, X)[:, :3])
        assert np.abs(out.x.array[rows] - want).max() <= 1e-12 * scale


def test_the_two_meshes_must_be_of_one_section():
    comm = MPI.COMM_WORLD
    with (
        build_section(_params("box", 0.1), comm) as sc,
        build_section(_params("box", 0.05, length=0.4), comm) as sf,
    ):
        with pytest.raises(ValueError, match="one section"):
            SectionProlongation(sc.problem, sf.problem)
