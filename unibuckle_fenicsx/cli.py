"""Command line: ``unibuckle solve``, ``unibuckle sweep`` and ``unibuckle nonlinear``.

One problem, a grid of them, and the load path of the imperfect plate:

``unibuckle solve --case c1 --nx 20 --ny 20 --json out.json``;
``unibuckle sweep --config base.toml --vary plate.length=0.1:0.4:7 --json out.jsonl``;
``unibuckle nonlinear --case c1 --nx 20 --ny 20 --imperfection 1e-3 --json out.json``.

Unrecognised ``-prefix_option value`` pairs are passed to PETSc, e.g.
``-unibuckle_eps_view`` or ``-unibuckle_prestress_ksp_view``.

The module is about 860 lines: the three subcommands' parsers, their epilogs (the exit
statuses) and drivers. It is to be split by subcommand once the rework of its exit
statuses and error handling (on another branch) has landed, to keep that merge small.
"""

from __future__ import annotations

import argparse
import logging
import os
import re
import sys
import traceback
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

from unibuckle_fenicsx.errors import InputError, NumericalError
from unibuckle_fenicsx.spec import METHODS, OPTIONS

if TYPE_CHECKING:  # pragma: no cover
    from unibuckle_fenicsx.spec import ProblemSpec

__all__ = ["EXIT_BAD_INPUT", "EXIT_INTERRUPTED", "EXIT_NOT_CERTIFIED", "EXIT_OK", "main"]

#: A certified critical state was found.
EXIT_OK = 0
#: The input was refused (the message names the parameter); nothing was solved.
EXIT_BAD_INPUT = 2
#: A numerical difficulty: no certified critical state (the JSON holds what was found).
EXIT_NOT_CERTIFIED = 3
#: An internal error (a bug): the traceback and a request for a report.
EXIT_BUG = 1
#: Interrupted (Ctrl-C): 128 + SIGINT, the shell's convention.
EXIT_INTERRUPTED = 130
#: The line after the traceback of an internal error.
BUG_REPORT = (
    "unibuckle: internal error: this is a bug in unibuckle_fenicsx, not a problem with "
    "your input; please report it (the command, the problem file and the traceback above)"
)

#: What --json and --output may create (README, "Command line").
OUTPUT_HELP = """\
--json PATH writes one file; its folder must exist. --output DIR writes its files
in DIR, creating DIR (not its parents) if it is missing. Both are checked before
anything is solved: a path that cannot be written is refused (exit status 2)."""

#: ... for ``nonlinear``, which writes no fields (no --output).
JSON_HELP = """\
--json PATH writes one file; its folder must exist. It is checked before anything
is solved: a path that cannot be written is refused (exit status 2)."""

EPILOG = f"""\
{OUTPUT_HELP}

exit status:
  {EXIT_OK}  a critical state satisfying its certificate (KKT) was found
  {EXIT_BAD_INPUT}  bad input (the message names the parameter and the allowed range);
     no result was computed
  {EXIT_NOT_CERTIFIED}  a numerical difficulty: no certified critical state; the JSON (--json)
     still holds the best admissible load found (an upper bound), the lower bound and a
     certificate saying what failed; when no admissible mode with a finite load
     exists (or none was found), the message gives the lower bound and no JSON is written
  {EXIT_BUG}  an internal error (a bug): the traceback and a request for a report
  {EXIT_INTERRUPTED}  interrupted (Ctrl-C); nothing written

Single-dash options that argparse does not know go to PETSc/SLEPc under the package's
prefixes, e.g. -unibuckle_eps_view, -unibuckle_eps_tol 1e-12, -unibuckle_ldl_ksp_view.
"""


SWEEP_EPILOG = f"""\
--vary PATH=START:STOP:N gives N values from START to STOP (ends included);
--vary PATH=V1,V2,... gives a list. PATH is the dotted path of a number of the
problem file, list entries by index: plate.thickness, material.nu,
edges.left.normal_stress, plate.corners.1.0 (x1), obstacle.zone.0.1, mesh.size,
edges.top.rotational_stiffness, points.0.spacing, material.plies.0.angle,
load.fixed_factor (the fixed part's factor: an interaction curve);
plate.length and plate.width set x1 = x0 + value and y1 = y0 + value. Several
--vary make a grid (the first varies slowest). Values are in the file's units. Give
[mesh] size = h in the file for a cell count that follows the plate's size.

Each finished point appends one JSON line to --json: index, point, status and the keys
of 'unibuckle solve --json' (without wall times). Re-running the same command resumes:
a point already in the file is skipped if its line's input equals the point's problem
(after an edit of the base file, the points it changes are solved again). The folder
of --json must exist; a file that is not a sweep's JSON lines is refused, not
overwritten. Under mpiexec -n P the points are shared among P/R groups of
--ranks-per-point R ranks.

exit status:
  {EXIT_OK}  every point has a certified critical state
  {EXIT_BAD_INPUT}  bad input (a --vary, the base file, a point the schema refuses);
     nothing was solved
  {EXIT_NOT_CERTIFIED}  some points have no certified critical state (their lines say why)
  {EXIT_BUG}  an internal error (a bug): the traceback and a request for a report
  {EXIT_INTERRUPTED}  interrupted (Ctrl-C): the finished points are in --json; the same
     command resumes
"""


NONLINEAR_EPILOG = f"""\
The linear critical load and mode come first (as 'unibuckle solve'); the von Karman
plate, given the imperfection delta t times that mode (the unilateral mode with the
obstacle, the free mode without), is loaded step by step against the obstacle (PETSc
SNES vinewtonrsls); the JSON holds the path (load_Pa, max_w_m, contact_nodes,
end_shortening_m per step), southwell_load_Pa, inflection_load_Pa and
linear_critical_load_Pa. A progress line per load step goes to stderr (-q hides it).

exit status:
  {EXIT_OK}  the path reached --max-load, both loads were read off it and the last state
     satisfies the contact conditions
  {EXIT_BAD_INPUT}  bad input (the message names the parameter and the allowed range);
     nothing was solved
  {EXIT_NOT_CERTIFIED}  a numerical difficulty: the path stopped early (SNES did not converge
     at the smallest step; the JSON holds the path up to there and stop_reason), the
     knee was not passed, or the contact conditions fail; the message lists what the
     path validated (the loads read off it, the contact conditions) and what it did
     not; when no load step converged or the linear solve failed, the message says
     why and no JSON is written
  {EXIT_BUG}  an internal error (a bug): the traceback and a request for a report
  {EXIT_INTERRUPTED}  interrupted (Ctrl-C); nothing written

{JSON_HELP}

Single-dash options go to PETSc under the prefixes unibuckle_nl_ (the SNES, its KSP:
-unibuckle_nl_snes_monitor, -unibuckle_nl_snes_view), unibuckle_ (the linear eigen
solves) and unibuckle_prestress_.
"""


#: A negative number as a value, exponent form included (``-1e-3``, ``-2.5E+4``): argparse
#: 3.13 reads ``-1e-3`` as an unknown option ("expected one argument") because its own
#: pattern has no exponent; the package has no option that looks like a number.
NEGATIVE_NUMBER = re.compile(r"^-(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?$")


class _Parser(argparse.ArgumentParser):
    """argparse's parser, reading a negative number in exponent form as a value."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER


class _Formatter(argparse.RawDescriptionHelpFormatter, argparse.ArgumentDefaultsHelpFormatter):
    """Epilogs as written; each option's default appended to its help (when it has one)."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        default = action.default
        if default in (None, []) or isinstance(default, bool) or action.nargs == 0:
            return action.help  # no default, a switch, a counter or a list: nothing to add
        return super()._get_help_string(action)


def _solver_default(name: str) -> str:
    """``(default D, or the file's)`` for the solver field ``name`` (schema default D)."""
    from unibuckle_fenicsx.spec import SolverSpec

    value = getattr(SolverSpec(), name)
    return (
        f"(default: {value:g}, or the file's)"
        if isinstance(value, float)
        else (f"(default: {value}, or the file's)")
    )


def _common_flags() -> _Parser:
    """Flags of every subcommand: logging and progress."""
    common = _Parser(add_help=False)
    common.add_argument("-v", "--verbose", action="count", default=0, help="log more (-vv: debug)")
    common.add_argument(
        "-q", "--quiet", action="store_true", help="no progress output on stderr (warnings stay)"
    )
    return common


def _problem_flags() -> _Parser:
    """Flags naming one problem (solve, nonlinear): its source, mesh, --set and --json."""
    from unibuckle_fenicsx.spec.cases import CASES

    problem = _Parser(add_help=False)
    src = problem.add_mutually_exclusive_group(required=True)
    src.add_argument(
        "--case",
        choices=list(CASES),
        help="the paper's plate: free (no obstacle), c1 = [-0.04,0.04]x[-0.05,0.05], "
        "c2 = [-0.04,0.04]x[-0.02,0.02], c3 = whole plate",
    )
    src.add_argument(
        "--config",
        metavar="FILE",
        help="problem file: TOML (its keys: unibuckle schema --keys), or a result JSON to "
        "re-run its input",
    )
    problem.add_argument("--nx", type=int, help="cells along x, >= 2 (default: the problem's)")
    problem.add_argument("--ny", type=int, help="cells along y, >= 2 (default: the problem's)")
    problem.add_argument(
        "--set",
        metavar="PATH=VALUE",
        action="append",
        default=[],
        dest="settings",
        help="set a value of the problem file by its dotted path (as --vary of the sweep): "
        "--set solver.tau=1e-9 --set plate.thickness=0.004 (repeatable; the file's units)",
    )
    problem.add_argument(
        "--json", metavar="PATH", help="write the result as JSON (the folder must exist)"
    )
    return problem


def _parser() -> tuple[argparse.ArgumentParser, dict[str, argparse.ArgumentParser]]:
    """The command line's parser and its subcommands' parsers by name."""
    parser = _Parser(
        prog="unibuckle",
        description=(
            "Unilateral buckling of thin plates (Reissner-Mindlin, MITC4): the critical "
            "load and the buckling mode that respects a rigid obstacle on one side. "
            "Arguments starting with a single dash that argparse does not know "
            "(-unibuckle_eps_view, ...) go to PETSc/SLEPc."
        ),
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    common, problem = _common_flags(), _problem_flags()
    s = sub.add_parser(
        "solve",
        parents=[problem, common],
        help="solve one problem (a paper case or a TOML file)",
        description="Compute the critical load of one problem and print a one-line summary.",
        epilog=EPILOG,
        formatter_class=_Formatter,
    )
    _solve_flags(s)
    w = sub.add_parser(
        "sweep",
        parents=[common],
        help="solve a problem file over a grid of values of some of its numbers",
        description="Solve the problem of --config at every point of the --vary grid, "
        "writing one JSON line per point (resumable), and optionally a chart of k.",
        epilog=SWEEP_EPILOG,
        formatter_class=_Formatter,
    )
    w.add_argument("--config", metavar="FILE", required=True, help="the base problem (TOML)")
    w.add_argument(
        "--vary",
        metavar="PATH=VALUES",
        action="append",
        required=True,
        help="a number to vary: PATH=START:STOP:N or PATH=V1,V2,... (repeat for a grid)",
    )
    w.add_argument(
        "--json",
        metavar="PATH",
        required=True,
        help="JSON-lines output (the folder must exist); an existing file of the same "
        "sweep is resumed",
    )
    w.add_argument(
        "--plot",
        metavar="PNG",
        help="draw k against the first --vary (bilateral and unilateral, with the "
        "exact curves where they exist)",
    )
    w.add_argument(
        "--ranks-per-point",
        type=int,
        default=1,
        metavar="R",
        help="under mpiexec: ranks of each point's mesh (1: one point per rank)",
    )
    _nonlinear_parser(sub, [problem, common])
    k = sub.add_parser(
        "schema",
        help="print the JSON Schema of a problem file (or its dotted keys)",
        description="Print the JSON Schema of a problem file: for editor completion of "
        "TOML files (e.g. a '#:schema' line for taplo) and the reference of the keys. "
        "The repository keeps it in schema/unibuckle-problem.schema.json.",
    )
    k.add_argument("--keys", action="store_true", help="print the dotted keys instead")
    k.add_argument("--output", metavar="PATH", help="write to PATH instead of stdout")
    return parser, dict(sub.choices)


def _solve_flags(s: argparse.ArgumentParser) -> None:
    """The ``solve`` subcommand's own flags (the solver's, and --output)."""
    s.add_argument(
        "--method",
        choices=list(METHODS),
        help="unilateral algorithm (auto: exact enumeration when 2^i <= --max-candidates "
        "and its estimated time fits --enumeration-budget, else interior-point on thin "
        "plates (t/b < 0.02) and active-set on thicker ones; enumerate alone = the "
        "paper's stopping rule) " + _solver_default("method"),
    )
    s.add_argument(
        "--complete",
        action="store_true",
        help="enumerate: visit every subset (checks the paper's monotonicity)",
    )
    s.add_argument(
        "--until-proven",
        action="store_true",
        help="enumerate: go past the paper's stopping size p* until the interlacing bound "
        "proves the best set optimal (exact; implied by --method auto)",
    )
    s.add_argument(
        "--max-candidates",
        type=int,
        metavar="N",
        help="enumerate: refuse above N candidate sets " + _solver_default("max_candidates"),
    )
    s.add_argument(
        "--enumeration-budget",
        type=float,
        metavar="SECONDS",
        help="auto: enumerate only if the estimated time is below this "
        + _solver_default("enumeration_budget_s"),
    )
    s.add_argument(
        "--max-iterations",
        type=int,
        metavar="N",
        help="active-set: iterates per seed and mesh level (the feasible descent, the last "
        "fallback, may use 10x as many solves); interior-point: the same for its "
        "active-set fallback " + _solver_default("max_iterations"),
    )
    s.add_argument(
        "--bound-budget",
        type=int,
        metavar="N",
        help="active-set: eigen solves for the lattice lower bound "
        + _solver_default("bound_budget"),
    )
    s.add_argument(
        "--no-certify",
        action="store_true",
        help="skip the global-optimality certificate (for speed studies; KKT is still checked)",
    )
    s.add_argument(
        "--bracket",
        action="store_true",
        help="also try the low-rank verified bracket when several pencil eigenvalues lie "
        "below the load (thin long plates; tens of free solves' time)",
    )
    s.add_argument(
        "--penalty",
        type=float,
        metavar="RHO",
        help="penalty stiffness rho for --method penalty (relative to max diag A) "
        + _solver_default("penalty"),
    )
    s.add_argument(
        "--tau", type=float, help="relative feasibility tolerance " + _solver_default("tau")
    )
    s.add_argument(
        "--candidate-parallel",
        action="store_true",
        help="under mpiexec: each rank holds a serial copy and enumerates a share "
        "of the candidate sets (without it: distribute the mesh)",
    )
    s.add_argument(
        "--output",
        metavar="DIR",
        help="write the mode, obstacle zone and contact set for ParaView (VTX .bp) and "
        "as VTK (.pvd/.vtu, readable by pyvista.read) into DIR (created if missing; its "
        "parent must exist): NAME_w.bp, NAME_theta.bp, NAME.pvd, with NAME the problem's "
        "name, characters other than letters, digits, '.', '-' and '_' replaced by '_'",
    )


def _nonlinear_parser(sub: Any, parents: list[_Parser]) -> None:
    """The ``nonlinear`` subcommand's arguments (defaults: :class:`NonlinearOptions`)."""
    from unibuckle_fenicsx.nonlinear.choices import CONTROLS, SHAPES

    n = sub.add_parser(
        "nonlinear",
        parents=parents,
        help="validate the critical load by the load path of the imperfect plate "
        "(von Karman, against the obstacle)",
        description="Follow the load path of the imperfect von Karman plate against the "
        "obstacle and read the buckling load off it (Southwell, steepest rise), next to "
        "the linear critical load.",
        epilog=NONLINEAR_EPILOG,
        formatter_class=_Formatter,
    )
    n.add_argument(
        "--imperfection",
        type=float,
        default=_NONLINEAR_DEFAULTS["imperfection"],
        metavar="DELTA",
        help="imperfection amplitude max|w0| / thickness, in (0, 1]",
    )
    n.add_argument(
        "--shape",
        choices=list(SHAPES),
        default=_NONLINEAR_DEFAULTS["shape"],
        help="imperfection shape: the linear free or unilateral mode (auto: unilateral "
        "with the obstacle, free without)",
    )
    n.add_argument(
        "--control",
        choices=list(CONTROLS),
        default=_NONLINEAR_DEFAULTS["control"],
        help="load control (edge traction, adaptive steps) or displacement control (end "
        "shortening of the loaded edges; uniaxial compression only)",
    )
    n.add_argument("--no-obstacle", action="store_true", help="the same plate without its obstacle")
    n.add_argument(
        "--max-load",
        type=float,
        default=_NONLINEAR_DEFAULTS["max_load"],
        metavar="RATIO",
        help="stop at RATIO times the linear critical load, in (0, 5]",
    )
    n.add_argument(
        "--max-step",
        type=float,
        default=_NONLINEAR_DEFAULTS["max_step"],
        metavar="FRACTION",
        help="largest load step, relative to the linear critical load",
    )


#: The nonlinear flags' defaults: those of NonlinearOptions (its dataclass fields),
#: repeated here so that building the parser imports no DOLFINx; a test holds them equal.
_NONLINEAR_DEFAULTS: dict[str, Any] = {
    "imperfection": 1e-3,
    "shape": "auto",
    "control": "load",
    "max_load": 1.2,
    "max_step": 0.05,
}


#: Flags that matter only for some methods: flag -> (the methods whose options Struct
#: reads its SolverSpec field, the field).
_METHOD_FLAGS = {
    flag: (
        tuple(m.value for m, options in OPTIONS.items() if field in options.__struct_fields__),
        field,
    )
    for flag, field in {
        "--complete": "complete",
        "--until-proven": "until_proven",
        "--max-candidates": "max_candidates",
        "--enumeration-budget": "enumeration_budget_s",
        "--max-iterations": "max_iterations",
        "--bound-budget": "bound_budget",
        "--penalty": "penalty",
    }.items()
}


def _solver_changes(args: argparse.Namespace) -> tuple[dict[str, Any], list[str]]:
    """SolverSpec changes from the flags, and the method-specific flags given."""
    values = {
        "--complete": args.complete or None,
        "--until-proven": args.until_proven or None,
        "--max-candidates": args.max_candidates,
        "--enumeration-budget": args.enumeration_budget,
        "--max-iterations": args.max_iterations,
        "--bound-budget": args.bound_budget,
        "--penalty": args.penalty,
    }
    changes: dict[str, Any] = {
        k: v for k, v in {"method": args.method, "tau": args.tau}.items() if v is not None
    }
    if args.no_certify:
        changes["certify"] = False
    if args.bracket:
        changes["bracket"] = True
    given = []
    for flag, value in values.items():
        if value is not None:
            changes[_METHOD_FLAGS[flag][1]] = value
            given.append(flag)
    return changes, given


def _unused_flags(flags: list[str], method: str, chosen: str | None = None) -> list[str]:
    """The flags of ``flags`` that do not apply to ``method`` (the one in force).

    Under "auto" a flag of the enumeration applies if auto enumerates: before the solve
    (``chosen`` None) it is kept; after it, it is unused when ``chosen`` (the method
    that answered) is not the enumeration.
    """
    unused = []
    for flag in flags:
        methods = _METHOD_FLAGS[flag][0]
        if method in methods:
            continue
        if method == "auto" and "enumerate" in methods and chosen in (None, "enumerate"):
            continue
        unused.append(f"{flag} (applies to --method {' or '.join(methods)})")
    return unused


def _probe_folder(flag: str, folder: Path, target: Path) -> str | None:
    """Why ``target`` cannot be created in the existing ``folder``, or None (a probe file)."""
    import tempfile

    try:
        fd, name = tempfile.mkstemp(prefix=".unibuckle-probe-", dir=folder)
    except OSError as err:
        return f"{flag}: cannot create {target}: {folder} takes no new file ({err.strerror or err})"
    os.close(fd)
    os.unlink(name)
    return None


def _missing_folder(flag: str, folder: Path) -> str:
    """The message for a folder that does not exist (naming a file in its way, if any)."""
    existing = folder
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if existing.exists() and not existing.is_dir():
        return f"{flag}: {existing} is not a directory"
    return f"{flag}: the folder {folder} does not exist; create it first"


def _check_outputs(args: argparse.Namespace) -> str | None:
    """Why --json, --plot or --output cannot be written, or None; run before any solve.

    --json PATH (and --plot PNG) needs an existing folder in which a file can be created (tried, not
    inferred from permission bits, which root and /proc ignore); --output DIR is
    created later if missing, so its parent must exist and take a new entry. Nothing is
    left behind.
    """
    files = [("--json", args.json), ("--plot", getattr(args, "plot", None))]  # plot: sweep
    for flag, value in files:
        if not value:
            continue
        path = Path(value)
        folder = path.parent
        if path.is_dir():
            return f"{flag}: {path} is a directory; give a file name"
        if not folder.is_dir():
            return _missing_folder(flag, folder)
        if path.exists():
            try:  # appending nothing leaves the file as it is
                with path.open("ab"):
                    pass
            except OSError as err:
                return f"{flag}: cannot write {path} ({err.strerror or err})"
        elif problem := _probe_folder(flag, folder, path):
            return problem
    if getattr(args, "output", None):  # solve only
        directory = Path(args.output)
        if directory.exists() and not directory.is_dir():
            return f"--output: {directory} is not a directory"
        folder = directory
        if not directory.exists():
            folder = directory.parent
            if not folder.is_dir():
                return _missing_folder("--output", folder) + " (--output creates one folder)"
        if problem := _probe_folder("--output", folder, directory):
            return problem
    return None


def _logging(verbose: int, quiet: bool, rank: int) -> None:
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(levelname)s %(name)s: %(message)s"))
    root = logging.getLogger()
    root.handlers[:] = [handler]
    root.setLevel([logging.WARNING, logging.INFO, logging.DEBUG][min(verbose, 2)])
    progress = logging.getLogger("unibuckle_fenicsx.progress")
    quiet = quiet or rank != 0
    progress.setLevel(logging.WARNING if quiet else min(root.level, logging.INFO))


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    parser, commands = _parser()
    args, rest = parser.parse_known_args(argv)
    unknown = [a for a in rest if a.startswith("--")]
    if unknown:  # the subcommand's usage line, not the top-level one
        commands[args.command].error(f"unrecognized arguments: {' '.join(unknown)}")

    if args.command == "schema":
        return _schema(args)

    from mpi4py import MPI  # before petsc4py: loads libmpi

    comm = MPI.COMM_WORLD
    _PENDING.clear()
    # The outputs first: a path that cannot be written is refused before PETSc, DOLFINx
    # and the problem are even loaded.
    problem = comm.bcast(_check_outputs(args) if comm.rank == 0 else None, root=0)
    if problem is not None:
        if comm.rank == 0:
            print(f"unibuckle: error: {problem}", file=sys.stderr)
        return EXIT_BAD_INPUT
    _logging(args.verbose, args.quiet, comm.rank)
    ending = _Ending(comm)
    status, raised = _guarded_run(args, rest, comm)
    return ending.finish(status, raised or bool(_PENDING))


def _abort(comm: Any, status: int, message: str | None) -> NoReturn:
    """Print ``message`` and end every rank of ``comm`` with ``status`` (``MPI_Abort``)."""
    if message is not None:
        print(f"unibuckle: error: {message}", file=sys.stderr, flush=True)
    comm.Abort(status)
    os._exit(status)  # MPI_Abort does not return; had it, this process ends all the same


def _guarded_run(args: argparse.Namespace, rest: Sequence[str], comm: Any) -> tuple[int, bool]:
    """The exit status of :func:`_run`, and whether this rank raised (it may be alone)."""
    try:
        return _run(args, rest, comm), False
    except KeyboardInterrupt:
        return _interrupted(args, comm), True
    except InputError as err:
        return _fail(comm, str(err)), True
    except NumericalError as err:
        return _fail(comm, f"{err} (no result written)", EXIT_NOT_CERTIFIED), True
    except Exception as err:
        if _in_chain(err, KeyboardInterrupt) is not None:
            # Ctrl-C inside a Python callback of PETSc (the nonlinear path's SNES
            # residual): petsc4py turns it into PETSc error 101 with the interrupt as
            # its context. An interrupt all the same.
            return _interrupted(args, comm), True
        refused = _petsc_error(err, rest)
        if refused is not None:
            return _fail(comm, *refused), True
        traceback.print_exc()  # on every rank that fails: the bug may be on one
        print(BUG_REPORT, file=sys.stderr, flush=True)
        return EXIT_BUG, True


#: Seconds a rank that failed waits for the others at the end of the run before it
#: aborts it: ranks that fail together (a collective check, a collective solve) arrive
#: within a fraction of this; a rank that fails alone leaves the others blocked in their
#: next collective call, which only MPI_Abort ends.
FAILURE_WAIT_S = 5.0
#: This rank's error messages of the run, printed once at its end (:class:`_Ending`).
_PENDING: list[tuple[int, str]] = []


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

        message = _PENDING[-1][1] if _PENDING else None
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


def _in_chain(err: BaseException, kind: type[BaseException]) -> BaseException | None:
    """``err`` or the first of its causes or contexts (8 deep at most) that is a ``kind``."""
    found: BaseException | None = err
    for _ in range(8):
        if found is None or isinstance(found, kind):
            return found
        found = found.__cause__ or found.__context__
    return None


def _schema(args: argparse.Namespace) -> int:
    """``unibuckle schema``: the JSON Schema of a problem file, or its dotted keys."""
    import json

    from unibuckle_fenicsx.spec import accepted_keys, json_schema

    text = "\n".join(accepted_keys()) if args.keys else json.dumps(json_schema(), indent=2)
    if not args.output:
        try:
            print(text, flush=True)
        except BrokenPipeError:
            # The reader stopped early (``| head``): not an error. Python's recipe (the
            # signal module's "Note on SIGPIPE"): stdout to devnull, so that the
            # interpreter's last flush at exit does not fail again.
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    try:
        Path(args.output).write_text(text + "\n")
    except OSError as err:
        print(f"unibuckle: error: --output {args.output}: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    return EXIT_OK


def _petsc_error(err: BaseException, options: Sequence[str]) -> tuple[str, int] | None:
    """The message and exit status of a PETSc/SLEPc error in ``err`` (or its causes).

    An error raised while an object reads its options (``*SetFromOptions``) is a bad
    command-line option (exit 2); any other PETSc error is a numerical difficulty.
    petsc4py reports an error inside a Cython call as a SystemError whose cause is the
    PETSc.Error: the chain is searched.
    """
    from petsc4py import PETSc

    found = _in_chain(err, PETSc.Error)
    if found is None:
        return None
    lines = [line.removeprefix("[0] ").strip() for line in str(found).splitlines()]
    reason = "; ".join(line for line in lines[1:] if line and "() at " not in line)
    reason = reason or lines[0]
    if any("SetFromOptions()" in line for line in lines):
        given = " ".join(options) or "none"
        return (
            f"PETSc/SLEPc refused an option ({reason}); the options given: {given}",
            EXIT_BAD_INPUT,
        )
    return f"PETSc/SLEPc failed: {reason} ({lines[0]}); no result written", EXIT_NOT_CERTIFIED


def _run(args: argparse.Namespace, rest: Sequence[str], comm: Any) -> int:
    """The subcommand of ``args``, with PETSc given the single-dash options ``rest``."""
    import petsc4py

    petsc4py.init([sys.argv[0], *rest])

    if args.command == "sweep":
        return _sweep(args, comm)
    if args.command == "nonlinear":
        return _nonlinear(args, comm)
    return _solve(args, comm)


def _solve(args: argparse.Namespace, comm: Any) -> int:
    """``unibuckle solve``: one problem, its summary, JSON and fields."""
    from unibuckle_fenicsx.analysis import solve
    from unibuckle_fenicsx.io import write_fields, write_json

    def fail(message: str, status: int = EXIT_BAD_INPUT) -> int:
        return _fail(comm, message, status)

    try:
        spec = _spec_from_args(args)
        changes, flags = _solver_changes(args)
        spec = spec.with_solver(**changes)
    except (ValueError, OSError) as err:
        return fail(str(err))
    method = spec.solver.method  # the flag's, or the problem file's
    _warn_unused(flags, method, comm)
    _warn_plate_model(spec, comm)
    try:
        analysis = solve(spec, comm, candidate_parallel=args.candidate_parallel)
    except (InputError, ImportError) as err:  # ImportError: an extra is missing (gmsh)
        return fail(str(err))
    except NumericalError as err:
        return fail(f"{err} (no result written)", EXIT_NOT_CERTIFIED)
    unwritten = None
    with analysis:
        if args.output:
            try:
                write_fields(analysis, args.output)
            except OSError as err:  # the folder went away during the solve
                unwritten = f"--output {args.output}: {err}"
    result = analysis.result
    _warn_unused(flags, method, comm, result)
    status = EXIT_OK
    certificate = result.certificate
    if certificate is not None and not certificate["kkt"]:
        status = EXIT_NOT_CERTIFIED
    if comm.rank == 0:
        if args.json:
            try:
                write_json(result, args.json)
            except OSError as err:
                unwritten = f"--json {args.json}: {err}"
        print(result.summary(), flush=True)
        if status != EXIT_OK:
            notes = "; ".join((certificate or {}).get("notes", [])) or "see the certificate"
            print(
                f"unibuckle: error: no certified critical state ({notes}); the bracket "
                f"[{result.lower_bound_Pa}, {result.upper_bound_Pa}] Pa is "
                + (f"in {args.json}" if args.json and unwritten is None else "above"),
                file=sys.stderr,
            )
    unwritten = comm.bcast(unwritten, root=0)
    if unwritten is not None:
        return fail(f"could not write {unwritten}; the result is the summary above")
    return status


def _warn_unused(flags: list[str], method: str, comm: Any, result: Any = None) -> None:
    """Warn of the flags that do not apply to ``method`` (rank 0).

    Before the solve (``result`` None): those that cannot apply; after it, under auto,
    the enumeration's flags that auto's choice (``result.method``) left unused.
    """
    if comm.rank != 0 or (result is not None and method != "auto"):
        return
    if result is None:
        for flag in _unused_flags(flags, method):
            print(f"unibuckle: warning: {flag} is ignored with --method {method}", file=sys.stderr)
        return
    for flag in _unused_flags(flags, "auto", result.method):
        print(
            f"unibuckle: warning: {flag} was not used: auto chose {result.method} "
            f"({result.method_chosen_by.removeprefix('auto: ')})",
            file=sys.stderr,
        )


def _warn_plate_model(spec: ProblemSpec, comm: Any) -> None:
    """A warning on stderr when the plate lies outside the plate model's usual range."""
    from unibuckle_fenicsx.spec.checks import plate_model_note

    note = plate_model_note(spec.plate)
    if note is not None and comm.rank == 0:
        print(f"unibuckle: warning: {note}", file=sys.stderr)


def _nonlinear(args: argparse.Namespace, comm: Any) -> int:
    """``unibuckle nonlinear``: the load path, the Southwell and inflection loads."""
    import json

    from unibuckle_fenicsx.nonlinear import NonlinearOptions, solve_nonlinear

    def fail(message: str, status: int = EXIT_BAD_INPUT) -> int:
        return _fail(comm, message, status)

    try:
        options = NonlinearOptions(
            imperfection=args.imperfection,
            shape=args.shape,
            control=args.control,
            obstacle=not args.no_obstacle,
            max_load=args.max_load,
            max_step=args.max_step,
            min_step=min(1e-5, args.max_step),
        )
        spec = _spec_from_args(args)
    except (ValueError, OSError) as err:
        message = str(err)
        for name in _NONLINEAR_FLAGS:  # name the flag, not the option
            if message.startswith(name):
                message = "--" + name.replace("_", "-") + message[len(name) :]
        return fail(message)
    if args.shape == "unilateral" and (args.no_obstacle or not spec.all_obstacles):
        why = "--no-obstacle removes it" if args.no_obstacle else "the problem has none"
        return fail(
            f"--shape unilateral takes the imperfection from the unilateral mode, which needs "
            f"an obstacle, and {why}: give --shape free (or auto)"
        )
    _warn_plate_model(spec, comm)
    try:
        analysis = solve_nonlinear(spec, options, comm)
    except (InputError, ImportError) as err:
        return fail(str(err))
    except NumericalError as err:
        return fail(f"{err} (no result written)", EXIT_NOT_CERTIFIED)
    with analysis:
        result = analysis.result
    unwritten = None
    if comm.rank == 0:
        if args.json:
            try:
                Path(args.json).write_text(json.dumps(result.as_dict(), indent=2) + "\n")
            except OSError as err:
                unwritten = f"could not write --json {args.json}: {err}"
        print(result.summary(), flush=True)
        if not result.ok:
            print(
                f"unibuckle: error: {nonlinear_verdict(result, args.max_load)}"
                + (f"; the path obtained is in {args.json}" if args.json and not unwritten else ""),
                file=sys.stderr,
            )
    unwritten = comm.bcast(unwritten, root=0)
    if unwritten is not None:
        return fail(f"{unwritten}; the result is the summary above")
    return EXIT_OK if result.ok else EXIT_NOT_CERTIFIED


def nonlinear_verdict(result: Any, max_load: float) -> str:
    """What an unsuccessful load path validated, and what it did not (one paragraph).

    Args:
        result: A :class:`~unibuckle_fenicsx.nonlinear.NonlinearResult` that is not ``ok``.
        max_load: The --max-load asked for (a multiple of the linear critical load).
    """
    from unibuckle_fenicsx.nonlinear.verdict import judge

    verdict = judge(result, max_load)
    validated, missing = ", ".join(verdict.validated), ", ".join(verdict.missing)
    if verdict.gap:
        closed = result.unilateral_load_Pa
        return (
            "with a gap the knee lies between the free load "
            f"{result.linear_critical_load_Pa:.6e} Pa and the unilateral load with the gaps "
            "closed "
            + ("(not computed)" if closed is None else f"{closed:.6e} Pa")
            + f"; the load path is not consistent with them. Consistent: {validated or 'nothing'}."
            f" Not consistent: {missing}"
        )
    return (
        f"the load path does not validate everything against the linear critical load "
        f"{result.linear_critical_load_Pa:.6e} Pa. Validated: {validated or 'nothing'}. "
        f"Not validated: {missing}"
    )


def _after_interrupt(unraisable: Any) -> None:
    """``sys.unraisablehook`` once interrupted: a destructor's error is logged, not printed."""
    logging.getLogger(__name__).debug(
        "after the interrupt, in %r: %s", unraisable.object, unraisable.exc_value
    )


def _fail(comm: Any, message: str, status: int = EXIT_BAD_INPUT) -> int:
    """Record the error message (printed once, at the end of the run) and return the status.

    The rank that prints it is the first with a non-zero status (:class:`_Ending`): rank 0
    when the ranks fail together, the failing one when it fails alone.
    """
    _PENDING.append((status, message))
    return status


def _spec_from_args(args: argparse.Namespace) -> ProblemSpec:
    """The problem of --case or --config, with --nx/--ny applied."""
    from unibuckle_fenicsx.spec import load_problem
    from unibuckle_fenicsx.spec.cases import paper_case

    spec = paper_case(args.case) if args.case else _load_config(args.config, load_problem)
    if args.settings:
        spec = _with_settings(spec, args.settings)
    if args.nx is not None or args.ny is not None:
        spec = spec.with_mesh(
            spec.mesh.nx if args.nx is None else args.nx,
            spec.mesh.ny if args.ny is None else args.ny,
        )
    return spec


def _with_settings(spec: ProblemSpec, settings: Sequence[str]) -> ProblemSpec:
    """``spec`` with the ``--set PATH=VALUE`` changes (dotted paths of the problem file).

    Raises:
        ValueError: A setting without '=', a path the problem file does not have, or a
            value the schema refuses (the message names the path).
    """
    from unibuckle_fenicsx.spec import problem_from_dict, problem_to_dict
    from unibuckle_fenicsx.sweep import set_text

    data = problem_to_dict(spec, units=spec.units)
    for setting in settings:
        path, sep, text = setting.partition("=")
        if not sep or not path.strip():
            raise InputError(f"--set {setting!r}: give PATH=VALUE, e.g. solver.tau=1e-9")
        set_text(data, path.strip(), text.strip())
    try:
        return problem_from_dict(data, name=spec.name)
    except ValueError as err:
        raise InputError(f"--set {' '.join(settings)}: {err}") from None


def _load_config(path: str, load: Any) -> Any:
    """``load(path)``, an unreadable file named with its option (ValueError)."""
    try:
        return load(path)
    except OSError as err:
        raise InputError(f"--config {path}: cannot read it ({err.strerror or err})") from None


#: Option names of the nonlinear analysis that are also command-line flags.
_NONLINEAR_FLAGS = ("imperfection", "shape", "control", "max_load", "max_step")


def _check_chart(base: Any) -> None:
    """Refuse --plot for a sweep whose scaled load has no edge stress (before any solve).

    The chart draws k = t lambda b^2/(pi^2 D), a buckling coefficient of edge loads; for a
    temperature rise alone lambda is a factor on the rise and k means nothing.
    """
    from unibuckle_fenicsx.spec import problem_from_dict

    if not problem_from_dict(base).plate.loaded:
        raise InputError(
            "--plot draws the buckling coefficient k of edge loads; this problem's scaled "
            "load is a temperature rise alone (lambda is a factor on it, k is not defined): "
            "leave --plot out, or load an edge"
        )


def _sweep(args: argparse.Namespace, comm: Any) -> int:
    """``unibuckle sweep``: the grid, the JSON lines, the chart."""
    from unibuckle_fenicsx.sweep import base_mapping, parse_variation, run_sweep

    def fail(message: str) -> int:
        return _fail(comm, message)

    if args.plot and comm.rank == 0:
        try:
            import matplotlib as mpl  # noqa: F401
        except ImportError:
            return fail("--plot needs matplotlib: pip install 'unibuckle_fenicsx[demo]'")
    # Each point's own progress lines and warnings would interleave with the sweep's
    # (the warnings are in the point's JSON line, under details).
    if args.verbose == 0:
        logging.getLogger("unibuckle_fenicsx").setLevel(logging.ERROR)
        logging.getLogger("unibuckle_fenicsx.progress").setLevel(logging.ERROR)
        sweep_lines = logging.getLogger("unibuckle_fenicsx.progress.sweep")
        sweep_lines.setLevel(logging.ERROR if args.quiet or comm.rank else logging.INFO)
    try:
        variations = [parse_variation(v) for v in args.vary]
        base = _load_config(args.config, base_mapping)
        if args.plot:
            _check_chart(base)
        lines = run_sweep(
            base,
            variations,
            args.json,
            comm,
            ranks_per_point=args.ranks_per_point,
            progress=not args.quiet,
        )
    except (InputError, OSError, ImportError) as err:
        return fail(str(err))
    if comm.rank == 0:
        from collections import Counter

        counts = Counter(line["status"] for line in lines)
        print(
            f"sweep: {len(lines)} points in {args.json}: "
            + ", ".join(f"{n} {status}" for status, n in sorted(counts.items())),
            flush=True,
        )
        if args.plot:
            from unibuckle_fenicsx.viz.charts import plot_sweep

            print(f"sweep: chart {plot_sweep(lines, variations, base, args.plot)}")
    ok = all(line["status"] == "ok" for line in lines)
    return EXIT_OK if ok else EXIT_NOT_CERTIFIED


if __name__ == "__main__":
    sys.exit(main())
