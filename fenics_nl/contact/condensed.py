"""A linear pair's saddle point on one factorization: the active rows by their Schur complement.

With a linear residual R(u) = K u − f, the equilibrium with the contact forces λ on the
active slave nodes A is

    u = u_0 + Σ_{j∈A} w_j λ_j,     w_j = K⁻¹ b_j,

u_0 the equilibrium without them and b_j the j-th row of B (its prescribed dofs zeroed:
the supports take no multiplier). The gaps of the active nodes close when

    S_AA λ_A = −(B_A u_0 + γ_A),     S = B W  (the contact surface's flexibility),

a dense system of the active nodes only. So K is factorized once for the whole run; a
column w_j is solved the first time node j becomes active and kept (with B w_j, a column of
S); an active-set iteration is then a small dense solve and vector updates, and a load step
costs one back-substitution (the new u_0) besides the new columns. The rigid obstacle's row
update (`solvers.row_update`) does the same with Dirichlet rows.
"""

from __future__ import annotations

import time

import numpy as np
from dolfinx.fem import petsc
from mpi4py import MPI
from petsc4py import PETSc

from fenics_nl.errors import SolveError
from fenics_nl.solvers.result import WorkCounts

__all__ = ["CondensedSaddle"]


class CondensedSaddle:
    """K factorized once and the columns w_j = K⁻¹ b_j of the nodes ever active.

    Args:
        J: the tangent form (constant: the residual is linear).
        bcs: the Dirichlet conditions (identity rows of K).
        B: the gap rows of every slave node (global columns).
        held: the prescribed dofs (global indices, this rank's).
    """

    def __init__(self, J, bcs, B: PETSc.Mat, held: PETSc.IS):
        self.J, self.bcs, self.B, self.held = J, bcs, B, held
        self.comm = B.comm.tompi4py()
        self.start = B.getOwnershipRange()[0]
        self.n = B.getSize()[0]
        self.ksp = None
        self.w: dict[int, PETSc.Vec] = {}  # global slave row -> w_j
        self.S: dict[int, np.ndarray] = {}  # global slave row -> B w_j (every slave row)

    def factorize(self, work: WorkCounts) -> None:
        """K assembled with its supports and factorized by MUMPS (once)."""
        K = petsc.assemble_matrix(self.J, self.bcs)
        K.assemble()
        work.tangent_assemblies += 1
        self.ksp = PETSc.KSP().create(K.comm)
        self.ksp.setOperators(K)
        self.ksp.setType("preonly")
        self.ksp.getPC().setType("lu")
        self.ksp.getPC().setFactorSolverType("mumps")
        t0 = time.perf_counter()
        self.ksp.setUp()
        work.factorizations += 1
        work.time["solve"] = work.time.get("solve", 0.0) + time.perf_counter() - t0

    def back_solve(self, b: PETSc.Vec, work: WorkCounts) -> PETSc.Vec:
        """K⁻¹ b on the kept factorization."""
        if self.ksp is None:
            self.factorize(work)
        x = b.duplicate()
        t0 = time.perf_counter()
        self.ksp.solve(b, x)
        work.time["solve"] = work.time.get("solve", 0.0) + time.perf_counter() - t0
        if self.ksp.getConvergedReason() < 0:
            raise SolveError(f"contact pair: the back-substitution failed "
                             f"({self.ksp.getConvergedReason()})")
        return x

    def columns(self, rows: np.ndarray, work: WorkCounts) -> None:
        """w_j and B w_j for the global slave rows `rows` not yet kept (collective).

        The new columns in one block: MUMPS solves many right-hand sides at once faster
        than one after the other.
        """
        new = [int(j) for j in rows if int(j) not in self.w]
        if not new:
            return
        if self.ksp is None:
            self.factorize(work)
        E = PETSc.Mat().createDense((self.B.getSizes()[0], (None, len(new))), comm=self.B.comm)
        E.setUp()
        for k, j in enumerate(new):
            if self.start <= j < self.start + self.B.getLocalSize()[0]:
                E.setValue(j, k, 1.0)
        E.assemble()
        b = self.B.transposeMatMult(E)  # the rows of B, as columns
        b.zeroRows(self.held, diag=0.0)  # the supports take no multiplier
        b = b.convert("dense")
        x = b.duplicate()
        t0 = time.perf_counter()
        self.ksp.matSolve(b, x)
        work.time["solve"] = work.time.get("solve", 0.0) + time.perf_counter() - t0
        work.update_columns += len(new)
        Bx = self.B.matMult(x)
        local = Bx.getDenseArray()
        every = np.vstack(self.comm.allgather(np.asarray(local)))
        for k, j in enumerate(new):
            self.w[j] = x.getColumnVector(k)
            self.S[j] = every[:, k].copy()

    def flexibility(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """S[rows, cols] (dense, the same on every rank)."""
        if len(cols) == 0:
            return np.zeros((len(rows), 0))
        return np.column_stack([self.S[int(j)][rows] for j in cols])

    def add(self, u: PETSc.Vec, rows: np.ndarray, values: np.ndarray) -> None:
        """u += Σ_j w_j values_j."""
        for j, value in zip(rows, values, strict=True):
            u.axpy(float(value), self.w[int(j)])


def every_rank(comm: MPI.Comm, values: np.ndarray) -> np.ndarray:
    """This rank's owned values of a slave-row vector, joined in the global row order."""
    return np.concatenate(comm.allgather(np.asarray(values)))
