"""Frictionless unilateral contact by the course's active-set algorithm.

On the candidate surface S_C (a facet tag; flat, with outward normal n = ±e_k) against a
rigid obstacle at gap γ(x) along n, the conditions are

    u_n − γ ≤ 0,   T_n ≤ 0,   (u_n − γ) T_n = 0,   T − T_n n = 0.

Iteration k solves the equilibrium with u_n = γ on the active part S_C^(k) and T = 0 on the
rest, then updates the set node by node, exactly as the course says:

* an active node with T_n > 0 (tension) leaves;
* an inactive node with u_n − γ > 0 (penetration) joins;

and stops when the set does not change. Two formulations of each iteration:

* ``elimination``: the active normal displacements are Dirichlet rows; the contact forces
  are the residual's reactions there. Symmetric positive definite, no extra unknowns.
* ``multiplier``: the course's saddle point [K −A; −Aᵀ 0]{U; T} = {F; −γ} with the
  multiplier (the contact pressure) on a facet submesh of S_C, coupled by a vertex
  quadrature so that the constraint is nodal, as in the elimination.

The nodes are the displacement dofs on S_C: vertices for P1, vertices and edge midpoints for
P2 (the multiplier formulation is written for P1). Non-linear materials: each active-set
iteration is a full Newton solve (warm-started), so the set is only updated from
equilibrium states, where the course's rules are meaningful.
The active set is kept as DOLFINx meshtags: vertices (`active_vertices`) and the facets of
S_C whose vertices are all active (`active_facets`), ready to write out.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import ufl
from dolfinx import fem, la, mesh
from dolfinx.fem import petsc
from mpi4py import MPI
from petsc4py import PETSc

from fenics_nl.errors import SolveError
from fenics_nl.newton import NewtonSolver, WorkCounts

log = logging.getLogger(__name__)

FORMULATIONS = ("elimination", "multiplier")


class ContactError(SolveError):
    """The active-set iteration cycled or did not settle within its limit."""


@dataclass
class ContactResult:
    """Outcome of one contact solve."""

    iterations: int
    active_sizes: list[int]  # global number of active nodes after each iteration
    newton_iterations: int
    linear_solves: int
    factorizations: int
    wall_time: float
    force: float = 0.0  # total normal contact force, −Σ T_n (positive in compression)
    history: list[dict] = field(default_factory=list)
    work: WorkCounts = field(default_factory=WorkCounts)  # summed over the inner solves
    residual_norms: list[float] = field(default_factory=list)  # of the last inner solve


class ActiveSetContact:
    """Active-set contact solver on a flat candidate surface with normal ±e_axis.

    With ``newton_options={"reuse_factorization": True}`` (elimination), an iteration
    that changes at most SMALL_CHANGE nodes keeps the last factorization as a CG
    preconditioner: the new matrix differs by a few rows and columns, so CG needs about
    two iterations per changed node.
    """

    SMALL_CHANGE = 8

    def __init__(
        self,
        residual: ufl.Form,
        u: fem.Function,
        bcs: Sequence[fem.DirichletBC],
        facets: np.ndarray,
        gap: Callable[[np.ndarray], np.ndarray],
        *,
        normal_axis: int,
        normal_sign: int = 1,
        formulation: str = "elimination",
        initial: str = "all",
        max_iterations: int = 50,
        newton_options: dict | None = None,
        prefix: str = "contact_",
    ):
        if formulation not in FORMULATIONS:
            raise ValueError(f"formulation must be one of {', '.join(FORMULATIONS)}, "
                             f"got {formulation!r}")
        if initial not in ("all", "none", "penetrating"):
            raise ValueError(f"initial must be all, none or penetrating, got {initial!r}")
        V = u.function_space
        if V.element.basix_element.degree != 1 and formulation == "multiplier":
            raise ValueError("the multiplier formulation needs a P1 displacement space")
        self.u, self.bcs, self.gap_fn = u, list(bcs), gap
        self.axis, self.sign = normal_axis, int(np.sign(normal_sign))
        self.formulation, self.max_iterations = formulation, max_iterations
        self.mesh = V.mesh
        self.comm = self.mesh.comm
        fdim = self.mesh.topology.dim - 1
        self.facets = np.asarray(facets, dtype=np.int32)
        if self.comm.allreduce(len(self.facets)) == 0:
            raise ValueError("the contact surface has no facets (missing or wrong tag?)")
        if V.dofmap.index_map_bs == 1:  # one component (a bar): no sub-space to extract
            self.Vn, self._Vsub = V, V
            self.dofs_V = self.dofs_n = fem.locate_dofs_topological(V, fdim, self.facets)
        else:
            self._Vsub = V.sub(self.axis)
            self.Vn, _ = self._Vsub.collapse()
            dofs = fem.locate_dofs_topological((self._Vsub, self.Vn), fdim, self.facets)
            self.dofs_V, self.dofs_n = dofs[0], dofs[1]
        self.x = self.Vn.tabulate_dof_coordinates()[self.dofs_n]
        self.gamma = np.asarray(gap(self.x.T), dtype=float)  # γ at the S_C nodes
        self.g = fem.Function(self.Vn)  # prescribed u_axis = sign·γ on active nodes
        self.g.x.array[self.dofs_n] = self.sign * self.gamma
        self._flags = la.vector(self.Vn.dofmap.index_map)  # 1.0 = active, synced to ghosts
        self._R = fem.form(residual)
        self._reaction = petsc.create_vector(V)
        self._vertex_of_dof = _vertex_of_dof(self.Vn)
        self.active = self._initial_set(initial)
        opts = {"method": "full", "rtol": 1e-10, "max_it": 50}
        if formulation == "elimination":
            opts["reuse_factorization"] = True
        opts.update(newton_options or {})
        prefix += formulation[:4] + "_"  # each formulation reads its own PETSc options
        if formulation == "elimination":
            self.solver = NewtonSolver(residual, u, self._bcs(), prefix=prefix, **opts)
        else:
            from fenics_nl.contact_multiplier import MultiplierSystem

            self.solver = MultiplierSystem(residual, u, self.bcs, self, prefix=prefix, **opts)

    # -- set bookkeeping ---------------------------------------------------------------

    def _sync(self, local: np.ndarray) -> np.ndarray:
        """Owners' values of a nodal flag array pushed to the ghosts."""
        self._flags.array[:] = 0.0
        self._flags.array[self.dofs_n] = local
        self._flags.scatter_forward()
        return self._flags.array[self.dofs_n] > 0.5

    def _initial_set(self, initial: str) -> np.ndarray:
        if initial == "all":  # the course's S_C^(0) = S_C
            return np.ones(len(self.dofs_n), dtype=bool)
        if initial == "none":
            return np.zeros(len(self.dofs_n), dtype=bool)
        u_n = self.sign * self.u.x.array[self.dofs_V]
        return self._sync(u_n - self.gamma >= 0)

    def _bcs(self) -> list[fem.DirichletBC]:
        a = self.active
        if self._Vsub is self.Vn:
            bc = fem.dirichletbc(self.g, self.dofs_V[a])
        else:
            bc = fem.dirichletbc(self.g, [self.dofs_V[a], self.dofs_n[a]], self._Vsub)
        return [*self.bcs, bc]

    def _owned(self) -> np.ndarray:
        """Mask of the S_C nodes this rank owns (counts and sums use only these)."""
        return self.dofs_n < self.Vn.dofmap.index_map.size_local

    owned = property(_owned, doc="Mask of the S_C nodes this rank owns.")

    def nodal_field(self, values: np.ndarray, name: str) -> fem.Function:
        """A function on the normal component's space: `values` at the S_C nodes, 0 elsewhere.

        For writing out the contact pressure or the active set.
        """
        f = fem.Function(self.Vn, name=name)
        f.x.array[self.dofs_n] = values
        f.x.scatter_forward()
        return f

    # -- contact quantities ------------------------------------------------------------

    def normal_forces(self) -> np.ndarray:
        """Nodal normal contact forces T_n = n·(f_int − f_ext) at the S_C nodes.

        The residual without any condition on S_C is the force the obstacle exerts there.
        Negative in compression.
        """
        if self.formulation == "multiplier":
            return self.solver.normal_forces()
        b = self._reaction
        with b.localForm() as loc:
            loc.set(0.0)
        petsc.assemble_vector(b, self._R)
        b.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
        b.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        with b.localForm() as loc:
            return self.sign * loc.array_r[self.dofs_V].copy()

    def nodal_areas(self, weight=1.0) -> np.ndarray:
        """Lumped areas m_j = ∫_{S_C} φ_j w ds at the S_C nodes (w = 2πr if axisymmetric)."""
        if not hasattr(self, "_areas"):
            V = self.u.function_space
            fdim = self.mesh.topology.dim - 1
            tags = mesh.meshtags(self.mesh, fdim, np.sort(self.facets),
                                 np.ones(len(self.facets), dtype=np.int32))
            ds = ufl.Measure("ds", domain=self.mesh, subdomain_data=tags)(1)
            v = ufl.TestFunction(V)
            b = petsc.assemble_vector(fem.form(v[self.axis] * weight * ds))
            b.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
            b.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
            with b.localForm() as loc:
                self._areas = loc.array_r[self.dofs_V].copy()
        return self._areas

    def pressure(self, weight=1.0) -> np.ndarray:
        """Nodal contact pressure p_j = −T_n,j / m_j (positive in compression)."""
        return -self.normal_forces() / self.nodal_areas(weight)

    def normal_gap(self) -> np.ndarray:
        """u_n − γ at the S_C nodes (positive = penetration)."""
        return self.sign * self.u.x.array[self.dofs_V] - self.gamma

    def total_force(self, T_n: np.ndarray | None = None) -> float:
        """−Σ T_n over owned S_C nodes, summed over ranks (positive in compression)."""
        T_n = self.normal_forces() if T_n is None else T_n
        return 0.0 - self.comm.allreduce(float(np.sum(T_n[self._owned()])))  # no −0.0

    def set_gap(self, gap: Callable[[np.ndarray], np.ndarray]) -> None:
        """New obstacle position (a load step); the active set is kept as a warm start."""
        self.gap_fn = gap
        self.gamma = np.asarray(gap(self.x.T), dtype=float)
        self.g.x.array[self.dofs_n] = self.sign * self.gamma

    # -- the loop ----------------------------------------------------------------------

    def solve(self) -> ContactResult:
        """Run the active-set iteration to a fixed set; raise ContactError if it cannot."""
        t0 = time.perf_counter()
        seen = set()
        res = ContactResult(0, [], 0, 0, 0, 0.0)
        owned = self._owned()
        changes = None  # nodes that changed since the last solve (None: unknown, many)
        for k in range(1, self.max_iterations + 1):
            if self.formulation == "elimination":
                small = changes is not None and changes <= self.SMALL_CHANGE
                self.solver.set_bcs(self._bcs(), small_change=small)
            else:
                self.solver.set_active(self.active)
            nr = self.solver.solve()
            res.newton_iterations += nr.iterations
            res.linear_solves += nr.work.linear_solves
            res.factorizations += nr.work.factorizations
            res.work.add(nr.work)
            res.residual_norms = nr.residual_norms
            T_n, d = self.normal_forces(), self.normal_gap()
            scale_T = self.comm.allreduce(float(np.max(np.abs(T_n), initial=0.0)), op=MPI.MAX)
            # the problem's own displacement scale: the obstacle's gap, or the motion itself
            scale_u = self.comm.allreduce(max(float(np.max(np.abs(self.gamma), initial=0.0)),
                                              float(np.max(np.abs(self.u.x.array), initial=0.0))),
                                          op=MPI.MAX)
            leave = self.active & (T_n > 1e-10 * scale_T)
            join = ~self.active & (d > 1e-10 * scale_u)
            new = self._sync((self.active & ~leave) | join)
            changes = self.comm.allreduce(int(np.sum((new != self.active)[owned])))
            n_active = self.comm.allreduce(int(np.sum(new[owned])))
            res.iterations, res.active_sizes = k, [*res.active_sizes, n_active]
            res.history.append({"active": n_active, "left": self.comm.allreduce(
                int(np.sum(leave[owned]))), "joined": self.comm.allreduce(int(np.sum(join[owned]))),
                "newton_iterations": nr.iterations})
            log.info("active set iteration %d: %d active, %d changes", k, n_active, changes)
            if changes == 0:
                res.force = self.total_force(T_n)
                res.wall_time = time.perf_counter() - t0
                return res
            key = self._fingerprint(new)
            if key in seen:
                raise ContactError(f"active set cycles (iteration {k}, {n_active} active nodes)")
            seen.add(key)
            self.active = new
        raise ContactError(f"active set did not settle in {self.max_iterations} iterations")

    def _fingerprint(self, mask: np.ndarray) -> tuple[int, int]:
        """Global signature of a set: its size and the sum of its nodes' global indices."""
        im = self.Vn.dofmap.index_map
        gidx = im.local_to_global(self.dofs_n[mask & self._owned()].astype(np.int32))
        total = int(np.sum(gidx, dtype=np.int64))
        return self.comm.allreduce(len(gidx)), self.comm.allreduce(total)

    # -- meshtags ----------------------------------------------------------------------

    def active_vertices(self) -> mesh.MeshTags:
        """Vertex meshtags of the active nodes (value 1)."""
        verts = self._vertex_of_dof[self.dofs_n[self.active]]
        verts = verts[verts >= 0]
        order = np.argsort(verts)
        return mesh.meshtags(self.mesh, 0, verts[order].astype(np.int32),
                             np.ones(len(verts), dtype=np.int32))

    def active_facets(self) -> mesh.MeshTags:
        """Facet meshtags of S_C: 1 where all the facet's vertices are active, else 0."""
        fdim = self.mesh.topology.dim - 1
        self.mesh.topology.create_connectivity(fdim, 0)
        f2v = self.mesh.topology.connectivity(fdim, 0)
        active_v = np.zeros(self.mesh.topology.index_map(0).size_local
                            + self.mesh.topology.index_map(0).num_ghosts, dtype=bool)
        verts = self._vertex_of_dof[self.dofs_n[self.active]]
        active_v[verts[verts >= 0]] = True
        values = np.array([active_v[f2v.links(f)].all() for f in self.facets], dtype=np.int32)
        order = np.argsort(self.facets)
        return mesh.meshtags(self.mesh, fdim, self.facets[order], values[order])


def _vertex_of_dof(V: fem.FunctionSpace) -> np.ndarray:
    """Mesh vertex of each dof of a scalar Lagrange space, −1 for dofs not at a vertex.

    A Lagrange cell numbers its vertex dofs first, in the order of the cell's vertices.
    """
    topo = V.mesh.topology
    tdim = topo.dim
    topo.create_connectivity(tdim, 0)
    c2v = topo.connectivity(tdim, 0).array.reshape(-1, tdim + 1)
    dofs = V.dofmap.list[:, : tdim + 1]
    out = np.full(V.dofmap.index_map.size_local + V.dofmap.index_map.num_ghosts, -1,
                  dtype=np.int32)
    out[dofs.ravel()] = c2v[: dofs.shape[0]].ravel()
    return out
