"""A pair's active set with the relative condition eliminated: no multiplier, no saddle point.

The course's first formulation, between two bodies. On an active slave node s (normal n,
projected at ξ on the master facet of nodes m_j), the closed gap

    g_s = γ_s + n · (u_s − Σ_j N_j(ξ) u_{m_j}) = 0

gives one component of the slave's displacement, k (the one of largest |n_k| among those
no support holds), in terms of the others: a multi-point constraint u = T ũ + c. The
equilibrium is then solved on the free dofs only, Tᵀ K T dũ = Tᵀ R (the eliminated rows
an identity): symmetric positive definite as K, the size of the displacement, where the
multipliers' saddle point is indefinite and larger. The contact force is the residual's
reaction at the eliminated dof, R_{s,k}(u) = n_k λ_s (R = Bᵀλ there, the only row of B
on that dof). The active set's rules and loop are `PairContact`'s; each set is a Newton
solve of the eliminated system (one iteration for a linear material).

A slave node is no master node (`ContactPair` refuses surfaces that share nodes), so
the eliminated dofs depend on free ones only.
"""

from __future__ import annotations

import numpy as np
from dolfinx.fem import petsc
from petsc4py import PETSc

from fenics_nl.contact.condensed import every_rank
from fenics_nl.contact.pair import PREFIX, PairContact
from fenics_nl.errors import SolveError, SupportError
from fenics_nl.solvers.linear_solver import create_ksp, factorized_counting_null_pivots
from fenics_nl.solvers.result import WorkCounts

__all__ = ["EliminatedPair"]


class EliminatedPair(PairContact):
    """The active set on a pair, each set's gaps eliminated (a multi-point constraint).

    Args: as `PairContact` (without `linear`: each set is factorized).
    """

    def __init__(self, residual, u, bcs, pair, **options):
        if options.get("linear"):
            raise ValueError("EliminatedPair factorizes each set's system: no linear=True")
        super().__init__(residual, u, bcs, pair, **options)
        n_owned = u.function_space.dofmap.index_map.size_local * pair.bs
        self.start = u.x.petsc_vec.getOwnershipRange()[0]
        self.n_dofs = (self.start, n_owned, u.x.petsc_vec.getSize())
        held = np.zeros(n_owned, dtype=bool)
        held[self.held.indices - self.start] = True
        # which component of each owned slave node is eliminated: the largest |n_k| free
        local = self.pair.slave * pair.bs  # local dof of the x component
        free = ~np.stack([held[local + d] for d in range(pair.gdim)], axis=1)
        self.component = np.argmax(np.abs(pair.normal) * free, axis=1)
        stuck = int((~free[np.arange(len(local)), self.component]).sum())
        if pair.comm.allreduce(stuck):  # every rank raises, or none
            raise ValueError("a slave node held in both components cannot take a gap")

    def equilibrium(self, active: np.ndarray, work: WorkCounts | None = None) -> int:
        """The equilibrium with g_s = 0 on the `active` slave nodes, eliminated.

        Returns:
            Newton's iterations; `lam` holds each owned slave node's force (0 if inactive).
        """
        work = work if work is not None else WorkCounts()
        self.active = np.asarray(active, dtype=bool).copy()
        which = np.flatnonzero(self.active)
        T = self._transform(which)
        eliminated = self.bs_dof(which)
        u = self.u
        for bc in self.bcs:
            bc.set(u.x.array)
        for it in range(1, self.max_it + 1):
            self._close(which)  # the gaps exactly closed: u on the constraint
            R = self._unbalanced(work, None)
            r = T.createVecRight()
            T.multTranspose(R, r)  # Tᵀ R: the equations of the free dofs
            r.array[eliminated - self.start] = 0.0
            norm = r.norm()
            if it == 1:
                reference = self.scale if self.scale is not None else max(norm, 1e-300)
            if it > 1 and norm <= self.rel * reference:
                break
            K = petsc.assemble_matrix(self.J, self.bcs)
            K.assemble()
            work.tangent_assemblies += 1
            Kt = K.ptap(T)
            Kt.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
            for dof in eliminated:  # their rows and columns are zero: an identity there
                Kt.setValue(int(dof), int(dof), 1.0, addv=PETSc.InsertMode.INSERT_VALUES)
            Kt.assemble()
            dz = r.duplicate()
            ksp = create_ksp(Kt, "lu", prefix=PREFIX)
            free = factorized_counting_null_pivots(ksp)
            if free:
                raise SupportError(f"contact pair (eliminated): {free} motion(s) free: a "
                                   "body that neither its supports nor the contact in force "
                                   "hold")
            ksp.solve(r, dz)
            work.factorizations += 1
            work.linear_solves += 1
            if ksp.getConvergedReason() < 0:
                raise SolveError(f"contact pair (eliminated): the solve failed "
                                 f"({ksp.getConvergedReason()})")
            du = R.duplicate()
            T.mult(dz, du)
            u.x.petsc_vec.axpy(-1.0, du)
            u.x.scatter_forward()
        else:
            raise SolveError(f"contact pair (eliminated): Newton did not converge in "
                             f"{self.max_it} iterations (|Tᵀ R| = {norm:.2e})")
        self._iterations = it - 1
        # the reactions at the eliminated dofs (no support holds them: R has their rows),
        # R_{s,k} = n_k λ_s, from the converged step's residual
        self.lam[:] = 0.0
        n_k = self.pair.normal[which, self.component[which]]
        self.lam[which] = R.array[eliminated - self.start] / n_k
        return self._iterations

    def bs_dof(self, which: np.ndarray) -> np.ndarray:
        """The global dof eliminated at each owned slave node of `which`."""
        return self.pair.bs * self.pair.slave_global[which] + self.component[which]

    def _rows(self, which):
        """Each eliminated dof's row of the constraint: (its dof, [(dof, coefficient)]).

        u_{s,k} = −(γ_s + Σ_{i≠k} n_i u_{s,i} − Σ_j N_j Σ_i n_i u_{m_j,i}) / n_k: the
        coefficients of the other dofs (the constant is `_close`'s).
        """
        pair, bs = self.pair, self.pair.bs
        out = []
        for i in which:
            n, k = pair.normal[i], self.component[i]
            g = pair.gdim
            terms = [(bs * pair.slave_global[i] + d, -n[d] / n[k]) for d in range(g) if d != k]
            for j, w in enumerate(pair.weights[i]):
                terms += [(bs * pair.master_nodes[i, j] + d, w * n[d] / n[k])
                          for d in range(g)]
            out.append((bs * pair.slave_global[i] + k, terms))
        return out

    def _transform(self, which) -> PETSc.Mat:
        """T: the identity on the free dofs, the constraint's row on each eliminated one.

        The increments' transform: the held dofs' columns are left out (their increment is
        0), so that Tᵀ K T keeps their identity rows. Built row by row as CSR arrays.
        """
        start, n_owned, N = self.n_dofs
        held = set(every_rank(self.pair.comm, self.held.indices).tolist())
        rows = {dof - start: [(col, c) for col, c in terms if col not in held]
                for dof, terms in self._rows(which)}
        indptr, indices, values = [0], [], []
        for r in range(n_owned):
            entries = sorted(rows.get(r, [(start + r, 1.0)]))
            indices += [col for col, _ in entries]
            values += [c for _, c in entries]
            indptr.append(len(indices))
        T = PETSc.Mat().createAIJ(((n_owned, N), (n_owned, N)), csr=(
            np.array(indptr, dtype=PETSc.IntType), np.array(indices, dtype=PETSc.IntType),
            np.array(values)), comm=self.pair.comm)
        T.assemble()
        return T

    def _close(self, which) -> None:
        """The eliminated dofs set so that the active gaps are exactly 0."""
        u = self.u
        if self.pair.comm.allreduce(len(which)) == 0:
            return
        g = self.pair.gaps(u)  # γ + B u at every owned slave node
        n_k = self.pair.normal[which, self.component[which]]
        dofs = self.bs_dof(which) - self.start
        # g is linear in u_{s,k} with slope n_k: the correction that zeroes it
        u.x.petsc_vec.array[dofs] -= g[which] / n_k
        u.x.scatter_forward()
