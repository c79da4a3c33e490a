"""The KSP factory: a factorization chosen by option stays MUMPS (PETSc's own is 7x slower)."""

import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

from fenics_nl.solvers.linear_solver import create_ksp


def laplacian(n=50):
    A = PETSc.Mat().createAIJ([n, n], nnz=3, comm=MPI.COMM_SELF)
    for i in range(n):
        A[i, i] = 2.0
        if i:
            A[i, i - 1] = A[i - 1, i] = -1.0
    A.assemble()
    return A


def test_cholesky_by_option_keeps_mumps_and_solves():
    opts = PETSc.Options()
    opts["cholopt_pc_type"] = "cholesky"
    try:
        A = laplacian()
        ksp = create_ksp(A, "lu", prefix="cholopt_")
        assert ksp.getPC().getType() == "cholesky"
        assert ksp.getPC().getFactorSolverType() == "mumps"
        assert A.isSymmetricKnown()[1]  # flagged for LDLᵀ
        b, x = A.createVecs()
        b.set(1.0)
        ksp.solve(b, x)
        r = b.duplicate()
        A.mult(x, r)
        r.axpy(-1.0, b)
        assert r.norm() < 1e-10 * b.norm()
    finally:
        opts.delValue("cholopt_pc_type")
    assert np.isfinite(x.norm())


def _elasticity_with_a_support(comm):
    """P2 elasticity of a unit square clamped on x = 0: its bilinear form (UFL), support and
    modulus (a Constant)."""
    import ufl
    from dolfinx import fem, mesh

    msh = mesh.create_unit_square(comm, 6, 6)
    V = fem.functionspace(msh, ("Lagrange", 2, (2,)))
    E = fem.Constant(msh, 1.0)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    eps = ufl.sym(ufl.grad(u))
    a = E * (ufl.inner(eps, ufl.sym(ufl.grad(v))) + 0.5 * ufl.div(u) * ufl.div(v)) * ufl.dx
    clamped = fem.locate_dofs_geometrical(V, lambda x: np.isclose(x[0], 0.0))
    return a, fem.dirichletbc(np.zeros(2), clamped, V), E


def test_the_native_tangent_is_petscs_bit_for_bit_and_refactorized_when_it_changes():
    # FormMatrix on one rank: DOLFINx's CSR assembler writes into the arrays of the PETSc
    # matrix MUMPS factorizes; the same entries as petsc.assemble_matrix, and a new assembly
    # is a new matrix state (a stale factorization would solve with the old values)
    from dolfinx import fem
    from dolfinx.fem import petsc

    from fenics_nl.solvers.form_matrix import FormMatrix

    a, bc, E = _elasticity_with_a_support(MPI.COMM_SELF)
    a = fem.form(a)
    native = FormMatrix(a)
    assert native.mat.getType() == "seqaij"
    for modulus in (1.0, 3.0):
        E.value = modulus
        native.assemble(a, [bc])
        reference = petsc.assemble_matrix(a, bcs=[bc], diag=1.0)
        reference.assemble()
        reference.axpy(-1.0, native.mat, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        assert reference.norm() == 0.0
    ksp = create_ksp(native.mat, "lu")
    b, x = native.mat.createVecs()
    b.set(1.0)
    petsc.set_bc(b, [bc])
    ksp.solve(b, x)
    before = x.copy()
    E.value = 6.0  # twice the modulus: half the displacement (to round-off), same KSP
    native.assemble(a, [bc])
    ksp.solve(b, x)
    free = np.abs(before.array) > 0
    assert np.allclose(x.array[free] * 2.0, before.array[free], rtol=1e-10, atol=0.0)
    # PETSc's own row operations keep the CSR's pattern: the next assembly is still exact
    # (a compacted pattern would put the values where the CSR's indices do not say)
    rows = np.arange(0, 40, 3, dtype=PETSc.IntType)
    native.mat.zeroRowsColumnsLocal(rows, diag=1.0)
    native.mat.zeroRowsLocal(rows + 1, diag=1.0)  # this one would compact by default
    native.assemble(a, [bc])
    reference = petsc.assemble_matrix(a, bcs=[bc], diag=1.0)
    reference.assemble()
    reference.axpy(-1.0, native.mat, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    assert reference.norm() == 0.0


def test_newtons_tangent_is_the_native_matrix_on_one_rank():
    # DOLFINx's own PETSc matrix of this 2-vector space has block size 2, the native one 1
    import ufl
    from dolfinx import fem

    from fenics_nl.solvers.newton import NewtonSolver

    a, bc, _ = _elasticity_with_a_support(MPI.COMM_SELF)
    V = a.arguments()[0].ufl_function_space()
    u, v = fem.Function(V), ufl.TestFunction(V)
    residual = ufl.action(a, u) - ufl.dot(ufl.as_vector((0.0, -1.0)), v) * ufl.dx
    for kind, block in (("lu", 1), ("gamg", 2)):
        solver = NewtonSolver(residual, u, [bc], linear_solver=kind, prefix=f"native_{kind}_")
        assert solver.A.getBlockSize() == block


@pytest.mark.mpi
def test_on_two_ranks_the_csr_fills_petscs_matrix_by_coordinates():
    # the CSR's ghost rows summed by PETSc's COO exchange: petsc.assemble_matrix's matrix
    # to round-off (another summation order), after a new assembly and PETSc's row operations
    from dolfinx import fem
    from dolfinx.fem import petsc

    from fenics_nl.solvers.form_matrix import FormMatrix

    a, bc, E = _elasticity_with_a_support(MPI.COMM_WORLD)
    a = fem.form(a)
    matrix = FormMatrix(a)
    assert matrix.mat.getType() == "mpiaij" and MPI.COMM_WORLD.size > 1

    def assert_is_petscs():
        matrix.assemble(a, [bc])
        reference = petsc.assemble_matrix(a, bcs=[bc], diag=1.0)
        reference.assemble()
        scale = reference.norm()
        reference.axpy(-1.0, matrix.mat, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        assert reference.norm() <= 1e-14 * scale

    for modulus in (1.0, 3.0):
        E.value = modulus
        assert_is_petscs()
    rows = np.arange(0, 40, 3, dtype=PETSc.IntType)
    matrix.mat.zeroRowsColumnsLocal(rows, diag=1.0)
    assert_is_petscs()


def test_gamg_on_an_indefinite_tangent_is_right_preconditioned_gmres_and_solves_it():
    # a tangent past a limit point: K shifted between its two lowest eigenvalues (one
    # negative direction), where CG stops at once (KSP_DIVERGED_INDEFINITE_PC, residual 1.8)
    from dolfinx import fem
    from dolfinx.fem import petsc

    from fenics_nl.solvers.linear_solver import rigid_body_modes

    a, bc, _ = _elasticity_with_a_support(MPI.COMM_SELF)
    A = petsc.assemble_matrix(fem.form(a), bcs=[bc])
    A.assemble()
    dense = A.copy().convert("dense")
    lowest = np.linalg.eigvalsh(dense.getDenseArray())[:2]
    dense.destroy()
    A.shift(-lowest.mean())
    V = a.arguments()[0].ufl_function_space()
    ksp = create_ksp(A, "gamg", prefix="indef_", near_nullspace=rigid_body_modes(V),
                     rtol=1e-10, indefinite=True)
    assert ksp.getType() == "gmres" and ksp.getPCSide() == PETSc.PC.Side.RIGHT
    b, x = A.createVecs()
    b.setRandom()
    ksp.solve(b, x)
    assert ksp.getConvergedReason() > 0
    assert ksp.getIterationNumber() < 60  # 32 with GAMG; GMRES unpreconditioned takes 177
    r = b.duplicate()
    A.mult(x, r)
    r.axpy(-1.0, b)
    assert r.norm() < 1e-9 * b.norm()  # the true residual: right preconditioning's norm


def test_gmres_and_gamg_smooth_by_sor_unless_the_options_say_otherwise():
    # Chebyshev (PETSc's smoother) is built on bounds of a real positive spectrum, which an
    # indefinite or non-symmetric tangent lacks: GMRES's GAMG levels are smoothed by SOR,
    # and converge in fewer iterations on the shifted (indefinite) elasticity matrix (19
    # against 27); CG's keep Chebyshev; an option given keeps its choice
    from dolfinx import fem
    from dolfinx.fem import petsc

    from fenics_nl.solvers.linear_solver import allow_unsymmetric, rigid_body_modes

    a, bc, _ = _elasticity_with_a_support(MPI.COMM_SELF)
    K = petsc.assemble_matrix(fem.form(a), bcs=[bc])
    K.assemble()
    dense = K.copy().convert("dense")
    A = K.copy()
    A.shift(-np.linalg.eigvalsh(dense.getDenseArray())[:2].mean())  # one negative eigenvalue
    dense.destroy()
    modes = rigid_body_modes(a.arguments()[0].ufl_function_space())
    b, x = A.createVecs()
    b.setRandom()

    def solved(prefix, indefinite, options=(), unsymmetric_later=False):
        matrix = A if indefinite or unsymmetric_later else K
        for name, value in options:
            PETSc.Options()[f"{prefix}{name}"] = value
        ksp = create_ksp(matrix, "gamg", prefix=prefix, near_nullspace=modes, rtol=1e-8,
                         indefinite=indefinite)
        if unsymmetric_later:  # friction's consistent tangent turns CG into GMRES
            assert allow_unsymmetric(ksp) and ksp.getType() == "gmres"
        x.set(0.0)
        ksp.solve(b, x)
        for name, _ in options:
            PETSc.Options().delValue(f"{prefix}{name}")
        assert ksp.getConvergedReason() > 0
        smoother = ksp.getPC().getMGSmoother(1)
        return ksp.getIterationNumber(), smoother.getType(), smoother.getPC().getType()

    sor_its, *sor = solved("sor_", True)
    cheb_its, *cheb = solved("cheb_", True, (("mg_levels_ksp_type", "chebyshev"),
                                            ("mg_levels_pc_type", "jacobi")))
    assert sor == ["richardson", "sor"] and cheb == ["chebyshev", "jacobi"]
    assert sor_its < cheb_its
    assert solved("spd_", False)[1:] == ("chebyshev", "jacobi")
    # the database outlives a solver: CG after GMRES under one prefix is Chebyshev's again
    assert solved("sor_", False)[1:] == ("chebyshev", "jacobi")
    assert solved("later_", False, unsymmetric_later=True)[1:] == ("richardson", "sor")
