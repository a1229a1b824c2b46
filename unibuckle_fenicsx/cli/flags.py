"""The command line's parsers: the subcommands' flags, their help and epilogs.

The method flags and their defaults come from the ``[solver]`` options Structs
(:data:`~unibuckle_fenicsx.spec.OPTIONS`), the nonlinear ones from
:class:`~unibuckle_fenicsx.nonlinear.NonlinearOptions`.
"""

from __future__ import annotations

import argparse
import re
from importlib import metadata
from typing import Any

from unibuckle_fenicsx.cli.status import (
    EXIT_BAD_INPUT,
    EXIT_BROKEN_PIPE,
    EXIT_BUG,
    EXIT_INTERRUPTED,
    EXIT_NOT_CERTIFIED,
    EXIT_OK,
)
from unibuckle_fenicsx.spec import METHODS, OPTIONS

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
examples:
  unibuckle solve --config demos/plate.toml --json plate.json --output out/
  unibuckle solve --case c1 --nx 20 --ny 20        # the paper's plate, zone c1
  unibuckle solve --config demos/box.toml --set obstacle.core=false   # the hollow box
  unibuckle solve --config plate.toml --set design.yield_stress=3.55e8 --bracket
  unibuckle solve --config plate.json              # re-run the problem a result holds

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
  {EXIT_BROKEN_PIPE}  standard output closed by its reader (| head -1): ended quietly (mpiexec
     gives the same status); the files written before stay

Single-dash options that argparse does not know go to PETSc/SLEPc under the package's
prefixes, e.g. -unibuckle_eps_view, -unibuckle_eps_tol 1e-12, -unibuckle_ldl_ksp_view.
"""

SWEEP_EPILOG = f"""\
examples:
  unibuckle sweep --config demos/plate.toml --vary plate.thickness=0.002:0.004:3 \\
      --json t.jsonl --plot t.png
  unibuckle sweep --config ssss.toml --vary plate.length=0.5:4:15 \\
      --vary plate.thickness=0.001,0.01 --json grid.jsonl --csv grid.csv
  unibuckle sweep --config demos/box.toml --vary section.thickness=0.001:0.002:5 \\
      --json box_bt.jsonl --plot box_bt.png

--vary PATH=START:STOP:N gives N values from START to STOP (ends included);
--vary PATH=V1,V2,... gives a list. PATH is the dotted path of a number of the
problem file, list entries by index: plate.thickness, material.nu,
edges.left.normal_stress, plate.corners.1.0 (x1), obstacle.zone.0.1, mesh.size,
edges.top.rotational_stiffness, points.0.spacing, material.plies.0.angle,
load.fixed_factor (the fixed part's factor: an interaction curve);
plate.length and plate.width set x1 = x0 + value and y1 = y0 + value. Several
--vary make a grid (the first varies slowest). Values are in the file's units. Give
[mesh] size = h in the file for a cell count that follows the plate's size. A
section's file: section.thickness (b/t, D/t), section.length, section.width,
section.diameter, load.bending_stress, mesh.size.

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
  {EXIT_BROKEN_PIPE}  standard output closed by its reader (| head -1): ended quietly (mpiexec
     gives the same status); the files written before stay
"""

NONLINEAR_EPILOG = f"""\
examples:
  unibuckle nonlinear --case c1 --nx 20 --ny 20 --imperfection 1e-3 --json nl.json
  unibuckle nonlinear --config plate.toml --no-obstacle --control displacement

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
  {EXIT_BROKEN_PIPE}  standard output closed by its reader (| head -1): ended quietly (mpiexec
     gives the same status); the files written before stay

{JSON_HELP}

Single-dash options go to PETSc under the prefixes unibuckle_nl_ (the SNES, its KSP:
-unibuckle_nl_snes_monitor, -unibuckle_nl_snes_view), unibuckle_ (the linear eigen
solves) and unibuckle_prestress_.
"""

#: A negative number as a value, exponent form included (``-1e-3``, ``-2.5E+4``): argparse
#: 3.13 reads ``-1e-3`` as an unknown option ("expected one argument") because its own
#: pattern has no exponent; the package has no option that looks like a number.
NEGATIVE_NUMBER = re.compile(r"^-(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?$")


class Parser(argparse.ArgumentParser):
    """argparse's parser, reading a negative number in exponent form as a value."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER


class Formatter(argparse.RawDescriptionHelpFormatter, argparse.ArgumentDefaultsHelpFormatter):
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


def common_flags() -> Parser:
    """Flags of every subcommand: logging and progress."""
    common = Parser(add_help=False)
    common.add_argument("-v", "--verbose", action="count", default=0, help="log more (-vv: debug)")
    common.add_argument(
        "-q", "--quiet", action="store_true", help="no progress output on stderr (warnings stay)"
    )
    return common


def problem_flags() -> Parser:
    """Flags naming one problem (solve, nonlinear): its source, mesh, --set and --json."""
    from unibuckle_fenicsx.spec.cases import CASES

    problem = Parser(add_help=False)
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
        "--set solver.tau=1e-9 --set plate.thickness=0.004, or add a key the file leaves "
        "out: --set design.yield_stress=3.55e8, a list as obstacle.span=0.05,0.15 "
        "(repeatable; the file's units)",
    )
    problem.add_argument(
        "--json",
        metavar="PATH",
        help="write the result as JSON: every number in SI (Pa, m, N/m) whatever the "
        "file's units (the folder must exist)",
    )
    return problem


def build_parser() -> tuple[argparse.ArgumentParser, dict[str, argparse.ArgumentParser]]:
    """The command line's parser and its subcommands' parsers by name."""
    parser = Parser(
        prog="unibuckle",
        description=(
            "Unilateral buckling of thin plates (Reissner-Mindlin, MITC4) and of box and "
            "tube sections (a shell of the same element): the critical load and the "
            "buckling mode that respects a rigid obstacle on one side (a face, a core). "
            "Arguments starting with a single dash that argparse does not know "
            "(-unibuckle_eps_view, ...) go to PETSc/SLEPc."
        ),
    )
    parser.add_argument(
        "--version", action="version", version=f"%(prog)s {metadata.version('unibuckle_fenicsx')}"
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    common, problem = common_flags(), problem_flags()
    s = sub.add_parser(
        "solve",
        parents=[problem, common],
        help="solve one plate (a paper case or a TOML file) or box or tube section",
        description="Compute the critical load of one problem and print its summary.\n"
        "The problem is a plate (a paper case or a TOML file) or a section: a file with a\n"
        "[section] table (a box or a tube, with a core or hollow), solved on its [mesh]\n"
        "size and levels. Of the solver's flags a section takes --method (auto,\n"
        "interior-point or active-set: the last two with a rigid core only), --tau and\n"
        "--max-iterations (with a core only); the others, and --nx, --ny and\n"
        "--candidate-parallel, are a plate's (refused: exit status 2).",
        epilog=EPILOG,
        formatter_class=Formatter,
    )
    solve_flags(s)
    _sweep_parser(sub, common)
    nonlinear_parser(sub, [problem, common])
    _schema_parser(sub)
    return parser, dict(sub.choices)


def _sweep_parser(sub: Any, common: argparse.ArgumentParser) -> None:
    """The ``sweep`` subcommand: a problem file over a grid of values."""
    w = sub.add_parser(
        "sweep",
        parents=[common],
        help="solve a problem file over a grid of values of some of its numbers",
        description="Solve the problem of --config (a plate's or a section's file) at every\n"
        "point of the --vary grid, writing one JSON line per point (resumable), and\n"
        "optionally a chart of k (a section's: its critical stress over the classical one).",
        epilog=SWEEP_EPILOG,
        formatter_class=Formatter,
    )
    w.add_argument(
        "--config",
        metavar="FILE",
        required=True,
        help="the base problem: a TOML file (its keys: unibuckle schema --keys), or a "
        "result JSON (its input)",
    )
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
        help="JSON-lines output, numbers in SI (the folder must exist); an existing file "
        "of the same sweep is resumed",
    )
    w.add_argument(
        "--csv",
        metavar="PATH",
        help="also write the table printed at the end as CSV (the folder must exist): its "
        "columns, numbers at full precision, an empty cell where it shows -",
    )
    w.add_argument(
        "--plot",
        metavar="PNG",
        help="draw the buckling coefficient k = sigma t b^2/(pi^2 D) against the first "
        "--vary (bilateral: without the obstacle, and "
        "unilateral: with it, with the exact curves where they exist; a section: sigma_cr "
        "over the classical stress, hollow and with its core)",
    )
    w.add_argument(
        "--ranks-per-point",
        type=int,
        default=1,
        metavar="R",
        help="under mpiexec: ranks of each point's mesh (1: one point per rank)",
    )


def _schema_parser(sub: Any) -> None:
    """The ``schema`` subcommand: the JSON Schema of a problem file."""
    k = sub.add_parser(
        "schema",
        help="print the JSON Schema of a problem file (or its dotted keys)",
        description="Print the JSON Schema of a problem file: for editor completion of\n"
        "TOML files (e.g. a '#:schema' line for taplo) and the reference of the keys.\n"
        "The repository keeps it in schema/unibuckle-problem.schema.json.",
        epilog="examples:\n"
        "  unibuckle schema --keys                  # every dotted key of a problem file\n"
        "  unibuckle schema --output problem.schema.json",
        formatter_class=Formatter,
    )
    k.add_argument("--keys", action="store_true", help="print the dotted keys instead")
    k.add_argument("--output", metavar="PATH", help="write to PATH instead of stdout")


def solve_flags(s: argparse.ArgumentParser) -> None:
    """The ``solve`` subcommand's own flags (the solver's, and --output)."""
    _method_flags(s)
    s.add_argument(
        "--max-iterations",
        type=int,
        metavar="N",
        help="active-set: iterates per seed and mesh level (the feasible descent, the last "
        "fallback, may use 10x as many solves); interior-point: the same for its "
        "active-set fallback; N >= 1 " + _solver_default("max_iterations"),
    )
    s.add_argument(
        "--bound-budget",
        type=int,
        metavar="N",
        help="active-set: eigen solves for the lattice lower bound, N >= 0 "
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
        help="run the verified bracket when several pencil eigenvalues lie below the load "
        "(long plates) whatever its cost, down to a relative width of 1e-6 (by default: "
        "only where it costs at most 3 free solves)",
    )
    s.add_argument(
        "--penalty",
        type=float,
        metavar="RHO",
        help="penalty stiffness rho for --method penalty (relative to max diag A), 1e-6 to 1e16 "
        + _solver_default("penalty"),
    )
    s.add_argument(
        "--tau",
        type=float,
        help="relative feasibility tolerance, in [1e-12, 0.01] " + _solver_default("tau"),
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
        "parent must exist): NAME_w.bp, NAME_theta.bp, NAME.pvd (a section: NAME_u.bp, "
        "NAME_outward.bp, NAME.pvd), with NAME the problem's name, characters other than "
        "letters, digits, '.', '-' and '_' replaced by '_'",
    )


def _method_flags(s: argparse.ArgumentParser) -> None:
    """The ``solve`` flags that choose the method and bound the enumeration."""
    s.add_argument(
        "--method",
        choices=list(METHODS),
        help="unilateral algorithm. A plate's auto: exact enumeration when 2^i <= "
        "--max-candidates (i: the nodes the obstacle acts on) and its estimated time fits "
        "--enumeration-budget, else interior-point on thin plates (t/b < 0.02) and "
        "active-set on thicker ones; enumerate alone = the paper's stopping rule. A "
        "section's auto: interior-point from about 10^4 DOFs, checked by the active "
        "set's seeds on its coarsest section, below that both interior-point and active-set, "
        "the lower load kept; a section takes no other "
        "method " + _solver_default("method"),
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
        help="enumerate: refuse above N candidate sets, N >= 1 "
        + _solver_default("max_candidates"),
    )
    s.add_argument(
        "--enumeration-budget",
        type=float,
        metavar="SECONDS",
        help="auto: enumerate only if the estimated time is below this (s, > 0) "
        + _solver_default("enumeration_budget_s"),
    )


def nonlinear_parser(sub: Any, parents: list[Parser]) -> None:
    """The ``nonlinear`` subcommand's arguments (defaults: :class:`NonlinearOptions`)."""
    from unibuckle_fenicsx.nonlinear.choices import CONTROLS, SHAPES
    from unibuckle_fenicsx.nonlinear.options import NonlinearOptions

    defaults = NonlinearOptions()
    n = sub.add_parser(
        "nonlinear",
        parents=parents,
        help="validate the critical load by the load path of the imperfect plate "
        "(von Karman, against the obstacle)",
        description="Follow the load path of the imperfect von Karman plate against the\n"
        "obstacle and read the buckling load off it (Southwell, steepest rise), next to\n"
        "the linear critical load.",
        epilog=NONLINEAR_EPILOG,
        formatter_class=Formatter,
    )
    n.add_argument(
        "--imperfection",
        type=float,
        default=defaults.imperfection,
        metavar="DELTA",
        help="imperfection amplitude max|w0| / thickness, in (0, 1]",
    )
    n.add_argument(
        "--shape",
        choices=list(SHAPES),
        default=defaults.shape,
        help="imperfection shape: the linear free or unilateral mode (auto: unilateral "
        "with the obstacle, free without)",
    )
    n.add_argument(
        "--control",
        choices=list(CONTROLS),
        default=defaults.control,
        help="load control (edge traction, adaptive steps) or displacement control (end "
        "shortening of the loaded edges; uniaxial compression only)",
    )
    n.add_argument("--no-obstacle", action="store_true", help="the same plate without its obstacle")
    n.add_argument(
        "--max-load",
        type=float,
        default=defaults.max_load,
        metavar="RATIO",
        help="stop at RATIO times the linear critical load, in (0, 5]",
    )
    n.add_argument(
        "--max-step",
        type=float,
        default=defaults.max_step,
        metavar="FRACTION",
        help="largest load step, relative to the linear critical load, in (0, 1]",
    )


#: Flags that matter only for some methods: flag -> (the methods whose options Struct
#: reads its SolverSpec field, the field).
METHOD_FLAGS = {
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


def solver_changes(args: argparse.Namespace) -> tuple[dict[str, str | float | bool], list[str]]:
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
    changes: dict[str, str | float | bool] = {
        k: v for k, v in {"method": args.method, "tau": args.tau}.items() if v is not None
    }
    if args.no_certify:
        changes["certify"] = False
    if args.bracket:
        changes["bracket"] = True
    given = []
    for flag, value in values.items():
        if value is not None:
            changes[METHOD_FLAGS[flag][1]] = value
            given.append(flag)
    return changes, given


def unused_flags(flags: list[str], method: str, chosen: str | None = None) -> list[str]:
    """The flags of ``flags`` that do not apply to ``method`` (the one in force).

    Under "auto" a flag of the enumeration applies if auto enumerates: before the solve
    (``chosen`` None) it is kept; after it, it is unused when ``chosen`` (the method
    that answered) is not the enumeration.
    """
    unused = []
    for flag in flags:
        methods = METHOD_FLAGS[flag][0]
        if method in methods:
            continue
        if method == "auto" and "enumerate" in methods and chosen in (None, "enumerate"):
            continue
        unused.append(f"{flag} (applies to --method {' or '.join(methods)})")
    return unused


#: Option names of the nonlinear analysis that are also command-line flags.
NONLINEAR_FLAGS = ("imperfection", "shape", "control", "max_load", "max_step")
