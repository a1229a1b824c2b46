r"""Sections with a core: the free solve and the unilateral solve, their times and ratio.

Usage::

    OMP_NUM_THREADS=1 flock /tmp/unibuckle-bigmem.lock \\
        .venv/bin/python bench/bench_sections.py --shape box --size 0.00526 --levels 2

A square box (b = d = 0.2 m, t = 2 mm: b/t = 100, L = 3b) or a circular tube (R = 0.1 m,
t = 1 mm: R/t = 100, L = R), steel, simply supported ends, a rigid core over the whole
length. One process: the set-up (mesh, prestress, assembly, change of basis), the free
eigen solve (min of ``--repeat`` solves of the same pencil), and the unilateral solve
(:func:`~unibuckle_fenicsx.algorithms.section_levels.solve_levels` over the section and its
``--levels`` coarser copies, its sections' set-up included) by ``--route``:
``active-set`` (the active-set seeds on the coarsest section, the contact set polished
level by level; ``levels`` is its old name), ``interior-point`` (the nested
interior-point chain, the mode carried from section to section), ``auto`` (the route
:func:`~unibuckle_fenicsx.algorithms.registry.choose_section_method` chooses: below 10⁴ DOFs both,
the lower KKT point kept) or ``single`` (the
interior-point chain on the section itself, no coarser one); then the certificate.
The factorisations are PETSc's count of numeric ones (MUMPS) in the unilateral solve, in
all and, for the active set, per section level; the interior point's per level are its
Newton kernel's count. Per level too: the seconds of its section's build (mesh,
prestress, assembly, change of basis: ``build_s``) and of the numeric factorisations
through the section's shared LDLᵀ (``factor_s``: the Newton steps', the inertia
corrections', the certificate's on the finest). Prints one Markdown row, then one row
per level (its steps: the active set's or the Newton steps; eigen solves, factorisations
and seconds); ``--json FILE`` appends the row, with the levels, and the unilateral load
(``core_load_Pa``) to compare routes by.

Ratios, both within the one process: ``ratio`` is the unilateral solve (its sections'
set-up included) over the free eigen solve; ``process_ratio`` the whole cored run
(unilateral solve and certificate) over the whole hollow run (the section's set-up and
its free solve): what a user waits for with a core over what without.

Note:
    Timings are only meaningful on a quiet machine; the ratio (unilateral over free) is
    measured within one process.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time
from typing import TYPE_CHECKING

from _results import append_rows, print_header

if TYPE_CHECKING:
    from unibuckle_fenicsx.model.shell.section import SectionParameters

COLUMNS = (
    "shape", "route", "dofs", "constrained", "cells_around", "free_load/ref", "core_load/ref",
    "kkt", "certificate", "setup_s", "rotation_s", "free_s", "unilateral_s", "ratio",
    "certify_s", "process_ratio", "eigensolves_fine", "eigensolves_coarse", "factorisations",
)  # fmt: skip
#: The columns of a link of the finest section (``--links``).
LINK_COLUMNS = (
    "link", "seed", "status", "steps", "factorizations", "eigensolves", "contact_nodes",
    "load", "kkt",
)  # fmt: skip
#: The columns of a level's row (coarsest first).
LEVEL_COLUMNS = (
    "mesh_size", "dofs", "constrained", "seeded", "steps", "eigensolves", "factorisations",
    "build_s", "factor_s", "wall_time_s", "load",
)  # fmt: skip


def section_parameters(
    shape: str,
    size: float,
    corner_cell: float | None = None,
    geometric: str = "full",
    tube: dict | None = None,
) -> SectionParameters:
    """The benchmark's box or tube with a rigid core on cells of ``size`` (m).

    ``geometric``: the geometric stiffness's components
    (:data:`~unibuckle_fenicsx.model.shell.section.GEOMETRIC`; the package's default
    "full", or "donnell" as the rows measured before it was the default). ``tube``: the
    tube's fields that differ from the benchmark's (``diameter``, ``thickness``,
    ``length``, ``core_span``, ``ends``).
    """
    from unibuckle_fenicsx.model.shell.section import SectionParameters

    geometry: dict = (
        {"width": 0.2, "depth": 0.2, "thickness": 0.002, "length": 0.6}
        if shape == "box"
        else {"diameter": 0.2, "thickness": 0.001, "length": 0.1} | (tube or {})
    )
    geometry.setdefault("ends", "simply_supported")
    return SectionParameters(
        shape, E=2.1e11, nu=0.3, mesh_size=size, core=True,
        corner_cell=corner_cell if shape == "box" else None, geometric=geometric, **geometry,
    )  # fmt: skip


def _factorisations() -> int:
    """Numeric factorisations so far (PETSc's log: MUMPS's Cholesky and LU events)."""
    from petsc4py import PETSc

    return sum(
        int(PETSc.Log.Event(name).getPerfInfo()["count"])
        for name in ("MatCholFctrNum", "MatLUFactorNum")
    )


def _timed_by_rows(owner: object, name: str, seconds: dict[int, float], rows) -> None:  # type: ignore[no-untyped-def]
    """Wrap ``owner.name`` to add its seconds to ``seconds[rows(args)]``."""
    inner = getattr(owner, name)

    def timed(*args, **kwargs):  # type: ignore[no-untyped-def]
        t0 = time.perf_counter()
        out = inner(*args, **kwargs)
        key = rows(args, out)
        seconds[key] = seconds.get(key, 0.0) + time.perf_counter() - t0
        return out

    setattr(owner, name, timed)


def _fine_links(details: object) -> list[dict]:
    """The interior point's links on the finest section (its route's, or before a fallback)."""
    import msgspec

    from unibuckle_fenicsx.algorithms.records import InteriorPointDetails, SectionLevelsDetails

    levels = []
    if isinstance(details, InteriorPointDetails):
        levels = details.levels
    elif isinstance(details, SectionLevelsDetails) and details.interior_point_levels:
        levels = details.interior_point_levels
    return [msgspec.to_builtins(link) for link in levels[-1].links] if levels else []


def _keep_turns(keep: bool) -> None:
    """Without ``keep``: every section built from now on has no turns (all seeds run)."""
    from unibuckle_fenicsx.model.shell import section as section_module

    if not keep:
        section_module._symmetries = lambda *args: ()  # type: ignore[assignment]


def run(
    shape: str,
    size: float,
    levels: int,
    repeat: int,
    corner_cell: float | None,
    route: str,
    geometric: str = "full",
    release_steps: int | None = None,
    chain: dict | None = None,
    tube: dict | None = None,
    symmetries: bool = True,
) -> dict:
    """One section: set-up, free solve, unilateral solve, certificate.

    ``route``: "active-set", "interior-point" (the routes of
    :func:`~unibuckle_fenicsx.algorithms.section_levels.solve_levels`), "auto" (the one
    :func:`~unibuckle_fenicsx.algorithms.registry.choose_section_method` chooses) or "single" (the
    interior-point chain on the section itself). ``geometric``: as
    :func:`section_parameters`. ``release_steps``: the section route's
    :attr:`~unibuckle_fenicsx.algorithms.chain.ChainOptions.release_steps` for this run
    (None: the package's :data:`~unibuckle_fenicsx.algorithms.section_levels.CHAIN_OPTIONS`).
    ``chain``: other fields of those options for this run (``--escape-either``,
    ``--quick-descent``, ``--max-steps``), by name. ``tube``: as
    :func:`section_parameters`. ``symmetries``: False runs every seed of the active set,
    as if no turn left the section alike (the section's turns dropped, to measure what
    leaving out their images saves).
    """
    from mpi4py import MPI
    from petsc4py import PETSc

    import msgspec

    from unibuckle_fenicsx.algorithms import section_levels
    from unibuckle_fenicsx.algorithms.chain import solve_interior_point
    from unibuckle_fenicsx.algorithms.records import InteriorPointDetails, SectionLevelsDetails
    from unibuckle_fenicsx.algorithms.registry import choose_section_method
    from unibuckle_fenicsx.certificate.certify import certify
    from unibuckle_fenicsx.la import factor
    from unibuckle_fenicsx.la.eigen import GEPSolver
    from unibuckle_fenicsx.model.shell.section import build_section
    from unibuckle_fenicsx.spec import SolverSpec

    _keep_turns(symmetries)

    # Each level's factorisations: the count before and after it (in order, coarsest first).
    per_level: list[int] = []
    level = section_levels._level

    def counted(*args, **kwargs):  # type: ignore[no-untyped-def]
        n0 = _factorisations()
        out = level(*args, **kwargs)
        per_level.append(_factorisations() - n0)
        return out

    section_levels._level = counted
    overrides = dict(chain or {})
    if release_steps is not None:
        overrides["release_steps"] = release_steps
    options = section_levels.CHAIN_OPTIONS = dataclasses.replace(
        section_levels.CHAIN_OPTIONS, **overrides
    )
    # Seconds per section (keyed by its rows): its builds, its shared LDL^T's factorisations.
    build_s: dict[int, float] = {}
    factor_s: dict[int, float] = {}
    dofs_of: dict[int, int] = {}  # a built section's rows by its constrained directions

    def built_rows(args, out) -> int:  # type: ignore[no-untyped-def]
        rows = int(out.model.A.getSize()[0])
        dofs_of[out.constraints.size] = rows
        return rows

    _timed_by_rows(section_levels, "_build", build_s, built_rows)
    _timed_by_rows(
        factor.SharedFactorization,
        "factor",
        factor_s,
        lambda args, out: int(args[0].matrix.getSize()[0]),
    )

    params = section_parameters(shape, size, corner_cell, geometric, tube)
    PETSc.Log.begin()  # the factorisations' counts
    t0 = time.perf_counter()
    with build_section(params, MPI.COMM_WORLD) as section:
        setup = time.perf_counter() - t0
        rotation = section.problem.timings["rotation_s"]
        ref = section.classical_stress()
        times = []
        for _ in range(repeat):
            solver = GEPSolver(section.problem.pencil.A, section.problem.pencil.B, prefix="bench_")
            t1 = time.perf_counter()
            free = solver.solve().value
            times.append(time.perf_counter() - t1)
            solver.destroy()
        dofs, cells = section.model.num_dofs, section.mesh.cells_around
    t1 = time.perf_counter()
    before = _factorisations()
    if route != "single":
        chosen = route
        if route == "auto":
            chosen, _ = choose_section_method(params, SolverSpec())
        fine, solution = section_levels.solve_levels(params, levels=levels, route=chosen)
    else:
        fine = build_section(params, MPI.COMM_WORLD)
        t1 = time.perf_counter()  # the set-up is not the unilateral solve's
        solution = solve_interior_point(fine.problem)
    unilateral = time.perf_counter() - t1
    factorisations = _factorisations() - before
    with fine:
        t2 = time.perf_counter()
        cert = certify(fine.problem, solution)
        certify_s = time.perf_counter() - t2
        details = solution.details
        fine_links = _fine_links(details)
        if isinstance(details, SectionLevelsDetails):
            levels_log = [msgspec.to_builtins(level) for level in details.levels]
            for entry, count in zip(levels_log, per_level, strict=True):
                entry["factorisations"] = count
            coarse = details.coarse_eigensolves
        elif isinstance(details, InteriorPointDetails):
            sizes = [size * 2.0**k for k in range(len(details.levels) - 1, -1, -1)]
            levels_log = [
                {
                    "mesh_size": h,
                    "dofs": dofs_of.get(level.constrained_nodes, ""),
                    "cells": level.mesh,
                    "constrained": level.constrained_nodes,
                    "steps": level.newton_steps,
                    "factorisations": level.factorizations,
                    "eigensolves": level.eigensolves,
                    "wall_time_s": level.seconds,
                    "load": min((r.load for r in level.links if r.kkt), default=math.nan),
                }
                for h, level in zip(sizes, details.levels, strict=True)
            ]
            levels_log[-1]["eigensolves"] = details.fine_eigensolves
            coarse = details.coarse_eigensolves
        else:
            levels_log = [{"eigensolves": solution.eigensolves, "factorisations": factorisations}]
            coarse = 0
        for entry in levels_log:  # the seconds of its section's build and factorisations
            rows = entry.get("dofs") or dofs_of.get(entry.get("constrained", -1))
            if rows:
                entry["dofs"] = rows
                entry["build_s"] = build_s.get(rows, 0.0)
                entry["factor_s"] = factor_s.get(rows, 0.0)
        per_level_text = "; ".join(
            f"{1e3 * entry['mesh_size']:g} mm{' seeds' if entry.get('seeded') else ''}: "
            f"{entry.get('steps', '-')} / {entry['factorisations']} / {entry['eigensolves']}"
            if "mesh_size" in entry
            else f"{entry['factorisations']} / {entry['eigensolves']}"
            for entry in levels_log
        )
        return {
            "shape": shape,
            "route": route,
            "size_m": size,
            "levels_requested": levels,
            "per_level": per_level_text,
            "dofs": dofs,
            "constrained": fine.constraints.size if fine.constraints is not None else 0,
            "cells_around": cells,
            "free_load/ref": free / ref,
            "core_load/ref": solution.load / ref,
            "core_load_Pa": solution.load,
            "kkt": bool(solution.candidate.kkt),
            "certificate": f"kkt={cert.kkt}, smallest={cert.smallest_of_reduced}, "
            f"gap={cert.relative_gap:.3g} ({cert.proven_by})",
            "setup_s": setup,
            "rotation_s": rotation,
            "free_s": min(times),
            "unilateral_s": unilateral,
            "ratio": unilateral / min(times),
            "certify_s": certify_s,
            "process_ratio": (unilateral + certify_s) / (setup + min(times)),
            "eigensolves": solution.eigensolves,
            "eigensolves_fine": levels_log[-1]["eigensolves"],
            "eigensolves_coarse": coarse,
            "factorisations": factorisations,
            "levels": levels_log,
            "corner_cell": corner_cell,
            "geometric": geometric,
            "release_steps": options.release_steps,
            "escape_either": options.escape_either,
            "quick_descent": options.quick_descent,
            "max_steps": options.max_steps,
            "fine_links": fine_links,
            "tube": tube,
            "symmetries": symmetries,
        }


def _given(args: argparse.Namespace, names: tuple[str, ...]) -> dict:
    """The options of ``names`` given on the command line (not None), by name."""
    return {name: getattr(args, name) for name in names if getattr(args, name) is not None}


def main() -> None:
    """Parse the options, run, print the row."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--shape", choices=("box", "tube"), default="box")
    parser.add_argument("--size", type=float, default=0.00526, help="mesh size (m)")
    parser.add_argument("--levels", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--corner-cell", type=float, default=None)
    parser.add_argument(
        "--route",
        choices=("auto", "active-set", "levels", "interior-point", "single"),
        default="auto",
    )
    parser.add_argument(
        "--geometric", choices=("full", "donnell"), default="full",
        help="the geometric stiffness's components (donnell: as before 2026-11-30)",
    )  # fmt: skip
    parser.add_argument(
        "--release-steps", type=int, default=None,
        help="the interior point's release_steps on the sections (default: the package's)",
    )  # fmt: skip
    parser.add_argument(
        "--escape-either", action=argparse.BooleanOptionalAction, default=None,
        help="escape a saddle along either set read (default: the package's)",
    )  # fmt: skip
    parser.add_argument(
        "--quick-descent", action=argparse.BooleanOptionalAction, default=None,
        help="the feasible descent after the first try's polish (default: the package's)",
    )  # fmt: skip
    parser.add_argument(
        "--max-steps", type=int, default=None,
        help="Newton steps per run on the sections (default: the package's)",
    )  # fmt: skip
    parser.add_argument(
        "--symmetries", action=argparse.BooleanOptionalAction, default=True,
        help="leave out the active set's seeds that a turn of the section maps onto another's",
    )  # fmt: skip
    parser.add_argument("--diameter", type=float, default=None, help="tube: 2R (m), 0.2")
    parser.add_argument("--thickness", type=float, default=None, help="tube: t (m), 0.001")
    parser.add_argument("--length", type=float, default=None, help="tube: L (m), 0.1")
    parser.add_argument("--ends", choices=("simply_supported", "clamped"), default=None)
    parser.add_argument(
        "--core-span", type=float, nargs=2, default=None, help="tube: the core's x0 x1 (m)"
    )
    parser.add_argument("--links", action="store_true", help="print the finest section's links too")
    parser.add_argument(
        "--progress", action="store_true", help="the route's progress lines on stderr"
    )
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    if args.progress:
        import logging

        logging.basicConfig(format="%(asctime)s %(message)s", level=logging.WARNING)
        logging.getLogger("unibuckle_fenicsx.progress").setLevel(logging.INFO)
    route = "active-set" if args.route == "levels" else args.route
    chain = _given(args, ("escape_either", "quick_descent", "max_steps"))
    tube = _given(args, ("diameter", "thickness", "length", "ends", "core_span"))
    if "core_span" in tube:
        tube["core_span"] = tuple(tube["core_span"])
    row = run(
        args.shape, args.size, args.levels, args.repeat, args.corner_cell, route,
        args.geometric, args.release_steps, chain, tube or None, args.symmetries,
    )  # fmt: skip
    print_header("Sections with a core (one rank)", COLUMNS)
    cells = []
    for c in COLUMNS:
        v = row[c]
        cells.append(f"{v:.4g}" if isinstance(v, float) else str(v))
    print("| " + " | ".join(cells) + " |", flush=True)
    print()
    print_header("Its levels, coarsest first", LEVEL_COLUMNS)
    for level in row["levels"]:
        cells = [level.get(c, "") for c in LEVEL_COLUMNS]
        print(
            "| " + " | ".join(f"{v:.6g}" if isinstance(v, float) else str(v) for v in cells) + " |"
        )
    print(f"per level (steps / factorisations / eigen solves): {row['per_level']}")
    print(f"core load {row['core_load_Pa']!r} Pa, {row['eigensolves']} eigen solves", flush=True)
    if args.links:
        print()
        print_header("The finest section's links", LINK_COLUMNS)
        for link in row["fine_links"]:
            cells = [link.get(c, "") for c in LINK_COLUMNS]
            print(
                "| "
                + " | ".join(f"{v:.10g}" if isinstance(v, float) else str(v) for v in cells)
                + " |"
            )
    append_rows(args.json, [row])


if __name__ == "__main__":
    main()
