"""Contact between two deformable bodies: the course's active set on a slave–master pair.

The *slave* surface's nodes are projected on the *master* surface's facets (2D: segments,
3D: triangles; the closest point, its shape functions N_j and the master's outward normal
n there; small sliding: the projection is made once, in the reference configuration;
finite sliding, 2D and frictionless: made again where the bodies are after every solve,
`ContactPair.follow`). At a slave node s projected on the master facet with nodes m_j,
the gap is

    g_s(u) = γ_s + (u_s − Σ_j N_j u_{m_j}) · n ≥ 0,     γ_s = (x_s − x_m) · n,

a linear condition B_s u + γ_s ≥ 0: B has one row per slave node, +n on the slave node's
components, −N_j n on the master nodes'. Each active-set iteration solves the
equilibrium with the relative normal displacement prescribed on the active nodes and no
traction elsewhere, by Lagrange multipliers (the course's saddle point, with A coupling
both bodies):

    [ K   −B_Aᵀ ] [u]   [f   ]
    [−B_A   0   ] [λ] = [γ_A ],

λ_s ≥ 0 the normal force that node s and the master exchange (compression), and then
updates the set by the course's two rules: an active node in tension (λ_s < 0) leaves, an
inactive node that penetrates (g_s < 0) joins; until the set repeats. With a non-linear
residual each iteration is a Newton solve of the same saddle point (K the tangent).

The master's facets are gathered on every rank (a surface is small against the body), so
that a slave node finds its facet wherever its nodes are owned; B and the saddle point are
PETSc matrices in the unknowns' global numbering, solved by MUMPS.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc
from mpi4py import MPI
from petsc4py import PETSc

from fenics_nl.contact.condensed import PREFIX, CondensedSaddle, every_rank
from fenics_nl.errors import SolveError, SupportError
from fenics_nl.solvers.linear_solver import create_ksp, factorized_counting_null_pivots
from fenics_nl.solvers.result import SolveResult, WorkCounts

__all__ = ["ArchardWear", "ContactPair", "FrictionalPair", "PairContact", "PairState"]

log = logging.getLogger(__name__)


class ContactPair:
    """Slave nodes on one body's facets against the master facets of the other (P1).

    2D: node to segment (plane strain, plane stress, axisymmetric); 3D: node to triangle.
    Each slave node has its master's normal n and a tangent basis (2D: t = (−n_y, n_x);
    3D: t1 the coordinate axis farthest from n made orthogonal to it, t2 = n × t1;
    `FrictionalPair` takes an axis its supports hold as t1 instead, not quite orthogonal
    to a facet's tilted normal: its row binds held dofs only).

    Args:
        V: the displacement space (vector, P1; 2D: plane strain, plane stress or
            axisymmetric; or 3D).
        slave_facets: this rank's facets of the slave surface.
        master_facets: this rank's facets of the master surface.
        weight: the measure's weight (2πr in the axisymmetric model), for nodal areas.
    """

    def __init__(self, V: fem.FunctionSpace, slave_facets, master_facets, weight=1.0):
        msh = V.mesh
        if V.element.basix_element.degree != 1:
            raise ValueError("a contact pair takes P1 displacements (node to segment or "
                             "triangle)")
        self.V, self.mesh, self.comm = V, msh, msh.comm
        self.gdim = msh.geometry.dim
        self.bs = V.dofmap.index_map_bs
        fdim = msh.topology.dim - 1
        imap = V.dofmap.index_map
        nodes = fem.locate_dofs_topological(V, fdim, np.asarray(slave_facets, np.int32))
        self.slave = nodes[nodes < imap.size_local]  # the owned slave nodes (V's blocks)
        x = V.tabulate_dof_coordinates()
        self.x = x[self.slave, :self.gdim]
        self.slave_global = imap.local_to_global(self.slave)
        segments = _master_facets(V, np.asarray(master_facets, np.int32))
        shared = self.comm.allreduce(int(np.isin(self.slave_global, segments["nodes"]).sum()))
        if shared:
            raise ValueError(f"{shared} slave nodes are master nodes too: a pair's surfaces "
                             "are two bodies' (they share no node)")
        self.segments = segments  # every rank's master facets, reference configuration
        self.facet, self.weights, self.normal, self.gamma = _project(self.x, segments)
        self.opened = np.zeros(len(self.slave))  # gap added to the geometry's (wear)
        self.master_nodes = segments["nodes"][self.facet]  # (n, nodes) global blocks
        self.tangents = _tangents(self.normal)  # (nodes, gdim − 1, gdim)
        self.B, self._Bt = self.rows(np.arange(len(self.slave))), None
        self.areas = _nodal_areas(V, np.asarray(slave_facets, np.int32), weight)[self.slave]
        self.part = np.zeros(len(self.slave), dtype=np.int64)  # which pair (`joined`)
        # the bodies' size: what a gap is small against (round-off)
        self.length = self.comm.allreduce(float(np.ptp(msh.geometry.x, axis=0).max()),
                                          op=MPI.MAX)

    @classmethod
    def joined(cls, pairs: list[ContactPair]) -> ContactPair:
        """Several pairs as one: their slave nodes one after the other, `part` says whose.

        One active set then runs over every pair (a node may be the slave of two pairs: it
        has a row in each).
        """
        if len(pairs) == 1:
            return pairs[0]
        out = object.__new__(cls)
        first = pairs[0]
        out.V, out.mesh, out.comm, out.bs = first.V, first.mesh, first.comm, first.bs
        out.gdim = first.gdim
        for name in ("slave", "x", "slave_global", "weights", "normal", "tangents", "gamma",
                     "master_nodes", "areas", "opened"):
            setattr(out, name, np.concatenate([getattr(p, name) for p in pairs]))
        out.part = np.concatenate([np.full(len(p.slave), k) for k, p in enumerate(pairs)])
        out.length = max(p.length for p in pairs)
        out.B, out._Bt = out.rows(np.arange(len(out.slave))), None
        return out

    def open(self, depth: np.ndarray) -> None:
        """Open the gap of each owned slave node by `depth` (wear: the surface worn away)."""
        self.gamma += depth
        self.opened += depth

    def follow(self, u: fem.Function) -> int:
        """The projection made again where the bodies are now (finite sliding).

        Each slave node at x_s + u_s is projected on the master facets at x_m + u_m (their
        normals turned with them, on the same side); B is rebuilt at the new points, and γ
        set so that γ + B u is the gap there (plus what `open` added): the gap linearized
        about the current state. Collective.

        Returns:
            The slave nodes (every rank's) whose master facet changed.
        """
        if not hasattr(self, "segments"):
            raise ValueError("follow: a single pair's (not `joined`)")
        if self.gdim != 2:
            raise ValueError("follow: finite sliding is 2D (segments)")
        seg, bs = self.segments, self.bs
        ids = np.unique(seg["nodes"])
        imap = self.V.dofmap.index_map
        local = imap.global_to_local(ids)
        mine = (local >= 0) & (local < imap.size_local)
        values = u.x.array.reshape(-1, bs)[local[mine], :2]
        every = np.vstack(self.comm.allgather(np.c_[ids[mine], values]))
        moved = dict(zip(every[:, 0].astype(np.int64), every[:, 1:], strict=True))
        P = seg["points"] + np.array([[moved[int(n)] for n in row] for row in seg["nodes"]])
        normal = _normal(P)
        normal *= np.sign(np.einsum("ij,ij->i", normal, seg["normal"]))[:, None]
        now = {"points": P, "normal": normal, "nodes": seg["nodes"]}
        x = self.x + u.x.array.reshape(-1, bs)[self.slave, :2]
        facet, self.weights, self.normal, gap = _project(x, now)
        changed = self.comm.allreduce(int((facet != self.facet).sum()))
        self.facet, self.master_nodes = facet, seg["nodes"][facet]
        self.tangents = _tangents(self.normal)
        self.B, self._Bt = self.rows(np.arange(len(self.slave))), None
        Bu = self.B.createVecLeft()
        self.B.mult(u.x.petsc_vec, Bu)
        self.gamma = gap - Bu.array + self.opened
        return changed

    def keys(self, which: np.ndarray) -> tuple:
        """The nodes `which` of every rank as one sorted tuple (a set's identity)."""
        parts = self.comm.allreduce(int(self.part.max(initial=0)), op=MPI.MAX) + 1
        ids = self.slave_global[which] * parts + self.part[which]
        return tuple(np.sort(np.concatenate(self.comm.allgather(ids))))

    @property
    def size(self) -> int:
        """The slave nodes over every rank."""
        return self.comm.allreduce(len(self.slave))

    def rows(self, which: np.ndarray, directions: np.ndarray | None = None) -> PETSc.Mat:
        """The rows d·(u_s − Σ_j N_j u_{m_j}) of the owned slave nodes `which` (global columns).

        Args:
            which: indices into this rank's slave nodes.
            directions: d, one unit vector per node of `which` (a tangent: the relative
                tangential displacement); None: the normals (B's rows).

        Returns:
            A new PETSc matrix, one row per node of `which`.
        """
        g = self.gdim
        d_all = self.normal[which] if directions is None else np.asarray(directions)
        n_local = len(which)
        N = self.V.dofmap.index_map.size_global * self.bs
        n_owned = self.V.dofmap.index_map.size_local * self.bs
        nnz = g * (self.weights.shape[1] + 1)
        B = PETSc.Mat().createAIJ(((n_local, None), (n_owned, N)), nnz=(nnz, nnz),
                                  comm=self.comm)
        B.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        start = B.getOwnershipRange()[0]
        for row, (i, d) in enumerate(zip(which, d_all, strict=True)):
            cols = [self.bs * self.slave_global[i] + k for k in range(g)]
            vals = list(d)
            for j, w in enumerate(self.weights[i]):
                cols += [self.bs * self.master_nodes[i, j] + k for k in range(g)]
                vals += list(-w * d)
            # (round-off entries dropped: a row on a symmetry plane's held dofs stays one)
            keep = np.abs(vals) > 1e-14
            B.setValues(start + row, np.asarray(cols, PETSc.IntType)[keep], np.asarray(vals)[keep],
                        addv=PETSc.InsertMode.ADD_VALUES)
        B.assemble()
        return B

    @property
    def Bt(self) -> list[PETSc.Mat]:
        """The tangential rows, one matrix per tangent (every slave node; friction)."""
        if self._Bt is None:
            every = np.arange(len(self.slave))
            self._Bt = [self.rows(every, self.tangents[:, k]) for k in range(self.gdim - 1)]
        return self._Bt

    def tangential(self, u: fem.Function) -> np.ndarray:
        """(u_s − u_m)·t_k at this rank's slave nodes, one column per tangent."""
        out = np.zeros((len(self.slave), self.gdim - 1))
        for k, Bt in enumerate(self.Bt):
            g = Bt.createVecLeft()
            Bt.mult(u.x.petsc_vec, g)
            out[:, k] = g.array
        return out

    def gaps(self, u: fem.Function) -> np.ndarray:
        """g_s(u) = γ_s + B_s u at this rank's slave nodes."""
        g = self.B.createVecLeft()
        self.B.mult(u.x.petsc_vec, g)
        return g.array + self.gamma

    def total(self, values) -> float:
        """The sum over every rank's slave nodes."""
        return self.comm.allreduce(float(np.sum(values)))


def _master_facets(V, facets) -> dict:
    """Every rank's master facets (2D segments, 3D triangles), gathered on every rank.

    Each: its nodes' global blocks and coordinates (`points`: facets × nodes × dim) and
    the master body's outward normal (pointing away from the cell the facet bounds).
    """
    msh = V.mesh
    g, fdim = msh.geometry.dim, msh.topology.dim - 1
    msh.topology.create_connectivity(fdim, fdim + 1)
    msh.topology.create_connectivity(fdim, 0)
    f2c, f2v = msh.topology.connectivity(fdim, fdim + 1), msh.topology.connectivity(fdim, 0)
    imap = V.dofmap.index_map
    nf = msh.topology.index_map(fdim).size_local
    facets = facets[facets < nf]  # owned: each facet once
    x = V.tabulate_dof_coordinates()
    from fenics_nl.contact.surface import vertex_of_dof

    dof_of_vertex = np.full(msh.topology.index_map(0).size_local
                            + msh.topology.index_map(0).num_ghosts, -1, dtype=np.int64)
    vod = vertex_of_dof(V)
    dof_of_vertex[vod[vod >= 0]] = np.nonzero(vod >= 0)[0]
    rows = []
    msh.topology.create_connectivity(fdim + 1, 0)
    c2v = msh.topology.connectivity(fdim + 1, 0)
    for f in facets:
        dofs = dof_of_vertex[f2v.links(f)]
        P = x[dofs, :g]
        n = _normal(P)
        cell = f2c.links(f)[0]  # its vertices' coordinates: P1 dofs (not geometry.x,
        centre = x[dof_of_vertex[c2v.links(cell)], :g].mean(axis=0)  # numbered apart)
        if np.dot(n, P.mean(axis=0) - centre) < 0:
            n = -n
        rows.append([*P.ravel(), *n, *imap.local_to_global(dofs.astype(np.int32))])
    k = g  # nodes per facet
    local = np.array(rows, dtype=float).reshape(-1, k * g + g + k)
    every = np.vstack(msh.comm.allgather(local))
    return {"points": every[:, :k * g].reshape(-1, k, g),
            "normal": every[:, k * g:k * g + g],
            "nodes": every[:, k * g + g:].astype(np.int64)}


def _normal(P: np.ndarray) -> np.ndarray:
    """The unit normal of segments (2D: the tangent turned clockwise) or triangles.

    3D: (p1 − p0) × (p2 − p0), normalized; its sense is the caller's to set.
    """
    if P.shape[-1] == 2:
        t = P[..., 1, :] - P[..., 0, :]
        n = np.stack([t[..., 1], -t[..., 0]], axis=-1)
    else:
        n = np.cross(P[..., 1, :] - P[..., 0, :], P[..., 2, :] - P[..., 0, :])
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def _tangents(normal: np.ndarray) -> np.ndarray:
    """Each normal's tangent basis (nodes × (dim − 1) × dim), orthonormal with it.

    2D: t = (−n_y, n_x); 3D: t1 the coordinate axis least along n made orthogonal to it
    (so that on a flat face normal to an axis the tangents are the other two axes, and a
    symmetry plane's held component is one tangent's), t2 = n × t1.
    """
    n = np.asarray(normal, dtype=float)
    if n.shape[1] == 2:
        return np.stack([-n[:, 1], n[:, 0]], axis=1)[:, None, :]
    e = np.eye(3)[np.argmin(np.abs(n), axis=1)]
    t1 = e - np.einsum("ij,ij->i", e, n)[:, None] * n
    t1 /= np.linalg.norm(t1, axis=1)[:, None]
    return np.stack([t1, np.cross(n, t1)], axis=1)


def _closest(x: np.ndarray, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The point of each facet P (facets × nodes × dim) closest to x, and its weights.

    The weights are the facet's shape functions at that point.
    """
    if P.shape[1] == 2:  # segments
        t = P[:, 1] - P[:, 0]
        s = np.clip(np.einsum("ij,ij->i", x - P[:, 0], t) / np.einsum("ij,ij->i", t, t),
                    0.0, 1.0)
        return P[:, 0] + s[:, None] * t, np.c_[1 - s, s]
    a, b, c = P[:, 0], P[:, 1], P[:, 2]  # triangles: the plane's foot if inside, else
    v0, v1 = b - a, c - a               # the closest point of the three edges
    n = np.cross(v0, v1)
    n /= np.linalg.norm(n, axis=1)[:, None]
    q = x - np.einsum("ij,ij->i", x - a, n)[:, None] * n
    v2 = q - a
    d00, d01, d11 = (np.einsum("ij,ij->i", p, r) for p, r in ((v0, v0), (v0, v1), (v1, v1)))
    d20, d21 = np.einsum("ij,ij->i", v2, v0), np.einsum("ij,ij->i", v2, v1)
    den = d00 * d11 - d01 * d01
    v, w = (d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den
    weights = np.c_[1 - v - w, v, w]
    closest = q.copy()
    outside = np.any(weights < 0, axis=1)
    if outside.any():
        best = np.full(len(P), np.inf)
        for i, j in ((0, 1), (1, 2), (2, 0)):
            e0, e1 = P[outside, i], P[outside, j]
            t = e1 - e0
            s = np.clip(np.einsum("ij,ij->i", x - e0, t) / np.einsum("ij,ij->i", t, t),
                        0.0, 1.0)
            point = e0 + s[:, None] * t
            d = np.linalg.norm(x - point, axis=1)
            better = d < best[outside]
            rows = np.flatnonzero(outside)[better]
            best[rows] = d[better]
            closest[rows] = point[better]
            weights[rows] = 0.0
            weights[rows, i], weights[rows, j] = 1 - s[better], s[better]
    return closest, weights


def _project(points: np.ndarray, facets: dict):
    """Each point's closest master facet: (its index, its weights, the normal, the gap γ)."""
    P, normals = facets["points"], facets["normal"]
    nodes = np.sort(facets["nodes"], axis=1)
    scale = float(np.linalg.norm(P[:, 1] - P[:, 0], axis=1).max(initial=0.0))
    facet = np.zeros(len(points), dtype=np.int64)
    weights = np.zeros((len(points), P.shape[1]))
    for i, x in enumerate(points):
        closest, w = _closest(x, P)
        d = np.linalg.norm(x - closest, axis=1)
        # at a master vertex or edge facets tie: the one of the lowest global nodes, so
        # that the choice does not depend on the order of the ranks' facets
        near = np.flatnonzero(d <= d.min() + 1e-12 * scale)
        k = int(near[np.lexsort(nodes[near].T[::-1])[0]])
        facet[i], weights[i] = k, w[k]
    closest = np.einsum("nk,nkg->ng", weights, P[facet])
    normal = normals[facet]
    gamma = np.einsum("ij,ij->i", points - closest, normal)
    return facet, weights, normal, gamma


def _nodal_areas(V, facets, weight) -> np.ndarray:
    """∫ N_i weight ds over `facets` for every node of V's first component (local blocks)."""
    from dolfinx import mesh

    msh = V.mesh
    tags = mesh.meshtags(msh, msh.topology.dim - 1, np.sort(facets),
                         np.ones(len(facets), dtype=np.int32))
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
    V0, dofs = V.sub(0).collapse()
    q = ufl.TestFunction(V0)
    b = petsc.assemble_vector(fem.form(q * weight * ds(1)))
    b.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
    b.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
    with b.localForm() as local:
        values = local.array_r.copy()
    out = np.zeros(V.dofmap.index_map.size_local + V.dofmap.index_map.num_ghosts)
    out[np.asarray(dofs) // V.dofmap.index_map_bs] = values
    return out


class _Unsettled(SolveError):
    """A linear pair's loop whose u, moved at its end, fails Newton's check."""


@dataclass
class PairState:
    """The pair after a solve: each owned slave node's status, force λ and pressure."""

    active: np.ndarray
    force: np.ndarray  # λ_s (compression > 0) at the owned slave nodes, 0 where inactive
    pressure: np.ndarray  # λ_s over the node's area


class PairContact:
    """The active-set loop on a contact pair; each iteration a (Newton) saddle-point solve.

    Args:
        residual: R(u; v), the bodies' equilibrium without contact (UFL form).
        u: the displacement (P1).
        bcs: the Dirichlet conditions.
        pair: the contact pair.
        atol: Newton's tolerance on ‖R‖ (times `force_scale`); the gaps of the active
            nodes to 1e-12 of the bodies' size.
        force_scale: the scale of the forces (the load); None: each solve's first residual
            and contact forces set it (displacements drive the bodies).
        max_it: Newton iterations per active-set iteration.
        max_iterations: active-set iterations before giving up.
        linear: the residual is linear in u: K is factorized once for the whole run and
            each set solved by its Schur complement on the active rows
            (`contact.condensed`), instead of a saddle point factorized at every iteration.
        finite_sliding: the projection made again after every solve where the bodies are
            (`ContactPair.follow`), the loop ending when the set repeats and the active
            gaps so measured are closed; frictionless, each set a saddle point.
    """

    def __init__(self, residual, u, bcs, pair: ContactPair, *,
                 atol: float = 1e-10, force_scale: float | None = None, max_it: int = 20,
                 max_iterations: int = 50, linear: bool = False,
                 finite_sliding: bool = False):
        if finite_sliding and linear:
            raise ValueError("finite sliding moves B: no one factorization (linear=False)")
        self.finite_sliding = finite_sliding
        self.u, self.bcs, self.pair = u, list(bcs), pair
        self.F = fem.form(residual)
        self.J = fem.form(ufl.derivative(residual, u))
        self.rel, self.scale = atol, force_scale
        self.max_it, self.max_iterations = max_it, max_iterations
        self.active = pair.gamma <= 1e-12 * self.pair.length  # touching at the start
        self.lam = np.zeros(len(pair.slave))
        dofs = np.concatenate([bc.dof_indices()[0] for bc in self.bcs]) if self.bcs else \
            np.zeros(0, dtype=np.int32)
        n_owned = u.function_space.dofmap.index_map.size_local * pair.bs
        owned = dofs[dofs < n_owned]
        start = u.x.petsc_vec.getOwnershipRange()[0]
        self.held = PETSc.IS().createGeneral((owned + start).astype(np.int32),
                                             comm=pair.comm)
        self.history: list[dict] = []
        self.condensed = CondensedSaddle(self.J, self.bcs, [pair.B], self.held) if linear \
            else None
        # a compliance in the gap of each owned slave node (g + c λ = 0 where active):
        # the wear of a step (`ArchardWear`); None: none
        self.compliance: np.ndarray | None = None
        # the motions K's supports leave free (None: not counted yet; a linear K's
        # factorization counts them) and the last solve's force scale (its first
        # residual's, or `force_scale`)
        self.free_motions, self._load = None, 0.0
        # inside a linear pair's loop: every row's value (gaps, slips) and the forces' change
        # u has not been moved by yet (`_begin`, `_settle`)
        self._values: np.ndarray | None = None
        self._moved: np.ndarray | None = None
        self._reference = 0.0

    def solve(self) -> SolveResult:
        """The active-set loop from the current set (warm start) to a set that repeats.

        With one factorization (`linear`) the loop moves the forces only, each iteration's
        gaps read off S (`_begin`); u is moved once when the set has settled (`_settle`),
        and checked: if it fails the check (a residual not linear in u), the loop is run
        again from its start, each set a saddle point.

        Returns:
            The result, its iterations the Newton iterations summed, its
            `active_set_iterations` the loop's, `history` each iteration's set changes.

        Raises:
            SolveError: the set did not settle within `max_iterations`.
        """
        start = self.u.x.array.copy(), self.checkpoint_arrays()
        try:
            return self._loop()
        except _Unsettled as err:
            self.u.x.array[:] = start[0]
            self.u.x.scatter_forward()
            self.restore_arrays(start[1])
            log.warning("contact pair: %s: each set is solved as a saddle point", err)
            self.condensed = None
            return self._loop()

    def _loop(self) -> SolveResult:
        """`solve`'s loop."""
        t0, work, its, history, seen = time.perf_counter(), WorkCounts(), 0, [], set()
        comm, length = self.pair.comm, self.pair.length
        if self.finite_sliding:
            self.pair.follow(self.u)
        self._begin(work)
        for k in range(1, self.max_iterations + 1):
            its += self.equilibrium(self.active, work)
            moved, open_gap = 0, 0.0
            if self.finite_sliding:  # the gaps where the bodies are now
                moved = self.pair.follow(self.u)
                open_gap = comm.allreduce(float(np.abs(self.pair.gaps(self.u)[
                    self.active]).max(initial=0.0)), op=MPI.MAX)
            g = self._gaps()
            leave = self.active & (self.lam < 0)
            join = ~self.active & (g < -1e-12 * length)
            changes = comm.allreduce(int(leave.sum() + join.sum()))
            history.append({"iteration": k, "active": comm.allreduce(int(self.active.sum())),
                            "leave": comm.allreduce(int(leave.sum())),
                            "join": comm.allreduce(int(join.sum())), "moved": moved})
            if changes == 0 and open_gap <= 1e-10 * length:
                self._settle(work)
                self._held()
                self.history = history
                return SolveResult(True, "converged", its, [], work,
                                   time.perf_counter() - t0, active_set_iterations=k,
                                   history=history)
            new = (self.active & ~leave) | join
            key = self.pair.keys(new)
            if key in seen and changes and not moved:  # (the geometry may still settle)
                raise SolveError(f"the active set cycles (iteration {k})")
            seen.add(key)
            self.active = new
        raise SolveError(f"the active set did not settle in {self.max_iterations} iterations")

    def _held(self) -> None:
        """Refuse an answer that no force holds.

        K leaves motions free and the contact carries no force (round-off of the load):
        the bodies' position along those motions is anyone's (a block without its
        support, moved by the push and touching it with no force: any lower position is
        as good).

        Raises:
            SupportError: the supports and the contact in force leave a motion free.
        """
        # (K's null pivots are counted only then: one factorization, in that case only)
        carried = self.pair.comm.allreduce(float(np.abs(self.lam).max(initial=0.0)),
                                           op=MPI.MAX)
        if carried > 1e-9 * self._load:
            return
        if self.free_motions is None:  # not known yet (no K factorized alone): count them
            K = petsc.assemble_matrix(self.J, self.bcs)
            K.assemble()
            self.free_motions = factorized_counting_null_pivots(create_ksp(K, "lu",
                                                                           prefix=PREFIX))
        if self.free_motions:
            raise SupportError(f"contact pair: {self.free_motions} motion(s) free: a body "
                               "that neither its supports nor the contact in force hold "
                               f"(the contact carries {carried:.1e}, the load "
                               f"{self._load:.1e})")

    def checkpoint_arrays(self) -> dict[str, np.ndarray]:
        """What a restart needs after a converged step: the set and the forces (this rank's).

        Returns:
            The arrays, for `restore_arrays`.
        """
        return {"active": self.active.astype(np.uint8), "lam": self.lam.copy()}

    def restore_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """The state of `checkpoint_arrays` back (the next solve starts from it)."""
        self.active = arrays["active"].astype(bool)
        self.lam = arrays["lam"].copy()

    def summary(self, part: int = 0, axisymmetric: bool = False) -> dict:
        """One pair's (`ContactPair.part`) force, nodes in contact, radius, largest pressure.

        The force: the master's on the slave body (every rank's; axisymmetric: its axial
        resultant over the revolution, the radial one 0); `contact_radius`: the
        largest x (the radius, axisymmetric) of a node in contact, or in plane strain half
        the largest distance between two nodes in contact (the half-width); 0 when none.
        """
        mine = self.pair.part == part
        st = self.state()
        on = mine & st.active
        comm = self.pair.comm
        x = np.vstack(comm.allgather(self.pair.x[on]))
        p = comm.allreduce(float(st.pressure[on].max(initial=0.0)), op=MPI.MAX)
        if len(x) == 0:
            radius = 0.0
        elif axisymmetric:
            radius = float(x[:, 0].max())
        else:
            radius = 0.5 * float(np.max(np.linalg.norm(x[:, None] - x[None], axis=2)))
        force = self.force(mine)
        if axisymmetric:  # the radial resultant vanishes over the revolution (as reactions)
            force[0] = 0.0
        return {"force": force.tolist(), "nodes_in_contact": len(x),
                "contact_radius": radius, "max_pressure": p}

    def state(self) -> PairState:
        """Statuses, forces and pressures at this rank's owned slave nodes."""
        areas = np.where(self.pair.areas > 0, self.pair.areas, 1.0)
        return PairState(self.active.copy(), self.lam.copy(), self.lam / areas)

    def nodal_forces(self) -> np.ndarray:
        """The force the master exerts on each owned slave node, λ_s n_s (nodes × dim)."""
        return self.lam[:, None] * self.pair.normal

    def force(self, which: np.ndarray | None = None) -> np.ndarray:
        """The force the master exerts on the slave body, the nodal forces' sum (every rank's).

        Args:
            which: flags of the slave nodes to sum over (one pair's); None: all.
        """
        F = self.nodal_forces()
        keep = np.ones(len(F), bool) if which is None else which
        return np.array([self.pair.total(F[keep, k]) for k in range(self.pair.gdim)])

    def profile(self) -> tuple[np.ndarray, np.ndarray]:
        """(x, pressure) of the active slave nodes, gathered on every rank (x: n × dim)."""
        st, g = self.state(), self.pair.gdim
        rows = np.c_[self.pair.x[st.active], st.pressure[st.active]]
        every = np.vstack(self.pair.comm.allgather(rows.reshape(-1, g + 1)))
        return every[:, :g], every[:, g]

    def equilibrium(self, active: np.ndarray, work: WorkCounts | None = None) -> int:
        """The equilibrium with g_s = 0 on the `active` slave nodes and no force elsewhere.

        Newton on the saddle point (one iteration for a linear residual); `lam` then holds
        each owned slave node's λ (0 where inactive), and `active` (what `state`, `force`
        and `profile` report) the set.

        Args:
            active: one flag per owned slave node.
            work: the counts to add this solve's to.

        Returns:
            Newton's iterations.
        """
        work = work if work is not None else WorkCounts()
        self.active = np.asarray(active, dtype=bool).copy()  # what `state` reports
        c = np.zeros(len(self.lam)) if self.compliance is None else self.compliance
        comm = self.pair.comm
        if self.condensed is not None and self._condensed(
                np.flatnonzero(every_rank(comm, self.active)), np.zeros(self.condensed.n),
                lambda: every_rank(comm, self._gaps() + c * self.lam), work,
                every_rank(comm, c)):
            return 1
        which = np.flatnonzero(self.active)
        lam = self._saddle(self.pair.rows(which), self.pair.gamma[which], None, work,
                           None if self.compliance is None else c[which])[0]
        self.lam[:] = 0.0
        self.lam[which] = lam
        return self._iterations

    # -- a linear residual: one factorization for the run (`contact.condensed`) ----------

    def _rows(self) -> np.ndarray:
        """Every row's force (every rank's): the normal ones."""
        return every_rank(self.pair.comm, self.lam)

    def _set_rows(self, forces: np.ndarray) -> None:
        start = self.condensed.start
        self.lam[:] = forces[start:start + len(self.lam)]

    def _contact_forces(self) -> PETSc.Vec:
        """Bᵀλ: the contact forces on the nodes (u's layout)."""
        out = self.pair.B.createVecRight()
        self.pair.B.multTranspose(_vec(self.pair.B, self.lam), out)
        return out

    def _condensed(self, unknown, known, conditions, work: WorkCounts,
                   compliance=None, frame=None) -> bool:
        """The statuses' equilibrium on the kept factorization; False if it cannot be.

        The forces of the `unknown` rows that zero their `conditions()` (gaps, slips) with
        the `known` ones given (`_defer`). Inside `solve`'s loop u moves at its end; called
        on its own (`equilibrium`), the load's back-substitution first (`_begin`) and u
        moved and checked after (`_settle`). K singular (a body held by the contact alone)
        or a residual not linear in u fails: the state is put back, said, and from then on
        each set is a saddle point factorized (False). With a `frame` Q (rows turned,
        `CondensedSaddle.solve`), `unknown`, `known`, `compliance` and `conditions()` are
        the turned rows'.
        """
        c = self.condensed
        saved = self.u.x.array.copy(), self._rows()
        alone = self._values is None
        if alone:
            self._begin(work)
            if self.condensed is None:  # (K singular: said by `_begin`)
                return False
        try:
            self._defer(unknown, known, conditions, work, compliance, frame)
            if alone:
                self._settle(work)
            return True
        except (SolveError, np.linalg.LinAlgError, PETSc.Error) as err:
            self.u.x.array[:] = saved[0]
            self._set_rows(saved[1])
            self._values = None
            log.warning("contact pair: %s: each set is solved as a saddle point", err)
            self.free_motions = c.free_motions
            self.condensed = None
            return False

    def _begin(self, work: WorkCounts) -> None:
        """A linear pair's loop begins: u_0 for the loads now, every row's value kept.

        One back-substitution if the loads moved since the last solve (R(u) − Bᵀλ ≠ 0);
        then the rows' values (the gaps B u + γ and the tangential B_t u) are kept, and
        each iteration moves them by S's columns, Δ(Bu) = S Δλ, instead of moving u
        (`_defer`): the loop reads them (`_gaps`, `_tangential`) and `_settle` moves u
        once at its end. A singular K is said and left to the saddle point.
        """
        self._values = None
        c = self.condensed
        if c is None:
            return
        try:
            r = self._out_of_balance(work)
            forces = self._rows()
            self._reference = self.scale if self.scale is not None else max(
                r.norm(), float(np.linalg.norm(forces)))
            if r.norm() > self.rel * self._reference:  # the loads moved: the new u_0 (+ W λ)
                self.u.x.petsc_vec.axpy(-1.0, c.back_solve(r, work))
                self.u.x.scatter_forward()
                work.linear_solves += 1
        except (SolveError, PETSc.Error) as err:  # K singular: nothing moved
            self.free_motions = c.free_motions
            log.warning("contact pair: %s: each set is solved as a saddle point", err)
            self.condensed = None
            return
        self._values, self._moved = self._block_values(), np.zeros(len(forces))

    def _defer(self, unknown, known, conditions, work, compliance, frame) -> None:
        """The statuses' forces on the kept factorization; the rows' values moved by S."""
        c, before = self.condensed, self._rows()
        after = c.solve(before, unknown, known, conditions(), work, compliance, frame)
        change = after - before
        rows = np.flatnonzero(change)
        if len(rows):
            self._values += c.S[:, [c.column[int(k)] for k in rows]] @ change[rows]
        self._moved += change
        self._set_rows(after)

    def _settle(self, work: WorkCounts) -> None:
        """u moved by the loop's change of the forces (one back-substitution), and checked.

        As a Newton solve checks its answer: R(u) − Bᵀλ = 0, and the rows' values at u
        those the loop read off S (to 1e-12 of the bodies' size).

        Raises:
            _Unsettled: they are not (a residual not linear in u).
        """
        if self._values is None:
            return
        c, predicted, moved = self.condensed, self._values, self._moved
        self._values = self._moved = None
        c.move(self.u.x.petsc_vec, np.zeros_like(moved), moved, work)
        self.u.x.scatter_forward()
        norm = self._out_of_balance(work).norm()
        reference = self._reference if self.scale is not None else max(
            self._reference, float(np.linalg.norm(self._rows())))
        off = float(np.abs(self._block_values() - predicted).max(initial=0.0))
        if not (norm <= self.rel * reference and off <= 1e-12 * self.pair.length):
            raise _Unsettled(f"the condensed solve left |R| = {norm:.2e} and its rows "
                             f"{off:.2e} off (K singular, a body held by the contact "
                             "alone; or a residual not linear in u)")
        self.free_motions, self._load = c.free_motions, reference

    def _block_values(self) -> np.ndarray:
        """Every row's value at u (every rank's): the gaps, then each tangential block's."""
        comm = self.pair.comm
        out = [every_rank(comm, self.pair.gaps(self.u))]
        for M in self.condensed.blocks[1:]:
            v = M.createVecLeft()
            M.mult(self.u.x.petsc_vec, v)
            out.append(every_rank(comm, v.array))
        return np.concatenate(out)

    def _gaps(self) -> np.ndarray:
        """This rank's gaps: at u, or (inside a linear pair's loop) those S gives."""
        if self._values is None:
            return self.pair.gaps(self.u)
        start = self.condensed.start
        return self._values[start:start + len(self.lam)].copy()

    def _tangential(self) -> np.ndarray:
        """This rank's relative tangential displacements (nodes × tangents), as `_gaps`."""
        if self._values is None:
            return self.pair.tangential(self.u)
        n, start, local = self.condensed.n, self.condensed.start, len(self.lam)
        return np.column_stack([self._values[k * n + start:k * n + start + local]
                                for k in range(1, self.pair.gdim)])

    def _out_of_balance(self, work: WorkCounts) -> PETSc.Vec:
        """R(u) − (the contact forces) with the supports' values set in u (their rows 0)."""
        for bc in self.bcs:
            bc.set(self.u.x.array)
        self.u.x.scatter_forward()
        return self._unbalanced(work, self._contact_forces())

    def _unbalanced(self, work: WorkCounts, forces: PETSc.Vec | None) -> PETSc.Vec:
        """R(u) − `forces` (None: R(u)) at u as it is, the prescribed dofs' rows zeroed."""
        R = petsc.assemble_vector(self.F)
        R.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
        work.residual_assemblies += 1
        if forces is not None:
            R.axpy(-1.0, forces)
        _zero(R, self.held)  # the prescribed dofs: no equation
        return R

    def _saddle(self, B, offset, forces, work, compliance=None):
        """Newton on R(u) − Bᵀλ − forces = 0, B u + offset + c λ = 0: (λ, ).

        `forces`: known contact forces (a PETSc Vec in u's layout: friction), or None;
        `compliance`: c, one per row of B (wear: the step's wear in the gap), or None.
        """
        u = self.u
        lam = np.zeros(B.getLocalSize()[0])
        for bc in self.bcs:  # the prescribed values, then increments of 0 there
            bc.set(u.x.array)
        u.x.scatter_forward()
        for it in range(1, self.max_it + 1):
            Bt_lam = B.createVecRight()
            B.multTranspose(_vec(B, lam), Bt_lam)
            if forces is not None:
                Bt_lam.axpy(1.0, forces)
            R = self._unbalanced(work, Bt_lam)  # R(u) − Bᵀλ − forces
            g = B.createVecLeft()
            B.mult(u.x.petsc_vec, g)
            g.array[:] += offset + (0.0 if compliance is None else compliance * lam)
            norm = R.norm()
            closed = g.norm(PETSc.NormType.INFINITY) <= 1e-12 * self.pair.length
            if it == 1:
                reference = self.scale if self.scale is not None else norm
                self._load = reference
            if norm <= self.rel * reference and closed and it > 1:
                self._iterations = it - 1
                return (lam,)
            K = petsc.assemble_matrix(self.J, self.bcs)
            K.assemble()
            work.tangent_assemblies += 1
            du, dlam = _saddle_solve(K, B, R, g, self.held, work, compliance)
            u.x.petsc_vec.axpy(-1.0, du)
            u.x.scatter_forward()
            lam -= dlam
            if it == 1 and self.scale is None:  # the contact forces found: a scale too
                reference = max(reference, _vec(B, lam).norm())
            if norm <= self.rel * reference and closed:
                self._iterations = it
                return (lam,)
        raise SolveError(f"contact pair: Newton did not converge in {self.max_it} iterations "
                         f"(|R| = {norm:.2e})")


def _vec(B: PETSc.Mat, values: np.ndarray) -> PETSc.Vec:
    v = B.createVecLeft()
    v.array[:] = values
    return v


def _zero(R: PETSc.Vec, rows: PETSc.IS) -> None:
    start = R.getOwnershipRange()[0]
    R.array[rows.indices - start] = 0.0


def _saddle_solve(K, B, R, g, held, work: WorkCounts, compliance=None):
    """[K −Bᵀ; −B −C] [du; dλ] = [R; −g] by MUMPS LU: (du, dλ), a Vec and an array.

    The prescribed dofs (`held`, identity rows of K) take no multiplier: their rows of Bᵀ
    are zero, so du = 0 there. C = diag(`compliance`), or 0.
    """
    Bt = B.transpose(PETSc.Mat())  # a new matrix (without `out`, B itself is transposed)
    Bt.scale(-1.0)
    Bn = B.copy()
    Bn.scale(-1.0)
    Bt.zeroRows(held, diag=0.0)  # the prescribed dofs keep their value: no multiplier there
    nest = PETSc.Mat().createNest([[K, Bt], [Bn, _multiplier_block(Bt, compliance)]],
                                  comm=K.comm)
    A = nest.convert("aij")
    rhs = A.createVecRight()
    n_u = R.getLocalSize()
    rhs.array[:n_u] = R.array
    rhs.array[n_u:] = -g.array
    ksp = create_ksp(A, "lu", prefix=PREFIX)
    x = A.createVecLeft()
    t0 = time.perf_counter()
    free = factorized_counting_null_pivots(ksp)
    if free:
        raise SupportError(f"contact pair: {free} motion(s) free: a body that neither its "
                           "supports nor the contact in force hold (the saddle point is "
                           "singular)")
    ksp.solve(rhs, x)
    work.factorizations += 1
    work.linear_solves += 1
    work.time["solve"] = work.time.get("solve", 0.0) + time.perf_counter() - t0
    if ksp.getConvergedReason() < 0:
        raise SolveError("contact pair: the saddle point solve failed "
                         f"({ksp.getConvergedReason()})")
    du = R.duplicate()
    du.array[:] = x.array[:n_u]
    dlam = x.array[n_u:].copy()
    return du, dlam


def _multiplier_block(Bt: PETSc.Mat, compliance=None) -> PETSc.Mat | None:
    """The saddle point's lower right block: −C, and 1 on a row binding held dofs only.

    C = diag(`compliance`) (wear: the step's wear k Δs/A per unit force, in the gap). A row
    of B on prescribed dofs only (the tangential row of a node on the axis, where both
    bodies' u_r are held) constrains nothing the solve can change: its multiplier is left
    out (dλ = −g, 0 for a condition the supports already meet) instead of making the
    saddle point singular. None if the block is 0.
    """
    B = Bt.transpose(PETSc.Mat())
    start, n = B.getOwnershipRange()[0], B.getLocalSize()[0]
    diagonal = np.zeros(n) if compliance is None else -np.asarray(compliance, dtype=float)
    for i in range(n):
        if not np.any(B.getRow(start + i)[1]):
            diagonal[i] = 1.0
    if not B.comm.tompi4py().allreduce(int(np.count_nonzero(diagonal))):
        return None
    D = PETSc.Mat().createAIJ((B.getSizes()[0], B.getSizes()[0]), nnz=(1, 0), comm=B.comm)
    for i in np.flatnonzero(diagonal):
        D.setValue(start + i, start + i, diagonal[i])
    D.assemble()
    return D


class FrictionalPair(PairContact):
    """The active set on a pair with Coulomb friction: open, stuck or slipping nodes.

    The course's statuses, as on a rigid obstacle (`contact.friction`), between the bodies:
    the relative tangential displacement g_t = (u_s − u_m)·t_k (one per tangent of the
    node's basis, `ContactPair.tangents`) since the last committed state (`commit`) is the
    slip. Each iteration solves the saddle point with

    * open nodes free;
    * stuck nodes: g_n = 0 and Δg_t = 0 (multipliers λ_n and λ_t, one per tangent);
    * slipping nodes: g_n = 0 and the tangential force f λ_n s on the slave (s a unit
      direction in the tangent plane; its opposite, by the shape functions, on the master),
      λ_n from the last iteration;

    then updates the statuses: a closed node in tension opens; an open node that penetrates
    closes, slipping without friction (it cannot stick where it was at the step's start:
    it touched down within the step), until its slip gives the friction's sense,
    s = −Δg_t/|Δg_t|, or sticks if it has not slipped; a stuck node whose |λ_t| exceeds
    f λ_n slips, s = λ_t/|λ_t|; a slipping node whose slip goes along its friction force
    (Δg_t·s > 0) sticks.

    3D: the direction of a slipping node is found by iteration as on a rigid obstacle: the
    node carries f λ_n s and a spring k = f λ_n/|Δg_t| against slip across s (a multiplier
    μ on the row s⊥·Δg_t with the compliance 1/k: the linearization of −f λ_n Δg_t/|Δg_t|
    at the fixed point); s then turns to the node's whole tangential force,
    f λ_n s + μ s⊥, and at the fixed point μ = 0, the slip along −s.

    The loop ends when no status changes and the friction forces agree with the normal
    forces and directions of the same solve (to 1e-9 of the largest normal force).

    Args:
        residual: R(u; v), the bodies' equilibrium without contact (UFL form).
        u: the displacement (P1, 2D or 3D).
        bcs: the Dirichlet conditions.
        pair: the contact pair.
        friction: Coulomb's coefficient f, or one per pair (`ContactPair.part`).
        **options: `PairContact`'s (tolerances, iteration limits).
    """

    def __init__(self, residual, u, bcs, pair: ContactPair, friction: float, **options):
        if options.get("finite_sliding"):
            raise ValueError("friction on a pair is small sliding (its slip is measured on "
                             "the projection it started from)")
        super().__init__(residual, u, bcs, pair, **options)
        f = np.asarray(friction, dtype=float)
        if not np.all(f >= 0):
            raise ValueError(f"the friction coefficient must be >= 0, got {friction}")
        # one per pair (`ContactPair.joined`), as one per slave node
        self.f = f[pair.part] if f.ndim else np.full(len(pair.slave), float(f))
        n, m = len(pair.slave), pair.gdim - 1
        if m == 2:
            self._tangents_along_supports()
        self.slip = self.f == 0  # no friction: slipping for good
        self.s = np.zeros((n, m))  # the friction force's direction (tangent basis; 0: none)
        self.lam_t = np.zeros((n, m))
        self.spring = np.zeros(n)  # 3D: k against slip across s
        self.committed = pair.tangential(u)
        if self.condensed is not None:  # the stuck nodes' slips are rows too
            self.condensed = CondensedSaddle(self.J, self.bcs, [pair.B, *pair.Bt], self.held)

    def commit(self) -> None:
        """The converged step's tangential displacement: the next step's slip is from it."""
        self.committed = self.pair.tangential(self.u)

    def _tangents_along_supports(self) -> None:
        """3D: tangents along the axes the supports hold.

        A slave node whose relative motion along an axis the supports hold (that
        component held at the node and at its master nodes: a symmetry plane, a slice's
        ends) gets that axis as its first tangent t1, and t2 = n × t1 normalized. The row
        along t1 then binds held dofs only, and takes no multiplier; the basis made
        orthogonal to a normal tilted by the facets (the faceted bore of a slice) would
        give t1 a part of the normal's row on the free dofs: two rows nearly dependent, a
        singular saddle point.
        """
        pair = self.pair
        bs, g = pair.bs, pair.gdim
        # the held dofs of the pairs' nodes (every rank's; not the whole model's)
        nodes = np.unique(np.concatenate(pair.comm.allgather(np.concatenate(
            [pair.slave_global, pair.master_nodes.ravel()]))))
        candidates = (bs * nodes[:, None] + np.arange(g)).ravel()
        mine = self.held.indices.astype(np.int64)
        held = np.concatenate(pair.comm.allgather(mine[np.isin(mine, candidates)]))
        touching = pair.weights > 1e-14  # the master nodes the slave node's rows bind
        axes = np.zeros((len(pair.slave), g), dtype=bool)
        for k in range(g):
            master = np.isin(bs * pair.master_nodes + k, held) | ~touching
            axes[:, k] = np.isin(bs * pair.slave_global + k, held) & master.all(axis=1)
        # an axis held and in the tangent plane (roughly: the normal's own axis is not)
        axes &= np.abs(pair.normal) < 0.5
        turned = np.flatnonzero(axes.any(axis=1))
        if not pair.comm.allreduce(len(turned)):
            return
        t1 = np.eye(g)[np.argmax(axes[turned], axis=1)]
        t2 = np.cross(pair.normal[turned], t1)
        pair.tangents[turned] = np.stack([t1, t2 / np.linalg.norm(t2, axis=1)[:, None]],
                                         axis=1)
        pair._Bt = None  # built again on these

    def nodal_forces(self) -> np.ndarray:
        """The force on each owned slave node, λ_n n + Σ_k λ_t,k t_k (nodes × dim)."""
        return super().nodal_forces() + np.einsum("nk,nkg->ng", self.lam_t,
                                                  self.pair.tangents)

    def checkpoint_arrays(self) -> dict[str, np.ndarray]:
        """The set, the slip statuses, directions and springs, the forces, the committed slip."""
        return super().checkpoint_arrays() | {
            "slip": self.slip.astype(np.uint8), "s": self.s.copy(),
            "lam_t": self.lam_t.copy(), "spring": self.spring.copy(),
            "committed": self.committed.copy()}

    def restore_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """The state of `checkpoint_arrays` back."""
        super().restore_arrays(arrays)
        self.slip = arrays["slip"].astype(bool)
        m = self.pair.gdim - 1
        self.s = arrays["s"].reshape(-1, m).copy()
        self.lam_t = arrays["lam_t"].reshape(-1, m).copy()
        self.spring = arrays.get("spring", np.zeros(len(self.lam))).copy()
        self.committed = arrays["committed"].reshape(-1, m).copy()

    def _loop(self) -> SolveResult:
        """The active-set loop with friction, from the current statuses (warm start).

        Returns:
            The result, its `history` each iteration's counts (active, slip, changes).

        Raises:
            SolveError: the statuses did not settle within `max_iterations`.
        """
        t0, work, its, history = time.perf_counter(), WorkCounts(), 0, []
        comm = self.pair.comm
        lam_n, seen = self.lam.copy(), {}
        tol_u = 1e-12 * self.pair.length  # a slip of round-off
        rubs = self.f > 0  # a pair without friction: its nodes slip freely, for good
        self._begin(work)
        for k in range(1, self.max_iterations + 1):
            its += self._equilibrium(lam_n, work)
            g = self._gaps()
            dg = self._tangential() - self.committed
            slid = np.linalg.norm(dg, axis=1)
            size = np.linalg.norm(self.lam_t, axis=1)
            sensed = np.any(self.s != 0, axis=1)
            stick = self.active & ~self.slip
            scale = comm.allreduce(float(np.abs(self.lam).max(initial=0.0)), op=MPI.MAX)
            opening = self.active & (self.lam < 0)
            closing = ~self.active & (g < -tol_u)
            sliding = stick & (size > self.f * self.lam * (1 + 1e-9) + 1e-12 * scale)
            slipping = self.active & self.slip & rubs
            holding = slipping & (np.einsum("ij,ij->i", dg, self.s) > tol_u)
            landed = slipping & ~sensed  # no sense yet
            sensing = landed & (slid > tol_u)
            resting = landed & ~sensing  # it has not slipped since it landed: it sticks
            s = self.s.copy()
            s[sliding] = self.lam_t[sliding] / size[sliding, None]
            s[sensing] = -dg[sensing] / slid[sensing, None]  # friction against the slip
            kept = slipping & sensed & ~holding & (size > 1e-12 * scale)
            spring = self._springs(s, kept, dg)
            # the friction forces the solve had (λ_n s of the last iteration) and those of
            # its answer: their drift
            drift = comm.allreduce(float(np.abs(
                (self.lam[:, None] * s - lam_n[:, None] * self.s)[slipping]).max(initial=0.0)),
                op=MPI.MAX)
            changes = comm.allreduce(int((opening | closing | sliding | holding | landed
                                          ).sum()))
            history.append({"iteration": k, "active": comm.allreduce(int(self.active.sum())),
                            "slip": comm.allreduce(int((self.active & self.slip).sum())),
                            "changes": changes, "drift": drift})
            if changes == 0 and drift <= 1e-9 * max(scale, 1e-300):
                self._settle(work)
                self._held()
                self.history = history
                return SolveResult(True, "converged", its, [], work, time.perf_counter() - t0,
                                   active_set_iterations=k, history=history)
            self.s = np.where(closing[:, None], 0.0, s)
            # a node that lands sticks, if it does, where it landed (not where it was at
            # the step's start, when it was open)
            self.committed = np.where(closing[:, None], self._tangential(), self.committed)
            self.slip = (self.slip & ~holding & ~resting | sliding | closing) & ~opening
            self.active = (self.active & ~opening) | closing
            self.spring = np.where(self.active & self.slip, spring, 0.0)
            # (3D directions compared to 1e-9: a cycle of directions repeats them only so)
            key = self.pair.keys(self.active) + self.pair.keys(self.active & self.slip) + \
                tuple(np.concatenate(comm.allgather(np.round(self.s[self.active], 9).ravel())))
            # a set of statuses may come back while the friction forces still move (they
            # follow the normal forces of the last solve): its third visit is a cycle
            seen[key] = seen.get(key, 0) + 1
            if seen[key] > 2 and changes:
                raise SolveError(f"the frictional statuses cycle (iteration {k})")
            lam_n = self.lam.copy()
        raise SolveError(f"the frictional statuses did not settle in {self.max_iterations} "
                         "iterations")

    def _springs(self, s: np.ndarray, kept: np.ndarray, dg: np.ndarray) -> np.ndarray:
        """3D: each slipping node's spring against slip across s (0 in 2D).

        The nodes `kept` turned to their tangential force (`s` updated in place), and
        each one's spring k = f λ_n/|Δg_t| (the linearization of −f λ_n Δg_t/|Δg_t| across
        the slip at the fixed point, where −Δg_t·s = |Δg_t|; a slip that has turned away
        from −s still gets its spring, which turns it back). A node that barely slides
        (below 1e-6 of the largest slip) gets no spring: k = f λ_n/slip would amplify
        round-off in u into the residual.
        """
        spring = np.zeros(len(s))
        if s.shape[1] == 1:  # 2D: the direction is a sense, kept until the node sticks
            return spring
        s[kept] = self.lam_t[kept] / np.linalg.norm(self.lam_t[kept], axis=1)[:, None]
        slid = np.linalg.norm(dg, axis=1)
        floor = 1e-6 * self.pair.comm.allreduce(float(np.where(kept, slid, 0.0).max(
            initial=0.0)), op=MPI.MAX)
        moving = kept & (slid > max(1e-12 * self.pair.length, floor))
        spring[moving] = self.f[moving] * self.lam[moving] / slid[moving]
        return spring

    def _across(self) -> np.ndarray:
        """s⊥ = n × s in the tangent basis, (−s_2, s_1) (3D)."""
        return np.c_[-self.s[:, 1], self.s[:, 0]]

    def _rows(self) -> np.ndarray:
        """Every row's force (every rank's): the normal ones, then each tangent's."""
        comm = self.pair.comm
        return np.concatenate([every_rank(comm, self.lam),
                               *(every_rank(comm, t) for t in self.lam_t.T)])

    def _set_rows(self, forces: np.ndarray) -> None:
        n, start, local = self.condensed.n, self.condensed.start, len(self.lam)
        self.lam[:] = forces[start:start + local]
        for k in range(self.lam_t.shape[1]):
            first = (k + 1) * n + start
            self.lam_t[:, k] = forces[first:first + local]

    def _contact_forces(self) -> PETSc.Vec:
        """Bᵀλ_n + Σ_k B_t,kᵀλ_t,k."""
        out = super()._contact_forces()
        for Bt, lam in zip(self.pair.Bt, self.lam_t.T, strict=True):
            tangential = Bt.createVecRight()
            Bt.multTranspose(_vec(Bt, lam), tangential)
            out.axpy(1.0, tangential)
        return out

    def _condensed_statuses(self, lam_n: np.ndarray, work: WorkCounts) -> bool:
        """The statuses' equilibrium on the kept factorization (False: it cannot be).

        The rows: the normals, then each tangent's. 3D: a slipping node's two tangential
        rows turned to (along s, across s) (the frame Q, `CondensedSaddle.solve`): its
        force along s is known, f λ_n, and across s the spring's, compliance 1/k.
        """
        comm, n, m = self.pair.comm, self.condensed.n, self.lam_t.shape[1]
        closed = every_rank(comm, self.active)
        slipping = closed & every_rank(comm, self.slip)
        stuck = np.flatnonzero(closed & ~slipping)
        s = np.vstack(comm.allgather(self.s))
        force = every_rank(comm, self.f * lam_n)
        known = np.zeros((m + 1) * n)
        frame, compliance = None, None
        unknown = [np.flatnonzero(closed), *(k * n + stuck for k in range(1, m + 1))]
        if m == 1:
            known[n:][slipping] = (force * s[:, 0])[slipping]
        else:
            turned = np.flatnonzero(slipping & np.any(s != 0, axis=1))
            frame = _turned_rows(n, turned, s[turned])
            known[n + turned] = force[turned]
            spring = every_rank(comm, self.spring)
            sprung = turned[spring[turned] > 0]
            unknown.append(2 * n + sprung)
            compliance = np.zeros((m + 1) * n)
            compliance[2 * n + sprung] = 1.0 / spring[sprung]

        def conditions():  # the gaps, and the slips since the last committed state
            dg = self._tangential() - self.committed
            rows = np.concatenate([every_rank(comm, self._gaps()),
                                   *(every_rank(comm, d) for d in dg.T)])
            if frame is None:
                return rows
            return frame.T @ rows + compliance * (frame.T @ self._rows())

        return self._condensed(np.concatenate(unknown), known, conditions, work,
                               compliance, frame)

    def _equilibrium(self, lam_n: np.ndarray, work: WorkCounts) -> int:
        """One solve for the current statuses; the slip forces from `lam_n`."""
        if self.condensed is not None and self._condensed_statuses(lam_n, work):
            return 1
        pair, m = self.pair, self.lam_t.shape[1]
        t = pair.tangents
        stick = np.flatnonzero(self.active & ~self.slip)
        closed = np.flatnonzero(self.active)
        sliding = np.flatnonzero(self.active & self.slip)
        sprung = np.flatnonzero(self.active & self.slip & (self.spring > 0))
        across = self._across() if m > 1 else np.zeros((len(self.s), 0))
        blocks = [pair.rows(closed), *(pair.rows(stick, t[stick, k]) for k in range(m))]
        offset = [pair.gamma[closed], *(-self.committed[stick, k] for k in range(m))]
        compliance = None
        if m > 1 and pair.comm.allreduce(len(sprung)):  # 3D: the springs across s
            blocks.append(pair.rows(sprung, np.einsum("nk,nkg->ng", across[sprung],
                                                      t[sprung])))
            offset.append(-np.einsum("ij,ij->i", across, self.committed)[sprung])
            compliance = np.concatenate([np.zeros(len(closed) + m * len(stick)),
                                         1.0 / self.spring[sprung]])
        forces = None
        if pair.comm.allreduce(len(sliding)):
            Bs = pair.rows(sliding, np.einsum("nk,nkg->ng", self.s[sliding], t[sliding]))
            forces = Bs.createVecRight()
            Bs.multTranspose(_vec(Bs, (self.f * lam_n)[sliding]), forces)
        lam = self._saddle(_stacked(blocks), np.concatenate(offset), forces, work,
                           compliance)[0]
        self.lam[:] = 0.0
        self.lam_t[:] = 0.0
        self.lam[closed] = lam[: len(closed)]
        first = len(closed)
        for k in range(m):
            self.lam_t[stick, k] = lam[first:first + len(stick)]
            first += len(stick)
        self.lam_t[sliding] = (self.f * lam_n)[sliding, None] * self.s[sliding]
        if compliance is not None:
            self.lam_t[sprung] += lam[first:, None] * across[sprung]
        return self._iterations


def _turned_rows(n: int, nodes: np.ndarray, s: np.ndarray):
    """Q: the rows [B; B_t1; B_t2] (3n) with each of `nodes`' tangential rows turned.

    Its columns are the new rows in the old ones: node j's (along s, across s) =
    (s_1 t1 + s_2 t2, −s_2 t1 + s_1 t2) at rows n + j, 2n + j; every other row kept.
    Orthonormal: forces go to the new rows by Qᵀ, back by Q.
    """
    from scipy import sparse

    keep = np.setdiff1d(np.arange(3 * n), np.r_[n + nodes, 2 * n + nodes])
    a, b = n + nodes, 2 * n + nodes
    rows = np.concatenate([keep, a, b, a, b])
    cols = np.concatenate([keep, a, a, b, b])
    vals = np.concatenate([np.ones(len(keep)), s[:, 0], s[:, 1], -s[:, 1], s[:, 0]])
    return sparse.csr_array((vals, (rows, cols)), shape=(3 * n, 3 * n))


def _stacked(blocks: list[PETSc.Mat]) -> PETSc.Mat:
    """The rows of each block, one block after the other (each rank's, in that order)."""
    first = blocks[0]
    n_rows = [M.getLocalSize()[0] for M in blocks]
    B = PETSc.Mat().createAIJ(((sum(n_rows), None), first.getSizes()[1]), nnz=(12, 12),
                              comm=first.comm)
    B.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
    start = B.getOwnershipRange()[0]
    for offset, M in zip(np.cumsum([0, *n_rows[:-1]]), blocks, strict=True):
        head = M.getOwnershipRange()[0]
        for i in range(M.getLocalSize()[0]):
            cols, vals = M.getRow(head + i)
            B.setValues(start + int(offset) + i, cols, vals)
    B.assemble()
    return B


class ArchardWear:
    """Archard's wear of the slave surface, integrated over the sliding distance.

    The wear depth grows as dh = k p ds (k the wear coefficient over the hardness, p the
    contact pressure, s the sliding distance), and moves the worn surface away: the gap of
    each slave node grows by its wear, so that the pressure redistributes. Backward Euler
    over a step of sliding Δs: the wear of the step is that of the pressure at its end,
    Δh_s = k λ_s Δs / A_s (λ_s the node's normal force, A_s its area), so the contact of
    the step is solved with it in the gap, g_s + (k Δs / A_s) λ_s = 0 on the active nodes:
    a compliance in series with the bodies, which makes the update stable whatever the
    step (the explicit one, the wear of the step's start, oscillates with too few steps).
    The worn volume Σ Δh_s A_s is k Δs Σ λ_s exactly, a discrete identity of the
    integration: k F_n Δs with F_n the sum of the nodal normal forces (on a flat face, the
    normal force; on a curved one, more than the resultant).

    The sliding is its distance per step, not a motion of the mesh: a pin sliding on a
    long flat track meets the same flat everywhere (the track's own wear, spread over its
    length, is left out).

    Args:
        contact: the pair's active set (`PairContact`), its slave surface the worn one.
        k: the wear coefficient (volume per unit force and sliding distance), or one per
            pair (`ContactPair.part`; 0: a pair that does not wear).
    """

    def __init__(self, contact: PairContact, k):
        k = np.asarray(k, dtype=float)
        if not (np.all(np.isfinite(k)) and np.all(k >= 0) and np.any(k > 0)):
            raise ValueError(f"the wear coefficient must be > 0, got {k}")
        if isinstance(contact, FrictionalPair):
            raise ValueError("wear on a pair with friction is not built (the wear's "
                             "compliance is in the frictionless loop)")
        self.contact = contact
        self.k = k[contact.pair.part] if k.ndim else k
        self.depth = np.zeros(len(contact.pair.slave))  # each owned slave node's wear
        self.distance = 0.0

    def slide(self, ds) -> SolveResult:
        """The contact and the wear of a sliding distance `ds` (the step's end pressure).

        Args:
            ds: the sliding distance of the step, or one per pair (`ContactPair.part`).

        Returns:
            The contact solve's result.
        """
        ds = np.asarray(ds, dtype=float)
        if not (np.all(np.isfinite(ds)) and np.all(ds > 0)):
            raise ValueError(f"the sliding distance of a step must be > 0, got {ds}")
        contact, pair = self.contact, self.contact.pair
        areas = np.where(pair.areas > 0, pair.areas, np.inf)  # a node of no area: no wear
        contact.compliance = self.k * (ds[pair.part] if ds.ndim else ds) / areas
        try:
            result = contact.solve()
        finally:
            c, contact.compliance = contact.compliance, None
        dh = c * np.where(contact.active, contact.lam, 0.0)
        self.depth += dh
        pair.open(dh)  # the worn slave surface moves away from the master
        self.distance = self.distance + ds  # (one per pair if ds is)
        return result

    @property
    def volume(self) -> float:
        """The worn volume so far, Σ h_s A_s (every rank's)."""
        return float(self.volumes().sum())

    def volumes(self) -> np.ndarray:
        """The worn volume of each pair (`ContactPair.part`; every rank's)."""
        pair = self.contact.pair
        parts = pair.comm.allreduce(int(pair.part.max(initial=0)), op=MPI.MAX) + 1
        return np.array([pair.total((self.depth * pair.areas)[pair.part == k])
                         for k in range(parts)])

    def checkpoint_arrays(self) -> dict[str, np.ndarray]:
        """The wear so far: each owned slave node's depth and the distance."""
        return {"depth": self.depth.copy(),
                "distance": np.atleast_1d(self.distance).astype(float)}

    def restore_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """The wear of `checkpoint_arrays` back, the slave surface worn by it again."""
        pair = self.contact.pair
        pair.open(arrays["depth"] - self.depth)
        self.depth = arrays["depth"].copy()
        distance = arrays["distance"].copy()
        self.distance = distance if np.ndim(self.distance) else float(distance[0])
