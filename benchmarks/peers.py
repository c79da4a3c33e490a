"""Other ways to solve the punch, to compare with the active-set method on the same mesh.

* SNES VI (`vinewtonrsls`): the bound u_n ≤ γ on the S_C normal dofs, a reduced-space
  active-set Newton method inside PETSc.
* Penalty: R(u; v) + k ∫_{S_C} ⟨u_n − γ⟩₊ v_n ds = 0, solved by full Newton; the
  pressure is k times the penetration, so the constraint only holds as k → ∞.
* Friction penalty: the same, with the tangential traction an elastic spring of stiffness
  k up to the Coulomb bound f p_n (`solve_friction_penalty`).
"""

from __future__ import annotations

import time

import numpy as np
import ufl
from dolfinx import fem, mesh
from dolfinx.fem import petsc
from petsc4py import PETSc

from fenics_nl.contact.surface import nodal_quadrature
from fenics_nl.parallel import global_max
from fenics_nl.solvers.convergence import ConvergenceTest
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.solvers.snes import (
    EventCounter,
    all_event_names,
    petsc_work,
    solver_options,
)

__all__ = ["solve_friction_penalty", "solve_penalty", "solve_snes_vi"]


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
    with solver_options(prefix, opts) as passed:
        problem = petsc.NonlinearProblem(punch.residual, u, bcs=punch.bcs,
                                         petsc_options_prefix=prefix, petsc_options=passed)
    lower, upper = problem.x.duplicate(), problem.x.duplicate()
    lower.set(PETSc.NINFINITY)
    upper.set(PETSc.INFINITY)
    with upper.localForm() as up:  # u_axis ≤ sign·γ, i.e. u_n ≤ γ (sign = +1 here)
        up.array[c.surface.dofs_V] = c.surface.sign * c.surface.gamma
    problem.solver.setVariableBounds(lower, upper)
    ConvergenceTest(1e-10, 1e-12, 100).attach(problem.solver)
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


def solve_friction_penalty(punch, delta: float, shift: float, stiffness: float,
                           friction: float, prefix: str = "fpen_") -> dict:
    """Cattaneo–Mindlin's two steps, regularised by one penalty stiffness k.

    Press by δ, then move the punch by `shift` along x; k in force/length³. Normal:
    p_n = k ⟨u_n − γ⟩₊. Tangential, from the state after pressing: the elastic-plastic
    law of the slip Δg = Δu_t − (shift, 0): the trial t* = −k Δg returned to the disc
    |t| ≤ f p_n (in 2D, the clip of one component): stick is an elastic spring, slip the
    Coulomb bound. Both conditions hold only as k → ∞, at the nodes (a nodal rule on S_C:
    P1 in 3D), so the limit is the active set's discrete problem. The parabolic gap.
    """
    if punch.model not in ("plane_strain", "3d") or punch.gap_shape != "parabola":
        raise ValueError("the friction penalty peer is written for the plane-strain "
                         "cylinder and the 3D sphere, with the parabolic gap")
    u, c = punch.u, punch.contact
    u.x.array[:] = 0.0
    c.set_gap(punch.gap(delta))
    msh, s, axis = punch.mesh, c.surface.sign, c.surface.axis
    x = ufl.SpatialCoordinate(msh)
    axes = c.axes
    gamma = sum(x[i] ** 2 for i in axes) / (2 * punch.R) - delta
    pressed = fem.Function(u.function_space)  # the state the slip is counted from
    d = fem.Constant(msh, 0.0)
    k = fem.Constant(msh, float(stiffness))
    p_n = k * ufl.max_value(s * u[axis] - gamma, 0.0)
    bound = friction * p_n
    slip = ufl.as_vector([u[i] - pressed[i] - (d if i == 0 else 0.0) for i in axes])
    if len(axes) == 1:
        t = ufl.as_vector([-ufl.max_value(ufl.min_value(k * slip[0], bound), -bound)])
    else:  # the return to the disc; the floor under the root keeps its derivative finite
        trial = k * slip
        size = ufl.sqrt(ufl.dot(trial, trial) + (1e-30 * stiffness) ** 2)
        t = -trial * bound / ufl.max_value(size, bound)
    v = punch.residual.arguments()[0]
    # the nodal rule: the penalty acts at the nodes, as the active set's conditions do, so
    # its limit k → ∞ is the same discrete problem (and t at a node is its nodal traction)
    fdim = msh.topology.dim - 1
    f_tags = np.sort(punch.block.contact_facets)
    tags = mesh.meshtags(msh, fdim, f_tags, np.ones(len(f_tags), dtype=np.int32))
    rule = nodal_quadrature(c.surface.Vn.element.basix_element.degree, fdim)
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags, metadata=rule)(1)
    v_t = ufl.as_vector([v[i] for i in axes])
    R = punch.residual + (p_n * s * v[axis] - ufl.dot(t, v_t)) * ds
    solver = NewtonSolver(R, u, punch.bcs, method="full", line_search=True, prefix=prefix,
                          rtol=1e-10, atol=1e-12, max_it=200)
    t0 = time.perf_counter()
    iterations, factorizations = 0, 0
    for step_shift in (0.0, shift):
        pressed.x.array[:] = u.x.array
        d.value = step_shift
        res = solver.solve()
        iterations += res.iterations
        factorizations += res.work.factorizations
    wall = time.perf_counter() - t0
    comm, factor = msh.comm, punch.block.symmetry_factor
    force = comm.allreduce(fem.assemble_scalar(fem.form(p_n * ds))) * factor
    tangential = comm.allreduce(fem.assemble_scalar(fem.form(t[0] * ds))) * factor
    S = c.surface
    traction = fem.Function(S.Vn)
    traction.interpolate(fem.Expression(t[0], S.Vn.element.interpolation_points))
    return {"force": force, "tangential_force": tangential, "wall_time_s": wall,
            "iterations": iterations, "factorizations": factorizations,
            "x": S.x[S.owned, 0], "traction": traction.x.array[S.dofs_n][S.owned],
            "max_penetration": _max_penetration(punch)}
