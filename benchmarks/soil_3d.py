"""A square footing on a 3D soil block: Mohr–Coulomb's exact return against Drucker–Prager's.

A rigid smooth square footing (half-width 0.5, a quarter of it by symmetry) pushed 0.04 into
a weightless block (a quarter 2 × 2 × 1.5: c = 1, φ = 20°, ψ = φ, E = 1e4, ν = 0.3), rollers
on the symmetry planes and the far sides, the bottom held; P2 tetrahedra (`create_box`, n
cells a unit length, n even: the footing's edge on nodes), degree-4 quadrature, the
hand-written full Newton on MUMPS LU, 10 equal steps (the secant predictor, a failed step
halved).

* **Mohr–Coulomb**: `MohrCoulomb` in 3D: `principal_3d` (the Lode angle's closed form, the
  pair from the simple stress's projection), the multi-surface return, its UFL derivative.
* **Drucker–Prager**: `DruckerPrager` with the cone through Mohr–Coulomb's compression
  meridian (`fit = "compression"`), a closed-form radial return: the cheapest consistent
  soil law, and a different surface (outside the pyramid but on that meridian), so a
  different force.

What is compared is the cost of the exact pyramid in 3D: Newton iterations, time per
iteration and in all, against one linear solve of the same mesh (assembly, factorization,
solve). Times are of the load loops only: the forms are compiled before.

    python benchmarks/soil_3d.py [--quick] [--update-docs]   (--quick: n = 2, nothing written)

A cost benchmark: the block is too small and the meshes too coarse for the bearing capacity
itself (its force is that of this mesh and this push).
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
from fenics_nl.materials.drucker_prager import DruckerPrager
from fenics_nl.materials.mohr_coulomb import MohrCoulomb
from fenics_nl.solvers.loading import solve_incrementally
from fenics_nl.solvers.newton import NewtonSolver

PUSH, STEPS = 0.04, 10
LAWS = {"Mohr–Coulomb": lambda: MohrCoulomb(1e4, 0.3, c=1.0, phi=20.0),
        "Drucker–Prager": lambda: DruckerPrager(1e4, 0.3, c=1.0, phi=20.0)}


def footing(n: int, name: str) -> dict:
    """The footing on the block at n cells a unit length with the law `name`."""
    m = mesh.create_box(MPI.COMM_WORLD, [[0.0, 0.0, -1.5], [2.0, 2.0, 0.0]],
                        [2 * n, 2 * n, 3 * n // 2], cell_type=mesh.CellType.tetrahedron)
    V = fem.functionspace(m, ("Lagrange", 2, (3,)))
    u, v = fem.Function(V), ufl.TestFunction(V)
    law = LAWS[name]()
    law.bind(m, 4)
    dx = kinematics.quadrature_measure("dx", m, 4)
    residual = ufl.inner(law.stress(kinematics.small_strain(u)), kinematics.small_strain(v)) * dx

    def side(where):
        return mesh.locate_entities_boundary(m, 2, where)

    under = side(lambda x: np.isclose(x[2], 0.0) & (x[0] <= 0.5 + 1e-12) & (x[1] <= 0.5 + 1e-12))
    bottom = side(lambda x: np.isclose(x[2], -1.5))
    push = boundary.component(V, 2, under)
    bcs = [push, *(boundary.component(V, i, bottom) for i in range(3))]
    bcs += [boundary.component(V, i, side(lambda x, i=i: np.isclose(x[i], 0.0)
                                          | np.isclose(x[i], 2.0))) for i in range(2)]
    solver = NewtonSolver(residual, u, bcs, rtol=1e-10, atol=1e-10, force_scale=1.0,
                          max_it=40, prefix=f"soil3d{n}_")
    solver.solve()  # (at u = 0: the forms compiled, nothing pushed)

    def load(t):
        push.g.x.array[:] = -PUSH * t

    forces = []
    MPI.COMM_WORLD.Barrier()
    t0 = time.perf_counter()
    path = solve_incrementally(solver, load, STEPS, max_step=1.0 / STEPS,
                               commit=lambda: law.commit(u),
                               on_step=lambda t, r: forces.append(-4 * boundary.reactions(
                                   residual, u, {"under": under})["under"][2]))
    seconds = MPI.COMM_WORLD.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    # one linear solve of the same mesh: the tangent at the end state assembled, factorized
    one = common.timed_linear_solve(fem.form(ufl.derivative(residual, u)), fem.form(residual),
                                    bcs, "lu", f"soil3d_lu{n}_")
    return {"n": n, "dofs": V.dofmap.index_map.size_global * 3,
            "newton_iterations": path.iterations, "failed_steps": path.failures,
            "steps": len(forces), "time_s": seconds, "force": forces[-1],
            "linear_solve_s": one}


def table(out: dict) -> str:
    lines = [f"A rigid smooth square footing (half-width 0.5) pushed {PUSH} into a weightless "
             "block (a quarter 2 × 2 × 1.5; c = 1, φ = ψ = 20°, E = 1e4, ν = 0.3), P2 "
             f"tetrahedra, degree-4 quadrature, full Newton on MUMPS LU, {STEPS} steps. "
             "Drucker–Prager's cone through Mohr–Coulomb's compression meridian. "
             "`python benchmarks/soil_3d.py`.", "",
             "| cells a unit | unknowns | law | Newton its | time [s] | per iteration [s] | "
             "/ one linear solve | MC / DP per iteration | footing force |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in out["rows"]:
        dp = r["Drucker–Prager"]
        for name in LAWS:
            c = r[name]
            per = c["time_s"] / c["newton_iterations"]
            ratio = per / (dp["time_s"] / dp["newton_iterations"])
            lines.append(f"| {r['n']} | {c['dofs']} | {name} | {c['newton_iterations']} | "
                         f"{c['time_s']:.1f} | {per:.2f} | {per / c['linear_solve_s']:.1f} | "
                         f"{ratio:.2f} | {c['force']:.4f} |")
    return "\n".join(lines)


if __name__ == "__main__":
    args = common.options(__doc__, "n = 2 only, nothing written")
    sizes = (2,) if args.quick else (2, 4)
    out = {"machine": common.machine(MPI.COMM_WORLD.size),
           "rows": [{"n": n, **{name: footing(n, name) for name in LAWS}} for n in sizes]}
    common.publish("soil_3d", out, table, args)
