r"""From a problem's description to a set-up problem, stage by stage.

:func:`build_problem` runs the stages below in order; each is a function of what the
previous ones made, testable alone, and each refusal of the input comes as early as the
information for it exists:

1. :func:`place_mesh`: the user's mesh (checked against the plate), or the memory
   estimate (:func:`~unibuckle_fenicsx.model.resources.check_memory`) and then the
   structured or gmsh mesh; the obstacle zones must hold mesh nodes.
2. :func:`solve_prestresses`: the membrane force per unit load, and that of the fixed
   part of the load (two in-plane solves).
3. :func:`build_plate`: the structural model and its pencil (A, B), with the springs of
   bilateral foundations.
4. :func:`check_pencil`: B is not round-off; a fixed load alone does not buckle the
   plate (:math:`A - B_{fixed}` positive definite).
5. :func:`build_eigensolver`: the pencil's eigen solver.
6. :func:`build_contact`: the contact manager of the one-sided obstacles, foundations
   and points (none without them).

A stage that fails destroys what the stages before it made (collectively: every rank
takes the same branch) before the error propagates.
"""

from __future__ import annotations

import functools
import logging
import time
from dataclasses import dataclass

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx

from msgspec.structs import replace

from unibuckle_fenicsx.errors import BilateralZoneError, EmptyZoneError, InputError, NumericalError
from unibuckle_fenicsx.la.eigen import EIGEN_OPTIONS, GEPSolver, lowest_eigenvalues
from unibuckle_fenicsx.la.factor import SymmetricFactorization
from unibuckle_fenicsx.la.options import Options, Prefix, push_run_options
from unibuckle_fenicsx.model.contact import (
    ContactSetManager,
    check_zone_has_nodes,
    foundation_springs,
)
from unibuckle_fenicsx.model.mesh import build_plate_mesh, check_user_mesh
from unibuckle_fenicsx.model.plate.model import PlateModel
from unibuckle_fenicsx.model.points import one_sided_conflicts, point_obstacles
from unibuckle_fenicsx.model.prestress import Prestress, solve_prestress
from unibuckle_fenicsx.model.problem import Problem, SetUp, UnilateralProblem
from unibuckle_fenicsx.model.resources import check_memory
from unibuckle_fenicsx.model.structure import StructuralModel
from unibuckle_fenicsx.spec import ProblemSpec
from unibuckle_fenicsx.spec.base import file_units
from unibuckle_fenicsx.tolerances import NULL_GEOMETRIC_STIFFNESS

logger = logging.getLogger(__name__)

__all__ = [
    "PlacedMesh",
    "build_contact",
    "build_eigensolver",
    "build_plate",
    "build_problem",
    "build_unilateral_problem",
    "check_pencil",
    "free_estimate",
    "place_mesh",
    "solve_prestresses",
]


@dataclass(frozen=True)
class PlacedMesh:
    """The mesh of a problem and what it says about the problem.

    Attributes:
        spec: The problem, its plate's edges tagged and a mesh file's corners its
            bounding box.
        mesh: The quadrilateral mesh.
        facet_tags: Its edge markers.
        comm: The mesh's communicator.
        structured: The structured rectangle of ``spec.mesh`` (coarser copies exist).
        custom: The mesh came from the user (no coarser copy can be made).
    """

    spec: ProblemSpec
    mesh: dolfinx.mesh.Mesh
    facet_tags: dolfinx.mesh.MeshTags
    comm: MPI.Comm
    structured: bool
    custom: bool


def place_mesh(
    spec: ProblemSpec,
    comm: MPI.Comm,
    mesh: dolfinx.mesh.Mesh | None = None,
    facet_tags: dolfinx.mesh.MeshTags | None = None,
) -> PlacedMesh:
    """Stage 1: the user's ``mesh`` checked, or ``spec``'s mesh built; its zones checked.

    Raises:
        InputError: A user mesh without facet tags, not quadrilateral, or off the plate;
            a mesh too large for the memory; a zone that holds no mesh node.

    Note:
        Collective on ``comm`` (a user mesh: on its own communicator).
    """
    if mesh is not None:
        if facet_tags is None:
            raise InputError(
                "facet_tags: a user mesh needs its edge facet tags (EdgeSpec.tag, or "
                "tags 1..4 for edges named left, right, bottom, top)"
            )
        if mesh.topology.cell_type != dolfinx.mesh.CellType.quadrilateral:
            raise InputError("mesh: the MITC plate element needs a quadrilateral mesh")
        check_user_mesh(mesh, facet_tags, spec.plate)
        placed = PlacedMesh(spec, mesh, facet_tags, mesh.comm, structured=False, custom=True)
    else:
        check_memory(spec, comm)
        built, tags, plate = build_plate_mesh(spec.plate, spec.mesh, comm, spec.all_obstacles)
        # A file's edges get their tags, its corners the mesh's bounding box.
        spec = replace(spec, plate=plate)
        structured = not spec.plate.meshed_by_gmsh
        placed = PlacedMesh(spec, built, tags, comm, structured=structured, custom=False)
    obstacles = spec.all_obstacles
    if obstacles:
        size = max(spec.plate.length, spec.plate.width)
        labels = [spec.obstacle_label(k) for k in range(len(obstacles))]
        check_zone_has_nodes(placed.mesh, obstacles, size, labels)
    return placed


def solve_prestresses(placed: PlacedMesh) -> tuple[Prestress, Prestress | None]:
    """Stage 2: the membrane force per unit load, and the fixed part's (or None).

    Note:
        Collective.
    """
    spec = placed.spec
    degree = spec.solver.prestress_degree
    scaled = solve_prestress(
        placed.mesh,
        placed.facet_tags,
        spec.plate,
        spec.material,
        degree,
        temperature=spec.load.temperature,
        plate_mesh=not placed.custom,
    )
    if not spec.has_fixed_load:
        return scaled, None
    fixed = solve_prestress(
        placed.mesh,
        placed.facet_tags,
        spec.plate.fixed_part(),
        spec.material,
        degree,
        temperature=spec.load.fixed_temperature,
        fixed=True,
        plate_mesh=not placed.custom,
    )
    return scaled, fixed


def build_plate(
    placed: PlacedMesh, prestress: Prestress, fixed_prestress: Prestress | None
) -> PlateModel:
    """Stage 3: the plate's pencil (A, B), with the springs of bilateral foundations.

    The caller owns the model (destroy it).

    Note:
        Collective.
    """
    spec = placed.spec
    model = PlateModel(
        placed.mesh,
        placed.facet_tags,
        spec.plate,
        spec.material,
        prestress,
        spec.solver.shear,
        points=spec.points,
        fixed_prestress=fixed_prestress,
        fixed_factor=spec.load.fixed_factor,
    )
    try:
        if spec.bilateral_foundations:
            model.add_springs(*foundation_springs(model, spec.bilateral_foundations))
    except BaseException:
        model.destroy()
        raise
    return model


def check_pencil(
    model: StructuralModel,
    prestress: Prestress,
    fixed_prestress: Prestress | None,
    with_obstacle: bool,
) -> None:
    """Stage 4: refuse a pencil that cannot buckle, or whose first matrix is not SPD.

    B's entries are of the order of the membrane force |N0| (a Q1 stiffness integral is
    O(1)); below :data:`~unibuckle_fenicsx.tolerances.NULL_GEOMETRIC_STIFFNESS` of it,
    b(w, w) vanishes identically on the free deflections (e.g. pure shear on a mesh with
    a single row of free nodes, whose contributions above and below cancel) and no load
    buckles the plate. With a fixed load the pencil is :math:`(A - B_{fixed}, B)`; every
    algorithm and the certificate need its first matrix positive definite, which the
    inertia of its :math:`LDL^T` (MUMPS) tells: no negative and no zero pivot.

    Args:
        model: The structural model (not destroyed here).
        prestress: The scaled load's membrane force.
        fixed_prestress: The fixed load's, or None.
        with_obstacle: The problem has obstacles (the message says what they change).

    Raises:
        InputError: B is round-off, or A - B_fixed is not positive definite.

    Note:
        Collective.
    """
    scale = max(prestress.max_compression, prestress.max_tension)
    b_norm = float(model.B.norm(PETSc.NormType.INFINITY))
    if b_norm <= NULL_GEOMETRIC_STIFFNESS * scale:
        raise InputError(
            "the plate has no positive buckling load on this mesh: the geometric "
            f"stiffness b(w, w) vanishes on the free deflections (|B| = {b_norm:.3g} "
            f"against |N0| = {scale:.3g} N/m); refine the mesh or check the edge loads"
        )
    if fixed_prestress is None:
        return
    K = model.A.duplicate(copy=True)
    try:
        with SymmetricFactorization(K, Prefix.FIXED) as factor:
            negative, zero, _ = factor.inertia()
    finally:
        K.destroy()
    if negative or zero:
        # With an obstacle the plate may still carry such a fixed part (its unilateral
        # critical load lies higher), but the solvers and certificates here all rest
        # on a positive definite first matrix of the pencil: say so, not that it buckles.
        obstacle = (
            " without its obstacle (with it, the plate may carry this fixed part, but "
            "every solver here needs A - B_fixed positive definite, i.e. the fixed part "
            "below the free plate's critical value)"
            if with_obstacle
            else ""
        )
        raise InputError(
            "the fixed load alone buckles the plate"
            f"{obstacle} (fixed_normal_stress, "
            "fixed_shear_stress, fixed_temperature): the stiffness less its geometric "
            f"stiffness, A - B_fixed, has {negative} negative and {zero} zero "
            "eigenvalue(s); lower the fixed part below its own critical value"
        )


def build_eigensolver(
    model: StructuralModel,
    prestress: Prestress,
    spec: ProblemSpec,
    eps_options: Options | None,
    reused: bool = False,
) -> GEPSolver:
    """Stage 5: the pencil's eigen solver (the caller destroys it).

    ``reused``: the problem has one-sided obstacles or points, whose route's contact
    sets make many factorisations (their ordering:
    :func:`~unibuckle_fenicsx.la.options.mumps_ordering`).

    Note:
        Collective.
    """
    return GEPSolver(
        model.A,
        model.B,
        indefinite=prestress.indefinite,
        tol=spec.solver.eps_tol,
        options={**EIGEN_OPTIONS, **(eps_options or {})},
        reused=reused,
    )


#: The free solve's shift comes from the plate on a mesh this many times coarser along
#: each side (a sixteenth of the DOFs; its load lies within a few tenths of a percent
#: of the fine one on a mesh that resolves the mode).
FREE_ESTIMATE_COARSENING = 4
#: Meshes of at least this many (w, theta) DOFs get a coarse estimate of their free load:
#: from there the estimate and the shifted solve cost less than the solve at target 0
#: and its check (:doc:`/verification/floor`).
FREE_ESTIMATE_DOFS = 5_000
#: ... and whose coarse mesh keeps at least this many cells across (a structured one:
#: with fewer the coarse load lies tens of percent off and the shifts miss).
FREE_ESTIMATE_CELLS = 6


def free_estimate(placed: PlacedMesh, dofs: int) -> tuple[float, ...]:
    """The free pencil's two lowest eigenvalues on a coarser mesh, or () if none is made.

    The plate as it is without its one-sided obstacles and points (the free pencil keeps
    the bilateral foundations and points), on a mesh :data:`FREE_ESTIMATE_COARSENING`
    times coarser; () below :data:`FREE_ESTIMATE_DOFS` (``dofs``: the fine pencil's
    rows), for a user's mesh or a file, and when the coarse plate is refused (a feature
    smaller than its cells, no buckling load there). What
    :meth:`~unibuckle_fenicsx.model.problem.Problem.solve_free` shifts by.

    Note:
        Collective.
    """
    spec, k = placed.spec, FREE_ESTIMATE_COARSENING
    if placed.custom or dofs < FREE_ESTIMATE_DOFS:
        return ()
    free = replace(
        spec,
        obstacle=None,
        obstacles=spec.bilateral_foundations,
        points=tuple(p for p in spec.points if p.kind != "one-sided"),
    )
    try:
        if placed.structured:
            nx, ny = spec.mesh.nx // k, spec.mesh.ny // k
            if min(nx, ny) < FREE_ESTIMATE_CELLS:
                return ()
            coarse = free.with_mesh(nx, ny)
        elif spec.plate.file is None and spec.mesh.size is not None:
            coarse = replace(free, mesh=replace(spec.mesh, size=k * spec.mesh.size))
        else:
            return ()
        with build_problem(coarse, placed.comm) as problem:
            return lowest_eigenvalues(problem.model.A, problem.model.B, Prefix.ESTIMATE)
    except (InputError, NumericalError) as err:
        logger.debug("no coarse estimate of the free load: %s", err)
        return ()


def build_contact(model: PlateModel, spec: ProblemSpec) -> ContactSetManager | None:
    """Stage 6: the contact manager of the one-sided obstacles and points, or None.

    Raises:
        EmptyZoneError: The constrained nodes are all held already (the message names
            the one-sided points when they are among the obstacles).
        BilateralZoneError: A node is held from both sides.

    Note:
        Collective.
    """
    unilateral = spec.unilateral_obstacles + tuple(point_obstacles(model.points, spec.plate))
    if not unilateral:
        return None
    try:
        return ContactSetManager(model, unilateral)
    except EmptyZoneError as err:
        if not spec.one_sided_points:
            raise
        one_sided = [k for k, p in enumerate(spec.points) if p.kind == "one-sided"]
        raise EmptyZoneError(
            f"{_points_label(spec, one_sided)}: the one-sided points"
            + (" and the obstacle zones" if spec.unilateral_obstacles else "")
            + " act on no free node: each such node is held already (by an edge "
            "support or a bilateral point), so the point restrains nothing; move it off "
            "the support or leave it out"
        ) from err
    except BilateralZoneError as err:
        if not spec.one_sided_points:
            raise
        clash = one_sided_conflicts(model.points, spec.unilateral_obstacles, spec.plate)
        raise BilateralZoneError(
            f"{_points_label(spec, clash) if clash else 'points'}: a one-sided point acts "
            "on a node held from the other side too (an obstacle zone or another point): "
            'that holds w = 0, give it kind = "bilateral"'
        ) from err


def _points_label(spec: ProblemSpec, indices: list[int]) -> str:
    """``points[k] (what)`` for each index, for messages, in the file's units."""
    return ", ".join(f"points[{k}] ({spec.points[k].describe(spec.units)})" for k in indices)


def build_problem(
    spec: ProblemSpec,
    comm: MPI.Comm = MPI.COMM_WORLD,
    eps_options: Options | None = None,
    *,
    mesh: dolfinx.mesh.Mesh | None = None,
    facet_tags: dolfinx.mesh.MeshTags | None = None,
) -> Problem | UnilateralProblem:
    """The problem ``spec`` set up for its solves: the stages of the module docstring.

    Args:
        spec: The problem.
        comm: Communicator of the mesh (``MPI.COMM_SELF`` gives each rank its own
            serial copy, for candidate-parallel enumeration).
        eps_options: Extra EPS options of the run: under the prefix ``unibuckle_`` (so
            ``eps_view`` is ``-unibuckle_eps_view``) for this pencil and the coarser
            levels' copies, and under ``unibuckle_penalty_`` and ``unibuckle_foundation_``
            for the penalty stages and the foundation
            (:data:`~unibuckle_fenicsx.la.options.RUN_EPS_PREFIXES`). The problem holds
            them in PETSc's options database until it is destroyed; the command line's
            win.
        mesh: A quadrilateral DOLFINx mesh to use instead of ``spec.mesh`` (the
            rectangle, or gmsh's plate); ``spec.plate.corners`` must be its bounding
            box (used for tolerances and the buckling coefficient's width), and each
            edge's facet tag must mark facets of it (both checked).
        facet_tags: Edge markers of ``mesh``, matched by :class:`EdgeSpec` ``tag``.

    Returns:
        A :class:`~unibuckle_fenicsx.model.problem.UnilateralProblem` when the problem
        has one-sided obstacles, foundations or points, else a
        :class:`~unibuckle_fenicsx.model.problem.Problem`; the caller destroys it (or
        uses it in a ``with`` block).

    Raises:
        InputError: The problem is refused (the stage that refuses it says why).

    Note:
        Collective on ``comm``.
    """
    with file_units(spec.units):  # its refusals and warnings speak the file's units
        return _build_problem(spec, comm, eps_options, mesh, facet_tags)


def _build_problem(
    spec: ProblemSpec,
    comm: MPI.Comm,
    eps_options: Options | None,
    mesh: dolfinx.mesh.Mesh | None,
    facet_tags: dolfinx.mesh.MeshTags | None,
) -> Problem | UnilateralProblem:
    """The stages of :func:`build_problem`."""
    t0 = time.perf_counter()
    if spec.has_fixed_load:
        spec.check_scaled_load()
    placed = place_mesh(spec, comm, mesh, facet_tags)
    prestress, fixed = solve_prestresses(placed)
    t1 = time.perf_counter()
    model = build_plate(placed, prestress, fixed)
    t2 = time.perf_counter()
    spec = placed.spec
    try:
        check_pencil(model, prestress, fixed, with_obstacle=bool(spec.all_obstacles))
        unilateral = spec.unilateral_obstacles + tuple(point_obstacles(model.points, spec.plate))
        eigensolver = build_eigensolver(model, prestress, spec, eps_options, bool(unilateral))
        try:
            contact = build_contact(model, spec)
        except BaseException:
            eigensolver.destroy()  # collective: every rank raises (the checks agree)
            raise
    except BaseException:
        model.destroy()
        raise
    parts = SetUp(
        spec=spec,
        comm=placed.comm,
        mesh=placed.mesh,
        facet_tags=placed.facet_tags,
        structured=placed.structured,
        custom_mesh=placed.custom,
        prestress=prestress,
        fixed_prestress=fixed,
        model=model,
        eigensolver=eigensolver,
        # Last: a refused problem leaves nothing in the options database.
        run_options=push_run_options(eps_options),
        timings={"prestress_s": t1 - t0, "assembly_s": t2 - t1},
        estimate=functools.partial(free_estimate, placed, int(model.A.getSize()[0])),
    )
    problem = Problem(parts) if contact is None else UnilateralProblem(parts, contact)
    problem.timings["setup_s"] = time.perf_counter() - t0
    return problem


def build_unilateral_problem(
    spec: ProblemSpec, comm: MPI.Comm = MPI.COMM_WORLD, eps_options: Options | None = None
) -> UnilateralProblem:
    """:func:`build_problem` for a problem that has an obstacle (a coarser mesh's copy).

    Raises:
        InputError: The problem has no one-sided obstacle, foundation or point.

    Note:
        Collective on ``comm``.
    """
    problem = build_problem(spec, comm, eps_options)
    if not isinstance(problem, UnilateralProblem):
        problem.destroy()
        raise InputError(
            f"{spec.name}: the problem has no obstacle (give an [obstacle] zone, a "
            "tensionless foundation or a one-sided point)"
        )
    return problem
