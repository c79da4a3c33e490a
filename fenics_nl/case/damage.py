"""A case in gradient damage (``law = "at1"`` or ``"at2"``): its load steps' solver.

The case's energy is the law's, ∫ a(α) ψ0(ε(u)) + (Gc/c_w)(w(α)/ell + ell |∇α|²), less the
work of its dead loads (tractions, pressures: the potential whose derivative is the case's
residual). At each load step it is minimized by alternate minimization (u by Newton, α by
PETSc's bound-constrained SNES within the committed damage and 1): `DamageSteps` is that
solve as `solve_incrementally` takes it. A cut step starts again from the committed damage.
"""

from __future__ import annotations

import time

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.solvers.alternate import AlternateMinimization, AlternateResult
from fenics_nl.solvers.result import SolveResult

__all__ = ["DamageSteps", "cell_sizes"]


class DamageSteps:
    """Alternate minimization of a damage case's energy, one load step per `solve`.

    `last`: the last step's counts (alternate, Newton and SNES VI iterations).
    """

    def __init__(self, problem, prefix: str):
        material = problem.material  # a DamagedElastic, bound to the mesh
        law, u, alpha = material.law, problem.u, material.alpha
        self.u, self.alpha, self.lower = problem.unknown, alpha, material.lower
        energy = law.energy(u, alpha, problem.model) * problem.dx + problem.load_potential()
        h = cell_sizes(problem.mesh).min(initial=np.inf)
        h = problem.mesh.comm.allreduce(h, op=MPI.MIN)
        # the loads', or the force the peak stress puts on a cell's side (displacements drive
        # the body: a step's first residual can be round-off, no scale to stop Newton at)
        dim = problem.mesh.topology.dim
        force = problem.force_scale or law.critical_stress * h ** (dim - 1)
        self.alternate = AlternateMinimization(
            energy, u, alpha, problem.bcs, force_scale=force,
            damage_scale=law.Gc / law.ell * h**dim,
            lower=material.lower, tol=1e-6, max_it=2000, prefix=prefix,
            acceleration="anderson")
        self._fracture = fem.form(law.fracture_energy(alpha) * problem.weight * problem.dx)
        self.last: AlternateResult | None = None

    def solve(self) -> SolveResult:
        """Minimize at the current loads, from the committed damage (not committed here)."""
        self.alpha.x.array[:] = self.lower.x.array  # a cut step leaves no damage behind
        t0 = time.perf_counter()
        self.last = self.alternate.solve()
        return SolveResult(True, "converged", self.last.newton_iterations, [], self.last.work,
                           wall_time=time.perf_counter() - t0)

    def dissipated_energy(self) -> float:
        """∫ (Gc/c_w)(w(α)/ell + ell |∇α|²) (times 2πr axisymmetric; collective)."""
        return self.alpha.function_space.mesh.comm.allreduce(
            fem.assemble_scalar(self._fracture), op=MPI.SUM)


def cell_sizes(mesh) -> np.ndarray:
    """The owned cells' diameters (this rank's)."""
    tdim = mesh.topology.dim
    owned = np.arange(mesh.topology.index_map(tdim).size_local, dtype=np.int32)
    return mesh.h(tdim, owned)
