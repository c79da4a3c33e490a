"""Incremental loading: a load factor t from 0 to 1 with adaptive step control.

Each step sets the load (a user callback, typically scaling `fem.Constant` values), predicts
the state by extrapolating the last two converged ones (secant predictor), calls the solver,
and on failure restores the last converged state and halves the step. After an easy step
(few iterations) the step grows. Below `min_step` it stops with a clear error.

Any solver fits that has `u` (the unknown Function) and `solve()` returning a
`SolveResult` or raising a `SolveError`: NewtonSolver, SnesSolver, ActiveSetContact.
Path-dependent state that the solver itself does not hold (internal variables at
quadrature points, slip at contact nodes) is kept right by two hooks: `commit()` after each
converged step, `restore()` when a step is cut (the displacement is restored here). A
commit may refuse its step by raising SolveError before it stores anything (a step too
large for the law's integration, on every rank): the step is then cut like a failed solve.

The predictor matters past a bifurcation: from the last state alone Newton can settle on a
nearby unstable branch (a column that stays straight above its Euler load); extrapolation
carries the growing buckling mode into the next step.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from fenics_nl.errors import SolveError
from fenics_nl.solvers.result import SolveResult, WorkCounts

__all__ = ["DriverState", "LoadPath", "LoadStepError", "solve_incrementally"]

log = logging.getLogger(__name__)


class LoadStepError(SolveError):
    """The load could not be reached: the step was cut below its minimum.

    `reached` is the last converged load factor, `target` the one that failed.
    """

    def __init__(self, message: str, result=None, *, reached: float = 0.0, target: float = 0.0):
        super().__init__(message, result)
        self.reached, self.target = reached, target


@dataclass
class DriverState:
    """Where a load path stands after a converged step: enough to go on from it exactly.

    `t` the converged load factor, `dt` the next increment, and, for the predictor, the
    increment that led to `t` and the state before it (this rank's array of the unknown, or
    None). A restart from a checkpoint hands it back to `solve_incrementally` (`start`).
    """

    t: float
    dt: float
    dt_previous: float | None = None
    previous: np.ndarray | None = None


@dataclass
class LoadPath:
    """Converged load factors and their solve results."""

    factors: list[float] = field(default_factory=list)
    results: list[SolveResult] = field(default_factory=list)
    failures: int = 0
    work: WorkCounts = field(default_factory=WorkCounts)

    @property
    def iterations(self) -> int:
        """Newton iterations summed over converged steps."""
        return sum(r.iterations for r in self.results)


def solve_incrementally(
    solver,
    set_load: Callable[[float], None],
    steps: int = 1,
    *,
    adaptive: bool = True,
    min_step: float = 1e-4,
    max_step: float = 1.0,
    easy_iterations: int = 4,
    predictor: bool = True,
    on_step: Callable[[float, SolveResult], None] | None = None,
    progress: Callable[[str], None] | None = None,
    progress_every: int = 1,
    commit: Callable[[], None] | None = None,
    restore: Callable[[], None] | None = None,
    start: DriverState | None = None,
    path_so_far: LoadPath | None = None,
    on_state: Callable[[DriverState, LoadPath], None] | None = None,
) -> LoadPath:
    """Drive the load factor from 0 to 1, starting with `steps` equal increments.

    Args:
        solver: the solver of each step: it has `u` and `solve()` (see the module).
        set_load: ``set_load(t)`` sets the load at the load factor t.
        steps: the first increment is 1/`steps`.
        adaptive: halve the increment of a failed step and grow it after an easy one (False:
            the first failure raises LoadStepError).
        min_step: the smallest increment; a step cut below it raises LoadStepError.
        max_step: the largest increment an easy step grows to.
        easy_iterations: a step converged in at most this many iterations is easy: the next
            increment is 1.5 times larger.
        predictor: start each step from the extrapolation of the last two converged states
            (the secant predictor) rather than from the last one.
        on_step: ``on_step(t, result)`` after each converged step, with its SolveResult.
        progress: ``progress(message)``: a line for every `progress_every`-th converged step,
            and one for every cut step.
        progress_every: how many converged steps between two `progress` lines.
        commit: ``commit()`` after each converged step (it may refuse the step by raising
            SolveError: see the module).
        restore: ``restore()`` when a step is cut (u itself is restored here).
        start: go on from a converged state (a restart: `solver.u` and the internal
            variables already hold it).
        path_so_far: the path before `start` (the one returned goes on from it).
        on_state: ``on_state(state, path)`` after each converged step, with what a restart
            needs (a checkpoint) and the path so far.

    Returns:
        The path, its converged load factors with their SolveResults, the steps cut and the
        work (`path_so_far` itself, if given, extended).

    Raises:
        LoadStepError: if a step fails and cannot be cut (below `min_step`, or not
            `adaptive`); the load is set back to the last converged t.
    """
    if steps < 1:
        raise ValueError(f"steps must be >= 1, got {steps}")
    path = path_so_far if path_so_far is not None else LoadPath()
    x = solver.u.x.petsc_vec
    saved = x.copy()  # last converged state
    previous, dt_previous = None, None  # the one before, for the predictor
    t, dt = 0.0, 1.0 / steps
    if start is not None:
        t, dt, dt_previous = start.t, start.dt, start.dt_previous
        if start.previous is not None:
            previous = x.duplicate()
            previous.array[:] = start.previous
        set_load(t)  # the load of the converged state, as after its step
    while t < 1.0 - 1e-12:
        dt = min(dt, 1.0 - t)
        set_load(t + dt)
        if predictor and previous is not None:  # u = u_k + (dt/dt_k)(u_k − u_{k−1})
            x.axpy(dt / dt_previous, saved)
            x.axpy(-dt / dt_previous, previous)
            x.ghostUpdate()
        result = None
        try:
            result = solver.solve()
            if commit:  # may refuse the step (a SolveError) before it stores anything
                commit()
        except SolveError as err:
            path.failures += 1
            spent = err.result if err.result is not None else result  # a refused commit's
            if spent is not None:
                path.work.add(spent.work)
            saved.copy(x)
            x.ghostUpdate()
            if restore:
                restore()
            if not adaptive or dt / 2 < min_step:
                set_load(t)
                raise LoadStepError(f"load factor {t + dt:.4g} not reached from {t:.4g}: {err}"
                                    + ("" if not adaptive else f"; step cut below {min_step:g}"),
                                    err.result, reached=t, target=t + dt) from err
            dt /= 2
            if progress:
                progress(f"  the step to t = {t + 2 * dt:.4g} is not taken ({err}): retried "
                         f"as two of dt = {dt:.4g}")
            continue
        t += dt
        if predictor:
            if previous is None:
                previous = saved.duplicate()
            saved.copy(previous)
            dt_previous = dt
        x.copy(saved)
        path.factors.append(t)
        path.results.append(result)
        path.work.add(result.work)
        if progress and len(path.factors) % progress_every == 0:
            # a solver may keep no residual history (a composite load, say)
            norm = (f", |R| = {result.residual_norms[-1]:.2e}" if result.residual_norms
                    else "")
            progress(f"step {len(path.factors)}: t = {t:.4g}, {result.iterations} "
                     f"iterations{norm}")
        if on_step:
            on_step(t, result)
        if adaptive and result.iterations <= easy_iterations:
            dt = min(1.5 * dt, max_step)
        if on_state:
            on_state(DriverState(t, dt, dt_previous if predictor else None,
                                 previous.array.copy() if predictor and previous is not None
                                 else None), path)
    return path
