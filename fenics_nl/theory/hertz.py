"""Hertz's closed forms for a rigid indenter on an elastic half-space (frictionless).

And for two elastic bodies (`pair_modulus`, `relative_radius`: 1/E* = (1 − ν1²)/E1 +
(1 − ν2²)/E2, 1/R = 1/R1 + 1/R2, in the same laws with E* and R), Sneddon's for a rigid
cone, the other axisymmetric indenter of instrumented indentation, and the fit of Hertz's
pressure ellipse to a computed profile (`fitted_ellipse`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = [
    "HertzCheck",
    "compare_with_hertz",
    "cone_from_indentation",
    "contact_radius_for",
    "cylinder_from_force",
    "effective_modulus",
    "fitted_ellipse",
    "pair_modulus",
    "pressure_profile",
    "relative_radius",
    "sphere_from_force",
    "sphere_from_indentation",
]


def effective_modulus(E: float, nu: float) -> float:
    """E* = E / (1 − ν²) (rigid indenter)."""
    return E / (1 - nu**2)


def pair_modulus(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """E* of two elastic bodies: 1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2.

    Hertz's laws below take it as E with ν = 0 (`effective_modulus(E*, 0) = E*`).
    """
    return 1.0 / ((1 - nu1**2) / E1 + (1 - nu2**2) / E2)


def relative_radius(R1: float, R2: float | None = None) -> float:
    """R of two convex bodies: 1/R = 1/R1 + 1/R2 (R2 None: a plane; negative: a hollow)."""
    return 1.0 / (1.0 / R1 + (0.0 if R2 is None else 1.0 / R2))


def fitted_ellipse(r, p) -> tuple[float, float]:
    """(p0, a) of Hertz's p = p0 √(1 − r²/a²) fitted to a profile: p² linear in r².

    Args:
        r: the radii (the distances from the centre) of nodes inside the contact.
        p: their pressures.

    Returns:
        (p0, a) of the least-squares line p² = p0² − (p0/a)² r².
    """
    slope, intercept = np.polyfit(np.asarray(r, float) ** 2, np.asarray(p, float) ** 2, 1)
    return math.sqrt(intercept), math.sqrt(-intercept / slope)


def sphere_from_indentation(E: float, nu: float, R: float, delta: float) -> dict[str, float]:
    """Sphere of radius R pressed by δ: force P, contact radius a, peak pressure p0."""
    Es = effective_modulus(E, nu)
    a = math.sqrt(R * delta)
    P = 4.0 / 3.0 * Es * math.sqrt(R) * delta**1.5
    return {"force": P, "contact_radius": a, "max_pressure": 3 * P / (2 * math.pi * a * a)}


def sphere_from_force(E: float, nu: float, R: float, P: float) -> dict[str, float]:
    """Sphere of radius R under force P: indentation δ, contact radius a, peak pressure p0."""
    Es = effective_modulus(E, nu)
    a = (3 * P * R / (4 * Es)) ** (1 / 3)
    return {"indentation": a * a / R, "contact_radius": a,
            "max_pressure": 3 * P / (2 * math.pi * a * a)}


def cylinder_from_force(E: float, nu: float, R: float, P: float) -> dict[str, float]:
    """Cylinder of radius R, plane strain, force P per unit length: half-width a, p0."""
    Es = effective_modulus(E, nu)
    a = math.sqrt(4 * P * R / (math.pi * Es))
    return {"contact_radius": a, "max_pressure": 2 * P / (math.pi * a)}


def cone_from_indentation(E: float, nu: float, cot: float, delta: float) -> dict[str, float]:
    """Cone of slope cot α pressed by δ (Sneddon): P = 2 E* δ² tan α / π, a = 2 δ tan α / π.

    The mean pressure P/(π a²) = E* cot α / 2 does not depend on δ (a cone is self-similar);
    the pressure is infinite (logarithmically) at the tip: no peak pressure is given.
    """
    Es = effective_modulus(E, nu)
    a = 2 * delta / (math.pi * cot)
    return {"force": 2 * Es * delta**2 / (math.pi * cot), "contact_radius": a}


def pressure_profile(p0: float, a: float, r):
    """p(r) = p0 √(1 − r²/a²) inside the contact, 0 outside."""
    r = np.asarray(r, dtype=float)
    return p0 * np.sqrt(np.clip(1 - (r / a) ** 2, 0.0, None))


def contact_radius_for(model: str, E: float, nu: float, radius: float,
                       indentation: float | None, force: float | None) -> float:
    """The contact radius a punch's block is meshed for.

    Args:
        model: ``axisymmetric``, ``3d`` (a sphere) or ``plane_strain`` (a cylinder).
        E: Young's modulus.
        nu: Poisson's ratio.
        radius: the punch's radius R.
        indentation: the depth δ prescribed (used when `force` is None).
        force: the force P prescribed (per unit length for the cylinder), or None.

    Returns:
        Hertz's a for the force (the cylinder's half-width), else √(R |δ|) (for a cylinder,
        a safe overestimate of its half-width).
    """
    if force is None:
        return math.sqrt(radius * abs(indentation))
    law = cylinder_from_force if model == "plane_strain" else sphere_from_force
    return law(E, nu, radius, force)["contact_radius"]


@dataclass
class HertzCheck:
    """A loaded state against Hertz, and the lines that say it.

    `ref`: Hertz's values (None: no contact); `errors`: the relative ones; `exponent`: m of
    P ∝ δ^m fitted over the loading steps (None with fewer than two); `lines`: the check in
    words, for the run's output.
    """

    ref: dict | None
    errors: dict = field(default_factory=dict)
    exponent: float | None = None
    lines: list[str] = field(default_factory=list)


def compare_with_hertz(loading: list, hertz_of, model: str, h: float) -> HertzCheck:
    """The last loading state's force, contact radius and largest pressure against Hertz.

    The force is not checked for the cylinder; the radius is the outermost active node's.

    Args:
        loading: the converged loading states (`indentation`, `force`, `contact_radius`,
            `max_pressure`).
        hertz_of: Hertz's values for a state (a dict with some of those keys).
        model: ``axisymmetric``, ``3d`` or ``plane_strain``.
        h: the element size under the punch.

    Returns:
        The check: Hertz's values, the relative errors, the fitted exponent, and its lines
        (the errors in one, the exponent in another).
    """
    last = loading[-1]
    if not last.force > 0:
        return HertzCheck(None, lines=["the punch does not touch the block: zero contact "
                                       "force"])
    ref = hertz_of(last)
    errors = {k: getattr(last, k) / ref[k] - 1 for k in ("force", "contact_radius",
                                                         "max_pressure") if k in ref}
    checked = [f"{k.replace('_', ' ')} {getattr(last, k):.6g} (Hertz {ref[k]:.6g}, "
               f"{100 * e:+.3f} %)" for k, e in errors.items()]
    if model == "plane_strain":  # a cylinder: Hertz's a and p0 for the computed P
        checked.insert(0, f"P = {last.force:.6g} per unit length (not checked)")
    lines = ["; ".join(checked) + f"; h = {h:.2g}"]
    exponent = None
    if len(loading) >= 2 and all(s.force > 0 for s in loading):
        exponent = float(np.polyfit(np.log([s.indentation for s in loading]),
                                    np.log([s.force for s in loading]), 1)[0])
        lines.append(f"P ∝ δ^{exponent:.4f} over the steps" + (
            "" if model == "plane_strain" else " (Hertz: 1.5)"))
    return HertzCheck(ref, errors, exponent, lines)
