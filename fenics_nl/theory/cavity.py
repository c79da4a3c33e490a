"""A cylindrical cavity unloaded in a Mohr–Coulomb ground (plane strain): Salençon's solution.

Compression positive here (the literature's sign). A cavity of radius R in a ground under
the isotropic in-situ stress p0 has its support pressure lowered from p0 to p_i; with
K_p = (1 + sinφ)/(1 − sinφ) and σ_c = 2c cosφ/(1 − sinφ) (Salençon, *Contraction quasi-
statique d'une cavité à symétrie sphérique ou cylindrique dans un milieu
élastoplastique*, Annales des Ponts et Chaussées, 1969), plasticity starts at
p_i = p0 (1 − sinφ) − c cosφ, and in the plastic zone R < r < R_p

    σ_r = (p_i + c cotφ)(r/R)^(K_p − 1) − c cotφ,     σ_θ = K_p σ_r + σ_c;

outside, Lamé's field. In an infinite ground σ_r(R_p) = (2 p0 − σ_c)/(K_p + 1) and

    R_p = R [2 (p0 + c cotφ) / ((K_p + 1)(p_i + c cotφ))]^(1/(K_p − 1));

φ → 0 (Tresca) gives R_p = R exp((p0 − p_i)/(2c) − 1/2). Here the ground may also end at
r = b under the pressure p0 (a mesh's outer boundary): the same plastic zone, the elastic
ring's Lamé field through σ_r(b) = p0, and R_p the root of the yield condition at its
inner edge (b = ∞: the closed form above).

The wall's displacement (Carranza-Torres & Fairhurst, *The elasto-plastic response of
underground excavations in rock masses that satisfy the Hoek–Brown failure criterion*,
IJRMMS 36, 1999, §3, for the method): the flow rule of the main plane, ε_r^p + K_ψ ε_θ^p = 0
with K_ψ = (1 + sinψ)/(1 − sinψ), makes u' + K_ψ u/r = ε_r^e + K_ψ ε_θ^e, integrated here by
quadrature from u(R_p) = R_p ε_θ^e(R_p) of the elastic ring; the elastic strains are the
plane-strain Hooke's of the stresses less p0. It assumes σ_z stays the intermediate stress
(σ_r ≤ σ_z ≤ σ_θ; σ_z = p0 + ν (σ_r + σ_θ − 2 p0) while no plastic strain is along z):
`out_of_plane` gives σ_z to check.
"""

from __future__ import annotations

import math

from scipy.integrate import quad
from scipy.optimize import brentq

__all__ = ["Cavity"]


class Cavity:
    """Salençon's cavity: radius R, in-situ p0, support p_i, the ground ending at b (or ∞).

    Args:
        R: the cavity's radius.
        p0: the in-situ stress (compression positive).
        p_i: the support pressure, below p0.
        c: the cohesion.
        phi: the friction angle, degrees.
        psi: the dilatancy angle, degrees (None: φ).
        E: Young's modulus (for the displacement).
        nu: Poisson's ratio.
        b: the outer radius under p0 (math.inf: an infinite ground).
    """

    def __init__(self, R, p0, p_i, c, phi, psi=None, E=1.0, nu=0.3, b=math.inf):
        if not (0 < R < b and -c / math.tan(math.radians(phi)) < p_i < p0):
            raise ValueError(f"a cavity needs 0 < R < b and −c cotφ < p_i < p0, got R = {R}, "
                             f"b = {b}, p_i = {p_i}, p0 = {p0}")
        self.R, self.p0, self.p_i, self.c, self.E, self.nu, self.b = R, p0, p_i, c, E, nu, b
        s, t = math.sin(math.radians(phi)), math.sin(math.radians(phi if psi is None else psi))
        self.Kp, self.Kpsi = (1 + s) / (1 - s), (1 + t) / (1 - t)
        self.sigma_c = 2 * c * math.cos(math.radians(phi)) / (1 - s)
        self.h = c / math.tan(math.radians(phi))  # c cotφ
        self.Rp = self._plastic_radius()
        self.A, self.B = self._ring(self.Rp)

    def _radial_plastic(self, r):
        return (self.p_i + self.h) * (r / self.R) ** (self.Kp - 1) - self.h

    def _ring(self, Rp):
        """Lamé's σ = A ∓ B/r² of the elastic ring yielding at its inner edge Rp."""
        s_rp = self._radial_plastic(Rp)
        A = (self.sigma_c + (1 + self.Kp) * s_rp) / 2
        return A, (A - s_rp) * Rp ** 2

    def _plastic_radius(self):
        if math.isinf(self.b):  # (below R: the wall has not yielded)
            return max(self.R, self.R * (2 * (self.p0 + self.h) / (
                (self.Kp + 1) * (self.p_i + self.h))) ** (1 / (self.Kp - 1)))

        def outer_mismatch(Rp):
            A, B = self._ring(Rp)
            return A - B / self.b ** 2 - self.p0

        if outer_mismatch(self.R) >= 0:  # the wall has not yielded
            return self.R
        if outer_mismatch(self.b) < 0:
            raise ValueError(f"the whole ring r < b = {self.b} is plastic at p_i = "
                             f"{self.p_i}: no elastic ring is left (the ring's limit load)")
        return brentq(outer_mismatch, self.R, self.b, xtol=1e-14 * self.R, rtol=1e-15)

    def stresses(self, r):
        """(σ_r, σ_θ) at the radius r (compression positive)."""
        if r <= self.Rp and self.Rp > self.R:
            s_r = self._radial_plastic(r)
            return s_r, self.Kp * s_r + self.sigma_c
        if self.Rp == self.R:  # elastic throughout: Lamé's between p_i and p0
            A, B = self._elastic_ring()
        else:
            A, B = self.A, self.B
        return A - B / r ** 2, A + B / r ** 2

    def _elastic_ring(self):
        b2 = self.b ** 2 if math.isfinite(self.b) else math.inf
        if math.isinf(b2):
            return self.p0, (self.p0 - self.p_i) * self.R ** 2
        B = (self.p0 - self.p_i) * self.R ** 2 * b2 / (b2 - self.R ** 2)
        return self.p0 + B / b2, B

    def out_of_plane(self, r):
        """σ_z at the radius r: p0 + ν (σ_r + σ_θ − 2 p0) (compression positive)."""
        s_r, s_t = self.stresses(r)
        return self.p0 + self.nu * (s_r + s_t - 2 * self.p0)

    def _elastic_strains(self, r):
        """(ε_r^e, ε_θ^e) of the stress change at r (tension-positive strains, plane strain)."""
        s_r, s_t = (self.p0 - s for s in self.stresses(r))  # the change, tension positive
        E, nu = self.E, self.nu
        return (((1 - nu ** 2) * s_r - nu * (1 + nu) * s_t) / E,
                ((1 - nu ** 2) * s_t - nu * (1 + nu) * s_r) / E)

    def wall_displacement(self) -> float:
        """u(R), outward positive (a cavity unloaded converges: u < 0)."""
        Rp, k = self.Rp, self.Kpsi
        u_rp = Rp * self._elastic_strains(Rp)[1]
        if Rp == self.R:
            return u_rp

        def g(r):
            e_r, e_t = self._elastic_strains(r)
            return r ** k * (e_r + k * e_t)

        integral, _ = quad(g, self.R, Rp, epsabs=0.0, epsrel=1e-12, limit=200)
        return (u_rp * Rp ** k - integral) / self.R ** k

    @staticmethod
    def tresca_radius(R, p0, p_i, c):
        """φ = 0's R_p = R exp((p0 − p_i)/(2c) − 1/2) (an infinite ground)."""
        return R * math.exp((p0 - p_i) / (2 * c) - 0.5)
