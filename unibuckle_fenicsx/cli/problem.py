"""The problem a run solves: ``--case`` or ``--config``, ``--nx``/``--ny`` and ``--set``."""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from unibuckle_fenicsx.errors import InputError

if TYPE_CHECKING:  # pragma: no cover
    from unibuckle_fenicsx.spec import ProblemSpec
from unibuckle_fenicsx.spec.section import SectionProblemSpec


def input_notes(spec: ProblemSpec | SectionProblemSpec, design: bool = True) -> dict[str, str]:
    """The warnings a problem draws before its solve, by kind (none: an empty dict).

    ``"modulus"``: E below any structural material's (another unit?); ``"plate model"``:
    a plate outside the plate model's usual range; with ``design``, ``"design
    material"``: ``[design]`` asked of a Poisson's ratio not a steel's; ``"design yield
    stress"``: a t <= 40 mm f_y of EN 1993-1-1 Table 3.1 on a thicker plate; ``"design
    stainless"``: E = 200 GPa, stainless steel's, whose rho EN 1993-1-4 gives. A section's walls
    and its design material are checked by the section's solve (its log's warnings).
    ``unibuckle solve`` and ``unibuckle nonlinear`` print them (:func:`warn_input`),
    ``unibuckle sweep`` once per kind over its points.
    """
    from unibuckle_fenicsx.en1993 import stainless_note, steel_poisson_note, yield_stress_note
    from unibuckle_fenicsx.spec.checks import plate_model_note
    from unibuckle_fenicsx.spec.material import modulus_note

    notes = {"modulus": modulus_note(spec.material.E, spec.units)}
    if not isinstance(spec, SectionProblemSpec):
        notes["plate model"] = plate_model_note(spec.plate, spec.units)
        if design and spec.design is not None:
            notes["design material"] = steel_poisson_note(spec.material.nu)
            notes["design stainless"] = stainless_note(spec.material.E)
            notes["design yield stress"] = yield_stress_note(
                spec.design.yield_stress, spec.plate.thickness, "plate.thickness"
            )
    return {kind: note for kind, note in notes.items() if note is not None}


def warn_input(spec: ProblemSpec | SectionProblemSpec, comm: Any, design: bool = True) -> None:
    """Print the problem's :func:`input_notes` as warnings on stderr (rank 0)."""
    for note in input_notes(spec, design).values():
        _warn(note, comm)


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


def name_flag(error: InputError, flags: dict[str, str]) -> InputError:
    """``error`` led by the flag that set the key it names (``flags``: key -> flag).

    A value given by a flag is checked as the problem file's key ("solver.tau must lie
    in ..."); the message then names the flag typed too ("--tau: solver.tau ..."). Other
    errors are returned as they are.
    """
    text = str(error)
    for key, flag in flags.items():
        if re.match(rf"{re.escape(key)}\b(?![.\[])", text):
            return InputError(f"{flag}: {text}")
    return error


def refuse_flag_and_set(settings: Sequence[str], flags: dict[str, str]) -> None:
    """Refuse a value given twice: by a flag and by ``--set`` on its key (or its table).

    ``flags``: key -> the flag typed that sets it (``{"mesh.nx": "--nx"}``). Neither is
    taken over the other in silence: the message names both. The same for one path
    given to ``--set`` twice (the last would be taken).

    Raises:
        InputError: A ``--set`` path that is one of the keys or a table holding one, or
            a path set twice.
    """
    seen: dict[str, str] = {}
    for setting in settings:
        path = setting.partition("=")[0].strip()
        if path in seen:
            raise InputError(
                f"--set {seen[path]} and --set {setting} both set {path}: give one of them"
            )
        seen[path] = setting
        for key, flag in flags.items():
            if path and (path == key or key.startswith(path + ".")):
                raise InputError(f"{flag} and --set {setting} both set {key}: give one of them")


#: The PETSc option that sets the buckling eigen solves' tolerance, solver.eps_tol's
#: (docs/guide/cli.md): given on the command line, it wins over the file's key.
EPS_TOL_OPTION = "unibuckle_eps_tol"


def petsc_solver_changes() -> tuple[dict[str, float], dict[str, str]]:
    """The solver keys the PETSc command line sets, checked, and the options naming them.

    ``-unibuckle_eps_tol`` is ``solver.eps_tol``: SLEPc takes it over the file's key,
    which would then read in the result's ``input`` (a sweep's lines, the nonlinear
    JSON's ``options``) and in the certificate's checks a tolerance the solves did not
    use. Returns ``({"eps_tol": value}, {"solver.eps_tol": "-unibuckle_eps_tol"})``, or
    two empty dicts when the option is not given. ``unibuckle solve``, ``sweep`` and
    ``nonlinear`` read it before the problem file.

    Raises:
        InputError: A value that is not a number, or outside ``solver.eps_tol``'s range
            (the message names the option, the key and the range).
    """
    from petsc4py import PETSc

    from unibuckle_fenicsx.spec import SolverSpec

    options = PETSc.Options()
    if not options.hasName(EPS_TOL_OPTION):
        return {}, {}
    text = options.getString(EPS_TOL_OPTION)
    try:
        value = float(text)
    except ValueError:
        raise InputError(f"-{EPS_TOL_OPTION} takes a number, got {text!r}") from None
    named = {"solver.eps_tol": f"-{EPS_TOL_OPTION}"}
    try:
        SolverSpec(eps_tol=value)  # the key's range
    except InputError as err:
        raise name_flag(err, named) from None
    return {"eps_tol": value}, named


def _warn(note: str | None, comm: Any) -> None:
    """Print ``note``, if any, as a warning on stderr from rank 0."""
    if note is not None and comm.rank == 0:
        print(f"unibuckle: warning: {note}", file=sys.stderr)


def spec_from_args(args: argparse.Namespace) -> ProblemSpec | SectionProblemSpec:
    """The problem of --case or --config, with --set and --nx/--ny applied."""
    from unibuckle_fenicsx.spec import load_problem
    from unibuckle_fenicsx.spec.cases import paper_case

    cells = {"mesh.nx": ("--nx", args.nx), "mesh.ny": ("--ny", args.ny)}
    refuse_flag_and_set(args.settings, {k: f for k, (f, v) in cells.items() if v is not None})
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
        return spec
    if args.nx is not None or args.ny is not None:
        try:
            spec = spec.with_mesh(
                spec.mesh.nx if args.nx is None else args.nx,
                spec.mesh.ny if args.ny is None else args.ny,
            )
        except InputError as err:
            raise name_flag(err, {"mesh.nx": "--nx", "mesh.ny": "--ny"}) from None
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
