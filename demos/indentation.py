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

from fenics_nl.domain.probes import Probes
from fenics_nl.io import cli
from fenics_nl.io.parameters import number, switch
from fenics_nl.materials.plasticity import J2Plasticity
from fenics_nl.parallel import global_max
from fenics_nl.scenes import punch_run
from fenics_nl.scenes.punch import Punch, PunchLoad, check_contact_resolution
from fenics_nl.solvers.loading import solve_incrementally

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

# -

# ### Parameters
#
# The punch demos' common flags (`punch_run.PunchParameters`) and the plastic material;
# the punch is taken back up in as many steps as it went down.

# +
@dataclass
class Indentation(punch_run.PunchParameters):
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


args = cli.arguments(Indentation,
                     prefixes=lambda a: punch_run.prefixes(a.model, a.formulation))
unload = not args.loading_only
# -

# ### The block and the plastic material
#
# The block of `punch.py`. `J2Plasticity` keeps its state (plastic strain, cumulated
# plastic strain) at the quadrature points of the block's rule; its stress at a step is
# the derivative of the step's condensed energy after the radial return, and its tangent
# the consistent one, both by UFL.

# +
a = punch_run.contact_radius_for(args.model, args.E, args.nu, args.radius, args.indentation,
                                 args.force)
block = punch_run.block_for(args.model, a, refine=args.refine, block=args.block,
                            mixed=args.mixed)
material = J2Plasticity(args.E, args.nu, sigma0=args.sigma0, H=args.hardening)
material.bind(block.mesh, block.quadrature_degree)
punch = Punch(block, material, block.residual(material), args.radius,
              formulation=args.formulation, gap=args.gap)
cli.say(f"{args.model} punch, {args.formulation}, {punch.dofs} unknowns, h = {block.h:.3g}")
# -

# ### Loading, then unloading
#
# Each load step is an active-set loop whose iterations are Newton solves of the plastic
# residual; a converged step commits the plastic state (`commit`), which is where the next
# step starts from. Unloading runs the load factor back from 1 to 0: the active set shrinks
# and the punch leaves the block with no force.

# +
load = PunchLoad(punch, indentation=args.indentation, force=args.force,
                 first_guess=a * a / args.radius)
report = punch_run.StepReport(load.states, args.steps, args.steps * (2 if unload else 1),
                              punch.output_fields)


def commit():
    material.commit(block.u, block.kinematics)


# --restart: the displacement, the plastic state, the statuses and the states back;
# --checkpoint: saved after each converged step of the loading
checkpoints = punch_run.checkpointing(punch, load, material.state_functions())
solve_incrementally(load, load.set_load, args.steps, adaptive=False, predictor=False,
                    on_step=report, commit=commit, **checkpoints.options)
# -

# At the largest load: the force and the contact zone against elastic Hertz (a reference,
# not a check: plasticity lowers the force), the largest cumulated plastic strain, and the
# pictures' snapshot of this state (the curve gets the unloading too).

# +
loaded = list(load.states)
nodes = punch.nodes_in_contact()
warnings = check_contact_resolution(nodes, block.h, loaded[-1])
check = punch_run.compare_with_hertz(loaded, punch.hertz, punch.model, punch.block.h)
warnings.append("j2 material: Hertz's values are the linear reference, not a check")
p = material.cumulated_plastic_strain
plastic_strain = global_max(block.mesh.comm,
                            p.x.array[:p.function_space.dofmap.index_map.size_local])
cli.say(f"largest cumulated plastic strain {plastic_strain:.4g}")
drawn = punch_run.pictures(punch, load.states, check, png=args.png, plot=args.plot,
                           force_controlled=args.force is not None, plastic=True)
# -

# ### The imprint
#
# Back up in as many steps. The plastic strain stays: the surface keeps a dent, whose depth
# at the axis is the residual imprint.

imprint = None
if unload:
    solve_incrementally(load, lambda t: load.set_load(1 - t), args.steps, adaptive=False,
                        predictor=False, on_step=report, commit=commit)
    axis = [0.0] * (3 if args.model == "3d" else 2)
    imprint = -Probes(block.mesh, [axis]).continuous(block.displacement())[0][block.vertical]
    cli.say(f"unloaded: residual imprint depth {imprint:.5g} at the axis (δ_max = "
            f"{loaded[-1].indentation:.5g})")

# ## Outputs
#
# The JSON (the loaded state, the unloading path, the imprint), and when asked the fields
# of every step for ParaView (with the plastic strains), the load–depth curve, loading and
# unloading, and the block at the largest load coloured by the von Mises stress.

out = punch_run.summary(punch, load.states, loaded, nodes, check, "j2", warnings,
                        formulation=args.formulation)
out["max_cumulated_plastic_strain"] = plastic_strain
if imprint is not None:
    out["residual_imprint_depth"] = imprint
    out["unloading"] = [{"indentation": s.indentation, "force": s.force}
                        for s in load.states[args.steps:]]
cli.results(out, drawn)
