"""The documentation's generated pages say what the program does.

- The TOML reference (``docs/_ext/unibuckle_docs.py``, generated when the site is built)
  lists every key the loader accepts: those of ``unibuckle_fenicsx.spec.accepted_keys``
  where the package has it, and, independently of the page's own source, every key of
  the bad-input family's base files (which hold every key of the schema); and each key
  it lists is one the loader accepts (no "unknown key" error when a file gives it).
- Every TOML block of the guide's "Describing a plate" is a problem file the loader
  accepts.
- The command-line page holds each subcommand's ``--help``, the benchmark page the rows
  of ``bench/results/plates.jsonl``, and every page the site promises exists.

No Sphinx needed: the page generators are plain functions (``make docs`` builds the site).
"""

from __future__ import annotations

import re
import sys
import tomllib
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import pytest

from support.paths import ROOT
from support.problem_files import BASES
from unibuckle_fenicsx import spec
from unibuckle_fenicsx.spec import problem_from_dict, section_from_dict

sys.path.insert(0, str(ROOT / "docs" / "_ext"))

import unibuckle_docs

PAGES = [
    "index.md",
    "guide/quickstart.md",
    "guide/installing.md",
    "guide/plate.md",
    "guide/cli.md",
    "guide/python.md",
    "guide/mpi.md",
    "guide/sweeps.md",
    "guide/results.md",
    "guide/errors.md",
    "reference/schema.md",
    "reference/api.rst",
    "methods/problem.md",
    "methods/enumeration.md",
    "methods/interior_point.md",
    "methods/active_set.md",
    "methods/penalty.md",
    "methods/foundations.md",
    "methods/certificates.md",
    "methods/nonlinear.md",
    "methods/bibliography.md",
    "demos/index.md",
    "verification/index.md",
    "verification/benchmarks.md",
    "verification/interior_point_route.md",
    "verification/interior_point_saddles.md",
    "verification/interior_point_costs.md",
    "verification/floor.md",
    "changelog.md",
    "history/2026-11-27.md",
]


def _dotted(data: Mapping[str, Any], prefix: str = "") -> Iterator[str]:
    """The dotted keys of a problem mapping, in the reference's notation."""
    for key, value in data.items():
        path = f"{prefix}.{key}" if prefix else key
        if prefix == "edges":
            path = "edges.<name>"
        if isinstance(value, Mapping):
            yield from _dotted(value, path)
        elif isinstance(value, list) and value and all(isinstance(v, Mapping) for v in value):
            for item in value:
                yield from _dotted(item, f"{path}[]")
        else:
            yield path


def _edge_name(key: str) -> str:
    """An edge table's name as the placeholder ``<name>`` (notations may differ)."""
    return re.sub(r"^edges\.[^.]+\.", "edges.<name>.", key)


def _listed() -> set[str]:
    page = unibuckle_docs.schema_page()
    return {_edge_name(key) for key in re.findall(r"^\| `([^`]+)` \|", page, flags=re.M)}


def test_reference_lists_every_accepted_key() -> None:
    listed = _listed()
    keys, _ = unibuckle_docs.accepted_keys()
    assert {_edge_name(key) for key in keys} <= listed
    if hasattr(spec, "accepted_keys"):
        assert {_edge_name(key) for key in spec.accepted_keys()} <= listed


def test_reference_lists_every_key_of_the_bad_input_bases() -> None:
    # The bad-input family's base files hold every key of the schema (an independent,
    # hand-written list): each of their keys must be in the reference.
    listed = _listed()
    for name, base in BASES.items():
        missing = set(_dotted(base)) - listed
        assert not missing, f"{name}: {sorted(missing)}"


def _with_key(dotted: str) -> dict[str, Any]:
    """A minimal problem mapping that gives the key ``dotted`` (value: a string)."""
    parts = dotted.replace("<name>", "left").split(".")
    data: dict[str, Any] = {}
    node: Any = data
    for part in parts[:-1]:
        listed = part.endswith("[]")
        part = part.removesuffix("[]")
        child: dict[str, Any] = {}
        node[part] = [child] if listed else child
        node = child
    node[parts[-1]] = "?"
    return data


def test_every_listed_key_is_accepted_by_the_loader() -> None:
    """By the plate's loader, or by the section's (a section's key in a plate's file is refused)."""

    def section(data: dict[str, Any]) -> Any:
        return section_from_dict({"section": {}, **data})

    for key in sorted(_listed()):
        refusals = []
        for load in (problem_from_dict, section):
            try:
                load(_with_key(key))
            except ValueError as err:
                text = str(err)
                refusals.append("unknown key" in text or "a section's" in text)
            else:
                refusals.append(False)
        assert not all(refusals), key


def test_guide_toml_blocks_load() -> None:
    text = (ROOT / "docs" / "guide" / "plate.md").read_text()
    blocks = re.findall(r"^```toml\n(.*?)^```$", text, flags=re.S | re.M)
    assert len(blocks) >= 12  # a listing per table, and the examples
    for block in blocks:
        problem_from_dict(tomllib.loads(block))


def test_cli_pages_hold_every_subcommand() -> None:
    pages = unibuckle_docs.cli_pages()
    for name in ("solve", "sweep", "nonlinear"):
        assert f"usage: unibuckle {name}" in pages[f"cli_{name}.md"]
    assert "--config" in pages["cli_solve.md"]


def test_bench_page_renders_its_results_file() -> None:
    path = ROOT / "bench" / "results" / "plates.jsonl"
    rows = unibuckle_docs.bench_rows(path)
    page = unibuckle_docs.bench_page(path)
    assert "python bench/bench_plates.py --meshes" in page
    assert len(re.findall(r"^\| ", page, flags=re.M)) == len(rows) + 1  # and the header


@pytest.mark.parametrize("name", ["free", "free_estimates", "orderings"])
def test_the_floor_pages_name_their_commands(name: str) -> None:
    """The floor's tables (verification/floor) name the command that wrote each row."""
    path = ROOT / "bench" / "results" / f"{name}.jsonl"
    rows = unibuckle_docs.bench_rows(path)
    page = unibuckle_docs.bench_page(path)
    assert f"python bench/bench_{name}.py --" in page and "see bench/" not in page
    assert len(re.findall(r"^\| ", page, flags=re.M)) == len(rows) + 1  # and the header


def test_demo_pages_render_every_demo_with_its_figures() -> None:
    pages = unibuckle_docs.demo_pages()
    for name, (script, figures) in unibuckle_docs.DEMOS.items():
        assert (ROOT / "demos" / script).exists()
        for figure in figures:
            assert (ROOT / "figures" / figure).exists(), figure
            assert f"../../figures/{figure}" in pages[f"demo_{name}.md"]


@pytest.mark.parametrize("page", PAGES)
def test_page_exists(page: str) -> None:
    assert (ROOT / "docs" / page).exists()


def test_escape_bars_leaves_literals_and_math() -> None:
    line = "max |w| on Z, :math:`|w|`, ``|Z|`` and |Z| = 3"
    assert unibuckle_docs.escape_bars(line) == (
        r"max \|w\| on Z, :math:`|w|`, ``|Z|`` and \|Z\| = 3"
    )


def test_schema_rows_walk_a_json_schema() -> None:
    # The path the reference takes once the package has json_schema(): a small schema in
    # the shapes JSON Schema libraries write ($defs and $ref, anyOf with null, arrays of
    # objects, tables with free names); the expected rows are read off it by hand.
    schema = {
        "type": "object",
        "properties": {
            "name": {"type": "string", "default": "plate", "description": "Label."},
            "plate": {"$ref": "#/$defs/Plate"},
            "edges": {"type": "object", "additionalProperties": {"$ref": "#/$defs/Edge"}},
            "obstacle": {"anyOf": [{"$ref": "#/$defs/Obstacle"}, {"type": "null"}]},
        },
        "$defs": {
            "Plate": {
                "type": "object",
                "properties": {
                    "thickness": {"type": "number", "exclusiveMinimum": 0},
                    "holes": {"type": "array", "items": {"$ref": "#/$defs/Hole"}},
                },
            },
            "Hole": {"type": "object", "properties": {"radius": {"type": "number"}}},
            "Edge": {
                "type": "object",
                "properties": {"support": {"enum": ["clamped", "free"]}},
            },
            "Obstacle": {
                "type": "object",
                "properties": {"zone": {"anyOf": [{"const": "all"}, {"type": "array"}]}},
            },
        },
    }
    rows = dict(unibuckle_docs.schema_rows(schema))
    assert list(rows) == [
        "name",
        "plate.thickness",
        "plate.holes[].radius",
        "edges.<name>.support",
        "obstacle.zone",
    ]
    assert unibuckle_docs._range(rows["plate.thickness"]) == "> 0"
    assert unibuckle_docs._type(rows["edges.<name>.support"], schema) == '`"clamped"` \\| `"free"`'
    assert unibuckle_docs._type(rows["obstacle.zone"], schema) == '`"all"` or array'


def test_schema_page_from_a_json_schema(monkeypatch: pytest.MonkeyPatch) -> None:
    # With json_schema() and accepted_keys() in the package the page lists the accepted
    # keys with the schema's types, ranges, defaults and descriptions.
    schema = {
        "type": "object",
        "properties": {
            "mesh": {
                "type": "object",
                "properties": {
                    "nx": {"type": "integer", "minimum": 2, "default": 20, "description": "Cells."}
                },
            }
        },
    }
    monkeypatch.setattr(spec, "json_schema", lambda: schema, raising=False)
    monkeypatch.setattr(spec, "accepted_keys", lambda: ["mesh.nx"], raising=False)
    page = unibuckle_docs.schema_page()
    assert "| `mesh.nx` | integer | ≥ 2 | `20` | Cells. |" in page
    assert "1 keys." in page


def test_schema_page_gives_a_sections_own_words_for_the_keys_it_shares() -> None:
    # mesh.size means a rectangle's cell size on a plate, a target cell size on a
    # section (spec.section.SectionMeshSpec): the row names both.
    page = unibuckle_docs.schema_page()
    row = next(line for line in page.splitlines() if line.startswith("| `mesh.size` |"))
    assert "A rectangle's nx and ny" in row
    assert "A section's file: Target cell size (m), > 0 and below the section's length" in row


def _words(page: Path) -> int:
    return len(page.read_text().split())


def test_no_page_is_over_3000_words() -> None:
    """A page a reader can finish: none over 3 000 words, the changelog within 2 500.

    Measurements and tuning histories live on the verification pages, the dated record of
    the work on the history pages (both split to stay within the limit).
    """
    docs = ROOT / "docs"
    pages = [p for p in docs.rglob("*.md") if not {"_build", "_generated"} & set(p.parts)]
    long = {str(p.relative_to(docs)): _words(p) for p in pages if _words(p) > 3000}
    assert not long, long
    assert _words(docs / "changelog.md") <= 2500
