r"""The schema family: seeded random problem files over every feature of the schema.

Rectangles (cells or a size) and gmsh outlines with inclined edges and holes, the four
supports, uniform stress states and stress gradients, isotropic and anisotropic
stiffness, one to three obstacles (box, polygon, circle, whole plate) on either side,
tensionless and bilateral foundations, methods auto, active-set and enumerate
(``tests/support/families.py``, :func:`support.families.schema_family`). Each is solved
as a user would (``unibuckle_fenicsx.solve``, certificate on), and:

- *everywhere*, its certificate is checked independently: the returned mode satisfies
  the KKT conditions (rigid obstacles) or is stationary for the spring quotient
  (tensionless foundations), recomputed with dense numpy from a separately assembled
  problem (``tests/support/exhaustive.py``), and the bracket holds;
- *where 2^i is small* (i <= :data:`I_MAX`), the load equals the dense exhaustive
  minimum over all 2^i contact sets (rigid) or spring sets (tensionless foundations),
  to :data:`RTOL`, whenever the result claims to be proven or comes from an exact
  method; otherwise it is a KKT point at or above it, listed in :data:`KNOWN_ABOVE`.

A problem with no admissible mode must be reported so (NoAdmissibleModeError), and the
exhaustive search must agree.

The design output (``[design]``, EN 1993-1-5 4.4) is added to every file of the family:
the element it is (internal: both edges parallel to the direct stress supported;
outstand: one free) or the refusal (a plate that is not the rectangle, biaxial or no
compressive normal stress, both such edges free, a stress ratio outside the table) is
worked out here by hand from the file's tables and compared with the package's; where it
is accepted, the sample's solves check the reduction factor against eq. (4.2) or (4.3).

The default run takes the first :data:`SAMPLE` problems; ``-m stress`` runs all
:data:`FAMILY_SIZE`.
"""

from __future__ import annotations

import math
import re
from types import SimpleNamespace

from mpi4py import MPI

import numpy as np
import pytest

from support.exhaustive import (
    dense,
    dense_free_load,
    exhaustive_minimum,
    exhaustive_tensionless,
    membrane_force_scale,
    satisfies_kkt,
    satisfies_spring_kkt,
)
from support.families import schema_family
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.errors import EmptyZoneError, NoAdmissibleModeError
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.mesh import build_plate_mesh
from unibuckle_fenicsx.model.plate.model import PlateModel
from unibuckle_fenicsx.model.prestress import solve_prestress
from unibuckle_fenicsx.model.problem import UnilateralProblem
from unibuckle_fenicsx.spec import problem_from_dict

FAMILY_SIZE = 120
SAMPLE = 12
#: The exhaustive references run up to this many constrained nodes (2^12 dense solves).
I_MAX = 12
#: Loads compared to this (SLEPc's eps_tol = 1e-10 and LAPACK: a margin of 1e4; the
#: condensed pencil of the exhaustive search loses a few digits on thin plates).
RTOL = 1e-6
#: Problems whose unproven answer is a KKT point above the exhaustive minimum.
KNOWN_ABOVE: set[str] = set()

serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense reference is serial")
FAMILY = schema_family(FAMILY_SIZE)


def _ids(items):
    return [
        f"{data['name']}-{'-'.join(f.replace(' ', '_') for f in features)}"
        for data, features in items
    ]


def _reference(spec) -> tuple[UnilateralProblem, float | None]:
    """A separately assembled problem, and its exhaustive minimum (None if 2^i is large)."""
    reference = build_problem(spec, MPI.COMM_SELF)
    i = reference.num_constrained
    if i > I_MAX:
        return reference, None
    if spec.tensionless:
        return reference, exhaustive_tensionless(reference)
    best, _, _ = exhaustive_minimum(reference, RTOL)
    return reference, best


def _plate_model(spec) -> SimpleNamespace:
    """The plate's matrices, assembled without the problem's checks (as ``.model``)."""
    msh, tags, plate = build_plate_mesh(spec.plate, spec.mesh, MPI.COMM_SELF, spec.all_obstacles)
    prestress = solve_prestress(msh, tags, plate, spec.material, 1)
    return SimpleNamespace(model=PlateModel(msh, tags, plate, spec.material, prestress))


DESIGN = {"yield_stress": 3.55e8, "partial_factor": 1.0}


def _design_by_hand(data: dict) -> tuple[str, str | None] | str:
    """The family file's EN 1993-1-5 element (kind, free edge), or the refusal's words.

    The family's rectangles carry a uniform state (sxx on left/right, syy on bottom/top)
    with sxx + y-gradient [sxx - 0.5, sxx + 0.5] on left/right; supports at random; no
    in-plane supports, springs or temperatures.
    """
    edges = data["edges"]

    def ends(name):
        value = edges[name].get("normal_stress", 0.0)
        return list(value) if isinstance(value, list) else [value, value]

    if min(min(ends(name)) for name in edges) >= 0.0:
        return "compressive normal edge stress"
    if "corners" not in data["plate"]:
        return "plate.outline"
    along_x = any(any(ends(n)) for n in ("left", "right"))
    if along_x and any(any(ends(n)) for n in ("bottom", "top")):
        return "normal stress in both directions"
    loaded, unloaded = (("left", "right"), ("bottom", "top"))
    if not along_x:
        loaded, unloaded = unloaded, loaded
    free = [n for n in unloaded if edges[n]["support"] == "free"]
    if len(free) == 2:
        return 'are both "free"'
    compression = [-v for v in ends(loaded[0])]  # both loaded edges carry the same
    k = int(compression[1] > compression[0])  # the end of sigma_1 (0 start, 1 end)
    psi = compression[1 - k] / compression[k]
    at_supported = bool(free) and psi != 1.0 and unloaded[k] != free[0]
    if psi < (-1.0 if at_supported else -3.0):
        return "stress ratio psi"
    # EN 1993-1-5 is a steel code: E = 210 GPa (EN 1993-1-1 3.2.6), isotropic.
    if "membrane_voigt" in data["material"]:
        return "material.membrane_voigt gives a general stiffness"
    if data["material"]["E"] != 2.1e11:
        return "is not a steel's"
    return ("outstand", free[0]) if free else ("internal", None)


def test_the_design_element_of_every_family_file():
    """[design] on each file: the element, or the refusal, as worked out by hand."""
    from unibuckle_fenicsx.en1993 import design_element

    seen = set()
    for data, _ in FAMILY:
        expected = _design_by_hand(data)
        with_design = {**data, "design": DESIGN}
        if isinstance(expected, str):
            with pytest.raises(ValueError, match=re.escape(expected)):
                problem_from_dict(with_design)
            seen.add(expected)
            continue
        element = design_element(problem_from_dict(with_design))
        assert (element.kind, element.free_edge) == expected, data["name"]
        seen.add(expected[0])
    # The family draws each case (the refusals' words, and both elements).
    assert seen >= {
        "plate.outline", "normal stress in both directions", "internal", "outstand",
    }, seen  # fmt: skip


def _check_design(data: dict, load: float) -> None:
    """The sample's accepted [design]: rho against eq. (4.2) or (4.3) by hand."""
    expected = _design_by_hand(data)
    if isinstance(expected, str):
        return
    spec = problem_from_dict({**data, "design": DESIGN})
    from unibuckle_fenicsx.design import design_output

    d = design_output(spec, spec.design, load)
    lam = math.sqrt(DESIGN["yield_stress"] / d.sigma_cr_Pa)
    if expected[0] == "internal":
        rho = (lam - 0.055 * (3 + d.psi)) / lam**2
        rho = 1.0 if lam <= 0.5 + math.sqrt(0.085 - 0.055 * d.psi) else min(1.0, rho)
    else:
        rho = 1.0 if lam <= 0.748 else min(1.0, (lam - 0.188) / lam**2)
    # 4.5.4(1) for a/b < 1: rho_c between rho and the column's chi_c (curve a).
    plate, material = spec.plate, spec.material
    a, b = plate.length, plate.width
    if d.edge in ("bottom", "top"):
        a, b = b, a
    column = math.pi**2 * material.E * (plate.thickness / a) ** 2 / (12 * (1 - material.nu**2))
    # The plate as a column between its loaded edges (4.5.3(1)), Euler's columns
    # (Timoshenko and Gere, chapter 2): hinged ends 1, clamped 4 (length a/2), clamped and
    # hinged 2.0457 (tan u = u, u = 4.4934), clamped and free 1/4 (a cantilever, length
    # 2a); a free end with a hinged or free other end is a mechanism: no column buckling
    # stress, xi infinite, rho_c = rho (and no xi in the record).
    loaded = ("left", "right") if d.edge in ("left", "right") else ("bottom", "top")
    kinds = {"free": "free", "clamped": "clamped"}  # the simple supports: hinged
    supports = sorted(kinds.get(data["edges"][n]["support"], "hinged") for n in loaded)
    factor = {
        ("hinged", "hinged"): 1.0,
        ("clamped", "hinged"): (4.493409457909064 / math.pi) ** 2,
        ("clamped", "clamped"): 4.0,
        ("clamped", "free"): 0.25,
    }.get(tuple(supports), 0.0)
    column *= factor
    # The plate with its unloaded edges' supports removed buckles at no higher a stress
    # than the plate (fewer constraints, a smaller Rayleigh quotient): sigma_cr,c <=
    # sigma_cr,p, whatever eq. (4.8) gives (it knows no hole, shear or obstacle).
    column = min(column, d.sigma_cr_Pa)
    assert d.element == expected[0]
    assert d.plate_reduction_factor == pytest.approx(rho, rel=1e-14), data["name"]
    rho_c = rho
    if a < b and factor > 0.0:
        lam_c = math.sqrt(DESIGN["yield_stress"] / column)
        phi = 0.5 * (1 + 0.21 * (lam_c - 0.2) + lam_c**2)
        chi = min(1.0, 1 / (phi + math.sqrt(phi**2 - lam_c**2)))
        xi = min(1.0, max(0.0, d.sigma_cr_Pa / column - 1))
        rho_c = (rho - chi) * xi * (2 - xi) + chi
    assert (d.xi is None) == (a >= b or factor == 0.0), data["name"]
    assert d.reduction_factor == pytest.approx(rho_c, rel=1e-13, abs=1e-15), data["name"]


def _check(data: dict, features: list[str]) -> None:
    spec = problem_from_dict(data)
    where = f"{spec.name} ({', '.join(features)})"
    try:
        analysis = solve(spec, MPI.COMM_SELF)
    except EmptyZoneError as err:  # a zone between the nodes of a coarse mesh: refused
        assert "holds no free mesh node" in str(err), err
        return
    except ValueError as err:
        message = str(err)
        if "gmsh could not mesh" in message:  # refused naming the features and the size
            assert "mesh.size" in message and "plate.holes" in message, message
            return
        if "above max_candidates" in message:  # enumeration refused beyond its limit
            assert spec.solver.method == "enumerate", message
            return
        # No load buckles the plate on this mesh: b(w, w) is round-off against the
        # membrane force t*sigma, or the dense pencil has no positive load.
        assert "no positive buckling load" in message, message
        model = _plate_model(spec)
        if "vanishes" in message:
            scale = membrane_force_scale(spec)
            assert np.abs(dense(model.model.B)).max() <= 1e-10 * scale, where
        else:
            assert not math.isfinite(dense_free_load(model)), where
        model.model.destroy()
        return
    except NoAdmissibleModeError:
        reference, best = _reference(spec)
        reference.destroy()
        assert best is None or not math.isfinite(best), f"{where}: exhaustive {best}"
        return
    with analysis:
        result, cert = analysis.result, analysis.certificate
        assert cert is not None and cert.kkt, (where, cert)
        load = result.critical_load_Pa
        _check_design(data, load)
        x = analysis.mode.x.array.copy()
        active = tuple(int(k) for k in analysis.solution.active)
    assert result.lower_bound_Pa <= load * (1 + RTOL), where
    assert result.free_load_Pa <= load * (1 + RTOL), where
    reference, best = _reference(spec)
    try:
        A, B = dense(reference.model.A), dense(reference.model.B)
        if spec.tensionless:
            assert satisfies_spring_kkt(reference, A, B, x, load), where
        else:
            assert satisfies_kkt(reference, A, B, x, load, active), where
    finally:
        reference.destroy()
    if best is None:
        return
    assert math.isfinite(best), f"{where}: the exhaustive search finds no admissible mode"
    assert result.lower_bound_Pa <= best * (1 + RTOL), (where, result.lower_bound_Pa, best)
    assert load >= best * (1 - RTOL), (where, load, best)
    exact = cert.global_optimum_proven or result.method == "enumerate"
    if exact or spec.name not in KNOWN_ABOVE:
        assert load == pytest.approx(best, rel=RTOL), f"{where}: {load!r} vs exhaustive {best!r}"
    else:
        assert load > best * (1 + RTOL), f"{where}: listed above the minimum, but equals it"


@serial
@pytest.mark.parametrize(("data", "features"), FAMILY[:SAMPLE], ids=_ids(FAMILY[:SAMPLE]))
def test_schema_sample(data, features):
    """The first problems of the family (default run)."""
    _check(data, features)


@serial
@pytest.mark.stress
@pytest.mark.parametrize(("data", "features"), FAMILY[SAMPLE:], ids=_ids(FAMILY[SAMPLE:]))
def test_schema_family(data, features):
    """The rest of the family (``-m stress``)."""
    _check(data, features)


def test_the_family_covers_the_schema():
    """Every feature is drawn, in the sample and in the whole family."""
    wanted = (
        "gradient", "uniform", "outline trapezoid", "outline L", "outline house",
        "hole(s)", "anisotropic", "isotropic", "box above", "box below", "polygon",
        "circle", "all", "tensionless", "bilateral", "auto", "active-set", "enumerate",
    )  # fmt: skip
    for items, required in ((FAMILY, wanted), (FAMILY[:SAMPLE], ("uniform", "box", "auto"))):
        drawn = " | ".join(" | ".join(features) for _, features in items)
        missing = [w for w in required if w not in drawn]
        assert not missing, missing
    supports = {table.get("support") for data, _ in FAMILY for table in data["edges"].values()}
    assert {"simply_supported", "simply_supported_soft", "clamped", "free"} <= supports
    assert any("size" in data["mesh"] for data, _ in FAMILY)
    assert any("nx" in data["mesh"] for data, _ in FAMILY)
    assert np.mean([len(f) for _, f in FAMILY]) > 4
