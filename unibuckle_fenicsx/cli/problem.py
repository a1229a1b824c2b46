"""The problem a run solves: ``--case`` or ``--config``, ``--nx``/``--ny`` and ``--set``."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from unibuckle_fenicsx.errors import InputError

if TYPE_CHECKING:  # pragma: no cover
    from unibuckle_fenicsx.spec import ProblemSpec
from unibuckle_fenicsx.spec.section import SectionProblemSpec


def warn_plate_model(spec: ProblemSpec | SectionProblemSpec, comm: Any) -> None:
    """A warning on stderr when a plate lies outside the plate model's usual range.

    A section's walls are checked by the section's solve (its log's warnings).
    """
    from unibuckle_fenicsx.spec.checks import plate_model_note

    if not isinstance(spec, SectionProblemSpec):
        _warn(plate_model_note(spec.plate, spec.units), comm)


def warn_modulus_unit(spec: ProblemSpec | SectionProblemSpec, comm: Any) -> None:
    """A warning on stderr when E lies below any structural material's: another unit?"""
    from unibuckle_fenicsx.spec.material import modulus_note

    _warn(modulus_note(spec.material.E, spec.units), comm)


def warn_design_material(spec: ProblemSpec | SectionProblemSpec, comm: Any) -> None:
    """A warning on stderr when ``[design]`` is asked of a Poisson's ratio not a steel's.

    A section's is warned of by the section's solve (its log's warnings).
    """
    from unibuckle_fenicsx.en1993 import steel_poisson_note

    if not isinstance(spec, SectionProblemSpec) and spec.design is not None:
        _warn(steel_poisson_note(spec.material.nu), comm)


def warn_unused_design(spec: ProblemSpec, command: str, comm: Any) -> None:
    """A warning on stderr when ``[design]`` is given to a command that writes no design output."""
    if spec.design is not None:
        _warn(
            f"{command} writes no design output: [design] is read by unibuckle solve and "
            "unibuckle sweep",
            comm,
        )


def warn_coarse_mesh(spec: ProblemSpec | SectionProblemSpec, comm: Any) -> None:
    """A warning on stderr, after a solve, when a plate's cells are too coarse for a buckle.

    A section's cells are checked by the section's solve (its log's warnings).
    """
    from unibuckle_fenicsx.spec.checks import coarse_mesh_note

    if not isinstance(spec, SectionProblemSpec):
        _warn(coarse_mesh_note(spec.plate, spec.mesh, spec.units), comm)


def _warn(note: str | None, comm: Any) -> None:
    """Print ``note``, if any, as a warning on stderr from rank 0."""
    if note is not None and comm.rank == 0:
        print(f"unibuckle: warning: {note}", file=sys.stderr)


def spec_from_args(args: argparse.Namespace) -> ProblemSpec | SectionProblemSpec:
    """The problem of --case or --config, with --set and --nx/--ny applied."""
    from unibuckle_fenicsx.spec import load_problem
    from unibuckle_fenicsx.spec.cases import paper_case

    if args.case:
        spec = _with_settings(paper_case(args.case), args.settings)
    else:
        try:
            spec = load_config(args.config, load_problem)
        except InputError as err:
            spec = _repaired(args.config, args.settings, err)
        else:
            spec = _with_settings(spec, args.settings)
    if isinstance(spec, SectionProblemSpec):
        if args.nx is not None or args.ny is not None:
            raise InputError("--nx, --ny set a plate's cells; a section takes [mesh] size = h")
        if getattr(args, "output", None):
            raise InputError(
                f"--output {args.output}: a section's fields are not written (its mode: the "
                "Python API's SectionAnalysis.figure_data); give --json for the result"
            )
        return spec
    if args.nx is not None or args.ny is not None:
        spec = spec.with_mesh(
            spec.mesh.nx if args.nx is None else args.nx,
            spec.mesh.ny if args.ny is None else args.ny,
        )
    return spec


def _with_settings(
    spec: ProblemSpec | SectionProblemSpec, settings: Sequence[str]
) -> ProblemSpec | SectionProblemSpec:
    """``spec`` with the ``--set PATH=VALUE`` changes (dotted paths of the problem file).

    Raises:
        ValueError: A setting without '=', a path the problem file does not have, or a
            value the schema refuses (the message names the path).
    """
    from unibuckle_fenicsx.spec import problem_to_dict

    if not settings:
        return spec
    return _set(problem_to_dict(spec, units=spec.units), settings, spec.name)


def _repaired(
    path: str, settings: Sequence[str], error: InputError
) -> ProblemSpec | SectionProblemSpec:
    """The problem file at ``path`` that its checks refuse, with ``--set`` applied first.

    A file refused by a check (``error``) may be repaired by the settings: they are
    applied to the file's tables as written, then checked (an error then names the
    settings). ``error`` itself is raised when there is nothing to apply, when the file
    cannot be read as tables or is a result's JSON (its ``input`` is in SI, its settings
    in the units it solved), or when a setting cannot be applied to the file as written
    (a key it leaves out).
    """
    from pathlib import Path

    from unibuckle_fenicsx.spec import spec_from_dict
    from unibuckle_fenicsx.spec.files import read_problem_data

    if not settings:
        raise error
    try:
        data, units = read_problem_data(path)
    except (InputError, OSError):
        raise error from None
    if units is not None:
        raise error
    try:
        _apply(data, settings)
    except InputError:
        raise error from None
    try:
        return spec_from_dict(data, name=Path(path).stem)
    except ValueError as err:
        raise InputError(f"{path}: with --set {' --set '.join(settings)}: {err}") from None


def _set(
    data: dict[str, Any], settings: Sequence[str], name: str
) -> ProblemSpec | SectionProblemSpec:
    """The problem of the tables ``data`` with the ``--set PATH=VALUE`` changes applied."""
    from unibuckle_fenicsx.spec import spec_from_dict

    _apply(data, settings)
    try:
        return spec_from_dict(data, name=name)
    except ValueError as err:
        raise InputError(f"--set {' '.join(settings)}: {err}") from None


def _apply(data: dict[str, Any], settings: Sequence[str]) -> None:
    """Apply the ``--set PATH=VALUE`` changes to the tables ``data`` in place."""
    from unibuckle_fenicsx.sweep import set_text

    for setting in settings:
        path, sep, text = setting.partition("=")
        if not sep or not path.strip():
            raise InputError(f"--set {setting!r}: give PATH=VALUE, e.g. solver.tau=1e-9")
        set_text(data, path.strip(), text.strip())


def load_config(path: str, load: Any) -> Any:
    """``load(path)``, an unreadable file named with its option (ValueError)."""
    try:
        return load(path)
    except OSError as err:
        raise InputError(f"--config {path}: cannot read it ({err.strerror or err})") from None
