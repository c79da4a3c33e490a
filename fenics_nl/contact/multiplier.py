"""The course's saddle-point form of one active-set iteration, on a facet submesh.

Unknowns: u, and the multiplier λ (on a submesh of S_C, of the displacement's degree)
standing for the normal contact traction. The equations, for all (v, μ):

    R(u; v) − ∫_{S_C} λ v_n ds = 0
    −∫_{S_C} [χ (u_n − γ) − (1 − χ) λ / k] μ ds = 0

with χ the nodal indicator of the active set (a function on the submesh) and a *nodal*
quadrature rule on S_C: integrals become nodal sums, so an active node gets exactly
u_n = γ and an inactive one exactly λ = 0, the same discrete problem as the elimination.
P1: the vertex rule; P2 (2D and axisymmetric): Gauss–Lobatto's 3 points, the P2 nodes of
an edge, weights h/6, 2h/3, h/6. A P2 triangle (3D) has no nodal rule with positive
weights, so 3D P2 is refused. `u` may be a mixed (u, p) unknown: `u[axis]` is its
displacement's component.
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

from fenics_nl.contact.surface import nodal_quadrature
from fenics_nl.solvers.convergence import ConvergenceTest
from fenics_nl.solvers.newton import ConvergenceError
from fenics_nl.solvers.result import SolveResult
from fenics_nl.solvers.snes import (
    EventCounter,
    all_event_names,
    petsc_work,
    solver_options,
)

__all__ = ["MultiplierSystem", "dofs_at"]


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
        degree = surface.Vn.element.basix_element.degree
        if degree not in (1, 2) or (degree == 2 and fdim == 2):
            raise ValueError("the multiplier formulation takes P1 displacements, or P2 in 2D "
                             "and axisymmetric models (no nodal rule with positive weights "
                             "on a P2 triangle): use the elimination")
        rule = nodal_quadrature(degree, fdim)
        facets = np.sort(surface.facets)
        sub, emap, _, _ = mesh.create_submesh(msh, fdim, facets)
        Q = fem.functionspace(sub, ("Lagrange", degree))
        self.lam = fem.Function(Q, name="multiplier")
        self.chi = fem.Function(Q, name="active")
        self.gamma = fem.Function(Q, name="gap")
        self.q_of_node = dofs_at(Q, surface.x)  # S_C node i (the surface's order) -> Q dof
        tags = mesh.meshtags(msh, fdim, facets, np.ones(len(facets), dtype=np.int32))
        ds = ufl.Measure("ds", domain=msh, subdomain_data=tags, metadata=rule)(1)
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
        with solver_options(prefix, opts) as passed:
            self.problem = petsc.NonlinearProblem(
                [F_u, F_l], [u, self.lam], bcs=list(bcs), kind="mpi", entity_maps=[emap],
                petsc_options_prefix=prefix, petsc_options=passed)
        self.problem.solver.setConvergenceHistory(reset=True)
        ConvergenceTest(rtol, atol, max_it).attach(self.problem.solver, force_scale)
        self.counter = EventCounter(all_event_names())
        self.update_gap()

    def update_gap(self) -> None:
        """Copy the surface's nodal γ into the submesh function."""
        self.gamma.x.array[self.q_of_node] = self.surface.gamma
        self.gamma.x.scatter_forward()

    def set_active(self, active: np.ndarray, changes: int | None = None) -> None:
        """χ = 1 on the active S_C nodes, 0 elsewhere (and the current γ).

        Args:
            active: one flag per node of S_C: where the constraint u_n = γ holds.
            changes: unused (the saddle point is refactorized by SNES each solve).
        """
        self.chi.x.array[:] = 0.0
        self.chi.x.array[self.q_of_node] = active.astype(float)
        self.chi.x.scatter_forward()
        self.update_gap()

    def solve(self) -> SolveResult:
        """One SNES solve of the block system for the current active set.

        Returns:
            SNES's SolveResult.

        Raises:
            ConvergenceError: SNES did not converge.
        """
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
        """Nodal normal contact forces w_j λ_j at the S_C nodes (the surface's ordering).

        Returns:
            T_n at each node of S_C (negative in compression).
        """
        with self.weights.localForm() as w:
            return w.array_r[self.q_of_node] * self.lam.x.array[self.q_of_node]


def dofs_at(Q: fem.FunctionSpace, points: np.ndarray) -> np.ndarray:
    """The local dof of the scalar space Q at each of `points` (n x 3), checked.

    Every S_C node lies on a facet of the submesh on its own rank, so its dof is local.

    Args:
        Q: a scalar space on the facet submesh of S_C.
        points: the S_C nodes' coordinates (n × 3).

    Returns:
        Q's local dof at each point.

    Raises:
        RuntimeError: a point is not a dof of Q on this rank.
    """
    if len(points) == 0:
        return np.zeros(0, dtype=np.int32)
    from scipy.spatial import cKDTree

    xq = Q.tabulate_dof_coordinates()
    distance, index = cKDTree(xq).query(points)
    scale = float(np.ptp(xq, axis=0).max()) if len(xq) > 1 else 1.0
    if np.any(distance > 1e-9 * (scale or 1.0)):
        raise RuntimeError("an S_C node has no multiplier dof at its place")
    return index.astype(np.int32)
