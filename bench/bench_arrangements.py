"""Ranking the arrangements carried to the fine mesh by extrapolating their loads.

The interior point's route (``unibuckle_fenicsx.algorithms.chain``) carries every
arrangement whose barrier point lies within ``carry_margin`` of the lowest from one mesh
to the next, and on the fine mesh solves each to a KKT point and keeps the lowest. On the
plates with two arrangements of nearly equal load (CCCC, the unloaded edges clamped,
shear) the fine level is then run twice. This script measures the lever of ranking them
*before* the fine mesh: at the last intermediate mesh, each arrangement's loads on the
meshes it crossed (its barrier points at ``level_mu``, h = length / nx) are extrapolated
to the fine mesh's h, and only the arrangement predicted lowest is carried. Predictors:

- ``last``: the load on the last intermediate mesh (no extrapolation);
- ``h2``: L(h) = L* + C h^2 through the last two meshes, evaluated at the fine h;
- ``fit``: L(h) = L* + C h^p through the last three (p fitted, 1 <= p <= 4; ``h2``
  when fewer meshes or the differences change sign), evaluated at the fine h.

For each plate (the thin benchmark plates of ``bench_plates.py``: 0.3 x 0.1 m,
t = 0.1 mm, obstacle over the whole face) and mesh, fresh processes run:

1. today's route, recording per level the steps / factorisations / eigen solves, each
   arrangement's loads per mesh, the three predictors' rankings, and each arrangement's
   fine-level counts and KKT load (which arrangement today's answer comes from);
2. the route with only the arrangement that ``--policy`` ranks lowest carried from the
   last intermediate mesh (if two or more reach it): its per-level counts and load
   against today's.

Counts and loads are exact; the process seconds of ``solve`` (in-process: the free run
and the route) are on a shared machine.

Usage: python bench/bench_arrangements.py [--meshes 90x30,180x60]
[--cases ssss,cs,sc,cccc,shear] [--policy last|h2|fit] [--json FILE] [--from-json FILE];
today's route alone on one plate: --worker CASE NX NY today [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import subprocess
import sys
import time
from typing import Any

from mpi4py import MPI

from _results import append_rows, print_header
from bench_plates import LENGTH, _spec

from unibuckle_fenicsx.algorithms import chain
from unibuckle_fenicsx.analysis import solve

PREDICTORS = ("last", "h2", "fit")


def predict(history: list[tuple[float, float]], h_fine: float, how: str) -> float:
    """The load at ``h_fine`` predicted from ``history`` ((h, load), coarsest first)."""
    if how == "last" or len(history) < 2:
        return history[-1][1]
    (h1, l1), (h2, l2) = history[-2], history[-1]
    if how == "fit" and len(history) >= 3:
        l0 = history[-3][1]
        d1, d2 = l0 - l1, l1 - l2
        if d1 * d2 > 0 and abs(d2) < abs(d1):
            # d1 / d2 = (h0^p - h1^p) / (h1^p - h2^p) = (h1 / h2)^p when h halves.
            p = min(max(math.log(d1 / d2) / math.log(h1 / h2), 1.0), 4.0)
            c = (l1 - l2) / (h1**p - h2**p)
            return l2 + c * (h_fine**p - h2**p)
    c = (l1 - l2) / (h1**2 - h2**2)
    return l2 + c * (h_fine**2 - h2**2)


def instrument(policy: str) -> dict[str, Any]:
    """Wrap the chain's exploration, refinement and carry; the record they fill."""
    st: dict[str, Any] = {"hist": {}, "keys": {}, "keep": [], "fine": {}, "ranked": None}
    explore0, refine0, carry0 = chain.explore, chain._refine, chain._carry

    def explore(problem, level, options, carry=True):  # type: ignore[no-untyped-def]
        explored, carried = explore0(problem, level, options, carry=carry)
        for j, a in enumerate(carried):
            key = j + 1
            st["keys"][id(a.point)] = key
            st["keep"].append(a.point)
            st["hist"][key] = [(LENGTH / level.mesh[0], a.point.load)]
        return explored, carried

    def refine(carry, point, level, options, last, mu, label, quick, newton):  # type: ignore[no-untyped-def]
        key = st["keys"].get(id(point), 0)
        n0 = len(level.links)
        cand, new = refine0(carry, point, level, options, last, mu, label, quick, newton)
        if new is not None:
            st["keys"][id(new)] = key
            st["keep"].append(new)
        if not last and new is not None and key:
            st["hist"][key].append((LENGTH / level.mesh[0], new.load))
        if last:
            links = level.links[n0:]
            st["fine"][f"{label}#{key}"] = {
                "key": key,
                "counts": [
                    sum(r.steps for r in links if r.link == "interior-point"),
                    sum(r.factorizations for r in links),
                    sum(r.eigensolves for r in links),
                ],
                "load": None if cand is None else cand.load,
                "kkt": bool(cand is not None and cand.kkt),
            }
        return cand, new

    def carry(problems, k, points, level, options, mu, label, quick, newtons, carrier):  # type: ignore[no-untyped-def]
        found, carried = carry0(
            problems, k, points, level, options, mu, label, quick, newtons, carrier
        )
        if k == len(problems) - 2 and len(carried) > 1 and label == "prolonged":
            nx_fine = problems[-1].spec.mesh.nx
            h_fine = LENGTH / nx_fine
            keys = [st["keys"][id(p)] for p in carried]
            pred = {
                how: [predict(st["hist"][key], h_fine, how) for key in keys] for how in PREDICTORS
            }
            st["ranked"] = {
                "keys": keys,
                "history": {str(key): st["hist"][key] for key in keys},
                "predicted": pred,
                "choice": {how: keys[min(range(len(keys)), key=v.__getitem__)]
                           for how, v in pred.items()},
            }  # fmt: skip
            if policy != "today":
                chosen = st["ranked"]["choice"][policy]
                carried = [p for p in carried if st["keys"][id(p)] == chosen]
        return found, carried

    chain.explore, chain._refine, chain._carry = explore, refine, carry
    return st


def worker(case: str, nx: int, ny: int, policy: str) -> dict[str, Any]:
    """One plate in this process, the route run with ``policy``; print a JSON line."""
    logging.basicConfig(level=logging.INFO, stream=sys.stderr)  # the levels as they end
    spec = _spec(case, nx, ny)
    st = instrument(policy)
    c0 = time.process_time()
    with solve(spec, MPI.COMM_WORLD) as run:
        seconds = time.process_time() - c0
        sol = run.solution
        assert sol is not None
        levels = getattr(sol.details, "levels", None) or getattr(
            sol.details, "interior_point_levels", []
        )
        row = {
            "case": case,
            "mesh": f"{nx}x{ny}",
            "policy": policy,
            "load": sol.candidate.load,
            "kkt": bool(sol.candidate.kkt),
            "contact": int(sol.candidate.active.size),
            "route": list(sol.route),
            "eigensolves": int(sol.eigensolves),
            "levels": [
                ["x".join(map(str, lv.mesh)), lv.newton_steps, lv.factorizations, lv.eigensolves]
                for lv in levels
            ],
            "ranked": st["ranked"],
            "fine_runs": st["fine"],
            "process_s": seconds,
        }
    print("RESULT " + json.dumps(row), flush=True)
    return row


def _short(levels: list[list[Any]]) -> str:
    return " · ".join(f"{m}: {s}/{f}/{e}" for m, s, f, e in levels)


def finish(row: dict[str, Any], today: dict[str, Any] | None) -> dict[str, Any]:
    """``row`` with the scalar columns of the results page (``today``: the plate's row)."""
    rk = row["ranked"]
    out = dict(row)
    out["per_level"] = _short(row["levels"])
    out["ranking"] = "" if rk is None else ", ".join(f"{h} {rk['choice'][h]}" for h in PREDICTORS)
    out["choice"] = "" if rk is None or row["policy"] == "today" else rk["choice"][row["policy"]]
    if today is not None:
        out["rel_today"] = (row["load"] - today["load"]) / today["load"]
    return out


def print_tables(rows: list[dict[str, Any]]) -> None:
    """The rankings (from today's runs) and the ranked routes against today's."""
    today = {(r["case"], r["mesh"]): r for r in rows if r["policy"] == "today"}
    print_header(
        "Arrangements reaching the fine mesh (today's route): loads per mesh (Pa), "
        "predicted fine loads, fine KKT loads, fine counts",
        ["plate", "mesh", "arrangement", "loads per mesh", "last / h2 / fit",
         "fine KKT load", "fine steps/fact./eigen"],
    )  # fmt: skip
    for (case, mesh), r in today.items():
        rk = r["ranked"]
        if rk is None:
            print(f"| {case} | {mesh} | one | | | {r['load']:.6f} | |")
            continue
        fine = {
            v["key"]: v for k, v in r["fine_runs"].items() if not k.startswith("prolonged flat")
        }
        for i, key in enumerate(rk["keys"]):
            hist = " / ".join(f"{ld:.4f}" for _, ld in rk["history"][str(key)])
            pred = " / ".join(f"{rk['predicted'][h][i]:.4f}" for h in PREDICTORS)
            fv = fine.get(key)
            fl = "—" if fv is None or fv["load"] is None else f"{fv['load']:.7f}"
            if fv is not None and not fv["kkt"]:
                fl += " (no KKT)"
            fc = "—" if fv is None else "/".join(map(str, fv["counts"]))
            print(f"| {case} | {mesh} | {key} | {hist} | {pred} | {fl} | {fc} |")
    print()
    print_header(
        "Today's route against the ranked one (per level: Newton steps / factorisations / "
        "eigen solves; load relative to today's)",
        ["plate", "mesh", "policy", "choice", "levels", "load (Pa)", "rel. to today",
         "process s"],
    )  # fmt: skip
    for r in rows:
        base = today.get((r["case"], r["mesh"]))
        rel = "" if base is None else f"{(r['load'] - base['load']) / base['load']:+.1e}"
        choice = (
            ""
            if r["ranked"] is None or r["policy"] == "today"
            else str(r["ranked"]["choice"][r["policy"]])
        )
        print(
            f"| {r['case']} | {r['mesh']} | {r['policy']} | {choice} | {_short(r['levels'])} "
            f"| {r['load']:.7f}{'' if r['kkt'] else ' (no KKT)'} | {rel} "
            f"| {r['process_s']:.1f} |"
        )


def main() -> None:
    """Run the plates (``--meshes`` x ``--cases``), today's route and the ranked one."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default="90x30,180x60")
    parser.add_argument("--cases", default="cs,sc,cccc,shear")
    parser.add_argument("--policy", default="h2", choices=PREDICTORS)
    parser.add_argument("--json", default=None)
    parser.add_argument("--from-json", default=None, help="print the tables of a results file")
    parser.add_argument("--worker", nargs=4, default=None)
    args, _ = parser.parse_known_args()
    if args.from_json:
        with open(args.from_json, encoding="utf-8") as f:
            print_tables([json.loads(line) for line in f if line.strip()])
        return
    if args.worker:
        case, nx, ny, policy = args.worker
        row = worker(case, int(nx), int(ny), policy)
        if policy == "today":  # a row of its own (the main loop writes the others)
            append_rows(args.json, [finish(row, row)])
        return
    rows = []
    for m in args.meshes.split(","):
        nx, ny = (int(v) for v in m.split("x"))
        for case in args.cases.split(","):
            for policy in ("today", args.policy):
                cmd = [sys.executable, __file__, "--worker", case, str(nx), str(ny), policy]
                out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
                line = next(ln for ln in out.splitlines() if ln.startswith("RESULT "))
                row = json.loads(line[len("RESULT ") :])
                base = next((r for r in rows if r["policy"] == "today" and
                             (r["case"], r["mesh"]) == (case, m)), row)  # fmt: skip
                row = finish(row, base)
                rows.append(row)
                append_rows(args.json, [row])
                if policy == "today" and row["ranked"] is None:
                    break  # one arrangement reaches the fine mesh: nothing to rank
    print_tables(rows)


if __name__ == "__main__":
    main()
