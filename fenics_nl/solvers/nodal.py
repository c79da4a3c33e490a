"""Nodal terms: point forces, nodal springs and row couplings that no integral gives.

A `NewtonSolver` holds one `NodalTerms` (`solver.nodal`), its one hook for them: the
friction force of a slipping contact node and, in 3D, its spring against slip across the
force's direction (`contact.friction` sets both before each solve); the apex load of the
von Mises truss (tests/test_arclength.py). The solver adds them to every residual and
tangent it assembles, and rebuilds its tangent when the springs or couplings change.

A *coupling* makes a row take a multiple of another's, R_t + c R_s and K_t + c K_s, R_s
the residual at a Dirichlet dof (its reaction, before the Dirichlet row replaces it):
friction's force f |T_n| s at a slipping node with T_n its normal dof's reaction, in
Newton's iteration itself (the force follows the normal force, with its derivative),
rather than a point force from the last solve's T_n.
"""

from __future__ import annotations

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

__all__ = ["NodalTerms"]


class NodalTerms:
    """Point forces and nodal springs on the dofs of a function space (owned, local)."""

    def __init__(self, V, comm: MPI.Comm):
        self.V, self.comm = V, comm
        self.load = None  # (dofs, values)
        self.springs = None  # (dofs, stiffness, anchor)
        self.couplings = None  # (targets, sources, coefficients)
        self.version = 0  # grows when the springs or couplings change: the tangent is stale

    @property
    def plain(self) -> bool:
        """No springs and no couplings: the tangent is the form's alone."""
        return self.springs is None and self.couplings is None

    def set_load(self, dofs: np.ndarray, values: np.ndarray) -> None:
        """Point forces F = `values` at `dofs`: R(u) − F.

        Replaces the previous ones; the tangent does not depend on them.

        Args:
            dofs: the local indices of the loaded dofs.
            values: F at each of them.
        """
        self.load = (np.asarray(dofs, dtype=np.int32), np.asarray(values, dtype=float))

    def set_springs(self, dofs: np.ndarray, stiffness: np.ndarray, anchor: np.ndarray) -> None:
        """Nodal springs: R(u) + k (u − a) at each node's dofs, k added to the tangent.

        Replaces the previous ones. Collective: every rank's tangent is rebuilt if any rank
        has (or had) springs.

        Args:
            dofs: (n, m), the local indices of n nodes' m components.
            stiffness: (n, m, m), k, each node's symmetric spring.
            anchor: (n, m), a, where each spring is unstretched.
        """
        dofs = np.asarray(dofs, dtype=np.int32)
        had, has = self.springs is not None, self.comm.allreduce(bool(dofs.size), op=MPI.LOR)
        if had or has:
            self.version += 1
        self.springs = (dofs, np.asarray(stiffness, dtype=float),
                        np.asarray(anchor, dtype=float)) if has else None

    def set_couplings(self, targets: np.ndarray, sources: np.ndarray,
                      coefficients: np.ndarray) -> None:
        """Rows that take a multiple of others: R_t + c R_s, K_t + c K_s.

        Replaces the previous ones. Collective: every rank's tangent is rebuilt if any rank
        has (or had) couplings.

        Args:
            targets: the local indices t of the rows changed (owned dofs).
            sources: the local indices s of the rows added to them (owned dofs whose
                residual is a reaction: Dirichlet dofs, read before their rows are set).
            coefficients: c for each pair.
        """
        targets = np.asarray(targets, dtype=np.int32)
        had = self.couplings is not None
        has = self.comm.allreduce(bool(targets.size), op=MPI.LOR)
        if had or has:
            self.version += 1
        self.couplings = (targets, np.asarray(sources, dtype=np.int32),
                          np.asarray(coefficients, dtype=float)) if has else None

    def add_to_residual(self, u: np.ndarray, b: np.ndarray) -> None:
        """b_t += c b_s, b −= F, b += k (u − a): on the local arrays, after the assembly.

        Before the Dirichlet rows are set: b_s is still the reaction there.

        Args:
            u: the local array of the unknown.
            b: the local array of the residual R, changed in place.
        """
        if self.couplings is not None:
            targets, sources, c = self.couplings
            b[targets] += c * b[sources]
        if self.load is not None:
            dofs, values = self.load
            b[dofs] -= values
        if self.springs is not None:
            dofs, k, anchor = self.springs
            b[dofs] += np.einsum("nij,nj->ni", k, u[dofs] - anchor)

    def couple_rows(self, A: PETSc.Mat) -> None:
        """K_t += c K_s for each coupling (collective; nothing without).

        A must still have the source rows (assembled without their Dirichlet rows); the
        target's pattern holds the source's (two components of one node).

        Args:
            A: the assembled tangent K, changed in place.
        """
        if self.couplings is None:
            return
        targets, sources, c = self.couplings
        first = A.getOwnershipRange()[0]  # owned local dof i is global row first + i
        rows = [A.getRow(first + int(s)) for s in sources]
        for t, (cols, values), ct in zip(targets, rows, c, strict=True):
            A.setValues([first + int(t)], cols, ct * values, addv=PETSc.InsertMode.ADD_VALUES)
        A.assemble()

    def add_to_tangent(self, A: PETSc.Mat) -> None:
        """A += each spring's stiffness (collective, as A.assemble(); nothing without).

        Args:
            A: the assembled tangent K, changed in place.
        """
        if self.springs is None:
            return
        dofs, k, _ = self.springs
        bs = self.V.dofmap.index_map_bs
        lg = self.V.dofmap.index_map.local_to_global
        for node, block in zip(dofs, k, strict=True):
            blocks = lg(np.asarray(node // bs, dtype=np.int32))
            rows = (blocks * bs + node % bs).astype(PETSc.IntType)
            A.setValues(rows, rows, block, addv=PETSc.InsertMode.ADD_VALUES)
        A.assemble()
