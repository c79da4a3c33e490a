# # Indentation of an elastoplastic block: load, unload, and the imprint left behind
#
# The rigid sphere of `punch.py` is pressed into a block of von Mises (J2) material with
# linear isotropic hardening, then lifted off. Under the punch a plastic zone forms below
# the surface, where the shear is largest; the force needed for a given depth falls below
# Hertz's elastic one; and when the punch leaves, the surface keeps a dent: the residual
# imprint. This load–depth curve, loading and unloading, is what instrumented indentation
# measures to identify a material.
#
# ## Problem definition
#
# The contact conditions are the frictionless ones of `punch.py`, solved by the course's
# active set. The material: the stress is $\sigma = \mathbb{C} : (\varepsilon - \varepsilon^p)$,
# with the yield function and the flow rule
#
# $$ f(\sigma, p) = \sigma_{eq} - (\sigma_0 + H p) \le 0, \qquad
#    \dot\varepsilon^p = \dot p\, \tfrac32 \frac{s}{\sigma_{eq}}, \qquad
#    \dot p \ge 0, \quad \dot p\, f = 0, $$
#
# $s$ the deviatoric stress, $\sigma_{eq} = \sqrt{\tfrac32 s : s}$ and $p$ the cumulated
# plastic strain. The law is path-dependent, so the load goes in steps, each a converged
# state from which the next starts, and unloading is a path of its own. Elastic Hertz gives
# the first yield: the largest shear is $0.31\,p_0$ at depth $0.48\,a$, so the default
# $\sigma_0 = 0.02 E$, about $0.3\,p_0$ of the default indentation, yields a plastic zone.
#
# ## Implementation

# +
from dataclasses import dataclass

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.contact import ActiveSetContact
from fenics_nl.contact.obstacles import Indentation, RigidPunch
from fenics_nl.contact.surface import check_contact_resolution
from fenics_nl.domain import boundary
from fenics_nl.domain.meshes import punch_block, punch_block_size
from fenics_nl.domain.probes import Probes
from fenics_nl.io import cli, indentation_record, output
from fenics_nl.io.parameters import number, switch
from fenics_nl.io.punch_parameters import PunchParameters, prefixes
from fenics_nl.materials import kinematics, mixed
from fenics_nl.materials.plasticity import J2Plasticity
from fenics_nl.parallel import global_max
from fenics_nl.plots import indentation as indentation_pictures
from fenics_nl.solvers.force_control import MotionPath
from fenics_nl.solvers.loading import solve_incrementally
from fenics_nl.theory import hertz

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

# -

# ### Parameters
#
# The punch demos' common flags (`PunchParameters`) and the plastic material;
# the punch is taken back up in as many steps as it went down.

# +
@dataclass
class Imprint(PunchParameters):
    """Rigid spherical punch on a J2 elastoplastic block, loaded and unloaded: the
    load-depth curve and the residual imprint. Units are the user's, consistent."""

    steps: int = number(4, "load steps from 0 to the load (as many to unload)", at_least=1)
    sigma0: float | None = number(None, "yield stress σ0 (default 0.02 E)", unit="stress",
                                  above=0)
    hardening: float | None = number(None, "linear isotropic hardening modulus H (default "
                                     "0.1 E)", unit="stress", at_least=0)
    loading_only: bool = switch("stop at the largest load: no unloading, no imprint")

    def check(self):
        super().check()
        self.sigma0 = 0.02 * self.E if self.sigma0 is None else self.sigma0
        self.hardening = 0.1 * self.E if self.hardening is None else self.hardening
        if not self.loading_only and self.force is not None:
            raise ValueError("the unloading takes the punch back up under displacement "
                             "control: drop --force, or add --loading-only")


args = cli.arguments(Imprint, prefixes=lambda a: prefixes(a.model, a.formulation))
R, model, unload = args.radius, args.model, not args.loading_only
# -

# ### The mesh, the space and the supports
#
# The block of `punch.py`: graded from elements of $h = a/20$ under the punch (plane
# strain $a/40$, 3D $a/6$, halved by each `--refine`) for Hertz's contact radius $a$ of
# the load, 1000 contact radii wide (3D: 100); its bottom slides on a rigid base and the
# symmetry planes hold their normal component. P1 displacements, or with `--mixed`
# Taylor–Hood (P2 displacements, P1 pressure).

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


symmetry = {"axisymmetric": 1.0, "3d": 4.0, "plane_strain": 2.0}[model]  # whole / modelled
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
bcs = [boundary.component(V, 0, tagged("symmetry_x")),
       boundary.component(V, vertical, tagged("bottom"))]
if dim == 3:
    bcs.append(boundary.component(V, 1, tagged("symmetry_y")))
# -

# ### The plastic material and the residual
#
# `J2Plasticity` keeps its state (plastic strain, cumulated plastic strain) at the
# quadrature points of the residual's rule. Its stress at a step is the derivative of the
# step's condensed energy after the radial return, and its tangent the consistent one,
# both by UFL; the residual is the same $\int_\Omega \sigma(\varepsilon(u)) :
# \varepsilon(v)\,d\Omega$ as for the elastic punch.

# +
material = J2Plasticity(args.E, args.nu, sigma0=args.sigma0, H=args.hardening)
material.bind(msh, 2 * degree)
kinematic = "3d" if dim == 3 else model  # the strain model: hoop strain if axisymmetric
dx = kinematics.quadrature_measure("dx", msh, 2 * degree)
weight = kinematics.measure_weight(msh, kinematic)  # 2πr, or 1
if args.mixed:
    residual = mixed.internal_work(material, u, p, v, q, kinematic) * dx
else:
    def eps(z):
        return kinematics.small_strain(z, kinematic)

    residual = ufl.inner(material.stress(eps(u)), eps(v)) * weight * dx
# -

# ### The contact on the `contact` tag
#
# The course's active set of `punch.py` (`ActiveSetContact` runs the loop written out
# there) with the punch's gap $\gamma = h(r) - \delta$. Each of its iterations is now a
# Newton solve of the plastic residual, with a line search; Newton's absolute tolerance is
# scaled by Hertz's force for the expected $a$.

# +
punch = RigidPunch(R, dim, args.gap)
E_star = hertz.effective_modulus(args.E, args.nu)
P_scale = (np.pi / 4 * E_star * a * a / R if model == "plane_strain"
           else 4 / 3 * E_star * a**3 / R)
newton = {"line_search": True, "force_scale": P_scale / symmetry}
if args.mixed and args.formulation == "elimination":  # a symmetric saddle point: LDLᵀ
    newton["linear_solver"] = "cholesky"
contact = ActiveSetContact(residual, w, bcs, tagged("contact"), punch.gap(0.0),
                           normal_axis=vertical, formulation=args.formulation,
                           initial="penetrating", newton_options=newton,
                           prefix=f"punch_{model}_", displacement_space=V if args.mixed else None)
cli.say(f"{model} punch, {args.formulation}, {output.dofs(w.function_space)} unknowns, "
        f"h = {h:.3g}")
# -

# ### Loading, then unloading
#
# Each load step is an active-set loop at the punch's depth $\delta$ (with `--force`, the
# depth of the step's force); a converged step commits the plastic state, which is where
# the next step starts from. Unloading runs the load factor back from 1 to 0: the active
# set shrinks and the punch leaves the block with no force.

# +
def fields():
    """What --output writes: u (and p), the contact pressure and set, σ_eq, the plastic state."""
    return [parts.displacement(), *([parts.pressure()] if args.mixed else []),
            *contact.fields(weight), parts.von_mises(material, kinematic),
            *material.output_fields()]


def report(t, result):
    """Say and keep (JSON) the state just converged (unloading: t counts down)."""
    s, k = load.states[-1], len(load.states)
    cli.converged_step({"load_factor": t if k <= args.steps else 1 - t,
                        "indentation": s.indentation, "force": s.force,
                        "contact_radius": s.contact_radius, "max_pressure": s.max_pressure,
                        "active_set_iterations": s.active_set_iterations}, fields=fields)
    cli.say(f"step {k}/{args.steps * (2 if unload else 1)}: δ = {s.indentation:.5g}, P = "
            f"{s.force:.6g}, a = {s.contact_radius:.5g}, p0 = {s.max_pressure:.5g}, "
            f"{s.active_set_iterations} active-set iterations")


def commit():
    """The converged step's plastic state becomes the next step's start."""
    material.commit(u, kinematic)


def press(delta):
    """The state of the punch pressed by δ: the active-set loop, from the last set."""
    return punch.press(contact, delta, weight=weight, symmetry=symmetry)


load = MotionPath(press, w, displacement=args.indentation, force=args.force, guess=a * a / R)
# --checkpoint: the displacement, the plastic state, the active set and the states after
# each converged step of the loading; --restart takes them back
checkpoints = cli.checkpointing({"unknown": w, **material.state_functions()},
                                newton=contact.newton, contact=contact, kept=load.record)
if checkpoints.kept is not None:
    load.take_back(checkpoints.kept, Indentation)
solve_incrementally(load, load.set_load, args.steps, adaptive=False, predictor=False,
                    on_step=report, commit=commit, **checkpoints.options)
# -

# At the largest load: the force and the contact zone against elastic Hertz (a reference,
# not a check: plasticity lowers the force), the largest cumulated plastic strain, and the
# pictures' snapshot of this state (the curve gets the unloading too).

# +
loaded = list(load.states)
nodes = contact.surface.count(contact.active)
warnings = check_contact_resolution(nodes, h, loaded[-1])


def hertz_of(state):
    """Elastic Hertz for the state: the cylinder's for its P, the sphere's for its δ."""
    if model == "plane_strain":
        return hertz.cylinder_from_force(args.E, args.nu, R, state.force)
    return hertz.sphere_from_indentation(args.E, args.nu, R, state.indentation)


check = hertz.compare_with_hertz(loaded, hertz_of, model, h)
for line in check.lines:
    cli.say(line)
warnings.append("j2 material: Hertz's values are the linear reference, not a check")
p_cum = material.cumulated_plastic_strain
plastic_strain = global_max(msh.comm,
                            p_cum.x.array[:p_cum.function_space.dofmap.index_map.size_local])
cli.say(f"largest cumulated plastic strain {plastic_strain:.4g}")
drawn = None
if args.png or args.plot:  # the states unloaded later join the curve only
    drawn = indentation_pictures.PunchRun(
        model, load.states, check.ref, args.E, args.nu, R, rank0=msh.comm.rank == 0,
        profile=contact.surface.gathered(punch.distance(contact.x), contact.pressure(weight),
                                         contact.active),
        section=(output.section(parts.displacement(), parts.von_mises(material, kinematic),
                                normal_axis=1 if dim == 3 else None) if args.png else None),
        gap_at=lambda r, d: punch.height(r) - d, h=h, mixed=args.mixed,
        force_controlled=args.force is not None, loading_steps=len(load.states),
        plastic=True)
# -

# ### The imprint
#
# Back up in as many steps. The plastic strain stays: the surface keeps a dent, whose depth
# at the axis is the residual imprint.

imprint = None
if unload:
    solve_incrementally(load, lambda t: load.set_load(1 - t), args.steps, adaptive=False,
                        predictor=False, on_step=report, commit=commit)
    axis = [0.0] * dim
    imprint = -Probes(msh, [axis]).continuous(parts.displacement())[0][vertical]
    cli.say(f"unloaded: residual imprint depth {imprint:.5g} at the axis (δ_max = "
            f"{loaded[-1].indentation:.5g})")

# ## Outputs
#
# The JSON (the loaded state, the unloading path, the imprint, the supports' reactions),
# and when asked the fields of every step for ParaView (with the plastic strains), the
# load–depth curve, loading and unloading, and the block at the largest load coloured by
# the von Mises stress.

# +
out = indentation_record.record(load.states, loaded[-1], check, model=model,
                                formulation=args.formulation, material="j2",
                                mixed=args.mixed, h=h, nodes=nodes)
if model == "plane_strain" and check.ref is not None:
    warnings.append("plane strain: the force is not checked (a cylinder's indentation "
                    "depends on the block, Hertz gives no P(δ)); half-width and p0 are "
                    "checked against Hertz for the computed P")
groups = {name: tagged(name) for name in ("contact", "bottom", "symmetry_x")
          + (("symmetry_y",) if dim == 3 else ())}
out.update(reactions=boundary.reactions(residual, w, groups, space=V if args.mixed else None),
           reactions_of=indentation_record.REACTIONS_OF[model][False],
           dofs=output.dofs(w.function_space), ranks=msh.comm.size, warnings=warnings,
           max_cumulated_plastic_strain=plastic_strain)
if imprint is not None:
    out["residual_imprint_depth"] = imprint
    out["unloading"] = [{"indentation": s.indentation, "force": s.force}
                        for s in load.states[args.steps:]]
cli.results(out, [*([lambda: indentation_pictures.curves(drawn, args.plot)] if args.plot
                    else []),
                  *([lambda: indentation_pictures.section_picture(drawn, args.png)]
                    if args.png else [])])
# -
