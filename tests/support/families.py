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

from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.spec import (
    EDGE_NAMES,
    EdgeSpec,
    Material,
    MeshSpec,
    ObstacleSpec,
    PlateSpec,
    ProblemSpec,
    SolverSpec,
)


def tension_somewhere(nx: int, ny: int) -> ProblemSpec:
    """The paper's free plate with its left edge clamped in plane, the right one compressed.

    Poisson's effect puts part of the plate in tension: B is indefinite (the swapped
    pencil).
    """
    edges = (
        EdgeSpec("left", inplane="clamped"),
        EdgeSpec("right", normal_stress=-1.0),
        EdgeSpec("bottom"),
        EdgeSpec("top"),
    )
    return ProblemSpec(
        name="tension_somewhere", plate=PlateSpec(edges=edges), mesh=MeshSpec(nx, ny)
    )


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
        problem = build_problem(spec, MPI.COMM_SELF)
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
    rng = np.random.default_rng(seed)
    found = []
    while len(found) < count:
        aspect = float(rng.uniform(2.5, 4.5))
        ny = int(rng.integers(2, 4))
        nx = int(np.clip(round(aspect * ny * rng.uniform(0.8, 1.2)), 5, 10))
        supports = LONG_SUPPORTS[int(rng.integers(0, len(LONG_SUPPORTS)))]
        load = "shear" if rng.random() < 0.2 and ny == 3 else "uniaxial"
        item = _long_plate(rng, f"long{len(found)}", aspect, nx, ny, supports, load, 0.5)
        if 4 <= item[1] <= max_constrained:
            found.append(item)
    return found


def _long_plate(rng, name, aspect, nx, ny, supports, load, whole: float):
    """(spec, i) of one long plate of width 0.1 m.

    t/b log-uniform in [1e-3, 3e-2], the face over the whole plate (probability
    ``whole``) or a strip, above (0.7) or below; solved by the active set.
    """
    from unibuckle_fenicsx.spec.cases import plate_case

    width = 0.1
    length = aspect * width
    if rng.random() < whole:
        zone: str | tuple = "all"
    else:
        x0, x1 = np.sort(rng.uniform(0, length, 2))
        zone = ((float(x0), float(x1)), (0.0, width))
    side = "above" if rng.random() < 0.7 else "below"
    spec = plate_case(
        name,
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
    return spec, _constrained_nodes(spec.plate.edges, length, width, nx, ny, zone)


def translated_family(count: int, seed: int = 20260611, max_constrained: int = 14):
    """The first ``count`` very long plates with one row of free nodes (a/b 4-7, ny = 2).

    Their buckles slide along the row: families of nearly equal critical states
    translated along the plate, small enough for exhaustive enumeration (i = nx - 1 at
    most ``max_constrained`` on a whole-face obstacle, fewer on a strip). Each item is
    (spec, i); supports as in :func:`long_plate_family`, uniaxial compression.
    """
    rng = np.random.default_rng(seed)
    found = []
    while len(found) < count:
        aspect = float(rng.uniform(4.0, 7.0))
        nx = int(rng.integers(8, max_constrained + 2))
        supports = LONG_SUPPORTS[int(rng.integers(0, len(LONG_SUPPORTS)))]
        item = _long_plate(rng, f"slide{len(found)}", aspect, nx, 2, supports, "uniaxial", 0.7)
        if 4 <= item[1] <= max_constrained:
            found.append(item)
    return found


# -- the schema family: every feature of the problem file ---------------------------------
#: The family's numbers that reach the compiled forms (stiffness, thickness, plate size)
#: come from short lists: the forms hold them as literals, and each new value costs a JIT
#: compilation (about 10 s) on a cold cache.
MODULI = (1.0e9, 2.1e11)
POISSON = (0.0, 0.3, 0.45)
SLENDERNESS = (1e-3, 1e-2, 6e-2)
ASPECTS = (0.75, 1.0, 1.5, 2.0, 3.0)

#: Outlines of the schema family on the unit box (scaled to length x width): a rectangle,
#: a trapezoid (one inclined edge), an L and a house (two inclined edges).
OUTLINES = {
    "rectangle": ((0, 0), (1, 0), (1, 1), (0, 1)),
    "trapezoid": ((0, 0), (1, 0), (0.75, 1), (0, 1)),
    "L": ((0, 0), (1, 0), (1, 0.5), (0.5, 0.5), (0.5, 1), (0, 1)),
    "house": ((0, 0), (1, 0), (1, 0.6), (0.5, 1), (0, 0.6)),
}


def _rotated_voigt(q: np.ndarray, angle: float) -> np.ndarray:
    """The Voigt matrix (e11, e22, 2 e12) of the stiffness ``q`` turned by ``angle``."""
    index = ((0, 0), (1, 1), (0, 1))
    C = np.zeros((2, 2, 2, 2))
    for a, (i, j) in enumerate(index):
        for b, (k, m) in enumerate(index):
            for p, q_ in ((i, j), (j, i)):
                for r, s in ((k, m), (m, k)):
                    C[p, q_, r, s] = q[a, b]
    c, s_ = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s_], [s_, c]])
    Cr = np.einsum("ia,jb,kc,ld,abcd->ijkl", R, R, R, R, C)
    return np.array([[Cr[i, j, k, m] for (k, m) in index] for (i, j) in index])


def _material(rng: np.random.Generator, thickness: float) -> tuple[dict, str]:
    E, nu = float(rng.choice(MODULI)), float(rng.choice(POISSON))
    table = {"E": E, "nu": nu}
    if rng.random() < 0.3:  # orthotropic, turned: a fully populated SPD stiffness
        e2 = E * float(rng.choice((0.3, 0.7)))
        nu21 = nu * e2 / E
        g = E / (2 * (1 + nu)) * 0.5
        d = 1 - nu * nu21
        q = np.array([[E / d, nu * e2 / d, 0], [nu * e2 / d, e2 / d, 0], [0, 0, g]])
        q = _rotated_voigt(q, float(rng.choice((0.0, np.pi / 6, np.pi / 3))))
        table["membrane_voigt"] = (thickness * q).tolist()
        table["bending_voigt"] = (thickness**3 / 12 * q).tolist()
        return table, "anisotropic"
    return table, "isotropic"


def _stress_state(rng: np.random.Generator) -> tuple[float, float, float] | None:
    sxx, syy, sxy = (float(rng.choice(v)) for v in (SIGMA_XX, SIGMA_YY, SIGMA_XY))
    if 0.5 * (sxx + syy) - np.hypot(0.5 * (sxx - syy), sxy) >= 0.0:
        return None  # no compressive principal stress: nothing buckles
    return sxx, syy, sxy


def _segment_traction(sigma, p, q) -> tuple[float, float]:
    """(normal, counter-clockwise shear) stress of the uniform state on segment p -> q."""
    sxx, syy, sxy = sigma
    s = (np.asarray(q, float) - p) / np.linalg.norm(np.asarray(q, float) - p)
    n = np.array([s[1], -s[0]])  # outward for a counter-clockwise outline
    t = np.array([[sxx, sxy], [sxy, syy]]) @ n
    return float(n @ t), float(s @ t)


def _zone_table(rng: np.random.Generator, length: float, width: float, h: float):
    """A random zone table: box (inside or reaching out), polygon, circle or all."""
    kind = str(rng.choice(("box", "polygon", "circle", "all"), p=(0.45, 0.2, 0.2, 0.15)))
    if kind == "all":
        return {"zone": "all"}, kind
    cx, cy = rng.uniform(0.15, 0.85) * length, rng.uniform(0.15, 0.85) * width
    if kind == "circle":
        return {"circle": {"center": [cx, cy], "radius": float(rng.uniform(1.2, 2.5) * h)}}, kind
    hx, hy = (float(rng.uniform(1.2, 3.0) * h) for _ in range(2))
    if kind == "box":
        return {"zone": [[cx - hx, cx + hx], [cy - hy, cy + hy]]}, kind
    angles = np.sort(rng.uniform(0, 2 * np.pi, int(rng.integers(3, 6))))
    if np.diff(np.concatenate([angles, [angles[0] + 2 * np.pi]])).max() > 0.9 * np.pi:
        angles = np.linspace(0, 2 * np.pi, len(angles), endpoint=False) + angles[0]
    vertices = [[cx + hx * np.cos(a), cy + hy * np.sin(a)] for a in angles]
    return {"polygon": vertices}, kind


def _bounding_box(table: dict, length: float, width: float) -> np.ndarray:
    """[[xmin, ymin], [xmax, ymax]] of a zone table."""
    if "circle" in table:
        c, r = np.asarray(table["circle"]["center"]), table["circle"]["radius"]
        return np.array([c - r, c + r])
    if "polygon" in table:
        v = np.asarray(table["polygon"])
        return np.array([v.min(axis=0), v.max(axis=0)])
    if table["zone"] == "all":
        return np.array([[0.0, 0.0], [length, width]])
    (x0, x1), (y0, y1) = table["zone"]
    return np.array([[x0, y0], [x1, y1]])


def _apart(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two boxes are separated (by 1e-6 of their size) along x or y."""
    gap = 1e-6 * float(np.ptp(np.concatenate([a, b]), axis=0).max())
    return bool((a[0] > b[1] + gap).any() or (b[0] > a[1] + gap).any())


def _schema_problem(rng: np.random.Generator, name: str) -> tuple[dict, list[str]]:  # noqa: C901 - one branch per key of the schema, drawn in the schema's order
    """One random problem file (a mapping) and the features it uses."""
    features: list[str] = []
    width = 0.1
    length = width * float(rng.choice(ASPECTS))
    thickness = width * float(rng.choice(SLENDERNESS))
    sigma = _stress_state(rng)
    if sigma is None:
        raise ValueError("no compression")
    geometry = str(rng.choice(("rectangle", "outline", "holes"), p=(0.6, 0.25, 0.15)))
    data: dict = {"name": name, "plate": {"thickness": thickness}}
    edges: dict = {}
    cells = int(rng.integers(2, 5)) if geometry != "holes" else 4
    h = width / cells
    if geometry == "rectangle":
        data["plate"]["corners"] = [[0.0, 0.0], [length, width]]
        loads = {
            "left": (sigma[0], sigma[2]), "right": (sigma[0], sigma[2]),
            "bottom": (sigma[1], -sigma[2]), "top": (sigma[1], -sigma[2]),
        }  # fmt: skip
        gradient = rng.random() < 0.3
        for edge in EDGE_NAMES:
            normal, shear = loads[edge]
            table = {"support": str(rng.choice(SUPPORTS, p=SUPPORT_WEIGHTS))}
            table["normal_stress"], table["shear_stress"] = normal, shear
            if gradient and edge in ("left", "right"):  # + sigma_xx linear in y
                table["normal_stress"] = [normal - 0.5, normal + 0.5]
            edges[edge] = table
        features.append("gradient" if gradient else "uniform")
        if rng.random() < 0.3:
            data["mesh"] = {"size": h}
        else:
            data["mesh"] = {"nx": max(2, round(length / h)), "ny": cells}
    else:
        shape = str(rng.choice(list(OUTLINES))) if geometry == "outline" else "rectangle"
        vertices = [[x * length, y * width] for x, y in OUTLINES[shape]]
        features.append(f"outline {shape}")
        n = len(vertices)
        for k in range(n):
            p, q = np.asarray(vertices[k]), np.asarray(vertices[(k + 1) % n])
            normal, shear = _segment_traction(sigma, p, q)
            inclined = min(abs(q - p)) > 1e-12
            choices = ("simply_supported_soft", "clamped", "free") if inclined else SUPPORTS
            support = str(rng.choice(choices))
            edges[f"s{k}"] = {
                "segments": [k], "support": support, "normal_stress": normal, "shear_stress": shear,
            }  # fmt: skip
        data["plate"]["outline"] = vertices
        if geometry == "holes":
            holes = [{"center": [0.5 * length, 0.5 * width], "radius": 0.2 * width}]
            if length > 1.6 * width:
                holes[0]["center"][0] = 0.3 * length
                holes.append(
                    {"outline": [[0.65 * length, 0.35 * width], [0.8 * length, 0.35 * width],
                                 [0.72 * length, 0.65 * width]]}
                )  # fmt: skip
            data["plate"]["holes"] = holes
            edges["holes"] = {"support": str(rng.choice(("free", "clamped")))}
            features.append(f"{len(holes)} hole(s)")
        data["mesh"] = {"size": h}
    data["edges"] = edges
    material, kind = _material(rng, thickness)
    data["material"] = material
    features.append(kind)
    # Obstacles: rigid, or tensionless foundations, plus maybe a bilateral foundation.
    count = int(rng.choice((1, 2, 3), p=(0.55, 0.35, 0.1)))
    tensionless = rng.random() < 0.15
    D = material["E"] * thickness**3 / (12 * (1 - material["nu"] ** 2))
    tables, boxes = [], []
    side = str(rng.choice(("above", "below")))
    for _ in range(count):
        table, zone = _zone_table(rng, length, width, h)
        if zone == "all" and count > 1:
            continue
        box = _bounding_box(table, length, width)
        # The other side only for a zone apart from the others (no node in both).
        near = {t["side"] for t, other in zip(tables, boxes, strict=True) if not _apart(box, other)}
        if len(near) > 1:
            continue
        table["side"] = (
            near.pop() if near else str(rng.choice(("above", "below"))) if tables else side
        )
        if tensionless:
            table["foundation_stiffness"] = D / width**4 * float(rng.choice((1.0, 1e2, 1e4)))
        tables.append(table)
        boxes.append(box)
        features.append(f"{zone} {table['side']}")
    if tensionless:
        features.append("tensionless")
    elif rng.random() < 0.15:
        table, zone = _zone_table(rng, length, width, h)
        tables.append({**table, "side": "both", "foundation_stiffness": D / width**4 * 100})
        features.append(f"bilateral {zone}")
    if not tables:
        raise ValueError("no obstacle")
    if len(tables) == 1:
        data["obstacle"] = tables[0]
    else:
        data["obstacles"] = tables
    method = (
        "auto"
        if tensionless
        else str(rng.choice(("auto", "active-set", "enumerate"), p=(0.5, 0.3, 0.2)))
    )
    data["solver"] = {"method": method, "enumeration_budget_s": 2.0}
    if method == "enumerate":  # exact, and refused beyond 2^12 candidate sets
        data["solver"] |= {"until_proven": True, "max_candidates": 4096}
    features.append(method)
    return data, features


def schema_family(count: int, seed: int = 20260301) -> list[tuple[dict, list[str]]]:
    """The first ``count`` random problem files the schema accepts, with their features.

    Every feature of the problem file: the rectangle (cells or a size), outlines with
    inclined edges, holes (a circle, a polygon), the four supports, uniform normal and
    shear stress states and stress gradients, isotropic and anisotropic (turned
    orthotropic) stiffness, one to three obstacles with box, polygon, circle or
    whole-plate zones on either side, tensionless and bilateral foundations, and the
    methods auto, active-set and enumerate. Draws the schema refuses (a mechanism, two
    zones on both sides of the plate) are drawn again: refusing them is the bad-input
    family's concern.
    """
    from unibuckle_fenicsx.spec import problem_from_dict

    rng = np.random.default_rng(seed)
    found: list[tuple[dict, list[str]]] = []
    while len(found) < count:
        try:
            data, features = _schema_problem(rng, f"schema{len(found)}")
            problem_from_dict(data)
        except ValueError:
            continue
        found.append((data, features))
    return found
