r"""A stress family: seeded random plates of every kind the input schema describes.

Edge supports (simply supported, soft, clamped, free), uniform in-plane stress states
with compression, shear or both, t/b from 1e-4 to 0.1, aspect ratio 0.5 to 5, and zones
that touch an edge, are one node wide or cover the whole plate (``tests/support/families.py``).
Every problem is solved as a user would (``unibuckle_fenicsx.solve``, method
"active-set", certificate on) and must return a certified KKT point without raising, a
valid bracket of the global minimum, and the load and contact set of the exhaustive
minimum over all 2^i contact sets, computed independently with dense linear algebra
(``tests/support/exhaustive.py``), to 1e-8, or to ten times the spread of independent solves of
the plain pencil when conditioning makes that larger. The exceptions are listed in
:data:`support.stress.KNOWN_LOCAL_MINIMA` (a KKT point above the minimum, which must then not be
claimed proven).

Where no contact set has an admissible mode with a positive load (the load does not
buckle the plate on so coarse a mesh, or the obstacle prevents it), the solver must say
so with a clear error instead of returning a load; where b(w, w) vanishes identically,
it refuses the plate at assembly (checked on independently assembled dense matrices).

The default run takes the first :data:`support.stress.SAMPLE` problems; ``-m stress`` runs
all :data:`support.stress.FAMILY_SIZE`.
"""

from __future__ import annotations

from mpi4py import MPI

import pytest

from support.stress import FAMILY, SAMPLE, check

serial = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="dense reference is serial")


@serial
@pytest.mark.parametrize(
    ("spec", "kind", "i"), FAMILY[:SAMPLE], ids=[s.name for s, *_ in FAMILY[:SAMPLE]]
)
def test_stress_sample(spec, kind, i):
    """The first problems of the family: certified, and equal to the exhaustive minimum."""
    check(spec, kind, i)


@serial
@pytest.mark.stress
@pytest.mark.parametrize(
    ("spec", "kind", "i"), FAMILY[SAMPLE:], ids=[s.name for s, *_ in FAMILY[SAMPLE:]]
)
def test_stress_family(spec, kind, i):
    """The rest of the family (``-m stress``)."""
    check(spec, kind, i)
