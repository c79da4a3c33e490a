"""The buckling beam: a slender 2D cantilever under a dead axial load at its free end.

Clamped at x = 0, length L, height h (unit width), Q2 quadrilaterals, finite strain. The
end x = L carries the dead traction (−P, H)/h: the axial load P and a small lateral load
H = ε P, the imperfection that picks the buckled branch. Tip quantities are averages over
the end face (parallel-safe integrals): lateral deflection, axial displacement, and the
rotation α of the end section, from its deformed tangent F·e_y.

`mixed=True` (plane strain): the Q2–Q1 Taylor–Hood pair (u, p) of `materials.mixed`, for a
nearly or exactly incompressible beam, where Q2 displacements lock in bending.
"""

from __future__ import annotations

import math

import numpy as np
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.errors import SolveError
from fenics_nl.io import output
from fenics_nl.materials import kinematics, mixed
from fenics_nl.materials.laws import LinearElastic, NeoHookean, StVenantKirchhoff
from fenics_nl.materials.mixed import unknowns
from fenics_nl.solvers.arclength import ArcLength, ContinuationPath
from fenics_nl.solvers.buckling import critical_loads, geometric_stiffness, lowest_tangent_mode
from fenics_nl.solvers.loading import LoadPath, solve_incrementally
from fenics_nl.solvers.newton import ConvergenceError, NewtonSolver
from fenics_nl.theory import elastica
from fenics_nl.theory.elastica import euler_load

__all__ = ["Beam", "Cantilever", "build_beam"]

MATERIALS = {"svk": StVenantKirchhoff, "neo-hookean": NeoHookean}
# A load path that ends unstable is redone with 4x the steps, up to this many: small steps
# through P_cr let the imperfection pick the buckled branch.
MAX_PATH_STEPS = 256


class Cantilever:
    """The beam's mesh and conditions: clamped at x = 0, a dead traction on the end x = L.

    Q`degree` quadrilaterals, 2·2^refine through the height, square-ish. Everything a
    residual is written with is public: `u` (the displacement in forms), `V`, `model`
    (plane_stress | plane_strain), `dx` (degree 4), `traction` (set by `set_load`) and
    `ds_end`; `unknown` is the Function a solver updates (u, or (u, p) if `mixed`) and
    `fields` the `materials.mixed` unknown it belongs to.
    """

    def __init__(self, length: float, thickness: float, *, plane: str = "stress",
                 refine: int = 0, imperfection: float = 1e-4, degree: int = 2,
                 mixed: bool = False, comm: MPI.Comm = MPI.COMM_WORLD):
        if plane not in ("stress", "strain"):
            raise ValueError(f"plane must be stress or strain, got {plane!r}")
        if mixed and plane == "stress":
            raise ValueError("--mixed needs --plane strain (plane stress has no volumetric "
                             "constraint: its out-of-plane strain takes the volume change)")
        if not (length > 0 and thickness > 0):
            raise ValueError(f"length and thickness must be > 0, got {length}, {thickness}")
        if thickness > length / 5:
            raise ValueError(f"the beam must be slender: thickness <= length/5, got L/h = "
                             f"{length / thickness:.3g}")
        if refine < 0:
            raise ValueError(f"refine must be >= 0, got {refine}")
        self.L, self.h, self.imperfection = length, thickness, imperfection
        self.model = "plane_stress" if plane == "stress" else "plane_strain"
        ny = 2 * 2**refine
        nx = max(4, round(length / thickness * ny / 2))  # square-ish Q2 elements
        self.mesh = mesh.create_rectangle(comm, [[0, -thickness / 2], [length, thickness / 2]],
                                          [nx, ny], mesh.CellType.quadrilateral)
        self.fields = unknowns(self.mesh, degree, mixed)
        self.V, self.u, self.unknown = self.fields.V, self.fields.u, self.fields.w
        fdim = 1
        clamped = mesh.locate_entities_boundary(self.mesh, fdim, lambda x: np.isclose(x[0], 0))
        end = mesh.locate_entities_boundary(self.mesh, fdim, lambda x: np.isclose(x[0], length))
        tags = mesh.meshtags(self.mesh, fdim, end, np.ones(len(end), dtype=np.int32))
        self.bcs = [boundary.fixed(self.V, clamped)]
        self.groups = {"clamp": clamped}
        self.ds_end = ufl.Measure("ds", domain=self.mesh, subdomain_data=tags)(1)
        self.traction = fem.Constant(self.mesh, np.zeros(2))
        self.dx = kinematics.quadrature_measure("dx", self.mesh, 4)
        u = self.u
        F = kinematics.deformation_gradient(u, "plane_stress")  # 2x2 in-plane F
        self._tip_forms = [fem.form(f * self.ds_end) for f in
                           (u[0] / thickness, u[1] / thickness, F[0, 1], F[1, 1])]

    @property
    def dofs(self) -> int:
        """Global number of scalar unknowns (with the pressure's, if mixed)."""
        return output.dofs(self.unknown.function_space)

    def residual(self, material) -> ufl.Form:
        """R(u; v) of a finite-strain `material` under the end's dead traction.

        The unknown's internal work (`materials.mixed`): P(u) : ∇v, or δΠ(u, p) if mixed.
        """
        f = self.fields
        return (f.internal_work(material, self.model) * self.dx
                - ufl.dot(self.traction, f.v) * self.ds_end)

    def set_load(self, P: float) -> None:
        """Dead end load: axial compression P and the lateral imperfection ε P."""
        self.traction.value[:] = [-P / self.h, self.imperfection * P / self.h]

    def tip(self) -> dict[str, float]:
        """Mean end-face axial and lateral displacement, and the end-section rotation α."""
        comm = self.mesh.comm
        ux, uy, t0, t1 = (comm.allreduce(fem.assemble_scalar(f)) for f in self._tip_forms)
        return {"axial": ux, "lateral": uy, "rotation": math.atan2(-t0, t1)}


def build_beam(length: float, thickness: float, E: float, nu: float, *,
               material: str = "svk", **options) -> Beam:
    """The beam in one call, for tests and benchmarks (the demo writes these steps out).

    `options` go to `Cantilever` (plane, refine, imperfection, degree, comm).
    """
    if material not in MATERIALS:
        raise ValueError(f"material must be one of {', '.join(MATERIALS)}, got {material!r}")
    c = Cantilever(length, thickness, **options)
    law = MATERIALS[material](E, nu)
    return Beam(c.residual(law), c.fields, c.bcs, material=law, model=c.model, length=c.L,
                thickness=c.h, dx=c.dx, ds_end=c.ds_end, set_load=c.set_load, tip=c.tip,
                clamp=c.groups["clamp"])


class Beam:
    """Linear buckling, the post-buckling path and its stability, of a cantilever's residual.

    Args:
        residual: R(u; v) under the end's dead traction (UFL form), in `fields.w`.
        fields: the unknown (`materials.mixed.unknown_of`): u, or Taylor–Hood (u, p).
        bcs: the clamp's Dirichlet conditions.
        material: the residual's finite-strain law: its E and ν give Euler's load and
            Hooke's tangent of the linear buckling analysis.
        model: ``plane_stress`` or ``plane_strain``.
        length: L (Euler's load; the end face x = L, where a branch switch is scaled).
        thickness: h (Euler's load, I = h³/12).
        dx: the residual's volume measure.
        ds_end: the loaded end's measure.
        set_load: the end traction for an axial load P: `set_load(P)`.
        tip: the end's mean axial and lateral displacement and rotation: `tip()` gives
            {"axial", "lateral", "rotation"}.
        clamp: the clamped facets (their reaction).
    """

    def __init__(self, residual, fields, bcs, *, material, model: str, length: float,
                 thickness: float, dx, ds_end, set_load, tip, clamp):
        self.material, self.residual, self.fields = material, residual, fields
        self.L, self.h, self.model = length, thickness, model
        # `u`: what the solvers update (the mixed unknown (u, p) if mixed)
        self.V, self.u, self.bcs = fields.V, fields.w, list(bcs)
        self.mesh = self.u.function_space.mesh
        self.dx, self.ds_end, self.set_load, self.tip = dx, ds_end, set_load, tip
        self.groups = {"clamp": clamp}
        E, nu = material.E, material.nu
        self.E_bending = E if self.model == "plane_stress" else E / (1 - nu**2)
        self.P_euler = euler_load(self.E_bending, self.h**3 / 12, self.L)

    @property
    def dofs(self) -> int:
        """Global number of scalar unknowns (with the pressure's, if mixed)."""
        return output.dofs(self.u.function_space)

    def _split(self, w):
        """(displacement, pressure or None) of a Function or argument of the unknown's space."""
        return ufl.split(w) if self.fields.mixed else (w, None)

    def critical_loads(self, n: int = 3):
        """SLEPc: the first n critical loads and modes around the undeformed state.

        Mixed: K is the mixed tangent of Hooke's law and K_G acts on the displacement part.
        """
        f, W = self.fields, self.u.function_space
        lin = LinearElastic(self.material.E, self.material.nu)
        work = f.internal_work(lin, self.model)
        a = ufl.derivative(work * self.dx, f.w)  # Hooke's tangent: the same at any state
        # pre-stress of a unit compressive load: one linear solve
        w0 = fem.Function(W)
        t = fem.Constant(self.mesh, np.array([-1.0 / self.h, 0.0]))
        from dolfinx.fem.petsc import LinearProblem

        from fenics_nl.solvers.snes import solver_options

        direct = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
        with solver_options("beam_prestress_", direct) as passed:
            prestress = LinearProblem(a, ufl.dot(t, f.v) * self.ds_end, u=w0, bcs=self.bcs,
                                      petsc_options_prefix="beam_prestress_",
                                      petsc_options=passed)
        prestress.solve()
        u0, p0 = self._split(w0)
        sigma0 = (mixed.cauchy_stress(lin, u0, p0, self.model) if f.mixed
                  else lin.stress(kinematics.small_strain(u0, self.model)))
        du = self._split(ufl.TrialFunction(W))[0]
        a_G = geometric_stiffness(sigma0, du, f.v,  # embedded 3x3 ∇ matches a 3x3 σ₀
                                  lambda w: kinematics.displacement_gradient(w, self.model))
        return critical_loads(a, a_G * self.dx, self.bcs, W, n=n, prefix="beam_buckling_",
                              scale_dofs=f.displacement_dofs)

    def _displacement_mass(self) -> ufl.Form:
        """∫ du · v: the metric of the stability eigenproblem (zero on the pressure)."""
        du = self._split(ufl.TrialFunction(self.u.function_space))[0]
        return ufl.inner(du, self.fields.v) * self.dx

    def lowest_mode(self) -> tuple[float, fem.Function]:
        """The tangent's eigenvalue nearest 0 at the current state, and its mode.

        K_T φ = λ M φ with M the displacement's mass: for the mixed saddle point this is the
        tangent with the pressure condensed out, whose sign is the stability of the
        equilibrium (K_T's own spectrum also holds one negative value per pressure unknown,
        which `lowest_tangent_mode` discounts).
        """
        tangent = ufl.derivative(self.residual, self.u)
        return lowest_tangent_mode(tangent, self.bcs, self.u.function_space,
                                   "beam_stability_", mass=self._displacement_mass(),
                                   multipliers=self.fields.pressure_dofs)

    def solve_path(self, ratio: float, steps: int = 40, method: str = "full", *,
                   grow: bool = False, on_step=None, progress=None, progress_every: int = 1
                   ) -> tuple[LoadPath, bool]:
        """Load steps from 0 to ratio·P_Euler, then make sure the end state is stable.

        Steps start at 1/steps and are cut on failure; with `grow` they also grow after easy
        steps. Past P_cr the straight beam is an unstable equilibrium Newton can settle on;
        the tangent's eigenvalue nearest 0 (SLEPc) tells. An unstable end state is kicked
        along its unstable mode to the elastica's deflection and solved again (branch
        switching); if Newton cannot follow, the path is redone with 4x the steps, up to
        MAX_PATH_STEPS.
        Returns the path and whether the branch was switched.
        """
        P = ratio * self.P_euler
        # rtol 1e-8: near P_cr the tangent is nearly singular and modified Newton's linear
        # rate is close to 1; tighter tolerances stall there on round-off.
        solver = NewtonSolver(self.residual, self.u, self.bcs, method=method, rtol=1e-8,
                              atol=1e-9, force_scale=P, max_it=30 if method == "full" else 500,
                              prefix=f"beam_{method}_")
        while True:
            self.path_steps = steps  # the number of steps of the last path run
            self.u.x.array[:] = 0.0
            path = solve_incrementally(solver, lambda t: self.set_load(t * P), steps=steps,
                                       max_step=1.0 if grow else 1.0 / steps,
                                       on_step=on_step, progress=progress,
                                       progress_every=progress_every)
            lam, mode = self.lowest_mode()
            if lam >= 0:
                return path, False
            if progress:
                progress(f"end state unstable (tangent eigenvalue {lam:.3g}): switching branch")
            self.kick_along(mode, elastica.tip_position(ratio)[0] * self.L)
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
            if progress:
                progress(f"branch switching failed: load path again with {steps} steps")
        raise SolveError(f"no stable end state at P/P_cr = {ratio:g} with up to {steps} steps")

    def solve_arc_length(self, ratio: float, method: str = "full", *, arc_length: float = 0.2,
                         max_steps: int = 1000, on_step=None, progress=None,
                         progress_every: int = 1
                         ) -> ContinuationPath:
        """Arc-length continuation from 0 to ratio·P_Euler (λ = P/P_Euler).

        The inertia of the tangent is counted at every state; where it changes while the
        load keeps growing (a bifurcation: the straight beam past P_cr), the path leaves
        along the tangent's critical mode, scaled by the arc length alone (no elastica).
        With an imperfection there is no bifurcation: the path bends smoothly.
        """
        # atol 1e-8 of the reference load: bent past 90°, the internal forces' round-off
        # reaches ~5e-9 of it (membrane forces ≫ the load), where modified Newton stalls
        solver = NewtonSolver(self.residual, self.u, self.bcs, method=method, rtol=1e-8,
                              atol=1e-8, max_it=30 if method == "full" else 500,
                              prefix=f"beam_{method}_")
        f = self.fields
        arc = ArcLength(solver, lambda t: self.set_load(t * self.P_euler),
                        arc_length=arc_length, switch=True, prefix="beam_continuation_",
                        metric_dofs=f.displacement_dofs if f.mixed else None,
                        mass=self._displacement_mass(), multipliers=f.pressure_dofs)
        self.u.x.array[:] = 0.0
        return arc.run(ratio, max_steps, on_step=on_step, progress=progress,
                       progress_every=progress_every)

    def reactions(self) -> dict[str, list[float]]:
        """Resultant force of the clamp on the beam (per unit width), see `boundary`."""
        space = self.V if self.fields.mixed else None
        return boundary.reactions(self.residual, self.u, self.groups, space=space)

    def kick_along(self, mode: fem.Function, deflection: float) -> None:
        """u += η φ with η such that φ's mean end-face lateral displacement is `deflection`.

        φ is scaled as a whole (with its pressure part, if mixed). The mean is over the owned
        end-face nodes, so it is the same at any number of ranks.
        """
        comm, f = self.mesh.comm, self.fields
        owned = f.displacement_space.dofmap.index_map.size_local
        at_tip = np.isclose(f.displacement_space.tabulate_dof_coordinates()[:owned, 0], self.L)
        lateral = mode.x.array[f.displacement_dofs].reshape(-1, 2)[:owned, 1]
        mean = comm.allreduce(float(lateral[at_tip].sum())) / comm.allreduce(int(at_tip.sum()))
        self.u.x.array[:] += deflection / mean * mode.x.array
        self.u.x.scatter_forward()
