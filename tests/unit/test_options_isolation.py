"""A test that leaves PETSc options behind cannot change the tests after it.

PETSc's options database is global to the process. A test that puts options there and
fails before it takes them back (``with pytest.raises(...): solve(...,
eps_options=...)`` whose solve does not raise leaves the run's options in the
database: the analysis is never destroyed) changed the options of every later test:
made to leak ``{eps_tol: 0.1, eps_ncv: 3}`` by a verification that no longer raised,
``tests/unit/model/test_problem.py`` then failed two tests of ``tests/unit/la`` too.
Here two tests run in a pytest session of their own under the suite's conftest: the
first leaves an option and fails; the second must not see it.
"""

from __future__ import annotations

from pathlib import Path

from mpi4py import MPI

import pytest

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial")

LEAKING = """
from mpi4py import MPI
from petsc4py import PETSc


def test_leaves_an_option_and_fails():
    PETSc.Options()["unibuckle_isolation_eps_ncv"] = 3
    raise AssertionError("failed before taking the option back")


def test_after_it():
    assert not PETSc.Options().hasName("unibuckle_isolation_eps_ncv")
"""


def test_a_leaked_option_is_taken_back_and_reported(pytester):
    pytester.makeconftest((Path(__file__).parents[1] / "conftest.py").read_text())
    pytester.makepyfile(test_leak=LEAKING)
    result = pytester.runpytest_inprocess("-p", "no:cacheprovider", "-q")
    result.assert_outcomes(passed=1, failed=1, errors=1)
    result.stdout.fnmatch_lines(["*left PETSc options behind*unibuckle_isolation_eps_ncv*"])
