"""A section's inputs that cannot work, refused before any mesh, naming the key and its range.

Each number is the mesh's arithmetic (``unibuckle_fenicsx.model.shell.geometry``): ceil(L/h)
cells along the member, its nodes at x = i L/n; the end nodes' normal motion is held by
the end supports. ``mesh.levels`` doubles the cell size that many times; the coarsest
section needs 2 cells along (docs/guide/sections.md, ``[mesh]``).

The box below: L = 0.3 m, cells of 12.5 mm. Doubled k times: 25, 50, 100, 200, 400 mm,
so 4 levels keep 2 cells along (200 mm < 300 mm) and 5 do not (400 mm).
"""

from __future__ import annotations

from mpi4py import MPI

import pytest

from unibuckle_fenicsx import SectionParameters, solve_section
from unibuckle_fenicsx.cli import EXIT_BAD_INPUT, main
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.spec import SolverSpec, load_toml

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial sections")

BOX = """name = "b"
[section]
shape = "box"
width = 0.1
depth = 0.1
thickness = 0.001
length = 0.3
ends = "simply_supported"
[material]
E = 2.1e11
nu = 0.3
[obstacle]
core = true
{obstacle}
[mesh]
size = {size}
levels = {levels}
"""


def _file(tmp_path, size=0.0125, levels=1, obstacle=""):
    path = tmp_path / "box.toml"
    path.write_text(BOX.format(size=size, levels=levels, obstacle=obstacle))
    return path


def _no_mesh(*args, **kwargs):
    raise AssertionError("a mesh was built")


def test_too_many_levels_are_refused_when_the_file_is_read(tmp_path):
    """5 levels of 12.5 mm cells on 0.3 m: 400 mm cells; the range (<= 4) is said."""
    path = _file(tmp_path, levels=5)
    with pytest.raises(InputError) as err:
        load_toml(path)
    text = str(err.value)
    assert text.startswith(f"{path}: mesh.levels = 5")
    assert "mesh.levels <= 4" in text
    assert load_toml(_file(tmp_path, levels=4)).mesh.levels == 4


def test_cells_not_below_the_length_are_refused_when_the_file_is_read(tmp_path):
    """mesh.size 0.3 m on a 0.3 m member: 1 cell along, the ends' nodes only."""
    path = _file(tmp_path, size=0.3, levels=0)
    with pytest.raises(InputError, match=r"box.toml: mesh.size = 0.3 m must be below"):
        load_toml(path)


def test_an_elastic_core_takes_the_default_levels_on_any_mesh(tmp_path):
    """An elastic core's rigid start takes as many levels as the section allows (none here).

    Cells of 25 mm on a member 50 mm long: 2 along (4 across a face, the fewest a core is
    solved on), no coarser section; the default levels = 1 is not refused (the solve takes
    0), a levels = 1 written out is the same value and is not refused either; 2 are.
    """
    stiff = "foundation_stiffness = 1e10"

    def short(levels):
        path = _file(tmp_path, size=0.025, levels=levels, obstacle=stiff)
        path.write_text(path.read_text().replace("length = 0.3", "length = 0.05"))
        return path

    assert load_toml(short(1)).mesh.levels == 1
    with pytest.raises(InputError, match=r"mesh.levels = 2.*mesh.levels <= 0"):
        load_toml(short(2))


def test_a_span_without_a_node_on_a_coarser_section_is_refused_when_read(tmp_path):
    """A span 0.11-0.12 m: the 12.5 mm cells have a node at 0.1125 m, the 25 mm ones none.

    It was refused only once the solve had built the sections, without the file's name.
    """
    span = "span = [0.11, 0.12]"
    path = _file(tmp_path, levels=1, obstacle=span)
    with pytest.raises(InputError) as err:
        load_toml(path)
    text = str(err.value)
    assert text.startswith(f"{path}: obstacle.span = [0.11, 0.12]")
    assert "mesh.levels" in text and "25 mm" not in text and "0.025 m" in text
    assert load_toml(_file(tmp_path, levels=0, obstacle=span)).obstacle.span == (0.11, 0.12)
    # Between two nodes of the given cells: refused whatever the levels.
    with pytest.raises(InputError, match=r"obstacle.span = \[0.11, 0.112\].* no node"):
        load_toml(_file(tmp_path, levels=0, obstacle="span = [0.11, 0.112]"))
    # Only the end's nodes (held by the supports): refused.
    with pytest.raises(InputError, match=r"only nodes held by the end supports"):
        load_toml(_file(tmp_path, levels=0, obstacle="span = [0.0, 0.01]"))


def test_the_command_line_refuses_them_before_any_mesh(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr("unibuckle_fenicsx.model.shell.section.section_mesh", _no_mesh)
    path = _file(tmp_path)
    for args in (["--set", "mesh.levels=5"], ["--set", "obstacle.span=[0.11,0.12]"]):
        assert main(["solve", "--config", str(path), *args]) == EXIT_BAD_INPUT
        err = capsys.readouterr().err
        assert str(path) in err or "--set" in err, err


def _hollow() -> SectionParameters:
    return SectionParameters(
        "box", width=0.1, depth=0.1, thickness=0.001, length=0.3, E=2.1e11, nu=0.3,
        mesh_size=0.0125,
    )  # fmt: skip


@pytest.mark.parametrize(
    ("options", "key"),
    [
        ({"levels": 2}, "mesh.levels"),
        ({"solver": SolverSpec(tau=1e-6)}, "solver.tau"),
        ({"solver": SolverSpec(max_iterations=7)}, "solver.max_iterations"),
        ({"solver": SolverSpec(bracket=True)}, "solver.bracket"),
    ],
)
def test_solve_section_refuses_a_core_s_options_on_a_hollow_section(monkeypatch, options, key):
    """The file's route refuses them (``check_core_options``); the API said nothing.

    A hollow section is its free solve: levels, tau and max_iterations are a core's
    search's; a plate's option (bracket) is no section's.
    """
    monkeypatch.setattr("unibuckle_fenicsx.model.shell.section.section_mesh", _no_mesh)
    with pytest.raises(InputError, match=rf"^{key}\b"):
        solve_section(_hollow(), MPI.COMM_SELF, **options)


def test_solve_section_refuses_too_many_levels_before_any_mesh(monkeypatch):
    monkeypatch.setattr("unibuckle_fenicsx.model.shell.section.section_mesh", _no_mesh)
    cored = SectionParameters(
        "box", width=0.1, depth=0.1, thickness=0.001, length=0.3, E=2.1e11, nu=0.3,
        mesh_size=0.0125, core=True,
    )  # fmt: skip
    with pytest.raises(InputError, match=r"mesh.levels = 5.*mesh.levels <= 4"):
        solve_section(cored, MPI.COMM_SELF, levels=5)
    spanned = SectionParameters(
        "box", width=0.1, depth=0.1, thickness=0.001, length=0.3, E=2.1e11, nu=0.3,
        mesh_size=0.0125, core=True, core_span=(0.11, 0.12),
    )  # fmt: skip
    with pytest.raises(InputError, match=r"obstacle.span"):
        solve_section(spanned, MPI.COMM_SELF, levels=1)


def test_a_sweep_refuses_a_point_with_too_many_levels_before_solving_any(tmp_path, monkeypatch):
    """Points of mesh.size 12.5 mm and 200 mm with levels = 1: the second is refused first.

    It has no coarser section of 2 cells along (400 mm on 0.3 m). It was refused as that
    point's line, after the first had been solved.
    """
    from unibuckle_fenicsx import sweep

    solved = []
    monkeypatch.setattr(
        sweep, "solve_point", lambda spec, comm: solved.append(spec) or {"status": "ok"}
    )
    base = sweep.base_mapping(_file(tmp_path))
    variation = sweep.parse_variation("mesh.size=0.0125,0.2")
    with pytest.raises(InputError, match=r"sweep point .*mesh.size.*mesh.levels = 1"):
        sweep.run_sweep(base, [variation], tmp_path / "s.jsonl", MPI.COMM_SELF, progress=False)
    assert solved == []


def test_a_section_s_contact_dofs_are_documented_as_depending_on_the_ranks():
    """The same filled box on 1 and 2 ranks: contact_indices equal, contact_dofs not.

    Measured (tests/mpi/section_parallel.py's box, 62 directions in contact): the DOFs
    [30, 72, 126, ...] on 1 rank, [0, 6, 12, ...] on 2 (DOLFINx numbers the distributed
    mesh's DOFs by rank). A section's result did not say what its contact_dofs were.
    """
    from unibuckle_fenicsx.results.records import BucklingResult
    from unibuckle_fenicsx.section_analysis import SectionResult

    for doc in (SectionResult.__doc__, BucklingResult.__doc__):
        text = " ".join(doc.split())
        assert "contact_dofs" in text and "number of MPI ranks" in text


def test_a_section_needing_more_memory_than_there_is_is_refused_before_any_mesh(monkeypatch):
    """A plate's mesh was checked against the machine's memory; a section's was not.

    The box 0.1 x 0.1 x 0.3 m on 2.5 mm cells: 160 nodes around, 121 along, 6 DOFs each
    (116 160); at 13 kB per DOF (the least measured, ``BYTES_PER_SECTION_DOF``) 1.51 GB,
    refused with 1 GB available. On this machine's 24 GB, mesh.size = 0.1 mm (72 million
    DOFs) went on to mesh.
    """
    from unibuckle_fenicsx.model import resources

    monkeypatch.setattr("unibuckle_fenicsx.model.shell.section.section_mesh", _no_mesh)
    monkeypatch.setattr(resources, "available_memory", lambda: 10**9)
    box = SectionParameters(
        "box", width=0.1, depth=0.1, thickness=0.001, length=0.3, E=2.1e11, nu=0.3,
        mesh_size=0.0025,
    )  # fmt: skip
    match = r"mesh.size = 0.0025 m gives about 116,160 DOFs, which need about 1.51 GB"
    with pytest.raises(InputError, match=match):
        solve_section(box, MPI.COMM_SELF)


def test_solve_section_refuses_options_beside_a_problem_file(tmp_path, monkeypatch):
    """A file's mesh.levels, [solver] and [design] are solved: the arguments were ignored.

    ``solve_section(spec, levels=0)`` ran the file's levels = 1 and said nothing.
    """
    from unibuckle_fenicsx.spec import DesignSpec

    monkeypatch.setattr("unibuckle_fenicsx.model.shell.section.section_mesh", _no_mesh)
    spec = load_toml(_file(tmp_path))
    for options, key in (
        ({"levels": 0}, "mesh.levels"),
        ({"solver": SolverSpec(tau=1e-6)}, r"\[solver\]"),
        ({"design": DesignSpec(yield_stress=3.55e8)}, r"\[design\]"),
    ):
        with pytest.raises(InputError, match=rf"with a problem file .*whose {key} is the one"):
            solve_section(spec, MPI.COMM_SELF, **options)


def test_a_section_sweep_warns_of_coarse_cells_and_keeps_each_point_s_warnings(tmp_path, capsys):
    """A hollow box swept over mesh.size 50 and 40 mm: 2 and 4 cells across a face (even).

    The sweep silences its points' solves, so a section's warnings were said nowhere:
    k came out 7.549 and 5.321 (the box's 4.51 on fine cells: 67 % and 18 % high) with
    no word, and nothing in the points' lines. The plate's sweep says them once before
    solving; a section's now too, and each line keeps its solve's ``warnings``.
    """
    import json

    path = tmp_path / "hollow.toml"
    path.write_text(
        BOX.format(size=0.05, levels=1, obstacle="")
        .replace("[obstacle]\ncore = true\n", "")
        .replace("levels = 1\n", "")
    )
    out = tmp_path / "s.jsonl"
    args = ["sweep", "--config", str(path), "--vary", "mesh.size=0.05,0.04"]
    assert main([*args, "--json", str(out), "-q"]) == 0
    err = capsys.readouterr().err
    assert "2 of 2 sweep points have cells too coarse; point 0" in err, err
    assert "mesh.size = 0.05 m gives 2 cells across the narrowest face" in err, err
    lines = [json.loads(line) for line in out.read_text().splitlines()]
    assert [len(line["warnings"]) for line in lines] == [1, 1]
    assert "gives 2 cells across" in lines[0]["warnings"][0]
    assert "gives 4 cells across" in lines[1]["warnings"][0]


def test_a_hollow_column_s_warning_is_in_its_result():
    """The column note, said after the solve, is kept in the result's warnings.

    The hollow box 50 x 50 x 5 mm, 0.6 m between simply supported ends, on 12.5 mm cells
    (tests/mpi/test_mpi.py's column): its critical stress is 0.94 times the Euler stress
    pi^2 E (b^2/6)/L^2 = 2.40e9 Pa, and its cells 4 across a face (fewer than 5).
    """
    column = SectionParameters(
        "box", width=0.05, depth=0.05, thickness=0.005, length=0.6, E=2.1e11, nu=0.3,
        mesh_size=0.0125, ends="simply_supported",
    )  # fmt: skip
    with solve_section(column, MPI.COMM_SELF) as analysis:
        warnings = analysis.result.warnings
    assert len(warnings) == 2, warnings
    assert "cells across the narrowest face" in warnings[0]
    assert "Euler stress" in warnings[1] and "the mode is the column's" in warnings[1]


def test_cells_of_a_nanometre_are_counted_not_listed(tmp_path, monkeypatch):
    """mesh.size = 1e-12 m on 0.3 m: 3e11 cells along, refused by the memory check at once.

    Counting the span's nodes, the faces' cells and their widths built arrays of them
    (a read of mesh.size = 1e-9 m ran out of the 120 s it was given, at 4 GB); they are
    counted now (the mesh's own arithmetic, tested equal to its arrays in
    tests/unit/model/test_shell_model.py).
    """
    monkeypatch.setattr("unibuckle_fenicsx.model.shell.section.section_mesh", _no_mesh)
    spec = load_toml(_file(tmp_path, size=1e-12, levels=0, obstacle="span = [0.1, 0.2]"))
    with pytest.raises(InputError, match=r"mesh.size = 1e-12 m gives about .* DOFs"):
        solve_section(spec, MPI.COMM_SELF)
