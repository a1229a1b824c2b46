"""3-D figure of a section's buckling mode and where the wall presses on the core (PNG).

Draws from arrays (:class:`~unibuckle_fenicsx.model.shell.section.SectionFigureData`, made
by :func:`~unibuckle_fenicsx.model.shell.section.figure_data`), never from a live problem;
pyvista is imported inside the function (the ``demo`` extra), in the theme and off-screen
set-up of :mod:`unibuckle_fenicsx.viz.plotting`.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from unibuckle_fenicsx.viz.plotting import (
    THEME,
    _prepare,
    _pyvista,
    annotate,
    colour_scale,
    coloured_surface,
)

if TYPE_CHECKING:  # pragma: no cover
    from unibuckle_fenicsx.model.shell.section import SectionFigureData

__all__ = ["plot_section_mode_3d", "view_turn"]

#: The camera's offset from the section's centre before :func:`view_turn` (it sees a box's
#: top face, z = +d/2, and its face y = -b/2).
EYE = np.array([-0.6, -1.4, 1.0])


#: The view keeps :data:`EYE` when a buckle it sees is at least this fraction of the
#: largest: a hollow section buckles alike on every face (or all round), and its largest
#: node, decided by rounding, would turn each figure (and its axes triad) another way.
SEEN_FRACTION = 0.9


def view_turn(data: SectionFigureData) -> float:
    """The angle (rad) about the section's axis x that brings its largest buckle into view.

    The camera looks from :data:`EYE`; a buckle on the far side would not be seen (a
    filled tube's single outward buckle lies anywhere round the wall). The view stays
    (0) when the largest outward displacement (in magnitude) on the wall seen reaches
    :data:`SEEN_FRACTION` of the largest anywhere: the figures then share one view and
    one axes triad. Else a box turns by quarter turns, so that the face of the largest
    displacement is one of the two seen; a tube by the angle between the eye and that
    node. The wall seen: a box's top face (z = +d/2) and its face y = -b/2; a tube's
    nodes within 60 degrees of the eye's side.

    Args:
        data: The figure's arrays (:class:`SectionFigureData`).

    Returns:
        The angle, 0 when the largest buckle is seen from :data:`EYE`, or one nearly as
        large.
    """
    if data.shape not in ("box", "tube") or not len(data.outward):
        return 0.0
    size = np.abs(np.asarray(data.outward, dtype=float))
    y, z = data.points[:, 1], data.points[:, 2]
    eye = np.arctan2(EYE[2], EYE[1])
    if data.shape == "box":
        width, depth = data.size[1], data.size[2]
        # A node's face: the coordinate nearer its half-dimension.
        vertical = np.abs(z) / (0.5 * depth) >= np.abs(y) / (0.5 * width)
        seen = (vertical & (z > 0)) | (~vertical & (y < 0))  # the top face, the face y = -b/2
    else:
        seen = np.abs(np.angle(np.exp(1j * (np.arctan2(z, y) - eye)))) <= np.pi / 3
    if seen.any() and size[seen].max() >= SEEN_FRACTION * size.max():
        return 0.0
    largest = int(np.argmax(size))
    if data.shape == "box":
        bottom = bool(vertical[largest]) and z[largest] < 0
        return 0.5 * np.pi if bottom else -0.5 * np.pi
    return float(np.angle(np.exp(1j * (np.arctan2(z[largest], y[largest]) - eye))))


def _warped_surface(pv: Any, data: SectionFigureData, warp: float) -> Any:
    """The section's walls displaced by ``warp`` (:func:`plot_section_mode_3d`), lit outside."""
    width, depth = data.size[1:]
    across = max(width, depth)
    n = data.quads.shape[0]
    cells = np.hstack([np.full((n, 1), 4, dtype=np.int64), data.quads]).ravel()
    celltypes = np.full(n, pv.CellType.QUAD, dtype=np.uint8)
    grid = pv.UnstructuredGrid(cells, celltypes, data.points + warp * across * data.displacement)
    grid.point_data["outward"] = data.outward
    # The cells' normals point into the section (toward the core): flip them, so that the
    # walls seen from outside are lit; split at the box's corners for crisp edges.
    return grid.extract_surface(algorithm="dataset_surface").compute_normals(
        flip_normals=True, consistent_normals=False, split_vertices=True, feature_angle=30.0
    )


def _core(pv: Any, data: SectionFigureData) -> Any:
    """The core's solid (a box or a cylinder) over the section's length."""
    length, width, depth = data.size
    if data.shape == "box":
        return pv.Box(bounds=(0.0, length, -0.5 * width, 0.5 * width, -0.5 * depth, 0.5 * depth))
    return pv.Cylinder(
        center=(0.5 * length, 0.0, 0.0),
        direction=(1.0, 0.0, 0.0),
        radius=0.5 * width,
        height=length,
        resolution=96,
    )


def plot_section_mode_3d(
    data: SectionFigureData,
    path: str | Path,
    *,
    title: str = "",
    warp: float = 0.08,
    show_core: bool = True,
) -> Path:
    """Warped section coloured by the outward displacement, the core, the pressing nodes.

    The colour map is :func:`~unibuckle_fenicsx.viz.plotting.colour_scale`'s: sequential
    from 0 for a mode that moves only outward (a core over the whole length), diverging
    on [-1, 1] otherwise.

    Args:
        data: The arrays to draw
            (:class:`~unibuckle_fenicsx.model.shell.section.SectionFigureData`).
        path: PNG to write.
        title: Text at the top left.
        warp: Drawn displacement of max |u| = 1, relative to the section's largest
            dimension across (0.08: visible, without faces crossing).
        show_core: Outline the core.

    Returns:
        The written path.
    """
    pv = _pyvista()
    path = _prepare(path)
    length = data.size[0]
    n = data.quads.shape[0]
    surface = _warped_surface(pv, data, warp)
    # A filled section's mode moves only outward: the sequential map, as a plate's.
    cmap, clim = colour_scale(np.asarray(data.outward, dtype=float))
    plotter, font = coloured_surface(
        pv,
        surface,
        "outward",
        "outward u (normalised)",
        edges=n <= 4000,
        line_width=0.3,
        ambient=0.4,
        cmap=cmap,
        clim=clim,
    )
    legend: list[tuple[str, str, str]] = []
    if show_core and data.shape != "flat":
        plotter.add_mesh(_core(pv, data).extract_feature_edges(), color="black", line_width=2)
        legend.append(("core (outline)", "black", "line"))
    for pts, color, label in (
        (data.pressing, THEME["contact_color"], "presses on the core"),
        (data.touching, "gold", "on the core, no force"),
    ):
        if len(pts):
            plotter.add_points(pts, color=color, point_size=7, render_points_as_spheres=True)
            legend.append((f"{label}: {len(pts)}", color, "circle"))
    annotate(plotter, legend, title, font)
    plotter.add_axes(color="black", viewport=(0.72, 0.0, 0.86, 0.18))
    centre = np.array([0.5 * length, 0.0, 0.0])
    turn = view_turn(data)
    c, s = np.cos(turn), np.sin(turn)
    about_x = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    eye = centre + about_x @ EYE
    plotter.camera_position = [tuple(eye), tuple(centre), tuple(about_x @ (0.0, 0.0, 1.0))]
    plotter.reset_camera()
    plotter.camera.zoom(1.1)
    plotter.screenshot(str(path))
    plotter.close()
    return path
