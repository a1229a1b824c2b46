"""Command line: ``unibuckle solve``, ``sweep``, ``nonlinear`` and ``schema``.

One problem, a grid of them, and the load path of the imperfect plate:

``unibuckle solve --case c1 --nx 20 --ny 20 --json out.json``;
``unibuckle sweep --config base.toml --vary plate.length=0.1:0.4:7 --json out.jsonl``;
``unibuckle nonlinear --case c1 --nx 20 --ny 20 --imperfection 1e-3 --json out.json``.

Unrecognised ``-prefix_option value`` pairs are passed to PETSc, e.g.
``-unibuckle_eps_view`` or ``-unibuckle_prestress_ksp_view``.

This module is the run: parse (:mod:`.flags`), check the outputs (:mod:`.outputs`),
run one subcommand (:mod:`.solve`, :mod:`.sweep`, :mod:`.nonlinear`, :mod:`.schema`;
the problem they read: :mod:`.problem`) and end the run on every rank with one message
and one exit status (:mod:`.status`, :class:`~unibuckle_fenicsx.outcome.Outcome`).
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import sys
import traceback
from collections.abc import Iterator, Sequence
from typing import Any, NoReturn

from unibuckle_fenicsx.cli.flags import build_parser
from unibuckle_fenicsx.cli.nonlinear import nonlinear_command
from unibuckle_fenicsx.cli.outputs import check_outputs
from unibuckle_fenicsx.cli.schema import schema_command
from unibuckle_fenicsx.cli.solve import solve_command
from unibuckle_fenicsx.cli.status import (
    BROKEN_PIPE,
    BUG_REPORT,
    EXIT_BAD_INPUT,
    EXIT_BUG,
    EXIT_INTERRUPTED,
    EXIT_NOT_CERTIFIED,
    EXIT_OK,
    PENDING,
    ignore_broken_pipe,
    report_failure,
    stdout_closed,
    with_broken_pipe,
)
from unibuckle_fenicsx.cli.sweep import sweep_command
from unibuckle_fenicsx.errors import NumericalError
from unibuckle_fenicsx.outcome import Outcome, in_chain, petsc_failure

__all__ = [
    "BUG_REPORT",
    "EXIT_BAD_INPUT",
    "EXIT_BUG",
    "EXIT_INTERRUPTED",
    "EXIT_NOT_CERTIFIED",
    "EXIT_OK",
    "build_parser",
    "main",
]


@contextlib.contextmanager
def _logging(verbose: int, quiet: bool, rank: int) -> Iterator[None]:
    """The run's log on standard error; the caller's logging set back afterwards.

    ``main()`` may be called in-process (a notebook, a test): the handler it installs
    holds the ``sys.stderr`` of this run, which may be closed after it. Every rank
    computes the same warnings (from values reduced over the ranks): rank 0 prints the
    log, the others only their errors.
    """
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(levelname)s %(name)s: %(message)s"))
    handler.setLevel(logging.NOTSET if rank == 0 else logging.ERROR)
    root = logging.getLogger()
    progress = logging.getLogger("unibuckle_fenicsx.progress")
    handlers, root_level, progress_level = root.handlers[:], root.level, progress.level
    root.handlers[:] = [handler]
    root.setLevel([logging.WARNING, logging.INFO, logging.DEBUG][min(verbose, 2)])
    quiet = quiet or rank != 0
    progress.setLevel(logging.WARNING if quiet else min(root.level, logging.INFO))
    try:
        yield
    finally:
        root.handlers[:] = handlers
        root.setLevel(root_level)
        progress.setLevel(progress_level)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    parser, commands = build_parser()
    args, rest = parser.parse_known_args(argv)
    unknown = [a for a in rest if a.startswith("--")]
    if unknown:  # the subcommand's usage line, not the top-level one
        commands[args.command].error(f"unrecognized arguments: {' '.join(unknown)}")

    BROKEN_PIPE.clear()
    if args.command == "schema":
        return with_broken_pipe(schema_command(args))

    from mpi4py import MPI  # before petsc4py: loads libmpi

    comm = MPI.COMM_WORLD
    PENDING.clear()
    # The outputs first: a path that cannot be written is refused before PETSc, DOLFINx
    # and the problem are even loaded.
    problem = comm.bcast(check_outputs(args) if comm.rank == 0 else None, root=0)
    if problem is not None:
        if comm.rank == 0:
            print(f"unibuckle: error: {problem}", file=sys.stderr)
        return EXIT_BAD_INPUT
    with _logging(args.verbose, args.quiet, comm.rank):
        ending = _Ending(comm)
        status, raised = _guarded_run(args, rest, comm)
        return with_broken_pipe(ending.finish(status, raised or bool(PENDING)))


#: Seconds between the last line a failed rank writes and its ``MPI_Abort``. A rank's
#: output reaches the terminal through the process manager (hydra's proxy reads the
#: rank's pipe and forwards it to mpiexec); an abort kills every process at once, and
#: what the proxy had not yet read is lost. The pause lets it read.
ABORT_GRACE_S = 1.0


def _abort(comm: Any, status: int, message: str | None) -> NoReturn:
    """Print ``message`` and end every rank of ``comm`` with ``status`` (``MPI_Abort``)."""
    import time

    if message is not None:
        print(f"unibuckle: error: {message}", file=sys.stderr, flush=True)
    sys.stdout.flush()
    time.sleep(ABORT_GRACE_S)
    comm.Abort(status)
    os._exit(status)  # MPI_Abort does not return; had it, this process ends all the same


def _guarded_run(args: argparse.Namespace, rest: Sequence[str], comm: Any) -> tuple[int, bool]:
    """The exit status of :func:`run_command`, and whether this rank raised (it may be alone)."""
    try:
        return run_command(args, rest, comm), False
    except (KeyboardInterrupt, Exception) as err:
        if _broken_pipe(err):  # the reader of stdout stopped (| head): end quietly
            return stdout_closed(), True
        outcome = Outcome.of(err)
        if outcome is Outcome.INTERRUPTED:
            return _interrupted(args, comm), True
        if outcome is Outcome.BUG:
            traceback.print_exc()  # on every rank that fails: the bug may be on one
            print(BUG_REPORT, file=sys.stderr, flush=True)
            return outcome.exit_status, True
        return report_failure(comm, _message(err, rest), outcome.exit_status), True


#: Seconds a rank that failed waits for the others at the end of the run before it
#: aborts it: ranks that fail together (a collective check, a collective solve) arrive
#: within a fraction of this; a rank that fails alone leaves the others blocked in their
#: next collective call, which only MPI_Abort ends.
FAILURE_WAIT_S = 5.0


class _Ending:
    """The end of a run on every rank: one message, one exit status, no rank left waiting.

    Every rank ends the run with one collective call (on a duplicate of the communicator,
    so that no message of the computation can match it): a reduction that finds the
    first rank with a non-zero status. That rank prints its error message; every rank
    returns its status. A rank that failed (an exception, an error message) does not
    block on it: if the others do not arrive within :data:`FAILURE_WAIT_S` (they wait in a
    collective call of the computation that the failed rank will not make), it prints its
    message and aborts the run with its status (``MPI_Abort``: mpiexec ends every rank and
    exits with that status). Serial runs print the message and return.
    """

    def __init__(self, comm: Any) -> None:
        self.comm = comm
        self.dup = comm.Dup() if comm.size > 1 else None  # collective

    def finish(self, status: int, failed: bool) -> int:
        """The run's exit status on this rank (collective, or an abort: see the class)."""
        import time

        from mpi4py import MPI

        import numpy as np

        message = PENDING[-1][1] if PENDING else None
        if self.dup is None:
            if message is not None:
                print(f"unibuckle: error: {message}", file=sys.stderr, flush=True)
            return status
        comm, dup = self.comm, self.dup
        mine = np.array([comm.rank if status != EXIT_OK else comm.size], dtype=np.int64)
        first = np.empty(1, dtype=np.int64)
        request = dup.Iallreduce(mine, first, op=MPI.MIN)
        if failed:
            waited = time.monotonic() + FAILURE_WAIT_S
            while not request.Test():
                if time.monotonic() > waited:
                    _abort(comm, status, message)
                time.sleep(0.01)
        else:
            request.Wait()
        leader = int(first[0])
        if leader < comm.size:
            status = dup.bcast(status, root=leader)
            if comm.rank == leader and message is not None:
                print(f"unibuckle: error: {message}", file=sys.stderr, flush=True)
        dup.Free()
        return int(status)


def _interrupted(args: argparse.Namespace, comm: Any) -> int:
    """Say what an interrupt (Ctrl-C) left, on rank 0; the exit status."""
    # What the interrupt left half-built is destroyed with its traceback, when the
    # handler ends; a destructor that assumes a finished constructor (dolfinx's
    # LinearProblem.__del__ reads self._solver) would print "Exception ignored ...
    # Traceback" after the one-line message.
    sys.unraisablehook = _after_interrupt
    if comm.rank == 0:
        where = "nothing written"
        if args.command == "sweep":
            where = f"the finished points are in {args.json}; the same command resumes"
        print(f"\nunibuckle: interrupted; {where}", file=sys.stderr, flush=True)
    return EXIT_INTERRUPTED


def _broken_pipe(err: BaseException) -> bool:
    """Whether ``err`` is a write to a closed standard output, by Python or by a PETSc viewer."""
    import errno

    if in_chain(err, BrokenPipeError) is not None:
        return True
    failure = petsc_failure(err)
    return failure is not None and os.strerror(errno.EPIPE) in failure.reason


def _message(err: BaseException, options: Sequence[str]) -> str:
    """The error line of a run that raised ``err`` (``options``: those given to PETSc)."""
    failure = petsc_failure(err)
    if failure is not None and failure.refused_option:
        given = " ".join(options) or "none"
        return f"PETSc/SLEPc refused an option ({failure.reason}); the options given: {given}"
    if failure is not None:
        return f"PETSc/SLEPc failed: {failure.reason} ({failure.first_line}); no result written"
    if isinstance(err, NumericalError):
        return f"{err} (no result written)"
    return str(err)


def run_command(args: argparse.Namespace, rest: Sequence[str], comm: Any) -> int:
    """The subcommand of ``args``, with PETSc given the single-dash options ``rest``."""
    import petsc4py

    petsc4py.init([sys.argv[0], *rest])
    ignore_broken_pipe()  # after PETSc's signal handler, which takes SIGPIPE for a crash

    if args.command == "sweep":
        return sweep_command(args, comm)
    if args.command == "nonlinear":
        return nonlinear_command(args, comm)
    return solve_command(args, comm)


def _after_interrupt(unraisable: Any) -> None:
    """``sys.unraisablehook`` once interrupted: a destructor's error is logged, not printed."""
    logging.getLogger(__name__).debug(
        "after the interrupt, in %r: %s", unraisable.object, unraisable.exc_value
    )
