r"""Design output: EN 1993-1-5 slenderness and reduction factor from this package's σ_cr.

Expected values are the formulas of EN 1993-1-5:2006+AC:2009, 4.4(2), written out here
by hand: :math:`\bar\lambda_p = \sqrt{f_y/\sigma_{cr}}` (4.3) and, for internal
compression elements, :math:`\rho = (\bar\lambda_p - 0.055(3+\psi))/\bar\lambda_p^2`
above :math:`\bar\lambda_p = 0.5 + \sqrt{0.085 - 0.055\psi}`, 1 below (4.2). The
threshold is the root of :math:`\lambda^2 - \lambda + 0.055(3 + \psi) = 0`, so ρ is
continuous there (1 on both sides); for ψ = 1 it is the familiar 0.673.
"""

from __future__ import annotations

import math

from mpi4py import MPI

import pytest

from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.design import reduction_factor
from unibuckle_fenicsx.spec import problem_from_dict, problem_to_dict


def plate(edges, *, obstacle=None, design=None, **extra):
    data = {
        "units": "mm-N-MPa",
        "plate": {"corners": [[0, 0], [600, 200]], "thickness": 4.0},
        "material": {"E": 210000.0, "nu": 0.3},
        "edges": edges,
        "mesh": {"nx": 12, "ny": 4},
        "design": design or {"yield_stress": 355.0, "partial_factor": 1.1},
        **extra,
    }
    if obstacle:
        data["obstacle"] = obstacle
    return problem_from_dict(data)


def result(spec):
    with solve(spec, MPI.COMM_WORLD) as analysis:
        return analysis.result


@pytest.mark.parametrize(
    "slenderness, psi, rho",
    [
        (0.5, 1.0, 1.0),
        (1.0, 1.0, 0.78),  # (1 - 0.22) / 1
        (2.0, 1.0, 0.445),  # (2 - 0.22) / 4
        (1.0, -1.0, 0.89),  # (1 - 0.11) / 1
        (1.5, 0.0, (1.5 - 0.165) / 2.25),
        (0.79, 0.0, 1.0),  # below 0.5 + sqrt(0.085) = 0.7915
        (1.2, -3.0, 1.0 / 1.2),  # (1.2 - 0) / 1.44
    ],
)
def test_reduction_factor_is_en_1993_1_5_eq_4_2(slenderness, psi, rho):
    assert reduction_factor(slenderness, psi) == pytest.approx(rho, rel=1e-12)


@pytest.mark.parametrize("psi", [1.0, 0.5, 0.0, -1.0, -2.0, -3.0])
def test_reduction_factor_is_continuous_at_its_threshold(psi):
    threshold = 0.5 + math.sqrt(0.085 - 0.055 * psi)
    assert reduction_factor(threshold, psi) == 1.0
    assert reduction_factor(threshold * (1 + 1e-9), psi) == pytest.approx(1.0, abs=1e-8)
    with pytest.raises(ValueError, match=r"psi must lie in \[-3, 1\]"):
        reduction_factor(1.0, -3.5)


def test_design_keys_are_read_converted_and_written_back():
    spec = plate({"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}})
    assert spec.design.yield_stress == pytest.approx(355e6) and spec.design.partial_factor == 1.1
    assert problem_from_dict(problem_to_dict(spec, units="mm-N-MPa")) == spec
    assert problem_to_dict(spec, units="mm-N-MPa")["design"]["yield_stress"] == pytest.approx(355)


@pytest.mark.parametrize(
    "design, extra, match",
    [
        ({"yield_stress": 0.0}, {}, r"design\.yield_stress must be > 0 Pa"),
        ({"yield_stress": 355.0, "partial_factor": -1}, {}, r"design\.partial_factor must be > 0"),
        ({"partial_factor": 1.0}, {}, r"\[design\] needs yield_stress"),
        ({"yield_stress": 355.0, "gamma": 1.0}, {}, r"unknown key\(s\) \['gamma'\] in \[design\]"),
    ],
)
def test_bad_design_tables_are_refused(design, extra, match):
    with pytest.raises(ValueError, match=match):
        plate({"left": {"normal_stress": -1.0}}, design=design, **extra)


def test_design_needs_a_compressive_edge_stress():
    edges = {name: {"inplane": "clamped"} for name in ("left", "right", "bottom", "top")}
    with pytest.raises(ValueError, match=r"design: the EN 1993-1-5 output takes sigma_cr"):
        plate(
            edges,
            load={"temperature": 1.0},
            material={"E": 210000.0, "nu": 0.3, "thermal_expansion": 1.2e-5},
        )


def test_uniform_compression():
    """Uniform: psi = 1, sigma_cr = lambda_c; slenderness, rho, rho f_y / gamma_M1 by hand."""
    out = result(plate({"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}))
    d = out.design
    assert d["sigma_cr_Pa"] == out.critical_load_Pa and d["psi"] == 1.0
    slenderness = math.sqrt(355e6 / out.critical_load_Pa)
    assert d["relative_slenderness"] == pytest.approx(slenderness, rel=1e-14)
    rho = min(1.0, (slenderness - 0.22) / slenderness**2) if slenderness > 0.5 + 0.03**0.5 else 1
    assert d["reduction_factor"] == pytest.approx(rho, rel=1e-14)
    assert d["reduced_design_stress_Pa"] == pytest.approx(rho * 355e6 / 1.1, rel=1e-14)
    assert "calibrated on plates buckling freely to both sides" in d["notes"][0]
    assert "4.4(2), eq. (4.2)" in d["clauses"]
    assert "EN 1993-1-5: sigma_cr" in out.summary()


def test_stress_gradient_obstacle_shear_and_fixed_part():
    """The critical state's edge stresses give psi; notes for the obstacle and the shear."""
    edges = {
        "left": {"normal_stress": [-1.0, 0.0], "fixed_normal_stress": [-20.0, 20.0]},
        "right": {"normal_stress": [-1.0, 0.0], "fixed_normal_stress": [-20.0, 20.0]},
        "bottom": {"fixed_shear_stress": 5.0},
        "top": {"fixed_shear_stress": 5.0},
    }
    edges["left"]["fixed_shear_stress"] = edges["right"]["fixed_shear_stress"] = -5.0
    out = result(plate(edges, obstacle={"zone": "all"}))
    lam = out.critical_load_Pa
    sigma1, sigma2 = 20e6 + lam, -20e6  # compression positive, at y = 0 and y = b
    d = out.design
    assert d["sigma_cr_Pa"] == pytest.approx(sigma1, rel=1e-14)
    assert d["psi"] == pytest.approx(sigma2 / sigma1, rel=1e-14)
    assert any("unilateral" in n for n in d["notes"]) and any("section 10" in n for n in d["notes"])
