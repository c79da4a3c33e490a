"""Scalar r(u) = 0 by Newton, modified Newton and the secant method (the course, part 2).

    newton:   u_{k+1} = u_k − r(u_k) / r'(u_k)                      order 2
    modified: u_{k+1} = u_k − r(u_k) / K, K constant (default r'(u0))  order 1
    secant:   slope through the last two iterates                     order (1+√5)/2

The iteration works on any real number type with + − × ÷ (float, or `mpmath.mpf` for many
digits: in double precision round-off arrives after three or four meaningful iterates, too few
to watch an order settle).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from fenics_nl.solvers.convergence import observed_orders

__all__ = ["ScalarResult", "ScalarSolveError", "solve"]

METHODS = ("newton", "modified", "secant")
DIVERGED = 1e8  # |r(u_k)| / |r(u_0)| beyond which the iteration is declared divergent


class ScalarSolveError(ArithmeticError):
    """The iteration failed: zero slope, a non-finite value or no convergence.

    `result` holds the iterates up to the failure (what a divergence looks like).
    """

    result: ScalarResult | None = None


@dataclass
class ScalarResult:
    """Iterates (u0 first), residuals r(u_k), convergence flag and observed orders."""

    iterates: list[float]
    residuals: list[float]
    converged: bool
    orders: list[float] = field(default_factory=list)

    @property
    def root(self) -> float:
        """Last iterate."""
        return self.iterates[-1]

    @property
    def iterations(self) -> int:
        """Number of updates performed."""
        return max(len(self.iterates) - 1, 0)


def _derivative(r: Callable[[float], float], u: float) -> float:
    h = _eps(u) ** (1 / 3) * max(1, abs(u))  # central difference: error ~ h² + eps/h
    return (r(u + h) - r(u - h)) / (2 * h)


def _eps(u) -> float:
    """Unit round-off of u's number type."""
    if isinstance(u, float | int):
        return 2.0**-52
    import mpmath

    return mpmath.mp.eps


def solve(r: Callable[[float], float], u0: float, method: str = "newton",
          dr: Callable[[float], float] | None = None, k: float | None = None,
          tol: float = 1e-14, max_it: int = 100) -> ScalarResult:
    """Solve r(u) = 0 from u0; stop when |r(u)| <= tol or the update is below round-off.

    The secant method's second point is one Newton step from u0.

    Args:
        r: the residual r(u).
        u0: the starting point (a float, or an `mpmath.mpf` for many digits).
        method: ``newton``, ``modified`` or ``secant``.
        dr: r' (central differences if omitted).
        k: the constant slope K of modified Newton (default r'(u0)).
        tol: converged when |r(u)| <= tol.
        max_it: updates before ScalarSolveError.

    Returns:
        The iterates, their residuals and the observed orders.

    Raises:
        ScalarSolveError: on a zero or non-finite slope, a non-finite value, a failed
            arithmetic, a divergence or no convergence in `max_it` updates; its `result`
            holds the iterates up to the failure.
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    r = _guarded(r, method)
    dr = dr or (lambda u: _derivative(r, u))
    us, rs = [u0], []
    try:
        rs.append(r(u0))
        if method == "modified":
            k = dr(u0) if k is None else k
        return _iterate(r, dr, method, k, us, rs, tol, max_it)
    except (ScalarSolveError, ArithmeticError) as err:
        failure = err if isinstance(err, ScalarSolveError) else ScalarSolveError(
            f"{method}: arithmetic failed at u = {us[-1]!r}: {err}")
        failure.result = ScalarResult(us[: len(rs)], rs, False)
        raise failure from (None if failure is err else err)


def _iterate(r, dr, method, k, us, rs, tol, max_it) -> ScalarResult:
    """The loop of `solve`, appending to `us` and `rs` in place."""
    for _ in range(max_it):
        u, ru = us[-1], rs[-1]
        if not (math.isfinite(float(u)) and math.isfinite(float(ru))):
            raise ScalarSolveError(f"{method}: non-finite value at u = {u!r}, r = {ru!r}")
        if abs(ru) <= tol:
            return ScalarResult(us, rs, True, _orders(us, r, dr))
        if abs(ru) > DIVERGED * abs(rs[0]):
            raise ScalarSolveError(f"{method}: diverges (|r| grew from {float(abs(rs[0])):.3g} "
                                   f"to {float(abs(ru)):.3g} in {len(us) - 1} iterations)")
        if method == "newton" or (method == "secant" and len(us) == 1):
            slope = dr(u)
        elif method == "modified":
            slope = k
        else:
            slope = (ru - rs[-2]) / (u - us[-2]) if u != us[-2] else 0.0
        if slope == 0 or not math.isfinite(float(slope)):
            raise ScalarSolveError(f"{method}: zero or non-finite slope at u = {u!r}")
        u_new = u - ru / slope
        if u_new == u:  # update below round-off: as converged as it will get
            return ScalarResult(us, rs, True, _orders(us, r, dr))
        us.append(u_new)
        rs.append(r(u_new))
    raise ScalarSolveError(f"{method}: no convergence in {max_it} iterations "
                           f"(u = {us[-1]!r}, r = {rs[-1]!r})")


def _guarded(r, method):
    """r, with arithmetic failures (overflow, division by zero, domain) as ScalarSolveError."""

    def call(u):
        try:
            return r(u)
        except (ArithmeticError, ValueError) as err:
            raise ScalarSolveError(f"{method}: r(u) failed at u = {u!r}: {err}") from err

    return call


def _orders(us: list[float], r, dr) -> list[float]:
    """Orders from errors e_k = |u_k − u*| (errors near round-off dropped).

    u* is the last iterate polished by three extra Newton steps, so that the last iterates'
    errors are measured against something far more accurate than themselves.
    """
    root = us[-1]
    for _ in range(3):
        slope = dr(root)
        if slope == 0:
            break
        root = root - r(root) / slope
    errors = [abs(u - root) for u in us]
    return observed_orders(errors, floor=1e4 * _eps(root) * max(1, abs(root)))
