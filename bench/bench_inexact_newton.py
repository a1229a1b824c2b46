"""Measurement: the fine level's Newton steps solved by GMRES on an old factorisation.

The interior point's Newton matrices of one mesh, K_k = A - lambda_k B + Sigma_k
(Sigma_k the barrier's diagonal on the constrained DOFs), differ from step to step by a
multiple of B and a diagonal. An inexact Newton method would solve each step's two
systems, y2 = K^-1 Bu and y1 = K^-1 r, by a Krylov method preconditioned by the last
numeric LDL^T, and factorise again only when the Krylov iteration needs more than a
threshold of iterations. This script measures that along today's route, on its fine
level, without changing it (the loads are today's by construction):

- at every Newton direction of the fine level, after today's inertia-controlled
  factorisation, the same two systems (the final K, with its inertia correction) are
  solved again by GMRES (PETSc KSP, right-preconditioned so that its residual is the
  true one, restart = the cap, zero initial guess) preconditioned by a kept MUMPS
  LDL^T (the same ordering as the route's) of an older Newton matrix;
- ``prev``: the reference is the previous direction's matrix (the most favourable
  reuse, distance one step); the iterations to a relative residual of 1e-2, 1e-4 and
  1e-7 (the direct solve's own is at most 3e-7 at 180x60) are recorded, up to ``--cap``;
- a policy ``T:eta`` (``--policies``) reuses its reference while both systems reach
  ``eta`` in at most T iterations, and otherwise "refactorises": its reference becomes
  this step's matrix, and the step costs what today's did (its factorisations, the
  inertia loop included). ``T:eta:guard`` also refactorises wherever the scaled
  residual is at most ``local_residual`` (1e-2: where the route tests for a saddle,
  which needs the inertia of the unmodified K). Its count of factorisations is what
  the policy would have cost had it taken today's path (the steps it takes are exact
  to ``eta``, not to the direct solve's rounding); ``misses``: the reused steps whose
  unmodified K today had the wrong inertia (a correction or a saddle test the reuse
  would have skipped).

The bordered step: GMRES on the whole Newton system [[K, -Bu], [-Bu^T, 0]] [du; dlam] =
[r; -c] (c = (1 - u^T Bu)/2; K is nearly singular along the mode, the bordered matrix
is not), right-preconditioned by the same bordered matrix with K_ref (one solve with
its LDL^T per iteration, plus one for K_ref^-1 Bu, counted as an iteration). ``B:T:eta``
is a policy on the bordered step.

With ``--real today,B:10:1e-4,...`` the route itself runs with each policy on its fine
level (``today``: unchanged), one fresh process per plate and policy, and the table
gives its fine level, the reused steps and their Krylov iterations, and the load
against today's. A reused step has no inertia: it is taken only after a step whose
unmodified K had the right inertia, never where a contact set is read (the Tapia
indicator), and with ``guard`` never at a scaled residual at most 1e-2 (the saddle test).

The seconds (process time): one numeric factorisation of the fine Newton matrix and
one GMRES iteration (a triangular solve pair and a product with K), means over the run;
on a shared machine, to be re-measured on a quiet one. The counts are exact.

Usage: python bench/bench_inexact_newton.py [--meshes 180x60] [--cases cccc,shear]
[--policies 10:1e-4,B:10:1e-2,...] [--real today,B:10:1e-4,...] [--cap 60] [--json FILE]
[--from-json FILE]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from dataclasses import dataclass, field
from typing import Any

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
from _results import append_rows, print_header
from bench_plates import _spec

from unibuckle_fenicsx.algorithms.interior_point import kernel as kernel_module
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.la.factor import set_ldl_options

PREFIX = "bench_inexact_"
#: Relative residuals at which the iterations are recorded.
LEVELS = (1e-2, 1e-4, 1e-7)
_SAME = PETSc.Mat.Structure.SAME_NONZERO_PATTERN
#: The policies measured by default (``--policies``).
DEFAULT_POLICIES = "10:1e-4,10:1e-7,B:10:1e-4,B:10:1e-7,B:10:1e-4:guard,B:10:1e-2"


class Reference:
    """A kept LDL^T of an older Newton matrix and GMRES preconditioned by it."""

    def __init__(self, K: PETSc.Mat, prefix: str, cap: int) -> None:
        self.ref = K.duplicate(copy=True)
        self.ref.setOption(PETSc.Mat.Option.SPD, False)  # type: ignore[arg-type]
        self.ref.setOption(PETSc.Mat.Option.SYMMETRIC, True)  # type: ignore[arg-type]
        self.cur = K.duplicate(copy=True)
        self.ksp = PETSc.KSP().create(K.comm)
        self.ksp.setOperators(self.ref)
        set_ldl_options(self.ksp, prefix, reused=True)
        self.ksp.setOperators(self.cur, self.ref)
        self.ksp.setType(PETSc.KSP.Type.GMRES)
        self.ksp.setGMRESRestart(cap)
        self.ksp.setPCSide(PETSc.PC.Side.RIGHT)
        self.ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
        self.ksp.setTolerances(rtol=min(LEVELS), atol=0.0, max_it=cap)
        self.ksp.setConvergenceHistory(length=cap + 1, reset=True)
        self.x = K.createVecLeft()
        self.pc = self.ksp.getPC()
        self.valid = False
        self.t_factor = 0.0
        self.factors = 0
        self.t_gmres = 0.0
        self.iterations = 0

    def refresh(self, K: PETSc.Mat) -> None:
        """Factorise a copy of K as the reference."""
        K.copy(self.ref, structure=_SAME)
        self.ksp.getPC().setReusePreconditioner(False)
        self.ksp.setOperators(self.cur, self.ref)
        t0 = time.process_time()
        self.ksp.setUp()
        self.t_factor += time.process_time() - t0
        self.factors += 1
        self.ksp.getPC().setReusePreconditioner(True)
        self.valid = True

    def iterations_to(self, K: PETSc.Mat, b: PETSc.Vec, rtol: float, cap: int) -> list[int]:
        """GMRES on K x = b; the iterations to each of LEVELS (cap + 1: not reached)."""
        K.copy(self.cur, structure=_SAME)
        self.ksp.setTolerances(rtol=rtol, atol=0.0, max_it=cap)
        self.x.zeroEntries()
        t0 = time.process_time()
        self.ksp.solve(b, self.x)
        self.t_gmres += time.process_time() - t0
        hist = np.asarray(self.ksp.getConvergenceHistory())
        self.iterations += max(len(hist) - 1, 0)
        bnorm = float(b.norm())
        out = []
        for level in LEVELS:
            hit = np.flatnonzero(hist <= level * bnorm)
            out.append(int(hit[0]) if hit.size else cap + 1)
        return out

    def destroy(self) -> None:
        """Destroy the KSP, the matrices and the work vector."""
        for obj in (self.ksp, self.ref, self.cur, self.x):
            obj.destroy()


class _Bordered:
    """The step's bordered matrix [[K, -Bu], [-Bu^T, 0]] (a PETSc python Mat context)."""

    def __init__(self, K: PETSc.Mat, Bu: PETSc.Vec) -> None:
        self.K, self.Bu = K, Bu
        self.t = K.createVecLeft()

    def mult(self, mat: PETSc.Mat, x: PETSc.Vec, y: PETSc.Vec) -> None:
        n = self.t.getSize()
        xa = x.getArray(readonly=True)
        self.t.setArray(xa[:n])
        out = self.K.createVecLeft()
        self.K.mult(self.t, out)
        bu = self.Bu.getArray(readonly=True)
        y.setArray(np.append(out.getArray(readonly=True) - xa[n] * bu, -float(bu @ xa[:n])))
        out.destroy()


class _BorderedPC:
    """The bordered matrix with the reference's K_ref: one solve with its LDL^T per use."""

    def __init__(self, ref: Reference, Bu: PETSc.Vec) -> None:
        self.ref, self.Bu = ref, Bu
        self.a, self.x = Bu.duplicate(), Bu.duplicate()
        self.y2 = Bu.duplicate()
        self.ref.pc.apply(Bu, self.y2)  # K_ref^-1 Bu
        self.by2 = float(Bu.dot(self.y2))

    def apply(self, pc: PETSc.PC, r: PETSc.Vec, z: PETSc.Vec) -> None:
        n = self.a.getSize()
        ra = r.getArray(readonly=True)
        self.a.setArray(ra[:n])
        self.ref.pc.apply(self.a, self.x)
        bu = self.Bu.getArray(readonly=True)
        s = -(ra[n] + float(bu @ self.x.getArray(readonly=True))) / self.by2
        x = self.x.getArray(readonly=True)
        z.setArray(np.append(x + s * self.y2.getArray(readonly=True), s))

    def close(self) -> None:
        for v in (self.a, self.x, self.y2):
            v.destroy()


def bordered_solve(ref: Reference, K: PETSc.Mat, Bu: PETSc.Vec, r: PETSc.Vec, c: float,
                   cap: int, rtol: float) -> tuple[np.ndarray, np.ndarray, float]:  # fmt: skip
    """GMRES on the bordered step [[K, -Bu], [-Bu^T, 0]] [du; dlam] = [r; -c] (serial).

    Right-preconditioned by the bordered matrix with the reference's K_ref (one solve
    with its LDL^T per iteration, and one for K_ref^-1 Bu). Returns the solution, the
    residual history and the norm of the right-hand side.
    """
    n = K.getSize()[0]
    ctx = _Bordered(K, Bu)
    J = PETSc.Mat().createPython([n + 1, n + 1], ctx, comm=K.comm)
    J.setUp()
    pctx = _BorderedPC(ref, Bu)
    ksp = PETSc.KSP().create(K.comm)
    ksp.setOptionsPrefix(PREFIX + "bordered_")
    ksp.setOperators(J)
    ksp.setType(PETSc.KSP.Type.GMRES)
    ksp.setGMRESRestart(cap)
    pc = ksp.getPC()
    pc.setType(PETSc.PC.Type.PYTHON)
    pc.setPythonContext(pctx)
    ksp.setPCSide(PETSc.PC.Side.RIGHT)
    ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
    ksp.setTolerances(rtol=rtol, atol=0.0, max_it=cap)
    ksp.setConvergenceHistory(length=cap + 1, reset=True)
    b, x = J.createVecs()
    b.setArray(np.append(r.getArray(readonly=True), -c))
    x.zeroEntries()
    ksp.solve(b, x)
    hist = np.asarray(ksp.getConvergenceHistory())
    bnorm = float(b.norm())
    sol = x.getArray(readonly=True).copy()
    for obj in (ksp, J, b, x):
        obj.destroy()
    pctx.close()
    return sol, hist, bnorm


def bordered_iterations(ref: Reference, K: PETSc.Mat, Bu: PETSc.Vec, r: PETSc.Vec,
                        c: float, cap: int, rtol: float = min(LEVELS)) -> list[int]:  # fmt: skip
    """The iterations of :func:`bordered_solve` to each of LEVELS (cap + 1: not reached).

    One is counted for the preconditioner's set-up (the reference's solve of Bu).
    """
    _, hist, bnorm = bordered_solve(ref, K, Bu, r, c, cap, rtol)
    out = []
    for level in LEVELS:
        hit = np.flatnonzero(hist <= level * bnorm)
        out.append(int(hit[0]) + 1 if hit.size else cap + 1)
    return out


@dataclass
class Policy:
    """Reuse while both systems reach ``eta`` in ``threshold`` iterations."""

    threshold: int
    eta: float
    guard: bool
    bordered: bool
    ref: Reference | None = None
    factorisations: int = 0
    reused: int = 0
    misses: int = 0
    iterations: list[int] = field(default_factory=list)

    @property
    def name(self) -> str:
        """``[B:]T:eta[:guard]``."""
        head = "B:" if self.bordered else ""
        return f"{head}{self.threshold}:{self.eta:g}" + (":guard" if self.guard else "")


def _parse(text: str) -> list[Policy]:
    out = []
    for item in filter(None, text.split(",")):
        parts = item.split(":")
        bordered = parts[0] == "B"
        parts = parts[1:] if bordered else parts
        guard = len(parts) > 2 and parts[2] == "guard"
        out.append(Policy(int(parts[0]), float(parts[1]), guard, bordered))
    return out


def _apply_policy(p: Policy, kernel: Any, u: PETSc.Vec, e_u: float, wrong: bool) -> Any:
    """Whether ``p`` reuses its factorisation at this direction (else it refactorises).

    Returns the Krylov iterations of a reused step, or None.
    """
    assert p.ref is not None
    its: list[int] = []
    if p.ref.valid and not (p.guard and e_u <= 1e-2):
        if p.bordered:
            c = -0.5 * (float(u.dot(kernel.Bu)) - 1.0)
            got = bordered_iterations(p.ref, kernel.K, kernel.Bu, kernel.rhs, c, p.threshold, p.eta)
            its = [got[LEVELS.index(p.eta)]]
        else:
            its = [_reach(p.ref, kernel.K, b, p.eta, p.threshold) for b in (kernel.Bu, kernel.rhs)]
    if its and max(its) <= p.threshold:
        p.reused += 1
        p.iterations.append(sum(its))
        p.misses += int(wrong)
        return its
    p.factorisations += kernel._made
    p.ref.refresh(kernel.K)
    return None


def _scaled_residual(kernel: Any, lam: float) -> float:
    """The Newton step's scaled residual |F_u|_inf / (lambda |Bu|_inf) (the route's e_u)."""
    inf = PETSc.NormType.INFINITY
    return float(kernel.Fu.norm(inf)) / (lam * float(kernel.Bu.norm(inf)))


def _instrument(fine_dofs: int, policies: list[Policy], cap: int, steps: list[dict]) -> dict:
    """Wrap NewtonKernel.direction and .factor on the mesh of ``fine_dofs`` DOFs."""
    cls = kernel_module.NewtonKernel
    state: dict[str, Any] = {"prev": None, "outside": 0, "inside": False}
    direction_inner, factor_inner = cls.direction, cls.factor

    def factor(self: Any, *args: Any, **kwargs: Any) -> Any:
        if int(self.A.getSize()[0]) == fine_dofs and not state["inside"]:
            state["outside"] += 1
        return factor_inner(self, *args, **kwargs)

    def direction(self: Any, u: Any, lam: float, nu: Any, gap: Any, mu_abs: float,
                  plain_first: bool = True) -> Any:  # fmt: skip
        if int(self.A.getSize()[0]) != fine_dofs:
            return direction_inner(self, u, lam, nu, gap, mu_abs, plain_first)
        e_u = _scaled_residual(self, lam)
        f0 = self.factorizations
        state["inside"] = True
        try:
            got = direction_inner(self, u, lam, nu, gap, mu_abs, plain_first)
        finally:
            state["inside"] = False
        made = self.factorizations - f0
        self._made = made
        if got is None:
            steps.append({"made": made, "failed": True})
            for p in policies:
                p.factorisations += made
            return got
        # Today's step: K (final, with its correction) in self.K; rhs and Bu kept.
        wrong = made > 1 or self.last_correction > 0.0
        row: dict[str, Any] = {"made": made, "wrong": wrong, "e_u": e_u,
                               "correction": self.last_correction}  # fmt: skip
        if state["prev"] is None:
            state["prev"] = Reference(self.K, PREFIX + "prev_", cap)
            for k, p in enumerate(policies):
                p.ref = Reference(self.K, f"{PREFIX}p{k}_", cap)
        prev: Reference = state["prev"]
        if prev.valid:
            row["prev_y2"] = prev.iterations_to(self.K, self.Bu, min(LEVELS), cap)
            row["prev_y1"] = prev.iterations_to(self.K, self.rhs, min(LEVELS), cap)
            if self.comm.size == 1:
                c = -0.5 * (float(u.dot(self.Bu)) - 1.0)
                row["prev_bordered"] = bordered_iterations(prev, self.K, self.Bu, self.rhs, c, cap)
        prev.refresh(self.K)
        for p in policies:
            row[p.name] = _apply_policy(p, self, u, e_u, wrong)
        steps.append(row)
        return got

    cls.direction = direction  # type: ignore[method-assign]
    cls.factor = factor  # type: ignore[method-assign]
    return state


def _instrument_real(fine_dofs: int, policy: Policy, cap: int, log: list[dict]) -> dict:
    """Make the fine level's Newton steps follow ``policy`` (the route changes).

    A direction reuses the reference (GMRES on the bordered step, to ``policy.eta`` in
    at most ``policy.threshold`` iterations, with the plain K = A - lambda B + Sigma)
    where the reference's own step needed no inertia correction, no contact set is
    being read (the Tapia indicator needs the exact step and its factorisation) and,
    with ``guard``, the scaled residual is above 1e-2 (the saddle test needs the
    inertia of the plain K). Otherwise today's direction runs (its factorisations, the
    inertia loop) and its final matrix becomes the reference (a copy, factorised
    apart from the route's counts). A reused step has no correction, so no
    negative-curvature step follows it.
    """
    from unibuckle_fenicsx.algorithms.interior_point import newton

    cls = kernel_module.NewtonKernel
    ncls = newton.InteriorPointNewton
    st: dict[str, Any] = {"ref": None, "ok": False, "exact": 0, "refreshes": 0}
    direction_inner, pcs_inner = cls.direction, ncls.predicted_contact_set

    def pcs(self: Any, point: Any) -> Any:
        st["exact"] += 1
        try:
            return pcs_inner(self, point)
        finally:
            st["exact"] -= 1

    def direction(self: Any, u: Any, lam: float, nu: Any, gap: Any, mu_abs: float,
                  plain_first: bool = True) -> Any:  # fmt: skip
        if int(self.A.getSize()[0]) != fine_dofs:
            return direction_inner(self, u, lam, nu, gap, mu_abs, plain_first)
        e_u = _scaled_residual(self, lam)
        ref: Reference | None = st["ref"]
        guarded = policy.guard and e_u <= 1e-2
        if ref is not None and st["ok"] and not st["exact"] and not guarded:
            K = ref.cur
            self.A.copy(K, structure=_SAME)
            K.axpy(-lam, self.B_on_A, structure=_SAME)
            self.diag.zeroEntries()
            self.diag.array[self.dofs] += nu / gap
            K.setDiagonal(self.diag, addv=PETSc.InsertMode.ADD_VALUES)
            f_c = nu * gap - mu_abs
            self.Fu.copy(self.rhs)
            self.rhs.scale(-1.0)
            self.add_zone(self.rhs, f_c / gap)
            c = -0.5 * (float(u.dot(self.Bu)) - 1.0)
            t0 = time.process_time()
            x, hist, bnorm = bordered_solve(ref, K, self.Bu, self.rhs, c, policy.threshold,
                                            policy.eta)  # fmt: skip
            ref.t_gmres += time.process_time() - t0
            its = len(hist) - 1
            ref.iterations += its + 1
            if hist[-1] <= policy.eta * bnorm:
                n = self.du.getSize()
                self.du.setArray(x[:n])
                self.last_correction = 0.0
                dz = self.oriented(self.du)
                log.append({"reused": True, "its": its + 1, "e_u": e_u})
                return float(x[n]), dz, (-f_c + nu * dz) / gap
            log.append({"reused": False, "its": its + 1, "e_u": e_u})
        else:
            log.append({"reused": False, "its": 0, "e_u": e_u})
        f0 = self.factorizations
        got = direction_inner(self, u, lam, nu, gap, mu_abs, plain_first)
        log[-1]["made"] = self.factorizations - f0
        if got is not None:
            if ref is None:
                ref = st["ref"] = Reference(self.K, PREFIX + "real_", cap)
            ref.refresh(self.K)
            st["ok"] = self.last_correction == 0.0
        return got

    cls.direction = direction  # type: ignore[method-assign]
    ncls.predicted_contact_set = pcs  # type: ignore[method-assign]
    return st


def _reach(ref: Reference, K: PETSc.Mat, b: PETSc.Vec, eta: float, cap: int) -> int:
    K.copy(ref.cur, structure=_SAME)
    ref.ksp.setTolerances(rtol=eta, atol=0.0, max_it=cap)
    ref.x.zeroEntries()
    ref.ksp.solve(b, ref.x)
    hist = np.asarray(ref.ksp.getConvergenceHistory())
    hit = np.flatnonzero(hist <= eta * float(b.norm()))
    return int(hit[0]) if hit.size else cap + 1


def real_worker(case: str, nx: int, ny: int, policy_text: str, cap: int) -> None:
    """One plate in this process, its fine level run by ``policy``; print a JSON line."""
    spec = _spec(case, nx, ny)
    from unibuckle_fenicsx.model.build import build_problem

    with build_problem(spec, MPI.COMM_WORLD) as probe:
        fine_dofs = int(probe.model.A.getSize()[0])
    log: list[dict] = []
    st: dict[str, Any] = {"ref": None}
    if policy_text != "today":
        (policy,) = _parse(policy_text)
        st = _instrument_real(fine_dofs, policy, cap, log)
    c0 = time.process_time()
    with solve(spec, MPI.COMM_WORLD) as run:
        seconds = time.process_time() - c0
        sol = run.solution
        assert sol is not None
        levels = sol.details.levels
        ref: Reference | None = st["ref"]
        row = {
            "case": case,
            "mesh": f"{nx}x{ny}",
            "policy": policy_text,
            "load": sol.candidate.load,
            "kkt": bool(sol.candidate.kkt),
            "contact": int(sol.candidate.active.size),
            "route": list(sol.route),
            "levels": [[lv.newton_steps, lv.factorizations, lv.eigensolves] for lv in levels],
            "fine": [levels[-1].newton_steps, levels[-1].factorizations, levels[-1].eigensolves],
            "reused": sum(1 for e in log if e["reused"]),
            "krylov_reused": [e["its"] for e in log if e["reused"]],
            "krylov_failed": [e["its"] for e in log if not e["reused"] and e["its"]],
            "t_factor": ref.t_factor / max(ref.factors, 1) if ref else None,
            "t_iteration": ref.t_gmres / max(ref.iterations, 1) if ref else None,
            "process_s": seconds,
        }
        if ref is not None:
            ref.destroy()
    print("RESULT " + json.dumps(row), flush=True)


def worker(case: str, nx: int, ny: int, policies_text: str, cap: int) -> None:
    """One plate in this process: today's route, instrumented; print a JSON line."""
    spec = _spec(case, nx, ny)
    from unibuckle_fenicsx.model.build import build_problem

    with build_problem(spec, MPI.COMM_WORLD) as probe:
        fine_dofs = int(probe.model.A.getSize()[0])
    policies = _parse(policies_text)
    steps: list[dict] = []
    state = _instrument(fine_dofs, policies, cap, steps)
    c0 = time.process_time()
    with solve(spec, MPI.COMM_WORLD) as run:
        seconds = time.process_time() - c0
        sol = run.solution
        assert sol is not None
        lv = sol.details.levels[-1]
        prev: Reference = state["prev"]
        t_fact = prev.t_factor / max(prev.factors, 1)
        t_iter = prev.t_gmres / max(prev.iterations, 1)
        row: dict[str, Any] = {
            "case": case,
            "mesh": f"{nx}x{ny}",
            "dofs": fine_dofs,
            "load": sol.candidate.load,
            "kkt": bool(sol.candidate.kkt),
            "fine": [lv.newton_steps, lv.factorizations, lv.eigensolves],
            "directions": len(steps),
            "direction_factorisations": sum(s["made"] for s in steps),
            "outside_factorisations": state["outside"],
            "wrong_inertia_steps": sum(1 for s in steps if s.get("wrong")),
            "t_factor": t_fact,
            "t_iteration": t_iter,
            "process_s": seconds,
            "steps": steps,
            "policies": [
                {
                    "name": p.name,
                    "factorisations": p.factorisations,
                    "reused": p.reused,
                    "misses": p.misses,
                    "iterations": p.iterations,
                }
                for p in policies
            ],
        }
        for p in policies:
            if p.ref is not None:
                p.ref.destroy()
        prev.destroy()
    print("RESULT " + json.dumps(row), flush=True)


def _quantiles(values: list[int], cap: int) -> str:
    """min/median/max of iteration counts (cap + 1: not reached within the cap)."""
    if not values:
        return "-"
    arr = np.asarray(values)
    over = int((arr > cap).sum())

    def show(v: float) -> str:
        return f">{cap}" if v > cap else str(int(v))

    return f"{show(arr.min())}/{show(np.median(arr))}/{show(arr.max())} ({over} over)"


def print_tables(rows: list[dict[str, Any]], cap: int) -> None:
    """The two tables: GMRES on the previous step's LDL^T, and the reuse policies."""
    cols = ["plate", "mesh", "fine level (steps/fact./eigen)", "load (Pa)", "steps",
            "y2 to 1e-2", "y2 to 1e-7", "y1 to 1e-2", "y1 to 1e-7",
            "bordered to 1e-2", "bordered to 1e-4", "bordered to 1e-7",
            "t_fact (s)", "t_iter / t_fact"]  # fmt: skip
    print_header(
        "GMRES iterations per Newton direction, preconditioned by the previous "
        "direction's LDL^T (min/median/max; counts exact, seconds on a shared machine)",
        cols,
    )
    for row in rows:
        good = [s for s in row["steps"] if "prev_y2" in s]
        q = [
            _quantiles([s[f"prev_{name}"][k] for s in good if f"prev_{name}" in s], cap)
            for name, k in (("y2", 0), ("y2", 2), ("y1", 0), ("y1", 2),
                            ("bordered", 0), ("bordered", 1), ("bordered", 2))
        ]  # fmt: skip
        cells = [row["case"], row["mesh"], "/".join(str(v) for v in row["fine"]),
                 f"{row['load']:.6f}", str(len(good)), *q,
                 f"{row['t_factor']:.3f}",
                 f"{row['t_iteration'] / row['t_factor']:.3f}"]  # fmt: skip
        print("| " + " | ".join(cells) + " |", flush=True)
    print()
    cols = ["plate", "mesh", "policy", "direction factorisations (today)", "reused steps",
            "Krylov its per reused step (mean)", "misses (inertia)",
            "cost in factorisations' time (today)"]  # fmt: skip
    print_header("Reuse policies along today's path (T:eta; B: the bordered step)", cols)
    for row in rows:
        today = row["direction_factorisations"]
        ratio = row["t_iteration"] / row["t_factor"]
        for p in row["policies"]:
            its = p["iterations"]
            mean = f"{np.mean(its):.1f}" if its else "-"
            cost = p["factorisations"] + ratio * sum(its)
            cells = [row["case"], row["mesh"], p["name"], f"{p['factorisations']} ({today})",
                     str(p["reused"]), mean, str(p["misses"]), f"{cost:.1f} ({today})"]  # fmt: skip
            print("| " + " | ".join(cells) + " |", flush=True)


def print_real(rows: list[dict[str, Any]]) -> None:
    """The table of the routes run with the policies, against ``today`` where run.

    The cost counts every Krylov iteration (the failed tries' too) at the run's own
    price of an iteration against a numeric factorisation.
    """
    cols = ["plate", "mesh", "policy", "fine level (steps/fact./eigen)", "reused steps",
            "Krylov its per reused step (mean)", "failed tries (its)",
            "fine fact. + Krylov its (factorisations' time)", "route", "load (Pa)",
            "relative to today"]  # fmt: skip
    print_header("The route with its fine level run by a policy (counts exact)", cols)
    today = {(r["case"], r["mesh"]): r["load"] for r in rows if r["policy"] == "today"}
    for r in rows:
        ref = today.get((r["case"], r["mesh"]))
        rel = "-" if ref is None else f"{(r['load'] - ref) / ref:+.1e}"
        its, failed = r["krylov_reused"], r["krylov_failed"]
        ratio = r["t_iteration"] / r["t_factor"] if r["t_factor"] else 0.0
        cost = r["fine"][1] + ratio * (sum(its) + sum(failed))
        cells = [r["case"], r["mesh"], r["policy"], "/".join(str(v) for v in r["fine"]),
                 str(r["reused"]), f"{np.mean(its):.1f}" if its else "-",
                 f"{len(failed)} ({sum(failed)})", f"{cost:.1f}",
                 "+".join(r["route"]), f"{r['load']:.9f}", rel]  # fmt: skip
        print("| " + " | ".join(cells) + " |", flush=True)


def run_real(args: Any) -> None:
    """Run the route with each policy of ``--real`` (``today``: unchanged) per plate."""
    rows = []
    for m in args.meshes.split(","):
        nx, ny = (int(v) for v in m.split("x"))
        for case in args.cases.split(","):
            for policy in args.real.split(","):
                cmd = [sys.executable, __file__, "--worker", case, str(nx), str(ny),
                       "--real", policy, "--cap", str(args.cap)]  # fmt: skip
                out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
                line = next(ln for ln in out.splitlines() if ln.startswith("RESULT "))
                row = json.loads(line[len("RESULT ") :])
                rows.append(row)
                append_rows(args.json, [row])
    print_real(rows)


def main() -> None:
    """Run the plates (each in its own process) and print the tables."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default="180x60")
    parser.add_argument("--cases", default="cccc,shear")
    parser.add_argument("--policies", default=DEFAULT_POLICIES)
    parser.add_argument("--cap", type=int, default=60)
    parser.add_argument("--json", default=None)
    parser.add_argument("--from-json", default=None, help="print the tables of a results file")
    parser.add_argument("--worker", nargs=3, default=None)
    parser.add_argument(
        "--real", default=None, help="run the route with these policies (today: unchanged)"
    )
    args, _ = parser.parse_known_args()
    if args.cap < 1:
        parser.error(f"--cap must be at least 1, got {args.cap}")
    for p in _parse(args.policies):
        if p.bordered and p.eta not in LEVELS:
            parser.error(f"--policies: a bordered policy's eta must be one of {LEVELS}")
    if args.from_json:
        with open(args.from_json, encoding="utf-8") as f:
            rows = [json.loads(line) for line in f if line.strip()]
        if rows and "policy" in rows[0]:
            print_real(rows)
        else:
            print_tables(rows, args.cap)
        return
    if args.worker and args.real:
        case, nx, ny = args.worker
        real_worker(case, int(nx), int(ny), args.real, args.cap)
        return
    if args.worker:
        case, nx, ny = args.worker
        worker(case, int(nx), int(ny), args.policies, args.cap)
        return
    if args.real:
        run_real(args)
        return
    rows = []
    for m in args.meshes.split(","):
        nx, ny = (int(v) for v in m.split("x"))
        for case in args.cases.split(","):
            cmd = [sys.executable, __file__, "--worker", case, str(nx), str(ny),
                   "--policies", args.policies, "--cap", str(args.cap)]  # fmt: skip
            out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
            line = next(ln for ln in out.splitlines() if ln.startswith("RESULT "))
            row = json.loads(line[len("RESULT ") :])
            rows.append(row)
            append_rows(args.json, [row])
    print_tables(rows, args.cap)


if __name__ == "__main__":
    main()
