r"""A tube's modes of few circumferential waves: the geometric stiffness against Sanders'.

The reference (:func:`support.cylinders.sanders_stress`) is the classical critical stress
of a simply supported cylinder under axial load in m axial half-waves and n
circumferential waves, the 3 × 3 characteristic determinant of Sanders' first-order shell
equations (NASA TR R-24, 1959; Brush & Almroth, 1975, chapter 5) minimised over (m, n),
checked here against two closed forms: with Donnell's shallow-shell strains and load its
minimum is the classical :math:`\sigma_{cl} = Et/(R\sqrt{3(1-\nu^2)})` (Timoshenko &
Gere, section 11.4); a long tube's n = 2 mode, semi-inextensional
(:math:`\varepsilon_\theta = \gamma = 0`), tends to :math:`(n^2 - 1)/(n^2 + 1)\,\sigma_{cl}`
= 0.6 σ_cl (bending :math:`(n^2-1)^2 D/R^4` against the axial stretching, load term
:math:`1 + 1/n^2`).

The section's shell follows Sanders' stiffness (its Donnell option converges to the
reference with Donnell's load term: 0.9769, 0.9098 at n = 4, 3 on 3 mm cells against
0.9677, 0.9048), so its geometric stiffness must be the full one: Donnell's put the
n = 2 mode of a 0.5 m tube (R/t = 50, simply supported ends) at 0.790 σ_cl against the
reference's 0.616 (26 % high), and the former switch between the two at an Euler stress
of 4 σ_cl made the clamped tube's load step by 11 % between L = 1.0 and 1.02 m.
"""

from __future__ import annotations

import math

from mpi4py import MPI

import pytest

from support.cylinders import sanders_stress
from unibuckle_fenicsx import SectionParameters, solve_section
from unibuckle_fenicsx.errors import InputError

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial sections")

E, NU, R, T = 2.1e11, 0.3, 0.05, 0.001
SIGMA_CL = E * T / (R * math.sqrt(3.0 * (1.0 - NU**2)))


def _tube(length: float, size: float, ends: str = "simply_supported") -> SectionParameters:
    return SectionParameters(
        "tube", diameter=2 * R, thickness=T, length=length, E=E, nu=NU, mesh_size=size,
        ends=ends,
    )  # fmt: skip


def test_the_reference_gives_the_classical_values():
    # Donnell's strains and load: sigma_cl (Timoshenko & Gere 11.4) at any moderate length.
    assert sanders_stress(R, T, 0.5, E, NU, donnell=True)[0] == pytest.approx(SIGMA_CL, rel=1e-3)
    # A long tube's n = 2 mode tends to (n^2 - 1)/(n^2 + 1) sigma_cl = 0.6 (semi-inextensional).
    sigma, n = sanders_stress(R, T, 0.5, E, NU)
    assert n == 2
    assert sigma / SIGMA_CL == pytest.approx(0.6, abs=0.02)


@pytest.mark.parametrize(
    ("length", "size", "waves"),
    [(0.5, 0.008, 2), (0.25, 0.004, 3), (0.1, 0.003, 4)],
)
def test_a_tube_s_few_wave_modes_follow_sanders_equations(length, size, waves):
    # Reference / sigma_cl: 0.6160 (n = 2), 0.8096 (n = 3), 0.9046 (n = 4). The package
    # (full): 0.6251, 0.8175, 0.9124; Donnell's load term gave 0.7902, 0.9148, 0.9769.
    reference, n = sanders_stress(R, T, length, E, NU)
    assert n == waves
    with solve_section(_tube(length, size), MPI.COMM_WORLD) as analysis:
        load = analysis.result.critical_load_Pa
    assert load == pytest.approx(reference, rel=0.02), (load / SIGMA_CL, reference / SIGMA_CL)


def test_a_clamped_tube_s_load_is_continuous_in_its_length():
    # R/t = 50, 8 mm cells: at L = 1.0 m the Euler stress pi^2 E R^2/(2 (L/2)^2) is 4.07
    # sigma_cl, at 1.02 m 3.91: the former switch gave 1.001 and 0.888 sigma_cl (n = 3).
    loads = []
    for length in (1.0, 1.02):
        with solve_section(_tube(length, 0.008, "clamped"), MPI.COMM_WORLD) as analysis:
            loads.append(analysis.result.critical_load_Pa)
    assert loads[1] == pytest.approx(loads[0], rel=0.01), [x / SIGMA_CL for x in loads]


def test_the_former_switch_is_refused():
    with pytest.raises(InputError, match="geometric must be one of"):
        SectionParameters(
            "tube", diameter=0.1, thickness=T, length=0.5, E=E, nu=NU, mesh_size=0.01,
            geometric="auto",
        )  # fmt: skip
