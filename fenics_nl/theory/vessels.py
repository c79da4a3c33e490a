"""Thick pressure vessels in perfect J2 plasticity under internal pressure p (small strain).

Hollow sphere a < r < b (exact for every ν: σ_eq = |σ_θ − σ_r|)::

    yield onset p_e = (2σ0/3)(1 − a³/b³); plastic radius c from
    p = 2σ0 ln(c/a) + (2σ0/3)(1 − c³/b³); limit 2σ0 ln(b/a).

Cylinder, plane strain (Y = 2σ0/√3): limit Y ln(b/a) (exact); yield onset from Lamé with
σ_z = ν(σ_r + σ_θ) (exact for every ν); c(p) = from p = Y ln(c/a) + (Y/2)(1 − c²/b²),
which assumes σ_z = (σ_r + σ_θ)/2: exact for ν = 1/2 only.

And an incompressible neo-Hookean sphere inflated (finite strain, exact): reference radii
A < B, λ_a = a/A, λ_b = b/B with λ_b³ = 1 + (λ_a³ − 1) A³/B³ (the volume kept),

    p = 2μ [(1/λ_b + 1/(4λ_b⁴)) − (1/λ_a + 1/(4λ_a⁴))],

which rises to a maximum and falls: a limit point under pressure control.

And Norton creep (ε̇ = A σ_eqⁿ uniaxially) once the stresses no longer change (exact for any
elasticity, as the elastic strains are then constant and the flow incompressible), k = 2/n
(cylinder, plane strain) or 3/n (sphere):

    σ_r = −p [(b/r)^k − 1]/[(b/a)^k − 1],
    σ_θ = p [(k − 1)(b/r)^k + 1]/[(b/a)^k − 1]  (cylinder; σ_z = (σ_r + σ_θ)/2),
    σ_θ = p [(k/2 − 1)(b/r)^k + 1]/[(b/a)^k − 1]  (sphere),

Lamé's at n = 1. The velocity is C/r (cylinder) or C/r² (sphere): from σ_eq = (√3/2)(σ_θ −
σ_r) and ε̇_eq = (2/√3) C/r² (cylinder), σ_eq = σ_θ − σ_r and ε̇_eq = 2C/r³ (sphere),
integrating equilibrium from the bore's −p to the outside's 0,

    C = (√3/2) A b² [(√3/2) p k/((b/a)^k − 1)]ⁿ (cylinder),  (A/2) b³ [p k/(2((b/a)^k − 1))]ⁿ
    (sphere).
"""

from __future__ import annotations

import math

from scipy.optimize import brentq, minimize_scalar

__all__ = [
    "elastic_inner_compliance",
    "elastic_stresses",
    "limit_pressure",
    "neo_hookean_sphere_maximum",
    "neo_hookean_sphere_pressure",
    "plastic_radius",
    "residual_hoop_stress_inner",
    "sphere_inner_displacement",
    "stationary_creep_bore_rate",
    "stationary_creep_stresses",
    "von_mises",
    "yield_onset_pressure",
]


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


def stationary_creep_stresses(shape: str, a: float, b: float, p: float, n: float, r):
    """(σ_r, σ_θ) of stationary Norton creep at radius r (scalar or array; module).

    Args:
        shape: ``cylinder`` (plane strain) or ``sphere``.
        a: the inner radius.
        b: the outer radius.
        p: the inner pressure.
        n: Norton's exponent (1: Lamé's elastic stresses).
        r: the radius.

    Returns:
        (σ_r, σ_θ), tension positive.
    """
    k = (2.0 if shape == "cylinder" else 3.0) / n
    ratio, scale = (b / r) ** k, p / ((b / a) ** k - 1)
    hoop = (k - 1) if shape == "cylinder" else (k / 2 - 1)
    return -scale * (ratio - 1), scale * (hoop * ratio + 1)


def stationary_creep_bore_rate(shape: str, a: float, b: float, p: float, A: float,
                               n: float) -> float:
    """The bore's radial velocity u̇(a) of stationary Norton creep: C/a or C/a² (module).

    Args:
        shape: ``cylinder`` (plane strain) or ``sphere``.
        a: the inner radius.
        b: the outer radius.
        p: the inner pressure.
        A: Norton's coefficient (ε̇ = A σⁿ uniaxially).
        n: Norton's exponent.

    Returns:
        u̇(a), outwards positive.
    """
    if shape == "cylinder":
        k = 2 / n
        c = math.sqrt(3) / 2 * A * b**2 * (math.sqrt(3) / 2 * p * k / ((b / a) ** k - 1)) ** n
        return c / a
    k = 3 / n
    return A / 2 * b**3 * (p * k / (2 * ((b / a) ** k - 1))) ** n / a**2


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
    if gap(b) <= 0:  # at (or, by round-off, past) the limit: the whole wall
        return b
    return brentq(gap, a, b, xtol=1e-14 * b)


def residual_hoop_stress_inner(a: float, b: float, sigma0: float, p: float) -> float:
    """Sphere, after loading to p and unloading elastically: σ_θ(a).

    Zero if p did not reach the yield onset (the unloading undoes an elastic loading);
    else the plastic zone's σ_θ(a) less Lamé's elastic one for the same p.
    """
    if p <= yield_onset_pressure("sphere", a, b, sigma0):  # ν-free for the sphere
        return 0.0
    loaded = -p + sigma0  # plastic zone: σ_θ = σ_r + σ0, σ_r(a) = −p
    return loaded - elastic_stresses("sphere", a, b, p, a)[1]


def elastic_inner_compliance(shape: str, a: float, b: float, E: float, nu: float) -> float:
    """u(a)/p of Lamé's elastic solution (cylinder: plane strain)."""
    if shape == "sphere":
        return a**3 / (b**3 - a**3) * ((1 - 2 * nu) * a + (1 + nu) * b**3 / (2 * a * a)) / E
    return a * (1 + nu) * ((1 - 2 * nu) * a * a + b * b) / (E * (b * b - a * a))


def sphere_inner_displacement(a: float, b: float, E: float, nu: float, sigma0: float,
                              p: float) -> float:
    """u(a) of the sphere loaded monotonically to p ≤ p_lim (exact for every ν).

    Elastic zone c < r < b: Lamé's shell under p_c = (2σ0/3)(1 − c³/b³) at r = c. Plastic
    zone: σ_r = 2σ0 ln(r/c) − p_c, σ_θ = σ_r + σ0, and the plastic flow keeps the volume, so
    (r² u)' = r² tr ε = r² (1 − 2ν)/E (3σ_r + 2σ0) integrates from u(c) down to r = a.
    """
    p_lim = limit_pressure("sphere", a, b, sigma0)
    if p > p_lim * (1 + 1e-12):
        raise ValueError(f"p = {p:g} is beyond the limit pressure: no equilibrium")
    p = min(p, p_lim)
    c = plastic_radius("sphere", a, b, sigma0, p)
    if c == a:
        return p * elastic_inner_compliance("sphere", a, b, E, nu)
    p_c = 2 * sigma0 / 3 * (1 - c**3 / b**3)
    # Lamé's u(c) = p_c c³/(b³ − c³) (...), with p_c c³/(b³ − c³) = (2σ0/3) c³/b³: finite at c = b
    u_c = 2 * sigma0 / 3 * c**3 / b**3 * ((1 - 2 * nu) * c + (1 + nu) * b**3 / (2 * c * c)) / E
    # ∫_a^c ρ² (6σ0 ln(ρ/c) + 2σ0 − 3p_c) dρ
    integral = (6 * sigma0 * (-c**3 / 9 - a**3 / 3 * math.log(a / c) + a**3 / 9)
                + (2 * sigma0 - 3 * p_c) * (c**3 - a**3) / 3)
    return (c * c * u_c - (1 - 2 * nu) / E * integral) / (a * a)


def neo_hookean_sphere_pressure(stretch: float, A: float, B: float, mu: float) -> float:
    """p of the incompressible neo-Hookean sphere at the inner stretch λ_a = a/A (module)."""
    lb = (1 + (stretch**3 - 1) * A**3 / B**3) ** (1 / 3)
    return 2 * mu * ((1 / lb + 1 / (4 * lb**4)) - (1 / stretch + 1 / (4 * stretch**4)))


def neo_hookean_sphere_maximum(A: float, B: float, mu: float) -> tuple[float, float]:
    """(λ_a, p) at the pressure's maximum (B = 1.2 A: λ_a = 1.4702, p = 0.225138 μ)."""
    best = minimize_scalar(lambda s: -neo_hookean_sphere_pressure(s, A, B, mu),
                           bounds=(1.0, 10.0), method="bounded",
                           options={"xatol": 1e-10})
    return float(best.x), -float(best.fun)
