"""Cattaneo–Mindlin partial slip: a Hertz contact, then a tangential force Q < f P.

The normal force P is applied first, then Q, with Coulomb friction f. Exact for
elastically similar bodies (Dundurs β = 0), e.g. a rigid indenter on an incompressible body
(ν = 1/2): the normal pressure is Hertz's and does not change with Q. The traction is the
full-slip one, f p(x), less a Hertz-like correction over the stick zone, of radius
(half-width) c.
"""

from __future__ import annotations

import math

import numpy as np


def _load_ratio(Q: float, fP: float) -> float:
    if not (fP > 0 and 0 <= Q < fP):
        raise ValueError(f"partial slip needs 0 <= Q < f P, got Q = {Q:g}, f P = {fP:g}")
    return Q / fP


def cylinder_stick_half_width(a: float, Q: float, fP: float) -> float:
    """c = a √(1 − Q/(fP)) (plane strain, per unit length)."""
    return a * math.sqrt(1 - _load_ratio(Q, fP))


def traction(x, a: float, p0: float, f: float, c: float):
    """q = (f p0/a)(√(a² − x²) − √(c² − x²)), the second term for |x| < c only.

    x: the distance from the axis (the cylinder's x; the sphere's r has the same form, with
    its own c).
    """
    x = np.abs(np.asarray(x, dtype=float))
    full = np.sqrt(np.clip(a * a - x * x, 0.0, None))
    stick = np.sqrt(np.clip(c * c - x * x, 0.0, None))
    return f * p0 / a * (full - stick)
