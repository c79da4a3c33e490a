# # A bar that breaks: the course's brittle damage law, its closed form and its localization
#
# The course's overview models brittle damage by a stiffness that falls with a damage
# variable $\alpha \in [0, 1)$, $A(\alpha) = A_0 (1 - \alpha)$, and an irreversible
# threshold law:
#
# $$ \varepsilon : A(\alpha) : \varepsilon < w_c \Rightarrow \dot\alpha = 0, \qquad
#    \varepsilon : A(\alpha) : \varepsilon = w_c \Rightarrow \dot\alpha \ge 0 . $$
#
# This demo computes a bar in tension with it, first uniform, then with a weak spot, and
# shows what a user of such a law must know: its response softens, the damage localizes in
# one element, and the energy it takes to break the bar goes to zero as the mesh is refined.
# This is why the regularised (gradient) damage models exist.
#
# ## Problem definition
#
# In 1D ($A_0 = E$) the threshold reads $E(1-\alpha)\varepsilon^2 = w_c$. Nothing happens up
# to $\varepsilon_c = \sqrt{w_c/E}$, $\sigma_c = \sqrt{E w_c}$; beyond, while the strain grows,
# $1 - \alpha = w_c/(E\varepsilon^2)$ and
#
# $$ \sigma = E\varepsilon \ (\varepsilon \le \varepsilon_c), \qquad
#    \sigma = \frac{w_c}{\varepsilon} \ (\varepsilon > \varepsilon_c): $$
#
# the stress falls as the strain grows. Damaging dissipates $Y\,d\alpha$ with
# $Y = \tfrac12 E \varepsilon^2$, i.e. $w_c\, d\varepsilon/\varepsilon$ per unit volume: from
# $\sigma_c$ down to $\rho\,\sigma_c$ a damaged volume dissipates $w_c \ln(1/\rho)$.
#
# A uniform bar stays uniform (the closed form, exactly). But a bar of length $L$ whose
# first element (size $h$) is a little weaker damages in that element only: the others
# unload elastically as the stress falls. Its end displacement is
# $U = \sigma (L - h)/E + h\, w_c/\sigma$, which *decreases* past the peak if $L > 2h$ (a
# snap-back: displacement control cannot follow it), and the energy dissipated to bring the
# stress down to $\rho\,\sigma_c$ is
#
# $$ D = A\, h\, w_c \ln(1/\rho) \;\longrightarrow\; 0 \quad (h \to 0). $$
#
# ## Implementation

# +
import math
from dataclasses import dataclass
from typing import ClassVar

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np

from fenics_nl.io import cli
from fenics_nl.io.parameters import Parameters, choice, number
from fenics_nl.materials.damage import CourseDamage
from fenics_nl.scenes import damage_bar_pictures
from fenics_nl.scenes.damage_bar import DamageBar
from fenics_nl.solvers.arclength import ArcLength
from fenics_nl.solvers.newton import NewtonSolver

# -

# ### Parameters
#
# From the command line (`python demos/damage_bar.py --help`); in a notebook, the defaults.

# +
@dataclass
class Bar(Parameters):
    """A bar in tension with the course's brittle damage law: the uniform bar against the
    closed form, then a weak spot where the damage localizes, and the dissipated energy
    against the mesh size. Units are the user's, consistent."""

    EPILOG = ("PETSc options take the prefix -bar_ (the Newton solves' KSP) and "
              "-bar_arc_ (the continuation's), e.g. -bar_ksp_view.")
    OUTPUTS: ClassVar = {"plot": "stress against mean strain: the closed form, the uniform bar, "
                                 "the localized bars of every mesh"}

    model: str = choice("local", ["local"], "the damage law: the course's local law (the "
                        "gradient models AT1, AT2 are not built yet)")
    E: float = number(1.0, "Young's modulus", unit="stress", above=0)
    wc: float = number(1e-4, "the threshold w_c of ε:A(α):ε", unit="stress", above=0)
    length: float = number(1.0, "bar length L", unit="length", above=0)
    cells: int = number(10, "cells along the bar (the coarsest mesh of the table)",
                        at_least=3)
    refinements: int = number(3, "meshes of the table: cells, 2 cells, ... (each halves h)",
                              at_least=1, at_most=6)
    strain: float = number(4.0, "the uniform bar's final strain, in units of ε_c", unit="-",
                           above=1)
    steps: int = number(12, "the uniform bar's equal strain steps", at_least=2)
    weak: float = number(0.9, "the weak spot's w_c factor (the first cell)", unit="-",
                         above=0, at_most=0.999)
    stress_ratio: float = number(0.1, "the localized bars are followed down to this fraction "
                                 "ρ of their peak stress", unit="-", above=0, at_most=0.9)


args = cli.arguments(Bar, prefixes={"bar_": "Newton's KSP", "bar_arc_": "arc-length"})
eps_c, sigma_c = math.sqrt(args.wc / args.E), math.sqrt(args.E * args.wc)
# -

# ### The uniform bar against the closed form
#
# `DamageBar` is a strip one cell high in plane strain at ν = 0: a uniaxial stress state.
# `CourseDamage` writes the law as the derivative of the step's condensed energy
# $\psi(\varepsilon) = \tfrac12 (1-\alpha_n) W_0$ below the threshold and
# $\tfrac12 w_c (1 + \ln r)$ above it ($W_0 = \varepsilon:A_0:\varepsilon$,
# $r = (1-\alpha_n) W_0/w_c$), so that σ and the consistent tangent come from UFL; the
# damage is committed only after a step has converged. The right end is moved in equal
# strain steps; the stress is read from its reaction.

# +
height = args.length / args.cells  # the cross-section, the same on every mesh
bar = DamageBar(CourseDamage(args.E, 0.0, w_c=args.wc), args.length, args.cells,
                height=height)
uniform = []  # (strain, stress) of every step
iterations = 0
for strain in np.linspace(0.0, args.strain * eps_c, args.steps + 1)[1:]:
    solve = NewtonSolver(bar.residual, bar.u, bar.stretch_supports(strain), rtol=1e-12,
                         atol=1e-12, force_scale=sigma_c * bar.cross_section, prefix="bar_")
    iterations += solve.solve().iterations
    bar.commit()
    uniform.append((float(strain), bar.reaction_stress()))
exact = [args.E * e if e <= eps_c else args.wc / e for e, _ in uniform]
uniform_error = max(abs(s / x - 1) for (_, s), x in zip(uniform, exact, strict=True))
cli.say(f"uniform bar: σ against the closed form within {uniform_error:.1e} over "
        f"{args.steps} steps to {args.strain:g} ε_c ({iterations} Newton iterations)")
# -

# ### A weak spot: localization, followed by arc-length
#
# The first cell's $w_c$ is `weak` times the others': past its peak
# $\sigma_{c,w} = \sqrt{E\, w_c \cdot \text{weak}}$ it softens while the rest unloads. A
# traction $\lambda \sigma_{c,w}$ pulls the right end and arc-length continuation
# (`fenics_nl.solvers.arclength`) follows the path, measuring the arc on the weak cell's
# opening (its right edge's displacement), which grows all along even where the bar's end
# snaps back; it stops where λ falls through ρ. The dissipated energy is the external work
# less the stored elastic energy.

# +
def localize(cells):
    """The weak-spot bar of `cells` cells followed to ρ σ_c,w: its record."""
    b = DamageBar(CourseDamage(args.E, 0.0, w_c=args.wc), args.length, cells,
                  weak=args.weak, height=height)
    solver = NewtonSolver(b.residual, b.u, b.supports, rtol=1e-10, atol=1e-12,
                          force_scale=b.sigma_ref * b.cross_section, max_it=30,
                          prefix="bar_")
    arc = ArcLength(solver, b.set_load, arc_length=0.02, max_arc_length=0.05, psi=0.0,
                    metric_dofs=b.opening_dofs, detect=False, commit=b.commit,
                    prefix="bar_arc_")
    path = [(0.0, 0.0)]  # (end displacement, stress)
    arc.run(args.stress_ratio, 5000, descending=True,
            on_step=lambda lam, r: path.append((b.end_displacement(), lam * b.sigma_ref)))
    U, s = np.array(path).T
    work = float(np.sum(0.5 * (s[1:] + s[:-1]) * np.diff(U)) * b.cross_section)
    dissipated = work - b.stored_energy()
    expected = b.cross_section * b.h * args.wc * args.weak * math.log(1 / args.stress_ratio)
    return {"cells": cells, "h": b.h, "dissipated_energy": dissipated,
            "dissipated_energy_expected": expected,
            "dissipated_energy_rel_error": dissipated / expected - 1,
            "damaged_cells": b.damaged_cells(), "largest_damage": b.largest_damage(),
            "peak_stress": float(s.max()), "steps": len(path) - 1,
            "mean_strain": (U / args.length).tolist(), "stress": s.tolist(), "dofs": b.dofs}


table = [localize(args.cells * 2**k) for k in range(args.refinements)]
for t in table:
    cli.say(f"h = {t['h']:.4g}: damage in {t['damaged_cells']} cell(s), dissipated "
            f"{t['dissipated_energy']:.5e} (A h w_c ln(1/ρ) = "
            f"{t['dissipated_energy_expected']:.5e}, {100 * t['dissipated_energy_rel_error']:+.3f}"
            f" %), {t['steps']} arc-length steps")
# -

# ## What the table says
#
# Every mesh localizes the damage in its weak cell, and each dissipates what one cell of
# its size can: halving $h$ halves the energy it takes to break the bar. On a fine enough
# mesh a crack would cost nothing, which no material does: the local law has no length
# scale. The gradient damage models add one, $\ell$, and dissipate $G_c$ per unit area
# whatever the mesh.

# +
localized = all(t["damaged_cells"] == 1 for t in table)
ratios = [t["dissipated_energy"] / t["h"] for t in table]
cli.say(f"dissipated energy / h: {', '.join(f'{r:.5e}' for r in ratios)} (constant: the "
        f"energy goes to zero with h)" if localized else "the damage did not localize")
out = {"model": args.model, "critical_stress": sigma_c, "critical_strain": eps_c,
       "critical_stress_exact": sigma_c, "uniform_max_rel_error": uniform_error,
       "strain_history": [e for e, _ in uniform], "stress_history": [s for _, s in uniform],
       "stress_exact": exact, "newton_iterations": iterations,
       "weak_critical_stress": math.sqrt(args.E * args.wc * args.weak),
       "cross_section": bar.cross_section,
       "localized": localized, "mesh_table": table,
       "dissipated_energy": table[-1]["dissipated_energy"],
       "dissipated_energy_expected": table[-1]["dissipated_energy_expected"],
       "dofs": bar.dofs, "ranks": bar.mesh.comm.size,
       "warnings": ["local damage: the dissipated energy depends on the mesh (it is one "
                    "cell's), not a material property"]}
# -

# ## Outputs
#
# The JSON, and when asked the stress against the mean strain: the closed form, the uniform
# bar, and the localized bars, whose end snaps back the more the finer the mesh.

writers = ([lambda: damage_bar_pictures.stress_strain(out, args.plot, args.E, args.wc)]
           if args.plot else [])
cli.results(out, writers)
