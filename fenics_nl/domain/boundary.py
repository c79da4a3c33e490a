"""Tags on a mesh, and on tagged facets Dirichlet conditions and reactions.

`tags_where` tags entities by predicates; `fixed` and `component` hold the whole vector or
one component; `reactions` reads the supports' forces.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from dolfinx import fem, mesh

__all__ = ["component", "fixed", "out_of_balance", "reactions", "tags_where"]


def tags_where(msh: mesh.Mesh, dim: int, marked: dict[int, Callable], *,
               boundary: bool = True) -> mesh.MeshTags:
    """The entities of dimension `dim` where each marker holds, tagged with its key.

    Sorted and each entity once, as `dolfinx.mesh.meshtags` needs (an entity two markers
    hold keeps the first one's tag).

    Args:
        msh: the mesh.
        dim: the entities' dimension (the facets': msh.topology.dim − 1).
        marked: {tag value: a predicate of the coordinates x (3, n), as
            `dolfinx.mesh.locate_entities` takes}.
        boundary: look on the boundary only (`locate_entities_boundary`).

    Returns:
        The meshtags.
    """
    entities, values = np.empty(0, dtype=np.int32), np.empty(0, dtype=np.int32)
    for tag, where in marked.items():
        found = (mesh.locate_entities_boundary(msh, dim, where) if boundary
                 else mesh.locate_entities(msh, dim, where))
        found = np.setdiff1d(found, entities).astype(np.int32)
        entities = np.concatenate([entities, found])
        values = np.concatenate([values, np.full(len(found), tag, dtype=np.int32)])
    order = np.argsort(entities)
    return mesh.meshtags(msh, dim, entities[order], values[order])


def fixed(V: fem.FunctionSpace, facets: np.ndarray) -> fem.DirichletBC:
    """u = 0 on `facets` (V may be the displacement part of a mixed space)."""
    fdim = V.mesh.topology.dim - 1
    if V.component():  # a sub-space: located through its collapsed space, as `component`
        Vc, _ = V.collapse()
        dofs = fem.locate_dofs_topological((V, Vc), fdim, facets)
        return fem.dirichletbc(fem.Function(Vc), dofs, V)
    dofs = fem.locate_dofs_topological(V, fdim, facets)
    return fem.dirichletbc(fem.Function(V), dofs)  # a zero Function: works for any shape


def component(V: fem.FunctionSpace, i: int, facets: np.ndarray, value: float = 0.0
              ) -> fem.DirichletBC:
    """u_i = value on `facets`.

    On a blocked space, `locate_dofs_topological(V, ...)` returns block indices; one
    component is located through the pair (V.sub(i), its collapsed space), whose dofs
    `dirichletbc` expects (passing unrolled indices instead corrupts memory).
    """
    fdim = V.mesh.topology.dim - 1
    Vi, _ = V.sub(i).collapse()
    dofs = fem.locate_dofs_topological((V.sub(i), Vi), fdim, facets)
    g = fem.Function(Vi)
    g.x.array[:] = value
    return fem.dirichletbc(g, dofs, V.sub(i))


def reactions(residual: fem.Form | object, u: fem.Function, groups: dict[str, np.ndarray],
              components: dict[str, list[int]] | None = None,
              space: fem.FunctionSpace | None = None) -> dict[str, list[float]]:
    """Resultant force on each facet group: Σ R(u) over its nodes, per component.

    R = f_int − f_ext assembled without any Dirichlet row, at the current u: on a supported
    group it is the force the support exerts on the body (an axisymmetric residual carries
    2πr, so this is the force on the whole revolution). `u` is the residual's unknown and
    `space` the displacement space, if it is a part of `u`'s (the mixed formulation's
    `W.sub(0)`). `components`: the components each group holds (default: all); the others
    are reported as 0. A node component held by several groups (the edge of a clamped bolt
    hole on a floor) counts in the first of them only: list the groups that hold a node
    fully (clamped) first. Collective.
    """
    from dolfinx.fem import petsc
    from mpi4py import MPI
    from petsc4py import PETSc

    W = u.function_space
    if space is None and W.ufl_element().is_mixed:
        raise ValueError("reactions on a mixed unknown: give its displacement part as `space`")
    V = space or W
    form = residual if isinstance(residual, fem.Form) else fem.form(residual)
    b = petsc.assemble_vector(form)
    b.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
    R = b.array_r.copy()
    b.destroy()
    n_owned = W.dofmap.index_map.size_local * W.dofmap.index_map_bs
    parts = [V.sub(i) for i in range(V.num_sub_spaces)] or [V]  # a scalar space: itself
    n_comp = len(parts)
    fdim = V.mesh.topology.dim - 1
    counted = np.zeros(R.size, dtype=bool)
    out = {}
    for name, facets in groups.items():
        total = np.zeros(n_comp)
        for i in (components or {}).get(name, range(n_comp)):
            # a component's dofs, in the numbering of u's space (unrolled)
            dofs = fem.locate_dofs_topological(parts[i], fdim, facets)
            dofs = dofs[dofs < n_owned]  # owned only: R and `counted` hold no ghosts
            mine = dofs[~counted[dofs]]
            counted[mine] = True
            total[i] = R[mine].sum()
        out[name] = [float(x) for x in V.mesh.comm.allreduce(total, op=MPI.SUM)]
    return out


def out_of_balance(residual, bcs=()) -> float:
    """‖R‖ at the present unknowns, the rows of `bcs` left out (their reactions). Collective.

    An equilibrium check: an initial stress against the loads at 0, a construction
    stage's start against the forces it froze.

    Args:
        residual: R (a UFL form or a compiled one).
        bcs: the Dirichlet conditions whose rows are not counted.
    """
    from dolfinx.fem import petsc
    from petsc4py import PETSc

    b = petsc.assemble_vector(residual if isinstance(residual, fem.Form) else fem.form(residual))
    b.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
    petsc.set_bc(b, list(bcs), alpha=0.0)
    norm = b.norm()
    b.destroy()
    return norm
