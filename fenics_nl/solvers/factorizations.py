"""Factorizations kept and reused: a tangent equal to one already factorized is not redone.

Named part of `NewtonSolver`'s reuse machinery, beside `row_update` (new Dirichlet rows
solved on the last factorization) and `tangent_policy` (when a tangent is rebuilt).
"""

from __future__ import annotations

import collections
import hashlib
import os

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

__all__ = ["Factorizations"]


class Factorizations:
    """Which factorization solves with the tangent just assembled (none new if it has one).

    A tangent equal, bit for bit and on every rank, to one already factorized is not
    factorized again. Full Newton on a path-dependent law assembles Hooke's tangent again
    and again: at every elastic increment, and at the first iteration of every plastic one
    (the trial state is the committed one, on the yield surface, hence elastic). The
    factorization last made is reused when the tangent equals it; a tangent that comes back
    after its factorization was replaced is factorized aside instead, in a copy (once per
    solver, MUMPS, while both fit in a quarter of the memory), and solves each time it comes
    back again, while the other tangents are factorized in the solver's own matrix: the
    copy costs no factorization that would not be made anyway. Tangents are compared through
    their product with a fixed random vector, so that no copy is kept to compare with: a
    change it hides (rows whose change sums to zero against it, to the last bit) would
    leave a factorization off by round-off, which a Newton iteration tolerates (its
    residual is exact). A restarted run has no factorization in memory: where the
    uninterrupted one kept one across the restart point, the restart makes one more, on
    the same path. `ksp` is the solver of the tangent last assembled (the solver's own,
    or the copy's): solve through it, not through the solver's own KSP.
    """

    def __init__(self, A: PETSc.Mat, ksp: PETSc.KSP, make_ksp):
        self._probe, self._product = A.createVecs()
        rng = np.random.default_rng(A.comm.rank)
        self._probe.array[:] = rng.uniform(0.5, 1.5, self._probe.getLocalSize())
        self.ksp, self._own, self._make_ksp = ksp, ksp, make_ksp
        self._digest = None  # of the matrix `ksp`'s factorization is of
        self._kept = None  # (digest, its matrix, its KSP): a returning tangent's, aside
        self._replaced = collections.deque(maxlen=8)  # digests of replaced factorizations
        self._may_keep = ksp.getType() == "preonly"  # a direct solver

    def _same(self, a: bytes | None, b: bytes | None, comm) -> bool:
        return comm.allreduce(a is not None and a == b, op=MPI.LAND)

    def factorize(self, A: PETSc.Mat, setup) -> bool:
        """Point `ksp` at a factorization of A; whether one was made (collective).

        Args:
            A: the tangent K just assembled.
            setup: ``setup()`` factorizes the solver's own KSP on A when no factorization is
                of A.

        Returns:
            True if a factorization was made (by `setup`, or of a copy kept aside), False if
            one already made is reused.
        """
        comm = A.comm.tompi4py()
        A.mult(self._probe, self._product)
        digest = hashlib.blake2b(self._product.array_r, digest_size=16).digest()
        if self._kept and self._same(digest, self._kept[0], comm):
            self.ksp = self._kept[2]
            return False
        self.ksp = self._own
        pc = self._own.getPC()
        if self._same(digest, self._digest, comm):
            pc.setReusePreconditioner(True)  # A was assembled again: PETSc would refactor
            return False
        if (self._kept is None and self._may_keep  # the same on every rank
                and comm.allreduce(digest in self._replaced, op=MPI.LAND)
                and _room_for_another(pc, comm)):
            self._keep_aside(A, digest)
            return True
        pc.setReusePreconditioner(False)
        if self._digest is not None:
            self._replaced.append(self._digest)
        self._digest = None  # a factorization that fails leaves none behind to reuse
        setup()
        self._digest = digest
        return True

    def _keep_aside(self, A: PETSc.Mat, digest: bytes) -> None:
        copy = A.copy()
        ksp = self._make_ksp(copy, self._own.getPC().getType())  # lu or cholesky, as its own
        ksp.getPC().setUp()
        self._kept = (digest, copy, ksp)
        self.ksp = ksp


def _room_for_another(pc: PETSc.PC, comm) -> bool:
    """Whether a second MUMPS factorization as large as `pc`'s fits in a quarter of RAM."""
    try:
        megabytes = pc.getFactorMatrix().getMumpsInfog(22)  # summed over the ranks
    except PETSc.Error:
        return False
    ram = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    return comm.allreduce(2 * megabytes * 2**20 < ram / 4, op=MPI.LAND)


