# # A crack that propagates: Miehe's notched square in tension and shear, and a surfing crack
#
# Gradient damage (AT1 or AT2, as in `damage_bar.py`) on a plate: the crack is where the
# damage reaches 1, and it goes where minimizing the energy takes it, step by step under an
# imposed displacement. This demo runs the single-edge-notched square of Miehe et al. (2010)
# in tension (a straight crack from the notch) and in shear (a crack that turns down), and a
# *surfing* test, where a crack is dragged along a line by a moving mode-I field and its
# energy release rate is known.
#
# ## Problem definition
#
# The energy of the displacement $u$ and the damage $\alpha$ (plane strain) is
#
# $$ \mathcal E(u, \alpha) = \int_\Omega a(\alpha)\, \psi_0^+(\varepsilon) + \psi_0^-(\varepsilon)
#    + \frac{G_c}{c_w}\Big(\frac{w(\alpha)}{\ell} + \ell\,|\nabla\alpha|^2\Big), $$
#
# $a(\alpha) = (1-\alpha)^2 + k$; with the volumetric split (`--split volumetric`, Amor et al.
# 2009) $\psi_0^- = \tfrac{\kappa}{2}\langle \operatorname{tr}\varepsilon\rangle_-^2$ is not
# degraded, so that no crack grows where the material is compressed; without it
# ($\psi_0^- = 0$) the whole of Hooke's energy is. At each load step $\mathcal E$ is
# minimized over $u$ (its supports) and over $\alpha$ within $\alpha_{n-1} \le \alpha \le 1$,
# the last step's damage: a crack does not heal.
#
# * **Notched square** (`--test tension`, `--test shear`): the square $[0, 1]^2$ mm, a notch
#   from the left side to the centre along $y = 0.5$ drawn as a pre-crack (a band of one
#   cell at $\alpha = 1$), the bottom clamped and the top moved rigidly by $U$: up (tension,
#   $u_x = 0$ there) or to the right (shear, $u_y = 0$ there and on the sides). Miehe's
#   material: $E = 210$ kN/mm², $\nu = 0.3$, $G_c = 2.7\cdot10^{-3}$ kN/mm. No closed form
#   gives the force: the run reports its curve and peak. What is checked is where the crack
#   goes (straight in tension) and what it costs: a crack that has crossed the square has
#   dissipated $G_h L$, $G_h = G_c(1 + h/(c_w\ell))$ the toughness of a crack of the mesh
#   (a band of one cell at $\alpha = 1$, `damage_bar.py`), per mm of thickness.
# * **Surfing** (`--test surfing`): the upper half of a strip cracked along $y = 0$, loaded
#   on its outer sides by Irwin's displacement around a tip at $(x_c, 0)$ with
#   $K = \sqrt{G_h E/(1-\nu^2)}$, $x_c$ moved by $2h$ per step. In steady propagation the
#   elastic energy only translates, so the dissipated energy $D$ of the half strip grows by
#   $G_h/2$ per unit crack length: $2\,dD/da = G_h$, here that of a crack on a symmetry line,
#   $G_c(1 + 2h/(c_w\ell))$, checked to 2 %.
#
# ## Implementation

# +
from dataclasses import dataclass
from typing import ClassVar

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
from mpi4py import MPI

from fenics_nl.io import cli
from fenics_nl.io.parameters import Parameters, choice, number
from fenics_nl.materials.gradient_damage import GradientDamage
from fenics_nl.scenes import crack_pictures
from fenics_nl.scenes.notched_specimen import NotchedSpecimen
from fenics_nl.scenes.surfing import Surfing, release_rate

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

# -

# ### Parameters
#
# From the command line (`python demos/crack.py --help`); in a notebook, the defaults.

# +
FINAL = {"tension": 6.5e-3, "shear": 1.5e-2}  # the top's final displacement, mm


@dataclass
class Crack(Parameters):
    """A crack that propagates in gradient damage: Miehe's notched square in tension or
    shear, or a crack surfing on a moving K-field. Units: mm, kN."""

    EPILOG = ("PETSc options take the prefix -damage_ (the damage SNES), e.g. "
              "-damage_snes_monitor.")
    OUTPUTS: ClassVar = {"plot": "the force against the displacement (surfing: the tip "
                                 "against the field's centre) and the damage at three steps"}

    test: str = choice("tension", ["tension", "shear", "surfing"], "the test")
    model: str = choice("at1", ["at1", "at2"], "the gradient damage law")
    split: str = choice("volumetric", ["none", "volumetric"], "what damage degrades: all of "
                        "Hooke's energy, or not its compressive volumetric part")
    E: float = number(210.0, "Young's modulus", unit="kN/mm²", above=0)
    nu: float = number(0.3, "Poisson's ratio", unit="-", above=-1, at_most=0.499)
    Gc: float = number(2.7e-3, "the toughness G_c", unit="kN/mm", above=0)
    ell: float = number(0.03, "the length ℓ, at most 0.1 (Miehe's 0.015 runs in about 80 s "
                        "instead of 11)", unit="mm", above=0, at_most=0.1)
    resolution: float = number(2.0, "ℓ/h where the crack can go (below 2 its band of one "
                               "cell is a visible share of its cost)", unit="-", at_least=1)
    displacement: float = number(None, "notched square: the top's final displacement "
                                 "(default: 6.5e-3 in tension, 1.5e-2 in shear)", unit="mm",
                                 above=0)
    steps: int = number(13, "equal displacement steps (surfing: positions of the field, 2h "
                        "apart, as many as the strip holds)", at_least=2)
    acceleration: str = choice("anderson", ["none", "overrelaxed", "anderson"],
                               "the alternate minimization's acceleration")

    def check(self):
        if self.test == "surfing" and self.displacement is not None:
            raise ValueError("--displacement: the surfing test moves its K-field, not a side "
                             "(its steps: --steps)")


args = cli.arguments(Crack, {"damage_": "the damage SNES"})
law = GradientDamage(args.E, args.nu, Gc=args.Gc, ell=args.ell, model=args.model,
                     residual_stiffness=1e-6, split=args.split)
warnings = []
# -

# ### The body, its crack, its solver
#
# `NotchedSpecimen` and `Surfing` build the mesh (square cells of $h = \ell/$`resolution`
# where the crack can go, growing away from it), the energy above in UFL, the supports and
# the pre-crack, and an `AlternateMinimization`: at each step, $u$ at fixed $\alpha$ by
# Newton, $\alpha$ at fixed $u$ within its bounds by PETSc's SNES `vinewtonrsls`, until
# $\alpha$ changes by less than $10^{-6}$, Anderson-accelerated by default. Every converged
# step is committed ($\alpha_n$ becomes the lower bound) and kept for the JSON.

# +
if args.test == "surfing":
    h = args.ell / args.resolution  # a crack on the strip's symmetry line: two half bands
    body = Surfing(law, resolution=args.resolution, acceleration=args.acceleration,
                   toughness=args.Gc * (1 + 2 * h / (law.c_w * args.ell)))
    mesh_toughness = body.toughness
    loads = body.centres(args.steps, flag="--steps")
else:
    body = NotchedSpecimen(law, args.test, resolution=args.resolution,
                           acceleration=args.acceleration)
    mesh_toughness = args.Gc * (1 + body.h / (law.c_w * args.ell))
    final = args.displacement or FINAL[args.test]
    loads = np.linspace(0.0, final, args.steps + 1)[1:]
if args.resolution < 2:
    warnings.append(f"ℓ is smaller than two elements (ℓ/h = {args.resolution:g}): a crack "
                    f"dissipates {mesh_toughness:.4g} kN/mm, not G_c = {args.Gc:g} kN/mm")
cli.known(dofs=body.dofs, ranks=MPI.COMM_WORLD.size, mesh_toughness=mesh_toughness)
cli.say(f"{args.test}: {body.dofs} unknowns, h = {body.h:.4g} mm where the crack goes")
# -

# ### Load steps
#
# The top is moved (or the K-field's centre); each step prints its force, crack tip and
# dissipated energy $\int \frac{G_c}{c_w}(w(\alpha)/\ell + \ell|\nabla\alpha|^2)$.

# +
def progress(k, record):
    """Print a converged step and keep it for the JSON of a run that fails later."""
    tip = record.tip[-1] if args.test != "surfing" else [record.tip[-1], 0.0]
    step = {"load_factor": (k + 1) / len(loads), "load": float(loads[k]), "tip": tip,
            "dissipated_energy": record.dissipated_energy[-1]}
    if args.test != "surfing":
        step["force"] = record.force[-1]
    cli.converged_step(step)
    cli.say(f"step {k + 1}/{len(loads)}: {'x_c' if args.test == 'surfing' else 'U'} = "
            f"{loads[k]:.4g}" + (f", F = {record.force[-1]:.4g} kN" if "force" in step else "")
            + f", tip ({tip[0]:.3f}, {tip[1]:.3f}), D = {step['dissipated_energy']:.4g}, "
            f"{record.iterations[-1]} alternate iterations")


record = (body.advance(loads, progress) if args.test == "surfing"
          else body.load(loads, progress))
# -

# ## What the steps say
#
# * Tension: the force grows almost linearly, the damage at the notch's tip stays small, and
#   at the peak the crack runs through the ligament in one or two steps (brutally: the
#   alternate minimization then takes a hundred iterations or more). It is straight: its tip
#   stays on $y = 0.5$ within a cell.
#   Once broken, the square has dissipated $G_h$ per unit width. The energy release rate
#   measured between the first step and the last, $(D_{end} - D_1)/\Delta a$, reads a little
#   low: $D_1$ includes the damage around the notch's tip (about $G_c\ell$), which the crack
#   that leaves the square no longer has.
# * Shear: the crack leaves the notch downwards and reaches the right side or the bottom.
#   Its length is not measured (its tip jumps in one step along a path that turns), so
#   neither is its energy release rate.
# * Surfing: after a few steps the tip trails the field's centre by a constant distance and
#   $D$ grows linearly with it: $2\,dD/da$ by least squares over the last two thirds.

# +
if args.test == "surfing":
    G, lag = release_rate(record, skip=len(loads) // 3)
    tips = [[x, 0.0] for x in record.tip]
    error = G / mesh_toughness - 1
    cli.say(f"surfing: 2 dD/da = {G:.5g} against the mesh toughness {mesh_toughness:.5g} "
            f"({100 * error:+.2f} %); the tip is {lag:.3g} mm behind the field's centre")
    if abs(error) > 0.02:
        warnings.append(f"the surfing crack's release rate is {100 * error:+.1f} % from the "
                        f"mesh's toughness: not steady yet (a smaller ℓ, or more steps at "
                        f"a higher --resolution)")
    out = {"centre_history": loads.tolist(), "tip_lag": lag}
else:
    tension, tips = args.test == "tension", record.tip
    G = record.release_rate() if tension else None  # a turning crack's length: unknown
    error = G / mesh_toughness - 1 if G is not None else None
    broken = body.broken()
    per_width = record.dissipated_energy[-1] / body.side
    # a straight crack across the square has the width's length
    width_error = per_width / mesh_toughness - 1 if broken and tension else None
    k_peak = int(np.argmax(record.force))
    peaked = k_peak < len(loads) - 1  # else the force was still rising: no peak
    cli.say((f"peak force {record.force[k_peak]:.4g} kN at U = {loads[k_peak]:.4g} mm; "
             if peaked else "no peak: the force still rises at the last step; ")
            + (f"broken: D/L = {per_width:.5g} against the mesh toughness "
               f"{mesh_toughness:.5g} ({100 * width_error:+.2f} %)"
               if width_error is not None
               else "broken" if broken else "not broken by the last step"))
    if not broken:
        warnings.append("the crack has not crossed the square by the last step: raise "
                        "--displacement")
    out = {"peak_force": record.force[k_peak] if peaked else None,
           "peak_displacement": float(loads[k_peak]) if peaked else None,
           "force_history": record.force, "displacement_history": loads.tolist(),
           "broken": broken, "dissipated_energy_per_width": per_width,
           "dissipated_energy_per_width_rel_error": width_error,
           # how far the tip strayed from the notch's line (tension: a straight crack)
           "crack_straightness": (max(abs(y - body.notch_tip[1]) for _, y in tips)
                                  if tension else None),
           "reactions": body.reactions()}
if args.model == "at2":
    warnings.append("AT2 damages the whole body before a crack forms (no elastic phase)")
# -

# ## Outputs
#
# The JSON (its keys `peak_force`, `crack_tip_history`, `energy_release_rate`,
# `dissipated_energy` and the solver counts), and when asked the picture.

# +
out |= {"test": args.test, "model": args.model, "split": args.split, "ell": args.ell,
        "h": body.h, "crack_tip_history": tips,
        "energy_release_rate": G, "energy_release_rate_rel_error": error,
        "mesh_toughness": mesh_toughness,
        "dissipated_energy": record.dissipated_energy[-1],
        "dissipated_energy_history": record.dissipated_energy,
        "alternate_iterations": record.iterations,
        "newton_iterations": record.newton_iterations,
        "damage_iterations": record.damage_iterations, "acceleration": args.acceleration,
        "dofs": body.dofs, "ranks": MPI.COMM_WORLD.size, "warnings": warnings}
# three steps: the last before the crack moves, the first after, the last (surfing: the
# first, the middle, the last)
extension = np.linalg.norm(np.array(tips) - tips[0], axis=1)
moved = np.flatnonzero(extension > 0)
first = int(moved[0]) if len(moved) and args.test != "surfing" else len(tips) // 2
shown = sorted({0 if args.test == "surfing" else max(first - 1, 0), first, len(tips) - 1})
# -

writers = ([lambda: crack_pictures.crack_figure(out, body.A, record.damage, shown,
                                                args.plot)] if args.plot else [])
cli.results(out, writers)
