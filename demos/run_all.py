"""Run every demo, then print the results table and draw the combined convergence figure.

Usage::

    python demos/run_all.py [--coarse] [--figures DIR] [--output DIR]

Each demo (``demos/demo_*.py``) runs in its own process, writes its figures and a
``results.json`` under ``DIR/<case>/`` and ends with its own assertions. This script
collects the JSON files, prints one table (paper's mesh and refined mesh of every case),
writes it as Markdown to ``DIR/results.md`` and draws ``DIR/convergence.png``.
It exits non-zero if a demo fails. ``make demo`` runs it with the default (paper) sizes;
``--coarse`` (or ``UNIBUCKLE_DEMO_COARSE=1``) runs tiny meshes for the tests.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
DEMOS = (
    "demo_free_plate.py",
    "demo_obstacle_c1.py",
    "demo_obstacle_c2.py",
    "demo_obstacle_c3.py",
    "study_penalty.py",  # figures/penalty_*.png; no row in the table
)
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
    "eigen solves",
    "wall time (s)",
    "certificate",
)


def _row(r: dict[str, Any]) -> list[str]:
    cert = r.get("certificate") or {}
    if r["method"] == "free":
        verdict = "-"
    else:
        verdict = ("KKT" if cert.get("kkt") else "FAILS") + (
            ", proven" if cert.get("global_optimum_proven") else ""
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
        str(r["eigensolves"]),
        f"{r['wall_time_s']:.2f}",
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


def main(argv: list[str] | None = None) -> int:
    """Run the demos; return the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--coarse",
        action="store_true",
        default=os.environ.get("UNIBUCKLE_DEMO_COARSE") == "1",
        help="tiny meshes (for tests)",
    )
    parser.add_argument("--figures", type=Path, default=ROOT / "figures", help="PNG directory")
    parser.add_argument("--output", type=Path, default=None, help="also write VTX files here")
    args = parser.parse_args(argv)
    figures = args.figures.resolve()

    env = {**os.environ, "PYVISTA_OFF_SCREEN": "true", "OMP_NUM_THREADS": "1"}
    failed = []
    t_all = time.perf_counter()
    for demo in DEMOS:
        cmd = [sys.executable, str(ROOT / "demos" / demo), "--figures", str(figures)]
        if args.coarse:
            cmd.append("--coarse")
        if args.output is not None and demo.startswith("demo_"):
            cmd += ["--output", str(args.output.resolve())]
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=ROOT)
        elapsed = time.perf_counter() - t0
        status = "ok" if proc.returncode == 0 else f"FAILED ({proc.returncode})"
        print(f"{demo}: {status} in {elapsed:.1f} s", flush=True)
        if proc.returncode != 0:
            failed.append(demo)
            print(proc.stdout[-4000:], proc.stderr[-4000:], sep="\n", file=sys.stderr)

    rows, studies = [], {}
    for case in CASES:
        path = figures / case / "results.json"
        if not path.exists():
            continue
        data = json.loads(path.read_text())
        results = data["results"]
        keep = [tuple(data["paper_mesh"]), tuple(data["refined_mesh"])]
        rows += [_row(r) for r in results if tuple(r["mesh"]) in keep]
        studies[case] = [(*r["mesh"], r["critical_load_Pa"]) for r in results]
    if rows:
        text, md = _table(rows)
        print()
        print(text)
        (figures / "results.md").write_text(md + "\n")
    if studies:
        from unibuckle_fenicsx import plotting
        from unibuckle_fenicsx.materials import navier_load_mindlin

        free = json.loads((figures / "free" / "results.json").read_text())
        reference = free.get("reference_Pa") if "free" in studies else None
        if reference is None:
            reference, _ = navier_load_mindlin(1.0e9, 0.3, 0.006, 0.2, 0.1)
        path = plotting.plot_convergence(
            figures / "convergence.png",
            studies,
            reference=reference,
            reference_label="λ_RM (Navier, free plate)",
            title="Critical load under mesh refinement, all cases",
        )
        print(f"\nwrote {path.relative_to(figures.parent) if path.is_relative_to(ROOT) else path}")
    print(f"total {time.perf_counter() - t_all:.1f} s")
    if failed:
        print(f"failed demos: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
