# # A thick pressure vessel in J2 plasticity: yield onset, plastic zone, limit load
#
# A hollow sphere (or a long cylinder) of radii $a < b$ is loaded by an internal pressure
# $p$ past its yield onset, towards its limit load, and unloaded. The material is von Mises
# plasticity (perfect by default), whose state at the quadrature points is committed when a
# load step converges.
#
# ## Problem definition
#
# Sphere, perfect plasticity (exact for every $\nu$): the inner surface yields at
# $p_e = \tfrac{2\sigma_0}{3}(1 - a^3/b^3)$; the plastic zone $a < r < c$ grows with
#
# $$ p = 2\sigma_0 \ln\frac{c}{a} + \frac{2\sigma_0}{3}\Big(1 - \frac{c^3}{b^3}\Big), $$
#
# until $c = b$ at the limit pressure $p_{lim} = 2\sigma_0 \ln(b/a)$; beyond it there is no
# equilibrium. After unloading (elastic, if no reverse yielding) the residual stresses are
# the loaded ones minus Lamé's elastic solution for the same pressure: at $r = a$,
# $\sigma_\theta^{res} = \sigma_0 - p - p\,(b^3 + 2a^3)/(2(b^3 - a^3))$.
# Cylinder in plane strain: $p_{lim} = \tfrac{2}{\sqrt3}\sigma_0 \ln(b/a)$ (exact); the yield
# onset follows from Lamé with $\sigma_z = \nu(\sigma_r + \sigma_\theta)$; the closed-form
# $c(p)$ assumes $\nu = 1/2$.
#
# ## Implementation

# +
import math
import time
from dataclasses import dataclass
from typing import ClassVar

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.domain.meshes import quarter_annulus
from fenics_nl.domain.probes import Probes
from fenics_nl.errors import SolveError
from fenics_nl.io import cli, output
from fenics_nl.io.cli import say
from fenics_nl.io.parameters import Parameters, choice, number, switch
from fenics_nl.materials import kinematics, mixed
from fenics_nl.materials.plasticity import J2Plasticity
from fenics_nl.plots import plasticity as plasticity_pictures
from fenics_nl.solvers.loading import LoadStepError, solve_incrementally
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.solvers.snes import SnesSolver
from fenics_nl.theory import vessels

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

comm = MPI.COMM_WORLD
# -

# ### Parameters
#
# From the command line (`python demos/pressure_vessel.py --help`); in a notebook, the
# defaults. PETSc options take the prefix `-vessel_` (Newton's KSP) or `-vessel_snes_`
# (`--newton snes`).

# +
@dataclass
class Vessel(Parameters):
    """Thick sphere or cylinder under internal pressure in J2 plasticity: yield onset,
    plastic zone, limit load and residual stresses against the closed forms. Units are the
    user's, consistent (e.g. N, mm, MPa)."""

    EPILOG = ("PETSc options take the prefix -vessel_ (Newton's KSP) or -vessel_snes_ "
              "(--newton snes), e.g. -vessel_ksp_view.")
    OUTPUTS: ClassVar = {"png": "the deformed quarter coloured by the cumulated plastic strain",
                         "plot": "pressure against inner displacement, with the closed "
                                 "forms"}
    CHECKPOINTS = True

    shape: str = choice("sphere", ["sphere", "cylinder"],
                        "hollow sphere (axisymmetric) or long cylinder (plane strain)")
    inner_radius: float = number(100.0, "a", unit="length", above=0)
    outer_radius: float = number(200.0, "b", unit="length", above=0)
    E: float = number(210e3, "Young's modulus", unit="stress", above=0)
    nu: float = number(0.3, "Poisson's ratio", unit="-")
    sigma0: float = number(250.0, "yield stress", unit="stress", above=0)
    hardening: float = number(0.0, "linear isotropic hardening modulus H (0: perfect)",
                              unit="stress", at_least=0)
    pressure_ratio: float | None = number(
        None, "pressure control: final pressure / limit pressure (default 0.9)", above=0,
        group="load")
    inner_displacement: float | None = number(
        None, "displacement control: final radial displacement of the inner surface; the "
        "pressure is read from its reaction", unit="length", above=0, group="load")
    unload: bool = switch("unload to zero afterwards")
    steps: int = number(10, "equal load steps from zero to the final load (as many to "
                        "unload); a step that fails is cut in half", at_least=1)
    newton: str = choice("full", ["full", "modified", "bfgs", "snes"],
                         "full: consistent tangent; modified: the elastic tangent, factorized "
                         "once (the course's choice); bfgs: quasi-Newton; snes: PETSc SNES "
                         "newtonls on the same residual and consistent tangent")
    size: float | None = number(None, "element size (default (b - a)/16)", unit="length",
                                above=0)
    mixed: bool = switch("Taylor–Hood P2–P1 displacement–pressure elements: no locking in the "
                         "isochoric plastic flow on coarse meshes; ν = 0.5 allowed")

    def check(self):
        if not self.inner_radius < self.outer_radius:
            raise ValueError(f"--inner-radius must be below --outer-radius, got "
                             f"{self.inner_radius:g} and {self.outer_radius:g}")
        if self.pressure_ratio is None and self.inner_displacement is None:
            self.pressure_ratio = 0.9


args = cli.arguments(Vessel, prefixes={"vessel_": "Newton's KSP", "vessel_snes_": "SNES"})
a, b = args.inner_radius, args.outer_radius
s0, shape = args.sigma0, args.shape
p_lim = vessels.limit_pressure(shape, a, b, s0)
p_e_exact = vessels.yield_onset_pressure(shape, a, b, s0, args.nu)
# -

# ### The mesh and its tags
#
# The quarter $a < |x| < b$ of the $(r, z)$ plane (sphere) or of the $(x, y)$ plane
# (cylinder), P2 triangles on curved edges (`quarter_annulus`: gmsh, its edges tagged
# `inner`, `outer`, `x0`, `y0`), 16 elements through the wall by default.

# +
model = "axisymmetric" if shape == "sphere" else "plane_strain"
h = args.size or (b - a) / 16
mesh_data = quarter_annulus(comm, a, b, h)
msh = mesh_data.mesh


def tagged(name):
    """The facets of the physical group `name`."""
    return mesh_data.facet_tags.find(mesh_data.physical_groups[name].tag)


# -

# ### The function space and the boundary conditions
#
# P2 displacements (with `--mixed`, Taylor–Hood: a P1 mean stress as a second unknown).
# The symmetry lines hold their normal component ($u_x = 0$ on $x = 0$, the sphere's axis;
# $u_y = 0$ on $y = 0$). The inner surface carries the pressure $p$ (`p_inner`, a
# `fem.Constant`), or
# with `--inner-displacement` a prescribed radial motion (`inner_motion`), whose reaction
# gives the pressure back.

# +
if args.mixed:
    W = mixed.taylor_hood(msh, 2)
    w = fem.Function(W, name="displacement_pressure")
    (u, p_mean), (v, q) = ufl.split(w), ufl.TestFunctions(W)
    V = W.sub(0)  # the displacement part: its dofs are numbered in w
    U, u_dofs = mixed.collapsed(V)  # its own space, and where its values sit in w
else:
    V = U = fem.functionspace(msh, ("Lagrange", 2, (2,)))
    w = u = fem.Function(V, name="displacement")
    v, u_dofs = ufl.TestFunction(V), slice(None)
supports = [boundary.component(V, 0, tagged("x0")), boundary.component(V, 1, tagged("y0"))]
p_inner = fem.Constant(msh, 0.0)  # the pressure on the inner surface
motion = fem.Function(U)  # the inner surface's prescribed displacement
inner_motion = fem.dirichletbc(motion, fem.locate_dofs_topological((V, U), 1, tagged("inner")),
                               V) if args.mixed else fem.dirichletbc(
    motion, fem.locate_dofs_topological(V, 1, tagged("inner")))


def move_inner(delta):
    """The radial displacement δ of the inner surface (tangential 0)."""
    motion.interpolate(lambda x: delta * x[:2] / np.hypot(x[0], x[1]))


# -

# ### The material
#
# J2 plasticity with linear isotropic hardening $H$ (perfect at $H = 0$). Over a load step
# from the committed state $(\varepsilon^p_n, p_n)$, the trial stress
# $\sigma^{tr} = \mathbb{C} : (\varepsilon - \varepsilon^p_n)$ is returned radially onto the
# yield surface when it lies outside it:
#
# $$ \Delta p = \frac{\langle \sigma^{tr}_{eq} - \sigma_0 - H p_n \rangle}{3\mu + H},
#    \qquad \sigma = \sigma^{tr} - 3\mu\,\Delta p\, \frac{s^{tr}}{\sigma^{tr}_{eq}}, $$
#
# ($\langle x \rangle = \max(x, 0)$, $\mu$ the shear modulus). This is the minimiser of
# the step's condensed energy, so $\sigma$ is its derivative with respect to $\varepsilon$
# and the consistent tangent its second derivative: UFL takes both
# (`fenics_nl.materials.plasticity`), and full Newton converges quadratically even in the
# plastic zone. The state lives at the quadrature points of the residual's rule and is
# committed only when a step has converged: a failed step leaves no trace.

material = J2Plasticity(args.E, args.nu, sigma0=s0, H=args.hardening)
material.bind(msh, 4)  # its state at the quadrature points of dx (degree 4: P2's 2 × 2)

# ### The residual
#
# $R(u; v) = \int_\Omega \sigma(\varepsilon(u)) : \varepsilon(v)\,d\Omega +
# \int_{r=a} p\,N \cdot v\,dS$ ($N$ the outward normal, into the cavity; $2\pi r$ in
# both for the sphere). With `--mixed`, the mean stress is an unknown too: the first term
# is the variation of $\Pi(u, p)$ (`fenics_nl.materials.mixed`).

# +
dx = kinematics.quadrature_measure("dx", msh, 4)
ds = ufl.Measure("ds", domain=msh, subdomain_data=mesh_data.facet_tags)
ds_inner = ds(mesh_data.physical_groups["inner"].tag)
weight = kinematics.measure_weight(msh, model)  # 2πr for the sphere, else 1
if args.mixed:
    internal = mixed.internal_work(material, u, p_mean, v, q, model)
else:
    eps = kinematics.small_strain(u, model)  # with the hoop strain u_r/r for the sphere
    internal = ufl.inner(material.stress(eps), kinematics.small_strain(v, model)) * weight
N = ufl.FacetNormal(msh)
residual = internal * dx + p_inner * ufl.dot(N, v) * weight * ds_inner
# -

# ### The solver
#
# Full Newton has the consistent tangent (UFL's derivative of the residual); modified
# Newton (and BFGS's base) is the course's choice, Hooke's elastic tangent, factorized once
# for the whole run; `--newton snes` is PETSc's newtonls on the same residual and consistent
# tangent, a cross-check. The absolute tolerance is relative to the limit load's force on
# the inner surface.
#
# The elastic tangent $K$ is stiffer than the material everywhere (plastic flow only
# softens: the Hessian of the step's convex energy $\Pi$ lies below $K$), so a step
# $\Delta u = -K^{-1} R$ lowers $\Pi$ by at least $\tfrac12 R^T K^{-1} R$: modified Newton
# converges at every load below the limit, at a rate that worsens as the plastic zone
# spreads (near the limit load the structure's stiffness tends to zero while $K$ stays).
# Full Newton needs a few iterations per step, each a new factorization; modified Newton
# many more, each only a back-substitution. `--newton modified` shows the iteration counts
# growing step after step.

# +
control = "pressure" if args.inner_displacement is None else "displacement"
bcs = supports + ([inner_motion] if control == "displacement" else [])
force = p_lim * (math.pi * a * a if shape == "sphere" else a)
elastic_tangent = (mixed.modified_newton_tangent(material, w, model, dx) if args.mixed
                   else material.modified_newton_tangent(u, model, dx))  # Hooke's


# The tangent is symmetric (associated flow: the Hessian of the step's energy), so MUMPS
# factorizes it as $LDL^T$: on this 2D mesh 15 % faster than LU on one rank, and 1.6x
# faster again on two (`benchmarks/sphere_ranks.py`; in 3D, LU is the faster).


def make_solver(bcs):
    """The --newton variant on the residual, with `bcs`."""
    if args.newton == "snes":
        return SnesSolver(residual, w, bcs, rtol=1e-10, atol=1e-10, force_scale=force,
                          linear_solver="cholesky", prefix="vessel_snes_")
    return NewtonSolver(residual, w, bcs, method=args.newton, rtol=1e-10, atol=1e-10,
                        force_scale=force, max_it=50 if args.newton == "full" else 500,
                        constant_tangent=elastic_tangent, linear_solver="cholesky",
                        prefix="vessel_")


solver = make_solver(bcs)
# -

# ### What is measured
#
# At the inner and outer points of $y = 0$ (`Probes`): the radial displacement $u(a)$, and
# $\sigma_{eq}$ and the hoop stress at $r = a$. The pressure under displacement control:
# the reaction across the symmetry plane that cuts the wall, which carries the pressure's
# resultant ($p\,\pi a^2$ for the sphere, $p\,a$ per unit length for the quarter cylinder;
# the inner support's own reaction would also hold the corner node it shares with that
# plane, an O(h) error).

# +
probes = Probes(msh, [[a, 0.0], [b, 0.0]])
displacement = fem.Function(U, name="displacement")


def displacement_now():
    """u as a Function of its own space (a copy of w's part if mixed)."""
    displacement.x.array[:] = w.x.array[u_dofs]
    return displacement


def inner_displacement():
    """u_r(a) at y = 0."""
    return probes.continuous(displacement_now())[0][0]


def stresses_at_inner():
    """(σ_eq, σ_θ) at r = a, y = 0."""
    sigma = (mixed.cauchy_stress(material, u, p_mean, model) if args.mixed
             else material.cauchy_stress(u, model))
    s_dev = ufl.dev(sigma)
    vm = probes.discontinuous("vm", ufl.sqrt(1.5 * ufl.inner(s_dev, s_dev)), 2)
    return vm[0], probes.discontinuous("hoop", sigma[1, 1], 2)[0]


def pressure_from_support():
    """p from the reaction across the symmetry plane that cuts the wall."""
    plane, axis = ("y0", 1) if shape == "sphere" else ("x0", 0)
    held = boundary.reactions(residual, w, {plane: tagged(plane)}, {plane: [axis]},
                              space=V)[plane][axis]
    return -held / (math.pi * a * a if shape == "sphere" else a)


# -

# ### Yield onset
#
# One elastic step at half the closed-form onset (any elastic load would do: σ_eq grows in
# proportion) gives σ_eq at the inner surface per unit pressure, hence $p_e$.

# +
p_inner.value = 0.5 * p_e_exact  # elastic: σ_eq grows in proportion to p
NewtonSolver(residual, w, supports, rtol=1e-10, atol=1e-10, force_scale=force,
             prefix="vessel_onset_").solve()
vm_a = stresses_at_inner()[0]
if vm_a >= s0:
    raise SolveError(f"the onset step yielded (σ_eq(a) = {vm_a:.4g} >= σ0): it must be elastic")
p_e = float(p_inner.value) * s0 / vm_a
w.x.array[:] = 0.0
p_inner.value = 0.0
dofs = output.dofs(w.function_space)
say(f"{shape}, a = {a:g}, b = {b:g}, {dofs} unknowns; yield onset p_e = {p_e:.6g} "
    f"(closed form {p_e_exact:.6g}), limit {p_lim:.6g}")
# -

# ### Load steps
#
# Pressure control from 0 to the final pressure (or displacement control of the inner
# surface); each converged step commits the plastic state. Past the limit load a pressure
# has no equilibrium: the run stops there, saying so.

# +
path = [(0.0, 0.0)]  # (pressure, u(a)) after each converged step
step_iterations = []
pressure_from_reaction = control == "displacement"


def record(t, result):
    p_now = pressure_from_support() if pressure_from_reaction else float(p_inner.value)
    path.append((p_now, inner_displacement()))
    step_iterations.append(result.iterations)
    cli.converged_step({"load_factor": p_now / target_pressure, "pressure": p_now,
                        "inner_displacement": path[-1][1],
                        "newton_iterations": result.iterations})
    say(f"  step {len(path) - 1}: p = {p_now:.6g} ({p_now / p_lim:.4f} p_lim), "
        f"u(a) = {path[-1][1]:.6g}, {result.iterations} Newton iterations")


def commit():
    material.commit(u, model)


cli.known(dofs=dofs, ranks=comm.size, limit_pressure_exact=p_lim,
          yield_onset_pressure_exact=p_e_exact)
target_pressure = args.pressure_ratio * p_lim if control == "pressure" else p_lim
if control == "pressure":
    target = args.pressure_ratio * p_lim

    def load(t):
        p_inner.value = t * target
else:
    target = args.inner_displacement

    def load(t):
        move_inner(t * target)

# a restart (--restart) puts the checkpoint's state back: the displacement, the plastic
# state, the steps so far; --checkpoint saves it after each converged step of the loading
# (a run killed while it unloads restarts from the peak: the unloading is redone)
checkpoints = cli.checkpointing({"unknown": u, **material.state_functions()},
                                newton=solver if args.newton != "snes" else None)
for step in checkpoints.steps:
    path.append((step["pressure"], step["inner_displacement"]))
    step_iterations.append(step["newton_iterations"])
t0 = time.perf_counter()
try:
    run = solve_incrementally(solver, load, args.steps, max_step=1.0 / args.steps,
                              on_step=record, commit=commit, **checkpoints.options)
except LoadStepError as err:
    last = path[-1][0]
    if control == "pressure" and target >= p_lim:
        raise SolveError(f"the limit load was reached: no equilibrium beyond p = {last:.6g} "
                         f"({last / p_lim:.4f} of the limit pressure {p_lim:.6g}); asked "
                         f"{target:.6g}") from err
    raise SolveError(f"{args.newton} Newton failed at {last / p_lim:.4f} p_lim, below the "
                     f"limit load: {err}") from err
solve_time = time.perf_counter() - t0  # the load steps only, for the benchmarks
pressure, inner = path[-1]
loaded = pressure  # the peak, also after unloading
if args.hardening == 0 and pressure > p_lim * (1 + 1e-3):
    # perfect plasticity has no equilibrium there: a discrete one means the elements lock
    # in the isochoric plastic flow (P2 with a few elements through the wall)
    raise SolveError(f"p = {pressure / p_lim:.4f} p_lim found an equilibrium beyond the limit "
                     f"pressure, which has none: the mesh locks (h = {h:.3g}, "
                     f"{(b - a) / h:.0f} elements through the wall); refine --size")
c_fe = material.plastic_radius(a)  # the largest |x| where p > 0 (or a)
c_exact = vessels.plastic_radius(shape, a, b, s0, min(pressure, p_lim))
say(f"p = {pressure:.6g} = {pressure / p_lim:.4f} p_lim; plastic radius {c_fe:.5g} "
    f"(closed form {c_exact:.5g}{', for ν = 1/2' if shape == 'cylinder' else ''}; "
    f"h = {h:.3g})")
# -

# ### Unloading
#
# Back to zero pressure in the same number of steps (elastic when nothing yields in
# reverse): the residual hoop stress at the inner surface, against the closed form.

# +
residual_hoop = None
if args.unload:
    if control == "displacement":  # the same state, now held by its pressure
        bcs.remove(inner_motion)
        solver = make_solver(bcs)
        pressure_from_reaction = False

    def unload(t):
        p_inner.value = (1 - t) * loaded

    p_inner.value = loaded
    t0 = time.perf_counter()
    back = solve_incrementally(solver, unload, args.steps, max_step=1.0 / args.steps,
                               on_step=record, commit=commit)
    solve_time += time.perf_counter() - t0
    run.work.add(back.work)
    run.failures += back.failures
    run.results.extend(back.results)
    residual_hoop = stresses_at_inner()[1]
    say(f"unloaded: permanent u(a) = {path[-1][1]:.6g}, residual hoop stress at r = a "
        f"{residual_hoop:.6g}" + (f" (closed form "
                                  f"{vessels.residual_hoop_stress_inner(a, b, s0, loaded):.6g}"
                                  f", if nothing yields in reverse)"
                                  if shape == "sphere" and args.hardening == 0 else ""))
# -

# ### Inner displacement against the closed form
#
# Sphere in perfect plasticity: u(a) of the monotonic loading is exact up to the limit
# (`vessels.sphere_inner_displacement`: Lamé in the elastic zone, volume-preserving flow in
# the plastic one); the unloading is elastic, Lamé's compliance. The cylinder has the elastic
# line only.

# +
solve_time = comm.allreduce(solve_time, op=MPI.MAX)
compliance = vessels.elastic_inner_compliance(shape, a, b, args.E, args.nu)
exact_curve = shape == "sphere" and args.hardening == 0 and loaded <= p_lim
inner_exact = (vessels.sphere_inner_displacement(a, b, args.E, args.nu, s0, loaded)
               if exact_curve else None)
if inner_exact is not None:
    say(f"u(a) at p = {loaded:.6g}: {inner:.6g} (closed form {inner_exact:.6g})")
# -

# ## Outputs


def summary():
    """The quantities of the run, for --json."""
    out = {"shape": shape, "control": control, "newton": args.newton, "mixed": args.mixed,
           "yield_onset_pressure": p_e, "yield_onset_pressure_exact": p_e_exact,
           "limit_pressure_exact": p_lim, "pressure": pressure,
           "plastic_radius": c_fe, "plastic_radius_exact": c_exact, "element_size": h,
           "inner_displacement": inner,
           "newton_iterations": run.iterations, "factorizations": run.work.factorizations,
           "iterations_per_step": step_iterations, "step_cuts": run.failures,
           "phase_time_s": run.work.time,
           "path": [{"pressure": q, "inner_displacement": d} for q, d in path],
           "dofs": dofs, "ranks": comm.size, "solve_time_s": solve_time, "warnings": []}
    if inner_exact is not None:
        out["inner_displacement_exact"] = inner_exact
    if shape == "cylinder":
        out["warnings"].append("cylinder: the closed-form plastic radius assumes ν = 1/2")
    if args.hardening > 0:
        out["warnings"].append("hardening: the closed forms are for perfect plasticity")
    if residual_hoop is not None:
        out["residual_hoop_stress_inner"] = residual_hoop
        out["permanent_inner_displacement"] = path[-1][1]
        exact = vessels.residual_hoop_stress_inner(a, b, s0, loaded)
        if shape == "sphere" and args.hardening == 0 and abs(exact) <= s0:
            out["residual_hoop_stress_inner_exact"] = exact
        elif shape == "sphere":
            out["warnings"].append("the unloading yields in reverse (|σ_θ| would exceed σ0 at "
                                   "r = a, p > 2 p_e): the elastic-unloading closed form "
                                   "does not apply")
    return out


outcome = plasticity_pictures.VesselRun(
    shape, a, b, args.E, args.nu, s0, path, loaded, args.unload, p_lim, p_e_exact, c_fe,
    c_exact, compliance, exact_curve, inner, inner_exact)



def picture():
    """The plastic zone on the deformed quarter, and the path."""
    plasticity_pictures.vessel_plastic_zone(outcome, displacement_now(),
                                   material.cumulated_plastic_strain_per_cell(), args.png)
    say(f"wrote {args.png}")


cli.results(summary(), [*([lambda: plasticity_pictures.vessel_pressure_curve(outcome, args.plot)]
                          if args.plot else []), *([picture] if args.png else [])])
