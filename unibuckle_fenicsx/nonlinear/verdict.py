r"""What the load path says about the linear critical load, in words and as a status.

The knee of the imperfect plate's path, read off twice (Southwell, inflection), *agrees*
with a linear load when it lies within :data:`~unibuckle_fenicsx.tolerances.KNEE_RTOL` of
it: the linear load is then **validated**. A load further away validates nothing, whatever
else the path did.

With a gap between the plate and an obstacle there is no linear critical load to
validate: the linear state leaves the gapped obstacle out (an infinitesimal buckle does
not reach it), so its load is the free plate's, while the path reaches the obstacle at
a finite deflection. The knee then lies between the free load :math:`\lambda_{free}` and
the unilateral load with the gaps closed, :math:`\lambda_{c}(g = 0)` (the obstacle
stiffens the plate only once reached; a larger gap moves the knee towards the free load),
and where between depends on the gap and the imperfection. The verdict says so: both
loads read off must lie in :math:`[\lambda_{free}, \lambda_c(g = 0)]` (within the same
tolerance), and neither is called validated.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from unibuckle_fenicsx.spec import UNITS
from unibuckle_fenicsx.tolerances import KNEE_RTOL

__all__ = ["Verdict", "judge"]


@dataclass(frozen=True)
class Verdict:
    """The verdict on one path.

    Attributes:
        ok: The path is complete, both loads were read off it and agree with the linear
            load (or, with a gap, lie between the free and the gap-closed loads), and the
            contact conditions hold.
        validated: What the path validated (or, with a gap, found consistent).
        missing: What it did not, and why.
        gap: Whether the problem has a gapped obstacle (no single linear load).
    """

    ok: bool
    validated: list[str] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)
    gap: bool = False

    def summary(self, result: Any) -> str:
        """One line for the terminal: the verdict and the references it used."""
        if self.gap:
            head = (
                f"with a gap the knee lies between the free load "
                f"{_text(result.linear_critical_load_Pa, result)} and the unilateral load with "
                f"the gaps closed {_text(result.unilateral_load_Pa, result)}; no linear load is "
                "validated"
            )
        else:
            linear = _text(result.linear_critical_load_Pa, result)
            head = f"against the linear critical load {linear}"
        found = ", ".join(self.validated) or "nothing"
        word = "consistent" if self.gap else "validated"
        out = f"verdict ({head}): {word}: {found}"
        if self.missing:
            out += f"; not {word}: {', '.join(self.missing)}"
        return out


def _text(value: float | None, result: Any) -> str:
    """A load (Pa) in the problem file's units (``result.units``), as the summary gives it."""
    if value is None:
        return "(not computed)"
    scale, unit = UNITS[getattr(result, "units", "SI")][1:]
    return f"{value / scale:.6e} {unit}"


def judge(result: Any, max_load: float | None = None) -> Verdict:
    """The verdict on ``result`` (a :class:`~unibuckle_fenicsx.nonlinear.NonlinearResult`).

    Args:
        result: The path and the loads read off it.
        max_load: The --max-load asked for, for the message on an incomplete path
            (default: the options recorded in the result).
    """
    linear = result.linear_critical_load_Pa
    gap = bool(result.obstacle and result.gapped)
    upper = result.unilateral_load_Pa
    validated: list[str] = []
    missing: list[str] = []
    for name, load in (
        ("Southwell", result.southwell_load_Pa),
        ("inflection", result.inflection_load_Pa),
    ):
        if load is None:
            missing.append(f"the {name} load (the path stopped before it could be read)")
            continue
        relative = load / linear - 1.0
        if not gap:
            text = f"the {name} load {_text(load, result)} ({relative:+.1e} relative)"
            if abs(relative) <= KNEE_RTOL:
                validated.append(text)
            else:
                missing.append(
                    f"{text}: more than {KNEE_RTOL:.0%} from the linear load, which it does "
                    "not validate (a smaller --imperfection brings the knee closer to the "
                    "critical load)"
                )
            continue
        text = f"the {name} load {_text(load, result)} ({relative:+.1e} relative to the free load)"
        if upper is None:
            missing.append(f"{text}: the unilateral load with the gaps closed is unknown")
        elif linear * (1 - KNEE_RTOL) <= load <= upper * (1 + KNEE_RTOL):
            validated.append(text + " between the two")
        else:
            missing.append(f"{text}: outside [free, gaps closed] (tolerance {KNEE_RTOL:.0%})")
    check = result.contact_check
    if check.get("satisfied", True):
        validated.append("the contact conditions at the last converged state")
    else:
        missing.append(f"the contact conditions at the last converged state ({check})")
    if not result.completed:
        reached = result.path[-1]["load_Pa"] / linear if result.path else 0.0
        limit = max_load if max_load is not None else result.options.get("max_load")
        to = "its end" if limit is None else f"--max-load {limit:g} x the linear load"
        missing.append(f"the path from {reached:.4g} to {to} ({result.stop_reason})")
    return Verdict(not missing, validated, missing, gap)
