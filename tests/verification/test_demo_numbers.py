"""Each demo's pages quote numbers that ``make demo`` stored; one of each is pinned here.

The expected values are not the demos' own: an analytic formula worked out in this file,
an exact property of the discretisation, another algorithm of the package solving the
same problem, or the paper's statement. The stored files are ``figures/*/results.json``,
``figures/garland/*.jsonl`` and ``figures/quickstart/output.txt`` (pinned in
``tests/verification/test_quickstart.py``). The stored numbers are records (eight significant
digits, ``unibuckle_fenicsx.results.record``): a comparison with them is good to
:data:`RECORD` (the rounding of one number, at most half of it) and no closer.
"""

from __future__ import annotations

import json
import math
import warnings

from mpi4py import MPI

import pytest

from support.paths import ROOT
from unibuckle_fenicsx import paper_case, solve
from unibuckle_fenicsx.results import RECORD_DIGITS

FIGURES = ROOT / "figures"
#: The relative resolution of a stored number: one unit of its last (eighth) digit.
RECORD = 10.0 ** (1 - RECORD_DIGITS)
serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial solves")


def _stored(case: str, mesh: list[int]) -> dict:
    data = json.loads((FIGURES / case / "results.json").read_text())
    return next(r for r in data["results"] if r["mesh"] == mesh)


def _navier_mindlin(E, nu, t, a, b, kappa=5 / 6):
    """Reissner-Mindlin critical stress of the SSSS plate (n = 1, best m), by hand."""
    D, G = E * t**3 / (12 * (1 - nu**2)), E / (2 * (1 + nu))

    def stress(m):
        kirchhoff = (m * b / a + a / (m * b)) ** 2 * math.pi**2 * D / (t * b**2)
        return kirchhoff / (1 + math.pi**2 * D * (m**2 / a**2 + 1 / b**2) / (kappa * G * t))

    return min(stress(m) for m in range(1, 21))


def test_free_plate_converges_to_navier():
    """demo_free_plate: 80 x 80 within 5e-4 of Navier, 16 times closer than 20 x 20 (h^2)."""
    exact = _navier_mindlin(1.0e9, 0.3, 0.006, 0.2, 0.1)
    assert exact == pytest.approx(12.7559e6, rel=1e-5)  # the paper's plate, two half-waves
    fine = _stored("free", [80, 80])["critical_load_Pa"] / exact - 1
    coarse = _stored("free", [20, 20])["critical_load_Pa"] / exact - 1
    assert 0 < fine < 5e-4
    assert 12 < coarse / fine < 20, (coarse, fine)


@serial
@pytest.mark.parametrize("case", ["c1", "c2", "c3"])
def test_obstacle_demos_by_another_algorithm(case):
    """demo_obstacle_c*: the interior-point route gives the active set's stored load."""
    stored = _stored(case, [20, 20])
    spec = paper_case(case, 20, 20).with_solver(method="interior-point")
    with solve(spec, MPI.COMM_SELF) as analysis:
        load = analysis.result.critical_load_Pa
        assert analysis.certificate.kkt
    assert stored["method"] != "interior-point"
    assert load == pytest.approx(stored["critical_load_Pa"], rel=RECORD)


def test_garland_repeats_its_square_plate():
    """demo_garland: at a/b = 1, 2, 3, 4 the bilateral SSSS k is the same number.

    The plate's width carries 12 cells and its length 12 per unit of a/b, so each
    half-wave of the m = a/b mode is the same 12 x 12 discrete square plate: the discrete
    k repeats exactly (to the eigen solver's tolerance), whatever the mesh error; from
    three stored numbers, to three times their resolution.
    """
    lines = [
        json.loads(line) for line in (FIGURES / "garland" / "ssss.jsonl").open() if line.strip()
    ]
    k = {
        line["point"]["plate.length"]: line["buckling_coefficient_k"]
        * line["free_load_Pa"]
        / line["critical_load_Pa"]
        for line in lines
    }
    for phi in (2.0, 3.0, 4.0):
        assert k[phi] == pytest.approx(k[1.0], rel=3 * RECORD), (phi, k[phi], k[1.0])
    assert k[1.0] == pytest.approx(4.0, rel=0.02)  # Navier's k = 4, MITC4 at b/12


def test_nonlinear_path_reads_the_linear_load():
    """demo_nonlinear: the path's knee gives the eigen solve's load to 1e-3.

    The methods page's claim ("the Southwell load equals the linear one to 1e-3") for the
    smallest imperfection of the study.
    """
    data = json.loads((FIGURES / "nonlinear" / "results.json").read_text())
    run = min(data["study"], key=lambda r: r["imperfection"])
    assert run["completed"]
    for key in ("southwell_load_Pa", "inflection_load_Pa"):
        assert run[key] == pytest.approx(data["linear_critical_load_Pa"], rel=1e-3), key


def test_column_design_output_by_hand():
    """demo_column: EN 1993-1-5's rho and design stress from the stored sigma_cr, by hand."""
    data = json.loads((FIGURES / "column" / "results.json").read_text())
    fy, sigma = 355.0, data["critical_stress_MPa"]  # MPa: S355, the computed sigma_cr
    slenderness = math.sqrt(fy / sigma)  # (4.3)
    rho = min(1.0, (slenderness - 0.055 * (3 + 1)) / slenderness**2) if slenderness > 0.673 else 1
    assert data["design"]["relative_slenderness"] == pytest.approx(slenderness, rel=RECORD)
    assert data["design"]["reduction_factor"] == pytest.approx(rho, rel=RECORD)
    assert data["design_stress_MPa"] == pytest.approx(rho * fy, rel=RECORD)


def _rho_internal_psi_1(fy: float, sigma: float) -> float:
    """EN 1993-1-5 eq. (4.2) at psi = 1: 1 up to slenderness 0.673, else (l - 0.22)/l^2."""
    slenderness = math.sqrt(fy / sigma)
    return 1.0 if slenderness <= 0.673 else min(1.0, (slenderness - 0.22) / slenderness**2)


def test_column_page_gives_the_design_values_at_the_lower_bound():
    """demo_column: the page's safe values are EN 1993-1-5's at the verified lower bound.

    The face's critical state is a KKT point, not proven the lowest: its critical stress
    may lie as low as the verified lower bound (the free face's, by interlacing), where
    the slenderness is larger and rho smaller. The page gave rho = 0.694 and rho f_y =
    246.2 MPa at the KKT load as the output; the safe values, by hand from the stored lower
    bound 190.37 MPa: slenderness sqrt(355/190.37) = 1.366, rho = (1.366 - 0.22)/1.366^2
    = 0.614, rho f_y = 218.1 MPa; and each tie spacing's rho at its own lower bound.
    """
    data = json.loads((FIGURES / "column" / "results.json").read_text())
    assert not data["certificate"]["global_optimum_proven"]
    fy, low = 355.0, data["lower_bound_MPa"]  # MPa
    assert low == pytest.approx(data["free_stress_MPa"], rel=RECORD)  # interlacing
    rho = _rho_internal_psi_1(fy, low)
    assert rho == pytest.approx(0.6143, abs=1e-4)
    assert data["design_lower_bound"]["reduction_factor"] == pytest.approx(rho, rel=RECORD)
    assert data["design_stress_lower_bound_MPa"] == pytest.approx(rho * fy, rel=RECORD)
    assert rho < data["design"]["reduction_factor"]
    page = (ROOT / "docs" / "demos" / "column.md").read_text()
    assert f"(safe)** | {math.sqrt(fy / low):.3f} | 1 | **{rho:.3f}** | **{rho * fy:.1f}** |" in (
        page
    )
    lines = [
        json.loads(line)
        for line in (FIGURES / "column" / "tie_spacing.jsonl").open()
        if line.strip()
    ]
    safe = []
    for line in lines:
        rho = _rho_internal_psi_1(355e6, line["lower_bound_Pa"])
        assert line["design"]["lower_bound"]["reduction_factor"] == pytest.approx(rho, rel=RECORD)
        assert rho <= line["design"]["reduction_factor"]
        safe.append(f"**{rho:.3f}**")
    assert f"| **ρ (4.2) at the lower bound (safe)** | {' | '.join(safe)} |" in page, safe


@serial
def test_penalty_gap_falls_as_one_over_rho():
    """study_penalty: the penalty gap, 3.0e-8 at rho = 1e4 on c1 at 12 x 6, falls as 1/rho.

    The page's table gives the gap at rho = 1e4; at rho = 1e6 it is 100 times smaller.
    The exact load is the active set's, proven optimal by its certificate.
    """
    spec = paper_case("c1", 12, 6)
    with solve(spec.with_solver(method="active-set"), MPI.COMM_SELF) as analysis:
        exact = analysis.result.critical_load_Pa
        assert analysis.certificate.status == "proven"
    gaps = []
    for rho in (1e4, 1e6):
        with warnings.catch_warnings():  # the penalty mode fails its certificate: expected
            warnings.simplefilter("ignore")
            with solve(spec.with_solver(method="penalty", penalty=rho), MPI.COMM_SELF) as a:
                gaps.append((exact - a.result.critical_load_Pa) / exact)
    assert gaps[0] == pytest.approx(3.0e-8, rel=0.05)
    assert gaps[0] / gaps[1] == pytest.approx(100, rel=0.05)


@serial
@pytest.mark.slow
def test_realistic_plate_by_another_algorithm():
    """demo_realistic: the active set gives the interior point's stored stress.

    The demo's plate (a steel plate with an opening against a concrete face, under
    compression and shear) solved again by the multilevel active set, whose answer is
    also certified; measured: the two agree to 1e-12, the active set's proven optimal.
    """
    import re

    from unibuckle_fenicsx import problem_from_dict

    # The demo's problem mapping, with its full-size cell (not --coarse), as it defines it.
    source = (ROOT / "demos" / "demo_realistic.py").read_text()
    size = re.search(r"^SIZE = \S+ if args.coarse else (\S+)", source, flags=re.M)
    tau = re.search(r"^TAU = (\S+)", source, flags=re.M)
    assert size is not None and tau is not None
    block = source[
        source.index("PLATE = {") : source.index("# %% [markdown]", source.index("PLATE = {"))
    ]
    plate: dict = {"SIZE": float(size.group(1)), "TAU": float(tau.group(1))}
    exec(block, plate)

    stored = json.loads((FIGURES / "realistic" / "results.json").read_text())
    spec = problem_from_dict(plate["PLATE"]).with_solver(method="active-set")
    with solve(spec, MPI.COMM_SELF) as analysis:
        assert analysis.certificate.kkt
        stress = analysis.result.critical_load_Pa / 1e6  # MPa
    assert stored["method"] == "interior-point"
    assert stress == pytest.approx(stored["critical_stress_MPa"], rel=RECORD)


def test_tie_spacing_table_is_the_study_s():
    """The table of the real-plates page is study_ties.py's stored sweep, to its digits.

    And the study's plate without ties is Navier's long SSSS plate, k = 4 (the mesh's
    error at b/16 within 1 %); with the obstacle and no ties, the thin-plate limit 9/2
    (an end buckle that touches down; verification/thin_plates) within 1 %.
    """
    import re

    rows = json.loads((FIGURES / "ties" / "results.json").read_text())["rows"]
    page = (ROOT / "docs" / "verification" / "real_plates_restraints.md").read_text()
    cells = {
        label: [float(x) for x in re.findall(r"\| ([0-9.]+)", line)]
        for line in page.splitlines()
        for label in ("against the obstacle", "bilateral (no obstacle)")
        if line.startswith(f"| k, {label}")
    }
    assert [round(r["k"], 2) for r in rows] == cells["against the obstacle"]
    assert [round(r["k_bilateral"], 2) for r in rows] == cells["bilateral (no obstacle)"]
    none = rows[-1]
    assert none["k_bilateral"] == pytest.approx(4.0, rel=0.01)
    assert none["k"] == pytest.approx(4.5, rel=0.01)


@serial
def test_garland_clamped_point_ends_at_the_active_sets_arrangement():
    """demo_garland, loaded edges clamped, a/b = 2 (24 x 12 cells), with the bracket asked for.

    Without it the interior point ends at four lines of contact across the plate; the
    certificate refutes that point with an admissible mode of lower load, and the solve,
    continued from it, ends at two lines. The expected load is the multilevel active
    set's on the same plate (another algorithm, which reaches two lines by itself): the
    stored point equals it to the record's resolution, and is proven or bracketed.
    """
    from unibuckle_fenicsx.spec import problem_from_dict

    stored = next(
        json.loads(line)
        for line in (FIGURES / "garland" / "loaded_edges_clamped.jsonl").open()
        if line.strip() and json.loads(line)["point"]["plate.length"] == 2.0
    )
    assert stored["certificate"]["status"] in ("proven", "bracketed"), stored["certificate"]
    data = stored["input"]  # its cell size b/12 rounded to eight digits (a record) gives 25 x 13
    data["mesh"]["size"] = 1.0 / stored["mesh"][1]
    spec = problem_from_dict(data).with_solver(method="active-set", bracket=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with solve(spec, MPI.COMM_SELF) as analysis:
            load = analysis.result.critical_load_Pa
            assert analysis.result.mesh == stored["mesh"]
    assert stored["critical_load_Pa"] == pytest.approx(load, rel=RECORD)
