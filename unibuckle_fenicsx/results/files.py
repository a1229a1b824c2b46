"""Files of a solve: the JSON result and the fields for ParaView (VTX and VTK)."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    import dolfinx

    from unibuckle_fenicsx.algorithms import UnilateralSolution
    from unibuckle_fenicsx.model.problem import Problem
    from unibuckle_fenicsx.model.shell.section import Section
    from unibuckle_fenicsx.results.records import BucklingResult

__all__ = [
    "Solved",
    "SolvedSection",
    "file_stem",
    "write_fields",
    "write_json",
    "write_section_fields",
]


class Solved(Protocol):
    """What :func:`write_fields` reads of a solve (:class:`~unibuckle_fenicsx.analysis.Analysis`).

    Attributes:
        result: The result's records.
        problem: The set-up problem (its mesh, model and contact manager).
        solution: The unilateral solution (None without obstacle).
    """

    result: BucklingResult
    problem: Problem
    solution: UnilateralSolution | None

    @property
    def mode(self) -> dolfinx.fem.Function:
        """The critical mode (w, theta)."""
        ...

    @property
    def free_mode(self) -> dolfinx.fem.Function:
        """The free plate's mode."""
        ...


class SolvedSection(Protocol):
    """What :func:`write_section_fields` reads of a section's solve.

    (:class:`~unibuckle_fenicsx.section_analysis.SectionAnalysis`.)
    """

    @property
    def result(self) -> BucklingResult:
        """The result's records (their ``case`` names the files)."""
        ...

    @property
    def section(self) -> Section:
        """The finest section (mesh, shell model, the core's constraints, problem)."""
        ...

    @property
    def solution(self) -> UnilateralSolution | None:
        """The unilateral solution (None without a core)."""
        ...

    @property
    def mode(self) -> dolfinx.fem.Function:
        """The critical mode in global components."""
        ...

    @property
    def free_mode(self) -> dolfinx.fem.Function:
        """The hollow section's mode in global components."""
        ...


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


def write_fields(analysis: Solved, directory: str | Path) -> list[Path]:
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
    from unibuckle_fenicsx.model.problem import UnilateralProblem

    problem = analysis.problem
    w, theta = problem.model.split(analysis.mode)
    w_free, _ = problem.model.split(analysis.free_mode)
    w_free.name = "w_free"
    fields = [w, w_free]
    if isinstance(problem, UnilateralProblem) and analysis.solution is not None:
        fields.append(problem.contact.indicator())
        fields.append(problem.contact.node_function(analysis.solution.active))
        force = analysis.result.contact_force
        if force is not None:  # the obstacle's push (N/m), zero off the contact set
            push = np.asarray(force.push, dtype=float)
            fields.append(
                problem.contact.node_function(analysis.solution.active, "contact_force", push)
            )
    groups = {"w": fields, "theta": [theta]}
    return _write(problem.comm, directory, file_stem(analysis.result.case), groups)


def _write(comm: Any, directory: str | Path, case: str, groups: dict[str, list[Any]]) -> list[Path]:
    """Each group of functions to ``<case>_<group>.bp`` (VTX), all to ``<case>.pvd`` (VTK).

    ``directory`` is created (its parent must exist). Returns the paths, the ``.pvd``
    last. Collective on ``comm``.
    """
    import dolfinx.io

    directory = Path(directory)
    if comm.rank == 0:
        directory.mkdir(parents=True, exist_ok=True)
    comm.barrier()
    paths = []
    for group, funcs in groups.items():
        paths.append(directory / f"{case}_{group}.bp")
        with dolfinx.io.VTXWriter(comm, paths[-1], funcs, engine="BP4") as writer:
            writer.write(0.0)
    paths.append(directory / f"{case}.pvd")
    with dolfinx.io.VTKFile(comm, paths[-1], "w") as vtk:
        vtk.write_function([f for funcs in groups.values() for f in funcs], 0.0)
    return paths


def write_section_fields(analysis: SolvedSection, directory: str | Path) -> list[Path]:
    """Write a section's mode, its hollow mode and the core's contact for viewing.

    The section's counterpart of :func:`write_fields`, on its shell's nodes (3-D
    coordinates, m): ``<case>_u.bp`` (ADIOS2 VTX) holds the vectors ``u``, the critical
    mode's displacement in x, y, z scaled to max |u| = 1, ``u_free``, the hollow
    section's, scaled alike, and ``omega``, the mode's rotations (rad for max |u| = 1 m);
    ``<case>_outward.bp`` the scalars ``outward``, u along the wall's outward normal (a
    box's corner: the larger of its two faces'), ``core``, 1 on the nodes the core
    holds, and ``contact``, 1 where the mode touches the core (both 0 without a core);
    ``<case>.pvd`` (VTK) all of them.

    Returns:
        The paths of the two ``.bp`` directories and of the ``.pvd`` file.

    Note:
        Collective on the section's communicator.
    """
    from mpi4py import MPI

    import dolfinx.fem

    from unibuckle_fenicsx.model.shell.section import outward_component

    section = analysis.section
    comm = section.problem.comm
    W = section.model.W
    mesh = W.mesh
    V = dolfinx.fem.functionspace(mesh, ("Lagrange", 1, (3,)))
    S = dolfinx.fem.functionspace(mesh, ("Lagrange", 1))
    points = W.tabulate_dof_coordinates()
    if not all(
        np.array_equal(space.tabulate_dof_coordinates(), points) for space in (V, S)
    ):  # the same P1 nodes, in the same order, on every space of the mesh
        raise RuntimeError("write_section_fields: the output spaces' nodes differ from W's")

    def vectors(mode: dolfinx.fem.Function) -> tuple[np.ndarray, np.ndarray]:
        """(displacement, rotation) per node, scaled to max |u| = 1 over every rank."""
        values = mode.x.array.real.reshape(-1, 6)
        largest = comm.allreduce(float(np.abs(values[:, :3]).max(initial=0.0)), op=MPI.MAX)
        values = values / (largest or 1.0)
        return values[:, :3], values[:, 3:]

    def function(space: dolfinx.fem.FunctionSpace, name: str, values: np.ndarray) -> Any:
        f = dolfinx.fem.Function(space, name=name)
        f.x.array[:] = np.asarray(values, dtype=float).ravel()
        f.x.scatter_forward()
        return f

    u, omega = vectors(analysis.mode)
    u_free, _ = vectors(analysis.free_mode)
    core = np.zeros(points.shape[0])
    contact = np.zeros(points.shape[0])
    constraints = section.constraints
    if constraints is not None:  # each owned direction's node: its local DOF // 6
        nodes = constraints.owned_local_dofs // 6
        core[nodes] = 1.0
        if analysis.solution is not None:
            held = np.isin(constraints.owned_positions, analysis.solution.active)
            contact[nodes[held]] = 1.0
    vector_fields = [function(V, "u", u), function(V, "u_free", u_free)]
    vector_fields.append(function(V, "omega", omega))
    scalar_fields = [function(S, "outward", outward_component(section, points, u))]
    scalar_fields += [function(S, "core", core), function(S, "contact", contact)]
    groups = {"u": vector_fields, "outward": scalar_fields}
    return _write(comm, directory, file_stem(analysis.result.case), groups)
