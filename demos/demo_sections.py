# ---
# jupytext:
#   text_representation:
#     extension: .py
#     format_name: percent
# ---

# %% [markdown]
# # Concrete-filled tubes: a square box and a circular tube, hollow and filled
#
# The steel tube of a concrete-filled column is a thin-walled section whose walls can
# buckle only outward: the concrete core is a rigid obstacle on the inside of every wall.
# Here the whole section is one shell model in 3-D (the faces of a box restrain each
# other at the corners; a circular wall is curved), and the core is the obstacle of the
# unilateral problem. Two sections of steel (E = 210 GPa, ν = 0.3) under uniform axial
# compression, simply supported at their ends (rigid diaphragms, free to warp):
#
# - a square box, faces b = 200 mm between the mid-lines of the walls, t = 2 mm
#   (b/t = 100), length 3b;
# - a circular tube, mid-surface radius R = 100 mm, t = 1 mm (R/t = 100), length R.
#
# Each is solved hollow and filled, and compared with the classical references:
#
# - the hollow box: every face a plate simply supported on four edges (neighbouring faces
#   buckle in and out alternately, so the corners do not turn against them), k = 4,
#   σ = 4π²D/(t b²) (Timoshenko and Gere, section 9.2);
# - the hollow tube: σ_cl = E t / (R √(3(1 − ν²))) (Timoshenko and Gere, section 11.4),
#   Donnell's shallow-shell value; Sanders' equations give this short tube's mode of
#   n = 7 waves 0.960 σ_cl ({doc}`../verification/sections_geometric`);
# - the filled box: each face may only move outward; a corner that turns would push one
#   of its faces into the core, so it turns only by moving outward, which stretches the
#   walls: the corners restrain the faces elastically. The face's k lies between that of
#   the face as a plate against a rigid face with simply supported unloaded edges and with
#   clamped ones (the package's plate solver on the same cells; thin-plate values at
#   a/b = 3: 9/2 and 8.0996, {doc}`../verification/thin_plates`). For long plates against
#   a rigid medium the literature quotes k = 5.33 (simply supported) and 10.3 (clamped)
#   (Wright, 1993; Uy and Bradford, 1996): a gain of 1.33 to 2.6 over the hollow k = 4;
# - the filled tube: the one-sided axisymmetric bulge of a long tube buckles at 5/3 σ_cl
#   (a beam on the hoop's elastic foundation lifted off a rigid base,
#   {doc}`../verification/sections`); the gain √3 quoted for filled circular tubes
#   (Bradford, Loh and Uy, 2002) is the Rayleigh quotient of the bulge 1 − cos, an upper
#   bound of it.
#
# This demo illustrates how to:
#
# - describe a section (`SectionParameters`) and solve it hollow and filled
#   (`solve_section`: the same record as a plate's, with the section's reference stress);
# - check a box's filled faces against the plate solver with the edges that bound them;
# - draw the 3-D mode of a section and where its walls press on the core
#   (`plot_section_mode_3d`).

# %%
from __future__ import annotations

import logging
import math
import warnings

from mpi4py import MPI

from unibuckle_fenicsx import SectionParameters, problem_from_dict, solve, solve_section
from unibuckle_fenicsx.viz import study

warnings.filterwarnings("error")  # demos run warning-free


class KeepWarnings(logging.Handler):
    """The package's logged warnings (a coarse mesh's, a thick wall's), kept to check."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        """Keep the record's message."""
        self.messages.append(record.getMessage())


logged = KeepWarnings()
logging.getLogger("unibuckle_fenicsx").addHandler(logged)

# %% [markdown]
# ## Parameters
#
# Box cells of b/10 = 20 mm (`--coarse`: b/4 and a box of length 1.5b). The tube, hollow
# and filled, on cells of 4.5 mm (`--coarse`: 50 mm): 3.85 cells along its axisymmetric
# half-wave π√(Rt)/(12(1 − ν²))^¼ = 17.3 mm, where the package's rule asks 3.7 for this
# simply supported tube of 5.8 half-waves (`docs/guide/sections.md`, "Cell size"): on
# coarser cells a solve warns that its load comes out too high. The demo runs without a
# warning. The verification page ({doc}`../verification/sections`) has the meshes'
# convergence.

# %%
args = study.demo_arguments("Concrete-filled box and circular tubes, hollow and filled.")
E, NU = 2.1e11, 0.3
B, T_BOX = 0.2, 0.002  # m
R, T_TUBE = 0.1, 0.001  # m
BOX_CELL = B / (4 if args.coarse else 10)
BOX_LENGTH = (1.5 if args.coarse else 3.0) * B
TUBE_CELL = 0.05 if args.coarse else 0.0045  # hollow and filled
comm = MPI.COMM_WORLD
figures = args.figures / "sections"

BOX = SectionParameters(
    "box", width=B, depth=B, thickness=T_BOX, length=BOX_LENGTH, E=E, nu=NU,
    mesh_size=BOX_CELL, ends="simply_supported", core=True,
)  # fmt: skip
TUBE = SectionParameters(
    "tube", diameter=2 * R, thickness=T_TUBE, length=R, E=E, nu=NU,
    mesh_size=TUBE_CELL, ends="simply_supported", core=True,
)  # fmt: skip
D = E * T_BOX**3 / (12 * (1 - NU**2))  # the box walls' bending stiffness (N m)
SIGMA_BOX = 4 * math.pi**2 * D / (T_BOX * B**2)  # k = 4 (Pa)
SIGMA_CL = E * T_TUBE / (R * math.sqrt(3 * (1 - NU**2)))  # the classical tube (Pa)
SANDERS = 0.9601  # Sanders' equations over SIGMA_CL, L = R (tests/support/cylinders.py)


# %% [markdown]
# ## The sections, filled
#
# `solve_section` solves the hollow section (its free load, verified the smallest by an
# inertia count) and, with `core = True`, the filled one with its certificate, starting
# on a section of twice the cell size (`levels = 1`): on the box (below 10^4 DOFs) the
# interior point and the active set, the lower KKT point kept; on the tube (about
# 2·10^4 DOFs) the interior point. Its modes' arrays go to the 3-D figures.


# %%
#: What a figure's sigma_cr is divided by: a face of the box as a long simply supported
#: plate (k = 4), the tube's classical axisymmetric stress.
REFERENCES = {"box": "the k = 4 plate's", "tube": "classical sigma_cl"}


def title(name: str, state: str, sigma: float, reference: float) -> str:
    """A 3-D figure's title: the section, its state, sigma_cr in MPa and over its reference."""
    ratio = sigma / reference
    return f"{name}, {state}: sigma_cr = {sigma / 1e6:.1f} MPa = {ratio:.3f} x {REFERENCES[name]}"


def solve_and_draw(
    params: SectionParameters, name: str, reference: float, levels: int, hollow: bool
) -> dict:
    """Solve a filled section; draw its filled (and ``hollow``: hollow) mode; the numbers.

    The figures' titles give sigma_cr in MPa and over ``reference`` (:data:`REFERENCES`).
    """
    with solve_section(params, comm, levels=0 if args.coarse else levels) as analysis:
        result = analysis.result
        if comm.size == 1:
            from unibuckle_fenicsx.viz.section import plot_section_mode_3d

            filled = title(name, "filled", result.critical_load_Pa, reference)
            paths = [
                plot_section_mode_3d(
                    analysis.figure_data(),
                    figures / f"{name}_filled.png",
                    title=f"{filled} ({result.ratio_to_free:.2f} x hollow)",
                )
            ]
            if hollow:
                paths.append(
                    plot_section_mode_3d(
                        analysis.figure_data(free=True),
                        figures / f"{name}_hollow.png",
                        title=title(name, "hollow", result.free_load_Pa, reference),
                        show_core=False,
                    )
                )
            print("wrote " + " and ".join(str(p) for p in paths))
        return {
            "cell_m": params.mesh_size,
            "dofs": result.dofs,
            "hollow_Pa": result.free_load_Pa,
            "filled_Pa": result.critical_load_Pa,
            "reference_Pa": reference,
            "hollow/reference": result.free_load_Pa / reference,
            "filled/reference": result.critical_load_Pa / reference,
            "gain": result.ratio_to_free,
            "k_hollow": None if result.buckling_coefficient_k is None
            else result.buckling_coefficient_k / result.ratio_to_free,
            "k_filled": result.buckling_coefficient_k,
            "constrained": result.constrained_nodes,
            "contact_nodes": result.contact_nodes,
            "certificate": {
                k: getattr(result.certificate, k)
                for k in ("kkt", "status", "global_optimum_proven", "proven_by")
            },
            "lower_bound_Pa": result.lower_bound_Pa,
            "summary": result.summary(),
        }  # fmt: skip


box = solve_and_draw(BOX, "box", SIGMA_BOX, levels=1, hollow=True)
tube = solve_and_draw(TUBE, "tube", SIGMA_CL, levels=1, hollow=True)

# %% [markdown]
# ## A box's face as a plate: the bounds of the filled box
#
# The face (a/b = 3, b/t = 100, the same cells) against a rigid face, its loaded ends
# simply supported, its long edges simply supported (the lower bound: corners free to
# turn) or clamped (the upper bound: corners that do not turn).

# %%
n = round(B / BOX_CELL)
FACE = {
    "name": "box face",
    "plate": {"corners": [[0.0, 0.0], [BOX_LENGTH, B]], "thickness": T_BOX},
    "material": {"E": E, "nu": NU},
    "edges": {
        "left": {"normal_stress": -1.0},
        "right": {"normal_stress": -1.0},
        "bottom": {},
        "top": {},
    },
    "mesh": {"nx": round(BOX_LENGTH / BOX_CELL), "ny": n},
    "obstacle": {"zone": "all", "side": "below"},
}
plate_k = {}
for support in ("simply_supported", "clamped"):
    edges = dict(FACE["edges"], bottom={"support": support}, top={"support": support})
    with solve(problem_from_dict(dict(FACE, edges=edges)), comm) as analysis:
        plate_k[support] = analysis.result.buckling_coefficient_k
box["k_plate_bounds"] = plate_k

# %% [markdown]
# ## Results

# %%
summary = {"box": box, "tube": tube}
if comm.rank == 0:
    for name, row in summary.items():
        print(row["summary"])
        print(
            f"  {name}: hollow {row['hollow/reference']:.4f} x reference, filled "
            f"{row['filled/reference']:.4f} x reference, gain {row['gain']:.3f}"
        )
    print(
        f"  box k: hollow {box['k_hollow']:.4f} (4), filled {box['k_filled']:.4f}, face as a "
        f"plate against a rigid face: {plate_k['simply_supported']:.4f} (SS edges) to "
        f"{plate_k['clamped']:.4f} (clamped edges)"
    )
    stored = {
        name: {k: v for k, v in row.items() if k != "summary"} for name, row in summary.items()
    }
    # A record (study.write_record): the same on any machine. The walls are thin: nodes
    # flat on the core with no force fall in or out of the contact set with rounding.
    study.write_record(figures / "results.json", stored, contact=False)

# %% [markdown]
# ## Checks
#
# The cells meet the package's rule (no coarse-cell warning); the hollow sections meet
# their classical values (box within 1.5 %, tube within 3 % of Sanders' value: the
# verification pages' anchors, on these cells); the core never lowers the load
# (interlacing) and its result is a KKT point; the filled box's k lies between the face's
# plate bounds; the filled tube's gain lies between 1 and the Rayleigh bound √3.
# `--coarse` checks only what its tiny meshes can hold.

# %%
RTOL = 1e-8
for row in (box, tube):
    assert row["certificate"]["kkt"], row["certificate"]
    assert row["filled_Pa"] >= row["hollow_Pa"] * (1 - RTOL)
if not args.coarse:
    assert not logged.messages, logged.messages  # no coarse-cell (or other) warning
    assert abs(box["hollow/reference"] - 1) < 0.015, box
    assert abs(tube["hollow/reference"] / SANDERS - 1) < 0.03, tube
    assert plate_k["simply_supported"] < box["k_filled"] < plate_k["clamped"], box
    assert 1.0 < tube["gain"] < math.sqrt(3.0), tube
if comm.rank == 0:
    print("sections: all checks passed")
