# ---
# jupytext:
#   text_representation:
#     extension: .py
#     format_name: percent
# ---

# %% [markdown]
# # Unilateral buckling with an obstacle over the whole plate, ω_c3 = ω̄
#
# The paper's third obstacle (Ayadi, figures 8 and 9) covers the whole plate: the
# mode must lie on one side, w ≤ 0 everywhere. The free mode (two half-waves of
# opposite signs) is inadmissible, and so is any sign change. Since ω_c1 ⊂ ω_c3, the
# critical load is at least that of case c1 (`demo_obstacle_c1.py`). The deflection must
# satisfy w ≤ 0 at every mesh node of the closed zone, and the critical state is the
# smallest λ with a mode u ≠ 0 in that cone C:
#
# $$ (A u, v - u) \ge \lambda\, (B u, v - u) \quad \forall v \in C. $$
#
# `solve` with method "auto" runs the paper's enumeration of contact sets when the
# 2^i candidate sets are few, and the active-set method otherwise (i = 361 constrained
# nodes on the 20 × 20 mesh, every interior node). Every answer comes with a
# certificate: the optimality conditions of DESIGN.md §1 (residual off the contact set
# Z, mode strictly negative on I \ Z, obstacle only pushing on Z).
#
# This demo illustrates how to:
#
# - solve the unilateral buckling problem with the whole plate as contact zone on the
#   paper's mesh and on refined meshes, and compare it with case ω_c1;
# - read the certificate, the contact set and the bounds of the result;
# - draw the unilateral mode with the obstacle and the contact nodes (paper figure 8),
#   the section A along y = 0 with the free mode, the c1 mode and the obstacle (paper
#   figure 9), the contact set and the convergence of λ;
# - check λ_free < λ_c1 ≤ λ_c3 (nested zones) and that the mode is one-signed.

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
parser = argparse.ArgumentParser(
    description="Unilateral buckling, obstacle over the whole plate (c3)."
)
parser.add_argument(
    "--coarse", action="store_true", default=os.environ.get("UNIBUCKLE_DEMO_COARSE") == "1"
)
parser.add_argument("--figures", type=Path, default=Path("figures"), help="PNG directory")
parser.add_argument("--output", type=Path, default=None, help="VTX (ParaView) directory")
args, _ = parser.parse_known_args()

CASE = "c3"
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
# (The upper bound λ(Z = I) of the other cases is infinite here: with every node held
# at w = 0 nothing can buckle.)

# %%
results, sections, max_w = [], {}, np.inf
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
                    f"obstacle c3 (whole plate), {label} mesh: "
                    f"λ = {result.critical_load_Pa / 1e6:.4f} MPa"
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
            title=f"obstacle c3: contact set on the {label} mesh",
        )
        xy, w = plotting.nodal_deflection(problem)
        max_w = float(w.max())  # the mode is scaled to max |w| = 1
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
    print(f"lambda_c3 / lambda_c1 - 1 = {change:.3e} on the {PAPER_MESH} mesh")

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
        title=f"Obstacle c3 (whole plate), section A (y = 0), {paper_label} mesh",
        extra=[
            (xr, wr, refined_name),
            (xc, wc, f"unilateral mode of case c1, {paper_label} mesh" + c1_note),
        ],
    )
    plotting.plot_convergence(
        figures / "convergence.png",
        {
            "free": [(*r.mesh, r.free_load_Pa) for r in results],
            "c3": [(*r.mesh, r.critical_load_Pa) for r in results],
        },
        title="Obstacle c3 (whole plate): convergence of the critical load",
    )
    summary = {
        "case": CASE,
        "paper_mesh": list(PAPER_MESH),
        "refined_mesh": list(REFINED_MESH),
        "c1_paper_mesh": result_c1.as_dict(),
        "results": [r.as_dict() for r in results],
    }
    figures.mkdir(parents=True, exist_ok=True)
    (figures / "results.json").write_text(json.dumps(summary, indent=2) + "\n")

# %% [markdown]
# ## Checks
#
# On every mesh the certificate holds (KKT conditions within τ = 1e-8) and
# λ_free ≤ λ_c3. On the refined mesh the mode is one-signed: max w ≤ τ (it is scaled
# to max |w| = 1). On the paper's mesh λ_c3 > λ_free, and λ_c3 ≥ λ_c1 because
# ω_c1 ⊂ ω_c3.

# %%
for r in results:
    cert = r.certificate
    assert cert is not None and cert["kkt"], f"{r.mesh}: certificate fails: {cert}"
    assert r.critical_load_Pa >= r.free_load_Pa * (1 - RTOL), (r.mesh, r.ratio_to_free)
    assert r.lower_bound_Pa is not None and r.lower_bound_Pa >= r.free_load_Pa * (1 - RTOL)
assert max_w <= results[-1].certificate["tolerance"], max_w
assert paper.ratio_to_free > 1 + RTOL, paper.ratio_to_free
assert paper.critical_load_Pa >= result_c1.critical_load_Pa * (1 - RTOL), change
if comm.rank == 0:
    print("obstacle c3: all checks passed")
