# # Upsetting a billet between flat dies: plasticity, finite strain, contact and friction
#
# A cylinder of radius $R_0$ and height $h_0$ is compressed between two flat rigid dies to a
# height reduction of 50 %: the forging operation the course names as its example of
# several non-linearities at once. The metal flows plastically (von Mises, isotropic
# hardening) through strains of order one; the dies touch the billet on a surface that
# grows; and friction on the die faces holds the end faces back while the middle bulges.
#
# ## Problem definition
#
# The billet is axisymmetric and symmetric about its mid-plane: the half
# $0 < r < R_0$, $0 < z < h_0/2$ is computed, the upper die at $z = h_0/2 - d$. The material
# is J2 plasticity at finite strain (`fenics_nl.materials.finite_plasticity`): $F = F_e F_p$,
# Hencky's energy in the elastic logarithmic strain, yield stress $\sigma_y(p)$ on the
# Kirchhoff stress, isochoric flow integrated by the exponential map. On the die face,
# Coulomb's law with coefficient $f$: every node is open, sticking or slipping.
#
# **Without friction** the compression is homogeneous: with $\ln(h_0/h) = p + \sigma_y(p)/E$
# (plastic and elastic logarithmic strains), the force is exactly
#
# $$ F = \sigma_y(p)\,\pi R_0^2\, \frac{h_0}{h}. $$
#
# **With friction** the end faces are held back and the billet barrels; the slab method
# (Siebel) estimates the mean die pressure for small $f R/h$,
#
# $$ \frac{\bar p}{\sigma_y} = 1 + \frac{2 f R}{3 h}, $$
#
# $R$ and $h$ the current radius and height. The side folds onto the die as the reduction
# grows: its nodes join the contact surface one by one.
#
# ## Implementation

# +
import time
from dataclasses import dataclass
from typing import ClassVar

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

from mpi4py import MPI

from fenics_nl.io import cli
from fenics_nl.io.cli import say
from fenics_nl.io.parameters import Parameters, number, switch
from fenics_nl.materials.finite_plasticity import FiniteJ2Plasticity
from fenics_nl.scenes import upsetting_pictures
from fenics_nl.scenes.upsetting import Billet, Upsetting
from fenics_nl.solvers.loading import solve_incrementally
from fenics_nl.theory import forming

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

comm = MPI.COMM_WORLD
# -

# ### Parameters
#
# From the command line (`python demos/upsetting.py --help`); in a notebook, the defaults:
# a steel billet as high as it is wide, $f = 0.2$.

# +
@dataclass
class UpsettingParameters(Parameters):
    """A cylindrical billet upset between flat rigid dies: J2 plasticity at finite strain,
    contact with Coulomb friction; the force against the frictionless closed form and the
    slab method. Units are the user's, consistent (e.g. N, mm, MPa)."""

    EPILOG = ("PETSc options take the prefix -upsetting_elim_ (the Newton solves of the "
              "active set), e.g. -upsetting_elim_ksp_view.")
    OUTPUTS: ClassVar = {"png": "the barrelled billet coloured by the cumulated plastic "
                                "strain, the die and the contact statuses",
                         "plot": "the force against the reduction, with the frictionless "
                                 "closed form and the slab estimate",
                         "output": "the displacement, the cumulated plastic strain, the "
                                   "contact pressure and active set at every converged step"}
    CHECKPOINTS = True

    friction: float = number(0.2, "Coulomb friction coefficient f on the die faces (0: "
                             "frictionless, the homogeneous compression)", at_least=0)
    reduction: float = number(0.5, "final height reduction 1 - h/h0", above=0)
    aspect: float = number(1.0, "initial height / diameter h0/d0", above=0)
    radius: float = number(10.0, "initial radius R0", unit="length", above=0)
    E: float = number(200e3, "Young's modulus", unit="stress", above=0)
    nu: float = number(0.3, "Poisson's ratio (0.5 with --mixed)", unit="-")
    sigma0: float = number(400.0, "initial yield stress", unit="stress", above=0)
    hardening: float = number(1000.0, "linear isotropic hardening modulus H (0: perfect "
                              "plasticity)", unit="stress", at_least=0)
    steps: int = number(20, "equal steps of the die (a step that fails is cut)", at_least=1)
    cells: int = number(6, "cells across the radius (P2 triangles, four per square)",
                        at_least=2)
    mixed: bool = switch("Taylor–Hood P2–P1 displacement–pressure elements (nu = 0.5 "
                         "allowed)")

    def check(self):
        if not self.reduction < 0.9:
            raise ValueError(f"--reduction must be below 0.9, got {self.reduction:g}")
        if self.nu == 0.5 and not self.mixed:
            raise ValueError("nu = 0.5 needs --mixed (the displacement formulation locks)")


args = cli.arguments(UpsettingParameters, prefixes={"upsetting_elim_": "Newton's KSP"})
R0, h0 = args.radius, 2 * args.radius * args.aspect
# -

# ### The billet and its material
#
# P2 triangles on the half section (`Billet`), the axis and the mid-plane held. The
# material's state (the plastic metric $C_p^{-1}$ and $p$) lives at the quadrature points
# and is committed when a step converges. Its stress and consistent tangent are UFL's
# derivatives of the step's condensed energy, as at small strain.

# +
billet = Billet(R0, h0, cells=args.cells, mixed=args.mixed)
material = FiniteJ2Plasticity(args.E, args.nu, sigma0=args.sigma0, H=args.hardening)
material.bind(billet.mesh, billet.quadrature_degree)
# -

# ### The die
#
# The active set on the top face and the side (`Upsetting`): frictionless, or Coulomb's
# statuses with the slip history committed at each converged step. Each active-set
# iteration is a full Newton solve; the die moves in `--steps` equal steps, each cut in
# half if it fails (the active set cycles, Newton diverges, or the step is too large for
# the material's logarithmic strain).

# +
up = Upsetting(billet, material, friction=args.friction)
say(f"billet R0 = {R0:g}, h0 = {h0:g}, f = {args.friction:g}: {billet.dofs} unknowns, "
    f"h = {billet.h:.3g}")
cli.known(dofs=billet.dofs, ranks=comm.size, initial_radius=R0, initial_height=h0)

history = []


def record(t, result):
    """One converged step: the force, the closed forms, the contact zone."""
    r = t * args.reduction
    step = {"load_factor": t, "reduction": r, "force": up.force,
            "force_frictionless_exact": forming.frictionless_force(
                r, R0, material.yield_stress, args.E),
            "force_slab_estimate": forming.slab_force(r, R0, h0, args.friction,
                                                      material.yield_stress, args.E),
            "contact_radius": up.contact_radius(), "stick_radius": up.stick_radius(),
            "folded_nodes": up.folded_nodes(), "newton_iterations": result.iterations,
            "status_iterations": result.active_set_iterations}
    history.append(step)
    cli.converged_step(step, lambda: [billet.displacement(), *material.output_fields(),
                                      *up.contact.fields(billet.weight)])
    say(f"  reduction {r:.3f}: F = {up.force:.6g} (frictionless "
        f"{step['force_frictionless_exact']:.6g}), contact radius "
        f"{step['contact_radius']:.4g}, stick {step['stick_radius']:.4g}; "
        f"{result.iterations} Newton / {result.active_set_iterations} status iterations")


# --checkpoint saves, after each converged step, the displacement, the plastic state, the
# contact's statuses and slip history and the steps so far; --restart puts them back
checkpoints = cli.checkpointing({"unknown": billet.unknown, **material.state_functions()},
                                newton=up.contact.newton, contact=up.contact)
history += checkpoints.steps
t0 = time.perf_counter()
run = solve_incrementally(up, lambda t: up.set_reduction(t * args.reduction), args.steps,
                          adaptive=True, max_step=1.0 / args.steps,
                          easy_iterations=10**9, progress=say, progress_every=10**9,
                          commit=up.commit, restore=up.restore, on_step=record,
                          **checkpoints.options)
solve_time = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
# -

# ## Against the closed forms
#
# Frictionless: the force at every step against $\sigma_y(p)\pi R_0^2 h_0/h$ (the mesh
# represents the homogeneous state exactly: the error is the solver's). With friction: the
# force above it, and its ratio to the slab estimate.

# +
last = history[-1]
frictionless_error = max(abs(h["force"] / h["force_frictionless_exact"] - 1) for h in history)
slab_ratio = last["force"] / last["force_slab_estimate"]
if args.friction == 0:
    say(f"frictionless: F within {frictionless_error:.2e} of the closed form at every step")
else:
    say(f"f = {args.friction:g}: F = {last['force']:.6g} = "
        f"{last['force'] / last['force_frictionless_exact']:.4f} x frictionless, "
        f"{slab_ratio:.4f} x the slab estimate; stick radius {last['stick_radius']:.4g} of "
        f"contact radius {last['contact_radius']:.4g}; {last['folded_nodes']} side nodes "
        "folded onto the die")
# -

# ## Outputs

# +
out = {"force": last["force"], "reduction": last["reduction"], "friction": args.friction,
       "initial_radius": R0, "initial_height": h0,
       "force_history": [h["force"] for h in history],
       "reduction_history": [h["reduction"] for h in history],
       "force_frictionless_exact": last["force_frictionless_exact"],
       "force_frictionless_error": frictionless_error if args.friction == 0 else None,
       "force_slab_estimate": last["force_slab_estimate"], "force_over_slab": slab_ratio,
       "stick_radius": last["stick_radius"], "contact_radius": last["contact_radius"],
       "folded_nodes": last["folded_nodes"], "max_plastic_strain": up.max_plastic_strain(),
       "volume_change": up.volume() / up.initial_volume(R0, h0) - 1,
       "newton_iterations": run.iterations,
       "status_iterations": sum(h["status_iterations"] for h in history),
       "step_cuts": run.failures, "factorizations": run.work.factorizations,
       "dofs": billet.dofs, "ranks": comm.size, "solve_time_s": solve_time,
       "warnings": [] if args.friction == 0 else [
           "the slab estimate assumes sliding on the whole face and small f R/h: an "
           "estimate, not a closed form"]}
title = (f"upsetting to {100 * last['reduction']:.0f} %, f = {args.friction:g}: "
         f"F = {last['force']:.4g} ({last['force'] / last['force_frictionless_exact']:.3f} x "
         "frictionless)")


def picture():
    """The billet at the last state, coloured by its plastic strain."""
    upsetting_pictures.billet_picture(up, args.png, title)
    say(f"wrote {args.png}")


def curve():
    """The force against the reduction, every converged step."""
    if billet.mesh.comm.rank == 0:
        upsetting_pictures.force_curve(history, args.friction, args.plot, title)


cli.results(out, [*([picture] if args.png else []), *([curve] if args.plot else [])])
# -
