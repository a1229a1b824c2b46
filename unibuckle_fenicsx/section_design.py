r"""Design output of a section: EN 1993-1-5 per face of a box, and EN 1994-1-1's wall limits.

A section's ``[design]`` table (the plate's, :class:`~unibuckle_fenicsx.spec.DesignSpec`)
asks for the design quantities of its critical state :math:`\lambda_c`:

- :math:`\sigma_{cr}`, the largest compressive axial stress in the walls at
  :math:`\lambda_c` (the axial part plus the bending part at the extreme fibre), and the
  section's relative slenderness :math:`\bar\lambda = \sqrt{f_y/\sigma_{cr}}`;
- for a **box**, each face as an *internal* compression element of EN 1993-1-5:2006+AC:2009,
  4.4(2) (both its edges held by the neighbouring faces): the face's
  :math:`\sigma_{cr}` is its largest compression at the section's critical state (the walls
  buckle together, one load factor for all), :math:`\psi = \sigma_2/\sigma_1` the ratio of
  the axial stresses at its two edges (on a flange, a face at constant z, the gross
  section's: 1; on a web, a face spanning the depth, 4.4(3)'s, below),
  :math:`\bar\lambda_p = \sqrt{f_y/\sigma_{cr}}`, the buckling factor of Table 4.1 at
  that :math:`\psi`, and
  :math:`\rho` by eq. (4.2) (:mod:`unibuckle_fenicsx.en1993`); a face in tension has none;
  a face shorter than it is wide (:math:`a/b < 1`, a the section's length: a stub), by
  the note of 4.4(2), :math:`\rho_c` of 4.5.4(1) instead, between :math:`\rho` and the
  column-type :math:`\chi_c` (curve a; 4.5.3(1): :math:`\sigma_{cr,c}` of the face as a
  column between the section's ends, eq. (4.8) :math:`\pi^2 E t^2/(12(1 - \nu^2) a^2)`
  between simply supported ones, 4 times it between clamped ones), as a plate's
  (:mod:`unibuckle_fenicsx.design`); the face's stress limit :math:`\rho f_y/\gamma_M`
  (4.6(1) with :math:`\gamma_{M0}` at :math:`\psi = 1` in a section without bending,
  whose effective section has no shift :math:`e_N`; the reduced stress method of
  section 10 with :math:`\gamma_{M1}` below, and on every face of a bent section,
  :func:`~unibuckle_fenicsx.en1993.stress_limit`) and its effective widths of Table 4.1
  (:func:`~unibuckle_fenicsx.en1993.effective_widths`; :math:`\bar b` the face's
  mid-line width, the one computed);
- a web's :math:`\psi` by EN 1993-1-5 4.4(3): "for web elements the stress ratio
  :math:`\psi` used in Table 4.1 should be obtained using a stress distribution based on
  the effective area of the compression flange and the gross area of the web" (a
  flange's from the gross section). The compression flange is the one the bending
  compresses (:func:`web_compressions`), reduced to its effective area :math:`\rho b t`
  (its ``reduction_factor``, :math:`\rho_c` on a stub; at :math:`\psi = 1` its
  :math:`b_{e1} = b_{e2}` lie at its corners, all of it at the flange's mid-line z); the
  webs and the other flange gross; mid-line widths throughout (the faces' :math:`\bar
  b`, not 4.4(2)'s :math:`b - 3t` of a hollow section's flange). The input is the gross
  section's stress per unit load, :math:`\sigma_a + \sigma_b z/(d/2)`, an axial and a
  bending part; the web's distribution is the axial part plus the bending part about
  the neutral axis :math:`z'` of that section (its first moment of area), linear, and
  equal at the compression flange to the gross bending stress there, so that the
  compression edge keeps the computed stress (the web's :math:`\sigma_1`, its
  :math:`\sigma_{cr}` and slenderness stay the computed ones): :math:`\sigma(z) =
  \sigma_a - |\sigma_b|(z - z')/(z_c - z')`, :math:`z_c` the compression flange's z.
  This follows EN 1993-1-5 on an axial force with a moment: 4.3(3) takes :math:`A_{eff}` under
  uniform compression (for the doubly symmetric box centred, no shift :math:`e_N`, a
  uniform stress), 4.3(4) :math:`W_{eff}` under bending alone, where only the
  compression flange is reduced and 4.4(3) gives the web's :math:`\psi`; their ratio is
  the input's :math:`\sigma_a/\sigma_b` (the factors :math:`A/A_{eff}` and
  :math:`W/W_{eff}` of eq. (4.14) are not computed). Reducing a flange the axial force
  compresses too, with the gross N at the gross centroid, would shift :math:`z'` by the
  per-face :math:`\rho` of a section nearly in uniform compression, where 4.3(3) shifts
  nothing. The neutral axis moves towards the tension side: the web's compressed part
  and :math:`\psi` grow (never below the gross :math:`\psi`) and :math:`\rho` of eq.
  (4.2) falls. Without bending, or with the compression flange fully effective
  (:math:`\rho = 1`), :math:`\psi` is the gross one. ``psi_gross`` keeps the gross ratio;
  a note, the clauses and the summary line cite 4.4(3);
- a face whose :math:`\psi` lies below -3 (a web under bending with an axial tension) is
  outside Table 4.1 and eq. (4.2): no :math:`k_\sigma` or :math:`\rho`, a note and the
  summary say so (``faces_outside_table``);
- the tension fibre against yield, EN 1993-1-1 6.2.1(5): under bending with an axial
  tension it may reach :math:`f_y/\gamma_{M0}` at a smaller multiple of the critical load
  than the governing face reaches :math:`\rho f_y/\gamma_M` (one ``partial_factor``
  for both); then yield governs, and
  the output says so (``tension_yield_first``); a tube's tension fibre gets its multiple;
- for a **tube**, :math:`\bar\lambda` only: a circular wall is a shell, whose buckling
  reduction (EN 1993-1-6, section 8.5: the fabrication quality class, :math:`\alpha_x`,
  :math:`\chi_x`) this output does not apply;
- with a **core**, the limits of EN 1994-1-1:2004, 6.7.1(9) and Table 6.3, below which the
  local buckling of a concrete-filled section may be neglected in a composite column:
  :math:`\max(h/t) \le 52\varepsilon` for a rectangular section (h its greater overall
  dimension), :math:`d/t \le 90\varepsilon^2` for a circular one (d its outer diameter),
  :math:`\varepsilon = \sqrt{235/f_y}` with :math:`f_y` in N/mm². The overall dimensions
  are the mid-line ones plus t.

The clauses were calibrated on walls that buckle to both sides; with a core the computed
:math:`\sigma_{cr}` is the unilateral one, and the output says that applying 4.4(2) to it
is outside that calibration. The formulas are the codes' few lines; no maintained library
evaluates them for a computed :math:`\sigma_{cr}`, hence this module.
"""

from __future__ import annotations

import math
from typing import NamedTuple, Protocol

import msgspec
from msgspec import UNSET, Struct, UnsetType

from unibuckle_fenicsx.design import (
    CALIBRATION,
    UNPROVEN,
    ElementLimits,
    effective_widths_text,
    limit_clause_text,
    significant,
)
from unibuckle_fenicsx.en1993 import (
    INTERNAL,
    buckling_factor,
    column_end_factor,
    column_type,
    effective_widths,
    plate_euler_stress,
    psi_range,
    ratio_text,
    reduction_factor,
    stainless_note,
    stress_ratio,
    yield_stress_note,
)
from unibuckle_fenicsx.spec import DesignSpec

__all__ = [
    "FaceDesign",
    "SectionDesignRecord",
    "at_lower_bound",
    "face_compressions",
    "face_width",
    "member_note",
    "section_design",
    "web_compressions",
]

#: The clauses of a box's face.
FACE_CLAUSES = (
    "EN 1993-1-5:2006+AC:2009, 4.4(2), eq. (4.2): reduction factor rho of each face as an "
    "internal compression element; 4.4(2): relative slenderness; Table 4.1: psi, k_sigma, "
    "effective widths; 4.4(3): psi of a flange from the gross section, of a web from the "
    "effective compression flange and the gross webs"
)
#: Added where a face is shorter than its width (as a plate's record, only where applied).
COLUMN_CLAUSES = "4.5.3(1), 4.5.4(1): column-type buckling of a face shorter than its width, rho_c"
#: Why a face's stress limit is not 4.6(1) in a section under bending (even at psi = 1).
BENDING_SHIFT = (
    "the section is bent: its effective section (the compressed faces reduced) has its own "
    "W_eff and shift e_N"
)
#: The clause of a tube's slenderness.
TUBE_CLAUSES = (
    "relative slenderness sqrt(f_y/sigma_cr) only: a circular wall is a shell (EN 1993-1-6, "
    "8.5: its buckling reduction needs the fabrication quality class, not applied here)"
)
#: The clause of the filled sections' wall limits.
FILLED_CLAUSES = "EN 1994-1-1:2004, 6.7.1(9), Table 6.3: max(h/t) or max(d/t) of a filled section"


class DesignSection(Protocol):
    """What the design output reads of a section (its :class:`SectionParameters`)."""

    @property
    def shape(self) -> str: ...
    @property
    def thickness(self) -> float: ...
    @property
    def length(self) -> float: ...
    @property
    def E(self) -> float: ...
    @property
    def nu(self) -> float: ...
    @property
    def ends(self) -> str: ...
    @property
    def width(self) -> float | None: ...
    @property
    def depth(self) -> float | None: ...
    @property
    def diameter(self) -> float | None: ...
    @property
    def axial_stress(self) -> float: ...
    @property
    def bending_stress(self) -> float: ...
    @property
    def core(self) -> bool: ...
    @property
    def core_span(self) -> tuple[float, float] | None: ...
    def compression(self) -> float: ...
    def euler_stress(self) -> float: ...


class FaceDesign(ElementLimits, kw_only=True):
    r"""One face of a box as an internal compression element (EN 1993-1-5, 4.4(2)).

    Attributes:
        face: ``right``, ``top``, ``left`` or ``bottom`` (the result's ``faces``).
        sigma_cr_Pa: :math:`\sigma_1`, its largest compression at the critical state (Pa);
            <= 0: the face is in tension, and the fields below are None.
        psi: :math:`\psi = \sigma_2/\sigma_1` across the face: a web's by EN 1993-1-5
            4.4(3), from the section with its compression flange effective
            (:func:`web_compressions`), a flange's from the gross section.
        psi_gross: A web's :math:`\psi` of the gross section's stresses, where 4.4(3)'s
            ``psi`` differs from it (a compression flange with :math:`\rho < 1`); None
            otherwise.
        relative_slenderness: :math:`\bar\lambda_p = \sqrt{f_y/\sigma_1}`.
        k_sigma_table: Table 4.1's :math:`k_\sigma` at :math:`\psi`.
        reduction_factor: The reduction factor to apply: on a face shorter than it is
            wide (a/b < 1, the note of 4.4(2)) :math:`\rho_c` of 4.5.4(1), the
            plate-type ``plate_reduction_factor`` interpolated towards the column-type
            ``column_reduction_factor`` where :math:`\xi < 1`; else
            ``plate_reduction_factor``. None for :math:`\psi < -3`.
        plate_reduction_factor: :math:`\rho`, eq. (4.2).
        column_critical_stress_Pa: :math:`\sigma_{cr,c}`, the face as a column between
            the section's ends, its corners' support removed (4.5.3(1)): eq. (4.8),
            :math:`\pi^2 E t^2/(12(1 - \nu^2) a^2)` with a the section's length, between
            simply supported ends, 4 times it between clamped ones. None, as the two
            below, on a face not shorter than its width (no column-type check).
        column_reduction_factor: :math:`\chi_c` at :math:`\sqrt{f_y/\sigma_{cr,c}}`,
            curve a (4.5.3(4), (5)).
        xi: :math:`\xi = \sigma_{cr}/\sigma_{cr,c} - 1` bounded to
            :math:`0 \le \xi \le 1` (4.5.4(1)), the value used.
        xi_unclipped: :math:`\sigma_{cr}/\sigma_{cr,c} - 1` itself, before the bounds.
        reduced_design_stress_Pa: :math:`\rho_c f_y/\gamma_M` (Pa), with
            ``reduction_factor``: the stress limit of the face's :math:`\sigma_1`;
            its clause and the face's effective widths of Table 4.1 (``element_width_m``
            its mid-line width, ``effective_widths_placed`` naming the neighbouring
            faces): :class:`~unibuckle_fenicsx.design.ElementLimits`.
    """

    face: str
    sigma_cr_Pa: float
    psi: float | None = None
    psi_gross: float | None = None
    relative_slenderness: float | None = None
    k_sigma_table: float | None = None
    reduction_factor: float | None = None
    plate_reduction_factor: float | None = None
    column_critical_stress_Pa: float | None = None
    column_reduction_factor: float | None = None
    xi: float | None = None
    xi_unclipped: float | None = None
    reduced_design_stress_Pa: float | None = None


#: The faces at the two ends of each face's width, in the order of
#: :func:`face_compressions`' two compressions.
CORNERS = {
    "right": ("top", "bottom"),
    "top": ("right", "left"),
    "left": ("top", "bottom"),
    "bottom": ("right", "left"),
}


class SectionDesignRecord(Struct, kw_only=True):
    r"""The design quantities of a section's critical state (its JSON's ``design``).

    Attributes:
        yield_stress_Pa: :math:`f_y`.
        partial_factor: ``[design] partial_factor``: :math:`\gamma_{M0}` in the tension
            fibre's check and a face's limit at :math:`\psi = 1` without bending,
            :math:`\gamma_{M1}` in a face's at :math:`\psi < 1` or under bending (each
            face's ``partial_factor_name``).
        sigma_cr_Pa: The largest compressive axial stress in the walls at the critical
            state (Pa).
        relative_slenderness: :math:`\sqrt{f_y/\sigma_{cr}}`.
        clauses: The clauses applied.
        notes: What the output rests on, and what it leaves out.
        faces: A box's faces (:class:`FaceDesign`); empty for a tube.
        governing_face: The face that reaches :math:`\rho f_y/\gamma_M` at the
            smallest multiple of the critical load, the smallest :math:`\rho f_y/\sigma_1`
            (of faces reaching it together, the widest, and of equally wide ones the
            first of ``faces``; None for a tube).
        tied_faces: The faces that reach it together with the governing one, itself
            first (every face of a box in uniform compression without column-type
            buckling); empty when one face governs alone.
        width_to_thickness: With a core: :math:`h/t` (box, h the greater overall
            dimension) or :math:`d/t` (tube, d the outer diameter); else None.
        width_to_thickness_limit: EN 1994-1-1 Table 6.3's limit of that ratio.
        local_buckling_negligible: Whether the ratio is within the limit (6.7.1(9)) and
            the core fills the whole length (a hollow length is no filled section).
        faces_outside_table: The faces whose :math:`\psi` lies below -3 (a web under
            bending with an axial tension), outside Table 4.1 (:math:`1 \ge \psi \ge
            -3`): they get no :math:`k_\sigma` or :math:`\rho`, and a note says so.
        tension_Pa: The largest tensile axial stress in the walls at the critical state
            (Pa, > 0: the extreme fibre's :math:`\lambda_c(\sigma_a + |\sigma_b|)`); None
            without tension.
        tension_face: A box's face that carries it (``top`` or ``bottom``); None for a tube.
        tension_yield_multiple: The multiple of the critical load at which that fibre
            reaches :math:`f_y/\gamma_{M0}` (EN 1993-1-1 6.2.1(5)).
        tension_yield_first: A box's: whether that multiple is below the governing face's
            (:math:`\rho f_y/(\gamma_M\sigma_1)`): the tension face yields before the
            compressed faces reach their reduced stress, and yield governs. None for a
            tube (no :math:`\rho`) and without tension.
        lower_bound: With a core whose critical load is not proven the lowest (a KKT
            point: the sections' usual certificate), the same quantities at the verified
            lower bound (the hollow section's load by interlacing, unless a closer one was
            verified), the safe values; absent otherwise.
    """

    yield_stress_Pa: float
    partial_factor: float
    sigma_cr_Pa: float
    relative_slenderness: float
    clauses: list[str]
    notes: list[str]
    faces: list[FaceDesign]
    governing_face: str | None = None
    tied_faces: list[str] = msgspec.field(default_factory=list)
    width_to_thickness: float | None = None
    width_to_thickness_limit: float | None = None
    local_buckling_negligible: bool | None = None
    faces_outside_table: list[str] = msgspec.field(default_factory=list)
    tension_Pa: float | None = None
    tension_face: str | None = None
    tension_yield_multiple: float | None = None
    tension_yield_first: bool | None = None
    lower_bound: SectionDesignRecord | UnsetType = UNSET


def face_compressions(section: DesignSection) -> dict[str, tuple[float, float]]:
    """A box's faces: the compressions (Pa per unit load, > 0) at their two edges.

    The axial stress is ``axial_stress`` plus ``bending_stress`` times z/(d/2): the top
    (z = +d/2) and bottom (z = -d/2) faces carry one value, the right and left faces
    (spanning the depth) the two.
    """
    top = -(section.axial_stress + section.bending_stress)
    bottom = -(section.axial_stress - section.bending_stress)
    return {
        "right": (top, bottom),
        "top": (top, top),
        "left": (top, bottom),
        "bottom": (bottom, bottom),
    }


class WebStresses(NamedTuple):
    """A web's stresses by EN 1993-1-5 4.4(3) (:func:`web_compressions`).

    Attributes:
        top: The compression (> 0; per unit load, as the section's stresses) at the
            web's top end, z = +d/2.
        bottom: The same at its bottom end, z = -d/2.
        shift: :math:`z'`, the centroid of the section with the effective flanges above
            the gross one (m; < 0: towards the bottom).
    """

    top: float
    bottom: float
    shift: float


def web_compressions(section: DesignSection, rho: float) -> WebStresses:
    r"""A web's end compressions with the compression flange effective, EN 1993-1-5 4.4(3).

    The flange that the bending compresses (the top one for ``bending_stress`` < 0, at
    :math:`z_c = +d/2`; else the bottom one, :math:`z_c = -d/2`) reduced to :math:`\rho b
    t` on its mid-line, the other flange and the two webs gross (mid-line dimensions):
    the neutral axis of bending from the first moment of area, :math:`z' = -(1 - \rho) b
    t z_c/((1 + \rho) b t + 2 d t)`. The axial part :math:`\sigma_a` plus the bending part
    linear through :math:`z'` and equal to :math:`-|\sigma_b|` (the gross value, the
    computed compression) at :math:`z_c`: :math:`\sigma(z) = \sigma_a - |\sigma_b| (z -
    z')/(z_c - z')` (tension > 0, per unit load; the module docstring). Without bending,
    or with :math:`\rho = 1`, the gross stresses.
    """
    b, d, t = face_width(section, "top"), face_width(section, "right"), section.thickness
    z_c = 0.5 * d if section.bending_stress < 0.0 else -0.5 * d
    shift = -(1.0 - rho) * b * t * z_c / ((1.0 + rho) * b * t + 2.0 * d * t)
    bending = abs(section.bending_stress)

    def stress(z: float) -> float:
        return section.axial_stress - bending * (z - shift) / (z_c - shift)

    return WebStresses(-stress(0.5 * d), -stress(-0.5 * d), shift)


def _face(
    section: DesignSection,
    name: str,
    ends: tuple[float, float],
    design: DesignSpec,
    effective: tuple[float, float] | None = None,
) -> FaceDesign:
    """The face ``name`` of ``section`` whose edges carry the compressions ``ends`` (Pa).

    ``effective``: a web's end compressions by 4.4(3) (:func:`web_compressions`, in the
    order of ``ends``), from which its psi is taken; None: psi from ``ends``.
    """
    sigma1, sigma2 = max(ends), min(ends)
    if sigma1 <= 0.0:
        return FaceDesign(face=name, sigma_cr_Pa=sigma1)
    psi = stress_ratio(sigma1, sigma2)  # a whole number within rounding: the table's row
    first = ends.index(sigma1)
    slenderness = math.sqrt(design.yield_stress / sigma1)
    out = FaceDesign(face=name, sigma_cr_Pa=sigma1, psi=psi, relative_slenderness=slenderness)
    if effective is not None and max(effective) > 0.0:
        own = stress_ratio(max(effective), min(effective))
        if own != psi:
            out.psi_gross, out.psi = psi, own
            psi, first = own, effective.index(max(effective))
    if psi < psi_range(INTERNAL)[0]:
        return out
    out.k_sigma_table = buckling_factor(INTERNAL, psi)
    rho = reduction_factor(slenderness, psi, INTERNAL)
    out.plate_reduction_factor = out.reduction_factor = rho
    # The face as a column (4.5.3(1), 4.5.4(1)): a face shorter than its width may buckle
    # like one (the note of 4.4(2)), as a plate's (unibuckle_fenicsx.design): between the
    # section's ends as they are held, eq. (4.8) hinged, 4 times it clamped.
    if section.length < face_width(section, name):  # a/b < 1
        kappa = math.inf if section.ends == "clamped" else 0.0
        column = column_end_factor(kappa, kappa) * plate_euler_stress(
            section.E, section.nu, section.thickness, section.length
        )
        reduced = column_type(rho, sigma1, column, design.yield_stress)
        out.column_critical_stress_Pa, out.column_reduction_factor = column, reduced.chi
        out.xi, out.xi_unclipped = reduced.xi_used, reduced.xi
        out.reduction_factor = reduced.rho
    out.reduced_design_stress_Pa = (
        out.reduction_factor * design.yield_stress / design.partial_factor
    )
    corners = CORNERS[name]
    # Under bending the effective section (the compressed faces reduced, the others not)
    # has its own W_eff and shift e_N, which 4.6(1) needs even for a face at psi = 1.
    out.put_limit_and_widths(
        effective_widths(INTERNAL, out.reduction_factor, face_width(section, name), psi),
        psi,
        f"sigma_1 end: the corner with face {corners[first]}, other end: the corner with "
        f"face {corners[1 - first]}",
        shift=BENDING_SHIFT if section.bending_stress != 0.0 else None,
    )
    return out


def _reaches_reduced_stress(face: FaceDesign) -> float:
    r"""The multiple of the critical load at which ``face`` carries :math:`\rho f_y/\gamma_M`.

    Every face's stress grows with the one load factor: the face that reaches its reduced
    stress first governs (with one compression on every face, the one of the smallest
    :math:`\rho`; with bending, a lightly compressed face's smaller :math:`\rho` does
    not make it govern).
    Faces that reach it together (one compression on every face: the same :math:`\rho`)
    leave the widest to govern, the face whose own buckling the narrower ones restrain.
    """
    return (face.reduced_design_stress_Pa or 0.0) / face.sigma_cr_Pa


def _tension(
    out: SectionDesignRecord,
    section: DesignSection,
    design: DesignSpec,
    load: float,
    rated: list[FaceDesign],
) -> None:
    r"""The tension fibre against yield (EN 1993-1-1 6.2.1(5)): ``out``'s tension fields.

    The axial stress (tension > 0) is :math:`\sigma_a + \sigma_b\zeta`, largest at the
    extreme fibre, :math:`\sigma_a + |\sigma_b|`, on the top face for :math:`\sigma_b >
    0`; every stress grows with the load factor, so the fibre reaches
    :math:`f_y/\gamma_{M0}` at the multiple :math:`f_y/(\gamma_{M0}\sigma_t)` of the
    critical load. A box's governing face (``rated``: the faces with a :math:`\rho`)
    reaches its reduced stress at its own multiple: the smaller governs.
    """
    tension = load * (section.axial_stress + abs(section.bending_stress))
    if tension <= 0.0:
        return
    out.tension_Pa = tension
    multiple = design.yield_stress / design.partial_factor / tension
    out.tension_yield_multiple = multiple
    clause = "EN 1993-1-1 6.2.1(5)"
    if section.shape != "box":
        out.notes.append(
            f"the tension fibre ({significant(tension)} Pa at the critical load) reaches "
            f"f_y/gamma_M0 at {significant(multiple)} x the critical load ({clause})"
        )
        return
    out.tension_face = "top" if section.bending_stress > 0.0 else "bottom"
    compressed = min((_reaches_reduced_stress(f) for f in rated), default=math.inf)
    out.tension_yield_first = multiple < compressed
    if out.tension_yield_first:
        out.notes.append(
            f"the {out.tension_face} face yields in tension first ({clause}): its "
            f"{significant(tension)} Pa at the critical load reaches f_y/gamma_M0 at "
            f"{significant(multiple)} x the critical load, before face {out.governing_face} "
            f"reaches rho f_y/gamma_M (at {significant(compressed)} x): yield governs the "
            "section, not the buckling of its faces"
        )


def face_width(section: DesignSection, name: str) -> float:
    """The width (m) of the box's face ``name``: the right and left faces span the depth."""
    return float((section.depth if name in ("right", "left") else section.width) or 0.0)


def section_design(section: DesignSection, design: DesignSpec, load: float) -> SectionDesignRecord:
    """The design quantities of the section's critical load ``load`` (the module docstring)."""
    compression = load * section.compression()
    out = SectionDesignRecord(
        yield_stress_Pa=design.yield_stress,
        partial_factor=design.partial_factor,
        sigma_cr_Pa=compression,
        relative_slenderness=math.sqrt(design.yield_stress / compression),
        clauses=[],
        notes=[],
        faces=[],
    )
    if section.shape == "box":  # a tube's output applies no rho: no note of its calibration
        _box_faces(out, section, design, load)
    else:
        out.clauses.append(TUBE_CLAUSES)
        _tension(out, section, design, load, [])
    out.notes.append(member_note(section, design))
    out.notes += _material_notes(section, design)
    if section.core:
        _core_limits(out, section, design)
    return out


def _box_faces(
    out: SectionDesignRecord, section: DesignSection, design: DesignSpec, load: float
) -> None:
    """A box's faces in ``out``: their design quantities, the governing face, the notes.

    Every face at the section's critical load factor ``load``.
    """
    out.clauses.append(FACE_CLAUSES)
    out.notes.append(CALIBRATION)
    out.notes.append(
        "every face at the section's critical load factor: conservative for a face "
        "that buckles because its neighbours do"
    )
    ends = {name: (load * a, load * b) for name, (a, b) in face_compressions(section).items()}
    flanges = {name: _face(section, name, ends[name], design) for name in ("top", "bottom")}
    # EN 1993-1-5 4.4(3): the webs' psi with the compression flange effective, the one
    # that the bending compresses (none without bending: psi = 1 as in the gross section).
    compressed = "top" if section.bending_stress < 0.0 else "bottom"
    rho = flanges[compressed].reduction_factor or 1.0  # compressed: |sigma_b| > sigma_a
    webs = None
    if section.bending_stress != 0.0 and rho < 1.0:
        webs = web_compressions(section, rho)
    for name in CORNERS:
        if name in flanges:
            out.faces.append(flanges[name])
        else:
            effective = None if webs is None else (load * webs.top, load * webs.bottom)
            out.faces.append(_face(section, name, ends[name], design, effective))
    _web_note(out, compressed, rho, webs)
    column = [f for f in out.faces if f.xi is not None and f.xi < 1.0]  # rho_c, not rho
    if column:
        out.clauses.append(COLUMN_CLAUSES)
        out.notes.append(
            "column-type buckling (EN 1993-1-5 4.4(2) note, 4.5.4(1)): the section's "
            "length is below the width of face(s) "
            + ", ".join(
                f"{f.face} (xi = {ratio_text(f.xi)}, rho_c = {significant(f.reduction_factor)})"
                for f in column
            )
            + "; sigma_cr,c: the face as a column between the section's ends "
            + ("(clamped: 4 x eq. (4.8))" if section.ends == "clamped" else "(eq. (4.8))")
        )
    rated = [f for f in out.faces if f.reduced_design_stress_Pa is not None]
    for clause in dict.fromkeys(f.stress_limit_clause for f in rated):
        out.clauses[0] += (
            f"; faces {', '.join(f.face for f in rated if f.stress_limit_clause == clause)}: "
            f"{clause}"
        )
    if rated:
        first = min(_reaches_reduced_stress(f) for f in rated)
        tied = [f for f in rated if _reaches_reduced_stress(f) <= first * (1.0 + 1e-12)]
        out.governing_face = max(tied, key=lambda f: face_width(section, f.face)).face
        if len(tied) > 1:
            others = [f.face for f in tied if f.face != out.governing_face]
            out.tied_faces = [out.governing_face, *others]
    low = psi_range(INTERNAL)[0]
    off_table = [f for f in out.faces if f.psi is not None and f.psi < low]
    if off_table:
        out.faces_outside_table = [f.face for f in off_table]
        out.notes.append(
            f"face(s) {', '.join(f'{f.face} (psi = {ratio_text(f.psi)})' for f in off_table)}: "
            f"psi < {low:g}, outside EN 1993-1-5 Table 4.1 (1 >= psi >= {low:g}; eq. "
            "(4.2) likewise): no k_sigma or rho is given for them, and they are left out "
            "of the governing face; their compressed width b/(1 - psi) is checked by no "
            "rule here"
        )
    _tension(out, section, design, load, rated)


def _web_ratios(faces: list[FaceDesign], with_rho: bool = False) -> str:
    """The webs whose psi is 4.4(3)'s: "web(s) right, left: psi = ... (gross ...)".

    Webs of one value share the words (with ``with_rho``, their rho too); '' without such
    webs.
    """
    words: dict[str, list[str]] = {}
    for f in faces:
        if f.psi_gross is not None:
            said = f"psi = {ratio_text(f.psi, 4)} (gross {ratio_text(f.psi_gross, 4)})"
            if with_rho:
                said += f", rho = {significant(f.reduction_factor)}"
            words.setdefault(said, []).append(f.face)
    return "; ".join(f"web(s) {', '.join(names)}: {said}" for said, names in words.items())


def _web_note(out: SectionDesignRecord, flange: str, rho: float, webs: WebStresses | None) -> None:
    """The note on the webs' psi of EN 1993-1-5 4.4(3), where it is not the gross one.

    ``flange``: the compression flange, ``rho`` its reduction factor; ``webs``: the webs'
    stresses (None: the gross ones).
    """
    changed = _web_ratios(out.faces)
    if webs is None or not changed:
        return
    where = "above" if webs.shift > 0.0 else "below"
    out.notes.append(
        f"{changed} by EN 1993-1-5 4.4(3): the stress distribution with the compression "
        f"flange {flange} effective (rho = {significant(rho)}) and the webs and the other "
        "flange gross: the axial part plus the bending part about the neutral axis of that "
        f"section, {significant(abs(webs.shift) * 1e3)} mm {where} the gross one, the "
        "compression flange's stress the computed one; sigma_cr and the slenderness stay "
        "the computed ones"
    )


def _core_limits(out: SectionDesignRecord, section: DesignSection, design: DesignSpec) -> None:
    """A filled section's note, clauses and width-to-thickness limits in ``out``."""
    t = section.thickness
    outside = ": outside the calibration of EN 1993-1-5 4.4(2)"
    out.notes.append(
        "with the core sigma_cr is the unilateral critical stress"
        + (outside if section.shape == "box" else "")
    )
    out.clauses.append(FILLED_CLAUSES)
    epsilon = math.sqrt(235.0e6 / design.yield_stress)
    if section.shape == "box":
        across = max(section.width or 0.0, section.depth or 0.0) + t
        out.width_to_thickness_limit = 52.0 * epsilon
    else:
        across = (section.diameter or 0.0) + t
        out.width_to_thickness_limit = 90.0 * epsilon**2
    out.width_to_thickness = across / t
    within = out.width_to_thickness <= out.width_to_thickness_limit
    span = section.core_span
    if span is not None and not (span[0] <= 0.0 and span[1] >= section.length):
        # Table 6.3 is a filled section's: the hollow length is a steel member's.
        out.notes.append(
            f"the core fills x/L = {span[0] / section.length:.4g} to "
            f"{span[1] / section.length:.4g} of the length only: EN 1994-1-1 6.7.1(9) "
            "and Table 6.3 describe a concrete-filled section, not the hollow length, "
            "whose walls' local buckling is EN 1993's (EN 1993-1-1 Table 5.2, "
            "EN 1993-1-5); local_buckling_negligible is false"
            + (" although the ratio is within the limit" if within else "")
        )
        within = False
    out.local_buckling_negligible = within


def _material_notes(section: DesignSection, design: DesignSpec) -> list[str]:
    """The notes on the steel: stainless (a box's rho), f_y at a wall thicker than 40 mm."""
    notes = (
        stainless_note(section.E) if section.shape == "box" else None,  # a tube gets no rho
        yield_stress_note(design.yield_stress, section.thickness, "section.thickness"),
    )
    return [note for note in notes if note is not None]


def member_note(section: DesignSection, design: DesignSpec) -> str:
    r"""The note that the member's flexural buckling is not in the output, with its slenderness.

    The section's critical state is its walls' lowest mode: a hollow member's column
    mode shows only if it comes first (a warning says so), and a core keeps the walls
    off it. EN 1993-1-1, 6.3.1.2: the relative slenderness :math:`\sqrt{A f_y/N_{cr}} =
    \sqrt{f_y/\sigma_E}`, :math:`\sigma_E` the Euler stress of the walls' section
    (:meth:`~unibuckle_fenicsx.SectionParameters.euler_stress`);
    at 0.2 or less buckling may be ignored (6.3.1.2(4)). With the gross area A: for a
    Class 4 section eq. (6.51) takes :math:`A_{eff}`, a slenderness lower by
    :math:`\sqrt{A_{eff}/A}` at the same :math:`N_{cr}`, so the gross one never calls
    buckling negligible where (6.51) would not, and gives the smaller :math:`\chi`; the
    note says which it is. A filled member's needs the infill's stiffness (EN 1994-1-1,
    6.7.3.3), which the output does not have.
    """
    slenderness = math.sqrt(design.yield_stress / section.euler_stress())
    text = (
        "the member's flexural buckling (EN 1993-1-1, 6.3.1) is not part of this output: "
        "its walls' section as a column has relative slenderness sqrt(f_y/sigma_E) = "
        f"{slenderness:.3g} (sigma_E its Euler stress, L_e = L, or L/2 between clamped "
        "ends; the gross area: a Class 4 section's sqrt(A_eff f_y/N_cr) of 6.3.1.2(1) is "
        "lower by sqrt(A_eff/A); buckling may be ignored at 0.2 or less, 6.3.1.2(4))"
    )
    if section.core:
        text += (
            "; a filled member's needs the infill's stiffness (EN 1994-1-1, 6.7.3.3), "
            "and the core keeps its walls off the column's mode here"
        )
    return text


def at_lower_bound(
    record: SectionDesignRecord, section: DesignSection, design: DesignSpec, lower: float
) -> SectionDesignRecord:
    """``record`` with the design quantities at the verified lower bound ``lower`` added.

    The section's counterpart of :func:`unibuckle_fenicsx.design.at_lower_bound`: an
    unproven critical load may be on the unsafe side, down to ``lower``.
    """
    record.lower_bound = section_design(section, design, lower)
    record.lower_bound.notes = []  # the same as the record's
    record.notes.append(UNPROVEN)
    return record


def _tension_text(d: SectionDesignRecord, scale: float, unit: str) -> str:
    """The design line's words on the tension fibre ('' without tension).

    A box's only when it yields first; a tube's (no rho) always, with its multiple.
    """
    if d.tension_Pa is None or d.tension_yield_multiple is None:
        return ""
    tension = f"{significant(d.tension_Pa / scale)} {unit} of tension at sigma_cr"
    multiple = f"{significant(d.tension_yield_multiple)} x the critical load"
    if d.tension_face is None:  # a tube
        return f"; the tension fibre ({tension}) reaches f_y/gamma_M0 at {multiple}"
    if not d.tension_yield_first:
        return ""
    return (
        f"; face {d.tension_face} yields in tension first (EN 1993-1-1 6.2.1(5): {tension}, "
        f"f_y/gamma_M0 at {multiple}): yield governs, not rho"
    )


def _governing(d: SectionDesignRecord, *, rule: bool = True) -> str:
    r"""The governing face in the summary: its name, or the faces that tie with it.

    Faces that reach :math:`\rho f_y/\gamma_M` at one load tie (every face of a box in
    uniform compression): the line names them all and (``rule``) the rule that picked
    ``governing_face`` (the widest, then the first of ``faces``).
    """
    if not d.tied_faces:
        return f"face {d.governing_face}"
    text = f"faces {', '.join(d.tied_faces)} tie"
    if rule:
        text += (
            f" (one load to rho f_y/gamma_M; {d.governing_face} named: the widest, then the first)"
        )
    return text


def design_line(
    d: SectionDesignRecord,
    scale: float = 1.0,
    unit: str = "Pa",
    lengths: tuple[float, str] = (1.0, "m"),
) -> str:
    """The summary line of a section's design output (stresses in ``unit``, Pa / ``scale``).

    Lengths in ``lengths[1]``, m / ``lengths[0]``.
    """
    text = (
        f"design: largest compression sigma_cr = {significant(d.sigma_cr_Pa / scale)} {unit}, "
        f"slenderness {significant(d.relative_slenderness)}"
    )
    if not d.faces:  # a tube: a shell, whose reduction (EN 1993-1-6) is not applied
        text += " (sqrt(f_y/sigma_cr) only: EN 1993-1-6's buckling reduction not applied)"
    face = next((f for f in d.faces if f.face == d.governing_face), None)
    if face is not None and face.reduction_factor is not None:
        reduced = face.reduced_design_stress_Pa or 0.0
        rho = f"rho = {significant(face.reduction_factor)}"
        if face.xi is not None and face.xi < 1.0:  # rho_c (as the notes name the faces)
            rho = (
                f"rho_c = {significant(face.reduction_factor)} (column-type, EN 1993-1-5 4.5.4: "
                f"plate {significant(face.plate_reduction_factor)}, chi_c "
                f"{significant(face.column_reduction_factor)}, xi {ratio_text(face.xi)})"
            )
        column = ", rho_c 4.5.4(1)" if face.xi is not None and face.xi < 1.0 else ""
        text += (
            f"; EN 1993-1-5 {_governing(d)}: psi = {ratio_text(face.psi)}, {rho}, "
            f"rho f_y/{face.partial_factor_name} = {significant(reduced / scale)} {unit} "
            f"(psi {'4.4(3), ' if face.psi_gross is not None else ''}Table 4.1, "
            "slenderness 4.4(2), "
            f"rho 4.4(2) eq. (4.2){column}"
            f"{limit_clause_text(face.partial_factor_name)}, "
            f"b_eff {face.effective_widths_row}){effective_widths_text(face, *lengths)}"
        )
    webs = _web_ratios(d.faces, with_rho=True)
    if webs:  # EN 1993-1-5 4.4(3): not the gross section's psi
        text += f"; {webs} (psi 4.4(3): the effective compression flange, the gross webs)"
    if d.faces_outside_table:
        text += (
            f"; face(s) {', '.join(d.faces_outside_table)}: psi < -3, outside Table 4.1: "
            "no k_sigma or rho"
        )
    text += _tension_text(d, scale, unit)
    if d.width_to_thickness is not None and d.width_to_thickness_limit is not None:
        verdict = (
            "local buckling may be neglected"
            if d.local_buckling_negligible
            else "above it: local buckling to be considered"
            if d.width_to_thickness > d.width_to_thickness_limit
            else "within it where filled; the core does not fill the length: local "
            "buckling to be considered"
        )
        # A box has faces (h the greater overall dimension), a tube none (d its diameter).
        ratio, limit = ("h/t", "52 eps") if d.faces else ("d/t", "90 eps^2")
        text += (
            f"; EN 1994-1-1 6.7.1(9), Table 6.3: {ratio} = {significant(d.width_to_thickness)}"
            f" against {limit} = {significant(d.width_to_thickness_limit)} ({verdict})"
        )
    low = d.lower_bound
    if isinstance(low, SectionDesignRecord):
        text += (
            f"\n  design at the verified lower bound (the safe value, sigma_cr not proven "
            f"the lowest): sigma_cr = {significant(low.sigma_cr_Pa / scale)} {unit}, "
            f"slenderness {significant(low.relative_slenderness)}"
        )
        face = next((f for f in low.faces if f.face == low.governing_face), None)
        if face is not None and face.reduction_factor is not None:
            name = "rho" if face.reduction_factor == face.plate_reduction_factor else "rho_c"
            text += (
                f", {_governing(low, rule=False)}, {name} = {significant(face.reduction_factor)}"
                f", rho f_y/{face.partial_factor_name} = "
                f"{significant((face.reduced_design_stress_Pa or 0.0) / scale)} {unit}"
            )
        if low.tension_yield_first:
            text += _tension_text(low, scale, unit)
    return text
