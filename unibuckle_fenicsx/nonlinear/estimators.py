r"""Buckling loads read off a load path: Southwell's method and the inflection load.

The knee of the path max :math:`|w|` against :math:`\lambda` is read off twice,
independently of the linear eigen solve:

- **Southwell's method** (R. V. Southwell, *On the analysis of experimental observations
  in problems of elastic stability*, Proc. R. Soc. Lond. A 135, 1932, 601–616): below the
  critical load the additional deflection :math:`\delta_w = \max|w| - \delta t` of an
  imperfect structure grows as :math:`\delta_w = a\lambda/(\lambda_c - \lambda)`, i.e.
  :math:`\delta_w/\lambda = a/\lambda_c + \delta_w/\lambda_c`: a straight line in
  :math:`\delta_w` of slope :math:`1/\lambda_S`. Fitted on the path's points with
  :data:`SOUTHWELL_WINDOW` (:math:`0.5\,\lambda_i \le \lambda \le 0.95\,\lambda_i`, with
  :math:`\lambda_i` the inflection load) and :math:`\delta_w \le t/10` (small deflection:
  the relation is linear theory);
- the **inflection load** :math:`\lambda_i`: where max :math:`|w|` rises most steeply,
  the maximum of :math:`d\max|w|/d\lambda` by central differences on the path (uneven
  steps), refined by the vertex of the parabola through the largest slope and its two
  neighbours. For a stable symmetric bifurcation (plates) it tends to :math:`\lambda_c`
  as :math:`\delta \to 0`.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

__all__ = [
    "SOUTHWELL_MAX_DEFLECTION",
    "SOUTHWELL_WINDOW",
    "inflection_load",
    "southwell_load",
    "southwell_window",
]

#: Southwell fit window: loads between these fractions of the inflection load.
SOUTHWELL_WINDOW = (0.5, 0.95)
#: ... and additional deflections up to this fraction of the thickness.
SOUTHWELL_MAX_DEFLECTION = 0.1


def southwell_window(
    loads: npt.ArrayLike,
    max_w: npt.ArrayLike,
    initial: float,
    knee: float,
    thickness: float,
) -> npt.NDArray[np.bool_]:
    r"""The path points Southwell's fit uses.

    Those with :math:`\lambda` within :data:`SOUTHWELL_WINDOW` times ``knee`` and an
    additional deflection :math:`0 < \delta_w = \max|w| - w_0 \le`
    :data:`SOUTHWELL_MAX_DEFLECTION` t.
    """
    lam = np.asarray(loads, dtype=float)
    dw = np.asarray(max_w, dtype=float) - initial
    lo, hi = SOUTHWELL_WINDOW
    mask = (lam >= lo * knee) & (lam <= hi * knee) & (dw > 0.0)
    return np.asarray(mask & (dw <= SOUTHWELL_MAX_DEFLECTION * thickness), dtype=bool)


def southwell_load(
    loads: npt.ArrayLike,
    max_w: npt.ArrayLike,
    initial: float,
    knee: float,
    thickness: float,
) -> tuple[float | None, int]:
    r"""Southwell's estimate of the critical load from a path below its knee.

    Fits :math:`\delta_w/\lambda = a + \delta_w/\lambda_S` (least squares) on the
    points of :func:`southwell_window`, where :math:`\delta_w = \max|w| - w_0`.

    Args:
        loads: :math:`\lambda` along the path.
        max_w: max :math:`|w|` along the path.
        initial: max :math:`|w_0|`, the imperfection.
        knee: The load the window is relative to (the inflection load).
        thickness: t.

    Returns:
        :math:`\lambda_S` (None with fewer than three points in the window or a
        non-positive slope) and the number of points fitted.
    """
    lam = np.asarray(loads, dtype=float)
    dw = np.asarray(max_w, dtype=float) - initial
    mask = southwell_window(lam, max_w, initial, knee, thickness)
    count = int(mask.sum())
    if count < 3:
        return None, count
    slope, _ = np.polyfit(dw[mask], dw[mask] / lam[mask], 1)
    return (float(1.0 / slope) if slope > 0.0 else None), count


def inflection_load(loads: npt.ArrayLike, max_w: npt.ArrayLike) -> float | None:
    r"""The load where max :math:`|w|` rises most steeply along the path.

    Central differences on uneven steps (second order) at the interior points; the
    largest slope and its two neighbours define a parabola whose vertex is returned
    (kept within the neighbours' loads).

    Returns:
        The inflection load, or None if the steepest slope is at the path's first or
        last interior point (the path does not pass the knee).
    """
    lam = np.asarray(loads, dtype=float)
    w = np.asarray(max_w, dtype=float)
    if lam.size < 5 or np.any(np.diff(lam) <= 0.0):
        keep = np.concatenate([[True], np.diff(lam) > 0.0]) if lam.size else lam.astype(bool)
        lam, w = lam[keep], w[keep]
        if lam.size < 5:
            return None
    h0 = lam[1:-1] - lam[:-2]
    h1 = lam[2:] - lam[1:-1]
    slope = (
        -h1 / (h0 * (h0 + h1)) * w[:-2]
        + (h1 - h0) / (h0 * h1) * w[1:-1]
        + h0 / (h1 * (h0 + h1)) * w[2:]
    )
    k = int(np.argmax(slope))
    if k == 0 or k == slope.size - 1:
        return None
    x = lam[k : k + 3]  # interior points k-1, k, k+1 of slope <-> lam[k], lam[k+1], lam[k+2]
    y = slope[k - 1 : k + 2]
    a, b, _ = np.polyfit(x - x[1], y, 2)
    vertex = x[1] - b / (2 * a) if a < 0.0 else x[1]
    return float(np.clip(vertex, x[0], x[2]))
