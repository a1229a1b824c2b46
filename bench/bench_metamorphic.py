r"""Metamorphic sweep: random small plates and the relations between their answers.

The relations, and why each must hold: ``tests/support/metamorphic.py``. Problem n is
drawn from ``np.random.default_rng([seed, n])`` and checked with its relatives (other
methods, the mirrored plate, the scaled load, a larger zone, edge springs; every
``--full-every``-th also E scaled and six tensionless foundations). A violated relation
means a wrong answer somewhere.

With ``--foundations``: long plates, each with a rigid obstacle and eleven tensionless
foundations from K = 0.3 to 1e9 (``--dense``: each also against the minimum over every
spring set when i <= 12).

Run: ``python bench/bench_metamorphic.py --count 60 --seed 1 --out metamorphic.jsonl``
(one JSON line per problem: its data, loads and violations); ``--base-only`` solves each
problem alone and writes its load (run it under ``mpiexec -n 2`` and without to compare
the ranks).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import traceback
from pathlib import Path

from mpi4py import MPI

import numpy as np

from unibuckle_fenicsx.errors import UnibuckleError

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from support.metamorphic import (
    check_foundations,
    check_problem,
    foundation_plate,
    random_problem,
    run,
)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--count", type=int, default=20)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--start", type=int, default=0)
    p.add_argument("--full-every", type=int, default=3, help="foundations and E every n-th")
    p.add_argument("--base-only", action="store_true", help="each problem alone, its load")
    p.add_argument("--foundations", action="store_true", help="long plates, eleven foundations")
    p.add_argument("--dense", action="store_true", help="foundations: the dense minimum too")
    p.add_argument("--out", type=Path)
    args = p.parse_args(argv)
    root = MPI.COMM_WORLD.rank == 0
    counts: dict[str, int] = {}
    stream = np.random.default_rng(args.seed)
    for n in range(args.start + args.count):
        if args.foundations:
            rng, data = stream, foundation_plate(stream, f"mf{args.seed}_{n}")
            data["_load"] = "foundations"
        else:
            rng = np.random.default_rng([args.seed, n])
            data = random_problem(rng, f"mm{args.seed}_{n}")
        if n < args.start:
            continue
        t0 = time.perf_counter()
        if args.foundations:
            try:
                rec, viol = check_foundations(data, args.dense)
            except UnibuckleError as exc:  # no load on so coarse a mesh: no relation
                rec, viol = {"name": data["name"], "refused": str(exc)[:200]}, []
        elif args.base_only:
            rec, viol = {"name": data["name"], "auto": run(data)}, []
        else:
            try:
                rec, viol = check_problem(data, rng, full=(n % args.full_every == 0))
            except Exception:  # a crash is a finding too
                trace = traceback.format_exc()[-800:]
                rec, viol = {"name": data["name"]}, [{"relation": "crash", "trace": trace}]
        rec.update(data=data, violations=viol, seconds=time.perf_counter() - t0)
        for v in viol:
            counts[v["relation"]] = counts.get(v["relation"], 0) + 1
        if root:
            print(
                f"{data['name']} {data['_load']} {rec.get('auto', {}).get('load')} "
                f"{rec['seconds']:.1f}s {[v['relation'] for v in viol]}",
                flush=True,
            )
            if args.out:
                with args.out.open("a") as f:
                    f.write(json.dumps(rec, default=str) + "\n")
    if root:
        print(json.dumps({"tried": args.count, "violations": counts}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
