"""Shared fixtures: teardown, PETSc options, random problems, nothing built, thin plate.

What the tests share that is not a fixture (references, families, subprocesses) is the
package ``tests/support/``.
"""

from __future__ import annotations

import gc
import os

# Before numpy, MUMPS or BLAS load (nothing imports them before this file): one thread,
# as `make test` runs, unless the caller chose. Threaded BLAS reductions change the last
# bits between runs, and some tests compare a fresh process's result with this one's
# to the bit.
os.environ.setdefault("OMP_NUM_THREADS", "1")

from mpi4py import MPI

import pytest


@pytest.fixture(scope="module", autouse=True)
def _long_lived_objects_frozen():
    """Keep what outlives a module's tests out of every later collection (``gc.freeze``).

    The teardown below collects after every test, and a full collection walks every
    object the collector tracks: the imported DOLFINx, UFL and SciPy and the collected
    test modules, so that the teardowns of a module of small tests took about as long
    as its tests (docs/history/2026-12-02b-testspeed.md). What survives a collection at
    a module's start lives on (modules, session fixtures, caches): it is frozen, and
    each test's collection walks only what was made since. Frozen objects are still
    freed by their reference counts; the session's end unfreezes them.
    """
    gc.collect()
    MPI.COMM_WORLD.Barrier()
    gc.freeze()
    yield


def pytest_sessionfinish(session, exitstatus):
    """Give back to the collector what the modules froze (see above)."""
    gc.unfreeze()


@pytest.fixture(autouse=True)
def _collective_teardown(_petsc_options_restored):
    """Run collective PETSc destructors together on every rank (dolfinx conftest).

    Before the options are checked: an object's destructor may take its own back.
    """
    yield
    gc.collect()
    MPI.COMM_WORLD.Barrier()


@pytest.fixture(autouse=True)
def _petsc_options_restored():
    """Take back the PETSc options a test left (the database is global), and say so.

    A test that leaves options behind is an error of that test only: the options are
    removed before the next test starts, so its failure cannot fail the tests after it.
    """
    from support.options import options_restored

    with options_restored() as leaked:
        yield
    if leaked:
        pytest.fail(f"the test left PETSc options behind (taken back): {leaked}")


@pytest.fixture(scope="session")
def active_specs():
    """The seeded random problems whose obstacle is active (support.families.active_family)."""
    from support.families import active_family

    return active_family()[0]


@pytest.fixture
def nothing_built(monkeypatch):
    """Fail the test if a mesh is built or a solve starts: refusals come first."""
    import unibuckle_fenicsx.analysis
    import unibuckle_fenicsx.model.build
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
    monkeypatch.setattr(unibuckle_fenicsx.model.build, "build_plate_mesh", refuse)
    monkeypatch.setattr(unibuckle_fenicsx.nonlinear, "solve_nonlinear", refuse)


@pytest.fixture
def thin_plate():
    """The thin 3:1 plate against a whole-plate obstacle (:func:`support.plates.thin_plate`).

    Called as ``thin_plate(name, nx, ny, **kw)``: the interior-point route's, the split
    and low-rank certificates' and the sweep's and MPI tests' thin plate.
    """
    from support.plates import thin_plate

    return thin_plate
