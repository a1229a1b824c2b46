"""A file in ``units = "mm-N-MPa"`` is told of its errors in its own units.

The package converts such a file to SI on load; its messages quote the numbers and name
the units as the file writes them (2 mm, not 0.002 m), and an SI file's messages are
unchanged. Expected values: the numbers written in the files below, and the unit names
of the file's system (``spec.base.UNITS``: mm and MPa); each case is the same problem
written in both systems (lengths x 1e-3 and stresses x 1e6 from mm-N-MPa to SI).
"""

from __future__ import annotations

import copy
import re

import pytest

from unibuckle_fenicsx import problem_from_dict, section_from_dict

MM = 1e-3  # metres per mm
MPA = 1e6  # pascals per MPa


def _section(units: str, **changes: object) -> dict[str, object]:
    """A box section 200 x 100 x 2 mm, 400 mm long, in ``units``; ``changes``: table__key."""
    s, p = (1.0, 1.0) if units == "mm-N-MPa" else (MM, MPA)
    data: dict[str, dict[str, object]] = {
        "section": {
            "shape": "box",
            "width": 200.0 * s,
            "depth": 100.0 * s,
            "thickness": 2.0 * s,
            "length": 400.0 * s,
        },
        "material": {"E": 2.1e5 * p, "nu": 0.3},
        "mesh": {"size": 50.0 * s},
    }
    for dotted, value in changes.items():
        table, key = dotted.split("__")
        data.setdefault(table, {})[key] = value(s) if callable(value) else value
    return {"units": units, **data}


def _plate(units: str, **changes: object) -> dict[str, object]:
    """The 200 x 100 x 6 mm plate of a test of ``test_config``, in ``units``."""
    s, p = (1.0, 1.0) if units == "mm-N-MPa" else (MM, MPA)
    data: dict[str, object] = {
        "units": units,
        "plate": {"corners": [[-100.0 * s, -50.0 * s], [100.0 * s, 50.0 * s]], "thickness": 6 * s},
        "material": {"E": 1000.0 * p, "nu": 0.3},
        "obstacle": {"zone": [[-40.0 * s, 40.0 * s], [-50.0 * s, 50.0 * s]]},
    }
    for dotted, value in changes.items():
        node = data
        *tables, key = dotted.split("__")
        for table in tables:
            node = node[table]  # type: ignore[index]
        node[key] = value(s, p) if callable(value) else value  # type: ignore[index]
    return data


def _ply(s: float, p: float) -> dict[str, float]:
    """An isotropic ply 3 mm thick of E = 1000 MPa, nu = 0.3 (G = E / 2(1 + nu) rounded)."""
    return {
        "E1": 1000.0 * p,
        "E2": 1000.0 * p,
        "nu12": 0.3,
        "G12": 300.0 * p,
        "G13": 300.0 * p,
        "G23": 300.0 * p,
        "thickness": 3.0 * s,
        "angle": 0.0,
    }


def _refused(read, data: dict[str, object]) -> str:
    with pytest.raises(ValueError) as err:
        read(data)
    return str(err.value)


@pytest.mark.parametrize(
    ("read", "file", "changes", "mm", "si"),
    [
        (
            section_from_dict,
            _section,
            {"section__width": lambda s: -200.0 * s},
            "section.width must be > 0 mm, got -200.0",
            "section.width must be > 0 m, got -0.2",
        ),
        (
            section_from_dict,
            _section,
            {"material__E": lambda s: -2.1e5 * (1.0 if s == 1.0 else MPA)},
            "material.E must be > 0 MPa, got -210000.0",
            "material.E must be > 0 Pa, got -210000000000.0",
        ),
        (
            section_from_dict,
            _section,
            {"obstacle__core": True, "obstacle__foundation_stiffness": lambda s: -1.0},
            "obstacle.foundation_stiffness must be > 0 N/mm^3, got -1.0",
            "obstacle.foundation_stiffness must be > 0 N/m^3, got -1.0",
        ),
        (  # a badly shaped list: quoted as written, not scaled to SI
            section_from_dict,
            _section,
            {"obstacle__core": True, "obstacle__span": lambda s: [0.0, 100.0 * s, 200.0 * s]},
            "obstacle.span must be a pair [x0, x1] (from x0 to x1 along the member), "
            "got [0.0, 100.0, 200.0]",
            "obstacle.span must be a pair [x0, x1] (from x0 to x1 along the member), "
            "got [0.0, 0.1, 0.2]",
        ),
        (
            problem_from_dict,
            _plate,
            {"plate__corners": lambda s, p: [[0.0, 0.0, 1.0 * s], [100.0 * s, 50.0 * s]]},
            "plate.corners[0] must be a point [x, y], got [0.0, 0.0, 1.0]",
            "plate.corners[0] must be a point [x, y], got [0.0, 0.0, 0.001]",
        ),
        (
            problem_from_dict,
            _plate,
            {"obstacle__tolerance": lambda s, p: -1.0 * s},
            "obstacle.tolerance must be >= 0 mm, got -1.0",
            "obstacle.tolerance must be >= 0 m, got -0.001",
        ),
        (
            problem_from_dict,
            _plate,
            {"material": lambda s, p: {"plies": [{**_ply(s, p), "thickness": -3.0 * s}]}},
            "material.plies[0].thickness must be > 0 mm, got -3.0",
            "material.plies[0].thickness must be > 0 m, got -0.003",
        ),
    ],
    ids=["width", "E", "foundation_stiffness", "span_list", "corners_list", "tolerance", "ply"],
)
def test_a_value_out_of_its_type_or_range_is_quoted_as_written(read, file, changes, mm, si):
    """A value refused by its type or range: the file's number and its unit's name there."""
    assert _refused(read, file("mm-N-MPa", **changes)) == mm
    assert _refused(read, file("SI", **changes)) == si


@pytest.mark.parametrize(
    ("read", "file", "changes", "mm", "si"),
    [
        (
            section_from_dict,
            _section,
            {"section__thickness": lambda s: 60.0 * s},
            "section.thickness must be < half of width and depth (50 mm): the walls would "
            "meet, got 60.0",
            "section.thickness must be < half of width and depth (0.05 m): the walls would "
            "meet, got 0.06",
        ),
        (
            problem_from_dict,
            _plate,
            {"plate__thickness": lambda s, p: 150.0 * s},
            "plate.thickness = 150 mm is 1.5 times the plate's smaller side 100 mm: not a plate",
            "plate.thickness = 0.15 m is 1.5 times the plate's smaller side 0.1 m: not a plate",
        ),
        (
            problem_from_dict,
            _plate,
            {"plate__corners": lambda s, p: [[0.0, 0.0], [-100.0 * s, 50.0 * s]]},
            "plate.corners must satisfy x1 > x0 and y1 > y0 (a non-degenerate rectangle), got "
            "((0.0, 0.0), (-100.0, 50.0))",
            "plate.corners must satisfy x1 > x0 and y1 > y0 (a non-degenerate rectangle), got "
            "((0.0, 0.0), (-0.1, 0.05))",
        ),
        (
            problem_from_dict,
            _plate,
            {"obstacle__zone": lambda s, p: [[40.0 * s, -40.0 * s], [-50.0 * s, 50.0 * s]]},
            "obstacle.zone needs xmin <= xmax and ymin <= ymax, got ((40.0, -40.0), (-50.0, 50.0))",
            "obstacle.zone needs xmin <= xmax and ymin <= ymax, got ((0.04, -0.04), (-0.05, 0.05))",
        ),
        (
            problem_from_dict,
            _plate,
            {"points": lambda s, p: [{"spacing": -10.0 * s, "kind": "bilateral"}]},
            "points[0].spacing must be > 0 mm, got [-10.0, -10.0]",
            "points[0].spacing must be > 0 m, got [-0.01, -0.01]",
        ),
        (
            problem_from_dict,
            _plate,
            {"points": lambda s, p: [{"at": [0.0, 0.0], "kind": "spring"}]},
            'points[0].stiffness: kind = "spring" needs a stiffness > 0 N/mm, got None',
            'points[0].stiffness: kind = "spring" needs a stiffness > 0 N/m, got None',
        ),
        (
            problem_from_dict,
            _plate,
            {"material": lambda s, p: {"E": 5.0 * p, "nu": 0.3, "plies": [_ply(s, p)]}},
            "material.E and material.nu of a laminate are its in-plane constants E_x = 1000 MPa "
            "and nu_xy = 0.3 from the plies (got 5.0, 0.3)",
            "material.E and material.nu of a laminate are its in-plane constants E_x = 1e+09 Pa "
            "and nu_xy = 0.3 from the plies (got 5000000.0, 0.3)",
        ),
        (
            problem_from_dict,
            _plate,
            {"material": lambda s, p: {"plies": [_ply(s, p)]}},
            "plate.thickness = 6.0 mm differs from the plies' total 3.0 mm",
            "plate.thickness = 0.006 m differs from the plies' total 0.003 m",
        ),
    ],
    ids=[
        "walls_meet",
        "thick_plate",
        "corners",
        "zone",
        "spacing",
        "spring",
        "laminate_E",
        "plies",
    ],
)
def test_a_rule_between_keys_speaks_the_file_s_units(read, file, changes, mm, si):
    """A rule between keys broken (walls that meet, a thick plate, ...): in the file's units."""
    assert _refused(read, file("mm-N-MPa", **changes)).startswith(mm)
    assert _refused(read, file("SI", **changes)).startswith(si)


def test_a_tube_s_thickness_limit_speaks_the_file_s_units():
    """A tube 10 mm across with 6 mm walls: half its diameter is 5 mm."""
    data = _section("mm-N-MPa")
    data["section"] = {"shape": "tube", "diameter": 10.0, "thickness": 6.0, "length": 400.0}
    expected = "section.thickness must be < half of diameter (5 mm): the walls would meet, got 6.0"
    assert _refused(section_from_dict, data) == expected


@pytest.mark.parametrize(
    ("changes", "mm", "si"),
    [
        (
            {"mesh__size": lambda s: 500.0 * s},
            "mesh.size = 500 mm must be below section.length = 400 mm:",
            "mesh.size = 0.5 m must be below section.length = 0.4 m:",
        ),
        (  # 50 mm x 2^5 = 1600 mm; 50 x 2^2 = 200 mm is the coarsest below 400 mm
            {"obstacle__core": True, "mesh__levels": 5},
            "mesh.levels = 5: the coarsest section's cells, mesh.size x 2^5 = 1600 mm, are not "
            "below section.length = 400 mm (at least 2 cells along): mesh.levels <= 2 here",
            "mesh.levels = 5: the coarsest section's cells, mesh.size x 2^5 = 1.6 m, are not "
            "below section.length = 0.4 m (at least 2 cells along): mesh.levels <= 2 here",
        ),
    ],
    ids=["size", "levels"],
)
def test_the_cells_along_the_member_speak_the_file_s_units(monkeypatch, changes, mm, si):
    """The cells' checks, refused when the file is read (no mesh built), in its units.

    They were refused by the solve, before its mesh; the file's reader refuses them now.
    """
    import unibuckle_fenicsx.model.shell.section as section

    def no_mesh(*args, **kwargs):
        raise AssertionError("a mesh was built")

    monkeypatch.setattr(section, "section_mesh", no_mesh)
    for units, expected in (("mm-N-MPa", mm), ("SI", si)):
        with pytest.raises(ValueError, match=f"^{re.escape(expected)}"):
            section_from_dict(_section(units, **copy.deepcopy(changes)))


@pytest.mark.parametrize(
    ("changes", "mm", "si"),
    [
        (
            {"points": lambda s, p: [{"at": [500.0 * s, 0.0], "kind": "bilateral"}]},
            "points[0].at [500.0, 0.0] mm lies outside the plate",
            "points[0].at [0.5, 0.0] lies outside the plate",
        ),
        (
            {
                "points": lambda s, p: [
                    {"spacing": 10.0 * s, "region": [[200.0 * s, 300.0 * s], [0.0, 10.0 * s]]}
                ]
            },
            "points[0]: the grid of spacing [10.0, 10.0] mm holds no point of the plate",
            "points[0]: the grid of spacing [0.01, 0.01] holds no point of the plate",
        ),
        (
            {"load": lambda s, p: {"temperature": "hot"}},
            "load.temperature must be a number (K) or [T0, dT/dx, dT/dy] (K, K/mm)",
            "load.temperature must be a number (K) or [T0, dT/dx, dT/dy] (K, K/m)",
        ),
    ],
    ids=["at", "grid", "temperature_form"],
)
def test_points_and_a_temperature_s_form_speak_the_file_s_units(changes, mm, si):
    """A point outside the plate, a grid missing it, a temperature's form (K/mm).

    Before, the points were quoted in metres and the gradient named K/m in a mm-N-MPa file.
    """
    assert _refused(problem_from_dict, _plate("mm-N-MPa", **changes)).startswith(mm)
    assert _refused(problem_from_dict, _plate("SI", **changes)).startswith(si)


def test_an_empty_zone_found_on_the_mesh_speaks_the_file_s_units():
    """A zone between the nodes of 4 x 4 cells (50 x 25 mm): refused once the mesh exists.

    Before, its corners were quoted in metres ([0.001, 0.002] x ...) in a mm-N-MPa file.
    """
    from unibuckle_fenicsx import solve

    for units, expected in (
        ("mm-N-MPa", "obstacle.zone [1, 2] x [1, 2] mm holds no free mesh node"),
        ("SI", "obstacle.zone [0.001, 0.002] x [0.001, 0.002] holds no free mesh node"),
    ):
        zone = lambda s, p: [[1.0 * s, 2.0 * s], [1.0 * s, 2.0 * s]]  # noqa: E731
        spec = problem_from_dict(_plate(units, obstacle__zone=zone, mesh={"nx": 4, "ny": 4}))
        with pytest.raises(ValueError, match=f"^{re.escape(expected)}"):
            solve(spec)


def test_a_range_is_written_in_the_file_s_units_with_the_si_number_named():
    """E = 2.1e11 (steel in Pa) in a mm-N-MPa file: the range in MPa, and what to write.

    Expected: the SI range of E, [1e3, 1e13] Pa (``spec.material.MIN_MODULUS`` and
    ``MAX_MODULUS``), over 1e6 Pa per MPa: [0.001, 1e7] MPa; 2.1e11 Pa is 210000 MPa.
    Before, the message wrote the SI bounds with the unit MPa ([1000, 1e+13] MPa).
    """
    data = _plate("mm-N-MPa", material__E=2.1e11)
    assert _refused(problem_from_dict, data) == (
        "material.E must lie in [0.001, 1e+07] MPa, got 210000000000.0 (in range as "
        "2.1e+11 Pa: units = 'mm-N-MPa' takes MPa, here 210000)"
    )
    # A number out of range in both unit systems draws no hint; an SI file none either.
    assert _refused(problem_from_dict, _plate("mm-N-MPa", material__E=1e20)) == (
        "material.E must lie in [0.001, 1e+07] MPa, got 1e+20"
    )
    assert _refused(problem_from_dict, _plate("SI", material__E=1e20)) == (
        "material.E must lie in [1000, 1e+13] Pa, got 1e+20"
    )


@pytest.mark.parametrize(
    ("E", "units", "expected"),
    [
        (2.1e5, "SI", "material.E = 210000 Pa is below any structural material"),
        (2.1e5 * MPA, "SI", None),  # steel in Pa
        (1.0e8, "SI", None),  # the threshold itself
        (210.0 * MPA, "mm-N-MPa", None),
        (21.0 * MPA, "mm-N-MPa", "material.E = 21 MPa is below any structural material"),
    ],
)
def test_a_modulus_below_any_structural_material_s_is_warned_of(E, units, expected):
    """E in MPa in an SI file (210000 for steel) gives stresses in MPa printed as Pa.

    The threshold 1e8 Pa (``spec.material.STRUCTURAL_MODULUS``) lies below the softest
    structural materials (polymers about 3e9 Pa); an SI file is told of units =
    "mm-N-MPa", a mm-N-MPa file to write E in MPa.
    """
    from unibuckle_fenicsx.spec.material import modulus_note

    note = modulus_note(E, units)
    if expected is None:
        assert note is None
    else:
        assert note is not None and note.startswith(expected)
        assert ('units = "mm-N-MPa"' in note) == (units == "SI")
