"""Levenberg–Marquardt for a non-linear least-squares fit, with bounds, and its statistics.

Minimises ½‖r(x)‖² given r and its Jacobian J = ∂r/∂x (a model that computes both in one
run: direct differentiation). Each iteration solves the damped Gauss–Newton system

    (JᵀJ + λ diag(JᵀJ)) dx = −Jᵀr,

Marquardt's scaling (so the parameters' units do not matter). The step is shortened so that
no parameter changes by more than a factor `max_factor` (4: a multiplicative trust region, as
the forces respond to the parameters' ratios far more than to their differences), and a step
that would cross a bound goes 90 % of the way to it (the interior methods' fraction-to-the-
boundary rule: H may tend to 0, perfect plasticity, but an overshoot does not put it there in
one step). A step that lowers the misfit is taken and λ shrinks (towards Gauss–Newton,
quadratic convergence for a small residual); a step that does not, or whose model run fails,
is refused and λ grows (towards a short gradient step). Converged when the step taken, or the
Gauss–Newton step the current Jacobian predicts (then without running the model at its end),
is below `xtol` of the parameters or `spread_tol` of their standard deviations (finer than the
data can tell), or the misfit stops falling (relative `ftol`) under a step below 1e-3 of them.

At the solution, with m residuals and n parameters, the residual's noise s² = ‖r‖²/(m − n)
gives the parameters' covariance s² (JᵀJ)⁻¹, their standard deviations and correlations.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from fenics_nl.errors import SolveError

__all__ = ["FitResult", "levenberg_marquardt", "statistics"]

log = logging.getLogger(__name__)


@dataclass
class FitResult:
    """What a fit found, and what it cost."""

    x: np.ndarray
    residuals: np.ndarray
    jacobian: np.ndarray
    converged: bool
    reason: str
    iterations: int  # accepted steps
    evaluations: int  # model runs (each with its Jacobian), refused steps included
    iterates: list[np.ndarray] = field(default_factory=list)  # x0 and every accepted x
    misfits: list[float] = field(default_factory=list)  # ½‖r‖² at each iterate
    initial_residuals: np.ndarray | None = None  # r(x0)
    wall_time: float = 0.0

    @property
    def misfit(self) -> float:
        """½‖r‖² at the solution."""
        return self.misfits[-1]


def statistics(r: np.ndarray, J: np.ndarray) -> dict:
    """Noise, covariance, standard deviations and correlations of a least-squares fit.

    s² = ‖r‖²/(m − n); covariance s² (JᵀJ)⁻¹. Where JᵀJ is singular (a parameter the data
    does not determine) its inverse is the pseudo-inverse and `rank` says so.

    Args:
        r: the m residuals at the solution.
        J: their Jacobian ∂r/∂x, m × n (m > n).

    Returns:
        A dict with ``noise`` (s), ``covariance``, ``std`` (the parameters' standard
        deviations), ``correlation``, ``rank`` (of JᵀJ) and ``unit_inverse`` ((JᵀJ)⁻¹, the
        covariance for s = 1).

    Raises:
        ValueError: if there are no more residuals than parameters (m ≤ n).
    """
    m, n = J.shape
    if m <= n:
        raise ValueError(f"{m} residuals cannot give the noise of {n} parameters: the curve "
                         "needs more points than parameters")
    noise = math.sqrt(float(r @ r) / (m - n))
    JtJ = J.T @ J
    d = np.sqrt(np.diag(JtJ))
    d[d == 0] = 1.0
    scaled = JtJ / np.outer(d, d)  # unit diagonal: its conditioning is the parameters'
    rank = int(np.linalg.matrix_rank(scaled, tol=1e-12))
    inverse = np.linalg.pinv(scaled, rcond=1e-12) / np.outer(d, d)
    cov = noise**2 * inverse
    std = np.sqrt(np.clip(np.diag(cov), 0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = inverse / np.sqrt(np.outer(np.diag(inverse), np.diag(inverse)))
    return {"noise": noise, "covariance": cov, "std": std, "correlation": corr,
            "rank": rank, "unit_inverse": inverse}


def levenberg_marquardt(
    evaluate: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
    x0,
    lower,
    upper=None,
    *,
    max_it: int = 30,
    xtol: float = 1e-5,
    ftol: float = 1e-6,
    spread_tol: float = 0.01,
    max_factor: float = 4.0,
    progress: Callable[[str], None] | None = None,
) -> FitResult:
    """Minimise ½‖r(x)‖² from x0 within lower ≤ x ≤ upper; `evaluate(x)` returns (r, J).

    Args:
        evaluate: the model run, ``evaluate(x)`` → (r, J); a SolveError it raises refuses
            the step (the model could not be run there).
        x0: the initial parameters, within the bounds.
        lower: the lower bounds.
        upper: the upper bounds (None: none).
        max_it: the most iterations (steps taken); the fit stops unconverged after them.
        xtol: a step below this fraction of the parameters is negligible.
        ftol: the relative fall of the misfit below which it stopped falling.
        spread_tol: a step below this fraction of the parameters' standard deviations is
            negligible.
        max_factor: the most a parameter may be multiplied or divided by in one step.
        progress: ``progress(message)``, a line for each step taken.

    Returns:
        The parameters found, with the residuals and Jacobian there, whether and why the fit
        converged, its iterates and misfits, and its cost.

    Raises:
        ValueError: if x0 is outside the bounds.
    """
    t0 = time.perf_counter()
    x = np.asarray(x0, dtype=float).copy()
    lower = np.asarray(lower, dtype=float)
    upper = np.full_like(x, np.inf) if upper is None else np.asarray(upper, dtype=float)
    if np.any(x < lower) or np.any(x > upper):
        raise ValueError(f"the initial guess {x} is outside the bounds")
    r, J = evaluate(x)
    evaluations = 1
    cost = 0.5 * float(r @ r)
    result = FitResult(x, r, J, False, "max_it", 0, 1, [x.copy()], [cost], r.copy())
    lam = 1e-3
    def negligible(dx, x, r, J) -> bool:
        # below xtol of the parameters, or far below what the data determine (their
        # standard deviations): a step that changes nothing a user can tell
        std = statistics(r, J)["std"] if len(r) > len(x) else np.zeros_like(x)
        return _small(dx, x, xtol) or bool(np.all(np.abs(dx) <= spread_tol * std))

    for _ in range(max_it):
        g = J.T @ r
        A = J.T @ J
        # converged if the undamped (Gauss–Newton) step would be negligible: known from this
        # run's Jacobian, without running the model at its end
        gauss_newton = _towards_bounds(x, np.linalg.lstsq(J, -r, rcond=None)[0], lower,
                                       upper) - x
        if negligible(gauss_newton, x, r, J):
            result.converged, result.reason = True, "Gauss–Newton step negligible"
            break
        D = np.diag(np.diag(A)) + 1e-300
        step_taken = False
        while lam < 1e12:
            dx = _within_factor(x, np.linalg.solve(A + lam * D, -g), max_factor)
            x_new = _towards_bounds(x, dx, lower, upper)
            evaluations += 1
            try:
                r_new, J_new = evaluate(x_new)
                cost_new = 0.5 * float(r_new @ r_new)
            except SolveError as err:
                log.info("step to %s refused: %s", x_new, err)
                cost_new = math.inf
            if cost_new < cost:
                step_taken = True
                break
            lam *= 4.0
        if not step_taken:  # and the Gauss–Newton step was not negligible (tested above)
            result.reason, result.converged = "no step lowers the misfit", False
            break
        # the taken step says the fit converged only if it is close to Gauss–Newton's (a
        # heavily damped step is short anyway)
        near_gauss_newton = lam <= 1.0
        small_step = near_gauss_newton and negligible(x_new - x, x_new, r_new, J_new)
        # a misfit that no longer falls, from a step that is small too (a heavily damped
        # step far from the minimum lowers the misfit little as well)
        small_drop = (near_gauss_newton and cost - cost_new <= ftol * cost
                      and _small(x_new - x, x, 1e-3))
        x, r, J, cost = x_new, r_new, J_new, cost_new
        lam = max(lam / 3.0, 1e-9)
        result.iterations += 1
        result.iterates.append(x.copy())
        result.misfits.append(cost)
        if progress:
            progress(f"iteration {result.iterations}: x = {np.array2string(x, precision=6)}, "
                     f"misfit {cost:.4e}")
        if small_step or small_drop:
            result.converged, result.reason = True, ("step negligible" if small_step
                                                     else "misfit stopped falling")
            break
    result.x, result.residuals, result.jacobian = x, r, J
    result.evaluations = evaluations
    result.wall_time = time.perf_counter() - t0
    return result


def _within_factor(x, dx, factor: float) -> np.ndarray:
    """dx scaled (as a whole) so that no non-zero x_i changes by more than `factor`."""
    scale = 1.0
    for xi, di in zip(x, dx, strict=True):
        if xi == 0 or di == 0:
            continue
        limit = (factor - 1) * abs(xi) if di * xi > 0 else (1 - 1 / factor) * abs(xi)
        scale = min(scale, limit / abs(di))
    return scale * dx


def _towards_bounds(x, dx, lower, upper, fraction: float = 0.9) -> np.ndarray:
    """x + dx, each component stopped at `fraction` of its way to a bound it would cross."""
    new = x + dx
    below, above = new < lower, new > upper
    new[below] = x[below] - fraction * (x[below] - lower[below])
    new[above] = x[above] + fraction * (upper[above] - x[above])
    return new


def _small(dx: np.ndarray, x: np.ndarray, xtol: float) -> bool:
    return bool(np.all(np.abs(dx) <= xtol * (np.abs(x) + xtol)))
