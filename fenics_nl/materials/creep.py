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
from fenics_nl.materials.laws import Isotropic, LinearElastic, SmallStrain
from fenics_nl.materials.plasticity import (
    StateAtPoints,
    cell_max,
    hookes_tangent,
    quadrature_spaces,
    store_at_points,
)

__all__ = ["NEWTON_STEPS", "NortonCreep", "PerzynaViscoplasticity", "ViscousLaw", "ViscousState",
           "power_root"]

NEWTON_STEPS = 7  # the local equation's Newton steps: 6 reach round-off (module docstring)


def power_root(rhs, c, n: float, flows):
    """y ≥ 0 with y + c yⁿ = rhs (UFL), by `NEWTON_STEPS` Newton steps from an upper bound.

    From y₀ = min(rhs, (rhs/c)^(1/n)), within a factor 2^(1/n) of the root; the left side
    is convex and increasing, so the steps fall monotonically onto it.

    Args:
        rhs: the right side (UFL, > 0 where `flows`).
        c: the coefficient (UFL, > 0 where `flows`).
        n: the exponent, >= 1.
        flows: where the point flows (UFL condition); elsewhere rhs and c are replaced by 1
            so that nothing without a derivative (a root of 0) is evaluated.

    Returns:
        y (UFL; meaningless where not `flows`).
    """
    rhs = ufl.conditional(flows, rhs, 1.0)
    c = ufl.conditional(flows, c, 1.0)
    y = ufl.min_value(rhs, (rhs / c) ** (1 / n))
    for _ in range(NEWTON_STEPS):
        y = y - (y + c * y**n - rhs) / (1 + n * c * y ** (n - 1))
    return y


@dataclass(eq=False)
class ViscousState:
    """Norton's committed state at the quadrature points, its time step and update.

    Empty until `bind`: the law's parameters are frozen, its state is not.
    """

    eps_v: object = None  # the viscous strain εᵛ (quadrature Function, 3x3)
    p: object = None  # the cumulated viscous strain (quadrature Function)
    q: object = None  # the equivalent stress σ_eq of the committed state (quadrature Function)
    dt: object = None  # the time step Δt (fem.Constant)
    points: object = None  # the quadrature points (reference cell)
    commit: tuple | None = None  # (εᵛ, p, σ_eq) of the step as fem.Expressions, compiled once

    def bind(self, mesh, degree: int) -> None:
        """Zero εᵛ, p and σ_eq at the quadrature points of `degree` on `mesh`; Δt = 0.

        Args:
            mesh: the mesh.
            degree: the quadrature degree (the residual's rule).
        """
        from dolfinx import fem

        T, S = quadrature_spaces(mesh, degree)
        self.eps_v = fem.Function(T, name="viscous_strain")
        self.p = fem.Function(S, name="cumulated_viscous_strain")
        self.q = fem.Function(S, name="equivalent_stress")
        self.dt = fem.Constant(mesh, 0.0)
        self.points, self.commit = T.element.interpolation_points, None


@dataclass(frozen=True, eq=False)
class ViscousLaw(StateAtPoints, Isotropic, SmallStrain):
    """What Norton's and Perzyna's laws share: the state, the time step, σ, the commit.

    A law gives `return_map` (its inelastic strain after the step) and `dissipated` (the
    condensed energy's terms beyond Hooke's). Models: 3D, plane strain, axisymmetric (3x3),
    and plane stress with ε_zz an unknown at the points (`materials.plane_stress`).
    """

    state: ViscousState = field(default_factory=ViscousState, init=False, repr=False,
                                compare=False)

    path_dependent = True

    def _bound(self) -> ViscousState:
        if self.state.eps_v is None:
            raise ValueError(f"{type(self).__name__} has no state: call bind(mesh, "
                             "quadrature degree) before writing a form with it")
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
        for f in (st.eps_v, st.p, st.q):
            f.x.array[:] = 0.0

    def quadrature_space(self):
        """The scalar quadrature space of the state (σ_eq per cell is averaged over it)."""
        return self._bound().p.function_space

    @property
    def viscous_strain(self):
        """The committed viscous strain εᵛ (quadrature Function, 3x3)."""
        return self._bound().eps_v

    @property
    def cumulated_viscous_strain(self):
        """The committed cumulated viscous strain p (quadrature Function)."""
        return self._bound().p

    @property
    def equivalent_stress(self):
        """The von Mises stress σ_eq of the committed state (quadrature Function).

        Not a state variable (it follows from εᵛ and u): what the time driver's step control
        and stationary test read.
        """
        return self._bound().q

    def state_functions(self) -> dict:
        """The committed state's quadrature Functions by name (to checkpoint and restore).

        Returns:
            The committed εᵛ ("viscous_strain") and p ("cumulated_viscous_strain"), the
            Functions themselves, not copies.
        """
        st = self._bound()
        return {"viscous_strain": st.eps_v, "cumulated_viscous_strain": st.p}

    def output_fields(self) -> list:
        """What a time series writes of the state: p and σ_eq, each cell's largest (DG0).

        Returns:
            New DG0 Functions "cumulated_viscous_strain" and "equivalent_stress_at_points".
        """
        st = self._bound()
        return [cell_max(st.p, "cumulated_viscous_strain"),
                cell_max(st.q, "equivalent_stress_at_points")]

    def return_map(self, eps):
        """(εᵛ, p, Δp, the step's stress measure) after the time step: the law's own.

        Args:
            eps: the small strain ε (UFL, 3x3).
        """
        raise NotImplementedError

    def dissipated(self, p, dp, measure):
        """The condensed energy's terms beyond Hooke's, at the step's state (UFL).

        Args:
            p: the cumulated inelastic strain after the step.
            dp: its increment.
            measure: the fourth value of `return_map`.
        """
        raise NotImplementedError

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
        """ψ(ε) = W(ε − εᵛ) + the dissipated terms: the step's condensed energy.

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            ψ (UFL scalar).
        """
        eps_v, p, dp, measure = self.return_map(eps)
        return LinearElastic(self.E, self.nu).energy(eps - eps_v) + self.dissipated(p, dp,
                                                                                    measure)

    def volumetric_split(self, eps):
        """ψ = [μ |dev(ε − εᵛ)|² + the dissipated terms] + κ/2 (tr ε)²: isochoric flow.

        The mixed displacement–pressure form (`materials.mixed`) needs it here more than
        for any rate-independent law: stationary creep is an incompressible flow whose
        strain grows without bound, and P2 displacements alone cannot follow it (their
        divergence error grows with it, and with it a spurious pressure).

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            (μ |dev(ε − εᵛ)|² + the dissipated terms, tr ε, κ).
        """
        eps_v, p, dp, measure = self.return_map(eps)
        d = ufl.dev(eps - eps_v)
        return self.mu * ufl.inner(d, d) + self.dissipated(p, dp, measure), ufl.tr(eps), \
            self.kappa

    def modified_newton_tangent(self, u, model: str, dx):
        """Hooke's tangent (E, ν), factorized once: the law's instantaneous stiffness.

        Args:
            u: the displacement (the unknown Function).
            model: the kinematic model ("3d", "plane_strain" or "axisymmetric").
            dx: the measure of the residual.

        Returns:
            Hooke's tangent, a bilinear form (UFL) in `u`.
        """
        return hookes_tangent(self, u, model, dx)

    def commit_strain(self, strain) -> None:
        """Store the step's viscous state of a 3x3 strain expression, and σ_eq (`commit`).

        Plane stress: `plane_stress.whole_strain`.

        Args:
            strain: the small strain ε (UFL, 3x3); the update is compiled for the first given.
        """
        st = self._bound()
        if st.commit is None:  # compiled once
            eps_v, p, _, _ = self.return_map(strain)
            s = 2 * self.mu * ufl.dev(strain - eps_v)
            st.commit = tuple(Expression(e, st.points)
                              for e in (eps_v, p, ufl.sqrt(1.5 * ufl.inner(s, s))))
        store_at_points((st.eps_v, st.p, st.q), st.commit)


@dataclass(frozen=True, eq=False)
class NortonCreep(ViscousLaw):
    """Norton creep: ε̇ᵛ = A σ_eqⁿ uniaxially, A > 0, n ≥ 1 (n = 1: linear viscosity)."""

    A: float = 1.0
    n: float = 1.0

    def __post_init__(self):
        super().__post_init__()
        if not (math.isfinite(self.A) and self.A > 0):
            raise ValueError(f"A must be > 0 and finite, got {self.A!r}")
        if not (math.isfinite(self.n) and self.n >= 1):
            raise ValueError(f"n must be >= 1 and finite, got {self.n!r}")

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
        mu = self.mu
        s_tr = 2 * mu * ufl.dev(eps - st.eps_v)
        q_tr2 = 1.5 * ufl.inner(s_tr, s_tr)
        # an unstressed point (q_tr = 0: no direction) or an instantaneous step (Δt = 0)
        # does not flow; the other branch is then never evaluated (√ and q^(1/n) at 0
        # have no derivative)
        flows = ufl.And(ufl.gt(q_tr2, (1e-14 * self.E) ** 2), ufl.gt(st.dt, 0))
        q_tr = ufl.sqrt(ufl.conditional(flows, q_tr2, 1.0))
        q = power_root(q_tr, 3 * mu * self.A * st.dt, float(self.n), flows)
        dp = ufl.conditional(flows, (q_tr - q) / (3 * mu), 0)
        direction = ufl.conditional(flows, 1.5 * s_tr / q_tr, ufl.zero(3, 3))
        return st.eps_v + dp * direction, st.p + dp, dp, ufl.conditional(flows, q, 0)

    def dissipated(self, p, dp, measure):
        """Δt φ*(Δp/Δt) = n/(n + 1) q Δp (q: the step's equivalent stress).

        Args:
            p: the cumulated viscous strain after the step (unused).
            dp: its increment.
            measure: q.

        Returns:
            The term (UFL scalar).
        """
        n = float(self.n)
        return n / (n + 1) * measure * dp


@dataclass(frozen=True, eq=False)
class PerzynaViscoplasticity(ViscousLaw):
    """Perzyna (Norton–Hoff) viscoplasticity on J2: ṗ = ⟨(σ_eq − σ0 − H p)/K⟩^m.

    The plastic strain flows only above the yield stress σ0 + H p, at a rate set by the
    overstress y = σ_eq − σ0 − H p: ε̇ᵖ = (3/2) ṗ s/σ_eq. Backward Euler over Δt: with the
    trial f_tr = q_tr − σ0 − H pₙ > 0, the overstress solves y + (3μ + H) Δt (y/K)^m = f_tr
    (`power_root`, as Norton's), Δp = (f_tr − y)/(3μ + H). As Δt grows against the
    relaxation time, y → 0 and Δp → f_tr/(3μ + H): J2's radial return (tested). At a
    constant plastic strain rate the stress tends to σ0 + H p + K ṗ^(1/m).
    """

    sigma0: float = 1.0
    H: float = 0.0
    K: float = 1.0
    m: float = 1.0

    def __post_init__(self):
        super().__post_init__()
        for name, least in (("sigma0", 0.0), ("K", 0.0)):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > least):
                raise ValueError(f"{name} must be > 0 and finite, got {value!r}")
        if not (math.isfinite(self.H) and self.H >= 0):
            raise ValueError(f"H must be >= 0 and finite, got {self.H!r}")
        if not (math.isfinite(self.m) and self.m >= 1):
            raise ValueError(f"m must be >= 1 and finite, got {self.m!r}")

    def return_map(self, eps):
        """(εᵖ, p, Δp, y) at the strain ε after the time step, from the committed state.

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            (plastic strain εᵖ, cumulated plastic strain p, its increment Δp, the step's
            overstress y), UFL.
        """
        self.require_3x3(eps)
        st = self._bound()
        mu, H = self.mu, self.H
        s_tr = 2 * mu * ufl.dev(eps - st.eps_v)
        q_tr = ufl.sqrt(1.5 * ufl.inner(s_tr, s_tr))
        f_tr = q_tr - (self.sigma0 + H * st.p)
        # above yield, and a step that takes time (Δt = 0: the instantaneous, elastic
        # response); the other branch is then never evaluated
        flows = ufl.And(ufl.gt(f_tr, 1e-10 * self.sigma0), ufl.gt(st.dt, 0))
        m = float(self.m)
        y = power_root(f_tr, (3 * mu + H) * st.dt / self.K**m, m, flows)
        dp = ufl.conditional(flows, (f_tr - y) / (3 * mu + H), 0)
        q = ufl.conditional(flows, q_tr, 1.0)
        direction = ufl.conditional(flows, 1.5 * s_tr / q, ufl.zero(3, 3))
        return st.eps_v + dp * direction, st.p + dp, dp, ufl.conditional(flows, y, 0)

    def dissipated(self, p, dp, measure):
        """H/2 p² + σ0 Δp + m/(m + 1) y Δp (y: the step's overstress).

        Args:
            p: the cumulated plastic strain after the step.
            dp: its increment.
            measure: y.

        Returns:
            The terms (UFL scalar).
        """
        m = float(self.m)
        return 0.5 * self.H * p**2 + self.sigma0 * dp + m / (m + 1) * measure * dp
