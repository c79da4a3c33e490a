# # Rigid spherical punch on an elastic block: Hertz contact by the active-set method
#
# A rigid sphere of radius $R$ is pressed by $\delta$ into an elastic block, without
# friction. Where the two touch is not known in advance: the course's active-set algorithm
# finds it, and this demo writes its loop out. Hertz's theory gives the answer for a
# half-space and a parabolic gap, and the computation is checked against it. (With
# friction: `punch_friction.py`; a plastic block, loaded and unloaded: `indentation.py`.)
#
# ## Problem definition
#
# On the top surface $S_C$ (outward normal $n = e_z$) the gap to the punch is
# $\gamma(r) = r^2/(2R) - \delta$, and the unilateral conditions hold:
#
# $$ u_n - \gamma \le 0, \qquad T_n \le 0, \qquad (u_n - \gamma)\, T_n = 0 .$$
#
# Iteration $k$ of the active-set loop solves the equilibrium with $u_n = \gamma$ on the
# active nodes $S_C^{(k)}$ and $T = 0$ on the rest of $S_C$; then
#
# * an active node in tension ($T_n > 0$) leaves the set,
# * an inactive node that penetrates ($u_n - \gamma > 0$) joins it,
#
# and the loop stops when the set repeats. Hertz's solution, with $E^* = E/(1-\nu^2)$:
#
# $$ a = \sqrt{R\delta}, \qquad P = \tfrac43 E^* \sqrt{R}\, \delta^{3/2}, \qquad
#    p_0 = \frac{3P}{2\pi a^2}, \qquad p(r) = p_0\sqrt{1 - r^2/a^2}. $$
#
# In plane strain the punch is a cylinder and $\delta$ is not defined by Hertz (it depends
# on the block), so the half-width $a = \sqrt{4PR/(\pi E^*)}$ and $p_0 = 2P/(\pi a)$ are
# checked against the computed force per unit length $P$.
#
# ## Implementation

# +
from dataclasses import dataclass
from typing import ClassVar

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.contact import ContactError, ContactSurface, EliminationSystem, MultiplierSystem
from fenics_nl.contact.obstacles import Indentation, RigidPunch
from fenics_nl.contact.surface import check_contact_resolution
from fenics_nl.domain import boundary
from fenics_nl.domain.meshes import punch_block, punch_block_size
from fenics_nl.io import cli, output
from fenics_nl.io.parameters import choice, number
from fenics_nl.io.punch_parameters import PunchParameters, prefixes
from fenics_nl.materials import kinematics, mixed
from fenics_nl.materials.laws import LinearElastic, PowerLaw
from fenics_nl.parallel import global_max
from fenics_nl.plots import indentation as indentation_pictures
from fenics_nl.solvers.force_control import reach_force
from fenics_nl.theory import hertz

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

# -

# ### Parameters
#
# From the command line (`python demos/punch.py --help` lists them); in a notebook, the
# defaults (R = 1, δ = 0.01 R, E = 1, ν = 0.3, axisymmetric, one load step). The flags
# every punch demo has (the block, the load, the formulation) are
# `PunchParameters`; this one adds the material.

# +
@dataclass
class Hertz(PunchParameters):
    """Rigid spherical punch on an elastic block (Hertz contact, the course's active set).
    Units are the user's, consistent (e.g. N, m, Pa or N, mm, MPa)."""

    OUTPUTS: ClassVar = {
        "output": "displacement, von Mises stress, contact pressure and active set",
        "png": "the deformed contact zone (von Mises stress) beside the contact pressure, "
               "against Hertz",
        "plot": "force-indentation and pressure against Hertz"}
    CHECKPOINTS = False  # elastic and frictionless: no history to restart from

    material: str = choice("linear", ["linear", "power-law"], "linear elastic (Hertz "
                           "applies), or the power law (a Newton loop inside every "
                           "active-set iteration)")
    sigma0: float | None = number(None, "power law: stress where it turns non-linear "
                                  "(default 0.01)", unit="stress", above=0)
    n: float | None = number(None, "power law exponent (default 0.3)", unit="-", above=0)

    def check(self):
        super().check()
        self.material_flags(power_law={"sigma0": 0.01, "n": 0.3})


args = cli.arguments(Hertz, prefixes=lambda a: prefixes(a.model, a.formulation))
R, model = args.radius, args.model
# -

# ### The mesh and its tags
#
# The block must behave like Hertz's half-space: it is 1000 contact radii wide and deep
# (100 in 3D), with elements of a/40 under the punch (plane strain a/80, 3D a/12) within
# 1.5 a of the axis, growing by 5 % of the distance away from it (plane strain 20 %, 3D
# 10 %). On the axisymmetric model this keeps the block-size and far-field error near
# 0.15 %, below the 0.5 % asked of the force (measured in `benchmarks/contact.py`). The
# mesh is made for Hertz's contact radius of the load by `punch_block` (gmsh), which tags
# its facets: `contact` (the top, $S_C$), `bottom`, `symmetry_x`, `symmetry_y` (3D) and
# `side`.

# +
a = hertz.contact_radius_for(model, args.E, args.nu, R, args.indentation, args.force)
dim = 3 if model == "3d" else 2
vertical = dim - 1  # z in 3D, y in 2D: S_C's normal axis
size = punch_block_size(model, args.block)
cli.say(f"meshing the {model} block ({size:g} contact radii) ...")
mesh_data, h = punch_block(MPI.COMM_WORLD, model, a, refine=args.refine, size=size)
msh = mesh_data.mesh


def tagged(name):
    """The facets of the physical group `name`."""
    return mesh_data.facet_tags.find(mesh_data.physical_groups[name].tag)


# the whole body's force over the modelled part's (2πr is in the axisymmetric residual)
symmetry = {"axisymmetric": 1.0, "3d": 4.0, "plane_strain": 2.0}[model]
# -

# ### The function space and the boundary conditions
#
# P1 displacements (with `--mixed`, Taylor–Hood: P2 displacements and a P1 pressure $p$
# as a second unknown). The bottom slides on a rigid base ($u_z = 0$), the symmetry planes
# hold their normal component. The contact conditions on $S_C$ come with the active set.

# +
degree = 2 if args.mixed else 1
if args.mixed:
    W = mixed.taylor_hood(msh, degree)
    w = fem.Function(W, name="displacement_pressure")
    (u, p), (v, q) = ufl.split(w), ufl.TestFunctions(W)
    V = W.sub(0)  # the displacement part: its dofs are numbered in w
else:
    V = fem.functionspace(msh, ("Lagrange", degree, (dim,)))
    w = u = fem.Function(V, name="displacement")
    v = ufl.TestFunction(V)
parts = mixed.unknown_of(w)  # u (and p) as Functions of their own, to write out
bcs = [boundary.component(V, vertical, tagged("bottom")),
       boundary.component(V, 0, tagged("symmetry_x"))]
if dim == 3:
    bcs.append(boundary.component(V, 1, tagged("symmetry_y")))
# -

# ### The material and the residual
#
# A free energy $\varphi(\varepsilon)$; the stress $\sigma = \partial\varphi/\partial
# \varepsilon$ and its tangent are derived from it by UFL. The residual is
#
# $$ R(u; v) = \int_\Omega \sigma(\varepsilon(u)) : \varepsilon(v)\,d\Omega, $$
#
# with no external load: the punch acts only through the contact conditions. In the
# axisymmetric model $\varepsilon$ has the hoop strain $u_r/r$ and the weight is $2\pi r$,
# so that $R$ is the whole body's. With `--mixed`, $R$ is the variation of
# $\Pi(u, p) = \int \tilde\varphi(\varepsilon) + p\,\mathrm{tr}\,\varepsilon - p^2/(2\kappa)$,
# which holds at $\kappa = \infty$ ($\nu = 1/2$).

# +
material = (LinearElastic(args.E, args.nu) if args.material == "linear"
            else PowerLaw(args.E, args.nu, sigma0=args.sigma0, n=args.n))
kinematic = "3d" if dim == 3 else model  # the strain model: hoop strain if axisymmetric
# degree 2p: exact for Hooke's law on plane and 3D cells (not for the r and 1/r of the
# axisymmetric terms; the block-size error dominates there, `benchmarks/contact.py`)
dx = kinematics.quadrature_measure("dx", msh, 2 * degree)


def eps(z):
    return kinematics.small_strain(z, kinematic)


weight = kinematics.measure_weight(msh, kinematic)  # 2πr, or 1
if args.mixed:
    residual = mixed.internal_work(material, u, p, v, q, kinematic) * dx
else:
    residual = ufl.inner(material.stress(eps(u)), eps(v)) * weight * dx
# -

# ### The contact surface and one active-set iteration
#
# The punch (`RigidPunch`: its surface's height $h(r)$ above $S_C$ at the distance $r$ from
# its axis) gives the gap $\gamma(x) = h(r) - \delta$. `ContactSurface` holds the nodes of
# $S_C$ (the normal component's dofs on the `contact` facets), their gap and their areas.
# A *system* solves one iteration for a given set: `set_active(active)` prescribes
# $u_n = \gamma$ on the active nodes (as Dirichlet rows, or with `--formulation multiplier`
# through Lagrange multipliers on a facet submesh, the course's saddle point
# $[K\ {-A};\ {-A^T}\ 0]$), `solve()` runs Newton on the residual (one linear solve for the
# linear material; after the first iteration, a factorization updated by the rows that
# changed), `normal_forces()` gives $T_n$ at the nodes. Newton's absolute tolerance is
# scaled by Hertz's force for the expected $a$.


# +
punch = RigidPunch(R, dim, args.gap)  # its height h(r) above S_C: Hertz's r²/(2R), or the sphere
gap = punch.gap  # γ(x) = h(r) − δ for the punch pressed by δ
radius_of = punch.distance  # r, the distance of points (n × 3) from the punch's axis


surface = ContactSurface(V, tagged("contact"), gap(0.0), normal_axis=vertical,
                         unknown_space=w.function_space)
E_star = hertz.effective_modulus(args.E, args.nu)
P_scale = (np.pi / 4 * E_star * a * a / R if model == "plane_strain"
           else 4 / 3 * E_star * a**3 / R)
newton = {"rtol": 1e-10, "max_it": 50, "line_search": not material.is_linear,
          "force_scale": P_scale / symmetry}
if args.mixed and args.formulation == "elimination":  # a symmetric saddle point: LDLᵀ
    newton.update(linear_solver="cholesky")
System = EliminationSystem if args.formulation == "elimination" else MultiplierSystem
system = System(residual, w, bcs, surface, prefix=f"punch_{model}_{args.formulation[:4]}_",
                **newton)
cli.say(f"{model} punch, {args.formulation}, {output.dofs(w.function_space)} unknowns, "
        f"h = {h:.3g}")
# -

# ### The active-set loop
#
# The course's loop, at a given position of the punch: solve with the current set, apply
# the two rules, stop when the set repeats. The thresholds of the rules are round-off
# levels of the problem's own scales (the largest contact force, the larger of the gap and
# the displacement). A set that comes back after it changed would make the loop cycle: it
# is an error, not a result. The set is kept as a boolean array over the nodes of $S_C$,
# equal on the ranks that share a node (`surface.sync`), and shown as DOLFINx meshtags of
# the active facets at the end.


# +
def active_set_loop(active, verbose):
    """The settled set from `active`, its forces T_n, and the work it took."""
    work, seen, changes = {"iterations": 0, "newton": 0, "factorizations": 0}, set(), None
    for k in range(1, 51):
        system.set_active(active, changes)  # u_n = γ on S_C^(k), T = 0 elsewhere
        result = system.solve()
        work["iterations"], work["newton"] = k, work["newton"] + result.iterations
        work["factorizations"] += result.work.factorizations
        T_n, penetration = system.normal_forces(), surface.normal_gap(w)
        scale_u = max(global_max(msh.comm, np.abs(surface.gamma)),
                      surface.displacement_scale(w))
        leave = active & (T_n > 1e-10 * global_max(msh.comm, np.abs(T_n)))  # in tension
        join = ~active & (penetration > 1e-10 * scale_u)  # penetrating
        if verbose:
            cli.say(f"    S_C^({k}): {surface.count(active)} active nodes; "
                    f"{surface.count(leave)} leave (T_n > 0), {surface.count(join)} join "
                    f"(u_n > γ)")
        new = surface.sync((active & ~leave) | join)
        changes = surface.count(new != active)
        if changes == 0:
            return active, T_n, work
        if surface.fingerprint(new) in seen:
            raise ContactError(f"the active set cycles (iteration {k})")
        seen.add(surface.fingerprint(active))
        active = new
    raise ContactError("the active set did not settle in 50 iterations")


# -

# ### The load steps
#
# The punch goes down in equal steps of δ; each step starts from the last step's set plus
# every node that now penetrates. The state of a step: the force $P = -\sum T_n$ (the
# whole body's), the radius of the outermost active node and the largest nodal pressure
# $p_j = -T_{n,j}/m_j$ ($m_j$ the node's area). With `--force`, the δ of each step's force
# is found by secant steps on $\ln P(\ln\delta)$ (`reach_force`; Hertz: a slope of 3/2),
# each an active-set loop whose work counts in the step's. The states are
# `contact.obstacles.Indentation` records.

# +
active = surface.sync(surface.normal_gap(w) >= 0)  # S_C^(0): what touches already
areas = surface.nodal_areas(weight)


def press(delta, verbose=True):
    """The converged state of the punch pressed by δ (from the last state's set).

    The set and its nodal forces T_n stay in `active` and `T_n` for the outputs.
    """
    global active, T_n
    surface.set_gap(gap(delta))
    active = surface.sync(active | (surface.normal_gap(w) > 0))
    active, T_n, work = active_set_loop(active, verbose)
    r = radius_of(surface.x[active])
    return Indentation(delta, -symmetry * surface.total(T_n), global_max(msh.comm, r),
                       global_max(msh.comm, (-T_n / areas)[active]), work["iterations"],
                       work["newton"], work["factorizations"])


def fields():
    """What --output writes: u (and p), the contact pressure and set, σ_eq."""
    return [parts.displacement(), *([parts.pressure()] if args.mixed else []),
            surface.nodal_field(-T_n / areas, "contact_pressure"),
            surface.nodal_field(active.astype(float), "active_set"),
            parts.von_mises(material, kinematic)]


states = []
for step in range(1, args.steps + 1):
    t = step / args.steps
    if args.force is None:
        s = press(t * args.indentation)
    else:  # Hertz's δ ∝ P^(2/3) from the last step (the first: from a² / R)
        guess = (states[-1].indentation * (step / (step - 1)) ** (2 / 3) if states
                 else a * a / R * t ** (2 / 3))
        s, tried = reach_force(lambda d: press(d, verbose=False), t * args.force, guess)
        s = s.plus_work_of(x for _, x in tried[:-1])  # the work of every δ tried counts
    states.append(s)
    cli.converged_step({"load_factor": t, "indentation": s.indentation, "force": s.force,
                        "contact_radius": s.contact_radius, "max_pressure": s.max_pressure,
                        "active_set_iterations": s.active_set_iterations}, fields=fields)
    cli.say(f"step {step}/{args.steps}: δ = {s.indentation:.5g}, P = {s.force:.6g}, a = "
            f"{s.contact_radius:.5g}, p0 = {s.max_pressure:.5g}, {s.active_set_iterations} "
            "active-set iterations")
active_facets = surface.facet_tags(active).find(1)  # meshtags of S_C: 1 active, 0 not
owned = active_facets < msh.topology.index_map(dim - 1).size_local
cli.say(f"the active part of S_C: {msh.comm.allreduce(int(owned.sum()))} facets (meshtags, "
        "value 1)")
# -

# ## Against Hertz
#
# The force (not for the cylinder: Hertz gives no $P(\delta)$ for it), the radius of the
# outermost active node (within $h$ of the true edge) and the largest nodal pressure,
# against Hertz's values for the computed state; with several steps, the exponent $m$ of
# $P \propto \delta^m$ (Hertz: 1.5). A contact zone the mesh cannot resolve (fewer than 4
# nodes) is refused.

# +
last = states[-1]
nodes = surface.count(active)
warnings = check_contact_resolution(nodes, h, last)
out = {"model": model, "formulation": args.formulation, "material": args.material,
       "mixed": args.mixed, "elements": "P2-P1 (Taylor-Hood)" if args.mixed else "P1",
       **{k: getattr(last, k) for k in ("force", "indentation", "contact_radius",
                                        "max_pressure")},
       "element_size": h, "nodes_in_contact": nodes,
       **{k: sum(getattr(s, k) for s in states) for k in ("active_set_iterations",
                                                          "newton_iterations",
                                                          "factorizations")},
       "indentation_history": [s.indentation for s in states],
       "force_history": [s.force for s in states]}
ref = None
if last.force > 0:
    if model == "plane_strain":  # Hertz's a and p0 for the computed P per unit length
        ref = hertz.cylinder_from_force(args.E, args.nu, R, last.force)
        warnings.append("plane strain: the force is not checked (a cylinder's indentation "
                        "depends on the block, Hertz gives no P(δ)); half-width and p0 are "
                        "checked against Hertz for the computed P")
    else:
        ref = hertz.sphere_from_indentation(args.E, args.nu, R, last.indentation)
    for k in ("force", "contact_radius", "max_pressure"):
        if k in ref:
            out[f"hertz_{k}"], out[f"{k}_rel_error"] = ref[k], getattr(last, k) / ref[k] - 1
    said = [f"{k.replace('_', ' ')} {getattr(last, k):.6g} (Hertz {ref[k]:.6g}, "
            f"{100 * out[f'{k}_rel_error']:+.3f} %)" for k in ("force", "contact_radius",
                                                               "max_pressure") if k in ref]
    if model == "plane_strain":
        said.insert(0, f"P = {last.force:.6g} per unit length (not checked)")
    cli.say("; ".join(said) + f"; h = {h:.2g}")
else:
    cli.say("the punch does not touch the block: zero contact force")
if len(states) >= 2 and all(s.force > 0 for s in states):
    out["fitted_exponent"] = float(np.polyfit(np.log(out["indentation_history"]),
                                              np.log(out["force_history"]), 1)[0])
    cli.say(f"P ∝ δ^{out['fitted_exponent']:.4f} over the steps"
            + ("" if model == "plane_strain" else " (Hertz: 1.5)"))
if args.material != "linear":
    warnings.append(f"{args.material} material: Hertz's values are the linear reference, "
                    "not a check")
# -

# ## Outputs
#
# The JSON (every quantity above, the reactions of the supports: the bottom holds what
# the punch pushes), and when asked the fields for ParaView (written at every step as it
# converged), the force–indentation curve beside the pressure profile, and the deformed
# contact zone coloured by the von Mises stress.

# +
groups = {name: tagged(name) for name in ("contact", "bottom", "symmetry_x")
          + (("symmetry_y",) if dim == 3 else ())}
out.update(
    steps=[{k: getattr(s, k) for k in ("indentation", "force", "contact_radius",
                                       "active_set_iterations")} for s in states],
    reactions=boundary.reactions(residual, w, groups, space=V if args.mixed else None),
    reactions_of={"axisymmetric": "the whole body (2πr in the residual)",
                  "3d": "the modelled quarter",
                  "plane_strain": "the modelled half, per unit length"}[model],
    dofs=output.dofs(w.function_space), ranks=msh.comm.size, warnings=warnings)
drawn = indentation_pictures.PunchRun(
    model, states, ref, args.E, args.nu, R, rank0=msh.comm.rank == 0,
    profile=surface.gathered(radius_of(surface.x), -T_n / areas, active),
    section=(output.section(parts.displacement(), parts.von_mises(material, kinematic),
                            normal_axis=1 if dim == 3 else None) if args.png else None),
    gap_at=lambda r, d: punch.height(r) - d, h=h, mixed=args.mixed,
    force_controlled=args.force is not None)
cli.results(out, [*([lambda: indentation_pictures.curves(drawn, args.plot)] if args.plot
                    else []),
                  *([lambda: indentation_pictures.section_picture(drawn, args.png)]
                    if args.png else [])])
