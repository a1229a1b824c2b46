"""A section's core as a tensionless foundation, up to concrete and beyond.

A square box (faces 0.1 m, t = 2 mm steel, 0.2 m long, 25 mm cells: 4 across a face,
coarse but fast) filled with a core of modulus k_f (N/m^3). Independent limits: the
hollow box (k_f -> 0) and the rigid core (k_f -> infinity), both solved as such; the
load rises with k_f (the spring quotient grows pointwise) and never exceeds the rigid
core's (the rigid core's mode presses no spring: its quotient is its load). Concrete,
E_c = 30 GPa over the half width the wall's bulge strains (0.05 m), is k_f = 6e11.
"""

from __future__ import annotations

import itertools

from mpi4py import MPI

import pytest

from unibuckle_fenicsx.model.shell.section import SectionParameters
from unibuckle_fenicsx.section_analysis import solve_section

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial sections")


def _box(**changes):
    base = {
        "width": 0.1, "depth": 0.1, "thickness": 0.002, "length": 0.2, "E": 2.1e11,
        "nu": 0.3, "mesh_size": 0.025, "ends": "simply_supported", "core": True,
    }  # fmt: skip
    return SectionParameters("box", **{**base, **changes})


def _load(parameters):
    with solve_section(parameters, MPI.COMM_WORLD) as analysis:
        if parameters.foundation_stiffness is not None:
            assert analysis.result.method == "foundation"
            assert analysis.certificate is not None and analysis.certificate.kkt
        return analysis.result.critical_load_Pa


@pytest.mark.filterwarnings("ignore")
def test_a_concrete_core_lies_between_the_hollow_box_and_the_rigid_core():
    """k_f = 1e10, 6e11 (concrete), 1e16 N/m^3 against the hollow box and the rigid core.

    Measured: 4.6e-2, 1.0e-3 and 6.5e-8 below the rigid core; at 1e16 the gap is k_f's
    inverse times about 6.5e8 N/m^3 (1/k_f, the springs of the touch-down nodes a penalty).
    """
    hollow = _load(_box(core=False))
    rigid = _load(_box())
    loads = [_load(_box(foundation_stiffness=kf)) for kf in (1e10, 6e11, 1e16)]
    assert hollow < loads[0], (hollow, loads)
    assert all(x < y for x, y in itertools.pairwise(loads)), loads
    assert loads[-1] <= rigid * (1 + 1e-9), (loads, rigid)
    assert loads[-1] == pytest.approx(rigid, rel=1e-6), (loads, rigid)
    assert loads[1] == pytest.approx(rigid, rel=1e-2), (loads, rigid)
