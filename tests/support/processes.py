"""Subprocesses of the tests: ``mpiexec`` runs of the MPI scripts, a paused sweep."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

from support.paths import ROOT


def mpiexec() -> str:
    """The venv's mpiexec (the mpich wheel's), else the one on the path."""
    return shutil.which("mpiexec", path=str(Path(sys.executable).parent)) or "mpiexec"


def run_mpi(script: str | Path, nprocs: int, *args: str) -> str:
    """Run ``python script args`` under the venv's mpiexec; return stdout, raise on failure.

    No timeout: a test's outcome does not depend on the machine's load (a hang shows as a
    run that does not end, for the CI job's own limit to stop).
    """
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    proc = subprocess.run(
        [mpiexec(), "-n", str(nprocs), sys.executable, str(script), *args],
        capture_output=True,
        text=True,
        env=env,
        cwd=ROOT,
    )
    if proc.returncode != 0:
        raise AssertionError(
            f"mpiexec -n {nprocs} {script} failed ({proc.returncode}):\n"
            f"{proc.stdout}\n{proc.stderr}"
        )
    return proc.stdout


#: The console script's sweep, paused after its first point's line: the second point
#: waits, interruptibly, for a signal (Ctrl-C, a kill) to end the process, and says so by
#: writing the file argv[1]. A test that interrupts a sweep mid-way then does not race
#: the sweep's speed, which depends on the machine's load.
PAUSED_SWEEP = """
import sys
import time
from pathlib import Path

import unibuckle_fenicsx.sweep as sweep
from unibuckle_fenicsx import cli

original = sweep.solve_point
calls = []


def solve_point(spec, comm):
    calls.append(spec)
    if len(calls) == 2:
        Path(sys.argv[1]).write_text("paused")
        while True:
            time.sleep(0.05)
    return original(spec, comm)


sweep.solve_point = solve_point
sys.exit(cli.main(sys.argv[2:]))
"""


def paused_sweep(args: list[str], cwd: Path, **popen: object) -> subprocess.Popen:
    """Start ``unibuckle sweep args`` (:data:`PAUSED_SWEEP`); return once it is paused.

    The first point's line is then in the --json file and the second point has started.
    """
    script, marker = cwd / "paused_sweep.py", cwd / "paused"
    script.write_text(PAUSED_SWEEP)
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    proc = subprocess.Popen(  # type: ignore[call-overload]
        [sys.executable, str(script), str(marker), "sweep", *args], env=env, cwd=cwd, **popen
    )
    while not marker.exists():
        assert proc.poll() is None, "the sweep ended before its second point"
        time.sleep(0.02)
    return proc
