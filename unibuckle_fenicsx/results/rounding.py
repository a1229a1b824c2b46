"""Records for version control: a result's numbers to the digits every machine agrees on.

A result's JSON form (:meth:`~.records.BucklingResult.as_dict`) holds what the run did
on this machine (its eigen solves, times, round-off); :func:`record` keeps what the
problem decides, its results rounded to :data:`RECORD_DIGITS` significant digits and
its input exact (:data:`EXACT`), and :func:`rounded` is what a figure draws. The demos
write their records with them.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = ["EXACT", "RECORD_DIGITS", "record", "rounded"]

#: Significant digits of the numbers a record keeps (:func:`record`): the loads carry
#: about ten (the eigen solver's tolerance, 1e-10) and double precision fixes them to
#: 1e-13 on the paper's plate, 1e-9 to 1e-8 on thin ones (``load_resolution``); mode
#: values about eight. Eight keeps what every quantity carries and drops its rounding.
RECORD_DIGITS = 8
#: What a record leaves out: what depends on the machine (its BLAS kernels and threads,
#: the rank count, the clock), not on the problem. The algorithm's path (counts of eigen
#: solves and factorisations, the sets and loads it visited: on symmetric or thin
#: plates rounding decides between contact sets of equal load), round-off diagnostics
#: (residuals, margins, the load's resolution), times, versions, the rank count and the
#: partition's DOF numbering.
RUN_DEPENDENT = frozenset(
    {
        "eigensolves", "details", "timings", "wall_time_s", "method_chosen_by", "versions",
        "mpi_size", "contact_dofs", "load_resolution", "rejected_steps", "solves_cold",
        "solves_warm", "max_free_residual", "max_complementarity", "max_zone_w_m",
        "free_eigen_error", "free_eigen_iterations",
    }
)  # fmt: skip
#: Of a certificate, the verdict (its margins and residuals are round-off).
CERTIFICATE_VERDICT = (
    "feasible", "kkt", "smallest_of_reduced", "global_optimum_proven", "proven_by", "status",
    "negative_eigenvalues", "tolerance",
)  # fmt: skip
#: What a record keeps exact: the problem it solved (a result's ``input``, a sweep line's
#: ``point``). It is the same on every machine, and re-running a record's input must give
#: the same problem: ``mesh.size`` = b/12 rounded to 0.083333333 meshes 13 cells across.
EXACT = frozenset({"input", "point"})
#: The contact set's keys, left out of a record with ``contact=False`` (the contact
#: force lists its pushes in the order of the set).
CONTACT_KEYS = ("contact_nodes", "contact_coordinates", "contact_indices", "contact_force")


def record(data: Any, *, contact: bool = True) -> Any:
    """``data`` (a result's JSON mapping, or any JSON value) as a record for version control.

    The same on every machine up to its last digit: the keys of :data:`RUN_DEPENDENT`
    left out at any depth, a certificate reduced to its verdict
    (:data:`CERTIFICATE_VERDICT`), the problem (:data:`EXACT`) kept as it is, every
    other number rounded to :data:`RECORD_DIGITS`
    significant digits, those of a list of numbers to the digits of its largest (a
    coordinate's rounding, 3e-19 beside 0.1, is then 0). A number that lies within its
    noise of a rounding boundary may still change its last digit between machines.

    Args:
        data: A JSON value (``BucklingResult.as_dict()``, a sweep's line, a demo's summary).
        contact: Keep the contact set; on thin plates nodes with both a zero deflection
            and a zero contact force (DESIGN: degenerate complementarity) fall in or out
            of it with rounding, at the same load: ``False`` leaves it out.
    """
    if isinstance(data, dict):
        out = {}
        for key, value in data.items():
            if key in RUN_DEPENDENT or (not contact and key in CONTACT_KEYS):
                continue
            if key in EXACT:
                out[key] = value
                continue
            if key == "certificate" and isinstance(value, dict):
                value = {k: value[k] for k in CERTIFICATE_VERDICT if k in value}
            out[key] = record(value, contact=contact)
        return out
    if isinstance(data, list | tuple):
        numbers = [v for v in data if isinstance(v, float)]
        if numbers and len(numbers) == len(data):
            return [_rounded(v, max(abs(x) for x in numbers)) for v in numbers]
        return [record(v, contact=contact) for v in data]
    if isinstance(data, float):
        return _rounded(data, abs(data))
    return data


def rounded(values: Any) -> npt.NDArray[np.float64]:
    """``values`` (an array) to :data:`RECORD_DIGITS` significant digits of the largest.

    What a figure draws: an antialiased line moves a pixel's shade for a change of
    1e-13 in its data, so a figure of the full numbers differs between machines where
    one of the rounded numbers does not.
    """
    array = np.asarray(values, dtype=float)
    finite = np.abs(array[np.isfinite(array)])
    scale = float(finite.max()) if finite.size else 0.0
    if scale == 0.0:
        return array
    return np.round(array, _decimals(scale)) + 0.0


def _decimals(scale: float) -> int:
    """Decimals that keep :data:`RECORD_DIGITS` significant digits of ``scale`` (> 0).

    Of ``scale`` itself at those digits: a normalised mode's largest value is 1 within
    rounding, 0.9999999999997 on one machine and 1.0000000000002 on another, and both
    must give the same decimals.
    """
    return RECORD_DIGITS - 1 - math.floor(math.log10(float(f"{scale:.{RECORD_DIGITS - 1}e}")))


def _rounded(value: float, scale: float) -> float:
    """``value`` to :data:`RECORD_DIGITS` significant digits of ``scale`` (0.0 for -0.0)."""
    if not math.isfinite(value) or scale == 0.0:
        return value
    return round(value, _decimals(scale)) + 0.0
