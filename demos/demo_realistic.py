# ---
# jupytext:
#   text_representation:
#     extension: .py
#     format_name: percent
# ---

# %% [markdown]
# # A steel plate with a service opening against a concrete face, under compression + shear
#
# The steel face plate of a composite wall, or the side plate of a member bolted to
# concrete, can buckle only away from the concrete: the concrete is a rigid face on one
# side over the whole plate. Such plates have openings, and carry compression with shear.
# This demo takes a 1000 × 400 × 6 mm steel plate (E = 210 GPa, ν = 0.3), simply supported
# on its four edges, with a circular opening of 160 mm at its centre, under a compressive
# stress σ on its short edges plus a shear stress 0.4 σ, the concrete face below it
# (`side = "below"`: the plate may only deflect upwards, w ≥ 0). Free, it buckles in
# skewed half-waves of both signs; against the face, in one outward buckle around the
# opening between two inclined touch-down lines.
#
# This demo illustrates how to:
#
# - describe a plate with a hole in millimetres (`units = "mm-N-MPa"`, `[[plate.holes]]`,
#   `[mesh] size`): gmsh meshes it with quadrilaterals;
# - put a rigid obstacle below the plate and load it with compression + shear;
# - compare the critical stress with the free plate's and with the plate without opening;
# - draw the critical mode in 3-D and its contact map on the plate's own mesh.

# %%
from __future__ import annotations

import warnings

from mpi4py import MPI

import numpy as np

from unibuckle_fenicsx import problem_from_dict, solve
from unibuckle_fenicsx.viz import fields, study

warnings.filterwarnings("error")  # demos run warning-free

# %% [markdown]
# ## Parameters
#
# The problem as a problem file would give it (every length in mm, stresses in MPa). The
# mesh size is 15 mm (about 1 900 cells), 40 mm with `--coarse`.

# %%
args = study.demo_arguments("A steel plate with an opening against a concrete face.")
SIZE = 40.0 if args.coarse else 15.0  # mm
TAU = 0.4  # shear stress per unit compressive stress
comm = MPI.COMM_WORLD
figures = args.figures / "realistic"
PLATE = {
    "name": "steel plate with an opening",
    "units": "mm-N-MPa",
    "plate": {
        "corners": [[0.0, 0.0], [1000.0, 400.0]],
        "thickness": 6.0,
        "holes": [{"center": [500.0, 200.0], "radius": 80.0}],
    },
    "material": {"E": 210000.0, "nu": 0.3},
    "edges": {  # a uniform state sigma_x = -1, tau_xy = TAU per unit load
        "left": {"normal_stress": -1.0, "shear_stress": TAU},
        "right": {"normal_stress": -1.0, "shear_stress": TAU},
        "bottom": {"shear_stress": -TAU},
        "top": {"shear_stress": -TAU},
    },
    "mesh": {"size": SIZE},
    "obstacle": {"zone": "all", "side": "below"},
}

# %% [markdown]
# ## Three solves
#
# The plate against the concrete, the same plate free (no obstacle: the bilateral load),
# and the plate without opening, free (the hole's effect).

# %%
spec = problem_from_dict(PLATE)
no_hole = dict(PLATE, plate={k: v for k, v in PLATE["plate"].items() if k != "holes"})
solid = problem_from_dict({k: v for k, v in no_hole.items() if k != "obstacle"})
with solve(solid, comm) as analysis:
    solid_load = analysis.result.free_load_Pa
with solve(spec, comm) as analysis:
    result = analysis.result
    problem = analysis.problem
    # The critical mode at the contact nodes: admissible means w >= 0 everywhere.
    oriented = problem.contact.values(analysis.mode.x.petsc_vec)
    xy_zone = problem.contact.coordinates
    if comm.size == 1:
        xy, w, triangles = fields.mesh_triangles(problem, analysis.mode)
        from unibuckle_fenicsx.viz import plotting

        figures.mkdir(parents=True, exist_ok=True)
        title = (
            f"critical mode against the concrete face: sigma = {result.critical_load_Pa / 1e6:.1f} "
            f"MPa ({result.ratio_to_free:.3f} x free)"
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
        hole = spec.plate.holes[0]
        turn = np.linspace(0.0, 2 * np.pi, 97)[:-1]
        circle = np.column_stack(
            [
                hole.center[0] + hole.radius * np.cos(turn),
                hole.center[1] + hole.radius * np.sin(turn),
            ]
        )
        map_png = plotting.plot_contact_map(
            figures / "contact_map.png",
            xy,
            w,
            triangles,
            boundary=spec.plate.boundary,
            holes=[circle],
            zones=fields.zone_outlines(spec),
            contact_coordinates=result.contact_coordinates,
            contact_pressing=fields.pressing(result),
            title="contact map: mode w / max|w| and the nodes resting on the concrete",
            tau=problem.tau,
        )
        print(f"wrote {mode_png} and {map_png}")

# %% [markdown]
# ## Results

# %%
scale = 1e6  # Pa per MPa
summary = {
    "mesh_size_mm": SIZE,
    "cells": result.mesh[0],
    "dofs": result.dofs,
    "critical_stress_MPa": result.critical_load_Pa / scale,
    "free_stress_MPa": result.free_load_Pa / scale,
    "ratio_to_free": result.ratio_to_free,
    "without_opening_free_stress_MPa": solid_load / scale,
    "opening_effect": result.free_load_Pa / solid_load,
    "constrained_nodes": result.constrained_nodes,
    "contact_nodes": result.contact_nodes,
    "method": result.method,
    "eigensolves": result.eigensolves,
    "certificate": {k: result.certificate[k] for k in ("kkt", "global_optimum_proven")},
}
if comm.rank == 0:
    print(result.summary())
    for key, value in summary.items():
        print(f"  {key}: {value}")
    study.write_record(figures / "results.json", summary)

# %% [markdown]
# ## Checks
#
# The certificate holds (a KKT point: the mode lies on the admissible side of the face at
# every node, and the face only pushes); the face never lowers the load (interlacing);
# no constrained node lies in the opening (the zone is the whole plate, the opening is
# not plate); the opening lowers the free load.

# %%
RTOL = 1e-8
assert result.certificate["kkt"], result.certificate
assert result.critical_load_Pa >= result.free_load_Pa * (1 - RTOL)
assert oriented.max() <= problem.tau, oriented.max()
r = np.hypot(xy_zone[:, 0] - 0.5, xy_zone[:, 1] - 0.2)
assert r.min() >= 0.08 * np.cos(np.pi / 16) - 1e-9, r.min()
assert result.free_load_Pa < solid_load
if comm.rank == 0:
    print("realistic plate: all checks passed")
