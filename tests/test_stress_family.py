r"""A stress family: seeded random plates of every kind the input schema describes.

Edge supports (simply supported, soft, clamped, free), uniform in-plane stress states
with compression, shear or both, t/b from 1e-4 to 0.1, aspect ratio 0.5 to 5, and zones
that touch an edge, are one node wide or cover the whole plate (``tests/families.py``).
Every problem is solved as a user would (``unibuckle_fenicsx.solve``, method
"active-set", certificate on) and must return a certified KKT point without raising, a
valid bracket of the global minimum, and the load and contact set of the exhaustive
minimum over all 2^i contact sets, computed independently with dense linear algebra
(``tests/exhaustive.py``), to 1e-8, or to ten times the spread of independent solves of
the plain pencil when conditioning makes that larger. The exceptions are listed in
:data:`KNOWN_LOCAL_MINIMA` (a KKT point above the minimum, which must then not be
claimed proven).

Where no contact set has an admissible mode with a positive load (the load does not
buckle the plate on so coarse a mesh, or the obstacle prevents it), the solver must say
so with a clear error instead of returning a load; where b(w, w) vanishes identically,
it refuses the plate at assembly (checked on independently assembled dense matrices).

The default run takes the first :data:`SAMPLE` problems; ``-m stress`` runs all
:data:`FAMILY_SIZE`.
"""

from __future__ import annotations

import math

from mpi4py import MPI

import numpy as np
import pytest
from exhaustive import (
    RTOL,
    dense,
    dense_free_load,
    dense_reduced_load,
    exhaustive_minimum,
    membrane_force_scale,
)
from families import stress_family

from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.errors import NoAdmissibleModeError
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.mesh import create_plate_mesh
from unibuckle_fenicsx.model.plate.model import PlateModel
from unibuckle_fenicsx.model.prestress import solve_prestress

FAMILY_SIZE = 200
SAMPLE = 20
serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense reference is serial")
FAMILY = stress_family(FAMILY_SIZE)


#: Problems of the family where the active-set answer is a genuine KKT point above the
#: global minimum; the certificate must not claim it proven. stress37 (5x3 mesh,
#: whole-plate obstacle, clamped / simply supported edges under pure shear, i = 8): the
#: active set stops at 372.96 MPa, the exhaustive minimum is 368.40 MPa (1.2 % lower).
#: stress166 (6x3, whole plate, two free edges, shear, i = 14): 3012.91 against
#: 2995.35 Pa (0.6 %).
KNOWN_LOCAL_MINIMA = {"stress37", "stress166"}


def _reference(spec, i: int) -> tuple[float, list[tuple[int, ...]], float]:
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


def _check(spec, kind: str, i: int, known: set[str] = KNOWN_LOCAL_MINIMA) -> None:
    where = f"{spec.name} ({kind} zone, i = {i}, {spec.mesh}, edges {spec.plate.edges})"
    try:
        best, minimisers, rtol = _reference(spec, i)
    except ValueError as err:
        # Refused at assembly: b(w, w) vanishes identically. Check it independently: the
        # dense B of the plate model is round-off against the membrane force t*sigma.
        assert "no positive buckling load" in str(err), err
        model = _plate_model(spec)
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


def _plate_model(spec) -> PlateModel:
    """The plate's matrices, assembled without the problem's checks."""
    msh, tags = create_plate_mesh(spec.plate, spec.mesh, MPI.COMM_SELF)
    prestress = solve_prestress(msh, tags, spec.plate, spec.material, 1)
    return PlateModel(msh, tags, spec.plate, spec.material, prestress, spec.solver.shear)


@serial
@pytest.mark.parametrize(
    ("spec", "kind", "i"), FAMILY[:SAMPLE], ids=[s.name for s, *_ in FAMILY[:SAMPLE]]
)
def test_stress_sample(spec, kind, i):
    """The first problems of the family: certified, and equal to the exhaustive minimum."""
    _check(spec, kind, i)


@serial
@pytest.mark.stress
@pytest.mark.parametrize(
    ("spec", "kind", "i"), FAMILY[SAMPLE:], ids=[s.name for s, *_ in FAMILY[SAMPLE:]]
)
def test_stress_family(spec, kind, i):
    """The rest of the family (``-m stress``)."""
    _check(spec, kind, i)
