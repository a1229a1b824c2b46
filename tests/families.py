"""Seeded random problem families for the tests.

- :func:`random_specs` / :func:`active_family`: the paper's plate type (t = 6 mm, simply
  supported, uniaxial compression) with random aspect ratio and random box zones;
- :func:`stress_family`: every kind of plate the input schema describes (edge supports,
  uniform in-plane stress states with compression, shear or both, t/b from 1e-4 to 0.1,
  aspect ratio 0.5 to 5, zones that touch edges, are one node wide or cover the plate).
"""

from __future__ import annotations

from mpi4py import MPI

import numpy as np

from unibuckle_fenicsx.config import (
    EDGE_NAMES,
    EdgeSpec,
    Material,
    MeshSpec,
    ObstacleSpec,
    PlateSpec,
    ProblemSpec,
    SolverSpec,
)
from unibuckle_fenicsx.problem import BucklingProblem


def _interior_nodes_in_box(nx, ny, length, width, box) -> int:
    xs = np.linspace(0, length, nx + 1)[1:-1]
    ys = np.linspace(0, width, ny + 1)[1:-1]
    X, Y = np.meshgrid(xs, ys)
    tol = 1e-8 * length
    (x0, x1), (y0, y1) = box
    inside = (X >= x0 - tol) & (X <= x1 + tol) & (Y >= y0 - tol) & (Y <= y1 + tol)
    return int(inside.sum())


def random_specs(seed: int = 20240605, min_nodes: int = 3, max_nodes: int = 12):
    """Endless seeded stream of random plates with random box zones.

    Aspect 1-3, width 0.1 m, t = 6 mm; the zones hold ``min_nodes`` to ``max_nodes``
    free mesh nodes.
    """
    rng = np.random.default_rng(seed)
    count = 0
    while True:
        aspect = rng.uniform(1.0, 3.0)
        length, width = 0.1 * aspect, 0.1
        ny = int(rng.integers(2, 5))
        nx = max(2, round(aspect * ny) + int(rng.integers(-1, 2)))
        xa, xb = np.sort(rng.uniform(0, length, 2))
        ya, yb = np.sort(rng.uniform(0, width, 2))
        if rng.random() < 0.3:  # zones spanning the width, like the paper's c1
            ya, yb = 0.0, width
        box = ((float(xa), float(xb)), (float(ya), float(yb)))
        i = _interior_nodes_in_box(nx, ny, length, width, box)
        if not min_nodes <= i <= max_nodes:
            continue
        yield ProblemSpec(
            name=f"random{count}",
            plate=PlateSpec(corners=((0.0, 0.0), (length, width)), thickness=0.006),
            material=Material(E=1.0e9, nu=0.3),
            mesh=MeshSpec(nx, ny),
            obstacle=ObstacleSpec(zone=box),
            solver=SolverSpec(method="active-set"),
        )
        count += 1


def active_family(count: int = 50) -> tuple[list[ProblemSpec], int]:
    """The first ``count`` random problems whose obstacle is active.

    Active: the free mode violates it for both signs. Also returns how many inactive
    problems were skipped.
    """
    family, skipped = [], 0
    for spec in random_specs():
        problem = BucklingProblem(spec, MPI.COMM_SELF)
        v = problem.contact.values(problem.solve_free().function.x.petsc_vec)
        v = v / np.abs(v).max()
        problem.destroy()
        if min(v.max(), (-v).max()) > 1e-6:
            family.append(spec)
        else:
            skipped += 1
        if len(family) == count:
            return family, skipped
    raise AssertionError("unreachable")


# -- the stress family: every plate the schema describes ---------------------------------
#: Edge supports and their weights; at most two edges are free, and a plate with a single
#: supported edge has it clamped (no rigid motion).
SUPPORTS = ("simply_supported", "clamped", "simply_supported_soft", "free")
SUPPORT_WEIGHTS = (0.4, 0.3, 0.15, 0.15)
#: Uniform stress states (sigma_xx, sigma_yy, sigma_xy) per unit load, drawn from these.
SIGMA_XX = (-1.0, -1.0, -0.5, 0.0, 0.3)
SIGMA_YY = (0.0, 0.0, -0.5, -1.0, 0.3)
SIGMA_XY = (0.0, 0.0, 0.5, 1.0, -1.0)


def _edges(rng: np.random.Generator) -> tuple[EdgeSpec, ...] | None:
    supports = rng.choice(SUPPORTS, size=4, p=SUPPORT_WEIGHTS)
    held = [s for s in supports if s != "free"]
    if len(held) < 2 and held != ["clamped"]:
        return None
    sxx, syy, sxy = (float(rng.choice(v)) for v in (SIGMA_XX, SIGMA_YY, SIGMA_XY))
    # A compressive principal stress is needed for buckling.
    if 0.5 * (sxx + syy) - np.hypot(0.5 * (sxx - syy), sxy) >= 0.0:
        return None
    # Traction sigma . n and its counter-clockwise tangential part on each edge.
    loads = {"left": (sxx, sxy), "right": (sxx, sxy), "bottom": (syy, -sxy), "top": (syy, -sxy)}
    return tuple(
        EdgeSpec(edge, support=str(s), normal_stress=loads[edge][0], shear_stress=loads[edge][1])
        for edge, s in zip(EDGE_NAMES, supports, strict=True)
    )


def _zone(rng: np.random.Generator, length: float, width: float, nx: int, ny: int):
    """'all', a box touching an edge, a line one node wide, or a random box."""
    kind = rng.choice(("all", "edge", "line", "box"), p=(0.2, 0.25, 0.2, 0.35))
    if kind == "all":
        return "all", str(kind)
    hx, hy = length / nx, width / ny
    if kind == "line":  # one node wide, along x or y, through a mesh line
        if rng.random() < 0.5:
            x = hx * int(rng.integers(0, nx + 1))
            y0, y1 = np.sort(rng.uniform(0, width, 2))
            return ((x, x), (float(y0), float(y1))), str(kind)
        y = hy * int(rng.integers(0, ny + 1))
        x0, x1 = np.sort(rng.uniform(0, length, 2))
        return ((float(x0), float(x1)), (y, y)), str(kind)
    x0, x1 = np.sort(rng.uniform(0, length, 2))
    y0, y1 = np.sort(rng.uniform(0, width, 2))
    if kind == "edge":  # touch one edge
        side = int(rng.integers(0, 4))
        x0 = 0.0 if side == 0 else x0
        x1 = length if side == 1 else x1
        y0 = 0.0 if side == 2 else y0
        y1 = width if side == 3 else y1
    return ((float(x0), float(x1)), (float(y0), float(y1))), str(kind)


def _constrained_nodes(edges, length, width, nx, ny, zone) -> int:
    """i: mesh nodes in the closed zone whose deflection is free (not on a held edge)."""
    X, Y = np.meshgrid(np.linspace(0, length, nx + 1), np.linspace(0, width, ny + 1))
    tol = 1e-8 * max(length, width)
    inside = np.ones_like(X, dtype=bool)
    if zone != "all":
        (x0, x1), (y0, y1) = zone
        inside = (X >= x0 - tol) & (X <= x1 + tol) & (Y >= y0 - tol) & (Y <= y1 + tol)
    on_edge = {
        "left": np.isclose(X, 0.0),
        "right": np.isclose(X, length),
        "bottom": np.isclose(Y, 0.0),
        "top": np.isclose(Y, width),
    }
    for edge in edges:
        if edge.support != "free":
            inside &= ~on_edge[edge.name]
    return int(inside.sum())


def stress_family(
    count: int, seed: int = 20261122, min_constrained: int = 4, max_constrained: int = 14
):
    """The first ``count`` random problems whose zone holds min..max constrained nodes.

    (With fewer than four the obstacle is almost never active: one orientation of the
    free mode respects it.)

    Width 0.1 m, aspect ratio 0.5-5, t/b log-uniform in [1e-4, 0.1], meshes of 2-4
    cells across. Each item is (spec, zone kind, i); the solver method is "active-set".
    """
    rng = np.random.default_rng(seed)
    found = []
    while len(found) < count:
        aspect = float(np.exp(rng.uniform(np.log(0.5), np.log(5.0))))
        width = 0.1
        length = aspect * width
        edges = _edges(rng)
        if edges is None:
            continue
        ny = int(rng.integers(2, 5))
        nx = int(np.clip(round(aspect * ny), 2, 10))
        zone, kind = _zone(rng, length, width, nx, ny)
        if kind == "all":  # keep 2^i small enough for the exhaustive reference
            ny = int(rng.integers(2, 4))
            nx = int(np.clip(round(aspect * ny), 2, 6))
        thickness = width * float(10 ** rng.uniform(-4.0, -1.0))
        spec = ProblemSpec(
            name=f"stress{len(found)}",
            plate=PlateSpec(
                corners=((0.0, 0.0), (length, width)), thickness=thickness, edges=edges
            ),
            material=Material(E=1.0e9, nu=float(rng.uniform(0.0, 0.45))),
            mesh=MeshSpec(nx, ny),
            obstacle=ObstacleSpec(zone=zone),
            solver=SolverSpec(method="active-set"),
        )
        i = _constrained_nodes(edges, length, width, nx, ny, zone)
        if min_constrained <= i <= max_constrained:
            found.append((spec, kind, i))
    return found


# -- long plates with several pencil eigenvalues below the critical load -------------------
#: Edge supports of :func:`long_plate_family` (loaded edges x = const).
LONG_SUPPORTS = (
    {},  # SSSS
    {"left": "clamped", "right": "clamped"},
    {"bottom": "clamped", "top": "clamped"},
    dict.fromkeys(EDGE_NAMES, "clamped"),
)


def long_plate_family(count: int, seed: int = 20261207, max_constrained: int = 14):
    """The first ``count`` long plates (a/b 2.5-4.5) on coarse meshes, i <= ``max_constrained``.

    Uniaxial compression or shear, the four support cases of :data:`LONG_SUPPORTS`, t/b
    log-uniform in [1e-3, 3e-2], the obstacle over the whole plate or over a strip of it
    (above or below). Each item is (spec, i). Whether two or more pencil eigenvalues lie
    below the critical load is for the caller to check (it depends on the solution).
    """
    from unibuckle_fenicsx.cases import plate_case

    rng = np.random.default_rng(seed)
    found = []
    while len(found) < count:
        aspect = float(rng.uniform(2.5, 4.5))
        width, ny = 0.1, int(rng.integers(2, 4))
        nx = int(np.clip(round(aspect * ny * rng.uniform(0.8, 1.2)), 5, 10))
        supports = LONG_SUPPORTS[int(rng.integers(0, len(LONG_SUPPORTS)))]
        load = "shear" if rng.random() < 0.2 and ny == 3 else "uniaxial"
        length = aspect * width
        if rng.random() < 0.5:
            zone: str | tuple = "all"
        else:
            x0, x1 = np.sort(rng.uniform(0, length, 2))
            zone = ((float(x0), float(x1)), (0.0, width))
        side = "above" if rng.random() < 0.7 else "below"
        spec = plate_case(
            f"long{len(found)}",
            length=length,
            width=width,
            thickness=width * float(10 ** rng.uniform(-3.0, np.log10(3e-2))),
            supports=supports,
            load=load,
            nx=nx,
            ny=ny,
            zone=ObstacleSpec(zone=zone, side=side),
            solver=SolverSpec(method="active-set"),
        )
        edges = spec.plate.edges
        i = _constrained_nodes(edges, length, width, nx, ny, zone)
        if 4 <= i <= max_constrained:
            found.append((spec, i))
    return found
