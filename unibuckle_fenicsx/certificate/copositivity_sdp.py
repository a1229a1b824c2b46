r"""Copositivity certificates by semidefinite programming (two or more negative eigenvalues).

Needs the ``sdp`` extra (cvxpy with the Clarabel interior-point solver). Used by
:mod:`unibuckle_fenicsx.certificate.copositivity` when :math:`K(\lambda) = A - \lambda B` has two or
more negative eigenvalues, where the rank-2 route does not apply, and only for small i
(dense i x i programs).

**PSD + nonnegative split.** :math:`M = [K^{-1}]_{II}` (i solves), :math:`S = M^{-1}`, the
Schur complement of :math:`K_{FF}` on the constrained DOFs. Haynsworth:
:math:`\mathrm{In}(K) = \mathrm{In}(M) + \mathrm{In}(K_{FF})`, so
:math:`\mathrm{neg}(K) = \mathrm{neg}(S)` proves :math:`K_{FF} \succ 0`, and then the
cone condition on K is copositivity of S. The SDP maximises t with :math:`N \ge 0`,
:math:`D^{-1/2}(S - N)D^{-1/2} \succeq tI`; the answer is never trusted: N is clipped to
:math:`N \ge 0`, :math:`S - N \succ 0` is checked by LAPACK with a margin, and, as an
independent check, the sparse :math:`K - N_{pad}` must have no negative and no zero pivot
(MUMPS inertia).

**Sectors** (exactly two negative eigenvalues). The cone is split by the sector of
:math:`(g_1^Tu, g_2^Tu)`, :math:`g_j = B\psi_j` (:math:`\psi_j` the two lowest pencil
modes); on a piece with constraint rows G, :math:`K - G^TNG \succeq 0` with
:math:`N \ge 0` certifies it; with :math:`H = GK^{-1}G^T`, K is positive definite on
ker G iff :math:`\mathrm{neg}(H) = \mathrm{neg}(K)`, and then the condition is
:math:`N \preceq H^{-1}`. The split is valid for any :math:`g_j`.

Note:
    Collective on the problem's communicator; the dense programs run on every rank
    (identical data).
"""

from __future__ import annotations

import math
import warnings

from petsc4py import PETSc

import numpy as np
import numpy.typing as npt
from msgspec import UnsetType

try:
    import cvxpy as cp
except ImportError as err:  # pragma: no cover
    raise ImportError(
        "the SDP certificate needs cvxpy and Clarabel: pip install 'unibuckle_fenicsx[sdp]'"
    ) from err

from unibuckle_fenicsx.certificate.records import SdpRecord, SectorPiece, SectorRecord, SectorTry
from unibuckle_fenicsx.certificate.shifted import EPS, ShiftedMatrix
from unibuckle_fenicsx.la.factor import SymmetricFactorization
from unibuckle_fenicsx.la.options import Prefix
from unibuckle_fenicsx.model.problem import UnilateralProblem

__all__ = ["SDP_SOLVER", "sector_certificate", "spn_certificate"]

#: Interior-point solver and tight tolerances (the margin t scales like delta).
SDP_SOLVER: dict[str, str | float | int] = {
    "solver": "CLARABEL",
    "tol_gap_abs": 1e-13,
    "tol_gap_rel": 1e-13,
    "tol_feas": 1e-13,
    "tol_ktratio": 1e-10,
    "max_iter": 400,
}


def _inverse_on_constrained(
    problem: UnilateralProblem, matrix: ShiftedMatrix
) -> npt.NDArray[np.float64]:
    """M = [K^-1]_II by i refined solves, symmetrised."""
    n = problem.num_constrained
    M = np.empty((n, n))
    vec = problem.model.A.createVecRight()
    for k in range(n):
        e = np.zeros(n)
        e[k] = 1.0
        s = matrix.refined(problem.contact.scatter(e, vec.duplicate()))
        M[:, k] = problem.contact.values(s.x)
        s.destroy()
    vec.destroy()
    return 0.5 * (M + M.T)


def _psd_plus_nonnegative(
    H: npt.NDArray[np.float64],
) -> tuple[float, float, npt.NDArray[np.float64], str]:
    """Max t: N >= 0, D^-1/2 (H - N) D^-1/2 >= t I; returns (t, checked eigmin, N, status).

    N is clipped to >= 0 and symmetrised, and the smallest eigenvalue recomputed here.
    """
    d = 1.0 / np.sqrt(np.abs(np.diag(H)))
    Hs = H * d[:, None] * d[None, :]
    n = Hs.shape[0]
    N = cp.Variable((n, n), symmetric=True)
    t = cp.Variable()
    program = cp.Problem(cp.Maximize(t), [N >= 0, Hs - N - t * np.eye(n) >> 0, t <= 1.0])
    try:
        with warnings.catch_warnings():  # "inaccurate": the status says so, N is checked
            warnings.simplefilter("ignore", UserWarning)
            program.solve(**SDP_SOLVER)
    except cp.error.SolverError as err:
        return -math.inf, -math.inf, np.zeros((n, n)), f"solver failed: {err}"
    if N.value is None or t.value is None:
        return -math.inf, -math.inf, np.zeros((n, n)), str(program.status)
    Nv = np.maximum(0.5 * (N.value + N.value.T), 0.0)
    eig_min = float(np.linalg.eigvalsh(Hs - Nv).min())
    return float(t.value), eig_min, Nv / d[:, None] / d[None, :], str(program.status)


def _inertia_minus(
    problem: UnilateralProblem, matrix: ShiftedMatrix, N: npt.NDArray[np.float64]
) -> tuple[int, int]:
    """(negative, zero) pivots of K - N_pad, a separate MUMPS LDL^T."""
    if matrix.K is None:
        raise RuntimeError("_inertia_minus: expected matrix.K is not None (an internal invariant)")
    K = matrix.K.duplicate(copy=True)
    K.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)  # type: ignore[arg-type]
    rows = problem.contact.global_rows().astype(PETSc.IntType)
    owned = problem.contact._owned
    signs = problem.contact.signs  # N acts on the oriented values s_k u_k
    for position, row in zip(owned.positions, owned.global_dofs, strict=True):
        entries = -signs[position] * signs * N[position, :]
        K.setValues([row], rows, entries, addv=PETSc.InsertMode.ADD_VALUES)  # type: ignore[arg-type]
    K.assemble()
    factor = SymmetricFactorization(K, Prefix.CERTIFY + "sdp_")
    try:
        neg, zero, _ = factor.inertia()
    finally:
        factor.destroy()
        K.destroy()
    return neg, zero


def spn_certificate(problem: UnilateralProblem, matrix: ShiftedMatrix, lam: float) -> SdpRecord:
    r"""Copositivity of the Schur complement by a PSD + nonnegative split (see above).

    ``matrix`` holds the factorisation of :math:`K(\lambda)`, ``lam`` its shift.
    """
    if not matrix.factored:
        raise ValueError("spn_certificate: matrix must be factorised (ShiftedMatrix.factor)")
    neg_K = matrix.inertia()[0]
    S = np.linalg.inv(_inverse_on_constrained(problem, matrix))
    S = 0.5 * (S + S.T)
    neg_S = int((np.linalg.eigvalsh(S) < 0).sum())
    out = SdpRecord(ok=False, neg_K=neg_K, neg_S=neg_S, lam=lam)
    if neg_S != neg_K:
        out.why = "K_FF is not positive definite (neg(K) != neg(S))"
        return out
    t, eig_min, N, status = _psd_plus_nonnegative(S)
    n = S.shape[0]
    out.t, out.eig_min, out.status = t, eig_min, status
    if not eig_min > 1e3 * n * EPS:
        out.why = "S - N is not positive definite with margin"
        return out
    out.neg_zero_K_minus_N = list(_inertia_minus(problem, matrix, N))
    out.ok = out.neg_zero_K_minus_N == [0, 0]
    return out


def _lowest_modes(problem: UnilateralProblem, nev: int) -> list[PETSc.Vec]:
    """The nev lowest pencil modes with a positive load (for the sector rows).

    Lowest load first; the caller destroys the vectors. Collective.
    """
    from slepc4py import SLEPc

    from unibuckle_fenicsx.la.eigen import swapped_eigenpairs

    pairs = swapped_eigenpairs(
        problem.model.A,
        problem.model.B,
        Prefix.CERTIFY + "modes_",
        which=SLEPc.EPS.Which.LARGEST_REAL,
        nev=nev,
        tol=1e-12,
        vectors=True,
    )
    modes = []
    for theta, v in sorted(pairs, key=lambda p: -p[0]):
        if v is None:
            raise RuntimeError("_lowest_modes: expected v is not None (an internal invariant)")
        if theta > 0.0:
            modes.append(v)
        else:
            v.destroy()
    return modes


def sector_certificate(
    problem: UnilateralProblem, matrix: ShiftedMatrix, lam: float, sectors: tuple[int, ...]
) -> SectorRecord:
    """Copositivity on every sector piece of the cone (two negative eigenvalues)."""
    if not matrix.factored:
        raise RuntimeError("sector_certificate: expected matrix.factored (an internal invariant)")
    neg_K = matrix.inertia()[0]
    out = SectorRecord(ok=False, neg_K=neg_K, lam=lam)
    if neg_K != 2:
        out.why = "the sector split is implemented for two negative eigenvalues"
        return out
    n = problem.num_constrained
    rows: list[PETSc.Vec] = []
    vec = problem.model.A.createVecRight()
    for k in range(n):
        e = np.zeros(n)
        e[k] = 1.0
        rows.append(problem.contact.scatter(e, vec.duplicate()))
    for psi in _lowest_modes(problem, 2):
        g = vec.duplicate()
        problem.model.B.mult(psi, g)
        g.scale(1.0 / g.norm())
        rows.append(g)
        psi.destroy()
    vec.destroy()
    solves = [matrix.refined(g) for g in rows]  # each Solve owns its row vector
    r = len(rows)
    H0 = np.array([[rows[a].dot(solves[b].x).real for b in range(r)] for a in range(r)])
    H0 = 0.5 * (H0 + H0.T)
    for s in solves:
        s.destroy()
    for count in sectors:
        pieces: list[SectorPiece] = []
        for k in range(count):
            ta, tb = 2 * math.pi * k / count, 2 * math.pi * (k + 1) / count
            T = np.zeros((n + 2, r))
            T[:n, :n] = np.eye(n)
            T[n, n:] = [math.sin(ta), -math.cos(ta)]
            T[n + 1, n:] = [-math.sin(tb), math.cos(tb)]
            H = T @ H0 @ T.T
            eig = np.linalg.eigvalsh(H)
            if (
                int((eig < 0).sum()) != neg_K
                or np.abs(eig).min() <= 1e3 * r * EPS * np.abs(eig).max()
            ):
                pieces.append(SectorPiece(ok=False, why="K is not definite on the piece's kernel"))
                break
            t, eig_min, _, status = _psd_plus_nonnegative(np.linalg.inv(H))
            piece = SectorPiece(
                t=t, eig_min=eig_min, status=status, ok=bool(eig_min > 1e3 * r * EPS)
            )
            pieces.append(piece)
            if not piece.ok:
                break
        if isinstance(out.tries, UnsetType):
            out.tries = []
        out.tries.append(SectorTry(sectors=count, pieces=pieces))
        if len(pieces) == count and all(p.ok for p in pieces):
            out.ok, out.sectors = True, count
            out.eig_min = min(float(p.eig_min) for p in pieces if isinstance(p.eig_min, float))
            return out
    out.why = "a sector piece is not certified"
    return out
