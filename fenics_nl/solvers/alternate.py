"""Alternate minimization of a gradient damage energy E(u, α), α bounded by αⁿ ≤ α ≤ 1.

Each iteration minimizes E in u at fixed α (a Newton solve: E is convex in u) and then in α
at fixed u under the bounds (PETSc SNES `vinewtonrsls`, a reduced-space active-set Newton
method for the variational inequality: E is convex in α at fixed u too). It stops when the
damage changes by less than `tol` (max norm). The lower bound αⁿ is the last committed
damage: `commit()` after a converged load step makes the damage irreversible, and a cut step
leaves it as it was.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc
from mpi4py import MPI

from fenics_nl.errors import SolveError
from fenics_nl.solvers.newton import NewtonSolver

__all__ = ["AlternateMinimization", "AlternateResult"]


@dataclass
class AlternateResult:
    """One load step: alternate iterations, Newton iterations in u, SNES VI iterations."""

    iterations: int
    newton_iterations: int
    damage_iterations: int
    change: float  # the last iteration's max |Δα|


class AlternateMinimization:
    """Alternate minimization of `energy` (a UFL form in u and α).

    Args:
        energy: ∫ e(u, α) dx.
        u, alpha: the unknowns (their values start each step).
        bcs: Dirichlet conditions of u (set anew for each step through `solve(bcs)`).
        force_scale: the force scale of the u-problem's absolute tolerance.
        tol: stop when max |Δα| < tol.
        max_it: alternate iterations before SolveError.
        prefix: PETSc options prefix of the damage problem's SNES (``{prefix}snes_view``).
    """

    def __init__(self, energy: ufl.Form, u: fem.Function, alpha: fem.Function,
                 bcs: Sequence[fem.DirichletBC] = (), *, force_scale: float = 1.0,
                 tol: float = 1e-8, max_it: int = 500, prefix: str = "damage_"):
        self.u, self.alpha, self.bcs = u, alpha, list(bcs)
        self.force_scale, self.tol, self.max_it = force_scale, tol, max_it
        self.residual_u = ufl.derivative(energy, u, ufl.TestFunction(u.function_space))
        residual_a = ufl.derivative(energy, alpha, ufl.TestFunction(alpha.function_space))
        opts = {"snes_type": "vinewtonrsls", "snes_rtol": 1e-12, "snes_atol": 1e-14,
                "snes_stol": 0.0, "snes_max_it": 50, "ksp_type": "preonly", "pc_type": "lu",
                "pc_factor_mat_solver_type": "mumps"}
        self.damage_problem = petsc.NonlinearProblem(
            residual_a, alpha, bcs=[], petsc_options_prefix=prefix, petsc_options=opts)
        self.lower = fem.Function(alpha.function_space, name="committed_damage")
        self.lower.x.array[:] = alpha.x.array
        self._upper = self.damage_problem.x.duplicate()
        self._upper.set(1.0)

    def commit(self) -> None:
        """The current damage becomes the lower bound of the next steps (irreversibility)."""
        self.lower.x.array[:] = self.alpha.x.array

    def solve(self, bcs: Sequence[fem.DirichletBC] | None = None) -> AlternateResult:
        """One load step from the current (u, α), with the Dirichlet conditions `bcs`."""
        bcs = self.bcs if bcs is None else list(bcs)
        snes = self.damage_problem.solver
        displacement = NewtonSolver(self.residual_u, self.u, bcs, rtol=1e-12, atol=1e-14,
                                    force_scale=self.force_scale)
        newton_its = damage_its = 0
        for k in range(1, self.max_it + 1):
            newton_its += displacement.solve().iterations
            before = self.alpha.x.array.copy()
            snes.setVariableBounds(self.lower.x.petsc_vec, self._upper)
            self.damage_problem.solve()
            if snes.getConvergedReason() <= 0:
                raise SolveError(f"the damage problem did not converge (SNES reason "
                                 f"{snes.getConvergedReason()}) at alternate iteration {k}")
            damage_its += snes.getIterationNumber()
            change = self.alpha.function_space.mesh.comm.allreduce(
                float(np.abs(self.alpha.x.array - before).max(initial=0.0)),
                op=MPI.MAX)
            if change < self.tol:
                return AlternateResult(k, newton_its, damage_its, change)
        raise SolveError(f"alternate minimization did not converge in {self.max_it} "
                         f"iterations (last max |Δα| = {change:.3g})")

