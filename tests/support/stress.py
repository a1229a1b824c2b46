"""The stress family's check: the solver's answer against the exhaustive minimum.

Shared by the tests that run a method on the stress family (``tests/large/``,
``tests/unit/algorithms/``): :func:`check` solves a problem as a user would and compares
its load and contact set with :func:`reference` (:mod:`support.exhaustive`, dense linear
algebra, nothing of the package's algorithms).
"""

from __future__ import annotations

import math

from mpi4py import MPI

import numpy as np
import pytest

from support.exhaustive import (
    RTOL,
    dense,
    dense_free_load,
    dense_reduced_load,
    exhaustive_minimum,
    membrane_force_scale,
)
from support.families import stress_family
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.errors import NoAdmissibleModeError
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.mesh import create_plate_mesh
from unibuckle_fenicsx.model.plate.model import PlateModel
from unibuckle_fenicsx.model.prestress import solve_prestress

FAMILY_SIZE = 200
SAMPLE = 20
FAMILY = stress_family(FAMILY_SIZE)


#: Problems of the family where the active-set answer is a genuine KKT point above the
#: global minimum; the certificate must not claim it proven. stress37 (5x3 mesh,
#: whole-plate obstacle, clamped / simply supported edges under pure shear, i = 8): the
#: active set stops at 372.96 MPa, the exhaustive minimum is 368.40 MPa (1.2 % lower).
#: stress166 (6x3, whole plate, two free edges, shear, i = 14): 3012.91 against
#: 2995.35 Pa (0.6 %).
KNOWN_LOCAL_MINIMA = {"stress37", "stress166"}


def reference(spec, i: int) -> tuple[float, list[tuple[int, ...]], float]:
    """(global minimum, its contact sets, comparison tolerance), independently."""
    reference = build_problem(spec, MPI.COMM_SELF)
    assert reference.num_constrained == i
    # Loads can be compared no closer than independent solves of the plain pencil agree
    # (SLEPc; LAPACK with and without the edge DOFs): on thin plates (t/b ~ 1e-4) cond(A)
    # reaches 1e11 and their spread is up to a few 1e-8 itself.
    free_dense = dense_free_load(reference)
    rtol = RTOL
    if math.isfinite(free_dense):
        values = [free_dense, dense_reduced_load(reference, ()), reference.solve_free().load]
        rtol = max(RTOL, 10.0 * (max(values) - min(values)) / free_dense)
    # The fast exhaustive search (condensed pencil) finds the candidates; each is then
    # re-solved without condensation.
    best, candidates, _ = exhaustive_minimum(reference, 1e-6)
    loads = {z: dense_reduced_load(reference, z) for z in candidates}
    reference.destroy()
    if not math.isfinite(best):
        return best, [], rtol
    best = min(loads.values())
    return best, [z for z, v in loads.items() if v <= best * (1 + rtol)], rtol


def check(spec, kind: str, i: int, known: set[str] = KNOWN_LOCAL_MINIMA) -> None:
    where = f"{spec.name} ({kind} zone, i = {i}, {spec.mesh}, edges {spec.plate.edges})"
    try:
        best, minimisers, rtol = reference(spec, i)
    except ValueError as err:
        # Refused at assembly: b(w, w) vanishes identically. Check it independently: the
        # dense B of the plate model is round-off against the membrane force t*sigma.
        assert "no positive buckling load" in str(err), err
        model = plate_model(spec)
        assert np.abs(dense(model.B)).max() <= 1e-10 * membrane_force_scale(spec), where
        model.destroy()
        return
    if not math.isfinite(best):
        # No contact set has an admissible mode with a positive load (the load does not
        # buckle this plate on this coarse mesh, or the obstacle prevents it): the solver
        # must say so, not return a load.
        with pytest.raises(
            (ValueError, NoAdmissibleModeError), match=r"no positive buckling load|no admissible"
        ):
            solve(spec, MPI.COMM_SELF)
        return
    with solve(spec, MPI.COMM_SELF) as analysis:
        result, cert = analysis.result, analysis.certificate
        assert cert is not None and cert.kkt, (where, cert)
        assert cert.feasible
        load = result.critical_load_Pa
        assert analysis.solution is not None
        z = tuple(int(k) for k in analysis.solution.active)
    # The bracket is valid: lower bound <= global minimum <= load found.
    assert cert.lower_bound <= best * (1 + rtol), where
    assert load >= best * (1 - rtol), where
    agrees = abs(load - best) <= rtol * best and z in minimisers
    if spec.name in known:
        assert not agrees and not cert.global_optimum_proven, where
        return
    assert abs(load - best) <= rtol * best, f"{where}: {load!r} vs exhaustive {best!r}"
    assert z in minimisers, f"{where}: Z = {z}, exhaustive minimisers {minimisers}"


def plate_model(spec) -> PlateModel:
    """The plate's matrices, assembled without the problem's checks."""
    msh, tags = create_plate_mesh(spec.plate, spec.mesh, MPI.COMM_SELF)
    prestress = solve_prestress(msh, tags, spec.plate, spec.material, 1)
    return PlateModel(msh, tags, spec.plate, spec.material, prestress, spec.solver.shear)
