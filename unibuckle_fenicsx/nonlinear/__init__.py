"""Geometrically nonlinear (von Kármán) validation of the critical state.

:func:`solve_nonlinear` follows the load path of the imperfect plate against the obstacle
(:mod:`~unibuckle_fenicsx.nonlinear.model`: the plate and its SNES VI solver;
:mod:`~unibuckle_fenicsx.nonlinear.imperfection`: the imperfection;
:mod:`~unibuckle_fenicsx.nonlinear.path`: load stepping;
:mod:`~unibuckle_fenicsx.nonlinear.estimators`: Southwell and inflection loads;
:mod:`~unibuckle_fenicsx.nonlinear.choices`: the named choices;
:mod:`~unibuckle_fenicsx.nonlinear.options`: the options). Importing this package
is cheap: the names below load their module (and DOLFINx, PETSc) on first use.
"""

from importlib import import_module
from typing import Any

#: Where each public name lives.
_HOMES = {
    "CONTROLS": "choices",
    "SHAPES": "choices",
    "inflection_load": "estimators",
    "southwell_load": "estimators",
    "southwell_window": "estimators",
    "VonKarmanPlate": "model",
    "NonlinearAnalysis": "path",
    "NonlinearOptions": "options",
    "NonlinearResult": "path",
    "PathPoint": "path",
    "solve_nonlinear": "path",
}

__all__ = sorted(_HOMES)


def __getattr__(name: str) -> Any:
    """The public name ``name``, imported from its module on first use."""
    if name in _HOMES:
        return getattr(import_module(f"{__name__}.{_HOMES[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
