r"""Parametric sweeps: one problem file, some of its numbers varied over a grid.

``unibuckle sweep --config base.toml --vary plate.length=0.05:0.5:46 --json out.jsonl``
solves the base problem at every point of the grid of the ``--vary`` values (the first
``--vary`` varies slowest), each with the normal method and certificate, and writes one
JSON line per point as soon as it is done:

.. code-block:: text

    {"index": 0, "point": {"plate.length": 0.05}, "status": "ok",
     "critical_load_Pa": ..., "buckling_coefficient_k": ..., ...}

with the keys of ``unibuckle solve --json`` (without the wall times, so that a line
does not depend on the run). ``status`` is "ok" (a certified critical state),
"not-certified" (the result fails its KKT certificate; the line still holds the
bracket), "refused" (the problem was refused once its mesh existed, e.g. an obstacle
zone that holds no node or a load that buckles nothing), "no-admissible-mode" (no
admissible mode with a finite load was found), "eigen-failure" (an eigen solve did
not converge) or "failed" (another numerical failure,
:class:`~unibuckle_fenicsx.errors.NumericalError`); the last four lines hold ``error``
instead of the results. A failed point's PETSc objects are destroyed before the next
point (collectively: every rank of the point takes the same branch). Any other error is
a bug: it stops the sweep.

**Paths** name any number of the TOML schema (:doc:`/guide/plate`) by its dotted
path, list entries by index: ``plate.thickness``, ``material.nu``,
``edges.left.normal_stress``, ``plate.corners.1.0`` (x1), ``obstacle.zone.0.1``,
``mesh.size``, ``edges.top.rotational_stiffness``, ``points.0.spacing`` (a tie
spacing), ``material.plies.0.angle``, ``load.fixed_factor`` (the fixed part's factor:
an interaction curve), ``design.yield_stress``. Two shortcuts move a corner:
``plate.length`` sets x1 = x0 + value and ``plate.width`` sets y1 = y0 + value. Values
are in the base file's ``units``. Write ``[mesh] size = h`` in the base file so that the
cell count follows the plate's size. A section's file (:doc:`/guide/sections`) is swept
the same way, each point solved as ``unibuckle solve`` solves it: ``section.thickness``
(a wall's b/t or D/t), ``section.length``, ``section.width``, ``section.diameter``,
``load.bending_stress``, ``obstacle.foundation_stiffness``, ``mesh.size``.

**Resume.** Each line is appended with one ``write`` of the whole line and flushed to
disk, so a killed sweep leaves complete lines (and at most one truncated last line,
which is dropped). Run the same command again: a point already in the file is skipped
if its line's ``input`` (the problem solved, every key) equals the point's problem now,
and solved again otherwise (the base file was edited); the rest are solved; at the end
the file is rewritten (atomically) in point order, so an interrupted and resumed sweep
leaves the same file as an uninterrupted one. A file with a line that is not a sweep's
(another file given by mistake, bytes that are not UTF-8) is refused, not rewritten.

**Distribution.** Under ``mpiexec -n P`` with ``ranks_per_point = R`` (P divisible by
R), the ranks form P/R sub-communicators of R ranks; each solves every (P/R)-th of the
remaining points with its mesh distributed over its R ranks, and its first rank appends
the lines. With R = 1 every point is a serial solve, so the lines are those of a serial
sweep.

Note:
    :func:`run_sweep` is collective on its communicator.
"""

from __future__ import annotations

import contextlib
import copy
import functools
import itertools
import json
import logging
import math
import os
import re
import time
import tomllib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mpi4py import MPI

from unibuckle_fenicsx.errors import InputError, NumericalError
from unibuckle_fenicsx.outcome import Outcome
from unibuckle_fenicsx.progress import Progress
from unibuckle_fenicsx.spec import (
    ProblemSpec,
    SectionProblemSpec,
    load_problem,
    problem_to_dict,
    spec_from_dict,
)
from unibuckle_fenicsx.spec.base import did_you_mean

__all__ = [
    "STATUSES",
    "Variation",
    "base_mapping",
    "index_of",
    "parse_variation",
    "point_input",
    "point_problem",
    "read_lines",
    "run_sweep",
    "set_text",
    "set_value",
    "sweep_points",
]

#: The sweep's progress lines (a child of the package's progress logger, so that the
#: command line can show them while it hides the progress lines of each point's solve).
PROGRESS = logging.getLogger("unibuckle_fenicsx.progress.sweep")

#: Status of a sweep line, see the module docstring: how its run ended.
STATUSES = tuple(str(o) for o in Outcome if o not in (Outcome.INTERRUPTED, Outcome.BUG))
#: Shortcut paths: name -> the coordinate (0: x, 1: y) of the second corner they set.
SHORTCUTS = {"plate.length": 0, "plate.width": 1}
_RANGE = re.compile(r"^\s*([^:]+):([^:]+):([^:]+)\s*$")


@dataclass(frozen=True)
class Variation:
    """The values of one varied number.

    Attributes:
        path: Dotted path of the number in the problem file (see the module docstring).
        values: The values, in the order they are solved.
    """

    path: str
    values: tuple[float, ...]


def _float(text: str, what: str, flag: str = "--vary") -> float:
    try:
        value = float(text)
    except ValueError:
        raise InputError(f"{flag} {what}: {text.strip()!r} is not a number") from None
    if not math.isfinite(value):
        raise InputError(f"{flag} {what}: {text.strip()!r} is not a finite number")
    return value


def parse_variation(text: str) -> Variation:
    """``PATH=START:STOP:N`` (N values, ends included) or ``PATH=V1,V2,...``.

    Raises:
        ValueError: A malformed argument (the message quotes it).
    """
    path, sep, spec = text.partition("=")
    path = path.strip()
    if not sep or not path or not spec.strip():
        raise InputError(f"--vary {text!r}: expected PATH=START:STOP:N or PATH=V1,V2,...")
    match = _RANGE.match(spec)
    if match:
        start, stop = _float(match[1], text), _float(match[2], text)
        try:
            count = int(match[3])
        except ValueError:
            count = 0
        if count < 1 or str(count) != match[3].strip():
            raise InputError(f"--vary {text!r}: N must be an integer >= 1, got {match[3]!r}")
        if count == 1:
            values: tuple[float, ...] = (start,)
        else:
            values = tuple(start + (stop - start) * k / (count - 1) for k in range(count))
    elif ":" in spec:
        raise InputError(f"--vary {text!r}: a range is START:STOP:N (three numbers)")
    else:
        values = tuple(_float(v, text) for v in spec.split(","))
    return Variation(path, values)


def sweep_points(variations: Sequence[Variation]) -> list[dict[str, float]]:
    """The grid of points (the first variation varies slowest).

    Raises:
        ValueError: No variation, or a path given twice.
    """
    if not variations:
        raise InputError("a sweep needs at least one --vary")
    paths = [v.path for v in variations]
    if len(set(paths)) != len(paths):
        raise InputError(f"--vary: a path is given twice: {paths}")
    return [dict(zip(paths, combo, strict=True)) for combo in itertools.product(
        *(v.values for v in variations)
    )]  # fmt: skip


def base_mapping(path: str | Path) -> dict[str, object]:
    """The problem file ``path`` as a mapping with every key and the value used.

    In the file's own ``units``, and with ``[mesh] size`` kept if the file gives it.

    Raises:
        ValueError: An invalid problem file (the message names it).
        OSError: It cannot be read.
    """
    spec = load_problem(path)
    return problem_to_dict(spec, units=spec.units)


def _is_number(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _locate(data: dict[str, object], path: str, flag: str) -> tuple[Any, Any]:
    """The container and key of the value at the dotted ``path`` of ``data``.

    Raises:
        ValueError: ``path`` names nothing in ``data`` (the message, led by ``flag``,
            lists what is there).
    """
    keys = path.split(".")
    node: Any = data
    for depth, key in enumerate(keys):
        where = ".".join(keys[:depth]) or "the problem file"
        if isinstance(node, Mapping):
            if key not in node:
                # The shortcuts set a plate's corners: a section's file has none.
                shortcuts = f"; shortcuts: {sorted(SHORTCUTS)}" if "plate" in data else ""
                raise InputError(
                    f"{flag} {path}: {where} has no key {key!r} (keys: {sorted(node)}{shortcuts})"
                    + did_you_mean([key], list(node))
                )
        elif isinstance(node, list):
            if not (key.isdigit() and int(key) < len(node)):
                raise InputError(
                    f"{flag} {path}: {where} is a list of {len(node)}; {key!r} is not an "
                    f"index in [0, {len(node) - 1}]"
                )
        else:
            # A user's path through a value: bad input (exit 2), not a type error of the code.
            raise InputError(f"{flag} {path}: {where} = {node!r} is not a table or a list")
        if depth < len(keys) - 1:
            node = node[key] if isinstance(node, Mapping) else node[int(key)]
    leaf = keys[-1]
    return node, (leaf if isinstance(node, Mapping) else int(leaf))


def set_value(data: dict[str, object], path: str, value: float, flag: str = "--vary") -> None:
    """Set the number at the dotted ``path`` of the problem mapping ``data``, in place.

    A number that ``data`` leaves out but a problem file may hold
    (``design.yield_stress`` of a file without ``[design]``) is added (:func:`_add`).

    Raises:
        ValueError: ``path`` does not name a number of ``data`` (the message lists what
            is there), or ``value`` is not an integer where one is needed.
    """
    if path in SHORTCUTS:
        axis = SHORTCUTS[path]
        plate = data.get("plate")
        corners = plate.get("corners") if isinstance(plate, dict) else None
        if not isinstance(corners, list):
            raise InputError(f"{flag} {path}: the problem has no plate.corners")
        corners[1][axis] = corners[0][axis] + value
        return
    try:
        node, index = _locate(data, path, flag)
    except InputError:
        if _add(data, path, repr(float(value)), flag):
            return
        raise
    current = node[index]
    if not _is_number(current):
        raise InputError(f"{flag} {path}: the value there, {current!r}, is not a number")
    if isinstance(current, int):
        if value != int(value):
            raise InputError(f"{flag} {path}: must be an integer, got {value!r}")
        value = int(value)
    node[index] = value


def set_text(data: dict[str, object], path: str, text: str, flag: str = "--set") -> None:
    """Set the value at the dotted ``path`` of ``data`` from ``text``, read as the value there.

    A number, a boolean (true/false) or a string replaces one of its kind; a list
    (``[-1, 0]`` as TOML writes it, or ``-1,0``) replaces a number, a list or a string,
    and a number a list, for the keys of either form (an edge stress, a temperature,
    ``obstacle.zone``); the shortcuts of :data:`SHORTCUTS` take a number. A key that
    ``data`` leaves out but a problem file may hold (``obstacle.span``,
    ``design.yield_stress``) is added, its value read by its text (see :func:`_add`),
    and checked by the schema afterwards.

    Raises:
        ValueError: ``path`` names nothing in ``data``, or ``text`` is not of the kind of
            the value there (the message, led by ``flag``, names the path).
    """
    if path in SHORTCUTS:
        set_value(data, path, _float(text, path, flag), flag)
        return
    try:
        node, index = _locate(data, path, flag)
    except InputError:
        if _add(data, path, text, flag):
            return
        raise
    current = node[index]
    listed = None
    if _is_number(current) or isinstance(current, list):
        listed = _list_text(text, path, flag)
    elif isinstance(current, str):  # a string with commas ("name = 'a,b'") stays one
        with contextlib.suppress(InputError):
            listed = _list_text(text, path, flag)
    if isinstance(current, bool):
        if text.lower() not in ("true", "false"):
            raise InputError(f"{flag} {path}: must be true or false, got {text!r}")
        node[index] = text.lower() == "true"
    elif listed is not None:
        node[index] = listed  # a key of either form (a stress, a zone): the schema checks
    elif _is_number(current):
        set_value(data, path, _float(text, path, flag), flag)
    elif isinstance(current, str):
        node[index] = _string_text(text)
    elif isinstance(current, list) and _is_number_text(text):
        node[index] = _float(text, path, flag)  # a pair's key given one number
    else:
        raise InputError(
            f"{flag} {path}: the value there, {current!r}, is a table or a list: name one "
            "of its entries, or give a list as TOML writes it ([a, b])"
        )


def _string_text(text: str) -> str:
    """``text`` as a string value: a TOML string (``"tube"``, ``'tube'``) read as TOML reads it.

    ``--set section.shape="tube"`` is the file's line itself; the quotes are not the value's.
    """
    if len(text) >= 2 and text[0] == text[-1] and text[0] in "\"'":
        with contextlib.suppress(tomllib.TOMLDecodeError):
            value = tomllib.loads(f"value = {text}")["value"]
            if isinstance(value, str):
                return value
    return text


def _is_number_text(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _list_text(text: str, path: str, flag: str) -> list[Any] | None:
    """``text`` read as a list of numbers (``[a, b]``, ``[[a, b], [c, d]]``, ``a,b``), or None.

    A key that takes a number or a list (an edge stress, ``[start, end]``; a temperature,
    ``[T0, dTdx, dTdy]``; ``obstacle.zone``, ``"all"`` or a box) takes either form
    whatever the file holds there; the schema then checks the value against the key.

    Raises:
        InputError: A list whose entries are not finite numbers (the message names
            ``flag`` and ``path``).
    """
    inner = text.strip()
    if not (inner.startswith("[") and inner.endswith("]")):
        if "," not in inner:
            return None
        inner = f"[{inner}]"
    try:
        value = tomllib.loads(f"v = {inner}")["v"]
    except tomllib.TOMLDecodeError:
        raise InputError(f"{flag} {path}: {text.strip()!r} is not a list of numbers") from None

    def finite(v: object) -> bool:
        if isinstance(v, list):
            return all(finite(x) for x in v)
        return _is_number(v) and math.isfinite(float(v))  # type: ignore[arg-type]

    if not finite(value):
        raise InputError(f"{flag} {path}: {text.strip()!r} is not a list of finite numbers")
    return value


@functools.cache
def _schema_keys() -> frozenset[str]:
    """Every dotted key a problem file may hold (built once: a chart sets hundreds of points)."""
    from unibuckle_fenicsx.spec.schema import accepted_keys

    return frozenset(accepted_keys())


def _schema_key(path: str) -> str:
    """The schema's dotted key of ``path``: list indices as ``[]``, an edge's name ``<name>``."""
    parts = path.split(".")
    out: list[str] = []
    for depth, part in enumerate(parts):
        if part.isdigit() and out:
            out[-1] += "[]"
        elif depth == 1 and parts[0] == "edges":
            out.append("<name>")
        else:
            out.append(part)
    return ".".join(out)


def _add(data: dict[str, object], path: str, text: str, flag: str) -> bool:
    """Add the key ``path`` that ``data`` leaves out, if a problem file may hold it.

    The tables on the way are made; the value is read from ``text`` as a boolean
    (true/false), a list of numbers (``0.05,0.15``, or as in TOML ``[0.05, 0.15]``), a
    number, or else a string; the schema then checks it. False (nothing added) if no
    problem file has that key, or the path runs through a list entry that is not there.

    Raises:
        InputError: A list with an entry that is not a number (the message names ``flag``
            and ``path``).
    """
    if _schema_key(path) not in _schema_keys():
        return False
    keys = path.split(".")
    node: Any = data
    for key in keys[:-1]:
        if isinstance(node, list):
            if not (key.isdigit() and int(key) < len(node)):
                return False
            node = node[int(key)]
        elif isinstance(node, dict):
            node = node.setdefault(key, {})
        if not isinstance(node, dict | list):
            return False
    if not isinstance(node, dict):
        return False
    node[keys[-1]] = _new_value(text, path, flag)
    return True


def _new_value(text: str, path: str, flag: str) -> object:
    """A value for a key the file left out, read from ``text`` (see :func:`_add`)."""
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    inner = text.strip()
    if inner.startswith("[") and inner.endswith("]"):  # a TOML array: [0.05, 0.15]
        return [_float(part, path, flag) for part in inner[1:-1].split(",")]
    if "," in text:
        return [_float(part, path, flag) for part in text.split(",")]
    if re.fullmatch(r"\s*[+-]?\d+\s*", text):
        return int(text)
    try:
        return _float(text, path, flag)
    except InputError:
        return _string_text(text)


def point_problem(
    base: Mapping[str, object], point: Mapping[str, float]
) -> ProblemSpec | SectionProblemSpec:
    """The problem of one sweep point: ``base`` with the point's values set.

    A plate's, or a section's if ``base`` has a ``[section]`` table.

    Raises:
        ValueError: A bad path, or a value the schema refuses (the message names both).
    """
    data = copy.deepcopy(dict(base))
    for path, value in point.items():
        set_value(data, path, value)
    try:
        return spec_from_dict(data, name=str(base.get("name", "plate")))
    except ValueError as err:
        raise InputError(f"sweep point {dict(point)}: {err}") from None


def read_lines(path: str | Path, *, strict: bool = False) -> list[dict[str, object]]:
    """The JSON lines of a sweep file.

    Args:
        path: The file.
        strict: Refuse a line that is not a sweep's line (``ValueError`` naming the file
            and the line), except a last line without its newline, cut by a kill, which
            is dropped; otherwise every such line is dropped.
    """
    data = Path(path).read_bytes()
    texts = data.split(b"\n")
    cut = texts.pop()  # after the last newline: empty, or a line cut by a kill
    out = []
    for number, raw in enumerate(texts, start=1):
        line, why = _parse_line(raw)
        if line is not None:
            out.append(line)
        elif strict:
            raise InputError(
                f"--json {path}: line {number} is not a line of a sweep ({why}); give "
                "another file or delete this one"
            )
    line, _ = _parse_line(cut)
    if line is not None and not strict:
        out.append(line)
    return out


def _parse_line(raw: bytes) -> tuple[dict[str, object] | None, str]:
    """A sweep line from its bytes, or None and why not."""
    try:
        line = json.loads(raw.decode("utf-8"))
    except UnicodeDecodeError as err:
        return None, f"not UTF-8 text: {err.reason} at byte {err.start}"
    except json.JSONDecodeError as err:
        return None, f"not JSON: {err.msg}"
    if isinstance(line, dict) and isinstance(line.get("index"), int) and "point" in line:
        return line, ""
    return None, "no index and point"


def index_of(line: Mapping[str, object]) -> int:
    """The point number of a sweep line (:func:`read_lines` keeps only lines with one).

    Raises:
        InputError: ``line`` has no integer ``index`` (it is not a sweep's line).
    """
    index = line.get("index")
    if not isinstance(index, int):
        raise InputError(f"not a line of a sweep (no integer index): {dict(line)!r:.80}")
    return index


def point_input(spec: ProblemSpec | SectionProblemSpec) -> dict[str, object]:
    """The ``input`` a point's line stores: its problem, every key, as read back from JSON."""
    return json.loads(json.dumps(problem_to_dict(spec)))


def _write_atomically(path: Path, lines: list[dict[str, object]]) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text("".join(json.dumps(line) + "\n" for line in lines))
    os.replace(tmp, path)


def _append(path: Path, line: dict[str, object]) -> None:
    """Append one line with a single write, and flush it to disk."""
    data = (json.dumps(line) + "\n").encode()
    fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
    try:
        written = os.write(fd, data)
        while written < len(data):  # a short write (never seen on a regular file)
            written += os.write(fd, data[written:])
        os.fsync(fd)
    finally:
        os.close(fd)


def _done_points(
    path: Path, points: list[dict[str, float]], inputs: list[dict[str, object]]
) -> tuple[dict[int, dict[str, object]], int]:
    """The lines of ``path`` that can be kept, and how many are stale; the file cleaned up.

    A line is kept if its point is this sweep's and its stored ``input`` equals the
    point's problem now (the base file may have changed since); a stale line is dropped,
    so that its point is solved again.

    Raises:
        ValueError: A line of another sweep, or one that is not a sweep's line.
    """
    if not path.exists():
        return {}, 0
    done: dict[int, dict[str, object]] = {}
    stale = 0
    for line in read_lines(path, strict=True):
        k = index_of(line)
        if not 0 <= k < len(points) or line["point"] != points[k]:
            raise InputError(
                f"--json {path}: holds a point of another sweep (line index {k}, point "
                f"{line['point']}); give another file or delete it"
            )
        if line.get("input") != inputs[k]:
            stale += 1
            continue
        done.setdefault(k, line)
    _write_atomically(path, [done[k] for k in sorted(done)])  # drop a truncated last line
    return done, stale


def solve_point(spec: ProblemSpec | SectionProblemSpec, comm: MPI.Comm) -> dict[str, object]:
    """Solve one point; the JSON-ready line body (results, or the error; and the input)."""
    body = _solve(spec, comm)
    return {**body, "input": point_input(spec)}


def _solve(spec: ProblemSpec | SectionProblemSpec, comm: MPI.Comm) -> dict[str, object]:
    from unibuckle_fenicsx.run import analyse

    try:
        with analyse(spec, comm) as analysis:
            result = analysis.result
    except (InputError, NumericalError) as err:  # anything else is a bug: it stops the sweep
        return {"status": str(Outcome.of(err)), "error": str(err)}
    return {"status": str(Outcome.of(result)), **result.as_dict(timings=False)}


def _check_ranks(ranks_per_point: int, comm: MPI.Comm) -> None:
    """Refuse a ``ranks_per_point`` that is not a divisor of the ranks."""
    if int(ranks_per_point) != ranks_per_point or ranks_per_point < 1:
        raise InputError(
            f"ranks_per_point (--ranks-per-point) must be an integer >= 1, got {ranks_per_point!r}"
        )
    if comm.size % ranks_per_point:
        raise InputError(
            f"ranks_per_point (--ranks-per-point) = {ranks_per_point} must divide the number "
            f"of ranks ({comm.size})"
        )


def _resume(
    path: Path,
    points: list[dict[str, float]],
    specs: list[ProblemSpec | SectionProblemSpec],
    comm: MPI.Comm,
) -> tuple[dict[int, dict[str, object]], int]:
    """The lines of ``path`` kept and the stale ones' count, on every rank.

    See :func:`_done_points`.

    Raises:
        InputError: ``path`` cannot be made or holds another sweep (before any solve).

    Note:
        Collective.
    """
    error = None
    done: dict[int, dict[str, object]] = {}
    stale = 0
    if comm.rank == 0:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            done, stale = _done_points(path, points, [point_input(spec) for spec in specs])
        except (ValueError, OSError) as err:
            error = str(err)
    error, done, stale = comm.bcast((error, done, stale), root=0)
    if error is not None:
        raise InputError(error)
    return done, stale


def _say_resumed(path: Path, done: int, stale: int, points: int) -> None:
    """The progress lines of a resumed sweep: the points kept and those solved again."""
    if done:
        PROGRESS.info("sweep: %d of %d points already in %s", done, points, path)
    if stale:
        PROGRESS.info(
            "sweep: %d line(s) of %s hold another input (the base file changed): "
            "solving their points again",
            stale,
            path,
        )


def _solve_points(
    path: Path,
    points: list[dict[str, float]],
    specs: list[ProblemSpec | SectionProblemSpec],
    done: Mapping[int, object],
    stale: int,
    comm: MPI.Comm,
    ranks_per_point: int,
    progress: bool,
) -> None:
    """Solve the points not ``done`` (by index: those in ``path``), each group its share.

    Each point's line is appended to ``path`` as it is solved (by its group's rank 0);
    rank 0 shows the progress (:func:`run_sweep`). Collective on ``comm``.
    """
    todo = [k for k in range(len(points)) if k not in done]
    groups = comm.size // ranks_per_point
    color = comm.rank // ranks_per_point
    sub = comm.Split(color, comm.rank)
    try:
        mine = todo[color::groups]
        show = progress and comm.rank == 0
        if show:
            _say_resumed(path, len(done), stale, len(points))
        lines = Progress(
            "sweep",
            len(todo),
            interval=0.0,
            enabled=show,
            logger=PROGRESS,
            bar=True,
            initial=len(done),
            unit="point",
        )
        t0 = time.perf_counter()
        for count, k in enumerate(mine, start=1):
            body = solve_point(specs[k], sub)
            if sub.rank == 0:
                _append(path, {"index": k, "point": points[k], **body})
            if comm.rank == 0:
                # Lines on disk, every group's (a newline ends each complete line).
                finished = path.read_bytes().count(b"\n") - len(done)
                lines.update(
                    finished,
                    f"point {k} {points[k]}: {body['status']} "
                    f"({time.perf_counter() - t0:.1f} s for {count} point(s) on this rank)",
                )
        comm.Barrier()
        lines.close()
    finally:
        sub.Free()


def run_sweep(
    base: Mapping[str, object],
    variations: Sequence[Variation],
    out: str | Path,
    comm: MPI.Comm = MPI.COMM_WORLD,
    *,
    ranks_per_point: int = 1,
    progress: bool = True,
    check: Callable[[list[dict[str, float]], list[ProblemSpec | SectionProblemSpec]], None]
    | None = None,
) -> list[dict[str, object]]:
    """Solve every point of the grid of ``variations`` and write ``out`` (JSON lines).

    Args:
        base: The base problem (:func:`base_mapping`).
        variations: The varied numbers (:func:`parse_variation`).
        out: The JSON-lines file; points already in it are skipped (resume).
        comm: Communicator shared among the points.
        ranks_per_point: Ranks of each point's mesh, >= 1, dividing ``comm.size``.
        progress: Show a progress bar (tqdm, the 'progress' extra) or progress lines,
            on rank 0.
        check: Called once, on every rank, with the grid's points and their problems
            (each point read once) before anything is solved: the command line's
            warnings on them.

    Returns:
        The lines of the whole sweep in point order (on every rank).

    Raises:
        ValueError: Bad ``variations`` or ``ranks_per_point``, a point the schema
            refuses, or an ``out`` holding another sweep: before anything is solved.

    Note:
        Collective on ``comm``.
    """
    _check_ranks(ranks_per_point, comm)
    points = sweep_points(variations)
    specs = [point_problem(base, p) for p in points]  # every point checked before solving
    if check is not None:
        check(points, specs)
    path = Path(out)
    done, stale = _resume(path, points, specs, comm)
    _solve_points(path, points, specs, done, stale, comm, ranks_per_point, progress)
    final = None
    if comm.rank == 0:
        everything = {index_of(line): line for line in read_lines(path)}
        final = [everything[k] for k in sorted(everything)]
        _write_atomically(path, final)
    return comm.bcast(final, root=0)
