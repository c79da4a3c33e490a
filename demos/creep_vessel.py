# # A thick vessel creeping under a held pressure: from Lamé to the stationary state
#
# A long cylinder (plane strain) or a sphere of radii $a < b$, of a material that creeps
# (Norton's law), is loaded by an internal pressure $p$ applied quickly and then held. At
# first the stresses are Lamé's elastic ones; the material then flows, fastest where the
# stress is highest, and the stresses redistribute until they no longer change: the
# **stationary creep** state, where the hoop stress at the bore has fallen and the one at
# the outside has risen. Time is the load parameter, and the time steps are sized by their
# own error.
#
# ## Problem definition
#
# Norton's law: the viscous strain flows as $\dot\varepsilon^v = \tfrac32 A
# \sigma_{eq}^{n-1}\,\mathrm{dev}\,\sigma$ (uniaxially $\dot\varepsilon^v = A\sigma^n$),
# with $\sigma = \mathbb{C} : (\varepsilon - \varepsilon^v)$. Once the stresses no longer
# change the elastic strains are constant and the flow is incompressible; with $k = 2/n$
# (cylinder) or $3/n$ (sphere), for any elasticity (tension positive):
#
# $$ \sigma_{rr} = -p\,\frac{(b/r)^k - 1}{(b/a)^k - 1}, \qquad
#    \sigma_{\theta\theta} = p\,\frac{(k-1)(b/r)^k + 1}{(b/a)^k - 1}\ \text{(cylinder)},\quad
#    p\,\frac{(k/2-1)(b/r)^k + 1}{(b/a)^k - 1}\ \text{(sphere)}, $$
#
# Lamé's at $n = 1$. The bore then moves at a constant rate, $\dot u(a) = C/a$ (cylinder,
# $C = \tfrac{\sqrt3}{2} A b^2 [\tfrac{\sqrt3}{2} p k/((b/a)^k - 1)]^n$) or $C/a^2$
# (sphere, $C = \tfrac{A}{2} b^3 [p k/(2((b/a)^k - 1))]^n$): `fenics_nl.theory.vessels`.
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
from fenics_nl.materials.creep import NortonCreep
from fenics_nl.plots import plasticity as plasticity_pictures
from fenics_nl.solvers.loading import LoadStepError
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.solvers.time_stepping import LoadHistory, solve_in_time
from fenics_nl.theory import vessels

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

comm = MPI.COMM_WORLD
# -

# ### Parameters
#
# From the command line (`python demos/creep_vessel.py --help`); in a notebook, the
# defaults: a steel-like vessel at high temperature in N, mm, MPa and hours. PETSc options
# take the prefix `-creep_` (Newton's KSP).

# +
@dataclass
class CreepVessel(Parameters):
    """Thick cylinder or sphere of Norton creep under an internal pressure applied quickly
    and held: the stresses from Lamé's to the stationary creep state, against both closed
    forms, and the bore's stationary displacement rate. Units are the user's, consistent
    (e.g. N, mm, MPa, hours)."""

    EPILOG = "PETSc options take the prefix -creep_ (Newton's KSP), e.g. -creep_ksp_view."
    OUTPUTS: ClassVar = {"png": "the deformed quarter coloured by the cumulated viscous strain",
                         "plot": "the stress profiles at several times against Lamé and the "
                                 "stationary state, and the bore's stress and displacement "
                                 "against time"}
    CHECKPOINTS = True

    shape: str = choice("cylinder", ["cylinder", "sphere"],
                        "long cylinder (plane strain) or hollow sphere (axisymmetric)")
    inner_radius: float = number(100.0, "a", unit="length", above=0)
    outer_radius: float = number(200.0, "b", unit="length", above=0)
    E: float = number(200e3, "Young's modulus", unit="stress", above=0)
    nu: float = number(0.3, "Poisson's ratio", unit="-")
    A: float = number(5e-14, "Norton's coefficient: uniaxially dε/dt = A σ^n",
                      unit="1/(stress^n time)", above=0)
    n: float = number(5.0, "Norton's exponent (1: linear viscosity)", unit="-", at_least=1)
    pressure: float = number(30.0, "the internal pressure p", unit="stress", above=0)
    ramp: float = number(0.01, "the time over which p is applied (then held)", unit="time",
                         above=0)
    end: float | None = number(None, "the last time (default 40 relaxation times "
                               "1/(E A p^(n-1)))", unit="time", above=0)
    tolerance: float = number(1e-3, "the largest local error of a time step: 3μ Δt/2 "
                              "times the change of the viscous strain rate over it, over "
                              "the largest σ_eq", unit="-", above=0)
    steps: int = number(50, "with --fixed-steps, every time step is end/steps (else the "
                        "first), cut to land on the end of the ramp and the profiles' times",
                        at_least=1)
    fixed_steps: bool = switch("equal time steps end/steps (no error control; each step's "
                               "local error is still in the JSON)")
    stationary: float = number(1e-6, "the state is stationary once σ_eq, at its rate of "
                               "change, would change by less than this fraction of its "
                               "largest value over the time the pressure has been held",
                               unit="-", above=0)
    size: float | None = number(None, "element size (default (b - a)/10)", unit="length",
                                above=0)

    def check(self):
        if not self.inner_radius < self.outer_radius:
            raise ValueError(f"--inner-radius must be below --outer-radius, got "
                             f"{self.inner_radius:g} and {self.outer_radius:g}")
        if self.end is None:  # 40 relaxation times at the stress p: the stationary state
            self.end = 40 / (self.E * self.A * self.pressure ** (self.n - 1))
        if not self.ramp < self.end:
            raise ValueError(f"--ramp must be shorter than --end, got {self.ramp:g} and "
                             f"{self.end:g}")


args = cli.arguments(CreepVessel, prefixes={"creep_": "Newton's KSP"})
a, b, p, shape = args.inner_radius, args.outer_radius, args.pressure, args.shape
# the relaxation time at the stress p, the time scale of the redistribution (where σ_eq is
# 2.3 p, at the bore at first, the flow is 2.3ⁿ⁻¹ times faster); the run ends at `end`
tau, end = 1 / (args.E * args.A * p ** (args.n - 1)), args.end
QUADRATURE = 4  # the residual's and the state's rule: exact for P2's stiffness
# -

# ### The mesh and its tags
#
# The quarter $a < |x| < b$ of the $(x, y)$ plane (cylinder) or of the $(r, z)$ plane
# (sphere), triangles on curved edges (`quarter_annulus`: gmsh, its edges tagged `inner`,
# `outer`, `x0`, `y0`), 10 elements through the wall by default.

# +
model = "plane_strain" if shape == "cylinder" else "axisymmetric"
h = args.size or (b - a) / 10
mesh_data = quarter_annulus(comm, a, b, h)
msh = mesh_data.mesh


def tagged(name):
    """The facets of the physical group `name`."""
    return mesh_data.facet_tags.find(mesh_data.physical_groups[name].tag)


# -

# ### The function space and the boundary conditions
#
# Taylor–Hood: P2 displacements and a P1 mean stress. Stationary creep is an
# incompressible flow whose strain grows without bound; P2 displacements alone cannot
# follow it (their divergence error grows with the flow, and with it a spurious pressure:
# `tests/test_creep.py` measures their hoop stress at the bore drifting step after step
# where Taylor–Hood's stays at Lamé's). The symmetry lines hold their normal component.

# +
W = mixed.taylor_hood(msh, 2)
w = fem.Function(W, name="displacement_pressure")
(u, p_mean), (v, q) = ufl.split(w), ufl.TestFunctions(W)
V = W.sub(0)
U, u_dofs = mixed.collapsed(V)  # the displacement's own space, and its values in w
supports = [boundary.component(V, 0, tagged("x0")), boundary.component(V, 1, tagged("y0"))]
p_inner = fem.Constant(msh, 0.0)  # the pressure on the inner surface
# -

# ### The material
#
# `NortonCreep` integrates the flow over each time step $\Delta t$ by backward Euler from
# the committed viscous strain $\varepsilon^v_n$: with the trial deviator
# $s^{tr} = 2\mu\,\mathrm{dev}(\varepsilon - \varepsilon^v_n)$ and its equivalent stress
# $\sigma^{tr}_{eq}$, the step's equivalent stress $\sigma_{eq}$ solves
#
# $$ \sigma_{eq} + 3\mu A\,\Delta t\, \sigma_{eq}^n = \sigma^{tr}_{eq}, \qquad
#    \varepsilon^v = \varepsilon^v_n + \tfrac32 \frac{\sigma^{tr}_{eq} - \sigma_{eq}}{3\mu}\,
#    \frac{s^{tr}}{\sigma^{tr}_{eq}}, $$
#
# solved in UFL by Newton steps from an upper bound (`materials.creep.power_root`), so
# that $\sigma$ and the consistent tangent are UFL's derivatives through them. $\Delta t$ is
# a `fem.Constant` (`set_time_step`): one compiled form for every step; $\Delta t = 0$ is the
# instantaneous, elastic response. The state is committed when a step is accepted.

material = NortonCreep(args.E, args.nu, A=args.A, n=args.n)
material.bind(msh, QUADRATURE)  # its state at the quadrature points of dx

# ### The residual
#
# The variation of the mixed energy in $(u, p)$ (`materials.mixed.internal_work`: the
# law's deviatoric stress and $\kappa$, the flow being isochoric) and the pressure on
# the bore ($N$ the outward normal, into the cavity; $2\pi r$ for the sphere).

# +
dx = kinematics.quadrature_measure("dx", msh, QUADRATURE)
ds = ufl.Measure("ds", domain=msh, subdomain_data=mesh_data.facet_tags)
weight = kinematics.measure_weight(msh, model)  # 2πr for the sphere, else 1
N = ufl.FacetNormal(msh)
residual = (mixed.internal_work(material, u, p_mean, v, q, model) * dx
            + p_inner * ufl.dot(N, v) * weight * ds(mesh_data.physical_groups["inner"].tag))
# -

# ### The solver
#
# Full Newton on the consistent tangent, MUMPS; the absolute tolerance relative to the
# pressure's force on the bore.

solver = NewtonSolver(residual, w, supports, rtol=1e-10, atol=1e-10,
                      force_scale=p * (math.pi * a * a if shape == "sphere" else a),
                      prefix="creep_")

# ### What is measured
#
# Along $y = 0$, at nine radii from $a$ to $b$ (`Probes`): $\sigma_{rr}$ and the hoop
# stress (on the sphere's equator the meridional stress, equal to it), the stress of the
# committed state (between steps the law's $\Delta t$ is 0), and the bore's radial
# displacement.

# +
radii = np.linspace(a, b, 9)
probes = Probes(msh, [[r, 0.0] for r in radii])
sigma = mixed.cauchy_stress(material, u, p_mean, model)
displacement = fem.Function(U, name="displacement")


def profile():
    """(σ_rr, σ_θθ) at the nine radii."""
    s = np.array(probes.discontinuous("sigma", ufl.as_vector([sigma[0, 0], sigma[1, 1]]), 2))
    return s[:, 0], s[:, 1]


def displacement_now():
    """u as a Function of its own space (a copy of w's part)."""
    displacement.x.array[:] = w.x.array[u_dofs]
    return displacement


def bore_displacement():
    """u_r(a) at y = 0."""
    return probes.continuous(displacement_now())[0][0]


# -

# ### Time steps
#
# The load factor against time: 0 to 1 over the ramp, then held (`LoadHistory`). The
# steps land on the times whose profiles are drawn (`land_on`: 0.01, 0.1 and 1 relaxation
# time, and the end). `solve_in_time` sets the load and $\Delta t$, solves, commits, and
# estimates the step's local error from the change of the viscous strain rate over it
# (backward Euler is first order: the error is about half that change times $\Delta t$,
# here in units of the largest $\sigma_{eq}$); a step above the tolerance is undone (the
# displacement and the viscous state put back) and retaken shorter, the next one sized by
# $\Delta t \min(2, 0.9\sqrt{tol/e})$. Once the stresses no longer change, the state is
# stationary: said, and the steps grow to the end.

# +
profile_times = [t for t in (0.01 * tau, 0.1 * tau, tau) if args.ramp < t < end] + [
    end]
history = LoadHistory([(0.0, 0.0), (args.ramp, 1.0)])
times, bore_hoop, outer_hoop, bore_u, iterations = [0.0], [0.0], [0.0], [0.0], []
profiles = {}


def record(t, factor, result):
    sr, st = profile()
    times.append(t)
    bore_hoop.append(st[0])
    outer_hoop.append(st[-1])
    bore_u.append(bore_displacement())
    iterations.append(result.iterations)
    if t == args.ramp or t in profile_times:
        profiles[t] = (sr.tolist(), st.tolist())
    if len(iterations) % 10 == 0:
        say(f"  step {len(iterations)}: time {t:.4g}, hoop stress at the bore {st[0] / p:.4f} p")
    cli.converged_step({"load_factor": factor, "time": t, "bore_hoop_stress": st[0],
                        "outer_hoop_stress": st[-1], "bore_displacement": bore_u[-1],
                        "newton_iterations": result.iterations})


dofs = output.dofs(W)
say(f"{shape}, a = {a:g}, b = {b:g}, n = {args.n:g}, p = {p:g}: {dofs} unknowns; "
    f"relaxation time at the stress p, 1/(E A p^(n-1)) = {tau:.4g}; to time {end:.4g}")
cli.known(dofs=dofs, ranks=comm.size, relaxation_time=tau)
# --checkpoint saves the state after each accepted step (the displacement and pressure,
# the viscous state, the driver's last rate and σ_eq, the profiles drawn so far);
# --restart goes on from one as the uninterrupted run would have
checkpoints = cli.checkpointing(
    {"unknown": w, **material.state_functions()}, newton=solver,
    kept=lambda: {"profiles": [[t, *s] for t, s in profiles.items()]})
profiles.update({t: (sr, st) for t, sr, st in (checkpoints.kept or {}).get("profiles", [])})
for step in checkpoints.steps:
    times.append(step["time"])
    bore_hoop.append(step["bore_hoop_stress"])
    outer_hoop.append(step["outer_hoop_stress"])
    bore_u.append(step["bore_displacement"])
    iterations.append(step["newton_iterations"])
t0 = time.perf_counter()
try:
    run = solve_in_time(solver, material, lambda f: setattr(p_inner, "value", f * p),
                        history, end, args.steps, adaptive=not args.fixed_steps,
                        tolerance=args.tolerance, stationary=args.stationary,
                        land_on=profile_times, commit=lambda: material.commit(u, model),
                        on_step=record, **checkpoints.options,
                        # the steps undone or retried, and the stationary state
                        progress=lambda line: say(line) if line.startswith("  ") else None)
except LoadStepError as err:
    raise SolveError(f"time {err.target:.4g} not reached from {err.reached:.4g}: {err}") from err
solve_time = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
# -

# ### Against the closed forms
#
# Lamé's stresses at the end of the ramp, the stationary ones at the end, and the bore's
# displacement rate over the last step (in the stationary state backward Euler integrates
# it exactly). The differences at the nine points (on the boundary at $a$ and $b$) are
# the mesh's (0.3 % of p after the ramp, 0.12 % at the end with the defaults) and, after
# the ramp, some creep already: the ramp is short, but not against the flow at the bore,
# where $\sigma_{eq}$ is 2.3 p at first (about 0.2 % of p there).

# +
lame = vessels.elastic_stresses(shape, a, b, p, radii)[:2]
stationary_exact = vessels.stationary_creep_stresses(shape, a, b, p, args.n, radii)
errors = {}
for name, t_at, exact in (("lame", args.ramp, lame), ("stationary", end,
                                                      stationary_exact)):
    computed = profiles.get(t_at)
    if computed is not None:
        errors[name] = max(np.abs(np.array(computed[k]) - exact[k]).max()
                           for k in range(2)) / p
rate = (bore_u[-1] - bore_u[-2]) / (times[-1] - times[-2])
rate_exact = vessels.stationary_creep_bore_rate(shape, a, b, p, args.A, args.n)
say(f"{len(run.times)} steps ({run.rejected} undone for their error), "
    f"{sum(iterations)} Newton iterations, {solve_time:.3g} s")
if run.stationary_since is not None:  # settled within the step that ended there
    say(f"stationary between times {run.stationary_after:.4g} and {run.stationary_since:.4g} "
        f"({run.stationary_after / tau:.3g} and {run.stationary_since / tau:.3g} relaxation "
        "times)")
say(f"hoop stress at the bore: {profiles[args.ramp][1][0] / p:.4f} p after the ramp (Lamé "
    f"{lame[1][0] / p:.4f} p), {bore_hoop[-1] / p:.4f} p at the end (stationary "
    f"{stationary_exact[1][0] / p:.4f} p); outside {outer_hoop[-1] / p:.4f} p (stationary "
    f"{stationary_exact[1][-1] / p:.4f} p)")
say("largest error of σ_rr, σ_θθ along y = 0: " + ", ".join(
    f"{k} {100 * e:.3f} % of p" for k, e in errors.items()))
say(f"bore displacement rate at the end {rate:.6g} (stationary closed form "
    f"{rate_exact:.6g}, {100 * (rate / rate_exact - 1):+.3f} %)")
# -

# ## Outputs


def summary():
    """The quantities of the run, for --json."""
    out = {"shape": shape, "inner_radius": a, "outer_radius": b, "E": args.E, "nu": args.nu,
           "n": args.n, "A": args.A, "pressure": p, "ramp": args.ramp, "end": end,
           "relaxation_time": tau, "adaptive": not args.fixed_steps,
           "tolerance": args.tolerance, "local_errors": run.errors,
           "time": times[-1], "time_steps": len(run.times), "time_steps_undone": run.rejected,
           "step_cuts": run.failures, "newton_iterations": sum(iterations),
           "factorizations": run.work.factorizations,
           "stationary_since": run.stationary_since,
           "stationary_after": run.stationary_after, "stationary_measure": run.change,
           "bore_hoop_stress": bore_hoop[-1], "outer_hoop_stress": outer_hoop[-1],
           "bore_hoop_stress_stationary": float(stationary_exact[1][0]),
           "outer_hoop_stress_stationary": float(stationary_exact[1][-1]),
           "bore_hoop_stress_lame": float(lame[1][0]),
           "profile_error_lame": errors.get("lame"),
           "profile_error_stationary": errors.get("stationary"),
           "bore_displacement_rate": rate, "bore_displacement_rate_exact": rate_exact,
           "bore_displacement_rate_error": rate / rate_exact - 1,
           "profiles": {f"{t:.6g}": {"radius": radii.tolist(), "sigma_rr": s[0],
                                     "sigma_tt": s[1]} for t, s in profiles.items()},
           "element_size": h, "dofs": dofs, "ranks": comm.size, "solve_time_s": solve_time,
           "warnings": []}
    if run.stationary_since is None:
        out["warnings"].append(
            f"not stationary by time {times[-1]:.4g} ({times[-1] / tau:.3g} relaxation times): "
            f"at its last rate σ_eq would change by {run.change:.1e} of its largest value "
            f"over the time held (--stationary {args.stationary:g}); the errors against the "
            "stationary closed form are a state still moving towards it (a longer --end)")
    if h > (b - a) / 10 * (1 + 1e-9):
        out["warnings"].append(f"element size {h:.3g} above the validated (b - a)/10: the "
                               "stress errors grow as h²")
    return out


def plot():
    plasticity_pictures.creep_vessel_figure(
        shape, a, b, p, args.n, tau, profiles, times, bore_hoop, outer_hoop, bore_u,
        rate_exact, args.plot)


def picture():
    """The cumulated viscous strain (each cell's largest) on the deformed quarter."""
    from fenics_nl.plots.deformed import deformed_picture

    deformed_picture(displacement_now(), material.output_fields()[0], args.png,
                     f"{shape}, n = {args.n:g}: time {times[-1]:.4g} = {times[-1] / tau:.3g} "
                     f"relaxation times, hoop stress at the bore {bore_hoop[-1] / p:.3f} p",
                     label="cumulated viscous strain", axes=("x (length)", "y (length)"))
    say(f"wrote {args.png}")


cli.results(summary(), [*([plot] if args.plot else []), *([picture] if args.png else [])])
