r"""Independent reference for plates with holes: Reissner-Mindlin on cubic triangles.

Nothing of the package's discretisation: gmsh triangles (no recombination), plane stress
with quadratic (P2) displacements for the prestress, cubic (P3) deflection and rotations
with the plain (full) shear energy, which locks only mildly at this degree for the
plates used here (checked against the Navier load of the plate without hole), the edge
supports as DOF removal, and scipy's sparse Lanczos on the pencil (no SLEPc). Only
DOLFINx's assembly is shared.

Plate: the square [-b/2, b/2]^2 with a central circular hole of diameter d, simply
supported (hard: w = 0 and the tangential rotation on the outer edge; the hole free),
uniform compression sigma = 1 on the edges x = +-b/2, free in its plane (three point
constraints remove the rigid motions).
"""

from __future__ import annotations

from mpi4py import MPI

import basix.ufl
import dolfinx
import dolfinx.fem.petsc
import dolfinx.io.gmsh
import ufl

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg


def _mesh(b: float, d: float, h: float) -> tuple[dolfinx.mesh.Mesh, dolfinx.mesh.MeshTags]:
    import gmsh

    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        occ = gmsh.model.occ
        square = occ.addRectangle(-b / 2, -b / 2, 0.0, b, b)
        hole = occ.addDisk(0.0, 0.0, 0.0, d / 2, d / 2)
        (surface,), _ = occ.cut([(2, square)], [(2, hole)])
        occ.synchronize()
        gmsh.model.addPhysicalGroup(2, [surface[1]], 1)
        for dim, tag in gmsh.model.getBoundary([surface], oriented=False):
            x = gmsh.model.occ.getCenterOfMass(dim, tag)
            if abs(abs(x[0]) - b / 2) < 1e-9 * b:
                gmsh.model.addPhysicalGroup(1, [tag], 1 if x[0] < 0 else 2)
            elif abs(abs(x[1]) - b / 2) < 1e-9 * b:
                gmsh.model.addPhysicalGroup(1, [tag], 3 if x[1] < 0 else 4)
        gmsh.option.setNumber("Mesh.MeshSizeMax", h)
        gmsh.option.setNumber("Mesh.MeshSizeMin", h)
        gmsh.model.mesh.generate(2)
        data = dolfinx.io.gmsh.model_to_mesh(gmsh.model, MPI.COMM_SELF, 0, gdim=2)
    finally:
        gmsh.finalize()
    return data.mesh, data.facet_tags


def _csr(A) -> sp.csr_matrix:
    indptr, indices, data = A.getValuesCSR()
    return sp.csr_matrix((data, indices, indptr), shape=A.getSize())


def holed_plate_load(
    b: float, d: float, t: float, h: float, E: float = 1.0e9, nu: float = 0.3
) -> float:
    """Critical compressive stress (Pa) of the holed square plate (module docstring)."""
    msh, tags = _mesh(b, d, h)
    fdim = msh.topology.dim - 1
    n = ufl.FacetNormal(msh)
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
    # Plane stress, P2.
    V = dolfinx.fem.functionspace(msh, ("Lagrange", 2, (2,)))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    lam = E * nu / (1 - nu**2)
    mu = E / (2 * (1 + nu))

    def stress(w):
        eps = ufl.sym(ufl.grad(w))
        return lam * ufl.tr(eps) * ufl.Identity(2) + 2 * mu * eps

    a = ufl.inner(stress(u), ufl.sym(ufl.grad(v))) * ufl.dx
    L = -ufl.dot(n, v) * (ds(1) + ds(2))  # sigma = -1 on x = +-b/2 (unit thickness)
    pins = []
    for point, comps in (((0.0, -b / 2), (0, 1)), ((0.0, b / 2), (0,))):
        for c in comps:
            Vc, _ = V.sub(c).collapse()
            dofs = dolfinx.fem.locate_dofs_geometrical(
                (V.sub(c), Vc), lambda x, p=point: np.hypot(x[0] - p[0], x[1] - p[1]) < 1e-9 * b
            )
            pins.append(dolfinx.fem.dirichletbc(0.0, dofs[0], V.sub(c)))
    problem = dolfinx.fem.petsc.LinearProblem(
        a, L, bcs=pins, petsc_options_prefix="test_tri_prestress_"
    )
    # Set on the KSP, not as petsc_options: DOLFINx's LinearProblem deletes those from
    # the global options database without their prefix, so they stayed there.
    problem.solver.setType("preonly")
    problem.solver.getPC().setType("lu")
    problem.solver.getPC().setFactorSolverType("mumps")
    up = problem.solve()
    N0 = t * stress(up)
    # Reissner-Mindlin, P3 x P3^2, full integration.
    cell = msh.basix_cell().name
    P3 = basix.ufl.element("Lagrange", cell, 3)
    P3v = basix.ufl.element("Lagrange", cell, 3, shape=(2,))
    W = dolfinx.fem.functionspace(msh, basix.ufl.mixed_element([P3, P3v]))
    (w, th), (z, et) = ufl.TrialFunctions(W), ufl.TestFunctions(W)
    D = E * t**3 / (12 * (1 - nu**2))
    ks = 5 / 6 * mu * t

    def moment(k):
        return D * ((1 - nu) * k + nu * ufl.tr(k) * ufl.Identity(2))

    kw, kz = ufl.sym(ufl.grad(th)), ufl.sym(ufl.grad(et))
    a_plate = (
        ufl.inner(moment(kw), kz) + ks * ufl.dot(ufl.grad(w) - th, ufl.grad(z) - et)
    ) * ufl.dx
    b_plate = -ufl.dot(N0 * ufl.grad(w), ufl.grad(z)) * ufl.dx
    fixed = []
    for tag, tangential in ((1, 1), (2, 1), (3, 0), (4, 0)):
        facets = tags.find(tag)
        for path in ((0,), (1, tangential)):
            sub = W
            for i in path:
                sub = sub.sub(i)
            Vc, _ = sub.collapse()
            fixed.append(dolfinx.fem.locate_dofs_topological((sub, Vc), fdim, facets)[0])
    A = dolfinx.fem.petsc.assemble_matrix(dolfinx.fem.form(a_plate))
    A.assemble()
    B = dolfinx.fem.petsc.assemble_matrix(dolfinx.fem.form(b_plate))
    B.assemble()
    As, Bs = _csr(A), _csr(B)
    A.destroy()
    B.destroy()
    keep = np.setdiff1d(np.arange(As.shape[0]), np.concatenate(fixed))
    Ak, Bk = As[keep][:, keep], Bs[keep][:, keep]
    theta = scipy.sparse.linalg.eigsh(Bk, k=1, M=Ak.tocsc(), which="LA", tol=1e-12)[0][0]
    return 1.0 / theta


def navier_check(b: float, t: float, h: float) -> tuple[float, float]:
    """(this discretisation's load, the Navier load) of the square without hole (m = 1)."""
    from unibuckle_fenicsx.model.materials import navier_load_mindlin

    load = holed_plate_load(b, 1e-9 * b, t, h)  # a hole far below the mesh size
    return load, navier_load_mindlin(1.0e9, 0.3, t, b, b)[0]
