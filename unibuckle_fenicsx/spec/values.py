"""Names, unit systems and the scalar checks of the problem description.

The checks here serve the frozen dataclasses of the Python API (built directly in code,
not only from a file): each names the key and the allowed range.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.errors import InputError

#: Edge names of a rectangular plate, in facet-tag order 1..4.
EDGE_NAMES = ("left", "right", "bottom", "top")
#: Transverse (bending) conditions. "simply_supported" is the *hard* support of a
#: Reissner-Mindlin plate (w = 0 and tangential rotation = 0); "soft" fixes w only.
BENDING_SUPPORTS = ("simply_supported", "simply_supported_soft", "clamped", "free")
#: In-plane conditions for the prestress solve.
INPLANE_SUPPORTS = ("free", "clamped", "roller")
#: Unilateral solution methods.
METHODS = ("auto", "enumerate", "interior-point", "active-set", "penalty")
#: Unit systems of a problem file: name -> (metres per length unit, pascals per stress
#: unit, stress unit's name). Forces follow (N for both).
UNITS: dict[str, tuple[float, float, str]] = {
    "SI": (1.0, 1.0, "Pa"),
    "mm-N-MPa": (1e-3, 1e6, "MPa"),
}

Predicate = Callable[[npt.NDArray[np.float64]], npt.NDArray[np.bool_]]


def _number(name: str, value: Any) -> float:
    """``value`` as a finite float; a string, a boolean or NaN/inf is refused."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise InputError(f"{name} must be a number, got {value!r} ({type(value).__name__})")
    value = float(value)
    if not math.isfinite(value):
        raise InputError(f"{name} must be a finite number, got {value!r}")
    return value


def _integer(name: str, value: Any, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < minimum:
        raise InputError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def _boolean(name: str, value: Any) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise InputError(f"{name} must be true or false, got {value!r} ({type(value).__name__})")
    return bool(value)


def _stress(name: str, value: Any) -> float | tuple[float, float]:
    """An edge stress: a number, or a pair ``[start, end]`` of numbers (linear along the edge)."""
    if isinstance(value, list | tuple):
        if len(value) != 2:
            raise InputError(
                f"{name} must be a number or a pair [start, end] (linear along the edge), "
                f"got {value!r}"
            )
        return (_number(name, value[0]), _number(name, value[1]))
    return _number(name, value)


def stress_ends(value: float | tuple[float, float]) -> tuple[float, float]:
    """(start, end) of an edge stress: the pair itself, or the number twice."""
    if isinstance(value, tuple):
        return value
    return (value, value)


def _choice(name: str, value: Any, choices: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value not in choices:
        raise InputError(f"{name} must be one of {choices}, got {value!r}")
    return value


#: Name of the holes' boundary part in ``[edges.*]``.
HOLES = "holes"


#: Sides of an obstacle: "above" (on the +w side: w <= 0 in its zone), "below" (w >= 0);
#: "both" only for a foundation (a bilateral Winkler foundation, springs everywhere).
SIDES = ("above", "below", "both")

Box = tuple[tuple[float, float], tuple[float, float]]


def _box(name: str, value: Any) -> Box:
    """A box [[xmin, xmax], [ymin, ymax]] of finite numbers, min <= max."""
    try:
        (x0, x1), (y0, y1) = value
    except (TypeError, ValueError):
        raise InputError(f"{name} must be [[xmin, xmax], [ymin, ymax]], got {value!r}") from None
    box = ((_number(name, x0), _number(name, x1)), (_number(name, y0), _number(name, y1)))
    if box[0][0] > box[0][1] or box[1][0] > box[1][1]:
        raise InputError(f"{name} needs xmin <= xmax and ymin <= ymax, got {value!r}")
    return box


Temperature = float | tuple[float, float, float]


def _temperature(name: str, value: Any) -> Temperature:
    """A temperature rise: a number (K), or [T0, dT/dx, dT/dy] (K, K/m) for a linear field."""
    if isinstance(value, list | tuple):
        if len(value) != 3:
            raise InputError(
                f"{name} must be a number (a uniform rise, K) or [T0, dT/dx, dT/dy] (the "
                f"linear field T0 + dT/dx x + dT/dy y, K and K/m), got {value!r}"
            )
        return (_number(name, value[0]), _number(name, value[1]), _number(name, value[2]))
    return _number(name, value)


def temperature_field(value: Temperature) -> tuple[float, float, float]:
    """(T0, dT/dx, dT/dy) of a temperature rise."""
    return value if isinstance(value, tuple) else (value, 0.0, 0.0)


#: Kinds of point restraint: w = 0, the obstacle's cone at the point, or a spring.
POINT_KINDS = ("bilateral", "one-sided", "spring")


def _pair(name: str, value: Any) -> tuple[float, float]:
    """A pair [a, b] of finite numbers."""
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise InputError(f"{name} must be a pair [x, y] of numbers, got {value!r}")
    return (_number(name, value[0]), _number(name, value[1]))
