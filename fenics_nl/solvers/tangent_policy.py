"""The Newton variants as tangent policies: when K is rebuilt, and BFGS's corrections of it.

The course's variants differ only in *which* tangent solves each correction: full Newton
rebuilds it every iteration, periodic every few, modified keeps one (the start of the solve's,
or the elastic one for life) and BFGS keeps one and corrects its inverse with secant pairs.
`TangentPolicy` answers "rebuild now?" for `NewtonSolver`; `InverseBFGS` is the correction.
"""

from __future__ import annotations

import math

from petsc4py import PETSc

__all__ = ["InverseBFGS", "TangentPolicy"]


class TangentPolicy:
    """When the tangent is rebuilt and refactorized, and when a factorization is reused.

    * ``full``: every iteration; ``periodic``: every `period` iterations; ``modified`` and
      ``bfgs``: once per solve, or once for the solver's life with the elastic tangent;
    * a tangent with no coefficient (linear material) once per solve: it is exact;
    * with `reuse` (a direct solver as CG preconditioner), a new tangent keeps the last
      factorization while CG on it needs at most REUSE_ITERATIONS iterations, or while the
      Dirichlet rows changed only a little (`bcs_changed(small=True)`);
    * with `lag` (CG + AMG), a new tangent within a solve keeps the AMG hierarchy of the
      solve's first one while CG needs at most twice the iterations per digit of residual
      reduction it took on it fresh (per digit: the inexact-Newton tolerance tightens).

    "Factorization" stands for the preconditioner's set-up: an AMG hierarchy too.
    """

    REUSE_ITERATIONS = 10

    def __init__(self, method: str, period: int, *, fixed: bool, for_life: bool, reuse: bool,
                 lag: bool = False):
        self.method, self.period = method, period
        self.fixed, self.for_life, self.reuse, self.lag = fixed, for_life, reuse, lag
        self.ready = False  # a tangent valid for this solve is assembled and factorized
        self.factorization_current = False  # the factorization is of the current tangent
        self._fresh_rate = None  # lag: CG iterations per digit on the hierarchy's tangent
        self.stale = False  # the last tangent is solved with an older one's factorization

    def start_solve(self) -> None:
        """A new solve: the state moved, so every tangent is stale but two.

        A life-long one, and a linear material's (it changes with the Dirichlet rows and
        the springs only, which say so themselves).
        """
        if not (self.for_life or self.fixed):
            self.ready = False
        if self.lag:  # a new step: the hierarchy is rebuilt on its first tangent
            self.factorization_current = False

    def bcs_changed(self, small: bool) -> None:
        """New Dirichlet rows: rebuild the tangent; refactorize unless only a few changed.

        Args:
            small: only a few rows changed (or the springs): with `reuse` or `lag`, the
                last factorization may serve the new tangent.
        """
        self.ready = False
        if not small:
            self.factorization_current = False

    def needs_tangent(self, k: int) -> bool:
        """At iteration k.

        Args:
            k: the iteration within the solve (0: its first).

        Returns:
            Whether the tangent K is to be rebuilt now.
        """
        if self.fixed and self.ready:
            return False  # a linear material: the tangent built for this solve is exact
        if self.method == "full":
            return True
        if self.method == "periodic":
            return k % self.period == 0
        return not self.ready

    def needs_factorization(self) -> bool:
        """After a tangent assembly.

        Returns:
            Whether the new tangent is to be factorized; False while `reuse` or `lag` keeps
            the last factorization.
        """
        return not ((self.reuse or self.lag) and self.factorization_current)

    def factorized(self) -> None:
        """A factorization of the current tangent was made."""
        self.factorization_current = True
        self._fresh_rate = None
        self.stale = False

    def assembled(self) -> None:
        """The tangent for this solve is in place."""
        self.ready = True

    def krylov_iterations(self, its: int, rtol: float) -> None:
        """CG on a reused factorization took `its` to `rtol`: beyond a few, refactorize.

        Lagged AMG: beyond twice the iterations per digit the hierarchy's own tangent took,
        set it up again (next time).

        Args:
            its: the Krylov iterations of the last solve.
            rtol: the relative tolerance they were asked for.
        """
        if not self.lag:
            self.factorization_current = its <= self.REUSE_ITERATIONS
            return
        rate = its / max(-math.log10(rtol), 1.0)
        if self._fresh_rate is None:
            self._fresh_rate = rate
        else:
            self.factorization_current = rate <= 2 * self._fresh_rate


class InverseBFGS:
    """L-BFGS corrections of a constant tangent's inverse (Matthies–Strang), two-loop form.

    du = H R with H built on H0 = K0⁻¹ from the last `memory` pairs s_i = u_{i+1} − u_i,
    y_i = R_{i+1} − R_i, ρ_i = 1/(y_i·s_i); one solve with K0 per iteration.
    """

    def __init__(self, memory: int):
        self.memory = memory
        self.pairs: list[tuple[PETSc.Vec, PETSc.Vec, float]] = []

    def direction(self, b: PETSc.Vec, du: PETSc.Vec, solve) -> None:
        """du = H b.

        Args:
            b: the right-hand side (the residual R).
            du: receives H b.
            solve: ``solve(q)`` puts K0⁻¹ q into du.
        """
        q = b.copy()
        alphas = []
        for s, y, rho in reversed(self.pairs):
            a = rho * s.dot(q)
            q.axpy(-a, y)
            alphas.append(a)
        solve(q)
        for (s, y, rho), a in zip(self.pairs, reversed(alphas), strict=True):
            du.axpy(a - rho * y.dot(du), s)
        q.destroy()

    def store(self, du: PETSc.Vec, alpha: float, b_old: PETSc.Vec, b_new: PETSc.Vec) -> None:
        """Keep s = −α du and y = b_new − b_old if y·s > 0 (H stays positive definite).

        Args:
            du: the correction's direction (u moved by −α du).
            alpha: α, the step length taken.
            b_old: the residual R before the step.
            b_new: the residual R after it.
        """
        s = du.copy()
        s.scale(-alpha)
        y = b_old.copy()
        y.aypx(-1.0, b_new)
        self.store_pair(s, y)

    def store_pair(self, s: PETSc.Vec, y: PETSc.Vec) -> None:
        """Keep the pair (s, y), which it now owns, if y·s > 0 (else destroy it).

        Args:
            s: the change of u.
            y: the change of R it made.
        """
        ys = y.dot(s)
        if not ys > 1e-12 * y.norm() * s.norm():
            s.destroy()
            y.destroy()
            return  # curvature condition fails: skip the update
        self.pairs.append((s, y, 1.0 / ys))
        if len(self.pairs) > self.memory:
            for v in self.pairs.pop(0)[:2]:
                v.destroy()

    def clear(self) -> None:
        """Forget every pair (a new solve), destroying their vectors."""
        for s, y, _ in self.pairs:
            s.destroy()
            y.destroy()
        self.pairs.clear()


