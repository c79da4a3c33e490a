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
import math
from dataclasses import dataclass
from typing import ClassVar

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.domain.damage_specimens import (
    BOTTOM,
    LEFT,
    NOTCH,
    PRECRACK,
    RIGHT,
    TOP,
    notched_square,
    surfing_strip,
)
from fenics_nl.io import cli
from fenics_nl.io.parameters import Parameters, choice, number
from fenics_nl.materials import kinematics
from fenics_nl.materials.gradient_damage import GradientDamage, crack_tip
from fenics_nl.plots import damage as damage_pictures
from fenics_nl.solvers.alternate import AlternateMinimization, AlternateWork

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

comm = MPI.COMM_WORLD
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
surfing = args.test == "surfing"
h = args.ell / args.resolution  # the cells' size where the crack goes
warnings = []
# -

# ### The mesh and its tags
#
# Square cells of $h = \ell/$`resolution` where the crack can go, growing geometrically
# (ratio 1.3) away from it (`graded_grid`). The factories tag the sides `LEFT`, `RIGHT`,
# `BOTTOM`, `TOP`, and the pre-crack:
#
# * `notched_square`: the square $[0, 1]^2$ mm, fine within $3\ell$ of the notch's line
#   from $3\ell$ behind the notch's tip to the right side (and in shear the lower right
#   quarter, where the crack turns). Its rows of nodes are at $0.5 \pm h/2$: the notch is
#   the cell tag `NOTCH`, the band of one cell between them up to the centre, which is
#   what a crack of the mesh is (a line of nodes at $\alpha = 1$ alone would still carry
#   stress through its neighbouring cells).
# * `surfing_strip`: the half strip $[0, 1] \times [0, 0.3]$ mm (its length a whole number
#   of cells: the field moves by whole cells), fine up to $3\ell$ above the crack's line
#   $y = 0$, whose first 0.3 mm are the facet tag `PRECRACK` (the rest is `BOTTOM`).

# +
if surfing:
    height, notch = 0.3, 0.3
    cells = round(1.0 / h)
    length = cells * h
    msh, facet_tags = surfing_strip(comm, h, cells, height=height, notch=notch,
                                    fine=3 * args.ell)
else:
    side, notch = 1.0, 0.5
    notch_tip = np.array([notch, side / 2])
    msh, cell_tags, facet_tags = notched_square(comm, h, args.test, width=3 * args.ell,
                                                side=side)
# -

# ### The function spaces, the pre-crack and the supports
#
# P1 displacements $u$ and a P1 damage $\alpha$. The pre-crack is $\alpha = 1$, a Dirichlet
# condition of the damage on the nodes of `NOTCH` or `PRECRACK`.
#
# * Notched square: the bottom clamped; the top moved rigidly by $U$ (its value set at each
#   step), up (tension, $u_x = 0$ there) or to the right (shear, $u_y = 0$ there and on the
#   sides).
# * Surfing: $u_y = 0$ on the crack's line (the symmetric half: the crack's opening is the
#   strain of its damaged band, as in the whole plate), and on the rest of the boundary
#   Irwin's displacement around a tip at $(x_c, 0)$,
#
#   $$ u = \frac{K}{2\mu}\sqrt{\frac{r}{2\pi}}\,(\kappa - \cos\theta)
#      \big(\cos\tfrac\theta2, \sin\tfrac\theta2\big), \qquad \kappa = 3 - 4\nu, $$
#
#   with $K = \sqrt{G_h E/(1-\nu^2)}$, interpolated into a Function at each position.

# +
V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
A = fem.functionspace(msh, ("Lagrange", 1))
u = fem.Function(V, name="displacement")
alpha = fem.Function(A, name="damage")
facets = {name: facet_tags.find(tag) for name, tag in
          (("left", LEFT), ("right", RIGHT), ("bottom", BOTTOM), ("top", TOP))}
if surfing:
    crack_line = np.concatenate([facets["bottom"], facet_tags.find(PRECRACK)])
    cracked = fem.locate_dofs_topological(A, 1, facet_tags.find(PRECRACK))
    outer = fem.locate_dofs_topological(
        V, 1, np.concatenate([facets["left"], facets["top"], facets["right"]]))
    g = fem.Function(V)  # Irwin's field, on the outer sides but the crack's line
    bcs = [boundary.component(V, 1, crack_line),
           fem.dirichletbc(g, np.setdiff1d(outer, fem.locate_dofs_topological(V, 1,
                                                                              crack_line)))]
else:
    msh.topology.create_connectivity(2, 2)  # the cells' own entities, to locate their dofs
    cracked = fem.locate_dofs_topological(A, 2, cell_tags.find(NOTCH))
    moving = 0 if args.test == "shear" else 1  # the top's moving component
    top_motion = boundary.component(V, moving, facets["top"])
    bcs = [boundary.fixed(V, facets["bottom"]), top_motion,
           boundary.component(V, 1 - moving, facets["top"])]
    if args.test == "shear":
        facets["sides"] = np.concatenate([facets["left"], facets["right"]])
        bcs.append(boundary.component(V, 1, facets["sides"]))
alpha.x.array[cracked] = 1.0
precrack = fem.dirichletbc(1.0, cracked, A)
# -

# ### The law, its energy and the solver
#
# `GradientDamage`, the energy $\mathcal E(u, \alpha)$ above written in UFL (with the split,
# `elastic_energy` degrades $\psi_0^+$ only and keeps $\psi_0^-$ whole), and an
# `AlternateMinimization` of it: at each step, $u$ at fixed $\alpha$ by Newton, $\alpha$ at
# fixed $u$ within $\alpha_{n-1} \le \alpha \le 1$ by PETSc's SNES `vinewtonrsls`, until
# $\alpha$ changes by less than $10^{-6}$ (surfing $10^{-8}$), Anderson-accelerated by
# default. Its force scale is $\sigma_c h$ (surfing $K\sqrt h$), its damage scale
# $G_c h^2/\ell$: a node's share of the energy.

# +
law = GradientDamage(args.E, args.nu, Gc=args.Gc, ell=args.ell, model=args.model,
                     residual_stiffness=1e-6, split=args.split)
eps = kinematics.small_strain(u, "plane_strain")  # 3x3, ε_zz = 0
dissipation = law.Gc / law.c_w * (law.w(alpha) / law.ell
                                  + law.ell * ufl.inner(ufl.grad(alpha), ufl.grad(alpha)))
energy = (law.elastic_energy(eps, alpha) + dissipation) * ufl.dx  # a(α) ψ0 (+ the split)
if surfing:  # a crack on the strip's symmetry line: two half bands
    mesh_toughness = args.Gc * (1 + 2 * h / (law.c_w * args.ell))
    K = math.sqrt(mesh_toughness * args.E / (1 - args.nu**2))
    solver = AlternateMinimization(energy, u, alpha, bcs, damage_bcs=[precrack],
                                   force_scale=K * math.sqrt(h),
                                   damage_scale=law.Gc / law.ell * h**2,
                                   acceleration=args.acceleration)
else:
    mesh_toughness = args.Gc * (1 + h / (law.c_w * args.ell))
    solver = AlternateMinimization(energy, u, alpha, bcs, damage_bcs=[precrack],
                                   force_scale=law.critical_stress * h,
                                   damage_scale=law.Gc / law.ell * h**2, tol=1e-6,
                                   max_it=2000, acceleration=args.acceleration)
fracture = fem.form(law.fracture_energy(alpha) * ufl.dx)  # the dissipated energy
residual = fem.form(solver.residual_u)  # ∂E/∂u: the supports' reactions
dofs = V.dofmap.index_map.size_global * 2 + A.dofmap.index_map.size_global
if args.resolution < 2:
    warnings.append(f"ℓ is smaller than two elements (ℓ/h = {args.resolution:g}): a crack "
                    f"dissipates {mesh_toughness:.4g} kN/mm, not G_c = {args.Gc:g} kN/mm")
cli.known(dofs=dofs, ranks=comm.size, mesh_toughness=mesh_toughness)
cli.say(f"{args.test}: {dofs} unknowns, h = {h:.4g} mm where the crack goes")
# -

# ### Load steps
#
# The top is moved (or the K-field's centre, by $2h$ a step from the notch's tip, up to a
# strip's height from its end: the K-field is the far field). Each step is minimized and
# committed ($\alpha_n$ becomes the lower bound: a crack does not heal) and prints its
# force, crack tip and dissipated energy
# $D = \int \frac{G_c}{c_w}(w(\alpha)/\ell + \ell|\nabla\alpha|^2)$. The tip is the broken
# node farthest from the notch's: $\alpha \ge 0.9$ ahead of the notch (a crack of the mesh
# is a band of cells at $\alpha = 1$, whose neighbours' nodes are at most
# $(1 - h/(2\ell))^2$, 0.56 at $\ell/h = 2$), or on the surfing crack's line
# $\alpha \ge 0.5$.

# +
if surfing:
    room = int((length - height - notch) / (2 * h)) + 1
    if args.steps > room:
        raise ValueError(f"--steps: the strip holds {room} positions of the field 2h apart "
                         f"at ell/h = {args.resolution:g} (its centre {height:g} from the "
                         f"end at most)")
    loads = notch + 2 * h * np.arange(args.steps)
    mu, kappa = args.E / (2 * (1 + args.nu)), 3 - 4 * args.nu
else:
    loads = np.linspace(0.0, args.displacement or FINAL[args.test], args.steps + 1)[1:]


def irwin(x, centre):
    """Irwin's mode-I displacement around a tip at (centre, 0)."""
    r, theta = np.hypot(x[0] - centre, x[1]), np.arctan2(x[1], x[0] - centre)
    amplitude = K / (2 * mu) * np.sqrt(r / (2 * np.pi)) * (kappa - np.cos(theta))
    return np.vstack([amplitude * np.cos(theta / 2), amplitude * np.sin(theta / 2)])


work, dissipated, damage, force, tips = AlternateWork(), [], [], [], []
for k, load in enumerate(loads):
    if surfing:
        g.interpolate(lambda x, centre=load: irwin(x, centre))
    else:
        top_motion.g.x.array[:] = load
    work.count(solver.solve())
    solver.commit()
    dissipated.append(comm.allreduce(fem.assemble_scalar(fracture), op=MPI.SUM))
    damage.append(alpha.x.array.copy())  # for the pictures
    if surfing:
        tips.append([crack_tip(alpha, (0.0, 0.0), level=0.5,
                               where=lambda x: np.isclose(x[1], 0.0))[0], 0.0])
    else:
        force.append(boundary.reactions(residual, u, {"top": facets["top"]})["top"][moving])
        tips.append(crack_tip(alpha, notch_tip, level=0.9,
                              where=lambda x: x[0] > notch + 1e-9 * side))
    step = {"load_factor": (k + 1) / len(loads), "load": float(load), "tip": tips[-1],
            "dissipated_energy": dissipated[-1]} | ({} if surfing else {"force": force[-1]})
    cli.converged_step(step)  # kept for the JSON of a run that fails later
    cli.say(f"step {k + 1}/{len(loads)}: {'x_c' if surfing else 'U'} = {load:.4g}"
            + ("" if surfing else f", F = {force[-1]:.4g} kN")
            + f", tip ({tips[-1][0]:.3f}, {tips[-1][1]:.3f}), D = {dissipated[-1]:.4g}, "
            f"{work.iterations[-1]} alternate iterations")
# -

# ## What the steps say
#
# * Tension: the force grows almost linearly, the damage at the notch's tip stays small, and
#   at the peak the crack runs through the ligament in one or two steps (brutally: the plain
#   alternate minimization then takes a hundred iterations or more, Anderson's a few tens).
#   It is straight: its tip stays on $y = 0.5$ within a cell (the JSON's
#   `crack_straightness`).
#   Once broken, the square has dissipated $G_h$ per unit width. The energy release rate
#   measured between the first step and the last, $(D_{end} - D_1)/\Delta a$ ($\Delta a$ the
#   tip's path, the JSON's `energy_release_rate`), reads a little low: $D_1$ includes the
#   damage around the notch's tip (about $G_c\ell$), which the crack that leaves the square
#   no longer has.
# * Shear: the crack leaves the notch downwards and reaches the right side or the bottom.
#   Its length is not measured (its tip jumps in one step along a path that turns), so
#   neither is its energy release rate.
# * Surfing: after a few steps the tip trails the field's centre by a constant distance and
#   $D$ grows linearly with it: $2\,dD/da$ by least squares over the last two thirds.

# +
if surfing:
    skip = len(loads) // 3
    a = np.array([x for x, _ in tips[skip:]])
    G = 2 * np.polyfit(a, np.array(dissipated[skip:]), 1)[0]
    lag = float(np.mean(loads[skip:] - a))  # the tip behind the field's centre
    error = G / mesh_toughness - 1
    cli.say(f"surfing: 2 dD/da = {G:.5g} against the mesh toughness {mesh_toughness:.5g} "
            f"({100 * error:+.2f} %); the tip is {lag:.3g} mm behind the field's centre")
    if abs(error) > 0.02:
        warnings.append(f"the surfing crack's release rate is {100 * error:+.1f} % from the "
                        f"mesh's toughness: not steady yet (a smaller ℓ, or more steps at "
                        f"a higher --resolution)")
    out = {"centre_history": loads.tolist(), "tip_lag": lag}
else:
    tension = args.test == "tension"
    extension = np.cumsum(np.linalg.norm(np.diff(np.array(tips), axis=0), axis=1))[-1]
    # a turning crack's length is not known
    G = (dissipated[-1] - dissipated[0]) / extension if tension and extension > 0 else None
    error = G / mesh_toughness - 1 if G is not None else None
    x, y = tips[-1]
    broken = x >= side * (1 - 1e-9) or y <= 1e-9 * side  # at the right side or the bottom
    per_width = dissipated[-1] / side
    # a straight crack across the square has the width's length
    width_error = per_width / mesh_toughness - 1 if broken and tension else None
    k_peak = int(np.argmax(force))
    peaked = k_peak < len(loads) - 1  # else the force was still rising: no peak
    cli.say((f"peak force {force[k_peak]:.4g} kN at U = {loads[k_peak]:.4g} mm; "
             if peaked else "no peak: the force still rises at the last step; ")
            + (f"broken: D per unit width {per_width:.5g} against the mesh toughness "
               f"{mesh_toughness:.5g} ({100 * width_error:+.2f} %)"
               if width_error is not None
               else "broken" if broken else "not broken by the last step"))
    if not broken:
        warnings.append("the crack has not crossed the square by the last step: raise "
                        "--displacement")
    out = {"peak_force": force[k_peak] if peaked else None,
           "peak_displacement": float(loads[k_peak]) if peaked else None,
           "force_history": force, "displacement_history": loads.tolist(),
           "broken": broken, "dissipated_energy_per_width": per_width,
           "dissipated_energy_per_width_rel_error": width_error,
           # how far the tip strayed from the notch's line (tension: a straight crack)
           "crack_straightness": (max(abs(y - notch_tip[1]) for _, y in tips)
                                  if tension else None),
           "reactions": boundary.reactions(residual, u, {k: facets[k] for k in
                                                         ("top", "bottom", "sides")
                                                         if k in facets})}
if args.model == "at2":
    warnings.append("AT2 damages the whole body before a crack forms (no elastic phase)")
# -

# ## Outputs
#
# The JSON (its keys `crack_tip_history`, `energy_release_rate`, `dissipated_energy`, the
# solver counts, and for the notched square `peak_force`), and when asked the picture: the
# curve, and the damage at three steps (the last before the crack moves, the first after, the last;
# surfing: the first, the middle, the last).

# +
out |= {"test": args.test, "model": args.model, "split": args.split, "ell": args.ell,
        "h": h, "crack_tip_history": tips,
        "energy_release_rate": G, "energy_release_rate_rel_error": error,
        "mesh_toughness": mesh_toughness,
        "dissipated_energy": dissipated[-1], "dissipated_energy_history": dissipated,
        "alternate_iterations": work.iterations,
        "newton_iterations": work.newton_iterations,
        "damage_iterations": work.damage_iterations, "acceleration": args.acceleration,
        "dofs": dofs, "ranks": comm.size, "warnings": warnings}
moved = np.flatnonzero(np.linalg.norm(np.array(tips) - tips[0], axis=1) > 0)
first = int(moved[0]) if len(moved) and not surfing else len(tips) // 2
shown = sorted({0 if surfing else max(first - 1, 0), first, len(tips) - 1})
if surfing:
    title = (f"surfing: 2 dD/da = {G:.4g} kN/mm (mesh toughness {mesh_toughness:.4g})")
    writers = [lambda: damage_pictures.surfing_figure(args.plot, A, damage, shown, loads,
                                               [x for x, _ in tips], title=title)]
else:
    title = (f"{args.test}: {args.model.upper()}, ℓ = {args.ell:g} mm, "
             f"h = ℓ/{args.ell / h:.3g}")
    writers = [lambda: damage_pictures.notched_figure(args.plot, A, damage, shown, loads, force,
                                               peak_force=out["peak_force"], title=title)]
# -

cli.results(out, writers if args.plot else [])
