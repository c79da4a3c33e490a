"""Dirichlet conditions on facets: whole vector or one component."""

from __future__ import annotations

import numpy as np
from dolfinx import fem


def fixed(V: fem.FunctionSpace, facets: np.ndarray) -> fem.DirichletBC:
    """u = 0 on `facets`."""
    fdim = V.mesh.topology.dim - 1
    dofs = fem.locate_dofs_topological(V, fdim, facets)
    return fem.dirichletbc(fem.Function(V), dofs)  # a zero Function: works for any shape


def component(V: fem.FunctionSpace, i: int, facets: np.ndarray, value: float = 0.0
              ) -> fem.DirichletBC:
    """u_i = value on `facets` (located through the collapsed sub-space, see CONVENTIONS)."""
    fdim = V.mesh.topology.dim - 1
    Vi, _ = V.sub(i).collapse()
    dofs = fem.locate_dofs_topological((V.sub(i), Vi), fdim, facets)
    g = fem.Function(Vi)
    g.x.array[:] = value
    return fem.dirichletbc(g, dofs, V.sub(i))
