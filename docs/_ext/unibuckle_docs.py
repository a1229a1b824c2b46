"""Pages generated at build time: the command line, the TOML schema and the benchmarks.

Nothing here is typed by hand from the program: the ``builder-inited`` hook writes
Markdown files under ``docs/_generated/`` (not kept in git), which the pages include:

- ``cli_<command>.md``: ``unibuckle <command> --help``, from the package's argparse parser;
- ``schema.md``: every key of the problem file, from
  :func:`unibuckle_fenicsx.spec.json_schema` (its types, defaults, ranges and
  descriptions) and :func:`unibuckle_fenicsx.spec.accepted_keys`; where the installed
  package does not have them yet, from the loader itself (see :func:`loader_keys`);
- ``demo_<name>.md``: each demo (a jupytext percent script) as a page, with the figures
  ``make demo`` stored in ``figures/`` (the build executes no demo);
- ``bench_<name>.md``: a table per file ``bench/results/<name>.jsonl`` (one JSON object a
  line, as the bench scripts' ``--json FILE`` writes them), with the command that
  reproduces it.

The functions are importable without Sphinx (``tests/test_docs.py`` uses them).
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
GENERATED = ROOT / "docs" / "_generated"
RESULTS = ROOT / "bench" / "results"

# --------------------------------------------------------------------------------------
# The command line
# --------------------------------------------------------------------------------------


def cli_parser() -> argparse.ArgumentParser:
    """The ``unibuckle`` argparse parser, however the CLI module builds it."""
    from unibuckle_fenicsx import cli

    for name in ("build_parser", "parser", "_parser"):
        make = getattr(cli, name, None)
        if callable(make):
            made = make()
            parser = made[0] if isinstance(made, tuple) else made
            if isinstance(parser, argparse.ArgumentParser):
                return parser
    raise RuntimeError("unibuckle_fenicsx.cli has no parser factory (build_parser/_parser)")


def subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    """The parser's subcommands by name (in the order they were added)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _help(parser: argparse.ArgumentParser) -> str:
    # A fixed width: the page does not depend on the terminal that builds it.
    formatter = parser.formatter_class
    parser.formatter_class = lambda prog: formatter(prog, width=88)  # type: ignore[assignment]
    try:
        return parser.format_help()
    finally:
        parser.formatter_class = formatter


def cli_pages() -> dict[str, str]:
    """``{file name: Markdown}``: ``unibuckle --help`` and each ``unibuckle CMD --help``."""
    parser = cli_parser()
    pages = {"cli_unibuckle.md": f"```text\n{_help(parser)}```\n"}
    for name, sub in subcommands(parser).items():
        pages[f"cli_{name}.md"] = f"```text\n{_help(sub)}```\n"
    return pages


# --------------------------------------------------------------------------------------
# The problem file's schema
# --------------------------------------------------------------------------------------

#: A key that no table accepts: the loader's unknown-key check names the allowed ones.
_PROBE = "__unibuckle_docs_probe__"


def _allowed(data: Mapping[str, Any], where: str) -> list[str] | None:
    """The keys the loader allows in table ``where``, read off its unknown-key error."""
    from unibuckle_fenicsx.spec import problem_from_dict

    try:
        problem_from_dict(data)
    except ValueError as err:
        match = re.search(
            r"unknown key\(s\) \['" + _PROBE + r"'\] in \[" + re.escape(where) + r"\]; "
            r"allowed: (\[.*\])",
            str(err),
        )
        if match:
            return list(json.loads(match.group(1).replace("'", '"')))
    return None


def loader_keys() -> list[str]:
    """Every dotted key the loader accepts, asked of the loader table by table.

    The fallback of :func:`accepted_keys` for a package without
    ``unibuckle_fenicsx.spec.accepted_keys``: the loader checks each table's keys against
    a list of allowed names and names that list when a key is unknown, so a probe key in
    each table (a nested table inside a minimal valid file) reads the list the loader
    itself uses. List-valued tables are written ``name[]`` (``plate.holes[].radius``).
    """
    probe = {_PROBE: 1}
    rect = {"corners": [[0.0, 0.0], [0.2, 0.1]], "thickness": 0.006}
    tables: dict[str, dict[str, Any]] = {
        "": probe,
        "plate": {"plate": probe},
        "plate.holes[]": {"plate": {**rect, "holes": [probe]}},
        "material": {"material": probe},
        "material.plies[]": {"material": {"plies": [probe]}},
        "edges.left": {"edges": {"left": probe}},
        "mesh": {"mesh": probe},
        "obstacle": {"obstacle": probe},
        "obstacle.circle": {"obstacle": {"circle": probe}},
        "obstacles[]": {"obstacles": [probe]},
        "obstacles[].circle": {"obstacles": [{"circle": probe}]},
        "points[]": {"points": [probe]},
        "load": {"load": probe},
        "design": {"design": probe},
        "solver": {"solver": probe},
    }
    where = {
        "": "top",
        "plate.holes[]": "plate.holes[0]",
        "material.plies[]": "material.plies[0]",
        "obstacles[]": "obstacles[0]",
        "obstacles[].circle": "obstacles[0].circle",
        "points[]": "points[0]",
    }
    keys: list[str] = []
    for table, data in tables.items():
        allowed = _allowed(data, where.get(table, table))
        if allowed is None:
            raise RuntimeError(f"the loader did not name the keys of [{table or 'top'}]")
        for key in allowed:
            if table == "edges.left":
                keys.append(f"edges.<name>.{key}")
                continue
            dotted = f"{table}.{key}" if table else key
            if dotted.removesuffix("[]") in {t.removesuffix("[]") for t in tables} or (
                dotted in ("edges",)
            ):
                continue  # a table: its keys are listed as its own rows
            keys.append(dotted)
    return keys


def json_schema() -> dict[str, Any] | None:
    """The package's JSON Schema of the problem file, or None where it has none."""
    from unibuckle_fenicsx import spec

    make = getattr(spec, "json_schema", None)
    return make() if callable(make) else None


def accepted_keys() -> tuple[list[str], str]:
    """(every dotted key the loader accepts, where the list comes from)."""
    from unibuckle_fenicsx import spec

    listed = getattr(spec, "accepted_keys", None)
    if callable(listed):
        return list(listed()), "unibuckle_fenicsx.spec.accepted_keys()"
    return loader_keys(), "the loader's own unknown-key check (unibuckle_fenicsx.spec)"


def _resolve(node: Mapping[str, Any], root: Mapping[str, Any]) -> Mapping[str, Any]:
    while "$ref" in node:
        ref = str(node["$ref"])
        target: Any = root
        for part in ref.removeprefix("#/").split("/"):
            target = target[part]
        node = {**target, **{k: v for k, v in node.items() if k != "$ref"}}
    return node


def _alternatives(node: Mapping[str, Any], root: Mapping[str, Any]) -> list[Mapping[str, Any]]:
    for word in ("anyOf", "oneOf", "allOf"):
        if word in node:
            return [_resolve(n, root) for n in node[word]]
    return []


def schema_rows(  # noqa: C901 (one branch per JSON Schema construct)
    schema: Mapping[str, Any], root: Mapping[str, Any] | None = None, prefix: str = ""
) -> Iterator[tuple[str, Mapping[str, Any]]]:
    """(dotted key, its schema) for every leaf key of a JSON Schema.

    Objects nest with ``.``; arrays of objects with ``[]``; objects whose keys are free
    (``additionalProperties`` or ``patternProperties``, such as the edges' names) with
    ``<name>``.
    """
    root = schema if root is None else root
    node = _resolve(schema, root)
    branches = [node, *_alternatives(node, root)]
    seen: set[str] = set()
    leaf = True
    for branch in branches:
        branch = _resolve(branch, root)
        props = branch.get("properties")
        if isinstance(props, Mapping):
            leaf = False
            for key, sub in props.items():
                dotted = f"{prefix}.{key}" if prefix else key
                for row in schema_rows(sub, root, dotted):
                    if row[0] not in seen:
                        seen.add(row[0])
                        yield row
        extra = branch.get("additionalProperties")
        patterns = branch.get("patternProperties")
        free = [extra] if isinstance(extra, Mapping) else []
        if isinstance(patterns, Mapping):
            free += list(patterns.values())
        for sub in free:
            leaf = False
            for row in schema_rows(sub, root, f"{prefix}.<name>"):
                if row[0] not in seen:
                    seen.add(row[0])
                    yield row
        items = branch.get("items")
        if branch.get("type") == "array" and isinstance(items, Mapping):
            inner = _resolve(items, root)
            if "properties" in inner or _alternatives(inner, root):
                if any("properties" in b for b in [inner, *_alternatives(inner, root)]):
                    leaf = False
                    for row in schema_rows(inner, root, f"{prefix}[]"):
                        if row[0] not in seen:
                            seen.add(row[0])
                            yield row
    if leaf and prefix:
        yield prefix, node


def _type(node: Mapping[str, Any], root: Mapping[str, Any]) -> str:
    if "enum" in node:
        return " \\| ".join(f'`"{v}"`' if isinstance(v, str) else f"`{v}`" for v in node["enum"])
    if "const" in node:
        return f"`{json.dumps(node['const'])}`"
    alts = _alternatives(node, root)
    if alts:
        return " or ".join(_type(a, root) for a in alts)
    kind = node.get("type", "")
    if isinstance(kind, list):
        return " or ".join(kind)
    if kind == "array" and isinstance(node.get("items"), Mapping):
        return f"array of {_type(_resolve(node['items'], root), root)}"
    return str(kind)


def _range(node: Mapping[str, Any]) -> str:
    parts = []
    for word, sign in (
        ("exclusiveMinimum", ">"),
        ("minimum", "≥"),
        ("exclusiveMaximum", "<"),
        ("maximum", "≤"),
        ("minItems", "items ≥"),
        ("maxItems", "items ≤"),
    ):
        if word in node:
            parts.append(f"{sign} {node[word]}")
    return ", ".join(parts)


def _cell(text: Any) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def schema_page() -> str:
    """The TOML reference as Markdown: one row per key the loader accepts."""
    keys, source = accepted_keys()
    schema = json_schema()
    lines = []
    if schema is not None:
        described = dict(schema_rows(schema))
        lines += [
            f"Generated from `unibuckle_fenicsx.spec.json_schema()` and {source} when "
            "these pages were built.",
            "",
            "| key | type | range | default | description |",
            "|---|---|---|---|---|",
        ]
        for key in keys:
            node = described.get(key, {})
            default = node.get("default", "")
            lines.append(
                "| `{}` | {} | {} | {} | {} |".format(
                    key,
                    _cell(_type(node, schema)) if node else "",
                    _cell(_range(node)),
                    f"`{json.dumps(default)}`" if "default" in node else _cell(default),
                    _cell(node.get("description", "")),
                )
            )
        lines += [
            "",
            "## The JSON Schema",
            "",
            "```json",
            json.dumps(schema, indent=2, default=str),
            "```",
        ]
    else:
        defaults = _defaults()
        described = _described()
        lines += [
            f"Generated from {source} when these pages were built: the keys from the "
            "loader's unknown-key check, each one's meaning from the docstring of the "
            "class it fills (parent key's where it has none), its default the value the "
            "loader fills in for a file that omits it (the paper's plate; empty where it "
            "has none). Examples of every table: {doc}`../guide/plate`.",
            "",
            "| key | default | meaning |",
            "|---|---|---|",
        ]
        for key in keys:
            default = defaults.get(key)
            lines.append(
                "| `{}` | {} | {} |".format(
                    key,
                    "" if default is None else f"`{json.dumps(default)}`",
                    _cell(described.get(key, "")),
                )
            )
    lines += ["", f"{len(keys)} keys."]
    return "\n".join(lines) + "\n"


#: The class each table of the problem file fills, by its dotted prefix.
TABLE_CLASSES = {
    "": "ProblemSpec",
    "plate": "PlateSpec",
    "material": "Material",
    "material.plies[]": "Ply",
    "edges.<name>": "EdgeSpec",
    "mesh": "MeshSpec",
    "obstacle": "ObstacleSpec",
    "obstacles[]": "ObstacleSpec",
    "points[]": "PointSpec",
    "load": "LoadSpec",
    "design": "DesignSpec",
    "solver": "SolverSpec",
}


def _myst(text: str) -> str:
    """Inline markup of a reST docstring as MyST: math as $...$, roles and literals as code."""
    text = re.sub(r":math:`([^`]*)`", r"$\1$", text)
    text = re.sub(r":[\w:]+:`~?([^`]*)`", r"`\1`", text)
    return re.sub(r"``([^`]+)``", r"`\1`", text)


def arg_docs(cls: type) -> dict[str, str]:
    """``{argument: its description}`` from the ``Args:`` section of a Google docstring."""
    import inspect

    doc = inspect.getdoc(cls) or ""
    found: dict[str, str] = {}
    inside, name = False, None
    for line in doc.splitlines():
        if line.strip() in ("Args:", "Attributes:"):
            inside = True
            continue
        if inside:
            if line and not line.startswith(" "):
                inside = False
                continue
            match = re.match(r"^    (\w+)(?: \([^)]*\))?: (.*)$", line)
            if match:
                name = match.group(1)
                found[name] = match.group(2)
            elif name and line.startswith("        "):
                found[name] += " " + line.strip()
    return {key: _myst(text) for key, text in found.items()}


def _described() -> dict[str, str]:
    """Dotted key -> its meaning, from the docstrings of the classes the tables fill."""
    from unibuckle_fenicsx import spec

    keys, _ = accepted_keys()
    docs = {
        prefix: arg_docs(getattr(spec, name))
        for prefix, name in TABLE_CLASSES.items()
        if hasattr(spec, name)
    }
    described = {}
    for key in keys:
        parts = key.split(".")
        for cut in range(len(parts) - 1, -1, -1):  # the table's own class, then a parent's
            prefix, name = ".".join(parts[:cut]), parts[cut]
            text = docs.get(prefix, {}).get(name.removesuffix("[]"))
            if text:
                described[key] = text
                break
    return described


def _defaults() -> dict[str, Any]:
    """Dotted key -> the value the loader fills in for the paper's plate with c1's zone."""
    from unibuckle_fenicsx.spec import problem_from_dict, problem_to_dict

    data = problem_to_dict(problem_from_dict({"obstacle": {"zone": "all"}}))
    flat: dict[str, Any] = {}

    def walk(value: Any, path: str) -> None:
        if isinstance(value, Mapping):
            for key, sub in value.items():
                if path == "edges":
                    walk(sub, "edges.<name>")
                    continue
                walk(sub, f"{path}.{key}" if path else key)
        elif value is not None and (path not in flat):
            flat[path] = value

    walk(data, "")
    # Not defaults: the zone is the probe's, and an edge's normal stress depends on the
    # edge (the paper's unit compression on left and right only, see the guide).
    for key in ("obstacle.zone", "edges.<name>.normal_stress"):
        flat.pop(key, None)
    return flat


# --------------------------------------------------------------------------------------
# Benchmarks
# --------------------------------------------------------------------------------------


#: How each results file is reproduced: a function of its rows, so that the command
#: names the meshes and cases the file actually holds.
def _listed(rows: list[dict[str, Any]], key: str) -> str:
    return ",".join(dict.fromkeys(str(r[key]) for r in rows))


def _plates_commands(rows: list[dict[str, Any]]) -> str:
    """The ``bench_plates.py`` runs that wrote the rows: one per mesh, with its flags."""
    commands = []
    for mesh in dict.fromkeys(str(r["mesh"]) for r in rows):
        group = [r for r in rows if str(r["mesh"]) == mesh]
        flags = " --cli" if any(r.get("cli_ratio") is not None for r in group) else ""
        flags += " --bracket" if any(r.get("bracket") for r in group) else ""
        repeat = max(len(r.get("ratios", [0])) for r in group)
        flags += f" --repeat {repeat}" if repeat > 1 else ""
        commands.append(
            f"python bench/bench_plates.py --meshes {mesh} --cases {_listed(group, 'case')}"
            f"{flags} --json bench/results/plates.jsonl"
        )
    return "`, then `".join(commands)


def _routes_commands(rows: list[dict[str, Any]]) -> str:
    """The ``bench_routes.py`` runs that wrote the rows: one per plate length and mesh."""
    commands = []
    for length, mesh in dict.fromkeys((r["length_m"], str(r["mesh"])) for r in rows):
        group = [r for r in rows if (r["length_m"], str(r["mesh"])) == (length, mesh)]
        commands.append(
            f"python bench/bench_routes.py --length {length:g} --meshes {mesh} "
            f"--cases {_listed(group, 'case')} --thicknesses {_listed(group, 'thickness_m')} "
            "--json bench/results/routes.jsonl"
        )
    return "`, then `".join(commands)


def _bracket_commands(rows: list[dict[str, Any]]) -> str:
    """The ``bench_bracket.py`` runs that wrote the rows: by default, then as asked for."""
    commands = []
    for asked in dict.fromkeys(bool(r.get("bracket")) for r in rows):
        group = [r for r in rows if bool(r.get("bracket")) == asked]
        commands.append(
            f"python bench/bench_bracket.py --meshes {_listed(group, 'mesh')} "
            f"--cases {_listed(group, 'case')}{' --bracket' if asked else ''} "
            "--json bench/results/bracket.jsonl"
        )
    return "`, then `".join(commands)


COMMANDS = {
    "bracket": lambda rows: _bracket_commands(rows),
    "certify": lambda rows: (
        f"python bench/bench_certify.py --meshes {_listed(rows, 'mesh')} "
        f"--cases {_listed(rows, 'case')} --json bench/results/certify.jsonl"
    ),
    "plates": lambda rows: _plates_commands(rows),
    "routes": lambda rows: _routes_commands(rows),
}


def _format(value: Any) -> str:
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if value != 0 and abs(value) < 1e-3:
            return f"{value:.2g}"
        if abs(value) >= 1e6:
            return f"{value:.2f}"
        return f"{value:.4g}" if abs(value) < 100 else f"{value:.2f}"
    if value is None:
        return "-"
    return _cell(value)


def bench_rows(path: Path) -> list[dict[str, Any]]:
    """The JSON objects of a results file, one a line (blank lines skipped)."""
    rows = []
    for number, line in enumerate(path.read_text().splitlines(), 1):
        if line.strip():
            try:
                rows.append(json.loads(line))
            except json.JSONDecodeError as err:
                raise ValueError(f"{path}:{number}: not a JSON line ({err})") from err
    return rows


def bench_page(path: Path) -> str:
    """A Markdown table of a results file's scalar columns, with its command."""
    rows = bench_rows(path)
    name = path.stem
    columns = list(
        dict.fromkeys(
            key
            for row in rows
            for key, value in row.items()
            if not isinstance(value, dict | list) and not key.endswith("_records")
        )
    )
    command = COMMANDS[name](rows) if name in COMMANDS else f"see bench/{name}.py"
    lines = [
        f"Reproduce with `{command}` (one JSON line per row, appended to the file). "
        f"Generated from `bench/results/{path.name}` ({len(rows)} rows) when these pages "
        "were built.",
        "",
        "| " + " | ".join(columns) + " |",
        "|" + "---|" * len(columns),
    ]
    for row in rows:
        lines.append("| " + " | ".join(_format(row.get(c)) for c in columns) + " |")
    return "\n".join(lines) + "\n"


def bench_pages() -> dict[str, str]:
    """``{bench_<name>.md: table}`` for every ``bench/results/*.jsonl``."""
    return {f"bench_{p.stem}.md": bench_page(p) for p in sorted(RESULTS.glob("*.jsonl"))}


# --------------------------------------------------------------------------------------
# Demos
# --------------------------------------------------------------------------------------

#: Each demo page: its script and the figures it writes (stored in figures/ by
#: ``make demo``; the pages show them, the build runs nothing).
DEMOS = {
    "free_plate": ("demo_free_plate.py", ["free/mode_20x20.png", "free/convergence.png"]),
    "obstacle_c1": (
        "demo_obstacle_c1.py",
        ["c1/mode_20x20.png", "c1/section_A.png", "c1/contact_set.png", "c1/convergence.png"],
    ),
    "obstacle_c2": (
        "demo_obstacle_c2.py",
        ["c2/mode_20x20.png", "c2/section_A.png", "c2/contact_set.png", "c2/convergence.png"],
    ),
    "obstacle_c3": (
        "demo_obstacle_c3.py",
        ["c3/mode_20x20.png", "c3/section_A.png", "c3/contact_set.png", "c3/convergence.png"],
    ),
    "garland": (
        "demo_garland.py",
        ["garland/garland_ssss.png", "garland/garland_loaded_edges_clamped.png"],
    ),
    "penalty": (
        "study_penalty.py",
        [
            "penalty_load.png",
            "penalty_conditioning.png",
            "penalty_mode_change.png",
            "penalty_section.png",
        ],
    ),
    "nonlinear": (
        "demo_nonlinear.py",
        [
            "nonlinear/load_paths.png",
            "nonlinear/southwell.png",
            "nonlinear/deformed_c1.png",
            "nonlinear/section_c1.png",
        ],
    ),
    "realistic": ("demo_realistic.py", ["realistic/mode.png", "realistic/contact_map.png"]),
    "column": (
        "demo_column.py",
        ["column/mode.png", "column/contact_map.png", "column/tie_spacing.png"],
    ),
}


def percent_to_myst(source: str) -> str:
    """A jupytext percent script as MyST Markdown: markdown cells as text, code as code.

    Not executed: the demos take minutes (``make demo`` runs them and stores the figures).
    """
    cells: list[tuple[str, list[str]]] = []
    lines = source.splitlines()
    if lines and lines[0] == "# ---":  # the jupytext header
        end = lines.index("# ---", 1)
        lines = lines[end + 1 :]
    kind, body = "code", []
    for line in lines:
        if line.startswith("# %%"):
            cells.append((kind, body))
            kind, body = ("markdown" if "[markdown]" in line else "code"), []
        else:
            body.append(line)
    cells.append((kind, body))
    out = []
    for kind, body in cells:
        while body and not body[0].strip():
            body = body[1:]
        while body and not body[-1].strip():
            body = body[:-1]
        if not body:
            continue
        if kind == "markdown":
            out.append("\n".join(re.sub(r"^# ?", "", ln) for ln in body))
        else:
            out.append("```python\n" + "\n".join(body) + "\n```")
    return "\n\n".join(out) + "\n"


def demo_pages() -> dict[str, str]:
    """``{demo_<name>.md: page}``: the script rendered, then its stored figures."""
    pages = {}
    for name, (script, figures) in DEMOS.items():
        text = percent_to_myst((ROOT / "demos" / script).read_text())
        text += (
            f"\n## Figures\n\nWritten by `python demos/{script}` (all demos: `make demo`), "
            "as stored in the repository's `figures/`:\n\n"
        )
        for fig in figures:
            text += f"![{fig}](../../figures/{fig})\n\n"
        pages[f"demo_{name}.md"] = text
    return pages


# --------------------------------------------------------------------------------------
# Sphinx
# --------------------------------------------------------------------------------------


def write_all(out: Path = GENERATED) -> list[Path]:
    """Write every generated page under ``out``; unchanged files are left untouched."""
    out.mkdir(parents=True, exist_ok=True)
    pages = {**cli_pages(), "schema.md": schema_page(), **bench_pages(), **demo_pages()}
    written = []
    for name, text in pages.items():
        path = out / name
        if not path.exists() or path.read_text() != text:
            path.write_text(text)
        written.append(path)
    return written


def _builder_inited(app: Any) -> None:
    write_all()


def setup(app: Any) -> dict[str, Any]:
    """Sphinx extension entry point."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    app.connect("builder-inited", _builder_inited)
    # The package's docstrings write absolute values and set sizes as plain |w|, |Z|.
    app.connect("autodoc-process-docstring", _process_docstring)
    return {"parallel_read_safe": True, "parallel_write_safe": True}


# --------------------------------------------------------------------------------------
# Docstrings
# --------------------------------------------------------------------------------------

#: Inline literals and roles (``...``, :role:`...`, `...`): left as they are.
_LITERAL = re.compile(r"(:[\w:.+-]+:`[^`]*`|``[^`]+``|`[^`]*`)")
#: A plain-text absolute value or set size, |w|, |Z|, |w0|: reST would read a substitution.
_BARS = re.compile(r"(?<![|\\\w])\|([A-Za-z][\w]{0,3})\|(?![|\w])")


def escape_bars(line: str) -> str:
    r"""``|w|`` outside literals and roles becomes ``\|w\|`` (shown as written)."""
    parts = _LITERAL.split(line)
    return "".join(part if k % 2 else _BARS.sub(r"\\|\1\\|", part) for k, part in enumerate(parts))


def _process_docstring(app: Any, what: str, name: str, obj: Any, options: Any, lines: list[str]):
    lines[:] = [escape_bars(line) for line in lines]
