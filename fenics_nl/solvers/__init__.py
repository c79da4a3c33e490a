"""The solver core: the Newton family on PETSc KSP, its SNES cross-check, the drivers.

`newton`: `NewtonSolver` (full, modified, periodic, BFGS) and its public step interface
(`start_solve`, `residual`, `update_tangent`, `solve_linear`, `add_secant_pair`), on which
its own `solve` and arc-length are written; `snes`: `SnesSolver`, the same problem through
PETSc SNES; `loading`: `solve_incrementally`, load steps with cuts and a secant predictor;
`arclength`: Crisfield's continuation through limit points, with stability checks and
branch switching (their checkpoints: `io.restart`); `supports`: the free-body check;
`buckling`: SLEPc eigenproblems (critical loads, the tangent's inertia); `scalar`: the
course's scalar Newton, modified Newton and secant, for their orders; `sensitivity`: the
derivatives of a path-dependent solution with respect to material parameters (direct
differentiation); `least_squares`: Levenberg–Marquardt with bounds and its statistics.

    from fenics_nl.solvers import ArcLength, NewtonSolver, solve_incrementally
"""

from fenics_nl.solvers.arclength import ArcLength, ArcState, ContinuationError
from fenics_nl.solvers.loading import LoadStepError, solve_incrementally
from fenics_nl.solvers.newton import ConvergenceError, LinearSolveError, NewtonSolver
from fenics_nl.solvers.result import SolveResult, WorkCounts
from fenics_nl.solvers.snes import SnesSolver
from fenics_nl.solvers.supports import check_supports

__all__ = ["ArcLength", "ArcState", "ContinuationError", "ConvergenceError",
           "LinearSolveError", "LoadStepError", "NewtonSolver", "SnesSolver", "SolveResult",
           "WorkCounts", "check_supports", "solve_incrementally"]
