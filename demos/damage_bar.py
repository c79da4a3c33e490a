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
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.domain.damage_specimens import BOTTOM, LEFT, RIGHT, bar_strip
from fenics_nl.io import cli
from fenics_nl.io.parameters import Parameters, choice, number
from fenics_nl.materials import kinematics
from fenics_nl.materials.damage import CourseDamage
from fenics_nl.materials.gradient_damage import GradientDamage
from fenics_nl.materials.laws import LinearElastic
from fenics_nl.parallel import global_max
from fenics_nl.plots import damage as damage_pictures
from fenics_nl.solvers.alternate import AlternateMinimization, AlternateWork
from fenics_nl.solvers.arclength import ArcLength
from fenics_nl.solvers.damage_stability import BranchStability, DamageStability
from fenics_nl.solvers.newton import NewtonSolver

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

comm = MPI.COMM_WORLD
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
L = args.length
warnings = []
# -

# ### The bar: its mesh and tags, the displacement and its supports
#
# `bar_strip` is the strip $[0, L] \times [0, H]$ of P1 quadrilaterals, one cell high, with
# the facet tags `LEFT`, `RIGHT`, `BOTTOM` and `TOP`; in plane strain at ν = 0 it is the
# course's 1D bar (a uniaxial stress state). The displacement is P1; the left end slides on
# $x = 0$ ($u_x = 0$ on `LEFT`), the bottom on $y = 0$ ($u_y = 0$ on `BOTTOM`), and the
# right end's $u_x$ is prescribed on `RIGHT` (its value set at each step), or left free and
# pulled by a traction. The demo builds several bars (the mesh table below): `strip` makes
# one of `cells` cells. The local law's bars are $H = L/$`cells` high on every mesh, so
# that their cross-section $A = H$ (per unit thickness) stays; the gradient laws' are
# $L/\lceil L\,$`resolution`$/\ell\rceil$ high, one cell of the uniform bar's mesh.

# +
MODEL = "plane_strain"  # at ν = 0: uniaxial stress


def strip(cells, height):
    """A bar of `cells` cells: mesh, tags, displacement, supports, the right end's u_x."""
    msh, tags = bar_strip(comm, L, cells, height=height)
    V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
    u = fem.Function(V, name="displacement")
    supports = [boundary.component(V, 0, tags.find(LEFT)),
                boundary.component(V, 1, tags.find(BOTTOM))]
    end = boundary.component(V, 0, tags.find(RIGHT))  # its value: the end's displacement
    return msh, tags, V, u, supports, end


if local:
    law = CourseDamage(args.E, 0.0, w_c=args.wc)
    cells, height = args.cells, L / args.cells
else:
    law = GradientDamage(args.E, 0.0, Gc=args.Gc, ell=args.ell, model=args.model,
                         residual_stiffness=1e-6)
    cells = math.ceil(args.resolution * L / args.ell)
    height = L / cells
msh, tags, V, u, supports, end = strip(cells, height)


def stress_at_end(internal, u, tags):
    """σ = the right end's reaction over A, from the internal work (a compiled form in u)."""
    held = boundary.reactions(internal, u, {"right": tags.find(RIGHT)}, {"right": [0]},
                              space=u.function_space)["right"][0]
    return held / height


bcs = [*supports, end]
# the peak of the homogeneous response: ε_c for the local law and AT1, AT2's maximum
peak_strain = law.critical_strain or math.sqrt(args.Gc / (3 * args.ell * args.E))
sigma_c = law.critical_stress
# -

# ### The laws and their residuals
#
# * The local law (`CourseDamage`) is written as the derivative of the step's condensed
#   energy, $\psi = \tfrac12 (1-\alpha_n) W_0$ below the threshold and
#   $\tfrac12 w_c (1 + \ln r)$ above it ($W_0 = \varepsilon:A_0:\varepsilon$,
#   $r = (1-\alpha_n) W_0/w_c$), with $\alpha_n$ at the quadrature points (`bind`): the
#   residual is its internal work $\int \sigma(\varepsilon(u)) : \varepsilon(v)$, σ and the
#   consistent tangent from UFL. Each step is a Newton solve, and the damage is committed
#   once it has converged.
# * The gradient laws add the damage field α, P1, and their energy
#   $\mathcal E(u, \alpha)$ above, written in UFL below (`gradient_energy`), minimized at
#   each step by alternate minimization (`AlternateMinimization`): u at fixed α by Newton,
#   α at fixed u by PETSc's bound-constrained SNES (`vinewtonrsls`) within
#   $\alpha_n \le \alpha \le 1$, until α changes by less than $10^{-8}$. The bar's ends are
#   free for α ($\nabla\alpha\cdot n = 0$, the natural condition): a uniform bar has the
#   homogeneous solution.

# +
def eps(z):
    """The small strain of the plane-strain bar."""
    return kinematics.small_strain(z, MODEL)


def gradient_energy(u, alpha):
    """E(u, α) = ∫ a(α) ψ0(ε(u)) + (Gc/c_w)(w(α)/ℓ + ℓ |∇α|²): the gradient laws' energy."""
    psi0 = LinearElastic(args.E, 0.0).energy(eps(u))  # Hooke's, at ν = 0
    dissipation = law.Gc / law.c_w * (law.w(alpha) / law.ell
                                      + law.ell * ufl.inner(ufl.grad(alpha), ufl.grad(alpha)))
    return (law.stiffness(alpha) * psi0 + dissipation) * ufl.dx


if local:
    law.bind(msh, 2)  # α_n at the quadrature points of degree 2
    dx = kinematics.quadrature_measure("dx", msh, 2)
    internal = ufl.inner(law.stress(eps(u)), eps(ufl.TestFunction(V))) * dx  # σ = ∂ψ/∂ε
    newton = NewtonSolver(internal, u, bcs, rtol=1e-12, atol=1e-12,
                          force_scale=law.critical_stress * height, prefix="bar_")
else:
    A = fem.functionspace(msh, ("Lagrange", 1))
    alpha = fem.Function(A, name="damage")
    energy = gradient_energy(u, alpha)
    solver = AlternateMinimization(energy, u, alpha, force_scale=law.critical_stress * height,
                                   damage_scale=law.Gc / law.ell * height * height,
                                   acceleration=args.acceleration)
    internal = solver.residual_u  # ∂E/∂u
internal = fem.form(internal)  # compiled once: the reaction is read at every step
# -

# ### The uniform bar against the closed form
#
# The right end moved in equal strain steps, the stress read from its reaction. With the
# gradient laws, each step then computes the second variation's smallest eigenvalue on the
# damage's inactive set (`DamageStability`: the tangent's inertia, then shift-and-invert;
# infinite where no damage can grow). Where it turns negative (`BranchStability` keeps it
# step by step and says where it crossed 0) the bar leaves its branch along the
# eigenvector's damage β: α + 0.01 β, and the step is minimized again from there.

# +
strains = np.linspace(0.0, args.strain * peak_strain, args.steps + 1)[1:]
strain_history, stress_history, damage_history = [], [], []
iterations, work = 0, AlternateWork()
if not local:
    stability = DamageStability(energy, u, alpha, solver.lower, bcs, density=law.Gc / law.ell)
    branch = BranchStability()
for k, strain in enumerate(strains):
    end.g.x.array[:] = strain * L
    if local:
        iterations += newton.solve().iterations
        law.commit(u, MODEL)
    else:
        solves = [solver.solve(bcs)]
        if branch.bifurcation_step is None:  # until the branch bifurcates
            lam, mode = stability.lowest_mode()
            if branch.observe(strain, lam, stability.driving_margin()):  # λ < 0
                bifurcation_stress = stress_at_end(internal, u, tags)  # on the branch
                stability.perturb(mode, 0.01)
                solves.append(solver.solve(bcs))
        solver.commit()
        work.count(*solves)
        damage_history.append(global_max(comm, alpha.x.array))
    strain_history.append(float(strain))
    stress_history.append(stress_at_end(internal, u, tags))
    cli.converged_step({"load_factor": (k + 1) / args.steps, "strain": float(strain),
                        "stress": stress_history[-1]})  # kept for a run that fails later
if not local:
    iterations = sum(work.iterations)
    bifurcation = branch.bifurcation_load
    bifurcation_exact = law.bifurcation_strain(L)
exact = [law.homogeneous_stress(e) for e in strains]
stable = args.steps if local or branch.bifurcation_step is None else branch.bifurcation_step
uniform_error = max((abs(s / x - 1) for s, x in zip(stress_history[:stable], exact[:stable],
                                                    strict=True)), default=0.0)
cli.say(f"uniform bar: σ against the closed form within {uniform_error:.1e} over {stable} "
        f"steps ({iterations} {'Newton' if local else 'alternate'} iterations)")
if not local and bifurcation is not None:
    cli.say(f"the homogeneous state stops being stable at ε = {bifurcation:.5g} (closed form "
            f"{bifurcation_exact:.5g}, {100 * (bifurcation / bifurcation_exact - 1):+.2f} %); "
            f"the bar leaves it along the critical mode: largest α {damage_history[-1]:.3f} "
            f"at the last step")
# -

# ### A crack, on meshes ever finer
#
# * Local law: the first cell's $w_c$ is `weak` times the others'. A traction
#   $\lambda \sigma_{c,w}$ on `RIGHT` pulls the bar ($\sigma_{c,w}$ the weak cell's peak,
#   $\sqrt{E w_c}$ times $\sqrt{\text{weak}}$) and arc-length continuation (`ArcLength`)
#   follows the path down to $\rho\,\sigma_{c,w}$, measuring the arc on the weak cell's
#   opening (its right edge's $u_x$), which grows all along even where the bar's end snaps
#   back. The dissipated energy is the external work (trapezoids over the steps) less the
#   stored elastic energy.

# +
def localize(cells):
    """The bar of `cells` cells with a weak first cell, followed down to ρ of its peak."""
    msh, tags, V, u, supports, _ = strip(cells, height)
    h = L / cells
    law.bind(msh, 2)  # the same law on this mesh: undamaged
    law.weaken(mesh.locate_entities(msh, 2, lambda x: x[0] <= h * (1 + 1e-9)), args.weak)
    sigma_ref = math.sqrt(args.E * args.wc * args.weak)
    dx = kinematics.quadrature_measure("dx", msh, 2)
    ds = ufl.Measure("ds", msh, subdomain_data=tags)
    load_factor = fem.Constant(msh, 0.0)
    v = ufl.TestFunction(V)
    residual = (ufl.inner(law.stress(eps(u)), eps(v)) * dx
                - load_factor * sigma_ref * v[0] * ds(RIGHT))
    newton = NewtonSolver(residual, u, supports, rtol=1e-10, atol=1e-12, max_it=30,
                          force_scale=sigma_ref * height, prefix="bar_")
    Vx, _ = V.sub(0).collapse()
    opening = fem.locate_dofs_geometrical((V.sub(0), Vx), lambda x: np.isclose(x[0], h))[0]

    def set_load(lam):
        load_factor.value = lam

    arc = ArcLength(newton, set_load, arc_length=0.02, max_arc_length=0.05, psi=0.0,
                    metric_dofs=opening, detect=False, commit=lambda: law.commit(u, MODEL),
                    prefix="bar_arc_")
    n = V.dofmap.index_map.size_local  # the right end's u_x: this rank's owned dofs there
    ends = 2 * np.flatnonzero(np.isclose(V.tabulate_dof_coordinates()[:n, 0], L))
    path = [(0.0, 0.0)]  # (end displacement, stress)
    arc.run(args.stress_ratio, 5000, descending=True, on_step=lambda lam, r: path.append(
        (global_max(comm, u.x.array[ends]), lam * sigma_ref)))
    U, s = np.array(path).T
    external = float(np.sum(0.5 * (s[1:] + s[:-1]) * np.diff(U)) * height)  # its work
    stored = fem.form(law.energy(eps(u)) * dx)
    dissipated = external - comm.allreduce(fem.assemble_scalar(stored), op=MPI.SUM)
    expected = height * h * args.wc * args.weak * math.log(1 / args.stress_ratio)
    damage = law.damage_per_cell().x.array[:msh.topology.index_map(2).size_local]
    return {"cells": cells, "h": h, "dissipated_energy": dissipated,
            "dissipated_energy_expected": expected,
            "dissipated_energy_rel_error": dissipated / expected - 1,
            "damaged_cells": comm.allreduce(int(np.count_nonzero(damage > 0)), op=MPI.SUM),
            "largest_damage": global_max(comm, law.alpha.x.array),
            "peak_stress": float(s.max()), "steps": len(path) - 1,
            "mean_strain": (U / L).tolist(), "stress": s.tolist(),
            "dofs": V.dofmap.index_map.size_global * 2}


# -

# * Gradient laws: a bar held undamaged at both ends (α = 0 on `LEFT` and `RIGHT`), an odd
#   number of cells so that its middle is a cell's, pulled to the same final strain; the
#   dissipated energy is $\int \frac{G_c}{c_w}(w(\alpha)/\ell + \ell|\nabla\alpha|^2)$. Its
#   middle cell's two nodes reach α = 1: a band one cell wide, beside which the profile, at
#   a distance d from the band, is $(1 - d/(2\ell))^2$ (AT1) or $e^{-d/\ell}$ (AT2). AT1's
#   crack dissipates $G_c (1 + h/(c_w\ell))$ per unit section; AT2 more, in the damage it
#   spreads before it cracks (no expected value).

# +
def crack(cells):
    """The bar of `cells` cells held undamaged at its ends, cracked by the strain steps."""
    msh, tags, V, u, supports, end = strip(cells, height)
    h = L / cells
    A = fem.functionspace(msh, ("Lagrange", 1))
    alpha = fem.Function(A, name="damage")
    gripped = fem.locate_dofs_topological(A, 1, np.concatenate([tags.find(LEFT),
                                                                tags.find(RIGHT)]))
    solver = AlternateMinimization(gradient_energy(u, alpha), u, alpha,
                                   damage_bcs=[fem.dirichletbc(0.0, gripped, A)],
                                   force_scale=law.critical_stress * height,
                                   damage_scale=law.Gc / law.ell * h * height,
                                   acceleration=args.acceleration)
    work = AlternateWork()
    for strain in strains:
        end.g.x.array[:] = strain * L
        work.count(solver.solve([*supports, end]))
        solver.commit()
    # the damage along the bottom edge, gathered and sorted by x
    n = A.dofmap.index_map.size_local
    x = A.tabulate_dof_coordinates()[:n]
    bottom = np.isclose(x[:, 1], 0.0)
    xa = np.concatenate(comm.allgather(np.column_stack([x[bottom, 0],
                                                        alpha.x.array[:n][bottom]])))
    x, a = xa[np.argsort(xa[:, 0])].T
    band = x[a >= a.max() - 1e-9 * max(a.max(), 1.0)]
    d = np.min(np.abs(x[:, None] - band[None, :]), axis=1)
    exact = (np.clip(1 - d / (2 * law.ell), 0, 1) ** 2 if law.model == "at1"
             else np.exp(-d / law.ell))
    fracture = fem.form(law.fracture_energy(alpha) * ufl.dx)
    D = comm.allreduce(fem.assemble_scalar(fracture), op=MPI.SUM) / height
    share = law.Gc * (1 + h / (law.c_w * law.ell))  # the crack's
    expected = share if law.model == "at1" else None
    return {"cells": cells, "h": h, "h_over_ell": h / law.ell,
            "dissipated_energy": D * height, "crack_share": share * height,
            "dissipated_energy_expected": expected and expected * height,
            "dissipated_energy_rel_error": expected and D / expected - 1,
            "largest_damage": global_max(comm, alpha.x.array),
            "band_width": float(np.ptp(band)),
            "profile_max_error": float(np.max(np.abs(a - exact))),
            "profile": {"x": x.tolist(), "damage": a.tolist(), "damage_exact": exact.tolist()},
            "final_stress": stress_at_end(solver.residual_u, u, tags),
            "iterations": sum(work.iterations), "newton_iterations": work.newton_iterations,
            "damage_iterations": work.damage_iterations, "cross_section": height,
            "steps": len(strains), "dofs": (V.dofmap.index_map.size_global * 2
                                            + A.dofmap.index_map.size_global)}


if local:
    table = [localize(args.cells * 2**k) for k in range(args.refinements)]
else:
    odd = [2 * math.ceil(args.resolution * 2**k * L / args.ell / 2) + 1
           for k in range(args.refinements)]
    if args.resolution < 2:  # the crack's band of one cell is then a visible share
        h = L / odd[0]
        effective = args.Gc * (1 + h / (law.c_w * args.ell))
        warnings.append(f"ℓ is smaller than two elements (ℓ/h = {args.ell / h:.3g}): the "
                        f"crack dissipates G_c (1 + h/(c_w ℓ)) = {effective:.4g}, not "
                        f"G_c = {args.Gc:g}")
        cli.say(f"warning: {warnings[-1]}")
    table = [crack(n) for n in odd]
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
branch_stresses = stress_history[:stable] + ([] if local or bifurcation is None
                                             else [bifurcation_stress])
k_peak = int(np.argmax(branch_stresses))
peak = (max(branch_stresses), strain_history[k_peak])
if args.model == "at1" and branch.damage_onset is not None:
    elastic = len(branch.elastic_margins) - 1  # the last elastic step
    peak = (stress_history[elastic] * branch.damage_onset / strain_history[elastic],
            branch.damage_onset)
out = {"model": args.model, "critical_stress": peak[0], "critical_strain": peak[1],
       "critical_strain_exact": peak_strain, "critical_stress_exact": sigma_c,
       "uniform_max_rel_error": uniform_error,
       "strain_history": strain_history, "stress_history": stress_history,
       "stress_exact": exact, "iterations": iterations,
       "cross_section": height, "localized": localized, "mesh_table": table,
       "dissipated_energy": table[-1]["dissipated_energy"],
       "dissipated_energy_expected": table[-1]["dissipated_energy_expected"],
       "dofs": table[-1]["dofs"], "ranks": comm.size, "warnings": warnings}
if local:
    out |= {"newton_iterations": iterations, "bifurcation_strain": None,
            "weak_critical_stress": math.sqrt(args.E * args.wc * args.weak)}
else:
    out |= {"bifurcation_strain": bifurcation, "bifurcation_strain_exact": bifurcation_exact,
            "bifurcation_step": branch.bifurcation_step,
            # None where no damage could grow (the elastic steps: no finite eigenvalue)
            "lowest_eigenvalue": [x if math.isfinite(x) else None
                                  for x in branch.lowest_eigenvalue],
            "largest_damage_history": damage_history,
            "alternate_iterations": work.iterations, "acceleration": args.acceleration}
# -

writers = ([lambda: damage_pictures.stress_strain(
    args.plot, law, args.model, strain_history, stress_history, peak_strain=peak_strain,
    peak_stress=sigma_c, table=table, bifurcation=out["bifurcation_strain"],
    bifurcation_exact=out.get("bifurcation_strain_exact"))] if args.plot else [])
cli.results(out, writers)
