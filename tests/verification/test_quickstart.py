"""The quickstart page shows a real run, and the numbers its text quotes are that run's.

``make demo`` runs the README's first problem (``demos/plate.toml``) as a user types it and
stores the output in ``figures/quickstart/`` (``demos/run_all.py``); the page includes
that output and quotes its numbers through MyST substitutions read off it
(``docs/_ext/unibuckle_docs.py``: ``quickstart_numbers``). Checked here:

- the README's first problem file is ``demos/plate.toml``, and the commands the page and
  the README show are the ones ``make demo`` runs;
- the stored output agrees with formulas worked out independently of the program: the
  buckling coefficient k = t lambda b^2 / (pi^2 D) from the printed load and the file's
  plate, the relative slenderness sqrt(f_y / sigma_cr) (EN 1993-1-5 (4.3)), the lower
  bound of an unproven answer is the free load (interlacing), and the zone's cover lies
  between 100 % and the cover of a hole drawn as a 13-sided polygon (gmsh puts the hole's
  nodes on the circle, at most the cell size 0.01 m apart on its 0.126 m circumference:
  an inscribed polygon of at least 13 sides removes less than the circle);
- every substitution the page uses is one the generator provides;
- (``-m demo``) the command, run again, prints the stored output but for its wall time.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from support.paths import ROOT

sys.path.insert(0, str(ROOT / "docs" / "_ext"))
sys.path.insert(0, str(ROOT / "demos"))

import run_all
import unibuckle_docs

PAGE = (ROOT / "docs" / "guide" / "quickstart.md").read_text()
README = (ROOT / "README.md").read_text()
PLATE = ROOT / "demos" / "plate.toml"
OUTPUT = ROOT / "figures" / "quickstart" / "output.txt"


def _blocks(text: str, language: str) -> list[str]:
    return re.findall(rf"^```{language}\n(.*?)^```$", text, flags=re.S | re.M)


def test_readme_first_problem_is_the_quickstart_file() -> None:
    assert _blocks(README, "toml")[0] == PLATE.read_text()


def test_the_commands_shown_are_the_ones_make_demo_runs() -> None:
    shown = [
        line.split("unibuckle ", 1)[1]
        for block in _blocks(PAGE, "sh") + _blocks(README, "sh")
        for line in block.splitlines()
        if "unibuckle solve" in line
    ]
    run = {" ".join(args) for args in run_all.QUICKSTART.values()}
    for command in shown:
        # The page's first command also writes --output out/ (not kept by make demo).
        assert command.replace(" --output out/", "") in run, command


def test_stored_output_agrees_with_independent_formulas() -> None:
    numbers = unibuckle_docs.quickstart_numbers()
    problem = tomllib.loads(PLATE.read_text())
    E, nu = problem["material"]["E"], problem["material"]["nu"]
    t = problem["plate"]["thickness"]
    (x0, y0), (x1, y1) = problem["plate"]["corners"]
    b = y1 - y0
    load = float(numbers["load"])
    D = E * t**3 / (12 * (1 - nu**2))
    assert float(numbers["k"]) == pytest.approx(t * load * b**2 / (math.pi**2 * D), abs=1e-4)
    assert float(numbers["ratio"]) == pytest.approx(load / float(numbers["free"]), abs=1e-4)
    fy = problem["design"]["yield_stress"]
    assert float(numbers["slenderness"]) == pytest.approx(math.sqrt(fy / load), abs=5e-3)
    # Unproven: the verified lower bound is the free load (interlacing), the upper the load.
    assert numbers["proven"] == "no"
    assert numbers["lower"] == numbers["free"] and numbers["upper"] == numbers["load"]
    # The zone is the whole plate with its round hole; the mesh's hole is an inscribed polygon.
    hole = problem["plate"]["holes"][0]["radius"]
    area = (x1 - x0) * (y1 - y0) - math.pi * hole**2
    sides = math.ceil(2 * math.pi * hole / problem["mesh"]["size"])
    polygon = sides / 2 * hole**2 * math.sin(2 * math.pi / sides)
    largest = (area + math.pi * hole**2 - polygon) / area
    assert 100.0 <= float(numbers["cover"]) <= 100 * largest, (numbers["cover"], largest)


def test_no_substitution_inside_code() -> None:
    """MyST substitutes nothing inside a code span: a number there would print {{ ... }}."""
    spans = re.findall(r"`[^`\n]*`", PAGE)
    assert not [span for span in spans if "{{" in span], spans


def test_page_substitutions_exist() -> None:
    used = set(re.findall(r"\{\{ qs_(\w+) \}\}", PAGE))
    assert used, "the page quotes no number of the run"
    assert used <= set(unibuckle_docs.quickstart_numbers()), used - set(
        unibuckle_docs.quickstart_numbers()
    )


@pytest.mark.demo
@pytest.mark.serial
def test_the_stored_output_is_what_the_command_prints(tmp_path: Path) -> None:
    """The first command, run again: the same lines but for the wall time."""
    args = [
        a if not a.endswith(".json") else str(tmp_path / a)
        for a in run_all.QUICKSTART["output.txt"]
    ]
    unibuckle = str(Path(sys.executable).with_name("unibuckle"))
    proc = subprocess.run([unibuckle, *args], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    strip = run_all._WALL_TIME.sub
    assert strip("", proc.stdout) == strip("", OUTPUT.read_text())
