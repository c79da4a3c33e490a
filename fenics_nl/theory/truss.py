"""The von Mises (two-bar) truss: a shallow pinned arch of two bars that snaps through.

Bars from (±a, 0) to the apex (0, h), reference length L = √(a² + h²), axial energy
EA/2 e² per unit reference length in the Green–Lagrange strain e = (l² − L²)/(2L²). Under
a downward apex load P, with w the apex's downward displacement and z = h − w:

    Π(w) = EA L e² − P w,   P(w) = EA z (h² − z²) / L³,

a cubic with a maximum P_max = 2 EA h³/(3√3 L³) at z = h/√3 (the limit point), a minimum
−P_max at z = −h/√3, and P = P_max again at z = −2h/√3, on the inverted branch.

This is the symmetric path. With the apex free to sway, its horizontal stiffness
(EA/L³)(2a² + z² − h²) stays positive up to the limit point only for h < √3 a: a steeper
truss sways (an antisymmetric bifurcation) before it snaps.
"""

from __future__ import annotations

import math

__all__ = ["limit_displacements", "limit_load", "load"]


def load(w: float, EA: float, a: float, h: float) -> float:
    """The apex load P at downward apex displacement w (exact, SVK bars)."""
    z = h - w
    return EA * z * (h * h - z * z) / (a * a + h * h) ** 1.5


def limit_load(EA: float, a: float, h: float) -> float:
    """P_max = 2 EA h³ / (3√3 L³): the load at which the truss snaps through."""
    return 2 * EA * h**3 / (3 * math.sqrt(3) * (a * a + h * h) ** 1.5)


def limit_displacements(h: float) -> tuple[float, float]:
    """w at the maximum and at the minimum of P(w): h (1 ∓ 1/√3)."""
    return h * (1 - 1 / math.sqrt(3)), h * (1 + 1 / math.sqrt(3))
