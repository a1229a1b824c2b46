"""``unibuckle sweep``: a problem over a grid of values (one JSON line per point)."""

from __future__ import annotations

import argparse
import logging
from typing import Any

from unibuckle_fenicsx.cli.problem import load_config, petsc_solver_changes
from unibuckle_fenicsx.cli.status import print_out, report_failure
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.outcome import Outcome


def _check_chart(base: Any) -> None:
    """Refuse --plot for a sweep whose scaled load has no edge stress (before any solve).

    The chart draws k = t lambda b^2/(pi^2 D), a buckling coefficient of edge loads; for a
    temperature rise alone lambda is a factor on the rise and k means nothing.
    """
    from unibuckle_fenicsx.spec import is_section, problem_from_dict

    if is_section(base):  # loaded at its ends: the chart's ordinate is its stress
        return
    if not problem_from_dict(base).plate.loaded:
        raise InputError(
            "--plot draws the buckling coefficient k of edge loads; this problem's scaled "
            "load is a temperature rise alone (lambda is a factor on it, k is not defined): "
            "leave --plot out, or load an edge"
        )


def _warn_points(points: list[Any], specs: list[Any], comm: Any) -> None:
    """Warnings on stderr, before any solve, of the sweep points' inputs: one per kind.

    Each kind of ``unibuckle solve``'s warnings before its solve
    (:func:`~unibuckle_fenicsx.cli.problem.input_notes`: E in another unit, the plate
    model's range, a design material) and of cells too coarse: the note of the first
    such point, and how many there are. A section's are those its solve logs before
    it starts (:func:`_section_notes`), which the sweep's silenced solves do not print.
    ``points`` and their problems ``specs`` are those
    :func:`~unibuckle_fenicsx.sweep.run_sweep` read (its ``check``).
    """
    import sys

    from unibuckle_fenicsx.cli.problem import input_notes
    from unibuckle_fenicsx.spec.checks import coarse_mesh_note
    from unibuckle_fenicsx.spec.section import SectionProblemSpec

    found: dict[str, list[tuple[int, Any, str]]] = {}
    for k, (point, spec) in enumerate(zip(points, specs, strict=True)):
        notes = input_notes(spec)
        if isinstance(spec, SectionProblemSpec):
            notes.update(_section_notes(spec))
        else:
            coarse = coarse_mesh_note(spec.plate, spec.mesh, spec.units)
            if coarse is not None:
                notes["coarse"] = coarse
        for kind, note in notes.items():
            found.setdefault(kind, []).append((k, point, note))
    if comm.rank != 0:  # every rank checks the points (a refusal on every rank)
        return
    for kind, hits in found.items():
        k, point, note = hits[0]
        which = "have cells too coarse" if kind == "coarse" else "draw this warning"
        print(
            f"unibuckle: warning: {len(hits)} of {len(points)} sweep points {which}; "
            f"point {k} {point}: {note}",
            file=sys.stderr,
        )


def _section_notes(spec: Any) -> dict[str, str]:
    """A section's warnings before its solve, by kind: cells too coarse, a thick wall.

    Those :func:`~unibuckle_fenicsx.section_analysis.solve_section` logs before it
    starts (its ``coarse_mesh_note``, ``thick_wall_note``, and with ``[design]`` the
    steel's Poisson's ratio), in the file's units.
    """
    from unibuckle_fenicsx.en1993 import steel_poisson_note
    from unibuckle_fenicsx.model.shell.section import section_parameters
    from unibuckle_fenicsx.section_analysis import coarse_mesh_note, thick_wall_note
    from unibuckle_fenicsx.spec.base import file_units

    parameters = section_parameters(spec)
    with file_units(spec.units):
        notes = {
            "coarse": coarse_mesh_note(parameters),
            "thick wall": thick_wall_note(parameters),
            "design material": None
            if spec.design is None
            else steel_poisson_note(spec.material.nu),
        }
    return {kind: note for kind, note in notes.items() if note is not None}


def sweep_columns(lines: list[dict[str, Any]]) -> tuple[list[str], list[list[Any]]]:
    """The sweep table's header and its rows' values, one row per point.

    The swept values as the file gives them (in its units, named), the critical load (a
    section's: the extreme fibre's stress, as its summary's ``sigma_cr``) in the results'
    stress unit, its ratio to the load without the obstacle (the hollow section's), k,
    the certificate's status and the point's status; None where a point has no value.
    """
    from unibuckle_fenicsx.spec import UNITS
    from unibuckle_fenicsx.viz.charts import _unit

    if not lines:
        return [], []
    units = str(lines[0].get("units", "SI"))
    scale, unit = UNITS[units][1:]
    section = any("classical_stress_Pa" in line for line in lines)
    paths = list(lines[0].get("point", {}))
    header = [
        *(f"{path} ({_unit(path, units)})" if _unit(path, units) else path for path in paths),
        f"{'sigma_cr' if section else 'lambda_c'} ({unit})",
        "x hollow" if section else "x free",
        "k",
        "certificate",
        "status",
    ]

    def number(value: Any) -> float | None:
        return value if isinstance(value, (int, float)) else None

    rows = []
    for line in lines:
        load = number(line.get("compression_Pa") if section else line.get("critical_load_Pa"))
        cert = line.get("certificate")
        rows.append(
            [
                *(number(line.get("point", {}).get(path)) for path in paths),
                None if load is None else load / scale,
                number(line.get("ratio_to_free")),
                number(line.get("buckling_coefficient_k")),
                str(cert.get("status")) if isinstance(cert, dict) and "status" in cert else None,
                None if line.get("status") is None else str(line["status"]),
            ]
        )
    return header, rows


def sweep_table(lines: list[dict[str, Any]]) -> str:
    """The sweep's points as a table for the terminal (:func:`sweep_columns`).

    Swept values to 6 significant digits, the load in exponent form to 7, its ratio to 4
    decimals, k to 4 decimals (4 significant digits below 0.1,
    :func:`~unibuckle_fenicsx.results.records.coefficient_text`); ``-`` where a point has
    no value.
    """
    from unibuckle_fenicsx.results.records import coefficient_text

    header, rows = sweep_columns(lines)
    if not header:
        return ""
    formats = [".6g"] * (len(header) - 5) + [".6e", ".4f", "k", "", ""]
    cells = [
        [
            "-"
            if value is None
            else coefficient_text(value)
            if text == "k"
            else format(value, text)
            for value, text in zip(row, formats, strict=True)
        ]
        for row in rows
    ]
    widths = [max(len(r[i]) for r in [header, *cells]) for i in range(len(header))]
    return "\n".join(
        "  ".join(cell.ljust(w) for cell, w in zip(row, widths, strict=True)).rstrip()
        for row in [header, *cells]
    )


def write_sweep_csv(lines: list[dict[str, Any]], path: str) -> None:
    """Write the sweep table (:func:`sweep_columns`) to ``path`` as CSV.

    The terminal table's columns and header; numbers at full precision (Python's
    shortest repr, read back exactly), an empty cell where the table shows ``-``.

    Raises:
        OSError: ``path`` cannot be written.
    """
    import csv

    header, rows = sweep_columns(lines)
    with open(path, "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f)
        writer.writerow(header)
        for row in rows:
            writer.writerow(
                ["" if v is None else repr(v) if isinstance(v, float) else v for v in row]
            )


def _base_problem(path: str, variations: list[Any], vary: list[str]) -> dict[str, Any]:
    """The base problem of ``--config path``, with the solver keys PETSc's options set.

    ``-unibuckle_eps_tol`` is every point's ``solver.eps_tol``, recorded in each line's
    ``input`` as in ``unibuckle solve``'s result
    (:func:`~unibuckle_fenicsx.cli.problem.petsc_solver_changes`).

    Raises:
        InputError: The option out of its range, or given with ``--vary`` on its key
            (the texts ``vary`` of the ``variations``).
    """
    from unibuckle_fenicsx.sweep import base_mapping

    changes, named = petsc_solver_changes()
    for v, text in zip(variations, vary, strict=True):
        if v.path in named:
            raise InputError(
                f"{named[v.path]} and --vary {text} both set {v.path}: give one of them"
            )
    base: dict[str, Any] = load_config(path, base_mapping)
    if changes:
        base["solver"] = {**base["solver"], **changes}
    return base


def sweep_command(args: argparse.Namespace, comm: Any) -> int:
    """``unibuckle sweep``: the grid, the JSON lines, the chart."""
    from unibuckle_fenicsx.sweep import parse_variation, run_sweep

    def fail(message: str) -> int:
        return report_failure(comm, message)

    if args.plot and comm.rank == 0:
        try:
            import matplotlib as mpl  # noqa: F401
        except ImportError:
            return fail("--plot needs matplotlib: pip install 'unibuckle_fenicsx[demo]'")
    # Each point's own progress lines and warnings would interleave with the sweep's
    # (a plate's warnings are in the point's JSON line, under details; those before the
    # solve, a plate's and a section's, are said once for all points: _warn_points).
    if args.verbose == 0:
        logging.getLogger("unibuckle_fenicsx").setLevel(logging.ERROR)
        logging.getLogger("unibuckle_fenicsx.progress").setLevel(logging.ERROR)
        sweep_lines = logging.getLogger("unibuckle_fenicsx.progress.sweep")
        sweep_lines.setLevel(logging.ERROR if args.quiet or comm.rank else logging.INFO)
    try:
        variations = [parse_variation(v) for v in args.vary]
        base = _base_problem(args.config, variations, args.vary)
        if args.plot:
            _check_chart(base)
        lines = run_sweep(
            base,
            variations,
            args.json,
            comm,
            ranks_per_point=args.ranks_per_point,
            progress=not args.quiet,
            check=lambda points, specs: _warn_points(points, specs, comm),
        )
    except OSError as err:  # a refused input or a failed point raises: main() tells
        return fail(str(err))
    unwritten = None
    if comm.rank == 0:
        from collections import Counter

        counts = Counter(line["status"] for line in lines)
        print_out(sweep_table(lines))
        print_out(
            f"sweep: {len(lines)} points in {args.json}: "
            + ", ".join(f"{n} {status}" for status, n in sorted(counts.items()))
        )
        if args.csv:
            try:
                write_sweep_csv(lines, args.csv)
                print_out(f"sweep: table {args.csv}")
            except OSError as err:  # the folder went away during the sweep
                unwritten = f"--csv {args.csv}: {err}"
        if args.plot:
            from unibuckle_fenicsx.viz.charts import plot_sweep

            print_out(f"sweep: chart {plot_sweep(lines, variations, base, args.plot)}")
    unwritten = comm.bcast(unwritten, root=0)
    if unwritten is not None:
        return fail(f"could not write {unwritten}; the table is above, the points in {args.json}")
    ok = all(line["status"] == Outcome.OK for line in lines)
    return (Outcome.OK if ok else Outcome.NOT_CERTIFIED).exit_status
