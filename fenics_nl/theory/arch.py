"""The shallow sinusoidal arch under a sinusoidal load: snap-through in closed form.

A pinned arch of span L, centreline y₀ = e sin(πx/L), bending stiffness EI, axial stiffness
EA (radius of gyration r = √(I/A)), under the downward load q(x) = q₀ sin(πx/L) per unit
span. Shallow-arch (Marguerre) theory: EI (w − y₀)'''' − N w'' = −q with the uniform axial
force N = (EA/L) ∫ (w'² − y₀'²)/2 dx. The sine is exact, w = a sin(πx/L), and with
k = π/L, ā = a/r, ē = e/r:

    q₀ / (EI k⁴ r) = (ē − ā) + (ē² − ā²) ā / 4,

a cubic in the midspan rise ā (Fung & Kaplan 1952, NACA TN 2840; Simitses, "An
Introduction to the Elastic Stability of Structures", 1976, ch. 7). For ē > 2 it has a
limit point at ā = √((ē² − 4)/3) and the arch snaps through to the inverted branch; an
antisymmetric bifurcation (the second Euler load N = −4 EI k²) comes first only for
ē > √22 ≈ 4.69, so for 2 < ē < √22 the snap is symmetric and the path is this curve,
unstable branch included.
"""

from __future__ import annotations

import math

__all__ = ["limit_load", "limit_rise", "load"]


def load(rise: float, initial_rise: float) -> float:
    """q₀/(EI k⁴ r) at midspan rise ā = a/r, for the unloaded rise ē = e/r."""
    a, e = rise, initial_rise
    return (e - a) + (e * e - a * a) * a / 4


def limit_rise(initial_rise: float) -> float:
    """ā at the limit point, √((ē² − 4)/3); ValueError if ē ≤ 2 (no snap-through)."""
    if not initial_rise > 2:
        raise ValueError(f"a snap-through needs a rise e/r > 2, got {initial_rise}")
    return math.sqrt((initial_rise**2 - 4) / 3)


def limit_load(initial_rise: float) -> float:
    """q₀/(EI k⁴ r) at the limit point."""
    return load(limit_rise(initial_rise), initial_rise)
