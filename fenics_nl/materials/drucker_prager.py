"""Drucker–Prager plasticity of soils: cohesion c, friction angle φ, dilatancy angle ψ.

Stresses are positive in tension; p = tr σ / 3 is the mean stress (negative in
compression) and √J2 = |dev σ| / √2. The yield function and the flow potential are cones
about the hydrostatic axis,

    f = √J2 + η p − ξ c,      g = √J2 + η̄ p,

matched to Mohr–Coulomb on its compression meridian (the outer cone: a triaxial
compression test fails at Mohr–Coulomb's q = 6c cosφ/(3 − sinφ) + 6 p' sinφ/(3 − sinφ),
p' = −p), or through the plane-strain collapse load (`fit = "plane_strain"`):

    compression:   η = 6 sinφ / (√3 (3 − sinφ)),  ξ = 6 cosφ / (√3 (3 − sinφ)),
    plane strain:  η = 3 tanφ / √(9 + 12 tan²φ),  ξ = 3 / √(9 + 12 tan²φ),

and η̄ the same expression as η of the dilatancy angle ψ (ψ = φ: associated flow; ψ < φ:
the consistent tangent is not symmetric). The apex is at p = ξ c / η (c cotφ for the
compression fit).

The return map (perfect plasticity) is in closed form, written in UFL like J2's
(`materials.plasticity`): from the trial state (s_tr, p_tr) at the strain ε less the
committed plastic strain,

* on the cone: Δγ = f_tr / (G + K η η̄), s = (1 − G Δγ / √J2_tr) s_tr, p = p_tr − K η̄ Δγ,
  Δε_p = Δγ (s_tr / (2 √J2_tr) + η̄ I / 3);
* at the apex, if the cone's return would pass it (√J2_tr < G Δγ): s = 0, p = ξ c / η,
  Δε_p = s_tr / (2G) + (p_tr − p) / (3K) I.

σ = σ_0 + C : (ε − ε_p(ε)), σ_0 the initial stress (in situ; 0 by default), and its UFL
derivative through the return map the consistent tangent. The cumulated plastic strain
p̄ grows by √(2/3) |Δε_p|, as J2's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import ufl

from fenics_nl.materials.laws import Isotropic, LinearElastic, SmallStrain
from fenics_nl.materials.plasticity import YIELD_TOLERANCE, PlasticState, SmallStrainPlasticity

__all__ = ["DruckerPrager", "cone"]

FITS = ("compression", "plane_strain")


def cone(angle_degrees: float, fit: str = "compression") -> tuple[float, float]:
    """(η, ξ) of the Drucker–Prager cone matched to Mohr–Coulomb at a friction angle.

    Args:
        angle_degrees: the friction angle φ (or the dilatancy angle ψ, for η̄), degrees.
        fit: "compression" (the outer cone, through the compression meridian) or
            "plane_strain" (the same collapse load in plane strain, associated flow).

    Returns:
        (η, ξ).
    """
    a = math.radians(angle_degrees)
    if fit == "compression":
        d = math.sqrt(3.0) * (3.0 - math.sin(a))
        return 6.0 * math.sin(a) / d, 6.0 * math.cos(a) / d
    if fit == "plane_strain":
        d = math.sqrt(9.0 + 12.0 * math.tan(a) ** 2)
        return 3.0 * math.tan(a) / d, 3.0 / d
    raise ValueError(f"fit must be one of {FITS}, got {fit!r}")


@dataclass(frozen=True, eq=False)
class DruckerPrager(SmallStrainPlasticity, Isotropic, SmallStrain):
    """Drucker–Prager plasticity (perfect): cohesion c > 0, angles φ and ψ in degrees.

    0 < φ < 90°, 0 ≤ ψ ≤ φ (ψ = None: φ, associated). Models: 3D, plane strain,
    axisymmetric (3x3 strains).
    """

    c: float = 1.0
    phi: float = 30.0
    psi: float | None = None
    fit: str = "compression"
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
        cone(self.phi, self.fit)  # the fit is known
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
        """ψ = φ: the flow is normal to the yield cone, the tangent symmetric."""
        return self.dilatancy == self.phi

    @property
    def cone_constants(self) -> tuple[float, float]:
        """(η, ξ) of the yield cone."""
        return cone(self.phi, self.fit)

    @property
    def apex(self) -> float:
        """The mean stress p = ξ c / η at the cone's apex (tension: the most it bears)."""
        eta, xi = cone(self.phi, self.fit)
        return xi * self.c / eta

    def yield_function(self, sigma):
        """f(σ) = √J2 + η p − ξ c (UFL): ≤ 0 inside the cone."""
        eta, xi = cone(self.phi, self.fit)
        s = ufl.dev(sigma)
        return ufl.sqrt(0.5 * ufl.inner(s, s)) + eta * ufl.tr(sigma) / 3 - xi * self.c

    def energy(self, eps):
        """ψ(ε): the step's condensed energy (associated flow only), W(ε − ε_p) + D.

        The dissipation of an associated step is the support function of the cone:
        D = σ : Δε_p = (ξ c / η) tr Δε_p on the cone (ξ c Δγ) and at the apex alike. A
        flow that is not associated has no such energy: its σ is not a derivative.

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            ψ (UFL scalar).
        """
        if not self.associated:
            raise ValueError(f"Drucker–Prager with psi = {self.dilatancy} < phi = {self.phi} "
                             "has no energy (the flow is not associated): its stress is the "
                             "return map's, not a derivative")
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

    def return_map(self, eps):
        """(ε_p, p̄, Δp̄) at the strain ε from the committed state (UFL; module docstring).

        Args:
            eps: the small strain ε (UFL, 3x3).

        Returns:
            (plastic strain ε_p, cumulated plastic strain p̄, its increment), UFL.
        """
        self.require_3x3(eps)
        st = self._bound()
        eta, xi = cone(self.phi, self.fit)
        eta_bar, _ = cone(self.dilatancy, self.fit)
        G, K = self.mu, self.kappa
        eps_e = eps - st.eps_p
        sigma_0 = self.initial(eps)
        s_tr = ufl.dev(sigma_0) + 2 * G * ufl.dev(eps_e)
        p_tr = ufl.tr(sigma_0) / 3 + K * ufl.tr(eps_e)
        root_j2 = ufl.sqrt(0.5 * ufl.inner(s_tr, s_tr))
        f = root_j2 + eta * p_tr - xi * self.c
        # a point left on the cone by the last step has f = 0 up to round-off (of the
        # terms f is made of): it starts the next step elastic (as J2's)
        plastic = ufl.gt(f, YIELD_TOLERANCE * (xi * self.c + eta * abs(p_tr)))
        dgamma = f / (G + K * eta * eta_bar)
        on_cone = ufl.And(plastic, ufl.ge(root_j2, G * dgamma))
        at_apex = ufl.And(plastic, ufl.lt(root_j2, G * dgamma))
        identity = ufl.Identity(3)
        # the flow direction only where it is defined (√J2_tr > 0 on the cone)
        cone_flow = dgamma * (s_tr / (2 * ufl.conditional(on_cone, root_j2, 1.0))
                              + eta_bar / 3 * identity)
        apex_flow = s_tr / (2 * G) + (p_tr - xi * self.c / eta) / (3 * K) * identity
        d_eps_p = ufl.conditional(on_cone, cone_flow,
                                  ufl.conditional(at_apex, apex_flow, ufl.zero(3, 3)))
        d_p = ufl.conditional(plastic, ufl.sqrt(2.0 / 3.0 * ufl.inner(d_eps_p, d_eps_p)
                                                + ufl.conditional(plastic, 0.0, 1.0)), 0.0)
        return st.eps_p + d_eps_p, st.p + d_p, d_p
