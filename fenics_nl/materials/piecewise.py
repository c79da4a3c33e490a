"""A material per cell group: bodies (or layers, or a wall in a ground) of different laws.

Each *part* is a law on the cells of its groups; the internal work is the sum of each law's
over its cells, `Σ_p w_p(u; v) dx(tags_p)`, with `dx` carrying the mesh's cell tags. Where a
single expression of the whole mesh is wanted (the stress to probe or draw), each law's is
weighted by its part's indicator χ_p (a DG0 function, 1 on the part's cells).

Construction stages (`fenics_nl.construction`) make the parts come and go: `follow` takes
their presence indicators for χ_p (a dug part's cells weigh 0) and the strain each cell's
law measures from (`arrival_strain`: a wall is stress-free when it arrives). Then a group
may be in two parts (soil, then the wall that replaces it), and every law is small strain.

A path-dependent law (J2, Drucker–Prager, Mohr–Coulomb: a `SmallStrainPlasticity`) keeps
its state on the quadrature points of the whole mesh but commits it only on its part's
present cells: elsewhere it stays as it was bound (virgin), so a part that arrives starts
from no plastic strain, and what a law reports (its plastic zone) is its part's.
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.materials import kinematics
from fenics_nl.materials.laws import LinearElastic, Material, von_mises_of
from fenics_nl.materials.plasticity import SmallStrainPlasticity

__all__ = ["ByGroup"]


class ByGroup(Material):
    """Laws by cell tag, as one material.

    Args:
        laws: the law of each cell tag, `{tag: law}`; or each part's tags and law,
            `{name: (tags, law)}` (a tag may be in two parts when stages follow, `follow`).
            Every cell of the mesh in one of them.
        cell_tags: the mesh's cell tags (DOLFINx meshtags).
    """

    def __init__(self, laws: dict, cell_tags):
        if not laws:
            raise ValueError("laws: at least one group")
        self.parts = {key: ((key,), value) if isinstance(value, Material)
                      else (tuple(value[0]), value[1]) for key, value in laws.items()}
        self.laws = {key: law for key, (_, law) in self.parts.items()}
        kept = [law for law in self.laws.values() if law.path_dependent]
        if any(not isinstance(law, SmallStrainPlasticity) for law in kept):
            raise ValueError("laws: the path-dependent laws a group takes are the small-"
                             "strain plastic ones (J2, Drucker–Prager, Mohr–Coulomb), whose "
                             "state is committed on their part's cells")
        if len({law.finite_strain for law in self.laws.values()}) > 1:
            raise ValueError("laws: all small strain or all finite strain (the kinematics "
                             "is the body's)")
        self.cell_tags = cell_tags
        first = next(iter(self.laws.values()))
        self.finite_strain = first.finite_strain
        self.is_linear = all(law.is_linear for law in self.laws.values())
        self.path_dependent = bool(kept)
        self._indicators: dict = {}
        self.arrival_strain = None  # `follow`: the strain each cell's law measures from

    # -- the parts ----------------------------------------------------------------------

    def follow(self, construction) -> None:
        """Take the stages' parts: their presence for χ_p, their arrival strain.

        Call it before writing a form. Its parts must be this material's (same names).

        Args:
            construction: a `fenics_nl.construction.Construction` with a part of each name.
        """
        if set(construction.present) != set(self.parts):
            raise ValueError(f"the construction's parts {sorted(construction.present)} are "
                             f"not the material's {sorted(self.parts)}")
        if self.finite_strain:
            raise ValueError("construction stages take small-strain laws")
        self._indicators = dict(construction.present)
        self.arrival_strain = construction.arrival_strain

    def indicator(self, mesh, key) -> fem.Function:
        """χ_p: 1 on the cells where part `key` is (DG0; made once, or the stages')."""
        if key not in self._indicators:
            Q = fem.functionspace(mesh, ("DG", 0))
            chi = fem.Function(Q, name=f"group_{key}")
            for tag in self.parts[key][0]:
                chi.x.array[Q.dofmap.list[self.cell_tags.find(tag)].ravel()] = 1.0
            chi.x.scatter_forward()
            self._indicators[key] = chi
        return self._indicators[key]

    def measure(self, dx: ufl.Measure) -> ufl.Measure:
        """`dx` with the cell tags: `dx(tag)` integrates over a group."""
        return dx(subdomain_data=self.cell_tags)

    def law_strain(self, eps):
        """The strain a law measures: ε, less the arrival strain when stages follow."""
        return eps if self.arrival_strain is None else eps - self.arrival_strain

    def _law_work(self, law, u, v, model: str):
        if self.arrival_strain is None:
            return law.internal_work(u, v, model)
        eps_u, eps_v = (kinematics.small_strain(w, model) for w in (u, v))
        weight = kinematics.measure_weight(kinematics.domain(u), model)
        return ufl.inner(law.stress(self.law_strain(eps_u)), eps_v) * weight

    def work(self, u, v, model: str, dx: ufl.Measure):
        """Σ_p χ_p w_p(u; v) dx(tags_p): each law's internal work over its cells (UFL form).

        χ_p only when stages follow (it is 1 on a part's own cells otherwise).
        """
        dxg, mesh = self.measure(dx), u.function_space.mesh
        total = 0
        for key, (tags, law) in self.parts.items():
            w = self._law_work(law, u, v, model)
            if self.arrival_strain is not None:
                w = self.indicator(mesh, key) * w
            total += w * dxg(tags)
        return total

    def _weighted(self, mesh, of):
        return sum(self.indicator(mesh, key) * of(law) for key, law in self.laws.items())

    # -- the law's interface, each part on its cells -------------------------------------

    def energy(self, strain):
        """The free energy of the strain, each group's law on its cells."""
        mesh = ufl.domain.extract_unique_domain(strain)
        return self._weighted(mesh, lambda law: law.energy(self.law_strain(strain)))

    def stress(self, eps):
        """Σ_p χ_p σ_p(ε): the stress of each cell's law (small strain)."""
        mesh = ufl.domain.extract_unique_domain(eps)
        return self._weighted(mesh, lambda law: law.stress(self.law_strain(eps)))

    def internal_work(self, u, v, model: str = "3d"):
        """Σ_p χ_p w_p(u; v): every law evaluated everywhere (`work` integrates by group)."""
        return self._weighted(u.function_space.mesh,
                              lambda law: self._law_work(law, u, v, model))

    def cauchy_stress(self, u, model: str = "3d"):
        """Σ_p χ_p σ_p(u): the stress of each cell's law."""
        if self.arrival_strain is not None:
            return self.stress(kinematics.small_strain(u, model))
        return self._weighted(u.function_space.mesh, lambda law: law.cauchy_stress(u, model))

    def initial(self, like):
        """Σ_p χ_p σ0_p: the initial stress of the parts whose law has one (UFL, 3x3)."""
        mesh = ufl.domain.extract_unique_domain(like)
        return sum((self.indicator(mesh, key) * law.initial(like)
                    for key, law in self.laws.items() if hasattr(law, "initial")),
                   ufl.zero(3, 3))

    def modified_newton_tangent(self, u, model: str, dx):
        """Each part's constant tangent on its cells: Hooke's for a plastic law (its E, ν).

        A state-free law's own tangent at the displacement the solver assembles it at
        (exact for Hooke's law, whose tangent is constant). "initial" if no law is
        path-dependent (the tangent at each solve's start, as one law's).
        """
        if not self.path_dependent:
            return "initial"
        dxg, mesh = self.measure(dx), u.function_space.mesh
        v = ufl.TestFunction(u.function_space)
        total = 0
        for key, (tags, law) in self.parts.items():
            chi = self.indicator(mesh, key) if self.arrival_strain is not None else 1
            kept = LinearElastic(law.E, law.nu) if law.path_dependent else law
            total += chi * self._law_work(kept, u, v, model) * dxg(tags)
        return ufl.derivative(total, u)

    # -- the path-dependent parts' state -------------------------------------------------

    def _kept(self):
        """(key, law) of each path-dependent part."""
        return [(key, law) for key, law in self.laws.items() if law.path_dependent]

    def bind(self, mesh, degree: int) -> None:
        """Create each path-dependent law's state at the quadrature points (zero)."""
        for _, law in self._kept():
            law.bind(mesh, degree)

    def _present_cells(self, key, mesh) -> np.ndarray:
        chi = self.indicator(mesh, key)
        dofs = chi.function_space.dofmap.list[:, 0]
        return np.flatnonzero(chi.x.array[dofs] > 0).astype(np.int32)

    def commit(self, u, model: str = "3d") -> None:
        """Commit each path-dependent law's state on its part's present cells."""
        mesh = u.function_space.mesh
        eps = kinematics.small_strain(u, model)
        for key, law in self._kept():
            law.commit_strain(self.law_strain(eps), self._present_cells(key, mesh))

    def reset(self) -> None:
        """Every law back to its virgin state."""
        for _, law in self._kept():
            law.reset()

    def state_functions(self) -> dict:
        """Each path-dependent part's state Functions, named "<part>.<name>"."""
        return {f"{key}.{name}": f for key, law in self._kept()
                for name, f in law.state_functions().items()}

    def quadrature_space(self):
        """The scalar quadrature space of the state (the first path-dependent law's)."""
        return self._kept()[0][1].quadrature_space()

    @property
    def cumulated_plastic_strain(self):
        """Σ_p χ_p p_p: the cumulated plastic strain of each cell's law (UFL; 0 if none)."""
        mesh = self.quadrature_space().mesh
        return sum(self.indicator(mesh, key) * law.cumulated_plastic_strain
                   for key, law in self._kept())

    def _per_cell(self, of):
        """Σ_p χ_p of(law) over the path-dependent parts, per cell (DG0 Functions)."""
        mesh = self.quadrature_space().mesh
        out = None
        for key, law in self._kept():
            f, chi = of(law), self.indicator(mesh, key).x.array
            f.x.array[:] *= np.repeat(chi, f.x.array.size // chi.size)  # (each block its cell's)
            if out is None:
                out = f
            else:
                out.x.array[:] += f.x.array
        return out

    def cumulated_plastic_strain_per_cell(self):
        """The largest committed p of each cell's points, its own law's (DG0)."""
        return self._per_cell(lambda law: law.cumulated_plastic_strain_per_cell())

    def output_fields(self) -> list:
        """p (cell max) and ε_p (cell mean) of each cell's law, DG0 (as one law's)."""
        return [self.cumulated_plastic_strain_per_cell(),
                self._per_cell(lambda law: law.plastic_strain_per_cell())]

    def plastic_zone(self, dx) -> dict:
        """The largest p of the parts present, and the plastic share of their volume.

        Args:
            dx: the measure of the residual (the state's quadrature rule).

        Returns:
            A dict of floats, the same on every rank (collective):
            "max_cumulated_plastic_strain" and "plastic_volume_fraction".
        """
        mesh = self.quadrature_space().mesh
        comm = mesh.comm
        n = mesh.topology.index_map(mesh.topology.dim).size_local
        p = self.cumulated_plastic_strain_per_cell()
        present = sum(self.indicator(mesh, key) for key in self.laws)
        yielded = self.cumulated_plastic_strain
        volume, plastic = (comm.allreduce(fem.assemble_scalar(fem.form(f * dx)))
                           for f in (present, ufl.conditional(ufl.gt(yielded, 0), 1.0, 0.0)))
        return {"max_cumulated_plastic_strain": comm.allreduce(
                    float(p.x.array[:n].max(initial=0.0)), op=MPI.MAX),
                "plastic_volume_fraction": plastic / volume}

    def von_mises(self, u, model: str = "3d"):
        """σ_eq per cell (DG0): at the quadrature points if a law keeps a state there."""
        if not self.path_dependent:
            return super().von_mises(u, model)
        law = self._kept()[0][1]
        return law.cell_mean(von_mises_of(self.cauchy_stress(u, model)), "von_mises")

    def cells_without(self, num_cells: int) -> np.ndarray:
        """The local cells (of `num_cells`) in no group: a body without a material."""
        tagged = np.zeros(num_cells, dtype=bool)
        for tags, _ in self.parts.values():
            for tag in tags:
                cells = self.cell_tags.find(tag)
                tagged[cells[cells < num_cells]] = True
        return np.flatnonzero(~tagged)
