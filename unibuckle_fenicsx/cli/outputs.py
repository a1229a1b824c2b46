"""The outputs a run will write (``--json``, ``--plot``, ``--output``), checked before any solve."""

from __future__ import annotations

import argparse
import os
from pathlib import Path


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


def check_outputs(args: argparse.Namespace) -> str | None:
    """Why --json, --plot, --csv or --output cannot be written, or None; run before any solve.

    --json PATH (and --plot PNG, --csv PATH) needs an existing folder in which a file can
    be created (tried, not inferred from permission bits, which root and /proc ignore);
    --output DIR is created later if missing, so its parent must exist and take a new
    entry. Nothing is left behind.
    """
    # --plot and --csv: the sweep's
    files = [
        ("--json", args.json),
        ("--plot", getattr(args, "plot", None)),
        ("--csv", getattr(args, "csv", None)),
    ]
    for flag, value in files:
        if value and (problem := _check_file(flag, Path(value))):
            return problem
    if getattr(args, "output", None):  # solve only
        return _check_directory(Path(args.output))
    return None


def _check_file(flag: str, path: Path) -> str | None:
    """Why the file ``path`` of ``flag`` cannot be written, or None (nothing left behind)."""
    folder = path.parent
    if path.is_dir():
        return f"{flag}: {path} is a directory; give a file name"
    if not folder.is_dir():
        return _missing_folder(flag, folder)
    if not path.exists():
        return _probe_folder(flag, folder, path)
    try:  # appending nothing leaves the file as it is
        with path.open("ab"):
            pass
    except OSError as err:
        return f"{flag}: cannot write {path} ({err.strerror or err})"
    return None


def _check_directory(directory: Path) -> str | None:
    """Why --output ``directory`` cannot be made or written, or None (nothing left behind)."""
    if directory.exists() and not directory.is_dir():
        return f"--output: {directory} is not a directory"
    folder = directory
    if not directory.exists():
        folder = directory.parent
        if not folder.is_dir():
            return _missing_folder("--output", folder) + " (--output creates one folder)"
    return _probe_folder("--output", folder, directory)
