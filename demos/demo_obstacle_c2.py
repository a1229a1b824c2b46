# ---
# jupytext:
#   text_representation:
#     extension: .py
#     format_name: percent
# ---

# %% [markdown]
# # Unilateral buckling with an obstacle over ω_c2 = [−0.04, 0.04] × [−0.02, 0.02]
#
# The paper's second obstacle (Ayadi, figures 6 and 7) covers only the central part of
# the band ω_c1 of `demo_obstacle_c1.py`: the middle 40 % of the length and 40 % of the
# width. The paper reports that this "noticeable changing of the obstacle has slightly
# affected the shape of the unilateral buckling mode as well as the buckling critical
# load". Since ω_c2 ⊂ ω_c1, the c2 problem has fewer constraints and its critical load
# cannot exceed that of c1. The deflection must
# satisfy w ≤ 0 at every mesh node of the closed zone, and the critical state is the
# smallest λ with a mode u ≠ 0 in that cone C:
#
# $$ (A u, v - u) \ge \lambda\, (B u, v - u) \quad \forall v \in C. $$
#
# `solve` with method "auto" runs the paper's enumeration of contact sets when the
# 2^i candidate sets are few, and the active-set method otherwise (i = 81 constrained
# nodes on the 20 × 20 mesh). Every answer comes with a certificate: the optimality
# conditions of DESIGN.md §1 (residual off the contact set Z, mode strictly negative on
# I \ Z, obstacle only pushing on Z).
#
# This demo illustrates how to:
#
# - solve the unilateral buckling problem of the paper's case ω_c2 on the paper's mesh
#   and on refined meshes, and compare it with case ω_c1;
# - read the certificate, the contact set and the bounds of the result;
# - draw the unilateral mode with the obstacle and the contact nodes (paper figure 6),
#   the section A along y = 0 with the free mode, the c1 mode and the obstacle (paper
#   figure 7), the contact set and the convergence of λ;
# - check λ_free ≤ λ_c2 ≤ λ(Z = I), λ_c2 ≤ λ_c1 (nested zones) and the paper's claim
#   that the change from ω_c1 to ω_c2 affects the load only slightly.

# %%
from __future__ import annotations

import argparse
import json
import os
import warnings
from pathlib import Path

from mpi4py import MPI

import numpy as np

from unibuckle_fenicsx import SolverSpec, paper_case, plotting
from unibuckle_fenicsx.solver import solve, write_vtx

warnings.filterwarnings("error")  # demos run warning-free

# %% [markdown]
# ## Parameters
#
# The convergence study runs 10 × 10 … 80 × 80; 20 × 20 is the paper's mesh and
# 80 × 80 the refined mesh of the results table. `--coarse` (or
# `UNIBUCKLE_DEMO_COARSE=1`) runs tiny meshes for the test suite.
#
# Method "auto" enumerates the contact sets when there are at most `max_candidates`
# of them and runs the active-set method otherwise. We ask for the *exhaustive*
# enumeration (`complete=True`): the paper's rule of stopping at the first size p
# that gives a feasible mode can return a mode that is not critical (see
# `demo_obstacle_c2.py`). On these meshes only the tiny coarse ones enumerate.

# %%
parser = argparse.ArgumentParser(description="Unilateral buckling, obstacle zone c2.")
parser.add_argument(
    "--coarse", action="store_true", default=os.environ.get("UNIBUCKLE_DEMO_COARSE") == "1"
)
parser.add_argument("--figures", type=Path, default=Path("figures"), help="PNG directory")
parser.add_argument("--output", type=Path, default=None, help="VTX (ParaView) directory")
args, _ = parser.parse_known_args()

CASE = "c2"
MESHES = [(4, 4), (8, 8), (16, 16)] if args.coarse else [(10, 10), (20, 20), (40, 40), (80, 80)]
PAPER_MESH = MESHES[1]
REFINED_MESH = MESHES[-1]
SOLVER = SolverSpec(method="auto", complete=True, max_candidates=4096)
RTOL = 1e-8  # relative tolerance of load comparisons (SLEPc solves to eps_tol = 1e-10)
comm = MPI.COMM_WORLD
figures = args.figures / CASE

# %% [markdown]
# ## Solve on each mesh
#
# The mode left in `problem.u` is oriented away from the obstacle (w ≤ 0 in the zone)
# and scaled to max |w| = 1; `problem.free_mode` holds the mode without obstacle.
# On the refined mesh we also compute λ(Z = I), the load with *every* constrained node
# held at w = 0: an upper bound of the unilateral load (interlacing, DESIGN.md §1).

# %%
results, sections, upper_bound = [], {}, None
for nx, ny in MESHES:
    result, problem = solve(paper_case(CASE, nx, ny, SOLVER), comm)
    if comm.rank == 0:
        print(result.summary())
    results.append(result)
    label = f"{nx}x{ny}"
    if (nx, ny) in (PAPER_MESH, REFINED_MESH):
        sections[label] = (plotting.section(problem, problem.free_mode), plotting.section(problem))
        if comm.size == 1:
            plotting.plot_mode_3d(
                problem,
                figures / f"mode_{label}.png",
                contact_coordinates=result.contact_coordinates,
                title=(
                    f"obstacle c2, {label} mesh: λ = {result.critical_load_Pa / 1e6:.4f} MPa"
                    f" = {result.ratio_to_free:.3f} λ_free"
                ),
            )
    if args.output is not None:
        write_vtx(problem, result, args.output / CASE / label)
    if (nx, ny) == REFINED_MESH:
        plotting.plot_contact_set(
            problem,
            figures / "contact_set.png",
            result.contact_coordinates,
            title=f"obstacle c2: contact set on the {label} mesh",
        )
        everything = np.arange(problem.num_constrained, dtype=np.int64)
        upper_bound = problem.evaluate(everything).load  # overwrites problem.u
    problem.destroy()

# %% [markdown]
# ## Comparison with ω_c1 on the paper's mesh

# %%
result_c1, problem_c1 = solve(paper_case("c1", *PAPER_MESH, SOLVER), comm)
section_c1 = plotting.section(problem_c1)
problem_c1.destroy()
paper = results[MESHES.index(PAPER_MESH)]
change = paper.critical_load_Pa / result_c1.critical_load_Pa - 1
if comm.rank == 0:
    print(result_c1.summary())
    print(f"lambda_c2 / lambda_c1 - 1 = {change:.3e} on the {PAPER_MESH} mesh")

# %% [markdown]
# ## The paper's stopping rule, checked on a coarse mesh
#
# The paper enumerates the contact sets by size p = 0, 1, … and stops at the first
# size p* that yields a feasible mode, relying on its observation that
# λ(p) ≤ λ(q) for p ≤ q. On the 8 × 8 mesh ω_c2 holds i = 9 constrained nodes
# (2^9 = 512 sets), few enough to compare that rule with the exhaustive enumeration
# (exact: the minimum over all feasible sets) and with the active-set method.

# %%
STOP_RULE_MESH = (8, 8)
variants = {
    "paper's rule (stop at p*)": SolverSpec(method="enumerate"),
    "exhaustive enumeration": SolverSpec(method="enumerate", complete=True),
    "active-set": SolverSpec(method="active-set"),
}
stop_rule = {}
for name, solver in variants.items():
    r, prob = solve(paper_case(CASE, *STOP_RULE_MESH, solver), comm)
    prob.destroy()
    stop_rule[name] = r
    if comm.rank == 0:
        cert = r.certificate or {}
        print(
            f"  {name:27s} lambda = {r.critical_load_Pa:.6e} Pa  |Z| = {r.contact_nodes}  "
            f"p* = {r.p_star}  KKT = {cert.get('kkt')}  proven = "
            f"{cert.get('global_optimum_proven')}  {r.eigensolves} eigen solves"
        )

# %% [markdown]
# ## Section A (y = 0): free mode, unilateral modes and obstacle
#
# All modes are normalised to max |w| = 1 over the plate; the free mode's sign is
# chosen to match the unilateral mode, which lies below the obstacle (w ≤ 0). The
# plate and the zones are symmetric about x = 0, so a mode and its mirror image have
# the same load and a solver may return either: the other curves are drawn on the side
# of the paper-mesh mode (reflected if needed, and labelled so).

# %%
paper_label, refined_label = (f"{m[0]}x{m[1]}" for m in (PAPER_MESH, REFINED_MESH))
if comm.rank == 0:
    (xf, wf), (xu, wu) = sections[paper_label]
    sign = 1.0 if np.dot(wf, wu) >= 0 else -1.0
    # Mirror twins have equal loads: draw the other modes on the side of this one.
    xr, wr, flipped = plotting.mirror_to_match(xu, wu, *sections[refined_label][1])
    refined_name = f"unilateral mode, {refined_label} mesh" + (" (mirrored)" if flipped else "")
    xc, wc, flipped_c1 = plotting.mirror_to_match(xu, wu, *section_c1)
    c1_note = " (mirrored)" if flipped_c1 else ""
    zone = plotting.zone_box(paper_case(CASE))
    plotting.plot_section(
        figures / "section_A.png",
        xf,
        sign * wf,
        xu,
        wu,
        zone_x=zone[0],
        title=f"Obstacle c2, section A (y = 0), {paper_label} mesh",
        extra=[
            (xr, wr, refined_name),
            (xc, wc, f"unilateral mode of case c1, {paper_label} mesh" + c1_note),
        ],
    )
    plotting.plot_convergence(
        figures / "convergence.png",
        {
            "free": [(*r.mesh, r.free_load_Pa) for r in results],
            "c2": [(*r.mesh, r.critical_load_Pa) for r in results],
        },
        title="Obstacle c2: convergence of the critical load",
    )
    summary = {
        "case": CASE,
        "paper_mesh": list(PAPER_MESH),
        "refined_mesh": list(REFINED_MESH),
        "upper_bound_all_constrained_Pa": upper_bound,
        "c1_paper_mesh": result_c1.as_dict(),
        "stop_rule_8x8": {name: r.as_dict() for name, r in stop_rule.items()},
        "results": [r.as_dict() for r in results],
    }
    figures.mkdir(parents=True, exist_ok=True)
    (figures / "results.json").write_text(json.dumps(summary, indent=2) + "\n")

# %% [markdown]
# ## Checks
#
# On every mesh the certificate holds (KKT conditions within τ = 1e-8) and
# λ_free ≤ λ_c2; on the refined mesh λ_c2 ≤ λ(Z = I). On the paper's mesh the free
# mode is inadmissible (w > 0 in the zone), so λ_c2 > λ_free, and λ_c2 ≤ λ_c1 because
# ω_c2 ⊂ ω_c1. The paper's "slightly affected" load: we require
# |λ_c2/λ_c1 − 1| < 2 %. On the 8 × 8 mesh the exhaustive enumeration and the
# active-set method agree (relative 1e-8) and both are certified; the paper's stopping
# rule can only return a load at least as large (its set is one of the feasible sets).

# %%
for r in results:
    cert = r.certificate
    assert cert is not None and cert["kkt"], f"{r.mesh}: certificate fails: {cert}"
    assert r.critical_load_Pa >= r.free_load_Pa * (1 - RTOL), (r.mesh, r.ratio_to_free)
    assert r.lower_bound_Pa is not None and r.lower_bound_Pa >= r.free_load_Pa * (1 - RTOL)
assert upper_bound is not None and results[-1].critical_load_Pa <= upper_bound * (1 + RTOL)
assert paper.ratio_to_free > 1 + RTOL, paper.ratio_to_free
assert paper.critical_load_Pa <= result_c1.critical_load_Pa * (1 + RTOL), change
assert abs(change) < 2e-2, change
exact, active = stop_rule["exhaustive enumeration"], stop_rule["active-set"]
assert exact.certificate["kkt"] and exact.certificate["global_optimum_proven"]
assert active.certificate["kkt"]
assert abs(active.critical_load_Pa / exact.critical_load_Pa - 1) < RTOL
assert stop_rule["paper's rule (stop at p*)"].critical_load_Pa >= exact.critical_load_Pa * (
    1 - RTOL
)
if comm.rank == 0:
    print("obstacle c2: all checks passed")
