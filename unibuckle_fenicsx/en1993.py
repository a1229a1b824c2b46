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
no maintained library implements them for a given :math:`\sigma_{cr}`, hence this module.
:func:`design_element` classifies a plate by its edges, or refuses what the clause does
not describe; the module imports no other of the package (it reads a problem through
:class:`DesignProblem`), so that the problem checks (:mod:`unibuckle_fenicsx.spec`) can refuse
such a plate, or a stress ratio outside the tables, before any solve.

:func:`effective_widths` gives the widths of Tables 4.1 and 4.2 (what part of the element
carries the stress), and :func:`stress_limit` the clause and partial factor of the
stress limit :math:`\rho f_y/\gamma_M`: at :math:`\psi = 1` the lone internal
element's effective area is :math:`A_{eff} = \rho A` (:math:`b_{e1} = b_{e2}`, about
the gross centroid), and 4.6(1), eq. (4.14), with :math:`\gamma_{M0}`, reads
:math:`\sigma_1 \le \rho f_y/\gamma_{M0}`; at :math:`\psi < 1`, and at :math:`\psi
= 1` where the effective area lies off the gross centroid (an outstand with
:math:`\rho < 1`: :math:`b_{eff} = \rho c` at the supported edge, :math:`e_N = (1 -
\rho)c/2`; a box's face in a section under bending), 4.6(1) checks the effective
section (:math:`A_{eff}`, :math:`W_{eff}` and the shift :math:`e_N`), which is not
computed here, and
:math:`\sigma_1 \le \rho f_y/\gamma_{M1}` is the reduced stress method of section 10
with direct stress alone: eq. (10.1), :math:`\rho\,\alpha_{ult,k}/\gamma_{M1} \ge 1`,
with :math:`\alpha_{ult,k} = f_y/\sigma_1` (eq. (10.3) without :math:`\sigma_z`,
:math:`\tau`), :math:`\alpha_{cr} = \sigma_{cr}/\sigma_1`, so that eq. (10.2),
:math:`\bar\lambda_p = \sqrt{\alpha_{ult,k}/\alpha_{cr}} = \sqrt{f_y/\sigma_{cr}}`,
and :math:`\rho = \rho_x` of 4.5.4(1) (10(5)).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from unibuckle_fenicsx.errors import InputError

__all__ = [
    "COLUMN_IMPERFECTION",
    "ELEMENTS",
    "INTERNAL",
    "OUTSTAND",
    "OUTSTAND_SHIFT",
    "SHEAR_NOT_CHECKED",
    "STAINLESS_MODULUS",
    "STEEL_MODULUS",
    "STEEL_POISSON",
    "STEEL_YIELD_STRESS",
    "YIELD_STRESS_ABOVE_40_MM",
    "ColumnType",
    "DesignEdge",
    "DesignElement",
    "DesignLoad",
    "DesignPlate",
    "DesignProblem",
    "EffectiveWidths",
    "buckling_factor",
    "check_steel_modulus",
    "check_steel_yield_stress",
    "clipped_xi",
    "column_end_factor",
    "column_reduction_factor",
    "column_type",
    "design_element",
    "effective_widths",
    "interpolated_reduction_factor",
    "plate_euler_stress",
    "psi_range",
    "ratio_text",
    "reduction_factor",
    "stainless_note",
    "steel_poisson_note",
    "stress_limit",
    "stress_ratio",
    "table_row",
    "yield_stress_note",
]

#: An element with both unloaded edges supported (EN 1993-1-5 Table 4.1).
INTERNAL = "internal"
#: An element with one unloaded edge free (EN 1993-1-5 Table 4.2).
OUTSTAND = "outstand"
#: The elements of EN 1993-1-5 4.4(2).
ELEMENTS = (INTERNAL, OUTSTAND)
#: Young's moduli (Pa) taken as a steel's by the design output: structural steel's 210
#: GPa (EN 1993-1-1 3.2.6) and stainless steel's 200 GPa (EN 1993-1-4 Table 2.1), with
#: the 200-205 GPa some codes and texts give carbon steel; aluminium (70 GPa) and other
#: metals lie far outside.
STEEL_MODULUS = (1.9e11, 2.2e11)


def check_steel_modulus(E: float, stress: float, name: str) -> None:
    """Refuse a Young's modulus ``E`` (Pa) that is not a steel's (:data:`STEEL_MODULUS`).

    EN 1993-1-5 4.4's rho (and epsilon = sqrt(235/f_y)) rest on steel, E = 210 GPa
    (EN 1993-1-1 3.2.6); aluminium (70 GPa) has its own curves (EN 1999-1-1 6.1.4),
    which the design output does not give. ``stress`` and ``name`` are the file's
    stress unit in Pa and its name, for the message.

    Raises:
        InputError: ``E`` outside :data:`STEEL_MODULUS`, naming ``material.E``.
    """
    why = (
        "(EN 1993-1-5's rho rests on steel, E in [{low:.6g}, {high:.6g}] {name}: 210 GPa, "
        "stainless 200 GPa); for aluminium use EN 1999-1-1 6.1.4, whose curves this "
        "output does not give; leave [design] out"
    )
    _refuse_outside("design: material.E", E, STEEL_MODULUS, stress, name, why)


def _refuse_outside(
    key: str, value: float, bounds: tuple[float, float], stress: float, name: str, why: str
) -> None:
    """Refuse ``value`` (Pa) outside ``bounds``: "KEY = v NAME is not a steel's WHY".

    ``why`` is formatted with the bounds (``low``, ``high``) and ``name`` in the file's
    stress unit (``stress`` Pa).
    """
    low, high = bounds
    if not low <= value <= high:
        raise InputError(
            f"{key} = {value / stress:.6g} {name} is not a steel's "
            + why.format(low=low / stress, high=high / stress, name=name)
        )


#: Yield stresses (Pa) taken as a steel's by the design output: EN 1993-1-1 Table 3.1's
#: structural steels (S235 to S460, f_y from 215 MPa in thick plates), EN 1993-1-12's up
#: to S700 (and S960 in its revision) and EN 1993-1-4's stainless steels (from 200 MPa),
#: with a margin. A number in the wrong unit (355 Pa in an SI file, 3.55e8 MPa in a
#: mm-N-MPa one) lies orders of magnitude outside.
STEEL_YIELD_STRESS = (1.5e8, 1.0e9)


def check_steel_yield_stress(fy: float, stress: float, name: str) -> None:
    """Refuse a yield stress ``fy`` (Pa) that is not a steel's (:data:`STEEL_YIELD_STRESS`).

    The slenderness sqrt(f_y/sigma_cr) and rho f_y/gamma_M take f_y as it is: a number
    in another unit (355 in an SI file: 355 Pa) would give rho = 1 on any plate. ``stress``
    and ``name`` are the file's stress unit in Pa and its name, for the message; raises
    :class:`~unibuckle_fenicsx.errors.InputError` naming ``design.yield_stress``.
    """
    _refuse_outside(
        "design.yield_stress",
        fy,
        STEEL_YIELD_STRESS,
        stress,
        name,
        "yield stress (EN 1993-1-1 Table 3.1 and EN 1993-1-12: 235 to 700 MPa, stainless "
        "steel from 200 MPa; accepted: {low:.6g} to {high:.6g} {name}); give it in the "
        "file's unit, {name}",
    )


#: Young's modulus (Pa) below which the design output reads the material as possibly
#: stainless steel (EN 1993-1-4 Table 2.1: 200 GPa; EN 1993-1-1 3.2.6: 210 GPa).
STAINLESS_MODULUS = 2.05e11


def stainless_note(E: float) -> str | None:
    """A note when ``E`` (Pa) is stainless steel's (below :data:`STAINLESS_MODULUS`), else None.

    EN 1993-1-4 5.2.3 replaces EN 1993-1-5's eq. (4.2) and (4.3) for stainless steel by its
    own reduction factors, which reduce more; the output applies EN 1993-1-5's. The note
    names ``material.E``.
    """
    if E >= STAINLESS_MODULUS:
        return None
    return (
        f"design: material.E = {E / 1e9:.4g} GPa is stainless steel's (EN 1993-1-4 Table "
        "2.1: 200 GPa; structural steel's 210 GPa, EN 1993-1-1 3.2.6): for stainless steel "
        "EN 1993-1-4 5.2.3 gives its own reduction factor rho, which reduces more than EN "
        "1993-1-5's eq. (4.2) and (4.3) applied here"
    )


#: EN 1993-1-1 Table 3.1 (EN 10025-2 to -6, EN 10210-1): the nominal f_y (N/mm^2) of the
#: hot rolled structural steels at t <= 40 mm, and the table's value at 40 mm < t <= 80 mm.
YIELD_STRESS_ABOVE_40_MM = {
    235.0: "215",
    275.0: "255",
    355.0: "335",
    420.0: "390",
    440.0: "410",
    460.0: "430 (EN 10025-3, -4, EN 10210-1) or 440 (EN 10025-6)",
}


def yield_stress_note(fy: float, thickness: float, key: str) -> str | None:
    """A note when ``fy`` (Pa) is Table 3.1's t <= 40 mm value of a plate ``thickness`` (m) > 40 mm.

    EN 1993-1-1 Table 3.1 lowers the nominal f_y of every grade above t = 40 mm (S355:
    335 N/mm^2 for 40 < t <= 80 mm) and stops at 80 mm (the product standard's values
    below it). The output takes f_y as given; the note names ``design.yield_stress`` and
    ``key``, the thickness's key. None for t <= 40 mm or another f_y.
    """
    t_mm, fy_mm2 = thickness * 1e3, fy / 1e6
    nominal = next((v for v in YIELD_STRESS_ABOVE_40_MM if abs(fy_mm2 - v) <= 1e-9 * v), None)
    if t_mm <= 40.0 or nominal is None:
        return None
    where = (
        f"design.yield_stress: f_y = {nominal:g} N/mm^2 is EN 1993-1-1 Table 3.1's for t <= 40 mm"
    )
    if t_mm <= 80.0:
        return (
            f"{where}; at t = {t_mm:.4g} mm ({key}, 40 < t <= 80 mm) the table gives "
            f"{YIELD_STRESS_ABOVE_40_MM[nominal]} N/mm^2: the output takes f_y as given "
            "(slenderness, rho, rho f_y/gamma_M), check design.yield_stress"
        )
    return (
        f"{where}; at t = {t_mm:.4g} mm ({key}) the table, which stops at 80 mm, gives less "
        "already at 40 < t <= 80 mm: take f_y from the product standard (EN 10025) at this "
        "thickness; the output takes f_y as given, check design.yield_stress"
    )


#: Poisson's ratios taken as a steel's by the design output without a warning: EN
#: 1993-1-1 3.2.6 and EN 1993-1-4 2.2 give nu = 0.3, with a margin for the 0.28-0.29
#: some texts give. Another nu is warned of, not refused: sigma_cr is then the plate's
#: with that nu, which EN 1993-1-5's rho (calibrated on steel) does not describe.
STEEL_POISSON = (0.25, 0.35)


def steel_poisson_note(nu: float) -> str | None:
    """A warning when the design output is asked of a ``nu`` not a steel's, else None.

    :data:`STEEL_POISSON`; the message names ``material.nu``.
    """
    low, high = STEEL_POISSON
    if low <= nu <= high:
        return None
    return (
        f"design: material.nu = {nu:.6g} is not a steel's (EN 1993-1-1 3.2.6: nu = 0.3; "
        f"no warning in [{low:g}, {high:g}]): sigma_cr is computed with it, and EN 1993-1-5's "
        "rho rests on steel plates; check material.nu"
    )


def table_row(element: str, free_edge_most_compressed: bool) -> str:
    """The table and row of EN 1993-1-5 that describe ``element`` (for the output)."""
    if element == INTERNAL:
        return "Table 4.1 (internal compression element)"
    where = "free" if free_edge_most_compressed else "supported"
    return f"Table 4.2 (outstand compression element, larger compression at the {where} edge)"


#: Said of the stress limit of a load with shear: it checks the direct stress alone.
SHEAR_NOT_CHECKED = "the load's shear not checked"


def stress_limit(psi: float, shear: bool = False, shift: str | None = None) -> tuple[str, str]:
    r"""(partial factor's name, clause) of the stress limit :math:`\rho f_y/\gamma_M` at ``psi``.

    The module docstring says why: 4.6(1) with :math:`\gamma_{M0}` where the effective
    section is :math:`A_{eff} = \rho A` without a shift :math:`e_N` (:math:`\psi = 1`,
    ``shift`` None), the reduced stress method of section 10 with :math:`\gamma_{M1}`
    elsewhere. Both check the direct stress alone; with ``shear`` (the load has shear)
    the clause says that its shear is not checked (:data:`SHEAR_NOT_CHECKED`): section 5
    and the interaction of 7.1, or section 10 with :math:`\tau` in eq. (10.3), would
    include it.

    Args:
        psi: :math:`\psi`.
        shear: Whether the load has shear.
        shift: At :math:`\psi = 1`, why the effective section is not :math:`\rho A`
            about the gross centroid (an outstand's :math:`b_{eff}` at its supported edge,
            a section's bending), so that 4.6(1) would need :math:`e_N` and
            :math:`W_{eff}`; None where it is.
    """
    if psi == 1.0 and shift is None:
        clause = "4.6(1): rho f_y/gamma_M0 (eq. (4.14) at psi = 1: A_eff = rho A, no shift e_N)"
        if shear:
            clause += (
                f"; direct stress only, {SHEAR_NOT_CHECKED} (section 5 and the interaction "
                "of 7.1, or section 10 with tau in eq. (10.3), would include it)"
            )
        return "gamma_M0", clause
    stresses = (
        f"with tau = 0 ({SHEAR_NOT_CHECKED}: eq. (10.3) would include it)"
        if shear
        else "direct stress only"
    )
    why = "psi < 1" if psi != 1.0 else f"psi = 1, but {shift}"
    return "gamma_M1", (
        f"section 10, reduced stress method, {stresses}: eq. (10.1) rho "
        "alpha_ult,k/gamma_M1 >= 1 with alpha_ult,k = f_y/sigma_1 and eq. (10.2) "
        "slenderness sqrt(f_y/sigma_cr), rho = rho_x of 4.5.4(1) (10(5)): sigma_1 <= rho "
        f"f_y/gamma_M1 ({why}: 4.6(1) checks A_eff, W_eff and e_N, not computed here)"
    )


#: Why an outstand's effective section is shifted (:func:`stress_limit`'s ``shift``).
OUTSTAND_SHIFT = (
    "the outstand's b_eff = rho c lies at its supported edge (Table 4.2): its centroid is "
    "shifted by e_N = (1 - rho) c/2"
)


@dataclass(frozen=True)
class EffectiveWidths:
    r"""The effective widths of EN 1993-1-5 Table 4.1 or 4.2 (m), :func:`effective_widths`.

    Attributes:
        width: :math:`\bar b` (internal) or :math:`c` (outstand), the element's width.
        compressed: :math:`b_c`, its compressed part: the width for :math:`\psi \ge 0`,
            width/(1 - psi) below.
        effective: :math:`b_{eff}`, rho times ``width`` (:math:`\psi \ge 0`) or times
            ``compressed``.
        first: :math:`b_{e1}`, the internal element's part at its :math:`\sigma_1` end;
            None for an outstand.
        second: :math:`b_{e2}`, the rest of ``effective``; None for an outstand.
        row: The table's row applied.
        placed: Where the widths lie, from the element's edges ``sigma_1 end`` and
            ``other end`` (internal) or ``supported`` and ``free`` (outstand).
    """

    width: float
    compressed: float
    effective: float
    first: float | None
    second: float | None
    row: str
    placed: str


def effective_widths(
    element: str, rho: float, width: float, psi: float, free_edge_most_compressed: bool = True
) -> EffectiveWidths:
    r"""The effective widths of EN 1993-1-5 Table 4.1 (internal) or 4.2 (outstand).

    Table 4.1: :math:`\psi = 1`: :math:`b_{eff} = \rho\bar b`, :math:`b_{e1} = b_{e2} =
    0.5 b_{eff}`; :math:`1 > \psi \ge 0`: :math:`b_{eff} = \rho\bar b`, :math:`b_{e1} =
    2b_{eff}/(5 - \psi)`, :math:`b_{e2} = b_{eff} - b_{e1}`; :math:`\psi < 0`:
    :math:`b_c = \bar b/(1 - \psi)`, :math:`b_{eff} = \rho b_c`, :math:`b_{e1} = 0.4
    b_{eff}`, :math:`b_{e2} = 0.6 b_{eff}`. :math:`b_{e1}` lies at the :math:`\sigma_1`
    end; :math:`b_{e2}` at the other end (:math:`\psi \ge 0`) or next to the
    tension zone :math:`b_t = \bar b - b_c`, which is effective (:math:`\psi < 0`).
    Table 4.2, both rows (larger compression at the free or at the supported edge):
    :math:`b_{eff} = \rho c` for :math:`1 \ge \psi \ge 0`, :math:`\rho b_c = \rho
    c/(1 - \psi)` for :math:`\psi < 0`; the effective part lies at the supported edge,
    after the tension zone when that is there (larger compression at the free edge),
    else from the edge, the tension zone at the free edge then effective too.

    Args:
        element: :data:`INTERNAL` or :data:`OUTSTAND`.
        rho: The reduction factor applied (:math:`\rho`, or :math:`\rho_c`, 4.5.4(1)).
        width: :math:`\bar b` or :math:`c` (m).
        psi: :math:`\psi` in the table's range (:func:`psi_range`).
        free_edge_most_compressed: For an outstand, the row of Table 4.2.
    """
    _check(element, psi, free_edge_most_compressed)
    compressed = width if psi >= 0.0 else width / (1.0 - psi)
    effective = rho * compressed
    row = table_row(element, free_edge_most_compressed).split(" (")[0]
    if element == INTERNAL:
        if psi == 1.0:
            first, cell = 0.5 * effective, "psi = 1"
        elif psi >= 0.0:
            first, cell = 2.0 * effective / (5.0 - psi), "1 > psi >= 0"
        else:
            first, cell = 0.4 * effective, "psi < 0"
        placed = (
            "b_e1 from the sigma_1 end, b_e2 from the other end"
            if psi >= 0.0
            else "b_e1 from the sigma_1 end, b_e2 ending at b_c from it (where the "
            "compression ends); the tension zone b_t = b - b_c at the other end effective"
        )
        return EffectiveWidths(
            width, compressed, effective, first, effective - first, f"{row}, {cell}", placed
        )
    where = "free" if free_edge_most_compressed else "supported"
    cell = "1 >= psi >= 0" if psi >= 0.0 else "psi < 0"
    if psi >= 0.0:
        placed = "b_eff from the supported edge; c - b_eff at the free edge ineffective"
    elif free_edge_most_compressed:
        placed = (
            "the tension zone b_t = c - b_c from the supported edge, then b_eff, effective; "
            "b_c - b_eff at the free edge ineffective"
        )
    else:
        placed = (
            "b_eff from the supported edge and the tension zone b_t = c - b_c at the free "
            "edge effective; b_c - b_eff between them ineffective"
        )
    return EffectiveWidths(
        width,
        compressed,
        effective,
        None,
        None,
        f"{row}, larger compression at the {where} edge, {cell}",
        placed,
    )


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


def stress_ratio(sigma1: float, sigma2: float) -> float:
    r""":math:`\psi = \sigma_2/\sigma_1` (:math:`\sigma_1 > 0`), an integer when within 1e-12.

    The tables' ends and rows are at whole numbers (-3, -1, 0, 1): a ratio a rounding
    off one (``[-0.7, 2.1]`` gives -3.0000000000000004) is that number, not outside the
    table.
    """
    return _whole(sigma2 / sigma1)


def _whole(ratio: float) -> float:
    """``ratio``, or the whole number within 1e-12 (relative, above 1) of it; no -0.0."""
    whole = float(round(ratio))
    return (whole if abs(ratio - whole) <= 1e-12 * max(1.0, abs(ratio)) else ratio) + 0.0


def ratio_text(value: float | None, digits: int = 3) -> str:
    r"""A ratio (:math:`\psi`, :math:`\xi`, a/b) to ``digits`` significant digits, or more.

    The tables' rows and the clauses' bounds lie at whole numbers (:math:`\psi` = 1, 0,
    -1, -3; :math:`\xi` = 0, 1; a/b = 1): a ratio that is not one is printed with the
    digits that show it, so that the row or branch taken is visible (:math:`\psi` =
    -0.9996 is in Table 4.1's row 0 > psi > -1: "-0.9996", not "-1"); one within 1e-12
    of a whole number is that number, as in :func:`stress_ratio` (a/b = 0.6/0.2 =
    2.9999999999999996 prints "3"). "none" for None.
    """
    if value is None:
        return "none"
    value = _whole(value)
    for n in range(digits, 18):
        text = f"{value:.{n}g}"
        if value == round(value) or float(text) != round(float(text)):
            return text
    return repr(value)


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


#: The imperfection factor of an unstiffened plate's column-type buckling (EN 1993-1-5
#: 4.5.3(5): buckling curve a of EN 1993-1-1 Table 6.1).
COLUMN_IMPERFECTION = 0.21


def column_reduction_factor(slenderness: float, alpha: float = COLUMN_IMPERFECTION) -> float:
    r""":math:`\chi_c` of EN 1993-1-1 6.3.1.2 (eq. (6.49)) at :math:`\bar\lambda_c`, <= 1.

    :math:`\Phi = 0.5(1 + \alpha(\bar\lambda_c - 0.2) + \bar\lambda_c^2)`,
    :math:`\chi_c = 1/(\Phi + \sqrt{\Phi^2 - \bar\lambda_c^2})`; for an unstiffened plate
    :math:`\bar\lambda_c = \sqrt{f_y/\sigma_{cr,c}}` and :math:`\alpha` = 0.21 (EN 1993-1-5
    4.5.3(4), (5)).
    """
    phi = 0.5 * (1.0 + alpha * (slenderness - 0.2) + slenderness**2)
    return min(1.0, 1.0 / (phi + math.sqrt(phi**2 - slenderness**2)))


def plate_euler_stress(E: float, nu: float, thickness: float, length: float) -> float:
    r""":math:`\pi^2 E t^2/(12(1 - \nu^2) l^2)` (Pa): a plate strip of length l, bent.

    With l the loaded edge's length b, the reference stress :math:`\sigma_E` of EN
    1993-1-5 eq. (A.2); with l the length a along the stress, the hinged column's
    :math:`\sigma_{cr,c}` of eq. (4.8) (4.5.3(2)).
    """
    return math.pi**2 * E * (thickness / length) ** 2 / (12.0 * (1.0 - nu**2))


def column_end_factor(
    start: float,
    end: float,
    start_translation: float = math.inf,
    end_translation: float = math.inf,
) -> float:
    r""":math:`\sigma_{cr,c}` of a column with restrained ends over that of a hinged one.

    EN 1993-1-5 4.5.3(1) defines :math:`\sigma_{cr,c}` as the plate's buckling stress
    with the supports along its unloaded edges removed: a column (a strip in cylindrical
    bending) between the loaded edges, as these are supported. Eq. (4.8) is the hinged
    column's; here each end has a rotational restraint :math:`\kappa = k_r a/D` (0
    hinged, ``math.inf`` clamped) and a translational one :math:`\tau = k_t a^3/D`
    (``math.inf``, the default: held, w = 0; 0: free). With s = x/a,
    :math:`u^2 = P a^2/D` and :math:`w = c_1 + c_2 s + c_3 (1 - \cos us)/u^2 + c_4 (us -
    \sin us)/u^3` (a basis that stays independent as u tends to 0), the end conditions
    of the energy (at s = 0: :math:`-w'' + \kappa w' = 0` and :math:`w''' + u^2 w' +
    \tau w = 0`; at s = 1: :math:`w'' + \kappa w' = 0` and :math:`-w''' - u^2 w' + \tau
    w = 0`) have a determinant whose smallest root u > 0 gives the factor
    :math:`(u/\pi)^2`: 1 hinged, 4 clamped (effective length a/2), 2.046 clamped and
    hinged, 1/4 clamped and free (a cantilever). 0 when the ends leave a rigid motion of
    the column free (both free, or one free and the other hinged: a mechanism, no column
    buckling stress).

    Args:
        start: :math:`\kappa` of one end, >= 0 (``math.inf``: clamped).
        end: :math:`\kappa` of the other.
        start_translation: :math:`\tau` of the first end, >= 0 (``math.inf``: held).
        end_translation: :math:`\tau` of the other.
    """
    restraints = (start, end, start_translation, end_translation)
    if min(restraints) < 0.0:
        raise InputError(f"column end restraints must be >= 0, got {restraints!r}")
    held = start_translation == end_translation == math.inf
    if held and start == end == 0.0:
        return 1.0
    if held and start == end == math.inf:
        return 4.0
    # The rigid motions c1 + c2 s that the restraints hold: a mechanism if one is free.
    rigid = [
        row
        for row, on in (
            ([1.0, 0.0], start_translation > 0.0),
            ([1.0, 1.0], end_translation > 0.0),
            ([0.0, 1.0], start > 0.0 or end > 0.0),
        )
        if on
    ]
    if not rigid or np.linalg.matrix_rank(np.array(rigid)) < 2:
        return 0.0

    def det(u: float) -> float:
        ends = _end_rows(start, start_translation, u, False)
        ends += _end_rows(end, end_translation, u, True)
        return float(np.linalg.det(ends))

    grid = [2.0 * math.pi * (k / 800.0) ** 2 for k in range(1, 801)]  # fine near u = 0
    grid += [2.0 * math.pi * (1.0 + k / 400.0) for k in (1, 2)]
    values = [det(u) for u in grid]
    for k in range(len(grid) - 1):
        (u0, u1), (f0, f1) = grid[k : k + 2], values[k : k + 2]
        if f0 == 0.0:
            return (u0 / math.pi) ** 2
        if f0 * f1 < 0.0:
            return (_bisect(det, u0, u1, f0) / math.pi) ** 2
    raise AssertionError("no column buckling load up to the clamped one")


def _end_rows(kappa: float, tau: float, u: float, at_end: bool) -> list[list[float]]:
    r"""The two rows of one column end's conditions in :func:`column_end_factor`'s basis.

    The moment row (:math:`\pm w'' + \kappa w'`) and the force row (:math:`\mp(w''' +
    u^2 w') + \tau w`), upper signs at s = 1 (``at_end``), lower at s = 0, divided by
    :math:`1 + \kappa` (:math:`1 + \tau`): a clamped (held) end keeps w' (w) alone.
    """
    s = 1.0 if at_end else 0.0
    c, n = math.cos(u * s), math.sin(u * s)
    w = [1.0, s, (1.0 - c) / u**2, (u * s - n) / u**3]
    slope = [0.0, 1.0, n / u, (1.0 - c) / u**2]
    curvature = [0.0, 0.0, c, n / u]
    shear = [0.0, u * u, 0.0, 1.0]  # the third derivative plus u^2 times the slope
    sign = 1.0 if at_end else -1.0
    moment, force = slope, w
    if kappa != math.inf:
        pairs = zip(curvature, slope, strict=True)
        moment = [(sign * k + kappa * v) / (1.0 + kappa) for k, v in pairs]
    if tau != math.inf:
        force = [(-sign * q + tau * v) / (1.0 + tau) for q, v in zip(shear, w, strict=True)]
    return [moment, force]


def _bisect(f: Callable[[float], float], a: float, b: float, fa: float) -> float:
    """A root of f in [a, b] (f(a) = fa and f(b) of opposite signs), to round-off.

    Hand-written: SciPy's ``brentq`` would do, but SciPy is no dependency of the package.
    """
    for _ in range(200):
        mid = 0.5 * (a + b)
        fm = f(mid)
        if fm == 0.0 or mid in (a, b):
            return mid
        if (fm < 0.0) == (fa < 0.0):
            a, fa = mid, fm
        else:
            b = mid
    return 0.5 * (a + b)


def interpolated_reduction_factor(rho: float, chi: float, xi: float) -> float:
    r""":math:`\rho_c = (\rho - \chi_c)\,\xi(2 - \xi) + \chi_c`, EN 1993-1-5 4.5.4(1).

    The interaction of plate-type (:math:`\rho`) and column-type (:math:`\chi_c`)
    buckling, :math:`\xi = \sigma_{cr,p}/\sigma_{cr,c} - 1` clipped to [0, 1]: at
    :math:`\xi \ge 1` the plate-type :math:`\rho` itself.
    """
    xi = clipped_xi(xi)
    if xi == 1.0:
        return rho  # exactly: (rho - chi) + chi may differ from it in the last bit
    return (rho - chi) * xi * (2.0 - xi) + chi


def clipped_xi(xi: float) -> float:
    r""":math:`\xi` as EN 1993-1-5 4.5.4(1) uses it: bounded to :math:`0 \le \xi \le 1`."""
    return min(1.0, max(0.0, xi))


@dataclass(frozen=True)
class ColumnType:
    r"""Column-type buckling of a plate (EN 1993-1-5 4.5.3, 4.5.4(1)), :func:`column_type`.

    Attributes:
        chi: :math:`\chi_c`, curve a at :math:`\bar\lambda_c = \sqrt{f_y/\sigma_{cr,c}}`.
        xi: :math:`\xi = \sigma_{cr}/\sigma_{cr,c} - 1`, unclipped.
        rho: :math:`\rho_c`, the plate's :math:`\rho` interpolated towards :math:`\chi_c`.
    """

    chi: float
    xi: float
    rho: float

    @property
    def xi_used(self) -> float:
        """``xi`` bounded to [0, 1], the value 4.5.4(1) uses (:func:`clipped_xi`)."""
        return clipped_xi(self.xi)


def column_type(rho: float, sigma_cr: float, column: float, yield_stress: float) -> ColumnType:
    r"""The column-type reduction of a plate or face (EN 1993-1-5 4.5.3(4), (5), 4.5.4(1)).

    Args:
        rho: The plate-type :math:`\rho` (eq. (4.2) or (4.3)).
        sigma_cr: The plate's :math:`\sigma_{cr}` (Pa), > 0.
        column: :math:`\sigma_{cr,c}` (Pa), > 0: the plate as a column (4.5.3(1)).
        yield_stress: :math:`f_y` (Pa).
    """
    chi = column_reduction_factor(math.sqrt(yield_stress / column))
    xi = sigma_cr / column - 1.0
    return ColumnType(chi, xi, interpolated_reduction_factor(rho, chi, xi))


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


# -- the element of a plate ----------------------------------------------------------------

#: The rectangle's edges in pairs of opposite edges, and the pair each pair's edges run
#: along (a [start, end] stress runs from the smaller coordinate to the larger).
_PAIRS = {("left", "right"): ("bottom", "top"), ("bottom", "top"): ("left", "right")}
_NAMES = tuple(name for pair in _PAIRS for name in pair)


@dataclass(frozen=True)
class DesignElement:
    """The plate as a compression element of EN 1993-1-5 4.4 (:func:`design_element`).

    Attributes:
        kind: :data:`INTERNAL` (both unloaded edges supported) or :data:`OUTSTAND` (one
            free).
        loaded: The two opposite edges across which the direct stress acts.
        unloaded: The two edges parallel to it.
        free_edge: The free unloaded edge of an outstand, else None.
    """

    kind: str
    loaded: tuple[str, str]
    unloaded: tuple[str, str]
    free_edge: str | None = None

    @property
    def free_end(self) -> int | None:
        """Which end (0 start, 1 end) of a loaded edge lies on the free edge, or None.

        A loaded edge runs from its end with the smaller coordinate to the larger, so its
        start lies on the first edge of ``unloaded`` (bottom, or left).
        """
        if self.free_edge is None:
            return None
        return self.unloaded.index(self.free_edge)


class DesignEdge(Protocol):
    """What :func:`design_element` reads of an edge (:class:`~unibuckle_fenicsx.spec.EdgeSpec`)."""

    @property
    def name(self) -> str:
        """The edge's name: "left", "right", "bottom" or "top"."""

    @property
    def support(self) -> str:
        """Its transverse condition ("free", "simply_supported", ...)."""

    @property
    def inplane(self) -> str:
        """Its in-plane condition ("free", "clamped", "roller")."""

    @property
    def translational_stiffness(self) -> float:
        """Its springs on the deflection (N/m^2), >= 0."""

    @property
    def normal_stress(self) -> float | tuple[float, float]:
        """Its normal stress per unit load (Pa/Pa): a number or (start, end)."""

    @property
    def fixed_normal_stress(self) -> float | tuple[float, float]:
        """Its fixed normal stress (Pa): a number or (start, end)."""


class DesignPlate(Protocol):
    """What :func:`design_element` reads of a plate (:class:`~unibuckle_fenicsx.spec.PlateSpec`)."""

    @property
    def outline(self) -> object:
        """The plate's outline, or None for a rectangle."""

    @property
    def file(self) -> str | None:
        """The plate's gmsh file, or None."""

    @property
    def edges(self) -> Sequence[DesignEdge]:
        """The edges the plate names (the others are free)."""


class DesignLoad(Protocol):
    """What :func:`design_element` reads of a load (:class:`~unibuckle_fenicsx.spec.LoadSpec`)."""

    @property
    def thermal(self) -> bool:
        """Whether the scaled load has a temperature rise."""

    @property
    def fixed_thermal(self) -> bool:
        """Whether the fixed load has a temperature rise."""

    @property
    def fixed_factor(self) -> float:
        """The factor on the fixed load (0: none)."""


class DesignProblem(Protocol):
    """What :func:`design_element` reads of a :class:`~unibuckle_fenicsx.spec.ProblemSpec`."""

    @property
    def plate(self) -> DesignPlate:
        """The plate."""

    @property
    def load(self) -> DesignLoad:
        """The load besides the edge stresses."""


@dataclass(frozen=True)
class _FreeEdge:
    """An edge of the rectangle that the plate does not name: free, without stress."""

    name: str
    support: str = "free"
    inplane: str = "free"
    translational_stiffness: float = 0.0
    normal_stress: float = 0.0
    fixed_normal_stress: float = 0.0


def _ends(value: float | tuple[float, float]) -> tuple[float, float]:
    """(start, end) of an edge stress: the pair itself, or the number twice."""
    return (value, value) if isinstance(value, float | int) else value


def design_element(spec: DesignProblem) -> DesignElement:
    """Classify the plate for the design output (EN 1993-1-5 4.4(2)), or refuse it.

    The direct stress acts across the edges given a normal stress (scaled or fixed); the
    other two edges are the unloaded ones: both supported, an internal element (Table
    4.1); one free (``support = "free"``, no translational spring), an outstand (Table
    4.2). A stress ratio outside the element's table is refused here when the scaled
    stresses alone fix it (no fixed normal stress); with a fixed part it depends on the
    load and the output says so.

    Raises:
        InputError: What clause 4.4 does not describe, naming the keys: a plate that is
            not a rectangle (outline, file), a temperature rise, normal stress in
            both directions (biaxial), both unloaded edges free, a free edge on springs,
            an unloaded edge held in its plane (a transverse stress), a stress ratio
            outside the table.
    """
    _check_plate(spec.plate, spec.load)
    fixed = spec.load.fixed_factor != 0.0
    named = {e.name: e for e in spec.plate.edges}
    sides: dict[str, DesignEdge] = {name: named.get(name, _FreeEdge(name)) for name in _NAMES}
    _check_rectangle_loaded(spec.plate.edges, sides, fixed)
    loaded = _loaded_pair(sides, fixed)
    unloaded = _PAIRS[loaded]
    for name in unloaded:
        _check_unloaded(sides[name])
    free = [name for name in unloaded if sides[name].support == "free"]
    if len(free) == 2:
        raise InputError(
            f'design: edges.{unloaded[0]}.support and edges.{unloaded[1]}.support are both "free": '
            "with both unloaded edges free the plate is a strut (column-like buckling), "
            "neither an internal nor an outstand element of EN 1993-1-5 4.4; leave [design] "
            "out or support an unloaded edge"
        )
    element = DesignElement(
        OUTSTAND if free else INTERNAL, loaded, unloaded, free[0] if free else None
    )
    if not (fixed and any(any(_ends(sides[name].fixed_normal_stress)) for name in loaded)):
        _check_stress_ratio([sides[name] for name in loaded], element)
    return element


def _check_plate(plate: DesignPlate, load: DesignLoad) -> None:
    """Refuse a plate that is not a rectangle, and a temperature rise."""
    why = (
        "is given by its outline"
        if plate.outline is not None
        else "is a gmsh file"
        if plate.file is not None
        else ""
    )
    if why:
        raise InputError(
            f"design: EN 1993-1-5 4.4 describes a rectangular plate element by its two "
            f"unloaded edges; this plate {why} (plate.outline, plate.file): leave [design] "
            "out, or give the rectangle's plate.corners"
        )
    if load.thermal or (load.fixed_thermal and load.fixed_factor != 0.0):
        key = "load.temperature" if load.thermal else "load.fixed_temperature"
        raise InputError(
            f"design: {key}: a temperature rise adds a membrane stress (set by the in-plane "
            "supports) that the edge stresses, from which the design output takes sigma_cr "
            "and psi, do not show: leave [design] or the temperature out"
        )


def _normal_keys(e: DesignEdge, fixed: bool) -> list[str]:
    """``edges.NAME.normal_stress`` (and the fixed one, with a fixed part) where ``e`` has one."""
    keys = [f"edges.{e.name}.normal_stress"] if any(_ends(e.normal_stress)) else []
    if fixed and any(_ends(e.fixed_normal_stress)):
        keys.append(f"edges.{e.name}.fixed_normal_stress")
    return keys


def _check_rectangle_loaded(
    edges: Sequence[DesignEdge], sides: dict[str, DesignEdge], fixed: bool
) -> None:
    """Refuse a normal stress given on other boundary parts (the holes) than the rectangle's."""
    if any(_normal_keys(e, fixed) for e in sides.values()):
        return
    given = ", ".join(key for e in edges if e.name not in sides for key in _normal_keys(e, fixed))
    raise InputError(
        f"design: {given or 'no normal stress'} on none of the rectangle's edges: EN 1993-1-5 "
        "4.4 takes the direct stress across two opposite edges of the plate element (its "
        "loaded edges), from which the design output reads sigma_cr and psi; give "
        f"edges.NAME.normal_stress on two of {list(_NAMES)} or leave [design] out"
    )


def _loaded_pair(sides: dict[str, DesignEdge], fixed: bool) -> tuple[str, str]:
    """The pair of opposite edges given a normal stress, or refuse a biaxial one."""
    stressed = [
        f"edges.{name}.normal_stress" for name, e in sides.items() if any(_ends(e.normal_stress))
    ]
    stressed += [
        f"edges.{name}.fixed_normal_stress"
        for name, e in sides.items()
        if fixed and any(_ends(e.fixed_normal_stress))
    ]
    pairs = [pair for pair in _PAIRS if any(key.split(".")[1] in pair for key in stressed)]
    if len(pairs) != 1:
        given = ", ".join(stressed)
        raise InputError(
            f"design: {given} give normal stress in both directions (biaxial): EN 1993-1-5 "
            "4.4 describes direct stress in one direction (section 10 combines biaxial "
            "stresses, which is not done here); leave [design] out"
        )
    return pairs[0]


def _check_unloaded(e: DesignEdge) -> None:
    """Refuse an unloaded edge held in its plane, or free on springs."""
    if e.inplane != "free":
        raise InputError(
            f'design: edges.{e.name}.inplane = "{e.inplane}" holds an unloaded edge in '
            "its plane, which adds a transverse stress (Poisson's ratio times the direct "
            "stress) that EN 1993-1-5 4.4 does not describe: leave the unloaded edges "
            'free in their plane (inplane = "free") or [design] out'
        )
    if e.support == "free" and e.translational_stiffness > 0.0:
        raise InputError(
            f"design: edges.{e.name}.translational_stiffness: an unloaded edge on springs "
            "is neither supported (an internal element, EN 1993-1-5 Table 4.1) nor free "
            '(an outstand, Table 4.2): give it support = "simply_supported" or no springs'
        )


def _check_stress_ratio(loaded: list[DesignEdge], element: DesignElement) -> None:
    """Refuse a stress ratio psi (of the scaled stresses alone) outside the element's table."""
    best: tuple[float, float, int, str] = (0.0, 0.0, 0, "")
    for e in loaded:
        ends = [-v for v in _ends(e.normal_stress)]  # compression positive
        for k in (0, 1):
            if ends[k] > best[0]:
                best = (ends[k], ends[1 - k], k, e.name)
    sigma1, sigma2, k, name = best
    if sigma1 <= 0.0:
        return  # no scaled compression: the compression check says so
    psi = stress_ratio(sigma1, sigma2)
    at_free = element.free_end is None or k == element.free_end or psi == 1.0
    low, _ = psi_range(element.kind, at_free)
    if psi < low:
        raise InputError(
            f"design: edges.{name}.normal_stress gives the stress ratio psi = sigma_2/sigma_1 "
            f"= {ratio_text(psi, 4)}, outside EN 1993-1-5 {table_row(element.kind, at_free)}, "
            f"which covers 1 >= psi >= {low:g}: leave [design] out or change the stress gradient"
        )
