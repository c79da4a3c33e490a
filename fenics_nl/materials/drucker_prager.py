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
from dataclasses import dataclass

import ufl

from fenics_nl.materials.plasticity import YIELD_TOLERANCE
from fenics_nl.materials.soil import SoilPlasticity

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
class DruckerPrager(SoilPlasticity):
    """Drucker–Prager plasticity (perfect): cohesion c > 0, angles φ and ψ in degrees.

    0 < φ < 90°, 0 ≤ ψ ≤ φ (ψ = None: φ, associated). Models: 3D, plane strain,
    axisymmetric (3x3 strains).
    """

    fit: str = "compression"

    def __post_init__(self):
        super().__post_init__()
        cone(self.phi, self.fit)  # the fit is known

    @property
    def cone_constants(self) -> tuple[float, float]:
        """(η, ξ) of the yield cone."""
        return cone(self.phi, self.fit)

    @property
    def yield_scale(self) -> float:
        """ξ c, f's constant term (the tolerances' scale)."""
        return cone(self.phi, self.fit)[1] * self.c

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
        sigma_tr = self.trial(eps)
        s_tr, p_tr = ufl.dev(sigma_tr), ufl.tr(sigma_tr) / 3
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
        return (st.eps_p + d_eps_p, *self.cumulated(d_eps_p, plastic))
