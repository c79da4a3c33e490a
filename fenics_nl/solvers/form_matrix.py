"""A bilinear form's PETSc matrix, filled by DOLFINx's own CSR assembler.

`petsc.assemble_matrix` inserts each cell's element matrix through PETSc's
MatSetValuesBlockedLocal, which for P2 elements costs more than the kernel: the J2 tangent of
the thick cylinder assembles faster into DOLFINx's `MatrixCSR` than through PETSc, the same
values to the last bit (the times are in docs/benchmarks.md, section "J2 plasticity against
dolfinx-external-operator"). On one rank the PETSc matrix is therefore made on the CSR's own
arrays (MatCreateSeqAIJWithArrays shares them, no copy): the assembler writes into the very
matrix MUMPS factorizes, whose pattern never changes, so the symbolic factorization is kept
as before. On several ranks the CSR holds ghost rows too: its entries, ghost rows included,
are handed to PETSc as coordinates (MatSetPreallocationCOO once, with global indices;
MatSetValuesCOO per assembly), and PETSc sums what belongs to another rank's rows over a
pattern of messages it built once. The sphere's elastic tangent on 2 ranks, too, assembles
faster this way than through PETSc, the same matrix to round-off (summation order).
"""

from __future__ import annotations

import numpy as np
from dolfinx import fem, la
from dolfinx.fem import petsc
from petsc4py import PETSc

__all__ = ["FormMatrix"]


class FormMatrix:
    """`mat`, the PETSc matrix of bilinear form `form`'s pattern; `assemble` fills it.

    `native=False` keeps PETSc's own matrix and assembler: GAMG, for one, reads the block
    size that DOLFINx gives its PETSc matrices (the native one has 1).
    """

    def __init__(self, form: fem.Form, native: bool = True):
        self._csr = None
        self._coordinates = False  # several ranks: the CSR's entries go to PETSc as COO
        if not (native and form.dtype == PETSc.ScalarType):
            self.mat = petsc.create_matrix(form)
            return
        self._csr = fem.create_matrix(form, block_mode=la.BlockMode.expanded)
        if form.mesh.comm.size > 1:
            self._by_coordinates(form.mesh.comm)
            return
        rows, cols = (self._csr.index_map(i).size_global * self._csr.block_size[i]
                      for i in (0, 1))
        # the values array is shared (the indices are copied to PETSc's integer type)
        pattern = (self._csr.indptr.astype(PETSc.IntType), self._csr.indices.astype(
            PETSc.IntType), self._csr.data)
        self.mat = PETSc.Mat().createAIJWithArrays((rows, cols), pattern, comm=PETSc.COMM_SELF)
        # the pattern is the CSR's, for life: a PETSc operation that compacted it (MatZeroRows
        # without this) or allocated a new entry would move the values away from the CSR's
        self.mat.setOption(PETSc.Mat.Option.KEEP_NONZERO_PATTERN, True)
        self.mat.setOption(PETSc.Mat.Option.NEW_NONZERO_LOCATION_ERR, True)
        # the solver's *Local calls (Dirichlet rows of a fixed tangent): local is global here
        row_map, col_map = (PETSc.LGMap().create(np.arange(n, dtype=PETSc.IntType),
                                                 comm=PETSc.COMM_SELF) for n in (rows, cols))
        self.mat.setLGMap(row_map, col_map)
        self.mat.assemble()

    def _by_coordinates(self, comm) -> None:
        """The PETSc matrix of the CSR's pattern on several ranks, filled by coordinates."""
        csr = self._csr
        rows, cols = (_global_indices(csr.index_map(i), csr.block_size[i]) for i in (0, 1))
        n_rows = len(csr.indptr) - 1  # owned and ghost rows
        i = np.repeat(rows[:n_rows], np.diff(csr.indptr)).astype(PETSc.IntType)
        j = cols[csr.indices].astype(PETSc.IntType)
        sizes = [(csr.index_map(k).size_local * csr.block_size[k],
                  csr.index_map(k).size_global * csr.block_size[k]) for k in (0, 1)]
        self.mat = PETSc.Mat().create(comm)
        self.mat.setSizes(sizes)
        self.mat.setType(PETSc.Mat.Type.AIJ)
        self.mat.setPreallocationCOO(i, j)
        self.mat.setOption(PETSc.Mat.Option.KEEP_NONZERO_PATTERN, True)
        self.mat.setOption(PETSc.Mat.Option.NEW_NONZERO_LOCATION_ERR, True)
        # the solver's *Local calls (Dirichlet rows of a fixed tangent): local, unrolled
        row_map, col_map = (PETSc.LGMap().create(g.astype(PETSc.IntType), comm=comm)
                            for g in (rows, cols))
        self.mat.setLGMap(row_map, col_map)
        self._coordinates = True

    def assemble(self, form: fem.Form, bcs=(), diag: float = 1.0) -> None:
        """Fill `mat` with the matrix of `form` (this pattern's).

        Args:
            form: the compiled bilinear form (the tangent K), of the pattern `mat` was made
                for.
            bcs: Dirichlet conditions whose rows and columns are zero but for `diag` on the
                diagonal.
            diag: the Dirichlet rows' diagonal value.
        """
        if self._csr is None:
            self.mat.zeroEntries()
            petsc.assemble_matrix(self.mat, form, bcs=list(bcs), diag=diag)
        else:
            self._csr.set_value(0.0)
            fem.assemble_matrix(self._csr, form, bcs=list(bcs), diag=diag)
            if self._coordinates:  # (the diagonal of a Dirichlet row is on its owner only)
                self.mat.setValuesCOO(self._csr.data, addv=PETSc.InsertMode.INSERT_VALUES)
        self.mat.assemble()  # a new state: a factorization of the old values is stale


def _global_indices(index_map, bs: int) -> np.ndarray:
    """Global unrolled index of every local (owned, then ghost) unrolled index."""
    n = index_map.size_local + index_map.num_ghosts
    nodes = index_map.local_to_global(np.arange(n, dtype=np.int32))
    return (nodes[:, None] * bs + np.arange(bs)).ravel()
