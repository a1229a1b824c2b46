"""How a run of the command line ends: its exit statuses and its one error message."""

from __future__ import annotations

import os
import signal
import sys
from typing import Any

from unibuckle_fenicsx.outcome import Outcome

#: A certified critical state was found.
EXIT_OK = Outcome.OK.exit_status

#: The input was refused (the message names the parameter); nothing was solved.
EXIT_BAD_INPUT = Outcome.REFUSED.exit_status

#: A numerical difficulty: no certified critical state (the JSON holds what was found).
EXIT_NOT_CERTIFIED = Outcome.NOT_CERTIFIED.exit_status

#: An internal error (a bug): the traceback and a request for a report.
EXIT_BUG = Outcome.BUG.exit_status

#: Interrupted (Ctrl-C): 128 + SIGINT, the shell's convention.
EXIT_INTERRUPTED = Outcome.INTERRUPTED.exit_status

#: Standard output closed by its reader before the run wrote all of it (``| head``):
#: 128 + SIGPIPE, the status of a command that a broken pipe ends (``seq 100 | head -1``
#: under ``set -o pipefail``), and the one mpiexec gives when it forwards the output.
EXIT_BROKEN_PIPE = 128 + 13

#: The line after the traceback of an internal error.
BUG_REPORT = (
    "unibuckle: internal error: this is a bug in unibuckle_fenicsx, not a problem with "
    "your input; please report it (the command, the problem file and the traceback above)"
)

#: This rank's error messages of the run, printed once at its end (:class:`_Ending`).
PENDING: list[tuple[int, str]] = []
#: Whether this run's standard output was closed by its reader (:func:`print_out`).
BROKEN_PIPE: list[bool] = []


def report_failure(comm: Any, message: str, status: int = EXIT_BAD_INPUT) -> int:
    """Record the error message (printed once, at the end of the run) and return the status.

    The rank that prints it is the first with a non-zero status (:class:`_Ending`): rank 0
    when the ranks fail together, the failing one when it fails alone.
    """
    PENDING.append((status, message))
    return status


def ignore_broken_pipe() -> None:
    """Give SIGPIPE back Python's disposition (ignored: a write raises BrokenPipeError).

    PETSc, once loaded, takes SIGPIPE for a crash and aborts the run ("Caught signal
    number 13 Broken Pipe", MPI_Abort): a viewer's output (``-unibuckle_eps_view |
    head``) would end the run there. Call it after PETSc is initialised.
    """
    from petsc4py import PETSc  # noqa: F401  (initialises PETSc: its handlers are set)

    _ignore_sigpipe()


def _ignore_sigpipe() -> None:
    """SIGPIPE ignored (Python's disposition at start-up), where the platform has it."""
    if hasattr(signal, "SIGPIPE"):
        signal.signal(signal.SIGPIPE, signal.SIG_IGN)


def print_out(text: str) -> None:
    """Print ``text`` on stdout; a reader that stopped early (``| head``) ends it quietly.

    SIGPIPE is ignored first (as in :func:`ignore_broken_pipe`, for a caller that has not
    run it), so that the write raises BrokenPipeError; then :func:`stdout_closed`. The
    run goes on (what it writes to files is written) and ends with
    :data:`EXIT_BROKEN_PIPE`, as a command that the signal ends would.
    """
    _ignore_sigpipe()
    try:
        print(text, flush=True)
    except BrokenPipeError:
        stdout_closed()


def stdout_closed() -> int:
    """Note that the reader of stdout stopped; stdout to devnull; :data:`EXIT_BROKEN_PIPE`.

    Python's recipe (the signal module's "Note on SIGPIPE"): the interpreter's last flush
    at exit then does not fail again.
    """
    os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    BROKEN_PIPE.append(True)
    return EXIT_BROKEN_PIPE


def with_broken_pipe(status: int) -> int:
    """The run's exit status: :data:`EXIT_BROKEN_PIPE` for a success whose output was cut."""
    return EXIT_BROKEN_PIPE if BROKEN_PIPE and status == EXIT_OK else status
