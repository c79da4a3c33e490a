"""The elastica: post-buckling of an inextensible cantilever under a dead axial load.

With α the tip rotation, k = sin(α/2) and K, E the complete elliptic integrals of modulus k:
    P/P_cr = (2K(k)/π)²,   lateral tip deflection δ/L = 2k/K,   axial tip position x/L = 2E/K − 1,
and P_cr = π²EI/(4L²) (Euler). SciPy's ellipk/ellipe take the parameter m = k².
"""

from __future__ import annotations

import math

from scipy.optimize import brentq
from scipy.special import ellipe, ellipk


def euler_load(E: float, I: float, L: float) -> float:  # noqa: E741
    """P_cr = π² E I / (4 L²) of a clamped–free column."""
    return math.pi**2 * E * I / (4 * L**2)


def load_ratio(alpha: float) -> float:
    """P/P_cr at tip rotation α [rad] (α in [0, π))."""
    k = math.sin(alpha / 2)
    return (2 * ellipk(k * k) / math.pi) ** 2


def tip_rotation(ratio: float) -> float:
    """Tip rotation α [rad] on the buckled branch at P/P_cr = ratio (0 below 1)."""
    if ratio <= 1.0:
        return 0.0
    return brentq(lambda a: load_ratio(a) - ratio, 1e-12, math.pi - 1e-9, xtol=1e-14)


def tip_position(ratio: float) -> tuple[float, float]:
    """(lateral deflection δ/L, axial position x/L) of the tip at P/P_cr = ratio."""
    k = math.sin(tip_rotation(ratio) / 2)
    K, Ek = ellipk(k * k), ellipe(k * k)
    return 2 * k / K, 2 * Ek / K - 1
