"""Other ways to solve the punch, to compare with the active-set method on the same mesh.

* SNES VI (`vinewtonrsls`): the bound u_n ≤ γ on the S_C normal dofs, a reduced-space
  active-set Newton method inside PETSc.
* Penalty: R(u; v) + k ∫_{S_C} ⟨u_n − γ⟩₊ v_n ds = 0, solved by full Newton; the
  pressure is k times the penetration, so the constraint only holds as k → ∞.
"""

from __future__ import annotations

import time

import numpy as np
import ufl
from dolfinx import fem, mesh
from dolfinx.fem import petsc
from petsc4py import PETSc

from fenics_nl.parallel import global_max
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.solvers.snes import (
    EventCounter,
    all_event_names,
    petsc_work,
    scale_absolute_tolerance,
    unless_set,
)


def _surface_measure(punch):
    fdim = punch.mesh.topology.dim - 1
    f = np.sort(punch.block.contact_facets)
    tags = mesh.meshtags(punch.mesh, fdim, f, np.ones(len(f), dtype=np.int32))
    return ufl.Measure("ds", domain=punch.mesh, subdomain_data=tags,
                       metadata={"quadrature_degree": 4})(1)


def solve_snes_vi(punch, delta: float, prefix: str = "vi_") -> dict:
    """The punch at indentation δ by SNES vinewtonrsls with upper bounds u_n ≤ γ."""
    u = punch.u
    u.x.array[:] = 0.0
    c = punch.contact
    c.set_gap(punch.gap(delta))
    opts = {"snes_type": "vinewtonrsls", "snes_rtol": 1e-10, "snes_stol": 0.0,
            "snes_max_it": 100, "ksp_type": "preonly", "pc_type": "lu",
            "pc_factor_mat_solver_type": "mumps"}
    problem = petsc.NonlinearProblem(punch.residual, u, bcs=punch.bcs,
                                     petsc_options_prefix=prefix,
                                     petsc_options=unless_set(prefix, opts))
    lower, upper = problem.x.duplicate(), problem.x.duplicate()
    lower.set(PETSc.NINFINITY)
    upper.set(PETSc.INFINITY)
    with upper.localForm() as up:  # u_axis ≤ sign·γ, i.e. u_n ≤ γ (sign = +1 here)
        up.array[c.surface.dofs_V] = c.surface.sign * c.surface.gamma
    problem.solver.setVariableBounds(lower, upper)
    scale_absolute_tolerance(problem.solver, 1e-12)
    counter = EventCounter(all_event_names())
    t0 = time.perf_counter()
    problem.solve()
    wall = time.perf_counter() - t0
    reason = problem.solver.getConvergedReason()
    work = petsc_work(counter)
    force = c.total_force() * punch.block.symmetry_factor
    return {"force": force, "wall_time_s": wall, "iterations": problem.solver.getIterationNumber(),
            "factorizations": work.factorizations, "converged": reason > 0,
            "max_penetration": _max_penetration(punch)}


def solve_penalty(punch, delta: float, stiffness: float, prefix: str = "pen_") -> dict:
    """The punch at indentation δ with a penalty stiffness k [Pa/m] on the penetration."""
    u, c = punch.u, punch.contact
    u.x.array[:] = 0.0
    c.set_gap(punch.gap(delta))
    x = ufl.SpatialCoordinate(punch.mesh)
    r2 = x[0] ** 2 + (x[1] ** 2 if punch.model == "3d" else 0)
    gamma = r2 / (2 * punch.R) - delta
    if punch.gap_shape != "parabola":
        raise ValueError("the penalty peer is written for the parabolic gap")
    v = ufl.TestFunction(u.function_space)
    k = fem.Constant(punch.mesh, float(stiffness))
    pen = ufl.max_value(c.surface.sign * u[c.surface.axis] - gamma, 0.0)
    ds = _surface_measure(punch)
    w = punch.block.weight
    R = punch.residual + k * pen * c.surface.sign * v[c.surface.axis] * w * ds
    solver = NewtonSolver(R, u, punch.bcs, method="full", line_search=True, prefix=prefix,
                          rtol=1e-10, atol=1e-12, max_it=100)
    t0 = time.perf_counter()
    res = solver.solve()
    wall = time.perf_counter() - t0
    force = fem.assemble_scalar(fem.form(k * pen * w * ds))
    force = punch.mesh.comm.allreduce(force) * punch.block.symmetry_factor
    return {"force": force, "wall_time_s": wall, "iterations": res.iterations,
            "factorizations": res.work.factorizations, "converged": res.converged,
            "max_penetration": _max_penetration(punch)}


def _max_penetration(punch) -> float:
    return global_max(punch.mesh.comm, punch.contact.normal_gap())
