r"""Design charts of a sweep (matplotlib): k against the swept number.

One figure, :func:`plot_sweep`: the buckling coefficient :math:`k = N b^2/(\pi^2 D)`
of the plate without obstacle (bilateral, the free load) and with it (unilateral), one
curve per combination of the other swept numbers. Unilateral points are marked by their
certificate: filled circle = proven globally optimal, filled diamond = bracketed (a
verified relative gap of at most 1e-3, written beside it), open circle = KKT point only,
cross = not certified. When the sweep varies ``plate.length`` or ``plate.width`` the abscissa is the
aspect ratio a/b. A section's sweep draws its critical stress over its classical stress
instead (:func:`plot_sweep`).

Exact thin-plate curves are drawn where they exist (:func:`reference_k`):

- SSSS plate, uniform compression of the short edges x = const, no obstacle:
  :math:`k = \min_m (m/\phi + \phi/m)^2`, :math:`\phi = a/b` (Timoshenko and Gere,
  *Theory of Elastic Stability*, 1961, section 9.2);
- the same plate with a rigid obstacle (no gap) over the whole plate: the single buckle
  :math:`(\phi + 1/\phi)^2` up to :math:`\phi = \sqrt 2`, where it reaches 4.5, and 4.5
  beyond (:doc:`/verification/thin_plates`: a buckle against the loaded edge
  that touches down, f = 2 sin t (1 + cos t), has k = 9/2);
- loaded edges clamped, unloaded simply supported, whole-plate obstacle: the long-plate
  value 16/3 (an interior buckle between two touch-downs, f = cos³(px)).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from unibuckle_fenicsx.results import rounded
from unibuckle_fenicsx.spec import EDGE_NAMES, UNITS, ProblemSpec, is_section
from unibuckle_fenicsx.sweep import Variation, point_problem

__all__ = ["axis_label", "plot_sweep", "reference_k", "sweep_figure"]

_SS = ("simply_supported", "simply_supported_soft")


def _uniaxial_x(spec: ProblemSpec) -> bool:
    """Uniform compression of the edges x = const only.

    The edges y = const free in their plane (held, they add the transverse stress
    nu sigma_x: k = 4/(1 + nu) for the square), the loaded ones not clamped in it.
    """
    e = {edge.name: edge for edge in spec.plate.edges}
    if set(e) != set(EDGE_NAMES) or not all(edge.uniform for edge in e.values()):
        return False
    if e["bottom"].inplane != "free" or e["top"].inplane != "free":
        return False
    if "clamped" in (e["left"].inplane, e["right"].inplane):
        return False
    left, right = e["left"].normal_ends[0], e["right"].normal_ends[0]
    return (
        left < 0
        and left == right
        and not e["bottom"].loaded
        and not e["top"].loaded
        and all(edge.shear_ends[0] == 0 for edge in e.values())
    )


def reference_k(spec: ProblemSpec) -> tuple[float | None, float | None, str]:
    """Exact thin-plate k of ``spec`` without and with the obstacle, where known.

    Returns:
        (bilateral k or None, unilateral k or None, what the unilateral value is).
    """
    plain = not (
        spec.points
        or spec.has_fixed_load
        or spec.load.thermal
        or spec.material.plies
        or spec.material.membrane_voigt is not None
        or spec.material.bending_voigt is not None
        or spec.plate.holes
        or spec.bilateral_foundations
        or any(e.springs for e in spec.plate.edges)
    )
    if not plain or not _uniaxial_x(spec):  # the curves below know none of these
        return None, None, ""
    supports = {edge.name: edge.support for edge in spec.plate.edges}
    phi = spec.plate.length / spec.plate.width
    obstacles = spec.all_obstacles
    # The rigid obstacle in contact: not a foundation, nor one with a gap (left out).
    whole = (
        len(obstacles) == 1
        and obstacles[0].zone == "all"
        and obstacles[0].foundation_stiffness is None
        and obstacles[0].gap == 0.0
    )
    if all(s in _SS for s in supports.values()):
        m_max = max(1, math.ceil(phi)) + 1
        bilateral = min((m / phi + phi / m) ** 2 for m in range(1, m_max + 1))
        unilateral = ((phi + 1 / phi) ** 2 if phi <= math.sqrt(2) else 4.5) if whole else None
        return bilateral, unilateral, "exact"
    clamped_loaded = supports["left"] == supports["right"] == "clamped"
    if clamped_loaded and supports["bottom"] in _SS and supports["top"] in _SS and whole:
        return None, 16 / 3, "long-plate limit"
    return None, None, ""


def _unit(path: str, units: str) -> str:
    length = "mm" if units == "mm-N-MPa" else "m"
    stress = UNITS[units][2]
    last = path.rsplit(".", 1)[-1]
    if path in ("plate.length", "plate.width", "mesh.size", "plate.thickness"):
        return length
    if path.startswith("section.") and last != "ends":
        return length
    if path.startswith(("plate.corners", "obstacle.zone", "obstacle.tolerance", "obstacle.gap")):
        return length
    if path.startswith("points.") and path.split(".")[2] in ("at", "spacing", "offset", "region"):
        return length
    if path in ("material.E", "material.G") or last.endswith("_stress"):
        return stress
    # Per unit length of edge: N m/m/rad (rotational) and N/m/m (translational).
    if last == "rotational_stiffness":
        return "N·m/(m·rad)"
    if last == "translational_stiffness":
        return stress
    if last == "foundation_stiffness":
        return f"{stress}/{length}"
    if last == "stiffness" and path.startswith("points."):
        return f"N/{length}"
    if last in ("temperature", "fixed_temperature"):
        return "K"
    return ""


#: The swept number in words, by the last part of its dotted path (the chart's axis).
_WORDS = {
    "thickness": "plate thickness",
    "size": "cell size",
    "E": "Young's modulus E",
    "nu": "Poisson's ratio ν",
    "rotational_stiffness": "rotational stiffness of the {edge} edge",
    "translational_stiffness": "translational stiffness of the {edge} edge",
    "normal_stress": "normal stress on the {edge} edge",
    "shear_stress": "shear stress on the {edge} edge",
    "foundation_stiffness": "foundation modulus",
    "gap": "gap to the obstacle",
    "fixed_factor": "factor on the fixed load",
    "stiffness": "{kind} stiffness",
    "spacing": "{kind} spacing",
    "angle": "ply angle",
}


#: A section file's numbers in words, by their dotted path (before :data:`_WORDS`).
_SECTION_WORDS = {
    "section.thickness": "wall thickness",
    "section.length": "section length",
    "section.width": "box width",
    "section.depth": "box depth",
    "section.diameter": "tube diameter",
    "load.bending_stress": "bending stress at the extreme fibre",
    "load.axial_stress": "axial stress",
    "obstacle.foundation_stiffness": "core's foundation modulus",
}


def axis_label(path: str, base: Mapping[str, Any]) -> str:
    """The swept number in words with its unit, e.g. "tie spacing (m)", for a chart's axis.

    A point row is named by its kind ("bilateral" points are ties); a key the table does
    not know is shown as its dotted path.
    """
    parts = path.split(".")
    section = _SECTION_WORDS.get(path) if is_section(base) else None
    words = section or _WORDS.get(parts[-1], path)
    edge = parts[1] if parts[0] == "edges" and len(parts) > 2 else ""
    kind = "point"
    if parts[0] == "points" and len(parts) > 2 and parts[1].isdigit():
        points = base.get("points") or []
        index = int(parts[1])
        if index < len(points):
            kind = {"bilateral": "tie", "one-sided": "one-sided support", "spring": "spring"}.get(
                str(points[index].get("kind", "bilateral")), "point"
            )
    text = words.format(edge=edge, kind=kind)
    unit = _unit(path, str(base.get("units", "SI")))
    return f"{text} ({unit})" if unit else text


def _plate_point(base: Mapping[str, Any], point: Mapping[str, float]) -> ProblemSpec:
    """The plate's problem at a sweep point (:func:`plot_sweep` draws plates' charts)."""
    spec = point_problem(base, point)
    if not isinstance(spec, ProblemSpec):
        raise TypeError("a section's sweep is drawn by plot_sweep")
    return spec


def _groups(
    lines: Sequence[Mapping[str, Any]], others: Sequence[str]
) -> list[tuple[tuple[float, ...], str, list[Mapping[str, Any]]]]:
    """The lines by the values of the other swept numbers: (values, legend suffix, lines)."""
    groups: dict[tuple[float, ...], list[Mapping[str, Any]]] = {}
    for line in lines:
        groups.setdefault(_group_key(line, others), []).append(line)
    out = []
    for key, members in sorted(groups.items()):
        label = ", ".join(f"{p} = {v:g}" for p, v in zip(others, key, strict=True))
        out.append((key, f" ({label})" if label else "", members))
    return out


def _finish(fig: Any, ax: Any) -> Any:
    """Grid, legend and layout of a chart; returns ``fig``."""
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    fig.tight_layout()
    return fig


def _write(fig: Any, path: str | Path) -> Path:
    """The figure written to ``path`` (its folder made); returns it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=150)
    return path


def _group_key(line: Mapping[str, Any], others: Sequence[str]) -> tuple[float, ...]:
    return tuple(line["point"][p] for p in others)


#: The certificate markers: a point's kind -> (marker, face colour; None: the line's, size).
CERTIFICATE_MARKERS: dict[str, tuple[str, str | None, float]] = {
    "proven optimal": ("o", None, 6),
    "bracketed (verified gap)": ("D", None, 5),
    "KKT only": ("o", "white", 6),
    "not certified": ("x", None, 7),
}


def _certificate_kind(cert: Mapping[str, Any]) -> str:
    """A point's key of :data:`CERTIFICATE_MARKERS`."""
    if not cert.get("kkt"):
        return "not certified"
    if cert.get("global_optimum_proven"):
        return "proven optimal"
    if cert.get("status") == "bracketed":
        return "bracketed (verified gap)"
    return "KKT only"


def _certificate_mark(ax: Any, x: float, k: float, cert: Mapping[str, Any], colour: str) -> str:
    """Draw a point's marker (proven, bracketed with its gap, KKT only, not certified).

    Returns its kind (:data:`CERTIFICATE_MARKERS`), for the legend.
    """
    kind = _certificate_kind(cert)
    marker, face, size = CERTIFICATE_MARKERS[kind]
    ax.plot(x, k, marker, color=colour, mfc=face or colour, ms=size)
    if kind.startswith("bracketed"):
        ax.annotate(f"{float(cert['relative_gap']):.0e}", (x, k),
                    textcoords="offset points", xytext=(4, 4), fontsize=6,
                    color=colour)  # fmt: skip
    return kind


def _exact_curves(
    ax: Any,
    base: Mapping[str, Any],
    first: Variation,
    others: Mapping[str, float],
    abscissa: Any,
    suffix: str,
) -> None:
    """The thin plate's exact k (bilateral, and unilateral where known) along ``first``."""
    dense = np.linspace(min(first.values), max(first.values), 400)
    refs: list[tuple[float, float | None, float | None]] = []
    kind = ""
    for value in dense:
        point = {first.path: float(value), **others}
        try:
            spec = _plate_point(base, point)
        except ValueError:
            continue
        bil, uni, what = reference_k(spec)
        kind = what or kind
        refs.append((abscissa(spec, float(value)), bil, uni))
    for col, style, name in ((1, ":", "bilateral"), (2, "-.", "unilateral")):
        pts = [(r[0], r[col]) for r in refs if r[col] is not None]
        if pts:
            xs, ys = np.array(pts).T
            o = np.argsort(xs)
            what = kind if col == 2 else "exact"
            label = f"{name}, thin plate ({what}){suffix}"
            ax.plot(xs[o], ys[o], style, color="0.35", lw=1.2, label=label)


def _marker_legend(ax: Any, drawn: set[str]) -> None:
    """Legend entries for the certificate markers drawn, none for those not shown.

    ``drawn``: the kinds (:data:`CERTIFICATE_MARKERS`) of the chart's points.
    """
    for kind, (marker, face, _) in CERTIFICATE_MARKERS.items():
        if kind in drawn:
            ax.plot([], [], marker, color="0.2", mfc=face or "0.2", label=kind)


#: Above this ratio of the largest k to the smallest an aspect sweep's k axis is
#: logarithmic (:func:`_k_range`).
LOG_K_SPAN = 2.5
#: The labelled ticks of a logarithmic k axis, per decade.
_LOG_K_TICKS = (1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0)


def _k_range(ax: Any, lines: Sequence[Mapping[str, Any]], aspect: bool) -> None:
    """Show every point, with the interesting range readable.

    Very short plates have large k (aspect sweeps): where the largest k shown is above
    ``LOG_K_SPAN`` times the smallest, the axis is logarithmic (ticks labelled as
    numbers), so that the short plates' points stay on the chart and the long plates'
    flat range keeps its height.
    """
    solved_lines = [m for m in lines if m.get("buckling_coefficient_k") is not None]
    shown = [float(m["buckling_coefficient_k"]) for m in solved_lines] + [
        float(m["buckling_coefficient_k"]) * m["free_load_Pa"] / m["critical_load_Pa"]
        for m in solved_lines
    ]
    if not shown:
        return
    low, high = min(shown), max(shown)
    if aspect and low > 0 and high > LOG_K_SPAN * low:
        from matplotlib import ticker

        ax.set_yscale("log")
        ax.set_ylim(0.9 * low, 1.05 * high)
        ax.yaxis.set_major_locator(ticker.LogLocator(base=10.0, subs=_LOG_K_TICKS))
        ax.yaxis.set_major_formatter(ticker.FormatStrFormatter("%g"))
        ax.yaxis.set_minor_formatter(ticker.NullFormatter())
        return
    ax.set_ylim(0.9 * low, 1.05 * high)


def plot_sweep(
    lines: Sequence[Mapping[str, Any]],
    variations: Sequence[Variation],
    base: Mapping[str, Any],
    path: str | Path,
    *,
    title: str | None = None,
) -> Path:
    """Write :func:`sweep_figure`'s chart to ``path`` (PNG, 150 dpi); returns ``path``."""
    return _write(sweep_figure(lines, variations, base, title=title), path)


def sweep_figure(
    lines: Sequence[Mapping[str, Any]],
    variations: Sequence[Variation],
    base: Mapping[str, Any],
    *,
    title: str | None = None,
) -> Any:
    r"""The chart of k against the first variation (the module docstring), a ``Figure``.

    One ``Axes`` (``fig.axes[0]``) holds the curves, the legend and the grid; the figure
    is drawn and not written (:func:`plot_sweep` writes it).

    A section's sweep (``base`` with a ``[section]`` table) draws
    its critical stress over its classical stress instead: the reference being each line's
    ``classical_stress_Pa`` (a box: its widest face as a long simply supported plate,
    k = 4; a tube: :math:`E t/(R\sqrt{3(1-\nu^2)})`), so that 1 is what the design codes'
    elastic values assume; the stress the extreme fibre's, as the summary's sigma_cr (the
    load factor times the compression per unit load, ``compression_Pa``); the hollow
    section (``free_load_Pa``) solid, with its core (``critical_load_Pa``) dashed and
    marked by its certificate.
    """
    if is_section(base):
        return _section_figure(lines, variations, base, title)
    import matplotlib as mpl
    from matplotlib.figure import Figure

    first = variations[0]
    others = [v.path for v in variations[1:]]
    aspect = first.path in ("plate.length", "plate.width")

    def abscissa(spec: ProblemSpec, value: float) -> float:
        return spec.plate.length / spec.plate.width if aspect else value

    fig = Figure(figsize=(7.5, 5.0))
    ax = fig.subplots()
    colours = mpl.rcParams["axes.prop_cycle"].by_key()["color"]
    drawn: set[str] = set()
    for g, (key, suffix, members) in enumerate(_groups(lines, others)):
        colour = colours[g % len(colours)]
        solved = [m for m in members if m.get("buckling_coefficient_k") is not None]
        specs = [_plate_point(base, m["point"]) for m in solved]
        x = np.array(
            [abscissa(s, m["point"][first.path]) for s, m in zip(specs, solved, strict=True)]
        )
        # The records' digits (results.rounded): the same picture on every machine.
        k = rounded([m["buckling_coefficient_k"] for m in solved])
        k_free = rounded(k * np.array([m["free_load_Pa"] / m["critical_load_Pa"] for m in solved]))
        order = np.argsort(x)
        ax.plot(x[order], k_free[order], "-", color=colour, lw=1.0, marker=".",
                label=f"bilateral (no obstacle){suffix}")  # fmt: skip
        unilateral = [m.get("certificate") is not None for m in solved]
        if any(unilateral):
            idx = [int(i) for i in order if unilateral[i]]
            ax.plot(x[idx], k[idx], "--", color=colour, lw=1.0,
                    label=f"unilateral (with the obstacle){suffix}")  # fmt: skip
            for i in idx:
                drawn.add(_certificate_mark(ax, x[i], k[i], solved[i]["certificate"], colour))
        # Exact curves on a fine grid of the swept number.
        point = dict(zip(others, key, strict=True))
        _exact_curves(ax, base, first, point, abscissa, suffix)
    _marker_legend(ax, drawn)
    _k_range(ax, lines, aspect)
    xlabel = "aspect ratio a/b" if aspect else axis_label(first.path, base)
    ax.set_xlabel(xlabel)
    log = " (log scale)" if ax.get_yscale() == "log" else ""
    ax.set_ylabel(r"buckling coefficient $k = N b^2 / (\pi^2 D)$" + log)
    ax.set_title(title or f"{base.get('name', 'plate')}: k against the {xlabel}")
    return _finish(fig, ax)


def _fibre_per_unit_load(line: Mapping[str, Any]) -> float:
    r"""A section's extreme-fibre compression per unit load factor (its line's numbers).

    ``compression_Pa`` over ``critical_load_Pa``: 1 under ``axial_stress = -1`` alone,
    :math:`|\sigma_b| - \sigma_a` with bending; 1 for a line written before the field.
    """
    compression = line.get("compression_Pa")
    load = float(line["critical_load_Pa"])
    if compression is None or not math.isfinite(float(compression)) or load == 0.0:
        return 1.0
    return float(compression) / load


def _section_figure(
    lines: Sequence[Mapping[str, Any]],
    variations: Sequence[Variation],
    base: Mapping[str, Any],
    title: str | None,
) -> Any:
    """A section's chart (:func:`sweep_figure`)."""
    import matplotlib as mpl
    from matplotlib.figure import Figure

    first = variations[0]
    others = [v.path for v in variations[1:]]
    fig = Figure(figsize=(7.5, 5.0))
    ax = fig.subplots()
    colours = mpl.rcParams["axes.prop_cycle"].by_key()["color"]
    drawn: set[str] = set()
    for g, (_, suffix, members) in enumerate(_groups(lines, others)):
        colour = colours[g % len(colours)]
        solved = [m for m in members if m.get("classical_stress_Pa") is not None]
        solved.sort(key=lambda m: m["point"][first.path])
        x = np.array([m["point"][first.path] for m in solved])
        reference = np.array([float(m["classical_stress_Pa"]) for m in solved])
        # The loads are factors on the stresses per unit load; the chart's stress is the
        # extreme fibre's (the summary's sigma_cr), the factor times its compression.
        fibre = np.array([_fibre_per_unit_load(m) for m in solved])
        hollow = rounded(np.array([float(m["free_load_Pa"]) for m in solved]) * fibre / reference)
        ax.plot(x, hollow, "-", color=colour, lw=1.0, marker=".", label=f"hollow{suffix}")
        cored = [i for i, m in enumerate(solved) if m.get("certificate") is not None]
        if cored:
            loads = np.array([float(m["critical_load_Pa"]) for m in solved])
            ratio = rounded(loads * fibre / reference)
            ax.plot(x[cored], ratio[cored], "--", color=colour, lw=1.0, label=f"core{suffix}")
            for i in cored:
                drawn.add(_certificate_mark(ax, x[i], ratio[i], solved[i]["certificate"], colour))
    ax.axhline(1.0, ls=":", color="0.35", lw=1.2, label="classical stress")
    _marker_legend(ax, drawn)
    ax.set_xlabel(axis_label(first.path, base))
    ax.set_ylabel(r"$\sigma_{cr}$ / classical stress")
    ax.set_title(
        title
        or f"{base.get('name', 'section')}: critical stress against the "
        f"{axis_label(first.path, base)}"
    )
    return _finish(fig, ax)
