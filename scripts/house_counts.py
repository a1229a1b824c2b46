"""The package's size and shape counts, measured from the repository (stdlib only).

Run from the repository's root: ``python scripts/house_counts.py [--list]``. It prints one
line per count with its target; ``--list`` also names the functions, classes and lines
that each count is made of. What is counted:

- functions (and methods) over 100 and over 80 lines, classes over 400 lines: from the
  ``def``/``class`` line to the last line of the body (decorators and docstring included);
- ``noqa: C901`` comments, C901 in a ``per-file-ignores`` table of pyproject.toml, and the
  ``max-complexity`` set for ruff's C901;
- the words of tuning histories in the package's code: ``Measured`` (any case), the
  arrow ``→`` and ``not adopted``;
- ``dict[str, Any]`` and ``contact is None`` / ``contact is not None`` as written in the
  package's code;
- error classes (a class deriving from an ``...Error`` or ``Exception``) outside
  ``errors.py``;
- the lines of the problem-file package (``spec/``, or ``config/`` before it);
- import circles among the package's modules (every import, inside functions and
  ``TYPE_CHECKING`` blocks too: a circle of types is a circle a reader walks);
- in ``tests/``: the files that import a test module (``test_*`` or ``conftest``; what
  tests share belongs in ``tests/support/`` or a fixture), and the package's private
  names (a leading underscore) that tests import, read from an imported module
  (``module._name``) or replace (``monkeypatch.setattr(module, "_name", ...)``).
"""

from __future__ import annotations

import ast
import re
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "unibuckle_fenicsx"
TESTS = ROOT / "tests"


def _sources() -> list[Path]:
    return sorted(PACKAGE.rglob("*.py"))


def _module(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _long_defs(
    trees: dict[Path, ast.Module],
) -> tuple[list[tuple[str, int]], list[tuple[str, int]]]:
    functions, classes = [], []
    for path, tree in trees.items():
        rel = path.relative_to(ROOT)
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                length = (node.end_lineno or node.lineno) - node.lineno + 1
                name = f"{rel}:{node.lineno} {node.name}"
                (classes if isinstance(node, ast.ClassDef) else functions).append((name, length))
    return functions, classes


def _imports(path: Path, tree: ast.Module, modules: set[str]) -> set[str]:
    """The package's modules that ``path`` imports at import time."""
    here = _module(path)
    package = here if path.name == "__init__.py" else here.rpartition(".")[0]
    out: set[str] = set()

    def visit(body: list[ast.stmt]) -> None:
        for node in body:
            if isinstance(node, ast.Import):
                for alias in node.names:
                    if alias.name in modules:
                        out.add(alias.name)
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    anchor = package.split(".")
                    anchor = anchor[: len(anchor) - node.level + 1]
                    base = ".".join([*anchor, base] if base else anchor)
                for alias in node.names:
                    full = f"{base}.{alias.name}"
                    if full in modules:
                        out.add(full)
                    elif base in modules:
                        out.add(base)
            else:
                for field in ("body", "orelse", "finalbody", "handlers"):
                    visit([n for n in getattr(node, field, []) if isinstance(n, ast.AST)])

    visit(tree.body)
    out.discard(here)
    return out


def _circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    found: list[list[str]] = []

    def connect(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                connect(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    sys.setrecursionlimit(10_000)
    for v in sorted(graph):
        if v not in index:
            connect(v)
    return found


def _waivers() -> tuple[list[str], object]:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    lint = config.get("tool", {}).get("ruff", {}).get("lint", {})
    ignores = lint.get("per-file-ignores", {})
    files = [f"{k}: {v}" for k, v in ignores.items() if any(c.startswith("C90") for c in v)]
    files += [f"ignore: {c}" for c in lint.get("ignore", []) if c.startswith("C90")]
    return files, lint.get("mccabe", {}).get("max-complexity")


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def _bindings(tree: ast.Module, where: str) -> tuple[set[str], dict[str, str], list[str]]:
    """(modules imported, local names bound to the package's modules, private imports)."""
    package = PACKAGE.name
    imported: set[str] = set()
    modules: dict[str, str] = {}
    private = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                imported.add(alias.name)
                if alias.name.split(".")[0] == package:
                    modules[alias.asname or package] = alias.name if alias.asname else package
        elif isinstance(node, ast.ImportFrom) and not node.level:
            base = node.module or ""
            imported.add(base)
            for alias in node.names if base.split(".")[0] == package else []:
                if _private(alias.name):
                    private.append(f"{where}:{node.lineno} {base}.{alias.name}")
                else:
                    modules.setdefault(alias.asname or alias.name, f"{base}.{alias.name}")
    return imported, modules, private


def _private_uses(tree: ast.Module, modules: dict[str, str], where: str) -> list[str]:
    """``module._name`` and ``setattr``-like ``(module, "_name", ...)`` on the package's modules."""
    found = []
    for node in ast.walk(tree):
        owner, name = None, ""
        if isinstance(node, ast.Attribute) and _private(node.attr):
            owner, name = node.value, node.attr
        elif isinstance(node, ast.Call) and len(node.args) >= 2:
            key = node.args[1]
            if isinstance(key, ast.Constant) and isinstance(key.value, str) and _private(key.value):
                owner, name = node.args[0], key.value
        chain = []
        while isinstance(owner, ast.Attribute):
            chain.insert(0, owner.attr)
            owner = owner.value
        if isinstance(owner, ast.Name) and owner.id in modules:
            found.append(f"{where}:{node.lineno} {'.'.join([modules[owner.id], *chain, name])}")
    return found


def _test_imports(trees: dict[Path, ast.Module]) -> tuple[list[str], list[str]]:
    """(files importing a test module, private package names used), in ``tests/``."""
    importing, private = [], []
    for path, tree in trees.items():
        where = str(path.relative_to(ROOT))
        imported, modules, names = _bindings(tree, where)
        if any(m.split(".")[-1].startswith("test_") or m == "conftest" for m in imported):
            importing.append(where)
        private += names + _private_uses(tree, modules, where)
    return importing, sorted(set(private))


def counts() -> list[tuple[str, int | object, str, list[str]]]:
    """(what, value, target, the items counted) for each count."""
    sources = _sources()
    texts = {p: p.read_text() for p in sources}
    trees = {p: ast.parse(t) for p, t in texts.items()}
    functions, classes = _long_defs(trees)

    def lines_with(pattern: str, flags: int = 0) -> list[str]:
        hits = []
        for path, text in texts.items():
            for n, line in enumerate(text.splitlines(), 1):
                hits += [f"{path.relative_to(ROOT)}:{n}"] * len(re.findall(pattern, line, flags))
        return hits

    over100 = [f"{n} ({k})" for n, k in functions if k > 100]
    over80 = [f"{n} ({k})" for n, k in functions if k > 80]
    big_classes = [f"{n} ({k})" for n, k in classes if k > 400]
    waivers, complexity = _waivers()
    errors = []
    for path, tree in trees.items():
        if path.name == "errors.py" and path.parent == PACKAGE:
            continue
        for node in ast.walk(tree):
            if isinstance(node, ast.ClassDef):
                bases = [ast.unparse(b) for b in node.bases]
                if any(b.endswith(("Error", "Exception")) for b in bases):
                    errors.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name}")
    spec_dir = PACKAGE / "spec" if (PACKAGE / "spec").is_dir() else PACKAGE / "config"
    spec_lines = sum(len(p.read_text().splitlines()) for p in spec_dir.rglob("*.py"))
    modules = {_module(p) for p in sources}
    graph = {_module(p): _imports(p, trees[p], modules) for p in sources}
    circles = _circles(graph)
    test_trees = {p: ast.parse(p.read_text()) for p in sorted(TESTS.rglob("*.py"))}
    importing, private = _test_imports(test_trees)
    return [
        ("functions over 100 lines", len(over100), "0", over100),
        ("functions over 80 lines", len(over80), "<= 3", over80),
        ("classes over 400 lines", len(big_classes), "0", big_classes),
        ("noqa: C901", len(lines_with(r"noqa:[^\n]*C901")), "0", lines_with(r"noqa:[^\n]*C901")),
        ("file-wide C901 waivers", len(waivers), "0", waivers),
        ("ruff max-complexity", complexity, "12", []),
        ("'Measured' / '→' / 'not adopted'",
         len(lines_with(r"measured|→|not adopted", re.IGNORECASE)), "<= 5",
         lines_with(r"measured|→|not adopted", re.IGNORECASE)),
        ("dict[str, Any]", len(lines_with(r"dict\[str, Any\]")), "<= 10",
         lines_with(r"dict\[str, Any\]")),
        ("contact is (not) None", len(lines_with(r"contact is (?:not )?None")), "<= 5",
         lines_with(r"contact is (?:not )?None")),
        ("error classes outside errors.py", len(errors), "0", errors),
        (f"lines of {spec_dir.name}/", spec_lines, "<= 1600", []),
        ("import circles", len(circles), "0", [" <-> ".join(c) for c in circles]),
        ("test modules importing a test module", len(importing), "0", importing),
        ("tests importing a private package name", len(private), "0", private),
    ]  # fmt: skip


def main(argv: list[str]) -> int:
    """Print the counts (``--list``: with what each is made of)."""
    for what, value, target, items in counts():
        print(f"{what:40s} {value!s:>6}   target {target}")
        if "--list" in argv:
            for item in items:
                print(f"    {item}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
