# ---
# jupytext:
#   text_representation:
#     extension: .py
#     format_name: percent
# ---

# %% [markdown]
# # k against the tie spacing
#
# A long plate (a/b = 4: 4 m × 1 m, t = 1 mm, t/b = 1e-3, simply supported on every
# edge, compressed on its short edges) rests on a rigid face over its whole area and is
# tied to it by one row of bilateral ties at mid-width (w = 0 there). How close must the
# ties be to raise the critical load? The sweep engine of `unibuckle sweep` varies the
# spacing `points.0.spacing` from b/4 to the plate's length (4 m: ties at the plate's ends
# only, on its supported edges, so no tie at all), with and without the face (the free
# load of every point is the bilateral plate's), on a 64 × 16 mesh. The table of
# {doc}`../verification/real_plates_restraints` is this sweep's.

# %%
from __future__ import annotations

import tempfile
from pathlib import Path

from mpi4py import MPI

from unibuckle_fenicsx.sweep import Variation, run_sweep
from unibuckle_fenicsx.viz import study
from unibuckle_fenicsx.viz.charts import plot_sweep

args = study.demo_arguments(__doc__ or "k against the tie spacing")
figures = args.figures / "ties"
comm = MPI.COMM_WORLD
NX, NY = (16, 4) if args.coarse else (64, 16)
SPACINGS = [0.25, 0.375, 0.5, 0.75, 1.0, 1.5, 2.0, 4.0]  # m; b = 1 m

# %% [markdown]
# ## The plate, as a problem file would give it

# %%
base = {
    "name": "tie spacing study",
    "plate": {"corners": [[0.0, 0.0], [4.0, 1.0]], "thickness": 1.0e-3},
    "material": {"E": 2.1e11, "nu": 0.3},
    "edges": {
        "left": {"support": "simply_supported", "normal_stress": -1.0},
        "right": {"support": "simply_supported", "normal_stress": -1.0},
    },
    "mesh": {"nx": NX, "ny": NY},
    "obstacle": {"zone": "all", "side": "above"},
    "points": [{"spacing": 1.0, "region": [[0.0, 4.0], [0.5, 0.5]], "kind": "bilateral"}],
}

# %% [markdown]
# ## The sweep

# %%
figures.mkdir(parents=True, exist_ok=True)
variation = Variation("points.0.spacing", SPACINGS)
# The sweep's JSON lines (each point's whole result) go to a scratch file: the study keeps
# the numbers of its table (results.json, below) and its chart.
scratch = Path(tempfile.mkdtemp()) if comm.rank == 0 else None
scratch = comm.bcast(scratch, root=0)
lines = run_sweep(base, [variation], scratch / "tie_spacing.jsonl", comm, progress=False)
if comm.rank == 0:
    chart = plot_sweep(
        lines,
        [variation],
        base,
        figures / "tie_spacing_study.png",
        title="a/b = 4, SSSS, t/b = 1e-3, whole-face obstacle: k against the tie spacing",
    )
    print(f"wrote {chart}")

# %% [markdown]
# ## Results and checks
#
# Every point is a KKT point at or above its free load (interlacing), and the free
# (bilateral) k of the plate without ties is that of a long SSSS plate: 4 (Timoshenko and
# Gere, section 9.2) within the mesh's error.

# %%
rows = []
for line in lines:
    k = line["buckling_coefficient_k"]
    rows.append(
        {
            "spacing_m": line["point"]["points.0.spacing"],
            "k": k,
            "k_bilateral": k * line["free_load_Pa"] / line["critical_load_Pa"],
            "kkt": bool((line.get("certificate") or {}).get("kkt")),
        }
    )
if comm.rank == 0:
    print("s/b    k (face)  k (no face)  KKT")
    for row in rows:
        print(f"{row['spacing_m']:<6g} {row['k']:8.4f}  {row['k_bilateral']:10.4f}  {row['kkt']}")
    # A record (study.write_record): the same on any machine.
    study.write_record(figures / "results.json", {"mesh": [NX, NY], "rows": rows})
    assert all(row["kkt"] for row in rows), rows
    assert all(row["k"] >= row["k_bilateral"] * (1 - 1e-8) for row in rows), rows
    none = next(row for row in rows if row["spacing_m"] == 4.0)
    if not args.coarse:
        assert abs(none["k_bilateral"] - 4.0) < 0.05, none
    print("tie spacing study: all checks passed")
