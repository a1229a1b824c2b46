"""Files of a solve: the JSON result and the fields for ParaView (VTX and VTK)."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from unibuckle_fenicsx.analysis import Analysis
    from unibuckle_fenicsx.results import BucklingResult

__all__ = ["file_stem", "write_fields", "write_json"]


def write_json(result: BucklingResult, path: str | Path) -> Path:
    """Write ``result`` as JSON (call on one rank only)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(result.as_dict(), indent=2) + "\n")
    return path


def file_stem(name: str) -> str:
    """``name`` as one file name, which leads out of no folder.

    Characters other than letters, digits, '.', '-' and '_' become '_', and so do
    leading dots.
    """
    stem = re.sub(r"[^A-Za-z0-9._-]", "_", name)
    stem = re.sub(r"^\.+", lambda m: "_" * len(m.group()), stem)
    return stem or "plate"


def write_fields(analysis: Analysis, directory: str | Path) -> list[Path]:
    """Write the mode, the free mode, the obstacle zone and the contact set for viewing.

    ``<case>`` is the problem's name made a safe file name (:func:`file_stem`). Files,
    for ParaView (ADIOS2 VTX reader): ``<case>_w.bp`` (w, w_free, obstacle_zone,
    contact and contact_force on the Q1 space: the obstacle's push at each contact node,
    N per metre of the mode's largest deflection, as the JSON's ``contact_force``) and
    ``<case>_theta.bp`` (the rotation); and the same fields
    as VTK, ``<case>.pvd`` (with ``.pvtu``/``.vtu`` pieces), which ParaView and
    ``pyvista.read`` open without ADIOS2.

    Returns:
        The paths of the two ``.bp`` directories and of the ``.pvd`` file.

    Note:
        Collective on the mesh communicator.
    """
    import dolfinx.io

    problem = analysis.problem
    directory = Path(directory)
    if problem.comm.rank == 0:
        directory.mkdir(parents=True, exist_ok=True)
    problem.comm.barrier()
    w, theta = problem.model.split(analysis.mode)
    w_free, _ = problem.model.split(analysis.free_mode)
    w_free.name = "w_free"
    fields = [w, w_free]
    if problem.contact is not None and analysis.solution is not None:
        fields.append(problem.contact.indicator())
        fields.append(problem.contact.node_function(analysis.solution.active))
        force = analysis.result.contact_force
        if force is not None:  # the obstacle's push (N/m), zero off the contact set
            push = np.asarray(force["push"], dtype=float)
            fields.append(
                problem.contact.node_function(analysis.solution.active, "contact_force", push)
            )
    case = file_stem(analysis.result.case)
    paths = [directory / f"{case}_w.bp", directory / f"{case}_theta.bp"]
    for path, funcs in ((paths[0], fields), (paths[1], [theta])):
        with dolfinx.io.VTXWriter(problem.comm, path, funcs, engine="BP4") as writer:
            writer.write(0.0)
    paths.append(directory / f"{case}.pvd")
    if not all(path.parent == directory for path in paths):
        raise RuntimeError(
            "write_fields: expected all(path.parent == directory for path in paths) (an internal "
            "invariant)"
        )
    with dolfinx.io.VTKFile(problem.comm, paths[-1], "w") as vtk:
        vtk.write_function([*fields, theta], 0.0)
    return paths
