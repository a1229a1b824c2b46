"""What each algorithm records of its run: typed records, JSON-ready by ``to_builtins``.

A record holds numbers, names and other records, never a live object (a mode, a
problem): :mod:`unibuckle_fenicsx.results` writes them into the output's ``details``
under the names given here, in this order. A field that a run leaves out of its
record (a fallback that did not run, a warning not raised) is ``UNSET`` and absent from
the JSON.
"""

from __future__ import annotations

from msgspec import UNSET, Struct, UnsetType

__all__ = [
    "ActiveSetDetails",
    "ActiveSetLevel",
    "ContinuedRecord",
    "DescentRecord",
    "EnumerationDetails",
    "Fallback",
    "FoundationDetails",
    "InteriorPointDetails",
    "KktPoint",
    "LevelRecord",
    "LinkRecord",
    "MethodDetails",
    "PenaltyDetails",
    "RunSummary",
    "SectionLevel",
    "SectionLevelsDetails",
]


class ContinuedRecord(Struct, kw_only=True):
    """One continuation of the solve from a certificate's refuting mode (feasible descent).

    Attributes:
        from_load: The refuting mode's load (Pa).
        to_load: The load the descent ended at (Pa), at most ``from_load``.
        status: How the descent ended (a :class:`~unibuckle_fenicsx.algorithms.RunStatus`
            value).
        steps: Its solves (eigen and gradient).
        refuted_load: The refuted answer's load (Pa).
    """

    from_load: float
    to_load: float
    status: str
    steps: int
    refuted_load: float


class RunSummary(Struct, kw_only=True):
    """One primal-dual active-set run from one seed.

    Attributes:
        seed: The seed's name.
        status: How it ended (a :class:`~unibuckle_fenicsx.algorithms.RunStatus` value).
        iterations: Eigen solves used.
        load: Its last candidate's load (None if none, or not finite).
        contact_nodes: Its last candidate's |Z| (None if none).
        kkt: The last candidate is a KKT point.
    """

    seed: str
    status: str
    iterations: int
    load: float | None
    contact_nodes: int | None
    kkt: bool


class ActiveSetLevel(Struct, kw_only=True):
    """The active set's runs on one coarser mesh.

    Attributes:
        mesh: [nx, ny].
        constrained_nodes: i on this mesh.
        eigensolves: Eigen solves on it.
        wall_time_s: Seconds on it.
        runs: Its runs.
        kkt_loads: The loads of its distinct KKT points, lowest first.
        skipped: Why no seed ran on it (no positive buckling load on this mesh),
            where none did.
    """

    mesh: list[int]
    constrained_nodes: int
    eigensolves: int
    wall_time_s: float
    runs: list[RunSummary]
    kkt_loads: list[float]
    skipped: str | UnsetType = UNSET


class KktPoint(Struct, kw_only=True):
    """A KKT point met: its load and |Z|."""

    load: float
    contact_nodes: int


class DescentRecord(Struct, kw_only=True):
    """The feasible descent of a fallback: its eigen solves, end, and steps by kind."""

    eigensolves: int
    status: str
    steps: dict[str, int]


class Fallback(Struct, kw_only=True):
    """What ran when the active-set iteration stalled on the fine mesh.

    Attributes:
        method: "penalty continuation".
        penalty_eigensolves: Its eigen solves.
        status: How it ended.
        descent: The feasible descent that followed (when the continuation stalled too).
    """

    method: str
    penalty_eigensolves: int
    status: str
    descent: DescentRecord | UnsetType = UNSET


class LinkRecord(Struct):
    """One run of one link of the interior point's route on one mesh.

    Attributes:
        link: "interior-point", "evaluate", "active-set polish", "feasible descent".
        seed: The start (or level) it ran from.
        status: How it ended.
        steps: Newton steps or active-set iterates.
        factorizations: Numeric factorisations (interior point).
        eigensolves: Eigen solves.
        seconds: Wall time.
        load: The load it ended with (None if none).
        contact_nodes: |Z| (None if no contact set was read).
        kkt: It ended at a KKT point.
    """

    link: str
    seed: str
    status: str
    steps: int = 0
    factorizations: int = 0
    eigensolves: int = 0
    seconds: float = 0.0
    load: float | None = None
    contact_nodes: int | None = None
    kkt: bool = False


class LevelRecord(Struct, kw_only=True):
    """What the interior point's route did on one mesh.

    Attributes:
        mesh: [nx, ny] (structured), ["h=<cell size>"] (meshed by gmsh) or ["fine"] (a
            user's mesh or a mesh file).
        constrained_nodes: i on this mesh.
        newton_steps: Interior-point Newton steps on it.
        factorizations: Numeric factorisations on it.
        eigensolves: Eigen solves on it.
        seconds: Wall time on it (set-up included).
        links: The runs on it.
    """

    mesh: list[int | str]
    constrained_nodes: int
    newton_steps: int
    factorizations: int
    eigensolves: int
    seconds: float
    links: list[LinkRecord]


class EnumerationDetails(Struct, kw_only=True):
    """The paper's enumeration (section 5.3): per contact-set size p, what it found.

    Attributes:
        constrained_nodes: i.
        candidate_count: 2^i.
        candidates_evaluated: Contact sets solved (all ranks).
        candidate_ranks: Ranks sharing the candidate sets.
        complete: Every subset was visited.
        until_proven: It went past p* until the bound proved the best set.
        p_optimum: |Z| of the returned set.
        lambda_by_p: Per size, the smallest admissible load (None if none).
        feasible_by_p: Per size, the sets with an admissible mode.
        candidates_by_p: Per size, the sets solved.
        lambda_min_by_p: Per size, the smallest load of any set (None if none).
        wall_by_p_s: Per size, seconds.
        monotone: The loads grow with p (checked with ``complete``; else None).
        monotone_violations: Pairs of sizes [p, q] that break it.
        lower_bound_interlacing: The smallest load of the first size with an admissible
            mode (interlacing bounds the larger sets by it).
        enumeration_wall_s: Seconds.
    """

    constrained_nodes: int
    candidate_count: int
    candidates_evaluated: int
    candidate_ranks: int
    complete: bool
    until_proven: bool
    p_optimum: int
    lambda_by_p: list[float | None]
    feasible_by_p: list[int]
    candidates_by_p: list[int]
    lambda_min_by_p: list[float | None]
    wall_by_p_s: list[float]
    monotone: bool | None
    monotone_violations: list[list[int]]
    lower_bound_interlacing: float
    enumeration_wall_s: float


class ActiveSetDetails(Struct, kw_only=True):
    """The multilevel active set: its levels, runs, KKT points, fallbacks and bound.

    Attributes:
        free_load: lambda_free.
        seeded_on: The mesh whose KKT points seeded the fine mesh ([nx, ny], or "fine").
        fallback: What ran when the iteration stalled on the fine mesh.
        levels: The coarser meshes' runs.
        runs: The fine mesh's runs.
        kkt_points: The distinct KKT points of the fine mesh.
        twins: Groups of equal-load KKT points (their contact sets).
        coarse_kkt_loads: The coarsest seeded level's KKT loads.
        fine_eigensolves: Eigen solves on the fine mesh.
        coarse_eigensolves: ... on the coarser meshes.
        penalty_eigensolves: ... of the penalty continuation.
        bound_evaluations: Eigen solves of the lattice lower bound.
        bound_search_complete: The lattice search finished.
        wall_time_s: Seconds.
        warning: What went wrong, in words.
        interior_point_levels: When the interior point's route fell back to the active
            set: what that route did first, mesh by mesh.
    """

    free_load: float
    seeded_on: list[int] | str
    fallback: Fallback | UnsetType = UNSET
    levels: list[ActiveSetLevel]
    runs: list[RunSummary]
    kkt_points: list[KktPoint]
    twins: list[list[list[int]]]
    coarse_kkt_loads: list[float]
    fine_eigensolves: int
    coarse_eigensolves: int
    penalty_eigensolves: int
    bound_evaluations: int
    bound_search_complete: bool
    wall_time_s: float
    warning: str | UnsetType = UNSET
    interior_point_levels: list[LevelRecord] | UnsetType = UNSET


class InteriorPointDetails(Struct, kw_only=True):
    """The interior point's nested route: its meshes, KKT points and bound.

    Attributes:
        free_load: lambda_free.
        levels: What it did on each mesh, coarsest first.
        coarse_kkt_loads: The KKT points' loads on the coarsest mesh.
        fine_eigensolves: Eigen solves on the fine mesh.
        coarse_eigensolves: ... on the coarser meshes.
        bound_evaluations: Eigen solves of the lattice lower bound.
        bound_search_complete: The lattice search finished.
        wall_time_s: Seconds.
        warning: What went wrong, in words.
    """

    free_load: float
    levels: list[LevelRecord]
    coarse_kkt_loads: list[float]
    fine_eigensolves: int
    coarse_eigensolves: int
    bound_evaluations: int
    bound_search_complete: bool
    wall_time_s: float
    warning: str | UnsetType = UNSET


class PenaltyDetails(Struct, kw_only=True):
    """The penalty method's spring-set iteration (the route the paper rejects).

    Attributes:
        penalty_rho: The penalty stiffness, relative to max diag A.
        penalty_rho_abs: The spring stiffness (N/m).
        penalty_max_diag_A: max diag A.
        penalty_status: How the iteration ended.
        penalty_cycle_length: Length of its cycle (0 if none).
        penalty_iterations: Eigen solves.
        penalty_orientation_ties: Orientation ties broken by the deterministic rule.
        penalty_max_penetration: The returned mode's largest penetration (max |w| = 1).
        penalty_penetrating_set: Its penetrating nodes.
        penalty_springs: Its spring set.
        penalty_eigenvalue: Its load.
        penalty_history: The quotient per iterate.
        penalty_eig_min_A_pen: The penalised stiffness's smallest eigenvalue (on request).
        penalty_eig_max_A_pen: ... its largest.
        penalty_condition_number: ... their ratio.
    """

    penalty_rho: float
    penalty_rho_abs: float | list[float]
    penalty_max_diag_A: float
    penalty_status: str
    penalty_cycle_length: int
    penalty_iterations: int
    penalty_orientation_ties: int
    penalty_max_penetration: float
    penalty_penetrating_set: list[int]
    penalty_springs: list[int]
    penalty_eigenvalue: float
    penalty_history: list[float]
    penalty_eig_min_A_pen: float | UnsetType = UNSET
    penalty_eig_max_A_pen: float | UnsetType = UNSET
    penalty_condition_number: float | UnsetType = UNSET


class FoundationDetails(Struct, kw_only=True):
    """The tensionless foundation's spring-set iteration from its starts.

    Attributes:
        foundation_start: The start whose fixed point was returned (``+arc``: after the
            arc descent).
        foundation_arc_steps: Steps of the arc descent.
        foundation_iterations: Per start, its iterates.
        foundation_loads: Per start, its load.
        foundation_statuses: Per start, how it ended.
        foundation_pressing_nodes: Nodes pressing the foundation.
        foundation_max_penetration: The largest press, relative to max|w|.
        foundation_spring_range_N_per_m: The smallest and largest nodal spring.
        foundation_history: The returned start's quotient per iterate.
        foundation_status: How the returned start's iteration ended.
    """

    foundation_start: str
    foundation_arc_steps: int
    foundation_iterations: dict[str, int]
    foundation_loads: dict[str, float]
    foundation_statuses: dict[str, str]
    foundation_pressing_nodes: int
    foundation_max_penetration: float
    foundation_spring_range_N_per_m: list[float]
    foundation_history: list[float]
    foundation_status: str


class SectionLevel(Struct, kw_only=True):
    """One section of the coarse-to-fine sections' solve.

    Attributes:
        mesh_size: Its cell size (m).
        dofs: Its DOFs (six per node).
        constrained: The core's constrained directions.
        load: The critical stress found there (Pa).
        kkt: Its state satisfies the KKT conditions.
        eigensolves: Eigen solves on it (its free solve and its penalty continuation's
            included).
        penalty_eigensolves: Those of its penalty continuation (the seeds' fallback,
            which has its own eigen solver).
        steps: Active-set steps on it: the polish's from the carried contact set, or,
            where the seeds ran (``seeded``), all of theirs and any fallback's.
        seeded: The seeds ran on it (the coarsest section, or a carried set that did
            not reach a KKT point).
        wall_time_s: Seconds.
    """

    mesh_size: float
    dofs: int
    constrained: int
    load: float
    kkt: bool
    eigensolves: int
    penalty_eigensolves: int = 0
    steps: int = 0
    seeded: bool = False
    wall_time_s: float


class SectionLevelsDetails(Struct, kw_only=True):
    """The sections' coarse-to-fine active set (a section with a core).

    Attributes:
        free_load: The finest hollow section's lambda_free.
        polish_iterations: The active-set iterations from the contact set carried from
            the coarser section, when they reached a KKT point.
        active_set: The active set's record, when it ran from its seeds on the finest
            section (the coarsest, or a carried contact set that did not polish).
        levels: The sections, coarsest first.
        coarse_eigensolves: Eigen solves on the coarser sections.
        wall_time_s: Seconds.
        interior_point_levels: When the interior point's route fell back to this one,
            its per-section records (:class:`LevelRecord`, coarsest first), as
            :class:`ActiveSetDetails` keeps a plate's.
    """

    free_load: float
    polish_iterations: int | UnsetType = UNSET
    active_set: ActiveSetDetails | UnsetType = UNSET
    levels: list[SectionLevel]
    coarse_eigensolves: int
    wall_time_s: float
    interior_point_levels: list[LevelRecord] | UnsetType = UNSET


#: The record of whichever algorithm ran.
MethodDetails = (
    EnumerationDetails
    | ActiveSetDetails
    | InteriorPointDetails
    | PenaltyDetails
    | FoundationDetails
    | SectionLevelsDetails
)
