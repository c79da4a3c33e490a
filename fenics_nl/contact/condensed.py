"""A linear pair's saddle point on one factorization: the active rows by their Schur complement.

With a linear residual R(u) = K u − f, the equilibrium with the contact forces λ on the
active slave nodes A is

    u = u_0 + Σ_{j∈A} w_j λ_j,     w_j = K⁻¹ b_j,

u_0 the equilibrium without them and b_j the j-th row of B (its prescribed dofs zeroed:
the supports take no multiplier). The gaps of the active nodes close when

    S_AA λ_A = −(B_A u_0 + γ_A),     S = B W  (the contact surface's flexibility),

a dense system of the active nodes only. So K is factorized once for the whole run; a
column w_j is solved the first time node j becomes active (in one block with the others
new at that iteration) and B w_j, a column of S (every row's), kept; an active-set
iteration is then a small dense solve, every row's gap moved by S's columns (Δ(Bu) = S Δλ,
`PairContact._defer`); u itself is moved once the set has settled, one back-substitution
(Σ w_j Δλ_j), and a load step needs one more (the new u_0). The rigid obstacle's row
update (`solvers.row_update`) does the same with Dirichlet rows.

The rows come in blocks (the normal gaps B; with friction also the tangential slips B_t):
a force on a row of any block, unknown (an active gap, a stuck node's slip) or known (a
slipping node's f λ_n), moves u by its column. `solve` takes the forces of every row
before and the rows whose force is unknown, and returns the new forces.
"""

from __future__ import annotations

import time

import numpy as np
from dolfinx.fem import petsc
from mpi4py import MPI
from petsc4py import PETSc

from fenics_nl.errors import SolveError
from fenics_nl.solvers.linear_solver import create_ksp, factorized_counting_null_pivots
from fenics_nl.solvers.result import WorkCounts

__all__ = ["CondensedSaddle"]

PREFIX = "pair_"  # the PETSc options of a pair's solves (-pair_ksp_view, ...)
CHUNK = 64  # new columns solved at once: MUMPS's multiple right-hand sides, memory bounded


class CondensedSaddle:
    """K factorized once and the flexibility S = B K⁻¹ Bᵀ's columns of the rows ever loaded.

    A row is (block, j): the j-th global row of the block's matrix.

    Args:
        J: the tangent form (constant: the residual is linear).
        bcs: the Dirichlet conditions (identity rows of K).
        blocks: the row blocks (PETSc matrices of the same layout, global columns).
        held: the prescribed dofs (global indices, this rank's).
    """

    def __init__(self, J, bcs, blocks: list[PETSc.Mat], held: PETSc.IS):
        self.J, self.bcs, self.blocks, self.held = J, bcs, blocks, held
        B = blocks[0]
        self.comm = B.comm.tompi4py()
        self.start, self.local = B.getOwnershipRange()[0], B.getLocalSize()[0]
        self.n = B.getSize()[0]  # rows per block (every rank's)
        self.ksp = None
        self.free_motions = 0  # K's null pivots: motions its supports leave free
        self.column: dict[int, int] = {}  # row (block * n + j) -> its column of S
        # S's columns [B w; B_t w; ...] (every row), in an array with room for twice
        # the columns (grown by doubling, not copied at every new column); the w
        # themselves are not kept (rows of u × columns: too many), u moves by a
        # back-substitution instead (`move`)
        self._S = np.zeros((len(blocks) * self.n, 0))

    @property
    def S(self) -> np.ndarray:
        """The flexibility's kept columns, [B w; B_t w; ...] (every row, dense)."""
        return self._S[:, :len(self.column)]

    def factorize(self, work: WorkCounts) -> None:
        """K assembled with its supports and factorized by MUMPS (once)."""
        K = petsc.assemble_matrix(self.J, self.bcs)
        K.assemble()
        work.tangent_assemblies += 1
        self.ksp = create_ksp(K, "lu", prefix=PREFIX)
        t0 = time.perf_counter()
        free = factorized_counting_null_pivots(self.ksp)
        work.factorizations += 1
        work.time["solve"] = work.time.get("solve", 0.0) + time.perf_counter() - t0
        self.free_motions = free
        if free:  # a body the contact alone holds: its saddle point may not be singular
            raise SolveError(f"K is singular ({free} motion(s) free without the contact)")

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
        """S's columns [B w; ...] (w = K⁻¹ b) of the rows (block * n + j) not yet kept.

        The new columns in blocks of `CHUNK`: MUMPS solves many right-hand sides at once
        faster than one after the other. Collective.
        """
        new = [int(k) for k in rows if int(k) not in self.column]
        if self.ksp is None and new:
            self.factorize(work)
        for first in range(0, len(new), CHUNK):  # dense n × CHUNK blocks at most
            self._new_columns(new[first:first + CHUNK], work)

    def _new_columns(self, new: list[int], work: WorkCounts) -> None:
        b = self._unit_loads(new)
        x = b.duplicate()
        t0 = time.perf_counter()
        self.ksp.matSolve(b, x)
        work.time["solve"] = work.time.get("solve", 0.0) + time.perf_counter() - t0
        work.update_columns += len(new)
        every = np.vstack([np.vstack(self.comm.allgather(np.asarray(
            M.matMult(x).getDenseArray()))) for M in self.blocks])
        first, last = len(self.column), len(self.column) + len(new)
        if last > self._S.shape[1]:  # more room: twice what is needed
            grown = np.zeros((self._S.shape[0], 2 * last))
            grown[:, :first] = self.S
            self._S = grown
        self._S[:, first:last] = every
        self.column.update({k: first + col for col, k in enumerate(new)})

    def _unit_loads(self, rows: list[int]) -> PETSc.Mat:
        """b_k for the rows k, as the columns of a dense matrix (u's rows).

        b_k: the row k of its block, transposed, the supports' dofs zeroed (they take no
        force).
        """
        b = None
        for block, M in enumerate(self.blocks):
            E = PETSc.Mat().createDense((M.getSizes()[0], (None, len(rows))), comm=M.comm)
            E.setUp()
            for col, k in enumerate(rows):
                j = k - block * self.n
                if k // self.n == block and self.start <= j < self.start + self.local:
                    E.setValue(j, col, 1.0)
            E.assemble()
            part = M.transposeMatMult(E)
            if b is None:
                b = part
            else:
                b.axpy(1.0, part, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        b.zeroRows(self.held, diag=0.0)
        return b.convert("dense")

    def _load(self, forces: np.ndarray) -> PETSc.Vec:
        """Σ_k b_k forces_k (every row's force; u's layout, the supports' dofs zeroed)."""
        out = None
        for block, M in enumerate(self.blocks):
            v = M.createVecLeft()
            first = block * self.n + self.start
            v.array[:] = forces[first:first + self.local]
            part = M.createVecRight()
            M.multTranspose(v, part)
            out = part if out is None else out + part
        out.array[self.held.indices - out.getOwnershipRange()[0]] = 0.0
        return out

    def solve(self, before: np.ndarray, unknown: np.ndarray, known: np.ndarray,
              residual: np.ndarray, work: WorkCounts,
              compliance: np.ndarray | None = None, frame=None) -> np.ndarray:
        """The rows' new forces, and u moved by their columns (`move` applies it).

        Args:
            before: every row's force now (u is in equilibrium with them).
            unknown: the rows whose force makes their `residual` (a gap, a slip) zero.
            known: every row's force where it is given (slipping nodes), else 0.
            residual: every row's condition at u now (gaps, slips since the last step),
                with its compliance's term c λ if any.
            work: the counts.
            compliance: c, one per row (the first ones: of the first block) or None: each
                unknown row's condition is then residual + S Δλ + c Δλ = 0 (wear in the
                gap, a spring across a slip).
            frame: Q, an orthonormal sparse matrix (rows × rows) whose columns are new
                rows in the blocks' (a 3D slipping node's tangential rows turned along and
                across its slip), or None. With it `unknown`, `known`, `residual` and
                `compliance` are the new rows' (forces Qᵀλ, conditions Qᵀr; S is QᵀSQ);
                `before` and the answer stay the blocks' rows'.

        Returns:
            Every row's new force (0 outside `unknown` and the given ones).
        """
        if frame is None:
            return self._solve(before, unknown, known, residual, work, compliance)
        return frame @ self._solve(frame.T @ before, unknown, known, residual, work,
                                   compliance, frame)

    def _solve(self, before, unknown, known, residual, work, compliance=None, frame=None):
        """`solve` with every force and condition the frame's rows' (`before` too)."""
        after = known.copy()
        loaded = np.flatnonzero(before)
        rows = np.union1d(np.union1d(unknown, np.flatnonzero(known)), loaded)
        self.columns(rows if frame is None else _support(frame, rows), work)
        unknown = np.asarray(unknown, dtype=int)
        S = self.flexibility(unknown, unknown, frame)
        keep = np.abs(np.diag(S)) > 0  # a row on held dofs only (S_kk = 0) takes no force
        free, S = unknown[keep], S[np.ix_(keep, keep)]
        if len(free):
            rhs = -residual[free] + self.flexibility(free, loaded, frame) @ before[loaded]
            given = np.flatnonzero(known)
            rhs -= self.flexibility(free, given, frame) @ known[given]
            if compliance is not None:  # c (λ_new − λ_before) joins the residual's c λ_before
                c = np.zeros(len(before))
                c[:len(compliance)] = compliance
                S = S + np.diag(c[free])
                rhs += c[free] * before[free]
            after[free] = np.linalg.solve(S, rhs)
        return after

    def flexibility(self, rows: np.ndarray, cols: np.ndarray, frame=None) -> np.ndarray:
        """S[rows, cols] (dense, the same on every rank); with a `frame` Q, (QᵀSQ)[rows, cols]."""
        rows, cols = np.asarray(rows, dtype=int), np.asarray(cols, dtype=int)
        if frame is None:
            return self.S[np.ix_(rows, [self.column[int(k)] for k in cols])]
        old_rows, old_cols = _support(frame, rows), _support(frame, cols)
        left = frame[old_rows][:, rows].toarray()  # Q[old, new]
        right = frame[old_cols][:, cols].toarray()
        return left.T @ self.flexibility(old_rows, old_cols) @ right

    def move(self, u: PETSc.Vec, before: np.ndarray, after: np.ndarray,
             work: WorkCounts) -> None:
        """u += K⁻¹ Σ_k b_k (after_k − before_k): one back-substitution."""
        if np.any(after != before):
            u.axpy(1.0, self.back_solve(self._load(after - before), work))
            work.linear_solves += 1


def _support(frame, rows: np.ndarray) -> np.ndarray:
    """The old rows that the new `rows` (columns of the frame Q) are made of."""
    return np.unique(frame[:, np.asarray(rows, dtype=int)].nonzero()[0])


def every_rank(comm: MPI.Comm, values: np.ndarray) -> np.ndarray:
    """This rank's owned values of a slave-row vector, joined in the global row order."""
    return np.concatenate(comm.allgather(np.asarray(values)))
