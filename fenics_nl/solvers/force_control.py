"""Force control of a problem driven by a prescribed displacement: the displacement of a force.

A rigid punch, a die, a grip: the solver prescribes the displacement d and the force P(d)
is the result. To reach a given force, d is found by secant steps: on (ln d, ln P) from
rest (`reach_force`: exact in one step for a power law P ∝ d^m, Hertz's m = 3/2, and quick
for laws close to one), or on (d, Q) from a loaded state (`reach_load`: a tangential force
that bends as the contact slips).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

from fenics_nl.errors import SolveError
from fenics_nl.solvers.result import SolveResult, WorkCounts

__all__ = ["MotionPath", "reach_force", "reach_load"]


def reach_force(state_at: Callable[[float], object], force: float, guess: float, *,
                exponent: float = 1.5, rtol: float = 1e-10, max_it: int = 30
                ) -> tuple[object, int]:
    """The state whose `force` is `force`, and the states it took.

    Args:
        state_at: the converged state at a prescribed displacement d (a record with its
            total `force`, positive, growing with d).
        force: the force to reach, > 0.
        guess: the first displacement tried.
        exponent: the m of P ∝ d^m expected, for the second displacement tried.
        rtol: the relative tolerance on the force.
        max_it: the states tried at most.

    Returns:
        (the state at P = force within rtol, every (d, state) tried, in order; the work
        spent is theirs all).

    Raises:
        SolveError: the force is not reached in `max_it` states.
    """
    if not force > 0:
        raise ValueError(f"force must be > 0, got {force}")
    tried = []

    def at(d):
        tried.append((d, state_at(d)))
        return tried[-1][1]

    d0, s0 = guess, at(guess)
    d1 = d0 * (force / s0.force) ** (1 / exponent) if s0.force > 0 else 2 * d0
    for _ in range(max_it - 1):
        s1 = at(d1)
        if abs(s1.force / force - 1) < rtol:
            return s1, tried
        if s1.force <= 0 or s0.force <= 0 or s1.force == s0.force:  # not touching yet
            d0, s0, d1 = d1, s1, 1.5 * d1
            continue
        slope = math.log(s1.force / s0.force) / math.log(d1 / d0)
        d0, s0 = d1, s1
        d1 = d1 * (force / s1.force) ** (1 / slope)
    raise SolveError(f"force {force:g} not reached in {max_it} positions")


def reach_load(state_at: Callable[[float], object], load: float, start: tuple[float, float],
               first: float, *, of: Callable[[object], tuple[float, float]], atol: float,
               max_it: int = 60) -> tuple[object, int]:
    """The state whose load is `load`, by secant steps on the position from a known state.

    For a load Q(d) that grows with the position d and bends as the body gives way (a
    tangential force as nodes slip: concave from a full stick), secant steps from the
    first slope approach the load from its side and do not overshoot.

    Args:
        state_at: the converged state at the position d.
        load: the load to reach.
        start: (d, Q) of the state the steps start from (the last committed one).
        first: the first position tried (close to the start: the initial slope).
        of: (d, Q) of a state.
        atol: the tolerance on the load.
        max_it: the positions tried at most.

    Returns:
        (the state at Q = load within atol, the number of `state_at` calls).

    Raises:
        SolveError: Q does not grow with d, or is not reached in `max_it` positions.
    """
    d_prev, q_prev = start
    s = state_at(first)
    for k in range(max_it):
        d, q = of(s)
        if abs(q - load) <= atol:
            return s, k + 1
        slope = (q - q_prev) / (d - d_prev)
        if not slope > 0:
            raise SolveError(f"the load does not grow with the position (slope {slope:.3g} "
                             f"at d = {d:.6g})")
        d_prev, q_prev = d, q
        s = state_at(d + (load - q) / slope)
    raise SolveError(f"load {load:g} not reached in {max_it} positions")


class MotionPath:
    """A load path by a prescribed motion, as `loading.solve_incrementally` drives a solver.

    The load factor t scales the displacement, d = t `displacement`, or the force,
    P = t `force`: d is then found by `reach_force`, from d ∝ t^(1/m) (the last step's d,
    or `guess` at t = 1 for the first). Each converged state is kept in `states`.

    Args:
        state_at: the converged state at the displacement d: a record with its `force`, the
            work it took (`newton_iterations`, `factorizations`, `active_set_iterations`)
            and `plus_work_of(states)` (`contact.obstacles.Indentation`).
        u: the unknown the states are solved for (the driver restores it after a failure).
        displacement: the displacement at t = 1 (displacement control), or None.
        force: the force at t = 1 (force control), or None.
        guess: force control: the displacement expected at t = 1.
        exponent: force control: the m of P ∝ d^m expected (Hertz's 3/2).
    """

    def __init__(self, state_at: Callable[[float], object], u, *,
                 displacement: float | None = None, force: float | None = None,
                 guess: float | None = None, exponent: float = 1.5):
        if (displacement is None) == (force is None):
            raise ValueError("give either a displacement or a force")
        if force is not None and not (guess is not None and guess > 0):
            raise ValueError("force control needs the displacement expected at t = 1 (guess)")
        self.state_at, self.u = state_at, u
        self.displacement, self.force, self.guess = displacement, force, guess
        self.exponent = exponent
        self.states: list = []
        self.positions: list[float] = []  # the displacement of each state
        self.t, self.t_last = 0.0, 0.0

    def set_load(self, t: float) -> None:
        """The load factor of the next solve.

        Args:
            t: the load factor.
        """
        self.t = t

    def solve(self) -> SolveResult:
        """The state at the current load factor, from the last one.

        Returns:
            Its work as a converged SolveResult, whose iterations are Newton's.
        """
        t = self.t
        if self.force is None:
            d = t * self.displacement
            s = self.state_at(d)
        else:  # the step's state, with the work of every position tried to reach its force
            d0, t0 = (self.positions[-1], self.t_last) if self.positions else (self.guess, 1.0)
            s, tried = reach_force(self.state_at, t * self.force,
                                   d0 * (t / t0) ** (1 / self.exponent), exponent=self.exponent)
            d, s = tried[-1][0], s.plus_work_of(x for _, x in tried[:-1])
        self.states.append(s)
        self.positions.append(d)
        self.t_last = t
        return SolveResult(True, "prescribed motion", s.newton_iterations, [],
                           WorkCounts(factorizations=s.factorizations),
                           active_set_iterations=s.active_set_iterations)

    def record(self) -> dict:
        """The converged states, their displacements and the last load factor, JSON-able.

        Returns:
            What `take_back` takes (a checkpoint's).
        """
        return {"states": [dataclasses.asdict(s) for s in self.states],
                "positions": self.positions, "t": self.t_last}

    def take_back(self, record: dict, state_type: type) -> None:
        """The states of `record()` back: the next solve goes on from the last of them.

        Args:
            record: what `record` gave.
            state_type: the states' dataclass.
        """
        self.states[:] = [state_type(**s) for s in record["states"]]
        self.positions[:] = record["positions"]
        self.t_last = record["t"]
