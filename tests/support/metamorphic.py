r"""Metamorphic relations: what must hold between the answers of related problems.

No expected value here comes from a formula: each check compares two answers of the
package whose order (or ratio) follows from the problem's definition (docs/methods/
problem.md, foundations.md), so a violated relation means a wrong answer somewhere.

- **Ordering**: :math:`\lambda_\text{free} \le \lambda_c \le \lambda(I)`. The cone C
  contains the bilateral space {u_k = 0, k in I} and lies in the whole space, and
  :math:`\lambda = \min a/b` over each (problem.md, "The KKT conditions").
- **Zone monotonicity**: a zone whose nodes are a superset gives a smaller cone: the
  minimum cannot drop.
- **Foundation monotonicity**: the tensionless quotient a + sum rho_k max(0, s_k v_k)^2
  grows pointwise with k_f, and is a(v)/b(v) on the rigid cone's modes: lambda(k_f) is
  non-decreasing and at most lambda_rigid (foundations.md).
- **Edge-spring monotonicity**: (1/2) int k_r (theta.n)^2 ds grows with k_r: the
  quotient grows pointwise, so the minimum over the same cone does not drop.
- **Invariance**: mirroring x -> L - x maps the plate, its supports, loads (shear changes
  sign, edge pairs along x reverse) and zone onto the mirrored ones, the forms onto
  themselves: the load is the same. a scales with E and b does not: lambda(sE) =
  s lambda(E) (a thermal prestress scales with E too: lambda(sE) = lambda). b scales
  with the unit stress c: lambda(c sigma) = lambda(sigma)/c.
- **Agreement**: every method minimises over the same cone; a lower admissible load from
  one refutes a higher one claimed proven, and a verified lower bound above another
  method's admissible load is unsound.

Problem n of a sweep of plates is drawn from ``np.random.default_rng([seed, n])``: each
problem is reproduced from its two numbers; the foundations' long plates
(:func:`foundation_plate`) are the stream of one ``default_rng(seed)``. The sweep:
``bench/bench_metamorphic.py``; fixed-seed cases: ``tests/unit/algorithms/test_metamorphic.py``.
"""

from __future__ import annotations

import copy
import itertools
import math

from mpi4py import MPI

import numpy as np

from support.exhaustive import dense_reduced_load, exhaustive_tensionless
from unibuckle_fenicsx import problem_from_dict
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.errors import UnibuckleError
from unibuckle_fenicsx.model.build import build_problem

#: Relative slack of an inequality between two computed loads: the eigen solves converge
#: to eps_tol = 1e-10 and a thin plate's load is fixed only to ~1e-8 of it
#: (problem.md, "load resolution"); 1e-7 is the tolerance the project allows between
#: routes (foundations.md, "Stiff foundations").
RTOL = 1e-7

# Short lists: each distinct value reaching the compiled forms costs a JIT compilation.
WIDTH = 0.1
ASPECTS = (1.0, 2.0, 3.0)
SLENDERNESS = (1e-3, 1e-2, 5e-2)
E0 = 1.0e9
NU = 0.3
SUPPORTS = ("simply_supported", "simply_supported_soft", "clamped", "free")
LOADS = ("compression", "shear", "gradient", "thermal", "biaxial")


def _edges(rng, load: str) -> dict:
    supports = {e: str(rng.choice(SUPPORTS, p=(0.45, 0.15, 0.3, 0.1))) for e in EDGES}
    held = [s for s in supports.values() if s != "free"]
    if len(held) < 2 and held != ["clamped"]:
        supports["bottom"] = supports["top"] = "simply_supported"
    if load == "thermal":
        # every edge held in plane: a rise compresses the plate
        return {e: {"support": s, "inplane": "clamped"} for e, s in supports.items()}
    edges = {e: {"support": s} for e, s in supports.items()}
    if load == "compression":
        edges["left"]["normal_stress"] = edges["right"]["normal_stress"] = -1.0
    elif load == "biaxial":
        edges["left"]["normal_stress"] = edges["right"]["normal_stress"] = -1.0
        edges["bottom"]["normal_stress"] = edges["top"]["normal_stress"] = -0.5
    elif load == "shear":
        # sigma_xy = tau: traction tangent +tau on left/right... counter-clockwise tangent
        edges["left"]["shear_stress"] = edges["right"]["shear_stress"] = 1.0
        edges["bottom"]["shear_stress"] = edges["top"]["shear_stress"] = -1.0
    elif load == "gradient":  # psi = -0.5 (compression at y = 0)
        edges["left"]["normal_stress"] = edges["right"]["normal_stress"] = [-1.0, 0.5]
    return edges


EDGES = ("left", "right", "bottom", "top")


def random_problem(rng, name: str) -> dict:
    """One random rectangular plate with a box (or whole) obstacle, as a problem mapping."""
    aspect = float(rng.choice(ASPECTS))
    length = aspect * WIDTH
    load = str(rng.choice(LOADS, p=(0.35, 0.2, 0.2, 0.1, 0.15)))
    ny = int(rng.integers(3, 8))
    nx = max(3, round(aspect * ny))
    hx, hy = length / nx, WIDTH / ny
    if rng.random() < 0.2:
        zone: str | list = "all"
    else:  # a box on mesh lines, at least one cell each way
        i0, i1 = np.sort(rng.choice(nx + 1, 2, replace=False))
        j0, j1 = np.sort(rng.choice(ny + 1, 2, replace=False))
        zone = [[float(i0 * hx), float(i1 * hx)], [float(j0 * hy), float(j1 * hy)]]
    data = {
        "name": name,
        "plate": {
            "corners": [[0.0, 0.0], [length, WIDTH]],
            "thickness": float(WIDTH * rng.choice(SLENDERNESS)),
        },
        "material": {"E": E0, "nu": NU},
        "edges": _edges(rng, load),
        "mesh": {"nx": nx, "ny": ny},
        "obstacle": {"zone": zone, "side": str(rng.choice(("above", "below")))},
        "solver": {"method": "auto"},
    }
    if load == "thermal":
        data["material"]["thermal_expansion"] = 1.2e-5
        data["load"] = {"temperature": 1.0}
    data["_load"] = load
    return data


def spec_of(data: dict):
    d = {k: v for k, v in data.items() if not k.startswith("_")}
    return problem_from_dict(d)


def run(data: dict, method: str | None = None, *, bilateral: bool = False) -> dict:
    """Solve ``data``; its load, status, lower bound, i; with ``bilateral`` also lambda(I)."""
    d = copy.deepcopy(data)
    if method is not None:
        d.setdefault("solver", {})["method"] = method
    spec = spec_of(d)
    out: dict = {}
    try:
        with solve(spec, MPI.COMM_WORLD) as analysis:
            r = analysis.result
            out["load"] = r.critical_load_Pa
            out["free"] = r.free_load_Pa
            out["method"] = r.method
            out["i"] = r.constrained_nodes
            out["lower"] = r.lower_bound_Pa
            cert = analysis.certificate
            out["status"] = getattr(cert, "status", None)
            if bilateral and r.constrained_nodes and MPI.COMM_WORLD.size == 1:
                # the pencil without the zone's deflections, by LAPACK (not the package's
                # eigen solver)
                problem = analysis.problem
                out["bilateral"] = dense_reduced_load(
                    problem, tuple(range(problem.num_constrained))
                )
    except UnibuckleError as exc:
        out["error"] = f"{type(exc).__name__}: {exc}"[:300]
    return out


def mirrored(data: dict) -> dict:
    """The plate mirrored about x = L/2: supports and loads of left/right swapped."""
    d = copy.deepcopy(data)
    (x0, _y0), (x1, _y1) = d["plate"]["corners"]
    edges = d["edges"]
    edges["left"], edges["right"] = edges["right"], edges["left"]
    for e in EDGES:
        t = edges[e]
        if "shear_stress" in t:  # sigma_xy -> -sigma_xy under x -> -x
            t["shear_stress"] = -t["shear_stress"]
        if e in ("bottom", "top") and isinstance(t.get("normal_stress"), list):
            t["normal_stress"] = t["normal_stress"][::-1]
    zone = d["obstacle"]["zone"]
    if zone != "all":
        (a, b), yz = zone
        d["obstacle"]["zone"] = [[x0 + x1 - b, x0 + x1 - a], yz]
    return d


def scaled_load(data: dict, c: float) -> dict:
    d = copy.deepcopy(data)
    if "load" in d:
        d["load"]["temperature"] *= c
    for t in d["edges"].values():
        for key in ("normal_stress", "shear_stress"):
            if key in t:
                v = t[key]
                t[key] = [c * x for x in v] if isinstance(v, list) else c * v
    return d


def scaled_modulus(data: dict, s: float) -> dict:
    d = copy.deepcopy(data)
    d["material"]["E"] *= s
    return d


def superset_zone(data: dict, rng) -> dict | None:
    d = copy.deepcopy(data)
    zone = d["obstacle"]["zone"]
    if zone == "all":
        return None
    (x0, y0), (x1, y1) = d["plate"]["corners"]
    (a, b), (c, e) = zone
    nx, ny = d["mesh"]["nx"], d["mesh"]["ny"]
    hx, hy = (x1 - x0) / nx, (y1 - y0) / ny
    grow = rng.integers(0, 3, 4)
    d["obstacle"]["zone"] = [
        [max(x0, a - grow[0] * hx), min(x1, b + grow[1] * hx)],
        [max(y0, c - grow[2] * hy), min(y1, e + grow[3] * hy)],
    ]
    return d if d["obstacle"]["zone"] != zone else None


def with_spring(data: dict, edge: str, k: float) -> dict:
    d = copy.deepcopy(data)
    d["edges"][edge]["rotational_stiffness"] = k
    return d


def foundation(data: dict, kf: float) -> dict:
    d = copy.deepcopy(data)
    d["obstacle"]["foundation_stiffness"] = kf
    return d


def lower(a: float, b: float, rtol: float = RTOL) -> bool:
    """Whether a < b beyond the slack: a relation a >= b violated."""
    return a < b * (1 - rtol)


#: Relations a KKT point that is not the global minimum may break without being wrong:
#: such answers are allowed (problem.md: "kkt-only", a verified critical state not proven
#: the lowest), and recorded as notes, not violations.
NOTES = ("unproven above another method", "unproven above its relative")


class Checker:
    """The violations (and notes) of one problem's relations."""

    def __init__(self) -> None:
        self.violations: list[dict] = []

    def bad(self, relation: str, **numbers) -> None:
        """Record a violation of ``relation`` with its numbers."""
        self.violations.append({"relation": relation, **numbers})

    def at_least(
        self, relation: str, small: dict, big: dict, *, strict: bool = False, **context
    ) -> None:
        """``big``'s load >= ``small``'s: the problem of ``big`` minimises over a subset.

        Violated when ``big`` is lower; if ``small``'s answer is not proven the global
        minimum, ``big`` lower only shows ``small`` at a KKT point above its minimum (a
        note), unless ``big``'s load lies below ``small``'s verified lower bound, or
        ``strict`` (the tensionless foundation's relations, which the package claims for
        its answers: docs/methods/foundations.md).
        """
        if "load" not in small or "load" not in big or not lower(big["load"], small["load"]):
            return
        numbers = {"load": small["load"], "relative": big["load"], **context}
        if strict or small.get("status") == "proven":
            self.bad(relation, **numbers)
        elif small.get("lower") is not None and lower(big["load"], small["lower"]):
            self.bad(relation + " (below the lower bound)", bound=small["lower"], **numbers)
        else:
            self.bad(
                "unproven above its relative", of=relation, status=small.get("status"), **numbers
            )

    def scaled(self, relation: str, one: dict, other: dict, factor: float, **context) -> None:
        """``other``'s load = ``factor`` x ``one``'s: each maps onto the other's problem."""
        if "load" not in one or "load" not in other:
            return
        mapped = {**other, "load": other["load"] / factor}
        if mapped.get("lower") is not None:
            mapped["lower"] = mapped["lower"] / factor
        self.at_least(relation, one, mapped, **context)
        self.at_least(relation, mapped, one, **context)


def check_problem(data: dict, rng, full: bool) -> tuple[dict, list[dict]]:
    """Solve ``data`` and its relatives; the loads and the violations (with notes).

    ``full``: also E scaled and six tensionless foundations.
    """
    check = Checker()
    rec: dict = {"name": data["name"], "load_kind": data["_load"]}
    base = run(data, bilateral=True)
    rec["auto"] = base
    if "load" not in base:
        return rec, check.violations
    lam, free = base["load"], base["free"]
    # ordering: the whole space, the cone, the bilateral subspace
    if lower(lam, free):
        check.bad("ordering free<=unilateral", free=free, load=lam)
    if "bilateral" in base and lower(base["bilateral"], lam):
        check.bad("ordering unilateral<=bilateral", load=lam, bilateral=base["bilateral"])
    _methods(data, base, rec, check)
    _invariance(data, base, rec, check, rng)
    _monotone(data, base, rec, check, rng)
    if full:
        _full(data, base, rec, check)
    return rec, check.violations


def _methods(data: dict, base: dict, rec: dict, check: Checker) -> None:
    """Every method minimises over the same cone."""
    answers = {"auto": base}
    methods = ["active-set", "interior-point"]
    if base["i"] <= 12:
        methods.append("enumerate")
    for m in methods:
        d = copy.deepcopy(data)
        if m == "enumerate":
            d["solver"]["until_proven"] = True
        answers[m] = run(d, m)
    rec["methods"] = {k: v for k, v in answers.items() if k != "auto"}
    for m, v in answers.items():
        for other, w in answers.items():
            if other != m:
                check.at_least("agreement", v, w, method=m, other=other)


def _invariance(data: dict, base: dict, rec: dict, check: Checker, rng) -> None:
    """The mirrored plate, and the load per unit scaled."""
    rec["mirror"] = run(mirrored(data))
    check.scaled("invariance mirror", base, rec["mirror"], 1.0)
    c = float(rng.choice((0.5, 4.0)))
    rec["scaled_load"] = run(scaled_load(data, c))
    check.scaled("invariance load scale", base, rec["scaled_load"], 1.0 / c, c=c)


def _monotone(data: dict, base: dict, rec: dict, check: Checker, rng) -> None:
    """A larger zone, stiffer edge springs."""
    sup = superset_zone(data, rng)
    if sup is not None:
        rec["superset"] = run(sup)
        check.at_least("monotone zone", base, rec["superset"], zone=sup["obstacle"]["zone"])
    not_clamped = [e for e, t in data["edges"].items() if t["support"] != "clamped"]
    if not_clamped:
        edge = str(rng.choice(not_clamped))
        D = E0 * data["plate"]["thickness"] ** 3 / (12 * (1 - NU**2))
        ks = [D / WIDTH, 10 * D / WIDTH]
        springs = [run(with_spring(data, edge, k)) for k in ks]
        rec["spring"] = {"edge": edge, "k": ks, "r": springs}
        for soft, stiff in itertools.pairwise([base, *springs]):
            check.at_least("monotone edge spring", soft, stiff, edge=edge)


def _full(data: dict, base: dict, rec: dict, check: Checker) -> None:
    """E scaled, and tensionless foundations from soft to stiff."""
    # a thermal prestress is E alpha T: a and b both scale with E, lambda does not
    s = 2.0
    rec["E_scaled"] = run(scaled_modulus(data, s))
    factor = 1.0 if data["_load"] == "thermal" else s
    check.scaled("invariance E scale", base, rec["E_scaled"], factor)
    D = E0 * data["plate"]["thickness"] ** 3 / (12 * (1 - NU**2))
    kfs = [K * math.pi**4 * D / WIDTH**4 for K in (1.0, 10.0, 1e2, 1e4, 1e6, 1e9)]
    res = [run(foundation(data, kf)) for kf in kfs]
    rec["foundation"] = {"kf": kfs, "r": res}
    chain = [{"load": base["free"]}, *res]
    loads = [r.get("load") for r in chain]
    for soft, stiff in itertools.pairwise(chain):
        check.at_least("monotone foundation", soft, stiff, strict=True, loads=loads)
    for r in res:  # at most the rigid obstacle's: its mode presses no spring
        check.at_least("foundation <= rigid", r, base, strict=True, loads=loads)


# -- tensionless foundations on long plates ---------------------------------------------
#: Foundations of :func:`check_foundations`: K = k_f b^4/(pi^4 D), from soft to stiff.
KS = (0.3, 1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1e3, 1e4, 1e6, 1e9)
LONG_SUPPORTS = ("simply_supported", "clamped")


def foundation_plate(rng, name: str) -> dict:
    """A long plate (a/b 2 or 3) on a coarse mesh, the foundation over all or a strip.

    2 or 3 cells across, simply supported or clamped loaded and long edges, compression
    (or shear, 1 in 5), t/b = 1e-3 or 1e-2, above or below. The plate with a rigid
    obstacle: :func:`check_foundations` makes its foundations.
    """
    aspect = float(rng.choice((2.0, 3.0)))
    width = 0.1
    length = aspect * width
    ny = int(rng.integers(2, 4))
    nx = round(aspect * ny * float(rng.choice((1.0, 1.5))))
    loaded = str(rng.choice(LONG_SUPPORTS))
    long_ = str(rng.choice(LONG_SUPPORTS))
    shear = rng.random() < 0.2
    edges = {
        "left": {"support": loaded}, "right": {"support": loaded},
        "bottom": {"support": long_}, "top": {"support": long_},
    }  # fmt: skip
    if shear:
        for e, s in (("left", 1.0), ("right", 1.0), ("bottom", -1.0), ("top", -1.0)):
            edges[e]["shear_stress"] = s
    else:
        edges["left"]["normal_stress"] = edges["right"]["normal_stress"] = -1.0
    if rng.random() < 0.5:
        zone: str | list = "all"
    else:
        i0, i1 = np.sort(rng.choice(nx + 1, 2, replace=False))
        zone = [[i0 * length / nx, i1 * length / nx], [0.0, width]]
    return {
        "name": name,
        "plate": {"corners": [[0.0, 0.0], [length, width]],
                  "thickness": float(width * rng.choice((1e-3, 1e-2)))},
        "material": {"E": 1.0e9, "nu": 0.3},
        "edges": edges,
        "mesh": {"nx": nx, "ny": ny},
        "obstacle": {"zone": zone, "side": str(rng.choice(("above", "below")))},
    }  # fmt: skip


def _starts(result) -> dict:
    """The foundation's start kept, and each start's load."""
    run = result.details.run
    return {k: getattr(run, k, None) for k in ("foundation_start", "foundation_loads")}


def check_foundations(data: dict, dense: bool) -> tuple[dict, list[dict]]:
    """``data``'s rigid obstacle made a foundation of every K in :data:`KS`: the relations.

    lambda_free <= lambda(K) non-decreasing <= lambda_rigid; with ``dense`` and i <= 12,
    each load against the minimum over every spring set (:func:`exhaustive_tensionless`).
    """
    t = data["plate"]["thickness"]
    D = 1.0e9 * t**3 / (12 * (1 - 0.3**2))
    b = data["plate"]["corners"][1][1]
    rec: dict = {"name": data["name"], "loads": [], "dense": []}
    viol: list[dict] = []
    with solve(spec_of(data), MPI.COMM_WORLD) as rigid:
        lam_rigid = rigid.result.critical_load_Pa
        free = rigid.result.free_load_Pa
        i = rigid.result.constrained_nodes
    rec.update(rigid=lam_rigid, free=free, i=i)
    for K in KS:
        d = copy.deepcopy(data)
        d["obstacle"]["foundation_stiffness"] = K * math.pi**4 * D / b**4
        with solve(spec_of(d), MPI.COMM_WORLD) as analysis:
            lam = analysis.result.critical_load_Pa
            rec["loads"].append(lam)
            rec.setdefault("starts", []).append(_starts(analysis.result))
        if dense and i <= 12:
            problem = build_problem(spec_of(d), MPI.COMM_WORLD)
            try:
                ref = exhaustive_tensionless(problem)
            finally:
                problem.destroy()
            rec["dense"].append(ref)
            if lam > ref * (1 + RTOL):
                viol.append({"relation": "above dense minimum", "K": K, "load": lam, "dense": ref})
    chain = [("free", free), *list(zip(KS, rec["loads"], strict=True)), ("rigid", lam_rigid)]
    for (ka, a), (kb, bb) in itertools.pairwise(chain):
        if bb < a * (1 - RTOL):
            viol.append(
                {
                    "relation": "monotone foundation",
                    "K": [ka, kb],
                    "loads": [a, bb],
                    "excess": a / bb - 1,
                }
            )
    return rec, viol
