"""The Python entry point for sections: ``unibuckle_fenicsx.solve_section``.

The loads themselves are checked elsewhere (``tests/unit/model/test_shell_core.py``: the
active set against a dense enumeration of every contact set on this same small box;
``tests/verification/test_shell_convergence.py``: the classical anchors). Here the record:
each field against its definition worked out by hand (k = sigma t b^2/(pi^2 D) with the widest face,
the classical stresses 4 pi^2 D/(t b^2) and E t/(R sqrt(3(1 - nu^2)))), interlacing
(the core never lowers the load), the certificate's bracket, the sign of the core's push
(a rigid core pushes, never pulls: KKT), and bad input refused before any mesh.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math
import re

from mpi4py import MPI

import pytest

import unibuckle_fenicsx
from support.paths import ROOT
from unibuckle_fenicsx import SectionParameters, solve_section
from unibuckle_fenicsx.errors import InputError

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial sections")

E, NU, T = 2.1e11, 0.3, 0.002
D = E * T**3 / (12.0 * (1.0 - NU**2))


def _tube(**changes):
    base = {"diameter": 0.2, "thickness": T, "length": 0.2, "E": E, "nu": NU, "mesh_size": 0.02}
    return SectionParameters("tube", **{**base, **changes})


def _box(**changes):
    base = {
        "width": 0.2, "depth": 0.1, "thickness": T, "length": 0.2, "E": E, "nu": NU,
        "mesh_size": 0.1, "ends": "simply_supported", "core": True,
    }  # fmt: skip
    return SectionParameters("box", **{**base, **changes})


def test_box_with_a_core_gives_the_plate_record():
    # 40 mm cells: 4 across the 0.1 m faces (the fewest a core is solved on), 6 across the
    # 0.2 m ones, 5 along 0.2 m.
    with solve_section(_box(mesh_size=0.04), MPI.COMM_SELF, levels=0) as analysis:
        r = analysis.result
        assert isinstance(r, unibuckle_fenicsx.results.records.BucklingResult)
        load = r.critical_load_Pa
        # The widest face is the width, 0.2 m (the depth is 0.1 m).
        assert r.buckling_coefficient_k == pytest.approx(T * load * 0.2**2 / (math.pi**2 * D))
        assert r.classical_stress_Pa == pytest.approx(4.0 * math.pi**2 * D / (T * 0.2**2))
        assert r.critical_force_N_per_m == pytest.approx(T * load)
        assert r.free_load_Pa <= load and r.ratio_to_free == pytest.approx(load / r.free_load_Pa)
        cert = r.certificate
        assert cert is not None and cert.kkt
        assert r.lower_bound_Pa <= load * (1 + 1e-9)
        assert r.upper_bound_Pa is None or load <= r.upper_bound_Pa * (1 + 1e-9)
        # By hand: 20 nodes around (4 + 6 + 4 + 6 cells), the 4 corners with 2 directions
        # each: 24 directions at each of the 4 stations between the supported ends.
        assert r.constrained_nodes == 96 and 0 < r.contact_nodes == len(r.contact_coordinates)
        assert r.contact_force is not None
        push = r.contact_force.push
        assert len(push) == r.contact_nodes
        assert r.contact_force.resolution is not None
        assert min(push) >= -r.contact_force.resolution
        data = json.loads(json.dumps(r.as_dict()))
        assert data["input"]["section"]["shape"] == "box" and data["input"]["section"]["core"]
        assert "x hollow" in r.summary() and "KKT = yes" in r.summary()
        # The 3-D figure's arrays come with it: the contact set drawn on the walls.
        fig = analysis.figure_data()
        assert len(fig.pressing) + len(fig.touching) == r.contact_nodes
        assert analysis.mode.x.array.size == r.dofs


def test_tube_without_a_core_is_its_free_load():
    params = SectionParameters(
        "tube", diameter=0.2, thickness=T, length=0.1, E=E, nu=NU, mesh_size=0.05,
        ends="simply_supported",
    )  # fmt: skip
    with solve_section(params, MPI.COMM_SELF) as analysis:
        r = analysis.result
        assert r.method == "free" and r.certificate is None and analysis.solution is None
        assert r.critical_load_Pa == r.free_load_Pa == r.lower_bound_Pa == r.upper_bound_Pa
        assert r.buckling_coefficient_k is None
        assert r.classical_stress_Pa == pytest.approx(E * T / (0.1 * math.sqrt(3 * (1 - NU**2))))
        assert r.constrained_nodes == 0 and r.contact_force is None


@pytest.mark.parametrize(
    ("call", "error", "words"),
    [
        (lambda: solve_section({"shape": "box"}), TypeError, "SectionParameters"),
        (lambda: solve_section(_box(), levels=-1), InputError, "levels"),
        (lambda: solve_section(_box(), levels=1.5), InputError, "levels"),
        (lambda: _box(diameter=0.2), InputError, "section.diameter"),
        (lambda: _box(core=False, core_span=(0.0, 0.1)), InputError, "core_span"),
        (lambda: _box(thickness=0.05), InputError, "section.thickness"),
        # corner_cell grades a box's faces: a tube has no corners, and cells no finer
        # than mesh_size at the corners are the uniform mesh (either would be ignored).
        (
            lambda: _tube(corner_cell=0.005),
            InputError,
            "corner_cell = 0.005 grades a box's faces at its corners; a tube has no corners",
        ),
        (lambda: _box(corner_cell=0.1), InputError, r"corner_cell = 0.1 m must be < mesh_size"),
        # corner_cell is SectionParameters' argument alone, no file key: a message naming
        # section.corner_cell sent the reader to a [section] key that does not exist.
        *(
            (
                lambda v=v: _box(corner_cell=v),
                InputError,
                r"^corner_cell \(an argument of SectionParameters, not a file key\) must be a "
                rf"finite number > 0 \(m\), got {re.escape(repr(v))}$",
            )
            for v in (-0.01, 0.0, math.nan)
        ),
    ],
)
def test_bad_section_input_is_refused_before_any_mesh(call, error, words):
    with pytest.raises(error, match=words):
        call()


@pytest.mark.parametrize(
    ("changes", "cells"),
    [
        ({}, 2),  # the 0.1 m depth on 0.1 m cells: ceil(1) = 1, at least 2
        ({"mesh_size": 0.05}, 2),  # ceil(2) = 2 across the depth (4 across the width)
        ({"mesh_size": 0.05, "foundation_stiffness": 1e12}, 2),  # an elastic core too
    ],
)
def test_a_core_on_a_box_face_of_too_few_cells_is_refused_before_any_mesh(
    monkeypatch, changes, cells
):
    """solve_section refuses a core on a face of 2 cells, naming mesh.size and its range.

    The box 0.2 x 0.1 m: its narrowest face 0.1 m needs 4 cells with a core, mesh.size
    below 0.05 m (a face's cells are ceil(width/mesh.size) made even).
    """

    def no_mesh(*args, **kwargs):
        raise AssertionError("a mesh was built")

    monkeypatch.setattr("unibuckle_fenicsx.model.shell.section.section_mesh", no_mesh)
    box = _box(**changes)
    size = box.mesh_size
    with pytest.raises(InputError) as caught:
        solve_section(box, MPI.COMM_SELF, levels=0)
    text = str(caught.value)
    assert text.startswith(
        f"mesh.size = {size:g} m gives {cells} cells across the box's narrowest face (0.1 m)"
    ), text
    assert "mesh.size must be < 0.05 m here" in text
    # The hollow box on these cells is solved (its coarse cells only warned of).
    with pytest.raises(AssertionError, match="a mesh was built"):
        solve_section(dataclasses.replace(box, core=False, foundation_stiffness=None))


def test_the_check_counts_a_box_s_cells_as_its_mesh_does():
    """The refusal's count is the mesh's: the box's nodes around from the same helper."""
    from unibuckle_fenicsx.model.shell.geometry import grid_nodes
    from unibuckle_fenicsx.spec.section import face_cells

    # ceil(w/h) made even, at least 2: by hand
    assert [face_cells(0.1, h) for h in (0.1, 0.05, 0.0499, 0.034, 0.025, 0.0249)] == [
        2, 2, 4, 4, 4, 6,
    ]  # fmt: skip
    for size in (0.1, 0.05, 0.0499, 0.03, 0.02):
        around, _ = grid_nodes("box", (0.2, 0.1), 0.2, size, None)
        assert around == 2 * (face_cells(0.2, size) + face_cells(0.1, size))


def test_sections_are_public_and_lazy():
    """Exported in ``__all__``; importing the package imports no DOLFINx (the plate rule)."""
    import subprocess
    import sys

    assert {"SectionParameters", "solve_section"} <= set(unibuckle_fenicsx.__all__)
    code = "import sys, unibuckle_fenicsx; print('dolfinx' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_an_unproven_section_is_not_sent_to_the_bracket_it_refuses():
    """The summary's bracket line names no ``--bracket``: a section refuses it.

    The filled square box 100 x 100 x 1 mm, L = 0.2 m, on b/4 cells: a KKT point whose
    lower bound is the hollow box's by interlacing, with several pencil eigenvalues below
    the load (where a plate's line adds "--bracket may raise it"); the same file with
    ``solver.bracket = true`` is refused, naming the key.
    """
    from unibuckle_fenicsx.spec import section_from_dict

    data = {
        "section": {"shape": "box", "width": 0.1, "depth": 0.1, "thickness": 0.001,
                    "length": 0.2, "ends": "simply_supported"},
        "material": {"E": E, "nu": NU}, "obstacle": {"core": True},
        "mesh": {"size": 0.025, "levels": 0},
    }  # fmt: skip
    with solve_section(section_from_dict(data), MPI.COMM_SELF) as analysis:
        r = analysis.result
        cert = r.certificate
        assert cert is not None and not cert.global_optimum_proven
        assert cert.proven_by == "interlacing" and (cert.negative_eigenvalues or 0) >= 2
        summary = r.summary()
    assert "not proven: the critical stress lies between" in summary
    assert "--bracket" not in summary
    with pytest.raises(InputError, match=r"solver\.bracket"):
        section_from_dict({**data, "solver": {"bracket": True}})


def test_levels_end_no_higher_than_the_seeds_on_the_given_section():
    """The coarse-to-fine route keeps the critical state the seeds find on the given cells.

    ``demos/box.toml`` (the README's filled box, clamped ends, b/8 cells): a carried
    contact set polished by the plain rule once ended at a KKT point 6e-4 above the one
    the seeds reach on these cells (``levels = 0``); the route must not end higher than
    that (to the eigen solves' tolerance).
    """
    from msgspec.structs import replace

    from unibuckle_fenicsx.spec import load_problem

    spec = load_problem(ROOT / "demos" / "box.toml")
    loads = {}
    route = replace(spec.solver, method="active-set")  # the route under test ("auto" runs
    # the interior point beside it on this section)
    for levels in (1, 0):
        file = replace(spec, mesh=replace(spec.mesh, levels=levels), solver=route)
        with solve_section(file, MPI.COMM_SELF) as analysis:
            assert analysis.result.certificate is not None and analysis.result.certificate.kkt
            loads[levels] = analysis.result.critical_load_Pa
    assert loads[1] <= loads[0] * (1 + 1e-7), loads


def test_a_filled_box_does_not_depend_on_what_the_process_solved_before(tmp_path):
    """The same file gives the same bits first in a fresh process and after other solves.

    Nothing of one run reaches the next: no PETSc option left in the database, no cache,
    no random state, no warm start. A small filled box (b = 0.1 m, b/t = 50, L = 2b,
    cells b/4) is solved by ``unibuckle solve`` in a fresh process, then here after a
    plate with an obstacle, the hollow box and itself: its load, eigen solves and contact
    set equal the fresh run's to the bit, and the options database is as it was.
    Rounding is another matter: a 1-ulp change of the input (a length of 3 * 0.2 against
    0.6) may take the active set to another KKT point of a flat landscape.
    """
    import subprocess
    import sys

    from petsc4py import PETSc

    from unibuckle_fenicsx.cli import EXIT_OK, main

    box = tmp_path / "box.toml"
    box.write_text(
        '[section]\nshape = "box"\nwidth = 0.1\ndepth = 0.1\nthickness = 0.002\n'
        'length = 0.2\nends = "simply_supported"\n[material]\nE = 2.1e11\nnu = 0.3\n'
        "[obstacle]\ncore = true\n[mesh]\nsize = 0.025\n"
    )
    fresh = tmp_path / "fresh.json"
    code = "import sys; from unibuckle_fenicsx.cli import main; sys.exit(main(sys.argv[1:]))"
    args = ["solve", "--config", str(box), "-q", "--json"]
    subprocess.run([sys.executable, "-c", code, *args, str(fresh)], check=True, cwd=ROOT)
    before = PETSc.Options().getAll()
    runs = [
        ["solve", "--case", "c1", "--nx", "8", "--ny", "4", "-q"],
        [*args[:-2], "-q", "--set", "obstacle.core=false"],
        [*args, str(tmp_path / "1.json")],
        [*args, str(tmp_path / "2.json")],
    ]
    for run in runs:
        assert main(run) == EXIT_OK
    assert PETSc.Options().getAll() == before
    expected = json.loads(fresh.read_text())
    for name in ("1.json", "2.json"):
        got = json.loads((tmp_path / name).read_text())
        for key in ("critical_load_Pa", "free_load_Pa", "eigensolves", "contact_indices"):
            assert got[key] == expected[key], (name, key)


def test_the_section_problem_s_k_is_the_result_s_with_any_stress_per_unit_load():
    """The problem's k is the result's, sigma t b^2/(pi^2 D) at the extreme fibre.

    A hollow 0.1 x 0.06 m box (b/t = 50) under axial_stress = -2 with bending_stress = 0.5
    per unit load: the extreme fibre carries 2.5 times the load factor. The result's k and
    the section problem's ``buckling_coefficient`` (a Python user's, as on a plate's
    problem) are that formula worked here by hand; before, the problem's took the load
    factor itself as the stress (2.5 times too small).
    """
    box = SectionParameters(
        "box", width=0.1, depth=0.06, thickness=0.002, length=0.2, E=2.1e11, nu=0.3,
        mesh_size=0.02, ends="simply_supported", axial_stress=-2.0, bending_stress=0.5,
    )  # fmt: skip
    D = 2.1e11 * 0.002**3 / (12.0 * (1.0 - 0.3**2))
    with solve_section(box, MPI.COMM_SELF) as analysis:
        load = analysis.result.critical_load_Pa
        k = 2.5 * load * 0.002 * 0.1**2 / (math.pi**2 * D)
        assert analysis.result.buckling_coefficient_k == pytest.approx(k, rel=1e-13)
        assert analysis.section.problem.buckling_coefficient(load) == pytest.approx(k, rel=1e-13)


def test_cells_too_coarse_for_the_buckles_draw_a_warning(caplog):
    # Box: cells across the narrowest face, min(width, depth)/mesh.size, here 0.1/0.05 = 2
    # (below MIN_FACE_CELLS = 5); 0.1/0.02 = 5 is not. Tube (R = 0.1 m, t = 2 mm,
    # nu = 0.3): the axisymmetric half-wave pi sqrt(R t)/(12 (1 - nu^2))^(1/4)
    # = pi * 0.0141421 / 1.81762 = 0.024444 m, so 0.02 m cells give 1.22 of them (10
    # cells of 20 mm along, 32 facets of 19.6 mm) and 0.016 m cells 1.56 (13 cells of
    # 15.4 mm along, 40 facets of 2R sin(pi/40) = 15.69 mm: simply supported, L = 2R =
    # 8.2 half-waves, below MIN_HALF_WAVE_CELLS_LONG = 2.5, this tube is 9 % high on 1.5
    # cells, docs/guide/sections.md "Cell size"), 0.0097 m cells 2.57 (66 facets of
    # 9.52 mm). Between clamped ends 2.57 cells are below MIN_HALF_WAVE_CELLS = 4.
    from unibuckle_fenicsx.section_analysis import coarse_mesh_note

    assert coarse_mesh_note(_box(mesh_size=0.02)) is None
    note = coarse_mesh_note(_box(mesh_size=0.05))
    assert note is not None and "2 cells across the narrowest face" in note
    assert "mesh.size to 0.02 m" in note
    tube = SectionParameters(
        "tube", diameter=0.2, thickness=T, length=0.2, E=E, nu=NU, mesh_size=0.02,
        ends="simply_supported",
    )  # fmt: skip
    note = coarse_mesh_note(tube)
    assert note is not None and "1.2 cells" in note and "(0.0244 m)" in note
    note = coarse_mesh_note(dataclasses.replace(tube, mesh_size=0.016))
    assert note is not None and "1.6 cells" in note and "fewer than 2.5" in note
    assert coarse_mesh_note(dataclasses.replace(tube, mesh_size=0.0097)) is None
    note = coarse_mesh_note(dataclasses.replace(tube, mesh_size=0.0097, ends="clamped"))
    assert note is not None and "2.6 cells" in note and "fewer than 4" in note
    # The warning is logged by the solve (a hollow box on two cells a face: a free solve).
    with caplog.at_level(logging.WARNING, logger="unibuckle_fenicsx.section_analysis"):
        with solve_section(_box(mesh_size=0.05, core=False), MPI.COMM_SELF):
            pass
    assert any("cells across the narrowest face" in r.getMessage() for r in caplog.records)


def test_a_short_thin_tube_on_coarse_cells_draws_a_warning(caplog):
    """A hollow tube R/t = 200, L = 40 mm, simply supported, on 4.79 mm cells.

    Its axisymmetric half-wave pi sqrt(R t)/(12 (1 - nu^2))^(1/4) = 12.22 mm spans 2.57
    of its cells (9 of 4.44 mm along, 132 facets of 4.76 mm): the rule asked 2.5 and
    said nothing, while its load is 1.0545 sigma_cl, 6.9 % above the converged 0.987
    sigma_cl (h^2 extrapolation of 4.0 and 5.0 cells; docs/verification/tube_cells.md).
    The independent value here: Donnell's critical stress, the minimum over m, n of
    D (a^2 + b^2)^2/(t a^2) + E a^2/(R^2 (a^2 + b^2)^2), a = m pi/L, b = n/R, which is
    sigma_cl = E t/(R sqrt(3 (1 - nu^2))) to 1e-4 at this length; the load on these
    cells lies more than 5 % above it. A short simply supported tube asks for 4 cells.
    """
    import numpy as np

    R, t, L = 0.1, 0.0005, 0.04
    D = E * t**3 / (12 * (1 - NU**2))
    a = np.arange(1, 20)[:, None] * math.pi / L
    b = np.arange(0, 80)[None, :] / R
    donnell = float(
        (D * (a**2 + b**2) ** 2 / (t * a**2) + E * a**2 / (R**2 * (a**2 + b**2) ** 2)).min()
    )
    classical = E * t / (R * math.sqrt(3 * (1 - NU**2)))
    assert donnell == pytest.approx(classical, rel=1e-4)
    tube = SectionParameters(
        "tube", diameter=2 * R, thickness=t, length=L, E=E, nu=NU, mesh_size=0.00479,
        ends="simply_supported", core=False,
    )  # fmt: skip
    with caplog.at_level(logging.WARNING, logger="unibuckle_fenicsx.section_analysis"):
        with solve_section(tube, MPI.COMM_SELF) as analysis:
            load = analysis.result.critical_load_Pa
    assert load > 1.05 * donnell
    notes = [r.getMessage() for r in caplog.records if "half-wave" in r.getMessage()]
    assert len(notes) == 1 and "2.6 cells" in notes[0] and "fewer than 4" in notes[0]


def test_the_cells_asked_along_a_tube_fall_with_its_length_and_stop_at_thin_walls():
    """The cells asked along a tube's half-wave: 4, 2.5 on long simply supported tubes.

    Measured (docs/verification/tube_cells.md): on n cells along the half-wave the hollow
    tube lies about C/n^2 above its converged load, C up to 81 % between clamped ends and
    on simply supported tubes of up to 5 half-waves, 23 % from 8 half-waves.

    R = 0.1 m, t = 1 mm: half-wave 17.28 mm. Simply supported: L = 100 mm (5.79
    half-waves) asks 4 - 1.5 (0.79/3) = 3.61, 3.7 rounded up (this tube is 4.9 % high on
    2.5 cells), and 6.8 mm cells give 2.6 (15 of 6.67 mm along); L = 150 mm (8.7
    half-waves) asks 2.5; clamped, 4 at any length. R/t = 1000 lies beyond the R/t = 800
    measured: a warning on any cells.
    """
    from unibuckle_fenicsx.section_analysis import coarse_mesh_note, min_half_wave_cells

    tube = SectionParameters(
        "tube", diameter=0.2, thickness=0.001, length=0.1, E=E, nu=NU, mesh_size=0.0068,
        ends="simply_supported",
    )  # fmt: skip
    assert min_half_wave_cells(tube) == 3.7
    note = coarse_mesh_note(tube)
    assert note is not None and "2.6 cells" in note and "fewer than 3.7" in note
    long = dataclasses.replace(tube, length=0.15)
    assert min_half_wave_cells(long) == 2.5 and coarse_mesh_note(long) is None
    assert min_half_wave_cells(dataclasses.replace(long, ends="clamped")) == 4.0
    thin = dataclasses.replace(tube, thickness=0.0001, mesh_size=0.001)
    note = coarse_mesh_note(thin)
    assert note is not None and "R/t = 1000 is above 800" in note
    assert coarse_mesh_note(dataclasses.replace(thin, thickness=0.000125)) is None


def test_cells_exactly_enough_draw_no_warning():
    """0.35/0.07 is 4.999999999999999 in floating point: 5 cells, not fewer than 5.

    The mesh rounds the same way (geometry's ceil(extent/size - 1e-9): a face of 0.35 m
    gets 5 cells, made 6); the note said "gives 5 cells ..., fewer than 5" and asked to
    refine to the size given.
    """
    from unibuckle_fenicsx.section_analysis import coarse_mesh_note

    assert 0.35 / 0.07 < 5
    across = SectionParameters(
        "box", width=0.35, depth=0.35, thickness=T, length=1.0, E=E, nu=NU, mesh_size=0.07,
        ends="simply_supported",
    )  # fmt: skip
    assert coarse_mesh_note(across) is None
    # Along the member the rule asks 6 cells: 0.42/0.07 is 5.999999999999999.
    assert 0.42 / 0.07 < 6
    along = dataclasses.replace(across, width=0.5, depth=0.5, length=0.42)
    assert coarse_mesh_note(along) is None


def test_the_coarse_cell_warning_counts_the_cells_the_mesh_has():
    """The warning counts the mesh's cells, not the nominal width/mesh.size.

    A box 100 x 60 mm on 13 mm cells: 60/13 = 4.6 was reported ("gives 4.6 cells across
    the narrowest face ..., fewer than 5"), where the mesh puts an even number of cells
    of at most 13 mm across each face, 6 of 10 mm on the 60 mm faces (the hollow square
    box with 6 cells across a face is 3.8 % above its converged k, docs/guide/sections.md
    "Cell size": no warning due). On 17 mm cells it makes 4 (60/17 = 3.5 was reported).
    A tube D = 0.2 m on 16 mm cells: 40 facets of 15.69 mm and 13 cells of 15.38 mm
    along; its half-wave of 24.44 mm spans 1.56 facets, not 24.44/16 = 1.53 cells. The
    counts are read off the meshes themselves (their nodes), independently of the rule.
    """
    import numpy as np

    from unibuckle_fenicsx.model.shell.geometry import box_mesh, tube_mesh
    from unibuckle_fenicsx.section_analysis import coarse_mesh_note, half_wave

    def distinct(values):
        return np.unique(np.round(values, 9))

    box = SectionParameters(
        "box", width=0.1, depth=0.06, thickness=0.001, length=0.2, E=E, nu=NU,
        mesh_size=0.013, ends="simply_supported",
    )  # fmt: skip
    assert 0.06 / 0.013 < 5 and coarse_mesh_note(box) is None
    note = coarse_mesh_note(dataclasses.replace(box, mesh_size=0.017))
    assert note is not None and "gives 4 cells across the narrowest face (0.06 m)" in note
    from unibuckle_fenicsx.section_analysis import mesh_cell_counts

    for size, across in ((0.013, 6), (0.017, 4)):
        x = box_mesh(0.1, 0.06, 0.2, size, MPI.COMM_SELF).mesh.geometry.x
        face = x[np.isclose(x[:, 1], 0.05) & np.isclose(x[:, 0], 0.0)]  # y = +b/2, depth d
        assert distinct(face[:, 2]).size - 1 == across
        along = distinct(x[:, 0]).size - 1
        counts = mesh_cell_counts(dataclasses.replace(box, mesh_size=size))
        assert counts == pytest.approx((across, along), rel=1e-12)
    tube = SectionParameters(
        "tube", diameter=0.2, thickness=T, length=0.2, E=E, nu=NU, mesh_size=0.016
    )
    x = tube_mesh(0.2, 0.2, 0.016, MPI.COMM_SELF).mesh.geometry.x
    ring = x[np.isclose(x[:, 0], 0.0)]
    angles = np.sort(np.arctan2(ring[:, 2], ring[:, 1]))
    chord = 0.2 * math.sin(0.5 * (angles[1] - angles[0]))
    cell = 0.2 / (distinct(x[:, 0]).size - 1)
    assert (ring.shape[0], chord, cell) == pytest.approx((40, 0.015692, 0.015385), rel=1e-4)
    expected = half_wave(tube) / max(chord, cell)
    assert mesh_cell_counts(tube)[0] == pytest.approx(expected, rel=1e-12)
    assert expected == pytest.approx(1.5575, rel=1e-4)


def test_walls_thick_for_the_shell_model_draw_a_warning():
    # The plate's rule, t over the width of the buckles at most THICK_PLATE_RATIO = 0.2.
    # Box: 0.03/0.1 = 0.3 warns, 0.002/0.1 does not. Tube (R = 0.1 m, nu = 0.3): the
    # half-wave pi sqrt(R t)/(12 (1 - nu^2))^(1/4) is 0.05466 m at t = 0.01 m (ratio
    # 0.183: no warning) and 0.07730 m at t = 0.02 m (ratio 0.259: a warning).
    from unibuckle_fenicsx.section_analysis import half_wave, thick_wall_note

    assert thick_wall_note(_box()) is None
    note = thick_wall_note(_box(thickness=0.03))
    assert note is not None and "section.thickness = 0.03 m is 0.3 times" in note
    tube = SectionParameters(
        "tube", diameter=0.2, thickness=0.01, length=0.2, E=E, nu=NU, mesh_size=0.01
    )
    assert half_wave(tube) == pytest.approx(0.05466, rel=1e-3)
    assert thick_wall_note(tube) is None
    thick = dataclasses.replace(tube, thickness=0.02)
    assert half_wave(thick) == pytest.approx(0.07730, rel=1e-3)
    note = thick_wall_note(thick)
    assert note is not None and "0.259 times the tube's axisymmetric half-wave" in note


def test_the_warnings_of_a_file_in_mm_n_mpa_are_in_its_units(caplog):
    """A file in mm-N-MPa: its warnings in mm and MPa, not in the SI of the solve.

    The column's warning said "Euler stress 5.527e+08 Pa" and the cells' "mesh.size =
    0.05 m" to a file that writes 50 mm and 210000 MPa. The box 100 x 100 x 4 mm, 2.5 m
    between simply supported ends: Euler's pi^2 E (b^2/6)/L^2 = 552.7 MPa.
    """
    from unibuckle_fenicsx import section_from_dict
    from unibuckle_fenicsx.section_analysis import column_note
    from unibuckle_fenicsx.spec.base import file_units

    column = SectionParameters(
        "box", width=0.1, depth=0.1, thickness=0.004, length=2.5, E=E, nu=NU, mesh_size=0.02,
        ends="simply_supported",
    )  # fmt: skip
    euler = math.pi**2 * E * (0.1**2 / 6.0) / 2.5**2
    with file_units("mm-N-MPa"):  # a mm-N-MPa file's run
        note = column_note(column, 5.457e8, False)
    assert note is not None
    assert (
        "critical axial stress 545.7 MPa" in note and f"Euler stress {euler / 1e6:.4g} MPa" in note
    )
    assert "Pa is" not in note.replace("MPa", "")
    mm = section_from_dict({
        "units": "mm-N-MPa",
        "section": {"shape": "box", "width": 200.0, "depth": 100.0, "thickness": 2.0,
                    "length": 200.0, "ends": "simply_supported"},
        "material": {"E": 2.1e5, "nu": NU},
        "mesh": {"size": 50.0},  # hollow: no levels (its free solve)
    })  # fmt: skip
    with caplog.at_level(logging.WARNING, logger="unibuckle_fenicsx.section_analysis"):
        with solve_section(mm, MPI.COMM_SELF):
            pass
    messages = " ".join(r.getMessage() for r in caplog.records)
    assert "mesh.size = 50 mm gives 2 cells across the narrowest face (100 mm)" in messages
    assert "refine mesh.size to 20 mm or less" in messages


def test_a_section_s_design_with_a_poisson_s_ratio_not_a_steel_s_is_warned_of(caplog):
    """[design] of a box with nu = -0.2: a warning naming material.nu, none at 0.3.

    Steel's nu is 0.3 (EN 1993-1-1 3.2.6); a plate's is warned of alike.
    """
    from unibuckle_fenicsx import section_from_dict

    def run(nu):
        spec = section_from_dict({
            "section": {"shape": "box", "width": 0.1, "depth": 0.1, "thickness": 0.002,
                        "length": 0.1, "ends": "simply_supported"},
            "material": {"E": 2.1e11, "nu": nu},
            "mesh": {"size": 0.025},  # hollow: no levels (its free solve)
            "design": {"yield_stress": 3.55e8},
        })  # fmt: skip
        caplog.clear()
        with caplog.at_level(logging.WARNING, logger="unibuckle_fenicsx.section_analysis"):
            with solve_section(spec, MPI.COMM_SELF):
                pass
        return " ".join(r.getMessage() for r in caplog.records)

    assert "design: material.nu = -0.2 is not a steel's" in run(-0.2)
    assert "material.nu" not in run(0.3)


@pytest.mark.parametrize("foundation", [None, 1e10])
def test_a_filled_member_near_its_euler_stress_is_warned_of_its_column(foundation):
    """The core keeps the walls off the column's mode: the result says nothing of it.

    The box 100 x 100 x 4 mm, 1.5 m between simply supported ends, filled: its walls'
    reference stress 4 pi^2 D/(t b^2) = 1.215e9 Pa, about 1.9 times that with the core
    (2.3e9 Pa), while the walls' section alone has Euler's pi^2 E (b^2/6)/L^2 = 1.535e9
    Pa (thin-walled square box: I/A = b^2/6). The rigid core lets the walls move only
    outward, and an elastic one resists them with springs fixed in space: no column mode
    either way. The result said nothing; it now names the member's flexural buckling
    (EN 1994-1-1, 6.7.3). Below 0.8 of Euler's stress (a short member) no warning.
    """
    from unibuckle_fenicsx.section_analysis import column_note

    member = SectionParameters(
        "box", width=0.1, depth=0.1, thickness=0.004, length=1.5, E=E, nu=NU,
        mesh_size=0.02, ends="simply_supported", core=True, foundation_stiffness=foundation,
    )  # fmt: skip
    euler = math.pi**2 * E * (0.1**2 / 6.0) / 1.5**2
    assert euler == pytest.approx(1.535e9, rel=1e-3)
    note = column_note(member, 2.3e9, True)
    assert note is not None
    assert f"{2.3e9 / euler:.3g} times the member's Euler stress {euler:.4g} Pa" in note
    assert "flexural buckling" in note and "EN 1994-1-1, 6.7.3" in note
    assert column_note(member, 0.79 * euler, True) is None
    # The hollow member's warning is the column's mode itself (unchanged).
    hollow = dataclasses.replace(member, core=False, foundation_stiffness=None)
    assert "the mode is the column's" in (column_note(hollow, 0.9 * euler, False) or "")


def test_a_uniform_stress_is_not_called_the_extreme_fibre_s():
    """``axial_stress = -2`` and no bending: every fibre carries twice the load factor.

    The summary said "sigma_cr = ... at the extreme fibre, load factor ..." for this
    uniform stress; it names the stress uniform. With bending it keeps "the extreme fibre"
    (tests/verification/test_section_anchors.py). The compression is 2 x the load factor
    by the load's definition (compression per unit load 2).
    """
    tube = SectionParameters(
        "tube", diameter=0.1, thickness=0.001, length=0.01, E=E, nu=NU, mesh_size=0.002,
        ends="simply_supported", core=False, axial_stress=-2.0,
    )  # fmt: skip
    with solve_section(tube, MPI.COMM_SELF) as analysis:
        result = analysis.result
    assert result.compression_Pa == pytest.approx(2 * result.critical_load_Pa, rel=1e-14)
    summary = result.summary()
    assert f"sigma_cr = {result.compression_Pa:.6e} Pa (uniform), load factor" in summary
    assert "fibre" not in summary
    # A file's run echoes its [load] table (bending_stress 0 by default): the same words.
    result.input = {"load": {"axial_stress": -2.0, "bending_stress": 0.0}}
    assert "(uniform), load factor" in result.summary()
    result.input = {"load": {"axial_stress": -2.0, "bending_stress": 0.5}}
    assert "at the extreme fibre, load factor" in result.summary()
