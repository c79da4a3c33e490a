"""Norton creep: a viscous strain that flows at any stress, faster the higher it is.

    ε̇ᵛ = (3/2) A σ_eqⁿ⁻¹ dev σ        (uniaxially ε̇ᵛ = A σⁿ),   σ = C : (ε − εᵛ).

The state is the committed viscous strain εᵛₙ and cumulated viscous strain pₙ at the
quadrature points, and the time step Δt a `fem.Constant` (`set_time_step`). Over a step the
flow is integrated by backward Euler: with the trial deviator s_tr = 2μ dev(ε − εᵛₙ) and its
equivalent stress q_tr = √(3/2) |s_tr|, the step's equivalent stress q solves

    q + 3μ A Δt qⁿ = q_tr,

and then Δp = (q_tr − q)/(3μ), εᵛ = εᵛₙ + (3/2) Δp s_tr/q_tr (the deviator keeps its
direction). That scalar equation has no closed form for n ≠ 1: it is solved in UFL by
`NEWTON_STEPS` Newton steps from q₀ = min(q_tr, (q_tr/(3μAΔt))^(1/n)). Its left side is
convex and increasing in q, and q₀ bounds the root from above within a factor 2^(1/n), so
the steps fall monotonically onto it: 6 reach 2e-15 relative for n in [1, 12] and
3μAΔt q_trⁿ⁻¹ over 24 decades (checked by bisection, `tests/test_creep.py`). Being UFL, the
stress and its consistent tangent (through the steps) are derived, not typed.

The condensed energy of the step, W(ε − εᵛ) + Δt φ*(Δp/Δt) with the dissipation potential
φ*(ṗ) = n/(n + 1) A^(−1/n) ṗ^((n+1)/n), is W(ε − εᵛ) + n/(n + 1) q Δp. At Δt = 0 the law is
Hooke's (the instantaneous response of a load applied at once).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import ufl

from fenics_nl.expression import Expression
from fenics_nl.materials import kinematics
from fenics_nl.materials.laws import Isotropic, LinearElastic, SmallStrain
from fenics_nl.materials.plasticity import quadrature_spaces

__all__ = ["NEWTON_STEPS", "NortonCreep", "ViscousState"]

NEWTON_STEPS = 7  # the local equation's Newton steps: 6 reach round-off (module docstring)


@dataclass(eq=False)
class ViscousState:
    """Norton's committed state at the quadrature points, its time step and update.

    Empty until `bind`: the law's parameters are frozen, its state is not.
    """

    eps_v: object = None  # the viscous strain εᵛ (quadrature Function, 3x3)
    p: object = None  # the cumulated viscous strain (quadrature Function)
    dt: object = None  # the time step Δt (fem.Constant)
    points: object = None  # the quadrature points (reference cell)
    commit: tuple | None = None  # (εᵛ, p) of the step as fem.Expressions, compiled once

    def bind(self, mesh, degree: int) -> None:
        """Zero εᵛ and p at the quadrature points of `degree` on `mesh`; Δt = 0.

        Args:
            mesh: the mesh.
            degree: the quadrature degree (the residual's rule).
        """
        from dolfinx import fem

        T, S = quadrature_spaces(mesh, degree)
        self.eps_v = fem.Function(T, name="viscous_strain")
        self.p = fem.Function(S, name="cumulated_viscous_strain")
        self.dt = fem.Constant(mesh, 0.0)
        self.points, self.commit = T.element.interpolation_points, None


@dataclass(frozen=True, eq=False)
class NortonCreep(Isotropic, SmallStrain):
    """Norton creep: ε̇ᵛ = A σ_eqⁿ uniaxially, A > 0, n ≥ 1 (n = 1: linear viscosity).

    Models: 3D, plane strain, axisymmetric (3x3 strains).
    """

    A: float = 1.0
    n: float = 1.0
    state: ViscousState = field(default_factory=ViscousState, init=False, repr=False,
                                compare=False)

    path_dependent = True

    def __post_init__(self):
        super().__post_init__()
        if not (math.isfinite(self.A) and self.A > 0):
            raise ValueError(f"A must be > 0 and finite, got {self.A!r}")
        if not (math.isfinite(self.n) and self.n >= 1):
            raise ValueError(f"n must be >= 1 and finite, got {self.n!r}")

    def bind(self, mesh, degree: int) -> None:
        """Create the state (zero) at the quadrature points of `degree` on `mesh`.

        Args:
            mesh: the mesh.
            degree: the quadrature degree (the residual's rule).
        """
        self.state.bind(mesh, degree)

    def _bound(self) -> ViscousState:
        if self.state.eps_v is None:
            raise ValueError("NortonCreep has no state: call bind(mesh, quadrature degree) "
                             "before writing a form with it")
        return self.state

    def set_time_step(self, dt: float) -> None:
        """The time step Δt of the next steps (0: the instantaneous, elastic response).

        Args:
            dt: Δt >= 0.
        """
        if not (math.isfinite(dt) and dt >= 0):
            raise ValueError(f"the time step must be >= 0 and finite, got {dt!r}")
        self._bound().dt.value = float(dt)

    def reset(self) -> None:
        """Back to the virgin state (a new load path on the same forms)."""
        st = self._bound()
        st.eps_v.x.array[:] = 0.0
        st.p.x.array[:] = 0.0

    @property
    def viscous_strain(self):
        """The committed viscous strain εᵛ (quadrature Function, 3x3)."""
        return self._bound().eps_v

    @property
    def cumulated_viscous_strain(self):
        """The committed cumulated viscous strain p (quadrature Function)."""
        return self._bound().p

    def state_functions(self) -> dict:
        """The committed state's quadrature Functions by name (to checkpoint and restore).

        Returns:
            The committed εᵛ ("viscous_strain") and p ("cumulated_viscous_strain"), the
            Functions themselves, not copies.
        """
        st = self._bound()
        return {"viscous_strain": st.eps_v, "cumulated_viscous_strain": st.p}

    def return_map(self, eps):
        """(εᵛ, p, Δp, q) at the strain ε after the time step, from the committed state.

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            (viscous strain εᵛ, cumulated viscous strain p, its increment Δp, the step's
            equivalent stress q), UFL.
        """
        self.require_3x3(eps)
        st = self._bound()
        mu, n = self.mu, float(self.n)
        s_tr = 2 * mu * ufl.dev(eps - st.eps_v)
        q_tr2 = 1.5 * ufl.inner(s_tr, s_tr)
        # an unstressed point (q_tr = 0: no direction) or an instantaneous step (Δt = 0)
        # does not flow; the other branch is then never evaluated (√ and q^(1/n) at 0
        # have no derivative)
        flows = ufl.And(ufl.gt(q_tr2, (1e-14 * self.E) ** 2), ufl.gt(st.dt, 0))
        q_tr = ufl.sqrt(ufl.conditional(flows, q_tr2, 1.0))
        c = 3 * mu * self.A * ufl.conditional(flows, st.dt, 1.0)
        q = ufl.min_value(q_tr, (q_tr / c) ** (1 / n))
        for _ in range(NEWTON_STEPS):
            q = q - (q + c * q**n - q_tr) / (1 + n * c * q ** (n - 1))
        dp = ufl.conditional(flows, (q_tr - q) / (3 * mu), 0)
        direction = ufl.conditional(flows, 1.5 * s_tr / q_tr, ufl.zero(3, 3))
        return st.eps_v + dp * direction, st.p + dp, dp, ufl.conditional(flows, q, 0)

    def stress(self, eps):
        """σ = C : (ε − εᵛ) at the step's viscous strain.

        Its derivative, through the local Newton steps, is the consistent tangent.

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            σ (UFL, 3x3).
        """
        eps_v, _, _, _ = self.return_map(eps)
        return LinearElastic(self.E, self.nu).stress(eps - eps_v)

    def deviatoric_stress(self, eps):
        """dev σ = 2μ dev(ε − εᵛ): what the mixed form takes instead of φ̃'s derivative.

        (The flow is isochoric, so the volumetric part is κ tr ε, the mixed form's p.)

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            dev σ (UFL, 3x3).
        """
        eps_v, _, _, _ = self.return_map(eps)
        return 2 * self.mu * ufl.dev(eps - eps_v)

    def energy(self, eps):
        """ψ(ε) = W(ε − εᵛ) + n/(n + 1) q Δp: the step's condensed energy.

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            ψ (UFL scalar).
        """
        eps_v, _, dp, q = self.return_map(eps)
        n = float(self.n)
        return LinearElastic(self.E, self.nu).energy(eps - eps_v) + n / (n + 1) * q * dp

    def volumetric_split(self, eps):
        """ψ = [μ |dev(ε − εᵛ)|² + n/(n + 1) q Δp] + κ/2 (tr ε)²: the flow is isochoric.

        The mixed displacement–pressure form (`materials.mixed`) needs it here more than
        for any rate-independent law: stationary creep is an incompressible flow whose
        strain grows without bound, and P2 displacements alone cannot follow it (their
        divergence error grows with it, and with it a spurious pressure).

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            (μ |dev(ε − εᵛ)|² + n/(n + 1) q Δp, tr ε, κ).
        """
        eps_v, _, dp, q = self.return_map(eps)
        d = ufl.dev(eps - eps_v)
        n = float(self.n)
        return self.mu * ufl.inner(d, d) + n / (n + 1) * q * dp, ufl.tr(eps), self.kappa

    def modified_newton_tangent(self, u, model: str, dx):
        """Hooke's tangent (E, ν), factorized once: the law's instantaneous stiffness.

        Args:
            u: the displacement (the unknown Function).
            model: the kinematic model ("3d", "plane_strain" or "axisymmetric").
            dx: the measure of the residual.

        Returns:
            Hooke's tangent, a bilinear form (UFL) in `u`.
        """
        v = ufl.TestFunction(u.function_space)
        work = LinearElastic(self.E, self.nu).internal_work(u, v, model)
        return ufl.derivative(work * dx, u)

    def commit(self, u, model: str = "3d") -> None:
        """Store the step's viscous state of the displacement `u` (a converged step).

        The update is compiled for the first `u` given: one displacement per bound material.

        Args:
            u: the displacement.
            model: the kinematic model ("3d", "plane_strain" or "axisymmetric").
        """
        from dolfinx import fem

        st = self._bound()
        if st.commit is None:  # compiled once
            eps_v, p, _, _ = self.return_map(kinematics.small_strain(u, model))
            st.commit = (Expression(eps_v, st.points), Expression(p, st.points))
        new_eps_v, new_p = st.commit
        # evaluate both before storing: each reads the committed state
        a = fem.Function(st.eps_v.function_space)
        a.interpolate(new_eps_v)
        b = fem.Function(st.p.function_space)
        b.interpolate(new_p)
        st.eps_v.x.array[:] = a.x.array
        st.p.x.array[:] = b.x.array
