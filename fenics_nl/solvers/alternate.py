"""Alternate minimization of a gradient damage energy E(u, α), α bounded by αⁿ ≤ α ≤ 1.

Each iteration minimizes E in u at fixed α (a Newton solve: E is convex in u) and then in α
at fixed u under the bounds (PETSc SNES `vinewtonrsls`, a reduced-space active-set Newton
method for the variational inequality: E is convex in α at fixed u too). It stops when the
damage changes by less than `tol` (max norm). The lower bound αⁿ is the last committed
damage: `commit()` after a converged load step makes the damage irreversible, and a cut step
leaves it as it was.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc
from mpi4py import MPI
from petsc4py import PETSc

from fenics_nl.errors import SolveError
from fenics_nl.solvers.acceleration import accelerator
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.solvers.result import WorkCounts
from fenics_nl.solvers.snes import solver_options

__all__ = ["AlternateMinimization", "AlternateResult", "AlternateWork"]


@dataclass
class AlternateResult:
    """One load step: alternate iterations, Newton iterations in u, SNES VI iterations."""

    iterations: int
    newton_iterations: int
    damage_iterations: int
    change: float  # the last iteration's max |Δα|
    rejected: int = 0  # accelerated iterates that did not lower the energy
    # the u-solves' counts (NewtonSolver's), and the damage solves': each SNES VI iteration
    # assembles the Jacobian and factorizes it (LU) once
    work: WorkCounts = field(default_factory=WorkCounts)


@dataclass
class AlternateWork:
    """The work of alternate minimization over load steps (a record's counts)."""

    iterations: list[int] = field(default_factory=list)  # alternate iterations per step
    newton_iterations: int = 0  # the displacement's, over the steps
    damage_iterations: int = 0  # the bound-constrained damage solves', over the steps

    def count(self, *solves: AlternateResult) -> None:
        """One load step's solves (a step solved again counts in the same step).

        Args:
            solves: the step's results (`AlternateResult`), whose iterations are added up.
        """
        self.iterations.append(sum(r.iterations for r in solves))
        self.newton_iterations += sum(r.newton_iterations for r in solves)
        self.damage_iterations += sum(r.damage_iterations for r in solves)


class AlternateMinimization:
    """Alternate minimization of `energy` (a UFL form in u and α).

    Args:
        energy: ∫ e(u, α) dx.
        u, alpha: the unknowns (their values start each step).
        bcs: Dirichlet conditions of u (set anew for each step through `solve(bcs)`).
        damage_bcs: Dirichlet conditions of α (e.g. α = 0 where a bar is gripped).
        force_scale: the force scale of the u-problem's absolute tolerance (None: the
            largest first residual of a step's Newton solves, `NewtonSolver`'s default).
        damage_scale: that of the α-problem (its residual, E's derivative in α: Gc/ell
            times a cell's measure is a nodal value of it).
        tol: stop when max |Δα| < tol.
        max_it: alternate iterations before SolveError.
        prefix: PETSc options prefix of the damage problem's SNES (``{prefix}snes_view``).
        lower: the irreversibility bound αⁿ, if another object keeps it (a material's
            state); by default a copy of α, owned here.
        acceleration: ``none`` (the plain alternate iteration), ``overrelaxed`` (α moved
            `omega` times its update) or ``anderson`` (`depth` past iterates combined): see
            `solvers.acceleration`. The accelerated damage is put back within the bounds
            before the next u-solve; the stop is on the plain iteration's change.
    """

    def __init__(self, energy: ufl.Form, u: fem.Function, alpha: fem.Function,
                 bcs: Sequence[fem.DirichletBC] = (), *,
                 damage_bcs: Sequence[fem.DirichletBC] = (),
                 force_scale: float | None = 1.0, damage_scale: float = 1.0,
                 lower: fem.Function | None = None,
                 tol: float = 1e-8, max_it: int = 500, prefix: str = "damage_",
                 acceleration: str = "none", omega: float = 1.5, depth: int = 5):
        self.u, self.alpha, self.bcs = u, alpha, list(bcs)
        A = alpha.function_space
        self.accelerate = accelerator(acceleration, A.mesh.comm, A.dofmap.index_map.size_local,
                                      omega=omega, depth=depth)
        self.force_scale, self.tol, self.max_it = force_scale, tol, max_it
        self.residual_u = ufl.derivative(energy, u, ufl.TestFunction(u.function_space))
        self._energy_form = fem.form(energy)
        residual_a = ufl.derivative(energy, alpha, ufl.TestFunction(alpha.function_space))
        # E is quadratic in α (a and w are): one full Newton step solves it on an active set
        opts = {"snes_type": "vinewtonrsls", "snes_linesearch_type": "basic",
                "snes_rtol": 1e-12, "snes_stol": 0.0, "snes_max_it": 50,
                "ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
        with solver_options(prefix, opts) as passed:
            self.damage_problem = petsc.NonlinearProblem(
                residual_a, alpha, bcs=list(damage_bcs), petsc_options_prefix=prefix,
                petsc_options=passed)
        self.damage_scale = damage_scale
        self._user_atol = PETSc.Options().hasName(f"{prefix}snes_atol")  # the user's stays
        # the α-residual's round-off grows with the elastic energy that drives damage: its
        # scale at a step is that of ∂E/∂α at α = 0 (−a'(0) ψ0 + the local dissipation)
        undamaged = fem.Function(alpha.function_space)
        self._driving = fem.form(ufl.replace(residual_a, {alpha: undamaged}))
        if lower is None:
            lower = fem.Function(alpha.function_space, name="committed_damage")
            lower.x.array[:] = alpha.x.array
        self.lower = lower
        self._upper = self.damage_problem.x.duplicate()
        self._upper.set(1.0)
        # u at fixed α: one Newton solver for every step (its forms compiled once), the
        # step's conditions set by `solve`
        self._displacement = NewtonSolver(self.residual_u, u, self.bcs, rtol=1e-12,
                                          atol=1e-10, force_scale=force_scale)

    def _damage_atol(self) -> float:
        """The damage problem's absolute tolerance.

        1e-11 of the larger of `damage_scale` and the driving force's norm (its round-off is
        1e-16 of it).
        """
        driving = petsc.assemble_vector(self._driving)
        driving.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        norm = driving.norm()
        driving.destroy()
        return 1e-11 * max(self.damage_scale, norm)

    def commit(self) -> None:
        """The current damage becomes the lower bound of the next steps (irreversibility)."""
        self.lower.x.array[:] = self.alpha.x.array

    def solve(self, bcs: Sequence[fem.DirichletBC] | None = None) -> AlternateResult:
        """One load step from the current (u, α), with the Dirichlet conditions `bcs`.

        With an acceleration, the accelerated damage is kept only if, after its u-solve, the
        energy is below that of the plain iterate (u_k, G(α_k)), which the plain next step
        would lower further: the energy falls at every iteration, as in the plain scheme, so
        that the iteration cannot be drawn to an unstable stationary state (a fixed point
        that is not a minimum: the homogeneous bar past its bifurcation). Otherwise the plain
        iterate is restored and the history forgotten.

        Args:
            bcs: the Dirichlet conditions of u for this step (None: those given at
                construction).

        Returns:
            The step's iteration counts, its last max |Δα| and its work.

        Raises:
            SolveError: if max |Δα| is still ≥ `tol` after `max_it` iterations, or if a u- or
                damage solve does not converge.
        """
        bcs = self.bcs if bcs is None else list(bcs)
        snes = self.damage_problem.solver
        displacement = self._displacement
        displacement.set_bcs(bcs)
        displacement.force_reference = 0.0  # without a force scale: this step's own
        counts = AlternateResult(0, 0, 0, math.inf)
        if self.accelerate is not None:
            self.accelerate.reset()
        plain = None  # (G(α_k), E(u_k, G(α_k))) while an accelerated α is on trial
        for k in range(1, self.max_it + 1):
            counts.iterations = k
            self._count_u(counts, displacement.solve())
            if plain is not None and self._energy() > plain[1]:
                self.alpha.x.array[:] = plain[0]  # rejected: back to the plain iterate
                self.accelerate.reset()
                counts.rejected += 1
                self._count_u(counts, displacement.solve())
            if k == 1 and not self._user_atol:  # once per step: its first u's driving force
                snes.setTolerances(atol=self._damage_atol())
            before = self.alpha.x.array.copy()
            its = self._minimize_damage(k)
            counts.damage_iterations += its
            counts.work.tangent_assemblies += its
            counts.work.factorizations += its
            counts.work.linear_solves += its
            counts.change = self.alpha.function_space.mesh.comm.allreduce(
                float(np.abs(self.alpha.x.array - before).max(initial=0.0)), op=MPI.MAX)
            if counts.change < self.tol:
                return counts
            if self.accelerate is not None:
                plain = (self.alpha.x.array.copy(), self._energy())
                moved = self.accelerate(before, self.alpha.x.array)
                # α's Dirichlet values stay: they are the same in `before` and in G(before)
                self.alpha.x.array[:] = np.clip(moved, self.lower.x.array, 1.0)
        raise SolveError(f"alternate minimization did not converge in {self.max_it} "
                         f"iterations (last max |Δα| = {counts.change:.3g})")

    @staticmethod
    def _count_u(counts: AlternateResult, result) -> None:
        counts.newton_iterations += result.iterations
        counts.work.add(result.work)

    def _minimize_damage(self, k: int) -> int:
        """α at fixed u within the bounds (SNES VI): its iterations."""
        snes = self.damage_problem.solver
        snes.setVariableBounds(self.lower.x.petsc_vec, self._upper)
        self.damage_problem.solve()
        if snes.getConvergedReason() <= 0:
            raise SolveError(f"the damage problem did not converge (SNES reason "
                             f"{snes.getConvergedReason()}) at alternate iteration {k}")
        return snes.getIterationNumber()

    def _energy(self) -> float:
        """E(u, α) as they are."""
        comm = self.alpha.function_space.mesh.comm
        return comm.allreduce(fem.assemble_scalar(self._energy_form), op=MPI.SUM)
