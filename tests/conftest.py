"""Shared fixtures: teardown, the random active problems, nothing built before a refusal."""

from __future__ import annotations

import gc
import os
import shutil
import subprocess
import sys
from pathlib import Path

from mpi4py import MPI

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(autouse=True)
def _collective_teardown():
    """Run collective PETSc destructors together on every rank (dolfinx conftest)."""
    yield
    gc.collect()
    MPI.COMM_WORLD.Barrier()


@pytest.fixture(scope="session")
def active_specs():
    """The seeded random problems whose obstacle is active (families.active_family)."""
    from families import active_family

    return active_family()[0]


@pytest.fixture
def nothing_built(monkeypatch):
    """Fail the test if a mesh is built or a solve starts: refusals come first."""
    import unibuckle_fenicsx.analysis
    import unibuckle_fenicsx.model.problem
    import unibuckle_fenicsx.nonlinear

    # Modules that bind analysis.solve when imported: imported here, before it is
    # replaced (imported while it is, they would keep the replacement for the session's
    # later tests), and their names replaced for this test only.
    import unibuckle_fenicsx.nonlinear.path
    import unibuckle_fenicsx.viz.study

    def refuse(*args, **kwargs):
        raise AssertionError("work started before the input was refused")

    monkeypatch.setattr(unibuckle_fenicsx.analysis, "solve", refuse)
    monkeypatch.setattr(unibuckle_fenicsx.nonlinear.path, "solve_linear", refuse)
    monkeypatch.setattr(unibuckle_fenicsx.viz.study, "solve", refuse)
    monkeypatch.setattr(unibuckle_fenicsx.model.problem, "build_plate_mesh", refuse)
    monkeypatch.setattr(unibuckle_fenicsx.nonlinear, "solve_nonlinear", refuse)


def run_mpi(script: str | Path, nprocs: int, *args: str, timeout: float = 600) -> str:
    """Run ``python script args`` under the venv's mpiexec; return stdout, raise on failure."""
    mpiexec = shutil.which("mpiexec", path=str(Path(sys.executable).parent)) or "mpiexec"
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    proc = subprocess.run(
        [mpiexec, "-n", str(nprocs), sys.executable, str(script), *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
        cwd=ROOT,
    )
    if proc.returncode != 0:
        raise AssertionError(
            f"mpiexec -n {nprocs} {script} failed ({proc.returncode}):\n"
            f"{proc.stdout}\n{proc.stderr}"
        )
    return proc.stdout
