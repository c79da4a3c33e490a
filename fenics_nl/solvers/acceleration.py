"""Acceleration of a fixed-point iteration x ← G(x) on a distributed vector, within bounds.

Alternate minimization is such an iteration on the damage (G: minimize in u, then in α). It
converges linearly, and slowly where the damage localizes (hundreds of iterations in one
load step). Two ways to take longer steps, both projected back on the bounds:

* `OverRelaxation`: x ← x + ω (G(x) − x), ω in [1, 2).
* `Anderson` (depth m): x ← G(x) − ΔG γ, where γ minimizes |f − ΔF γ| over the last m
  differences of the residuals f = G(x) − x (ΔF) and of the G(x) (ΔG): a secant method for
  the fixed point (Walker & Ni 2011), with the least squares in global inner products.
"""

from __future__ import annotations

import numpy as np
from mpi4py import MPI

__all__ = ["Anderson", "OverRelaxation", "accelerator"]


class OverRelaxation:
    """x ← x + ω (G(x) − x)."""

    def __init__(self, omega: float = 1.5):
        if not 1.0 <= omega < 2.0:
            raise ValueError(f"the over-relaxation factor must be in [1, 2), got {omega!r}")
        self.omega = omega

    def reset(self) -> None:
        """Nothing is remembered from one fixed point to the next."""

    def __call__(self, x: np.ndarray, gx: np.ndarray) -> np.ndarray:
        """The next iterate from x and G(x)."""
        return x + self.omega * (gx - x)


class Anderson:
    """Anderson acceleration of depth m (type II, no damping).

    Args:
        comm: the vector's communicator.
        owned: how many leading entries this rank owns (the rest are ghosts: they take the
            same combination, which keeps them consistent).
        depth: m, the differences kept.
    """

    def __init__(self, comm: MPI.Comm, owned: int, depth: int = 5):
        if depth < 1:
            raise ValueError(f"Anderson's depth must be >= 1, got {depth!r}")
        self.comm, self.owned, self.depth = comm, owned, depth
        self.reset()

    def reset(self) -> None:
        """Forget the history (a new fixed point: the next load step)."""
        self._last: tuple[np.ndarray, np.ndarray] | None = None
        self._dF: list[np.ndarray] = []
        self._dG: list[np.ndarray] = []

    def __call__(self, x: np.ndarray, gx: np.ndarray) -> np.ndarray:
        """The next iterate from x and G(x), and the history kept."""
        f = gx - x
        if self._last is not None:
            f0, g0 = self._last
            self._dF.append(f - f0)
            self._dG.append(gx - g0)
            del self._dF[:-self.depth], self._dG[:-self.depth]
        self._last = (f, gx.copy())
        if not self._dF:
            return gx
        n = self.owned
        dF = np.column_stack([d[:n] for d in self._dF])
        normal = self.comm.allreduce(dF.T @ dF, op=MPI.SUM)
        rhs = self.comm.allreduce(dF.T @ f[:n], op=MPI.SUM)
        if np.trace(normal) == 0:  # the residual did not change: nothing to combine
            return gx
        # a small Tikhonov term: successive differences become parallel near convergence
        normal += 1e-12 * np.trace(normal) * np.eye(len(rhs))
        gamma = np.linalg.solve(normal, rhs)
        return gx - np.column_stack(self._dG) @ gamma


def accelerator(name: str, comm: MPI.Comm, owned: int, *, omega: float = 1.5,
                depth: int = 5):
    """None (plain iteration), an `OverRelaxation` or an `Anderson` by its name.

    Args:
        name: ``none``, ``overrelaxed`` or ``anderson``.
        comm: the vector's communicator (Anderson's global inner products).
        owned: how many leading entries this rank owns (Anderson's).
        omega: ω, the over-relaxation factor, in [1, 2).
        depth: m, the differences Anderson keeps.

    Returns:
        The accelerator, called as ``accelerate(x, G(x))`` for the next iterate, or None
        for ``none``.

    Raises:
        ValueError: for another name.
    """
    if name == "none":
        return None
    if name == "overrelaxed":
        return OverRelaxation(omega)
    if name == "anderson":
        return Anderson(comm, owned, depth)
    raise ValueError(f"acceleration must be none, overrelaxed or anderson, got {name!r}")
