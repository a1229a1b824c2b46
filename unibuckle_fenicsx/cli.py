"""Command line: ``unibuckle solve --case c1 --nx 20 --ny 20 --json out.json``.

Unrecognised ``-prefix_option value`` pairs are passed to PETSc, e.g.
``-unibuckle_eps_view`` or ``-unibuckle_prestress_ksp_view``.
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Sequence

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="unibuckle",
        description=(
            "Unilateral buckling of thin plates (Reissner-Mindlin, MITC4): the critical "
            "load and the buckling mode that respects a rigid obstacle on one side. "
            "Arguments starting with a single dash that argparse does not know "
            "(-unibuckle_eps_view, ...) go to PETSc/SLEPc."
        ),
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    s = sub.add_parser(
        "solve",
        help="solve one problem (a paper case or a TOML file)",
        description="Compute the critical load of one problem and print a one-line summary.",
    )
    src = s.add_mutually_exclusive_group(required=True)
    src.add_argument(
        "--case",
        choices=["free", "c1", "c2", "c3"],
        help="the paper's plate: free (no obstacle), c1 = [-0.04,0.04]x[-0.05,0.05], "
        "c2 = [-0.04,0.04]x[-0.02,0.02], c3 = whole plate",
    )
    src.add_argument("--config", metavar="TOML", help="problem file (schema in the README)")
    s.add_argument("--nx", type=int, help="cells along x (default: paper 20, or the TOML's)")
    s.add_argument("--ny", type=int, help="cells along y (default: paper 20, or the TOML's)")
    s.add_argument(
        "--method",
        choices=["auto", "enumerate", "active-set", "penalty"],
        help="unilateral algorithm (default auto: exact enumeration if 2^i <= "
        "--max-candidates, else active-set; enumerate alone = the paper's stopping rule)",
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
        help="enumerate: refuse above N candidate sets (default 100000)",
    )
    s.add_argument(
        "--penalty",
        type=float,
        metavar="RHO",
        help="penalty stiffness rho for --method penalty (relative to max diag A)",
    )
    s.add_argument("--tau", type=float, help="relative feasibility tolerance (default 1e-8)")
    s.add_argument(
        "--candidate-parallel",
        action="store_true",
        help="under mpiexec: each rank holds a serial copy and enumerates a share "
        "of the candidate sets (default: distribute the mesh)",
    )
    s.add_argument("--json", metavar="PATH", help="write the result as JSON")
    s.add_argument(
        "--output",
        metavar="DIR",
        help="write the mode, obstacle zone and contact set as VTX (.bp) for ParaView",
    )
    s.add_argument("-v", "--verbose", action="count", default=0, help="log more (-vv: debug)")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    args, rest = _parser().parse_known_args(argv)
    unknown = [a for a in rest if a.startswith("--")]
    if unknown:
        _parser().error(f"unrecognized arguments: {' '.join(unknown)}")

    import petsc4py
    from mpi4py import MPI  # before petsc4py: loads libmpi

    petsc4py.init([sys.argv[0], *rest])

    from unibuckle_fenicsx.analysis import solve
    from unibuckle_fenicsx.cases import paper_case
    from unibuckle_fenicsx.config import load_toml
    from unibuckle_fenicsx.results import write_json, write_vtx

    comm = MPI.COMM_WORLD
    logging.basicConfig(
        level=[logging.WARNING, logging.INFO, logging.DEBUG][min(args.verbose, 2)],
        format="%(levelname)s %(name)s: %(message)s",
    )
    try:
        spec = paper_case(args.case) if args.case else load_toml(args.config)
        if args.nx is not None or args.ny is not None:
            spec = spec.with_mesh(
                spec.mesh.nx if args.nx is None else args.nx,
                spec.mesh.ny if args.ny is None else args.ny,
            )
        changes = {
            "method": args.method,
            "max_candidates": args.max_candidates,
            "penalty": args.penalty,
            "tau": args.tau,
        }
        changes = {k: v for k, v in changes.items() if v is not None}
        if args.complete:
            changes["complete"] = True
        if args.until_proven:
            changes["until_proven"] = True
        spec = spec.with_solver(**changes)
    except (ValueError, OSError) as err:
        if comm.rank == 0:
            print(f"unibuckle: error: {err}", file=sys.stderr)
        return 2
    try:
        analysis = solve(spec, comm, candidate_parallel=args.candidate_parallel)
    except ValueError as err:
        if comm.rank == 0:
            print(f"unibuckle: error: {err}", file=sys.stderr)
        return 2
    with analysis:
        if args.output:
            write_vtx(analysis, args.output)
    if comm.rank == 0:
        print(analysis.result.summary())
        if args.json:
            write_json(analysis.result, args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
