"""unibuckle_fenicsx: unilateral buckling of thin plates with FEniCSx.

Importing the package does not import PETSc, SLEPc, DOLFINx or pyvista:
``unibuckle_fenicsx.solve`` (:func:`unibuckle_fenicsx.analysis.solve`) imports them on
first use, as do the sections' ``SectionParameters``
(:class:`unibuckle_fenicsx.model.shell.section.SectionParameters`) and ``solve_section``
(:func:`unibuckle_fenicsx.section_analysis.solve_section`).
"""

from typing import Any

from unibuckle_fenicsx.spec import (
    EdgeSpec,
    Material,
    MeshSpec,
    ObstacleSpec,
    PlateSpec,
    ProblemSpec,
    SectionProblemSpec,
    SolverSpec,
    load_toml,
    problem_from_dict,
    problem_to_dict,
    section_from_dict,
)
from unibuckle_fenicsx.spec.cases import CASES, paper_case

__version__ = "0.1.0"

__all__ = [
    "CASES",
    "EdgeSpec",
    "Material",
    "MeshSpec",
    "ObstacleSpec",
    "PlateSpec",
    "ProblemSpec",
    "SectionParameters",
    "SectionProblemSpec",
    "SolverSpec",
    "__version__",
    "load_toml",
    "paper_case",
    "problem_from_dict",
    "problem_to_dict",
    "section_from_dict",
    "solve",
    "solve_section",
]


def __getattr__(name: str) -> Any:
    """Lazy ``solve`` and sections: the computations import DOLFINx, PETSc and SLEPc."""
    if name == "solve":
        from unibuckle_fenicsx.analysis import solve

        return solve
    if name == "solve_section":
        from unibuckle_fenicsx.section_analysis import solve_section

        return solve_section
    if name == "SectionParameters":
        from unibuckle_fenicsx.model.shell.section import SectionParameters

        return SectionParameters
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
