"""The methods and their options: the ``[solver]`` table.

:class:`Method` names each unilateral method once: the file's choices and the command
line's read it. :class:`SolverSpec` is the ``[solver]`` table, every option
once with its range and default; each method's own options Struct (:data:`OPTIONS`)
holds the options that method reads, typed and defaulted from it; the algorithms check
their arguments of the same name with it.
"""

from __future__ import annotations

import enum
from typing import Annotated, Any, ClassVar, Literal

import msgspec
from msgspec import Meta

from unibuckle_fenicsx.spec.base import Table


class Method(enum.StrEnum):
    """The unilateral methods (``[solver] method``, ``--method``)."""

    #: Enumeration when it fits its budget, else the interior point (thin plates) or the
    #: active set.
    AUTO = "auto"
    #: The paper's enumeration of contact sets (:doc:`/methods/enumeration`).
    ENUMERATE = "enumerate"
    #: The nested interior-point (barrier) method (:doc:`/methods/interior_point`).
    INTERIOR_POINT = "interior-point"
    #: The multilevel primal-dual active-set method (:doc:`/methods/active_set`).
    ACTIVE_SET = "active-set"
    #: A penalty on the obstacle's side (:doc:`/methods/penalty`).
    PENALTY = "penalty"


#: The method names, in :class:`Method` order.
METHODS: tuple[str, ...] = tuple(m.value for m in Method)

MaxCandidates = Annotated[int, Meta(ge=1)]
Iterations = Annotated[int, Meta(ge=1)]
BoundBudget = Annotated[int, Meta(ge=0)]
Seconds = Annotated[float, Meta(gt=0, extra={"unit": "s"})]
#: The relative penalty's range, the one :doc:`/methods/penalty` studies (c1, c2, c3):
#: below its low end the springs barely raise the free load (the mode crosses the
#: obstacle freely: never a KKT point); above its high end nothing is gained (the gap
#: to lambda_c has reached rounding).
PENALTY_RANGE = (1e-6, 1e16)
Penalty = Annotated[float, Meta(ge=PENALTY_RANGE[0], le=PENALTY_RANGE[1])]


#: The highest Lagrange degree of the prestress solve's in-plane displacement: degree 2
#: resolves compression with in-plane bending exactly, and the cells' count of the
#: membrane DOFs grows as the degree squared (its cost:
#: docs/history/2026-11-30f-platehunt.md).
MAX_PRESTRESS_DEGREE = 4


class SolverSpec(Table, frozen=True):
    """Solver options (the file's ``[solver]``).

    Args:
        method: One of :class:`Method`; "auto" enumerates (with ``until_proven``) when the
            candidate count 2^i is at most ``max_candidates`` and the estimated enumeration
            time is within ``enumeration_budget_s``; otherwise it runs the nested
            interior-point method on thin plates (thickness below
            :data:`~unibuckle_fenicsx.algorithms.chain.THIN_PLATE` of the shorter side) and
            the multilevel active-set method on the others.
        tau: Relative feasibility/contact tolerance (:doc:`/methods/problem`), in
            [1e-12, 1e-2]: below, the rounding of a computed mode (the unit round-off
            times the pencil's condition number) can exceed it, and no answer passes the
            KKT test.
        eps_tol: SLEPc convergence tolerance, in (0, 1e-4].
        max_candidates: Largest candidate count the enumeration accepts, >= 1.
        enumeration_budget_s: "auto" enumerates only if the estimate (2^i times the time
            of one eigen solve) is at most this many seconds, > 0.
        complete: Enumerate every subset instead of stopping after the first feasible
            size p (to check the paper's monotonicity).
        until_proven: Enumerate past the paper's stopping size p* until the interlacing
            bound proves the best feasible set optimal (exact; the paper's rule is not, see
            :doc:`/methods/enumeration`).
        max_iterations: Active-set iterates per seed and mesh level, >= 1 (the feasible
            descent, the chain's last link, may use as many solves again).
        bound_budget: Eigen solves allowed for the active set's lattice lower bound, >= 0
            (it runs when the budget covers the i singletons).
        certify: Verify the result's global optimality (:doc:`/methods/certificates`);
            off for speed studies.
        bracket: Run the verified bracket when two or more pencil eigenvalues lie below
            the load whatever its cost, with smaller distances and larger budgets
            (:doc:`/methods/certificates`); by default it runs only where its estimated
            cost is at most 3 free solves (the summary says when it did not).
        penalty: Penalty stiffness rho for ``method="penalty"`` (relative to the largest
            diagonal entry of A), 1e-6 to 1e16 (:data:`PENALTY_RANGE`).
        prestress_degree: Lagrange degree of the in-plane displacement, 1 to 4.
        shear: "mitc" (MacNeal/MITC4, locking-free) or "full" (plain full integration,
            locks; for comparison only).
    """

    KEY: ClassVar[str] = "solver"
    method: Method = Method.AUTO
    tau: Annotated[float, Meta(ge=1e-12, le=1e-2)] = 1e-8
    eps_tol: Annotated[float, Meta(gt=0.0, le=1e-4)] = 1e-10
    max_candidates: MaxCandidates = 100_000
    enumeration_budget_s: Seconds = 60.0
    complete: bool = False
    until_proven: bool = False
    max_iterations: Iterations = 100
    bound_budget: BoundBudget = 64
    certify: bool = True
    bracket: bool = False
    penalty: Penalty = 1e3
    prestress_degree: Annotated[int, Meta(ge=1, le=MAX_PRESTRESS_DEGREE)] = 1
    shear: Literal["mitc", "full"] = "mitc"


def default(name: str) -> Any:
    """The default of the ``[solver]`` option ``name``."""
    return next(f.default for f in msgspec.structs.fields(SolverSpec) if f.name == name)


class EnumerateOptions(Table, frozen=True):
    """The options of :attr:`Method.ENUMERATE` (meanings: :class:`SolverSpec`)."""

    KEY: ClassVar[str] = "solver"
    complete: bool = default("complete")
    until_proven: bool = default("until_proven")
    max_candidates: MaxCandidates = default("max_candidates")


class ActiveSetOptions(Table, frozen=True):
    """The options of :attr:`Method.ACTIVE_SET` (meanings: :class:`SolverSpec`)."""

    KEY: ClassVar[str] = "solver"
    max_iterations: Iterations = default("max_iterations")
    bound_budget: BoundBudget = default("bound_budget")


class InteriorPointOptions(ActiveSetOptions, frozen=True):
    """The options of :attr:`Method.INTERIOR_POINT`: its active-set fallback's."""


class AutoOptions(ActiveSetOptions, frozen=True):
    """The options of :attr:`Method.AUTO`: its choice's, and those of the routes it runs."""

    max_candidates: MaxCandidates = default("max_candidates")
    enumeration_budget_s: Seconds = default("enumeration_budget_s")


class PenaltyOptions(Table, frozen=True):
    """The options of :attr:`Method.PENALTY` (meanings: :class:`SolverSpec`)."""

    KEY: ClassVar[str] = "solver"
    penalty: Penalty = default("penalty")


class FoundationOptions(Table, frozen=True):
    """The options of a tensionless foundation's spring-set iteration.

    No :class:`Method` names it: a problem whose obstacle is a tensionless foundation
    runs it under "auto" (meanings: :class:`SolverSpec`).
    """

    KEY: ClassVar[str] = "solver"
    max_iterations: Iterations = default("max_iterations")


#: Each method's options Struct: the ``[solver]`` options it reads.
OPTIONS: dict[Method, type[Table]] = {
    Method.AUTO: AutoOptions,
    Method.ENUMERATE: EnumerateOptions,
    Method.INTERIOR_POINT: InteriorPointOptions,
    Method.ACTIVE_SET: ActiveSetOptions,
    Method.PENALTY: PenaltyOptions,
}
