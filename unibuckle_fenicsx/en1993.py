r"""EN 1993-1-5, clause 4.4: the reduction factor and the buckling factors, as numbers.

EN 1993-1-5:2006 (Eurocode 3, *Design of steel structures*, part 1-5, *Plated structural
elements*, with its corrigendum AC:2009), clause 4.4(2), distinguishes two elements by
their edges parallel to the direct stress (the *unloaded* edges):

- an **internal** compression element (both unloaded edges supported), Table 4.1:
  :math:`\rho = 1` for :math:`\bar\lambda_p \le 0.5 + \sqrt{0.085 - 0.055\psi}`, else
  :math:`\rho = (\bar\lambda_p - 0.055(3 + \psi))/\bar\lambda_p^2 \le 1` (eq. (4.2)),
  for :math:`1 \ge \psi \ge -3`;
- an **outstand** compression element (one unloaded edge free), Table 4.2:
  :math:`\rho = 1` for :math:`\bar\lambda_p \le 0.748`, else
  :math:`\rho = (\bar\lambda_p - 0.188)/\bar\lambda_p^2 \le 1` (eq. (4.3)); its table has
  two rows, by where the larger compression :math:`\sigma_1` acts: at the free edge
  (:math:`1 \ge \psi \ge -3`), or at the supported edge (:math:`1 \ge \psi \ge -1`).

:math:`\psi = \sigma_2/\sigma_1` is the ratio of the stresses at the two ends of the
loaded edge, :math:`\sigma_1` the larger compression. The tables' buckling factors
:math:`k_\sigma` (long plates, hinged edges) are given for comparison with the computed
:math:`\sigma_{cr}`; the slenderness here is :math:`\bar\lambda_p = \sqrt{f_y/\sigma_{cr}}`
(4.4(2)) with this package's :math:`\sigma_{cr}`. The formulas are a few lines each and
no maintained library implements them for a given :math:`\sigma_{cr}`, hence this module;
it has no dependency, so that the problem checks (:mod:`unibuckle_fenicsx.spec`) can
refuse, before any solve, a stress ratio outside the tables.
"""

from __future__ import annotations

import math

from unibuckle_fenicsx.errors import InputError

__all__ = [
    "ELEMENTS",
    "INTERNAL",
    "OUTSTAND",
    "buckling_factor",
    "psi_range",
    "reduction_factor",
    "table_row",
]

#: An element with both unloaded edges supported (EN 1993-1-5 Table 4.1).
INTERNAL = "internal"
#: An element with one unloaded edge free (EN 1993-1-5 Table 4.2).
OUTSTAND = "outstand"
#: The elements of EN 1993-1-5 4.4(2).
ELEMENTS = (INTERNAL, OUTSTAND)


def table_row(element: str, free_edge_most_compressed: bool) -> str:
    """The table and row of EN 1993-1-5 that describe ``element`` (for the output)."""
    if element == INTERNAL:
        return "Table 4.1 (internal compression element)"
    where = "free" if free_edge_most_compressed else "supported"
    return f"Table 4.2 (outstand compression element, larger compression at the {where} edge)"


def psi_range(element: str, free_edge_most_compressed: bool = True) -> tuple[float, float]:
    r"""(lowest, highest) :math:`\psi` the table of ``element`` covers.

    Args:
        element: :data:`INTERNAL` or :data:`OUTSTAND`.
        free_edge_most_compressed: For an outstand, whether :math:`\sigma_1` acts at the
            free edge (Table 4.2, upper row: down to -3) or at the supported one (lower
            row: down to -1).
    """
    if element == OUTSTAND and not free_edge_most_compressed:
        return (-1.0, 1.0)
    return (-3.0, 1.0)


def _check(element: str, psi: float, free_edge_most_compressed: bool) -> None:
    if element not in ELEMENTS:
        raise InputError(f"element must be one of {ELEMENTS}, got {element!r}")
    low, high = psi_range(element, free_edge_most_compressed)
    if not low <= psi <= high:
        table = "Table 4.1" if element == INTERNAL else "Table 4.2"
        raise InputError(f"psi must lie in [{low:g}, {high:g}] (EN 1993-1-5, {table}), got {psi!r}")


def reduction_factor(
    slenderness: float,
    psi: float,
    element: str = INTERNAL,
    free_edge_most_compressed: bool = True,
) -> float:
    r""":math:`\rho` of EN 1993-1-5 4.4(2) (eq. (4.2) internal, (4.3) outstand).

    Args:
        slenderness: :math:`\bar\lambda_p > 0`.
        psi: :math:`\psi = \sigma_2/\sigma_1` in the table's range (:func:`psi_range`).
        element: :data:`INTERNAL` (default: the clause's first case) or :data:`OUTSTAND`.
        free_edge_most_compressed: For an outstand, where :math:`\sigma_1` acts (it
            decides the range of :math:`\psi`, not :math:`\rho`).
    """
    _check(element, psi, free_edge_most_compressed)
    if element == OUTSTAND:
        if slenderness <= 0.748:
            return 1.0
        return min(1.0, (slenderness - 0.188) / slenderness**2)
    if slenderness <= 0.5 + math.sqrt(0.085 - 0.055 * psi):
        return 1.0
    return min(1.0, (slenderness - 0.055 * (3.0 + psi)) / slenderness**2)


def buckling_factor(element: str, psi: float, free_edge_most_compressed: bool = True) -> float:
    r""":math:`k_\sigma` of EN 1993-1-5 Table 4.1 (internal) or 4.2 (outstand).

    The tables' values at :math:`\psi` = 1, 0 and -1 (4.0, 7.81, 23.9; 0.43, 0.57, 0.85
    with :math:`\sigma_1` at the free edge; 0.43, 1.70, 23.8 at the supported edge) and
    their formulas between.
    """
    _check(element, psi, free_edge_most_compressed)
    if element == INTERNAL:
        if psi == 1.0:
            return 4.0
        if psi > 0.0:
            return 8.2 / (1.05 + psi)
        if psi == 0.0:
            return 7.81
        if psi > -1.0:
            return 7.81 - 6.29 * psi + 9.78 * psi**2
        if psi == -1.0:
            return 23.9
        return 5.98 * (1.0 - psi) ** 2
    if free_edge_most_compressed:
        return {1.0: 0.43, 0.0: 0.57, -1.0: 0.85}.get(psi, 0.57 - 0.21 * psi + 0.07 * psi**2)
    if psi == 1.0:
        return 0.43
    if psi > 0.0:
        return 0.578 / (psi + 0.34)
    if psi == 0.0:
        return 1.70
    if psi > -1.0:
        return 1.70 - 5.0 * psi + 17.1 * psi**2
    return 23.8
