# ---
# jupytext:
#   text_representation:
#     extension: .py
#     format_name: percent
# ---

# %% [markdown]
# # The steel face of a concrete-filled box column: tie bars, restrained edges, shear
#
# A concrete-filled steel box column: each steel face is a long plate between the
# column's corners, filled with concrete on its inside, so it can buckle only outward
# (the concrete is a rigid obstacle over the whole face). The corners do not pin the face
# freely: the neighbouring faces restrain its rotation along the long edges. Tie bars
# through the concrete at a spacing s along the axis, at mid-width, hold the face to the
# core (w = 0 there). The face carries the column's compression, which grows, and a
# shear from a lateral load, which is fixed. Here: a face 400 mm wide and 6 mm thick
# (b/t = 67), a 1200 mm segment between diaphragms (simply supported there), S355 steel
# (E = 210 GPa, ν = 0.3, f_y = 355 MPa), rotational springs k_r = 2D/b on the corners
# (a neighbouring face of the same size bent in a symmetric mode: the stiffness 2EI/L of a
# beam whose ends turn equally and oppositely; a face itself compressed restrains less),
# a fixed shear of 80 MPa, tie bars at 300 mm.
#
# This demo illustrates how to:
#
# - describe elastically restrained edges (`rotational_stiffness`), a row of tie bars
#   (`[[points]]` with `spacing` and a degenerate `region`), a fixed shear with a growing
#   compression (`fixed_shear_stress`), in millimetres (`units = "mm-N-MPa"`);
# - get the EN 1993-1-5 slenderness and reduction factor from this σ_cr (`[design]`);
# - draw the mode against the concrete and its contact map with the ties;
# - sweep the tie spacing (`points.0.spacing`, the engine of `unibuckle sweep`) and draw
#   k against it.

# %%
from __future__ import annotations

import itertools
import warnings

from mpi4py import MPI

import numpy as np

from unibuckle_fenicsx import problem_from_dict, problem_to_dict, solve
from unibuckle_fenicsx.sweep import Variation, run_sweep
from unibuckle_fenicsx.viz import fields, study

warnings.filterwarnings("error")  # demos run warning-free

# %% [markdown]
# ## Parameters
#
# The problem as a problem file would give it (mm, N, MPa). Cells of 25 mm (48 × 16);
# `--coarse`: 100 mm (12 × 4) and fewer tie spacings.

# %%
args = study.demo_arguments("The steel face of a concrete-filled box column.")
SIZE = 100.0 if args.coarse else 25.0  # mm
SPACINGS = (200.0, 400.0, 1200.0) if args.coarse else (150.0, 200.0, 300.0, 400.0, 600.0, 1200.0)
T, B, A = 6.0, 400.0, 1200.0  # mm
E, NU, FY = 210000.0, 0.3, 355.0  # MPa
TAU = 80.0  # MPa, the fixed shear
TIE_SPACING = 400.0 if args.coarse else 300.0  # mm
D = E * T**3 / (12 * (1 - NU**2))  # the plate's bending stiffness (N mm)
KR = 2.0 * D / B  # N mm/mm/rad = N
comm = MPI.COMM_WORLD
figures = args.figures / "column"

EDGES = {  # a uniform state sigma_x = -lambda (scaled) and tau_xy = TAU (fixed)
    "left": {"normal_stress": -1.0, "fixed_shear_stress": TAU},
    "right": {"normal_stress": -1.0, "fixed_shear_stress": TAU},
    "bottom": {"rotational_stiffness": KR, "fixed_shear_stress": -TAU},
    "top": {"rotational_stiffness": KR, "fixed_shear_stress": -TAU},
}
FACE = {
    "name": "column face",
    "units": "mm-N-MPa",
    "plate": {"corners": [[0.0, 0.0], [A, B]], "thickness": T},
    "material": {"E": E, "nu": NU},
    "edges": EDGES,
    "mesh": {"size": SIZE},
    "obstacle": {"zone": "all", "side": "below"},  # the concrete: w >= 0, outward only
    "points": [{"spacing": TIE_SPACING, "region": [[0.0, A], [B / 2, B / 2]]}],
    "design": {"yield_stress": FY, "partial_factor": 1.0},
}

# %% [markdown]
# ## The face against the concrete, without it, and without the shear

# %%
spec = problem_from_dict(FACE)
free_spec = problem_from_dict({k: v for k, v in FACE.items() if k != "obstacle"})
no_shear = dict(FACE, edges={k: {**v, "fixed_shear_stress": 0.0} for k, v in EDGES.items()})
with solve(free_spec, comm) as analysis:
    free = analysis.result
with solve(problem_from_dict(no_shear), comm) as analysis:
    without_shear = analysis.result
with solve(spec, comm) as analysis:
    result = analysis.result
    problem = analysis.problem
    oriented = problem.contact.values(analysis.mode.x.petsc_vec)
    ties = problem.model.points[0].unique_nodes
    node_xy, node_w = fields.nodal_deflection(problem, analysis.mode)
    at_ties = np.abs(node_xy[:, None, :] - ties[None, :, :]).max(axis=2).min(axis=1) < 1e-9
    w_ties = node_w[at_ties]
    if comm.size == 1:
        from unibuckle_fenicsx.viz import plotting

        xy, w, triangles = fields.mesh_triangles(problem, analysis.mode)
        title = (
            f"against the concrete: sigma_cr = {result.critical_load_Pa / 1e6:.0f} MPa with "
            f"tau = {TAU:g} MPa fixed ({result.ratio_to_free:.2f} x free)"
        )
        mode_png = plotting.plot_mode_3d(
            problem,
            analysis.mode,
            figures / "mode.png",
            contact_coordinates=result.contact_coordinates,
            contact_pressing=fields.pressing(result),
            title=title,
            tau=problem.tau,
        )
        map_png = plotting.plot_contact_map(
            figures / "contact_map.png",
            xy,
            w,
            triangles,
            boundary=spec.plate.boundary,
            zones=fields.zone_outlines(spec),
            contact_coordinates=result.contact_coordinates,
            contact_pressing=fields.pressing(result),
            title=f"contact map: w / max|w|, contact nodes, tie bars at {TIE_SPACING:g} mm",
            tau=problem.tau,
            ties=ties,
        )
        print(f"wrote {mode_png} and {map_png}")

# %% [markdown]
# ## k against the tie spacing: a sweep
#
# The same face for every spacing in `SPACINGS` (1200 mm: ties at the diaphragms only,
# which hold the face already: no tie), through the sweep engine of `unibuckle sweep`
# (one JSON line per point, resumable).

# %%
base = problem_to_dict(spec, units="mm-N-MPa")
variation = Variation("points.0.spacing", SPACINGS)
lines_path = figures / "tie_spacing.jsonl"
if comm.rank == 0 and lines_path.exists():
    lines_path.unlink()  # a fresh sweep (the file would resume an old one)
comm.Barrier()
lines = run_sweep(base, [variation], lines_path, comm, progress=False)
if comm.rank == 0:
    from unibuckle_fenicsx.viz.charts import plot_sweep

    chart = plot_sweep(
        lines,
        [variation],
        base,
        figures / "tie_spacing.png",
        title=f"column face, fixed shear {TAU:g} MPa: k against the tie spacing",
    )
    print(f"wrote {chart}")

# %% [markdown]
# ## Results and the EN 1993-1-5 output
#
# The critical load is a KKT point, not proven the lowest: the critical stress may lie
# lower, down to the verified lower bound (here the free face's, by interlacing). The
# design output gives the same quantities there (`design.lower_bound`): the safe values,
# which are the design values to use. Both check the direct stress alone: the fixed
# shear is not in ρ f_y/γ_M (EN 1993-1-5 section 5 and the interaction of 7.1 would
# include it).

# %%
scale = 1e6  # Pa per MPa
design = result.design
assert design is not None, "the plate has a design output ([design] in the problem)"
safe = design.lower_bound or design  # proven: the lower bound is the critical load
summary = {
    "mesh_size_mm": SIZE,
    "cells": result.mesh,
    "tie_spacing_mm": TIE_SPACING,
    "rotational_stiffness_N": KR,
    "fixed_shear_MPa": TAU,
    "critical_stress_MPa": result.critical_load_Pa / scale,
    "free_stress_MPa": free.critical_load_Pa / scale,
    "without_shear_MPa": without_shear.critical_load_Pa / scale,
    "buckling_coefficient_k": result.buckling_coefficient_k,
    "method": result.method,
    "certificate": {k: getattr(result.certificate, k) for k in ("kkt", "global_optimum_proven")},
    "design": {k: getattr(design, k) for k in ("relative_slenderness", "psi", "reduction_factor")},
    "design_stress_MPa": design.reduced_design_stress_Pa / scale,
    "lower_bound_MPa": result.lower_bound_Pa / scale,
    "design_lower_bound": {
        k: getattr(safe, k) for k in ("relative_slenderness", "psi", "reduction_factor")
    },
    "design_stress_lower_bound_MPa": safe.reduced_design_stress_Pa / scale,
    "tie_spacing_study": [
        {
            "spacing_mm": line["point"]["points.0.spacing"],
            "status": line["status"],
            "k": line.get("buckling_coefficient_k"),
            "k_free": line.get("buckling_coefficient_k", 0.0)
            * line.get("free_load_Pa", 0.0)
            / line.get("critical_load_Pa", 1.0),
            "rho": (line.get("design") or {}).get("reduction_factor"),
            "rho_lower_bound": (
                (line.get("design") or {}).get("lower_bound") or line.get("design") or {}
            ).get("reduction_factor"),
        }
        for line in lines
    ],
}
if comm.rank == 0:
    print(result.summary())
    print(f"  without the concrete: {free.critical_load_Pa / scale:.1f} MPa")
    print(f"  without the shear: {without_shear.critical_load_Pa / scale:.1f} MPa")
    for row in summary["tie_spacing_study"]:
        print(
            f"  ties at {row['spacing_mm']:g} mm: k = {row['k']:.4f}, rho = {row['rho']:.4f} "
            f"(at the lower bound, the safe value: {row['rho_lower_bound']:.4f})"
        )
    # Records (study.write_record): the same on any machine. The face is thin
    # (t/b = 0.015): nodes flat on the concrete with no contact force join the contact
    # set or not with rounding, at the same load, so the set is left out.
    study.write_record(figures / "results.json", summary, contact=False)
    study.write_record(lines_path, lines, contact=False)

# %% [markdown]
# ## Checks
#
# The certificate holds (a KKT point); the concrete never lowers the load (interlacing);
# the mode is outward at every node (w ≥ 0) and zero at the ties; the fixed shear lowers
# the critical compression; every sweep point is a KKT point above its free load, and the
# free loads never rise when ties are taken away (150, 300, 600, 1200 mm are nested sets:
# interlacing); ρ is EN 1993-1-5's (4.2) for the slenderness √(f_y/σ_cr) with ψ = 1, at the
# KKT load and at the lower bound, where it is the smaller (the safe value).

# %%
RTOL = 1e-8
assert result.certificate.kkt, result.certificate
assert result.critical_load_Pa >= free.critical_load_Pa * (1 - RTOL)
assert oriented.max() <= problem.tau, oriented.max()
assert np.abs(w_ties).max() <= 1e-12, w_ties
assert result.critical_load_Pa < without_shear.critical_load_Pa
slenderness = np.sqrt(FY * scale / result.critical_load_Pa)
assert design.psi == 1.0
assert np.isclose(design.relative_slenderness, slenderness, rtol=1e-12)
# EN 1993-1-5 (4.2), internal compression element, psi = 1: rho = 1 up to 0.673, else
# (slenderness - 0.055 (3 + psi)) / slenderness^2 (worked out here, not by the package).
rho = 1.0 if slenderness <= 0.673 else (slenderness - 0.22) / slenderness**2
assert np.isclose(design.reduction_factor, min(rho, 1.0), rtol=1e-12)
slenderness = np.sqrt(FY * scale / result.lower_bound_Pa)
rho = 1.0 if slenderness <= 0.673 else (slenderness - 0.22) / slenderness**2
assert np.isclose(safe.reduction_factor, min(rho, 1.0), rtol=1e-12)
assert safe.reduction_factor <= design.reduction_factor
assert all(line["status"] == "ok" for line in lines), [line["status"] for line in lines]
by_spacing = {line["point"]["points.0.spacing"]: line for line in lines}
for line in lines:
    assert line["critical_load_Pa"] >= line["free_load_Pa"] * (1 - RTOL)
nested = [by_spacing[s]["free_load_Pa"] for s in (150.0, 300.0, 600.0, 1200.0) if s in by_spacing]
assert all(a >= b * (1 - RTOL) for a, b in itertools.pairwise(nested)), nested
if comm.rank == 0:
    print("column face: all checks passed")
