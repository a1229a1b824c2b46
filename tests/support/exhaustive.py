"""Independent reference for small problems: the exhaustive minimum by dense linear algebra.

Used by the tests of the active-set method and of the random stress family: nothing here
calls the package's algorithms, only its assembled matrices A and B.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import scipy.linalg

from unibuckle_fenicsx.model.problem import UnilateralProblem

#: Relative agreement of loads: SLEPc converges to a relative residual of eps_tol = 1e-10
#: and LAPACK to about 1e-13 here, so 1e-8 leaves a margin of 100.
RTOL = 1e-8


def dense(mat) -> np.ndarray:
    n = mat.getSize()[0]
    idx = np.arange(n, dtype=np.int32)
    return np.asarray(mat.getValues(idx, idx))


def condensed(problem: UnilateralProblem):
    r"""(S, B_ww, free w-DOFs, position of each constrained node among them), densely.

    :math:`S = A_{ww} - A_{w\theta} A_{\theta\theta}^{-1} A_{\theta w}` on the free
    w-DOFs: the rotations condensed out (b acts on w only).
    """
    A, B = dense(problem.model.A), dense(problem.model.B)
    n = A.shape[0]
    bc = problem.model.bc_dofs
    w_all = problem.model.w_dofs
    w = np.setdiff1d(w_all, bc)  # free w-DOFs (serial: local == global)
    th = np.setdiff1d(np.setdiff1d(np.arange(n), w_all), bc)
    Ath = A[np.ix_(th, th)]
    S = A[np.ix_(w, w)] - A[np.ix_(w, th)] @ np.linalg.solve(Ath, A[np.ix_(th, w)])
    contact = problem.contact
    rows = [int(contact.removed_rows(np.array([k]))[0]) for k in range(contact.size)]
    return S, B[np.ix_(w, w)], w, np.searchsorted(w, rows)


def exhaustive_minimum(
    problem: UnilateralProblem, rtol: float = RTOL
) -> tuple[float, list[tuple[int, ...]], int]:
    r"""Smallest feasible :math:`\lambda(Z)` over all Z in 2^I, by dense linear algebra.

    The rotations are condensed out: :math:`S = A_{ww} - A_{w\theta} A_{\theta\theta}^{-1}
    A_{\theta w}` on the free w-DOFs; removing the w-DOFs of Z from (A, B) and condensing
    equals taking the principal submatrices of (S, B_ww). The largest eigenvalue mu of
    :math:`B_{ff} x = \mu S_{ff} x` gives :math:`\lambda = 1/\mu`; a mode is feasible
    when, for one sign, :math:`s_k w_k \le \tau \max|w|` on :math:`I \setminus Z`
    (:math:`s_k` = +1 under an obstacle above, -1 below).

    Returns:
        (lambda_min, or inf if no subset has a positive load; every Z with a feasible
        mode and lambda within ``rtol`` of the minimum; number of feasible sets).
    """
    S, Bw, w, node_pos = condensed(problem)
    contact = problem.contact
    i = contact.size
    tau = problem.tau
    loads: list[tuple[float, tuple[int, ...]]] = []
    for p in range(i + 1):
        combos = list(itertools.combinations(range(i), p))
        keep = np.ones((len(combos), len(w)), dtype=bool)
        for c, z in enumerate(combos):
            keep[c, node_pos[list(z)]] = False
        idx = np.array([np.flatnonzero(k) for k in keep])  # (C, m)
        if idx.shape[1] == 0:
            continue  # every w-DOF removed: no finite load
        Sz = S[idx[:, :, None], idx[:, None, :]]
        Bz = Bw[idx[:, :, None], idx[:, None, :]]
        L = np.linalg.cholesky(Sz)
        Li = np.linalg.inv(L)
        C = Li @ Bz @ np.swapaxes(Li, 1, 2)
        mu, Y = np.linalg.eigh(0.5 * (C + np.swapaxes(C, 1, 2)))
        X = np.swapaxes(Li, 1, 2) @ Y[:, :, -1:]  # w at the free w-DOFs
        for c, z in enumerate(combos):
            if mu[c, -1] <= 0.0:
                continue
            x = np.zeros(len(w))
            x[idx[c]] = X[c, :, 0]
            x /= np.abs(x).max()
            rest = np.setdiff1d(np.arange(i), z)
            vals = contact.signs[rest] * x[node_pos[rest]]  # oriented: <= 0 is admissible
            if rest.size == 0 or vals.max() <= tau or (-vals).max() <= tau:
                loads.append((1.0 / mu[c, -1], z))
    if not loads:  # no subset has a positive load: the plate does not buckle
        return math.inf, [], 0
    best = min(v for v, _ in loads)
    minimisers = [z for v, z in loads if v <= best * (1 + rtol)]
    return best, minimisers, len(loads)


def dense_free_load(problem: UnilateralProblem) -> float:
    """Smallest positive load of the whole pencil by LAPACK (``scipy.linalg.eigh``, inf if none).

    theta = 1/lambda below 1e-10 of the largest |theta| is round-off, not a load (LAPACK's
    generalized solver is accurate to about 1e-16 of it; e.g. a pure-shear plate with one
    row of free nodes, where b(w, w) vanishes identically by symmetry).
    """
    A, B = dense(problem.model.A), dense(problem.model.B)
    theta = scipy.linalg.eigh(B, A, eigvals_only=True)
    top = theta[-1]
    return 1.0 / top if top > 1e-10 * np.abs(theta).max() else math.inf


def dense_reduced_load(problem: UnilateralProblem, active: tuple[int, ...]) -> float:
    """lambda(Z) of the pencil with the edge DOFs and the w-DOFs of Z removed, by LAPACK.

    No condensation (the Schur complement of :func:`exhaustive_minimum` cancels digits on
    thin plates, where cond(A) reaches 1e11): the reference value of one contact set.
    """
    A, B = dense(problem.model.A), dense(problem.model.B)
    removed = np.union1d(problem.model.bc_dofs, problem.contact.removed_rows(np.array(active)))
    keep = np.setdiff1d(np.arange(A.shape[0]), removed)
    theta = scipy.linalg.eigh(B[np.ix_(keep, keep)], A[np.ix_(keep, keep)], eigvals_only=True)
    return 1.0 / theta[-1] if theta[-1] > 1e-10 * np.abs(theta).max() else math.inf


def satisfies_kkt(problem: UnilateralProblem, A, B, x: np.ndarray, load: float, active) -> bool:
    """Whether the mode x (all DOFs) of the contact set ``active`` satisfies the KKT conditions.

    Oriented to each node's obstacle (:math:`s_k w_k`, s = +1 under an obstacle above, -1
    over one below), it must stay off the obstacle off Z and the obstacle must only push
    on Z (README, "The problem"), both to the solver's tolerance tau. A and B are the
    assembled matrices (dense arrays or scipy sparse).
    """
    u = x / np.abs(x[problem.model.w_dofs]).max()
    rows = problem.contact.global_rows()
    signs = problem.contact.signs
    on_z = np.zeros(problem.num_constrained, dtype=bool)
    on_z[np.asarray(active, dtype=int)] = True
    tau = problem.tau
    for v in (u, -u):
        r = A @ v - load * (B @ v)
        z, force = signs * v[rows], signs * r[rows]
        if (
            z[~on_z].max(initial=-1.0) <= tau  # off the obstacle
            and force[on_z].max(initial=-1.0) <= tau * np.abs(A @ v).max()  # only pushes
        ):
            return True
    return False


def membrane_force_scale(spec) -> float:
    """T times the largest edge stress of ``spec`` (N/m per unit load): the size of N0."""
    stresses = [e.max_stress() for e in spec.plate.edges]
    return spec.plate.thickness * max(stresses)


def exhaustive_tensionless(problem: UnilateralProblem) -> float:
    r"""The critical load on tensionless foundations, by trying every spring set.

    The load minimises :math:`R(v) = (a(v, v) + \sum_k \rho_k \max(0, s_k v_k)^2)/b(v, v)`
    (the spring term counts where the plate presses). For a set S of nodes let
    :math:`\lambda_S, u_S` be the smallest eigenpair of :math:`(A + \sum_{k \in S}
    \rho_k e_k e_k^T, B)`. Then :math:`R(\pm u_S) \le \lambda_S` when the nodes
    :math:`\pm u_S` presses lie in S, and at the minimiser u*, with S* the nodes it
    presses, :math:`\lambda_{S^*} \le R(u^*)`: so :math:`\min_S \min_\pm R(\pm u_S)`,
    over every S, is the critical load (R(v) is never below it). Dense, on the condensed
    pencil (rotations out, the springs act on w); inf if no mode has b > 0.
    """
    S, Bw, _, node_pos = condensed(problem)
    contact = problem.contact
    rho, signs, i = contact.stiffness, contact.signs, contact.size
    best = math.inf
    subsets = np.array(list(itertools.product((False, True), repeat=i)), dtype=bool)
    for chunk in np.array_split(subsets, max(1, len(subsets) // 1024)):
        K = np.repeat(S[None], len(chunk), axis=0)
        diag = np.zeros((len(chunk), S.shape[0]))
        diag[:, node_pos] = chunk * rho
        K[:, np.arange(S.shape[0]), np.arange(S.shape[0])] += diag
        Li = np.linalg.inv(np.linalg.cholesky(K))
        C = Li @ Bw @ np.swapaxes(Li, 1, 2)
        _, Y = np.linalg.eigh(0.5 * (C + np.swapaxes(C, 1, 2)))
        X = (np.swapaxes(Li, 1, 2) @ Y[:, :, -1:])[:, :, 0]
        for x in (X, -X):
            b = np.einsum("cm,mn,cn->c", x, Bw, x)
            z = signs * x[:, node_pos]
            a = np.einsum("cm,mn,cn->c", x, S, x) + (rho * np.maximum(z, 0.0) ** 2).sum(axis=1)
            ok = b > 1e-12 * np.abs(b).max()
            if ok.any():
                best = min(best, float((a[ok] / b[ok]).min()))
    return best


def satisfies_spring_kkt(problem: UnilateralProblem, A, B, x: np.ndarray, load: float) -> bool:
    r"""Whether x (all DOFs) is stationary for the tensionless quotient at ``load``.

    The residual :math:`Au + \sum_k \rho_k \max(0, z_k) s_k e_k - \lambda Bu`, z the
    oriented mode at the foundation's nodes, against :math:`\|Au\|_2`: at most
    :math:`\sqrt\tau` (the solver's tolerance for a stationary point).
    """
    u = x / np.abs(x[problem.model.w_dofs]).max()
    contact = problem.contact
    rows = contact.global_rows()
    z = contact.signs * u[rows]
    r = A @ u - load * (B @ u)
    r[rows] += contact.stiffness * np.maximum(z, 0.0) * contact.signs
    return bool(np.linalg.norm(r) <= math.sqrt(problem.tau) * np.linalg.norm(A @ u))
