"""Five base problem files that together hold every key of the schema (as mappings).

A rectangle with an anisotropic material, every edge key, three obstacles (box, polygon,
circle), every solver key and design output; a bilateral foundation; an outline with
holes, segments and a cell size; restrained edges, fixed and thermal loads, point
restraints and a gapped obstacle; a laminate. The bad-input family changes each of their
values in turn; the schema and the documentation's tests read them as valid files.
"""

from __future__ import annotations

_D = 1e9 * 0.006**3 / 12 / (1 - 0.09)
_Q = [[1.0, 0.3, 0.0], [0.3, 1.0, 0.0], [0.0, 0.0, 0.35]]
RECTANGLE = {
    "name": "base",
    "units": "SI",
    "plate": {"corners": [[0.0, 0.0], [0.2, 0.1]], "thickness": 0.006},
    "material": {"E": 2.1e11, "nu": 0.3},  # a steel's: the design output refuses others
    "edges": {
        "left": {
            "support": "simply_supported",
            "inplane": "free",
            "normal_stress": -1.0,
            "shear_stress": 0.0,
        },
        "right": {"support": "clamped", "normal_stress": [-1.0, -1.0], "shear_stress": 0.0},
        "bottom": {"support": "simply_supported_soft"},
        "top": {"support": "free"},
    },
    "mesh": {"nx": 8, "ny": 4},
    "design": {"yield_stress": 3.55e8, "partial_factor": 1.1},
    "obstacles": [
        {"zone": [[0.05, 0.1], [0.0, 0.1]], "side": "above", "tolerance": 1e-9},
        {"polygon": [[0.12, 0.02], [0.18, 0.02], [0.15, 0.08]], "side": "above"},
        {"circle": {"center": [0.15, 0.05], "radius": 0.02}, "side": "above"},
    ],
    "solver": {
        "method": "auto",
        "tau": 1e-8,
        "eps_tol": 1e-10,
        "max_candidates": 1000,
        "enumeration_budget_s": 10.0,
        "complete": False,
        "until_proven": False,
        "max_iterations": 50,
        "bound_budget": 10,
        "certify": True,
        "penalty": 100.0,
        "prestress_degree": 1,
        "shear": "mitc",
    },
}
FOUNDATION = {
    "plate": {"corners": [[0.0, 0.0], [0.2, 0.1]], "thickness": 0.006},
    "material": {
        "E": 1.0e9,
        "nu": 0.3,
        "shear_correction": 0.8,
        "membrane_voigt": [[6.6e6 * q for q in row] for row in _Q],
        "bending_voigt": [[_D * q for q in row] for row in _Q],
    },
    "obstacle": {"zone": "all", "side": "both", "foundation_stiffness": 1.0e7},
}
OUTLINE = {
    "plate": {
        "outline": [[0.0, 0.0], [0.3, 0.0], [0.3, 0.1], [0.0, 0.1]],
        "thickness": 0.006,
        "holes": [
            {"center": [0.08, 0.05], "radius": 0.02},
            {"outline": [[0.18, 0.03], [0.24, 0.03], [0.21, 0.07]]},
        ],
    },
    "material": {"E": 1.0e9, "nu": 0.3},
    "edges": {
        "ends": {"segments": [1, 3], "support": "simply_supported", "normal_stress": -1.0},
        "sides": {"segments": [0, 2], "support": "clamped"},
        "holes": {"support": "free"},
    },
    "mesh": {"size": 0.02},
    "obstacle": {"zone": [[0.1, 0.15], [0.0, 0.1]], "side": "below"},
}
_PLY = {"E1": 1.4e11, "E2": 1.0e10, "nu12": 0.3, "G12": 5.0e9, "G13": 5.0e9, "G23": 3.0e9}
LAMINATE = {
    "plate": {"corners": [[0.0, 0.0], [0.3, 0.1]]},
    "material": {
        "plies": [
            {"thickness": 0.002, "angle": 0.0, **_PLY},
            {"thickness": 0.002, "angle": 90.0, **_PLY},
            {"thickness": 0.002, "angle": 0.0, **_PLY},
        ],
    },
    "mesh": {"nx": 12, "ny": 4},
}
FEATURES = {
    "plate": {"corners": [[0.0, 0.0], [0.3, 0.1]], "thickness": 0.006},
    "material": {"E": 2.1e11, "nu": 0.3, "thermal_expansion": 1.2e-5},
    "edges": {
        "left": {
            "support": "simply_supported",
            "inplane": "free",
            "normal_stress": -1.0,
            "rotational_stiffness": 100.0,
            "fixed_normal_stress": -0.5,
        },
        "right": {"support": "simply_supported", "inplane": "clamped"},
        "bottom": {
            "support": "free",
            "translational_stiffness": 1.0e6,
            "fixed_shear_stress": 0.1,
        },
    },
    "load": {"temperature": 1.0, "fixed_temperature": 0.5, "fixed_factor": 0.5},
    "points": [
        {"at": [0.15, 0.05], "kind": "spring", "stiffness": 1.0e5},
        {"spacing": [0.1, 0.05], "offset": [0.05, 0.0], "region": [[0.0, 0.3], [0.0, 0.1]]},
        {"at": [0.2, 0.05], "kind": "one-sided", "side": "below"},
    ],
    "mesh": {"nx": 12, "ny": 4},
    "obstacle": {"zone": "all", "side": "above", "gap": 1e-4},
    "solver": {"bracket": True},
}
BASES = {
    "rectangle": RECTANGLE,
    "foundation": FOUNDATION,
    "outline": OUTLINE,
    "features": FEATURES,
    "laminate": LAMINATE,
}
