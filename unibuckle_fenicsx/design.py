r"""Design output: the plate slenderness and reduction factor of EN 1993-1-5 from this σ_cr.

EN 1993-1-5:2006 (Eurocode 3, *Design of steel structures*, part 1-5, *Plated structural
elements*, with its corrigendum AC:2009), clause 4.4 (the formulas:
:mod:`unibuckle_fenicsx.en1993`):

- 4.4(2): the relative plate slenderness :math:`\bar\lambda_p = \sqrt{f_y/\sigma_{cr}}`;
- the element, from the plate's edges parallel to the direct stress (its *unloaded*
  edges, :func:`~unibuckle_fenicsx.en1993.design_element`): both supported, an
  **internal** compression element, :math:`\rho = (\bar\lambda_p - 0.055(3 + \psi))/
  \bar\lambda_p^2 \le 1` above :math:`\bar\lambda_p = 0.5 + \sqrt{0.085 - 0.055\psi}`
  (eq. (4.2)) and Table 4.1 (:math:`1 \ge \psi \ge -3`); one free, an **outstand**,
  :math:`\rho = (\bar\lambda_p - 0.188)/\bar\lambda_p^2 \le 1` above 0.748 (eq. (4.3))
  and Table 4.2, whose row depends on where the larger compression acts (at the free
  edge :math:`1 \ge \psi \ge -3`, at the supported one :math:`1 \ge \psi \ge -1`);
- :math:`\psi = \sigma_2/\sigma_1`, the ratio of the loaded edge's end stresses with
  :math:`\sigma_1` the larger compression.
- a short plate (:math:`a/b < 1`, the note of 4.4(2)) may buckle like a column: 4.5.4(1)
  interpolates :math:`\rho_c = (\rho - \chi_c)\xi(2 - \xi) + \chi_c` between the
  plate's :math:`\rho` and the column's :math:`\chi_c` (curve a), :math:`\xi =
  \sigma_{cr}/\sigma_{cr,c} - 1` in [0, 1], with :math:`\sigma_{cr,c}` the plate's
  stress with the supports along its unloaded edges removed (4.5.3(1)): eq. (4.8),
  :math:`\pi^2 E t^2/(12(1 - \nu^2) a^2)`, between hinged loaded edges, four times that
  between clamped ones, a quarter of it between a clamped and a free one, none (a
  mechanism, :math:`\rho_c = \rho`) between two free ones (:func:`column_stress`),
  bounded by the plate's :math:`\sigma_{cr}` (the plate with those supports removed
  buckles at no higher a stress: :math:`\xi = 0`, :math:`\rho_c = \chi_c` at
  :math:`\sqrt{f_y/\sigma_{cr}}`, where a hole, say, puts :math:`\sigma_{cr}` below
  eq. (4.8)); at :math:`\xi \ge 1` it is
  :math:`\rho`; for :math:`a/b \ge 1` it is :math:`\rho`, the column fields are None
  and a note says why;

- the stress limit :math:`\rho f_y/\gamma_M` (:func:`~unibuckle_fenicsx.en1993.stress_limit`):
  at :math:`\psi = 1` 4.6(1) with :math:`\gamma_{M0}` (:math:`A_{eff} = \rho A`); at
  :math:`\psi < 1`, and for an outstand with :math:`\rho < 1` at :math:`\psi = 1`
  (its :math:`b_{eff}` at the supported edge: a shift :math:`e_N = (1 - \rho)c/2`),
  the reduced stress method of section 10 for direct stress alone
  (eq. (10.1), :math:`\gamma_{M1}`), as 4.6(1) then checks the effective section
  (:math:`A_{eff}`, :math:`W_{eff}`, :math:`e_N`), not computed here; ``[design]
  partial_factor`` is the factor of the one applied (EN 1993-1-1 6.1 recommends 1.0 for
  both);
- the effective widths of Table 4.1 or 4.2 with that reduction factor, and where they
  lie (:func:`~unibuckle_fenicsx.en1993.effective_widths`);
- a loaded edge in compression plus bending (:math:`\psi < 0`) carries tension at its
  other end: where it reaches :math:`f_y/\gamma_{M0}` (EN 1993-1-1 6.2.1(5)) before
  :math:`\sigma_1` reaches :math:`\rho f_y/\gamma_{M1}` (:math:`\sigma_t/\sigma_1 >
  1/\rho`, the critical state's stresses scaled together, one partial factor for both),
  yield governs, and the output says so with the :math:`\sigma_1` at which it yields.

What the clause does not describe is refused when the problem is built (both unloaded
edges free, biaxial stress, a temperature rise, a plate that is not a rectangle, ...);
a rectangle with holes is classified by its edges, and the output notes that the
clause describes plates without openings.
Here :math:`\sigma_{cr}` is the critical state this package computes: the largest
compressive normal stress on a loaded edge at the critical load (the fixed part plus
:math:`\lambda_c` times the scaled one), and :math:`\psi` the stress ratio along that
edge. The clause's reduction factors were calibrated on plates that buckle freely to
both sides (bilateral buckling); with an obstacle this :math:`\sigma_{cr}` is the
unilateral one, and applying them to it is outside that calibration: the output says
so. A critical load not proven the lowest (a KKT point, or bracketed) is that of an
admissible mode, so the critical stress may lie lower, down to the certificate's verified
lower bound: the output then gives the same quantities at that bound too
(:func:`at_lower_bound`), the safe values. With shear in the load, EN 1993-1-5
combines the stresses by the reduced stress method (section 10,
:math:`\bar\lambda_p = \sqrt{\alpha_{ult,k}/\alpha_{cr}}`), which is not done here: the
output then notes that ρ is the direct stress's.
"""

from __future__ import annotations

import math

from msgspec import UNSET, Struct, UnsetType

from unibuckle_fenicsx.en1993 import (
    INTERNAL,
    OUTSTAND,
    OUTSTAND_SHIFT,
    SHEAR_NOT_CHECKED,
    DesignElement,
    EffectiveWidths,
    buckling_factor,
    column_end_factor,
    column_type,
    design_element,
    effective_widths,
    plate_euler_stress,
    psi_range,
    ratio_text,
    reduction_factor,
    stainless_note,
    steel_poisson_note,
    stress_limit,
    stress_ratio,
    table_row,
    yield_stress_note,
)
from unibuckle_fenicsx.spec import DesignSpec, ProblemSpec, stress_ends

__all__ = [
    "CLAUSES",
    "DesignRecord",
    "ElementLimits",
    "at_lower_bound",
    "clauses",
    "column_stress",
    "design_output",
    "effective_widths_text",
    "euler_stress",
    "limit_clause_text",
    "reduction_factor",
    "significant",
]

#: The clauses the design output of an internal element rests on (:func:`clauses`).
CLAUSES = (
    "EN 1993-1-5:2006+AC:2009, 4.4(2), eq. (4.2): reduction factor rho of an internal "
    "compression element; 4.4(2): relative slenderness; Table 4.1: stress ratio psi, "
    "effective widths"
)

#: Said with every design output.
CALIBRATION = (
    "EN 1993-1-5's rho (4.4(2)) was calibrated on plates buckling freely to both sides "
    "(bilateral buckling); it is applied here to this package's sigma_cr"
)


def significant(value: float | None, digits: int = 4) -> str:
    """``value`` to ``digits`` significant digits, its trailing zeros kept ("none" for None).

    ``format(x, ".4g")`` drops them, and a stress in Pa then reads as one digit:
    2.000149e8 as "2e+08" (anything from 1.5e8 to 2.5e8), where "2.000e+08" says four.
    """
    if value is None:
        return "none"
    text = f"{value:#.{digits}g}"
    return text[:-1] if text.endswith(".") else text


class ElementLimits(Struct, kw_only=True):
    r"""An element's stress limit and effective widths (a plate's design, a box's face).

    The base of :class:`DesignRecord` and
    :class:`~unibuckle_fenicsx.section_design.FaceDesign`; None without :math:`\rho`.

    Attributes:
        partial_factor_name: "gamma_M0" (4.6(1)) or "gamma_M1" (section 10): what
            ``partial_factor`` stands for in the limit ``reduced_design_stress_Pa``.
        stress_limit_clause: The clause of that limit
            (:func:`~unibuckle_fenicsx.en1993.stress_limit`): 4.6(1) at :math:`\psi =
            1` where the effective section is :math:`\rho A` without a shift
            :math:`e_N`; section 10, eq. (10.1), the reduced stress method with direct
            stress alone, at :math:`\psi < 1`, for an outstand with :math:`\rho < 1`
            and for a face of a section under bending.
        element_width_m: :math:`\bar b` (internal) or :math:`c` (outstand): the loaded
            edge's length.
        compressed_width_m: :math:`b_c`, its compressed part (``element_width_m`` for
            :math:`\psi \ge 0`, ``element_width_m``/(1 - psi) below).
        effective_width_m: :math:`b_{eff}`, Table 4.1 or 4.2 with ``reduction_factor``.
        effective_width_1_m: :math:`b_{e1}` (internal element; None for an outstand).
        effective_width_2_m: :math:`b_{e2}` (internal element; None for an outstand).
        effective_widths_row: The table row applied.
        effective_widths_placed: Where the widths lie, naming the edges.
    """

    partial_factor_name: str | None = None
    stress_limit_clause: str | None = None
    element_width_m: float | None = None
    compressed_width_m: float | None = None
    effective_width_m: float | None = None
    effective_width_1_m: float | None = None
    effective_width_2_m: float | None = None
    effective_widths_row: str | None = None
    effective_widths_placed: str | None = None

    def put_limit_and_widths(
        self,
        w: EffectiveWidths,
        psi: float,
        named: str,
        shear: bool = False,
        shift: str | None = None,
    ) -> None:
        """Set the fields from ``psi`` and the widths ``w``; ``named``: where its ends lie.

        ``shear``: the load has shear, which the stress limit does not check; ``shift``:
        why the effective section at psi = 1 is shifted (4.6(1) not applied,
        :func:`~unibuckle_fenicsx.en1993.stress_limit`), None where it is not.
        """
        self.partial_factor_name, self.stress_limit_clause = stress_limit(psi, shear, shift)
        self.element_width_m, self.compressed_width_m = w.width, w.compressed
        self.effective_width_m = w.effective
        self.effective_width_1_m, self.effective_width_2_m = w.first, w.second
        self.effective_widths_row = w.row
        self.effective_widths_placed = f"{w.placed} ({named})"


class DesignRecord(ElementLimits, kw_only=True):
    r"""The design quantities of a critical load (the JSON's ``design``).

    Attributes:
        yield_stress_Pa: :math:`f_y`.
        partial_factor: ``[design] partial_factor``: :math:`\gamma_{M0}` at
            :math:`\psi = 1` (4.6(1)) and in the tension-yield check (EN 1993-1-1
            6.2.1(5)), :math:`\gamma_{M1}` at :math:`\psi < 1` and for an outstand
            with :math:`\rho < 1` (section 10); which one the stress limit uses:
            ``partial_factor_name``.
        element: "internal" or "outstand" (:func:`~unibuckle_fenicsx.en1993.design_element`).
        free_edge: An outstand's free unloaded edge (None for an internal element).
        table: The table row of :math:`\psi` and :math:`k_\sigma` (Table 4.1 or 4.2).
        edge: The loaded edge of the largest compression.
        sigma_cr_Pa: :math:`\sigma_1`, that compression at the critical load; <= 0 when
            the loaded edges are in tension there (a fixed compression outgrown by a
            scaled tension), and then ``psi`` and the fields below are None.
        clauses: The clauses applied.
        notes: What the output rests on, and what it leaves out.
        psi: :math:`\psi = \sigma_2/\sigma_1` along that edge.
        relative_slenderness: :math:`\bar\lambda_p`, 4.4(2).
        k_sigma: This plate's buckling factor :math:`k_\sigma = \sigma_{cr}/\sigma_E`,
            :math:`\sigma_E = \pi^2 E t^2/(12(1 - \nu^2) b^2)` with b the loaded edge's
            length (EN 1993-1-5 Annex A.1, eq. (A.2)): what the plate's edges, aspect,
            obstacle and points give.
        k_sigma_table: The table's :math:`k_\sigma` at :math:`\psi`, for comparison: a
            long plate with hinged edges (Table 4.1 or 4.2), not this plate's (a clamped
            square's ``k_sigma`` is 10.1, its ``k_sigma_table`` 4.0); None outside the
            table's range of :math:`\psi`.
        reduction_factor: The reduction factor to apply: for a short plate (a/b < 1,
            the note of 4.4(2)) :math:`\rho_c` of 4.5.4(1), the plate-type
            ``plate_reduction_factor`` interpolated towards the column-type
            ``column_reduction_factor`` where :math:`\xi < 1`; else
            ``plate_reduction_factor``. None outside the table's range of :math:`\psi`.
        plate_reduction_factor: :math:`\rho`, eq. (4.2) or (4.3).
        column_critical_stress_Pa: :math:`\sigma_{cr,c}`, the plate as a column between
            its loaded edges, its unloaded edges' supports removed (4.5.3(1)): eq. (4.8),
            :math:`\pi^2 E t^2/(12(1 - \nu^2) a^2)` with a the plate's length along the
            stress, for hinged loaded edges, times 4 for clamped ones
            (:func:`column_stress`), bounded by ``sigma_cr_Pa`` (the plate with those
            supports removed buckles at no higher a stress; a note says when); 0 when
            free loaded edges leave the column a mechanism (``xi`` None, the reduction
            factor the plate's). None, as
            ``column_reduction_factor`` and ``xi``, for a/b >= 1, where the column-type
            check is not applied (a note says so).
        column_reduction_factor: :math:`\chi_c` at :math:`\bar\lambda_c = \sqrt{f_y/
            \sigma_{cr,c}}`, curve a (:math:`\alpha` = 0.21, 4.5.3(4), (5)).
        xi: :math:`\xi = \sigma_{cr}/\sigma_{cr,c} - 1` bounded to
            :math:`0 \le \xi \le 1` (4.5.4(1)), the value used; below 1 on a short
            plate column-type buckling lowers the reduction factor.
        xi_unclipped: :math:`\sigma_{cr}/\sigma_{cr,c} - 1` itself, before the bounds.
        reduced_design_stress_Pa: :math:`\rho_c f_y/\gamma_M`, the stress limit of
            :math:`\sigma_1` (absent without :math:`\rho`), by ``stress_limit_clause``
            (that and the effective widths: :class:`ElementLimits`).
        tension_Pa: The largest tensile normal stress on the loaded edges at the
            critical state (Pa, > 0; an edge in compression plus bending, psi < 0);
            None without tension.
        sigma_1_at_tension_yield_Pa: :math:`\sigma_1` when that tension reaches
            :math:`f_y/\gamma_{M0}` (EN 1993-1-1 6.2.1(5)), the critical state's
            stresses scaled together: :math:`f_y\sigma_1/(\gamma_{M0}\sigma_t)`; None
            without tension.
        tension_yield_first: Whether the tension edge yields before :math:`\sigma_1`
            reaches :math:`\rho f_y/\gamma_M` (:math:`\sigma_t/\sigma_1 > 1/\rho`, one
            partial factor for both):
            then the element's stress is limited by yield, not by its buckling, and
            ``sigma_1_at_tension_yield_Pa``, below ``reduced_design_stress_Pa``, governs.
            None without tension or without :math:`\rho`.
        lower_bound: When the critical load is not proven the lowest (a KKT point, or
            bracketed), the same quantities at the verified lower bound of the critical
            load, the safe value (:func:`at_lower_bound`); absent when proven.
    """

    yield_stress_Pa: float
    partial_factor: float
    element: str
    free_edge: str | None
    table: str
    edge: str
    sigma_cr_Pa: float
    clauses: str
    notes: list[str]
    psi: float | None = None
    relative_slenderness: float | None = None
    k_sigma: float | None = None
    k_sigma_table: float | None = None
    reduction_factor: float | None = None
    plate_reduction_factor: float | None = None
    column_critical_stress_Pa: float | None = None
    column_reduction_factor: float | None = None
    xi: float | None = None
    xi_unclipped: float | None = None
    reduced_design_stress_Pa: float | UnsetType = UNSET
    tension_Pa: float | None = None
    sigma_1_at_tension_yield_Pa: float | None = None
    tension_yield_first: bool | None = None
    lower_bound: DesignRecord | UnsetType = UNSET


def clauses(element: DesignElement, free_edge_most_compressed: bool = True) -> str:
    """The clauses the output rests on, naming the element and the table row."""
    if element.kind == INTERNAL:
        return CLAUSES
    return (
        "EN 1993-1-5:2006+AC:2009, 4.4(2), eq. (4.3): reduction factor rho of an outstand "
        f"compression element (edges.{element.free_edge} free); 4.4(2): relative "
        f"slenderness; {table_row(element.kind, free_edge_most_compressed)}: stress ratio psi, "
        "effective width"
    )


def _critical_edge_ends(
    spec: ProblemSpec, load: float, edges: tuple[str, str]
) -> list[tuple[str, list[float]]]:
    """Each loaded edge's normal stress at its two ends at the critical state (tension > 0).

    Pa, over the ``edges`` named, the fixed part included: its stress per unit load
    times ``load`` plus the fixed stress times the fixed part's factor.
    """
    factor = spec.load.fixed_factor
    return [
        (e.name, [factor * f + load * s for s, f in zip(
            stress_ends(e.normal_stress), stress_ends(e.fixed_normal_stress), strict=True
        )])
        for e in spec.plate.edges
        if e.name in edges
    ]  # fmt: skip


def _critical_edge_stress(
    spec: ProblemSpec, load: float, edges: tuple[str, str]
) -> tuple[float, float, int, str]:
    """(sigma_1, sigma_2, end of sigma_1, edge): the largest compression at the critical state.

    Pa, compression positive, over the loaded ``edges``; sigma_2 is the other end (0
    start, 1 end) of the same edge. Edges in tension alone: the least tension, negative.
    """
    best = (-math.inf, 0.0, 0, "")
    for name, stresses in _critical_edge_ends(spec, load, edges):
        ends = [-v for v in stresses]
        for k in (0, 1):
            if ends[k] > best[0]:
                best = (ends[k], ends[1 - k], k, name)
    return best


def _critical_edge_tension(spec: ProblemSpec, load: float, edges: tuple[str, str]) -> float:
    """The largest tensile normal stress (Pa, > 0) on the loaded ``edges`` at the critical state.

    0 when they carry none.
    """
    return max([0.0, *(v for _, ends in _critical_edge_ends(spec, load, edges) for v in ends)])


def design_output(spec: ProblemSpec, design: DesignSpec, load: float) -> DesignRecord:
    """The design quantities of the critical load ``load``, see the module docstring."""
    element = design_element(spec)
    sigma1, sigma2, end, edge = _critical_edge_stress(spec, load, element.loaded)
    psi = stress_ratio(sigma1, sigma2) if sigma1 > 0.0 else None
    at_free = element.free_end is None or end == element.free_end or psi == 1.0
    shear = _has_shear(spec)
    out = DesignRecord(
        yield_stress_Pa=design.yield_stress,
        partial_factor=design.partial_factor,
        element=element.kind,
        free_edge=element.free_edge,
        table=table_row(element.kind, at_free),
        edge=edge,
        sigma_cr_Pa=sigma1,
        clauses=clauses(element, at_free),
        notes=[CALIBRATION, *_scope_notes(spec, design, shear)],
    )
    if psi is None:
        out.notes.append(
            f"the loaded edges are in tension at the critical state (least tension "
            f"{significant(-sigma1)} Pa on edges.{edge}: the fixed compression is outgrown by the "
            "scaled tension): no sigma_cr, slenderness or rho"
        )
        return out
    out.psi = psi
    tension = _critical_edge_tension(spec, load, element.loaded)
    if tension > 0.0:
        out.tension_Pa = tension
        out.sigma_1_at_tension_yield_Pa = (
            design.yield_stress / design.partial_factor * sigma1 / tension
        )
    slenderness = math.sqrt(design.yield_stress / sigma1)
    out.relative_slenderness = slenderness
    sigma_e = euler_stress(spec, element.loaded)
    out.k_sigma = sigma1 / sigma_e
    low, _ = psi_range(element.kind, at_free)
    if psi < low:  # only with a fixed part: a scaled one alone is refused beforehand
        out.notes.append(f"psi = {ratio_text(psi)} < {low:g}: outside {out.table}, no rho")
        return out
    _reduced_stress(out, spec, design, element, min(psi, 1.0), slenderness, end, at_free, shear)
    return out


def _has_shear(spec: ProblemSpec) -> bool:
    """Whether an edge of the plate carries a shear stress (scaled or fixed)."""
    return any(
        any(stress_ends(e.shear_stress)) or any(stress_ends(e.fixed_shear_stress))
        for e in spec.plate.edges
    )


def _scope_notes(spec: ProblemSpec, design: DesignSpec, shear: bool) -> list[str]:
    """The notes on what lies outside 4.4's scope (material, holes, restraints, shear)."""
    notes = []
    for note in (
        stainless_note(spec.material.E),
        steel_poisson_note(spec.material.nu),
        yield_stress_note(design.yield_stress, spec.plate.thickness, "plate.thickness"),
    ):
        if note is not None:
            notes.append(note)
    if spec.plate.holes:
        notes.append(
            "the plate has holes (plate.holes): 4.4 describes a plate without openings; "
            "the element is the rectangle's, and sigma_cr (computed with the holes) "
            "includes their effect"
        )
    foundation = 'a bilateral foundation (obstacle.side = "both")'
    unilateral = "sigma_cr is the unilateral critical stress"
    restrained = {
        (True, False): f"with an obstacle {unilateral}",
        (False, True): f"with {foundation} sigma_cr includes the foundation's stiffness",
        (True, True): f"with an obstacle and {foundation} {unilateral} and includes the "
        "foundation's stiffness",
    }.get(
        (bool(spec.one_sided_points or spec.unilateral_obstacles), bool(spec.bilateral_foundations))
    )
    if restrained is not None:
        notes.append(f"{restrained}: outside the calibration of 4.4(2)")
    if any(p.kind != "one-sided" for p in spec.points):
        notes.append(
            "with point restraints (points: bilateral ties or springs) sigma_cr includes "
            "them: 4.4 describes a plate held by its edges alone, outside the calibration "
            "of 4.4(2)"
        )
    if shear:
        notes.append(
            "the load has shear: EN 1993-1-5 section 10 (reduced stress method) would "
            "combine it; rho here is the direct stress's, with this sigma_cr"
        )
    return notes


def _reduced_stress(
    out: DesignRecord,
    spec: ProblemSpec,
    design: DesignSpec,
    element: DesignElement,
    psi: float,
    slenderness: float,
    end: int,
    at_free: bool,
    shear: bool,
) -> None:
    """Fill ``out`` from the table's k and rho on: the reduced stress and the widths.

    ``psi`` is the stress ratio (at most 1) within the table's range, ``slenderness``
    the relative slenderness; ``out`` holds sigma_cr (``sigma_cr_Pa``) already.
    """
    sigma1 = out.sigma_cr_Pa
    out.k_sigma_table = buckling_factor(element.kind, psi, at_free)
    rho = reduction_factor(slenderness, psi, element.kind, at_free)
    out.plate_reduction_factor = rho
    out.reduction_factor = _column_type(out, spec, design, element, rho)
    rho_c = out.reduction_factor
    out.reduced_design_stress_Pa = rho_c * design.yield_stress / design.partial_factor
    _widths(out, element, rho_c, end, at_free, euler_length(spec, element.loaded), shear)
    out.clauses += f"; {out.stress_limit_clause}"
    if out.tension_Pa is not None:
        # sigma_1 f_y/(gamma sigma_t) < rho f_y/gamma (gamma = partial_factor in both):
        # sigma_t/sigma_1 > 1/rho
        out.tension_yield_first = out.tension_Pa * rho_c > sigma1
        if out.tension_yield_first:
            out.notes.append(_tension_note(out, rho_c))


def _widths(
    out: DesignRecord,
    element: DesignElement,
    rho: float,
    end: int,
    at_free: bool,
    width: float,
    shear: bool,
) -> None:
    """Put the effective widths of Table 4.1 or 4.2 in ``out``, naming the edges they lie at.

    ``end`` is the end (0 start, 1 end) of the loaded edge where sigma_1 acts, ``width``
    the loaded edge's length; ``shear``: the load has shear (the stress limit's clause).
    """
    assert out.psi is not None
    psi = min(out.psi, 1.0)
    if element.free_edge is None:
        named = (
            f"sigma_1 end: edges.{element.unloaded[end]}, "
            f"other end: edges.{element.unloaded[1 - end]}"
        )
    else:
        supported = next(e for e in element.unloaded if e != element.free_edge)
        named = f"supported edge: edges.{supported}, free edge: edges.{element.free_edge}"
    widths = effective_widths(element.kind, rho, width, psi, at_free)
    # An outstand's b_eff = rho c lies at its supported edge: with rho < 1 its centroid
    # shifts by (1 - rho) c/2, and 4.6(1) would need e_N (and W_eff) even at psi = 1.
    shift = OUTSTAND_SHIFT if element.kind == OUTSTAND and rho < 1.0 else None
    out.put_limit_and_widths(widths, psi, named, shear, shift)


def _tension_note(out: DesignRecord, rho: float) -> str:
    """The note that the tension edge yields before sigma_1 reaches rho f_y/gamma_M."""
    return (
        f"the tension edge yields first (EN 1993-1-1 6.2.1(5)): its {significant(out.tension_Pa)} "
        f"Pa at the critical state, {significant((out.tension_Pa or 0.0) / out.sigma_cr_Pa)} "
        f"times sigma_1, reaches f_y/gamma_M0 when sigma_1 = "
        f"{significant(out.sigma_1_at_tension_yield_Pa)} Pa, below "
        f"rho f_y/{out.partial_factor_name} = "
        f"{significant(rho * out.yield_stress_Pa / out.partial_factor)} Pa (rho = "
        f"{significant(rho)}): yield governs the element, not its buckling"
    )


def _column_type(
    out: DesignRecord, spec: ProblemSpec, design: DesignSpec, element: DesignElement, rho: float
) -> float:
    """The reduction factor with column-type buckling (EN 1993-1-5 4.5.3, 4.5.4), and its notes.

    A short plate (a/b < 1, the note of 4.4(2)) gets rho_c of 4.5.4(1), with sigma_cr,c the
    plate as a column between its loaded edges as they are supported (4.5.3(1));
    otherwise rho, the column fields left None and the reason noted.
    """
    sigma1 = out.sigma_cr_Pa
    column, ends = column_stress(spec, element.loaded)
    plate = spec.plate
    aspect = plate.length / plate.width  # a/b, a along the stress
    if element.loaded == ("bottom", "top"):
        aspect = 1.0 / aspect
    if aspect >= 1.0:
        xi = sigma1 / column - 1.0 if column > 0.0 else math.inf
        out.notes.append(
            "column-type buckling (EN 1993-1-5 4.5.4) not applied: a/b = "
            f"{ratio_text(aspect)} >= 1, and the note of 4.4(2) asks for it below 1; rho is "
            "the plate-type"
            + (
                f" (the plate as a column, {ends}, would buckle at sigma_cr,c = "
                f"{significant(column)} Pa: xi = sigma_cr/sigma_cr,c - 1 = {ratio_text(xi)} < 1, "
                "so column-like behaviour is not excluded)"
                if xi < 1.0
                else ""
            )
        )
        return rho
    out.clauses += "; 4.5.3(1), 4.5.4(1): column-type buckling, rho_c"
    if column == 0.0:  # the column a mechanism: xi infinite, rho_c = rho
        out.column_critical_stress_Pa, out.column_reduction_factor = 0.0, 0.0
        out.notes.append(
            f"column-type buckling (EN 1993-1-5 4.5.4(1)): the plate as a column ({ends}): "
            "sigma_cr,c = 0, xi >= 1, rho_c = rho"
        )
        return rho
    # The plate with the supports along its unloaded edges removed (4.5.3(1)) buckles at
    # no higher a stress than with them (fewer constraints: a smaller Rayleigh quotient):
    # sigma_cr,c <= sigma_cr,p. A column stress above the plate's (eq. (4.8) knows no
    # hole, no fixed shear, no shear deformation) is bounded by it: xi = 0, rho_c = chi_c
    # at sqrt(f_y/sigma_cr,p), not the larger chi_c of the column's own stress.
    if column > sigma1:
        out.notes.append(
            f"column-type buckling (EN 1993-1-5 4.5.3(1), 4.5.4(1)): the plate as a column "
            f"({ends}) gives {significant(column)} Pa, above the plate's sigma_cr = "
            f"{significant(sigma1)} Pa; with the supports along its unloaded edges removed "
            "the plate buckles at no higher a stress, so sigma_cr,c = sigma_cr (xi = 0)"
        )
        column = sigma1
    reduced = column_type(rho, sigma1, column, design.yield_stress)
    chi, rho_c = reduced.chi, reduced.rho
    out.column_critical_stress_Pa, out.column_reduction_factor = column, chi
    out.xi, out.xi_unclipped = reduced.xi_used, reduced.xi
    if out.xi < 1.0:
        out.notes.append(
            f"column-type buckling (EN 1993-1-5 4.5.4(1)): xi = sigma_cr/sigma_cr,c - 1 = "
            f"{ratio_text(reduced.xi)} < 1, rho_c = {significant(rho_c)} between the plate's rho = "
            f"{significant(rho)} and the column's chi_c = {significant(chi)} (sigma_cr,c: the "
            f"plate as a column, {ends})"
        )
    else:
        out.notes.append(
            f"column-type buckling (EN 1993-1-5 4.5.4(1)): sigma_cr/sigma_cr,c - 1 = "
            f"{ratio_text(reduced.xi)} >= 1, xi = 1, rho_c = rho (sigma_cr,c: the plate as a "
            f"column, {ends})"
        )
    return rho_c


def column_stress(spec: ProblemSpec, loaded: tuple[str, str]) -> tuple[float, str]:
    r"""(:math:`\sigma_{cr,c}` (Pa), its ends in words): the plate as a column (4.5.3(1)).

    "The buckling stress with the supports along the longitudinal edges removed": the
    column between the ``loaded`` edges, each as it is supported: hinged (simply
    supported, hard or soft), clamped, on its rotational springs, or free (its deflection
    on its translational springs, or on none)
    (:func:`~unibuckle_fenicsx.en1993.column_end_factor` times eq. (4.8)). 0 when the
    ends leave the column a mechanism (both loaded edges free, or one free and the other
    hinged): no column-type buckling.
    """
    hinged = euler_stress(spec, loaded, along=True)
    named = {e.name: e for e in spec.plate.edges}
    plate, material = spec.plate, spec.material
    d = material.E * plate.thickness**3 / (12.0 * (1.0 - material.nu**2))
    length = plate.length if loaded == ("left", "right") else plate.width  # a
    kappas, taus, words = [], [], []
    for name in loaded:
        e = named.get(name)
        support = "free" if e is None else e.support
        kappa = 0.0 if e is None else e.rotational_stiffness * length / d
        tau = 0.0 if e is None else e.translational_stiffness * length**3 / d
        if support == "clamped":
            kappa, tau, word = math.inf, math.inf, "clamped"
        elif support != "free":
            tau, word = math.inf, "on rotational springs" if kappa > 0.0 else "hinged"
        else:
            springs = [w for w, v in (("rotational", kappa), ("translational", tau)) if v > 0.0]
            word = "free" + (f" on {' and '.join(springs)} springs" if springs else "")
        kappas.append(kappa)
        taus.append(tau)
        words.append(f"{name} {word}")
    factor = column_end_factor(kappas[0], kappas[1], taus[0], taus[1])
    if factor == 0.0:
        return 0.0, f"{' and '.join(words)}: a mechanism, no column buckling stress"
    how = "eq. (4.8)" if factor == 1.0 else f"{factor:.4g} x eq. (4.8)"
    return factor * hinged, f"{' and '.join(words)}: {how}"


def euler_length(spec: ProblemSpec, loaded: tuple[str, str], *, along: bool = False) -> float:
    """The length (m) of the ``loaded`` edges: the y extent for left and right, else x.

    With ``along``, the plate's length along the stress instead (the other extent).
    """
    plate = spec.plate
    return plate.width if (loaded == ("left", "right")) != along else plate.length


def euler_stress(spec: ProblemSpec, loaded: tuple[str, str], *, along: bool = False) -> float:
    r""":math:`\sigma_E = \pi^2 E t^2/(12(1 - \nu^2) b^2)` (Pa), EN 1993-1-5 eq. (A.2).

    b is the length of the ``loaded`` edges (:func:`euler_length`): the y extent for left
    and right, the x extent for bottom and top; with ``along``, the plate's length a along
    the stress instead: :math:`\sigma_{cr,c}`, the plate as a column (4.5.3(2), eq.
    (4.8)). The material is isotropic (the design output refuses a laminate and a Voigt
    matrix).
    """
    material = spec.material
    length = euler_length(spec, loaded, along=along)
    return plate_euler_stress(material.E, material.nu, spec.plate.thickness, length)


def effective_widths_text(d: ElementLimits, length: float, name: str) -> str:
    """The design line's effective widths, '' without them (in ``name``, m / ``length``)."""
    if d.effective_width_m is None:
        return ""
    text = f"; effective width b_eff = {significant(d.effective_width_m / length)} {name}"
    if d.effective_width_1_m is not None and d.effective_width_2_m is not None:
        text += (
            f" (b_e1 {significant(d.effective_width_1_m / length)}, "
            f"b_e2 {significant(d.effective_width_2_m / length)} {name})"
        )
    if d.compressed_width_m != d.element_width_m:
        text += f" of b_c = {significant((d.compressed_width_m or 0.0) / length)} {name}"
    return text


def limit_clause_text(factor: str | None, clause: str | None = None) -> str:
    """The design line's clause of rho f_y/gamma_M ('' without it).

    ``factor``: the record's ``partial_factor_name``, "gamma_M0" for 4.6(1), "gamma_M1"
    for section 10 (:func:`~unibuckle_fenicsx.en1993.stress_limit`); ``clause``: the
    record's ``stress_limit_clause``; the line says when it leaves the load's shear
    unchecked (:data:`~unibuckle_fenicsx.en1993.SHEAR_NOT_CHECKED`).
    """
    if factor is None:
        return ""
    shear = clause is not None and SHEAR_NOT_CHECKED in clause
    if factor == "gamma_M0":
        return f", rho f_y/{factor} 4.6(1)" + (
            f" (direct stress; {SHEAR_NOT_CHECKED})" if shear else ""
        )
    stresses = f"tau = 0: {SHEAR_NOT_CHECKED}" if shear else "direct stress"
    return f", rho f_y/{factor} section 10 eq. (10.1) (reduced stress method, {stresses})"


#: Said when the critical load is not proven the lowest.
UNPROVEN = (
    "sigma_cr is that of a critical state not proven the lowest: the critical stress may "
    "lie lower, down to the verified lower bound; lower_bound holds the design quantities "
    "there (the safe values)"
)


def at_lower_bound(
    record: DesignRecord, spec: ProblemSpec, design: DesignSpec, lower: float
) -> DesignRecord:
    """``record`` with the design quantities at the verified lower bound ``lower`` added.

    A critical load not proven the lowest is that of an admissible mode: the critical
    load may lie lower, down to the certificate's lower bound, so sigma_cr, and with it
    the slenderness and rho, may be on the unsafe side; the output gives both.
    """
    record.lower_bound = design_output(spec, design, lower)
    record.lower_bound.notes = []  # the same as the record's
    record.notes.append(UNPROVEN)
    return record
