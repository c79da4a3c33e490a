"""What the soils' plastic laws share: cohesion, friction and dilatancy, the in-situ stress.

Stresses are positive in tension. A soil's law (Drucker–Prager, `materials.drucker_prager`;
Mohr–Coulomb, `materials.mohr_coulomb`) is perfectly plastic with a cohesion c > 0, a
friction angle 0 < φ < 90° and a dilatancy angle 0 ≤ ψ ≤ φ (ψ = φ: associated flow; ψ < φ:
the consistent tangent is not symmetric), and bears the ground's initial stress σ_0: the
stress is σ = σ_0 + C : (ε − ε_p(ε)), its UFL derivative through the return map the
consistent tangent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import ufl

from fenics_nl.materials.laws import Isotropic, LinearElastic, SmallStrain
from fenics_nl.materials.plasticity import PlasticState, SmallStrainPlasticity

__all__ = ["SoilPlasticity"]


@dataclass(frozen=True, eq=False)
class SoilPlasticity(SmallStrainPlasticity, Isotropic, SmallStrain):
    """c, φ and ψ (degrees), the initial stress; the subclass gives the yield surface.

    The subclass gives `return_map(ε)` (σ_0 included in its trial stress),
    `yield_function(σ)` (UFL, ≤ 0 inside), `yield_scale` (the size of f's constant term,
    for tolerances) and `apex` (the mean stress at the apex, the most tension it bears).
    """

    c: float = 1.0
    phi: float = 30.0
    psi: float | None = None
    # the stress at ε = 0 (in situ: the ground's before any work): 3x3 in the model's
    # components (uniform), or geostatic {"unit_weight", "K0", "surface"}; None: 0. Not a
    # case file's material key: its [initial_stress] table
    initial_stress: tuple | dict | None = field(default=None, metadata={"case": False})
    state: PlasticState = field(default_factory=PlasticState, init=False, repr=False,
                                compare=False)

    def __post_init__(self):
        super().__post_init__()
        # (each message begins with its parameter's name: a case file names the key)
        if not (math.isfinite(self.c) and self.c > 0):
            raise ValueError(f"c must be > 0 (the cohesion), got {self.c!r}")
        if not 0 < self.phi < 90:
            raise ValueError(f"phi must be in (0, 90) degrees (the friction angle), got "
                             f"{self.phi!r}")
        if not 0 <= self.dilatancy <= self.phi:
            raise ValueError(f"psi must be in [0, phi = {self.phi}] degrees (the dilatancy "
                             f"angle), got {self.psi!r}")
        s0 = self.initial_stress
        if isinstance(s0, dict):
            if set(s0) != {"unit_weight", "K0", "surface"} or not (
                    s0["unit_weight"] > 0 and s0["K0"] > 0 and math.isfinite(s0["surface"])):
                raise ValueError("initial_stress (geostatic) takes unit_weight > 0, K0 > 0 "
                                 f"and a finite surface, got {s0!r}")
        elif s0 is not None:
            rows = [[float(x) for x in row] for row in s0]
            if len(rows) != 3 or any(len(row) != 3 for row in rows) or any(
                    rows[i][j] != rows[j][i] for i in range(3) for j in range(3)):
                raise ValueError(f"initial_stress must be a symmetric 3x3 stress, got {s0!r}")

    def initial(self, like):
        """σ_0, the initial stress (UFL, 3x3; 0 if none) on the domain of `like`.

        Geostatic: the vertical axis is the mesh's last (y in 2D and axisymmetric, z in
        3D); σ_v = −γ (surface − height), the others K0 σ_v, no shear.
        """
        s0 = self.initial_stress
        if s0 is None:
            return ufl.zero(3, 3)
        if not isinstance(s0, dict):
            return ufl.as_matrix([[float(x) for x in row] for row in s0])
        from ufl.domain import extract_unique_domain

        x = ufl.SpatialCoordinate(extract_unique_domain(like))
        up = x.ufl_shape[0] - 1
        vertical = -s0["unit_weight"] * (s0["surface"] - x[up])
        return ufl.diag(ufl.as_vector([vertical if i == up else s0["K0"] * vertical
                                       for i in range(3)]))

    @property
    def dilatancy(self) -> float:
        """ψ in degrees (φ when not given: associated flow)."""
        return self.phi if self.psi is None else float(self.psi)

    @property
    def associated(self) -> bool:
        """ψ = φ: the flow is normal to the yield surface, the tangent symmetric."""
        return self.dilatancy == self.phi

    def energy(self, eps):
        """ψ(ε): the step's condensed energy (associated flow only), W(ε − ε_p) + D.

        The dissipation of an associated step is the support function of the yield
        surface, a cone (or pyramid) with its apex at p_a I: D = σ : Δε_p = p_a tr Δε_p
        (σ − p_a I is orthogonal to the flow on a cone through p_a I). A flow that is not
        associated has no such energy: its σ is not a derivative.

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            ψ (UFL scalar).
        """
        if not self.associated:
            raise ValueError(f"{type(self).__name__} with psi = {self.dilatancy} < phi = "
                             f"{self.phi} has no energy (the flow is not associated): its "
                             "stress is the return map's, not a derivative")
        eps_p, _, _ = self.return_map(eps)
        return (LinearElastic(self.E, self.nu).energy(eps - eps_p)
                + ufl.inner(self.initial(eps), eps - eps_p)
                + self.apex * ufl.tr(eps_p - self._bound().eps_p))

    def stress(self, eps):
        """σ = σ_0 + C : (ε − ε_p(ε)) (UFL, 3x3): the initial stress and Hooke's of the rest.

        Args:
            eps: the small strain ε (UFL, 3x3).
        """
        return self.initial(eps) + super().stress(eps)

    def trial(self, eps):
        """The trial stress σ_0 + C : (ε − ε_p committed) (UFL, 3x3): no flow this step.

        Args:
            eps: the small strain ε (UFL, 3x3).
        """
        eps_e = eps - self._bound().eps_p
        return (self.initial(eps) + 2 * self.mu * ufl.dev(eps_e)
                + self.kappa * ufl.tr(eps_e) * ufl.Identity(3))

    def cumulated(self, d_eps_p, plastic):
        """(p̄, Δp̄) after the step's plastic strain Δε_p: p̄ grows by √(2/3) |Δε_p| (UFL).

        Args:
            d_eps_p: the step's plastic strain (UFL, 3x3), 0 where the step is elastic.
            plastic: where the step flows (a UFL condition).
        """
        # (the root is taken of 1 where the step is elastic: its derivative at 0 is not)
        d_p = ufl.conditional(plastic, ufl.sqrt(2.0 / 3.0 * ufl.inner(d_eps_p, d_eps_p)
                                                + ufl.conditional(plastic, 0.0, 1.0)), 0.0)
        return self._bound().p + d_p, d_p
