"""The stability of a gradient damage state: the second variation of E(u, α) where α can grow.

A state (u, α) that minimizes E(u, α) under αⁿ ≤ α ≤ 1 is stable if the second variation

    E''(u, α)[(v, β), (v, β)] ≥ 0

for every v that keeps the Dirichlet conditions and every β that vanishes where the bound is
active (α = αⁿ with the damage criterion strict, or α = 1): there α cannot move. On the rest,
the inactive set, β is free, and a negative eigenvalue of

    E'' (v, β) = λ M (v, β),    M = ∫ β β̃ dx   (the damage's mass; none on v),

means a direction in which the energy falls: the state is past a bifurcation. The mass on β
only condenses v out (its eigenvalues are infinite): λ is that of the Schur complement
E''_αα − E''_αu (E''_uu)⁻¹ E''_uα, per unit volume, whatever the mesh. Its eigenvector's β is
the critical mode. Both come from `buckling.lowest_tangent_mode` (the tangent's inertia,
then shift-and-invert) on the mixed space of (u, α), the second derivative by UFL.

Along a load path, `BranchStability` keeps λ step by step and tells where it crossed 0;
`DamageStability.perturb` moves α along the critical mode, where the path leaves its branch.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import basix.ufl
import numpy as np
import ufl
from dolfinx import fem, la
from mpi4py import MPI

from fenics_nl.solvers import buckling

__all__ = ["BranchStability", "DamageStability"]

# α is at its bound if within this of it and E pushes against it by more than DRIVING times
# the node's share of the damage's energy scale (∫ density · β): the damage criterion is met
# with equality where α grows, up to the alternate minimization's tolerance
BOUND_TOLERANCE = 1e-9
DRIVING = 1e-6


class DamageStability:
    """The smallest eigenvalue of the second variation of `energy` on the inactive set.

    Args:
        energy: ∫ e(u, α) dx (the form that `AlternateMinimization` minimizes).
        u, alpha: its unknowns; lower: the committed damage αⁿ (the lower bound).
        bcs: u's Dirichlet conditions (v vanishes there).
        damage_bcs: α's (β vanishes there).
        density: the energy density that sets the damage's scale (Gc/ell for gradient
            damage): a node whose driving force is below DRIVING times its share of it is on
            the damage criterion.
    """

    def __init__(self, energy: ufl.Form, u: fem.Function, alpha: fem.Function,
                 lower: fem.Function, bcs: Sequence[fem.DirichletBC] = (),
                 damage_bcs: Sequence[fem.DirichletBC] = (), *, density: float = 1.0,
                 prefix: str = "stability_"):
        self.u, self.alpha, self.lower, self.prefix = u, alpha, lower, prefix
        V, A = u.function_space, alpha.function_space
        self.W = W = fem.functionspace(
            V.mesh, basix.ufl.mixed_element([V.ufl_element(), A.ufl_element()]))
        self.w = fem.Function(W)
        u_w, alpha_w = ufl.split(self.w)
        energy_w = ufl.replace(energy, {u: u_w, alpha: alpha_w})
        # compiled once: the check runs at every load step
        self.hessian = fem.form(ufl.derivative(ufl.derivative(energy_w, self.w), self.w))
        _, beta = ufl.split(ufl.TrialFunction(W))
        _, beta_ = ufl.split(ufl.TestFunction(W))
        self.mass = fem.form(beta * beta_ * ufl.dx)
        self.driving = fem.form(ufl.derivative(energy, alpha, ufl.TestFunction(A)))
        share = fem.assemble_vector(fem.form(density * ufl.TestFunction(A) * ufl.dx))
        share.scatter_reverse(la.InsertMode.add)
        share.scatter_forward()
        self._threshold = DRIVING * share.array.copy()
        self._fixed_u = self._dofs_in_w(0, [d for bc in bcs for d in bc.dof_indices()[0]])
        self._fixed_alpha = [d for bc in damage_bcs for d in bc.dof_indices()[0]]
        self._zero = fem.Function(W)

    def _dofs_in_w(self, part: int, dofs) -> np.ndarray:
        """W's local dofs of the `part` (0: u, 1: α) dofs `dofs` (local to its own space)."""
        source = (self.u, self.alpha)[part]
        marker = fem.Function(source.function_space)
        marker.x.array[np.asarray(dofs, dtype=np.int32)] = 1.0
        mark = fem.Function(self.W)
        mark.sub(part).interpolate(marker)  # the same element: a nodal copy
        return np.flatnonzero(mark.x.array > 0.5).astype(np.int32)

    def _driving_force(self) -> np.ndarray:
        """∂E/∂α at the current state, nodal (ghosts updated)."""
        b = fem.assemble_vector(self.driving)
        b.scatter_reverse(la.InsertMode.add)
        b.scatter_forward()
        return b.array

    def driving_margin(self) -> float:
        """How far the state is from the damage criterion, in units of `density`.

        The minimum over the free nodes of ∂E/∂α over the node's share of ∫ density: > 0
        where α can grow nowhere; affine in ε² on an elastic branch.
        """
        n = self.alpha.function_space.dofmap.index_map.size_local
        share = self._threshold[:n] / DRIVING
        free = np.ones(n, dtype=bool)
        free[[d for d in self._fixed_alpha if d < n]] = False
        margin = self._driving_force()[:n][free] / share[free]
        return self.W.mesh.comm.allreduce(float(margin.min(initial=np.inf)), op=MPI.MIN)

    def active_set(self) -> np.ndarray:
        """α's local dofs at a bound: α = αⁿ pushed down by E, or α = 1."""
        g = self._driving_force()
        a, low = self.alpha.x.array, self.lower.x.array
        at_lower = (a - low <= BOUND_TOLERANCE) & (g > self._threshold)
        return np.flatnonzero(at_lower | (a >= 1 - BOUND_TOLERANCE)).astype(np.int32)

    def lowest_mode(self) -> tuple[float, fem.Function | None]:
        """(λ, β): the smallest eigenvalue on the inactive set and its damage mode.

        β is scaled to max |β| = 1 (β ≥ its opposite); (inf, None) if α cannot move anywhere
        (an elastic state).
        """
        comm = self.W.mesh.comm
        fixed_alpha = np.union1d(self.active_set(), self._fixed_alpha)
        n = self.alpha.function_space.dofmap.index_map.size_local
        free_owned = n - np.count_nonzero(fixed_alpha < n)
        if comm.allreduce(int(free_owned), op=MPI.SUM) == 0:
            return float("inf"), None
        self.w.sub(0).interpolate(self.u)
        self.w.sub(1).interpolate(self.alpha)
        fixed = np.union1d(self._fixed_u, self._dofs_in_w(1, fixed_alpha))
        bc = fem.dirichletbc(self._zero, fixed)
        lam, mode = buckling.lowest_tangent_mode(self.hessian, [bc], self.W,
                                                 prefix=self.prefix, mass=self.mass)
        beta = fem.Function(self.alpha.function_space, name="critical_mode")
        beta.interpolate(mode.sub(1))
        top = comm.allreduce(float(beta.x.array.max(initial=-np.inf)), op=MPI.MAX)
        bottom = comm.allreduce(float(beta.x.array.min(initial=np.inf)), op=MPI.MIN)
        beta.x.array[:] /= top if top >= -bottom else bottom
        return float(lam), beta

    def perturb(self, mode: fem.Function, amplitude: float) -> None:
        """α + amplitude · mode, kept within αⁿ ≤ α ≤ 1: where a step leaves its branch.

        Args:
            mode: the critical mode (`lowest_mode`'s β, max |β| = 1).
            amplitude: its factor.
        """
        a = self.alpha.x.array
        a[:] = np.clip(a + amplitude * mode.x.array, self.lower.x.array, 1.0)


@dataclass
class BranchStability:
    """The lowest eigenvalue of each step of a load path, until it turns negative.

    A load path of alternate minimization leaves its branch where the second variation's
    lowest eigenvalue λ on the inactive set (`DamageStability.lowest_mode`) turns negative.
    Where it does, `observe` says so, and the bifurcation load is where λ crossed 0 between
    the last step and this one, interpolated linearly in the load's square (exact for the
    homogeneous bar, whose λ is affine in ε²). If no damage could grow at the step before (λ
    infinite: AT1 unstable as soon as it damages), it is the damage's onset: where the
    driving margin of the elastic steps (`DamageStability.driving_margin`), affine in the
    load's square too, reaches 0, extrapolated from the last two (None with fewer).
    """

    loads: list[float] = field(default_factory=list)  # the steps observed
    lowest_eigenvalue: list[float] = field(default_factory=list)  # inf: no damage can grow
    # (load, driving margin) of the steps where no damage could grow (elastic)
    elastic_margins: list[tuple[float, float]] = field(default_factory=list)
    damage_onset: float | None = None  # the load where the margin reaches 0, extrapolated
    bifurcation_load: float | None = None
    bifurcation_step: int | None = None  # the index of the step where λ turned negative

    def observe(self, load: float, lam: float, margin: float) -> bool:
        """One converged step's λ: whether the path bifurcates at it (λ < 0, the first time).

        Args:
            load: the step's load (e.g. the bar's mean strain).
            lam: the lowest eigenvalue there (inf where no damage can grow).
            margin: the driving margin there (read where λ is infinite).

        Returns:
            True at the step where λ is negative, the first time.
        """
        self.loads.append(float(load))
        self.lowest_eigenvalue.append(lam)
        if not math.isfinite(lam):
            self.elastic_margins.append((float(load), margin))
        elif self.damage_onset is None:
            self.damage_onset = self._onset()
        if lam >= 0 or self.bifurcation_step is not None:
            return False
        self.bifurcation_step = len(self.loads) - 1
        self.bifurcation_load = self._crossing(load, lam)
        return True

    def _crossing(self, load: float, lam: float) -> float | None:
        """Where λ crossed 0 since the last step (affine in the load's square), or the onset."""
        if len(self.loads) < 2 or not math.isfinite(self.lowest_eigenvalue[-2]):
            return self.damage_onset
        e0, l0 = self.loads[-2], self.lowest_eigenvalue[-2]
        return math.sqrt(e0**2 + (load**2 - e0**2) * l0 / (l0 - lam))

    def _onset(self) -> float | None:
        """The load where the elastic steps' margin, affine in its square, reaches 0.

        None with fewer than two elastic steps, or if their margin does not fall as the
        load grows (nothing to extrapolate to).
        """
        if len(self.elastic_margins) < 2:
            return None
        (e1, m1), (e2, m2) = self.elastic_margins[-2:]
        square = e2**2 + (e2**2 - e1**2) * m2 / (m1 - m2) if m1 > m2 else -1.0
        return math.sqrt(square) if square >= 0 else None
