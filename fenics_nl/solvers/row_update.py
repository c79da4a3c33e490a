"""New Dirichlet rows on an old factorization: a bordered solve on the rows that changed.

A linear material's tangent K does not change; contact changes which rows are Dirichlet
rows (u_n = γ at the active nodes). The matrix of a row set B is M_B = P K P + (I − P),
P zeroing B's rows and columns, so that M_B x = r means x_B = r_B and, on the free rows F,
Σ_{j∈F} K_ij x_j = r_i. With M_b factorized for a base set B_b, a set B adds the rows J
(free in the base) and releases the rows L (constrained in it). Write x = M_b⁻¹ y, with the
base's right-hand side y = r on B ∩ B_b, y_L = v (the released rows' values), y_J free
(μ: whatever else lands on the added rows is absorbed there), and on the rows free in both
r + K_{·,J} r_J − K_{·,L} v (the forces M_B puts there, less those M_b adds itself). Then

    x = x₀ + Z μ + W v,   Z_j = M_b⁻¹ e_j,   W_l = M_b⁻¹ (e_l − P_b K e_l),

and the |J| + |L| unknowns (μ, v) follow from x_J = r_J and the released rows' equilibrium
(K (x − r_B))_L = r_L (r_B: r on B, 0 elsewhere): the capacitance system, Woodbury's
identity in bordered form.
It is regular when M_B is: (μ, v) ↦ x is one-to-one.

The columns Z_j, W_l are back-solves with the base's factors, made once per row (blocked,
MUMPS's MatMatSolve, the right-hand sides sparse) and kept until the next factorization.
A solve then costs one back-solve, two products with K and a dense solve of |J| + |L|
unknowns. The columns stop paying when they would cost more than the factorization they
stand for (`columns_per_factorization`): `set_rows` then declines, and the caller
factorizes again (a new base).
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg
from mpi4py import MPI
from petsc4py import PETSc

from fenics_nl.solvers.result import WorkCounts

__all__ = ["RowUpdate", "columns_per_factorization"]


def columns_per_factorization(factor: PETSc.Mat) -> int:
    """Back-solves that cost a MUMPS factorization: its flops over a column's.

    The elimination's flops (RINFOG(3)) over a forward and a backward substitution's,
    twice the entries of the factors (INFOG(29), −millions past 2³¹). Counted, not timed,
    so that a run and its restart, or its ranks, decide alike. Blocked, a column's
    substitution runs at about the factorization's flop rate: on the axisymmetric and 3D
    punches this count is somewhat above the ratio of their times.

    Args:
        factor: MUMPS's factors (the factor matrix of the KSP's PC, factorized).

    Returns:
        The number of columns (back-solves) one factorization is worth; 0 if the factors
        have no entries.
    """
    flops, entries = factor.getMumpsRinfog(3), factor.getMumpsInfog(29)
    entries = entries if entries >= 0 else -entries * 1e6
    return int(flops / (2 * entries)) if entries else 0


class RowUpdate:
    """Solves with M_B for a row set B on a factorization of M_b (`rebase`).

    `K`: the matrix without Dirichlet rows (the linear material's tangent), kept unchanged.
    Rows are the owned local indices of K's layout (what `DirichletBC.dof_indices` gives).
    """

    MAX_BYTES = 2**30  # kept columns (Z or W, and K times them) per rank
    # the capacitance matrix's least reciprocal condition number (equilibrated rows): below,
    # its solve would keep fewer than about 6 of the 16 digits
    RCOND_MIN = 1e-10

    def __init__(self, K: PETSc.Mat):
        self.K = K
        self.comm = K.comm.tompi4py()
        self.start = K.getOwnershipRange()[0]
        self.n = K.getLocalSize()[0]
        self.factor = None  # the base's factors (None: no base, solve otherwise)
        self.serving = False  # the current rows are solved here
        self._vecs = [K.createVecRight() for _ in range(3)]

    def rebase(self, factor: PETSc.Mat, rows: np.ndarray) -> None:
        """A new base, M_b just factorized: the columns made on the old one are dropped.

        Args:
            factor: MUMPS's factors of M_b.
            rows: the base rows B_b (owned local indices), the current rows until
                `set_rows`.
        """
        self.factor = factor
        self.base = np.zeros(self.n, dtype=bool)
        self.base[rows] = True
        self.budget = columns_per_factorization(factor)
        self.column_of: dict[int, int] = {}  # global row -> its column
        for M in getattr(self, "_mats", ()):
            M.destroy()
        self._mats: list[PETSc.Mat] = []  # the dense X and K X, which the blocks view
        self._blocks: list[tuple[int, np.ndarray, np.ndarray]] = []  # (first, X, K X)
        self._set(rows, [], [])

    def set_rows(self, rows: np.ndarray, work: WorkCounts) -> bool:
        """Solve with the Dirichlet rows `rows` from now on; False if a factorization pays.

        (It pays when the columns would cost more than one, and when their capacitance
        matrix is singular to working precision: see `_set`.)

        Collective. Makes the columns of the rows that changed and have none yet.

        Args:
            rows: the Dirichlet rows B (owned local indices).
            work: the counts the columns made are added to (`update_columns`).

        Returns:
            True if `solve` serves the rows B from now on, False if a factorization pays
            (or there is no base).
        """
        if self.factor is None:
            return False
        now = np.zeros(self.n, dtype=bool)
        now[rows] = True
        added = self._gather(np.flatnonzero(now & ~self.base))
        released = self._gather(np.flatnonzero(self.base & ~now))
        new = [(g, False) for g in added if g not in self.column_of]
        new += [(g, True) for g in released if g not in self.column_of]
        if not (self._make_columns(new, work) and self._set(rows, added, released)):
            self.serving = False
            return False
        return True

    def solve(self, rhs: PETSc.Vec, out: PETSc.Vec) -> None:
        """out = M_B⁻¹ rhs on the owned entries (collective).

        Args:
            rhs: the right-hand side r.
            out: receives M_B⁻¹ r.
        """
        r = rhs.array_r[: self.n]
        w, Kw, x0 = self._vecs
        # the base's right-hand side: the forces of the added rows' values on the free rows
        w.array[:] = np.where(self.now & ~self.base, r, 0.0)
        Kw_ = self._times_K(w, Kw)
        y = r + np.where(self.base, 0.0, Kw_)
        y[self.released_local] = 0.0
        w.array[:] = y
        self.factor.solve(w, x0)
        x = x0.array_r.copy()
        # the conditions' right-hand sides: x_J = r_J and (K (x − r_B))_L = r_L
        w.array[:] = x - np.where(self.now, r, 0.0)
        K_free = self._times_K(w, Kw)
        rows_J, rows_L = self.added_local, self.released_local
        local = np.concatenate([r[rows_J] - x[rows_J], r[rows_L] - K_free[rows_L]])
        if self.size:
            parts = self.comm.allgather((local[: len(rows_J)], local[len(rows_J):]))
            b = np.concatenate([p[0] for p in parts] + [p[1] for p in parts])
            coefficients = np.zeros(len(self.column_of))
            r_scale, c_scale = self.scales
            coefficients[self.columns] = scipy.linalg.lu_solve(self.lu, b / r_scale) / c_scale
            for first, X, _ in self._blocks:  # the unused columns' coefficients are 0
                x += X @ coefficients[first:first + X.shape[1]]
        out.array[: self.n] = x

    # -- pieces ----------------------------------------------------------------------

    def _set(self, rows, added: list[int], released: list[int]) -> bool:
        """The current rows, and the capacitance matrix of their change, factorized.

        False if that matrix is singular to working precision (then M_B is, or nearly):
        a reciprocal condition number below RCOND_MIN leaves the rows to a new
        factorization, which has its own checks, rather than solve them to a few digits.
        Its entries are compliances (Z on the added rows), numbers (W there, K Z on the
        released rows) and stiffnesses (K W): equilibrated on both sides, rows then
        columns, its condition does not depend on the units.
        """
        self.now = np.zeros(self.n, dtype=bool)
        self.now[rows] = True
        local = lambda g: np.asarray([i - self.start for i in g  # noqa: E731
                                      if self.start <= i < self.start + self.n], dtype=int)
        self.added_local, self.released_local = local(added), local(released)
        self.columns = [self.column_of[g] for g in [*added, *released]]
        self.size = len(self.columns)
        self.serving = True
        if not self.size:
            return True
        parts = self.comm.allgather((self._pick(0, self.added_local),
                                     self._pick(1, self.released_local)))
        G = np.vstack([p[0] for p in parts] + [p[1] for p in parts])
        self.scales = []
        for axis in (1, 0):  # G ← diag(1/r) G diag(1/c)
            scale = np.abs(G).max(axis=axis)
            scale[scale == 0] = 1.0
            G /= scale[:, None] if axis else scale[None, :]
            self.scales.append(scale)
        with warnings.catch_warnings():  # a zero pivot: rcond says it below
            warnings.simplefilter("ignore", scipy.linalg.LinAlgWarning)
            self.lu = scipy.linalg.lu_factor(G)
        rcond = scipy.linalg.lapack.dgecon(self.lu[0], np.linalg.norm(G, 1), norm="1")[0]
        # every rank has the same G: one decision all the same (the calls that follow are
        # collective)
        return self.comm.allreduce(bool(rcond >= self.RCOND_MIN), op=MPI.LAND)

    def _gather(self, local_rows: np.ndarray) -> list[int]:
        """Global indices of every rank's `local_rows`, in increasing order.

        The same list on every rank: ranks own consecutive ranges.
        """
        return [int(g) for part in self.comm.allgather(local_rows + self.start) for g in part]

    def _make_columns(self, rows: list[tuple[int, bool]], work: WorkCounts) -> bool:
        """Columns of `rows` (global index, released); False if a factorization pays.

        Declined when the base would then have more columns than `budget`, or columns
        taking more than MAX_BYTES.
        """
        total = len(self.column_of) + len(rows)
        too_big = 2 * total * self.n * 8 > self.MAX_BYTES
        if total > self.budget or self.comm.allreduce(too_big, op=MPI.LOR):
            return False
        if rows:
            self._solve_columns(rows)
            work.update_columns += len(rows)
        return True

    def _solve_columns(self, rows: list[tuple[int, bool]]) -> None:
        """Z_j = M_b⁻¹ e_j (rows added), W_l = M_b⁻¹ (e_l − P_b K e_l) (rows released).

        Kept with K times them.

        The right-hand sides go to MUMPS as a sparse matrix (transposed, as MatMatSolve
        takes it): its forward elimination then skips what they do not reach (faster than
        dense ones on the axisymmetric punch). On one rank only: on two,
        MUMPS refuses distributed sparse ones (INFOG(1) = −27, PETSc 3.25), and gathered
        on rank 0 they gave zero columns for released rows (measured): dense there.
        """
        m, comm = len(rows), self.comm
        sizes = ((self.n, PETSc.DETERMINE), (PETSc.DECIDE, m))
        E = PETSc.Mat().createAIJ(sizes, nnz=(1, 1), comm=comm)
        E.setUp()
        for c, (g, _) in enumerate(rows):
            if self.start <= g < self.start + self.n:
                E.setValue(g, c, 1.0)
        E.assemble()
        B = E.copy()
        if any(released for _, released in rows):
            KE = self.K.matMult(E)
            which, free = KE.createVecs()  # over its columns, over its rows
            free.array[:] = ~self.base
            c0, c1 = which.getOwnershipRange()
            which.array[:] = [released for _, released in rows[c0:c1]]
            KE.diagonalScale(L=free, R=which)
            B.axpy(-1.0, KE, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            KE.destroy()
        X = PETSc.Mat().createDense(sizes, comm=comm)
        X.setUp()
        if comm.size == 1:
            Bt = B.transpose()
            self.factor.matSolve(PETSc.Mat().createTranspose(Bt), X)
        else:
            Bt = PETSc.Mat().createDense(sizes, comm=comm)
            Bt.setUp()
            B.convert("dense", Bt)
            self.factor.matSolve(Bt, X)
        KX = self.K.matMult(X)
        first = len(self.column_of)
        # PETSc's own storage (column-major), kept and viewed, not copied
        self._mats += [X, KX]
        self._blocks.append((first, X.getDenseArray(readonly=True),
                             KX.getDenseArray(readonly=True)))
        for c, (g, _) in enumerate(rows):
            self.column_of[g] = first + c
        for M in (E, B, Bt):
            M.destroy()

    def _pick(self, which: int, rows: np.ndarray) -> np.ndarray:
        """The current columns of X (`which` 0) or K X (1) at the few local `rows`."""
        every = np.hstack([arrays[which][rows] for _, *arrays in self._blocks])
        return every[:, self.columns]

    def _times_K(self, w: PETSc.Vec, out: PETSc.Vec) -> np.ndarray:
        self.K.mult(w, out)
        return out.array_r

