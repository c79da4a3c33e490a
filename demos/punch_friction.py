# # A rigid punch pressed, then pulled sideways, with Coulomb friction: Cattaneo–Mindlin
#
# A rigid cylinder (plane strain) or sphere (3D) is pressed into an elastic block as in
# `punch.py`, and then pulled along $x$ by a tangential force $Q$ smaller than $fP$.
# The punch does not slide: the centre of the contact zone sticks while an annulus at its
# edge slips. Cattaneo (1938) and Mindlin (1949) found the size of the stick zone and the
# tractions; this demo computes them with the course's active set extended to friction,
# and checks them.
#
# ## Problem definition
#
# On $S_C$ the normal conditions of the frictionless punch hold, and Coulomb's law for the
# tangential traction $T_t$ and the slip $g_t$ (relative to the punch):
#
# $$ |T_t| \le f\,|T_n|, \qquad |T_t| < f|T_n| \Rightarrow g_t = 0, \qquad
#    |T_t| = f|T_n| \Rightarrow g_t = -\lambda\, T_t,\ \lambda \ge 0 .$$
#
# Every node of $S_C$ is **open**, **sticking** or **slipping**; each iteration solves the
# linear problem of its statuses (sticking nodes keep their place relative to the punch,
# slipping ones carry $f|T_n|$ against their slip) and updates the statuses, until they stop
# changing. For a rigid punch on an incompressible body ($\nu = 1/2$) the normal and
# tangential problems decouple and Cattaneo–Mindlin is exact: the stick half-width of the
# cylinder and the stick radius of the sphere are
#
# $$ c = a\sqrt{1 - Q/(fP)} \quad\text{(cylinder)}, \qquad
#    c = a\,(1 - Q/(fP))^{1/3} \quad\text{(sphere)}, $$
#
# and the cylinder's traction is $q(x) = f p_0 \sqrt{1 - x^2/a^2}$ in the slip zone, less
# $f p_0 (c/a)\sqrt{1 - x^2/c^2}$ inside the stick zone.
#
# ## Implementation

# +
from dataclasses import dataclass

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

from fenics_nl.io import cli
from fenics_nl.io.parameters import choice, number
from fenics_nl.materials.laws import LinearElastic
from fenics_nl.scenes import punch_run
from fenics_nl.scenes.punch import Punch, PunchLoad, check_contact_resolution
from fenics_nl.solvers.loading import solve_incrementally

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

# -

# ### Parameters
#
# The punch demos' common flags (`punch_run.PunchParameters`: the block, the normal load,
# the solver) and the friction and tangential load. By default the plane-strain cylinder on
# an incompressible block, pulled to $Q = fP/2$.

# +
@dataclass
class CattaneoMindlin(punch_run.PunchParameters):
    """A rigid punch pressed, then pulled sideways, with Coulomb friction (Cattaneo–Mindlin
    partial slip). Units are the user's, consistent (e.g. N, m, Pa or N, mm, MPa)."""

    model: str = choice("plane_strain", ["axisymmetric", "3d", "plane_strain"],
                        "plane strain (a cylinder), 3D half block (a sphere), or axisymmetric "
                        "(normal load only)", spelling=True)
    nu: float = number(0.5, "Poisson's ratio (at 1/2, where Cattaneo-Mindlin is exact, with "
                       "Taylor-Hood elements)", unit="-")
    refine: int = number(0, "element size under the punch a/(40·2^refine) (3D: a/(6·2^refine))",
                         at_least=0, at_most=punch_run.MAX_REFINE)
    block: float = number(100.0, "block size in contact radii, >= 10 (on both sides of the "
                          "punch with a tangential load)", above=0)
    friction: float = number(0.3, "Coulomb friction coefficient f (statuses open / stick / "
                             "slip)", at_least=0, metavar="F")
    tangential_ratio: float | None = number(
        None, "after the normal load, a tangential force Q = R f P along x, 0 <= R < 1 "
        "(default 0.5; axisymmetric: none)", at_least=0, group="tangential", metavar="R")
    tangential_force: float | None = number(
        None, "after the normal load, the tangential force Q (per unit length in plane "
        "strain), below f P", unit="force", at_least=0, group="tangential", metavar="Q")
    tangential_displacement: float | None = number(
        None, "after the normal load, move the punch by D along +x", unit="length", above=0,
        group="tangential", metavar="D")

    def check(self):
        if self.nu == 0.5:  # the incompressible limit needs the pressure as an unknown
            self.mixed = True
        super().check()
        if self.formulation == "multiplier":
            raise ValueError("--friction is written for --formulation elimination")
        given = [x for x in (self.tangential_ratio, self.tangential_force,
                             self.tangential_displacement) if x is not None]
        if given and self.model == "axisymmetric":
            raise ValueError("a tangential load breaks the axial symmetry: use --model "
                             "plane_strain or 3d")
        if not given and self.model != "axisymmetric":
            self.tangential_ratio = 0.5
        if self.tangential_ratio is not None and not self.tangential_ratio < 1:
            raise ValueError(f"--tangential-ratio must be in [0, 1), got "
                             f"{self.tangential_ratio} (at Q = f P the punch slides: no static "
                             "equilibrium)")
        if self.moved and self.friction == 0:
            raise ValueError("a tangential load needs --friction F > 0: without friction "
                             "nothing holds the punch")

    @property
    def moved(self) -> bool:
        """A tangential load follows the normal one."""
        return self.model != "axisymmetric"


args = cli.arguments(CattaneoMindlin,
                     prefixes=lambda a: punch_run.prefixes(a.model, a.formulation))
# -

# ### The block, the material, the frictional punch
#
# As for Hertz (`punch.py`), with two differences. A tangential load needs the block on
# both sides of the punch, clamped at its bottom (the 3D model is then the half $y \ge 0$).
# And the contact is `fenics_nl.contact.friction.FrictionalContact`: the active set with
# the stick and slip statuses, and the slip history committed at each converged step.

# +
a = punch_run.contact_radius_for(args.model, args.E, args.nu, args.radius, args.indentation,
                                 args.force)
block = punch_run.block_for(args.model, a, refine=args.refine, block=args.block,
                            mixed=args.mixed, tangential=args.moved)
material = LinearElastic(args.E, args.nu)
punch = Punch(block, material, block.residual(material), args.radius,
              formulation=args.formulation, gap=args.gap, friction=args.friction)
cli.say(f"{args.model} punch, {args.formulation}, {punch.dofs} unknowns, h = {block.h:.3g}")
# -

# ### The normal load
#
# In load steps, each started from the last statuses. With friction the surface under the
# punch is held back from its inward slip (Spence's problem) unless $\nu = 1/2$.

# +
load = PunchLoad(punch, indentation=args.indentation, force=args.force,
                 first_guess=a * a / args.radius)
report = punch_run.StepReport(load.states, args.steps, args.steps, punch.output_fields)
# --restart: the displacement, the statuses and the slip history, the states back;
# --checkpoint: saved after each converged step of the normal load
checkpoints = punch_run.checkpointing(punch, load)
solve_incrementally(load, load.set_load, args.steps, adaptive=False, predictor=False,
                    on_step=report, **checkpoints.options)
pressed = load.states[-1]
nodes = punch.nodes_in_contact()
warnings = check_contact_resolution(nodes, block.h, pressed)
check = punch_run.compare_with_hertz(punch, load.states)
# -

# ### The tangential load
#
# The punch moves along $x$ by a prescribed $D$, or until the tangential force is $Q$
# (`Punch.pull`: secant steps on the punch's position, from the full-stick slope). In 3D
# the compliance of this mesh and block before any slip is measured first: the finite
# block adds a far-field share to the punch's displacement that Mindlin's half-space has
# not, and it is taken out.

# +
traction, mindlin = None, {}
if args.moved:
    if not pressed.force > 0:
        raise ValueError("the punch does not touch the block: no normal force holds it "
                         "against a tangential load")
    bonded = punch.bonded_compliance() if args.model == "3d" else None
    if args.tangential_displacement is not None:
        traction = punch.shift(args.tangential_displacement)
    else:
        Q = (args.tangential_force if args.tangential_force is not None
             else args.tangential_ratio * args.friction * pressed.force)
        traction, _ = punch.pull(Q)
    punch.commit()
    T, fP = traction, args.friction * traction.normal_force  # (at ν < 1/2 Q changes P)
    cli.say(f"tangential: d = {T.tangential_displacement:.5g}, Q = {T.tangential_force:.6g} "
            f"= {T.tangential_force / fP:.4f} f P; {T.stick_nodes} nodes stick, "
            f"{T.slip_nodes} slip, stick radius {T.stick_radius:.5g}; "
            f"{T.status_iterations} status iterations")
# -

# ## Against Cattaneo–Mindlin
#
# For the computed $P$ (and Hertz's $a$, $p_0$ for it): the stick half-width or radius $c$
# (the outermost sticking node is within $h$ of it); the cylinder's tangential traction
# away from the stick–slip edges $\pm c$ (where the exact one has an infinite slope); the
# sphere's tangential force inside each radius, $Q(r)$, and its displacement $\delta_t(Q)$.

if traction is not None and check.ref is not None and 0 <= T.tangential_force < fP:
    mindlin = punch_run.compare_with_mindlin(punch, T, args.friction, bonded)
if traction is not None and args.nu != 0.5:
    warnings.append(f"Cattaneo-Mindlin is exact for a rigid punch on an incompressible "
                    f"body (ν = 1/2, --mixed); at ν = {args.nu:g} the normal and tangential "
                    "problems couple")

# ## Outputs
#
# The JSON (the normal state as for Hertz, the tangential one, the checks), and when asked
# the fields of the normal load's steps for ParaView, the curves with the traction profile
# against Cattaneo–Mindlin's, and the deformed contact zone.

# +
out = punch_run.summary(punch, load.states, load.states, nodes, check, "linear", warnings,
                        formulation=args.formulation)
out["friction"] = args.friction
if traction is not None:
    out.update({"tangential_force": T.tangential_force,
                "tangential_displacement": T.tangential_displacement,
                "stick_radius": T.stick_radius, "stick_nodes": T.stick_nodes,
                "slip_nodes": T.slip_nodes, "status_iterations": T.status_iterations,
                **mindlin})
cli.results(out, punch_run.pictures(punch, load.states, check, png=args.png, plot=args.plot,
                                    force_controlled=args.force is not None,
                                    friction=args.friction, traction=traction,
                                    stick_radius_exact=mindlin.get("stick_radius_exact")))
# -
