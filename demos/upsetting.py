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

from fenics_nl.contact import ActiveSetContact, FrictionalContact
from fenics_nl.domain import boundary
from fenics_nl.domain.axisymmetric import billet
from fenics_nl.io import cli, output
from fenics_nl.io.cli import say
from fenics_nl.io.parameters import Parameters, number, switch
from fenics_nl.materials import kinematics, mixed
from fenics_nl.materials.finite_plasticity import FiniteJ2Plasticity
from fenics_nl.parallel import global_max
from fenics_nl.plots import plasticity as plasticity_pictures
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
                                   "contact pressure and active set"}
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

# ### The mesh and its tags
#
# The half section $0 < r < R_0$, $0 < z < h_0/2$ (`domain.axisymmetric.billet`): squares
# cut into four triangles by their diagonals, its edges tagged `axis` ($r = 0$), `mid`
# (the mid-plane $z = 0$), `top` and `side` ($r = R_0$ above the first row of cells: its
# foot on the mid-plane is held by the symmetry).

# +
model = "axisymmetric"
mesh_data = billet(comm, R0, h0, cells=args.cells)
msh = mesh_data.mesh


def tagged(name):
    """The facets of the group `name`."""
    return mesh_data.facet_tags.find(mesh_data.physical_groups[name].tag)


# -

# ### The function space and the supports
#
# P2 displacements (with `--mixed`, Taylor–Hood: a P1 pressure as a second unknown; no
# triangle has all its vertices on the boundary, so the pair is stable). The axis holds
# $u_r = 0$, the mid-plane $u_z = 0$.

# +
if args.mixed:
    W = mixed.taylor_hood(msh, 2)
    w = fem.Function(W, name="displacement_pressure")
    (u, p), (v, q) = ufl.split(w), ufl.TestFunctions(W)
    V = W.sub(0)  # the displacement part: its dofs are numbered in w
else:
    V = fem.functionspace(msh, ("Lagrange", 2, (2,)))
    w = u = fem.Function(V, name="displacement")
    v = ufl.TestFunction(V)
parts = mixed.unknown_of(w)  # u (and p) as Functions of their own, to write out
supports = [boundary.component(V, 0, tagged("axis")), boundary.component(V, 1, tagged("mid"))]
# -

# ### The material and the residual
#
# The material's state (the plastic metric $C_p^{-1}$ and $p$) lives at the quadrature
# points of the residual's rule and is committed when a step converges. Its stress and
# consistent tangent are UFL's derivatives of the step's condensed energy, as at small
# strain. The residual is the virtual work of the first Piola stress on the reference
# section, $R(u; v) = \int P(F) : \nabla v \; 2\pi r\,dr\,dz$ (with `--mixed`, the
# variation of $\Pi(u, p)$, `fenics_nl.materials.mixed`).

# +
material = FiniteJ2Plasticity(args.E, args.nu, sigma0=args.sigma0, H=args.hardening)
material.bind(msh, 4)  # its state at the quadrature points of dx (degree 4: P2's 2 × 2)
dx = kinematics.quadrature_measure("dx", msh, 4)
weight = kinematics.measure_weight(msh, model)  # 2πr: totals per turn
if args.mixed:
    residual = mixed.internal_work(material, u, p, v, q, model) * dx
else:
    residual = ufl.inner(material.first_piola(u, model),
                         kinematics.displacement_gradient(v, model)) * weight * dx
# -

# ### The die and the active set
#
# The die is the plane $z = h_0/2 - d$, $d = $ reduction $\cdot h_0/2$. Its candidate
# surface $S_C$ is the top face and the side, whose nodes fold onto the die as the billet
# barrels. A node's condition $u_z \le \gamma = h_0/2 - d - Z$ is exact at any
# deformation for a flat die (its current height $Z + u_z$ stays below the die), and so is
# its slip: the die does not move along $r$, and a node's slip on it is its increment of
# $u_r$. The active set on $S_C$: frictionless (`ActiveSetContact`), or Coulomb's statuses
# (`FrictionalContact`) with the slip history committed at each converged step. Each
# active-set iteration is a full Newton solve, its absolute tolerance scaled by the force of
# a yielded die face. A slipping node's friction force $f\,|T_n|\,s$ is written with $T_n$
# the reaction of its own normal row in Newton's iteration (the tangential row takes
# $f s$ times the normal one, residual and tangent: not symmetric, LU), so that the force
# follows the normal force as Newton converges and the statuses settle in one or two
# iterations a step; a step where that Newton fails is taken again with the friction
# forces of the last solve (a fixed point, slower). Each Newton iteration is factorized
# afresh: the tangent of the plastic billet moves too much for an older factorization to
# precondition it cheaply (measured: the time in linear solves was twice the
# factorizations' with it), and the line search backtracks on $\|R\|$. A Newton solve
# whose $\|R\|$ passes 100 times its first is abandoned at once, for the fallback and then
# the cut: where the side folds onto the die, a predicted state can send Newton away for
# good (at 9k and 50k unknowns, none of the 16 solves that grew past 100× came back;
# the solver's default, 1e8, let them run on for up to 30 iterations first).

# +
def die_gap(reduction):
    """γ(x) = h0/2 (1 − reduction) − z: the die's height above each node."""
    return lambda x: 0.5 * h0 * (1.0 - reduction) - x[1]


newton = {"method": "full", "rtol": 1e-10, "atol": 1e-10,
          "force_scale": args.sigma0 * R0**2, "max_it": 30, "divergence_tol": 100.0,
          "line_search": True,
          "reuse_factorization": False}
on_die = {"normal_axis": 1, "initial": "penetrating", "newton_options": newton,
          "prefix": "upsetting_", "displacement_space": V if args.mixed else None}
S_C = np.union1d(tagged("top"), tagged("side"))
if args.friction > 0:
    contact = FrictionalContact(residual, w, supports, S_C, die_gap(0.0),
                                friction=args.friction, **on_die)
else:
    contact = ActiveSetContact(residual, w, supports, S_C, die_gap(0.0), **on_die)
dofs = output.dofs(w.function_space)
say(f"billet R0 = {R0:g}, h0 = {h0:g}, f = {args.friction:g}: {dofs} unknowns, "
    f"h = {R0 / args.cells:.3g}")
# -

# ### What is measured
#
# The die's force (the contact forces' total over the turn), and on $S_C$ the current
# radius $r + u_r$ of its nodes: the outermost one on the die (the contact radius), the
# outermost sticking one, and how many nodes of the side have folded onto the die.

# +
r_dofs, _ = contact.surface.tangential(0)  # u_r at the nodes of S_C, in w's numbering
on_top = np.isclose(contact.x[:, 1], 0.5 * h0, atol=1e-9 * 0.5 * h0)


def current_radius():
    """r + u_r at the nodes of S_C."""
    return contact.x[:, 0] + w.x.array[r_dofs]


def outermost(nodes):
    """The largest current radius of the nodes of S_C in the mask `nodes` (0: none)."""
    return global_max(comm, current_radius()[nodes & contact.owned])


# -

# ### Load steps
#
# The die moves in `--steps` equal steps; each step's solver is the active-set loop
# (`contact.solve()`), from the last step's set and the die's new gap. A step that fails
# (the active set cycles, Newton diverges, or the step is too large for the material's
# logarithmic strain) is cut in half. A converged step commits the plastic state and, with
# friction, the slip history; a cut one restores the statuses of the last converged step.

# +
cli.known(dofs=dofs, ranks=comm.size, initial_radius=R0, initial_height=h0)
history = []


def record(t, result):
    """One converged step: the force, the closed forms, the contact zone."""
    r = t * args.reduction
    step = {"load_factor": t, "reduction": r, "force": contact.force,
            "force_frictionless_exact": forming.frictionless_force(
                r, R0, material.yield_stress, args.E),
            "force_slab_estimate": forming.slab_force(r, R0, h0, args.friction,
                                                      material.yield_stress, args.E),
            "contact_radius": outermost(contact.active),
            "stick_radius": outermost(contact.stick) if args.friction > 0 else 0.0,
            "folded_nodes": contact.surface.count(contact.active & ~on_top),
            "newton_iterations": result.iterations,
            "status_iterations": result.active_set_iterations}
    history.append(step)
    cli.converged_step(step, lambda: [parts.displacement(), *material.output_fields(),
                                      *contact.fields(weight)])
    say(f"  reduction {r:.3f}: F = {contact.force:.6g} (frictionless "
        f"{step['force_frictionless_exact']:.6g}), contact radius "
        f"{step['contact_radius']:.4g}"
        + (f", stick {step['stick_radius']:.4g}" if args.friction > 0 else "") + "; "
        f"{result.iterations} Newton / {result.active_set_iterations} status iterations")


def commit():
    """A converged step: the material's state and (friction) the slip history."""
    material.commit(u, model)
    if args.friction > 0:
        contact.commit()


# --checkpoint saves, after each converged step, the displacement, the plastic state, the
# contact's statuses and slip history and the steps so far; --restart puts them back
checkpoints = cli.checkpointing({"unknown": w, **material.state_functions()},
                                newton=contact.newton, contact=contact)
history += checkpoints.steps
t0 = time.perf_counter()
run = solve_incrementally(contact, lambda t: contact.set_gap(die_gap(t * args.reduction)),
                          args.steps, adaptive=True, max_step=1.0 / args.steps,
                          easy_iterations=10**9, progress=say, progress_every=10**9,
                          commit=commit, restore=contact.restore if args.friction > 0 else None,
                          on_step=record, **checkpoints.options)
solve_time = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
# -

# ## Against the closed forms
#
# Frictionless: the force at every step against $\sigma_y(p)\pi R_0^2 h_0/h$ (the mesh
# represents the homogeneous state exactly: the error is the solver's). With friction: the
# force above it, and its ratio to the slab estimate. And the volume of the whole billet,
# $2 \cdot 2\pi \int J\, r\,dr\,dz$: the plastic flow keeps it, the elastic strain
# changes it a little.

# +
last = history[-1]
p_cum = material.cumulated_plastic_strain
owned = p_cum.function_space.dofmap.index_map.size_local
max_plastic_strain = global_max(comm, p_cum.x.array[:owned])
J = ufl.det(kinematics.deformation_gradient(u, model))
volume = 2 * comm.allreduce(fem.assemble_scalar(fem.form(J * weight * dx)))
frictionless_error = max(abs(h["force"] / h["force_frictionless_exact"] - 1) for h in history)
slab_ratio = last["force"] / last["force_slab_estimate"]
if args.friction == 0:
    say(f"frictionless: F within {frictionless_error:.2e} of the closed form at every step")
else:
    say(f"f = {args.friction:g}: F = {last['force']:.6g} = "
        f"{last['force'] / last['force_frictionless_exact']:.4f} x frictionless, "
        f"{slab_ratio:.4f} x the slab estimate; stick radius {last['stick_radius']:.4g} of "
        f"contact radius {last['contact_radius']:.4g}; side nodes folded onto the die: "
        f"{last['folded_nodes']}")
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
       "folded_nodes": last["folded_nodes"], "max_plastic_strain": max_plastic_strain,
       "volume_change": volume / (math.pi * R0**2 * h0) - 1,
       "newton_iterations": run.iterations,
       "status_iterations": sum(h["status_iterations"] for h in history),
       "step_cuts": run.failures, "factorizations": run.work.factorizations,
       "linear_solves": run.work.linear_solves,
       "point_force_steps": contact.fallbacks if args.friction > 0 else 0,
       "dofs": dofs, "ranks": comm.size, "solve_time_s": solve_time,
       "warnings": [] if args.friction == 0 else [
           "the slab estimate assumes sliding on the whole face and small f R/h: an "
           "estimate, not a closed form"]}
title = (f"upsetting to {100 * last['reduction']:.0f} %, f = {args.friction:g}: "
         f"F = {last['force']:.4g} ({last['force'] / last['force_frictionless_exact']:.3f} x "
         "frictionless)")


def picture():
    """The billet at the last state, coloured by its plastic strain; the nodes on the die."""
    # S_C's nodes where they are now: r + u_r, and z + u_z (S_C's normal component)
    x = np.column_stack([current_radius(), contact.x[:, 1] + w.x.array[contact.surface.dofs_V]])
    on = contact.owned & contact.active
    marked = ({"sticking nodes": x[on & contact.stick], "slipping nodes": x[on & contact.slip]}
              if args.friction > 0 else {"nodes on the die": x[on]})
    plasticity_pictures.billet_picture(
        parts.displacement(), material.cumulated_plastic_strain_per_cell(), args.png, title,
        die_height=0.5 * h0 * (1 - last["reduction"]), marked=marked)
    say(f"wrote {args.png}")


def curve():
    """The force against the reduction, every converged step."""
    if comm.rank == 0:
        plasticity_pictures.upsetting_force_curve(history, args.friction, args.plot, title)


cli.results(out, [*([picture] if args.png else []), *([curve] if args.plot else [])])
# -
