"""The course's local brittle damage law: A(α) = A0 (1 − α), a threshold on ε:A(α):ε.

The course writes it as: damage is irreversible and evolves by the threshold law

    ε:A(α):ε < w_c  ⇒  α̇ = 0,        ε:A(α):ε = w_c  ⇒  α̇ ≥ 0,

with A0 Hooke's moduli (E, ν) and w_c > 0 the critical value. Over a load step from the
committed damage αⁿ, write W0 = ε:A0:ε (twice Hooke's energy) and r = (1 − αⁿ) W0 / w_c.
While r ≤ 1 nothing changes; beyond, the threshold holds, 1 − α = w_c / W0, and the stress
σ = (1 − α) A0:ε = w_c A0:ε / W0. Both are the derivative of one condensed energy,

    ψ(ε) = (1 − αⁿ) W0 / 2            (r ≤ 1),
    ψ(ε) = w_c (1 + ln r) / 2         (r > 1),

continuous with its derivative at r = 1, so that σ = ∂ψ/∂ε and the consistent tangent
∂²ψ/∂ε∂ε come from UFL as for every other law of the project. It is not convex where the
material damages: the response softens (in 1D, σ = w_c/ε past ε_c = √(w_c/E)), which is
why a bar with a weak spot localizes its damage in one element.

The state αⁿ lives at the quadrature points (`bind(mesh, degree)`) and changes only by
`commit(u)` after a converged step: a cut step leaves it as it was.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import ufl

from fenics_nl.expression import Expression
from fenics_nl.materials import kinematics
from fenics_nl.materials.laws import Isotropic, LinearElastic, SmallStrain, check_range

__all__ = ["CourseDamage", "DamageState"]

# r > 1 + 1e-10 damages. A point left on the threshold by the last step has r = 1 up to
# round-off: it must start the next step with the damaged secant (as J2 starts elastic on
# its yield surface), else the round-off picks the softening tangent at some points and not
# at others, and a homogeneous state is lost at its first iteration.
THRESHOLD_TOLERANCE = 1e-10


@dataclass(eq=False)
class DamageState:
    """The committed damage αⁿ at the quadrature points, and its compiled update."""

    alpha: object = None  # quadrature Function
    toughness: object = None  # w_c's factor per cell (DG0 Function, 1: a weak spot below)
    points: object = None  # the quadrature points (reference cell)
    update: object = None  # α of the threshold law as a fem.Expression, compiled once

    def bind(self, mesh, degree: int) -> None:
        """Zero damage at the quadrature points of `degree` on `mesh`, w_c everywhere.

        Args:
            mesh: the mesh.
            degree: the quadrature degree (the residual's rule).
        """
        import basix.ufl
        from dolfinx import fem

        S = fem.functionspace(mesh, basix.ufl.quadrature_element(
            mesh.basix_cell(), value_shape=(), scheme="default", degree=degree))
        self.alpha = fem.Function(S, name="damage")
        self.toughness = fem.Function(fem.functionspace(mesh, ("DG", 0)), name="toughness")
        self.toughness.x.array[:] = 1.0
        self.points, self.update = S.element.interpolation_points, None


@dataclass(frozen=True, eq=False)
class CourseDamage(Isotropic, SmallStrain):
    """The course's brittle damage: Hooke's A0 (E, ν) softened to A0 (1 − α), threshold w_c.

    In 1D (uniaxial stress, or ν = 0): σ = E ε up to ε_c = √(w_c/E), σ_c = √(E w_c), then
    σ = w_c/ε while the strain grows; unloading is elastic with the damaged modulus.
    """

    w_c: float = 1.0
    state: DamageState = field(default_factory=DamageState, init=False, repr=False,
                               compare=False)
    path_dependent = True

    def __post_init__(self):
        super().__post_init__()
        check_range("w_c", self.w_c, 0.0, math.inf)

    @property
    def critical_strain(self) -> float:
        """ε_c = √(w_c/E): where a uniaxial stress state starts to damage."""
        return math.sqrt(self.w_c / self.E)

    @property
    def critical_stress(self) -> float:
        """σ_c = √(E w_c), the peak of the uniaxial response."""
        return math.sqrt(self.E * self.w_c)

    def homogeneous_stress(self, strain: float) -> float:
        """σ of the uniaxial bar loaded monotonically (ν = 0): E ε, then w_c/ε past ε_c.

        Args:
            strain: the bar's strain ε.

        Returns:
            σ (float).
        """
        if abs(strain) <= self.critical_strain:
            return self.E * strain
        return self.w_c / strain

    def bind(self, mesh, degree: int) -> None:
        """Create the state (no damage) at the quadrature points of `degree` on `mesh`.

        Args:
            mesh: the mesh.
            degree: the quadrature degree (the residual's rule).
        """
        self.state.bind(mesh, degree)

    def _bound(self) -> DamageState:
        if self.state.alpha is None:
            raise ValueError("CourseDamage has no state: call bind(mesh, quadrature degree) "
                             "before writing a form with it")
        return self.state

    def weaken(self, cells, factor: float) -> None:
        """w_c times `factor` (in (0, 1]) in this rank's `cells` (local indices): a weak spot.

        Args:
            cells: the weak cells, by their local indices on this rank.
            factor: the factor of w_c there, in (0, 1].
        """
        if not 0 < factor <= 1:
            raise ValueError(f"a weak spot's factor must be in (0, 1], got {factor!r}")
        t = self._bound().toughness
        t.x.array[cells] = factor
        t.x.scatter_forward()

    def _critical(self):
        """w_c where it is: w_c times the cell's toughness factor."""
        return self.w_c * self._bound().toughness

    def _undamaged(self, eps):
        """W0 = ε:A0:ε, twice Hooke's energy (plane stress: with λ*)."""
        return 2 * LinearElastic(self.E, self.nu).energy(eps)

    def energy(self, eps):
        """ψ(ε): the step's condensed energy at the threshold law's damage.

        Args:
            eps: the small strain ε (UFL, 3x3; 2x2 in plane stress, with λ*).

        Returns:
            ψ (UFL scalar).
        """
        alpha_n, w_c = self._bound().alpha, self._critical()
        W0 = self._undamaged(eps)
        r = (1 - alpha_n) * W0 / w_c
        # both branches are evaluated by the generated code: ln only of r >= 1
        damaging = 0.5 * w_c * (1 + ufl.ln(ufl.max_value(r, 1.0)))
        return ufl.conditional(ufl.gt(r, 1.0 + THRESHOLD_TOLERANCE), damaging,
                               0.5 * (1 - alpha_n) * W0)

    def damage(self, eps):
        """α at the strain ε from the committed state (UFL): max(αⁿ, 1 − w_c/W0).

        Args:
            eps: the small strain ε (UFL, 3x3; 2x2 in plane stress).

        Returns:
            α (UFL scalar).
        """
        alpha_n = self._bound().alpha
        r = (1 - alpha_n) * self._undamaged(eps) / self._critical()
        return ufl.conditional(ufl.gt(r, 1.0 + THRESHOLD_TOLERANCE),
                               1 - (1 - alpha_n) / ufl.max_value(r, 1.0), alpha_n)

    def modified_newton_tangent(self, u, model: str, dx):
        """The tangent at the start of each solve (the step's damaged secant, "initial").

        Args:
            u: the displacement (unused).
            model: the kinematic model (unused).
            dx: the measure of the residual (unused).

        Returns:
            "initial".
        """
        return "initial"

    def reset(self) -> None:
        """Back to the undamaged state (a new load path on the same forms)."""
        self._bound().alpha.x.array[:] = 0.0

    @property
    def alpha(self):
        """The committed damage αⁿ (quadrature Function)."""
        return self._bound().alpha

    def damage_per_cell(self):
        """The largest committed α of each cell's quadrature points (DG0 Function).

        Returns:
            The maxima, a new DG0 Function named "damage".
        """
        from fenics_nl.materials.plasticity import cell_max

        return cell_max(self.alpha, "damage")

    def state_functions(self) -> dict:
        """The committed state's quadrature Functions by name (to checkpoint and restore).

        Returns:
            The committed damage αⁿ under the name "damage" (the Function itself, not a copy).
        """
        return {"damage": self.alpha}

    def output_fields(self) -> list:
        """What --output writes of the state: the damage per cell.

        Returns:
            The one DG0 Function of `damage_per_cell`.
        """
        return [self.damage_per_cell()]

    def commit(self, u, model: str = "3d") -> None:
        """Store the threshold law's damage at the displacement `u` (a converged step).

        Args:
            u: the displacement; the update is compiled for the first `u` given.
            model: the kinematic model ("3d", "plane_strain", "plane_stress", "axisymmetric").
        """
        from dolfinx import fem

        st = self._bound()
        if st.update is None:  # compiled once, for the first u given
            st.update = Expression(self.damage(kinematics.small_strain(u, model)),
                                   st.points)
        new = fem.Function(st.alpha.function_space)
        new.interpolate(st.update)
        st.alpha.x.array[:] = new.x.array
