"""The nonlinear analysis' named choices, importable without DOLFINx (the command line's)."""

from __future__ import annotations

__all__ = ["CONTROLS", "SHAPES"]

#: Path controls: the edge load, or the end shortening of the loaded edges.
CONTROLS = ("load", "displacement")
#: Imperfection shapes: the linear free mode, the unilateral mode, or "auto" (the
#: unilateral mode with the obstacle, the free mode without).
SHAPES = ("auto", "free", "unilateral")
