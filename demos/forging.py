# # Closed-die forging in 3D: a billet pressed into a die cavity with a flash gap
#
# The course's forming example (a steering knuckle forged hot, computed with Forge3) is
# plasticity, finite strain and contact with friction at once, on a die whose cavity the
# metal must fill. Here a cylindrical billet is forged between two identical dies, each
# with an elongated cavity (an oval, longer along $x$ than across) cut into a flat land.
# The metal first upsets under the cavity's ceiling, reaches the cavity's walls across,
# flows along the cavity to its ends, and the excess escapes between the lands: the
# **flash**, whose thin gap and friction hold the pressure that fills the cavity.
#
# ## Problem definition
#
# A billet of radius $R_0$ and height $h_0$, J2 plasticity at finite strain
# (`fenics_nl.materials.finite_plasticity`: $F = F_e F_p$, Hencky's energy, linear
# hardening). The dies are rigid and symmetric about the billet's mid-plane, and the cavity
# about the planes $x = 0$ and $y = 0$: an eighth of the billet is computed. The upper die
# is the surface $z = Z + h(x, y)$: $h = D$ on the cavity's ceiling, $h = 0$ on the land
# beyond the cavity's outline, the ellipse of semi-axes $a$ (along $x$) and $b$, and a
# smooth wall of width $w$ between. The die goes down by $d$: $Z = h_0/2 - D - d$.
#
# **Contact** is a penalty energy on the billet's top and side (`fenics_nl.contact.penalty`):
# a point at $\varphi = X + u$ has the gap $g = (Z + h(\varphi_x, \varphi_y) -
# \varphi_z)/\sqrt{1 + |\nabla h|^2}$ along the die's normal $n$, and
# $\Pi_c = \int \tfrac{\kappa}{2}\langle -g\rangle^2\,dS$; the pressure
# $p = \kappa\langle -g\rangle$. **Friction**: Coulomb's law regularized over a slip
# $\varepsilon$, $t_f = -f p\, \Delta s_t / \sqrt{|\Delta s_t|^2 + \varepsilon^2}$,
# $\Delta s_t$ the tangential slip on the die since the step's start, in rate form:
# $\varepsilon$ = `--slip-ratio` $\cdot |\Delta Z|$, the die's travel in the step, so that the law
# compares the slip's rate with the die's and does not change with the steps (an $\varepsilon$
# fixed in length made the die fill 0.880, 0.901, 0.939 in 20, 40, 80 steps at 3417
# unknowns; in rate form 0.879, 0.888, 0.890: `benchmarks/results/forging_3d_fixed_slip.json`
# against `forging_3d.json`). (The project's
# active-set contact prescribes $u_n = \gamma$ along one coordinate axis; a die with walls
# has a normal that turns, which the penalty's UFL gap carries: Forge3's choice too.)
#
# **Checks.** Until the billet's radius reaches the ceiling's edge $b - w$, its top sees a
# flat die: without friction the compression is homogeneous and the force is the
# upsetting's closed form $F = \sigma_y(p)\,\pi R_0^2\,h_0/h$, with
# $\ln(h_0/h) = p + \sigma_y(p)/E$. At the end, the slab method of the flash (a strip of
# width $w_f$ and gap $t$, Coulomb friction) estimates the load,
# $F \approx \sigma_f[(1 + 2 f w_f/t) A_c + (1 + f w_f/t) A_f]$, $A_c$ the cavity's and
# $A_f$ the flash's area in plan, $\sigma_f = 2\sigma_y/\sqrt3$ (plane strain). The volume
# is kept by the plastic flow, to the elastic change.
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
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.contact import penalty
from fenics_nl.domain import boundary
from fenics_nl.domain.meshes import quarter_cylinder
from fenics_nl.io import cli, output
from fenics_nl.io.cli import say
from fenics_nl.io.parameters import Parameters, choice, number
from fenics_nl.materials import kinematics
from fenics_nl.materials.finite_plasticity import FiniteJ2Plasticity
from fenics_nl.parallel import global_max
from fenics_nl.plots import plasticity as plasticity_pictures
from fenics_nl.solvers.loading import solve_incrementally
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.theory import forming

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

comm = MPI.COMM_WORLD
# -

# ### Parameters
#
# From the command line (`python demos/forging.py --help`); in a notebook, the defaults: a
# steel billet as high as it is wide, a cavity 31 × 25 × 2·3.5 deep, $f = 0.2$.

# +
@dataclass
class ForgingParameters(Parameters):
    """A cylindrical billet forged between two dies with an elongated cavity and a flash
    land: J2 plasticity at finite strain, penalty contact with Coulomb friction, in 3D (an
    eighth of the billet). Units are the user's, consistent (e.g. N, mm, MPa)."""

    EPILOG = "PETSc options take the prefix -forging_, e.g. -forging_ksp_view."
    OUTPUTS: ClassVar = {"png": "the forged part coloured by the cumulated plastic strain, "
                                "the dies' cavity outline",
                         "plot": "the load against the stroke, with the frictionless "
                                 "closed form of the flat start and the slab estimate",
                         "output": "the displacement and the cumulated plastic strain "
                                   "(each cell's largest)"}

    friction: float = number(0.2, "Coulomb friction coefficient f on the dies (0: "
                             "frictionless)", at_least=0)
    reduction: float = number(0.42, "the stroke: final height reduction of the billet under "
                              "the cavity's ceiling, 1 - h/h0", above=0)
    radius: float = number(10.0, "billet radius R0", unit="length", above=0)
    height: float = number(20.0, "billet height h0", unit="length", above=0)
    cavity_length: float = number(31.0, "the cavity's length along x, 2a",
                                  unit="length", above=0)
    cavity_width: float = number(25.0, "the cavity's width along y, 2b", unit="length",
                                 above=0)
    cavity_depth: float = number(3.5, "the cavity's depth D in each die", unit="length",
                                 above=0)
    wall: float = number(1.5, "the width w of the cavity's wall, from the land to the "
                         "ceiling", unit="length", above=0)
    E: float = number(200e3, "Young's modulus", unit="stress", above=0)
    nu: float = number(0.3, "Poisson's ratio", unit="-")
    sigma0: float = number(400.0, "initial yield stress", unit="stress", above=0)
    hardening: float = number(1000.0, "linear isotropic hardening modulus H", unit="stress",
                              at_least=0)
    steps: int = number(20, "steps of the stroke, the first one ramped up from an eighth "
                        "of a step (a step that fails is cut)", at_least=1)
    size: float = number(2.5, "tetrahedra's size (P2 displacements)", unit="length",
                         above=0)
    penalty: float = number(3.0, "the penalty's stiffness kappa, in E/size", above=0)
    slip_ratio: float = number(0.05, "friction's regularization: the slip below which it "
                               "sticks elastically, as a fraction of the die's travel in "
                               "the step (a rate form: the law does not change with "
                               "--steps)", above=0)
    linear_solver: str = choice("lu", ["lu", "gamg"], "MUMPS LU, or GMRES + GAMG (the "
                                "rigid-body modes as near-nullspace): cheaper per Newton "
                                "iteration from about 50k unknowns")

    def check(self):
        b, w = self.cavity_width / 2, self.wall
        if not w < b - self.radius:
            raise ValueError(f"the billet (radius {self.radius:g}) must fit under the "
                             f"cavity's flat ceiling: --wall must be below "
                             f"{b - self.radius:g} (cavity half-width minus radius)")
        if not self.cavity_length >= self.cavity_width:
            raise ValueError("--cavity-length must be at least --cavity-width (the cavity "
                             "is elongated along x)")
        if not self.reduction < 1 - 2 * self.cavity_depth / self.height:
            raise ValueError(f"--reduction must be below "
                             f"{1 - 2 * self.cavity_depth / self.height:.3g}: the lands "
                             f"would meet")


args = cli.arguments(ForgingParameters, prefixes={"forging_": "Newton's KSP"})
R0, h0, D = args.radius, args.height, args.cavity_depth
a, b, w = args.cavity_length / 2, args.cavity_width / 2, args.wall
# -

# ### The mesh and its tags
#
# The eighth $x, y \ge 0$, $0 < z < h_0/2$ of the billet (`domain.meshes.quarter_cylinder`):
# P2-curved tetrahedra, its faces tagged `top`, `side`, `mid` ($z = 0$), `x0`, `y0`.

# +
mesh_data = quarter_cylinder(comm, R0, h0 / 2, args.size)
msh = mesh_data.mesh


def tagged(name):
    """The facets of the group `name`."""
    return mesh_data.facet_tags.find(mesh_data.physical_groups[name].tag)


# -

# ### The function space and the symmetry planes
#
# P2 displacements; the planes $x = 0$, $y = 0$ and the mid-plane hold the normal component.

# +
V = fem.functionspace(msh, ("Lagrange", 2, (3,)))
u = fem.Function(V, name="displacement")
v = ufl.TestFunction(V)
u_start = fem.Function(V)  # u at the step's start: the slip is measured from it
supports = [boundary.component(V, 0, tagged("x0")), boundary.component(V, 1, tagged("y0")),
            boundary.component(V, 2, tagged("mid"))]
# -

# ### The material
#
# The plastic state (the plastic metric $C_p^{-1}$ and $p$) at the quadrature points of
# the degree-2 rule, committed when a step converges; the first Piola stress is UFL's
# derivative of the step's condensed energy.

# +
material = FiniteJ2Plasticity(args.E, args.nu, sigma0=args.sigma0, H=args.hardening)
material.bind(msh, 2)
dx = kinematics.quadrature_measure("dx", msh, 2)
# -

# ### The die
#
# The cavity's shape $h(x, y)$: how far a point is inside the oval outline,
# $s = b\,(1 - \sqrt{(x/a)^2 + (y/b)^2})$, and a smooth step
# $\tau^3(10 - 15\tau + 6\tau^2)$, $\tau = s/w$ clipped to $[0, 1]$, from the land to
# the ceiling: $h$ has continuous second derivatives, so the die's normal and its
# derivative, in Newton's tangent, have no jump.
# The die's height $Z$ is a Constant set at each step.

# +
def inside_outline(x, y, tiny=1e-9):
    """s: how far (x, y) is inside the cavity's oval outline (negative outside), along y.

    s = b (1 − √((x/a)² + (y/b)²)): smooth everywhere (a stadium's distance is not: its
    curvature jumps where the arc meets the straight, and so would the die's normal).
    """
    return b * (1 - ufl.sqrt((x / a) ** 2 + (y / b) ** 2 + tiny**2))


def cavity(lateral):
    """h(x, y): D on the ceiling, 0 on the land, a C² wall between (Newton sees no kink)."""
    tau = ufl.min_value(ufl.max_value(inside_outline(lateral[0], lateral[1]) / w, 0), 1)
    return D * tau**3 * (10 - 15 * tau + 6 * tau**2)


Z = fem.Constant(msh, 0.5 * h0 - D)  # the land's height; the ceiling at Z + D
Z_start = fem.Constant(msh, 0.5 * h0 - D)  # at the step's start
# -

# ### The residual
#
# The virtual work of the first Piola stress, the variation of the penalty energy on the
# top and the side (`S_C`: the side folds onto the land as the flash), and the friction
# traction's work. The penalty's stiffness is $\kappa$ = `--penalty` $\cdot E/$`--size`:
# the penetration $p/\kappa$ is then about $10^{-3}$ of a cell at $p \approx 2\sigma_y$.

# +
S_C = np.union1d(tagged("top"), tagged("side"))
S_C_tags = mesh.meshtags(msh, 2, S_C, np.ones(len(S_C), dtype=np.int32))
ds = ufl.Measure("ds", msh, subdomain_data=S_C_tags, metadata={"quadrature_degree": 4})(1)
X = ufl.SpatialCoordinate(msh)
gap, n = penalty.die_gap(X + u, cavity, Z)
# the parameters as Constants: one compiled form for every f, κ and ε
kappa = fem.Constant(msh, args.penalty * args.E / args.size)
f, slip_ratio = fem.Constant(msh, args.friction), fem.Constant(msh, args.slip_ratio)
eps = slip_ratio * abs(Z - Z_start)  # the rate form: a fraction of the die's travel
p_contact = penalty.pressure(gap, kappa)
slip = u - u_start - (Z - Z_start) * ufl.as_vector([0, 0, 1])
t_friction = penalty.friction_traction(p_contact, n, slip, f, eps)
residual = (ufl.inner(material.first_piola(u, "3d"), ufl.grad(v)) * dx
            + ufl.derivative(penalty.penalty_energy(gap, kappa) * ds, u, v)
            - ufl.dot(t_friction, v) * ds)
press_force = p_contact * n[2] - t_friction[2]  # the die's vertical load per unit area
# -

# ### The solver and the load steps
#
# Newton's method with the full tangent (UFL's derivative of the residual: the penalty's,
# the friction's, not symmetric, and the material's), MUMPS LU (`--linear-solver gamg`:
# GMRES + GAMG, for large meshes), a line search on $\|R\|$. The die goes down in
# `--steps` steps, the first one an eighth of a step, each next 1.5 times the last up to a
# full one; each starts from the extrapolation of the last two converged states (the
# driver's predictor: without it, the first iterate of a step presses the side's top edge
# far into the die and Newton crawls back), and a step that fails is cut in half. A
# converged step commits the plastic state, measures the die's load (friction's part needs
# the step's slip) and moves the slip's origin to its state.

# +
newton = NewtonSolver(residual, u, supports, rtol=1e-8, atol=1e-8,
                      force_scale=args.sigma0 * R0**2, max_it=25, line_search=True,
                      linear_solver=args.linear_solver, prefix="forging_",
                      indefinite=True)  # with GAMG: GMRES, friction's tangent is not symmetric
stroke = args.reduction * 0.5 * h0  # the die's travel
dofs = output.dofs(V)
say(f"billet R0 = {R0:g}, h0 = {h0:g}; cavity {args.cavity_length:g} x {args.cavity_width:g}"
    f" x {D:g} deep; f = {args.friction:g}: {dofs} unknowns")
cli.known(dofs=dofs, ranks=comm.size)


def set_stroke(t):
    """The die at the load factor t: down by t · stroke."""
    Z.value = 0.5 * h0 - D - t * stroke


def commit():
    """A converged step: the plastic state (it may refuse the step), the load (friction's
    part needs the step's slip: before the slip's origin moves), the slip's origin."""
    material.commit(u, "3d")
    load["now"] = comm.allreduce(fem.assemble_scalar(load_form))
    u_start.x.array[:] = u.x.array
    Z_start.value = float(Z.value)
# -

# ### What is measured
#
# The die's load (×4: the quarter), the plan area of the contact on the cavity's ceiling
# (the **die fill**: 1 when the metal covers the whole flat ceiling; the walls' corners
# are not in it), the metal outside the cavity's outline (the **flash**: its volume, and
# its reach $-s$ beyond the outline, the distance across the cavity's ends and $b/a$ of it
# along), the volume against the mesh's own.

# +
F_def = ufl.Identity(3) + ufl.grad(u)
J = ufl.det(F_def)
x_now = X + u
s_now = inside_outline(x_now[0], x_now[1])
plan = ufl.dot(J * ufl.inv(F_def).T * ufl.FacetNormal(msh), ufl.as_vector([0, 0, 1]))
touching = ufl.conditional(ufl.lt(gap, 0), 1, 0)
on_ceiling = ufl.conditional(ufl.ge(s_now, w), 1, 0)
# the die's load: assembled in `commit`, while the step's slip (friction's part) is there
load_form, load = fem.form(4 * press_force * ds), {}
forms = {"ceiling": fem.form(touching * on_ceiling * plan * ds),
         "land": fem.form(touching * ufl.conditional(ufl.le(s_now, 0), 1, 0) * plan * ds),
         "flash": fem.form(8 * ufl.conditional(ufl.lt(s_now, 0), J, 0) * dx),
         "flash_p": fem.form(8 * ufl.conditional(ufl.lt(s_now, 0), J, 0)
                             * material.cumulated_plastic_strain * dx),
         "volume": fem.form(8 * J * dx)}
# the mesh's own volume (its P2 arc's, 1e-6 off π R0² h0): the volume change's reference
mesh_volume = comm.allreduce(fem.assemble_scalar(fem.form(fem.Constant(msh, 8.0) * dx)))
ceiling_area = math.pi * a * (b - w) ** 2 / b / 4  # the quarter's: semi-axes a(1 − w/b), b − w
nodes = V.tabulate_dof_coordinates()


def measured():
    """The load (`commit`'s), die fill, flash volume and reach, land area and volume."""
    values = {k: comm.allreduce(fem.assemble_scalar(f)) for k, f in forms.items()}
    x = nodes + u.x.array.reshape(-1, 3)
    # −s: how far beyond the outline, the distance across it (along x, b/a of it)
    outside = b * (np.hypot(x[:, 0] / a, x[:, 1] / b) - 1)
    return {"force": load["now"], "die_fill": values["ceiling"] / ceiling_area,
            "flash_volume": values["flash"], "flash_reach": max(0.0, global_max(comm, outside)),
            "flash_plastic_strain": values["flash_p"] / max(values["flash"], 1e-300),
            "flash_area": 4 * values["land"], "volume": values["volume"]}


history = []


def record(t, result):
    """One converged step: the load, the closed form of the flat start, the fill."""
    r = t * args.reduction
    step = {"load_factor": t, "reduction": r, "stroke": t * stroke, **measured(),
            "force_flat_die_exact": forming.frictionless_force(r, R0, material.yield_stress,
                                                               args.E),
            "under_ceiling_alone": R0 / math.sqrt(1 - r) < b - w,
            "newton_iterations": result.iterations,
            "krylov_iterations": result.work.krylov_iterations}
    history.append(step)
    cli.converged_step(step, lambda: [u, *material.output_fields()])
    say(f"  reduction {r:.3f}: F = {step['force']:.6g} (flat die, frictionless "
        f"{step['force_flat_die_exact']:.6g}), die fill {step['die_fill']:.3f}, flash "
        f"reach {step['flash_reach']:.3g}; {result.iterations} Newton iterations")


t0 = time.perf_counter()
run = solve_incrementally(newton, set_stroke, 8 * args.steps, adaptive=True,
                          max_step=1.0 / args.steps, easy_iterations=10**9, progress=say,
                          progress_every=10**9, commit=commit, on_step=record)
solve_time = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
# -

# ## Against the closed forms
#
# The flat start: while the billet is under the ceiling alone ($R_0\sqrt{h_0/h} < b - w$),
# the force against the homogeneous closed form (exact without friction; with friction
# above it). The end: the flash's slab estimate with the computed flash area and the
# land's gap. The volume, $8\int J\,dV$ against $\pi R_0^2 h_0$.

# +
last = history[-1]
flat = [h for h in history if h["under_ceiling_alone"]]
# (with friction the flat start is not homogeneous: the difference is friction's, no error)
flat_error = max((abs(h["force"] / h["force_flat_die_exact"] - 1) for h in flat),
                 default=None) if args.friction == 0 else None
gap_end = 2 * (0.5 * h0 - D - stroke)  # the flash's thickness between the lands
perimeter = math.pi * (3 * (a + b) - math.sqrt((3 * a + b) * (a + 3 * b)))  # Ramanujan
cavity_area = math.pi * a * b
slab = forming.flash_slab_force(material.yield_stress(last["flash_plastic_strain"]),
                                args.friction, cavity_area, last["flash_area"], perimeter,
                                gap_end)
p_cum = material.cumulated_plastic_strain
owned = p_cum.function_space.dofmap.index_map.size_local
max_plastic_strain = global_max(comm, p_cum.x.array[:owned])
volume_change = last["volume"] / mesh_volume - 1
if flat_error is not None:
    say(f"flat start ({len(flat)} steps): F within {flat_error:.2e} of the closed form")
flash_fraction = last["flash_volume"] / (math.pi * R0**2 * h0)
say(f"end: F = {last['force']:.6g} = {last['force'] / slab:.3f} x the flash's slab estimate "
    f"{slab:.6g}; die fill {last['die_fill']:.3f}; flash {flash_fraction:.3f} of the volume, "
    f"reaching {last['flash_reach']:.3g} beyond the outline; volume change "
    f"{volume_change:.2e}")
# -

# ## Outputs

# +
out = {"force": last["force"], "reduction": last["reduction"], "friction": args.friction,
       "force_history": [h["force"] for h in history],
       "stroke_history": [h["stroke"] for h in history],
       "reduction_history": [h["reduction"] for h in history],
       "die_fill": last["die_fill"], "die_fill_history": [h["die_fill"] for h in history],
       "flash_reach": last["flash_reach"], "penalty_stiffness": float(kappa.value),
       "flash_fraction": flash_fraction,
       "flash_area": last["flash_area"], "force_slab_estimate": slab,
       "force_over_slab": last["force"] / slab, "flat_steps": len(flat),
       "flat_force_error": flat_error, "max_plastic_strain": max_plastic_strain,
       "volume_change": volume_change, "newton_iterations": run.iterations,
       "step_cuts": run.failures, "factorizations": run.work.factorizations,
       "linear_solves": run.work.linear_solves,
       "krylov_iterations": run.work.krylov_iterations, "dofs": dofs, "ranks": comm.size,
       "solve_time_s": solve_time,
       **{f"{k}_phase_time_s": t for k, t in run.work.time.items()},  # where it went
       "warnings": ["the flash's slab estimate assumes Coulomb sliding on a strip of "
                    "uniform width: an estimate, not a closed form"]}
title = (f"closed-die forging to {100 * last['reduction']:.0f} %, f = {args.friction:g}: "
         f"F = {last['force']:.4g}, die fill {last['die_fill']:.2f}")


def picture():
    """The forged eighth, coloured by its plastic strain; the cavity's outline."""
    angle = np.linspace(0, 0.5 * math.pi, 40)  # the outline's quarter
    outline = np.column_stack([a * np.cos(angle), b * np.sin(angle)])
    plasticity_pictures.forging_picture(u, material.cumulated_plastic_strain_per_cell(),
                                        args.png, title, outline=outline,
                                        land=float(Z.value))
    say(f"wrote {args.png}")


def curve():
    """The load against the stroke."""
    if comm.rank == 0:
        plasticity_pictures.forging_load_curve(history, slab, args.plot, title)


cli.results(out, [*([picture] if args.png else []), *([curve] if args.plot else [])])
# -
