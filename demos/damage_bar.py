# # A bar that breaks: the course's local damage law, then gradient damage (AT1, AT2)
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
# ### Gradient damage (`--model at1`, `--model at2`)
#
# The variational models add a length $\ell$: the energy of $(u, \alpha)$ is
#
# $$ \mathcal E(u, \alpha) = \int a(\alpha)\, \psi_0(\varepsilon(u))
#    + \frac{G_c}{c_w}\Big(\frac{w(\alpha)}{\ell} + \ell\, |\nabla\alpha|^2\Big),
#    \qquad a(\alpha) = (1-\alpha)^2 + k, $$
#
# with $w = \alpha$, $c_w = 8/3$ (AT1) or $w = \alpha^2$, $c_w = 2$ (AT2), minimized at each
# load under $\alpha_{n-1} \le \alpha \le 1$ (irreversibility). The uniform bar has a
# homogeneous solution from the same energy (AT1: elastic up to
# $\sigma_c = \sqrt{3 G_c E/(8\ell)}$, then $1 - \alpha = \varepsilon_c^2/\varepsilon^2$),
# but it is an equilibrium, not necessarily a minimum: its second variation on the damage's
# inactive set, for a damage perturbation $\beta$ of zero mean (the displacement condensed
# out),
#
# $$ -3E\varepsilon^2 \int \beta^2 + \frac{G_c}{c_w}\int \Big(\frac{w''}{\ell}\beta^2 +
#    2\ell\,\beta'^2\Big), $$
#
# turns negative along $\cos(\pi x/L)$ at
#
# $$ 3E\varepsilon_b^2 = \frac{G_c}{c_w}\Big(\frac{w''}{\ell} + \frac{2\ell\pi^2}{L^2}\Big)
#    \quad (\text{AT1: not before } \varepsilon_c). $$
#
# Past it the bar leaves the homogeneous branch along that mode and a crack forms. A bar held
# undamaged at both ends cracks in its middle; a fully developed crack dissipates $G_c$ per
# unit section (its profile $(1 - |x|/(2\ell))^2$ on each side, AT1) plus, on P1 elements,
# a band of one cell at $\alpha = 1$: $D = G_c\,(1 + h/(c_w \ell))$, whatever the mesh.
#
# ## Implementation

# +
import math
from dataclasses import dataclass
from typing import ClassVar

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
from mpi4py import MPI

from fenics_nl.io import cli
from fenics_nl.io.parameters import Parameters, choice, number
from fenics_nl.materials.damage import CourseDamage
from fenics_nl.materials.gradient_damage import GradientDamage
from fenics_nl.scenes import damage_bar, damage_bar_pictures, gradient_damage_bar
from fenics_nl.scenes.gradient_damage_bar import GradientDamageBar

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

# -

# ### Parameters
#
# From the command line (`python demos/damage_bar.py --help`); in a notebook, the defaults.

# +
@dataclass
class Bar(Parameters):
    """A bar in tension with a damage law: the uniform bar against the closed form, then a
    crack: where the local law's energy goes to zero with the mesh, and the gradient laws'
    tends to Gc. Units are the user's, consistent."""

    EPILOG = ("PETSc options take the prefix -bar_ (the local law's Newton KSP), -bar_arc_ "
              "(its continuation), -damage_ (the gradient laws' damage SNES) and "
              "-stability_ (their eigensolver), e.g. -bar_ksp_view.")
    OUTPUTS: ClassVar = {"plot": "stress against mean strain with the closed form; for "
                                 "gradient damage also the crack's profile"}

    model: str = choice("local", ["local", "at1", "at2"], "the damage law: the course's "
                        "local law, or gradient damage AT1, AT2")
    E: float = number(1.0, "Young's modulus", unit="stress", above=0)
    wc: float = number(1e-4, "local law: the threshold w_c of ε:A(α):ε", unit="stress",
                       above=0)
    Gc: float = number(1.0, "gradient laws: the toughness G_c", unit="stress·length", above=0)
    ell: float = number(0.1, "gradient laws: the length ℓ", unit="length", above=0)
    length: float = number(1.0, "bar length L", unit="length", above=0)
    cells: int = number(10, "local law: cells along the bar (the coarsest mesh of the table)",
                        at_least=3)
    resolution: float = number(5.0, "gradient laws: ℓ/h on the coarsest mesh (below 2 the "
                               "crack dissipates visibly more than G_c)", unit="-", above=0)
    refinements: int = number(3, "meshes of the table, each halving h", at_least=1,
                              at_most=6)
    strain: float = number(4.0, "the final mean strain, in units of the peak's (the uniform "
                           "bar's, and the gradient laws' cracked bars')", unit="-", above=1)
    steps: int = number(12, "the equal strain steps to it", at_least=2)
    weak: float = number(0.9, "local law: the weak spot's w_c factor (the first cell)",
                         unit="-", above=0, at_most=0.999)
    stress_ratio: float = number(0.1, "local law: the localized bars are followed down to "
                                 "this fraction ρ of their peak stress", unit="-", above=0,
                                 at_most=0.9)
    acceleration: str = choice("none", ["none", "overrelaxed", "anderson"], "gradient laws: "
                               "the alternate minimization's acceleration")


args = cli.arguments(Bar, prefixes={"bar_": "Newton's KSP", "bar_arc_": "arc-length",
                                    "damage_": "the damage SNES",
                                    "stability_": "the stability eigensolver"})
local = args.model == "local"
if local:
    law = CourseDamage(args.E, 0.0, w_c=args.wc)
else:
    law = GradientDamage(args.E, 0.0, Gc=args.Gc, ell=args.ell, model=args.model,
                         residual_stiffness=1e-6)
# the peak of the homogeneous response: ε_c for the local law and AT1, AT2's maximum
peak_strain = law.critical_strain or math.sqrt(args.Gc / (3 * args.ell * args.E))
sigma_c = law.critical_stress
warnings = []
# -

# ### The uniform bar against the closed form
#
# `DamageBar` is a strip one cell high in plane strain at ν = 0: a uniaxial stress state,
# its right end moved in equal strain steps and the stress read from its reaction.
#
# * The local law (`CourseDamage`) is written as the derivative of the step's condensed
#   energy, $\psi = \tfrac12 (1-\alpha_n) W_0$ below the threshold and
#   $\tfrac12 w_c (1 + \ln r)$ above it ($W_0 = \varepsilon:A_0:\varepsilon$,
#   $r = (1-\alpha_n) W_0/w_c$), so that σ and the consistent tangent come from UFL; each
#   step is a Newton solve and the damage is committed once it has converged.
# * The gradient laws' bar (`GradientDamageBar`, $\nabla\alpha\cdot n = 0$ at its ends) is
#   minimized at each step by alternate minimization: u at fixed α by Newton, α at fixed u
#   by PETSc's bound-constrained SNES (`vinewtonrsls`). After each step, the second
#   variation's smallest eigenvalue on the damage's inactive set (the tangent's inertia,
#   then shift-and-invert); where it turns negative the bar leaves its branch along the
#   eigenvector's damage, and the step is minimized again from there.

# +
strains = np.linspace(0.0, args.strain * peak_strain, args.steps + 1)[1:]


def keep(k, strain, stress):
    """A converged step, kept for the JSON of a run that fails later."""
    cli.converged_step({"load_factor": (k + 1) / args.steps, "strain": strain,
                        "stress": stress})



height = args.length / args.cells  # the local bars' cross-section, the same on every mesh
if local:
    uniform, iterations = damage_bar.uniform(law, args.length, args.cells, strains,
                                             height=height,
                                             on_step=lambda k, p: keep(k, *p[-1]))
    bifurcation = None
else:
    cells = math.ceil(args.resolution * args.length / args.ell)
    bar = GradientDamageBar(law, args.length, cells, acceleration=args.acceleration)
    height = bar.cross_section
    record = gradient_damage_bar.pull(
        bar, strains, progress=lambda k, r: keep(k, r.strain[-1], r.stress[-1]))
    uniform = list(zip(record.strain, record.stress, strict=True))
    iterations = sum(record.iterations)
    bifurcation = record.bifurcation_strain
    bifurcation_exact = law.bifurcation_strain(args.length)
exact = [law.homogeneous_stress(e) for e in strains]
stable = len(uniform) if local or record.bifurcation_step is None else record.bifurcation_step
uniform_error = max((abs(s / x - 1) for (_, s), x in zip(uniform[:stable], exact[:stable],
                                                        strict=True)), default=0.0)
cli.say(f"uniform bar: σ against the closed form within {uniform_error:.1e} over {stable} "
        f"steps ({iterations} {'Newton' if local else 'alternate'} iterations)")
if bifurcation is not None:
    cli.say(f"the homogeneous state stops being stable at ε = {bifurcation:.5g} (closed form "
            f"{bifurcation_exact:.5g}, {100 * (bifurcation / bifurcation_exact - 1):+.2f} %); "
            f"the bar leaves it along the critical mode: largest α "
            f"{record.largest_damage[-1]:.3f} at the last step")
# -

# ### A crack, on meshes ever finer
#
# * Local law: the first cell's $w_c$ is `weak` times the others'. A traction
#   $\lambda \sigma_{c,w}$ pulls the right end and arc-length continuation follows the path
#   down to $\rho\,\sigma_{c,w}$, measuring the arc on the weak cell's opening, which grows
#   all along even where the bar's end snaps back. The dissipated energy is the external work
#   less the stored elastic energy.
# * Gradient laws: a bar held undamaged at both ends (α = 0 there), an odd number of cells
#   so that its middle is a cell's, pulled to the same final strain; the dissipated energy
#   is $\int \frac{G_c}{c_w}(w(\alpha)/\ell + \ell|\nabla\alpha|^2)$.

# +
if local:
    table = [damage_bar.localize(law, args.length, args.cells * 2**k, weak=args.weak,
                                 height=height, stress_ratio=args.stress_ratio)
             for k in range(args.refinements)]
else:
    odd = [2 * math.ceil(args.resolution * 2**k * args.length / args.ell / 2) + 1
           for k in range(args.refinements)]
    if args.resolution < 2:  # the crack's band of one cell is then a visible share
        h = args.length / odd[0]
        effective = args.Gc * (1 + h / (law.c_w * args.ell))
        warnings.append(f"ℓ is smaller than two elements (ℓ/h = {args.ell / h:.3g}): the "
                        f"crack dissipates G_c (1 + h/(c_w ℓ)) = {effective:.4g}, not "
                        f"G_c = {args.Gc:g}")
        cli.say(f"warning: {warnings[-1]}")
    table = [gradient_damage_bar.crack(law, args.length, n, strains, height=height,
                                       acceleration=args.acceleration) for n in odd]
for t in table:
    cli.say(f"h = {t['h']:.4g}: dissipated {t['dissipated_energy']:.5e}" + (
        f" (expected {t['dissipated_energy_expected']:.5e}, "
        f"{100 * t['dissipated_energy_rel_error']:+.3f} %)"
        if t["dissipated_energy_expected"] is not None else ""))
# -

# ## What the table says
#
# With the local law every mesh localizes the damage in its weak cell, and each dissipates
# what one cell of its size can: halving $h$ halves the energy it takes to break the bar. On
# a fine enough mesh a crack would cost nothing, which no material does: the local law has
# no length scale. The gradient laws add one, $\ell$: their crack dissipates
# $G_c (1 + h/(c_w\ell))$, which tends to $G_c$ per unit area as the mesh is refined. AT2
# dissipates more than its crack's share: it damages the whole bar before the peak
# (irreversibly), which that formula does not count (a warning says so).

# +
if local:
    localized = all(t["damaged_cells"] == 1 for t in table)
    ratios = [t["dissipated_energy"] / t["h"] for t in table]
    cli.say(f"dissipated energy / h: {', '.join(f'{r:.5e}' for r in ratios)} (constant: "
            f"the energy goes to zero with h)" if localized else "the damage did not localize")
    warnings.append("local damage: the dissipated energy depends on the mesh (it is one "
                    "cell's), not a material property")
else:
    localized = all(t["largest_damage"] > 0.99 and math.isclose(t["band_width"], t["h"])
                    for t in table)
    if not localized:
        warnings.append("the crack did not form in every bar by the final strain: raise "
                        "--strain")
    elif args.model == "at1" and max(abs(t["dissipated_energy_rel_error"]) for t in table) > .01:
        warnings.append("a crack dissipates more than 1 % away from G_c (1 + h/(c_w ℓ))")
    if args.model == "at2":
        warnings.append("AT2 damages the whole bar before its crack forms: its dissipated "
                        "energy exceeds the crack's G_c (1 + h/(c_w ℓ)); no expected value")
# -

# ## Outputs
#
# The JSON, and when asked the stress against the mean strain with the closed form (and, for
# gradient damage, the crack's profile against its closed form).
#
# The peak of the homogeneous branch: for AT1, the elastic branch extended to the damage's
# onset (found where the driving force of the elastic steps, affine in ε², vanishes); else
# the largest stress computed on the branch (its stable steps, and the step where it
# bifurcates, before the bar leaves it).

# +
# the peak of the homogeneous branch: its stable steps, and the step where it bifurcates
# (before the bar leaves it)
branch = [s for _, s in uniform[:stable]] + ([] if local or bifurcation is None
                                             else [record.bifurcation_stress])
peak = (max(branch), uniform[int(np.argmax(branch))][0])
if args.model == "at1" and record.damage_onset_strain is not None:
    e_el, s_el = uniform[len(record.elastic_margins) - 1]
    peak = (s_el * record.damage_onset_strain / e_el, record.damage_onset_strain)
out = {"model": args.model, "critical_stress": peak[0], "critical_strain": peak[1],
       "critical_strain_exact": peak_strain, "critical_stress_exact": sigma_c,
       "uniform_max_rel_error": uniform_error,
       "strain_history": [e for e, _ in uniform], "stress_history": [s for _, s in uniform],
       "stress_exact": exact, "iterations": iterations,
       "cross_section": height, "localized": localized, "mesh_table": table,
       "dissipated_energy": table[-1]["dissipated_energy"],
       "dissipated_energy_expected": table[-1]["dissipated_energy_expected"],
       "dofs": table[-1]["dofs"], "ranks": MPI.COMM_WORLD.size,
       "warnings": warnings}
if local:
    out |= {"newton_iterations": iterations, "bifurcation_strain": None,
            "weak_critical_stress": math.sqrt(args.E * args.wc * args.weak)}
else:
    out |= {"bifurcation_strain": bifurcation, "bifurcation_strain_exact": bifurcation_exact,
            "bifurcation_step": record.bifurcation_step,
            # None where no damage could grow (the elastic steps: no finite eigenvalue)
            "lowest_eigenvalue": [x if math.isfinite(x) else None
                                  for x in record.lowest_eigenvalue],
            "largest_damage_history": record.largest_damage,
            "alternate_iterations": record.iterations, "acceleration": args.acceleration}
# -

writers = ([lambda: damage_bar_pictures.stress_strain(out, args.plot, law)]
           if args.plot else [])
cli.results(out, writers)
