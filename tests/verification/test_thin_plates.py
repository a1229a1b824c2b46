r"""Thin plates other than the paper's against thin-plate (Kirchhoff) values.

A 0.3 x 0.1 m plate (a/b = 3), t = 1e-4 m (t/b = 1e-3), the obstacle over the whole
plate, under five edge conditions and loads. The buckling coefficient
k = N b^2/(pi^2 D) must converge, from above and at about rate h^2, to:

- SSSS, uniaxial: 9/2, and loaded edges clamped: 16/3. Closed forms of the thin plate
  with w = f(x) sin(pi y / b), f'''' - (2 - k) pi^2 f'' + pi^4 f = 0: a buckle against a
  simply supported loaded edge, ending in a touch-down f = f' = f'' = 0, is
  f = 2 sin(p x)(1 + cos(p x)) with k = 2 + 2 + 1/2; a buckle between two touch-downs is
  f = cos^3(p x) with k = 2 + 3 + 1/3 (the long plate buckles into such lobes).
- unloaded edges clamped 8.0996, CCCC 9.9848, SSSS under shear 6.671: an independent
  Kirchhoff computation (C^1 bicubic Bogner-Fox-Schmit elements, its own cone solver, no
  shared code; 144 x 48 elements, 72 x 24 for shear), the README's "Every plate" table.

Each case is solved on 45x15 and 90x30 (the README's benchmark mesh); at t/b = 1e-3 the
Reissner-Mindlin plate differs from the Kirchhoff one far less than the discretisation
error of these meshes (0.2-0.8 % at 90x30). Slow (minutes): ``-m convergence``.
"""

from __future__ import annotations

from mpi4py import MPI

import pytest

from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.spec import ObstacleSpec
from unibuckle_fenicsx.spec.cases import plate_case

#: name -> (supports, load, thin-plate k)
CASES = {
    "ssss": ("simply_supported", "uniaxial", 9 / 2),
    "cs": ({"left": "clamped", "right": "clamped"}, "uniaxial", 16 / 3),
    "sc": ({"bottom": "clamped", "top": "clamped"}, "uniaxial", 8.0996),
    "cccc": ("clamped", "uniaxial", 9.9848),
    "shear": ("simply_supported", "shear", 6.671),
}


def _k(name: str, nx: int, ny: int) -> float:
    supports, load, _ = CASES[name]
    spec = plate_case(
        name,
        length=0.3,
        width=0.1,
        thickness=1e-4,
        supports=supports,
        load=load,
        nx=nx,
        ny=ny,
        zone=ObstacleSpec(zone="all"),
    )
    with solve(spec, MPI.COMM_WORLD) as analysis:
        assert analysis.certificate is not None and analysis.certificate.kkt
        return analysis.problem.buckling_coefficient(analysis.result.critical_load_Pa)


@pytest.mark.convergence
@pytest.mark.parametrize("name", list(CASES))
def test_thin_plate_converges_to_kirchhoff(name):
    k_ref = CASES[name][2]
    coarse, fine = _k(name, 45, 15), _k(name, 90, 30)
    # From above (the discrete problem is stiffer), within the reference's own accuracy
    # (1e-4) at worst, and the error shrinks as h^2 would (a factor 4; at least 2.5).
    assert coarse > fine > k_ref * (1 - 1e-4), (coarse, fine, k_ref)
    assert fine - k_ref < (coarse - k_ref) / 2.5, (coarse, fine, k_ref)
    assert abs(fine - k_ref) / k_ref < 1e-2, (fine, k_ref)
