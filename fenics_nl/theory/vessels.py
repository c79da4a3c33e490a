"""Thick pressure vessels in perfect J2 plasticity under internal pressure p (small strain).

Hollow sphere a < r < b (exact for every ν: σ_eq = |σ_θ − σ_r|):
    yield onset p_e = (2σ0/3)(1 − a³/b³); plastic radius c from
    p = 2σ0 ln(c/a) + (2σ0/3)(1 − c³/b³); limit 2σ0 ln(b/a).
Cylinder, plane strain (Y = 2σ0/√3): limit Y ln(b/a) (exact); yield onset from Lamé with
σ_z = ν(σ_r + σ_θ) (exact for every ν); c(p) = from p = Y ln(c/a) + (Y/2)(1 − c²/b²),
which assumes σ_z = (σ_r + σ_θ)/2: exact for ν = 1/2 only.
"""

from __future__ import annotations

import math

from scipy.optimize import brentq


def limit_pressure(shape: str, a: float, b: float, sigma0: float) -> float:
    """The pressure at which the whole wall is plastic."""
    if shape == "sphere":
        return 2 * sigma0 * math.log(b / a)
    return 2 / math.sqrt(3) * sigma0 * math.log(b / a)


def elastic_stresses(shape: str, a: float, b: float, p: float, r: float, nu: float = 0.3):
    """Lamé's (σ_r, σ_θ, σ_third) at radius r: σ_φ = σ_θ (sphere), σ_z = ν(σ_r + σ_θ)."""
    if shape == "sphere":
        k = p * a**3 / (b**3 - a**3)
        sr, st = -k * (b**3 / r**3 - 1), k * (b**3 / (2 * r**3) + 1)
        return sr, st, st
    k = p * a * a / (b * b - a * a)
    sr, st = k * (1 - b * b / (r * r)), k * (1 + b * b / (r * r))
    return sr, st, nu * (sr + st)


def von_mises(s1: float, s2: float, s3: float) -> float:
    """σ_eq of principal stresses."""
    return math.sqrt(0.5 * ((s1 - s2) ** 2 + (s2 - s3) ** 2 + (s3 - s1) ** 2))


def yield_onset_pressure(shape: str, a: float, b: float, sigma0: float,
                         nu: float = 0.3) -> float:
    """The pressure at which r = a first yields (σ_eq ∝ p in the elastic range)."""
    return sigma0 / von_mises(*elastic_stresses(shape, a, b, 1.0, a, nu))


def plastic_radius(shape: str, a: float, b: float, sigma0: float, p: float) -> float:
    """c(p) between the yield onset and the limit (cylinder: the ν = 1/2 closed form)."""
    if shape == "sphere":
        def gap(c):
            return 2 * sigma0 * math.log(c / a) + 2 * sigma0 / 3 * (1 - c**3 / b**3) - p
    else:
        Y = 2 * sigma0 / math.sqrt(3)

        def gap(c):
            return Y * math.log(c / a) + Y / 2 * (1 - c * c / (b * b)) - p
    if gap(a) >= 0:
        return a
    return brentq(gap, a, b, xtol=1e-14 * b)


def residual_hoop_stress_inner(a: float, b: float, sigma0: float, p: float) -> float:
    """Sphere, after loading to p (a < c ≤ b) and unloading elastically: σ_θ(a)."""
    loaded = -p + sigma0  # plastic zone: σ_θ = σ_r + σ0, σ_r(a) = −p
    return loaded - elastic_stresses("sphere", a, b, p, a)[1]
