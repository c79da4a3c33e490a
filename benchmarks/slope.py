"""A vertical cut collapsing under its weight in Mohr–Coulomb: the limit load against Chen's.

dolfinx-external-operator's Mohr–Coulomb demo: the rectangle L × H = 1.2 × 1 held on its
right side and its bottom, its left side and top free (a vertical cut of height H), in
plane strain, E = 6778, ν = 0.25, c = 3.45, φ = ψ = 30°, loaded by its unit weight γ.
Chen's limit analysis (Limit Analysis of Soil Plasticity, 1990) gives γ_lim = 6.69 c/H =
23.08; the peer loads to 22.99 with Abbo–Sloan's smoothed surface (not the exact
pyramid).

Ours: `MohrCoulomb` (the exact return to the planes, edges and apex, in UFL), P2 on the
peer's grid (`create_rectangle`, n × n, its diagonal), its quadrature (degree 2), full
Newton (MUMPS LU), γ stepped to 24 in 10 steps cut in half when one fails, down to 1e-4 of
the way: the last converged γ is the limit load found (a finite element mechanism
overestimates it, as an upper bound). The peer's run beside ours, on the same grid and
load path, is not written yet (its return is JAX code of the package's demo, to be written
from the package's API as `benchmarks/plasticity_peer.py` did for J2).

    python benchmarks/slope.py [--quick] [--update-docs]
"""

from __future__ import annotations

import time

import common  # first: loads the wheel's MPI/PETSc before dolfinx

# isort: split

import numpy as np
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.materials import kinematics
from fenics_nl.materials.mohr_coulomb import MohrCoulomb
from fenics_nl.solvers.loading import LoadStepError, solve_incrementally
from fenics_nl.solvers.newton import NewtonSolver

CHEN = 6.69 * 3.45  # γ_lim H / c = 6.69


def limit_load(n: int) -> dict:
    """The slope on the peer's n × n grid: the largest γ converged, the work, the time."""
    m = mesh.create_rectangle(MPI.COMM_WORLD, [[0.0, 0.0], [1.2, 1.0]], [n, n])
    V = fem.functionspace(m, ("Lagrange", 2, (2,)))
    u, v = fem.Function(V), ufl.TestFunction(V)
    law = MohrCoulomb(6778.0, 0.25, c=3.45, phi=30.0)
    law.bind(m, 2)
    dx = kinematics.quadrature_measure("dx", m, 2)
    gamma = fem.Constant(m, 0.0)
    eps, eps_v = (kinematics.small_strain(w, "plane_strain") for w in (u, v))
    residual = ufl.inner(law.stress(eps), eps_v) * dx + gamma * v[1] * dx
    held = mesh.locate_entities_boundary(
        m, 1, lambda x: np.isclose(x[0], 1.2) | np.isclose(x[1], 0.0))
    solver = NewtonSolver(residual, u, [boundary.component(V, i, held) for i in (0, 1)],
                          rtol=1e-10, atol=1e-10, force_scale=3.45, max_it=30,
                          prefix=f"slope{n}_")
    reached, iterations = [0.0], []

    def load(t):
        gamma.value = 24.0 * t

    def record(t, result):
        reached.append(24.0 * t)
        iterations.append(result.iterations)

    t0 = time.perf_counter()
    try:
        path = solve_incrementally(solver, load, 10, min_step=1e-4, on_step=record,
                                   commit=lambda: law.commit(u, "plane_strain"))
        cuts = path.failures
    except LoadStepError:  # the mechanism: no equilibrium beyond
        cuts = None
    seconds = MPI.COMM_WORLD.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    return {"n": n, "dofs": V.dofmap.index_map.size_global * 2, "limit_load": reached[-1],
            "error_against_chen": reached[-1] / CHEN - 1, "steps": len(iterations),
            "newton_iterations": sum(iterations), "completed": cuts is not None,
            "time_s": seconds}


def table(out: dict) -> str:
    rows = out["rows"]
    lines = ["A vertical cut (1.2 × 1, E = 6778, ν = 0.25, c = 3.45, φ = ψ = 30°) under its "
             "unit weight γ, stepped to collapse: the largest γ converged against Chen's "
             f"limit analysis {CHEN:.2f}; P2 on dolfinx-external-operator's grid and "
             "quadrature, exact Mohr–Coulomb (its planes, edges and apex), full Newton.", "",
             "| grid | unknowns | γ_lim | against Chen | steps | Newton its | time [s] |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['n']} × {r['n']} | {r['dofs']} | {r['limit_load']:.3f} | "
                     f"{100 * r['error_against_chen']:+.2f} % | {r['steps']} | "
                     f"{r['newton_iterations']} | {r['time_s']:.2f} |")
    if len(rows) > 1:
        a, b = rows[-2]["limit_load"], rows[-1]["limit_load"]
        lines += ["", f"Richardson (first order, h halved): {2 * b - a:.3f}, "
                      f"{100 * ((2 * b - a) / CHEN - 1):+.2f} % against Chen's upper bound. "
                      "The peer (22.99 with Abbo–Sloan's smoothing, its own load path) run "
                      "beside ours is not written yet."]
    return "\n".join(lines)


if __name__ == "__main__":
    args = common.options(__doc__, "the 25 × 25 grid only, nothing written")
    out = {"machine": common.machine(MPI.COMM_WORLD.size),
           "rows": [limit_load(n) for n in ((25,) if args.quick else (25, 50))]}
    common.publish("slope", out, table, args)
