"""A vertical cut collapsing under its weight in Mohr–Coulomb: ours and the peer's, Chen's limit.

dolfinx-external-operator's Mohr–Coulomb demo: the rectangle L × H = 1.2 × 1 held on its
right side and its bottom, its left side and top free (a vertical cut of height H), in
plane strain, E = 6778, ν = 0.25, c = 3.45, φ = ψ = 30°, loaded by its unit weight γ.
Chen's limit analysis (Limit Analysis of Soil Plasticity, 1990) gives γ_lim = 6.69 c/H =
23.08, an upper bound of the exact pyramid's limit.

* **ours**: `MohrCoulomb` (the exact return to the pyramid's planes, edges and apex, in UFL,
  its tangent by UFL's derivative), the hand-written full Newton (MUMPS LU).
* **peer**: dolfinx-external-operator's API (`FEMExternalOperator`,
  `replace_external_operators`, `evaluate_operands`, `evaluate_external_operators`,
  `petsc.assemble_residual_with_callback`) with its demo's model and solver: Abbo–Sloan's
  smoothed surface returned by a local Newton in JAX (benchmarks/abbo_sloan.py, written from
  the papers), SNES `vinewtonrsls` with a basic line search, MUMPS LU.

Both on the very same grid (`create_rectangle`, n × n, its diagonal), P2, degree-2 quadrature
(three points per triangle), the same stopping test ‖R‖ ≤ max(1e-10 ‖R₀‖, 1e-10 c), two runs:

1. **the peer's load path**: γ = 2 … 22.9 in 50 increments, then 22.96 and 22.99, each from
   the last converged state: time, Newton iterations, the crest's displacement u_x(0, H).
2. **the limit load**: γ stepped to 24 in 10 steps by the same driver for both
   (`solve_incrementally`: a failed step halved, down to 1e-4 of the way; an easy one grown;
   the secant predictor): the last converged γ is the limit load found (a finite element
   mechanism overestimates it). The peer's on the 25 × 25 grid only (3.5 min there: each
   failed step near the limit spends SNES's 30 iterations).

The two models differ: the smoothed surface lies inside the pyramid near its edges (on the
compression meridian its q is 2.6 % below, on the extension meridian 0.6 %) and at its
apex, so its limit load is lower; the displacements at 22.99, near collapse, differ more.

Times are of the load loops only: the forms and the JAX kernel are compiled before (JAX's
compilation, about 6 s per grid, is not counted).

    python benchmarks/slope.py [--quick] [--update-docs]   (--quick: 25 × 25, the peer's path)

Needs the benchmarks' extra (`make bench` installs it): jax, and
`pip install --no-deps dolfinx-external-operator==0.11.0`.
"""

from __future__ import annotations

import math
import time
from functools import partial

import common  # first: loads the wheel's MPI/PETSc before dolfinx

# isort: split

# Before any UFL algorithm runs: UFL's transformers size their tables by the expression
# classes defined when they are first used, and the package defines a new one.
try:
    import abbo_sloan
    import dolfinx_external_operator as peer_package
except ImportError as err:
    raise SystemExit("benchmarks/slope.py needs the bench extra: pip install -e '.[bench]' "
                     "&& pip install --no-deps dolfinx-external-operator==0.11.0") from err

# isort: split

import basix.ufl
import numpy as np
import ufl
from dolfinx import fem, mesh
from dolfinx.fem.petsc import NonlinearProblem
from dolfinx_external_operator.petsc import assemble_residual_with_callback
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.domain.probes import Probes
from fenics_nl.materials import kinematics
from fenics_nl.materials.mohr_coulomb import MohrCoulomb
from fenics_nl.solvers.loading import LoadStepError, solve_incrementally
from fenics_nl.solvers.newton import ConvergenceError, NewtonSolver
from fenics_nl.solvers.result import SolveResult, WorkCounts
from fenics_nl.solvers.snes import solver_options

L, H, E, NU, C, PHI = 1.2, 1.0, 6778.0, 0.25, 3.45, 30.0
CHEN = 6.69 * C / H
PEER_PATH = np.concatenate([np.linspace(2.0, 22.9, 50), [22.96, 22.99]])
TOL = 1e-10
LIMIT_SEARCH_TO = 24.0


class Slope:
    """The cut on the peer's n × n grid: its space, supports, weight γ and crest probe."""

    def __init__(self, n: int):
        self.n = n
        self.mesh = mesh.create_rectangle(MPI.COMM_WORLD, [[0.0, 0.0], [L, H]], [n, n])
        self.V = fem.functionspace(self.mesh, ("Lagrange", 2, (2,)))
        held = mesh.locate_entities_boundary(
            self.mesh, 1, lambda x: np.isclose(x[0], L) | np.isclose(x[1], 0.0))
        self.supports = [boundary.component(self.V, i, held) for i in (0, 1)]
        self.gamma = fem.Constant(self.mesh, 0.0)
        self.crest = Probes(self.mesh, [[0.0, H]])
        self.dofs = self.V.dofmap.index_map.size_global * 2

    def weight(self, v):
        """The weight's virtual work, on the residual's side: γ v_y (gravity along −y)."""
        return self.gamma * v[1]


class Ours:
    """fenics_nl: exact Mohr–Coulomb in UFL, full Newton."""

    name = "ours"

    def __init__(self, slope: Slope):
        self.u, v = fem.Function(slope.V), ufl.TestFunction(slope.V)
        self.law = MohrCoulomb(E, NU, c=C, phi=PHI)
        self.law.bind(slope.mesh, 2)
        dx = kinematics.quadrature_measure("dx", slope.mesh, 2)
        eps, eps_v = (kinematics.small_strain(w, "plane_strain") for w in (self.u, v))
        residual = (ufl.inner(self.law.stress(eps), eps_v) + slope.weight(v)) * dx
        self.solver = NewtonSolver(residual, self.u, slope.supports, rtol=TOL, atol=TOL,
                                   force_scale=C, max_it=30, prefix=f"slope{slope.n}_")

    def solve(self) -> SolveResult:
        return self.solver.solve()

    def commit(self) -> None:
        self.law.commit(self.u, "plane_strain")


def mandel(w):
    """ε(w) as the peer's vectors: (xx, yy, zz, √2 xy), plane strain."""
    g = ufl.grad(w)
    return ufl.as_vector([g[0, 0], g[1, 1], 0.0, (g[0, 1] + g[1, 0]) / math.sqrt(2)])


class Peer:
    """dolfinx-external-operator: the stress an external operator of the strain increment
    ε(u) − ε(u_n), evaluated by the JAX return at every residual (SNES's callback)."""

    name = "peer"

    def __init__(self, slope: Slope, snes_type: str = "vinewtonrsls"):
        m, V = slope.mesh, slope.V
        S = fem.functionspace(m, basix.ufl.quadrature_element(
            m.topology.cell_name(), degree=2, value_shape=(4,)))
        self.u, self.u_n = fem.Function(V), fem.Function(V)
        self.sigma_n = fem.Function(S)
        kernel = abbo_sloan.return_map(E, NU, C, PHI, PHI)
        self.kernel_time = 0.0  # seconds in the JAX return map

        def evaluate(derivatives):
            if derivatives != (1,):
                raise NotImplementedError(derivatives)

            def tangent_and_stress(deps):
                t0 = time.perf_counter()
                s, t, _ = kernel(deps.reshape(-1, 4), self.sigma_n.x.array.reshape(-1, 4))
                s, t = np.asarray(s).reshape(-1), np.asarray(t).reshape(-1)  # computed now
                self.kernel_time += time.perf_counter() - t0
                return t, s

            return tangent_and_stress

        sigma = peer_package.FEMExternalOperator(mandel(self.u) - mandel(self.u_n),
                                                 function_space=S)
        sigma.external_function = evaluate
        v = ufl.TestFunction(V)
        dx = ufl.Measure("dx", domain=m, metadata={"quadrature_degree": 2})
        F = (ufl.inner(sigma, mandel(v)) + slope.weight(v)) * dx
        J = ufl.derivative(F, self.u, ufl.TrialFunction(V))
        F_hat, self.F_ops = peer_package.replace_external_operators(F)
        J_hat, J_ops = peer_package.replace_external_operators(J)

        def update():
            (_, s_new), = peer_package.evaluate_external_operators(
                J_ops, peer_package.evaluate_operands(self.F_ops))
            self.F_ops[0].ref_coefficient.x.array[:] = s_new

        update()  # JAX compiles its kernel for this grid's points now, not in the loop
        self.kernel_time = 0.0
        options = {"snes_type": snes_type, "snes_linesearch_type": "basic",
                   "snes_rtol": TOL, "snes_atol": TOL * C, "snes_stol": 0.0,
                   "snes_max_it": 30, "ksp_type": "preonly", "pc_type": "lu",
                   "pc_factor_mat_solver_type": "mumps"}
        prefix = f"slope_peer{slope.n}_"
        with solver_options(prefix, options) as passed:
            self.problem = NonlinearProblem(F_hat, self.u, J=J_hat, bcs=slope.supports,
                                            petsc_options_prefix=prefix, petsc_options=passed)
        self.problem.solver.setFunction(partial(
            assemble_residual_with_callback, self.problem.u, self.problem.F, self.problem.J,
            slope.supports, update, []), self.problem.b)

    def solve(self) -> SolveResult:
        self.problem.solve()
        snes = self.problem.solver
        result = SolveResult(snes.getConvergedReason() > 0, str(snes.getConvergedReason()),
                             snes.getIterationNumber(), [], WorkCounts())
        if not result.converged:  # the driver's failure: the step is cut
            raise ConvergenceError(f"SNES: reason {result.reason}", result)
        return result

    def commit(self) -> None:
        self.u_n.x.array[:] = self.u.x.array
        self.sigma_n.x.array[:] = self.F_ops[0].ref_coefficient.x.array


def along_the_peers_path(slope: Slope, code) -> dict:
    """The peer's 52 increments, each from the last converged state."""
    iterations = []
    t0 = time.perf_counter()
    for g in PEER_PATH:
        slope.gamma.value = g
        iterations.append(code.solve().iterations)
        code.commit()
    seconds = MPI.COMM_WORLD.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    return {"time_s": seconds, "newton_iterations": sum(iterations),
            "crest_ux": slope.crest.continuous(code.u)[0][0],
            "return_map_time_s": getattr(code, "kernel_time", None)}


def limit_load(slope: Slope, code) -> dict:
    """γ stepped to collapse by our driver: the last converged γ."""
    reached, iterations = [0.0], []

    def load(t):
        slope.gamma.value = LIMIT_SEARCH_TO * t

    def record(t, result):
        reached.append(LIMIT_SEARCH_TO * t)
        iterations.append(result.iterations)

    t0 = time.perf_counter()
    try:
        solve_incrementally(code, load, 10, min_step=1e-4, commit=code.commit, on_step=record)
        completed = True
    except LoadStepError:  # the mechanism: no equilibrium beyond
        completed = False
    seconds = MPI.COMM_WORLD.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    return {"limit_load": reached[-1], "error_against_chen": reached[-1] / CHEN - 1,
            "steps": len(iterations), "converged_step_iterations": sum(iterations),
            "completed": completed, "limit_time_s": seconds}


def compare(n: int, peer_limit: bool) -> dict:
    """Both codes on the n × n grid: the peer's path, then the limit search (fresh states;
    the peer's only if `peer_limit`: 206 s on 25 × 25, its failed steps' 30 iterations)."""
    slope = Slope(n)
    row = {"n": n, "dofs": slope.dofs}
    for run in (along_the_peers_path, limit_load):
        for code in (Ours, Peer):
            if run is limit_load and code is Peer and not peer_limit:
                continue
            row.setdefault(code.name, {}).update(run(slope, code(slope)))
    return row


def table(out: dict) -> str:
    lines = ["A vertical cut (1.2 × 1, E = 6778, ν = 0.25, c = 3.45, φ = ψ = 30°) under its "
             "unit weight γ, P2 on dolfinx-external-operator's grid and quadrature, MUMPS LU. "
             "Ours: exact Mohr–Coulomb (planes, edges, apex) in UFL, full Newton; the peer: "
             "Abbo–Sloan's smoothing (θ_T = 26°, a = 0.26 c cotφ) in JAX behind its "
             "external operator, SNES vinewtonrsls. The peer's path: its 52 increments to "
             "γ = 22.99; the limit: the same driver for both, γ stepped to 24, a failed step "
             f"halved; Chen's upper bound {CHEN:.2f}. `python benchmarks/slope.py`.", "",
             "The peer's path:", "",
             "| grid | unknowns | code | Newton its | time [s] | / ours | "
             "of which the return map [s] | u_x(0, H) at 22.99 |",
             "|---|---|---|---|---|---|---|---|"]
    for r in out["rows"]:
        for name in ("ours", "peer"):
            c, kernel = r[name], r[name]["return_map_time_s"]
            lines.append(
                f"| {r['n']} × {r['n']} | {r['dofs']} | {name} | {c['newton_iterations']} | "
                f"{c['time_s']:.2f} | {c['time_s'] / r['ours']['time_s']:.1f} | "
                f"{'in the forms' if kernel is None else f'{kernel:.2f}'} | "
                f"{c['crest_ux']:.3e} |")
    lines += ["", "The limit load (the peer's on 25 × 25 only):", "",
              "| grid | code | limit γ | against Chen | steps | time [s] |",
              "|---|---|---|---|---|---|"]
    lines += [f"| {r['n']} × {r['n']} | {name} | {r[name]['limit_load']:.3f} | "
              f"{100 * r[name]['error_against_chen']:+.2f} % | {r[name]['steps']} | "
              f"{r[name]['limit_time_s']:.1f} |"
              for r in out["rows"] for name in ("ours", "peer") if "limit_load" in r[name]]
    return "\n".join(lines)


if __name__ == "__main__":
    args = common.options(__doc__, "the 25 × 25 grid only, nothing written")
    out = {"machine": common.machine(MPI.COMM_WORLD.size),
           "rows": [compare(25, peer_limit=not args.quick)]
           + ([] if args.quick else [compare(50, peer_limit=False)])}
    common.publish("slope", out, table, args)
