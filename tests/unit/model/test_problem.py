"""A problem on a user-supplied mesh, and the swapped pencil for an indefinite B."""

from __future__ import annotations

from mpi4py import MPI

import dolfinx

import numpy as np
import pytest
from msgspec.structs import replace

from support.families import tension_somewhere
from unibuckle_fenicsx import MeshSpec, ObstacleSpec, paper_case
from unibuckle_fenicsx.analysis import solve
from unibuckle_fenicsx.la.eigen import GEPSolver
from unibuckle_fenicsx.model.build import build_problem
from unibuckle_fenicsx.model.mesh import create_plate_mesh
from unibuckle_fenicsx.spec.cases import plate_case


def test_user_mesh_with_own_tags_matches_rectangle():
    """A user mesh with its own facet tags gives the built-in rectangle's results.

    The same plate, tagged 11..14: identical discretisation, so equal to 1e-10.
    """
    spec = paper_case("c2", 8, 4)
    with solve(spec) as analysis:
        reference = analysis.result

    msh, tags = create_plate_mesh(spec.plate, MeshSpec(8, 4), MPI.COMM_WORLD)
    user_tags = dolfinx.mesh.meshtags(msh, 1, tags.indices, tags.values + 10)
    edges = tuple(
        replace(e, tag=t) for e, t in zip(spec.plate.edges, (11, 12, 13, 14), strict=True)
    )
    user_spec = replace(spec, plate=replace(spec.plate, edges=edges))
    with solve(user_spec, mesh=msh, facet_tags=user_tags) as analysis:
        result = analysis.result
        assert analysis.problem.custom_mesh
    assert result.free_load_Pa == pytest.approx(reference.free_load_Pa, rel=1e-10)
    assert result.critical_load_Pa == pytest.approx(reference.critical_load_Pa, rel=1e-10)
    assert result.contact_indices == reference.contact_indices
    assert result.mesh == [32]


def test_a_user_mesh_s_unbalanced_load_is_refused_after_a_balanced_one():
    """The self-equilibrium check is not skipped for a user's mesh.

    The same plate (free in its plane) solved first on its own mesh, then on a user mesh
    whose tags put the left edge's load on the bottom edge: the loads no longer balance
    (resultant (-0.1, 0.2) N/m per Pa). The check had been cached per plate description,
    and the second solve returned half the load, "proven".
    """
    spec = paper_case("c1", 8, 4)
    with solve(spec) as analysis:
        assert analysis.result.critical_load_Pa > 0.0
    msh, tags = create_plate_mesh(spec.plate, MeshSpec(8, 4), MPI.COMM_WORLD)
    swap = {1: 3, 3: 1}  # left <-> bottom
    values = np.array([swap.get(int(v), int(v)) for v in tags.values], dtype=np.int32)
    swapped = dolfinx.mesh.meshtags(msh, 1, tags.indices, values)
    with pytest.raises(ValueError, match="not self-equilibrated"):
        solve(spec, mesh=msh, facet_tags=swapped)


def test_a_user_mesh_that_does_not_fit_the_plate_is_refused():
    """Tags that mark no facet, or a mesh off plate.corners: a message naming it.

    Tagged 5..8 instead of 1..4 the edges' loads act nowhere, and the plate was refused
    as "in tension everywhere"; a mesh over [0, 0.4] x [0, 0.2] for the paper's plate
    (corners [-0.1, 0.1] x [-0.05, 0.05]) was solved with its zone clipped.
    """
    spec = paper_case("c1", 8, 4)
    msh, tags = create_plate_mesh(spec.plate, MeshSpec(8, 4), MPI.COMM_WORLD)
    shifted = dolfinx.mesh.meshtags(msh, 1, tags.indices, tags.values + 4)
    with pytest.raises(
        ValueError, match=r"edge 'left' \(facet tag 1\) holds no facet .* \[5, 6, 7, 8\]"
    ):
        build_problem(spec, mesh=msh, facet_tags=shifted)
    other = replace(spec.plate, corners=((0.0, 0.0), (0.4, 0.2)))
    big, big_tags = create_plate_mesh(other, MeshSpec(8, 4), MPI.COMM_WORLD)
    with pytest.raises(ValueError, match=r"mesh: its bounding box .* is not plate\.corners"):
        build_problem(spec, mesh=big, facet_tags=big_tags)


def test_user_mesh_needs_facet_tags():
    spec = paper_case("free", 4, 2)
    msh, _ = create_plate_mesh(spec.plate, spec.mesh, MPI.COMM_WORLD)
    with pytest.raises(ValueError, match="facet_tags"):
        build_problem(spec, mesh=msh)


def test_swapped_pencil_equals_ghep():
    """The swapped pencil (indefinite-B path) gives the GHEP load.

    B x = mu A x for the largest mu gives lambda = 1/mu, equal to the shift-invert GHEP
    solve of the same pencil to the eigen tolerance.
    """
    problem = build_problem(paper_case("free", 20, 10))
    ghep = problem.solve_free().load
    swapped = GEPSolver(problem.model.A, problem.model.B, indefinite=True, prefix="swapped_")
    value = swapped.solve().value
    swapped.destroy()
    problem.destroy()
    assert value == pytest.approx(ghep, rel=1e-8)
    # Navier (hard support): lambda_RM = 12.7559 MPa; 20x10 is 1.4 % above it (README).
    assert value == pytest.approx(12.7559e6, rel=2e-2)


def test_indefinite_prestress_uses_swapped_pencil():
    """An indefinite B (tension somewhere) selects the swapped pencil.

    Left edge clamped in plane, right edge compressed: Poisson's effect puts part of the
    plate in tension. The load found must be the one GHEP shift-invert finds on the same
    pencil here.
    """
    problem = build_problem(tension_somewhere(20, 10))
    assert problem.prestress.indefinite
    assert problem.eigensolver.indefinite
    value = problem.solve_free().load
    ghep = GEPSolver(problem.model.A, problem.model.B, prefix="ghep_check_")
    check = ghep.solve().value
    ghep.destroy()
    problem.destroy()
    assert np.isfinite(value) and value > 0
    # Both pick the smallest positive eigenvalue here (the negative ones, from the tension
    # zone, lie far from 0): identical to the eigen tolerance.
    assert value == pytest.approx(check, rel=1e-8)


def test_command_line_option_wins_and_defaults_do_not_leak():
    """README, "Command line": an option under a package prefix wins over its default.

    The defaults pushed for one object are removed afterwards (no leak into the next
    object with that prefix), and with ``setup=True`` options read only at set-up (MUMPS
    ICNTL(13) and ICNTL(24), which make the inertia count reliable in parallel) reach the
    factorisation: the inertia of diag(-1, 1, 2) is (1, 0, 2).
    """
    from petsc4py import PETSc

    from unibuckle_fenicsx.la.factor import LDL_OPTIONS, SymmetricFactorization
    from unibuckle_fenicsx.la.options import set_options

    opts = PETSc.Options()
    opts.setValue("unibuckle_test_ksp_type", "gmres")  # as if given on the command line
    try:
        ksp = PETSc.KSP().create(MPI.COMM_SELF)
        set_options(ksp, "unibuckle_test_", {"ksp_type": "preonly", "pc_type": "jacobi"})
        assert ksp.getType() == "gmres"  # the user's value
        assert ksp.getPC().getType() == "jacobi"  # the default
        assert not opts.hasName("unibuckle_test_pc_type")  # removed again
        ksp.destroy()
    finally:
        opts.delValue("unibuckle_test_ksp_type")

    mat = PETSc.Mat().createAIJ((3, 3), nnz=1, comm=MPI.COMM_SELF)
    for k, value in enumerate((-1.0, 1.0, 2.0)):
        mat.setValue(k, k, value)
    mat.assemble()
    ldl = SymmetricFactorization(mat, "unibuckle_test_ldl_")
    factor = ldl.ksp.getPC().getFactorMatrix()
    assert factor.getMumpsIcntl(13) == LDL_OPTIONS["mat_mumps_icntl_13"]
    assert factor.getMumpsIcntl(24) == LDL_OPTIONS["mat_mumps_icntl_24"]
    assert ldl.inertia() == (1, 0, 2)
    assert not opts.hasName("unibuckle_test_ldl_mat_mumps_icntl_13")
    ldl.destroy()
    mat.destroy()


def test_a_discarded_problem_takes_its_run_options_back():
    """A problem that is never destroyed leaves nothing in PETSc's options database.

    The run's EPS options go into the database for every solver the run creates
    (``push_run_options``); ``destroy()`` takes them back, and so does the problem's
    collection when a user drops it without ``destroy()`` (or a ``with`` block).
    """
    import gc

    from petsc4py import PETSc

    problem = build_problem(paper_case("c1", 8, 4), eps_options={"eps_ncv": 40})
    opts = PETSc.Options()
    assert opts.getInt("unibuckle_eps_ncv") == 40  # in the database while the problem lives
    del problem
    gc.collect()
    assert not opts.hasName("unibuckle_eps_ncv")


def test_the_factorisations_of_a_mesh_share_one_symbolic_analysis():
    """One MUMPS analysis per mesh for the Newton matrix, shifted solves and certificate.

    All three have A's pattern: PETSc counts one symbolic LDL^T factorisation, and each
    factorisation is of its user's values.

    References: the shifted solve's load against the solve of the same reduced pencil at
    target 0 (its own LU); the inertia of K(1.5 lambda_free) against the count of the
    pencil's eigenvalues below 1.5 lambda_free from a dense solve (scipy's ``eigh`` of B x =
    mu A x); a solve with K after another user has factorised the shared matrix against
    the same solve before (the certificate factorises again).
    """
    from petsc4py import PETSc

    from scipy.linalg import eigh
    from scipy.sparse import csr_matrix

    from unibuckle_fenicsx.algorithms.interior_point import InteriorPointNewton
    from unibuckle_fenicsx.certificate.shifted import ShiftedMatrix

    PETSc.Log.begin()
    symbolic = PETSc.Log.Event("MatCholFctrSym")
    spec = plate_case(
        "thin", length=0.3, width=0.1, thickness=1e-3, nx=12, ny=4, zone=ObstacleSpec(zone="all")
    )
    problem = build_problem(spec, MPI.COMM_SELF)
    assert problem.contact is not None
    before = symbolic.getPerfInfo()["count"]
    with InteriorPointNewton(problem) as newton:
        newton.starts.pressure_mode()  # a factorisation of A: the analysis
    active = np.arange(problem.contact.size)[::3]
    cold = problem.evaluate(active)
    warm = problem.evaluate(active, initial=cold.mode.x.petsc_vec, near=cold.load * (1 + 1e-5))
    assert problem.eigensolver.shifted_solves == 1
    lam = 1.5 * problem.solve_free().load
    pencil = (problem.model.A, problem.model.B)
    A, B = (csr_matrix(m.getValuesCSR()[::-1]).toarray() for m in pencil)
    below = int((eigh(B, A, eigvals_only=True) > 1.0 / lam).sum())
    shared = problem.eigensolver.factorization
    with ShiftedMatrix(problem.model.A, problem.model.B, shared=shared) as matrix:
        assert matrix.factor(lam)[0] == below >= 1
        b = problem.model.A.createVecLeft()
        b.setArray(np.linspace(1.0, 2.0, b.getLocalSize()))
        x1, x2 = b.duplicate(), b.duplicate()
        matrix.solve(b, x1)
        problem.evaluate(active, initial=cold.mode.x.petsc_vec, near=warm.load)  # takes it
        assert not shared.holds(matrix)
        matrix.solve(b, x2)
        assert matrix.factorisations == 2  # factorised again, numerically only
        assert np.allclose(x2.array_r, x1.array_r, rtol=1e-12, atol=0.0)
        for v in (b, x1, x2):
            v.destroy()
    assert symbolic.getPerfInfo()["count"] - before == 1
    assert warm.load == pytest.approx(cold.load, rel=1e-9)
    problem.destroy()


@pytest.mark.parametrize("load", ["uniaxial", "shear"])
def test_eigen_solve_near_an_estimate_is_the_smallest(load):
    """A solve shifted just below an estimate returns the smallest eigenpair, or solves again.

    Reference: the same reduced pencil solved at target 0 (the free plate's path), and a
    dense generalized eigensolver (scipy's ``eigh`` of the swapped pencil B x = mu A x,
    A SPD). A good estimate (1e-5 above) is used as the shift; an estimate three times
    the load puts eigenvalues below the shift, which the factorisation's inertia shows,
    and the solve at target 0 runs instead. Under shear B is indefinite (the pencil's
    loads come in pairs of opposite sign): the shifted solve is then of the swapped
    pencil, and the inertia counts its positive eigenvalues.
    """
    from scipy.linalg import eigh
    from scipy.sparse import csr_matrix

    if load == "uniaxial":
        spec = paper_case("c1", 12, 6)
    else:
        spec = plate_case(
            "shear", length=0.3, width=0.1, thickness=1e-3, load="shear", nx=12, ny=6,
            zone=ObstacleSpec(zone="all"),
        )  # fmt: skip
    problem = build_problem(spec, MPI.COMM_SELF)
    assert problem.contact is not None
    assert problem.eigensolver.indefinite == (load == "shear")
    zone = np.arange(problem.contact.size)
    active = zone[: zone.size // 2]  # any contact set will do
    cold = problem.evaluate(active)
    solver = problem.eigensolver
    keep = np.setdiff1d(
        np.arange(problem.model.A.getSize()[0]), problem.contact.removed_rows(active)
    )
    A, B = (
        csr_matrix(m.getValuesCSR()[::-1]).toarray()[np.ix_(keep, keep)]
        for m in (problem.model.A, problem.model.B)
    )
    mu = eigh(B, A, eigvals_only=True)
    dense = 1.0 / mu.max()
    shifted, again = solver.shifted_solves, solver.unshifted_again
    start = cold.mode.x.petsc_vec
    warm = problem.evaluate(active, initial=start, near=cold.load * (1.0 + 1e-5))
    assert (solver.shifted_solves, solver.unshifted_again) == (shifted + 1, again)
    far = problem.evaluate(active, initial=start, near=3.0 * cold.load)
    assert (solver.shifted_solves, solver.unshifted_again) == (shifted + 1, again + 1)
    problem.destroy()
    assert cold.load == pytest.approx(dense, rel=1e-8)
    assert warm.load == pytest.approx(dense, rel=1e-8)
    assert far.load == pytest.approx(dense, rel=1e-8)
    # Three times the load lies above the second eigenvalue: the pair nearest that
    # shift would not have been the smallest.
    assert np.sort(1.0 / mu[mu > 0])[1] < 3.0 * cold.load * (1.0 - 1e-3)


def test_a_destroyed_problem_refuses_use():
    """After solve()'s with block the problem's PETSc objects are gone: a clear error.

    Before, evaluate() on it ended the process (SEGV, MPI_Abort); the result, the mode
    and the certificate stay usable.
    """
    with solve(paper_case("c1", nx=8, ny=4), MPI.COMM_WORLD) as analysis:
        active = analysis.solution.active
        load = analysis.result.critical_load_Pa
    assert analysis.mode.x.petsc_vec.norm() > 0.0 and analysis.result.critical_load_Pa == load
    with pytest.raises(RuntimeError, match="problem was destroyed"):
        analysis.problem.evaluate(active)
    with pytest.raises(RuntimeError, match="destroyed"):
        analysis.problem.model  # noqa: B018 - the access itself is the test
    analysis.problem.destroy()  # a second destroy is harmless


@pytest.mark.parametrize("spec", [None, "c1", {"plate": {}}, 42])
def test_solve_names_what_it_needs(spec):
    """Not a ProblemSpec: a TypeError naming it, not an AttributeError from inside."""
    with pytest.raises(TypeError, match=r"spec must be a ProblemSpec \(paper_case"):
        solve(spec, MPI.COMM_WORLD)
    with pytest.raises(TypeError, match="comm must be an MPI communicator"):
        solve(paper_case("c1", nx=4, ny=2), "world")


def test_a_free_load_that_is_not_the_smallest_is_caught():
    """SLEPc with loose options stops on a higher pair: the inertia check refuses it.

    With a tolerance of 0.1 and three basis vectors the paper's free plate at 40x20 gave
    15113428 Pa, 18 % above the smallest eigenvalue; that was then a "proven" lower bound
    (interlacing), and c3's critical load came out below the free load. Two pencil
    eigenvalues lie below the returned one.
    """
    from unibuckle_fenicsx.errors import EigenSolveError

    loose = {"eps_tol": 0.1, "eps_ncv": 3}
    for case in ("free", "c3"):
        with pytest.raises(EigenSolveError, match=r"free eigen solve returned .* 2 eigenvalue"):
            # In a with block: a solve that fails to raise takes its options back.
            with solve(paper_case(case, 40, 20), eps_options=loose):
                pass
    with solve(paper_case("free", 40, 20)) as analysis:  # the default options: verified
        assert analysis.problem._free_verified
        # Navier's value for the paper's plate, 12.7559 MPa (README); the mesh error at
        # 40x20 is 3.4e-3 (it falls as h^2: tests/verification/test_plate.py).
        assert abs(analysis.result.critical_load_Pa / 12.7559e6 - 1.0) < 4e-3
