"""Displacement gradients and strains for 3D, plane-strain and axisymmetric models.

Every model returns a 3x3 displacement gradient `H` (plane strain: zero third row and
column; axisymmetric in (r, z): hoop term `u_r / r`), so materials see full 3D tensors and
`tr`, `dev` and `det` mean what they mean in 3D. Plane stress is the exception: it keeps the
2x2 in-plane gradient and materials that support it use their plane-stress energy.
"""

from __future__ import annotations

import ufl

__all__ = [
    "check_model",
    "deformation_gradient",
    "displacement_gradient",
    "domain",
    "green_lagrange",
    "measure_weight",
    "quadrature_measure",
    "small_strain",
]

MODELS = ("3d", "plane_strain", "plane_stress", "axisymmetric")


def check_model(model: str) -> str:
    """Return `model` if it is one of MODELS, else raise ValueError.

    Args:
        model: the kinematic model's name.

    Returns:
        `model` itself.
    """
    if model not in MODELS:
        raise ValueError(f"model must be one of {', '.join(MODELS)}, got {model!r}")
    return model


def domain(u):
    """The mesh (UFL domain) of `u`: a Function, or a part of one (`ufl.split`).

    Args:
        u: the displacement (or any UFL expression on one mesh).

    Returns:
        Its UFL domain (`ufl.Mesh`).
    """
    return ufl.domain.extract_unique_domain(u)


def displacement_gradient(u, model: str = "3d"):
    """Return the (embedded) displacement gradient H = ∇u of `u` for `model`.

    Args:
        u: the displacement (Function, part of one, or a test function).
        model: "3d", "plane_strain", "plane_stress" or "axisymmetric" (u = (u_r, u_z)).

    Returns:
        H (UFL), 3x3 (2x2 in plane stress).
    """
    check_model(model)
    g = ufl.grad(u)
    if model in ("3d", "plane_stress"):
        return g
    hoop = 0
    if model == "axisymmetric":
        r = ufl.SpatialCoordinate(domain(u))[0]
        hoop = u[0] / r
    return ufl.as_tensor([[g[0, 0], g[0, 1], 0], [g[1, 0], g[1, 1], 0], [0, 0, hoop]])


def small_strain(u, model: str = "3d"):
    """Linearised strain ε = ½(∇u + ∇ᵀu).

    Args:
        u: the displacement.
        model: the kinematic model (see `displacement_gradient`).

    Returns:
        ε (UFL), 3x3 (2x2 in plane stress).
    """
    return ufl.sym(displacement_gradient(u, model))


def deformation_gradient(u, model: str = "3d"):
    """F = I + ∇u.

    Args:
        u: the displacement.
        model: the kinematic model (see `displacement_gradient`).

    Returns:
        F (UFL), 3x3 (2x2 in plane stress).
    """
    H = displacement_gradient(u, model)
    return ufl.Identity(H.ufl_shape[0]) + H


def green_lagrange(u, model: str = "3d"):
    """Green–Lagrange strain e = ½(∇u + ∇ᵀu + ∇ᵀu·∇u).

    Args:
        u: the displacement.
        model: the kinematic model (see `displacement_gradient`).

    Returns:
        e (UFL), 3x3 (2x2 in plane stress).
    """
    H = displacement_gradient(u, model)
    return 0.5 * (H + H.T + H.T * H)


def measure_weight(mesh, model: str = "3d"):
    """Integration weight: 2πr in the axisymmetric model (totals per full turn), else 1.

    Args:
        mesh: the mesh (r is its first coordinate).
        model: the kinematic model (see `displacement_gradient`).

    Returns:
        2πr (UFL), or the float 1.0.
    """
    if check_model(model) == "axisymmetric":
        return 2 * ufl.pi * ufl.SpatialCoordinate(mesh)[0]
    return 1.0


def quadrature_measure(integral: str, mesh, degree: int = 2, **kwargs):
    """A `dx`/`ds` measure with a fixed quadrature degree.

    Non-polynomial energies (power law, ln J) make UFL estimate a different degree for a
    residual and for its derivative; the assembled tangent is then not the derivative of the
    assembled residual and Newton loses its quadratic rate. A fixed degree on the measure is
    inherited by `ufl.derivative`, so both forms integrate with the same rule.

    Args:
        integral: the integral type ("dx", "ds", ...).
        mesh: the mesh integrated over.
        degree: the quadrature degree.
        **kwargs: passed on to `ufl.Measure` (e.g. `subdomain_data`).

    Returns:
        The `ufl.Measure`.
    """
    return ufl.Measure(integral, domain=mesh, metadata={"quadrature_degree": degree}, **kwargs)
