"""Closed forms of the upsetting of a cylinder between flat dies, and a closed die's load.

The homogeneous compression without friction, and the slab method's estimate with it;
the slab estimate of a closed-die forging's load, from its flash.

Without friction the compression stays homogeneous: the logarithmic strain ln(h0/h) is the
plastic strain p plus the elastic σ_y(p)/E (Hencky's law in uniaxial stress), and the force
is the Kirchhoff stress σ_y(p) on the initial area scaled by h0/h: the plastic flow keeps
the volume, the elastic change J multiplies the area by J and divides the Cauchy stress by
it. With friction f, the slab method (Siebel; Hosford & Caddell, Metal Forming, ch. 7)
gives the mean die pressure p̄/σ_y = 1 + 2 f R / (3 h) for small f R / h (Coulomb
sliding everywhere on the face), R and h the current radius and height.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from scipy.optimize import brentq

__all__ = ["flash_slab_force", "frictionless_force", "homogeneous_plastic_strain", "slab_force"]


def homogeneous_plastic_strain(reduction: float, yield_stress: Callable[[float], float],
                               E: float) -> float:
    """p with ln(h0/h) = p + σ_y(p)/E at the height reduction 1 − h/h0 (0 if elastic)."""
    strain = -math.log(1.0 - reduction)
    if yield_stress(0.0) / E >= strain:
        return 0.0
    return brentq(lambda p: p + yield_stress(p) / E - strain, 0.0, strain)


def frictionless_force(reduction: float, radius: float, yield_stress: Callable[[float], float],
                       E: float) -> float:
    """F = σ_y(p) π R0² h0/h in the plastic range (elastic: E ln(h0/h) π R0² h0/h)."""
    strain = -math.log(1.0 - reduction)
    p = homogeneous_plastic_strain(reduction, yield_stress, E)
    tau = yield_stress(p) if p > 0 else E * strain
    return tau * math.pi * radius**2 / (1.0 - reduction)


def slab_force(reduction: float, radius: float, height: float, friction: float,
               yield_stress: Callable[[float], float], E: float) -> float:
    """The slab method's F = σ_y π R² (1 + 2 f R / (3 h)), R = R0 √(h0/h), h the height."""
    h = height * (1.0 - reduction)
    R = radius / math.sqrt(1.0 - reduction)
    return frictionless_force(reduction, radius, yield_stress, E) * (
        1.0 + 2.0 * friction * R / (3.0 * h))


def flash_slab_force(yield_stress: float, friction: float, cavity_area: float,
                     flash_area: float, perimeter: float, gap: float) -> float:
    """The slab estimate of a closed die's load from its flash (Schey; Altan et al.).

    The flash is a strip of width w = A_f / perimeter and thickness t between the lands,
    in plane strain (flow stress σ_f = 2σ_y/√3) with Coulomb friction f: its pressure
    rises from σ_f at the exit to σ_f (1 + 2 f w/t) at the cavity (linearized), which the
    cavity takes whole: F = σ_f [(1 + 2 f w/t) A_c + (1 + f w/t) A_f].

    Args:
        yield_stress: σ_y of the metal in the flash.
        friction: f.
        cavity_area: A_c, the cavity's area in plan.
        flash_area: A_f, the flash's (the metal on the lands) in plan.
        perimeter: the cavity outline's length.
        gap: t, the lands' distance apart.

    Returns:
        The estimated load.
    """
    flow = 2.0 * yield_stress / math.sqrt(3.0)
    rise = friction * flash_area / perimeter / gap
    return flow * ((1.0 + 2.0 * rise) * cavity_area + (1.0 + rise) * flash_area)
