"""Pages generated at build time: the command line, the TOML schema and the benchmarks.

Nothing here is typed by hand from the program: the ``builder-inited`` hook writes
Markdown files under ``docs/_generated/`` (not kept in git), which the pages include:

- ``cli_<command>.md``: ``unibuckle <command> --help``, from the package's argparse parser;
- ``schema.md``: every key of the problem file, from
  :func:`unibuckle_fenicsx.spec.json_schema` (its types, defaults, ranges and
  descriptions) and :func:`unibuckle_fenicsx.spec.accepted_keys`;
- ``demo_<name>.md``: each demo (a jupytext percent script) as a page, with the figures
  ``make figures`` stored in ``figures/`` (the build executes no demo);
- ``bench_<name>.md``: a table per file ``bench/results/<name>.jsonl`` (one JSON object a
  line, as the bench scripts' ``--json FILE`` writes them), with the command that
  reproduces it.

The site loads no script from the network: MathJax comes from the ``django-static-mathjax``
wheel of the ``docs`` extra (MathJax 3.2.2, the same files as the npm package), copied into
``_static/mathjax`` when the site is written (:func:`copy_mathjax`).

The functions are importable without Sphinx (``tests/docs/test_docs.py`` uses them).
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
def json_schema() -> dict[str, Any]:
    """The package's JSON Schema of the problem file."""
    from unibuckle_fenicsx import spec

    return spec.json_schema()


def accepted_keys() -> tuple[list[str], str]:
    """(every dotted key the loader accepts, where the list comes from)."""
    from unibuckle_fenicsx import spec

    return list(spec.accepted_keys()), "unibuckle_fenicsx.spec.accepted_keys()"


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
    """The TOML reference as Markdown: one row per key the loader accepts.

    Types, ranges, defaults and descriptions are the JSON Schema's, which the package
    generates from its Structs (the descriptions from their docstrings).
    """
    keys, source = accepted_keys()
    schema = json_schema()
    described = dict(schema_rows(schema))
    # A key a section's file shares with a plate's (mesh.size, material.E, ...) is
    # described by the plate's branch first: its row adds the section's own words.
    branch = schema.get("$defs", {}).get("SectionProblemSpec")
    section = {} if branch is None else dict(schema_rows(branch, schema))
    lines = [
        f"Generated from `unibuckle_fenicsx.spec.json_schema()` and {source} when "
        "these pages were built.",
        "",
        "| key | type | range | default | description |",
        "|---|---|---|---|---|",
    ]
    for key in keys:
        node = described.get(key, {})
        default = node.get("default", "")
        text = _myst(node.get("description", ""))
        own = section.get(key, {}).get("description", "")
        if own and section[key] is not node and _myst(own) != text:
            text += f" A section's file: {_myst(own)}"
        lines.append(
            "| `{}` | {} | {} | {} | {} |".format(
                key,
                _cell(_type(node, schema)) if node else "",
                _cell(_range(node)),
                f"`{json.dumps(default)}`" if "default" in node else _cell(default),
                _cell(text),
            )
        )
    lines += [
        "",
        "## The JSON Schema",
        "",
        "```json",
        json.dumps(schema, indent=2, default=str),
        "```",
        "",
        f"{len(keys)} keys.",
    ]
    return "\n".join(lines) + "\n"


def _myst(text: str) -> str:
    """Inline markup of a reST docstring as MyST: math as $...$, roles and literals as code."""
    text = re.sub(r":math:`([^`]*)`", r"$\1$", text)
    text = re.sub(r":[\w:]+:`~?([^`]*)`", r"`\1`", text)
    return re.sub(r"``([^`]+)``", r"`\1`", text)


# --------------------------------------------------------------------------------------
# Benchmarks
# --------------------------------------------------------------------------------------


#: How each results file is reproduced: a function of its rows, so that the command
#: names the meshes and cases the file actually holds.
def _listed(rows: list[dict[str, Any]], key: str) -> str:
    return ",".join(dict.fromkeys(str(r[key]) for r in rows))


def _plates_commands(rows: list[dict[str, Any]], name: str = "plates") -> str:
    """The ``bench_plates.py`` runs that wrote the rows: one per mesh, with its flags.

    ``name``: the results file's.
    """
    commands = []
    for mesh in dict.fromkeys(str(r["mesh"]) for r in rows):
        group = [r for r in rows if str(r["mesh"]) == mesh]
        flags = " --cli" if any(r.get("cli_ratio") is not None for r in group) else ""
        if any(r.get("baseline_cli_ratios") for r in group):
            flags += " --baseline PYTHON_OF_19a5414"
        flags += " --bracket" if any(r.get("bracket") for r in group) else ""
        repeat = max(len(r.get("ratios", [0])) for r in group)
        flags += f" --repeat {repeat}" if repeat > 1 else ""
        thickness = {r.get("thickness") for r in group} - {None}
        flags += f" --thickness {thickness.pop():g}" if len(thickness) == 1 else ""
        commands.append(
            f"python bench/bench_plates.py --meshes {mesh} --cases {_listed(group, 'case')}"
            f"{flags} --json bench/results/{name}.jsonl"
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
    """The ``bench_bracket.py`` runs that wrote the rows: as asked for, uncapped, by default."""
    commands = []

    def mode(r: dict[str, Any]) -> tuple[bool, bool, int]:
        return bool(r.get("bracket")), bool(r.get("uncapped")), int(r.get("repeat") or 1)

    for asked, uncapped, repeat in dict.fromkeys(mode(r) for r in rows):
        group = [r for r in rows if mode(r) == (asked, uncapped, repeat)]
        flags = (" --bracket" if asked else "") + (" --uncapped" if uncapped else "")
        flags += f" --repeat {repeat}" if repeat > 1 else ""
        commands.append(
            f"python bench/bench_bracket.py --meshes {_listed(group, 'mesh')} "
            f"--cases {_listed(group, 'case')}{flags} --json bench/results/bracket.jsonl"
        )
    return "`, then `".join(commands)


def _free_commands(rows: list[dict[str, Any]]) -> str:
    """The ``bench_free.py`` run that wrote the rows (one per plate)."""
    meshes = ",".join(f"{r['plate']}={r['mesh']}" for r in rows)
    flags = " --cli" if any(r.get("cli_s") is not None for r in rows) else ""
    if any(r.get("baseline_cli_s") is not None for r in rows):
        flags += " --baseline PYTHON_OF_19a5414"
    return (
        f"python bench/bench_free.py --plates {_listed(rows, 'plate')} --meshes {meshes} "
        f"--repeat {max(r['repeat'] for r in rows)}{flags} --json bench/results/free.jsonl"
    )


def _orderings_commands(rows: list[dict[str, Any]]) -> str:
    """The ``bench_orderings.py`` runs that wrote the rows.

    One per plate, repeat count, orderings and matrices: the meshes that share them.
    """

    def run(row: dict[str, Any]) -> tuple[str, int, str, str]:
        mesh = [r for r in rows if (r["plate"], r["mesh"]) == (row["plate"], row["mesh"])]
        return row["plate"], row["repeat"], _listed(mesh, "ordering"), _listed(mesh, "kind")

    commands = []
    for key in dict.fromkeys(run(r) for r in rows):
        group = [r for r in rows if run(r) == key]
        plate, repeat = key[:2]
        commands.append(
            f"python bench/bench_orderings.py --plates {plate} --meshes {_listed(group, 'mesh')} "
            f"--orderings {_listed(group, 'ordering')} --kinds {_listed(group, 'kind')} "
            f"--repeat {repeat} --json bench/results/orderings.jsonl"
        )
    return "`, then `".join(commands)


def _sections_commands(rows: list[dict[str, Any]], name: str = "sections") -> str:
    """The ``bench_sections.py`` runs that wrote the rows: one per section, size and levels.

    With a row's ``geometric`` and ``release_steps`` where it has them, and the chain's
    settings it turned on (``escape_either``, ``quick_descent``; ``name``: the results
    file's).
    """

    def flags(r: dict[str, Any]) -> str:
        out = f" --geometric {r['geometric']}" if "geometric" in r else ""
        out += f" --release-steps {r['release_steps']}" if "release_steps" in r else ""
        out += " --escape-either" if r.get("escape_either") else ""
        return out + (" --quick-descent" if r.get("quick_descent") else "")

    return "`, then `".join(
        f"python bench/bench_sections.py --shape {r['shape']} --size {r['size_m']:g} "
        f"--levels {r['levels_requested']} --route {r['route']}{flags(r)} "
        f"--json bench/results/{name}.jsonl"
        for r in rows
    )


def _compare_commands(rows: list[dict[str, Any]]) -> str:
    """The ``bench_bracket.py --compare`` runs that wrote the rows (budgets, repeats)."""
    commands = []

    def mode(r: dict[str, Any]) -> tuple[bool, int]:
        return bool(r.get("bracket")), int(r.get("repeat") or 1)

    for asked, repeat in dict.fromkeys(mode(r) for r in rows):
        group = [r for r in rows if mode(r) == (asked, repeat)]
        flags = (" --bracket" if asked else "") + (f" --repeat {repeat}" if repeat > 1 else "")
        commands.append(
            f"python bench/bench_bracket.py --compare --meshes {_listed(group, 'mesh')} "
            f"--cases {_listed(group, 'case')}{flags} --json bench/results/bracket_compare.jsonl"
        )
    return "`, then `".join(commands)


def _arrangements_commands(rows: list[dict[str, Any]]) -> Iterator[str]:
    """The ``bench_arrangements.py`` runs that wrote the rows (today's route alone: a worker)."""
    for mesh in dict.fromkeys(str(r["mesh"]) for r in rows):
        group = [r for r in rows if r["mesh"] == mesh]
        if any(r["policy"] != "today" for r in group):
            yield (
                f"python bench/bench_arrangements.py --meshes {mesh} --cases "
                f"{_listed(group, 'case')} --policy h2 --json bench/results/arrangements.jsonl"
            )
        else:
            nx, ny = mesh.split("x")
            yield from (
                f"python bench/bench_arrangements.py --worker {r['case']} {nx} {ny} today "
                "--json bench/results/arrangements.jsonl"
                for r in group
            )


COMMANDS = {
    "bracket": lambda rows: _bracket_commands(rows),
    "bracket_compare": lambda rows: _compare_commands(rows),
    "sections": lambda rows: _sections_commands(rows),
    "sections_full": lambda rows: _sections_commands(rows, "sections_full"),
    "sections_first_carry": lambda rows: _sections_commands(rows, "sections_first_carry"),
    "sections_first_carry_plates": lambda rows: _plates_commands(
        rows, "sections_first_carry_plates"
    ),
    "sections_box_levels_plates": lambda rows: _plates_commands(rows, "sections_box_levels_plates"),
    "sections_route": lambda rows: _sections_commands(rows, "sections_route"),
    "sections_route_plates": lambda rows: _plates_commands(rows, "sections_route_plates"),
    "section_inertia": lambda rows: (
        "python bench/bench_section_inertia.py --problems "
        + ",".join(f"{r['problem']}@{r['load_Pa']!r}" for r in rows)
        + " --json bench/results/section_inertia.jsonl"
    ),
    "step_cost": lambda rows: (
        f"python bench/bench_step_cost.py --problems {_listed(rows, 'problem')} "
        f"--orderings {_listed(rows, 'ordering')} --json bench/results/step_cost.jsonl"
    ),
    "certify": lambda rows: (
        f"python bench/bench_certify.py --meshes {_listed(rows, 'mesh')} "
        f"--cases {_listed(rows, 'case')} --json bench/results/certify.jsonl"
    ),
    "free": lambda rows: _free_commands(rows),
    "free_estimates": lambda rows: (
        f"python bench/bench_free_estimates.py --count {len(rows)} "
        f"--cells {_listed(rows, 'cells')} --seed {_listed(rows, 'seed')} "
        "--json bench/results/free_estimates.jsonl"
    ),
    "orderings": lambda rows: _orderings_commands(rows),
    "plates": lambda rows: _plates_commands(rows),
    "routes": lambda rows: _routes_commands(rows),
    "arrangements": lambda rows: "`, then `".join(_arrangements_commands(rows)),
    "fixed_factor": lambda rows: (
        f"python bench/bench_fixed_factor.py --meshes {_listed(rows, 'mesh')} "
        f"--cases {_listed(rows, 'case')} --repeat {rows[0]['runs']} "
        "--json bench/results/fixed_factor.jsonl"
    ),
    "phases": lambda rows: "`, then `".join(
        f"python bench/bench_stages.py --phases --case {case} "
        f"--meshes {_listed([r for r in rows if r['case'] == case], 'mesh')} "
        "--json bench/results/phases.jsonl"
        for case in dict.fromkeys(str(r["case"]) for r in rows)
    ),
    "profile": lambda rows: "`, then `".join(
        f"python bench/bench_profile.py --case {case} "
        f"--meshes {_listed([r for r in rows if r['case'] == case], 'mesh')} "
        "--json bench/results/profile.jsonl"
        for case in dict.fromkeys(str(r["case"]) for r in rows)
    ),
    "stages": lambda rows: "`, then `".join(
        f"python bench/bench_stages.py --case {case} "
        f"--meshes {_listed([r for r in rows if r['case'] == case], 'mesh')} "
        "--json bench/results/stages.jsonl"
        for case in dict.fromkeys(str(r["case"]) for r in rows)
    ),
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


#: The columns of a ``bench_sections.py`` results file's table.
SECTIONS_COLUMNS = [
    ("shape", "section"),
    ("route", "route"),
    ("dofs", "DOFs"),
    ("constrained", "constrained directions"),
    ("per_level", "per level: steps / factorisations / eigen solves"),
    ("factorisations", "factorisations"),
    ("ratio", "time (free solves)"),
    ("process_ratio", "whole run (hollow runs)"),
    ("core_load/ref", "σ/σ_ref"),
    ("kkt", "KKT"),
    ("core_load_Pa", "σ_c (Pa)"),
]
#: The columns each results file's table shows, with their headers (words and units);
#: every other scalar is in the file. A file not listed shows every scalar column.
BENCH_COLUMNS: dict[str, list[tuple[str, str]]] = {
    "plates": [
        ("case", "plate"),
        ("mesh", "mesh"),
        ("i", "i"),
        ("contact_nodes", "\\|Z\\|"),
        ("route", "route"),
        ("levels", "per level: steps / factorisations / eigen solves"),
        ("ratio", "time (free solves)"),
        ("cli_ratio", "`unibuckle solve` (free solves)"),
        ("cli_cpu_ratio", "its CPU time (free runs)"),
        ("m", "m"),
        ("certificate", "certificate"),
        ("k", "k"),
        ("load_Pa", "λ_c (Pa)"),
    ],
    "sections": SECTIONS_COLUMNS,
    "sections_full": [
        *SECTIONS_COLUMNS[:4],
        ("geometric", "geometric"),
        ("release_steps", "release_steps"),
        *SECTIONS_COLUMNS[4:],
    ],
    "sections_first_carry": [
        *SECTIONS_COLUMNS[:4],
        ("escape_either", "escape_either"),
        ("quick_descent", "quick_descent"),
        ("versions", "versions of the levers"),
        *SECTIONS_COLUMNS[4:],
    ],
    "bracket": [
        ("case", "case"),
        ("mesh", "mesh"),
        ("bracket", "--bracket"),
        ("uncapped", "--uncapped"),
        ("m", "m"),
        ("load_Pa", "λ_c (Pa)"),
        ("lower_bound_Pa", "lower bound (Pa)"),
        ("relative_gap", "gap"),
        ("status", "status"),
        ("distances", "distances (δ: verified, or why not)"),
        ("r", "r"),
        ("pieces", "pieces"),
        ("examined", "pieces examined"),
        ("rhs", "right-hand sides"),
        ("estimated_cost", "estimated cost (free solves)"),
        ("route_ratio", "route time (free solves)"),
        ("certify_ratio", "certificate time (free solves)"),
    ],
    "bracket_compare": [
        ("case", "case"),
        ("mesh", "mesh"),
        ("bracket", "--bracket"),
        ("m", "m"),
        ("load_Pa", "λ_c (Pa)"),
        *[
            (f"{key}_{tag}", f"{header} ({tag})")
            for key, header in (
                ("gap", "gap"),
                ("factorisations", "factorisations"),
                ("rhs", "right-hand sides"),
                ("examined", "pieces examined"),
                ("pieces", "pieces proven"),
                ("route_ratio", "route time (free solves)"),
            )
            for tag in ("without", "with")
        ],
    ],
    "certify": [
        ("case", "case"),
        ("mesh", "mesh"),
        ("i", "i"),
        ("contact_nodes", "\\|Z\\|"),
        ("proven_by", "proven by"),
        ("relative_gap", "gap"),
        ("factorisations", "factorisations"),
        ("solves", "solves"),
        ("ratio", "certificate time (free solves)"),
        ("load_Pa", "λ_c (Pa)"),
    ],
    "arrangements": [
        ("case", "plate"),
        ("mesh", "mesh"),
        ("policy", "route"),
        ("ranking", "ranked lowest by (last, h2, fit)"),
        ("per_level", "per level: steps / factorisations / eigen solves"),
        ("load", "λ_c (Pa)"),
        ("rel_today", "− today's (relative)"),
        ("contact", "\\|Z\\|"),
        ("kkt", "KKT"),
        ("process_s", "process s (shared machine)"),
    ],
    "fixed_factor": [
        ("case", "plate"),
        ("mesh", "mesh"),
        ("today_fine", "today's fine level: steps / factorisations / eigen solves"),
        ("start", "start"),
        ("start_nodes", "its nodes"),
        ("start_after", "today's fine factorisations before it"),
        ("factorisations", "factorisations"),
        ("solves", "solves"),
        ("columns", "G columns"),
        ("eigensolves", "eigen solves"),
        ("end", "end"),
        ("contact", "\\|Z\\|"),
        ("rel_diff", "load − today's (relative)"),
        ("t_factor", "LDL (s)"),
        ("t_capacitance", "G (s)"),
        ("t_eigen", "eigen (s)"),
        ("t_total", "polish (s)"),
        ("factor_equivalents", "polish (fine factorisations)"),
    ],
    "phases": [
        ("case", "plate"),
        ("mesh", "mesh"),
        ("level", "level"),
        ("dofs", "DOFs"),
        ("steps", "Newton steps"),
        ("factorisations", "factorisations"),
        ("solves", "solves"),
        ("eigensolves", "eigen solves"),
        ("setup", "setup (s)"),
        ("kernel", "kernel (s)"),
        ("prolong", "prolong (s)"),
        ("relax", "relax (s)"),
        ("lift", "lift (s)"),
        ("LDL calls", "LDL count"),
        ("LDL", "LDL (s)"),
        ("Newton", "Newton (s)"),
        ("sets", "sets (s)"),
        ("eigen", "eigen (s)"),
        ("other", "other (s)"),
        ("level total", "level (s)"),
        ("free solve", "free solve (s)"),
        ("certificate", "certificate (s)"),
        ("total", "total (s)"),
        ("free run", "free run (s)"),
        ("ratio", "total / free run"),
        ("load_Pa", "λ_c (Pa)"),
    ],
    "stages": [
        ("case", "plate"),
        ("mesh", "mesh"),
        ("dofs", "DOFs"),
        ("setup", "setup (s)"),
        ("free solve", "free solve (s)"),
        ("coarse levels", "coarse levels (s)"),
        ("fine IP", "fine interior point (s)"),
        ("fine LDL calls", "fine factorisations"),
        ("fine LDL", "their time (s)"),
        ("fine eigen", "fine eigen solves (s)"),
        ("certificate", "certificate (s)"),
        ("total", "total (s)"),
        ("free run", "free run (s)"),
        ("ratio", "total / free run"),
        ("per_level", "per level: steps / factorisations / solves / eigen solves"),
        ("factorisations", "factorisations (run)"),
        ("free_factorisations", "factorisations (free run)"),
        ("solves", "solves (run)"),
        ("free_solves", "solves (free run)"),
        ("tolerance", "KKT tolerance"),
        ("load_Pa", "λ_c (Pa)"),
    ],
    "routes": [
        ("case", "plate"),
        ("mesh", "mesh"),
        ("t_over_b", "t/b"),
        ("auto", "auto's route"),
        ("ip_ratio", "interior point (free solves)"),
        ("ip_eigensolves", "its eigen solves"),
        ("as_ratio", "active set (free solves)"),
        ("as_eigensolves", "its eigen solves"),
        ("load_difference", "load difference (AS − IP)/IP"),
    ],
    "free": [
        ("plate", "plate"),
        ("mesh", "mesh"),
        ("dofs", "DOFs"),
        ("package_s", "free solve and proof (s)"),
        ("estimate_s", "of which the estimate (s)"),
        ("factorisations", "factorisations"),
        ("solves", "solves"),
        ("plain_s", "plain SLEPc (s)"),
        ("plain_proof_s", "plain SLEPc with the proof (s)"),
        ("floor_ratio", "free solve / plain with proof"),
        ("cli_s", "`unibuckle solve` (s)"),
        ("total_s", "its total_s"),
        ("baseline_cli_s", "before (s)"),
        ("baseline_total_s", "its total_s"),
        ("package_load", "λ_free (Pa)"),
        ("plain_proof_rdiff", "plain with proof: load − λ_free (rel.)"),
    ],
    "free_estimates": [
        ("plate", "plate"),
        ("mesh", "mesh"),
        ("indefinite", "B indefinite"),
        ("coarse_error", "coarse load error"),
        ("gap", "λ₂/λ₁ − 1"),
        ("first_below", "below the first shift"),
        ("factorisations", "factorisations"),
        ("agrees", "load as at target 0"),
    ],
    "orderings": [
        ("plate", "plate"),
        ("dofs", "rows"),
        ("kind", "matrix"),
        ("ordering", "ordering"),
        ("analysis_s", "analysis (CPU s)"),
        ("numeric_s", "numeric (CPU s)"),
        ("solve_s", "solve (CPU s)"),
        ("free_s", "analysis + numeric + 10 solves"),
        ("factor_entries", "entries in the factors"),
        ("flops", "operations"),
        ("memory_MB", "memory (MB)"),
    ],
}
#: The plates measured beside the filled sections, as the plates' file shows them.
BENCH_COLUMNS["sections_first_carry_plates"] = BENCH_COLUMNS["plates"]
#: The faces of the filled box as plates (b/t = 100), measured beside it.
BENCH_COLUMNS["sections_box_levels_plates"] = [
    ("thickness", "t (m)"),
    *BENCH_COLUMNS["plates"],
]
#: The section route per level beside its free solve, in seconds too.
BENCH_COLUMNS["sections_route"] = [
    *SECTIONS_COLUMNS[:5],
    ("free_s", "free solve (s)"),
    ("unilateral_s", "unilateral solve (s)"),
    *SECTIONS_COLUMNS[5:],
]
BENCH_COLUMNS["sections_route_plates"] = BENCH_COLUMNS["sections_box_levels_plates"]
#: The pencil's eigenvalues below the critical load, section and plate.
BENCH_COLUMNS["section_inertia"] = [
    ("problem", "problem"),
    ("rows", "rows"),
    ("free_load_Pa", "λ_free (Pa)"),
    ("load_Pa", "λ_c (Pa)"),
    ("load/free", "λ_c / λ_free"),
    ("below", "eigenvalues below λ_c"),
]
BENCH_COLUMNS["profile"] = [
    ("case", "plate"),
    ("mesh", "mesh"),
    ("free", "free run"),
    ("dofs", "DOFs"),
    ("method", "route"),
    ("eigensolves", "eigen solves"),
    ("wall", "solve, wall (s)"),
    ("process_wall", "process, wall (s)"),
    ("process_cpu", "process, CPU (s)"),
    ("maxrss_kib", "peak RSS (KiB)"),
    ("load_Pa", "load (Pa)"),
]
#: Long texts shown as numbered notes under the table (the cell holds the note's
#: number and the text up to its first colon).
BENCH_NOTES = {"plates": "certificate"}


def bench_page(path: Path) -> str:
    """A Markdown table of a results file's chosen columns, with its command and notes."""
    rows = bench_rows(path)
    name = path.stem
    columns = BENCH_COLUMNS.get(name) or [
        (key, key)
        for key in dict.fromkeys(
            key
            for row in rows
            for key, value in row.items()
            if not isinstance(value, dict | list) and not key.endswith("_records")
        )
    ]
    command = COMMANDS[name](rows) if name in COMMANDS else f"see bench/{name}.py"
    noted = BENCH_NOTES.get(name)
    notes: dict[str, int] = {}
    lines = [
        f"Reproduce with `{command}` (one JSON line per row, appended to the file). "
        f"Generated from `bench/results/{path.name}` ({len(rows)} rows; every number of a "
        "row is in the file) when these pages were built.",
        "",
        "| " + " | ".join(header for _, header in columns) + " |",
        "|" + "---|" * len(columns),
    ]
    for row in rows:
        cells = []
        for key, _ in columns:
            value = row.get(key)
            if key == noted and isinstance(value, str) and value:
                number = notes.setdefault(value, len(notes) + 1)
                cells.append(f"{_cell(value.split(':', 1)[0])} ({number})")
            else:
                cells.append(_format(value))
        lines.append("| " + " | ".join(cells) + " |")
    for text, number in notes.items():
        flags = re.sub(r"(?<![\w`])(--[\w-]+|\w+\.\w+ = \w+)", r"`\1`", _cell(text))
        lines += ["", f"({number}) {flags}"]
    return "\n".join(lines) + "\n"


def bench_pages() -> dict[str, str]:
    """``{bench_<name>.md: table}`` for every ``bench/results/*.jsonl``."""
    return {f"bench_{p.stem}.md": bench_page(p) for p in sorted(RESULTS.glob("*.jsonl"))}


# --------------------------------------------------------------------------------------
# Demos
# --------------------------------------------------------------------------------------

#: Each demo page: its script and the figures it writes (stored in figures/ by
#: ``make figures``; the pages show them, the build runs nothing).
DEMOS = {
    "free_plate": ("demo_free_plate.py", ["free/mode_20x20.png", "free/convergence.png"]),
    "obstacle_c1": (
        "demo_obstacle_c1.py",
        [
            "c1/mode_20x20.png",
            "c1/section_A.png",
            "c1/contact_set.png",
            "c1/contact_force.png",
            "c1/convergence.png",
        ],
    ),
    "obstacle_c2": (
        "demo_obstacle_c2.py",
        [
            "c2/mode_20x20.png",
            "c2/section_A.png",
            "c2/contact_set.png",
            "c2/contact_force.png",
            "c2/convergence.png",
        ],
    ),
    "obstacle_c3": (
        "demo_obstacle_c3.py",
        [
            "c3/mode_20x20.png",
            "c3/section_A.png",
            "c3/contact_set.png",
            "c3/contact_force.png",
            "c3/convergence.png",
        ],
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
    "ties": ("study_ties.py", ["ties/tie_spacing_study.png"]),
    "sections": (
        "demo_sections.py",
        [
            "sections/box_filled.png",
            "sections/box_hollow.png",
            "sections/tube_filled.png",
            "sections/tube_hollow.png",
        ],
    ),
}


def percent_to_myst(source: str) -> str:
    """A jupytext percent script as MyST Markdown: markdown cells as text, code as code.

    Not executed: the demos take minutes (``make figures`` runs them and stores the figures).
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


#: Where ``make demo`` keeps each demo's printed output (``demos/run_all.py``).
OUTPUTS = ROOT / "figures" / "stdout"


def demo_pages() -> dict[str, str]:
    """``{demo_<name>.md: page}``: a download link, the script, its output and figures.

    The output is the one ``make demo`` stored (``figures/stdout/<script>.txt``); the
    build runs nothing.
    """
    pages = {}
    for name, (script, figures) in DEMOS.items():
        download = (
            f"{{download}}`Download the script demos/{script} <../../demos/{script}>` "
            f"(run it with `python demos/{script}`; all demos: `make demo`).\n\n"
        )
        body = percent_to_myst((ROOT / "demos" / script).read_text())
        if body.startswith("# "):  # under the page's title
            title, _, rest = body.partition("\n")
            text = f"{title}\n\n{download}{rest.lstrip()}"
        else:
            text = download + body
        output = OUTPUTS / script.replace(".py", ".txt")
        if output.exists():
            text += (
                "\n## Output\n\nWhat the script printed when `make demo` last ran it "
                f"(`figures/stdout/{output.name}`):\n\n"
                f"```{{literalinclude}} ../../figures/stdout/{output.name}\n"
                ":language: text\n```\n"
            )
        text += (
            f"\n## Figures\n\nWritten by `python demos/{script} --figures figures` (all demos: "
            "`make figures`), as stored in the repository's `figures/`:\n\n"
        )
        for fig in figures:
            text += f"![{fig}](../../figures/{fig})\n\n"
        pages[f"demo_{name}.md"] = text
    return pages


def gallery() -> str:
    """The demos' thumbnail gallery: each demo's first figure, linked to its page."""
    cells = []
    for name, (script, figures) in DEMOS.items():
        cells.append(
            f"```{{figure}} ../../figures/{figures[0]}\n:target: {name}.html\n"
            f":alt: {name}\n\n[{name.replace('_', ' ')}]({name}.md): `demos/{script}`\n```\n"
        )
    return "::::{container} gallery\n\n" + "\n".join(cells) + "\n::::\n"


# --------------------------------------------------------------------------------------
# Links to other projects' documentation, offline (intersphinx)
# --------------------------------------------------------------------------------------

#: The other projects' objects the pages and docstrings name, with their pages: the
#: intersphinx inventories (``objects.inv``) the build would download, written here from
#: this table instead, since the build has no network. Each entry: (role, page and
#: anchor under the project's base address). Private paths that type hints produce
#: (``numpy._typing._array_like.NDArray``, ``dolfinx.fem.function.Function``) point to
#: the public object's page.
INVENTORIES: dict[str, tuple[str, dict[str, tuple[str, str]]]] = {
    "python": (
        "https://docs.python.org/3/",
        {
            "collections.abc.Callable": ("class", "library/collections.abc.html#$"),
            "collections.abc.Iterator": ("class", "library/collections.abc.html#$"),
            "collections.abc.Mapping": ("class", "library/collections.abc.html#$"),
            "collections.abc.Sequence": ("class", "library/collections.abc.html#$"),
            "pathlib.Path": ("class", "library/pathlib.html#$"),
            "Path": ("class", "library/pathlib.html#pathlib.Path"),
            "argparse.ArgumentParser": ("class", "library/argparse.html#$"),
            "argparse.Namespace": ("class", "library/argparse.html#$"),
            "argparse.RawDescriptionHelpFormatter": ("class", "library/argparse.html#$"),
            "argparse.ArgumentDefaultsHelpFormatter": ("class", "library/argparse.html#$"),
            "contextvars.ContextVar": ("class", "library/contextvars.html#$"),
            "enum.Enum": ("class", "library/enum.html#$"),
            "enum.StrEnum": ("class", "library/enum.html#$"),
            "logging.Logger": ("class", "library/logging.html#$"),
            "math.fsum": ("function", "library/math.html#$"),
            "itertools.combinations": ("function", "library/itertools.html#$"),
        },
    ),
    "numpy": (
        "https://numpy.org/doc/stable/",
        {
            "numpy.ndarray": ("class", "reference/generated/numpy.ndarray.html#$"),
            "numpy.float64": ("class", "reference/arrays.scalars.html#$"),
            "numpy.int64": ("class", "reference/arrays.scalars.html#$"),
            "numpy.int32": ("class", "reference/arrays.scalars.html#$"),
            "numpy.bool": ("class", "reference/arrays.scalars.html#$"),
            "numpy.bool_": ("class", "reference/arrays.scalars.html#numpy.bool"),
            "numpy.typing.NDArray": ("class", "reference/typing.html#$"),
            "numpy.typing.ArrayLike": ("class", "reference/typing.html#$"),
            "numpy._typing._array_like.NDArray": (
                "class",
                "reference/typing.html#numpy.typing.NDArray",
            ),
            "numpy._typing._array_like.ArrayLike": (
                "class",
                "reference/typing.html#numpy.typing.ArrayLike",
            ),
            # The aliases the package's type hints use (import numpy as np, ... as npt).
            "npt.NDArray": ("class", "reference/typing.html#numpy.typing.NDArray"),
            "npt.ArrayLike": ("class", "reference/typing.html#numpy.typing.ArrayLike"),
            "np.ndarray": ("class", "reference/generated/numpy.ndarray.html#numpy.ndarray"),
            "np.float64": ("class", "reference/arrays.scalars.html#numpy.float64"),
            "np.int64": ("class", "reference/arrays.scalars.html#numpy.int64"),
            "np.int32": ("class", "reference/arrays.scalars.html#numpy.int32"),
            "np.bool_": ("class", "reference/arrays.scalars.html#numpy.bool"),
        },
    ),
    "petsc4py": (
        "https://petsc.org/release/petsc4py/",
        {
            f"{prefix}PETSc.{name}": ("class", f"reference/petsc4py.PETSc.{name}.html")
            for name in ("Vec", "Mat", "KSP", "PC", "SNES", "Options", "Viewer")
            for prefix in ("petsc4py.", "")  # as the hints write it: from petsc4py import PETSc
        },
    ),
    "slepc4py": (
        "https://slepc.upv.es/slepc4py-current/docs/apiref/",
        {
            f"{prefix}SLEPc.EPS": ("class", "slepc4py.SLEPc.EPS-class.html")
            for prefix in ("slepc4py.", "")  # as the hints write it: from slepc4py import SLEPc
        },
    ),
    "mpi4py": (
        "https://mpi4py.readthedocs.io/en/stable/",
        {
            "mpi4py.MPI.Comm": ("class", "reference/mpi4py.MPI.Comm.html"),
            "MPI.Comm": ("class", "reference/mpi4py.MPI.Comm.html"),
        },
    ),
    "dolfinx": (
        "https://docs.fenicsproject.org/dolfinx/v0.11.0/python/",
        {
            "dolfinx.fem.Function": ("class", "generated/dolfinx.fem.html#$"),
            "dolfinx.fem.function.Function": (
                "class",
                "generated/dolfinx.fem.html#dolfinx.fem.Function",
            ),
            "dolfinx.fem.FunctionSpace": ("class", "generated/dolfinx.fem.html#$"),
            "dolfinx.fem.function.FunctionSpace": (
                "class",
                "generated/dolfinx.fem.html#dolfinx.fem.FunctionSpace",
            ),
            "dolfinx.fem.Constant": ("class", "generated/dolfinx.fem.html#$"),
            "dolfinx.fem.function.Constant": (
                "class",
                "generated/dolfinx.fem.html#dolfinx.fem.Constant",
            ),
            "dolfinx.fem.DirichletBC": ("class", "generated/dolfinx.fem.html#$"),
            "dolfinx.fem.bcs.DirichletBC": (
                "class",
                "generated/dolfinx.fem.html#dolfinx.fem.DirichletBC",
            ),
            "dolfinx.mesh.Mesh": ("class", "generated/dolfinx.mesh.html#$"),
            "dolfinx.mesh.MeshTags": ("class", "generated/dolfinx.mesh.html#$"),
            "dolfinx.la.Vector": ("class", "generated/dolfinx.la.html#$"),
            "dolfinx.io.gmsh.model_to_mesh": ("function", "generated/dolfinx.io.gmsh.html#$"),
            "dolfinx.fem.petsc.LinearProblem": ("class", "generated/dolfinx.fem.petsc.html#$"),
        },
    ),
    "ufl": (
        "https://docs.fenicsproject.org/ufl/main/",
        {
            "ufl.core.expr.Expr": ("class", "api-doc/ufl.core.html#$"),
            "ufl.form.Form": ("class", "api-doc/ufl.html#$"),
            "ufl.argument.Argument": ("class", "api-doc/ufl.html#$"),
            "ufl.Argument": ("class", "api-doc/ufl.html#ufl.argument.Argument"),
            "ufl.Form": ("class", "api-doc/ufl.html#ufl.form.Form"),
        },
    ),
    "msgspec": (
        "https://jcristharif.com/msgspec/",
        {
            "msgspec.Struct": ("class", "api.html#$"),
            "msgspec.Meta": ("class", "api.html#$"),
            "msgspec.UnsetType": ("class", "api.html#$"),
            "msgspec.convert": ("function", "api.html#$"),
            "msgspec.ValidationError": ("exception", "api.html#$"),
        },
    ),
}


def write_inventory(project: str, out: Path = GENERATED / "inventories") -> Path:
    """Write ``project``'s :data:`INVENTORIES` entry as an intersphinx ``objects.inv``.

    Sphinx's inventory format, version 2: four header lines, then zlib-compressed lines
    ``name domain:role priority uri display`` (``$`` in the uri stands for the name).
    """
    import zlib

    _, objects = INVENTORIES[project]
    header = (
        "# Sphinx inventory version 2\n"
        f"# Project: {project}\n"
        "# Version: \n"
        "# The remainder of this file is compressed using zlib.\n"
    )
    # A class entry is also written as py:type: Sphinx 9 refers to type aliases so.
    body = "".join(
        f"{name} py:{kind} 1 {uri} -\n"
        for name, (role, uri) in sorted(objects.items())
        for kind in ((role, "type") if role == "class" else (role,))
    )
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{project}.inv"
    data = header.encode() + zlib.compress(body.encode())
    if not path.exists() or path.read_bytes() != data:
        path.write_bytes(data)
    return path


def intersphinx_mapping() -> dict[str, tuple[str, str]]:
    """``conf.py``'s ``intersphinx_mapping``: each project's address and local inventory."""
    return {name: (base, str(write_inventory(name))) for name, (base, _) in INVENTORIES.items()}


# --------------------------------------------------------------------------------------
# The public API
# --------------------------------------------------------------------------------------


def public_callables() -> list[str]:
    """The public classes and functions (their pages are the API page's stubs)."""
    import unibuckle_fenicsx

    return [n for n in public_names() if callable(getattr(unibuckle_fenicsx, n))]


def public_names() -> list[str]:
    """The package's public names: ``unibuckle_fenicsx.__all__`` (not ``__version__``)."""
    import unibuckle_fenicsx

    return [name for name in unibuckle_fenicsx.__all__ if not name.startswith("_")]


def api_public_page() -> str:
    """An autosummary table of :func:`public_names`, for ``reference/api.rst`` to include.

    Generated from ``__all__``, so a name the package adds, moves or drops follows here
    without an edit (its page comes from the object's docstring, wherever it lives). The
    stub pages are written by :func:`write_public_stubs` (autosummary does not read an
    included file). Data (``CASES``) have no docstring of their own: they are listed with
    their defining module's description instead.
    """
    import unibuckle_fenicsx

    lines = [".. autosummary::", "   :toctree: _autosummary", "   :nosignatures:", ""]
    data = []
    for name in public_names():
        if callable(getattr(unibuckle_fenicsx, name)):
            lines.append(f"   unibuckle_fenicsx.{name}")
        else:
            data.append(name)
    for name in data:
        home = _home_module(name)
        lines += ["", f"``{name}``: :data:`{home}.{name}` (see :mod:`{home}`)."]
    return "\n".join(lines) + "\n"


def _home_module(name: str) -> str:
    """The module that defines the public data ``name`` (where its ``#:`` comment is)."""
    import importlib
    import pkgutil

    import unibuckle_fenicsx

    for info in pkgutil.iter_modules(unibuckle_fenicsx.__path__, "unibuckle_fenicsx."):
        module = importlib.import_module(info.name)
        if name in getattr(module, "__all__", ()) and name in vars(module):
            value = vars(module)[name]
            if value is getattr(unibuckle_fenicsx, name):
                return info.name
    return "unibuckle_fenicsx"


def write_public_stubs(out: Path) -> list[Path]:
    """The autosummary stub page of each public class and function, under ``out``."""
    import inspect

    import unibuckle_fenicsx

    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name in public_names():
        obj = getattr(unibuckle_fenicsx, name)
        if not callable(obj):
            continue
        full = f"unibuckle_fenicsx.{name}"
        if inspect.isclass(obj):
            body = f".. autoclass:: {name}\n   :members:\n   :show-inheritance:\n"
        else:
            body = f".. autofunction:: {name}\n"
        text = f"{full}\n{'=' * len(full)}\n\n.. currentmodule:: unibuckle_fenicsx\n\n{body}"
        path = out / f"{full}.rst"
        if not path.exists() or path.read_text() != text:
            path.write_text(text)
        written.append(path)
    return written


# --------------------------------------------------------------------------------------
# The quickstart's numbers
# --------------------------------------------------------------------------------------

#: The output ``make demo`` stores for the quickstart (``demos/run_all.py``).
QUICKSTART = ROOT / "figures" / "quickstart"

_SUMMARY = re.compile(
    r"lambda_c = (?P<load>\S+) Pa \((?P<ratio>\S+) x free (?P<free>\S+) Pa\), "
    r"k = (?P<k>\S+), method (?P<method>\S+)\s+i=(?P<i>\d+) \|Z\|=(?P<z>\d+)\s+"
    r"KKT=(?P<kkt>\w+)\s+proven=(?P<proven>\w+) \(KKT only, m=(?P<m>\d+)(?:; [^)]*)?\), "
    r"(?P<solves>\d+) eigensolves, (?P<seconds>\S+) s"
)
_BOUND = re.compile(r"lies between (?P<lower>\S+) Pa .* and (?P<upper>\S+) Pa")
_DESIGN = re.compile(r"slenderness (?P<slenderness>\S+), rho = (?P<rho>\S+), ")
_ZONE = re.compile(r"cover (?P<cover>\S+)% of its area \((?P<nodes>\d+) nodes\)")


def quickstart_numbers(folder: Path = QUICKSTART) -> dict[str, str]:
    """The numbers the quickstart's text quotes, read off the output it shows.

    ``{name: text}`` for MyST substitutions (``{{ name }}`` in the page): the loads in MPa,
    the ratio, k, the node counts, the zone's cover, the design output, and two numbers
    worked out from them by hand's formulas (the load over the yield stress of the problem
    file, the relative slenderness at the lower bound, EN 1993-1-5 (4.3)).
    """
    import tomllib

    text = (folder / "output.txt").read_text()
    found: dict[str, str] = {}
    for pattern in (_SUMMARY, _BOUND, _DESIGN, _ZONE):
        match = pattern.search(text)
        if match is None:
            raise ValueError(f"{folder / 'output.txt'}: no match for {pattern.pattern!r}")
        found.update(match.groupdict())
    problem = tomllib.loads((ROOT / "demos" / "plate.toml").read_text())
    fy = float(problem["design"]["yield_stress"])
    mpa = {key: float(found[key]) / 1e6 for key in ("load", "free", "lower", "upper")}
    return {
        **found,
        **{f"{key}_MPa": f"{value:.0f}" for key, value in mpa.items()},
        "fy_MPa": f"{fy / 1e6:.0f}",
        "load_over_fy": f"{float(found['load']) / fy:.1f}",
        "slenderness_lower": f"{math.sqrt(fy / float(found['lower'])):.2f}",
        "k_free": f"{float(found['k']) / float(found['ratio']):.2f}",
        "rise_percent": f"{100 * (float(found['ratio']) - 1):.0f}",
    }


# --------------------------------------------------------------------------------------
# Sphinx
# --------------------------------------------------------------------------------------


def write_all(out: Path = GENERATED) -> list[Path]:
    """Write every generated page under ``out``; unchanged files are left untouched."""
    out.mkdir(parents=True, exist_ok=True)
    pages = {
        **cli_pages(),
        "schema.md": schema_page(),
        **bench_pages(),
        **demo_pages(),
        "gallery.md": gallery(),
        "api_public.rst": api_public_page(),
    }
    written = []
    for name, text in pages.items():
        path = out / name
        if not path.exists() or path.read_text() != text:
            path.write_text(text)
        written.append(path)
    return written


def _builder_inited(app: Any) -> None:
    write_all()
    write_public_stubs(ROOT / "docs" / "reference" / "_autosummary")


#: The parts of MathJax's ``es5`` build the pages use: the TeX and MathML input with its
#: extensions (loaded on demand, e.g. ``\boldsymbol``), the CommonHTML output and its
#: fonts, the context menu and the assistive MathML. Not copied: the SVG output and the
#: speech rule engine's maps (4 MB, for the menu's speech option only).
MATHJAX_PARTS = ("tex-mml-chtml.js", "input", "output/chtml", "ui", "a11y")
#: Where the pages load it from (``conf.py``'s ``mathjax_path``, under ``_static``).
MATHJAX_PATH = "mathjax/tex-mml-chtml.js"


def mathjax_source() -> Path:
    """The ``es5`` directory of the installed MathJax (the ``django-static-mathjax`` wheel)."""
    try:
        import mathjax  # type: ignore[import-not-found]
    except ImportError as err:
        raise RuntimeError(
            "MathJax is not installed: pip install -e '.[docs]' (django-static-mathjax)"
        ) from err
    es5 = Path(mathjax.__file__).parent / "static" / "mathjax" / "es5"
    if not (es5 / "tex-mml-chtml.js").is_file():
        raise RuntimeError(f"no MathJax build at {es5} (django-static-mathjax changed layout)")
    return es5


def copy_mathjax(outdir: Path) -> Path:
    """Copy :data:`MATHJAX_PARTS` and MathJax's licence into ``outdir/_static/mathjax``."""
    import shutil

    source = mathjax_source()
    target = outdir / "_static" / "mathjax"
    for part in MATHJAX_PARTS:
        src, dst = source / part, target / part
        if src.is_dir():
            shutil.copytree(src, dst, dirs_exist_ok=True)
        else:
            dst.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dst)
    shutil.copy2(source.parent / "LICENSE", target / "LICENSE")
    return target


def _build_finished(app: Any, exception: Exception | None) -> None:
    if exception is None and app.builder.format == "html":
        copy_mathjax(Path(app.outdir))


def _annotations_without_metadata() -> None:
    """Render ``Annotated[T, Meta(...)]`` as ``T`` in the API pages.

    msgspec's constraints and units on the problem's fields (``Meta(gt=0, extra={"unit":
    "m"})``) are checked by the schema and documented on the key reference page; Sphinx would
    print them inside the type and read their words as class names. Sphinx has no option
    for this, so its ``stringify_annotation`` is wrapped where autodoc and napoleon import it.
    """
    import importlib
    import typing

    import sphinx.util.typing as sphinx_typing

    original = sphinx_typing.stringify_annotation
    if getattr(original, "_unibuckle", False):
        return

    def stringify(annotation: Any, *args: Any, **kwargs: Any) -> str:
        if typing.get_origin(annotation) is typing.Annotated:
            annotation = typing.get_args(annotation)[0]
        return original(annotation, *args, **kwargs)

    stringify._unibuckle = True  # type: ignore[attr-defined]
    sphinx_typing.stringify_annotation = stringify
    for name in (
        "sphinx.util.inspect",
        "sphinx.ext.napoleon.docstring",
        "sphinx.ext.autodoc._dynamic._loader",
        "sphinx.ext.autodoc._dynamic._type_annotations",
        "sphinx.ext.autodoc._legacy_class_based._documenters",
        "sphinx.ext.autodoc._generate",
    ):
        try:
            module = importlib.import_module(name)
        except ImportError:
            continue
        if hasattr(module, "stringify_annotation"):
            module.stringify_annotation = stringify  # type: ignore[attr-defined]


def setup(app: Any) -> dict[str, Any]:
    """Sphinx extension entry point."""
    _annotations_without_metadata()
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    app.connect("builder-inited", _builder_inited)
    app.connect("build-finished", _build_finished)
    # The package's docstrings write absolute values and set sizes as plain |w|, |Z|.
    app.connect("autodoc-process-docstring", _process_docstring)
    # After intersphinx (priority 500): names the package's pages hold under another name.
    app.connect("missing-reference", _missing_reference, priority=900)
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
    if what in ("attribute", "data", "property"):
        lines[:] = prose_type_restored(lines, name)


_BUILTIN_TYPES = {"int", "float", "str", "bool", "bytes", "None", "dict", "list", "tuple", "set"}


def _is_type(text: str, name: str) -> bool:
    """Whether ``text`` reads as a type expression in the module of the object ``name``.

    A type is words joined by ``.``, ``[ ]``, ``,`` and ``|``; a single word must be a
    builtin type, a name of the object's module, or start with a module of its own
    (``numpy.``): otherwise it is prose ("m", "Kind", "the zone").
    """
    import importlib

    t = text.strip()
    if not re.fullmatch(r"[\w.\[\], |]+", t):
        return False
    if re.search(r"\w \w", t.replace(" | ", "|").replace(", ", ",")):
        return False
    words = re.findall(r"[A-Za-z_][\w.]*", t)
    module = None
    parts = name.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            module = importlib.import_module(".".join(parts[:cut]))
            break
        except ImportError:
            continue
    for word in words:
        head = word.split(".")[0]
        if word in _BUILTIN_TYPES or head in ("numpy", "np", "npt", "typing", "collections"):
            continue
        if module is not None and hasattr(module, head):
            continue
        return False
    return True


def prose_type_restored(lines: list[str], name: str) -> list[str]:
    """Undo napoleon's reading of an attribute's opening words as its type.

    Napoleon takes the text before the first colon of an attribute's or property's
    docstring as its type (``int: the count.``); the package's docstrings open with prose
    there ("The plate's area (m^2): ..."), which became a type nobody can link. Such a
    ``:type:`` line is put back in front of the description.
    """
    for k, line in enumerate(lines):
        if line.startswith(":type: ") and not _is_type(line[len(":type: ") :], name):
            prose = line[len(":type: ") :].strip()
            rest = [ln for j, ln in enumerate(lines) if j != k]
            while rest and not rest[-1].strip():
                rest.pop()
            first = next((j for j, ln in enumerate(rest) if ln.strip()), None)
            if first is None:
                return [prose]
            rest[first] = f"{prose}: {rest[first]}"
            return rest
    return lines


# --------------------------------------------------------------------------------------
# References the package's own pages do not hold under the name used
# --------------------------------------------------------------------------------------


def _python_objects(env: Any) -> dict[str, Any]:
    return dict(env.get_domain("py").objects)


def reference_candidates(target: str, objects: dict[str, Any], module: str | None) -> list[str]:
    """Documented names that ``target`` may mean, best first.

    - ``unibuckle_fenicsx.spec.ProblemSpec`` (re-exported by a package): the object's
      public name (``unibuckle_fenicsx.ProblemSpec``) or its defining module's name;
    - a bare name (``ProblemSpec``, ``CASES``, ``ShiftedMatrix.bilinear``): the one
      documented object whose name ends with it, the one in ``module`` first.
    """
    import importlib

    found: list[str] = []
    if target.startswith("unibuckle_fenicsx."):
        parts = target.split(".")
        for cut in range(len(parts) - 1, 0, -1):
            try:
                obj: Any = importlib.import_module(".".join(parts[:cut]))
            except ImportError:
                continue
            try:
                for attr in parts[cut:]:
                    obj = getattr(obj, attr)
            except AttributeError:
                break
            import unibuckle_fenicsx

            found += [
                f"unibuckle_fenicsx.{n}"
                for n in public_names()
                if getattr(unibuckle_fenicsx, n) is obj
            ]
            home = getattr(obj, "__module__", None)
            qual = getattr(obj, "__qualname__", None)
            if home and qual:
                found.append(f"{home}.{qual}")
            else:  # data (a tuple, a dict): the package's one object of that name
                last = "." + parts[-1]
                found += [n for n in objects if n.endswith(last) and n.startswith("unibuckle")]
            break
    else:
        suffix = "." + target
        matches = [n for n in objects if n.endswith(suffix) or n == target]
        local = [n for n in matches if module and n.startswith(module + ".")]
        public = [n for n in matches if n.count(".") == 1]
        found += local or public or (matches if len(matches) == 1 else [])
    return [n for n in dict.fromkeys(found) if n in objects]


def _missing_reference(app: Any, env: Any, node: Any, contnode: Any) -> Any:
    """Resolve what the py domain missed: re-exported and bare names, quoted hints."""
    from docutils import nodes
    from sphinx.util.nodes import make_refnode

    if node.get("refdomain") != "py":
        return None
    target = str(node.get("reftarget", ""))
    if target == "TypeAliasForwardRef":
        # Sphinx's wrapper of a hint it could not evaluate: TypeAliasForwardRef('x.Y').
        # Drop the wrapper and its parentheses; the inner name is a reference of its own.
        parent, index = node.parent, node.parent.index(node)
        siblings = parent.children
        if index + 3 < len(siblings) and siblings[index + 1].astext() == "(":
            parent.replace(siblings[index + 1], nodes.Text(""))
            after = siblings[index + 3]
            if isinstance(after, nodes.Text) and after.astext().startswith(")"):
                parent.replace(after, nodes.Text(after.astext()[1:]))
        return nodes.inline("", "")
    bare = target.strip("'\"‘’")
    if bare != target:  # a quoted hint: the name inside the quotes
        node = node.deepcopy()
        node["reftarget"] = bare
        contnode = contnode.deepcopy()
        contnode.children = [nodes.Text(bare)]
        from sphinx.ext import intersphinx

        resolved = intersphinx.missing_reference(app, env, node, contnode)
        if resolved is not None:
            return resolved
    objects = _python_objects(env)
    for name in reference_candidates(bare, objects, node.get("py:module")):
        entry = objects[name]
        return make_refnode(
            app.builder, node["refdoc"], entry.docname, entry.node_id, contnode, name
        )
    return None
