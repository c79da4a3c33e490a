"""What every solver returns: one result type, and the work it counts."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from fenics_nl.solvers.convergence import observed_orders

__all__ = ["SolveResult", "WorkCounts"]

PHASES = ("residual", "tangent", "factorization", "solve")


@dataclass
class WorkCounts:
    """What a solve spent: assemblies, factorizations, linear solves and time per phase."""

    residual_assemblies: int = 0
    tangent_assemblies: int = 0
    factorizations: int = 0
    linear_solves: int = 0
    krylov_iterations: int = 0  # CG iterations (GAMG, or a reused factorization), else 0
    update_columns: int = 0  # back-solves of new Dirichlet rows on an old factorization
    time: dict[str, float] = field(default_factory=lambda: dict.fromkeys(PHASES, 0.0))

    def add(self, other: WorkCounts) -> None:
        """Accumulate `other` into self.

        Args:
            other: the counts and times added (a solve's, a step's).
        """
        self.residual_assemblies += other.residual_assemblies
        self.tangent_assemblies += other.tangent_assemblies
        self.factorizations += other.factorizations
        self.linear_solves += other.linear_solves
        self.krylov_iterations += other.krylov_iterations
        self.update_columns += other.update_columns
        for k, v in other.time.items():
            self.time[k] = self.time.get(k, 0.0) + v


@dataclass
class SolveResult:
    """Outcome of one solve of the current load state, whatever the solver.

    `iterations` are non-linear (Newton) iterations, summed over the inner solves of an
    active-set loop, whose own count is `active_set_iterations` (0 without contact).
    """

    converged: bool
    reason: str  # converged, nan, max_it, round_off (max_it at round-off), diverged, ksp...
    iterations: int
    residual_norms: list[float]
    work: WorkCounts
    wall_time: float = 0.0
    elapsed: list[float] = field(default_factory=list)  # seconds from the start, per norm
    active_set_iterations: int = 0
    active_sizes: list[int] = field(default_factory=list)  # active nodes after each
    history: list[dict] = field(default_factory=list)  # per active-set iteration

    @classmethod
    def restored(cls, iterations: int) -> SolveResult:
        """A step converged before a restart: its iteration count, no norms.

        Its work is in the totals of the path it came back with.

        Args:
            iterations: the step's iteration count, as the checkpoint recorded it.

        Returns:
            A converged result with that count, no residual norms and no work.
        """
        return cls(True, "converged (before the restart)", iterations, [], WorkCounts())

    @property
    def orders(self) -> list[float]:
        """Observed orders from the residual norms (round-off tail excluded)."""
        r = self.residual_norms
        return observed_orders(r, floor=1e-11 * max(r)) if r else []

    @property
    def order(self) -> float:
        """Last observed order, NaN when fewer than three meaningful residuals exist."""
        q = self.orders
        return q[-1] if q else math.nan
