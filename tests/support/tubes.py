"""The filled tube on which Krylov-Schur returned pairs that are no eigenpairs.

D = 0.1 m, t = 1 mm, L = 0.1 m, simply supported ends, a core (every wall node's
inward direction constrained): with every core direction removed, B (semidefinite)
loses most of its rank (docs/history/2026-11-30g-spurious.md).
"""

from __future__ import annotations

from unibuckle_fenicsx import SectionParameters


def filled_tube(mesh_size: float = 0.01) -> SectionParameters:
    """The filled tube's parameters at cells of ``mesh_size`` (10 mm: 2 112 DOFs)."""
    return SectionParameters(
        "tube", diameter=0.1, thickness=0.001, length=0.1, E=2.1e11, nu=0.3,
        mesh_size=mesh_size, ends="simply_supported", core=True,
    )  # fmt: skip
