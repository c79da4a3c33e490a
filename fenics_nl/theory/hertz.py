"""Hertz's closed forms for a rigid indenter on an elastic half-space (frictionless).

And Sneddon's for a rigid cone, the other axisymmetric indenter of instrumented indentation.
"""

from __future__ import annotations

import math

__all__ = [
    "cone_from_indentation",
    "cylinder_from_force",
    "effective_modulus",
    "pressure_profile",
    "sphere_from_force",
    "sphere_from_indentation",
]


def effective_modulus(E: float, nu: float) -> float:
    """E* = E / (1 − ν²) (rigid indenter)."""
    return E / (1 - nu**2)


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
    import numpy as np

    r = np.asarray(r, dtype=float)
    return p0 * np.sqrt(np.clip(1 - (r / a) ** 2, 0.0, None))
