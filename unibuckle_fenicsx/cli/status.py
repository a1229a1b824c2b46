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

#: The line after the traceback of an internal error.
BUG_REPORT = (
    "unibuckle: internal error: this is a bug in unibuckle_fenicsx, not a problem with "
    "your input; please report it (the command, the problem file and the traceback above)"
)

#: This rank's error messages of the run, printed once at its end (:class:`_Ending`).
PENDING: list[tuple[int, str]] = []


def report_failure(comm: Any, message: str, status: int = EXIT_BAD_INPUT) -> int:
    """Record the error message (printed once, at the end of the run) and return the status.

    The rank that prints it is the first with a non-zero status (:class:`_Ending`): rank 0
    when the ranks fail together, the failing one when it fails alone.
    """
    PENDING.append((status, message))
    return status


def print_out(text: str) -> None:
    """Print ``text`` on stdout; a reader that stopped early (``| head``) is not an error.

    PETSc, once loaded, takes SIGPIPE for a crash and aborts the run ("Caught signal
    number 13 Broken Pipe", MPI_Abort): Python's own disposition (ignored, so that the
    write raises BrokenPipeError) is restored first. Then Python's recipe (the signal
    module's "Note on SIGPIPE"): stdout to devnull, so that the interpreter's last flush
    at exit does not fail again.
    """
    if hasattr(signal, "SIGPIPE"):
        signal.signal(signal.SIGPIPE, signal.SIG_IGN)
    try:
        print(text, flush=True)
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
