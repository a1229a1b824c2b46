"""Every step of the pipeline on a distributed (ghosted) mesh, summarised as JSON.

``mpiexec -n P python tests/mpi/pipeline_steps.py NX NY [quick]`` prints, on rank 0, one JSON
line with partition-independent quantities: mesh counts, prestress checks, norms of the
assembled pencil, the contact nodes (coordinates), free and candidate loads, oriented
mode values at the contact nodes and certificates. ``tests/mpi/test_mpi.py`` compares them
with the same function run serially (:func:`collect`). The script itself asserts what
must hold on every rank (identical collective decisions, ghost layer present).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from support.plates import (
    clamped_left_plate,
    n0_at_quadrature_points,
    strip_average,
)
from unibuckle_fenicsx.certificate.certify import certify
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.mesh import create_plate_mesh
from unibuckle_fenicsx.model.prestress import solve_prestress
from unibuckle_fenicsx.results.assemble import certificate_record
from unibuckle_fenicsx.results.records import jsonable
from unibuckle_fenicsx.spec import MeshSpec
from unibuckle_fenicsx.spec.cases import paper_case


def same_on_all_ranks(comm: MPI.Comm, value: object) -> bool:
    """Whether ``value`` (JSON-able) is identical on every rank."""
    text = json.dumps(value, sort_keys=True)
    return all(t == text for t in comm.allgather(text))


def candidate_sets(coordinates: np.ndarray) -> dict[str, list[int]]:
    """Contact sets chosen by coordinates (so they mean the same nodes on any partition)."""
    x, y = coordinates[:, 0], coordinates[:, 1]
    tol = 1e-12
    return {
        "empty": [],
        "centre": np.flatnonzero((np.abs(x) < tol) & (np.abs(y) < tol)).tolist(),
        "centre_line": np.flatnonzero(np.abs(x) < tol).tolist(),
        "axis_y0": np.flatnonzero(np.abs(y) < tol).tolist(),
        "diagonal_pair": [0, len(x) - 1],
        "all": list(range(len(x))),
    }


def collect(comm: MPI.Comm, nx: int, ny: int, quick: bool = False) -> dict[str, object]:
    """Run every step on ``comm`` and return the partition-independent summary.

    ``quick`` evaluates one candidate set (feasible, with a contact force) instead of six:
    each distributed eigen solve costs seconds when ranks outnumber cores.
    """
    out: dict[str, object] = {"ranks": comm.size}
    spec = paper_case("c1", nx, ny)
    t = spec.plate.thickness

    # -- mesh ----------------------------------------------------------------------------
    msh, tags = create_plate_mesh(spec.plate, spec.mesh, comm)
    tdim = msh.topology.dim
    cmap = msh.topology.index_map(tdim)
    out["cells"] = cmap.size_global
    out["vertices"] = msh.topology.index_map(0).size_global
    owned_facets = msh.topology.index_map(tdim - 1).size_local
    out["edge_facets"] = [
        comm.allreduce(int(np.sum(tags.find(tag) < owned_facets)), op=MPI.SUM)
        for tag in (1, 2, 3, 4)
    ]
    ghosts = comm.allgather(cmap.num_ghosts)
    owned = comm.allgather(cmap.size_local)
    assert min(owned) > 0, owned
    if comm.size > 1:
        assert min(ghosts) > 0, f"no ghost cells: {ghosts}"

    # -- prestress -----------------------------------------------------------------------
    ps = solve_prestress(msh, tags, spec.plate, spec.material)
    n0 = n0_at_quadrature_points(msh, ps.N0)
    local = float(np.abs(n0 - np.diag([-t, 0.0])).max()) if n0.size else 0.0
    out["paper_n0_error"] = comm.allreduce(local, op=MPI.MAX) / t
    clamped = clamped_left_plate(t)
    cmsh, ctags = create_plate_mesh(clamped, MeshSpec(nx, ny), comm)
    cps = solve_prestress(cmsh, ctags, clamped, spec.material)
    h = clamped.length / nx
    force = -t * clamped.width
    out["clamped_strip_errors"] = [
        abs(strip_average(cmsh, cps.N0, -0.1 + k1 * h, -0.1 + k2 * h) / force - 1.0)
        for k1, k2 in [(0, 1), (1, nx // 2), (nx - 1, nx)]
    ]
    out["clamped_extremes"] = [cps.max_compression, cps.max_tension]

    # -- assembly, contact manager, eigen solves, certificates ---------------------------
    problem = build_problem(spec, comm)
    model, contact = problem.model, problem.contact
    assert contact is not None
    out["dofs"] = model.num_dofs
    out["norm_A"] = model.A.norm(PETSc.NormType.FROBENIUS)  # type: ignore[attr-defined]
    out["norm_B"] = model.B.norm(PETSc.NormType.FROBENIUS)  # type: ignore[attr-defined]
    out["coordinates"] = contact.coordinates.tolist()
    out["num_edge_fixed"] = contact.num_edge_fixed
    assert same_on_all_ranks(comm, out["coordinates"])

    # Numbering <-> node: values() of an interpolated function returns f at coordinates.
    f = dolfinx.fem.Function(model.W)
    f.sub(0).interpolate(lambda x: 1.0 + 3.0 * x[0] + 20.0 * x[1] + 500.0 * x[0] * x[1])
    f.x.scatter_forward()
    xy = contact.coordinates
    exact = 1.0 + 3.0 * xy[:, 0] + 20.0 * xy[:, 1] + 500.0 * xy[:, 0] * xy[:, 1]
    out["values_map_error"] = float(np.abs(contact.values(f.x.petsc_vec) - exact).max())

    sets = candidate_sets(contact.coordinates)
    checks = []
    for name, active in sets.items():
        arr = np.asarray(active, dtype=np.int64)
        rows = comm.allgather(contact.removed_rows(arr).tolist())
        flat = [r for part in rows for r in part]
        assert len(flat) == len(set(flat)) == len(active), (name, rows)
        indicator = contact.node_function(arr)
        n_owned_w = model.Vw.dofmap.index_map.size_local
        marked = comm.allreduce(float(indicator.x.array[:n_owned_w].sum()), op=MPI.SUM)
        assert marked == len(active), (name, marked)
        checks.append(name)
    out["removed_rows_checked"] = checks

    if quick:
        sets = {"diagonal_pair": sets["diagonal_pair"]}
    free = problem.solve_free()
    out["free_load"] = free.load
    out["free_error"] = free.eigen.error
    candidates = {}
    for name, active in sets.items():
        cand = problem.evaluate(np.asarray(active, dtype=np.int64))
        entry: dict[str, object] = {
            "active": active,
            "load": cand.load,
            "feasible": cand.feasible,
            "values": cand.values.tolist(),
        }
        if np.isfinite(cand.load) and active:
            entry["certificate"] = jsonable(certificate_record(certify(problem, cand)))
        assert same_on_all_ranks(comm, entry), name
        candidates[name] = entry
    out["candidates"] = candidates
    out["eigensolves"] = problem.eigensolver.solves
    problem.destroy()
    return out


def main() -> None:
    nx, ny = (int(a) for a in sys.argv[1:3])
    summary = collect(MPI.COMM_WORLD, nx, ny, quick="quick" in sys.argv[3:])
    if MPI.COMM_WORLD.rank == 0:
        print(json.dumps(summary))


if __name__ == "__main__":
    main()
