"""The same problems through PETSc SNES (`dolfinx.fem.petsc.NonlinearProblem`), for cross-checks.

`SnesSolver` has the surface of `NewtonSolver` (`solve()` → `SolveResult`), so demos and
benchmarks swap one for the other. Work is counted with PETSc's own logging events, so the
counts do not depend on our code being right. Modified and periodic Newton are SNES's
Jacobian lagging (`-snes_lag_jacobian`).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from contextlib import contextmanager

import ufl
from dolfinx import fem
from dolfinx.fem import petsc
from petsc4py import PETSc

from fenics_nl.solvers.convergence import ConvergenceTest
from fenics_nl.solvers.form_matrix import FormMatrix
from fenics_nl.solvers.linear_solver import LinearSolver
from fenics_nl.solvers.newton import ConvergenceError, Method
from fenics_nl.solvers.result import SolveResult, WorkCounts
from fenics_nl.solvers.supports import RigidMotions, check_supports

__all__ = [
    "EventCounter",
    "SnesSolver",
    "all_event_names",
    "petsc_work",
    "unless_set",
]

# PETSc event names behind each count; MUMPS factorizations log as Mat*FactorNum.
EVENTS = {
    "residual_assemblies": "SNESFunctionEval",
    "tangent_assemblies": "SNESJacobianEval",
    "factorizations": ("MatLUFactorNum", "MatCholFctrNum"),
    "linear_solves": "KSPSolve",
}
# timed with the numeric factorizations: NewtonSolver's factorization time is its PC's set-up,
# MUMPS's analysis included
SYMBOLIC = ("MatLUFactorSym", "MatCholFctrSym")


class EventCounter:
    """Counts and times of PETSc log events between `start()` and `stop()`."""

    def __init__(self, names: Sequence[str]):
        if not PETSc.Log.isActive():
            PETSc.Log.begin()
        self.events = {n: PETSc.Log.Event(n) for n in names}
        self.start()

    def _snapshot(self):
        return {n: e.getPerfInfo() for n, e in self.events.items()}

    def start(self) -> None:
        """Remember the current counts."""
        self._t0 = self._snapshot()

    def stop(self) -> dict[str, tuple[int, float]]:
        """(count, time) of each event since `start()`.

        Returns:
            By event name, the number of its calls and the seconds spent in them.
        """
        now = self._snapshot()
        return {n: (now[n]["count"] - self._t0[n]["count"], now[n]["time"] - self._t0[n]["time"])
                for n in self.events}


def petsc_work(counter: EventCounter) -> WorkCounts:
    """WorkCounts read off PETSc's event log.

    Args:
        counter: the events' counter, started at the solve's start.

    Returns:
        The counts and times of the events since `counter.start()`.
    """
    ev = counter.stop()
    work = WorkCounts()
    for attr, names in EVENTS.items():
        names = (names,) if isinstance(names, str) else names
        setattr(work, attr, sum(ev[n][0] for n in names))
    work.time["residual"] = ev["SNESFunctionEval"][1]
    work.time["tangent"] = ev["SNESJacobianEval"][1]
    work.time["factorization"] = sum(ev[n][1] for n in (*EVENTS["factorizations"], *SYMBOLIC))
    work.time["solve"] = ev["KSPSolve"][1]  # SNES factorizes in KSPSetUp, outside KSPSolve
    return work


def all_event_names() -> list[str]:
    """Every PETSc event name that `petsc_work` reads.

    Returns:
        The names, to build the `EventCounter` of a solver.
    """
    out = list(SYMBOLIC)
    for names in EVENTS.values():
        out += [names] if isinstance(names, str) else list(names)
    return out


@contextmanager
def solver_options(prefix: str, options: dict):
    """The `options` to give a dolfinx problem built under `prefix`, cleaned up after it.

    Yields `unless_set(prefix, options)`. dolfinx writes them into PETSc's global database
    and means to delete them once its solver has read them, but deletes the unprefixed
    names: they stay, and a later solver built under the same prefix took them for the
    user's (`unless_set`) and kept an earlier solver's method (a modified Newton that
    refactorized at every iteration, after a full one). Here they are deleted by their
    full names.

    Args:
        prefix: the problem's PETSc options prefix.
        options: the options by their names without the prefix.

    Yields:
        The options the command line did not set under `prefix`.
    """
    passed = unless_set(prefix, options)
    try:
        yield passed
    finally:
        db = PETSc.Options()
        for key in passed:
            db.delValue(prefix + key)


def unless_set(prefix: str, options: dict) -> dict:
    """`options` without those the command line set under `prefix`: the user's value wins.

    dolfinx's NonlinearProblem and LinearProblem write their `petsc_options` over the
    database and delete them afterwards; an option the user passed would be lost.

    Args:
        prefix: the problem's PETSc options prefix.
        options: the options by their names without the prefix.

    Returns:
        The options whose ``{prefix}name`` is not in PETSc's options database.
    """
    db = PETSc.Options()
    return {k: v for k, v in options.items() if not db.hasName(prefix + k)}


class SnesSolver:
    """Newton through SNES `newtonls` with a plain full step (no line search by default).

    `method`: ``full`` (lag 1), ``modified`` (Jacobian once per solve) or ``periodic``
    (lag = `period`). Convergence on ‖F‖ ≤ max(rtol ‖F₀‖, atol F) as in `NewtonSolver`
    (F = `force_scale`, or the largest ‖F₀‖ seen).
    """

    def __init__(self, residual: ufl.Form, u: fem.Function, bcs: Sequence[fem.DirichletBC] = (),
                 *, method: Method = "full", tangent: ufl.Form | None = None, period: int = 3,
                 linear_solver: LinearSolver = "lu", prefix: str = "snes_", rtol: float = 1e-10,
                 atol: float = 1e-10, force_scale: float | None = None, max_it: int = 50,
                 line_search: str = "basic"):
        lags = {"full": 1, "modified": -2, "periodic": period}
        if method not in lags:
            raise ValueError(f"SNES method must be one of {', '.join(lags)}, got {method!r}")
        if linear_solver not in ("lu", "cholesky"):
            raise ValueError(f"SNES linear solver must be lu or cholesky, got {linear_solver!r}")
        self.u, self.bcs, self.method = u, list(bcs), method
        opts = {
            "snes_type": "newtonls",
            "snes_linesearch_type": line_search,
            "snes_rtol": rtol,
            "snes_stol": 0.0,
            "snes_max_it": max_it,
            "snes_lag_jacobian": lags[method],
            "ksp_type": "preonly",
            "pc_type": linear_solver,
            "pc_factor_mat_solver_type": "mumps",
        }
        J = ufl.derivative(residual, u) if tangent is None else tangent
        with solver_options(prefix, opts) as passed:
            self.problem = petsc.NonlinearProblem(residual, u, bcs=self.bcs, J=J,
                                                  petsc_options_prefix=prefix,
                                                  petsc_options=passed)
        self.snes = self.problem.solver
        # the Jacobian in the matrix NewtonSolver assembles (form_matrix: DOLFINx's CSR on one
        # rank), so that the two loops are compared on the same assembly
        self._matrix = self._own_jacobian(self.problem, self.bcs)
        self.A = self._matrix.mat
        if linear_solver == "cholesky":
            self.A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
            self.A.setOption(PETSc.Mat.Option.SYMMETRY_ETERNAL, True)
        self.snes.setConvergenceHistory(reset=True)
        ConvergenceTest(rtol, atol, max_it).attach(self.snes, force_scale)  # Newton's test
        # time of each residual norm, as SolveResult.elapsed. The monitor holds the list,
        # not self: a cycle self → snes → monitor → self would leave the PETSc objects to the
        # garbage collector, which destroys them in a different order on each rank (hang).
        self._stamps: list[float] = []
        stamps = self._stamps
        self.snes.setMonitor(lambda snes, it, norm: stamps.append(time.perf_counter()))
        self.counter = EventCounter(all_event_names())
        self.motions = RigidMotions.of(u.function_space)
        self._supports_checked = False

    def _own_jacobian(self, problem, bcs) -> FormMatrix:
        """SNES's Jacobian assembled into a `FormMatrix` (DOLFINx's PETSc matrix freed)."""
        matrix = FormMatrix(problem.J)
        form, u = problem.J, problem.u

        # a closure, not a method: SNES holding self would make a cycle that the garbage
        # collector breaks in a different order on each rank
        def jacobian(snes, x, J, P):
            x.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
            petsc.assign(x, u)
            matrix.assemble(form, bcs)

        self.snes.setJacobian(jacobian, matrix.mat, matrix.mat)
        problem.A.destroy()  # no longer SNES's (NonlinearProblem's own destroy then skips it)
        return matrix

    def solve(self) -> SolveResult:
        """Solve from the current `u`, the boundary values imposed first.

        That is SNES's own way; NewtonSolver lifts them into its first correction instead.

        Returns:
            The converged result, with its iterations, residual norms and the work read off
            PETSc's event log; on a failure, the ConvergenceError's `result` instead.
        """
        t0 = time.perf_counter()
        x = self.u.x.petsc_vec
        petsc.set_bc(x, self.bcs)
        x.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        if not self._supports_checked and self.motions is not None:
            # MUMPS factorizes a singular K without a word, and SNES then converges to an
            # answer with an arbitrary rigid motion in it: the tangent at the start (an
            # unstressed state for a first solve) is checked before SNES runs
            self._matrix.assemble(self.problem.J, self.bcs)
            check_supports(self.A, self.motions, self.bcs)
            self._supports_checked = True
        self.counter.start()
        self._stamps.clear()
        self.problem.solve()
        work = petsc_work(self.counter)
        norms = [float(r) for r in self.snes.getConvergenceHistory()[0]]
        reason = self.snes.getConvergedReason()
        result = SolveResult(reason > 0, f"SNES reason {reason}",
                              self.snes.getIterationNumber(), norms, work,
                              time.perf_counter() - t0, [t - t0 for t in self._stamps])
        if reason <= 0:
            raise ConvergenceError(f"SNES did not converge (reason {reason})", result)
        return result
