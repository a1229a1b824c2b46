"""unibuckle_fenicsx: unilateral buckling of thin plates with FEniCSx.

Importing the package does not import PETSc, SLEPc, DOLFINx or pyvista; import
:mod:`unibuckle_fenicsx.solver` (``solve``) for the computations.
"""

from unibuckle_fenicsx.cases import CASES, paper_case
from unibuckle_fenicsx.config import (
    EdgeSpec,
    Material,
    MeshSpec,
    ObstacleSpec,
    PlateSpec,
    ProblemSpec,
    SolverSpec,
    load_toml,
)

__version__ = "0.1.0"

__all__ = [
    "CASES",
    "EdgeSpec",
    "Material",
    "MeshSpec",
    "ObstacleSpec",
    "PlateSpec",
    "ProblemSpec",
    "SolverSpec",
    "__version__",
    "load_toml",
    "paper_case",
]
