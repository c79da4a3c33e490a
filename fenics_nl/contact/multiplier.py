"""The course's saddle-point form of one active-set iteration, on a facet submesh.

Unknowns: u, and the multiplier λ (P1 on a submesh of S_C) standing for the normal contact
traction. The equations, for all (v, μ):

    R(u; v) − ∫_{S_C} λ v_n ds = 0
    −∫_{S_C} [χ (u_n − γ) − (1 − χ) λ / k] μ ds = 0

with χ the nodal indicator of the active set (a P1 function on the submesh) and a *vertex*
quadrature rule on S_C: integrals become nodal sums, so an active node gets exactly
u_n = γ and an inactive one exactly λ = 0, the same discrete problem as the elimination.
On active nodes the tangent is the course's [K −A; −Aᵀ 0]. `k` only scales the inactive
rows. Assembled as a mixed-dimensional block system (`entity_maps`) and solved by SNES with
MUMPS LU. In the axisymmetric model the 2πr weight is left out of these two integrals
(so that the node on the axis keeps a non-zero weight); λ is then 2πr times the traction.
"""

from __future__ import annotations

import time

import numpy as np
import ufl
from dolfinx import fem, mesh
from dolfinx.fem import petsc
from petsc4py import PETSc

from fenics_nl.contact.surface import vertex_of_dof
from fenics_nl.solvers.newton import ConvergenceError
from fenics_nl.solvers.result import SolveResult
from fenics_nl.solvers.snes import (
    EventCounter,
    all_event_names,
    petsc_work,
    scale_absolute_tolerance,
    unless_set,
)


class MultiplierSystem:
    """Block (u, λ) Newton solve for a given active set; used by ActiveSetContact."""

    def __init__(self, residual, u, bcs, surface, *, prefix="contact_", method="full",
                 rtol=1e-10, atol=1e-10, force_scale=None, max_it=50, line_search=False,
                 stiffness_scale=1.0):
        if method != "full":
            raise ValueError("the multiplier formulation runs full Newton (SNES) only")
        self.u, self.surface = u, surface
        msh = u.function_space.mesh
        fdim = msh.topology.dim - 1
        if fdim == 0:
            raise ValueError("the multiplier formulation needs a 2D or 3D mesh (use elimination)")
        facets = np.sort(surface.facets)
        sub, emap, vmap, _ = mesh.create_submesh(msh, fdim, facets)
        Q = fem.functionspace(sub, ("Lagrange", 1))
        self.lam = fem.Function(Q, name="multiplier")
        self.chi = fem.Function(Q, name="active")
        self.gamma = fem.Function(Q, name="gap")
        # S_C node i (the surface's ordering) <-> Q dof, through the parent mesh vertices
        q_parent_vertex = vmap.sub_topology_to_topology(vertex_of_dof(Q), inverse=False)
        parent_vertex_to_q = {int(pv): q for q, pv in enumerate(q_parent_vertex)}
        self.q_of_node = np.array([parent_vertex_to_q[int(vv)] for vv in surface.vertices],
                                  dtype=np.int32)
        tags = mesh.meshtags(msh, fdim, facets, np.ones(len(facets), dtype=np.int32))
        ds = ufl.Measure("ds", domain=msh, subdomain_data=tags,
                         metadata={"quadrature_rule": "vertex", "quadrature_degree": 1})(1)
        v = residual.arguments()[0]
        mu = ufl.TestFunction(Q)
        s, k = surface.sign, stiffness_scale
        u_n, v_n = s * u[surface.axis], s * v[surface.axis]
        F_u = residual - self.lam * v_n * ds
        F_l = -(self.chi * (u_n - self.gamma) - (1 - self.chi) * self.lam / k) * mu * ds
        self.weights = petsc.assemble_vector(fem.form(mu * ds, entity_maps=[emap]))
        self.weights.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
        self.weights.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        opts = {"snes_type": "newtonls", "snes_rtol": rtol,
                "snes_linesearch_type": "bt" if line_search else "basic",
                "snes_stol": 0.0, "snes_max_it": max_it,
                "ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
        self.problem = petsc.NonlinearProblem(
            [F_u, F_l], [u, self.lam], bcs=list(bcs), kind="mpi", entity_maps=[emap],
            petsc_options_prefix=prefix, petsc_options=unless_set(prefix, opts))
        self.problem.solver.setConvergenceHistory(reset=True)
        scale_absolute_tolerance(self.problem.solver, atol, force_scale)
        self.counter = EventCounter(all_event_names())
        self.update_gap()

    def update_gap(self) -> None:
        """Copy the surface's nodal γ into the submesh function."""
        self.gamma.x.array[self.q_of_node] = self.surface.gamma
        self.gamma.x.scatter_forward()

    def set_active(self, active: np.ndarray, changes: int | None = None) -> None:
        """χ = 1 on the active S_C nodes, 0 elsewhere (and the current γ)."""
        self.chi.x.array[:] = 0.0
        self.chi.x.array[self.q_of_node] = active.astype(float)
        self.chi.x.scatter_forward()
        self.update_gap()

    def solve(self) -> SolveResult:
        """One SNES solve of the block system for the current active set."""
        t0 = time.perf_counter()
        self.counter.start()
        self.problem.solve()
        snes = self.problem.solver
        norms = [float(r) for r in snes.getConvergenceHistory()[0]]
        reason = snes.getConvergedReason()
        result = SolveResult(reason > 0, f"SNES reason {reason}", snes.getIterationNumber(),
                              norms, petsc_work(self.counter), time.perf_counter() - t0)
        if reason <= 0:
            raise ConvergenceError(f"multiplier system: SNES did not converge (reason {reason})",
                                   result)
        return result

    def normal_forces(self) -> np.ndarray:
        """Nodal normal contact forces w_j λ_j at the S_C nodes (the surface's ordering)."""
        with self.weights.localForm() as w:
            return w.array_r[self.q_of_node] * self.lam.x.array[self.q_of_node]
