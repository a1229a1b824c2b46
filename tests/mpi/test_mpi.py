"""Distributed runs: the mesh distributed by DOLFINx over 2 and 3 ranks.

Each test launches ``mpiexec -n P`` on a helper under ``tests/mpi/`` and compares with
the same computation in this (serial) process: free and candidate loads to 1e-8
relative, contact nodes exactly as coordinates, certificates, JSON written once and VTX
output. Meshes are small: 3 ranks oversubscribe the 2-core CI machine.
"""

from __future__ import annotations

import importlib.util
import json
import math

from mpi4py import MPI

import numpy as np
import pytest

from support.paths import MPI_SCRIPTS
from support.processes import run_mpi
from unibuckle_fenicsx.cli import main as cli_main
from unibuckle_fenicsx.model.materials import navier_load_mindlin

STEPS = MPI_SCRIPTS / "pipeline_steps.py"
CLI = MPI_SCRIPTS / "pipeline_cli.py"
#: Relative agreement of loads between partitions: the eigen solves converge to a relative
#: residual of eps_tol = 1e-10, so two partitions' loads differ by about that; 1e-8 leaves
#: a margin of 100.
LOAD_RTOL = 1e-8
#: Mode values at contact nodes (scaled to max|w| = 1): eigenvector accuracy at eps_tol 1e-10.
VALUE_ATOL = 1e-7
#: Node coordinates (m): rounding only, 1e-15 of the 0.2 m plate, far below the spacing.
COORD_ATOL = 2e-16

pytestmark = [
    pytest.mark.mpi,
    pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="launches mpiexec itself"),
]


def _load_steps():
    spec = importlib.util.spec_from_file_location("pipeline_steps", STEPS)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def serial_steps():
    """The pipeline summary computed in this process (one rank)."""
    return _load_steps().collect(MPI.COMM_SELF, 12, 6)


def _same_load(a, b):
    if math.isinf(a) or math.isinf(b):
        return a == b
    return abs(a - b) <= LOAD_RTOL * abs(a)


def _compare_certificates(ser, par, where):
    for key in ("feasible", "kkt", "smallest_of_reduced", "global_optimum_proven", "tolerance"):
        assert ser[key] == par[key], (where, key, ser[key], par[key])
    for key in ("feasibility_margin", "max_contact_force"):
        assert par[key] == pytest.approx(ser[key], abs=VALUE_ATOL), (where, key)
    assert par["relative_residual"] < 1e-8 and ser["relative_residual"] < 1e-8, where


@pytest.mark.parametrize("nprocs", [2, 3])
def test_pipeline_steps_match_serial(nprocs, serial_steps):
    """Every step on 2 and 3 ranks equals the serial run.

    3 ranks: one candidate set only; on 2 cores each oversubscribed distributed eigen
    solve costs about 2 s.
    """
    args = ("12", "6") if nprocs == 2 else ("12", "6", "quick")
    par = json.loads(run_mpi(STEPS, nprocs, *args).strip().splitlines()[-1])
    ser = serial_steps
    assert par["ranks"] == nprocs
    # Mesh, assembly, contact manager: exact or to rounding.
    for key in ("cells", "vertices", "edge_facets", "dofs", "num_edge_fixed"):
        assert par[key] == ser[key], key
    assert par["removed_rows_checked"] == ser["removed_rows_checked"]
    # Same nodes in the same order, bit-identical: contact.coordinates are rounded to
    # 1e-12 m, which removes the partition-dependent last bits (0.0 vs 9e-19 was seen).
    assert par["coordinates"] == ser["coordinates"]
    # contact.coordinates are rounded to 1e-12 m (partition-independent last bits); the
    # bilinear test function's gradient is below 80 per metre, so the map error <= 1e-10.
    assert par["values_map_error"] <= 1e-10
    for key in ("norm_A", "norm_B"):
        assert par[key] == pytest.approx(ser[key], rel=1e-12), key
    # Prestress: exact uniaxial N0 and exact strip equilibrium on every partition.
    assert par["paper_n0_error"] < 1e-10
    assert max(par["clamped_strip_errors"]) < 1e-12
    assert par["clamped_extremes"] == pytest.approx(ser["clamped_extremes"], rel=1e-10)
    # Eigen solves and certificates.
    assert _same_load(ser["free_load"], par["free_load"]), (ser["free_load"], par["free_load"])
    if nprocs == 2:
        assert par["eigensolves"] == ser["eigensolves"]
        assert par["candidates"].keys() == ser["candidates"].keys()
    assert "diagonal_pair" in par["candidates"]
    for name, p in par["candidates"].items():
        s = ser["candidates"][name]
        assert p["active"] == s["active"], name
        assert _same_load(s["load"], p["load"]), (name, s["load"], p["load"])
        assert p["feasible"] == s["feasible"], name
        vs, vp = np.array(s["values"]), np.array(p["values"])
        if not s["feasible"]:
            # An infeasible mode's orientation is a tie-break (symmetric modes): compare
            # up to sign. A feasible mode's orientation is determined.
            vp = vp * np.sign(vp @ vs or 1.0)
        assert np.abs(vp - vs).max() < VALUE_ATOL, name
        assert ("certificate" in p) == ("certificate" in s), name
        if "certificate" in s:
            _compare_certificates(s["certificate"], p["certificate"], name)


def _config_on_two_ranks(tmp_path, path):
    """``unibuckle solve --config path`` serially and on 2 ranks: equal results (both)."""
    args = ["--config", str(path)]
    ser = _cli_serial(tmp_path, args)
    par, _ = _cli_parallel(tmp_path, args, 2)
    _compare_results(ser, par, 2)
    return ser, par


def _cli_serial(tmp_path, args):
    out = tmp_path / "serial.json"
    assert cli_main(["solve", *args, "--json", str(out), "--output", str(tmp_path / "vtx1")]) == 0
    return json.loads(out.read_text())


def _cli_parallel(tmp_path, args, nprocs):
    outdir = tmp_path / f"np{nprocs}"
    stdout = run_mpi(CLI, nprocs, str(outdir), "--", *args).strip().splitlines()
    report = json.loads(stdout[-1])
    assert report["status"] == [0] * nprocs, report
    assert report["json_writes"] == [1] + [0] * (nprocs - 1), report  # once, on rank 0
    assert report["vtx_calls"] == [1] * nprocs, report  # collective
    # One summary (two lines, and one per obstacle zone the mesh does not follow exactly).
    assert ": lambda_c = " in stdout[0] and sum(": lambda_c = " in line for line in stdout) == 1
    for name in ("w", "theta"):
        bp = (
            outdir / "vtx" / f"{json.loads((outdir / 'result.json').read_text())['case']}_{name}.bp"
        )
        assert (bp / "md.idx").is_file() and (bp / "md.0").is_file(), bp
        assert any(bp.glob("data.*")), bp
    return json.loads((outdir / "result.json").read_text()), outdir


def _compare_results(ser, par, nprocs):
    assert par["mpi_size"] == nprocs
    for key in ("case", "method", "mesh", "dofs", "constrained_nodes", "contact_nodes", "p_star"):
        assert par[key] == ser[key], key
    for key in ("critical_load_Pa", "free_load_Pa", "ratio_to_free", "buckling_coefficient_k"):
        assert _same_load(ser[key], par[key]), (key, ser[key], par[key])
    assert par["contact_indices"] == ser["contact_indices"]
    np.testing.assert_allclose(
        par["contact_coordinates"], ser["contact_coordinates"], rtol=0, atol=COORD_ATOL
    )
    if ser["certificate"] is not None:
        _compare_certificates(ser["certificate"], par["certificate"], ser["case"])


def test_cli_free_plate_two_ranks(tmp_path):
    """Mpiexec -n 2 gives the serial free load, near the Navier value.

    20x10: the MITC4 error against lambda_RM is 1.4 % there (README, "Verification"),
    so within 2 %.
    """
    args = ["--case", "free", "--nx", "20", "--ny", "10"]
    ser = _cli_serial(tmp_path, args)
    par, outdir = _cli_parallel(tmp_path, args, 2)
    _compare_results(ser, par, 2)
    exact, _ = navier_load_mindlin(1.0e9, 0.3, 0.006, 0.2, 0.1)
    assert par["critical_load_Pa"] == pytest.approx(exact, rel=2e-2)
    # The VTX metadata names the fields written (mode and free mode).
    meta = (outdir / "vtx" / "free_w.bp" / "md.0").read_bytes()
    assert b"w_free" in meta


def test_cli_enumerate_distributed(tmp_path):
    """The paper's enumeration on a tiny distributed case: c2 on 8x4.

    i = 3, two mirror-image feasible sets at p = 1 with equal loads: the tie-break must
    not depend on the ranks.
    """
    args = ["--case", "c2", "--nx", "8", "--ny", "4", "--method", "enumerate"]
    ser = _cli_serial(tmp_path, args)
    par, outdir = _cli_parallel(tmp_path, args, 2)
    _compare_results(ser, par, 2)
    assert par["eigensolves"] == ser["eigensolves"]
    assert ser["details"]["feasible_by_p"] == par["details"]["feasible_by_p"] == [0, 2]
    assert ser["contact_nodes"] == 1 and ser["certificate"]["kkt"]
    meta = (outdir / "vtx" / "c2_w.bp" / "md.0").read_bytes()
    assert b"obstacle_zone" in meta and b"contact" in meta


def test_cli_active_set_distributed(tmp_path):
    """The active-set method (multilevel, several seeds) on c1 20x10 (i = 81).

    Same path (eigensolve count), contact set and load as the serial run.
    """
    args = ["--case", "c1", "--nx", "20", "--ny", "10", "--method", "active-set"]
    ser = _cli_serial(tmp_path, args)
    par, _ = _cli_parallel(tmp_path, args, 2)
    _compare_results(ser, par, 2)
    assert par["eigensolves"] == ser["eigensolves"]
    assert ser["contact_nodes"] > 0 and ser["certificate"]["kkt"]


def test_cli_bad_input_distributed(tmp_path):
    """Bad input found after the distributed set-up: every rank exits with 2, together.

    An obstacle zone holding no mesh node: no hang, nothing written.
    """
    path = tmp_path / "empty.toml"
    zone = "[[0.001, 0.002], [0.001, 0.002]]"
    path.write_text(f"[mesh]\nnx = 8\nny = 4\n[obstacle]\nzone = {zone}\n")
    outdir = tmp_path / "np2"
    report = json.loads(run_mpi(CLI, 2, str(outdir), "--", "--config", str(path)).splitlines()[-1])
    assert report == {"status": [2, 2], "json_writes": [0, 0], "vtx_calls": [0, 0]}
    assert list(outdir.iterdir()) == []  # the folder of --json, made by the harness, empty


def test_cli_stress_gradient_distributed(tmp_path):
    """In-plane bending (normal_stress = [1, -1]) against a whole-plate obstacle on 2 ranks.

    a/b = 4/3, 16x12: the linear edge stress, the prestress and the active set give the
    serial load, contact set and certificate.
    """
    path = tmp_path / "bending.toml"
    path.write_text(
        "[plate]\ncorners = [[0.0, 0.0], [0.4, 0.3]]\nthickness = 0.003\n"
        "[edges.left]\nnormal_stress = [1.0, -1.0]\n"
        "[edges.right]\nnormal_stress = [1.0, -1.0]\n"
        "[mesh]\nnx = 16\nny = 12\n"
        '[obstacle]\nzone = "all"\n[solver]\nmethod = "active-set"\n'
    )
    ser, par = _config_on_two_ranks(tmp_path, path)
    assert ser["certificate"]["kkt"] and ser["ratio_to_free"] > 1.05
    assert par["edge_loads"]["left"]["normal_stress"] == [1.0, -1.0]


def test_cli_several_obstacles_distributed(tmp_path):
    """A polygon zone above the plate and a circle below it, on 2 ranks (c1's plate, 16x8).

    The oriented values (w <= 0 above, w >= 0 below) and the union of the zones' nodes
    are decided on values reduced over the ranks: same load, contact set and certificate.
    """
    path = tmp_path / "two.toml"
    path.write_text(
        "[mesh]\nnx = 16\nny = 8\n"
        "[[obstacles]]\npolygon = [[-0.1, -0.05], [-0.01, -0.05], [-0.01, 0.05], [-0.06, 0.05]]\n"
        '[[obstacles]]\ncircle = {center = [0.05, 0.0], radius = 0.03}\nside = "below"\n'
        '[solver]\nmethod = "active-set"\n'
    )
    ser, _ = _config_on_two_ranks(tmp_path, path)
    assert ser["certificate"]["kkt"] and ser["constrained_nodes"] > 20


def test_cli_interior_point_constraint_on_one_rank(tmp_path):
    """The interior point with constrained nodes on one rank only: no hang, the free load.

    One one-sided point (c1's plate, 16x8): its node is owned by one of the 2 ranks, the
    other owns no constrained node. Its complementarity residual skipped the reduction
    over the ranks there, and the first rank waited in it for ever. The free mode or its
    mirror image meets a single one-sided point, so the critical load is the free load
    (ratio 1), and the serial run's (every load within LOAD_RTOL).
    """
    path = tmp_path / "stud.toml"
    path.write_text(
        "[mesh]\nnx = 16\nny = 8\n"
        '[[points]]\nat = [-0.05, 0.0]\nkind = "one-sided"\nside = "below"\n'
        '[solver]\nmethod = "interior-point"\n'
    )
    ser, par = _config_on_two_ranks(tmp_path, path)
    assert par["method"] == "interior-point" and par["certificate"]["kkt"]
    assert par["constrained_nodes"] == 1
    assert par["critical_load_Pa"] == pytest.approx(ser["free_load_Pa"], rel=LOAD_RTOL)


@pytest.mark.parametrize(("side", "stiffness"), [("above", 2e7), ("above", 5e7), ("both", 1e7)])
def test_cli_foundation_distributed(tmp_path, side, stiffness):
    """A tensionless (side above) and a bilateral (side both) Winkler foundation on 2 ranks.

    0.3 x 0.1 m plate, loaded edges clamped, 24x8: the spring-set iteration takes the
    serial path (same load, pressing nodes and certificate); the bilateral springs are
    part of the stiffness (a free-plate solve). At k_f = 2e7 and 5e7 N/m^3 the loads
    differed by 8e-6 and 5.8e-5 on 1 and 2 ranks while a node within rounding of the
    foundation counted as pressing (tolerances.PRESSING_RTOL; docs/guide/mpi.md).
    """
    path = tmp_path / f"foundation_{side}.toml"
    path.write_text(
        "[plate]\ncorners = [[0.0, 0.0], [0.3, 0.1]]\nthickness = 0.001\n"
        '[edges.left]\nsupport = "clamped"\nnormal_stress = -1.0\n'
        '[edges.right]\nsupport = "clamped"\nnormal_stress = -1.0\n'
        "[mesh]\nnx = 24\nny = 8\n"
        f'[obstacle]\nzone = "all"\nside = "{side}"\nfoundation_stiffness = {stiffness:g}\n'
    )
    ser, par = _config_on_two_ranks(tmp_path, path)
    assert ser["method"] == ("foundation" if side == "above" else "free")
    if side == "above":
        assert ser["certificate"]["kkt"] and ser["contact_nodes"] > 0
        assert par["details"]["foundation_start"] == ser["details"]["foundation_start"]


def test_cli_gmsh_plate_distributed(tmp_path):
    """A plate meshed by gmsh on rank 0 and distributed over 2 ranks.

    An outline with a circular and a polygonal hole, a segment pushed with a stress
    gradient against one held in its plane, an obstacle below.

    Same mesh (cells), load, contact nodes (as coordinates) and certificate as serially.
    """
    pytest.importorskip("gmsh")
    path = tmp_path / "holes.toml"
    path.write_text(
        "[plate]\noutline = [[0, 0], [0.4, 0], [0.4, 0.2], [0.25, 0.2], [0, 0.2]]\n"
        "thickness = 0.004\n"
        "[[plate.holes]]\ncenter = [0.1, 0.1]\nradius = 0.04\n"
        "[[plate.holes]]\noutline = [[0.25, 0.06], [0.33, 0.06], [0.33, 0.14], [0.25, 0.14]]\n"
        "[edges.pushed]\nsegments = [1]\nnormal_stress = [-1.0, -0.5]\n"
        '[edges.held]\nsegments = [4]\ninplane = "clamped"\n'
        "[edges.sides]\nsegments = [0, 2, 3]\n"
        "[mesh]\nsize = 0.025\n"
        '[obstacle]\nzone = "all"\nside = "below"\n[solver]\nmethod = "active-set"\n'
    )
    ser, _ = _config_on_two_ranks(tmp_path, path)
    assert ser["certificate"]["kkt"] and len(ser["mesh"]) == 1


def test_lowrank_certificate_distributed_equals_serial(thin_plate):
    """The low-rank route on 2 ranks: same bound (to the loads' 1e-8), columns and pieces.

    A thin SSSS plate (t/b = 1e-3, 30 x 10 cells, two pencil eigenvalues below its
    load), the contact set of the serial active-set answer; the double-double residuals
    gather their ghost values through a PETSc scatter.
    """
    spec = importlib.util.spec_from_file_location(
        "lowrank_parallel", MPI_SCRIPTS / "lowrank_parallel.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    from unibuckle_fenicsx.algorithms.active_set import solve_active_set
    from unibuckle_fenicsx.model.build import build_problem

    plate = thin_plate("thin", 30, 10)
    with build_problem(plate, MPI.COMM_SELF) as problem:
        active = solve_active_set(problem).active
    serial = module.certificate(MPI.COMM_SELF, 30, 10, active)
    assert serial["method"] == "lowrank-spn" and serial["m"] >= 2, serial
    nodes = ",".join(str(k) for k in active)
    out = run_mpi(MPI_SCRIPTS / "lowrank_parallel.py", 2, "30", "10", nodes)
    par = json.loads(out.strip().splitlines()[-1])
    assert _same_load(par["load"], serial["load"])
    assert (par["method"], par["m"], par["r"], par["pieces"]) == (
        serial["method"],
        serial["m"],
        serial["r"],
        serial["pieces"],
    )
    assert abs(par["value"] - serial["value"]) <= LOAD_RTOL * serial["value"]


def test_a_section_on_two_ranks_equals_one():
    """A small box, hollow, with a rigid core and an elastic one: the serial loads on 2 ranks.

    The contact set is compared by its size (its coordinates: the serial tests').
    """
    spec = importlib.util.spec_from_file_location(
        "section_parallel", MPI_SCRIPTS / "section_parallel.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    serial = module.collect(MPI.COMM_SELF)
    parallel = json.loads(run_mpi(MPI_SCRIPTS / "section_parallel.py", 2).strip().splitlines()[-1])
    # The contact set's numbers are the same on 2 ranks; its DOFs are the partition's
    # (SectionResult: "compare runs by contact_indices"): 1 rank [30, 72, 126, ...],
    # 2 ranks [0, 6, 12, ...] for the same 62 directions.
    (indices, dofs), (p_indices, p_dofs) = (
        serial.pop("rigid core's contact"),
        parallel.pop("rigid core's contact"),
    )
    assert indices == p_indices and len(dofs) == len(p_dofs) == len(indices)
    for name, (load, free, contact, kkt) in serial.items():
        p_load, p_free, p_contact, p_kkt = parallel[name]
        assert _same_load(load, p_load) and _same_load(free, p_free), (name, serial, parallel)
        assert (contact, kkt) == (p_contact, p_kkt), name


def test_a_warning_is_printed_once_on_two_ranks(tmp_path):
    """Every rank computes the run's warnings; rank 0 alone prints them.

    A hollow box 50 x 50 x 5 mm, 0.6 m long, on cells of 12.5 mm: two warnings, the
    coarse cells (4 across a face, fewer than 5) and the column (its critical stress
    0.94 times the Euler stress pi^2 E (b^2/6)/L^2 = 2.40e9 Pa of a thin-walled square
    box). On 2 ranks each was printed twice.
    """
    import os
    import subprocess
    import sys

    from support.processes import mpiexec

    path = tmp_path / "column.toml"
    path.write_text(
        'name = "column"\n'
        '[section]\nshape = "box"\nwidth = 0.05\ndepth = 0.05\nthickness = 0.005\n'
        'length = 0.6\nends = "simply_supported"\n'
        "[material]\nE = 2.1e11\nnu = 0.3\n[load]\naxial_stress = -1.0\n"
        "[obstacle]\ncore = false\n[mesh]\nsize = 0.0125\n"
    )
    script = [sys.executable, "-m", "unibuckle_fenicsx.cli", "solve", "--config", str(path)]
    proc = subprocess.run(
        [mpiexec(), "-n", "2", *script],
        capture_output=True, text=True, env={**os.environ, "OMP_NUM_THREADS": "1"},
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.count("fewer than 5: on cells this coarse") == 1, proc.stderr
    assert proc.stderr.count("times the member's Euler stress") == 1, proc.stderr
    assert proc.stdout.count("column: sigma_cr = ") == 1, proc.stdout


def test_a_section_solved_from_python_logs_its_warnings_once_on_two_ranks():
    """``solve_section`` on 2 ranks from a script logs each warning once, from rank 0.

    The column above (two warnings: the coarse cells, the column's mode), solved by
    ``tests/mpi/section_warnings.py`` with every rank's log on stderr: each warning was
    logged by both ranks. The result keeps both on every rank.
    """
    import os
    import subprocess
    import sys

    from support.processes import mpiexec

    proc = subprocess.run(
        [mpiexec(), "-n", "2", sys.executable, str(MPI_SCRIPTS / "section_warnings.py")],
        capture_output=True, text=True, env={**os.environ, "OMP_NUM_THREADS": "1"},
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["2"], proc.stdout
    assert proc.stderr.count("fewer than 5: on cells this coarse") == 1, proc.stderr
    assert proc.stderr.count("times the member's Euler stress") == 1, proc.stderr
    assert "rank 1 WARNING" not in proc.stderr, proc.stderr
