"""The load-stepping driver: any solver with `u` and `solve()`, and the commit/restore hooks."""

import numpy as np
import pytest
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.errors import SolveError
from fenics_nl.solvers.loading import LoadStepError, solve_incrementally
from fenics_nl.solvers.result import SolveResult, WorkCounts


class ScalarLoad:
    """u = t everywhere; a step longer than `max_dt` fails (as Newton would)."""

    def __init__(self, max_dt):
        self.u = fem.Function(fem.functionspace(mesh.create_unit_interval(MPI.COMM_WORLD, 4),
                                                ("Lagrange", 1)))
        self.max_dt, self.t, self.t_done = max_dt, 0.0, 0.0

    def solve(self):
        if self.t - self.t_done > self.max_dt + 1e-12:
            raise SolveError("step too long", SolveResult(False, "test", 3, [1.0], WorkCounts()))
        self.u.x.array[:] = self.t
        self.t_done = self.t
        return SolveResult(True, "test", 1, [1.0, 0.0], WorkCounts())


def test_commit_after_each_converged_step_restore_after_each_cut():
    s = ScalarLoad(max_dt=0.3)
    state = {"committed": [], "restored": 0}

    def set_load(t):
        s.t = t

    def restore():
        state["restored"] += 1
        s.t_done = state["committed"][-1] if state["committed"] else 0.0

    path = solve_incrementally(s, set_load, steps=1, predictor=False, easy_iterations=0,
                               commit=lambda: state["committed"].append(s.t_done),
                               restore=restore)
    assert path.factors[-1] == pytest.approx(1.0)
    assert state["committed"] == pytest.approx(path.factors)  # one commit per converged step
    assert state["restored"] == path.failures >= 2  # 1 → 0.5 → 0.25 cut, then steps of 0.25
    assert np.allclose(s.u.x.array, 1.0)


def test_any_solve_error_is_a_load_step_error_with_the_factors():
    s = ScalarLoad(max_dt=0.3)
    with pytest.raises(LoadStepError, match="load factor 1 not reached from 0") as err:
        solve_incrementally(s, lambda t: setattr(s, "t", t), steps=1, adaptive=False)
    assert err.value.reached == 0.0 and err.value.target == 1.0
    assert err.value.result.iterations == 3  # the failed solve's record is kept
