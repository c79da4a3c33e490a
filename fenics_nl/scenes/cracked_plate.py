"""What the cracked plates (`notched_specimen`, `surfing`) share.

A plane-strain plate of a `GradientDamage` law, its pre-crack, its alternate minimization
and its step. A subclass builds its mesh and supports and calls `_plate`, then `_solver`;
its load loop sets the step's boundary data, calls `_step` and records what it reports.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.solvers.alternate import AlternateMinimization, AlternateWork

__all__ = ["CrackRecord", "CrackedPlate"]


@dataclass
class CrackRecord(AlternateWork):
    """The dissipated energy and (this rank's) damage of every converged step.

    The solves' work is counted as `AlternateWork`'s; the damage is kept for the pictures.
    """

    dissipated_energy: list[float] = field(default_factory=list)
    damage: list[np.ndarray] = field(default_factory=list, repr=False)


class CrackedPlate:
    """The fields, energy, pre-crack and solver of a cracked plate (plane strain)."""

    MODEL = "plane_strain"

    def _plate(self, law, msh, precracked) -> None:
        """u (P1 vector), α (P1) and the energy on `msh`; α = 1 where `precracked(x)`."""
        self.law, self.mesh = law, msh
        self.V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
        self.A = A = fem.functionspace(msh, ("Lagrange", 1))
        self.u = fem.Function(self.V, name="displacement")
        self.alpha = fem.Function(A, name="damage")
        self.energy = law.energy(self.u, self.alpha, self.MODEL) * ufl.dx
        cracked = fem.locate_dofs_geometrical(A, precracked)
        self.alpha.x.array[cracked] = 1.0
        self.precrack = fem.dirichletbc(1.0, cracked, A)
        self._fracture = fem.form(law.fracture_energy(self.alpha) * ufl.dx)

    def _solver(self, bcs, force_scale: float, **options) -> None:
        """Alternate minimization with the pre-crack held at 1 (its lower bound: α now)."""
        law = self.law
        self.bcs = bcs
        self.solver = AlternateMinimization(
            self.energy, self.u, self.alpha, bcs, damage_bcs=[self.precrack],
            force_scale=force_scale, damage_scale=law.Gc / law.ell * self.h**2, **options)

    def _step(self, record: CrackRecord) -> None:
        """Minimize at the current boundary data, commit, and record D and the damage."""
        record.count(self.solver.solve())
        self.solver.commit()
        record.dissipated_energy.append(self.dissipated_energy())
        record.damage.append(self.alpha.x.array.copy())

    def dissipated_energy(self) -> float:
        """∫ (Gc/c_w)(w(α)/ell + ell |∇α|²), per unit thickness (collective)."""
        return self.mesh.comm.allreduce(fem.assemble_scalar(self._fracture), op=MPI.SUM)

    @property
    def dofs(self) -> int:
        """Unknowns: the displacement's and the damage's."""
        return (self.V.dofmap.index_map.size_global * 2
                + self.A.dofmap.index_map.size_global)
