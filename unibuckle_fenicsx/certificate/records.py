r"""What the global-optimality certificate records: typed records of its routes and attempts.

The certificate's JSON (``certificate.copositivity``) holds a :class:`CopositivityRecord`:
the route that verified the lower bound, its margins (one record per route) and the
low-rank route's attempts. Fields a route leaves out are ``UNSET`` (absent from the
JSON); the field order is the JSON's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from msgspec import UNSET, Struct, UnsetType, field

__all__ = [
    "AttemptRecord",
    "CopositivityRecord",
    "LowRankAttempt",
    "LowRankMargins",
    "LowRankRecord",
    "Margins",
    "NoMargins",
    "PsdMargins",
    "Rank2Margins",
    "Rank2Record",
    "Rank2Try",
    "Refuting",
    "SdpRecord",
    "SearchRecord",
    "SectorPiece",
    "SectorRecord",
    "SectorTry",
    "SplitAttempt",
    "SplitRecord",
]


class NoMargins(Struct):
    """No route verified a bound: nothing to record."""


class PsdMargins(Struct, kw_only=True):
    r""":math:`A - \lambda_{lb} B` is positive definite: its inertia (negative, zero, positive)."""

    inertia: list[int]


class Rank2Try(Struct, kw_only=True):
    r"""One :math:`w_-` tried by the rank-2 route: its margins and whether they certify.

    Attributes:
        w_minus: Its name (a KKT point, a mirror image, "search").
        beta: :math:`-w_-^TK^{-1}w_-`.
        beta_err: Its verified error bound.
        gamma: :math:`w_+^TK^{-1}w_-`.
        gamma_err: Its verified error bound.
        ok: The margins certify.
    """

    w_minus: str
    beta: float
    beta_err: float
    gamma: float
    gamma_err: float
    ok: bool


class Rank2Record(Struct, kw_only=True):
    r"""The rank-2 route at one shift: :math:`\alpha` for :math:`w_+`, and each :math:`w_-`."""

    alpha: float
    alpha_err: float
    alpha_ok: bool
    tried: list[Rank2Try]


class Rank2Margins(Struct, kw_only=True):
    r"""The rank-2 certificate's verified quantities (:math:`c = 1/\gamma`)."""

    alpha: float
    alpha_err: float
    w_minus: str
    beta: float
    beta_err: float
    gamma: float
    gamma_err: float
    ok: bool
    c: float


class SectorPiece(Struct, kw_only=True):
    """One sector piece of the cone: the SDP's margin on it, or why it failed."""

    t: float | UnsetType = UNSET
    eig_min: float | UnsetType = UNSET
    status: str | UnsetType = UNSET
    ok: bool
    why: str | UnsetType = UNSET


class SectorTry(Struct, kw_only=True):
    """The cone split into ``sectors`` pieces."""

    sectors: int
    pieces: list[SectorPiece]


class SectorRecord(Struct, kw_only=True):
    """Copositivity on every sector piece of the cone (two negative eigenvalues).

    Attributes:
        ok: Every piece of a split is certified.
        neg_K: Negative eigenvalues of K.
        lam: The shift (JSON ``lambda``).
        tries: The splits tried.
        sectors: The pieces of the certified split.
        eig_min: Its smallest verified margin.
        why: Why it failed.
    """

    ok: bool
    neg_K: int
    lam: float = field(name="lambda")
    tries: list[SectorTry] | UnsetType = UNSET
    sectors: int | UnsetType = UNSET
    eig_min: float | UnsetType = UNSET
    why: str | UnsetType = UNSET


class SdpRecord(Struct, kw_only=True):
    """The SDP route: the Schur complement S split as PSD + nonnegative.

    Attributes:
        ok: Certified.
        neg_K: Negative eigenvalues of K.
        neg_S: ... of S.
        lam: The shift (JSON ``lambda``).
        t: The SDP's objective.
        eig_min: The smallest eigenvalue of S - N.
        status: The SDP solver's status.
        why: Why it failed.
        neg_zero_K_minus_N: Negative and zero pivots of K - N.
        sectors: The sector route tried after it (two negative eigenvalues).
        too_large: Not run: too many constrained nodes.
        unavailable: Not run: the 'sdp' extra is missing.
    """

    ok: bool = False
    neg_K: int | UnsetType = UNSET
    neg_S: int | UnsetType = UNSET
    lam: float | UnsetType = field(default=UNSET, name="lambda")
    t: float | UnsetType = UNSET
    eig_min: float | UnsetType = UNSET
    status: str | UnsetType = UNSET
    why: str | UnsetType = UNSET
    neg_zero_K_minus_N: list[int] | UnsetType = UNSET
    sectors: SectorRecord | UnsetType = UNSET
    too_large: bool | UnsetType = UNSET
    unavailable: bool | UnsetType = UNSET


class LowRankMargins(Struct, kw_only=True):
    """The low-rank certificate's size and margin: r columns, pieces, margin, m."""

    r: int
    pieces: int
    margin: float
    m: int


class LowRankAttempt(Struct, kw_only=True):
    """One shift of the low-rank route.

    Attributes:
        delta: Relative distance of the shift below the load.
        m: Negative eigenvalues of K there.
        proven: Copositivity proven.
        r: Columns used.
        pieces: Simplicial pieces.
        margin: Smallest verified margin of the pieces.
        why: What stopped it ("" when proven).
        columns: Columns held.
        cuts: Cuts added.
        G_negative: Negative eigenvalues of the Gram matrix G.
        G_margin: Its margin.
        best_t: The best SDP margin reached.
    """

    delta: float
    m: int
    proven: bool = False
    r: int = 0
    pieces: int = 0
    margin: float = -np.inf
    why: str = ""
    columns: int | UnsetType = UNSET
    cuts: int | UnsetType = UNSET
    G_negative: int | UnsetType = UNSET
    G_margin: float | UnsetType = UNSET
    best_t: float | UnsetType | None = UNSET


class LowRankRecord(Struct, kw_only=True):
    """The low-rank route's record (its refuting mode's vector left out)."""

    value: float | None
    delta: float | None
    m: int
    r: int
    pieces: int
    margin: float
    why: str
    attempts: list[LowRankAttempt]
    refuting_load: float | UnsetType = UNSET


class SplitAttempt(LowRankAttempt, kw_only=True):
    """One shift of the split route: the low-rank route's fields it fills, and its rounds.

    Attributes:
        rounds: Rounds of new columns (cuts and translates) added.
        examined: Pieces of the z-space examined (proven or bisected).
        spent: The route's counts up to this attempt's end (factorisations, right-hand
            sides, pieces) priced in free solves by the cost model, as its cost limit
            counts them.
    """

    rounds: int = 0
    examined: int | UnsetType = UNSET
    spent: float | UnsetType = UNSET


class SplitRecord(LowRankRecord, kw_only=True):
    """The split route's record: the low-rank route's, its cost and whether it was skipped.

    Its ``attempts`` are :class:`SplitAttempt` records.

    Attributes:
        solves: Triangular solve pairs used.
        estimated_cost: Its estimated cost in free solves (None if not estimated).
        skipped: Not run: the estimated cost exceeds the default limit.
        cost_limit: The limit in free solves it was held to (None: none, ``--bracket``).
    """

    solves: int = 0
    estimated_cost: float | None = None
    skipped: bool = False
    cost_limit: float | None = None


class SearchRecord(Struct, kw_only=True):
    r"""The search of the other nappe for a :math:`w_-`: its iterations and best f."""

    iterations: int
    f: float


class AttemptRecord(Struct, kw_only=True):
    """One shift of the copositivity certificate: the inertia there, what each route found.

    Attributes:
        delta: Relative distance of the shift below the load.
        inertia: (negative, zero, positive) of K there.
        why: Why no route ran (K singular).
        rank2: The rank-2 route (one negative eigenvalue).
        search: The search of the other nappe when no w- certified.
        rank2_search: The rank-2 route with the searched w-.
        sdp: The SDP route (two or more negative eigenvalues).
    """

    delta: float
    inertia: list[int]
    why: str | UnsetType = UNSET
    rank2: Rank2Record | UnsetType = UNSET
    search: SearchRecord | UnsetType = UNSET
    rank2_search: Rank2Record | UnsetType = UNSET
    sdp: SdpRecord | UnsetType = UNSET


#: The verified quantities of whichever route gave the bound.
Margins = NoMargins | PsdMargins | Rank2Margins | SdpRecord | SectorRecord | LowRankMargins


class CopositivityRecord(Struct, kw_only=True):
    """The copositivity certificate's record (the JSON's ``certificate.copositivity``).

    Attributes:
        method: The route that gave the bound ("psd", "rank2-spn", "sdp-spn",
            "sdp-sectors", "split-spn", "lowrank-spn") or "none".
        delta: Relative distance of the bound below the load (None if none).
        margins: The route's verified quantities.
        negative_eigenvalues: m, pencil eigenvalues below the first shift tried.
        factorisations: Numeric factorisations.
        solves: Triangular solve pairs.
        time_s: Seconds (the slowest rank's).
        free_solve_s: Seconds of the free eigensolve (None if not timed), the unit of
            the split route's estimated cost.
        split: The split route's record (None if it did not run).
        lowrank: The low-rank route's record (None if it did not run).
    """

    method: str
    delta: float | None
    margins: Margins
    negative_eigenvalues: int | None
    factorisations: int
    solves: int
    time_s: float
    free_solve_s: float | None = None
    split: SplitRecord | None = None
    lowrank: LowRankRecord | None


@dataclass(frozen=True)
class Refuting:
    """An admissible mode with a load below the KKT point's, met by the split or low-rank route.

    Attributes:
        load: Its Rayleigh quotient.
        values: Its oriented values at the constrained nodes (max |w| = 1).
        vector: The owned entries of its W-vector.
    """

    load: float
    values: npt.NDArray[np.float64]
    vector: npt.NDArray[np.float64]
