"""The KSP factory: a factorization chosen by option stays MUMPS (PETSc's own is 7x slower)."""

import numpy as np
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
