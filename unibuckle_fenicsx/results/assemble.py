"""The result of a solve, read off the live problem: the one place that turns objects into records.

:func:`assemble_result` reads the set-up problem, its free mode, the algorithm's solution
and its certificate, and returns a :class:`~.records.BucklingResult` that holds none of
them. It is collective (the contact DOFs are gathered); the records it builds are the
same on every rank.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from unibuckle_fenicsx.model.problem import UnilateralProblem
from unibuckle_fenicsx.model.zones import zone_report
from unibuckle_fenicsx.results.records import (
    BucklingResult,
    CertificateRecord,
    ContactForce,
    EdgeLoad,
    ResultDetails,
    split_route,
)
from unibuckle_fenicsx.spec import (
    ProblemSpec,
    problem_to_dict,
    stress_value,
    temperature_field,
)
from unibuckle_fenicsx.spec.checks import plate_model_note

if TYPE_CHECKING:  # pragma: no cover
    from unibuckle_fenicsx.algorithms import UnilateralSolution
    from unibuckle_fenicsx.certificate.certify import Certificate
    from unibuckle_fenicsx.model.problem import Mode, Problem

__all__ = ["assemble_result", "certificate_record", "record_contact", "versions"]


def assemble_result(
    problem: Problem,
    free: Mode,
    solution: UnilateralSolution | None,
    certificate: Certificate | None,
    *,
    wall_time_s: float,
    mpi_size: int,
    method_chosen_by: str = "",
) -> BucklingResult:
    """The result of ``problem``'s free mode and unilateral ``solution`` (None: no obstacle).

    Note:
        Collective on the problem's communicator (gathers the contact DOFs).
    """
    spec = problem.spec
    load = free.load if solution is None else solution.load
    result = BucklingResult(
        case=spec.name,
        method="free" if solution is None else solution.method,
        route=["free"] if solution is None else list(solution.route),
        critical_load_Pa=load,
        free_load_Pa=free.load,
        ratio_to_free=load / free.load,
        critical_force_N_per_m=_critical_force(spec, load),
        # k is a buckling coefficient of edge loads: none for a rise alone.
        buckling_coefficient_k=(problem.buckling_coefficient(load) if spec.plate.loaded else None),
        dofs=problem.model.num_dofs,
        mesh=(
            [problem.mesh.topology.index_map(2).size_global]
            if not problem.structured
            else [spec.mesh.nx, spec.mesh.ny]
        ),
        eigensolves=problem.free_solves + (0 if solution is None else solution.eigensolves),
        wall_time_s=wall_time_s,
        timings={**problem.timings, "total_s": wall_time_s},
        mpi_size=mpi_size,
        method_chosen_by=method_chosen_by,
        details=_details(problem, free),
        edge_loads={e.name: _edge_load(e) for e in spec.plate.edges},
        critical_load_factor=load,
        critical_temperature_K=_critical_temperature(spec, load),
        critical_total_temperature_K=_total_temperature(spec, load),
        units=spec.units,
        input=_input(spec),
        versions=versions(),
    )
    if not problem.tensionless:
        mode = free.function if solution is None else solution.candidate.mode
        result.load_resolution = problem.load_resolution(mode.x.petsc_vec, load)
    if spec.design is not None:
        from unibuckle_fenicsx.design import design_output

        result.design = design_output(spec, spec.design, load)
    if spec.all_obstacles:
        labels = [spec.obstacle_label(k) for k in range(len(spec.all_obstacles))]
        result.obstacle_zones = zone_report(problem.mesh, spec.all_obstacles, spec.plate, labels)
    if solution is None or certificate is None:
        result.lower_bound_Pa = result.upper_bound_Pa = free.load
        return result
    record_contact(result, problem, solution, certificate)
    if not certificate.global_optimum_proven:
        _design_at_lower_bound(result, spec, certificate.lower_bound)
    return result


def _critical_force(spec: ProblemSpec, load: float) -> float | None:
    """N = t sigma (N/m), sigma = load times the reference stress of k; None for a rise alone."""
    if not spec.plate.loaded:
        return None
    stress, _ = spec.plate.reference_load()
    return spec.plate.thickness * stress * load


def _design_at_lower_bound(result: BucklingResult, spec: ProblemSpec, lower: float) -> None:
    """The design output at the verified lower bound ``lower``: the safe values."""
    from unibuckle_fenicsx.design import DesignRecord, at_lower_bound

    design = result.design
    if spec.design is not None and isinstance(design, DesignRecord) and 0.0 < lower < math.inf:
        at_lower_bound(design, spec, spec.design, lower)


def record_contact(
    result: BucklingResult,
    problem: Problem,
    solution: UnilateralSolution,
    certificate: Certificate,
) -> None:
    """Fill in ``result``'s contact set, bracket, certificate and contact forces.

    The part of :func:`assemble_result` that reads the unilateral ``solution``; a
    section's result (:mod:`~unibuckle_fenicsx.section_analysis`) is filled in by it too.

    Note:
        Collective on the problem's communicator (gathers the contact DOFs).
    """
    unilateral = _contact(result, problem, solution)
    result.lower_bound_Pa = certificate.lower_bound
    result.upper_bound_Pa = (
        certificate.upper_bound if math.isfinite(certificate.upper_bound) else None
    )
    result.certificate = certificate_record(certificate)
    if solution.details is not None:
        result.details.run = solution.details
    if solution.lower_bound_by is not None:
        result.details.lower_bound_by = solution.lower_bound_by
    if solution.continued:
        result.details.continued = solution.continued
    if not problem.tensionless:
        result.contact_force = _contact_force(unilateral, solution, result.load_resolution)


def _details(problem: Problem, free: Mode) -> ResultDetails:
    """The free solve's report and the model's notes."""
    spec = problem.spec
    details = ResultDetails(
        free_eigen_error=free.eigen.error, free_eigen_iterations=free.eigen.iterations
    )
    if problem.model.points:
        details.point_restraints = [g.report() for g in problem.model.points]
    if spec.gapped_obstacles:
        details.gapped_obstacles = (
            f"{len(spec.gapped_obstacles)} obstacle(s) with a gap left out of the linear "
            "critical state (an infinitesimal buckle does not reach them); unibuckle "
            "nonlinear follows the plate onto them"
        )
    note = plate_model_note(spec.plate)
    if note is not None:
        details.plate_model = note
    return details


def _contact(
    result: BucklingResult, problem: Problem, solution: UnilateralSolution
) -> UnilateralProblem:
    """The contact set of ``solution`` into ``result`` (collective: the DOFs are gathered).

    Returns ``problem``, which has an obstacle.
    """
    if not isinstance(problem, UnilateralProblem):
        raise TypeError("assemble_result: a solution without an obstacle (an internal invariant)")
    contact = problem.contact
    active = solution.active
    rows = contact.removed_rows(active)
    result.constrained_nodes = problem.num_constrained
    result.contact_nodes = len(active)
    result.p_star = solution.p_star
    result.contact_indices = [int(k) for k in active]
    result.contact_coordinates = contact.coordinates[active].tolist()
    result.contact_dofs = sorted(
        int(r) for part in problem.comm.allgather(rows.tolist()) for r in part
    )
    return problem


def _contact_force(
    problem: UnilateralProblem, solution: UnilateralSolution, resolution: float | None
) -> ContactForce:
    """The obstacle's push at each contact node of the returned mode (N/m; collective).

    The mode is scaled to max |w| = 1 and oriented away from the obstacle, so the
    residual ``r = A u - lambda B u`` at a contact node is the obstacle's reaction on it
    with the sign of a pull: the push is ``-s_k r_k`` (``s_k`` the node's obstacle side).
    """
    r, au_inf, _ = problem.residual(solution.load, solution.candidate.mode.x.petsc_vec)
    push = -problem.contact.values(r)[solution.active]
    return ContactForce(
        push=[float(f) for f in push],
        resolution=None if resolution is None else float(resolution * au_inf),
    )


def certificate_record(cert: Certificate) -> CertificateRecord:
    """The record of the live certificate ``cert`` (its refuting mode's load only)."""
    return CertificateRecord(
        feasible=cert.feasible,
        feasibility_margin=cert.feasibility_margin,
        max_contact_force=cert.max_contact_force,
        max_contact_value=cert.max_contact_value,
        relative_residual=cert.relative_residual,
        tolerance=cert.tolerance,
        kkt=cert.kkt,
        smallest_of_reduced=cert.smallest_of_reduced,
        lower_bound_Pa=cert.lower_bound,
        upper_bound_Pa=cert.upper_bound,
        relative_gap=cert.relative_gap,
        global_optimum_proven=cert.global_optimum_proven,
        proven_by=cert.proven_by,
        status=cert.status,
        negative_eigenvalues=cert.negative_eigenvalues,
        refuting_load_Pa=None if cert.refuting_mode is None else cert.refuting_mode.load,
        copositivity=cert.copositivity,
        notes=list(cert.notes),
        split_route=split_route(
            cert.status,
            cert.proven_by,
            None if cert.copositivity is None else cert.copositivity.split,
        ),
    )


def _edge_load(edge: Any) -> EdgeLoad:
    """An edge's stresses per unit load, and its fixed part's when it has one."""
    load = EdgeLoad(
        normal_stress=stress_value(edge.normal_stress),
        shear_stress=stress_value(edge.shear_stress),
    )
    if edge.fixed_loaded:
        load.fixed_normal_stress = stress_value(edge.fixed_normal_stress)
        load.fixed_shear_stress = stress_value(edge.fixed_shear_stress)
    return load


def _critical_temperature(spec: ProblemSpec, load: float) -> float | None:
    """The critical rise: lambda times the scaled field's largest rise over the plate.

    The largest signed rise (the field is linear: its largest value lies on the
    boundary's vertices): where part of the plate cools, the heated part buckles it.
    """
    if not spec.load.thermal:
        return None
    T0, gx, gy = temperature_field(spec.load.temperature)
    rises = [T0 + gx * x + gy * y for x, y in spec.plate.boundary]
    return load * max(rises)


def _total_temperature(spec: ProblemSpec, load: float) -> float | None:
    """With a fixed rise: the largest total rise at the critical state (K), else None.

    ``fixed_factor`` times the fixed field plus lambda times the scaled one: a linear
    field, largest on a vertex of the boundary.
    """
    if not (spec.load.fixed_thermal and spec.load.fixed_factor):
        return None
    fixed = temperature_field(spec.load.fixed_temperature)
    scaled = temperature_field(spec.load.temperature)
    factor = spec.load.fixed_factor
    return max(
        factor * (fixed[0] + fixed[1] * x + fixed[2] * y)
        + load * (scaled[0] + scaled[1] * x + scaled[2] * y)
        for x, y in spec.plate.boundary
    )


def _input(spec: ProblemSpec) -> dict[str, object] | None:
    try:
        return problem_to_dict(spec)
    except ValueError:  # a predicate zone
        return None


def versions() -> dict[str, str]:
    """Versions of the package and of the libraries that computed the result."""
    import platform
    from importlib.metadata import PackageNotFoundError, version

    import numpy as np

    out = {"python": platform.python_version(), "numpy": np.__version__}
    # Distributions that can take part in a result (installed ones only): meshing (gmsh),
    # MPI, the SDP certificate (cvxpy, clarabel), the dense references (scipy).
    dists = (
        "unibuckle_fenicsx",
        "fenics-dolfinx",
        "petsc4py",
        "slepc4py",
        "fenics-basix",
        "mpi4py",
        "gmsh",
        "cvxpy",
        "clarabel",
        "scipy",
    )
    for dist in dists:
        try:
            out[dist] = version(dist)
        except PackageNotFoundError:
            pass
    try:
        import petsc4py
        import slepc4py
        from petsc4py import PETSc
        from slepc4py import SLEPc

        import dolfinx

        # The bindings' own versions: the PyPI wheel (dolfinx-solver-real) bundles them
        # under its own distribution name, where the loop above finds none.
        out.setdefault("petsc4py", petsc4py.__version__)
        out.setdefault("slepc4py", slepc4py.__version__)
        out["dolfinx"] = dolfinx.__version__
        out["PETSc"] = ".".join(str(v) for v in PETSc.Sys.getVersion())
        out["SLEPc"] = ".".join(str(v) for v in SLEPc.Sys.getVersion())
    except ImportError:  # pragma: no cover
        pass
    return out
