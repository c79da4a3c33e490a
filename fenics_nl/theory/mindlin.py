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

__all__ = [
    "cylinder_stick_half_width",
    "sphere_stick_radius",
    "sphere_tangential_displacement",
    "sphere_tangential_force_within",
    "traction",
]


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


def sphere_stick_radius(a: float, Q: float, fP: float) -> float:
    """c = a (1 − Q/(fP))^(1/3) (a sphere: circular contact of radius a)."""
    return a * (1 - _load_ratio(Q, fP)) ** (1 / 3)


def sphere_tangential_displacement(a: float, Q: float, fP: float, G: float, nu: float
                                   ) -> float:
    """δ_t = 3 fP (2 − ν)/(16 G a) [1 − (1 − Q/(fP))^(2/3)], the rigid sphere's.

    Its tangential displacement relative to the far body (shear modulus G, Poisson's ratio
    ν). For small Q it is Q (2 − ν)/(8 G a), the compliance of a bonded circular punch.
    """
    ratio = _load_ratio(Q, fP)
    return 3 * fP * (2 - nu) / (16 * G * a) * (1 - (1 - ratio) ** (2 / 3))


def sphere_tangential_force_within(r, a: float, p0: float, f: float, c: float):
    """Q(r) = ∫ q over the disc of radius r: the sphere's tangential force inside r.

    (f p0/a)(2π/3)[a³ − (a² − r²)^(3/2) − (c³ − (c² − r²)^(3/2))], each bracket frozen at
    its own radius; Q(a) = f P (1 − c³/a³) = Q. A sum of nodal forces, so it holds for any
    element (3D P2 nodal forces are not a pointwise traction: a vertex's is about 0).
    """
    r = np.asarray(r, dtype=float)

    def disc(b):
        return b**3 - np.clip(b * b - np.minimum(r, b) ** 2, 0.0, None) ** 1.5

    return f * p0 / a * 2 * math.pi / 3 * (disc(a) - disc(c))
