"""A section's method: chosen where a plate's is, named in its file or on the command line.

``registry.choose_section_method`` decides it before any mesh, by the documented rule
(``docs/verification/sections.md``, "Cost"): without a core the free load, with an
elastic core the spring-set iteration, with a rigid core the ``[solver] method`` given,
"auto" taking the interior point on sections of at least ``INTERIOR_POINT_DOFS`` = 10^4
DOFs, checked by the active set's seeds on its coarsest section, and both routes on
smaller ones, the lower KKT point kept. The expected DOFs are
worked out here by hand: a box of square faces b on uniform cells h has 4 b/h nodes
around, L/h + 1 along and six DOFs per node (the demo's box: 6 x 32 x 25 = 4 800; the
box b/16 of the Cost table: 6 x 64 x 49 = 18 816). A method given in a file runs that
route: its load is the one ``solve_levels`` gives with that route.
"""

from __future__ import annotations

import json

from mpi4py import MPI

import pytest

import unibuckle_fenicsx.algorithms.registry as registry
from unibuckle_fenicsx import SectionParameters, section_from_dict, solve_section
from unibuckle_fenicsx.algorithms.registry import choose_section_method
from unibuckle_fenicsx.algorithms.section_levels import solve_levels
from unibuckle_fenicsx.cli import EXIT_BAD_INPUT, EXIT_OK, main
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.model.shell.section import section_parameters
from unibuckle_fenicsx.spec import SolverSpec

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial sections")

E, NU = 2.1e11, 0.3
REFUSED = 'solver.method must be one of "auto", "interior-point", "active-set" for a section'


def _square_box(b, length, h, **changes):
    """A square box of faces ``b`` on cells ``h``: 6 (4 b/h) (L/h + 1) DOFs."""
    base = {
        "width": b, "depth": b, "thickness": 0.002, "length": length, "E": E, "nu": NU,
        "mesh_size": h, "ends": "simply_supported", "core": True,
    }  # fmt: skip
    return SectionParameters("box", **{**base, **changes})


def _dofs(b, length, h):
    return 6 * round(4 * b / h) * (round(length / h) + 1)


def test_auto_takes_the_checked_interior_point_from_ten_thousand_dofs():
    small, large = _square_box(0.1, 0.3, 0.0125), _square_box(0.2, 0.6, 0.0125)
    assert (_dofs(0.1, 0.3, 0.0125), _dofs(0.2, 0.6, 0.0125)) == (4800, 18816)
    auto = SolverSpec()
    assert choose_section_method(small, auto) == (
        "both",
        "auto: about 4800 DOFs (estimated before meshing) < INTERIOR_POINT_DOFS = 10000: "
        "the interior point and the active set, the lower KKT point kept",
    )
    assert choose_section_method(large, auto) == (
        "interior-point+seeds",
        "auto: about 18816 DOFs (estimated before meshing) >= INTERIOR_POINT_DOFS = 10000: "
        "the interior point, checked by the active set's seeds on its coarsest section, "
        "the lower KKT point kept",
    )


def test_auto_counts_a_section_of_exactly_the_threshold_as_large(monkeypatch):
    # "at least INTERIOR_POINT_DOFS": a threshold equal to the section's DOFs.
    monkeypatch.setattr(registry, "INTERIOR_POINT_DOFS", 4800)
    method, _ = choose_section_method(_square_box(0.1, 0.3, 0.0125), SolverSpec())
    assert method == "interior-point+seeds"


def test_a_given_method_runs_whatever_the_size():
    small, large = _square_box(0.1, 0.3, 0.0125), _square_box(0.2, 0.6, 0.0125)
    given = SolverSpec(method="interior-point")
    assert choose_section_method(small, given) == ("interior-point", "given")
    assert choose_section_method(large, SolverSpec(method="active-set")) == ("active-set", "given")


def test_no_core_and_an_elastic_core_run_their_own():
    hollow = _square_box(0.1, 0.3, 0.0125, core=False)
    assert choose_section_method(hollow, SolverSpec()) == ("free", "no core")
    elastic = _square_box(0.1, 0.3, 0.0125, foundation_stiffness=1e9)
    assert choose_section_method(elastic, SolverSpec()) == (
        "foundation",
        "elastic core: spring-set iteration",
    )


@pytest.mark.parametrize("method", ["enumerate", "penalty"])
def test_a_plate_only_method_is_refused_naming_the_key(method):
    with pytest.raises(InputError, match=f"{REFUSED}, got '{method}'"):
        choose_section_method(_square_box(0.1, 0.3, 0.0125), SolverSpec(method=method))
    with pytest.raises(InputError, match=REFUSED):
        solve_section(_square_box(0.1, 0.3, 0.0125), solver=SolverSpec(method=method))


#: A small square box with a core (b = 0.1 m, 25 mm cells: 6 x 16 x 9 = 864 DOFs).
FILE = {
    "section": {"shape": "box", "width": 0.1, "depth": 0.1, "thickness": 0.002,
                "length": 0.2, "ends": "simply_supported"},
    "material": {"E": E, "nu": NU},
    "obstacle": {"core": True},
    "mesh": {"size": 0.025, "levels": 1},
}  # fmt: skip


@pytest.mark.parametrize("method", ["interior-point", "active-set"])
def test_a_files_method_runs_that_route(method):
    spec = section_from_dict({**FILE, "solver": {"method": method}})
    with solve_section(spec, MPI.COMM_SELF) as solved:
        result = solved.result
    assert result.method == f"{method} (section levels)"
    assert result.method_chosen_by == "given"
    finest, solution = solve_levels(
        section_parameters(spec), levels=1, comm=MPI.COMM_SELF, route=method
    )
    with finest:
        assert result.critical_load_Pa == pytest.approx(solution.load, rel=1e-12)


def test_the_command_lines_method_reaches_a_section(tmp_path, capsys):
    path = tmp_path / "box.json"  # a problem file in JSON
    path.write_text(json.dumps(FILE))
    out = tmp_path / "result.json"
    args = ["solve", "--config", str(path), "--json", str(out)]
    assert main(args) == EXIT_OK
    auto = json.loads(out.read_text())
    assert auto["method"] in ("active-set (section levels)", "interior-point (section levels)")
    assert auto["method_chosen_by"].startswith("auto: about 864 DOFs")
    assert main([*args, "--method", "interior-point"]) == EXIT_OK
    given = json.loads(out.read_text())
    assert given["method"] == "interior-point (section levels)"
    assert given["method_chosen_by"] == "given"
    assert given["route"][0] == "interior-point"
    capsys.readouterr()
    assert main([*args, "--method", "penalty"]) == EXIT_BAD_INPUT
    assert REFUSED in capsys.readouterr().err


def _rayleigh_quotient(model, vec) -> float:
    """u'Au/u'Bu of ``vec`` on the model's assembled A and B (scipy copies of them)."""
    import scipy.sparse as sp

    def dense(mat):
        indptr, indices, values = mat.getValuesCSR()
        return sp.csr_matrix((values, indices, indptr), shape=mat.getSize())

    A, B = dense(model.A), dense(model.B)
    curvature = vec @ (B @ vec)
    assert curvature > 0.0
    return float(vec @ (A @ vec) / curvature)


def _admissible_rayleigh_quotient(analysis) -> tuple[float, float]:
    """An upper bound on the filled section's critical load from its mode, by hand.

    The unilateral critical load is the least u'Au/u'Bu over the displacements whose
    walls move only away from the core (u'Bu > 0). The mode (global components, the
    model's A and B with the supports) is made admissible by removing the inward part
    of each wall node's translation, n·u with n = -(0, y, z)/R toward the tube's axis,
    wherever it is positive; its Rayleigh quotient, products of sparse matrices with
    that vector, is then an upper bound whatever the algorithm that produced the mode.
    Returns the quotient and the largest inward part removed (relative to max |u|).
    """
    import numpy as np

    model = analysis.section.model
    u = analysis.mode.x.array.copy().reshape(-1, 6)
    X = model.W.tabulate_dof_coordinates()
    radius = np.hypot(X[:, 1], X[:, 2])
    inward = -np.stack([np.zeros_like(radius), X[:, 1], X[:, 2]], axis=1) / radius[:, None]
    along = np.einsum("ij,ij->i", u[:, :3], inward)
    removed = float(np.max(along, initial=0.0)) / float(np.abs(u[:, :3]).max())
    u[:, :3] -= np.maximum(along, 0.0)[:, None] * inward
    assert np.einsum("ij,ij->i", u[:, :3], inward).max() <= 1e-14
    return _rayleigh_quotient(model, u.ravel()), removed


def test_the_active_set_route_ends_no_higher_than_an_admissible_mode():
    """The default route of a small filled section is not above an admissible mode.

    A tube D = 0.1 m, t = 2 mm (R/t = 25), L = 70 mm between clamped ends, pure bending,
    6.5 mm cells (52 facets, 11 cells along: no coarse-cell warning), 3 600 DOFs: "auto"
    takes the active set, its seeds on a section of 13 mm cells and the contact set
    carried here. That carried set polished to a KKT point at 8.1349e9 Pa, and the route
    kept it, while the seeds on the given section reach 7.9998e9 Pa (1.7 % lower; on a
    tube R/t = 20 in bending between simply supported ends, 13.7 %). The reference is
    independent of either route: the mode of the seeds' run, made admissible by hand,
    and its Rayleigh quotient on the assembled matrices (_admissible_rayleigh_quotient),
    an upper bound on the critical load. The default route now lands at or below it.
    """
    tube = SectionParameters(
        "tube", diameter=0.1, thickness=0.002, length=0.07, E=E, nu=NU, mesh_size=0.0065,
        ends="clamped", axial_stress=0.0, bending_stress=-1.0, core=True,
    )  # fmt: skip
    with solve_section(tube, MPI.COMM_SELF, levels=0) as seeded:
        bound, removed = _admissible_rayleigh_quotient(seeded)
        assert seeded.result.certificate.kkt
        assert removed < 1e-6  # the mode was admissible to the tolerance already
        assert bound == pytest.approx(seeded.result.critical_load_Pa, rel=1e-6)
    assert bound == pytest.approx(7.9998e9, rel=1e-4)
    with solve_section(tube, MPI.COMM_SELF) as solved:  # "auto": the active set, levels 1
        result = solved.result
        assert result.method_chosen_by.startswith("auto")
        assert result.certificate.kkt
        assert result.critical_load_Pa <= bound * (1.0 + 1e-7)


def test_auto_on_a_small_section_ends_no_higher_than_the_interior_point():
    """The default method below 10^4 DOFs is not above the interior point's admissible mode.

    A tube D = 0.1 m, t = 2.5 mm (R/t = 20), L = 50 mm between clamped ends, pure
    bending, 8 mm cells (1 920 DOFs). "auto" took the active set alone below
    INTERIOR_POINT_DOFS, which ended at a KKT point at 1.1016e10 Pa, where the interior
    point reaches 1.0831e10 Pa (1.7 % lower; on the same tube L = 0.1 m on 5 mm cells,
    8 064 DOFs, 0.26 %). The reference is independent of either route: the interior
    point's mode made admissible by hand and its Rayleigh quotient on the assembled
    matrices (_admissible_rayleigh_quotient), an upper bound on the critical load.
    """
    tube = SectionParameters(
        "tube", diameter=0.1, thickness=0.0025, length=0.05, E=E, nu=NU, mesh_size=0.008,
        ends="clamped", axial_stress=0.0, bending_stress=-1.0, core=True,
    )  # fmt: skip
    given = SolverSpec(method="interior-point")
    with solve_section(tube, MPI.COMM_SELF, solver=given) as interior:
        bound, removed = _admissible_rayleigh_quotient(interior)
        assert interior.result.certificate.kkt
        assert removed < 1e-6  # the mode was admissible to the tolerance already
    assert bound == pytest.approx(1.0831e10, rel=1e-4)
    with solve_section(tube, MPI.COMM_SELF) as solved:  # "auto"
        result = solved.result
        assert result.dofs == 1920
        assert result.method_chosen_by.startswith("auto: about 1920 DOFs")
        assert result.certificate.kkt
        assert result.critical_load_Pa <= bound * (1.0 + 1e-7)


def _solver_counters(monkeypatch):
    """The eigen solves of every section the route builds, read before the certificate.

    The reference is the eigen solvers' own counters, read on every section the route
    built (the coarser ones when they are destroyed, the finest when the certificate
    starts). Returns the sections built and the list the sum is appended to.
    """
    import unibuckle_fenicsx.algorithms.section_levels as levels
    import unibuckle_fenicsx.section_analysis as section_analysis

    counted: dict[int, int] = {}
    built: list = []
    before_certificate: list[int] = []
    build, certify = levels.build_section, section_analysis.certify

    def read(section):
        if id(section) in counted:
            return counted[id(section)]
        return section.problem.eigensolver.solves

    def recorded_build(*args, **kwargs):
        section = build(*args, **kwargs)
        built.append(section)
        destroy = section.destroy

        def destroy_counted():
            if id(section) not in counted:  # the first destroy: its objects still there
                counted[id(section)] = section.problem.eigensolver.solves
            destroy()

        section.destroy = destroy_counted
        return section

    def recorded_certify(*args, **kwargs):
        before_certificate.append(sum(read(section) for section in built))
        return certify(*args, **kwargs)

    monkeypatch.setattr(levels, "build_section", recorded_build)
    monkeypatch.setattr(section_analysis, "certify", recorded_certify)
    return built, before_certificate


@pytest.mark.parametrize("method", ["active-set", "interior-point", "auto"])
def test_a_sections_eigensolves_count_every_solve_of_the_route(method, monkeypatch):
    """``eigensolves`` is every eigen solve on every section the route built.

    The reference is the eigen solvers' own counters (:func:`_solver_counters`). The
    active set counted only its kept run on the given section (47 of the 77 on the box
    of FILE), the interior point its finest section's free solve twice.
    """
    built, before_certificate = _solver_counters(monkeypatch)
    spec = section_from_dict({**FILE, "solver": {"method": method}})
    with solve_section(spec, MPI.COMM_SELF) as solved:
        result = solved.result
    assert len(built) == 2 and len(before_certificate) == 1
    assert result.eigensolves == before_certificate[0]


@pytest.mark.parametrize("method", ["active-set", "auto"])
def test_a_sections_eigensolves_count_the_penalty_continuations(method, monkeypatch):
    """A stalled seed's penalty continuation counts: it has its own eigen solver.

    The seeds' first fallback check is made to fail, so that the penalty continuation
    runs on the coarser section (a stall needs a larger section: the 10 mm tube of the
    sections' verification pages stalls on its 20 mm section). The reference is the
    eigen solvers' own counters on every section plus the solves each continuation
    returned; the starting code left the latter out.
    """
    import unibuckle_fenicsx.algorithms.active_set as active_set

    _, before_certificate = _solver_counters(monkeypatch)
    penalty: list[int] = []
    reached, continuation = active_set.reached_kkt, active_set.penalty_continuation

    def stalled_once(problem, runs):
        return reached(problem, runs) if penalty else False

    def recorded_continuation(*args, **kwargs):
        run, solves = continuation(*args, **kwargs)
        penalty.append(solves)
        return run, solves

    monkeypatch.setattr(active_set, "reached_kkt", stalled_once)
    monkeypatch.setattr(active_set, "penalty_continuation", recorded_continuation)
    spec = section_from_dict({**FILE, "solver": {"method": method}})
    with solve_section(spec, MPI.COMM_SELF) as solved:
        result = solved.result
    assert len(penalty) == 1 and penalty[0] > 0
    assert result.eigensolves == before_certificate[0] + penalty[0]


@pytest.mark.parametrize("method", ["interior-point", "active-set"])
@pytest.mark.parametrize(
    ("changes", "which"),
    [({"core": False}, "without a core"), ({"foundation_stiffness": 1e9}, "an elastic core")],
)
def test_a_rigid_cores_method_without_one_is_refused_naming_the_key(
    method, changes, which, tmp_path, capsys
):
    # A hollow section has one route (its free solve), an elastic core one (the
    # spring-set iteration): a route named for them would be ignored, so it is refused
    # before any mesh, in the API, in a file and on the command line (exit status 2).
    box = _square_box(0.1, 0.3, 0.0125, **changes)
    refused = f"solver.method = '{method}' chooses a rigid core's route; .*{which}"
    with pytest.raises(InputError, match=refused):
        choose_section_method(box, SolverSpec(method=method))
    with pytest.raises(InputError, match=refused):
        solve_section(box, solver=SolverSpec(method=method))
    obstacle = {"core": True, "foundation_stiffness": 1e9} if changes.get("core", True) else {}
    file = {**FILE, "obstacle": obstacle}
    with pytest.raises(InputError, match=refused):
        section_from_dict({**file, "solver": {"method": method}})
    path = tmp_path / "box.json"
    path.write_text(json.dumps(file))
    capsys.readouterr()
    assert main(["solve", "--config", str(path), "--method", method]) == EXIT_BAD_INPUT
    assert "solver.method" in capsys.readouterr().err
    # "auto" (the default) stays accepted.
    assert choose_section_method(box, SolverSpec())[0] in ("free", "foundation")


def _box_admissible_rayleigh_quotient(analysis, width, depth, span=None) -> tuple[float, float]:
    """The box's :func:`_admissible_rayleigh_quotient`: each face's inward part removed.

    ``span``: the core's (x from, x to); None: the whole length.

    A wall node on the face y = +b/2 may only move to +y, on y = -b/2 to -y, and so on
    for z (a corner node both ways): the translation's component into the core is set
    to zero wherever it points inward, and the Rayleigh quotient of the result on the
    assembled A and B is an upper bound on the critical load.
    """
    import numpy as np

    model = analysis.section.model
    u = analysis.mode.x.array.copy().reshape(-1, 6)
    X = model.W.tabulate_dof_coordinates()
    scale = float(np.abs(u[:, :3]).max())
    removed = 0.0
    for axis, half in ((1, 0.5 * width), (2, 0.5 * depth)):
        for side in (1.0, -1.0):
            on = np.abs(X[:, axis] - side * half) < 1e-9
            if span is not None:
                on &= (X[:, 0] > span[0] - 1e-9) & (X[:, 0] < span[1] + 1e-9)
            inward = np.maximum(-side * u[on, axis], 0.0)
            removed = max(removed, float(inward.max(initial=0.0)) / scale)
            u[on, axis] += side * inward
    return _rayleigh_quotient(model, u.ravel()), removed


#: A small clamped square box with a core (b = 0.1 m, t = 2 mm, L = 0.2 m, 25 mm
#: cells: 6 x 16 x 9 = 864 DOFs).
CLAMPED_BOX = {"ends": "clamped"}


def test_auto_on_a_large_section_ends_no_higher_than_the_active_sets_mode(monkeypatch):
    """The default method from 10^4 DOFs is not above the active set's admissible mode.

    At INTERIOR_POINT_DOFS and more "auto" ran the interior point alone. Its starts can
    settle in a higher arrangement than the active set's seeds: on the clamped box
    b = d = 0.1 m, t = 2 mm, L = 0.2 m on 6.25 mm cells (12 672 DOFs, ``levels = 1``)
    it ended at 7.1143e8 Pa, the active set at 7.1060e8 Pa (1.2e-3 lower;
    ``test_auto_on_a_clamped_box_of_twelve_thousand_dofs``). The same happens on the
    small box on 25 mm cells solved on its own cells (``levels = 0``): 8.9768e8 against
    8.9575e8 Pa; the threshold is lowered here so that "auto" takes its large-section
    route on it. The reference is independent of the interior point: the active set's
    mode made admissible by hand and its Rayleigh quotient on the assembled matrices
    (_box_admissible_rayleigh_quotient), an upper bound on the critical load.
    """
    box = _square_box(0.1, 0.2, 0.025, **CLAMPED_BOX)
    given = SolverSpec(method="active-set")
    with solve_section(box, MPI.COMM_SELF, levels=0, solver=given) as seeded:
        bound, removed = _box_admissible_rayleigh_quotient(seeded, 0.1, 0.1)
        assert seeded.result.certificate.kkt
        assert removed < 1e-6  # the mode was admissible to the tolerance already
        assert seeded.result.dofs == 864
    assert bound == pytest.approx(8.9575e8, rel=1e-4)
    monkeypatch.setattr(registry, "INTERIOR_POINT_DOFS", 500)
    with solve_section(box, MPI.COMM_SELF, levels=0) as solved:  # "auto"
        result = solved.result
        assert result.method_chosen_by.startswith("auto: about 864 DOFs")
        assert result.certificate.kkt
        assert result.critical_load_Pa <= bound * (1.0 + 1e-7)


@pytest.mark.slow
def test_auto_on_a_clamped_box_of_twelve_thousand_dofs():
    """The section of the defect: "auto" at 12 672 DOFs ends no higher than the active set.

    The clamped box b = d = 0.1 m, t = 2 mm, L = 0.2 m on 6.25 mm cells, ``levels = 1``:
    the interior point alone ended at 7.1143e8 Pa, 1.2e-3 above the active set's
    7.1060e8 Pa. The reference: the active set's mode made admissible by hand, its
    Rayleigh quotient (an upper bound on the critical load).
    """
    box = _square_box(0.1, 0.2, 0.00625, **CLAMPED_BOX)
    given = SolverSpec(method="active-set")
    with solve_section(box, MPI.COMM_SELF, solver=given) as seeded:
        bound, removed = _box_admissible_rayleigh_quotient(seeded, 0.1, 0.1)
        assert seeded.result.certificate.kkt and removed < 1e-6
    assert bound == pytest.approx(7.1060e8, rel=1e-4)
    with solve_section(box, MPI.COMM_SELF) as solved:  # "auto"
        result = solved.result
        assert result.method_chosen_by.startswith("auto: about 12672 DOFs")
        assert result.certificate.kkt
        assert result.critical_load_Pa <= bound * (1.0 + 1e-7)


#: A rectangular filled box, b = 0.2 m, d = 0.1 m, t = 2 mm, L = 0.3 m between simply
#: supported ends, 25 mm cells: 6 x 24 x 13 = 1 872 DOFs, "auto" runs both routes from
#: a coarser section of 6 x 12 x 7 = 504 DOFs (levels = 1).
RECTANGULAR_BOX = {
    "width": 0.2, "depth": 0.1, "thickness": 0.002, "length": 0.3, "E": E, "nu": NU,
    "mesh_size": 0.025, "ends": "simply_supported", "core": True,
}  # fmt: skip


@pytest.fixture(scope="module")
def rectangular_box_bound() -> float:
    """The interior point's mode on the box's own cells, made admissible: an upper bound.

    ``levels = 0``: the starts run on the given section and reach a KKT point at
    1.500221e8 Pa; its mode made admissible by hand and its Rayleigh quotient on the
    assembled matrices (_box_admissible_rayleigh_quotient) bound the critical load
    from above, whatever the route that produced the mode.
    """
    box = SectionParameters("box", **RECTANGULAR_BOX)
    given = SolverSpec(method="interior-point")
    with solve_section(box, MPI.COMM_SELF, levels=0, solver=given) as interior:
        bound, removed = _box_admissible_rayleigh_quotient(interior, 0.2, 0.1)
        assert interior.result.certificate.kkt
        assert removed < 1e-6  # the mode was admissible to the tolerance already
    return bound


def test_auto_on_a_rectangular_box_ends_no_higher_than_the_starts_on_its_cells(
    rectangular_box_bound,
):
    """The default route's coarser section of fewer than COARSEST_DOFS is not trusted alone.

    With ``levels = 1`` the interior point started on 50 mm cells (2 across the 0.1 m
    face, about 500 DOFs): its starts met one arrangement there, carried up to a KKT
    point at 1.506630e8 Pa, where the active set's seeds ended too; the starts on the
    given cells reach 1.500221e8 Pa (0.43 % lower). The reference is the admissible
    mode's Rayleigh quotient of the fixture (an upper bound on the critical load).
    """
    assert rectangular_box_bound == pytest.approx(1.500221e8, rel=1e-5)
    box = SectionParameters("box", **RECTANGULAR_BOX)
    with solve_section(box, MPI.COMM_SELF) as solved:  # "auto", levels 1
        result = solved.result
        assert result.method_chosen_by.startswith("auto: about 1872 DOFs")
        assert result.certificate.kkt
        assert result.critical_load_Pa <= rectangular_box_bound * (1.0 + 1e-7)


@pytest.mark.parametrize("stiffness", [8e10, 6e11, 1e13])
def test_an_elastic_core_ends_no_higher_than_the_rigid_cores_admissible_mode(
    stiffness, rectangular_box_bound
):
    """A foundation's critical load is at most the rigid core's (its quotient's springs).

    The spring quotient of a mode that presses no spring is its Rayleigh quotient, so
    the rigid core's admissible mode bounds every elastic core's critical load from
    above (the fixture's bound). The spring-set iteration's start from the rigid core's
    contact set took the active set's KKT point on the elastic core's problem, 1.506630e8
    Pa, and the core of 6e11 N/m^3 ended at 1.505791e8 Pa, of 1e13 at 1.506577e8 Pa:
    above the bound. It now takes the rigid core's route. The core of 8e10 N/m^3
    (kappa = 940, springs' energy over bending energy on the free mode) took no rigid
    start (only above kappa = 1e3): its other starts ended at 1.501033e8 Pa, above the
    bound and above the stiffer 1e11 N/m^3's 1.497063e8; every core now takes it.
    """
    box = SectionParameters("box", **RECTANGULAR_BOX, foundation_stiffness=stiffness)
    with solve_section(box, MPI.COMM_SELF) as solved:
        result = solved.result
        assert result.method == "foundation"
        assert result.free_load_Pa <= result.critical_load_Pa
        assert result.critical_load_Pa <= rectangular_box_bound * (1.0 + 1e-7)


@pytest.mark.parametrize(
    ("b", "length", "span"),
    [
        (0.1, 0.2, (0.11, 0.14)),
        # slow: the same property on the box b = 0.1 m, L = 0.2 m is the case above.
        pytest.param(0.2, 0.6, (0.31, 0.34), marks=pytest.mark.slow),
    ],
)
def test_an_elastic_core_whose_coarser_section_holds_no_core_node_is_solved(b, length, span):
    """The elastic core's rigid start drops the levels a rigid core would refuse.

    The box b = d = 0.2 m, L = 0.6 m on 25 mm cells with a core over 0.31..0.34 m holds
    core nodes at 0.325 m, none on 50 mm cells: a rigid core with ``levels = 1`` is
    refused naming mesh.levels. The elastic core asks no levels; its start from the
    rigid core's set runs on the given section. The bound is the rigid core's
    ``levels = 0`` mode made admissible by hand, its Rayleigh quotient (a foundation's
    load is at most it: the mode presses no spring). The same on the box b = d = 0.1 m,
    L = 0.2 m, a core over 0.11..0.14 m: its node at 0.125 m, none on 50 mm cells.
    """
    rigid = _square_box(b, length, 0.025, core_span=span)
    with solve_section(rigid, MPI.COMM_SELF, levels=0) as solved:
        bound, removed = _box_admissible_rayleigh_quotient(solved, b, b, span)
        assert solved.result.certificate.kkt and removed < 1e-6
    elastic = _square_box(b, length, 0.025, core_span=span, foundation_stiffness=1e15)
    with solve_section(elastic, MPI.COMM_SELF) as solved:  # levels 1
        result = solved.result
        assert result.method == "foundation"
        assert result.free_load_Pa <= result.critical_load_Pa <= bound * (1.0 + 1e-7)


def test_an_elastic_core_whose_starts_all_end_high_takes_the_rigid_mode(
    rectangular_box_bound, monkeypatch
):
    """The rigid core's mode is a candidate itself: the answer is at most its load.

    Its spring quotient is its load (it presses no spring), and the arc descent from it
    never rises. Here the start from the rigid core's contact set is made the free
    start (the other starts of the 8e10 N/m^3 core end at 1.501033e8 Pa, above the
    bound): only the rigid mode keeps the answer at or below the fixture's bound, the
    rigid core's admissible mode's Rayleigh quotient.
    """
    from unibuckle_fenicsx.algorithms import foundation

    original = foundation.run_from_start

    def no_rigid_start(solver, name, start, lower, max_iterations):
        if name == "rigid":
            start = start[:0]  # the free start's empty set
        return original(solver, name, start, lower, max_iterations)

    monkeypatch.setattr(foundation, "run_from_start", no_rigid_start)
    box = SectionParameters("box", **RECTANGULAR_BOX, foundation_stiffness=8e10)
    with solve_section(box, MPI.COMM_SELF) as solved:
        result, details = solved.result, solved.solution.details
    assert details.foundation_start == foundation.RIGID_MODE
    assert details.foundation_loads["free"] > rectangular_box_bound
    assert result.free_load_Pa <= result.critical_load_Pa
    assert result.critical_load_Pa <= rectangular_box_bound * (1.0 + 1e-7)
