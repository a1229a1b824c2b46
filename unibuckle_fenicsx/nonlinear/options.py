r"""The nonlinear analysis' options, importable without DOLFINx (the command line's).

:class:`NonlinearOptions` is a frozen msgspec Struct like the problem file's tables: each
option's range is in its type's ``Meta``, so a bad value is refused when the options are
made, with a message that names the option and its range
(:class:`~unibuckle_fenicsx.errors.InputError`, exit status 2 from the command line).
"""

from __future__ import annotations

import math
from typing import Annotated, ClassVar, Literal

from msgspec import Meta

from unibuckle_fenicsx.nonlinear.choices import Control, Shape
from unibuckle_fenicsx.spec.base import Table

__all__ = ["NonlinearOptions"]

Fraction = Annotated[float, Meta(gt=0.0, le=1.0)]


class NonlinearOptions(Table, frozen=True):
    r"""Options of the nonlinear analysis.

    Args:
        imperfection: :math:`\delta`, the imperfection's amplitude max :math:`|w_0|`
            relative to the thickness, in (0, 1].
        shape: Imperfection shape, one of :data:`~unibuckle_fenicsx.nonlinear.choices.SHAPES`.
        control: "load" (edge traction :math:`\lambda`, adaptive steps) or
            "displacement" (end shortening of the loaded edges; :math:`\lambda` from the
            edge reactions; a uniaxial compression only).
        obstacle: Keep the problem's obstacle (False: the same plate without it).
        max_load: Stop the path at this multiple of the linear critical load, in (0, 5].
        max_step: Largest step, relative to the linear critical load (or to the flat
            plate's end shortening under it), in (0, 1].
        min_step: Smallest step before giving up, relative as ``max_step``, in
            (0, max_step].
        deflection_step: Target relative change of max |w| per step, in (0, 1].
        max_steps: Largest number of accepted steps, >= 1.
        degree: Lagrange degree of the in-plane displacement (1 or 2); None: the
            problem's ``solver.prestress_degree``.
    """

    KEY: ClassVar[str] = ""
    imperfection: Fraction = 1e-3
    shape: Shape = "auto"
    control: Control = "load"
    obstacle: bool = True
    max_load: Annotated[float, Meta(gt=0.0, le=5.0)] = 1.2
    max_step: Fraction = 0.05
    min_step: Annotated[float, Meta(gt=0.0)] = 1e-5
    deflection_step: Fraction = 0.1
    max_steps: Annotated[int, Meta(ge=1)] = 400
    degree: Annotated[Literal[1, 2] | None, Meta(extra={"form": "1 or 2"})] = None

    def __post_init__(self) -> None:
        # A non-finite number is refused as such (not as out of its range).
        for name in self.__struct_fields__:
            value = getattr(self, name)
            if isinstance(value, float) and not math.isfinite(value):
                raise self.error(name, f" must be a finite number, got {value!r}")
        super().__post_init__()

    def check(self) -> None:
        """The smallest step is at most the largest."""
        if self.min_step > self.max_step:
            raise self.error(
                "min_step",
                f" must lie in (0, max_step = {self.max_step}], got {self.min_step!r}",
            )
