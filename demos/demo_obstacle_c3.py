# ---
# jupytext:
#   text_representation:
#     extension: .py
#     format_name: percent
# ---

# %% [markdown]
# # An obstacle over the whole plate, ω_c3 = ω
#
# The paper's plate with the obstacle everywhere (Ayadi, figures 8 and 9): the mode must
# be one-signed, w ≤ 0 at every node. The free mode (two half-waves) is inadmissible; the
# critical mode is a single buckle that lifts off the obstacle between the loaded edge
# and a contact line, with the rest of the plate lying *flat* on the obstacle. On that
# flat strip both the deflection and the contact force vanish (a degenerate contact
# set): which of its nodes count as "in contact" depends on the tolerance τ, the load
# does not.
#
# This demo illustrates how to:
#
# - solve case ω_c3 on the paper's mesh and on refined meshes and draw its mode,
#   section A, contact set and convergence;
# - check that the mode is one-signed and that the load is certified.

# %%
from __future__ import annotations

import warnings

from mpi4py import MPI

from unibuckle_fenicsx import SolverSpec, paper_case
from unibuckle_fenicsx.viz import fields, study

warnings.filterwarnings("error")  # demos run warning-free

# %% [markdown]
# ## Parameters
#
# As for ω_c1: 10 × 10 … 80 × 80, with the paper's 20 × 20 and the refined 80 × 80 mesh
# in the results table; `--coarse` for the tests. (The upper bound λ(Z = I) of the
# other cases is infinite here: with every node held at w = 0 nothing can buckle.)

# %%
args = study.demo_arguments("Unilateral buckling, obstacle over the whole plate (c3).")
CASE = "c3"
MESHES = study.COARSE_MESHES if args.coarse else study.PAPER_MESHES
PAPER_MESH, REFINED_MESH = MESHES[1], MESHES[-1]
SOLVER = SolverSpec(method="auto", complete=True, max_candidates=4096)
RTOL = 1e-8  # relative tolerance of load comparisons (SLEPc solves to eps_tol = 1e-10)
comm = MPI.COMM_WORLD
figures = args.figures / CASE

# %% [markdown]
# ## Solve on each mesh
#
# On each mesh we record the largest deflection of the mode over the whole plate (it is
# scaled to max |w| = 1, so a one-signed mode has max w ≤ τ).


# %%
def largest_deflection(analysis) -> dict[str, float]:
    """Max w of the critical mode (collective)."""
    _, w = fields.nodal_deflection(analysis.problem, analysis.mode)
    return {"max_w": float(w.max())}


series = study.mesh_study(
    [paper_case(CASE, nx, ny, SOLVER) for nx, ny in MESHES],
    comm=comm,
    figures=figures,
    keep=[PAPER_MESH, REFINED_MESH],
    output=args.output,
    at_each=largest_deflection,
)
paper = series.at(PAPER_MESH).result

# %% [markdown]
# ## Section A (y = 0), convergence, results

# %%
if comm.rank == 0:
    series.finish(figures, PAPER_MESH, REFINED_MESH, "Obstacle c3 (whole plate)")

# %% [markdown]
# ## Checks
#
# On every mesh the certificate holds, λ_free ≤ λ_c3 and the mode is one-signed
# (max w ≤ τ). On the paper's mesh λ_c3 > λ_free.

# %%
study.check_certified(series.results, RTOL)
for point in series.points:
    tau = point.result.certificate["tolerance"]
    assert point.extra["max_w"] <= tau, (point.mesh, point.extra["max_w"])
assert paper.ratio_to_free > 1 + RTOL, paper.ratio_to_free
if comm.rank == 0:
    print("obstacle c3: all checks passed")
