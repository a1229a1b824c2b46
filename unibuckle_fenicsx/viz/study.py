"""Mesh-refinement study of one problem: solve on each mesh, draw, record.

:func:`mesh_study` is the loop every demo of the paper's cases runs: solve the problem on
a sequence of meshes, print each result, keep section A (y = 0) of the free and critical
modes on the meshes asked for, draw their 3-D modes and the contact set, and write
ParaView files. :class:`MeshStudy` then draws section A and the convergence of the load
and writes the results as JSON (the demos' ``results.json``).

Note:
    :func:`mesh_study` is collective on ``comm``; figures are drawn on rank 0 (the 3-D
    figures only in serial runs).
"""

from __future__ import annotations

import argparse
import json
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mpi4py import MPI

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.analysis import Analysis, solve
from unibuckle_fenicsx.model.problem import UnilateralProblem
from unibuckle_fenicsx.results.files import write_fields
from unibuckle_fenicsx.results.records import BucklingResult
from unibuckle_fenicsx.results.rounding import record
from unibuckle_fenicsx.spec import ProblemSpec
from unibuckle_fenicsx.viz import fields, plotting

__all__ = [
    "COARSE_MESHES",
    "PAPER_MESHES",
    "MeshStudy",
    "StudyPoint",
    "all_constrained_load",
    "check_certified",
    "demo_arguments",
    "mesh_study",
]

#: The meshes of the paper's cases in the demos: 20 x 20 is the paper's, 80 x 80 refined.
PAPER_MESHES = [(10, 10), (20, 20), (40, 40), (80, 80)]
#: Their tiny stand-ins for the test suite (``--coarse``).
COARSE_MESHES = [(4, 4), (8, 8), (16, 16)]

Section = tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]


@dataclass
class StudyPoint:
    """One mesh of a study.

    Attributes:
        mesh: (nx, ny).
        result: The solve's result.
        section: Section A of the critical mode (kept meshes only).
        free_section: Section A of the free mode (kept meshes only).
        extra: What the study's ``at_each`` hook returned for this mesh.
    """

    mesh: tuple[int, int]
    result: BucklingResult
    section: Section | None = None
    free_section: Section | None = None
    extra: dict[str, float] = field(default_factory=dict)

    @property
    def label(self) -> str:
        """The mesh as in the file names, e.g. 20x20."""
        return f"{self.mesh[0]}x{self.mesh[1]}"


@dataclass
class MeshStudy:
    """The results of :func:`mesh_study`.

    Attributes:
        name: The problem's name (a paper case: "free", "c1", ...).
        points: One per mesh, coarsest first.
        zone: The obstacle zone's box, or None.
    """

    name: str
    points: list[StudyPoint]
    zone: tuple[tuple[float, float], tuple[float, float]] | None

    @property
    def results(self) -> list[BucklingResult]:
        """The results, coarsest mesh first."""
        return [p.result for p in self.points]

    def at(self, mesh: tuple[int, int]) -> StudyPoint:
        """The point of ``mesh``."""
        return next(p for p in self.points if p.mesh == tuple(mesh))

    def plot_section(
        self,
        path: Path,
        mesh: tuple[int, int],
        *,
        title: str,
        others: Sequence[tuple[tuple[int, int], str]] = (),
    ) -> Path:
        """Section A of the free and critical modes on ``mesh``, plus other meshes' modes.

        The critical mode lies below the obstacle; the free mode is drawn with the sign
        that matches it. The paper's plate and zones are symmetric about x = 0, so a mode
        and its mirror image have the same load and a solver may return either: the
        other curves are reflected onto the side of this one if that matches better
        (and labelled so).
        """
        point = self.at(mesh)
        if point.section is None or point.free_section is None:
            raise ValueError(f"plot_section: mesh {mesh} was run without a section")
        (xf, wf), (xu, wu) = point.free_section, point.section
        sign = 1.0 if np.dot(wf, wu) >= 0 else -1.0
        extra = []
        for other, label in others:
            section = self.at(other).section
            if section is None:
                raise ValueError(f"plot_section: mesh {other} was run without a section")
            x, w, flipped = fields.mirror_to_match(xu, wu, *section)
            extra.append((x, w, label + (" (mirrored)" if flipped else "")))
        return plotting.plot_section(
            path,
            xf,
            sign * wf,
            xu,
            wu,
            zone_x=None if self.zone is None else self.zone[0],
            title=title,
            extra=extra,
        )

    def plot_convergence(self, path: Path, *, title: str, reference: float | None = None,
                         reference_label: str = "analytic") -> Path:  # fmt: skip
        """The critical load (and the free load, with an obstacle) against the mesh."""
        studies = {}
        if self.zone is not None:
            studies["free"] = [(*p.mesh, p.result.free_load_Pa) for p in self.points]
        studies[self.name] = [(*p.mesh, p.result.critical_load_Pa) for p in self.points]
        return plotting.plot_convergence(
            path, studies, reference=reference, reference_label=reference_label, title=title
        )

    def write_json(self, path: Path, **extra: Any) -> Path:
        """``{"case", "results": [...], **extra}`` as a record (:func:`write_record`, rank 0).

        The file is the same on every run of the same problem, on any machine (up to a
        last digit that lies at a rounding boundary), so that it can be kept under
        version control (the figures directory); the times and eigen-solve counts are
        printed instead.
        """
        results = [r.as_dict(timings=False) for r in self.results]
        return write_record(path, {"case": self.name, **extra, "results": results})

    def finish(
        self,
        figures: Path,
        paper_mesh: tuple[int, int],
        refined_mesh: tuple[int, int],
        title: str,
        **extra: Any,
    ) -> None:
        """Section A and convergence figures, and ``results.json``, of a paper case.

        Section A is drawn on the paper's mesh with the refined mesh's mode; the JSON
        holds both meshes, section A on the paper's mesh and ``extra``. Call on rank 0.
        """
        refined = "x".join(str(n) for n in refined_mesh)
        self.plot_section(
            figures / "section_A.png",
            paper_mesh,
            title=f"{title}, section A (y = 0), {'x'.join(str(n) for n in paper_mesh)} mesh",
            others=[(refined_mesh, f"unilateral mode, {refined} mesh")],
        )
        self.plot_convergence(
            figures / "convergence.png", title=f"{title}: convergence of the critical load"
        )
        x, w = self.at(paper_mesh).section  # type: ignore[misc]
        self.write_json(
            figures / "results.json",
            paper_mesh=list(paper_mesh),
            refined_mesh=list(refined_mesh),
            section_A={"x": x.tolist(), "w": w.tolist()},
            **extra,
        )


def write_record(path: Path, data: Any, *, contact: bool = True) -> Path:
    """Write ``data`` at ``path`` as a record (:func:`~unibuckle_fenicsx.results.rounding.record`).

    A record is the same on every machine (eight significant digits, no times or
    eigen-solve counts), so that it can be kept under version control and compared
    between runs. Call it on one rank.

    Args:
        path: A ``.json`` file (``data`` indented), or a ``.jsonl`` file (``data`` a
            sequence of mappings, one line each, as :func:`~unibuckle_fenicsx.sweep.run_sweep`
            writes them).
        data: A JSON value (``BucklingResult.as_dict()``, a sweep's lines, a summary).
        contact: Keep the contact sets; ``False`` on thin plates, where nodes flat on the
            obstacle with no contact force fall in or out of the set with rounding.
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix == ".jsonl":
        text = "".join(json.dumps(record(line, contact=contact)) + "\n" for line in data)
    else:
        text = json.dumps(record(data, contact=contact), indent=2) + "\n"
    path.write_text(text)
    return path


def mesh_study(
    specs: Sequence[ProblemSpec],
    *,
    comm: MPI.Comm,
    figures: Path,
    keep: Sequence[tuple[int, int]],
    output: Path | None = None,
    contact_mesh: tuple[int, int] | None = None,
    at_each: Callable[[Analysis], dict[str, float]] | None = None,
) -> MeshStudy:
    """Solve the same problem on each mesh of ``specs`` (see the module docstring).

    Args:
        specs: The problem on each mesh (same name and zone), coarsest first.
        comm: Communicator (the mesh is distributed over it).
        figures: Directory of the PNGs (``mode_<nx>x<ny>.png``, ``contact_set.png``).
        keep: Meshes whose sections and 3-D modes are kept and drawn.
        output: Directory of ParaView (VTX) files, per mesh; None writes none.
        contact_mesh: Mesh whose contact set is drawn (default: the last one).
        at_each: Called with each solved analysis (before it is destroyed); its dict is
            stored in the point's ``extra``.

    Returns:
        The study.

    Note:
        Collective on ``comm``.
    """
    name = specs[0].name
    contact_mesh = (specs[-1].mesh.nx, specs[-1].mesh.ny) if contact_mesh is None else contact_mesh
    points: list[StudyPoint] = []
    zone = None
    for spec in specs:
        mesh = (spec.mesh.nx, spec.mesh.ny)
        with solve(spec, comm) as analysis:
            problem, result = analysis.problem, analysis.result
            zone = fields.problem_zone(problem)
            if comm.rank == 0:
                print(result.summary(), flush=True)
            point = StudyPoint(mesh, result)
            if mesh in keep:
                point.section = fields.section(problem, analysis.mode)
                point.free_section = fields.section(problem, analysis.free_mode)
                if comm.size == 1:
                    ratio = "" if zone is None else f" = {result.ratio_to_free:.3f} λ_free"
                    plotting.plot_mode_3d(
                        problem,
                        analysis.mode,
                        figures / f"mode_{point.label}.png",
                        contact_coordinates=result.contact_coordinates,
                        contact_pressing=fields.pressing(result),
                        title=f"{_title(name)}, {point.label} mesh: "
                        f"λ = {result.critical_load_Pa / 1e6:.4f} MPa{ratio}",
                        show_zone=zone is not None,
                        tau=problem.tau,
                    )
            if zone is not None and mesh == contact_mesh:
                _contact_figures(figures, name, point.label, spec, analysis, zone)
            if output is not None:
                write_fields(analysis, output / name / point.label)
            if at_each is not None:
                point.extra = at_each(analysis)
        points.append(point)
    return MeshStudy(name, points, zone)


def _contact_figures(
    figures: Path,
    name: str,
    label: str,
    spec: ProblemSpec,
    analysis: Analysis,
    zone: tuple[tuple[float, float], tuple[float, float]],
) -> None:
    """The contact set and the obstacle's push on the mesh ``label`` (drawn on rank 0).

    Note:
        Collective (the nodal deflection is gathered).
    """
    problem, result = analysis.problem, analysis.result
    xy, w = fields.nodal_deflection(problem, analysis.mode)
    if not isinstance(problem, UnilateralProblem):
        raise TypeError("a zone without a contact manager (an internal invariant)")
    if problem.comm.rank == 0:
        plotting.plot_contact_set(
            figures / "contact_set.png",
            xy,
            w,
            corners=spec.plate.corners,
            zone=zone,
            constrained=problem.contact.coordinates,
            contact_coordinates=result.contact_coordinates,
            contact_pressing=fields.pressing(result),
            title=f"{_title(name)}: contact set on the {label} mesh",
            tau=problem.tau,
        )
        force = result.contact_force
        if force is not None and force.resolution is not None:
            plotting.plot_contact_force(
                figures / "contact_force.png",
                result.contact_coordinates,
                force.push,
                force.resolution,
                corners=spec.plate.corners,
                zone=zone,
                title=f"{_title(name)}: the obstacle's push, {label} mesh",
            )


def _title(name: str) -> str:
    return "free plate" if name == "free" else f"obstacle {name}"


def demo_arguments(description: str) -> argparse.Namespace:
    """The demos' command line: ``--coarse``, ``--figures DIR``, ``--output DIR``.

    Unknown arguments are left for PETSc. ``UNIBUCKLE_DEMO_COARSE=1`` also selects the
    coarse meshes (for the test suite).
    """
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument(
        "--coarse",
        action="store_true",
        default=os.environ.get("UNIBUCKLE_DEMO_COARSE") == "1",
        help="tiny meshes (for the tests)",
    )
    parser.add_argument(
        "--figures",
        type=Path,
        default=Path("output") / "figures",
        help="the figures' directory (the repository keeps its own in figures/)",
    )
    parser.add_argument("--output", type=Path, default=None, help="VTX (ParaView) directory")
    args, _ = parser.parse_known_args()
    return args


def all_constrained_load(mesh: tuple[int, int]) -> Callable[[Analysis], dict[str, float]]:
    """An ``at_each`` hook: on ``mesh``, λ(Z = I), every constrained node held at w = 0.

    By interlacing (removing DOFs never lowers the smallest eigenvalue) it bounds the
    unilateral load from above.
    """

    def hook(analysis: Analysis) -> dict[str, float]:
        problem = analysis.problem
        if (problem.spec.mesh.nx, problem.spec.mesh.ny) != tuple(mesh):
            return {}
        if not isinstance(problem, UnilateralProblem):
            raise TypeError("upper_bound_hook: a problem without an obstacle")
        everything = np.arange(problem.num_constrained, dtype=np.int64)
        return {"upper_bound_all_constrained_Pa": problem.evaluate(everything).load}

    return hook


def check_certified(results: Sequence[BucklingResult], rtol: float) -> None:
    """Assert every result's certificate: KKT, proven or the smallest eigenvalue, a bracket.

    Raises:
        AssertionError: A result is not certified, or its load lies below the free load
            (the obstacle never lowers it: interlacing) by more than ``rtol``.
    """
    for r in results:
        cert = r.certificate
        # Explicit raises, not assert statements: the check must hold under python -O too.
        if cert is None or not cert.kkt:
            raise AssertionError(f"{r.mesh}: certificate fails: {cert}")
        if not (cert.global_optimum_proven or cert.smallest_of_reduced):
            raise AssertionError(f"{r.mesh}: neither proven nor the smallest eigenvalue: {cert}")
        if r.critical_load_Pa < r.free_load_Pa * (1 - rtol):
            raise AssertionError(f"{r.mesh}: load below the free load ({r.ratio_to_free})")
        if r.lower_bound_Pa is None or r.lower_bound_Pa < r.free_load_Pa * (1 - rtol):
            raise AssertionError(f"{r.mesh}: lower bound {r.lower_bound_Pa} below the free load")
