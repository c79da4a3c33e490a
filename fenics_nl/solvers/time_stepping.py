"""Time as the load parameter: steps in time for a rate-dependent law, sized by their error.

A viscous law (`materials.creep`) integrates its flow by backward Euler over each time step
Δt. The load factor is a function of time (`LoadHistory`, piecewise linear: a ramp, then a
hold). Each step sets the load at its end time and the law's Δt, solves, and commits; then
the step's **local error** is estimated from the viscous strain increments of this step and
the last one. Backward Euler evaluates the rate at the step's end, so over a step the
increment's error is about half the change of the rate:

    e = max over the points of 3μ · ½ ‖Δεᵛₙ₊₁ − (Δtₙ₊₁/Δtₙ) Δεᵛₙ‖_eq  /  max σ_eq

(‖·‖_eq = √(2/3 d:d), the equivalent of a deviatoric strain; 3μ turns it into a stress;
the first step after rest has Δεᵛₙ = 0). A step with e above the tolerance is undone (the
unknown and the law's state put back) and retaken shorter; after an accepted one the next
step is Δt · min(2, 0.9 √(tol/e)) (the error of a first-order method grows as Δt²). Steps
land on the load history's points, on the times asked for (`land_on`) and on the end: a
step that would end just short of one is replaced by two equal ones reaching it (no
sliver); the next step grows from the one taken. A step whose Newton solve fails is
halved. With `adaptive = False` every step is end/steps (cut
to land; the error is still reported).

Between steps (in `on_step`, `on_state`) the law's Δt is 0: its stress is the committed
state's, not one more step's flow from it.

Under a load that no longer changes the stresses may settle. The test does not depend on
the step: the state is stationary once, at the rate of σ_eq's largest change over the last
step, the time the load has been held would change σ_eq by less than `stationary` of its
largest value (max |Δσ_eq|/Δt · t_held ≤ stationary · max σ_eq): `TimePath.
stationary_since`, reset by a later change of the load; the run may end there
(`until_stationary`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from itertools import pairwise

import numpy as np
from mpi4py import MPI

from fenics_nl.errors import SolveError
from fenics_nl.solvers.loading import LoadPath, LoadStepError
from fenics_nl.solvers.result import SolveResult

__all__ = ["LoadHistory", "TimePath", "TimeState", "next_step", "solve_in_time", "step_error"]

GROWTH = 2.0  # the largest factor between two steps
SHRINK = 0.2  # the smallest factor of a rejected step
SAFETY = 0.9  # the step aims below the tolerance


class LoadHistory:
    """A load factor piecewise linear in time, constant after its last point.

    Args:
        points: ``[(t0, f0), (t1, f1), ...]``, times strictly increasing from t0 = 0.
    """

    def __init__(self, points):
        pts = [(float(t), float(f)) for t, f in points]
        times = [t for t, _ in pts]
        if not pts or times[0] != 0.0 or any(b <= a for a, b in pairwise(times)):
            raise ValueError("the load history's times must start at 0 and increase, got "
                             f"{times}")
        self.points = pts

    def __call__(self, t: float) -> float:
        """The load factor at time t."""
        times, factors = zip(*self.points, strict=True)
        return float(np.interp(t, times, factors))

    def breakpoints(self) -> list[float]:
        """The times of its points after 0 (the steps land on them)."""
        return [t for t, _ in self.points[1:]]


@dataclass
class TimeState:
    """Where a time path stands after an accepted step: enough to go on from it exactly.

    `dt` is the step wanted next, `rate` this rank's Δεᵛ/Δt of the last step (None before
    the first), `stress` its σ_eq at the quadrature points, `held_since` the time from
    which the load factor has not changed (None while it changes).
    """

    t: float
    dt: float
    rate: np.ndarray | None = None
    stress: np.ndarray | None = None
    stationary_since: float | None = None
    held_since: float | None = None


@dataclass
class TimePath(LoadPath):
    """The accepted steps' times (beside their load factors), errors and rejections.

    `errors[i]` is the local error of the step that ended at `times[i]` (0 for a load
    applied at once).
    """

    times: list[float] = field(default_factory=list)
    errors: list[float] = field(default_factory=list)
    rejected: int = 0  # steps undone for their error (`failures`: for their solve)
    stationary_since: float | None = None  # the end of the first stationary step
    stationary_after: float | None = None  # its start: the state settled in between
    change: float | None = None  # the last step's stationary measure (module docstring)


def step_error(increment, previous_rate, dt: float, mu: float, scale: float, comm) -> float:
    """The step's local error over the largest equivalent stress (module docstring).

    Args:
        increment: Δεᵛ of the step at this rank's owned points (array, 9 values a point).
        previous_rate: Δεᵛ/Δt of the last step there (None: at rest before).
        dt: the step's Δt.
        mu: the shear modulus.
        scale: the largest σ_eq at the step's end (over every rank).
        comm: the mesh's communicator.

    Returns:
        e, the same on every rank (0 where nothing is stressed).
    """
    d = increment.reshape(-1, 9)
    if previous_rate is not None:
        d = d - dt * previous_rate.reshape(-1, 9)
    local = 3 * mu * 0.5 * math.sqrt(2 / 3 * float(np.einsum("ij,ij->i", d, d).max(initial=0)))
    error = comm.allreduce(local, op=MPI.MAX)
    return error / scale if scale > 0 else 0.0


def next_step(t: float, dt: float, stops: list[float]) -> float:
    """The end of the step from t wanted as long as dt, landing on the next of `stops`.

    Args:
        t: the step's start.
        dt: the step wanted.
        stops: the times to land on, increasing, the last the end.

    Returns:
        The step's end: the next stop itself if dt reaches it, half the way to it if dt
        reaches more than half of it (two equal steps rather than one and a sliver), else
        t + dt.
    """
    stop = next(s for s in stops if s > t * (1 + 1e-12))
    remaining = stop - t
    if dt >= remaining * (1 - 1e-12):
        return stop
    if dt > 0.5 * remaining:
        return t + 0.5 * remaining
    return t + dt


class _Steps:
    """The unknown and the law's state: kept after an accepted step, put back after not."""

    def __init__(self, solver, law):
        self.x = solver.u.x.petsc_vec
        self.saved = self.x.copy()
        self.functions = [*law.state_functions().values(), law.equivalent_stress]
        self.eps_v, self.q = law.viscous_strain, law.equivalent_stress
        self.owned = self.eps_v.function_space.dofmap.index_map.size_local
        self.comm = self.eps_v.function_space.mesh.comm
        self.before = None

    def begin(self) -> None:
        """Before a step: what `undo` puts back."""
        self.before = [f.x.array.copy() for f in self.functions]

    def undo(self) -> None:
        """The unknown and the state (with σ_eq) back to the last accepted step."""
        self.saved.copy(self.x)
        self.x.ghostUpdate()
        for f, values in zip(self.functions, self.before, strict=True):
            f.x.array[:] = values

    def keep(self) -> None:
        """After an accepted step: it becomes what `undo` puts back."""
        self.x.copy(self.saved)

    def increment(self) -> np.ndarray:
        """Δεᵛ of the step at this rank's owned points."""
        n = 9 * self.owned
        return self.eps_v.x.array[:n] - self.before[0][:n]

    def stress(self) -> np.ndarray:
        """σ_eq at this rank's owned points (a copy)."""
        return self.q.x.array[: self.owned].copy()

    def largest(self, values) -> float:
        """The largest |value| over every rank."""
        return self.comm.allreduce(float(np.abs(values).max(initial=0.0)), op=MPI.MAX)


def solve_in_time(solver, law, set_load: Callable[[float], None], history: LoadHistory,
                  end: float, steps: int, *, commit: Callable[[], None],
                  adaptive: bool = True, tolerance: float = 1e-3, stationary: float = 1e-6,
                  until_stationary: bool = False, land_on: Sequence[float] = (),
                  min_step: float | None = None,
                  on_step: Callable[[float, float, SolveResult], None] | None = None,
                  progress: Callable[[str], None] | None = None,
                  start: TimeState | None = None, path_so_far: TimePath | None = None,
                  on_state: Callable[[TimeState, TimePath], None] | None = None) -> TimePath:
    """Step from time 0 (or `start`) to `end`, the load factor following `history`.

    If the load factor at time 0 is not 0, the load is first applied at once (a step of
    Δt = 0: the law's instantaneous, elastic response, recorded at time 0).

    Args:
        solver: the solver of each step: it has `u` and `solve()` (as `solve_incrementally`).
        law: the viscous law of the residual (`materials.creep.ViscousLaw`, bound).
        set_load: ``set_load(f)`` sets the load at the load factor f.
        history: the load factor against time.
        end: the last time.
        steps: the first step is end/steps, or less to land on the first stop (every step,
            if not `adaptive`).
        commit: stores the law's state of the converged `solver.u` (``law.commit(u, model)``).
        adaptive: size the steps by their error (else equal steps; a failed solve is then
            the end).
        tolerance: the largest local error e of an accepted step (module docstring).
        stationary: the relative change of σ_eq over the time held below which the state
            is stationary (module docstring).
        until_stationary: end the run at the first stationary step (before `end`).
        land_on: times the steps land on besides the history's points (outputs).
        min_step: the shortest step (default end · 1e-12); a step cut below it raises.
        on_step: ``on_step(time, load_factor, result)`` after each accepted step.
        progress: ``progress(message)``: a line for every accepted step, and one starting
            with two spaces for every step undone or retried and for the stationary state.
        start: go on from an accepted step (a restart: `solver.u` and the law hold it).
        path_so_far: the path before `start` (the one returned goes on from it).
        on_state: ``on_state(state, path)`` after each accepted step (a checkpoint).

    Returns:
        The path: the accepted steps' times, load factors, results and errors, the steps
        undone, the work, and the time from which the state was stationary (None: never).

    Raises:
        LoadStepError: a step cut below `min_step`, any failed step if not `adaptive`, or
            the load at time 0 not reached; its `reached` and `target` are times. The
            law's Δt is then 0 and the load the last accepted step's.
    """
    if steps < 1 or not end > 0:
        raise ValueError(f"need end > 0 and steps >= 1, got end = {end}, steps = {steps}")
    path = path_so_far if path_so_far is not None else TimePath()
    min_step = end * 1e-12 if min_step is None else min_step
    kept = _Steps(solver, law)
    stops = sorted({s for s in [*history.breakpoints(), *land_on] if 0 < s < end} | {end})

    def fail(t: float, target: float, why: str, result, cause=None):
        set_load(history(t))
        law.set_time_step(0.0)
        raise LoadStepError(f"time {target:.4g} not reached from {t:.4g}: {why}", result,
                            reached=t, target=target) from cause

    if start is None:
        t, dt, rate, stress_before, since = 0.0, end / steps, None, None, None
        held_since = 0.0 if history(0.0) != 0.0 else None
        if history(0.0) != 0.0:  # the load applied at once
            set_load(history(0.0))
            law.set_time_step(0.0)
            kept.begin()
            try:
                result = solver.solve()
                commit()
            except SolveError as err:
                kept.undo()
                fail(0.0, 0.0, f"the load applied at once: {err}", err.result, err)
            kept.keep()
            path.errors.append(0.0)
            _accept(path, 0.0, history(0.0), result, 0.0, on_step, progress)
            stress_before = kept.stress()
    else:
        t, dt, rate, since = start.t, start.dt, start.rate, start.stationary_since
        stress_before, held_since = start.stress, start.held_since
    while t < end * (1 - 1e-12):
        wanted = dt if adaptive else end / steps
        target = next_step(t, wanted, stops)
        taken = target - t
        f = history(target)
        set_load(f)
        law.set_time_step(taken)
        kept.begin()
        try:
            result = solver.solve()
            commit()
        except SolveError as err:
            path.failures += 1
            if err.result is not None:
                path.work.add(err.result.work)
            kept.undo()
            dt = taken / 2
            if not adaptive or dt < min_step:
                fail(t, target, str(err), err.result, err)
            if progress:
                progress(f"  the step to time {target:.4g} is not taken ({err}): "
                         f"retried with dt = {dt:.4g}")
            continue
        increment = kept.increment()
        stress = kept.stress()
        scale = kept.largest(stress)
        error = step_error(increment, rate, taken, law.mu, scale, kept.comm)
        if adaptive and error > tolerance:
            path.rejected += 1
            path.work.add(result.work)
            kept.undo()
            dt = taken * max(SHRINK, SAFETY * math.sqrt(tolerance / error))
            if dt < min_step:
                fail(t, target, f"the local error stays above {tolerance:g}", result)
            if progress:
                progress(f"  the step to time {target:.4g} is undone: local error "
                         f"{error:.2e} > {tolerance:g}")
            continue
        law.set_time_step(0.0)  # the stress forms now read the committed state
        kept.keep()
        held = history(t) == f
        held_since = (held_since if held_since is not None else t) if held else None
        t, rate = target, increment / taken
        if held_since is not None and stress_before is not None:
            # σ_eq's largest change at this step's rate over the time held
            change = kept.largest(stress - stress_before) / taken * (t - held_since)
            path.change = change / scale if scale > 0 else 0.0
            settled = path.change <= stationary
            if settled and since is None:
                since, path.stationary_after = t, t - taken
                if progress:
                    progress(f"  stationary between times {t - taken:.4g} and {t:.4g}: at "
                             f"σ_eq's rate of change, the time held would change it by "
                             f"{path.change:.1e} of its largest value")
            elif not settled:
                since = path.stationary_after = None
        else:
            since = path.stationary_after = path.change = None
        stress_before = stress
        path.errors.append(error)
        path.stationary_since = since
        _accept(path, t, f, result, error, on_step, progress)
        if adaptive:
            dt = taken * min(GROWTH, GROWTH if error == 0 else
                             SAFETY * math.sqrt(tolerance / error))
        if on_state:
            on_state(TimeState(t, dt, rate.copy(), stress.copy(), since, held_since), path)
        if until_stationary and since is not None:
            break
    return path


def _accept(path: TimePath, t: float, f: float, result: SolveResult, error: float,
            on_step, progress) -> None:
    path.times.append(t)
    path.factors.append(f)
    path.results.append(result)
    path.work.add(result.work)
    if progress:
        progress(f"time {t:.6g}: load factor {f:.4g}, {result.iterations} iterations, "
                 f"local error {error:.2e}")
    if on_step:
        on_step(t, f, result)
