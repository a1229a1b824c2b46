"""Numbers quoted in several places come from one source: ``docs/numbers.toml``.

The pages take them as MyST substitutions (``{{ tests }}``); the README, which GitHub
shows as it is, quotes them in words and is checked here against the file; no page
writes one of them by hand (a count of tests or a ``make`` time outside the changelog and
the history pages, which record what was true then). The test count itself is checked
against pytest's own count of the default selection.
"""

from __future__ import annotations

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from support.paths import ROOT

NUMBERS = tomllib.loads((ROOT / "docs" / "numbers.toml").read_text())
README = (ROOT / "README.md").read_text()
#: Pages that record the past (what was measured then): they keep their numbers.
DATED = ("changelog.md", "history")


def _pages() -> list[Path]:
    return [
        p
        for p in sorted((ROOT / "docs").rglob("*.md"))
        if "_build" not in p.parts
        and "_generated" not in p.parts
        and not any(part in p.parts or p.name == part for part in DATED)
    ]


def test_readme_quotes_the_numbers_of_the_file() -> None:
    assert f"{NUMBERS['tests']} tests" in README
    assert f"{NUMBERS['make_demo_time']} on 2 cores" in README
    assert f"{NUMBERS['make_test_time']} on 2 cores" in README
    assert f"{NUMBERS['make_setup_time']} on 2 cores" in README


@pytest.mark.parametrize(
    "pattern",
    [
        r"\b\d{3,4} tests\b",  # a test count
        r"make (demo|test)[^.\n]{0,80}\b\d+(\.\d+)?(–\d+(\.\d+)?)? ?min",  # a make time
    ],
)
def test_no_page_writes_a_repeated_number_by_hand(pattern: str) -> None:
    found = [
        f"{page.relative_to(ROOT)}: {match.group(0)}"
        for page in _pages()
        for match in re.finditer(pattern, page.read_text())
    ]
    assert not found, found


@pytest.mark.serial
def test_the_test_count_is_pytest_s() -> None:
    """``pytest --collect-only`` of the default selection counts ``tests`` tests."""
    proc = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:xdist"],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    match = re.search(r"^(\d+)(?:/\d+)? tests? collected", proc.stdout, flags=re.M)
    assert match is not None, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert int(match.group(1)) == NUMBERS["tests"], (
        f"pytest collects {match.group(1)} tests: update docs/numbers.toml and the README"
    )
