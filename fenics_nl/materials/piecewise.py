"""A material per cell group: bodies of different materials in one mesh.

Each law holds on the cells of its group; the internal work is the sum of each law's over
its cells, `Σ_g w_g(u; v) dx(g)`, with `dx` carrying the mesh's cell tags. Where a single
expression of the whole mesh is wanted (the stress to probe or draw), each law's is
weighted by its group's indicator (a DG0 function, 1 on the group's cells).

Only laws without internal variables: a path-dependent law's state lives on the
quadrature points of the whole mesh (`plasticity.StateAtPoints`), not of a group.
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem

from fenics_nl.materials.laws import Material

__all__ = ["ByGroup"]


class ByGroup(Material):
    """Laws by cell tag, as one material.

    Args:
        laws: the law of each cell tag (every cell of the mesh in one of them).
        cell_tags: the mesh's cell tags (DOLFINx meshtags).
    """

    def __init__(self, laws: dict[int, Material], cell_tags):
        if not laws:
            raise ValueError("laws: at least one group")
        if any(law.path_dependent for law in laws.values()):
            raise ValueError("laws: a path-dependent law takes the whole mesh (its state is "
                             "on every quadrature point), not one group")
        if len({law.finite_strain for law in laws.values()}) > 1:
            raise ValueError("laws: all small strain or all finite strain (the kinematics "
                             "is the body's)")
        self.laws, self.cell_tags = dict(laws), cell_tags
        first = next(iter(laws.values()))
        self.finite_strain = first.finite_strain
        self.is_linear = all(law.is_linear for law in laws.values())
        self._indicators: dict[int, fem.Function] = {}

    def indicator(self, mesh, tag: int) -> fem.Function:
        """1 on the cells of `tag`, 0 elsewhere (DG0; made once)."""
        if tag not in self._indicators:
            Q = fem.functionspace(mesh, ("DG", 0))
            chi = fem.Function(Q, name=f"group_{tag}")
            cells = self.cell_tags.find(tag)
            chi.x.array[Q.dofmap.list[cells].ravel()] = 1.0
            chi.x.scatter_forward()
            self._indicators[tag] = chi
        return self._indicators[tag]

    def measure(self, dx: ufl.Measure) -> ufl.Measure:
        """`dx` with the cell tags: `dx(tag)` integrates over a group."""
        return dx(subdomain_data=self.cell_tags)

    def work(self, u, v, model: str, dx: ufl.Measure):
        """Σ_g w_g(u; v) dx(g): each law's internal work over its cells (a UFL form)."""
        dxg = self.measure(dx)
        return sum(law.internal_work(u, v, model) * dxg(tag) for tag, law in self.laws.items())

    def _weighted(self, mesh, of):
        return sum(self.indicator(mesh, tag) * of(law) for tag, law in self.laws.items())

    def energy(self, strain):
        """The free energy of the strain, each group's law on its cells."""
        mesh = ufl.domain.extract_unique_domain(strain)
        return self._weighted(mesh, lambda law: law.energy(strain))

    def internal_work(self, u, v, model: str = "3d"):
        """Σ_g χ_g w_g(u; v): every law evaluated everywhere (`work` integrates by group)."""
        return self._weighted(u.function_space.mesh, lambda law: law.internal_work(u, v, model))

    def cauchy_stress(self, u, model: str = "3d"):
        """Σ_g χ_g σ_g(u): the stress of each cell's law."""
        return self._weighted(u.function_space.mesh, lambda law: law.cauchy_stress(u, model))

    def cells_without(self, num_cells: int) -> np.ndarray:
        """The local cells (of `num_cells`) in no group: a body without a material."""
        tagged = np.zeros(num_cells, dtype=bool)
        for tag in self.laws:
            cells = self.cell_tags.find(tag)
            tagged[cells[cells < num_cells]] = True
        return np.flatnonzero(~tagged)
