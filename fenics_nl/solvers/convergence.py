"""When an iteration has converged: one test for Newton, arc-length and SNES.

The course stops Newton when the out-of-balance force is small. Here "small" is relative to
forces of the problem itself, so that the same problem converges the same way in N–mm–MPa
or N–m–Pa::

    ‖R‖ ≤ max(rtol ‖R₀‖, atol F)

R₀ the residual at the start of the solve and F a force of the problem (the load, or the
largest R₀ seen). `ConvergenceTest` is that rule with its iteration limit and divergence
bound; `NewtonSolver.solve`, `ArcLength`'s corrector and `SnesSolver` (through
`SNES.setConvergenceTest`) all call it. `at_round_off` is the one test of a residual that
has stopped falling at the round-off of the internal forces.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

from petsc4py import PETSc

__all__ = ["ConvergenceTest", "at_round_off", "observed_orders"]

Reason = Literal["converged", "nan", "max_it", "diverged"]


@dataclass(frozen=True)
class ConvergenceTest:
    """‖R‖ ≤ max(rtol ‖R₀‖, atol F) within `max_it` iterations, unless ‖R‖ blows up.

    Args:
        rtol: tolerance relative to the first residual of the solve.
        atol: tolerance relative to the force scale F (dimensionless too).
        max_it: iterations before the solve fails (PETSc's ``max_it``).
        divergence_tol: ‖R‖ > divergence_tol ‖R₀‖ after the first iteration fails the solve
            (PETSc's ``-snes_divergence_tolerance``, and as in PETSc a value <= 0 turns the
            test off; larger than PETSc's 1e4: a first iteration of a large load step may
            rise that much and still converge).
        absolute: `atol` is a force itself (F = 1), as PETSc's ``-snes_atol`` is.
    """

    rtol: float = 1e-10
    atol: float = 1e-10
    max_it: int = 50
    divergence_tol: float = 1e8
    absolute: bool = False

    def with_options(self, prefix: str) -> ConvergenceTest:
        """This test, with what the command line gives under `prefix` taking precedence.

        ``-{prefix}snes_rtol``, ``snes_max_it``, ``snes_divergence_tolerance`` and
        ``snes_atol`` (then absolute, as in PETSc): the same names for `NewtonSolver` and
        for SNES.

        Args:
            prefix: the solver's PETSc options prefix.

        Returns:
            The test the solver stops by.
        """
        options = PETSc.Options()
        absolute = options.hasName(f"{prefix}snes_atol")
        return ConvergenceTest(
            options.getReal(f"{prefix}snes_rtol", self.rtol),
            options.getReal(f"{prefix}snes_atol") if absolute else self.atol,
            options.getInt(f"{prefix}snes_max_it", self.max_it),
            options.getReal(f"{prefix}snes_divergence_tolerance", self.divergence_tol),
            absolute or self.absolute)

    def threshold(self, r0: float, force: float) -> float:
        """The residual norm to reach.

        Args:
            r0: ‖R₀‖, the first residual of the solve.
            force: F, the force scale.

        Returns:
            max(rtol ‖R₀‖, atol F), F = 1 if `absolute`.
        """
        return max(self.rtol * r0, self.atol * (1.0 if self.absolute else force))

    def reason(self, norms: Sequence[float], force: float) -> Reason | None:
        """Whether the iterations stop after the residual norms so far, and why.

        Args:
            norms: ‖R‖ at iterations 0, 1, ..., k.
            force: F, the force scale.

        Returns:
            None while iterating; else ``converged``, ``nan`` (‖R‖ not finite), ``max_it``
            (k reached `max_it`) or ``diverged`` (‖R‖ > divergence_tol ‖R₀‖).
        """
        r, k = norms[-1], len(norms) - 1
        if not math.isfinite(r):
            return "nan"
        if r <= self.threshold(norms[0], force):
            return "converged"
        if k >= self.max_it:
            return "max_it"
        if k > 0 and self.divergence_tol > 0 and r > self.divergence_tol * norms[0]:
            return "diverged"
        return None

    def attach(self, snes: PETSc.SNES, force_scale: float | None = None) -> None:
        """Make this SNES stop by this test (`SNES.setConvergenceTest`).

        Args:
            snes: the solver; its options prefix's ``snes_rtol``, ``snes_max_it`` and
                ``snes_atol`` given on the command line take precedence (``snes_atol`` then
                absolute, as PETSc's).
            force_scale: F; None for the largest first residual of this SNES's solves.
        """
        test = self.with_options(snes.getOptionsPrefix() or "")
        absolute = test.absolute
        # the callback holds plain lists, not a Python solver object: a cycle through SNES
        # would leave PETSc objects to the garbage collector (destroyed in any order: a hang)
        norms, largest = [], [0.0]
        snes.setTolerances(rtol=test.rtol, max_it=test.max_it)  # as reported by SNES

        def converged(snes, it, xyf_norms):
            fnorm = xyf_norms[2]
            if it == 0:
                norms.clear()
                if math.isfinite(fnorm):  # an infinite one would make every test pass
                    largest[0] = max(largest[0], fnorm)
            norms.append(fnorm)
            force = 1.0 if absolute else (force_scale or largest[0])
            reason = test.reason(norms, force)
            if reason == "converged":  # PETSc's distinction: which tolerance was met
                return _R.CONVERGED_FNORM_ABS if fnorm <= test.atol * force else \
                    _R.CONVERGED_FNORM_RELATIVE
            return _SNES_REASONS[reason]

        snes.setConvergenceTest(converged)


_R = PETSc.SNES.ConvergedReason
_SNES_REASONS = {None: _R.ITERATING, "nan": _R.DIVERGED_FUNCTION_NANORINF,
                 "max_it": _R.DIVERGED_MAX_IT, "diverged": _R.DIVERGED_DTOL}


def at_round_off(norms: Sequence[float], largest: float, threshold: float = math.inf) -> bool:
    """‖R‖ has stopped falling, 1e6 below the run's largest (and within 1e4 of the tolerance).

    A slender body's internal forces are far larger than its load (membrane forces), and
    near a critical point K is nearly singular and amplifies the round-off of each
    correction: the residual then stops falling just above a tolerance on the load; the
    finer the mesh, the higher that floor. "Stopped": either a fall of 100x or more onto a
    residual that the next iteration does not halve (Newton in its quadratic phase meets the
    floor: one iteration confirms it), or the last 5 within a factor 3 and the last not below
    half the one 4 iterations earlier (a steady linear rate, even 0.85, halves it in 4
    iterations: the modified and quasi-Newton variants).

    Args:
        norms: ‖R‖ at iterations 0, 1, ..., k.
        largest: the largest first residual of the run (the internal forces' scale).
        threshold: the residual norm the test asks for: arc-length accepts a step whose ‖R‖
            stalls within 1e4 of it; by default none (Newton's diagnosis of a failed solve,
            whatever its tolerance).

    Returns:
        Whether ‖R‖ stalls at round-off.
    """
    low = min(1e-6 * largest, 1e4 * threshold)
    if (len(norms) >= 3 and norms[-2] <= 1e-2 * norms[-3] and norms[-1] > 0.5 * norms[-2]
            and max(norms[-2:]) < low):
        return True
    last = norms[-5:]
    return (len(last) == 5 and max(last) < low
            and max(last) < 3 * min(last) and last[-1] > 0.5 * last[0])


def observed_orders(errors: Sequence[float], floor: float = 0.0) -> list[float]:
    """Observed convergence orders q_k = ln(e_{k+1}/e_k) / ln(e_k/e_{k-1}).

    Args:
        errors: errors or residual norms of consecutive iterates.
        floor: values at or below it (round-off) are skipped, and so are non-decreasing
            triples, since the ratio means nothing there.

    Returns:
        One order per consecutive triple kept.
    """
    orders = []
    for e0, e1, e2 in zip(errors, errors[1:], errors[2:], strict=False):
        if min(e0, e1, e2) <= floor or not (e0 > e1 > e2):
            continue
        orders.append(math.log(e2 / e1) / math.log(e1 / e0))
    return orders
