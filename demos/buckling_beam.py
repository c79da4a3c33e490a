# # Buckling of a compressed cantilever: Euler's load and the elastica
#
# A slender beam (length $L$, height $h$), clamped at $x = 0$, carries a dead compressive
# load $P$ at its free end. Finite strain (St Venant–Kirchhoff in the Green–Lagrange strain,
# as in the course's practical). First the linear buckling load, then the post-buckling
# path, both checked against closed forms.
#
# ## Problem definition
#
# Linear buckling around the pre-stressed straight state: $(K + \lambda K_G)\,\varphi = 0$,
# $K_G$ the geometric stiffness of the stress of a unit load, solved by SLEPc
# (shift-and-invert). Euler: $P_{cr} = \pi^2 E I / (4 L^2)$, $I = h^3/12$ (plane stress;
# $E/(1-\nu^2)$ in plane strain).
#
# Post-buckling: load steps from 0 to $P = r P_{cr}$ ($P_{cr}$: Euler's), a Newton solve
# per step, a small lateral end load $\varepsilon P$ ($\varepsilon = 10^{-4}$) as
# imperfection. The elastica
# (inextensible, tip rotation $\alpha$, $k = \sin(\alpha/2)$):
#
# $$ P/P_{cr} = (2K(k)/\pi)^2, \qquad \delta/L = 2k/K(k), \qquad x/L = 2E(k)/K(k) - 1 .$$
#
# Past $P_{cr}$ the straight beam is still an equilibrium, but an unstable one: Newton can
# settle on it. The steps therefore never grow beyond 1/`--steps` of the load, and the end
# state is checked for stability (the tangent's eigenvalue nearest 0, by SLEPc); an unstable end
# state is pushed along its unstable mode, scaled to the elastica's deflection, and solved
# again (branch switching); if Newton cannot follow, the path is redone with 4 times the
# steps (up to 256), and only then does the run stop with a clear message.
#
# With `--path arc-length` the load is an unknown beside $u$ (Crisfield's arc-length
# continuation, `fenics_nl.solvers.arclength`) and no closed form is used: the number of
# negative eigenvalues of the tangent (its inertia, from an $LDL^T$ factorization) is
# counted at every state; where it changes while the load keeps growing, the path has
# crossed a bifurcation, which is bracketed and left along the tangent's critical mode by
# one arc length. With `--imperfection 0` the beam is perfect and this is how it buckles.
#
# ## Implementation

# +
import math
from dataclasses import dataclass
from typing import ClassVar

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem.petsc import LinearProblem
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.domain.strips import CLAMPED, END, cantilever_strip
from fenics_nl.errors import SolveError
from fenics_nl.io import cli, output
from fenics_nl.io.cli import say
from fenics_nl.io.parameters import Parameters, choice, number, switch
from fenics_nl.materials import kinematics, mixed
from fenics_nl.materials.laws import LinearElastic, NeoHookean, StVenantKirchhoff
from fenics_nl.parallel import gather_rows
from fenics_nl.plots import continuation as continuation_pictures
from fenics_nl.solvers.arclength import ArcLength
from fenics_nl.solvers.buckling import critical_loads, geometric_stiffness, lowest_tangent_mode
from fenics_nl.solvers.loading import solve_incrementally
from fenics_nl.solvers.newton import ConvergenceError, NewtonSolver
from fenics_nl.solvers.snes import solver_options
from fenics_nl.theory import elastica

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

comm = MPI.COMM_WORLD
# -

# ### Parameters
#
# From the command line (`python demos/buckling_beam.py --help`); in a notebook, the
# defaults. PETSc options take the prefix `-beam_` (`-beam_full_ksp_view`, ...).

# +
@dataclass
class Buckling(Parameters):
    """Buckling of a compressed cantilever: SLEPc critical load and the post-buckling path
    against the elastica. Units are the user's, consistent (e.g. N, m, Pa)."""

    EPILOG = ("PETSc options take the prefix -beam_<newton>_ (Newton's KSP, e.g. "
              "-beam_full_ksp_view), -beam_buckling_ (SLEPc EPS of the critical loads), "
              "-beam_stability_ (EPS of the end state's stability), -beam_continuation_ "
              "(the arc-length path's stability checks), -beam_prestress_ (KSP of the "
              "pre-stress). An option no solver reads is an error.")
    OUTPUTS: ClassVar = {"output": "the displacement",
                         "png": "deformed shapes along the path, with the elastica's",
                         "plot": "P/P_cr against tip rotation and deflection"}

    length: float = number(1.0, "beam length L", unit="length", above=0)
    thickness: float = number(0.02, "beam height h", unit="length", above=0)
    E: float = number(1e3, "Young's modulus", unit="stress", above=0)
    nu: float = number(0.3, "Poisson's ratio", unit="-")
    plane: str = choice("stress", ["stress", "strain"], "plane stress or plane strain (unit "
                        "width)")
    material: str = choice("svk", ["svk", "neo-hookean"], "St Venant-Kirchhoff or "
                           "compressible neo-Hookean (plane strain)")
    load_ratio: float = number(1.5, "final load P / P_cr (Euler)", above=0, at_most=20)
    steps: int = number(40, "equal load steps to the final load (a failed step is cut in "
                        "half)", at_least=1)
    newton: str = choice("full", ["full", "modified", "periodic", "bfgs"],
                         "Newton variant of each load step", spelling=True)
    path: str = choice("load", ["load", "arc-length"], "load control (steps of P, end state "
                       "checked and switched with the elastica's deflection if unstable) or "
                       "arc-length continuation (bifurcation found by the tangent's inertia "
                       "and left along its mode: no closed form)")
    arc_length: float = number(0.2, "with --path arc-length: the first arc length "
                               "(dimensionless, about one load step of Δs/√2 P_Euler on the "
                               "straight branch)", unit="-", above=0)
    imperfection: float = number(1e-4, "lateral end load as a fraction of P, in [0, 0.1)",
                                 unit="-", at_least=0)
    refine: int = number(0, "mesh: 2·2^refine Q2 elements through the height, twice as long "
                         "elements", at_least=0)
    mixed: bool = switch("Q2-Q1 Taylor-Hood displacement-pressure elements, for a nearly or "
                         "exactly incompressible beam (nu up to 0.5; --plane strain)")

    def check(self):
        if not self.imperfection < 0.1:
            raise ValueError(f"--imperfection must be in [0, 0.1), got {self.imperfection}")
        if self.material == "neo-hookean" and self.plane == "stress":
            raise ValueError("neo-hookean is implemented in plane strain only (--plane strain)")
        if self.thickness > self.length / 5:
            raise ValueError(f"the beam must be slender: --thickness <= --length/5, got L/h = "
                             f"{self.length / self.thickness:.3g}")
        if self.mixed and self.plane == "stress":
            raise ValueError("--mixed needs --plane strain (in plane stress the out-of-plane "
                             "strain takes the volume change: nothing locks)")


args = cli.arguments(Buckling, prefixes={"beam_": "Newton, SLEPc and pre-stress solvers"})


# -

# ### The mesh and its tags
#
# Quadrilaterals, 2·2^refine through the height and twice as long as high
# (`fenics_nl.domain.strips`); the facets of the clamped end x = 0 and of the loaded end
# x = L are tagged CLAMPED and END.

# +
L, h = args.length, args.thickness
msh, facet_tags = cantilever_strip(comm, L, h, args.refine)
# -

# ### The function space and the boundary conditions
#
# Q2 displacements (with `--mixed`, the Q2–Q1 Taylor–Hood pair $(u, p)$). The end $x = 0$
# is clamped; the end $x = L$ carries the dead traction $t = (-P, \varepsilon P)/h$, a
# `fem.Constant` the load steps set.

# +
clamped = facet_tags.find(CLAMPED)
if args.mixed:
    W = mixed.taylor_hood(msh, 2)
    w = fem.Function(W, name="displacement_pressure")
    (u, p), (v, q) = ufl.split(w), ufl.TestFunctions(W)
    du = ufl.split(ufl.TrialFunction(W))[0]
    V, (V0, _) = W.sub(0), W.sub(0).collapse()  # the displacement part, numbered in w
    dofs = fem.locate_dofs_topological((V, V0), 1, clamped)
    bcs = [fem.dirichletbc(fem.Function(V0), dofs, V)]
else:
    W = V = fem.functionspace(msh, ("Lagrange", 2, (2,)))
    w = u = fem.Function(V, name="displacement")
    v, du = ufl.TestFunction(V), ufl.TrialFunction(V)
    bcs = [fem.dirichletbc(np.zeros(2), fem.locate_dofs_topological(V, 1, clamped), V)]
fields = mixed.unknown_of(w)  # where the displacement's and pressure's dofs are in w
ds = ufl.Measure("ds", domain=msh, subdomain_data=facet_tags)
t = fem.Constant(msh, np.zeros(2))


def set_load(P):
    """The dead end load: axial compression P and the lateral imperfection ε P."""
    t.value[:] = [-P / h, args.imperfection * P / h]


# -

# ### The material: a free energy of the Green–Lagrange strain
#
# St Venant–Kirchhoff, the course's finite-strain law, in $e = \frac12(F^TF - I)$:
#
# $$ \varphi(e) = \frac{\lambda}{2} (\mathrm{tr}\,e)^2 + \mu\, e : e, $$
#
# written below in UFL (in plane stress $\lambda$ becomes $2\lambda\mu/(\lambda + 2\mu)$,
# the out-of-plane stress being zero). The second Piola–Kirchhoff stress
# $S = \partial\varphi/\partial e$ is UFL's derivative of it. `--material neo-hookean`
# takes the library's compressible neo-Hookean energy instead (`NeoHookean.energy`).

# +
model = "plane_stress" if args.plane == "stress" else "plane_strain"
law = {"svk": StVenantKirchhoff, "neo-hookean": NeoHookean}[args.material]
material = law(args.E, args.nu)  # E, ν checked; the neo-Hookean's φ
mu, lmbda = material.mu, material.lmbda  # Lamé's constants (λ = ∞ at ν = 1/2)
if model == "plane_stress":  # σ_zz = 0: λ* = 2λμ/(λ + 2μ), 2μ at ν = 1/2
    lmbda = 2 * mu if math.isinf(lmbda) else 2 * lmbda * mu / (lmbda + 2 * mu)
elif not args.mixed:
    material.require_compressible()  # ν = 1/2 needs the pressure as an unknown


def svk_energy(e):
    """φ(e) of St Venant–Kirchhoff."""
    return lmbda / 2 * ufl.tr(e) ** 2 + mu * ufl.inner(e, e)


phi = svk_energy if args.material == "svk" else material.energy
# -

# ### The residual
#
# Total Lagrangian: $R(u; v) = \int_{\Omega_0} F S(e) : \nabla v\,d\Omega_0 -
# \int_{end} t \cdot v\,dS_0$, $F S$ the first Piola–Kirchhoff stress. In plane strain the
# gradients are 3×3 with a zero third row and column (`kinematics.displacement_gradient`).
# With `--mixed` the first term is the variation of the perturbed Lagrangian
# $\Pi(u, p) = \int \tilde\varphi(e) + p\,g(e) - p^2/(2k)$ (`fenics_nl.materials.mixed`).

# +
dx = kinematics.quadrature_measure("dx", msh, 4)
if args.mixed:
    internal = mixed.internal_work(material, u, p, v, q, model)
else:
    H = kinematics.displacement_gradient(u, model)
    F = ufl.Identity(H.ufl_shape[0]) + H
    e = ufl.variable((H + H.T + H.T * H) / 2)  # Green–Lagrange
    S = ufl.diff(phi(e), e)
    internal = ufl.inner(F * S, kinematics.displacement_gradient(v, model))
residual = internal * dx - ufl.dot(t, v) * ds(END)
tangent = ufl.derivative(residual, w)  # K_T, for the stability checks
# -

# ### What is measured: the tip
#
# Means over the end face: the axial and lateral displacement, and the rotation α of the
# end section from its deformed tangent $F e_y$.

# +
F_plane = ufl.Identity(2) + ufl.grad(u)  # the in-plane F: the end's tangent F e_y
tip_forms = [fem.form(f * ds(END)) for f in (u[0] / h, u[1] / h, F_plane[0, 1], F_plane[1, 1])]


def tip():
    """{"axial", "lateral", "rotation"} of the end face."""
    ux, uy, t0, t1 = (comm.allreduce(fem.assemble_scalar(f)) for f in tip_forms)
    return {"axial": ux, "lateral": uy, "rotation": math.atan2(-t0, t1)}


E_bending = args.E if model == "plane_stress" else args.E / (1 - args.nu**2)
P_euler = elastica.euler_load(E_bending, h**3 / 12, L)
say(f"beam L/h = {L / h:g}, {output.dofs(W)} unknowns, {args.material}, plane {args.plane}"
    f"{', mixed Q2-Q1' if args.mixed else ''}")
# -

# ### Linear buckling (SLEPc) against Euler
#
# $(K + \lambda K_G)\varphi = 0$ around the straight state: $K$ is the tangent of Hooke's law
# (the small-strain limit of the energy: the residual's tangent at $u = 0$), $K_G$ the
# geometric stiffness $\int \sigma_0 : (\nabla\delta u^T \nabla v)$ of the stress $\sigma_0$
# of a unit compression, one linear solve. SLEPc's shift-and-invert gives the $\lambda$
# nearest 0 (`solvers.buckling.critical_loads`; with `--mixed`, $K$ is the mixed tangent and
# $K_G$ acts on the displacement).

# +
hooke = LinearElastic(args.E, args.nu)
linear = (mixed.internal_work(hooke, u, p, v, q, model) if args.mixed
          else hooke.internal_work(u, v, model))
K = ufl.derivative(linear * dx, w)  # Hooke's: the same at any state
w0 = fem.Function(W)  # the pre-stress state of a unit compression
unit = fem.Constant(msh, np.array([-1.0 / h, 0.0]))
direct = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
with solver_options("beam_prestress_", direct) as passed:
    LinearProblem(K, ufl.dot(unit, v) * ds(END), u=w0, bcs=bcs,
                  petsc_options_prefix="beam_prestress_", petsc_options=passed).solve()
u0, p0 = ufl.split(w0) if args.mixed else (w0, None)
sigma0 = (mixed.cauchy_stress(hooke, u0, p0, model) if args.mixed
          else hooke.stress(kinematics.small_strain(u0, model)))
K_G = geometric_stiffness(sigma0, du, v,  # embedded 3×3 ∇ matches a 3×3 σ₀
                          lambda z: kinematics.displacement_gradient(z, model)) * dx
loads, _ = critical_loads(K, K_G, bcs, W, n=3, prefix="beam_buckling_",
                          scale_dofs=fields.displacement_dofs)
P_slepc = loads[0]  # the FE model's critical load; P_cr in the text is Euler's
say(f"critical loads (SLEPc): {', '.join(f'{x:.6g}' for x in loads)}; Euler "
    f"{P_euler:.6g} ({100 * (P_slepc / P_euler - 1):+.3f} %)")
# -

# ### Stability: the tangent's eigenvalue nearest 0, and a push along its mode
#
# $K_T \varphi = \lambda M \varphi$ with $M = \int \delta u \cdot v$ (zero on the pressure:
# with `--mixed` it is the tangent with the pressure condensed out, whose sign is the
# stability; $K_T$'s own spectrum holds one negative value per pressure unknown, not
# counted). An unstable state is pushed along its mode, scaled so that the end face moves
# sideways by a given deflection (the mean over its nodes).

# +
mass = ufl.inner(du, v) * dx


def lowest_mode():
    """The tangent's eigenvalue nearest 0 (the lowest, if one is negative) and its mode."""
    return lowest_tangent_mode(tangent, bcs, W, "beam_stability_", mass=mass,
                               multipliers=fields.pressure_dofs)


owned = fields.displacement_space.dofmap.index_map.size_local
at_tip = np.isclose(fields.displacement_space.tabulate_dof_coordinates()[:owned, 0], L)


def push_along(mode, deflection):
    """w += η φ, η such that φ's mean end-face lateral displacement is `deflection`."""
    lateral = mode.x.array[fields.displacement_dofs].reshape(-1, 2)[:owned, 1]
    mean = comm.allreduce(float(lateral[at_tip].sum())) / comm.allreduce(int(at_tip.sum()))
    w.x.array[:] += deflection / mean * mode.x.array
    w.x.scatter_forward()


# -

# ### The post-buckling path
#
# Each converged state is recorded: its tip, and its centreline for the pictures.

# +
def progress(message):
    """The path's step lines (about ten of them: `progress_every`), every cut or switch."""
    say("  " + message)


def centreline():
    """Deformed centreline points (x + u) of the dofs on y = 0, gathered, sorted by x."""
    d = fields.displacement()
    n = d.function_space.dofmap.index_map.size_local  # owned: each point once
    X = d.function_space.tabulate_dof_coordinates()[:n]
    on = np.isclose(X[:, 1], 0.0)
    rows = gather_rows(comm, X[on, 0], X[on, :2] + d.x.array.reshape(-1, 2)[:n][on])
    return None if rows is None else rows[1][np.argsort(rows[0])]


history, shapes = [(0.0, 0.0, 0.0, 0.0)], []


def record(s, result):
    r = s * args.load_ratio
    # a redone path, or the branch-switched end state, replaces what it passes again (at
    # the same load up to the round-off of the summed steps: ten steps of 0.1 sum to
    # 0.9999999999999999)
    again = r - 1e-9 * args.load_ratio
    while len(history) > 1 and history[-1][0] >= again:
        history.pop()
    while shapes and shapes[-1][0] >= again:
        shapes.pop()
    end = tip()
    history.append((r, math.degrees(abs(end["rotation"])), abs(end["lateral"]), end["axial"]))
    cli.converged_step({"load_factor": s, "load_ratio": r, "tip_rotation_deg": history[-1][1],
                        "tip_deflection": history[-1][2], "tip_axial": history[-1][3],
                        "newton_iterations": result.iterations},
                       fields=lambda: [fields.displacement(),
                                       *([fields.pressure()] if args.mixed else [])])
    if args.png:
        shapes.append((r, centreline()))


# -

# Load control (`solvers.loading.solve_incrementally`: steps of at most 1/`--steps` of the
# load, cut on failure), then the end state's stability and, if it is unstable, the push
# along its mode to the elastica's deflection (branch switching), or the path again with 4
# times the steps. With `--path arc-length`, `solvers.arclength.ArcLength` with branch
# switching at the bifurcation its inertia count finds.

# +
redone, critical, switched = [], [], False
max_it = 30 if args.newton == "full" else 500
if args.path == "load":
    P = args.load_ratio * P_euler
    # rtol 1e-8: near P_cr the tangent is nearly singular and modified Newton's linear
    # rate is close to 1; tighter tolerances stall there on round-off
    solver = NewtonSolver(residual, w, bcs, method=args.newton, rtol=1e-8, atol=1e-9,
                          force_scale=P, max_it=max_it, prefix=f"beam_{args.newton}_")
    say(f"load path to P/P_cr = {args.load_ratio:g} in steps of at most 1/{args.steps}")
    steps = args.steps
    while True:
        w.x.array[:] = 0.0
        path = solve_incrementally(solver, lambda s: set_load(s * P), steps=steps,
                                   max_step=1.0 / steps, on_step=record, progress=progress,
                                   progress_every=max(1, args.steps // 10))
        lam, mode = lowest_mode()
        if lam >= 0:
            break
        progress(f"end state unstable (tangent eigenvalue {lam:.3g}): switching branch")
        push_along(mode, elastica.tip_position(args.load_ratio)[0] * L)
        try:
            result = solver.solve()
            if lowest_mode()[0] >= 0:
                path.results.append(result)
                path.work.add(result.work)
                record(1.0, result)
                switched = True
                break
        except ConvergenceError:
            pass
        if steps >= 256:
            raise SolveError(f"no stable end state at P/P_cr = {args.load_ratio:g} with up "
                             f"to {steps} steps")
        steps = min(4 * steps, 256)
        progress(f"branch switching failed: load path again with {steps} steps")
    if steps != args.steps:
        redone.append(f"the {args.steps}-step path ended on the straight (unstable) branch; "
                      f"it was redone with {steps} steps")
else:
    # atol 1e-8 of the reference load: bent past 90°, the internal forces' round-off
    # reaches ~5e-9 of it (membrane forces ≫ the load), where modified Newton stalls
    solver = NewtonSolver(residual, w, bcs, method=args.newton, rtol=1e-8, atol=1e-8,
                          max_it=max_it, prefix=f"beam_{args.newton}_")
    continuation = ArcLength(solver, lambda lam: set_load(lam * P_euler),
                             arc_length=args.arc_length, switch=True,
                             prefix="beam_continuation_", mass=mass,
                             metric_dofs=fields.displacement_dofs if args.mixed else None,
                             multipliers=fields.pressure_dofs)
    say(f"arc-length path to P/P_Euler = {args.load_ratio:g} (first arc {args.arc_length:g})")
    path = continuation.run(args.load_ratio, 1000, progress=progress, progress_every=4,
                            on_step=lambda lam, r: record(lam / args.load_ratio, r))
    switched = path.switched
    critical = [{"kind": c.kind, "load_ratio": c.factor, "between": list(c.between)}
                for c in path.critical_points]
# -

# ### Against the elastica
#
# Tip rotation, lateral deflection and axial displacement at the last load.

# +
end = tip()  # the end state's
alpha = math.degrees(abs(end["rotation"]))
alpha_el = math.degrees(elastica.tip_rotation(args.load_ratio))
d_el, x_el = elastica.tip_position(args.load_ratio)
say(f"P/P_cr = {args.load_ratio:g}: tip rotation {alpha:.3f} deg (elastica "
    f"{alpha_el:.3f}), lateral deflection {abs(end['lateral']):.5g} (elastica "
    f"{d_el * L:.5g}), axial displacement {end['axial']:.5g} (elastica "
    f"{(x_el - 1) * L:.5g}); {len(path.factors)} steps, "
    f"{path.iterations} Newton iterations, {path.failures} step cuts")
reactions = boundary.reactions(residual, w, {"clamp": clamped}, space=V if args.mixed else None)
out = {
    "critical_load": P_slepc, "critical_loads": loads, "euler_critical_load": P_euler,
    "critical_load_rel_error": P_slepc / P_euler - 1, "load_ratio": args.load_ratio,
    "tip_rotation_deg": alpha, "tip_deflection": abs(end["lateral"]),
    "tip_axial_displacement": end["axial"], "elastica_tip_rotation_deg": alpha_el,
    "elastica_tip_deflection": d_el * L, "elastica_tip_axial_displacement": (x_el - 1) * L,
    "load_steps": len(path.factors), "step_cuts": path.failures,
    "newton_iterations": sum(r.iterations for r in path.results),
    "factorizations": path.work.factorizations, "branch_switched": switched,
    "path_control": args.path, "critical_points": critical,
    "inertia_factorizations": getattr(path, "inertia_factorizations", 0),
    "newton": args.newton, "mixed": args.mixed, "reactions": reactions,
    "reactions_of": "the beam, per unit width", "dofs": output.dofs(W), "ranks": comm.size,
    "path": [{"load_ratio": x[0], "tip_rotation_deg": x[1], "tip_deflection": x[2]}
             for x in history],
    "warnings": ["the elastica is inextensible and shear-free: the FE beam differs from it "
                 "by O((h/L)²)", *redone],
}
# -

# ## Outputs
#
# The JSON (above), and when asked the final displacement for ParaView, the load path
# against the elastica and the deformed shapes.


writers = []  # (--output: the fields of every converged step were written as they came)
if args.plot:
    writers.append(lambda: continuation_pictures.path_against_elastica(
        history, L, h, args.imperfection, args.load_ratio, args.plot))
if args.png:
    writers.append(lambda: continuation_pictures.shapes_against_elastica(
        shapes, L, args.imperfection, args.load_ratio, args.png))
cli.results(out, writers)
