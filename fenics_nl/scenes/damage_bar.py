"""A bar in tension with a damage law: homogeneous, or with a weak spot where damage localizes.

The bar is a strip [0, L] x [0, H] of P1 quadrilaterals, one cell high (H = L/cells unless
given: keep it when refining, so that the cross-section stays), in plane strain at ν = 0:
a uniaxial stress state, the 1D bar of the course (σ = E ε (1 − α)). Its left end slides on
x = 0 (u_x = 0), its bottom on y = 0 (u_y = 0).

* `stretch(strain)`: the right end's displacement prescribed (the homogeneous state: a uniform
  bar stays uniform, its stress is the law's closed form).
* `load(λ)`: a traction λ σ_ref on the right end (σ_ref: the weak cell's critical stress),
  for arc-length continuation past the peak. With the first cell weakened, the damage
  localizes there; the arc measures that cell's opening (its right edge's displacement: its
  left edge is the held end), which grows monotonically while the stress falls, so that the
  snap-back of the whole bar's end displacement is followed.
"""

from __future__ import annotations

import math

import numpy as np
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.materials import kinematics
from fenics_nl.parallel import global_max

__all__ = ["BarStrip", "DamageBar", "localize", "uniform"]


class BarStrip:
    """The bar's geometry: its mesh, displacement, supports and right end (no material).

    Args:
        length: L.
        cells: cells along the bar (h = L/cells).
        height: H, the cross-section per unit thickness (default one cell's length).
    """

    MODEL = "plane_strain"

    def __init__(self, length: float, cells: int, *, height: float | None = None,
                 comm: MPI.Comm = MPI.COMM_WORLD):
        if cells < 2:
            raise ValueError(f"a bar needs at least 2 cells, got {cells}")
        self.L, self.cells = length, cells
        self.h = h = length / cells
        self.height = H = height or h
        self.mesh = msh = mesh.create_rectangle(comm, [[0.0, 0.0], [length, H]], [cells, 1],
                                                mesh.CellType.quadrilateral)
        self.V = V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
        self.u = fem.Function(V, name="displacement")

        def edge(where):
            return mesh.locate_entities_boundary(msh, 1, where)

        self.left = edge(lambda x: np.isclose(x[0], 0.0))
        self.right = edge(lambda x: np.isclose(x[0], length))
        self.supports = [boundary.component(V, 0, self.left),
                         boundary.component(V, 1, edge(lambda x: np.isclose(x[1], 0.0)))]
        self.cross_section = H  # per unit thickness
        # u_x at the right end: this rank's owned dofs there (read at every step)
        n = V.dofmap.index_map.size_local
        self._end_dofs = 2 * np.flatnonzero(np.isclose(V.tabulate_dof_coordinates()[:n, 0],
                                                       length))

    @property
    def dofs(self) -> int:
        """Global number of displacement unknowns."""
        im = self.V.dofmap.index_map
        return im.size_global * self.V.dofmap.index_map_bs

    def stretch_supports(self, strain: float) -> list:
        """The supports and the right end moved by strain · L (displacement control)."""
        return [*self.supports, boundary.component(self.V, 0, self.right, strain * self.L)]

    def end_displacement(self) -> float:
        """u_x at the right end."""
        return global_max(self.mesh.comm, self.u.x.array[self._end_dofs])

    def reaction_stress(self, internal) -> float:
        """σ from the right end's reaction to the internal work `internal` (a form in u)."""
        held = boundary.reactions(internal, self.u, {"right": self.right},
                                  {"right": [0]}, space=self.V)["right"][0]
        return held / self.cross_section


class DamageBar(BarStrip):
    """The bar, its damage material bound to it, its supports and its two ways of loading.

    Args:
        material: a damage law with `bind`, `weaken`, `commit`, `energy` (`CourseDamage`).
        length: L.
        cells: cells along the bar (its height is one cell, h = L/cells).
        weak: the first cell's w_c factor (1: a uniform bar).
        height: H, the cross-section per unit thickness (default one cell's length).
    """

    def __init__(self, material, length: float, cells: int, *, weak: float = 1.0,
                 height: float | None = None, comm: MPI.Comm = MPI.COMM_WORLD):
        if material.nu != 0:
            raise ValueError("the bar is the course's 1D bar: ν = 0 (uniaxial stress)")
        super().__init__(length, cells, height=height, comm=comm)
        self.material = material
        msh, V, h = self.mesh, self.V, self.h
        material.bind(msh, 2)
        self.dx = kinematics.quadrature_measure("dx", msh, 2)
        if weak != 1.0:
            first = mesh.locate_entities(msh, 2, lambda x: x[0] <= h * (1 + 1e-9))
            material.weaken(first, weak)
        self.weak = weak
        self.sigma_ref = math.sqrt(material.E * material.w_c * weak)
        tags = mesh.meshtags(msh, 1, self.right, np.ones(len(self.right), dtype=np.int32))
        ds = ufl.Measure("ds", msh, subdomain_data=tags)
        self.load_factor = fem.Constant(msh, 0.0)
        v = ufl.TestFunction(V)
        self.internal = material.internal_work(self.u, v, self.MODEL) * self.dx
        self.residual = self.internal - self.load_factor * self.sigma_ref * v[0] * ds(1)
        Vx, _ = V.sub(0).collapse()
        self.opening_dofs = fem.locate_dofs_geometrical(
            (V.sub(0), Vx), lambda x: np.isclose(x[0], h))[0]

    def set_load(self, lam: float) -> None:
        """The right end's traction λ σ_ref (force control, for arc-length)."""
        self.load_factor.value = lam

    def commit(self) -> None:
        """The converged state's damage becomes the committed one."""
        self.material.commit(self.u, self.MODEL)

    def reaction_stress(self) -> float:
        """σ from the right end's reaction under displacement control."""
        return super().reaction_stress(self.internal)

    def stored_energy(self) -> float:
        """The elastic energy of the committed state: ∫ (1 − α) W0 / 2."""
        eps = kinematics.small_strain(self.u, self.MODEL)
        value = fem.assemble_scalar(fem.form(self.material.energy(eps) * self.dx))
        return self.mesh.comm.allreduce(value, op=MPI.SUM)

    def damaged_cells(self) -> int:
        """Cells with some committed damage."""
        a = self.material.damage_per_cell()
        n = self.mesh.topology.index_map(2).size_local
        return self.mesh.comm.allreduce(int(np.count_nonzero(a.x.array[:n] > 0)),
                                        op=MPI.SUM)

    def largest_damage(self) -> float:
        """The largest committed α."""
        return global_max(self.mesh.comm, self.material.alpha.x.array)


def uniform(law, length: float, cells: int, strains, *, height: float,
            prefix: str = "bar_", on_step=None) -> tuple[list[tuple[float, float]], int]:
    """The uniform bar of `law` (`CourseDamage`) through `strains`, by Newton at each step.

    Returns the (strain, stress) of every step and the Newton iterations; `on_step(k, path)`
    after each converged step.
    """
    from fenics_nl.solvers.newton import NewtonSolver

    bar = DamageBar(law, length, cells, height=height)
    path, iterations = [], 0
    for strain in strains:
        solve = NewtonSolver(bar.residual, bar.u, bar.stretch_supports(strain), rtol=1e-12,
                             atol=1e-12, force_scale=law.critical_stress * bar.cross_section,
                             prefix=prefix)
        iterations += solve.solve().iterations
        bar.commit()
        path.append((float(strain), bar.reaction_stress()))
        if on_step:
            on_step(len(path) - 1, path)
    return path, iterations


def localize(law, length: float, cells: int, *, weak: float, height: float,
             stress_ratio: float, prefix: str = "bar_") -> dict:
    """The bar of `law` with a weak first cell, followed down to `stress_ratio` of its peak.

    Returns its path and its dissipated energy against A h w_c ln(1/ρ).

    The arc is measured on the weak cell's opening; the dissipated energy is the external
    work (trapezoids over the steps) less the stored elastic energy.
    """
    from fenics_nl.solvers.arclength import ArcLength
    from fenics_nl.solvers.newton import NewtonSolver

    b = DamageBar(law, length, cells, weak=weak, height=height)
    solver = NewtonSolver(b.residual, b.u, b.supports, rtol=1e-10, atol=1e-12,
                          force_scale=b.sigma_ref * b.cross_section, max_it=30, prefix=prefix)
    arc = ArcLength(solver, b.set_load, arc_length=0.02, max_arc_length=0.05, psi=0.0,
                    metric_dofs=b.opening_dofs, detect=False, commit=b.commit,
                    prefix=f"{prefix}arc_")
    path = [(0.0, 0.0)]  # (end displacement, stress)
    arc.run(stress_ratio, 5000, descending=True,
            on_step=lambda lam, r: path.append((b.end_displacement(), lam * b.sigma_ref)))
    U, s = np.array(path).T
    work = float(np.sum(0.5 * (s[1:] + s[:-1]) * np.diff(U)) * b.cross_section)
    dissipated = work - b.stored_energy()
    expected = b.cross_section * b.h * law.w_c * weak * math.log(1 / stress_ratio)
    return {"cells": cells, "h": b.h, "dissipated_energy": dissipated,
            "dissipated_energy_expected": expected,
            "dissipated_energy_rel_error": dissipated / expected - 1,
            "damaged_cells": b.damaged_cells(), "largest_damage": b.largest_damage(),
            "peak_stress": float(s.max()), "steps": len(path) - 1,
            "mean_strain": (U / length).tolist(), "stress": s.tolist(), "dofs": b.dofs}
