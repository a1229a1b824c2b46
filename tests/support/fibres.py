r"""A box section as thin fibres: the neutral axis of an effective section.

An independent reference for EN 1993-1-5 4.4(3) (a web's psi from the section with the
effective compression flange and the gross webs): no closed-form centroid, and nothing
of the package. The thin-walled box (mid-line width b, depth d, wall t) is cut into
fibres on its mid-line, each an area at a height z: the webs into ``n`` strips of height
d/n each, a flange into ``n`` strips across its effective width, :math:`b_{e1} = b_{e2} =
\rho b/2` at its two corners (Table 4.1, psi = 1), all at the flange's z = :math:`\pm
d/2`. A plane stress :math:`\sigma = c_0 + c_1 z` on the fibres is fixed by its
resultants, :math:`\sum a \sigma = N` and :math:`\sum a z \sigma = M`, two linear
equations in :math:`c_0, c_1`; in bending (N = 0) it vanishes at the neutral axis
:math:`z' = -c_0/c_1`.
"""

from __future__ import annotations

import numpy as np


def box_fibres(
    width: float, depth: float, thickness: float, rho_top: float, rho_bottom: float, n: int
) -> tuple[np.ndarray, np.ndarray]:
    """(z, area) of the fibres of the box with its flanges' effective widths rho b.

    Both webs gross, ``n`` strips each (their mid-heights); each flange ``n`` strips over
    its two corner parts rho b/2 (where on the width does not change z).
    """
    dz = depth / n
    web = -0.5 * depth + dz * (np.arange(n) + 0.5)
    z = [web, web]
    area = [np.full(n, thickness * dz), np.full(n, thickness * dz)]
    for rho, height in ((rho_top, 0.5 * depth), (rho_bottom, -0.5 * depth)):
        z.append(np.full(n, height))
        area.append(np.full(n, thickness * rho * width / n))
    return np.concatenate(z), np.concatenate(area)


def plane_stress(
    z: np.ndarray, area: np.ndarray, axial: float, moment: float
) -> tuple[float, float]:
    """(c0, c1) of the stress c0 + c1 z on the fibres whose resultants are N, M about z = 0."""
    first = float((area * z).sum())
    matrix = np.array([[area.sum(), first], [first, (area * z * z).sum()]])
    c0, c1 = np.linalg.solve(matrix, np.array([axial, moment]))
    return float(c0), float(c1)


def web_psi(
    width: float,
    depth: float,
    thickness: float,
    axial_stress: float,
    bending_stress: float,
    rho: float,
    n: int = 4000,
) -> float:
    """A web's psi = sigma_2/sigma_1 (compression the larger) by 4.4(3), on the fibres.

    The compression flange (top for ``bending_stress`` < 0, at z_c = +d/2; else bottom)
    reduced to ``rho``, the rest gross: the neutral axis z' where the fibres' plane
    stress under a moment alone vanishes. The web's stress: the axial part plus the
    bending part, linear through z' and equal at z_c to -|bending_stress| (tension > 0).
    """
    top = bending_stress < 0.0
    z_c = 0.5 * depth if top else -0.5 * depth
    fibres = box_fibres(width, depth, thickness, rho if top else 1.0, 1.0 if top else rho, n)
    c0, c1 = plane_stress(*fibres, 0.0, 1.0)
    neutral = -c0 / c1

    def stress(z: float) -> float:
        return axial_stress - abs(bending_stress) * (z - neutral) / (z_c - neutral)

    ends = [-stress(0.5 * depth), -stress(-0.5 * depth)]  # compression > 0
    return min(ends) / max(ends)
