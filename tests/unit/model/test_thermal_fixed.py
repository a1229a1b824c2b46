r"""Thermal loads and fixed + scaled loads: the pencil :math:`(A - B_{fixed}, B_{scaled})`.

Expected values:

- a fixed part of zero is today's problem (the same numbers); a fixed part equal to c
  times the scaled one lowers :math:`\lambda` by exactly c (the pencil :math:`(A - cB, B)`
  has the eigenvalues :math:`\lambda - c` with the same modes), with or without obstacle;
- a uniform rise :math:`\Delta T` in a plate held in its plane on every edge gives the
  biaxial membrane force :math:`N = E t \alpha\Delta T/(1-\nu)` (the strain is zero), so
  a simply supported plate buckles at :math:`\Delta T_{cr} = \pi^2 D (1-\nu)(1/a^2 +
  1/b^2)/(E t\alpha)` = :math:`\pi^2 t^2 (1/a^2 + 1/b^2)/(12(1+\nu)\alpha)` (the classical
  critical temperature: Boley and Weiner, *Theory of Thermal Stresses*, 1960, section
  14.8), here with the Reissner–Mindlin factor of the Navier solution (DESIGN's hard
  simple support, ``materials.navier_load_mindlin``);
- a rise linear in y, :math:`T_0 + g y`, with the loaded edges x = 0, a held by rollers
  and the others free, gives exactly :math:`N_{xx} = -E t\alpha(T_0 + g y)`,
  :math:`N_{yy} = N_{xy} = 0` (compatible strains): the plate of the edge stress pair
  :math:`[-E\alpha T_0, -E\alpha(T_0 + g b)]`;
- a fixed shear with a scaled compression: the bicubic Hermite Kirchhoff plate
  (``tests/support/hermite_plate.py``), whose pure shear load of the square plate is the
  published k = 9.325 (Stein and Neff, NACA TN 1222, 1947; Timoshenko and Gere, 1961,
  section 9.7, give 9.34 by a shorter series).
"""

from __future__ import annotations

import math

from mpi4py import MPI

import pytest
from msgspec.structs import replace

from support.hermite_plate import HermitePlate, isotropic
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.model.materials import bending_stiffness, navier_load_mindlin
from unibuckle_fenicsx.spec import LoadSpec, Material, problem_from_dict, problem_to_dict
from unibuckle_fenicsx.spec.cases import paper_case

E, NU, ALPHA = 2.0e11, 0.3, 1.2e-5


def result(spec):
    with solve(spec, MPI.COMM_WORLD) as analysis:
        return analysis.result


def with_fixed(spec, **edges):
    """``spec`` with fixed stresses on edges: name -> dict of fixed_* keys."""
    new = tuple(replace(e, **edges.get(e.name, {})) for e in spec.plate.edges)
    return replace(spec, plate=replace(spec.plate, edges=new))


def steel_plate(n, edges, load, thickness=0.002, a=1.0, b=0.5, **extra):
    return problem_from_dict(
        {
            "plate": {"corners": [[0, 0], [a, b]], "thickness": thickness},
            "material": {"E": E, "nu": NU, "thermal_expansion": ALPHA},
            "edges": edges,
            "mesh": {"nx": round(n * a / b), "ny": n},
            "load": load,
            **extra,
        }
    )


HELD = {name: {"inplane": "clamped"} for name in ("left", "right", "bottom", "top")}


# -- schema ------------------------------------------------------------------------------
def test_load_keys_are_read_converted_and_written_back():
    data = {
        "units": "mm-N-MPa",
        "plate": {"corners": [[0, 0], [1000, 500]], "thickness": 2.0},
        "material": {"E": 2.0e5, "nu": 0.3, "thermal_expansion": 1.2e-5},
        "edges": {
            "left": {"fixed_shear_stress": 20.0, "inplane": "roller"},
            "right": {"normal_stress": -1.0, "fixed_normal_stress": [-5.0, 5.0]},
        },
        "load": {"temperature": [10.0, 0.0, 0.02], "fixed_temperature": 5.0},  # K, K/mm
    }
    spec = problem_from_dict(data)
    assert spec.plate.edge("left").fixed_shear_stress == pytest.approx(20e6)
    assert spec.plate.edge("right").fixed_normal_stress == pytest.approx((-5e6, 5e6))
    assert spec.load.temperature == pytest.approx((10.0, 0.0, 20.0))  # K/m
    assert spec.load.fixed_temperature == 5.0 and spec.has_fixed_load
    assert problem_from_dict(problem_to_dict(spec, units="mm-N-MPa")) == spec
    written = problem_to_dict(spec, units="mm-N-MPa")
    assert written["load"]["temperature"] == pytest.approx([10.0, 0.0, 0.02])
    assert written["edges"]["left"]["fixed_shear_stress"] == pytest.approx(20.0)
    assert written["edges"]["bottom"]["fixed_normal_stress"] == 0.0
    # Without [load] and fixed stresses: no fixed part, and the echo has zeros.
    plain = problem_from_dict({})
    assert not plain.has_fixed_load and problem_to_dict(plain)["load"] == {
        "temperature": 0.0,
        "fixed_temperature": 0.0,
        "fixed_factor": 1.0,
    }


@pytest.mark.parametrize(
    "data, match",
    [
        (
            {"load": {"temperature": 10.0}},
            r"load\.temperature: a temperature rise needs \[material\] thermal_expansion",
        ),
        (
            {"material": {"E": 1e9, "nu": 0.3, "thermal_expansion": -1e-5}},
            r"material\.thermal_expansion must be >= 0",
        ),
        (
            {"load": {"temperature": [1.0, 2.0]}},
            r"load\.temperature must be a number .* or \[T0, dT/dx, dT/dy\]",
        ),
        ({"load": {"temperature": "hot"}}, r"load\.temperature must be a number"),
        ({"load": {"heat": 1.0}}, r"unknown key\(s\) \['heat'\] in \[load\]"),
        (
            {"edges": {"left": {"fixed_shear_stress": [1.0]}}},
            r"edges\.left\.fixed_shear_stress must be a number or a pair",
        ),
    ],
)
def test_bad_loads_are_refused(data, match):
    with pytest.raises(ValueError, match=match):
        problem_from_dict(data)


def test_a_fixed_load_alone_is_refused_before_the_mesh():
    spec = problem_from_dict({"edges": {"left": {"fixed_normal_stress": -1e6}}})
    with pytest.raises(
        ValueError, match=r"no load to scale: .* the fixed part .* is applied as is"
    ):
        solve(spec, MPI.COMM_WORLD)


def test_thermal_expansion_of_a_laminate_is_refused():
    ply = {"thickness": 0.001, "angle": 0.0, "E1": 1e11, "E2": 1e10, "G12": 5e9, "nu12": 0.3}
    ply |= {"G13": 5e9, "G23": 3e9}
    with pytest.raises(ValueError, match=r"material\.thermal_expansion: a laminate's plies"):
        problem_from_dict({"material": {"plies": [ply], "thermal_expansion": 1e-5}})


# -- fixed + scaled ----------------------------------------------------------------------
def test_a_fixed_part_of_zero_is_todays_answer():
    c1 = paper_case("c1", 10, 10)
    zero = with_fixed(c1, bottom={"fixed_shear_stress": 0.0})
    zero = replace(zero, material=replace(zero.material, thermal_expansion=1e-5))
    zero = replace(zero, load=LoadSpec(fixed_temperature=0.0))
    assert not zero.has_fixed_load
    a, b = result(c1), result(zero)
    assert b.critical_load_Pa == a.critical_load_Pa and b.contact_indices == a.contact_indices


@pytest.mark.parametrize("case", ["free", "c1"])
def test_a_fixed_multiple_of_the_scaled_load_shifts_lambda(case):
    """Fixed compression c on the loaded edges: lambda - c, the same contact set."""
    spec = paper_case(case, 10, 10)
    c = 2.0e6  # Pa, about 1/7 of lambda
    shifted = with_fixed(spec, left={"fixed_normal_stress": -c}, right={"fixed_normal_stress": -c})
    a, b = result(spec), result(shifted)
    assert b.critical_load_Pa == pytest.approx(a.critical_load_Pa - c, rel=1e-9)
    assert b.critical_load_factor == b.critical_load_Pa
    assert b.contact_indices == a.contact_indices
    if case == "c1":
        assert a.contact_nodes > 0 and b.certificate.kkt


def test_a_fixed_load_that_buckles_the_plate_alone_is_refused():
    """A fixed compression of 30 MPa: as many negative pivots as loads below 30 MPa.

    The count comes from the dense pencil of the plate without the fixed part (scipy).
    """
    import numpy as np
    import scipy.linalg

    from support.exhaustive import dense
    from unibuckle_fenicsx.model.build import build_problem

    spec = paper_case("c1", 8, 8)
    with build_problem(spec.without_obstacles(), MPI.COMM_SELF) as problem:
        A, B = dense(problem.model.A), dense(problem.model.B)
    theta = scipy.linalg.eigh(B, A, eigvals_only=True)
    below = int(np.count_nonzero(theta > 1 / 30e6))
    assert below >= 2  # lambda_free is 14 MPa on this mesh
    too_much = with_fixed(
        spec, left={"fixed_normal_stress": -30e6}, right={"fixed_normal_stress": -30e6}
    )
    with pytest.raises(
        ValueError,
        match=rf"the fixed load alone buckles the plate without its obstacle .* has {below} neg",
    ):
        solve(too_much, MPI.COMM_WORLD)


def test_fixed_shear_with_scaled_compression_against_the_hermite_plate():
    """Square SSSS plate, t/b = 1e-3: a fixed shear of half its own critical value.

    The Hermite plate's pure shear k is 9.325 (published), and with the fixed shear the
    compression's k falls from 4 to 3.0006; MITC4 16 x 16, 32 x 32, Richardson, to 1e-4.
    """
    t = 1e-3
    D = bending_stiffness(1e9, 0.3, t)
    bfs = HermitePlate(1.0, 1.0, 16, 16, isotropic(1e9, 0.3, t), membrane=(0.0, 0.0, 1.0))
    k_shear = bfs.free_load() / (math.pi**2 * D)
    assert k_shear == pytest.approx(9.325, abs=1e-3)
    tau = 0.5 * k_shear * math.pi**2 * D / t  # Pa
    bfs = HermitePlate(
        1.0, 1.0, 16, 16, isotropic(1e9, 0.3, t), membrane=(-1.0, 0.0, 0.0), fixed=(0, 0, tau * t)
    )
    reference = bfs.free_load() / (math.pi**2 * D)
    k = []
    for n in (16, 32):
        spec = paper_case("free", n, n)
        spec = replace(spec, plate=replace(spec.plate, corners=((0, 0), (1, 1)), thickness=t))
        # A uniform shear tau: +tau along x = const, -tau along y = const (counter-clockwise).
        spec = with_fixed(
            spec,
            left={"fixed_shear_stress": tau},
            right={"fixed_shear_stress": tau},
            bottom={"fixed_shear_stress": -tau},
            top={"fixed_shear_stress": -tau},
        )
        k.append(result(spec).buckling_coefficient_k)
    richardson = (4 * k[1] - k[0]) / 3
    assert richardson == pytest.approx(reference, rel=1e-4), (k, richardson, reference)


# -- thermal -------------------------------------------------------------------------------
def test_uniform_rise_gives_the_classical_critical_temperature():
    """SSSS 1 x 0.5 m steel plate, t = 2 mm, held in its plane: Richardson to 1e-4."""
    t, a, b = 0.002, 1.0, 0.5
    # N_cr of the biaxial state: the Navier load of mode (1, 1) with N_x = N_y.
    D = bending_stiffness(E, NU, t)
    s = 1 / a**2 + 1 / b**2
    kirchhoff = math.pi**2 * D * s
    G = E / (2 * (1 + NU))
    mindlin = kirchhoff / (1 + math.pi**2 * D * s / (5 / 6 * G * t))
    exact = mindlin * (1 - NU) / (E * t * ALPHA)  # K
    assert kirchhoff * (1 - NU) / (E * t * ALPHA) == pytest.approx(
        math.pi**2 * t**2 * s / (12 * (1 + NU) * ALPHA), rel=1e-14
    )
    rises = []
    for n in (16, 32):
        out = result(steel_plate(n, HELD, {"temperature": 1.0}))
        assert out.critical_temperature_K == out.critical_load_factor
        rises.append(out.critical_temperature_K)
    richardson = (4 * rises[1] - rises[0]) / 3
    assert richardson == pytest.approx(exact, rel=1e-4), (rises, richardson, exact)
    # A fixed rise of 0.2 K and a scaled one of 1 K: the scaled part's critical rise is 0.2 K less.
    both = result(steel_plate(16, HELD, {"temperature": 1.0, "fixed_temperature": 0.2}))
    assert both.critical_temperature_K == pytest.approx(rises[0] - 0.2, rel=1e-9)


def test_a_rise_linear_across_the_plate_is_a_stress_gradient():
    """T = T0 + g y, rollers on x = 0, a: the plate of the edge stress pair (degree 2: exact)."""
    T0, g = 10.0, 30.0  # K, K/m: 10 K at y = 0, 25 K at y = b = 0.5
    rollers = {"left": {"inplane": "roller"}, "right": {"inplane": "roller"}}
    thermal = steel_plate(8, rollers, {"temperature": [T0, 0.0, g]}, solver={"prestress_degree": 2})
    start, end = -E * ALPHA * T0, -E * ALPHA * (T0 + g * 0.5)
    mechanical = steel_plate(
        8,
        {"left": {"normal_stress": [start, end]}, "right": {"normal_stress": [start, end]}},
        {},
        solver={"prestress_degree": 2},
    )
    a, b = result(thermal), result(mechanical)
    assert a.critical_load_factor == pytest.approx(b.critical_load_factor, rel=1e-9)
    assert a.critical_temperature_K == pytest.approx(a.critical_load_factor * (T0 + g * 0.5))


def test_a_rise_alone_has_no_buckling_coefficient(tmp_path, capsys):
    """A rise alone (lambda a factor on it) has no buckling coefficient.

    k = t lambda b^2/(pi^2 D) needs an edge stress: the JSON's k is null, and a sweep's k
    chart is refused before anything is solved.
    """
    from unibuckle_fenicsx.cli import EXIT_BAD_INPUT, main

    out = result(steel_plate(4, HELD, {"temperature": 1.0}))
    assert out.buckling_coefficient_k is None and out.critical_temperature_K > 0.0
    assert out.as_dict()["buckling_coefficient_k"] is None
    path = tmp_path / "rise.toml"
    path.write_text(
        "[plate]\ncorners = [[0, 0], [1, 0.5]]\nthickness = 0.002\n"
        "[material]\nE = 2.1e11\nnu = 0.3\nthermal_expansion = 1.2e-5\n"
        + "".join(f'[edges.{n}]\ninplane = "clamped"\n' for n in ("left", "right", "bottom", "top"))
        + "[mesh]\nnx = 8\nny = 4\n[load]\ntemperature = 1.0\n"
    )
    args = ["sweep", "--config", str(path), "--vary", "plate.thickness=0.002,0.003"]
    out_json = tmp_path / "s.jsonl"
    assert (
        main([*args, "--json", str(out_json), "--plot", str(tmp_path / "k.png")]) == EXIT_BAD_INPUT
    )
    assert "--plot draws the buckling coefficient k of edge loads" in capsys.readouterr().err
    assert not out_json.exists()  # refused before any point was solved


def test_the_critical_rise_is_of_the_heated_part():
    """T = -3 K + 10 K/m y over y in [0, 0.5]: cooled below, heated above (+2 K at the top).

    The critical rise is lambda times the largest rise, +2 K, not the largest magnitude
    (the -3 K of the cooled edge: a negative "critical rise" before the fix).
    """
    out = result(steel_plate(8, HELD, {"temperature": [-3.0, 0.0, 10.0]}))
    assert out.critical_temperature_K == pytest.approx(out.critical_load_factor * 2.0, rel=1e-12)
    assert out.critical_temperature_K > 0.0


def test_the_total_critical_rise_with_a_fixed_rise():
    """A fixed 0.2 K and lambda x 1 K, uniform: the total rise at the critical state.

    The same uniform field as the scaled rise alone, so the total critical rise is that
    plate's critical rise (here it is compared with a separate solve of the rise alone);
    before, the output gave only lambda x 1 K. A fixed_factor of 0.5 halves the fixed
    part and leaves the total.
    """
    alone = result(steel_plate(8, HELD, {"temperature": 1.0}))
    assert alone.critical_total_temperature_K is None
    for load in (
        {"temperature": 1.0, "fixed_temperature": 0.2},
        {"temperature": 1.0, "fixed_temperature": 0.2, "fixed_factor": 0.5},
    ):
        both = result(steel_plate(8, HELD, load))
        total = both.critical_total_temperature_K
        assert total == pytest.approx(alone.critical_temperature_K, rel=1e-9)
        assert total == pytest.approx(
            load.get("fixed_factor", 1.0) * 0.2 + both.critical_load_factor, rel=1e-12
        )
        assert "total temperature rise at the critical state" in both.summary()
        assert f"{total:.6g} K" in both.summary()
        assert both.as_dict()["critical_total_temperature_K"] == total


def test_a_cooling_names_load_temperature():
    """A uniform cooling, two edges held in their plane: no buckling, and the key named."""
    rollers = {"left": {"inplane": "clamped"}, "right": {"inplane": "clamped"}}
    with pytest.raises(ValueError, match=r"load\.temperature = -1\.0 K per unit load is a cooling"):
        result(steel_plate(4, rollers, {"temperature": -1.0}))
    with pytest.raises(ValueError, match=r"reverse the sign of .* or of load\.temperature"):
        result(steel_plate(4, HELD, {"temperature": -1.0}))


@pytest.mark.parametrize("key", ["temperature", "fixed_temperature"])
def test_a_rise_on_a_plate_free_in_its_plane_is_refused(key):
    """A uniform or linear rise expands a free plate without stress: refused when read."""
    edges = {"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}}
    with pytest.raises(ValueError, match=rf"load\.{key}: the temperature rise leaves the plate"):
        steel_plate(4, edges, {key: [5.0, 10.0, -3.0]})


def test_cli_names_the_fixed_load_and_exits_2(tmp_path, capsys):
    from unibuckle_fenicsx.cli import EXIT_BAD_INPUT, main

    path = tmp_path / "p.toml"
    path.write_text(
        "[edges.left]\nnormal_stress = -1.0\nfixed_normal_stress = -3.0e7\n"
        "[edges.right]\nnormal_stress = -1.0\nfixed_normal_stress = -3.0e7\n"
        "[mesh]\nnx = 8\nny = 8\n"
    )
    assert main(["solve", "--config", str(path), "-q"]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "the fixed load alone buckles the plate (fixed_normal_stress" in err, err  # no obstacle
    path.write_text("[load]\ntemperature = 5.0\n")
    assert main(["solve", "--config", str(path), "-q"]) == EXIT_BAD_INPUT
    assert "thermal_expansion" in capsys.readouterr().err


def test_material_keeps_today_s_defaults():
    assert Material(E=1.0e9, nu=0.3).thermal_expansion == 0.0
    assert navier_load_mindlin(1e9, 0.3, 0.006, 0.2, 0.1)[1] == 2


def test_nonlinear_analysis_refuses_thermal_and_fixed_loads():
    from unibuckle_fenicsx.nonlinear import solve_nonlinear

    spec = steel_plate(4, HELD, {"temperature": 1.0})
    with pytest.raises(ValueError, match=r"nonlinear analysis .* temperature rises"):
        solve_nonlinear(spec, comm=MPI.COMM_WORLD)


def test_an_interaction_curve_by_a_sweep_over_the_fixed_factor(tmp_path):
    """``load.fixed_factor`` scales the whole fixed part: one --vary draws the curve.

    Square SSSS plate, compression scaled, a uniform fixed shear of 8430 Pa (about the
    plate's own critical shear) times the factor: factor 0 is the plain plate, and the
    compression's critical stress falls as the shear grows; each line is the direct
    solve of its problem, and factor 0.5 is the problem with half the shear.
    """
    from unibuckle_fenicsx.sweep import parse_variation, point_problem, run_sweep

    tau = 8430.0
    data = {
        "plate": {"corners": [[0, 0], [1, 1]], "thickness": 0.001},
        "edges": {
            "left": {"normal_stress": -1.0, "fixed_shear_stress": tau},
            "right": {"normal_stress": -1.0, "fixed_shear_stress": tau},
            "bottom": {"fixed_shear_stress": -tau},
            "top": {"fixed_shear_stress": -tau},
        },
        "mesh": {"nx": 8, "ny": 8},
    }
    base = problem_to_dict(problem_from_dict(data))
    lines = run_sweep(
        base, [parse_variation("load.fixed_factor=0,0.5,0.9")], tmp_path / "s.jsonl", progress=False
    )
    loads = [line["critical_load_Pa"] for line in lines]
    assert [line["status"] for line in lines] == ["ok"] * 3
    assert loads[0] > loads[1] > loads[2] > 0
    plain = dict(data, edges={"left": {"normal_stress": -1.0}, "right": {"normal_stress": -1.0}})
    assert loads[0] == pytest.approx(result(problem_from_dict(plain)).critical_load_Pa, rel=1e-12)
    half = problem_from_dict(
        {
            **data,
            "edges": {
                name: {k: v / 2 if k == "fixed_shear_stress" else v for k, v in edge.items()}
                for name, edge in data["edges"].items()
            },
        }
    )
    assert loads[1] == pytest.approx(result(half).critical_load_Pa, rel=1e-9)
    assert point_problem(base, {"load.fixed_factor": 0.5}).load.fixed_factor == 0.5


def test_the_summary_gives_a_rise_gradient_in_the_file_s_units():
    """A rise of 10 K + 0.03 K/mm y in a mm-N-MPa file: the summary says 0.03 K/mm.

    The input echoed is in SI (30 K/m), which the summary printed as it was, bare
    ("[10.0, 0.0, 30.0]") in a file that wrote 0.03; the fixed rise the same. Expected:
    the file's own numbers (1 K/mm = 1000 K/m), and in SI the SI ones.
    """
    rollers = {"left": {"inplane": "roller"}, "right": {"inplane": "roller"}}
    load = {"temperature": [10.0, 0.0, 0.03], "fixed_temperature": [1.0, 0.0, 0.002]}
    mm = problem_from_dict(
        {
            "units": "mm-N-MPa",
            "plate": {"corners": [[0, 0], [1000, 500]], "thickness": 2.0},
            "material": {"E": E / 1e6, "nu": NU, "thermal_expansion": ALPHA},
            "edges": rollers,
            "mesh": {"nx": 8, "ny": 4},
            "load": load,
        }
    )
    text = result(mm).summary()
    assert "temperature rise per unit lambda [10, 0, 0.03] (K, K/mm)" in text
    assert "temperature rise [1, 0, 0.002] (K, K/mm)" in text
    si = steel_plate(4, rollers, {"temperature": [10.0, 0.0, 30.0]})
    assert "temperature rise per unit lambda [10, 0, 30] (K, K/m)" in result(si).summary()
