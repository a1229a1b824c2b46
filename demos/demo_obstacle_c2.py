# ---
# jupytext:
#   text_representation:
#     extension: .py
#     format_name: percent
# ---

# %% [markdown]
# # A smaller obstacle, ω_c2 = [−0.04, 0.04] × [−0.02, 0.02], and the paper's stopping rule
#
# The paper's plate with the obstacle restricted to the middle of ω_c1 (Ayadi, figure
# 6): "the noticeable changing of the obstacle has slightly affected the shape of the
# unilateral buckling mode as well as the buckling critical load". The comparison with
# ω_c1 is drawn by `run_all.py` from both demos' results; this demo solves ω_c2 and then
# looks at the paper's *direct method* itself on a mesh small enough to enumerate.
#
# The paper enumerates the candidate contact sets by size p = 0, 1, … and stops at the
# first size p* that yields a feasible mode, relying on its observation that
# λ(p) ≤ λ(q) for p ≤ q. That observation fails on most meshes; then the rule returns an
# admissible mode whose load is above the critical one.
#
# This demo illustrates how to:
#
# - solve case ω_c2 on the paper's mesh and on refined meshes, and draw its mode,
#   section A, contact set and convergence;
# - run the paper's enumeration with its stopping rule, the exhaustive enumeration
#   (`complete=True`) and the active-set method on the same small problem, and compare
#   their loads, certificates and eigen-solve counts.

# %%
from __future__ import annotations

import warnings

from mpi4py import MPI

from unibuckle_fenicsx import SolverSpec, paper_case, solve
from unibuckle_fenicsx.viz import study

warnings.filterwarnings("error")  # demos run warning-free

# %% [markdown]
# ## Parameters
#
# As for ω_c1: 10 × 10 … 80 × 80, the paper's 20 × 20 mesh and the refined 80 × 80 mesh
# in the results table; `--coarse` for the tests. The stopping rule is checked on the
# 8 × 8 mesh, where ω_c2 holds i = 9 constrained nodes (2^9 = 512 candidate sets).

# %%
args = study.demo_arguments("Unilateral buckling, obstacle zone c2.")
CASE = "c2"
MESHES = study.COARSE_MESHES if args.coarse else study.PAPER_MESHES
PAPER_MESH, REFINED_MESH = MESHES[1], MESHES[-1]
STOP_RULE_MESH = (8, 8)
SOLVER = SolverSpec(method="auto", complete=True, max_candidates=4096)
RTOL = 1e-8  # relative tolerance of load comparisons (SLEPc solves to eps_tol = 1e-10)
comm = MPI.COMM_WORLD
figures = args.figures / CASE

# %% [markdown]
# ## Solve on each mesh
#
# With λ(Z = I) on the refined mesh, an upper bound (see `demo_obstacle_c1.py`).

# %%
series = study.mesh_study(
    [paper_case(CASE, nx, ny, SOLVER) for nx, ny in MESHES],
    comm=comm,
    figures=figures,
    keep=[PAPER_MESH, REFINED_MESH],
    output=args.output,
    at_each=study.all_constrained_load(REFINED_MESH),
)
paper = series.at(PAPER_MESH).result
upper_bound = series.at(REFINED_MESH).extra["upper_bound_all_constrained_Pa"]

# %% [markdown]
# ## The paper's stopping rule, checked on a coarse mesh
#
# Three solves of the same 8 × 8 problem: the paper's rule (stop at p*), the exhaustive
# enumeration (exact: the minimum over all feasible sets, proven), and the active-set
# method.

# %%
variants = {
    "paper's rule (stop at p*)": SolverSpec(method="enumerate"),
    "exhaustive enumeration": SolverSpec(method="enumerate", complete=True),
    "active-set": SolverSpec(method="active-set"),
}
stop_rule = {}
for name, solver in variants.items():
    with solve(paper_case(CASE, *STOP_RULE_MESH, solver), comm) as analysis:
        r = analysis.result
    stop_rule[name] = r
    if comm.rank == 0:
        cert = r.certificate
        print(
            f"  {name:27s} lambda = {r.critical_load_Pa:.6e} Pa  |Z| = {r.contact_nodes}  "
            f"p* = {r.p_star}  KKT = {cert and cert.kkt}  proven = "
            f"{cert and cert.global_optimum_proven}  {r.eigensolves} eigen solves"
        )

# %% [markdown]
# ## Section A (y = 0), convergence, results

# %%
if comm.rank == 0:
    series.finish(
        figures,
        PAPER_MESH,
        REFINED_MESH,
        "Obstacle c2",
        upper_bound_all_constrained_Pa=upper_bound,
        stop_rule_8x8={name: r.as_dict(timings=False) for name, r in stop_rule.items()},
    )

# %% [markdown]
# ## Checks
#
# On every mesh the certificate holds and λ_free ≤ λ_c2; on the refined mesh
# λ_c2 ≤ λ(Z = I); on the paper's mesh the free mode is inadmissible (w > 0 in the
# zone), so λ_c2 > λ_free. On the 8 × 8 mesh the exhaustive enumeration is certified and
# proven, the active-set method agrees with it (relative 1e-8), and the paper's stopping
# rule can only return a load at least as large (its set is one of the feasible sets).

# %%
study.check_certified(series.results, RTOL)
assert series.results[-1].critical_load_Pa <= upper_bound * (1 + RTOL)
assert paper.ratio_to_free > 1 + RTOL, paper.ratio_to_free
exact, active = stop_rule["exhaustive enumeration"], stop_rule["active-set"]
assert exact.certificate.kkt and exact.certificate.global_optimum_proven
assert active.certificate.kkt
assert abs(active.critical_load_Pa / exact.critical_load_Pa - 1) < RTOL
paper_rule = stop_rule["paper's rule (stop at p*)"]
assert paper_rule.critical_load_Pa >= exact.critical_load_Pa * (1 - RTOL)
if comm.rank == 0:
    print("obstacle c2: all checks passed")
