"""Prototype: the fine level's active-set polish on one fixed factorisation (capacitance).

Measures whether the fine level of the interior-point route could be one numeric
LDL^T plus solves, instead of today's Newton steps (one or two factorisations each).
For each benchmark thin plate of ``bench_plates.py`` (0.3 x 0.1 m, t = 0.1 mm, obstacle
over the whole face) and fine mesh, in one process:

1. today's route on the fine mesh (``solve``): its load and the fine level's Newton
   steps / factorisations / eigen solves; the contact sets the interior point reads on
   the fine mesh are recorded, each with the numeric factorisations (PETSc's
   ``MatCholFctrNum``) since the fine mesh's first Newton run;
2. the primal-dual active-set iteration (``pdas.iterate``, the chain's polish) from
   three starts: today's KKT set (a check of the solve: one eigen solve, today's
   load); the next coarser mesh's KKT set (today's route on that mesh) carried to the
   fine nodes (``multilevel.prolong``), with its mode interpolated; and the first set
   the interior point reads on the fine mesh, with its barrier point's mode;
3. every reduced pencil of the iteration (Z removed) is solved on ONE numeric
   factorisation of K = A - sigma B (sigma = (1 - ``--margin``) times the start's load),
   with the nodes of the start outside a *band* removed in it. The band: the nodes
   within ``--band`` node spacings of the start's boundary (either side), the carried
   degenerate nodes (on the coarse set with a force below ``--degenerate`` of the
   largest, or off it with a value above minus that) and, from today's set and the
   fine read, the whole set (none removed in K). A set that releases a removed node
   is solved on a new factorisation (counted). The capacitance matrix G = E^T K^-1 E
   of the unit vectors E of the nodes met (the band first, any other node when a set
   first holds it) comes from multi-RHS solves (``Mat.matSolve``), and the solve of
   the spectral transformation (a shell PC under Krylov-Schur's shift-and-invert) is

       x = K^-1 (r' - E_C z),   G_CC z = (K^-1 r')_C,   x_C = r_C   (r' = r, zero on C)

   (Woodbury: two sparse solves and a dense solve with the principal block G_CC of the
   set's nodes C), with the inertia of the reduced K_C by Haynsworth's formula,
   neg(K_C) = neg(K) - neg(G_CC) - zero(G_CC): 0 proves no eigenvalue below sigma.
   B indefinite (shear): the swapped pencil at 1/sigma, as ``la.eigen`` solves it.

Printed per plate and start: today's fine level, the prototype's factorisations,
sparse solves (G's columns + two per operator application), G's columns, eigen
solves, how it ended, its load against today's, and the process seconds of the
factorisations, of G, of the eigen solves and of the whole polish, also in numeric
factorisations of the fine pencil. The counts and loads are exact; the seconds are
the minimum of ``--repeat`` runs, on a shared machine to be re-measured on a quiet one.
MUMPS's own Schur complement (ICNTL(19)) would give G in one factorisation, but
petsc4py 3.25 does not expose ``MatFactorSetSchurIS``, and PETSc computes it in serial
only. Serial only (G is gathered on one process).

Usage: python bench/bench_fixed_factor.py [--meshes 90x30,180x60] [--cases ssss,cccc]
[--band 2] [--degenerate 1e-3] [--margin 1e-2] [--thresholds T1,T2] [--repeat N]
[--json FILE]
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from typing import Any

from mpi4py import MPI
from petsc4py import PETSc
from slepc4py import SLEPc

import numpy as np
import numpy.typing as npt
import scipy.linalg
from _results import append_rows, print_header
from bench_plates import _spec
from msgspec.structs import replace

from unibuckle_fenicsx.algorithms import pdas
from unibuckle_fenicsx.algorithms.multilevel import Prolongation, prolong, prolong_contact_set
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.la.factor import set_ldl_options
from unibuckle_fenicsx.model.problem import Candidate, UnilateralProblem
from unibuckle_fenicsx.spec import MeshSpec

PREFIX = "bench_fixed_"
#: Pairs asked of each reduced solve (the lowest two of a long plate lie within 0.1 %,
#: and with one pair a start close to the second mode converged to it).
NEV = 2
#: Capacitance columns per multi-RHS solve (bounds the dense work arrays).
BLOCK = 256
#: The process seconds kept per run (their minimum over the runs).
TIMES = ("t_factor", "t_capacitance", "t_eigen", "t_total")
#: ``pdas.iterate``'s looser tolerances (``--thresholds``; none: the chain's polish).
THRESHOLDS: tuple[float, ...] = ()
#: Eigen solves allowed to each active-set run.
MAX_ITERATIONS = 30


class Capacitance:
    """One LDL^T of A - sigma B with the nodes ``fixed`` removed; capacitance columns.

    The capacitance matrix G = E^T K^-1 E is kept for the nodes met so far (``nodes``),
    grown by one multi-RHS solve per batch of new nodes.
    """

    def __init__(
        self, problem: UnilateralProblem, fixed: npt.NDArray[np.int64], sigma: float
    ) -> None:
        solver = problem.eigensolver
        self.A, self.B, self.sigma = solver.A, solver.B, sigma
        self.problem = problem
        self.rows_of = problem.contact.global_rows()  # serial: global = local
        self.fixed = np.unique(np.asarray(fixed, dtype=np.int64))
        K = self.A.duplicate(copy=True)
        K.axpy(-sigma, self.B, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)  # type: ignore[arg-type]
        K.zeroRowsColumns(self.rows_of[self.fixed].astype(PETSc.IntType), diag=1.0)  # type: ignore[arg-type]
        K.setOption(PETSc.Mat.Option.SPD, False)  # type: ignore[arg-type]
        K.setOption(PETSc.Mat.Option.SYMMETRIC, True)  # type: ignore[arg-type]
        self.K = K
        self.ksp = PETSc.KSP().create(K.comm)
        self.ksp.setOperators(K)
        set_ldl_options(self.ksp, PREFIX + "ldl_", reused=False)
        t0 = time.process_time()
        self.ksp.setUp()
        self.t_factor = time.process_time() - t0
        self.neg = int(self.ksp.getPC().getFactorMatrix().getInertia()[0])
        self.nodes = np.empty(0, np.int64)
        self.G = np.empty((0, 0))
        self.t_capacitance = 0.0
        self.solves = 0
        self.applications = 0
        self._y = K.createVecLeft()
        self._r = K.createVecLeft()
        self.set_constrained(np.empty(0, np.int64))

    def ensure(self, nodes: npt.NDArray[np.int64]) -> None:
        """Grow G by the columns of ``nodes`` not met before (K^-1 of their unit vectors)."""
        new = np.setdiff1d(np.setdiff1d(nodes, self.nodes), self.fixed)
        if new.size == 0:
            return
        t0 = time.process_time()
        factor = self.ksp.getPC().getFactorMatrix()
        n = self.K.getSize()[0]
        every = np.concatenate([self.nodes, new])
        rows = self.rows_of[every]
        cols = np.empty((every.size, new.size))
        for lo in range(0, new.size, BLOCK):
            hi = min(lo + BLOCK, new.size)
            rhs = PETSc.Mat().createDense((n, hi - lo), comm=self.K.comm)
            rhs.setUp()
            rhs.getDenseArray()[self.rows_of[new[lo:hi]], np.arange(hi - lo)] = 1.0
            rhs.assemble()
            sol = PETSc.Mat().createDense((n, hi - lo), comm=self.K.comm)
            sol.setUp()
            sol.assemble()
            factor.matSolve(rhs, sol)
            cols[:, lo:hi] = sol.getDenseArray()[rows, :]
            rhs.destroy()
            sol.destroy()
        m = self.nodes.size
        G = np.empty((every.size, every.size))
        G[:m, :m] = self.G
        G[:, m:] = cols
        G[m:, :m] = cols[:m].T
        G[m:, m:] = 0.5 * (G[m:, m:] + G[m:, m:].T)
        self.G, self.nodes = G, every
        self.solves += new.size
        self.t_capacitance += time.process_time() - t0

    def set_constrained(self, C: npt.NDArray[np.int64]) -> int:
        """Constrain the nodes C (met by :meth:`ensure`); the pencil's eigenvalues below sigma."""
        where = np.flatnonzero(np.isin(self.nodes, C))
        self.C_rows = self.rows_of[self.nodes[where]].astype(np.int64)
        self.size = int(where.size)
        if where.size == 0:
            self._lu = None
            return self.neg
        G_CC = self.G[np.ix_(where, where)]
        self._lu = scipy.linalg.lu_factor(G_CC)
        ev = np.linalg.eigvalsh(G_CC)
        scale = np.abs(ev).max()
        neg = int((ev < -1e-13 * scale).sum())
        zero = int((np.abs(ev) <= 1e-13 * scale).sum())
        return self.neg - neg - zero

    def apply(self, r: PETSc.Vec, x: PETSc.Vec) -> None:
        """Solve K_C x = r (Woodbury on the fixed factorisation)."""
        self.applications += 1
        r.copy(self._r)
        keep = r.array_r[self.C_rows].copy()
        self._r.array[self.C_rows] = 0.0
        self.ksp.solve(self._r, self._y)
        if self._lu is not None:
            z = scipy.linalg.lu_solve(self._lu, self._y.array_r[self.C_rows])
            self._r.array[self.C_rows] = -z
            self.ksp.solve(self._r, x)
            self.solves += 2
        else:
            self._y.copy(x)
            self.solves += 1
        x.array[self.C_rows] = keep

    def destroy(self) -> None:
        """Destroy the factorisation and the work vectors."""
        for obj in (self.ksp, self.K, self._y, self._r):
            obj.destroy()


class _ShellPC:
    """The spectral transformation's solve: ``scale`` times the capacitance solve."""

    def __init__(self, cap: Capacitance, scale: float) -> None:
        self.cap, self.scale = cap, scale

    def apply(self, pc: PETSc.PC, x: PETSc.Vec, y: PETSc.Vec) -> None:
        self.cap.apply(x, y)
        if self.scale != 1.0:
            y.scale(self.scale)


class FixedEigen:
    """Reduced eigen solves by shift-and-invert at sigma with the capacitance solve.

    B positive semidefinite: the pencil (A_Z, B_Z) at target sigma. B indefinite (shear):
    the swapped pencil (B_Z, A_Z) at target 1/sigma (as ``la.eigen``), whose shifted
    matrix B_Z - A_Z/sigma = -(A_Z - sigma B_Z)/sigma is solved with the same
    factorisation; lambda = 1/mu.
    """

    def __init__(self, cap: Capacitance, tol: float, indefinite: bool) -> None:
        self.cap = cap
        self.indefinite = indefinite
        self.Aw = cap.A.duplicate(copy=True)
        self.Bw = cap.B.duplicate(copy=True)
        eps = SLEPc.EPS().create(cap.K.comm)
        eps.setOptionsPrefix(PREFIX + "eps_")
        eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
        eps.setType(SLEPc.EPS.Type.KRYLOVSCHUR)
        eps.setDimensions(NEV, 2 * NEV + 4)
        eps.setTolerances(tol, 500)
        eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_REAL)
        eps.setTarget(1.0 / cap.sigma if indefinite else cap.sigma)
        st = eps.getST()
        st.setType(SLEPc.ST.Type.SINVERT)
        st.setMatMode(SLEPc.ST.MatMode.SHELL)
        ksp = st.getKSP()
        ksp.setType(PETSc.KSP.Type.PREONLY)
        pc = ksp.getPC()
        pc.setType(PETSc.PC.Type.PYTHON)
        pc.setPythonContext(_ShellPC(cap, -cap.sigma if indefinite else 1.0))
        self.eps = eps
        self.solves = 0

    def solve(
        self, active: npt.NDArray[np.int64], initial: PETSc.Vec | None
    ) -> tuple[float, int, PETSc.Vec] | None:
        """Smallest pair with ``active`` removed and the eigenvalues below sigma, or None."""
        problem, cap = self.cap.problem, self.cap
        C = np.setdiff1d(active, cap.fixed)
        cap.ensure(C)
        below = cap.set_constrained(C)
        rows = problem.contact.removed_rows(active).astype(PETSc.IntType)
        same = PETSc.Mat.Structure.SAME_NONZERO_PATTERN
        cap.A.copy(self.Aw, structure=same)  # type: ignore[arg-type]
        cap.B.copy(self.Bw, structure=same)  # type: ignore[arg-type]
        self.Aw.zeroRowsColumns(rows, diag=1.0)  # type: ignore[arg-type]
        self.Bw.zeroRowsColumns(rows, diag=0.0)  # type: ignore[arg-type]
        if self.indefinite:
            self.eps.setOperators(self.Bw, self.Aw)
        else:
            self.eps.setOperators(self.Aw, self.Bw)
        start = None
        if initial is not None:
            start = initial.copy()
            start.array[rows] = 0.0  # in the reduced pencil's space
            self.eps.setInitialSpace([start])
        self.eps.solve()
        if start is not None:
            start.destroy()
        self.solves += 1
        if self.eps.getConverged() < 1:
            return None
        values = [self.eps.getEigenvalue(k).real for k in range(self.eps.getConverged())]
        if self.indefinite:
            loads = [1.0 / v if v > 0 else math.inf for v in values]
        else:
            loads = values
        k = int(np.argmin(loads))
        x = self.Aw.createVecRight()
        self.eps.getEigenvector(k, x)
        return float(loads[k]), below, x

    def destroy(self) -> None:
        """Destroy the EPS and the reduced matrices."""
        for obj in (self.eps, self.Aw, self.Bw):
            obj.destroy()


def _grid(problem: UnilateralProblem) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """Grid indices (ix, iy) of the constrained nodes of a structured plate."""
    plate, mesh = problem.spec.plate, problem.spec.mesh
    (x0, y0), _ = plate.corners
    xy = problem.contact.coordinates
    ix = np.rint((xy[:, 0] - x0) / (plate.length / mesh.nx)).astype(np.int64)
    iy = np.rint((xy[:, 1] - y0) / (plate.width / mesh.ny)).astype(np.int64)
    return ix, iy


def band_of(
    problem: UnilateralProblem, Z0: npt.NDArray[np.int64], width: int, extra: npt.NDArray[np.int64]
) -> npt.NDArray[np.int64]:
    """The nodes within ``width`` grid steps of Z0's boundary (both sides), and ``extra``."""
    ix, iy = _grid(problem)
    nx, ny = problem.spec.mesh.nx + 1, problem.spec.mesh.ny + 1
    index = -np.ones((nx, ny), dtype=np.int64)
    index[ix, iy] = np.arange(ix.size)
    inz = np.zeros((nx, ny), dtype=bool)
    inz[ix[Z0], iy[Z0]] = True
    valid = index >= 0
    edge = np.zeros_like(inz)
    for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
        shifted = np.roll(np.roll(inz, dx, 0), dy, 1)
        ok = np.roll(np.roll(valid, dx, 0), dy, 1)
        edge |= valid & ok & (shifted != inz)
    band = edge.copy()
    for _ in range(width):
        grown = band.copy()
        for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            grown |= np.roll(np.roll(band, dx, 0), dy, 1)
        band = grown & valid
    nodes = index[band]
    return np.union1d(nodes[nodes >= 0], extra).astype(np.int64)


def polish(
    problem: UnilateralProblem,
    Z0: npt.NDArray[np.int64],
    band: npt.NDArray[np.int64],
    sigma: float,
    initial: PETSc.Vec | None,
    max_iterations: int,
) -> dict[str, Any]:
    """``pdas.iterate`` from Z0 with every reduced pencil solved on one factorisation.

    The nodes of Z0 outside ``band`` are removed in the factorisation; the band's
    capacitance columns are computed first, any other node's when a set first holds
    it. A set that releases a removed node is solved on a new factorisation (counted).
    """
    c0 = time.process_time()
    state: dict[str, Any] = {"factorisations": 0, "solves": 0, "applications": 0,
                             "t_factor": 0.0, "t_capacitance": 0.0, "below": []}  # fmt: skip

    def new_cap(fixed: npt.NDArray[np.int64]) -> tuple[Capacitance, FixedEigen]:
        cap = Capacitance(problem, fixed, sigma)
        cap.ensure(band)
        state["factorisations"] += 1
        return cap, FixedEigen(cap, problem.eigensolver.tol, problem.eigensolver.indefinite)

    def close(cap: Capacitance, eig: FixedEigen) -> None:
        for key in ("solves", "applications", "t_factor", "t_capacitance"):
            state[key] += getattr(cap, key)
        state["nodes"] = max(state.get("nodes", 0), int(cap.nodes.size))
        eig.destroy()
        cap.destroy()

    fixed = np.setdiff1d(Z0, band)
    cap, eig = new_cap(fixed)
    t_eigen = [0.0, 0]

    def evaluate(
        active: npt.NDArray[np.int64], initial: PETSc.Vec | None = None, near: float | None = None
    ) -> Candidate:
        nonlocal cap, eig
        active = np.unique(np.asarray(active, dtype=np.int64))
        if not np.isin(cap.fixed, active).all():
            close(cap, eig)
            cap, eig = new_cap(np.intersect1d(cap.fixed, active))
        t0 = time.process_time()
        got = eig.solve(active, initial)
        t_eigen[0] += time.process_time() - t0
        t_eigen[1] += 1
        if got is None:
            raise RuntimeError("no pair converged")
        value, below, x = got
        state["below"].append(below)
        u = problem.new_mode()
        x.copy(u.x.petsc_vec)
        x.destroy()
        u.x.scatter_forward()
        return problem.candidate(u, value, active)

    problem.evaluate = evaluate  # type: ignore[method-assign]
    try:
        run = pdas.iterate(problem, "fixed", Z0, initial, max_iterations, False, THRESHOLDS)
    finally:
        del problem.evaluate
    close(cap, eig)
    final = run.final
    return {
        "band": int(band.size),
        "fixed": int(fixed.size),
        **state,
        "status": str(run.status),
        "load": None if final is None else final.load,
        "kkt": bool(final is not None and final.kkt),
        "contact": None if final is None else int(final.active.size),
        "eigensolves": t_eigen[1],
        "history": run.history,
        "t_eigen": t_eigen[0],
        "t_total": time.process_time() - c0,
    }


def _factorisations() -> int:
    return int(PETSc.Log.Event("MatCholFctrNum").getPerfInfo()["count"])


def _hook_reads(fine_dofs: int, reads: list[dict[str, Any]]) -> None:
    """Record the sets the interior point reads on the mesh of ``fine_dofs`` DOFs.

    Each read keeps its set, a copy of its barrier point's mode and load, and the
    numeric factorisations (PETSc's ``MatCholFctrNum``) since the first Newton run on
    that mesh.
    """
    from unibuckle_fenicsx.algorithms.interior_point import newton

    first: list[int] = []
    cls = newton.InteriorPointNewton
    solve_inner = cls.solve

    def solve_hooked(self: Any, *args: Any, **kwargs: Any) -> Any:
        if int(self.kernel.A.getSize()[0]) == fine_dofs and not first:
            first.append(_factorisations())
        return solve_inner(self, *args, **kwargs)

    cls.solve = solve_hooked  # type: ignore[method-assign]
    for name in ("predicted_contact_set", "contact_set"):
        inner = getattr(cls, name)

        def hooked(self: Any, point: Any, _inner: Any = inner, _name: str = name) -> Any:
            got = _inner(self, point)
            if int(self.kernel.A.getSize()[0]) == fine_dofs:
                reads.append({
                    "how": _name, "set": got, "load": point.load, "mu": point.mu,
                    "mode": point.mode.x.petsc_vec.copy(),
                    "factorisations": _factorisations() - (first[0] if first else 0),
                })  # fmt: skip
            return got

        setattr(cls, name, hooked)


def _fine_level(solution: Any) -> list[int] | None:
    levels = getattr(solution.details, "levels", None) if solution is not None else None
    if not levels:
        return None
    lv = levels[-1]
    return [lv.newton_steps, lv.factorizations, lv.eigensolves]


def worker(case: str, nx: int, ny: int, width: int, degenerate: float, margin: float) -> None:
    """One plate in this process: today's route, then the prototype; print a JSON line."""
    spec = _spec(case, nx, ny)
    coarse_spec = replace(spec, mesh=replace(spec.mesh, nx=nx // 2, ny=ny // 2))
    assert isinstance(spec.mesh, MeshSpec)
    PETSc.Log.begin()
    from unibuckle_fenicsx.model.build import build_problem

    with build_problem(spec, MPI.COMM_WORLD) as probe:
        fine_dofs = int(probe.model.A.getSize()[0])
    reads: list[dict[str, Any]] = []
    _hook_reads(fine_dofs, reads)
    c0 = time.process_time()
    with solve(spec, MPI.COMM_WORLD) as run:
        t_today = time.process_time() - c0
        fine = run.problem
        assert isinstance(fine, UnilateralProblem) and run.solution is not None
        ref = run.solution.candidate
        row: dict[str, Any] = {
            "case": case,
            "mesh": f"{nx}x{ny}",
            "dofs": int(fine.model.A.getSize()[0]),
            "today_load": ref.load,
            "today_kkt": ref.kkt,
            "today_contact": int(ref.active.size),
            "today_fine": _fine_level(run.solution),
            "today_route": list(run.solution.route),
            "today_process_s": t_today,
        }
        with solve(coarse_spec, MPI.COMM_WORLD) as crun:
            coarse = crun.problem
            assert isinstance(coarse, UnilateralProblem) and crun.solution is not None
            cc = crun.solution.candidate
            Z0 = prolong(coarse, fine, cc.active)
            inz = np.zeros(coarse.contact.size, dtype=bool)
            inz[cc.active] = True
            flat = np.flatnonzero(
                (inz & (cc.forces < degenerate * max(cc.forces.max(), 0.0) + 0.0))
                | (~inz & (cc.values > -degenerate))
            )
            plate = fine.spec.plate
            extra = prolong_contact_set(
                flat,
                coarse.contact.coordinates,
                fine.contact.coordinates,
                plate.corners[0],
                (plate.length / (nx // 2), plate.width / (ny // 2)),
                (nx // 2, ny // 2),
            )
            row["coarse_load"] = cc.load
            row["Z0"] = int(Z0.size)
            row["coarse_kkt_contact"] = int(cc.active.size)
            carried = crun.solution.candidate.mode
            pro = Prolongation(coarse, fine)
            start = pro.mode(carried)
            band = band_of(fine, Z0, width, extra)
            sigma = (1.0 - margin) * cc.load
            row["sigma"] = sigma
            proto = polish(fine, Z0, band, sigma, start.x.petsc_vec, MAX_ITERATIONS)
            row.update({f"proto_{k}": v for k, v in proto.items()})
            if proto["load"] is not None:
                row["rel_diff"] = (proto["load"] - ref.load) / ref.load
        # From the first set the interior point reads on the fine mesh.
        if reads:
            read = reads[0]
            row["read_how"], row["read_after"] = read["how"], read["factorisations"]
            row["read_size"], row["read_mu"] = int(read["set"].size), read["mu"]
            band = band_of(fine, read["set"], width, read["set"])  # none fixed
            sigma = (1.0 - margin) * read["load"]
            got = polish(fine, read["set"], band, sigma, read["mode"], MAX_ITERATIONS)
            row.update({f"read_{k}": v for k, v in got.items()})
            if got["load"] is not None:
                row["read_rel_diff"] = (got["load"] - ref.load) / ref.load
        # The check: from today's KKT set (one eigen solve, its load, if the solve is right).
        band = band_of(fine, ref.active, width, ref.active)
        sigma = (1.0 - margin) * ref.load
        got = polish(fine, ref.active, band, sigma, ref.mode.x.petsc_vec, MAX_ITERATIONS)
        row.update({f"check_{k}": v for k, v in got.items()})
        row["reads"] = [[r["how"], int(r["set"].size), r["mu"], r["factorisations"]] for r in reads]
        for r in reads:
            r["mode"].destroy()
    print(json.dumps(row))


def _run(case: str, nx: int, ny: int, args: argparse.Namespace) -> dict[str, Any]:
    cmd = [sys.executable, __file__, "--worker", case, str(nx), str(ny)]
    cmd += ["--band", str(args.band), "--degenerate", str(args.degenerate)]
    cmd += ["--margin", str(args.margin), "--thresholds", args.thresholds]
    out = subprocess.run(cmd, check=True, capture_output=True)
    return dict(json.loads(out.stdout.decode().strip().splitlines()[-1]))


def _after(count: int | None) -> str:
    return "" if count is None else f" ({count})"


def _rows(runs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """One row per start (the coarse set, the first fine read) of a plate's runs.

    The counts and loads are those of the first run (the same in every run); each
    time is the minimum over the runs.
    """
    first = runs[0]
    rows = []
    for prefix, start, after in (
        ("check", "today's KKT set", None),
        ("proto", "coarse KKT set", 0),
        ("read", "first fine read", first.get("read_after")),
    ):
        if f"{prefix}_status" not in first:
            continue
        times = {t: min(r[f"{prefix}_{t}"] for r in runs) for t in TIMES}
        load = first[f"{prefix}_load"]
        rows.append(
            {
                "case": first["case"],
                "mesh": first["mesh"],
                "dofs": first["dofs"],
                "today_fine": "/".join(map(str, first["today_fine"] or [])),
                "today_load": first["today_load"],
                "start": start,
                "start_nodes": {"check": first["today_contact"], "proto": first["Z0"]}.get(
                    prefix, first.get("read_size")
                ),
                "start_after": after,
                "factorisations": first[f"{prefix}_factorisations"],
                "solves": first[f"{prefix}_solves"],
                "columns": first[f"{prefix}_nodes"],
                "eigensolves": first[f"{prefix}_eigensolves"],
                "end": first[f"{prefix}_status"],
                "kkt": first[f"{prefix}_kkt"],
                "contact": first[f"{prefix}_contact"],
                "load": load,
                "rel_diff": (load - first["today_load"]) / first["today_load"],
                **times,
                "factor_equivalents": (
                    times["t_total"] * first[f"{prefix}_factorisations"] / times["t_factor"]
                ),
                "runs": len(runs),
                "sets": first[f"{prefix}_history"],
            }
        )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--meshes", default="90x30,180x60")
    parser.add_argument("--cases", default="ssss,cccc")
    parser.add_argument("--band", type=int, default=2, help="band width in node spacings, >= 0")
    parser.add_argument(
        "--degenerate", type=float, default=1e-3, help="carried degenerate nodes, in [0, 1)"
    )
    parser.add_argument(
        "--margin", type=float, default=1e-2, help="sigma below the start's load, in (0, 1)"
    )
    parser.add_argument(
        "--thresholds", default="", help="pdas looser tolerances, comma-separated (none)"
    )
    parser.add_argument("--repeat", type=int, default=1, help="runs per plate, >= 1")
    parser.add_argument("--json", help="append one JSON line per plate and start to this file")
    parser.add_argument("--worker", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.band < 0:
        parser.error(f"--band must be >= 0, got {args.band}")
    if not 0.0 <= args.degenerate < 1.0:
        parser.error(f"--degenerate must be in [0, 1), got {args.degenerate}")
    if not 0.0 < args.margin < 1.0:
        parser.error(f"--margin must be in (0, 1), got {args.margin}")
    if args.repeat < 1:
        parser.error(f"--repeat must be >= 1, got {args.repeat}")
    global THRESHOLDS
    THRESHOLDS = tuple(float(t) for t in args.thresholds.split(",") if t)
    if args.worker:
        worker(args.worker[0], int(args.worker[1]), int(args.worker[2]), args.band,
               args.degenerate, args.margin)  # fmt: skip
        return
    rows: list[dict[str, Any]] = []
    print_header(
        "the fine level's active-set polish on one factorisation (prototype), against "
        "today's fine level",
        ["plate", "mesh", "today: steps / fact. / eigen", "start (today's fact. before it)",
         "proto: fact. / solves / G columns / eigen", "end", "load vs today", "t LDL",
         "t G", "t eigen", "t proto", "t proto / t LDL"],
    )  # fmt: skip
    for mesh in args.meshes.split(","):
        nx, ny = (int(v) for v in mesh.split("x"))
        for case in args.cases.split(","):
            runs = [_run(case, nx, ny, args) for _ in range(args.repeat)]
            for row in _rows(runs):
                rows.append(row)
                print(
                    f"| {case} | {mesh} | {row['today_fine']} | {row['start']}, "
                    f"{row['start_nodes']} nodes{_after(row['start_after'])} | "
                    f"{row['factorisations']} / {row['solves']} / "
                    f"{row['columns']} / {row['eigensolves']} | {row['end']}, "
                    f"{row['contact']} nodes | {row['rel_diff']:+.1e} | {row['t_factor']:.3f} "
                    f"| {row['t_capacitance']:.2f} | {row['t_eigen']:.2f} | "
                    f"{row['t_total']:.2f} | {row['factor_equivalents']:.0f} |"
                )
    append_rows(args.json, rows)


if __name__ == "__main__":
    main()
