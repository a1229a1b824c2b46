"""``unibuckle solve``: one problem, its summary, JSON and fields."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from msgspec.structs import replace

from unibuckle_fenicsx.cli.flags import METHOD_FLAGS, solver_changes, unused_flags
from unibuckle_fenicsx.cli.problem import (
    name_flag,
    petsc_solver_changes,
    refuse_flag_and_set,
    spec_from_args,
    warn_coarse_mesh,
    warn_input,
)
from unibuckle_fenicsx.cli.status import print_out, report_failure
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.outcome import Outcome

#: The solver's switches as flags: their key's name -> the flag.
SWITCHES = {"certify": "--no-certify", "bracket": "--bracket"}


def solve_command(args: argparse.Namespace, comm: Any) -> int:
    """``unibuckle solve``: one problem, its summary, JSON and fields."""
    from unibuckle_fenicsx.results.files import write_fields, write_section_fields
    from unibuckle_fenicsx.run import analyse
    from unibuckle_fenicsx.spec.section import SectionProblemSpec

    # A refused input or a failed solve raises: main() tells the outcome.
    changes, flags = solver_changes(args)
    named = {f"solver.{key}": f"--{key}" for key in ("method", "tau") if key in changes}
    named.update({f"solver.{key}": flag for key, flag in SWITCHES.items() if key in changes})
    named.update({f"solver.{METHOD_FLAGS[flag][1]}": flag for flag in flags})
    petsc_changes, petsc_named = petsc_solver_changes()
    changes.update(petsc_changes)  # the eigen solves take them: the record and checks too
    named.update(petsc_named)
    refuse_flag_and_set(args.settings, named)
    spec = spec_from_args(args)
    try:
        spec = replace(spec, solver=replace(spec.solver, **changes))
    except InputError as err:  # name the flag typed, beside the key it sets
        raise name_flag(err, named) from None
    method = spec.solver.method  # the flag's, or the problem file's
    _warn_unused(flags, method, comm)
    warn_input(spec, comm)
    analysis = analyse(spec, comm, candidate_parallel=args.candidate_parallel)
    unwritten = None
    with analysis:
        if args.output:
            writer = write_section_fields if isinstance(spec, SectionProblemSpec) else write_fields
            try:
                writer(analysis, args.output)  # type: ignore[arg-type]
            except OSError as err:  # the folder went away during the solve
                unwritten = f"--output {args.output}: {err}"
    result = analysis.result
    _warn_unused(flags, method, comm, result)
    warn_coarse_mesh(spec, comm)
    return _report(args, result, comm, unwritten)


def _report(args: argparse.Namespace, result: Any, comm: Any, unwritten: str | None) -> int:
    """The summary, the JSON (rank 0) and the exit status of a solved ``result``."""
    from unibuckle_fenicsx.results.files import write_json

    outcome = Outcome.of(result)
    certificate = result.certificate
    if comm.rank == 0:
        if args.json:
            try:
                write_json(result, args.json)
            except OSError as err:
                unwritten = f"--json {args.json}: {err}"
        print_out(result.summary())
        coarse = resolution_note(result.load_resolution)
        if coarse is not None:
            print(f"unibuckle: warning: {coarse}", file=sys.stderr)
        if outcome is not Outcome.OK:
            notes = "; ".join([] if certificate is None else certificate.notes)
            notes = notes or "see the certificate"
            print(
                f"unibuckle: error: no certified critical state ({notes}); the bracket "
                f"[{result.lower_bound_Pa}, {result.upper_bound_Pa}] Pa is "
                + (f"in {args.json}" if args.json and unwritten is None else "above"),
                file=sys.stderr,
            )
    unwritten = comm.bcast(unwritten, root=0)
    if unwritten is not None:
        return report_failure(comm, f"could not write {unwritten}; the result is the summary above")
    return outcome.exit_status


#: The relative load resolution above which a warning says so (1 %): a load fixed only
#: that closely is no design value; well-conditioned plates are many orders below it
#: (docs/guide/results.md, ``load_resolution``; it grows as (b/t)^2).
RESOLUTION_WARNING = 1e-2


def resolution_note(resolution: float | None) -> str | None:
    """The warning on a critical load that double precision fixes only to ``resolution``.

    ``resolution``: the result's ``load_resolution`` (relative), or None.
    """
    if resolution is None or resolution <= RESOLUTION_WARNING:
        return None
    return (
        f"double precision fixes the critical load only to {resolution:.2g} of it "
        "(load_resolution, a rounding bound): the plate, or a section's wall, is so thin "
        "against its width that its stiffness loses that many digits; the load, k and "
        "the design values may be off by as much"
    )


def _warn_unused(flags: list[str], method: str, comm: Any, result: Any = None) -> None:
    """Warn of the flags that do not apply to ``method`` (rank 0).

    Before the solve (``result`` None): those that cannot apply; after it, under auto,
    the enumeration's flags that auto's choice (``result.method``) left unused.
    """
    if comm.rank != 0 or (result is not None and method != "auto"):
        return
    if result is None:
        for flag in unused_flags(flags, method):
            print(f"unibuckle: warning: {flag} is ignored with --method {method}", file=sys.stderr)
        return
    for flag in unused_flags(flags, "auto", result.method):
        print(
            f"unibuckle: warning: {flag} was not used: auto chose {result.method} "
            f"({result.method_chosen_by.removeprefix('auto: ')})",
            file=sys.stderr,
        )
