"""The buckling beam of `demos/buckling_beam.py` in one object, for the tests and benchmarks.

(The demo writes the same steps out: the strip and its tags, the space, the clamp, the
residual, the linear buckling analysis, the load path with its stability check and branch
switching, the arc-length path.) A slender cantilever, clamped at x = 0, length L, height h
(unit width), finite strain, under a dead end traction (−P, ε P)/h: the axial load P and a
small lateral load, the imperfection that picks the buckled branch. `theory.elastica` has
the closed forms it is checked against. Used by tests/test_arclength.py and
benchmarks/continuation.py, buckling.py and mixed.py.
"""

from __future__ import annotations

import math

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem.petsc import LinearProblem
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.domain.strips import CLAMPED, END, cantilever_strip
from fenics_nl.errors import SolveError
from fenics_nl.io import output
from fenics_nl.materials import kinematics
from fenics_nl.materials.laws import LinearElastic, NeoHookean, StVenantKirchhoff
from fenics_nl.materials.mixed import cauchy_stress, unknowns
from fenics_nl.solvers.arclength import ArcLength, ContinuationPath
from fenics_nl.solvers.buckling import critical_loads, geometric_stiffness, lowest_tangent_mode
from fenics_nl.solvers.loading import LoadPath, solve_incrementally
from fenics_nl.solvers.newton import ConvergenceError, NewtonSolver
from fenics_nl.solvers.snes import solver_options
from fenics_nl.theory import elastica

__all__ = ["MATERIALS", "BucklingBeam"]

MATERIALS = {"svk": StVenantKirchhoff, "neo-hookean": NeoHookean}
# A load path that ends unstable is redone with 4x the steps, up to this many: small steps
# through P_cr let the imperfection pick the buckled branch.
MAX_PATH_STEPS = 256


class BucklingBeam:
    """Length `length`, height `thickness`, material E, ν (`material`: svk | neo-hookean).

    `plane` stress | strain; Q`degree` displacements on the strip of 2·2^`refine` elements
    through the height (`domain.strips`), or with `mixed` (plane strain) the Q2–Q1
    Taylor–Hood pair (u, p); `imperfection`: the lateral end load ε as a fraction of P.
    `u` is what the solvers update (u, or (u, p) if mixed), `fields` the unknown it is
    (`materials.mixed.unknowns`).
    """

    def __init__(self, length: float, thickness: float, E: float, nu: float, *,
                 material: str = "svk", plane: str = "stress", refine: int = 0,
                 imperfection: float = 1e-4, degree: int = 2, mixed: bool = False,
                 comm: MPI.Comm = MPI.COMM_WORLD):
        if material not in MATERIALS:
            raise ValueError(f"material must be one of {', '.join(MATERIALS)}, got "
                             f"{material!r}")
        if plane not in ("stress", "strain"):
            raise ValueError(f"plane must be stress or strain, got {plane!r}")
        if mixed and plane == "stress":
            raise ValueError("mixed needs plane strain (plane stress has no volumetric "
                             "constraint: its out-of-plane strain takes the volume change)")
        if thickness > length / 5:
            raise ValueError(f"the beam must be slender: thickness <= length/5, got L/h = "
                             f"{length / thickness:.3g}")
        self.L, self.h, self.imperfection = length, thickness, imperfection
        self.model = "plane_stress" if plane == "stress" else "plane_strain"
        self.material = MATERIALS[material](E, nu)
        self.mesh, tags = cantilever_strip(comm, length, thickness, refine)
        self.fields = f = unknowns(self.mesh, degree, mixed)
        self.V, self.u = f.V, f.w
        self.clamp = tags.find(CLAMPED)
        self.bcs = [boundary.fixed(self.V, self.clamp)]
        self.ds_end = ufl.Measure("ds", domain=self.mesh, subdomain_data=tags)(END)
        self.dx = kinematics.quadrature_measure("dx", self.mesh, 4)
        self.traction = fem.Constant(self.mesh, np.zeros(2))
        self.residual = (f.internal_work(self.material, self.model) * self.dx
                         - ufl.dot(self.traction, f.v) * self.ds_end)
        trial = ufl.TrialFunction(self.u.function_space)
        self._du = ufl.split(trial)[0] if f.mixed else trial
        # ∫ du · v: the metric of the stability eigenproblem (zero on the pressure)
        self.mass = ufl.inner(self._du, f.v) * self.dx
        u = f.u
        F = kinematics.deformation_gradient(u, "plane_stress")  # the in-plane 2x2 F
        self._tip_forms = [fem.form(x * self.ds_end) for x in
                           (u[0] / thickness, u[1] / thickness, F[0, 1], F[1, 1])]
        self.E_bending = E if self.model == "plane_stress" else E / (1 - nu**2)
        self.P_euler = elastica.euler_load(self.E_bending, thickness**3 / 12, length)

    @property
    def dofs(self) -> int:
        """Global number of scalar unknowns (with the pressure's, if mixed)."""
        return output.dofs(self.u.function_space)

    def set_load(self, P: float) -> None:
        """Dead end load: axial compression P and the lateral imperfection ε P."""
        self.traction.value[:] = [-P / self.h, self.imperfection * P / self.h]

    def tip(self) -> dict[str, float]:
        """Mean end-face axial and lateral displacement, and the end-section rotation α."""
        comm = self.mesh.comm
        ux, uy, t0, t1 = (comm.allreduce(fem.assemble_scalar(f)) for f in self._tip_forms)
        return {"axial": ux, "lateral": uy, "rotation": math.atan2(-t0, t1)}

    def critical_loads(self, n: int = 3) -> tuple[list[float], list[fem.Function]]:
        """SLEPc: the first n critical loads and modes around the undeformed state.

        K is Hooke's tangent (mixed, if mixed), K_G the geometric stiffness of the stress of
        a unit compression (on the displacement part).
        """
        f, W = self.fields, self.u.function_space
        hooke = LinearElastic(self.material.E, self.material.nu)
        K = ufl.derivative(f.internal_work(hooke, self.model) * self.dx, f.w)
        w0 = fem.Function(W)
        unit = fem.Constant(self.mesh, np.array([-1.0 / self.h, 0.0]))
        direct = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
        with solver_options("beam_prestress_", direct) as passed:
            LinearProblem(K, ufl.dot(unit, f.v) * self.ds_end, u=w0, bcs=self.bcs,
                          petsc_options_prefix="beam_prestress_",
                          petsc_options=passed).solve()
        u0, p0 = ufl.split(w0) if f.mixed else (w0, None)
        sigma0 = (cauchy_stress(hooke, u0, p0, self.model) if f.mixed
                  else hooke.stress(kinematics.small_strain(u0, self.model)))
        K_G = geometric_stiffness(sigma0, self._du, f.v,  # embedded 3x3 ∇ matches a 3x3 σ₀
                                  lambda z: kinematics.displacement_gradient(z, self.model))
        return critical_loads(K, K_G * self.dx, self.bcs, W, n=n, prefix="beam_buckling_",
                              scale_dofs=f.displacement_dofs)

    def lowest_mode(self) -> tuple[float, fem.Function]:
        """The tangent's eigenvalue nearest 0 at the current state (the lowest, if one is
        negative), and its mode (`solvers.buckling.lowest_tangent_mode`)."""
        tangent = ufl.derivative(self.residual, self.u)
        return lowest_tangent_mode(tangent, self.bcs, self.u.function_space,
                                   "beam_stability_", mass=self.mass,
                                   multipliers=self.fields.pressure_dofs)

    def push_along(self, mode: fem.Function, deflection: float) -> None:
        """u += η φ with η such that φ's mean end-face lateral displacement is `deflection`.

        The mean is over the owned end-face nodes: the same at any number of ranks.
        """
        comm, f = self.mesh.comm, self.fields
        owned = f.displacement_space.dofmap.index_map.size_local
        at_tip = np.isclose(f.displacement_space.tabulate_dof_coordinates()[:owned, 0], self.L)
        lateral = mode.x.array[f.displacement_dofs].reshape(-1, 2)[:owned, 1]
        mean = comm.allreduce(float(lateral[at_tip].sum())) / comm.allreduce(int(at_tip.sum()))
        self.u.x.array[:] += deflection / mean * mode.x.array
        self.u.x.scatter_forward()

    def solve_path(self, ratio: float, steps: int = 40, method: str = "full", *,
                   grow: bool = False, on_step=None) -> tuple[LoadPath, bool]:
        """Load steps from 0 to ratio·P_Euler, then make sure the end state is stable.

        As the demo's load path: steps of at most 1/steps (with `grow`, growing after easy
        steps), cut on failure; an unstable end state pushed along its mode to the
        elastica's deflection and solved again, else the path redone with 4x the steps, up
        to MAX_PATH_STEPS. `path_steps` is then the number of steps of the last path run.

        Returns:
            The path and whether the branch was switched.
        """
        P = ratio * self.P_euler
        solver = NewtonSolver(self.residual, self.u, self.bcs, method=method, rtol=1e-8,
                              atol=1e-9, force_scale=P, max_it=30 if method == "full" else 500,
                              prefix=f"beam_{method}_")
        while True:
            self.path_steps = steps
            self.u.x.array[:] = 0.0
            path = solve_incrementally(solver, lambda t: self.set_load(t * P), steps=steps,
                                       max_step=1.0 if grow else 1.0 / steps, on_step=on_step)
            lam, mode = self.lowest_mode()
            if lam >= 0:
                return path, False
            self.push_along(mode, elastica.tip_position(ratio)[0] * self.L)
            try:
                result = solver.solve()
                if self.lowest_mode()[0] >= 0:
                    path.results.append(result)
                    path.work.add(result.work)
                    if on_step:
                        on_step(1.0, result)
                    return path, True
            except ConvergenceError:
                pass
            if steps >= MAX_PATH_STEPS:
                break
            steps = min(4 * steps, MAX_PATH_STEPS)
        raise SolveError(f"no stable end state at P/P_cr = {ratio:g} with up to {steps} steps")

    def solve_arc_length(self, ratio: float, method: str = "full", *,
                         arc_length: float = 0.2, max_steps: int = 1000) -> ContinuationPath:
        """Arc-length continuation from 0 to ratio·P_Euler (λ = P/P_Euler), as the demo's.

        The bifurcation is found by the tangent's inertia and left along its critical mode.
        """
        solver = NewtonSolver(self.residual, self.u, self.bcs, method=method, rtol=1e-8,
                              atol=1e-8, max_it=30 if method == "full" else 500,
                              prefix=f"beam_{method}_")
        f = self.fields
        arc = ArcLength(solver, lambda t: self.set_load(t * self.P_euler),
                        arc_length=arc_length, switch=True, prefix="beam_continuation_",
                        metric_dofs=f.displacement_dofs if f.mixed else None,
                        mass=self.mass, multipliers=f.pressure_dofs)
        self.u.x.array[:] = 0.0
        return arc.run(ratio, max_steps)

