"""``unibuckle nonlinear``: the load path of the imperfect plate against the obstacle."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from msgspec.structs import replace

from unibuckle_fenicsx.cli.flags import NONLINEAR_FLAGS
from unibuckle_fenicsx.cli.problem import (
    petsc_solver_changes,
    refuse_flag_and_set,
    spec_from_args,
    warn_coarse_mesh,
    warn_input,
    warn_unused_design,
)
from unibuckle_fenicsx.cli.status import print_out, report_failure
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.outcome import Outcome
from unibuckle_fenicsx.spec.section import SectionProblemSpec


def nonlinear_command(args: argparse.Namespace, comm: Any) -> int:
    """``unibuckle nonlinear``: the load path, the Southwell and inflection loads."""
    import json

    from unibuckle_fenicsx.nonlinear import NonlinearOptions, solve_nonlinear

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
    except InputError as err:
        message = str(err)
        for name in NONLINEAR_FLAGS:  # name the flag, not the option
            if message.startswith(name):
                message = "--" + name.replace("_", "-") + message[len(name) :]
        raise InputError(message) from None
    changes, named = petsc_solver_changes()  # the linear solves' -unibuckle_eps_tol
    refuse_flag_and_set(args.settings, named)
    spec = spec_from_args(args)
    if isinstance(spec, SectionProblemSpec):
        raise InputError("unibuckle nonlinear: a section's load path is not modelled (plates only)")
    if args.shape == "unilateral" and (args.no_obstacle or not spec.all_obstacles):
        why = "--no-obstacle removes it" if args.no_obstacle else "the problem has none"
        raise InputError(
            f"--shape unilateral takes the imperfection from the unilateral mode, which needs "
            f"an obstacle, and {why}: give --shape free (or auto)"
        )
    spec = replace(spec, solver=replace(spec.solver, **changes))  # in range: checked above
    warn_input(spec, comm, design=False)
    warn_unused_design(spec, "unibuckle nonlinear", comm)
    # A refused input or a failed solve raises: main() tells the outcome.
    analysis = solve_nonlinear(spec, options, comm)
    with analysis:
        result = analysis.result
    warn_coarse_mesh(spec, comm)
    unwritten = None
    if comm.rank == 0:
        if args.json:
            try:
                Path(args.json).write_text(json.dumps(result.as_dict(), indent=2) + "\n")
            except OSError as err:
                unwritten = f"could not write --json {args.json}: {err}"
        print_out(result.summary())
        if not result.certified:
            print(
                f"unibuckle: error: {result.shortfall()}"
                + (f"; the path obtained is in {args.json}" if args.json and not unwritten else ""),
                file=sys.stderr,
            )
    unwritten = comm.bcast(unwritten, root=0)
    if unwritten is not None:
        return report_failure(comm, f"{unwritten}; the result is the summary above")
    return Outcome.of(result).exit_status
