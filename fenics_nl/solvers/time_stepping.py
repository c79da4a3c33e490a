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
land on the load history's corners and on the end. A step whose Newton solve fails is
halved. With `adaptive = False` every step is end/steps (the error is still reported).

Between steps (in `on_step`, `on_state`) the law's Δt is 0: its stress is the committed
state's, not one more step's flow from it.

Under a load that no longer changes the stresses may settle: once the largest change of
σ_eq over a step is below `stationary` times the largest σ_eq, the run has reached a
stationary state (`TimePath.stationary_since`; a later change of the load resets it); the
run may end there (`until_stationary`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from itertools import pairwise

import numpy as np
from mpi4py import MPI

from fenics_nl.errors import SolveError
from fenics_nl.solvers.loading import LoadPath, LoadStepError
from fenics_nl.solvers.result import SolveResult

__all__ = ["LoadHistory", "TimePath", "TimeState", "solve_in_time", "step_error"]

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

    def corners(self) -> list[float]:
        """The times where the slope changes (the steps land on them)."""
        return [t for t, _ in self.points[1:]]


@dataclass
class TimeState:
    """Where a time path stands after an accepted step: enough to go on from it exactly.

    `rate` is this rank's Δεᵛ/Δt of that step (None before the first), `stress` its σ_eq
    at the quadrature points (for the stationary test).
    """

    t: float
    dt: float
    rate: np.ndarray | None = None
    stress: np.ndarray | None = None
    stationary_since: float | None = None


@dataclass
class TimePath(LoadPath):
    """The accepted steps' times (beside their load factors), errors and rejections."""

    times: list[float] = field(default_factory=list)
    errors: list[float] = field(default_factory=list)  # each accepted step's e
    rejected: int = 0  # steps undone for their error (`failures`: for their solve)
    stationary_since: float | None = None


def step_error(increment, previous_rate, dt: float, mu: float, stress, comm) -> float:
    """The step's local error over the largest equivalent stress (module docstring).

    Args:
        increment: Δεᵛ of the step at this rank's owned points (array, 9 values a point).
        previous_rate: Δεᵛ/Δt of the last step there (None: at rest before).
        dt: the step's Δt.
        mu: the shear modulus.
        stress: σ_eq at the step's end at the same points.
        comm: the mesh's communicator.

    Returns:
        e, the same on every rank (0 where nothing is stressed).
    """
    d = increment.reshape(-1, 9)
    if previous_rate is not None:
        d = d - dt * previous_rate.reshape(-1, 9)
    local = 3 * mu * 0.5 * math.sqrt(2 / 3 * float(np.einsum("ij,ij->i", d, d).max(initial=0)))
    error = comm.allreduce(local, op=MPI.MAX)
    scale = comm.allreduce(float(np.abs(stress).max(initial=0.0)), op=MPI.MAX)
    return error / scale if scale > 0 else 0.0


def solve_in_time(solver, law, set_load: Callable[[float], None], history: LoadHistory,
                  end: float, steps: int, *, commit: Callable[[], None],
                  adaptive: bool = True, tolerance: float = 1e-3, stationary: float = 1e-6,
                  until_stationary: bool = False, min_step: float | None = None,
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
        steps: the first step is end/steps (all of them if not `adaptive`).
        commit: stores the law's state of the converged `solver.u` (``law.commit(u, model)``).
        adaptive: size the steps by their error (else equal steps; a failed solve is then
            the end).
        tolerance: the largest local error e of an accepted step (module docstring).
        stationary: the relative change of σ_eq over a step below which the state is
            stationary.
        until_stationary: end the run at the first stationary step (before `end`).
        min_step: the shortest step (default end · 1e-12); a step cut below it raises.
        on_step: ``on_step(time, load_factor, result)`` after each accepted step.
        progress: ``progress(message)``: a line for every accepted and every undone step.
        start: go on from an accepted step (a restart: `solver.u` and the law hold it).
        path_so_far: the path before `start` (the one returned goes on from it).
        on_state: ``on_state(state, path)`` after each accepted step (a checkpoint).

    Returns:
        The path: the accepted steps' times, load factors, results and errors, the steps
        undone, the work, and the time from which the state was stationary (None: never).

    Raises:
        LoadStepError: a step cut below `min_step` (or any failed step, not `adaptive`);
            its `reached` and `target` are times.
    """
    if steps < 1 or not end > 0:
        raise ValueError(f"need end > 0 and steps >= 1, got end = {end}, steps = {steps}")
    path = path_so_far if path_so_far is not None else TimePath()
    min_step = end * 1e-12 if min_step is None else min_step
    x = solver.u.x.petsc_vec
    saved = x.copy()
    state = law.state_functions()
    eps_v, q = law.viscous_strain, law.equivalent_stress
    owned = eps_v.function_space.dofmap.index_map.size_local
    comm = eps_v.function_space.mesh.comm
    corners = [c for c in history.corners() if c < end] + [end]
    if start is None:
        t, dt, rate, stress_before, since = 0.0, end / steps, None, None, None
        if history(0.0) != 0.0:  # the load applied at once
            set_load(history(0.0))
            law.set_time_step(0.0)
            result = solver.solve()
            commit()
            x.copy(saved)
            _accept(path, 0.0, history(0.0), result, 0.0, on_step, progress)
            stress_before = q.x.array[:owned].copy()
    else:
        t, dt, rate, since = start.t, start.dt, start.rate, start.stationary_since
        stress_before = start.stress
    while t < end * (1 - 1e-12):
        if not adaptive:
            dt = end / steps
        corner = next(c for c in corners if c > t * (1 + 1e-12))
        target = corner if t + dt >= corner else t + dt  # a corner's time exactly
        dt = target - t
        f = history(target)
        set_load(f)
        law.set_time_step(dt)
        before = {k: g.x.array.copy() for k, g in state.items()}
        q_before = q.x.array.copy()
        try:
            result = solver.solve()
            commit()
        except SolveError as err:
            path.failures += 1
            if err.result is not None:
                path.work.add(err.result.work)
            _undo(x, saved, state, before, q, q_before)
            if not adaptive or dt / 2 < min_step:
                set_load(history(t))
                raise LoadStepError(f"time {target:.4g} not reached from {t:.4g}: {err}",
                                    err.result, reached=t, target=target) from err
            dt /= 2
            if progress:
                progress(f"  the step to time {target:.4g} is not taken ({err}): "
                         f"retried with dt = {dt:.4g}")
            continue
        increment = eps_v.x.array[: 9 * owned] - before["viscous_strain"][: 9 * owned]
        error = step_error(increment, rate, dt, law.mu, q.x.array[:owned], comm)
        if adaptive and error > tolerance:
            path.rejected += 1
            path.work.add(result.work)
            _undo(x, saved, state, before, q, q_before)
            if dt * SHRINK < min_step:
                set_load(history(t))
                raise LoadStepError(f"time {target:.4g} not reached from {t:.4g}: the local "
                                    f"error stays above {tolerance:g}", result,
                                    reached=t, target=target)
            if progress:
                progress(f"  the step to time {target:.4g} is undone: local error "
                         f"{error:.2e} > {tolerance:g}")
            dt *= max(SHRINK, SAFETY * math.sqrt(tolerance / error))
            continue
        law.set_time_step(0.0)  # the stress forms now read the committed state
        held = history(t) == f
        t = target
        x.copy(saved)
        rate = increment / dt
        stress = q.x.array[:owned].copy()
        if held and stress_before is not None:
            change = _relative_change(stress_before, stress, comm)
            if change <= stationary and since is None:
                since = t
                if progress:
                    progress(f"  stationary from time {t:.6g}: σ_eq changed by "
                             f"{change:.1e} of its largest value over the step")
            elif change > stationary:
                since = None
        else:
            since = None
        stress_before = stress
        path.errors.append(error)
        path.stationary_since = since
        _accept(path, t, f, result, error, on_step, progress)
        if adaptive:
            grow = GROWTH if error == 0 else SAFETY * math.sqrt(tolerance / error)
            dt *= min(GROWTH, grow)
        if on_state:
            on_state(TimeState(t, dt, rate.copy(), stress.copy(), since), path)
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


def _undo(x, saved, state: dict, before: dict, q, q_before) -> None:
    """The unknown and the law's state (and σ_eq) back to the last accepted step."""
    saved.copy(x)
    x.ghostUpdate()
    for k, g in state.items():
        g.x.array[:] = before[k]
    q.x.array[:] = q_before


def _relative_change(before, after, comm) -> float:
    change = comm.allreduce(float(np.abs(after - before).max(initial=0.0)), op=MPI.MAX)
    scale = comm.allreduce(float(np.abs(after).max(initial=0.0)), op=MPI.MAX)
    return change / scale if scale > 0 else 0.0
