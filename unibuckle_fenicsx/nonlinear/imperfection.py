"""The imperfection of the nonlinear analysis: a linear mode moved onto the von Kármán plate.

The imperfection is the linear free mode or the unilateral mode; with the obstacle it is
pushed strictly off it (:data:`PUSH_OFF` times the deflection under a uniform pressure,
which is negative inside the plate): a shape touching the obstacle with zero reaction
stalls the active set.
"""

from __future__ import annotations

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import dolfinx.fem.petsc
import ufl

from unibuckle_fenicsx.analysis import Analysis
from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.la.options import Prefix, set_options
from unibuckle_fenicsx.model.contact import ContactSetManager
from unibuckle_fenicsx.model.problem import Problem, UnilateralProblem
from unibuckle_fenicsx.nonlinear.model import THETA_SUB, VonKarmanPlate

__all__ = ["PUSH_OFF", "check_gaps", "embed", "imperfection_shape", "to_linear_space"]

#: Weight of the uniform-pressure deflection added to a mode to keep the imperfection
#: strictly off the obstacle (relative, both shapes scaled to max |w| = 1).
PUSH_OFF = 1e-2
#: Linear solve of the push-off shape (prefix ``unibuckle_nl_shape_``).
SHAPE_LU: dict[str, str | float | int | bool] = {
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
    "ksp_error_if_not_converged": True,
}


def to_linear_space(
    plate: VonKarmanPlate, x: dolfinx.fem.Function, problem: Problem
) -> dolfinx.fem.Function:
    """(w, theta) of the scaled state ``x`` in physical units on the linear (w, theta) space."""
    W = problem.model.W
    out = dolfinx.fem.Function(W, name="deflection")
    t = plate.thickness
    for sub_x, sub_w, factor in ((1, 0, t), (THETA_SUB, 1, 1.0)):
        source = x.sub(sub_x).collapse()
        Vt, dofs = W.sub(sub_w).collapse()
        target = dolfinx.fem.Function(Vt)
        target.interpolate(source)
        out.x.array[dofs[0]] = factor * target.x.array
    out.x.scatter_forward()
    return out


def embed(
    plate: VonKarmanPlate, shape: dolfinx.fem.Function, problem: Problem, amplitude: float
) -> None:
    """x0 = (0, amplitude * w / t, amplitude * theta) from a linear (w, theta) shape."""
    x0 = plate.x0
    x0.x.array[:] = 0.0
    for sub_w, sub_x, factor in ((0, 1, amplitude / plate.thickness), (1, THETA_SUB, amplitude)):
        source = shape.sub(sub_w).collapse()
        Vt, dofs = plate.W.sub(sub_x).collapse()
        target = dolfinx.fem.Function(Vt)
        target.interpolate(source)
        x0.x.array[dofs[0]] = factor * target.x.array
    x0.x.scatter_forward()


def _pressure_shape(problem: Problem, sign: float = 1.0) -> dolfinx.fem.Function:
    """Deflection under a uniform pressure away from the obstacles (linear plate), max |w| = 1.

    ``sign`` = +1 (obstacles above): downward, w <= 0; -1 (below): upward.
    """
    model = problem.model
    z, _ = ufl.split(ufl.TestFunction(model.W))
    f = dolfinx.fem.petsc.assemble_vector(dolfinx.fem.form(-sign * z * ufl.dx))
    f.ghostUpdate(addv=True, mode="reverse")  # ADD_VALUES, SCATTER_REVERSE
    dolfinx.fem.petsc.set_bc(f, model.bcs)
    ksp = PETSc.KSP().create(problem.comm)  # type: ignore[arg-type]
    ksp.setOperators(model.A)
    set_options(ksp, Prefix.NONLINEAR_SHAPE, SHAPE_LU)
    p = dolfinx.fem.Function(model.W, name="pressure_shape")
    try:
        ksp.solve(f, p.x.petsc_vec)
    finally:
        ksp.destroy()
        f.destroy()
    p.x.scatter_forward()
    p.x.petsc_vec.scale(1.0 / problem.max_abs_w(p.x.petsc_vec))
    p.x.scatter_forward()
    return p


def _orientation(problem: Problem, mode: dolfinx.fem.Function) -> float:
    """A partition-independent sign: that of the integral of w times an asymmetric weight."""
    (x0, y0), (x1, y1) = problem.spec.plate.corners
    xs = ufl.SpatialCoordinate(problem.mesh)
    weight = 1.0 + (xs[0] - x0) / (x1 - x0) + 0.37 * (xs[1] - y0) / (y1 - y0)
    w, _ = ufl.split(mode)
    value = dolfinx.fem.assemble_scalar(dolfinx.fem.form(weight * w * ufl.dx))
    value = problem.comm.allreduce(value, op=MPI.SUM)
    return -1.0 if value > 0.0 else 1.0  # mostly downward


def imperfection_shape(
    linear: Analysis, shape: str, obstacle: bool
) -> tuple[dolfinx.fem.Function, str]:
    """The imperfection's (w, theta) on the linear space, max |w| = 1, and its name.

    With the obstacle: w < 0 at every zone node (pushed off by :data:`PUSH_OFF` times the
    uniform-pressure deflection).

    Raises:
        ValueError: "unilateral" without an obstacle; "free" with an obstacle when the
            free mode crosses it whichever its sign.

    Note:
        Collective.
    """
    problem = linear.problem
    if not (obstacle and isinstance(problem, UnilateralProblem)):
        if shape == "unilateral":
            raise InputError('shape = "unilateral" needs a problem with its obstacle')
        out = dolfinx.fem.Function(problem.model.W, name="imperfection_shape")
        out.x.array[:] = linear.free_mode.x.array
        out.x.array[:] *= _orientation(problem, out)
        return out, "free"
    name = "unilateral" if shape == "auto" else shape
    if name == "unilateral" and linear.solution is None:
        raise InputError('shape = "unilateral" needs a problem with its obstacle')
    out = dolfinx.fem.Function(problem.model.W, name="imperfection_shape")
    if name == "unilateral":
        out.x.array[:] = linear.mode.x.array  # oriented: w <= 0 in the zone
    else:
        out.x.array[:] = linear.free_mode.x.array
        _orient_off(problem.contact, out)
    _push_off(problem, out, name)
    return out, name


def _orient_off(contact: ContactSetManager, out: dolfinx.fem.Function) -> None:
    """Give the free mode ``out`` the sign with the lower max over the zone, in place.

    Raises:
        InputError: It crosses the obstacle whichever its sign.

    Note:
        Collective.
    """
    values = contact.values(out.x.petsc_vec)
    if -values.min() < values.max():  # the sign with the lower max over the zone
        out.x.array[:] *= -1.0
        values = -values
    if values.max() > 0.0:
        raise InputError(
            'shape = "free": the free mode crosses the obstacle whichever its sign '
            f"(w > 0 at {int((values > 0).sum())} of the {contact.size} zone nodes); "
            'use shape = "unilateral"'
        )


def _push_off(problem: UnilateralProblem, out: dolfinx.fem.Function, name: str) -> None:
    """Push the shape ``out`` off the obstacles (:data:`PUSH_OFF`), max |w| = 1, in place.

    Raises:
        InputError: Obstacles on both sides, or the shape still touches one.

    Note:
        Collective.
    """
    contact = problem.contact
    sides = {float(v) for v in contact.signs}
    if len(sides) != 1:
        raise InputError(
            "the nonlinear analysis pushes the imperfection off the obstacles by a uniform "
            "pressure: it needs every obstacle on one side of the plate (all above or all "
            "below)"
        )
    p = _pressure_shape(problem, sides.pop())
    out.x.petsc_vec.axpy(PUSH_OFF, p.x.petsc_vec)
    out.x.scatter_forward()
    out.x.petsc_vec.scale(1.0 / problem.max_abs_w(out.x.petsc_vec))
    out.x.scatter_forward()
    worst = float(contact.values(out.x.petsc_vec).max())
    if worst >= 0.0:
        raise InputError(
            f'the imperfection shape "{name}" touches the obstacle (w = {worst:.3g} '
            "max|w| at a zone node after the push-off)"
        )


def check_gaps(plate: VonKarmanPlate, imperfection: float) -> None:
    """Refuse an imperfection that reaches an obstacle across its gap (collective)."""
    if not plate.contact.gaps.any():
        return  # no gap, or no obstacle
    clearance = plate.zone_clearance(plate.x0)
    gapped = plate.contact.gaps > 0
    if clearance[gapped].max() >= 0.0:
        raise InputError(
            f"obstacle.gap: the imperfection (delta = {imperfection:g}, max |w0| = "
            f"{imperfection * plate.thickness:.3g} m) reaches an obstacle across its gap "
            f"(smallest gap {plate.contact.gaps[gapped].min():.3g} m): lower the "
            "imperfection or widen the gap"
        )
