"""Geometrically nonlinear (von Kármán) validation of the critical state.

:func:`solve_nonlinear` follows the load path of the imperfect plate against the obstacle
(:mod:`~unibuckle_fenicsx.nonlinear.model`: the plate and its SNES VI solver;
:mod:`~unibuckle_fenicsx.nonlinear.imperfection`: the imperfection;
:mod:`~unibuckle_fenicsx.nonlinear.path`: load stepping;
:mod:`~unibuckle_fenicsx.nonlinear.estimators`: Southwell and inflection loads).
Importing this package imports DOLFINx and PETSc.
"""

from unibuckle_fenicsx.nonlinear.estimators import (
    inflection_load,
    southwell_load,
    southwell_window,
)
from unibuckle_fenicsx.nonlinear.model import CONTROLS, VonKarmanPlate
from unibuckle_fenicsx.nonlinear.path import (
    SHAPES,
    NonlinearAnalysis,
    NonlinearError,
    NonlinearOptions,
    NonlinearResult,
    PathPoint,
    solve_nonlinear,
)

__all__ = [
    "CONTROLS",
    "SHAPES",
    "NonlinearAnalysis",
    "NonlinearError",
    "NonlinearOptions",
    "NonlinearResult",
    "PathPoint",
    "VonKarmanPlate",
    "inflection_load",
    "solve_nonlinear",
    "southwell_load",
    "southwell_window",
]
