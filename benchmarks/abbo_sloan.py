"""The peer's Mohr–Coulomb for benchmarks/slope.py: Abbo–Sloan's smoothed surface in JAX.

dolfinx-external-operator's Mohr–Coulomb demo rounds the pyramid near its edges (Lode
angle |θ| > θ_T: K(θ) = A + B sin 3θ + C sin² 3θ, continuous to the second derivative) and
its apex (a hyperbola: √(J2 K² + a² sin²α)), Abbo & Sloan (1995), Abbo et al. (2011):

    h(σ, α) = p sin α + √(J2 K(θ, α)² + a_α² sin² α) − c cos α,   f = h(σ, φ), g = h(σ, ψ),

with p = tr σ / 3 (tension positive), θ_T = 26°, a = 0.26 c cot φ, a_ψ = a tan φ / tan ψ. The
return is a local Newton on (σ, Δλ): σ − σ_tr + Δλ C ∂g/∂σ = 0, f(σ) = 0, its Jacobian by
JAX's forward differentiation; the consistent tangent dσ/dε = [J⁻¹]_σσ C by the implicit
function theorem at the converged point (the same as differentiating the converged
iterations, one solve instead of their chain). Vectors are Mandel's (xx, yy, zz, √2 xy),
plane strain. Written here from the papers' formulas; the peer's demo is its model. A, B, C
are solved for K, dK/dθ and d²K/dθ² continuous at ±θ_T (the demo's closed-form coefficients give
those at +θ_T, but at −θ_T only K and dK/dθ: d²K/dθ² jumps by 0.25 there, measured).
"""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp
import numpy as np

jax.config.update("jax_enable_x64", True)

THETA_T = math.radians(26.0)
TRACE = np.array([1.0, 1.0, 1.0, 0.0])
DEVIATOR = np.eye(4) - np.outer(TRACE, TRACE) / 3


def rounding(alpha: float, sign: float) -> np.ndarray:
    """A, B, C of K = A + B sin 3θ + C sin² 3θ beyond θ = sign θ_T: K, K', K'' there equal to
    Mohr–Coulomb's K = cos θ − sin α sin θ / √3 (a linear system in A, B, C)."""
    t, s = sign * THETA_T, math.sin(alpha) / math.sqrt(3)
    exact = [math.cos(t) - s * math.sin(t), -math.sin(t) - s * math.cos(t),
             -math.cos(t) + s * math.sin(t)]
    s3, c3 = math.sin(3 * t), math.cos(3 * t)
    rows = [[1.0, s3, s3**2], [0.0, 3 * c3, 6 * s3 * c3], [0.0, -9 * s3, 18 * (c3**2 - s3**2)]]
    return np.linalg.solve(rows, exact)


def surface(alpha: float, c: float, a: float):
    """h(·, α) as a function of a Mandel stress vector."""
    plus, minus = rounding(alpha, 1.0), rounding(alpha, -1.0)
    s_alpha = math.sin(alpha)

    def h(sigma):
        s = DEVIATOR @ sigma
        j2 = jnp.maximum(0.5 * s @ s, 1e-30)  # θ is any on the axis: its K is then unused
        j3 = s[2] * (s[0] * s[1] - 0.5 * s[3] ** 2)
        sin3t = jnp.clip(-1.5 * math.sqrt(3) * j3 / j2**1.5, -1.0, 1.0)
        rounded = jnp.abs(sin3t) > math.sin(3 * THETA_T)  # |θ| > θ_T
        coef = jnp.where(sin3t > 0, plus, minus)
        # θ itself only where it is used: arcsin's derivative is infinite at ±1, and the
        # branch not taken by `where` still has its derivative taken (0 × ∞ = NaN)
        theta = jnp.arcsin(jnp.clip(sin3t, -math.sin(3 * THETA_T), math.sin(3 * THETA_T))) / 3
        k = jnp.where(rounded, coef[0] + coef[1] * sin3t + coef[2] * sin3t**2,
                      jnp.cos(theta) - s_alpha / math.sqrt(3) * jnp.sin(theta))
        return (TRACE @ sigma) / 3 * s_alpha + jnp.sqrt(j2 * k**2 + (a * s_alpha) ** 2) \
            - c * math.cos(alpha)

    return h


def return_map(E: float, nu: float, c: float, phi: float, psi: float, tol: float = 1e-10,
               max_it: int = 50):
    """σ, dσ/dε and the local iterations at n points: ``(deps (n, 4), sigma_n (n, 4))``.

    Angles in degrees. Compiled by JAX on its first call (vmapped over the points).
    """
    phi, psi = math.radians(phi), math.radians(psi)
    lmbda, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    C = lmbda * np.outer(TRACE, TRACE) + 2 * mu * np.eye(4)
    a = 0.26 * c / math.tan(phi)
    f = surface(phi, c, a)
    g = surface(psi, c, a * math.tan(phi) / math.tan(psi))
    dg = jax.grad(g)

    def residual(y, trial):
        sigma, dlam = y[:4], y[4]
        return jnp.concatenate([sigma - trial + dlam * (C @ dg(sigma)), f(sigma)[None]]) / c

    jacobian = jax.jacfwd(residual)

    def point(deps, sigma_n):
        trial = sigma_n + C @ deps
        plastic = f(trial) > 0.0
        y0 = jnp.concatenate([trial, jnp.zeros(1)])

        def unconverged(state):  # the residual relative to c
            y, k = state
            return plastic & (jnp.linalg.norm(residual(y, trial)) > tol) & (k < max_it)

        def newton(state):  # with a backtracking line search on |r|: a plain Newton
            y, k = state        # step cycles near the rounded edges (|θ| → 30°)
            r = residual(y, trial)
            dy = -jnp.linalg.solve(jacobian(y, trial), r)
            norm = jnp.linalg.norm(r)

            def longer(alpha):
                return (jnp.linalg.norm(residual(y + alpha * dy, trial)) >= norm) & (alpha > 1e-3)

            alpha = jax.lax.while_loop(longer, lambda alpha: alpha / 2, 1.0)
            return y + alpha * dy, k + 1

        y, its = jax.lax.while_loop(unconverged, newton, (y0, 0))
        tangent = jnp.linalg.solve(jacobian(y, trial), jnp.eye(5))[:4, :4] @ C / c
        return jnp.where(plastic, y[:4], trial), jnp.where(plastic, tangent, C), its

    return jax.jit(jax.vmap(point))
