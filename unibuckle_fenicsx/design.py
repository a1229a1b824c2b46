r"""Design output: the plate slenderness and reduction factor of EN 1993-1-5 from this σ_cr.

EN 1993-1-5:2006 (Eurocode 3, *Design of steel structures*, part 1-5, *Plated structural
elements*, with its corrigendum AC:2009), clause 4.4:

- (4.3): the relative plate slenderness :math:`\bar\lambda_p = \sqrt{f_y/\sigma_{cr}}`;
- (4.2): for internal compression elements the reduction factor
  :math:`\rho = 1` for :math:`\bar\lambda_p \le 0.5 + \sqrt{0.085 - 0.055\psi}`, else
  :math:`\rho = (\bar\lambda_p - 0.055(3 + \psi))/\bar\lambda_p^2 \le 1`;
- Table 4.1: :math:`\psi = \sigma_2/\sigma_1`, the ratio of the edge stresses with
  :math:`\sigma_1` the larger compression, for :math:`1 \ge \psi \ge -3`.

Here :math:`\sigma_{cr}` is the critical state this package computes: the largest
compressive normal stress on a loaded edge at the critical load (the fixed part plus
:math:`\lambda_c` times the scaled one), and :math:`\psi` the stress ratio along that
edge. The code's formula (Winter's, with the stress-ratio term) was calibrated on
plates that buckle freely to both sides (bilateral buckling); with an obstacle this
:math:`\sigma_{cr}` is the unilateral one, and applying (4.2) to it is outside that
calibration: the output says so. With shear in the load, EN 1993-1-5 combines the stresses
by the reduced stress method (section 10, :math:`\bar\lambda_p = \sqrt{\alpha_{ult,k}/
\alpha_{cr}}`), which is not done here: the output then notes that ρ is the direct
stress's.
"""

from __future__ import annotations

import math
from typing import Any

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.spec import DesignSpec, ProblemSpec, stress_ends

__all__ = ["CLAUSES", "design_output", "reduction_factor"]

#: The clauses the design output rests on.
CLAUSES = (
    "EN 1993-1-5:2006+AC:2009, 4.4(2), eq. (4.2): reduction factor rho of an internal "
    "compression element; eq. (4.3): relative slenderness; Table 4.1: stress ratio psi"
)

#: Said with every design output.
CALIBRATION = (
    "EN 1993-1-5's rho (4.2) was calibrated on plates buckling freely to both sides "
    "(bilateral buckling); it is applied here to this package's sigma_cr"
)


def reduction_factor(slenderness: float, psi: float) -> float:
    r""":math:`\rho` of EN 1993-1-5 (4.2), internal compression elements, :math:`\psi \ge -3`."""
    if not -3.0 <= psi <= 1.0:
        raise InputError(f"psi must lie in [-3, 1] (EN 1993-1-5, Table 4.1), got {psi!r}")
    if slenderness <= 0.5 + math.sqrt(0.085 - 0.055 * psi):
        return 1.0
    return min(1.0, (slenderness - 0.055 * (3.0 + psi)) / slenderness**2)


def _critical_edge_stress(spec: ProblemSpec, load: float) -> tuple[float, float, str]:
    """(sigma_1, sigma_2, edge): the largest compression at the critical state (Pa, > 0).

    Compression positive. sigma_2 is the other end of the same edge.
    """
    best = (0.0, 0.0, "")
    factor = spec.load.fixed_factor
    for e in spec.plate.edges:
        scaled, fixed = stress_ends(e.normal_stress), stress_ends(e.fixed_normal_stress)
        ends = [-(factor * f + load * s) for s, f in zip(scaled, fixed, strict=True)]
        for k in (0, 1):
            if ends[k] > best[0]:
                best = (ends[k], ends[1 - k], e.name)
    return best


def design_output(spec: ProblemSpec, design: DesignSpec, load: float) -> dict[str, Any]:
    """The design quantities of the critical load ``load`` (JSON-ready), see the docstring."""
    sigma1, sigma2, edge = _critical_edge_stress(spec, load)
    out: dict[str, Any] = {
        "yield_stress_Pa": design.yield_stress,
        "partial_factor": design.partial_factor,
        "edge": edge,
        "sigma_cr_Pa": sigma1,
        "clauses": CLAUSES,
        "notes": [CALIBRATION],
    }
    if spec.all_obstacles or spec.one_sided_points:
        out["notes"].append(
            "with an obstacle sigma_cr is the unilateral critical stress: outside the "
            "calibration of (4.2)"
        )
    shear = any(
        any(stress_ends(e.shear_stress)) or any(stress_ends(e.fixed_shear_stress))
        for e in spec.plate.edges
    )
    if shear:
        out["notes"].append(
            "the load has shear: EN 1993-1-5 section 10 (reduced stress method) would "
            "combine it; rho here is the direct stress's, with this sigma_cr"
        )
    psi = sigma2 / sigma1 + 0.0  # no -0.0
    out["psi"] = psi
    slenderness = math.sqrt(design.yield_stress / sigma1)
    out["relative_slenderness"] = slenderness
    if psi < -3.0:
        out["reduction_factor"] = None
        out["notes"].append(f"psi = {psi:.3g} < -3: outside Table 4.1, no rho")
        return out
    rho = reduction_factor(slenderness, min(psi, 1.0))
    out["reduction_factor"] = rho
    out["reduced_design_stress_Pa"] = rho * design.yield_stress / design.partial_factor
    return out
