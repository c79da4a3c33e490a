"""The elastica: post-buckling of an inextensible cantilever under a dead axial load.

With α the tip rotation, k = sin(α/2) and K, E the complete elliptic integrals of modulus k::

    P/P_cr = (2K(k)/π)²,   lateral tip deflection δ/L = 2k/K,   axial tip position x/L = 2E/K − 1,

and P_cr = π²EI/(4L²) (Euler). SciPy's ellipk/ellipe take the parameter m = k².
"""

from __future__ import annotations

import math

from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

__all__ = ["euler_load", "load_ratio", "shape", "tip_position", "tip_rotation"]


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


def shape(ratio: float, points: int = 200):
    """Deformed centreline (x/L, y/L) of the elastica at P/P_cr = ratio (straight below 1).

    EI θ'' = −P sin θ with θ(L) = α and θ'(L) = 0, integrated from the free end to the
    clamp (θ(0) = 0 follows from α = tip_rotation(ratio)); x = ∫cos θ, y = ∫sin θ.
    """
    import numpy as np
    from scipy.integrate import solve_ivp

    s = np.linspace(0.0, 1.0, points)
    alpha = tip_rotation(ratio)
    if alpha == 0.0:
        return s, np.zeros_like(s)
    lam2 = ratio * math.pi**2 / 4  # λ²L² = P L²/EI

    def rhs(_, y):  # y = (θ, θ', x, y), in s/L, integrated backwards
        return [y[1], -lam2 * math.sin(y[0]), math.cos(y[0]), math.sin(y[0])]

    sol = solve_ivp(rhs, (1.0, 0.0), [alpha, 0.0, 0.0, 0.0], t_eval=s[::-1], rtol=1e-10,
                    atol=1e-12)
    x, y = sol.y[2][::-1], sol.y[3][::-1]
    return x - x[0], y - y[0]
