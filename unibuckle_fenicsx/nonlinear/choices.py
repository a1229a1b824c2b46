"""The nonlinear analysis' named choices, importable without DOLFINx (the command line's)."""

from __future__ import annotations

import typing
from typing import Literal

__all__ = ["CONTROLS", "SHAPES", "Control", "Shape"]

#: Path controls: the edge load, or the end shortening of the loaded edges.
Control = Literal["load", "displacement"]
#: Imperfection shapes: the linear free mode, the unilateral mode, or "auto" (the
#: unilateral mode with the obstacle, the free mode without).
Shape = Literal["auto", "free", "unilateral"]
#: The names of :data:`Control`'s choices.
CONTROLS: tuple[str, ...] = typing.get_args(Control)
#: The names of :data:`Shape`'s choices.
SHAPES: tuple[str, ...] = typing.get_args(Shape)
