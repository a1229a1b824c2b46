# ---
# jupytext:
#   text_representation:
#     extension: .py
#     format_name: percent
# ---

# %% [markdown]
# # Validating the critical state by a nonlinear analysis: the imperfect plate against the obstacle
#
# The unilateral critical load λ_c is the smallest load of a *linear* eigenproblem over a
# cone. An engineer validates a buckling load otherwise: by a geometrically nonlinear
# analysis of the imperfect structure, loaded step by step (in a commercial code: contact
# plus a path-following method), whose deflection stays small up to a *knee* and then
# grows quickly. This demo runs that analysis with the von Kármán plate of
# `unibuckle_fenicsx.nonlinear`: membrane strain sym∇u + ½(∇w⊗∇w − ∇w₀⊗∇w₀) from a
# stress-free imperfect shape w₀, Reissner–Mindlin bending on sym∇(θ − θ₀), the same
# MITC shear, edge supports and edge loads as the linear model, and the obstacle
# (w ≤ 0 at the zone's nodes) as variable bounds of PETSc's VI Newton method.
#
# The imperfection is δ t times the critical mode of the linear problem (the unilateral
# mode with the obstacle, the free mode without). Two estimates of the buckling load
# are read off each path, without the linear eigenvalue:
#
# - Southwell's (R. V. Southwell, Proc. R. Soc. A 135, 1932): below the knee
#   δ_w/λ = a/λ_S + δ_w/λ_S, with δ_w = max|w| − δ t the additional deflection;
# - the load of the steepest rise of max|w| (the inflection).
#
# This demo illustrates how to:
#
# - solve the linear problem once and trace the nonlinear paths of the plate with and
#   without the obstacle for δ/t = 1e-2, 1e-3, 1e-4 (`solve_nonlinear`);
# - draw max|w|/t against λ with the linear free and unilateral loads marked, the
#   Southwell plot, and the deformed plate past the critical load with its contact nodes;
# - check that with the obstacle the knee converges to the unilateral λ_c (not to
#   λ_free) as δ → 0, and that the last state satisfies the contact conditions.

# %%
from __future__ import annotations

import time
import warnings

from mpi4py import MPI

import numpy as np

from unibuckle_fenicsx import paper_case, solve
from unibuckle_fenicsx.nonlinear import NonlinearOptions, solve_nonlinear, southwell_window
from unibuckle_fenicsx.viz import fields, plotting, study
from unibuckle_fenicsx.viz.fields import zone_box

warnings.filterwarnings("error")  # demos run warning-free

# %% [markdown]
# ## Parameters
#
# The paper's plate with the obstacle ω_c1 on the paper's 20 × 20 mesh (`--coarse`:
# 8 × 8). The paths run to 1.2 λ_ref, λ_ref the linear load of the same mesh (the
# unilateral λ_c with the obstacle, λ_free without), with load steps of at most
# 5 % of λ_ref and at most 10 % growth of max|w| per step. The claims are checked within
# 1 % at δ/t = 1e-3.

# %%
args = study.demo_arguments("Nonlinear validation of the critical state (von Karman plate).")
MESH = (8, 8) if args.coarse else (20, 20)
DELTAS = (1e-2, 1e-3, 1e-4)
RTOL = 1e-2  # the knee against the linear load, at delta/t <= 1e-3
comm = MPI.COMM_WORLD
figures = args.figures / "nonlinear"
spec = paper_case("c1", *MESH)
t = spec.plate.thickness

# %% [markdown]
# ## The linear reference, then the paths
#
# One linear solve gives both references and both imperfection shapes: the unilateral
# mode (with the obstacle) and the free mode (without it). Each nonlinear solve reuses
# it (`linear=`).

# %%
t0 = time.perf_counter()
rows = []
curves = []
southwell_series = []
with solve(spec, comm) as linear:
    lam_c = linear.result.critical_load_Pa
    lam_free = linear.result.free_load_Pa
    for obstacle in (True, False):
        for delta in DELTAS:
            options = NonlinearOptions(imperfection=delta, obstacle=obstacle)
            with solve_nonlinear(spec, options, comm, linear=linear) as analysis:
                r = analysis.result
                rows.append(r)
                loads = np.array([q["load_Pa"] for q in r.path])
                max_w = np.array([q["max_w_m"] for q in r.path])
                style = "-" if obstacle else "--"
                color = {1e-2: "tab:green", 1e-3: "tab:red", 1e-4: "tab:purple"}[delta]
                where = "obstacle" if obstacle else "no obstacle"
                curves.append((loads, max_w, f"δ/t = {delta:g}, {where}", color, style))
                if delta == 1e-3 and r.southwell_load_Pa is not None:
                    assert r.inflection_load_Pa is not None
                    mask = southwell_window(loads, max_w, max_w[0], r.inflection_load_Pa, t)
                    southwell_series.append(
                        (max_w - max_w[0], loads, mask, r.southwell_load_Pa, where,
                         "tab:red" if obstacle else "tab:blue")
                    )  # fmt: skip
                if obstacle and delta == 1e-3:
                    # The deformed plate at the last state (1.2 lambda_c), and section A.
                    plate = analysis.plate
                    deflection = analysis.deflection()
                    assert plate.contact is not None
                    contact_xy = plate.contact.coordinates[plate.contact_nodes()]
                    x_nl, w_nl = fields.section(linear.problem, deflection)
                    x_lin, w_lin = fields.section(linear.problem, linear.mode)
                    final = r.path[-1]
                    if comm.size == 1:
                        plotting.plot_mode_3d(
                            linear.problem,
                            deflection,
                            figures / "deformed_c1.png",
                            contact_coordinates=contact_xy,
                            title=(
                                f"ω_c1, {MESH[0]}×{MESH[1]}, δ/t = 1e-3: λ = "
                                f"{final['load_Pa'] / lam_c:.2f} λ_c, largest deflection "
                                f"{final['max_w_m'] / t:.2f} t"
                            ),
                        )
elapsed = time.perf_counter() - t0

# %% [markdown]
# ## The δ study
#
# With the obstacle the reference is λ_c (unilateral), without it λ_free.

# %%
header = (
    f"{'obstacle':>8}  {'delta/t':>7}  {'Southwell (Pa)':>14}  {'/ref':>7}  "
    f"{'inflection (Pa)':>15}  {'/ref':>7}  {'steps':>5}  {'contact':>7}  {'time (s)':>8}"
)
if comm.rank == 0:
    print(
        f"linear: lambda_c = {lam_c:.6e} Pa, lambda_free = {lam_free:.6e} Pa ({MESH[0]}x{MESH[1]})"
    )
    print(header)
    for r in rows:
        print(
            f"{'yes' if r.obstacle else 'no':>8}  {r.imperfection:>7g}  "
            f"{r.southwell_load_Pa:>14.6e}  {r.southwell_ratio:>7.5f}  "
            f"{r.inflection_load_Pa:>15.6e}  {r.inflection_ratio:>7.5f}  "
            f"{len(r.path) - 1:>5d}  {r.path[-1]['contact_nodes']:>7d}  "
            f"{r.timings['path_s']:>8.2f}"
        )
    print(f"all paths (linear solve included): {elapsed:.1f} s")

# %% [markdown]
# ## Figures
#
# max|w|/t against λ: with the obstacle (solid) the knees gather at λ_c as δ decreases,
# without it (dashed) at λ_free. The Southwell plot is a straight line of slope 1/λ_S
# on the fitted points (filled). Section A compares the deformed plate past λ_c with the
# linear unilateral mode.

# %%
if comm.rank == 0:
    marks = {
        f"λ_free (linear) = {lam_free / 1e6:.3f} MPa": (lam_free, "tab:blue"),
        f"λ_c (linear, unilateral) = {lam_c / 1e6:.3f} MPa": (lam_c, "black"),
    }
    written = [
        plotting.plot_load_paths(
            figures / "load_paths.png",
            curves,
            thickness=t,
            marks=marks,
            title=f"Paper's plate, obstacle ω_c1, {MESH[0]}×{MESH[1]}: von Kármán paths",
        ),
        plotting.plot_southwell(
            figures / "southwell.png",
            southwell_series,
            thickness=t,
            title="Southwell plot, δ/t = 1e-3",
        ),
        plotting.plot_section(
            figures / "section_c1.png",
            x_lin,
            w_lin,
            x_nl,
            np.asarray(w_nl) / np.abs(w_nl).max(),
            zone_x=zone_box(spec)[0],  # type: ignore[index]
            title=f"Section A (y = 0), ω_c1, {MESH[0]}×{MESH[1]}, δ/t = 1e-3",
            labels=(
                "linear unilateral mode",
                f"nonlinear state at λ = {final['load_Pa'] / lam_c:.2f} λ_c (scaled)",
            ),
        ),
    ]
    if comm.size == 1:
        written.append(figures / "deformed_c1.png")
    for path in written:
        print(f"wrote {path}")
    summary = {
        "mesh": list(MESH),
        "linear_critical_load_Pa": lam_c,
        "free_load_Pa": lam_free,
        # Without the paths (the file is versioned): a record, the same on any machine.
        "study": [{k: v for k, v in r.as_dict().items() if k != "path"} for r in rows],
    }
    study.write_record(figures / "results.json", summary)

# %% [markdown]
# ## Checks
#
# - Every path reaches 1.2 λ_ref and its last state satisfies the contact conditions
#   (w ≤ 0 in the zone, the obstacle pushes, zero residual on the free DOFs).
# - At δ/t = 1e-3 and 1e-4, the Southwell and inflection loads lie within 1 % of the
#   linear load of the same mesh: λ_c with the obstacle, λ_free without.
# - With the obstacle the knee is λ_c, not λ_free: the Southwell load exceeds λ_free by
#   at least 90 % of the linear gap λ_c − λ_free.
# - The Southwell load approaches the linear load as δ decreases (error at 1e-4 below
#   the error at 1e-2).

# %%
for r in rows:
    assert r.completed and r.contact_check["satisfied"], (r.stop_reason, r.contact_check)
    assert r.southwell_ratio is not None and r.inflection_ratio is not None
    if r.imperfection <= 1e-3:
        assert abs(r.southwell_ratio - 1) < RTOL, (r.obstacle, r.imperfection, r.southwell_ratio)
        assert abs(r.inflection_ratio - 1) < RTOL, (r.obstacle, r.imperfection, r.inflection_ratio)
    if r.obstacle:
        assert r.southwell_load_Pa is not None
        assert r.southwell_load_Pa - lam_free > 0.9 * (lam_c - lam_free)
for obstacle in (True, False):
    error = {r.imperfection: abs(r.southwell_ratio - 1) for r in rows if r.obstacle is obstacle}
    assert error[1e-4] <= error[1e-2], error
assert lam_c > lam_free
if comm.rank == 0:
    print("nonlinear validation: all checks passed")
