"""Results files of the benchmarks: one JSON object per table row, appended.

The documentation renders some of them as tables (``bench/results/*.jsonl``); every
bench script takes ``--json FILE`` and appends its rows there.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from typing import Any


def parse_plates(parser: Any) -> tuple[Any, list[tuple[int, int]]]:
    """(arguments, meshes) of a plate benchmark's ``--meshes`` and ``--repeat`` (>= 1)."""
    args, _ = parser.parse_known_args()
    if args.repeat < 1:
        parser.error(f"--repeat must be at least 1, got {args.repeat}")
    meshes = [(int(a), int(b)) for a, b in (m.split("x") for m in args.meshes.split(","))]
    return args, meshes


def print_header(title: str, columns: Iterable[str]) -> None:
    """Print ``title`` and the head of a Markdown table with ``columns``."""
    names = list(columns)
    print(title)
    print("| " + " | ".join(names) + " |")
    print("|" + "---|" * len(names), flush=True)


def append_rows(path: str | None, rows: Iterable[Mapping[str, Any]]) -> None:
    """Append ``rows`` to the file ``path``, one JSON line each (nothing if ``path`` is None)."""
    if not path:
        return
    with open(path, "a", encoding="utf-8") as f:
        for row in rows:
            f.write(json.dumps(dict(row)) + "\n")
