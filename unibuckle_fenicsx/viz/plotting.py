r"""Figures of buckling modes, sections, contact sets and mesh convergence (PNG).

pyvista and matplotlib are imported inside the functions that need them (install the
``demo`` extra), so importing this module is cheap. Every writer returns the path it
wrote. 3-D figures render off screen; without a display, VTK's EGL window is selected
so that no X server is needed (set ``VTK_DEFAULT_OPENGL_WINDOW`` to override).

This module only draws. The data (nodal deflections, sections, the zone's box) come from
:mod:`unibuckle_fenicsx.viz.fields`, whose functions are collective; the writers here are
called on one rank (3-D figures need a serial problem, ``comm.size == 1``). Deflections
within the feasibility tolerance of zero are drawn as zero (``tau``), so that rounding on a
flat contact region does not read as penetration.

Sign convention: an obstacle above the plate (the default) admits :math:`w \le 0` in its
zone and is drawn at :math:`w = 0^+`; one below admits :math:`w \ge 0`, drawn at
:math:`w = 0^-`.

The module is about 700 lines because it holds one self-contained writer per figure kind
(3-D mode, section, contact set and map, convergence, load paths, Southwell); they share
only the drawing helpers at the top.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypedDict

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.results import rounded
from unibuckle_fenicsx.viz.fields import problem_zone

if TYPE_CHECKING:  # pragma: no cover
    import dolfinx

    from unibuckle_fenicsx.model.problem import Problem

__all__ = [
    "THEME",
    "annotate",
    "colour_scale",
    "coloured_surface",
    "plot_contact_force",
    "plot_contact_map",
    "plot_contact_set",
    "plot_convergence",
    "plot_load_paths",
    "plot_mode_3d",
    "plot_section",
    "plot_southwell",
]


class Theme(TypedDict):
    """The look of every figure: sizes, fonts and colours."""

    window_size: tuple[int, int]  # pyvista, pixels
    font_size: int  # pyvista text
    cmap: str  # a mode of both signs: diverging, 0 neutral
    cmap_one_signed: str  # a one-signed mode: sequential, white at 0 to max|w|
    cmap_force: str  # the contact force, sequential on a log scale
    figsize: tuple[float, float]  # matplotlib, inches
    dpi: int
    mpl_font_size: int
    warp: float  # 3-D height (m) of |w| = 1 (plate 0.2 m x 0.1 m)
    obstacle_color: str
    contact_color: str
    touch_color: str  # a contact node that only touches (no force): visible on white
    free_color: str
    unilateral_color: str


#: The one theme of every figure (overridable module constant).
THEME: Theme = {
    "window_size": (1400, 900),  # pyvista, pixels
    "font_size": 18,  # pyvista text
    "cmap": "coolwarm",  # a mode of both signs: diverging, 0 neutral
    "cmap_one_signed": "Blues",  # a one-signed mode: sequential, white at 0 to max|w|
    "cmap_force": "magma_r",  # the contact force, sequential on a log scale
    "figsize": (9.0, 5.0),  # matplotlib, inches
    "dpi": 130,
    "mpl_font_size": 12,
    "warp": 0.035,  # 3-D height (m) of |w| = 1 (plate 0.2 m x 0.1 m)
    "obstacle_color": "dimgray",
    "contact_color": "black",
    "touch_color": "#a0a0a0",
    "free_color": "tab:blue",
    "unilateral_color": "tab:red",
}


# -- lazy imports ----------------------------------------------------------------------
def _pyvista() -> Any:
    if not os.environ.get("DISPLAY") and "VTK_DEFAULT_OPENGL_WINDOW" not in os.environ:
        # Off-screen without X: ask VTK for EGL up front (avoids the X connection warning).
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkEGLRenderWindow"
    try:
        import pyvista as pv
    except ImportError as err:  # pragma: no cover
        raise ImportError(
            "3-D figures need pyvista: pip install 'unibuckle_fenicsx[demo]'"
        ) from err
    pv.OFF_SCREEN = True
    return pv


def _font_file() -> str | None:
    """A TrueType font with Greek letters for VTK text (matplotlib's DejaVu Sans)."""
    try:
        import matplotlib as mpl
    except ImportError:  # pragma: no cover
        return None
    path = Path(mpl.get_data_path()) / "fonts" / "ttf" / "DejaVuSans.ttf"
    return str(path) if path.exists() else None


_VTK_FONT_FILE = 4  # vtkTextProperty font family "VTK_FONT_FILE"


def _matplotlib() -> Any:
    try:
        import matplotlib as mpl
    except ImportError as err:  # pragma: no cover
        raise ImportError("figures need matplotlib: pip install 'unibuckle_fenicsx[demo]'") from err
    return mpl


def _themed[**P, R](draw: Callable[P, R]) -> Callable[P, R]:
    """``draw`` run in the package's font size, matplotlib's own settings left alone.

    The figures are :class:`matplotlib.figure.Figure` objects, not pyplot's: drawing one
    neither switches the caller's backend nor changes its ``rcParams`` nor registers a
    figure in pyplot's list (a user's notebook or GUI session stays as it was).
    """

    @functools.wraps(draw)
    def themed(*args: P.args, **kwargs: P.kwargs) -> R:
        with _matplotlib().rc_context({"font.size": THEME["mpl_font_size"]}):
            return draw(*args, **kwargs)

    return themed


def _subplots(*args: Any, **kwargs: Any) -> tuple[Any, Any]:
    """``pyplot.subplots`` without pyplot: a figure of its own and its axes."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=kwargs.pop("figsize"), dpi=kwargs.pop("dpi"))
    return fig, fig.subplots(*args, **kwargs)


def _prepare(path: str | Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def _save(fig: Any, path: Path) -> Path:
    """Lay out ``fig``, write it to ``path``; ``path``."""
    fig.tight_layout()
    fig.savefig(path)
    return path


def _normalised(w: npt.NDArray[np.float64], tau: float) -> npt.NDArray[np.float64]:
    """Deflection divided by max |w|, values within ``tau`` of zero set to zero."""
    wmax = float(np.abs(w).max()) or 1.0
    out = np.asarray(w, dtype=float) / wmax
    out[np.abs(out) <= tau] = 0.0
    return out


#: A mode whose other sign stays below this fraction of max|w| is drawn as one-signed.
ONE_SIGNED_RTOL = 1e-2


def colour_scale(wn: npt.NDArray[np.float64]) -> tuple[str, tuple[float, float]]:
    """(colour map, limits) for a normalised deflection ``wn`` (max |wn| = 1).

    A one-signed mode (a unilateral mode against a whole-plate obstacle, say) gets the
    sequential map from 0 to its sign's extreme, so the whole scale shows it; a mode of
    both signs the diverging map on [-1, 1], 0 neutral. Parts of the other sign below
    :data:`ONE_SIGNED_RTOL` are drawn as 0.
    """
    if wn.size and wn.min() >= -ONE_SIGNED_RTOL:
        return THEME["cmap_one_signed"], (0.0, 1.0)
    if wn.size and wn.max() <= ONE_SIGNED_RTOL:
        return f"{THEME['cmap_one_signed']}_r", (-1.0, 0.0)
    return THEME["cmap"], (-1.0, 1.0)


# -- 3-D mode ----------------------------------------------------------------------------
def annotate(
    plotter: Any, legend: Sequence[tuple[str, str, str]], title: str, font: str | None
) -> None:
    """The legend (label, colour, face) at the lower left and the title at the upper left.

    ``face`` is pyvista's legend glyph of the entry: "line" for an outline, "circle" for
    nodes drawn as spheres, so that an outline and nodes of the same colour differ.
    """
    if legend:
        plotter.add_legend(
            labels=[[label, color, face] for label, color, face in legend],
            bcolor="white",
            border=True,
            size=(0.3, 0.1),
            loc="lower left",
        )
    if title:
        plotter.add_text(
            title,
            position="upper_left",
            font_size=THEME["font_size"] - 2,
            color="black",
            font_file=font,
        )


def coloured_surface(
    pv: Any,
    surface: Any,
    scalars: str,
    title: str,
    *,
    edges: bool,
    line_width: float = 0.5,
    ambient: float = 0.0,
    cmap: str | None = None,
    clim: tuple[float, float] = (-1.0, 1.0),
) -> tuple[Any, str | None]:
    """An off-screen plotter with ``surface`` coloured by ``scalars`` in [-1, 1] and its bar.

    ``ambient``: VTK's ambient light coefficient (0 to 1), so that walls seen at a grazing
    angle keep their colour; ``cmap`` and ``clim`` as :func:`colour_scale` gives them
    (default: the theme's diverging map on [-1, 1]).

    Returns:
        The plotter (the caller closes it) and the font file of its text (or None).
    """
    font = _font_file()
    plotter = pv.Plotter(off_screen=True, window_size=THEME["window_size"])
    plotter.set_background("white")
    plotter.add_mesh(
        surface,
        scalars=scalars,
        cmap=THEME["cmap"] if cmap is None else cmap,
        clim=clim,
        show_edges=edges,
        edge_color="gray",
        line_width=line_width,
        show_scalar_bar=False,
        ambient=ambient,
    )
    bar = plotter.add_scalar_bar(
        title=title,
        vertical=True,
        position_x=0.87,
        position_y=0.2,
        height=0.6,
        width=0.06,
        title_font_size=THEME["font_size"],
        label_font_size=THEME["font_size"] - 2,
        color="black",
        fmt="%.1f",
        n_labels=5,
    )
    if font is not None:
        for prop in (bar.GetTitleTextProperty(), bar.GetLabelTextProperty()):
            prop.SetFontFamily(_VTK_FONT_FILE)
            prop.SetFontFile(font)
    return plotter, font


def plot_mode_3d(
    problem: Problem,
    mode: dolfinx.fem.Function,
    path: str | Path,
    *,
    contact_coordinates: npt.ArrayLike | None = None,
    contact_pressing: npt.ArrayLike | None = None,
    title: str = "",
    show_zone: bool = True,
    tau: float = 0.0,
) -> Path:
    """Warped 3-D surface of the mode, with the obstacle zone and the contact nodes.

    The surface is coloured by w / max|w| (:func:`colour_scale`: sequential for a
    one-signed mode); the obstacle is a translucent grey plane just above w = 0 over its
    zone, outlined in black; contact nodes (|Z|) are black spheres where they press the
    obstacle and grey ones where they only touch it (``contact_pressing``).

    Args:
        problem: The solved problem (serial).
        mode: The mode (w, theta) to draw.
        path: PNG to write.
        contact_coordinates: (|Z|, 2) coordinates of the contact set.
        contact_pressing: (|Z|,) whether each contact node presses the obstacle (its
            push above the load's resolution, :func:`~unibuckle_fenicsx.viz.fields.pressing`);
            None draws every contact node alike.
        title: Text at the top left.
        show_zone: Draw the obstacle zone (if the problem has one).
        tau: Relative deflections below this are drawn as zero.

    Returns:
        The written path.
    """
    if problem.comm.size != 1:
        raise RuntimeError("plot_mode_3d draws serial problems only (comm.size == 1)")
    pv = _pyvista()
    import dolfinx.plot

    path = _prepare(path)
    w, _ = problem.model.split(mode)
    grid = pv.UnstructuredGrid(*dolfinx.plot.vtk_mesh(w.function_space))  # type: ignore[arg-type]
    wn = _normalised(w.x.array.real, tau)
    cmap, clim = colour_scale(wn)
    grid.point_data["w / max|w|"] = np.clip(wn, *clim)
    grid.set_active_scalars("w / max|w|")
    # The theme's sizes are for the paper's 0.2 m plate; others are scaled alike.
    scale = max(problem.spec.plate.length, problem.spec.plate.width) / 0.2
    warp = THEME["warp"] * scale
    warped = grid.warp_by_scalar("w / max|w|", factor=warp)

    plotter, font = coloured_surface(
        pv,
        warped,
        "w / max|w|",
        "w (normalised)",
        edges=grid.n_cells <= 2500,
        cmap=cmap,
        clim=clim,
    )
    # Flat reference outline of the plate at w = 0.
    (px0, py0), (px1, py1) = problem.spec.plate.corners
    plate_outline = pv.Rectangle([[px0, py0, 0.0], [px1, py0, 0.0], [px1, py1, 0.0]])
    plotter.add_mesh(plate_outline.extract_feature_edges(), color="gray", line_width=1.5)
    legend = _add_obstacle(plotter, problem, show_zone, warp, contact_coordinates, contact_pressing)
    annotate(plotter, legend, title, font)
    plotter.add_axes(
        xlabel="x", ylabel="y", zlabel="w", color="black", viewport=(0.72, 0.0, 0.86, 0.18)
    )
    plotter.camera_position = [
        (px0 - 0.12 * scale, py0 - 0.28 * scale, 0.22 * scale),
        (0.5 * (px0 + px1) + 0.01 * (px1 - px0), 0.5 * (py0 + py1), -0.005 * scale),
        (0.0, 0.0, 1.0),
    ]
    plotter.camera.zoom(1.18)
    plotter.screenshot(str(path))
    plotter.close()
    return path


def _add_obstacle(
    plotter: Any,
    problem: Problem,
    show_zone: bool,
    warp: float,
    contact_coordinates: npt.ArrayLike | None,
    contact_pressing: npt.ArrayLike | None,
) -> list[tuple[str, str, str]]:
    """The obstacle zone (a translucent plane just off w = 0) and the contact nodes.

    Nodes that press the obstacle are drawn black, those that only touch it grey (a
    one-signed mode is white at w = 0, where they lie).
    Returns the legend's entries.
    """
    pv = _pyvista()
    box = problem_zone(problem) if show_zone else None
    # An obstacle above is drawn just above w = 0, one below just below it.
    sides = {o.side for o in problem.spec.all_obstacles}
    below = sides == {"below"}
    lift = (-0.02 if below else 0.02) * warp
    legend: list[tuple[str, str, str]] = []
    if box is not None:
        (x0, x1), (y0, y1) = box
        plane = pv.Rectangle([[x0, y0, lift], [x1, y0, lift], [x1, y1, lift]])
        plotter.add_mesh(plane, color=THEME["obstacle_color"], opacity=0.2)
        plotter.add_mesh(plane.extract_feature_edges(), color="black", line_width=4)
        text = {
            frozenset({"above"}): "obstacle zone (w <= 0 there)",
            frozenset({"below"}): "obstacle zone below (w >= 0 there)",
        }.get(frozenset(sides), "obstacle zones (both sides)")
        legend.append((text, "black", "line"))
    cxy = np.asarray(contact_coordinates if contact_coordinates is not None else [], dtype=float)
    cxy = cxy.reshape(-1, 2)
    presses = _pressing_mask(contact_pressing, len(cxy))
    for mask, colour in ((presses, THEME["contact_color"]), (~presses, THEME["touch_color"])):
        if mask.any():
            pts = np.column_stack([cxy[mask, 0], cxy[mask, 1], np.full(mask.sum(), 0.5 * lift)])
            plotter.add_points(pts, color=colour, point_size=12, render_points_as_spheres=True)
    if box is not None and contact_pressing is None:
        legend.append((f"contact nodes: {len(cxy)}", THEME["contact_color"], "circle"))
    elif box is not None:
        legend.append(
            (f"pressing the obstacle: {int(presses.sum())}", THEME["contact_color"], "circle")
        )
        legend.append(
            (f"touching, no force: {int((~presses).sum())}", THEME["touch_color"], "circle")
        )
    return legend


# -- section A -------------------------------------------------------------------------
@_themed
def plot_section(
    path: str | Path,
    x_free: npt.ArrayLike,
    w_free: npt.ArrayLike,
    x_unilateral: npt.ArrayLike,
    w_unilateral: npt.ArrayLike,
    *,
    zone_x: tuple[float, float] | None,
    title: str = "",
    extra: Sequence[tuple[npt.ArrayLike, npt.ArrayLike, str]] = (),
    labels: tuple[str, str] = ("free mode (no obstacle)", "unilateral mode"),
) -> Path:
    """Section A (y = 0) of the free mode, the unilateral mode and the obstacle.

    Args:
        path: PNG to write.
        x_free: Abscissae of the free mode.
        w_free: Free mode along the section (normalised by the caller).
        x_unilateral: Abscissae of the unilateral mode.
        w_unilateral: Unilateral mode along the section.
        zone_x: x-extent of the obstacle on the section (``None``: no obstacle).
        title: Axes title.
        extra: More curves ``(x, w, label)``, drawn dashed.
        labels: Legend labels of the two modes.

    Returns:
        The written path.
    """
    path = _prepare(path)
    # At the records' digits: the same picture on every machine (results.rounded).
    x_free, w_free, x_unilateral, w_unilateral = map(
        rounded, (x_free, w_free, x_unilateral, w_unilateral)
    )
    extra = [(rounded(xe), rounded(we), label) for xe, we, label in extra]
    fig, ax = _subplots(figsize=THEME["figsize"], dpi=THEME["dpi"])
    ax.axhline(0.0, color="lightgray", lw=1.0, zorder=0)
    ax.plot(x_free, w_free, "-o", ms=3.5, color=THEME["free_color"], label=labels[0])
    ax.plot(
        x_unilateral, w_unilateral, "-s", ms=3.5, color=THEME["unilateral_color"], label=labels[1]
    )
    styles = (("--", "darkred"), ("-.", "tab:purple"), (":", "tab:green"), ("--", "tab:olive"))
    for k, (xe, we, label) in enumerate(extra):
        ls, color = styles[k % len(styles)]
        ax.plot(xe, we, ls, lw=1.8, color=color, label=label)
    if zone_x is not None:
        x0, x1 = zone_x
        ax.fill_between(
            [x0, x1],
            [0.0, 0.0],
            [0.25, 0.25],
            facecolor="lightgray",
            edgecolor=THEME["obstacle_color"],
            hatch="///",
            lw=0.0,
            label="obstacle (section A)",
        )
        ax.plot([x0, x1], [0.0, 0.0], color="black", lw=3.0)
    ax.set_xlabel("x (m)   [section A: y = 0]")
    ax.set_ylabel("w / max|w|")
    ax.set_ylim(-1.15, 1.15)
    ax.grid(True, alpha=0.3)
    if title:
        ax.set_title(title)
    ax.legend(loc="best", fontsize=THEME["mpl_font_size"] - 2, framealpha=0.9)
    return _save(fig, path)


# -- contact set -----------------------------------------------------------------------
def _mode_bands(
    fig: Any,
    ax: Any,
    xy: npt.NDArray[np.float64],
    w: npt.ArrayLike,
    tau: float,
    triangles: npt.ArrayLike | None = None,
) -> None:
    """Filled bands of w / max|w| and a colour bar (:func:`colour_scale`).

    A mode of both signs: bands centred on 0, ±0.1, ... (0 neutral); a one-signed mode:
    the sequential map from 0 to its extreme. ``triangles`` (the cells') keeps holes
    empty; without it the nodes are triangulated.
    """
    wn = _normalised(np.asarray(w), tau)
    cmap, (low, high) = colour_scale(wn)
    if (low, high) == (-1.0, 1.0):
        levels, ticks = np.linspace(-1.05, 1.05, 22), np.linspace(-1, 1, 5)
    else:
        levels, ticks = np.linspace(low, high, 11), np.linspace(low, high, 5)
    tri = () if triangles is None else (np.asarray(triangles),)
    cs = ax.tricontourf(
        xy[:, 0], xy[:, 1], *tri, np.clip(wn, low, high), levels=levels, cmap=cmap,
    )  # fmt: skip
    cbar = fig.colorbar(cs, ax=ax, shrink=0.8, ticks=ticks)
    cbar.set_label("w / max|w|")


def _pressing_mask(pressing: npt.ArrayLike | None, n: int) -> npt.NDArray[np.bool_]:
    """``pressing`` as a boolean array of ``n`` (None: every node presses)."""
    if pressing is None:
        return np.ones(n, dtype=bool)
    mask = np.asarray(pressing, dtype=bool).reshape(-1)
    if mask.size != n:
        raise ValueError(f"contact_pressing has {mask.size} entries for {n} contact nodes")
    return mask


def _contact_markers(
    ax: Any,
    coordinates: npt.ArrayLike,
    sizes: tuple[float, float],
    many: int,
    pressing: npt.ArrayLike | None = None,
) -> None:
    """The contact set Z (the smaller size from ``many`` nodes on).

    Without ``pressing``: black dots. With it: the nodes that press the obstacle as black
    dots, those that only touch it (zero deflection, no force) as open circles.
    """
    z = np.atleast_2d(np.asarray(coordinates, dtype=float))
    nz = z.shape[0] if z.size else 0
    if not nz:
        return
    ms = sizes[0] if nz < many else sizes[1]
    if pressing is None:
        ax.plot(z[:, 0], z[:, 1], "o", ms=ms, mfc="black", mec="white", mew=0.5,
                label=f"contact set Z ({nz})")  # fmt: skip
        return
    mask = _pressing_mask(pressing, nz)
    ax.plot(z[mask, 0], z[mask, 1], "o", ms=ms, mfc="black", mec="white", mew=0.5,
            label=f"pressing the obstacle ({int(mask.sum())})")  # fmt: skip
    ax.plot(z[~mask, 0], z[~mask, 1], "o", ms=ms, mfc="none", mec="black", mew=0.8,
            label=f"touching, no force ({int((~mask).sum())})")  # fmt: skip


def _finish_top_view(
    fig: Any,
    ax: Any,
    path: Path,
    title: str,
    corners: tuple[tuple[float, float], tuple[float, float]] | None = None,
) -> Path:
    """Equal axes in metres (over ``corners``), the title, the legend below; write."""
    if corners is not None:
        (px0, py0), (px1, py1) = corners
        ax.set_xlim(px0, px1)
        ax.set_ylim(py0, py1)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    if title:
        ax.set_title(title)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.18), ncol=3,
                  fontsize=THEME["mpl_font_size"] - 2, frameon=False)  # fmt: skip
    return _save(fig, path)


@_themed
def plot_contact_set(
    path: str | Path,
    xy: npt.ArrayLike,
    w: npt.ArrayLike,
    *,
    corners: tuple[tuple[float, float], tuple[float, float]],
    zone: tuple[tuple[float, float], tuple[float, float]] | None,
    constrained: npt.ArrayLike,
    contact_coordinates: npt.ArrayLike,
    contact_pressing: npt.ArrayLike | None = None,
    title: str = "",
    tau: float = 0.0,
) -> Path:
    """Top view: mode contours, constrained nodes (I) and the contact set (Z).

    Args:
        path: PNG to write.
        xy: (n, 2) node coordinates (:func:`~unibuckle_fenicsx.viz.fields.nodal_deflection`).
        w: (n,) deflection of the mode at those nodes.
        corners: The plate's corners.
        zone: The obstacle zone's box (:func:`~unibuckle_fenicsx.viz.fields.zone_box`).
        constrained: (i, 2) coordinates of the constrained nodes I.
        contact_coordinates: (|Z|, 2) coordinates of the contact set.
        contact_pressing: (|Z|,) whether each contact node presses the obstacle
            (:func:`~unibuckle_fenicsx.viz.fields.pressing`): filled where it does, open
            where it only touches; None draws every contact node filled.
        title: Axes title.
        tau: Relative deflections below this are drawn as zero.

    Returns:
        The written path.
    """
    from matplotlib.patches import Rectangle

    path = _prepare(path)
    xy, w = rounded(xy), rounded(w)  # the records' digits: the same picture on any machine
    fig, ax = _subplots(figsize=THEME["figsize"], dpi=THEME["dpi"])
    _mode_bands(fig, ax, xy, w, tau)
    if zone is not None:
        (x0, x1), (y0, y1) = zone
        ax.add_patch(
            Rectangle(
                (x0, y0),
                x1 - x0,
                y1 - y0,
                fill=False,
                ec="black",
                lw=2.5,
                ls="--",
                label="obstacle zone",
            )
        )
    cxy = np.asarray(constrained, dtype=float).reshape(-1, 2)
    if len(cxy):
        dense = len(cxy) > 1500
        ax.plot(
            cxy[:, 0],
            cxy[:, 1],
            ".",
            ms=1.2 if dense else 2.5,
            color="dimgray",
            alpha=0.6 if dense else 1.0,
            label=f"constrained nodes I ({len(cxy)})",
        )
    _contact_markers(ax, contact_coordinates, sizes=(5, 3), many=500, pressing=contact_pressing)
    return _finish_top_view(fig, ax, path, title, corners)


# -- contact force ---------------------------------------------------------------------
@_themed
def plot_contact_force(
    path: str | Path,
    contact_coordinates: npt.ArrayLike,
    push: npt.ArrayLike,
    resolution: float,
    *,
    corners: tuple[tuple[float, float], tuple[float, float]],
    zone: tuple[tuple[float, float], tuple[float, float]] | None = None,
    title: str = "",
) -> Path:
    """Top view of the obstacle's push at each contact node, on a logarithmic scale.

    Pressing nodes (push above ``resolution``) are coloured by their push (N/m: N per
    metre of the mode's largest deflection, the JSON's ``contact_force``) over the six
    decades below the largest; nodes that only touch (zero deflection, no force) are open
    circles.

    Args:
        path: PNG to write.
        contact_coordinates: (|Z|, 2) coordinates of the contact nodes.
        push: (|Z|,) the obstacle's push at each (N/m).
        resolution: The push double precision cannot tell from zero (N/m).
        corners: The plate's corners.
        zone: The obstacle zone's box, drawn dashed.
        title: Axes title.

    Returns:
        The written path.
    """
    from matplotlib.colors import LogNorm
    from matplotlib.patches import Rectangle

    path = _prepare(path)
    z = np.asarray(contact_coordinates, dtype=float).reshape(-1, 2)
    f = np.asarray(push, dtype=float).reshape(-1)
    presses = f > resolution
    fig, ax = _subplots(figsize=THEME["figsize"], dpi=THEME["dpi"])
    (px0, py0), (px1, py1) = corners
    ax.add_patch(Rectangle((px0, py0), px1 - px0, py1 - py0, fill=False, ec="black", lw=1))
    if zone is not None:
        (x0, x1), (y0, y1) = zone
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, ec="dimgray",
                                   lw=2.0, ls="--", label="obstacle zone"))  # fmt: skip
    ms = 16 if len(z) < 500 else 5
    if presses.any():
        top = float(f[presses].max())
        dots = ax.scatter(z[presses, 0], z[presses, 1], c=f[presses], s=ms,
                          cmap=THEME["cmap_force"], norm=LogNorm(top * 1e-6, top),
                          label=f"pressing the obstacle ({int(presses.sum())})")  # fmt: skip
        bar = fig.colorbar(dots, ax=ax, shrink=0.8, extend="min")
        bar.set_label("push per node (N/m of the largest deflection)")
    if (~presses).any():
        touching = f"touching, no force ({int((~presses).sum())})"
        ax.scatter(z[~presses, 0], z[~presses, 1], s=ms, facecolors="none", edgecolors="black",
                   linewidths=0.6, label=touching)  # fmt: skip
    return _finish_top_view(fig, ax, path, title, corners)


# -- contact map on the plate's own mesh -------------------------------------------------
@_themed
def plot_contact_map(
    path: str | Path,
    xy: npt.ArrayLike,
    w: npt.ArrayLike,
    triangles: npt.ArrayLike,
    *,
    boundary: npt.ArrayLike,
    holes: Sequence[npt.ArrayLike] = (),
    zones: Sequence[tuple[npt.ArrayLike, str]] = (),
    contact_coordinates: npt.ArrayLike = (),
    contact_pressing: npt.ArrayLike | None = None,
    title: str = "",
    tau: float = 0.0,
    ties: npt.ArrayLike = (),
) -> Path:
    """Top view of a plate of any shape: mode contours, holes, obstacle zones, contact nodes.

    Args:
        path: PNG to write.
        xy: (n, 2) node coordinates.
        w: (n,) deflection at the nodes.
        triangles: (m, 3) triangles of the plate's cells
            (:func:`~unibuckle_fenicsx.viz.fields.mesh_triangles`), so holes stay empty.
        boundary: (k, 2) outer boundary polygon.
        holes: Hole outlines (polygons; circles as many points).
        zones: (outline, side) of each obstacle zone
            (:func:`~unibuckle_fenicsx.viz.fields.zone_outlines`); dashed, labelled by side.
        contact_coordinates: (|Z|, 2) coordinates of the contact set.
        contact_pressing: (|Z|,) whether each contact node presses the obstacle: filled
            where it does, open where it only touches; None draws every node filled.
        title: Axes title.
        tau: Relative deflections below this are drawn as zero.
        ties: (k, 2) nodes of point restraints (bolts, tie bars), drawn as crosses.

    Returns:
        The written path.
    """
    path = _prepare(path)
    xy = np.asarray(xy, dtype=float)
    fig, ax = _subplots(figsize=THEME["figsize"], dpi=THEME["dpi"])
    points = np.asarray(ties, dtype=float).reshape(-1, 2)
    if len(points):
        ax.plot(points[:, 0], points[:, 1], "x", color="red", ms=9, mew=2.2, zorder=5,
                label="point restraints")  # fmt: skip
    _mode_bands(fig, ax, xy, w, tau, triangles)
    for outline in (boundary, *holes):
        ring = np.asarray(outline, dtype=float)
        ring = np.vstack([ring, ring[:1]])
        ax.plot(ring[:, 0], ring[:, 1], "-", color="black", lw=1.2)
    styles = {"above": ("--", "obstacle above (w <= 0)"), "below": (":", "obstacle below (w >= 0)")}
    shown: set[str] = set()
    for outline, side in zones:
        ring = np.asarray(outline, dtype=float)
        ring = np.vstack([ring, ring[:1]])
        ls, label = styles.get(side, ("-.", f"foundation ({side})"))
        ax.plot(ring[:, 0], ring[:, 1], ls, color="dimgray", lw=2.5,
                label=None if side in shown else label)  # fmt: skip
        shown.add(side)
    _contact_markers(ax, contact_coordinates, sizes=(4, 2.5), many=300, pressing=contact_pressing)
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    pad = 0.02 * float((hi - lo).max())
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    return _finish_top_view(fig, ax, path, title)


# -- convergence -----------------------------------------------------------------------
def _reference_errors(
    ax: Any,
    studies: Mapping[str, Sequence[tuple[int, int, float]]],
    reference: float,
    reference_label: str,
    markers: str,
) -> None:
    """The free studies' errors against ``reference``, dotted, on the log axes ``ax``."""
    for k, (label, rows) in enumerate(studies.items()):
        if label.startswith("free"):
            rows = sorted(rows)
            nx = np.array([r[0] for r in rows], dtype=float)
            err = np.abs(np.array([r[2] for r in rows]) - reference) / reference
            ax.loglog(
                nx,
                err,
                ":",
                marker=markers[k % len(markers)],
                color=f"C{k}",
                mfc="none",
                label=f"{label}: error vs {reference_label}",
            )


def _mesh_axes(ax0: Any, ax1: Any, studies: Mapping[str, Sequence[tuple[int, int, float]]]) -> None:
    """The meshes (nx × ny) on both x axes, the h² slope on the right, labels and legends."""
    all_nx = sorted({r[0] for rows in studies.values() for r in rows})
    ny_of = {r[0]: r[1] for rows in studies.values() for r in rows}
    ticks = [f"{n}×{ny_of[n]}" for n in all_nx]
    if len(all_nx) >= 2:
        n0 = float(all_nx[0])
        guide = np.array([n0, float(all_nx[-1])])
        ymax = max((line.get_ydata().max() for line in ax1.get_lines()), default=1e-2)
        ax1.loglog(guide, ymax * (guide / n0) ** -2, "k-", lw=0.8, alpha=0.6, label="slope h²")
    ax0.set_xscale("log", base=2)
    ax0.set_xticks(all_nx, ticks)
    ax0.set_xlabel("mesh (quadrilaterals nx × ny)")
    ax0.set_ylabel("critical load λ (MPa)")
    ax0.grid(True, alpha=0.3)
    ax0.legend(fontsize=THEME["mpl_font_size"] - 2)
    ax1.set_xscale("log", base=2)
    ax1.set_xticks(all_nx, ticks)
    ax1.set_xlabel("mesh (quadrilaterals nx × ny)")
    ax1.set_ylabel("relative difference")
    ax1.grid(True, which="both", alpha=0.3)
    ax1.legend(fontsize=THEME["mpl_font_size"] - 3)


@_themed
def plot_convergence(
    path: str | Path,
    studies: Mapping[str, Sequence[tuple[int, int, float]]],
    *,
    reference: float | None = None,
    reference_label: str = "analytic",
    title: str = "",
) -> Path:
    r"""Critical load against mesh refinement for one or several cases.

    Left: :math:`\lambda` (MPa) against the number of cells along x. Right: the relative
    difference to the finest mesh of each study (and, for ``reference``, the error
    against it), on log axes with an :math:`h^2` slope for comparison.

    Args:
        path: PNG to write.
        studies: ``{label: [(nx, ny, load_Pa), ...]}``.
        reference: A known limit (e.g. the analytic free load), drawn dashed.
        reference_label: Its legend label.
        title: Figure title.

    Returns:
        The written path.
    """
    path = _prepare(path)
    fig, (ax0, ax1) = _subplots(
        1, 2, figsize=(THEME["figsize"][0] * 1.3, THEME["figsize"][1]), dpi=THEME["dpi"]
    )
    markers = "osD^v<>"
    # Cases may nearly coincide: alternate open/filled markers of decreasing size.
    style = [
        {
            "marker": markers[k % len(markers)],
            "ms": max(10.0 - 1.5 * k, 4.0),
            "mfc": "none" if k % 2 else None,
            "color": f"C{k}",
        }
        for k in range(len(studies))
    ]
    for k, (label, rows) in enumerate(studies.items()):
        rows = sorted(rows)
        nx = np.array([r[0] for r in rows], dtype=float)
        lam = rounded([r[2] for r in rows])  # the records' digits: the same on every machine
        ax0.plot(nx, lam / 1e6, "-", label=label, **style[k])
        if len(rows) >= 2:
            diff = np.abs(lam[:-1] - lam[-1]) / lam[-1]
            ok = diff > 0
            ax1.loglog(
                nx[:-1][ok],
                diff[ok],
                "-",
                label=f"{label}: |λ_h − λ_finest| / λ_finest",
                **style[k],
            )
    if reference is not None:
        ax0.axhline(reference / 1e6, color="k", ls="--", lw=1.0, label=reference_label)
        _reference_errors(ax1, studies, reference, reference_label, markers)
    _mesh_axes(ax0, ax1, studies)
    if title:
        fig.suptitle(title)
    return _save(fig, path)


# -- nonlinear load paths ----------------------------------------------------------------
#: One curve of :func:`plot_load_paths`: loads (Pa), max |w| (m), label, colour, line style.
PathCurve = tuple[npt.ArrayLike, npt.ArrayLike, str, str, str]


@_themed
def plot_load_paths(
    path: str | Path,
    curves: Sequence[PathCurve],
    *,
    thickness: float,
    marks: Mapping[str, tuple[float, str]],
    title: str = "",
) -> Path:
    """Max |w| / t against the load for several nonlinear paths.

    Left: linear axes (the knees); right: log deflection axis (the small imperfections'
    amplification below the knee). Vertical lines mark reference loads.

    Args:
        path: PNG to write.
        curves: ``(loads_Pa, max_w_m, label, colour, line style)`` per path.
        thickness: t (m), the deflection's scale.
        marks: ``{label: (load_Pa, colour)}`` drawn as vertical dotted lines.
        title: Figure title.

    Returns:
        The written path.
    """
    path = _prepare(path)
    fw, fh = THEME["figsize"]
    fig, axes = _subplots(1, 2, figsize=(1.6 * fw, 1.1 * fh), dpi=THEME["dpi"])
    for ax in axes:
        for loads, max_w, label, color, style in curves:
            lam = np.asarray(loads, dtype=float) / 1e6
            ax.plot(lam, np.asarray(max_w, dtype=float) / thickness, style, color=color,
                    lw=1.6, label=label)  # fmt: skip
        for label, (load, color) in marks.items():
            ax.axvline(load / 1e6, color=color, ls=":", lw=1.5, label=label)
        ax.set_xlabel("load λ (MPa)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("max |w| / t")
    axes[1].set_yscale("log")
    axes[1].set_ylabel("max |w| / t (log scale)")
    axes[0].legend(fontsize=THEME["mpl_font_size"] - 3, loc="upper left", framealpha=0.9)
    if title:
        fig.suptitle(title)
    return _save(fig, path)


#: One series of :func:`plot_southwell`: additional deflection (m), loads (Pa), mask of
#: the fitted points, Southwell load (Pa), label, colour.
SouthwellSeries = tuple[npt.ArrayLike, npt.ArrayLike, npt.ArrayLike, float, str, str]


@_themed
def plot_southwell(
    path: str | Path, series: Sequence[SouthwellSeries], *, thickness: float, title: str = ""
) -> Path:
    r"""Southwell plot: :math:`\delta_w/\lambda` against :math:`\delta_w` with the fitted lines.

    The fitted points are filled, the others open; a line of slope
    :math:`1/\lambda_S` through the fitted points' mean.

    Args:
        path: PNG to write.
        series: ``(delta_w_m, loads_Pa, fitted_mask, southwell_Pa, label, colour)``.
        thickness: t (m), the deflection's scale.
        title: Axes title.

    Returns:
        The written path.
    """
    path = _prepare(path)
    fig, ax = _subplots(figsize=THEME["figsize"], dpi=THEME["dpi"])
    for dw, loads, mask, southwell, label, color in series:
        x = np.asarray(dw, dtype=float) / thickness
        lam = np.asarray(loads, dtype=float) / 1e6
        keep = (lam > 0) & (x > 0)
        fit = np.asarray(mask, dtype=bool) & keep
        shown = keep & (x <= 2.0 * x[fit].max()) if fit.any() else keep
        ax.plot(x[shown & ~fit], x[shown & ~fit] / lam[shown & ~fit], "o", mfc="none",
                color=color, ms=5)  # fmt: skip
        ax.plot(x[fit], x[fit] / lam[fit], "o", color=color, ms=5,
                label=f"{label}: λ_S = {southwell / 1e6:.4f} MPa")  # fmt: skip
        if fit.any():
            xm, ym = x[fit].mean(), (x[fit] / lam[fit]).mean()
            xs = np.array([0.0, x[shown].max()])
            ax.plot(xs, ym + (xs - xm) / (southwell / 1e6), "-", color=color, lw=1.0)
    ax.set_xlabel("additional deflection δ_w / t = (max |w| − δ t) / t")
    ax.set_ylabel("(δ_w / t) / λ  (1/MPa)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=THEME["mpl_font_size"] - 2, loc="upper left")
    if title:
        ax.set_title(title)
    return _save(fig, path)
