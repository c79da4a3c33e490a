"""The candidate contact surface S_C: its nodes, normal, gap, nodal areas and status meshtags.

S_C is a set of boundary facets, flat, with outward normal n = ±e_axis, facing a rigid
obstacle at gap γ(x) along n. Its *nodes* are the dofs of the displacement's normal
component on those facets (vertices for P1, vertices and edge midpoints for P2). A node's
status (active or not; later stick or slip) is a boolean array over these nodes, kept equal
on the ranks that share a node (`sync`). Everything a contact formulation or a scene needs
to know about S_C is here, in public names.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import ufl
from dolfinx import fem, la, mesh
from dolfinx.fem import petsc
from mpi4py import MPI
from petsc4py import PETSc

from fenics_nl.materials.mixed import collapsed
from fenics_nl.parallel import gather_rows

__all__ = ["ContactSurface", "check_contact_resolution", "nodal_quadrature", "vertex_of_dof"]

MIN_NODES = 4  # S_C nodes in contact below which a, p0 and P mean nothing
FEW_NODES = 10  # below this, a and p0 are coarse: say so


class ContactSurface:
    """Nodes of S_C for the displacement space V, and the obstacle's gap at them.

    `V` is the unknown's space, or its displacement part (`W.sub(0)` of the mixed
    formulation), and then `unknown_space` is W: node dofs (`dofs_V`) are in W's numbering.
    """

    def __init__(self, V: fem.FunctionSpace, facets: np.ndarray,
                 gap: Callable[[np.ndarray], np.ndarray], *, normal_axis: int,
                 normal_sign: int = 1, unknown_space: fem.FunctionSpace | None = None):
        self.V, self.mesh = V, V.mesh
        self.W = unknown_space or V
        # every displacement dof in the unknown's numbering (all of them without a pressure)
        self.displacement_dofs = (slice(None) if self.W is V
                                  else collapsed(V)[1])
        self.comm = self.mesh.comm
        self.axis, self.sign = normal_axis, int(np.sign(normal_sign))
        self.facets = np.asarray(facets, dtype=np.int32)
        if self.comm.allreduce(len(self.facets)) == 0:
            raise ValueError("the contact surface has no facets (missing or wrong tag?)")
        fdim = self.mesh.topology.dim - 1
        if V.num_sub_spaces == 0:  # one component (a bar): no sub-space to extract
            self.Vn, self.component = V, V
            self.dofs_V = self.dofs_n = fem.locate_dofs_topological(V, fdim, self.facets)
        else:
            self.component = V.sub(self.axis)
            self.Vn, _ = self.component.collapse()
            dofs = fem.locate_dofs_topological((self.component, self.Vn), fdim, self.facets)
            self.dofs_V, self.dofs_n = dofs[0], dofs[1]
        self.x = self.Vn.tabulate_dof_coordinates()[self.dofs_n]
        self.g = fem.Function(self.Vn)  # u_axis = sign·γ, prescribed on active nodes
        self.set_gap(gap)
        self.vertices = vertex_of_dof(self.Vn)[self.dofs_n]  # −1: not at a vertex
        self._flags = la.vector(self.Vn.dofmap.index_map)
        self._areas: dict = {}
        self._tangential: dict = {}

    # -- nodes --------------------------------------------------------------------------

    @property
    def owned(self) -> np.ndarray:
        """Mask of the nodes this rank owns (counts and sums use only these)."""
        return self.dofs_n < self.Vn.dofmap.index_map.size_local

    def sync(self, local: np.ndarray) -> np.ndarray:
        """A nodal flag array with the owners' values pushed to the ghosts.

        Args:
            local: one flag per node of S_C (this rank's view).

        Returns:
            The flags with every shared node's value its owner's (bool array).
        """
        self._flags.array[:] = 0.0
        self._flags.array[self.dofs_n] = local
        self._flags.scatter_forward()
        return self._flags.array[self.dofs_n] > 0.5

    def count(self, mask: np.ndarray) -> int:
        """Global number of nodes in `mask`.

        Args:
            mask: one flag per node of S_C.

        Returns:
            How many nodes of `mask` there are on all ranks (each node once).
        """
        return self.comm.allreduce(int(np.sum(mask & self.owned)))

    def total(self, values: np.ndarray) -> float:
        """Σ values over the nodes, every rank's owned ones.

        Args:
            values: one value per node of S_C.

        Returns:
            Their sum over all ranks (each node once).
        """
        return self.comm.allreduce(float(np.sum(values[self.owned])))

    def gathered(self, *columns: np.ndarray) -> tuple[np.ndarray, ...] | None:
        """Nodal arrays gathered on rank 0 (each node once), sorted by the first; else None.

        For a profile along the surface: `gathered(r, p, active)`. Collective.

        Args:
            columns: arrays of one value per node of S_C (this rank's view); the first is
                the sort key.

        Returns:
            On rank 0, each column over every rank's owned nodes, sorted (stably) by the
            first; None on the other ranks.
        """
        rows = gather_rows(self.comm, *(np.asarray(c)[self.owned] for c in columns))
        if rows is None:
            return None
        order = np.argsort(rows[0], kind="stable")
        return tuple(c[order] for c in rows)

    def fingerprint(self, mask: np.ndarray) -> tuple[int, int]:
        """Global signature of a node set: its size and the sum of its global indices.

        Args:
            mask: one flag per node of S_C.

        Returns:
            (size, sum of global indices), the same on every rank; equal for equal sets (and,
            rarely, for two different ones).
        """
        im = self.Vn.dofmap.index_map
        gidx = im.local_to_global(self.dofs_n[mask & self.owned].astype(np.int32))
        return (self.comm.allreduce(len(gidx)),
                self.comm.allreduce(int(np.sum(gidx, dtype=np.int64))))

    # -- gap and geometry ---------------------------------------------------------------

    def set_gap(self, gap: Callable[[np.ndarray], np.ndarray]) -> None:
        """New obstacle position: γ at the nodes, and the prescribed normal displacement.

        Args:
            gap: γ(x) for the points x (3 × n): the obstacle's distance along n.
        """
        self.gamma = np.asarray(gap(self.x.T), dtype=float)
        self.g.x.array[self.dofs_n] = self.sign * self.gamma

    def normal_displacement(self, u: fem.Function) -> np.ndarray:
        """u_n = n·u at the nodes.

        Args:
            u: the unknown (its displacement part is read).

        Returns:
            u_n at each node of S_C.
        """
        return self.sign * u.x.array[self.dofs_V]

    def normal_gap(self, u: fem.Function) -> np.ndarray:
        """u_n − γ at the nodes (positive = penetration).

        Args:
            u: the unknown.

        Returns:
            u_n − γ at each node of S_C.
        """
        return self.normal_displacement(u) - self.gamma

    def nodal_areas(self, weight=1.0) -> np.ndarray:
        """Lumped areas m_j at the nodes (w = 2πr in the axisymmetric model).

        Row sums m_j = ∫_{S_C} φ_j w ds; where they vanish (the vertices of P2 triangles,
        whose basis functions integrate to zero) the diagonal (HRZ) lumping instead:
        m_j ∝ ∫ φ_j² w ds, scaled to the same total area. Every m_j is then positive.

        Args:
            weight: the measure's weight (a UFL expression, or 1).

        Returns:
            m_j at each node of S_C (cached per weight).
        """
        key = id(weight) if not isinstance(weight, float | int) else float(weight)
        if key not in self._areas:
            fdim = self.mesh.topology.dim - 1
            tags = mesh.meshtags(self.mesh, fdim, np.sort(self.facets),
                                 np.ones(len(self.facets), dtype=np.int32))
            ds = ufl.Measure("ds", domain=self.mesh, subdomain_data=tags)(1)
            v_n = self._normal_part(ufl.TestFunction(self.W))
            m = self._at_nodes(petsc.assemble_vector(fem.form(v_n * weight * ds)))
            if self.comm.allreduce(bool(np.any(m[self.owned] <= 1e-12 * np.abs(m).max(initial=0))),
                                   op=MPI.LOR):
                w_n = self._normal_part(ufl.TrialFunction(self.W))
                M = petsc.assemble_matrix(fem.form(w_n * v_n * weight * ds))
                M.assemble()
                diagonal = petsc.create_vector(self.W)  # ghosted, like the row sums
                M.getDiagonal(diagonal)
                d = self._at_nodes(diagonal)
                M.destroy()
                m = d * self.total(m) / self.total(d)
            self._areas[key] = m
        return self._areas[key]

    def _normal_part(self, argument):
        """n-component of the displacement part of a test or trial function of W."""
        if self.W is not self.V:
            argument = ufl.split(argument)[0]
        return argument[self.axis] if ufl.shape(argument) else argument

    def displacement_scale(self, u: fem.Function) -> float:
        """The largest displacement component of `u`: a length scale of the current state.

        The pressure of a mixed unknown is left out.

        Args:
            u: the unknown.

        Returns:
            max |u_i| over the displacement dofs, on all ranks.
        """
        values = u.x.array[self.displacement_dofs]
        return self.comm.allreduce(float(np.abs(values).max(initial=0.0)), op=MPI.MAX)

    def _at_nodes(self, b: PETSc.Vec) -> np.ndarray:
        """An assembled vector's values at the nodes (owned and ghosts); destroys b."""
        b.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
        b.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        with b.localForm() as loc:
            values = loc.array_r[self.dofs_V].copy()
        b.destroy()
        return values

    def dirichlet(self, mask: np.ndarray) -> fem.DirichletBC:
        """u_n = γ on the nodes of `mask`.

        Args:
            mask: the nodes to hold (the active set).

        Returns:
            The Dirichlet condition on the normal component, with the current γ (sign included).
        """
        if self.component is self.Vn:
            return fem.dirichletbc(self.g, self.dofs_V[mask])
        return fem.dirichletbc(self.g, [self.dofs_V[mask], self.dofs_n[mask]], self.component)

    # -- tangential directions (friction) ------------------------------------------------

    @property
    def tangential_axes(self) -> list[int]:
        """The coordinate axes along S_C (every axis but the normal one)."""
        return [i for i in range(self.mesh.geometry.dim) if i != self.axis]

    def tangential(self, i: int) -> tuple[np.ndarray, fem.Function]:
        """(dofs of displacement component `i` at the nodes, a Function for its values).

        The dofs are in the unknown's numbering; the Function is on the component's space,
        for the Dirichlet values of sticking nodes.

        Component spaces share one layout (checked), so node j is dof `dofs_n[j]` in each.

        Args:
            i: a tangential axis (one of `tangential_axes`).

        Returns:
            (the dofs of component i at the nodes, in the unknown's numbering; a Function on
            the component's space).
        """
        if i not in self._tangential:
            part = self.V.sub(i)
            space, parent = collapsed(part)
            same = np.array_equal(space.tabulate_dof_coordinates()[self.dofs_n], self.x)
            if not self.comm.allreduce(same, op=MPI.LAND):
                raise RuntimeError("displacement components with different dof layouts")
            self._tangential[i] = (parent[self.dofs_n], fem.Function(space))
        return self._tangential[i]

    def tangential_dirichlet(self, i: int, mask: np.ndarray, values: np.ndarray
                             ) -> fem.DirichletBC:
        """u_i = `values` (one per node) on the nodes of `mask`.

        Args:
            i: a tangential axis.
            mask: the nodes to hold (the sticking ones).
            values: u_i at every node of S_C (those of `mask` are used).

        Returns:
            The Dirichlet condition on component i.
        """
        dofs, g = self.tangential(i)
        g.x.array[self.dofs_n] = values
        return fem.dirichletbc(g, [dofs[mask], self.dofs_n[mask]], self.V.sub(i))

    # -- output -------------------------------------------------------------------------

    def nodal_field(self, values: np.ndarray, name: str) -> fem.Function:
        """A function on the normal component's space: `values` at the nodes, 0 elsewhere.

        Args:
            values: one value per node of S_C.
            name: the Function's name (in the output files).

        Returns:
            The Function, ghosts updated.
        """
        f = fem.Function(self.Vn, name=name)
        f.x.array[self.dofs_n] = values
        f.x.scatter_forward()
        return f

    def vertex_tags(self, mask: np.ndarray) -> mesh.MeshTags:
        """Vertex meshtags (value 1) of the nodes of `mask` that are mesh vertices.

        Args:
            mask: one flag per node of S_C.

        Returns:
            Vertex meshtags, value 1 on the vertices in `mask`.
        """
        verts = self.vertices[mask]
        verts = np.sort(verts[verts >= 0]).astype(np.int32)
        return mesh.meshtags(self.mesh, 0, verts, np.ones(len(verts), dtype=np.int32))

    def facet_tags(self, mask: np.ndarray) -> mesh.MeshTags:
        """Facet meshtags of S_C: 1 where every vertex of the facet is in `mask`, else 0.

        Args:
            mask: one flag per node of S_C (the active set).

        Returns:
            Facet meshtags of every facet of S_C, sorted, valued 1 or 0.
        """
        fdim = self.mesh.topology.dim - 1
        self.mesh.topology.create_connectivity(fdim, 0)
        f2v = self.mesh.topology.connectivity(fdim, 0)
        imap = self.mesh.topology.index_map(0)
        in_mask = np.zeros(imap.size_local + imap.num_ghosts, dtype=bool)
        verts = self.vertices[mask]
        in_mask[verts[verts >= 0]] = True
        values = np.array([in_mask[f2v.links(f)].all() for f in self.facets], dtype=np.int32)
        order = np.argsort(self.facets)
        return mesh.meshtags(self.mesh, fdim, self.facets[order], values[order])


def check_contact_resolution(nodes: int, h: float, state) -> list[str]:
    """Refuse a contact zone of fewer than MIN_NODES nodes, warn below FEW_NODES.

    Args:
        nodes: the active nodes (all ranks).
        h: the element size under the contact.
        state: a converged state with its total `force` and `contact_radius`.

    Returns:
        The warnings, one below FEW_NODES, none when the zone is resolved or there is no
        contact.

    Raises:
        ValueError: fewer than MIN_NODES nodes in contact under a positive force.
    """
    if state.force > 0 and nodes < MIN_NODES:
        raise ValueError(f"only {nodes} node(s) of the surface are in contact (h = {h:.3g}, "
                         f"contact radius {state.contact_radius:.3g}): the mesh cannot "
                         f"resolve the contact zone; raise --refine or check the load")
    if state.force > 0 and nodes < FEW_NODES:
        return [f"only {nodes} nodes in contact: contact radius and p0 are resolved to about "
                f"h = {h:.3g} only"]
    return []


def nodal_quadrature(degree: int, facet_dim: int) -> dict:
    """Form metadata for a rule on S_C whose points are the nodes of degree `degree`.

    Integrals become nodal sums with positive weights (the nodal areas): the vertex rule
    for P1, Gauss–Lobatto's 3 points (h/6, 2h/3, h/6) for P2 on edges. A P2 triangle has
    no such rule (its vertex weights vanish): a ValueError.

    Args:
        degree: the Lagrange degree of the nodes (1 or 2).
        facet_dim: the facets' dimension (1: edges, 2: triangles).

    Returns:
        The measure's metadata (the quadrature rule and its degree).

    Raises:
        ValueError: P2 on triangles.
    """
    if degree == 1:
        return {"quadrature_rule": "vertex", "quadrature_degree": 1}
    if degree == 2 and facet_dim == 1:
        return {"quadrature_rule": "GLL", "quadrature_degree": 2}
    raise ValueError("no nodal rule with positive weights on P2 triangles (3D): use the "
                     "elimination")


def vertex_of_dof(V: fem.FunctionSpace) -> np.ndarray:
    """Mesh vertex of each dof of a scalar Lagrange space, −1 for dofs not at a vertex.

    A Lagrange cell on simplices numbers its vertex dofs first, in the order of the cell's
    vertices (checked: other cells are refused).

    Args:
        V: a scalar Lagrange space.

    Returns:
        One mesh vertex per local dof, −1 where the dof is not at a vertex.
    """
    topo = V.mesh.topology
    if topo.cell_type not in (mesh.CellType.interval, mesh.CellType.triangle,
                              mesh.CellType.tetrahedron):
        raise ValueError(f"contact surfaces are written for simplex meshes, got {topo.cell_type}")
    tdim = topo.dim
    topo.create_connectivity(tdim, 0)
    c2v = topo.connectivity(tdim, 0).array.reshape(-1, tdim + 1)
    dofs = V.dofmap.list[:, : tdim + 1]
    out = np.full(V.dofmap.index_map.size_local + V.dofmap.index_map.num_ghosts, -1,
                  dtype=np.int32)
    out[dofs.ravel()] = c2v[: dofs.shape[0]].ravel()
    return out

