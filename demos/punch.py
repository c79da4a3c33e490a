# # Rigid spherical punch on an elastic block: Hertz contact by the active-set method
#
# A rigid sphere of radius $R$ is pressed by $\delta$ into an elastic block, without
# friction. Where the two touch is not known in advance: the course's active-set algorithm
# finds it. Hertz's theory gives the answer for a half-space and a parabolic gap, and this
# demo checks the computation against it. (With friction: `punch_friction.py`; a plastic
# block, loaded and unloaded: `indentation.py`.)
#
# ## Problem definition
#
# On the top surface $S_C$ (outward normal $n = e_z$) the gap to the punch is
# $\gamma(r) = r^2/(2R) - \delta$, and the unilateral conditions hold:
#
# $$ u_n - \gamma \le 0, \qquad T_n \le 0, \qquad (u_n - \gamma)\, T_n = 0 .$$
#
# Iteration $k$ of the active-set loop solves linear elasticity with $u_n = \gamma$ on the
# active nodes and $T = 0$ elsewhere; then an active node in tension ($T_n > 0$) leaves the
# set and an inactive node that penetrates ($u_n - \gamma > 0$) joins it. The set has
# converged when nothing changes. Hertz's solution, with $E^* = E/(1-\nu^2)$:
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

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

from fenics_nl.io import cli
from fenics_nl.io.parameters import choice, number
from fenics_nl.materials.laws import LinearElastic, PowerLaw
from fenics_nl.scenes import punch_run
from fenics_nl.scenes.punch import Punch, PunchLoad, check_contact_resolution
from fenics_nl.solvers.loading import solve_incrementally

# -

# ### Parameters
#
# From the command line (`python demos/punch.py --help` lists them); in a notebook, the
# defaults. The flags every punch demo has (the block, the load, the solver) are
# `punch_run.PunchParameters`; this one adds the material.

# +
@dataclass
class Hertz(punch_run.PunchParameters):
    """Rigid spherical punch on an elastic block (Hertz contact, the course's active set).
    Units are the user's, consistent (e.g. N, m, Pa or N, mm, MPa)."""

    material: str = choice("linear", ["linear", "power-law"], "linear elastic (Hertz "
                           "applies), or the power law (a Newton loop inside every "
                           "active-set iteration)")
    sigma0: float | None = number(None, "power law: stress where it turns non-linear "
                                  "(default 0.01)", unit="stress", above=0)
    n: float | None = number(None, "power law exponent (default 0.3)", unit="-", above=0)

    def check(self):
        super().check()
        cli.material_flags(self, power_law={"sigma0": 0.01, "n": 0.3})


args = cli.arguments(Hertz, prefixes=punch_run.prefixes)
# -

# ### The block
#
# It must behave like Hertz's half-space: it is 1000 contact radii wide and deep (100 in
# 3D), with elements of a/40 under the punch (axisymmetric; plane strain a/80, 3D a/12)
# within 1.5 a of the axis, growing by 5 % of the distance away from it (3D: 10 %). On the
# axisymmetric model this keeps the block-size and far-field error near 0.15 %, below the
# 0.5 % asked of the force (measured in `fenics_nl/scenes/punch.py`). Its bottom slides on
# a rigid base, the symmetry planes carry their symmetry conditions, its top is $S_C$. The
# mesh is made for Hertz's contact radius of the load.

a = punch_run.contact_radius_for(args)
block = punch_run.block_for(args)

# ### The material and the residual
#
# A free energy $\varphi(\varepsilon)$; the stress $\sigma = \partial\varphi/\partial
# \varepsilon$ and its tangent are derived from it by UFL. The residual is
#
# $$ R(u; v) = \int_\Omega \sigma(\varepsilon(u)) : \varepsilon(v)\,d\Omega, $$
#
# with no external load: the punch acts only through the contact conditions. In the
# axisymmetric model $\varepsilon$ has the hoop strain $u_r/r$ and the weight is $2\pi r$,
# so that $R$ is the whole body's. With `--mixed` the pressure $p$ is an unknown too and
# $R$ is the variation of $\Pi(u, p) = \int \tilde\varphi(\varepsilon) + p\,\mathrm{tr}\,
# \varepsilon - p^2/(2\kappa)$, which holds at $\kappa = \infty$ ($\nu = 1/2$).

material = (LinearElastic(args.E, args.nu) if args.material == "linear"
            else PowerLaw(args.E, args.nu, sigma0=args.sigma0, n=args.n))
residual = block.residual(material)

# ### The active-set loop, in load steps
#
# `Punch` hands the residual, the supports and the gap $\gamma$ to
# `fenics_nl.contact.active_set.ActiveSetContact`, which runs the course's loop: solve with
# $u_n = \gamma$ on the active nodes (their rows eliminated, or Lagrange multipliers), then
# update the set, until it stops changing. The load (δ, or the force P by a secant
# iteration on δ) grows in equal steps, each started from the last active set.

# +
punch = Punch(block, material, residual, args.radius, formulation=args.formulation,
              gap=args.gap)
cli.say(f"{args.model} punch, {args.formulation}, {punch.dofs} unknowns, h = {block.h:.3g}")
load = PunchLoad(punch, indentation=args.indentation, force=args.force,
                 first_guess=a * a / args.radius)
report = punch_run.StepReport(load.states, args.steps, args.steps, punch.output_fields)
# --restart: the displacement, the contact statuses and the states back; --checkpoint:
# saved after each converged step
checkpoints = punch_run.checkpointing(punch, load)
solve_incrementally(load, load.set_load, args.steps, adaptive=False, predictor=False,
                    on_step=report, **checkpoints.options)
# -

# ## Against Hertz
#
# The force (not for the cylinder: Hertz gives no $P(\delta)$ for it), the radius of the
# outermost active node (within $h$ of the true edge) and the largest nodal pressure,
# against Hertz's values for the computed state; with several steps, the exponent $m$ of
# $P \propto \delta^m$ (Hertz: 1.5). A contact zone the mesh cannot resolve (fewer than 4
# nodes) is refused.

nodes = punch.nodes_in_contact()
warnings = check_contact_resolution(nodes, block.h, load.states[-1])
check = punch_run.compare_with_hertz(punch, load.states)
if args.material != "linear":
    warnings.append(f"{args.material} material: Hertz's values are the linear reference, "
                    "not a check")

# ## Outputs
#
# The JSON (every quantity above, the reactions of the supports), and when asked the
# fields for ParaView (written at every step as it converged), the force–indentation curve
# beside the pressure profile, and the deformed contact zone coloured by the von Mises
# stress.

out = punch_run.summary(args, punch, load.states, load.states, nodes, check, args.material,
                        warnings)
cli.results(out, punch_run.pictures(args, punch, load.states, check))
