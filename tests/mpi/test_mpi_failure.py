"""An error on one rank ends the run on every rank: one message, one exit status.

``tests/mpi/one_rank_fails.py`` forces an error on one rank where the free eigen solve
starts, a collective call: the other rank enters it and would wait there for ever (the
run hung, the error printed by nobody when it was rank 1's). The run must end on its
own (there is no timeout here: a hang fails by not ending), with the error message
printed once and the exit status of its kind (2 bad input, 1 a bug); an error on every
rank ends it the same way without aborting.
"""

from __future__ import annotations

import os
import subprocess
import sys

from mpi4py import MPI

import pytest

from support.paths import MPI_SCRIPTS, ROOT
from support.processes import mpiexec
from unibuckle_fenicsx.cli import BUG_REPORT, EXIT_BAD_INPUT, EXIT_BUG

SCRIPT = MPI_SCRIPTS / "one_rank_fails.py"
ARGS = ("solve", "--case", "c1", "--nx", "8", "--ny", "8")

pytestmark = [
    pytest.mark.mpi,
    pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="launches mpiexec itself"),
]


def _run(kind: str, rank: int) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    return subprocess.run(
        [mpiexec(), "-n", "2", sys.executable, str(SCRIPT), kind, str(rank), *ARGS],
        capture_output=True, text=True, env=env, cwd=ROOT,
    )  # fmt: skip


@pytest.mark.parametrize("rank", [1, 0])
def test_an_input_error_on_one_rank_ends_both_with_one_message(rank):
    proc = _run("input", rank)
    assert proc.returncode == EXIT_BAD_INPUT, proc.stderr
    assert proc.stderr.count("unibuckle: error: ") == 1, proc.stderr
    assert f"unibuckle: error: an error forced on rank {rank}\n" in proc.stderr
    assert proc.stdout == ""


def test_a_bug_on_one_rank_ends_both_with_one_traceback():
    proc = _run("bug", 1)
    assert proc.returncode == EXIT_BUG, proc.stderr
    assert proc.stderr.count("Traceback (most recent call last)") == 1, proc.stderr
    assert proc.stderr.count(BUG_REPORT) == 1 and "a bug forced on rank 1" in proc.stderr


def test_an_error_on_every_rank_ends_without_an_abort():
    """Ranks that fail together agree: rank 0's message, exit 2 on both, no MPI_Abort."""
    proc = _run("input", -1)
    assert proc.returncode == EXIT_BAD_INPUT, proc.stderr
    assert proc.stderr == "unibuckle: error: an error forced on rank 0\n", proc.stderr
