"""Run every demo, then print the results table and draw the combined convergence figure.

Usage::

    python demos/run_all.py [--coarse] [--figures DIR] [--output DIR]

Each demo (``demos/demo_*.py``) runs in its own process, writes its figures and a
``results.json`` under ``DIR/<case>/`` and ends with its own assertions. This script
collects the JSON files, prints one table (paper's mesh and refined mesh of every case),
writes it as Markdown to ``DIR/results.md``, draws ``DIR/convergence.png`` and
``DIR/sections_A.png`` (section A of every case on the paper's mesh), and checks the
paper's comparisons between the cases: the zones are nested (c2 within c1 within c3),
so their loads are ordered, and "the noticeable changing of the obstacle [c1 to c2] has
slightly affected [...] the buckling critical load" (we require below 2 %).
It exits non-zero if a demo or a check fails. ``make demo`` runs it with the default (paper) sizes;
``--coarse`` (or ``UNIBUCKLE_DEMO_COARSE=1``) runs tiny meshes for the tests.

``DIR`` is ``output/figures`` by default (not under version control: a run leaves the
repository as it was); the figures kept in the repository (``figures/``, which the
documentation shows) are written by ``make figures`` (``--figures figures``). A run into
another folder ends by comparing its JSON records with the repository's
(:func:`compare_records`): they agree to their stored resolution on any machine, and
any difference is listed. The figures themselves may differ in pixels between machines
(README, "What may differ").
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DEMOS = (
    "demo_free_plate.py",
    "demo_obstacle_c1.py",
    "demo_obstacle_c2.py",
    "demo_obstacle_c3.py",
    "demo_garland.py",  # figures/garland/; no row in the table
    "study_penalty.py",  # figures/penalty_*.png; no row in the table
    "demo_nonlinear.py",  # figures/nonlinear/; no row in the table
    "demo_realistic.py",  # figures/realistic/; no row in the table
    "demo_column.py",  # figures/column/; no row in the table
    "study_ties.py",  # figures/ties/: k against the tie spacing; no row in the table
    "demo_sections.py",  # figures/sections/: box and tube, hollow and filled; no row
)
#: The quickstart's runs (docs/guide/quickstart.md shows their output): the README's first
#: problem file, as a user runs it, without and with --bracket; and the README's section.
QUICKSTART = {
    "output.txt": ["solve", "--config", "demos/plate.toml", "--json", "plate.json"],
    "output_bracket.txt": ["solve", "--config", "demos/plate.toml", "--bracket"],
    "box.txt": ["solve", "--config", "demos/box.toml", "--json", "box.json"],
}
CASES = ("free", "c1", "c2", "c3")
COLUMNS = (
    "case",
    "mesh",
    "lambda (Pa)",
    "lambda/lambda_free",
    "k",
    "i",
    "|Z|",
    "method",
    "certificate",
)
#: The figures kept in the repository (written by ``make figures``).
STORED = ROOT / "figures"
#: Where ``make demo`` writes (``output/`` is not under version control).
OUTPUT = ROOT / "output" / "figures"
#: Numbers of two records agree within this (relative): a record keeps eight significant
#: digits, so a number that lies at a rounding boundary may change its last one.
RECORD_RTOL = 1e-6


def _row(r: dict[str, Any]) -> list[str]:
    cert = r.get("certificate") or {}
    if r["method"] == "free":
        verdict = "-"
    else:
        verdict = ("KKT" if cert.get("kkt") else "FAILS") + (
            f", proven ({cert.get('proven_by')})" if cert.get("global_optimum_proven") else ""
        )
    return [
        r["case"],
        "x".join(str(n) for n in r["mesh"]),
        f"{r['critical_load_Pa']:.6e}",
        f"{r['ratio_to_free']:.4f}",
        f"{r['buckling_coefficient_k']:.4f}",
        str(r["constrained_nodes"]),
        str(r["contact_nodes"]),
        r["method"],
        verdict,
    ]


def _table(rows: list[list[str]]) -> tuple[str, str]:
    """Plain-text and Markdown renderings."""
    widths = [max(len(c), *(len(row[k]) for row in rows)) for k, c in enumerate(COLUMNS)]
    lines = ["  ".join(c.ljust(w) for c, w in zip(COLUMNS, widths, strict=True))]
    lines.append("  ".join("-" * w for w in widths))
    lines += ["  ".join(v.ljust(w) for v, w in zip(row, widths, strict=True)) for row in rows]
    header = [c.replace("|", "\\|") for c in COLUMNS]  # |Z| inside a Markdown cell
    md = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in COLUMNS) + "|"]
    md += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines), "\n".join(md)


def _differences(a: Any, b: Any, where: str = "") -> list[str]:
    """Where two records differ (numbers beyond :data:`RECORD_RTOL`)."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = [f"{where}.{k}: only in one" for k in sorted(set(a) ^ set(b))]
        for k in sorted(set(a) & set(b)):
            out += _differences(a[k], b[k], f"{where}.{k}")
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{where}: {len(a)} entries against {len(b)}"]
        pairs = enumerate(zip(a, b, strict=True))
        return [d for k, (x, y) in pairs for d in _differences(x, y, f"{where}[{k}]")]
    numbers = (int, float)
    if isinstance(a, numbers) and isinstance(b, numbers) and not isinstance(a, bool):
        if abs(a - b) <= RECORD_RTOL * max(abs(a), abs(b)):
            return []
    elif a == b:
        return []
    return [f"{where}: {a!r} against {b!r}"]


def compare_records(figures: Path, stored: Path = STORED) -> list[str]:
    """The JSON records of ``figures`` that differ from those kept in ``stored``."""
    out = []
    for path in sorted([*figures.rglob("*.json"), *figures.rglob("*.jsonl")]):
        kept = stored / path.relative_to(figures)
        if not kept.exists():
            continue
        if path.suffix == ".jsonl":
            new = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
            old = [json.loads(line) for line in kept.read_text().splitlines() if line.strip()]
        else:
            new, old = json.loads(path.read_text()), json.loads(kept.read_text())
        found = _differences(new, old)
        if found:
            shown = "; ".join(found[:5]) + ("; ..." if len(found) > 5 else "")
            name = kept.relative_to(ROOT) if kept.is_relative_to(ROOT) else kept
            out.append(f"{name}: {len(found)} difference(s): {shown}")
    return out


def _compare_cases(paper: dict[str, dict[str, Any]], figures: Path) -> list[str]:
    """Section A of every case on the paper's mesh, and the paper's comparisons."""
    from unibuckle_fenicsx import paper_case
    from unibuckle_fenicsx.viz import plotting
    from unibuckle_fenicsx.viz.fields import mirror_to_match, zone_box

    load = {}
    for case, data in paper.items():
        mesh = data["paper_mesh"]
        load[case] = next(r for r in data["results"] if r["mesh"] == mesh)["critical_load_Pa"]
    x1, w1 = (np.asarray(paper["c1"]["section_A"][k]) for k in ("x", "w"))
    extra = []
    for case in ("c2", "c3"):
        x, w, flipped = mirror_to_match(
            x1, w1, paper[case]["section_A"]["x"], paper[case]["section_A"]["w"]
        )
        extra.append((x, w, f"unilateral mode, {case}" + (" (mirrored)" if flipped else "")))
    xf, wf = (np.asarray(paper["free"]["section_A"][k]) for k in ("x", "w"))
    sign = 1.0 if np.dot(np.interp(x1, xf, wf), w1) >= 0 else -1.0
    mesh = "x".join(str(n) for n in paper["c1"]["paper_mesh"])
    plotting.plot_section(
        figures / "sections_A.png",
        xf,
        sign * wf,
        x1,
        w1,
        zone_x=zone_box(paper_case("c1"))[0],  # type: ignore[index]
        title=f"Section A (y = 0) of every case, {mesh} mesh (obstacle of c1, c2 drawn)",
        extra=extra,
        labels=("free mode (no obstacle)", "unilateral mode, c1"),
    )
    change = load["c2"] / load["c1"] - 1
    print(
        f"\npaper's mesh: lambda_c2/lambda_c1 - 1 = {change:.2e}, "
        f"lambda_c3/lambda_c1 - 1 = {load['c3'] / load['c1'] - 1:.2e}"
    )
    rtol = 1e-7  # the records' eight digits
    checks = {
        "free <= c2 <= c1 <= c3 (nested zones)": load["free"] <= load["c2"] * (1 + rtol)
        and load["c2"] <= load["c1"] * (1 + rtol)
        and load["c1"] <= load["c3"] * (1 + rtol),
        "c1 -> c2 changes the load slightly (< 2 %)": abs(change) < 2e-2,
    }
    for name, ok in checks.items():
        print(f"check {name}: {'ok' if ok else 'FAILED'}")
    return [name for name, ok in checks.items() if not ok]


#: The wall time of a summary line: the one part of the output that changes between runs.
_WALL_TIME = re.compile(r"eigensolves, [0-9.]+ s")
#: Any time in seconds a demo prints ("12.3 s", "in 4 s"), and a table's last column of
#: two-decimal seconds (demo_nonlinear's "time (s)").
_SECONDS = re.compile(r"\b[0-9]+(\.[0-9]+)? ?s\b|  +[0-9]+\.[0-9]{2}$", re.M)


def keep_output(path: Path, text: str) -> bool:
    """Store a demo's printed output at ``path`` (its page shows it); True if written.

    An output that differs from the stored one only in its times is not rewritten, so
    that ``make demo`` leaves unchanged answers untouched.
    """
    old = path.read_text() if path.exists() else None
    if old is not None and _SECONDS.sub("", old) == _SECONDS.sub("", text):
        return False
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return True


def quickstart(figures: Path, env: dict[str, str]) -> list[str]:
    """Run the quickstart's commands and keep their output in ``figures/quickstart/``.

    The commands run as a user types them (the ``unibuckle`` of this Python, in the
    repository's root; the JSON goes to a scratch directory). A stored output is rewritten
    only when more than its times changed (:func:`keep_output`). Returns the commands
    that failed.
    """
    out = figures / "quickstart"
    out.mkdir(parents=True, exist_ok=True)
    unibuckle = str(Path(sys.executable).with_name("unibuckle"))
    failed = []
    with tempfile.TemporaryDirectory() as scratch:
        for name, args in QUICKSTART.items():
            argv = [unibuckle] + [str(Path(scratch, a)) if a.endswith(".json") else a for a in args]
            proc = subprocess.run(argv, capture_output=True, text=True, env=env, cwd=ROOT)
            if proc.returncode != 0:
                failed.append(" ".join(["unibuckle", *args]))
                print(proc.stdout, proc.stderr, sep="\n", file=sys.stderr)
                continue
            keep_output(out / name, proc.stdout)
            print(f"unibuckle {' '.join(args)}:\n{proc.stdout}", flush=True)
    return failed


def parser() -> argparse.ArgumentParser:
    """The command line (``--figures`` defaults to :data:`OUTPUT`)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--coarse",
        action="store_true",
        default=os.environ.get("UNIBUCKLE_DEMO_COARSE") == "1",
        help="tiny meshes (for tests)",
    )
    parser.add_argument(
        "--figures",
        type=Path,
        default=OUTPUT,
        help="the figures' and records' directory (make figures: figures, the repository's)",
    )
    parser.add_argument("--output", type=Path, default=None, help="also write VTX files here")
    return parser


def run_demo(demo: str, args: argparse.Namespace, figures: Path, env: dict[str, str]) -> bool:
    """Run one demo, keep its output (a full run), say how it went; whether it succeeded."""
    # Relative to the repository when inside it: the outputs print figures/... paths.
    where = figures.relative_to(ROOT) if figures.is_relative_to(ROOT) else figures
    cmd = [sys.executable, str(ROOT / "demos" / demo), "--figures", str(where)]
    if args.coarse:
        cmd.append("--coarse")
    if args.output is not None and demo.startswith("demo_"):
        cmd += ["--output", str(args.output.resolve())]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=ROOT)
    elapsed = time.perf_counter() - t0
    status = "ok" if proc.returncode == 0 else f"FAILED ({proc.returncode})"
    print(f"{demo}: {status} in {elapsed:.1f} s", flush=True)
    if proc.returncode == 0 and not args.coarse:
        keep_output(figures / "stdout" / demo.replace(".py", ".txt"), proc.stdout)
    if proc.returncode != 0:
        print(proc.stdout[-4000:], proc.stderr[-4000:], sep="\n", file=sys.stderr)
    return proc.returncode == 0


def main(argv: list[str] | None = None) -> int:
    """Run the demos; return the exit status."""
    args = parser().parse_args(argv)
    figures = args.figures.resolve()

    env = {**os.environ, "PYVISTA_OFF_SCREEN": "true", "OMP_NUM_THREADS": "1"}
    failed = []
    t_all = time.perf_counter()
    if not args.coarse:  # the quickstart's plate is the README's, as it is
        t0 = time.perf_counter()
        bad = quickstart(figures, env)
        print(f"quickstart: {'ok' if not bad else 'FAILED'} in {time.perf_counter() - t0:.1f} s")
        failed += bad
    failed += [demo for demo in DEMOS if not run_demo(demo, args, figures, env)]

    rows, studies, paper = [], {}, {}
    for case in CASES:
        path = figures / case / "results.json"
        if not path.exists():
            continue
        data = json.loads(path.read_text())
        results = data["results"]
        keep = [tuple(data["paper_mesh"]), tuple(data["refined_mesh"])]
        rows += [_row(r) for r in results if tuple(r["mesh"]) in keep]
        studies[case] = [(*r["mesh"], r["critical_load_Pa"]) for r in results]
        paper[case] = data
    if rows:
        text, md = _table(rows)
        print()
        print(text)
        (figures / "results.md").write_text(md + "\n")
    if studies:
        from unibuckle_fenicsx.viz import plotting

        # The Navier load demo_free_plate.py worked out (its results.json).
        reference = paper["free"].get("reference_Pa") if "free" in paper else None
        path = plotting.plot_convergence(
            figures / "convergence.png",
            studies,
            reference=reference,
            reference_label="λ_RM (Navier, free plate)",
            title="Critical load under mesh refinement, all cases",
        )
        print(f"\nwrote {path.relative_to(figures.parent) if path.is_relative_to(ROOT) else path}")
    if set(paper) == set(CASES):
        failed += _compare_cases(paper, figures)
    if figures != STORED.resolve() and not args.coarse:
        differ = compare_records(figures)
        print(
            "\nrecords against the repository's figures/: "
            + ("the same" if not differ else "\n  ".join(["differ:", *differ]))
        )
    print(f"total {time.perf_counter() - t_all:.1f} s")
    if failed:
        print(f"failed demos: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
