"""One problem file's analysis, a plate's or a section's: the one place that tells them apart.

A problem file describes a plate (:class:`~unibuckle_fenicsx.spec.ProblemSpec`, solved by
:func:`~unibuckle_fenicsx.analysis.solve`) or, with a ``[section]`` table, a box or a tube
(:class:`~unibuckle_fenicsx.spec.section.SectionProblemSpec`, solved by
:func:`~unibuckle_fenicsx.section_analysis.solve_section`). ``unibuckle solve`` and
``unibuckle sweep`` both solve whatever the file describes through :func:`analyse`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from mpi4py import MPI

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.spec.section import SectionProblemSpec

if TYPE_CHECKING:  # pragma: no cover
    from unibuckle_fenicsx.analysis import Analysis
    from unibuckle_fenicsx.section_analysis import SectionAnalysis
    from unibuckle_fenicsx.spec import ProblemSpec

__all__ = ["analyse"]


def analyse(
    spec: ProblemSpec | SectionProblemSpec,
    comm: MPI.Comm = MPI.COMM_WORLD,
    *,
    candidate_parallel: bool = False,
) -> Analysis | SectionAnalysis:
    """The critical state of ``spec``: a section's if it is one, else a plate's.

    Args:
        spec: A plate's problem or a section's.
        comm: Communicator; the mesh is distributed over it.
        candidate_parallel: A plate's enumeration shared among the ranks, each with a
            serial copy of the plate (:func:`~unibuckle_fenicsx.analysis.solve`); a
            section is not enumerated: True is refused for one.

    Returns:
        The analysis (its ``result`` is the JSON's numbers); the caller destroys it (or
        uses ``with``).

    Raises:
        InputError: ``candidate_parallel`` for a section, or what the solve refuses.

    Note:
        Collective on ``comm``.
    """
    # Looked up at the call, as the command line's imports: DOLFINx loads on the first
    # solve, and the module's own solve is called (a test may replace it).
    from unibuckle_fenicsx import analysis, section_analysis

    if isinstance(spec, SectionProblemSpec):
        if candidate_parallel:
            raise InputError(
                "--candidate-parallel shares a plate's enumeration among the ranks; a "
                "section is not enumerated (its mesh is distributed): leave it out"
            )
        return section_analysis.solve_section(spec, comm)
    return analysis.solve(spec, comm, candidate_parallel=candidate_parallel)
