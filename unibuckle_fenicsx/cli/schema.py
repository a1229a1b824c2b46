"""``unibuckle schema``: the JSON Schema of a problem file, or its dotted keys."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from unibuckle_fenicsx.cli.status import EXIT_BAD_INPUT, EXIT_OK


def schema_command(args: argparse.Namespace) -> int:
    """``unibuckle schema``: the JSON Schema of a problem file, or its dotted keys."""
    import json

    from unibuckle_fenicsx.spec import accepted_keys, json_schema

    text = "\n".join(accepted_keys()) if args.keys else json.dumps(json_schema(), indent=2)
    if not args.output:
        try:
            print(text, flush=True)
        except BrokenPipeError:
            # The reader stopped early (``| head``): not an error. Python's recipe (the
            # signal module's "Note on SIGPIPE"): stdout to devnull, so that the
            # interpreter's last flush at exit does not fail again.
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    try:
        Path(args.output).write_text(text + "\n")
    except OSError as err:
        print(f"unibuckle: error: --output {args.output}: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    return EXIT_OK
