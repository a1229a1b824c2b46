"""Absurd magnitudes are refused at input (exit 2), naming the key and the allowed range.

Each value below passed the schema and failed in the solve with exit 3 (a PETSc, MUMPS
or SLEPc error, or no certified state): E = 1e300 Pa, a shear correction of 1e300, an
edge stress of -1e308, t = 1e-9 m on a plate 0.1 m wide, a plate 1e300 m long, a
tensionless foundation of 1e20 N/m^3 on the paper's plate, tau = 1e-300; a fixed
tension of 1e300 Pa was refused as a load that "buckles the plate". The ranges
(``spec/material.py``, ``spec/plate.py``, ``spec/problem.py``, ``spec/solver.py``) are
an engineer's, with their reasons in the schema's descriptions; the values at their
ends load.

Under mpiexec every rank refuses the input with the same status; the message is printed
once, by rank 0 (``cli.main``), so only rank 0 reads it.
"""

from __future__ import annotations

import re

from mpi4py import MPI

import pytest

from unibuckle_fenicsx.cli import EXIT_BAD_INPUT, main
from unibuckle_fenicsx.spec import problem_from_dict


@pytest.mark.parametrize(
    "setting, match",
    [
        ("material.E=1e300", r"material\.E must lie in \[1000, 1e\+13\] Pa, got 1e\+300"),
        ("material.E=1e-300", r"material\.E must lie in \[1000, 1e\+13\] Pa, got 1e-300"),
        (
            "material.shear_correction=1e300",
            r"material\.shear_correction must lie in \[0\.001, 1\], got 1e\+300",
        ),
        (
            "edges.left.normal_stress=-1e308",
            r"edges\.left\.normal_stress = -1e\+308 must lie in \[-1e\+12, 1e\+12\]",
        ),
        (
            "edges.left.fixed_normal_stress=1e300",
            r"edges\.left\.fixed_normal_stress = 1e\+300 must lie in \[-1e\+12, 1e\+12\] Pa",
        ),
        (
            "plate.thickness=1e-9",
            r"plate\.thickness = 1e-09 m is 1e-08 times the plate's smaller side 0\.1 m: "
            r"plate\.thickness must be at least 1e-07 times it \(t/b in \[1e-07, 0\.5\]\)",
        ),
        (
            "plate.corners=[[0,0],[1e300,1e300]]",
            r"plate\.corners has a coordinate of magnitude 1e\+300 m and a smaller side of "
            r"1e\+300 m: coordinates must lie "
            r"in \[-1e\+06, 1e\+06\] m",
        ),
        (
            "obstacle.foundation_stiffness=1e20",
            # K = 1e20 * 0.1^4 / (pi^4 * 1e9 * 0.006^3 / 12) = 5.70e12
            r"obstacle\.foundation_stiffness = 1e\+20 N/m\^3 is K = k_f b\^4/\(pi\^4 D\) = "
            r"5\.7e\+12 .* needs K <= 1e\+12",
        ),
        ("solver.tau=1e-300", r"solver\.tau must lie in \[1e-12, 0\.01\], got 1e-300"),
    ],
)
def test_an_absurd_magnitude_is_refused_before_any_solve(tmp_path, capsys, setting, match):
    # The paper's plate, 0.2 x 0.1 m, t = 6 mm, E = 1 GPa, its zone c1.
    args = ["solve", "--case", "c1", "--nx", "6", "--ny", "4", "-q", "--set", setting]
    args += ["--output", str(tmp_path)]
    assert main(args) == EXIT_BAD_INPUT  # on every rank
    if MPI.COMM_WORLD.rank == 0:  # errors are printed on rank 0
        err = capsys.readouterr().err
        assert "lambda_c" not in err  # refused before the solve
        assert re.search(match, err), err


def test_the_ranges_ends_load():
    """The ends of each range are accepted (the ranges are closed)."""
    base = {
        "plate": {"corners": [[0.0, 0.0], [0.2, 0.1]], "thickness": 0.006},
        "material": {"E": 1.0e9, "nu": 0.3},
    }
    ends = [
        {"material": {"E": 1.0e3, "nu": 0.3}},
        {"material": {"E": 1.0e13, "nu": 0.3}},
        {"material": {"E": 1.0e9, "nu": 0.3, "shear_correction": 0.001}},
        {"material": {"E": 1.0e9, "nu": 0.3, "shear_correction": 1.0}},
        {"plate": {"corners": [[0.0, 0.0], [0.2, 0.1]], "thickness": 1e-8}},  # t/b = 1e-7
        {"plate": {"corners": [[-1e6, 0.0], [1e6, 0.1]], "thickness": 0.006}},
        {"edges": {"left": {"normal_stress": -1e12}, "right": {"normal_stress": [-1e12, 1e12]}}},
        {"solver": {"tau": 1e-12}},
    ]
    for change in ends:
        spec = problem_from_dict({**base, **change})
        assert spec is not None
