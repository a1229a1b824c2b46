"""``unibuckle schema``: the JSON Schema of a problem file, or its dotted keys."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from unibuckle_fenicsx.cli.status import EXIT_BAD_INPUT, EXIT_OK, print_out


def schema_command(args: argparse.Namespace) -> int:
    """``unibuckle schema``: the JSON Schema of a problem file, or its dotted keys."""
    import json

    from unibuckle_fenicsx.spec import accepted_keys, json_schema

    text = "\n".join(accepted_keys()) if args.keys else json.dumps(json_schema(), indent=2)
    if not args.output:
        print_out(text)
        return EXIT_OK
    try:
        Path(args.output).write_text(text + "\n")
    except OSError as err:
        print(f"unibuckle: error: --output {args.output}: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    return EXIT_OK
