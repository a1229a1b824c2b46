"""The engineering features under ``mpiexec -n 2``: the serial answers, partition-independent.

Restrained edges, point restraints (snapped off-grid, bilateral, one-sided, springs), an
angle-ply laminate, a thermal load with a fixed shear and rise, the design output, on
small meshes, each solved in this process and by ``tests/mpi/engineering.py`` on two
ranks: loads to 1e-8 relative (the eigen solves converge to 1e-10), contact nodes and
snapped nodes exactly (their choice is partition-independent by construction).
"""

from __future__ import annotations

import importlib.util
import json

from mpi4py import MPI

import pytest

from support.paths import MPI_SCRIPTS
from support.processes import run_mpi

SCRIPT = MPI_SCRIPTS / "engineering.py"
LOAD_RTOL = 1e-8

pytestmark = [
    pytest.mark.mpi,
    pytest.mark.slow,
    pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="launches mpiexec itself"),
]

PLATE = {"corners": [[0.0, 0.0], [2.0, 1.0]], "thickness": 0.01}
MATERIAL = {"E": 2.0e11, "nu": 0.3}
EDGES = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}

PLY = {"E1": 1.4e11, "E2": 1.0e10, "G12": 5.0e9, "nu12": 0.3, "G13": 5.0e9, "G23": 3.0e9}

PROBLEMS = {
    "restrained edges, obstacle": {
        "plate": PLATE,
        "material": MATERIAL,
        "edges": {
            **EDGES,
            "bottom": {"rotational_stiffness": 3.0e5},
            "top": {
                "support": "free",
                "translational_stiffness": 5.0e6,
                "rotational_stiffness": 1e4,
            },
        },
        "mesh": {"nx": 12, "ny": 6},
        "obstacle": {"zone": "all"},
    },
    "laminate (45/-45/-45/45), obstacle": {
        "plate": {"corners": [[0.0, 0.0], [2.0, 1.0]]},
        "material": {
            "plies": [{"thickness": 0.0025, "angle": a, **PLY} for a in (45, -45, -45, 45)]
        },
        "edges": EDGES,
        "mesh": {"nx": 12, "ny": 6},
        "obstacle": {"zone": [[0.0, 1.0], [0.0, 1.0]], "side": "below"},
    },
    "thermal scaled, fixed shear and rise, obstacle": {
        "plate": PLATE,
        "material": {**MATERIAL, "thermal_expansion": 1.2e-5},
        "edges": {
            "left": {"inplane": "roller", "fixed_shear_stress": 2.0e6},
            "right": {"inplane": "roller", "fixed_shear_stress": 2.0e6},
            "bottom": {"inplane": "roller", "fixed_shear_stress": -2.0e6},
            "top": {"fixed_shear_stress": -2.0e6},
        },
        "mesh": {"nx": 12, "ny": 6},
        "load": {"temperature": [1.0, 0.5, 0.0], "fixed_temperature": 2.0},
        "obstacle": {"zone": "all"},
    },
    "points: off-grid ties, springs, one-sided studs": {
        "plate": PLATE,
        "material": MATERIAL,
        "edges": EDGES,
        "mesh": {"nx": 12, "ny": 6},
        "points": [
            {"spacing": 0.55, "region": [[0.0, 2.0], [0.5, 0.5]]},
            {"at": [1.5, 0.25], "kind": "spring", "stiffness": 1.0e6},
            {"at": [0.5, 0.75], "kind": "one-sided", "side": "below"},
            # Four nodes at the same distance:
            {"at": [1.25, 0.75], "kind": "one-sided", "side": "above"},
            {"spacing": [1.0, 1.0], "offset": [0.5, 0.5], "kind": "one-sided", "side": "above"},
        ],
        # An internal element (unloaded edges simply supported); the edge on springs of
        # the first problem is neither supported nor free (refused).
        "design": {"yield_stress": 3.55e8, "partial_factor": 1.1},
    },
}


def _summary():
    spec = importlib.util.spec_from_file_location("engineering", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.summary


def test_engineering_features_on_two_ranks_give_the_serial_answer(tmp_path):
    summary = _summary()
    path = tmp_path / "problems.json"
    path.write_text(json.dumps(list(PROBLEMS.values())))
    parallel = json.loads(run_mpi(SCRIPT, 2, str(path)).splitlines()[-1])
    for (name, data), par in zip(PROBLEMS.items(), parallel, strict=True):
        ser = summary(data, MPI.COMM_SELF)
        for key in ("critical_load_Pa", "free_load_Pa", "critical_temperature_K"):
            if ser.get(key) is not None:
                assert par[key] == pytest.approx(ser[key], rel=LOAD_RTOL), (name, key)
        assert par["contact_coordinates"] == ser["contact_coordinates"], name
        if ser.get("design"):
            for key in ("sigma_cr_Pa", "relative_slenderness", "reduction_factor", "psi"):
                assert par["design"][key] == pytest.approx(ser["design"][key], rel=LOAD_RTOL)
        assert par["point_restraints"] == ser["point_restraints"], name
        assert par["kkt"] == ser["kkt"] is True, name
        assert ser["contact_coordinates"], name  # the obstacle or the points are active
