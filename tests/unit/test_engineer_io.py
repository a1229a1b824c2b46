r"""What an engineer gives and reads: inputs refused or honoured, outputs that say what they are.

- A hollow section runs its free solve only: a search option given to it (``mesh.levels``,
  ``solver.tau``, ``solver.max_iterations``) is refused naming the key (exit 2, before
  any mesh); an elastic core's levels beyond what its section allows are refused as a
  rigid core's are, not clipped.
- ``unibuckle sweep`` warns of E below any structural material's, as ``unibuckle
  solve`` does, from the one check both use.
- The stress limit's clause says when the load's shear is not checked.
- The summary's k (the scaled load's, :math:`\sigma = \lambda_c\sigma_1`) and the design's
  :math:`k_\sigma` (:math:`\sigma_{cr}`, the fixed load included) are told apart; the
  hand values: :math:`k = \lambda_c/\sigma_E`, :math:`k_\sigma = (\lambda_c +
  \sigma_{fixed})/\sigma_E`, :math:`\sigma_E = \pi^2 E t^2/(12(1 - \nu^2) b^2)` (EN
  1993-1-5 eq. (A.2)).
- A section's figure keeps its view (and its axes triad) when it sees a buckle nearly as
  large as the largest (a sweep chart's legend: ``tests/unit/results/test_output_labels.py``).
- ``--output`` writes a section's fields, read back here: the mode scaled to max |u| = 1,
  the contact nodes those of the JSON's ``contact_coordinates``, the outward
  displacement zero on them (the mode touches the core there) and nowhere negative (the
  core lets the walls move outward only).
"""

from __future__ import annotations

import json
import math

from mpi4py import MPI

import numpy as np
import pytest

from unibuckle_fenicsx.cli import EXIT_BAD_INPUT, EXIT_OK, main

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial command lines")

#: A square hollow box, 2 cells across a face: the cheapest section that solves.
HOLLOW = """\
name = "hollow box"
[section]
shape = "box"
width = 0.1
depth = 0.1
thickness = 0.001
length = 0.3
ends = "clamped"
[material]
E = 2.1e11
nu = 0.3
[mesh]
size = 0.05
"""
#: A steel plate 300 x 100 x 3 mm, simply supported, compressed across its short edges.
PLATE = """\
[plate]
corners = [[0.0, 0.0], [0.3, 0.1]]
thickness = 0.003
[material]
E = 2.1e11
nu = 0.3
[edges.left]
normal_stress = -1.0
[edges.right]
normal_stress = -1.0
[mesh]
nx = 12
ny = 4
"""


def _no_mesh(monkeypatch):
    """Make building a section's mesh fail the test: a refusal comes before it."""
    import unibuckle_fenicsx.model.shell.section as section

    def no_mesh(*args, **kwargs):
        raise AssertionError("a mesh was built")

    monkeypatch.setattr(section, "section_mesh", no_mesh)


@pytest.mark.parametrize(
    ("args", "text"),
    [
        (["--tau", "1e-9"], "solver.tau = 1e-09 sets the core's contact tolerance"),
        (["--max-iterations", "5"], "solver.max_iterations = 5 sets the core's search's"),
        (["--set", "mesh.levels=2"], "mesh.levels = 2 sets the core's search's coarser sections"),
    ],
)
def test_a_hollow_section_refuses_the_search_s_options(tmp_path, monkeypatch, capsys, args, text):
    # They were taken and ignored: a hollow section is its free solve.
    _no_mesh(monkeypatch)
    path = tmp_path / "hollow.toml"
    path.write_text(HOLLOW)
    assert main(["solve", "--config", str(path), *args]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert text in err, err
    assert "a section without a core (obstacle.core = false) is its free solve" in err, err


def test_a_hollow_section_takes_the_search_s_defaults_as_its_result_echoes_them():
    # A result's input holds every key with its default: it must re-run.
    from unibuckle_fenicsx import problem_to_dict, section_from_dict
    from unibuckle_fenicsx.spec.section import DEFAULT_LEVELS
    from unibuckle_fenicsx.spec.solver import default

    spec = section_from_dict(
        {
            "section": {"shape": "box", "width": 0.1, "depth": 0.1, "thickness": 0.001,
                        "length": 0.3},
            "material": {"E": 2.1e11, "nu": 0.3},
            "mesh": {"size": 0.05, "levels": DEFAULT_LEVELS},
            "solver": {"tau": default("tau"), "max_iterations": default("max_iterations")},
        }
    )  # fmt: skip
    assert section_from_dict(problem_to_dict(spec)) == spec


def test_an_elastic_core_s_levels_beyond_its_section_are_refused(tmp_path, monkeypatch, capsys):
    # 25 mm cells on 0.3 m (4 across a 0.1 m face, as a core needs): 3 coarser sections
    # keep 2 cells along (0.2 m < 0.3 m), 4 do not (0.4 m). The rigid core refused
    # levels = 4; the elastic core's start from the rigid core's set took 3 without a word.
    _no_mesh(monkeypatch)
    path = tmp_path / "elastic.toml"
    path.write_text(
        HOLLOW.replace("size = 0.05", "size = 0.025\nlevels = 4")
        + "[obstacle]\ncore = true\nfoundation_stiffness = 1e12\n"
    )
    assert main(["solve", "--config", str(path)]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "mesh.levels = 4: the coarsest section's cells, mesh.size x 2^4 = 0.4 m" in err, err
    assert "mesh.levels <= 3 here" in err, err


def test_sweep_and_solve_warn_alike_of_a_modulus_in_mpa(tmp_path, capsys):
    # E = 210000 in an SI file (steel's E in MPa): every stress printed in Pa is in MPa.
    # unibuckle solve said so; unibuckle sweep solved every point silently.
    from unibuckle_fenicsx.spec.material import modulus_note

    note = modulus_note(210000.0)
    assert note is not None and note.startswith("material.E = 210000 Pa is below")
    config = tmp_path / "mpa.toml"
    config.write_text(PLATE.replace("E = 2.1e11", "E = 210000.0"))
    assert main(["solve", "--config", str(config)]) == EXIT_OK
    assert f"unibuckle: warning: {note}" in capsys.readouterr().err
    out = tmp_path / "t.jsonl"
    args = ["sweep", "--config", str(config), "--vary", "plate.thickness=0.003,0.004"]
    assert main([*args, "--json", str(out), "-q"]) == EXIT_OK
    err = capsys.readouterr().err
    assert err.count("unibuckle: warning:") == 1, err
    assert "2 of 2 sweep points draw this warning; point 0 {'plate.thickness': 0.003}: " in err
    assert note in err, err


def _shear_plate(normal: object) -> object:
    from unibuckle_fenicsx.spec import problem_from_dict

    return problem_from_dict(
        {
            "plate": {"corners": [[0.0, 0.0], [0.3, 0.1]], "thickness": 0.003},
            "material": {"E": 2.1e11, "nu": 0.3},
            "edges": {
                "left": {"normal_stress": normal, "shear_stress": 0.3},
                "right": {"normal_stress": normal, "shear_stress": 0.3},
                "bottom": {"shear_stress": -0.3},
                "top": {"shear_stress": -0.3},
            },
            "mesh": {"nx": 12, "ny": 4},
            "design": {"yield_stress": 3.55e8},
        }
    )


@pytest.mark.parametrize("normal", [-1.0, [-1.0, 0.0]])
def test_the_stress_limit_says_it_leaves_the_shear_unchecked(normal):
    # psi = 1: 4.6(1), eq. (4.14), checks the direct stress; psi = 0: section 10's eq.
    # (10.1) with alpha_ult,k = f_y/sigma_1, which is eq. (10.3) with tau = 0. The clause
    # said "direct stress only" of a plate with shear, as if the load had none.
    from unibuckle_fenicsx.design import design_output, limit_clause_text
    from unibuckle_fenicsx.en1993 import SHEAR_NOT_CHECKED, stress_limit
    from unibuckle_fenicsx.spec import DesignSpec

    spec = _shear_plate(normal)
    d = design_output(spec, DesignSpec(yield_stress=3.55e8), 7.0e8)
    clause, factor = d.stress_limit_clause, d.partial_factor_name
    assert SHEAR_NOT_CHECKED in clause, clause
    line = limit_clause_text(factor, clause)
    assert SHEAR_NOT_CHECKED in line, line
    if d.psi == 1.0:
        assert factor == "gamma_M0" and clause.startswith("4.6(1): rho f_y/gamma_M0")
        assert "section 5 and the interaction of 7.1" in clause, clause
    else:
        assert d.psi == 0.0 and factor == "gamma_M1"
        assert clause.startswith("section 10, reduced stress method, with tau = 0"), clause
        assert "direct stress only" not in clause and "tau = 0" in line, line
    # Without shear: no such words, as before.
    for psi in (1.0, 0.0):
        factor, plain = stress_limit(psi)
        assert SHEAR_NOT_CHECKED not in plain
        assert SHEAR_NOT_CHECKED not in limit_clause_text(factor, plain)
    assert "direct stress only" in stress_limit(0.0)[1]


def test_the_summary_tells_k_of_the_scaled_load_from_k_sigma_with_the_fixed_load(tmp_path):
    # 50 MPa of fixed compression beside the scaled unit stress. k = sigma t b^2/(pi^2 D)
    # with sigma = lambda_c (the scaled stress at lambda_c) is lambda_c/sigma_E; k_sigma =
    # sigma_cr/sigma_E with sigma_cr = lambda_c + 50 MPa. By hand: sigma_E = pi^2 2.1e11
    # (0.003/0.1)^2/(12 x 0.91) = 1.70820e8 Pa, so k_sigma - k = 5e7/1.70820e8 = 0.29271.
    from unibuckle_fenicsx.analysis import solve
    from unibuckle_fenicsx.results.records import coefficient_text
    from unibuckle_fenicsx.spec import load_problem

    sigma_e = math.pi**2 * 2.1e11 * (0.003 / 0.1) ** 2 / (12.0 * (1.0 - 0.3**2))
    assert sigma_e == pytest.approx(1.70820e8, rel=1e-5)
    fixed = PLATE.replace(
        "normal_stress = -1.0", "normal_stress = -1.0\nfixed_normal_stress = -5.0e7"
    )
    design = "[design]\nyield_stress = 3.55e8\n"
    for text, with_fixed in ((fixed + design, True), (PLATE + design, False)):
        path = tmp_path / "p.toml"
        path.write_text(text)
        with solve(load_problem(path), MPI.COMM_SELF) as analysis:
            result = analysis.result
        load, k, d = result.critical_load_Pa, result.buckling_coefficient_k, result.design
        assert k == pytest.approx(load / sigma_e, rel=1e-12)
        summary = result.summary()
        head, line = (
            summary.splitlines()[0],
            next(s for s in summary.splitlines() if "EN 1993-1-5: " in s),
        )
        if with_fixed:
            assert d.sigma_cr_Pa == pytest.approx(load + 5e7, rel=1e-12)
            assert d.k_sigma == pytest.approx((load + 5e7) / sigma_e, rel=1e-12)
            assert d.k_sigma - k == pytest.approx(0.29271, abs=1e-5)
            assert f"k = {coefficient_text(k)} (of the scaled load alone, the fixed load " in head
            assert f"the fixed load included: k_sigma = {coefficient_text(d.k_sigma)})" in line
        else:
            assert d.k_sigma == pytest.approx(k, rel=1e-12)  # the same stress
            assert "scaled load alone" not in head and "k_sigma" not in line, summary


def _box_ring(top: float, bottom: float) -> object:
    """A 0.2 x 0.1 box's perimeter at x = 0.1, buckled outward on its top and bottom faces."""
    from unibuckle_fenicsx.model.shell.section import SectionFigureData

    s = np.linspace(-1.0, 1.0, 9)
    y = np.concatenate([0.1 * s, np.full(9, 0.1), 0.1 * s, np.full(9, -0.1)])
    z = np.concatenate([np.full(9, 0.05), 0.05 * s, np.full(9, -0.05), 0.05 * s])
    points = np.column_stack([np.full(y.size, 0.1), y, z])
    bump = np.exp(-50.0 * y**2) * (np.abs(np.abs(z) - 0.05) < 1e-12)
    outward = np.where(z > 0, top, bottom) * bump
    none = np.zeros((0, 3))
    return SectionFigureData(
        points, np.zeros((0, 4), dtype=np.int64), np.zeros_like(points), outward, none, none,
        "box", (0.2, 0.2, 0.1),
    )  # fmt: skip


def test_a_section_figure_keeps_its_view_when_it_sees_a_buckle_nearly_the_largest():
    # A hollow box buckles alike on opposite faces: which node is largest is rounding,
    # and the view (with its axes triad) turned a quarter from one figure to the next.
    from unibuckle_fenicsx.viz.section import SEEN_FRACTION, view_turn

    assert view_turn(_box_ring(top=1.0 - 1e-12, bottom=1.0)) == 0.0
    assert view_turn(_box_ring(top=SEEN_FRACTION, bottom=1.0)) == 0.0
    # A buckle seen well below the largest: the bottom face turns into view.
    assert view_turn(_box_ring(top=0.5, bottom=1.0)) == pytest.approx(0.5 * math.pi)


def test_a_section_s_fields_are_written_for_paraview_and_read_back(tmp_path):
    # A filled box on 25 mm cells (4 across a face, the fewest a core is solved on): the
    # I/O, not the load, is tested.
    from types import SimpleNamespace

    import pyvista

    from unibuckle_fenicsx.model.shell.core import perimeter_coordinate

    path = tmp_path / "filled.toml"
    path.write_text(
        HOLLOW.replace("size = 0.05", "size = 0.025\nlevels = 0")
        + '[obstacle]\ncore = true\n[solver]\nmethod = "active-set"\n'
    )
    out, result_path = tmp_path / "fields", tmp_path / "r.json"
    args = ["solve", "--config", str(path), "--output", str(out), "--json", str(result_path)]
    assert main([*args, "-q"]) == EXIT_OK
    names = sorted(p.name for p in out.iterdir())
    assert {"hollow_box_u.bp", "hollow_box_outward.bp", "hollow_box.pvd"} <= set(names), names
    grid = pyvista.read(out / "hollow_box.pvd")[0]
    result = json.loads(result_path.read_text())
    u, outward = grid.point_data["u"], grid.point_data["outward"]
    assert u.shape == (grid.n_points, 3)
    assert np.abs(u).max() == pytest.approx(1.0, rel=1e-12)
    assert np.abs(grid.point_data["u_free"]).max() == pytest.approx(1.0, rel=1e-12)
    # The contact nodes: those of the JSON (its coordinates unrolled: x and the arc length
    # along the mid-line), each once (a corner node's two directions share them).
    contact = grid.point_data["contact"] > 0
    assert np.all(grid.point_data["core"][contact] > 0)
    mesh = SimpleNamespace(shape="box", width=0.1, depth=0.1, tolerance=1e-9)
    unrolled = np.column_stack([grid.points[:, 0], perimeter_coordinate(mesh, grid.points.T)])
    written = {tuple(np.round(p, 9)) for p in unrolled[contact]}
    listed = {tuple(np.round(p, 9)) for p in np.asarray(result["contact_coordinates"])}
    assert result["contact_nodes"] > 0 and written == listed, written ^ listed
    # The mode touches the core on a face's contact node (a corner's other face may
    # lift) and nowhere moves into it.
    y, z = grid.points[:, 1], grid.points[:, 2]
    corner = (np.abs(np.abs(y) - 0.05) < 1e-9) & (np.abs(np.abs(z) - 0.05) < 1e-9)
    assert np.abs(outward[contact & ~corner]).max() < 1e-12
    assert outward.min() > -1e-6, outward.min()


def test_the_euler_length_and_stress_are_one_formula():
    # sigma_E = pi^2 E t^2/(12 (1 - nu^2) b^2), b the loaded edges' length (0.1 m across
    # left and right), a = 0.3 m along: by hand 1.70820e8 Pa and a ninth of it.
    from unibuckle_fenicsx.design import euler_length, euler_stress
    from unibuckle_fenicsx.spec import problem_from_dict

    spec = problem_from_dict(
        {
            "plate": {"corners": [[0.0, 0.0], [0.3, 0.1]], "thickness": 0.003},
            "material": {"E": 2.1e11, "nu": 0.3},
        }
    )
    loaded = ("left", "right")
    assert euler_length(spec, loaded) == pytest.approx(0.1)
    assert euler_length(spec, loaded, along=True) == pytest.approx(0.3)
    assert euler_length(spec, ("bottom", "top")) == pytest.approx(0.3)
    assert euler_stress(spec, loaded) == pytest.approx(1.70820e8, rel=1e-5)
    assert euler_stress(spec, loaded, along=True) == pytest.approx(1.70820e8 / 9, rel=1e-5)


@pytest.mark.parametrize(
    ("flags", "text"),
    [
        (["--tau", "1"], "--tau: solver.tau must lie in [1e-12, 0.01], got 1.0"),
        (["--max-iterations", "0"], "--max-iterations: solver.max_iterations must be an integer"),
        (["--nx", "0"], "--nx: mesh.nx must be an integer >= 2, got 0"),
    ],
)
def test_a_flag_out_of_range_is_named_with_the_key_it_sets(capsys, flags, text):
    # The message named the key (solver.tau) and not the flag the engineer typed.
    assert main(["solve", "--case", "c1", *flags]) == EXIT_BAD_INPUT
    assert text in capsys.readouterr().err


def test_a_hole_too_large_says_how_large_it_may_be():
    # A circle at (0.15, 0.05) in the 0.3 x 0.1 m plate: its centre lies 0.05 m from the
    # nearest edges (y = 0 and y = 0.1), so the radius must be below 0.05 m.
    from unibuckle_fenicsx.spec import problem_from_dict

    plate = {"corners": [[0.0, 0.0], [0.3, 0.1]], "thickness": 0.003}
    with pytest.raises(ValueError, match=r"distance to the plate's edge, 0.05 m, got radius = 0.2"):
        problem_from_dict({"plate": {**plate, "holes": [{"center": [0.15, 0.05], "radius": 0.2}]}})
    with pytest.raises(ValueError, match=r"its centre \[0.5, 0.05\] m lies outside the plate"):
        problem_from_dict({"plate": {**plate, "holes": [{"center": [0.5, 0.05], "radius": 0.01}]}})
