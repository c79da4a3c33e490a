"""A rigid die as a penalty energy in UFL, with regularized Coulomb friction.

The die is the surface z = Z + h(x_h) above the body (x_h the coordinates across the
pressing axis: (x, y) in 3D, r or x in 2D), h a shape given in UFL, Z its stroke-dependent
height. A point of the contact surface is where the deformation takes it, φ = X + u; its
gap to the die, to first order in the distance, is the vertical gap over the slope's factor:

    g = (Z + h(φ_h) − φ_z) / √(1 + |∇h|²),    n = (−∇h, 1) / √(1 + |∇h|²),

n the die's unit normal (pointing into the die), exact for a flat die and along the normal
of a sloped one. The contact is the penalty energy Π_c = ∫ κ/2 ⟨−g⟩² ds on the reference
surface (Forge3's choice for forging), so that the contact pressure p = κ⟨−g⟩, its
direction and its tangent are UFL's derivatives like the material's: no active set, the
contact zone is where g < 0 at the quadrature points. The penetration is p/κ; κ a stiffness
per unit area (e.g. 3 E/h: p/κ ≈ 1.3e-3 h at p = 800 MPa for steel). Its variation is
p n·δu to first order in g (δg also has g δ(1/√(1 + |∇h|²)) on a curved wall).

Friction: the slip of a point on the die since the step's start is the tangential part of
Δs = Δu − ΔZ e_z (the die moves along z only); Coulomb's law regularized over a slip ε,

    t_f = −f p Δs_t / √(|Δs_t|² + ε²),

slides at f p for |Δs_t| ≫ ε and is a stiff spring below it (the stick zone): a smooth
function of u whose tangent UFL derives, not symmetric.
"""

from __future__ import annotations

from collections.abc import Callable

import ufl

__all__ = ["die_gap", "friction_traction", "penalty_energy", "pressure"]


def die_gap(x, height: Callable, Z):
    """The gap g and the die's unit normal n at the current points x (first-order distance).

    Args:
        x: the current position φ = X + u (a UFL vector, its last component the pressing
            axis).
        height: h(x_h), the die's shape above its reference height, a UFL expression of the
            lateral coordinates (a UFL vector of the others).
        Z: the die's reference height (a Constant: it moves with the stroke).

    Returns:
        (g, n): g > 0 open, g < 0 penetrating; n the unit normal pointing into the die.
    """
    d = ufl.shape(x)[0]
    lateral = ufl.variable(ufl.as_vector([x[i] for i in range(d - 1)]))
    h = height(lateral)
    slope = ufl.diff(h, lateral)  # ∇h
    norm = ufl.sqrt(1 + ufl.dot(slope, slope))
    n = ufl.as_vector([-slope[i] / norm for i in range(d - 1)] + [1 / norm])
    return (Z + h - x[d - 1]) / norm, n


def pressure(g, stiffness):
    """p = κ ⟨−g⟩: the contact pressure of the penalty (0 where the die is open)."""
    return stiffness * ufl.conditional(ufl.lt(g, 0), -g, 0)


def penalty_energy(g, stiffness):
    """κ/2 ⟨−g⟩² per unit reference area: Π_c's density (its variation: p n·δu)."""
    return stiffness / 2 * ufl.conditional(ufl.lt(g, 0), g**2, 0)


def friction_traction(p, n, slip, friction, regularization):
    """Coulomb's traction on the body, regularized: −f p Δs_t / √(|Δs_t|² + ε²).

    Args:
        p: the contact pressure (`pressure`).
        n: the die's unit normal.
        slip: Δs, the displacement relative to the die since the step's start.
        friction: the coefficient f.
        regularization: ε > 0, the slip below which the law is a spring (a length; at
            ε = 0 no slip gives 0/0).

    Returns:
        The friction traction on the body (a UFL vector).
    """
    tangential = slip - ufl.dot(slip, n) * n
    return -friction * p * tangential / ufl.sqrt(ufl.dot(tangential, tangential)
                                                   + regularization**2)
