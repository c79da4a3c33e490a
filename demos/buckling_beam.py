# # Buckling of a compressed cantilever: Euler's load and the elastica
#
# A slender beam (length $L$, height $h$), clamped at $x = 0$, carries a dead compressive
# load $P$ at its free end. Finite strain (St Venant–Kirchhoff in the Green–Lagrange strain,
# as in the course's practical). First the linear buckling load, then the post-buckling
# path, both checked against closed forms.
#
# ## Problem definition
#
# Linear buckling around the pre-stressed straight state: $(K + \lambda K_G)\,\varphi = 0$,
# $K_G$ the geometric stiffness of the stress of a unit load, solved by SLEPc
# (shift-and-invert). Euler: $P_{cr} = \pi^2 E I / (4 L^2)$, $I = h^3/12$ (plane stress;
# $E/(1-\nu^2)$ in plane strain).
#
# Post-buckling: load steps from 0 to $P = r P_{cr}$ ($P_{cr}$: Euler's), a Newton solve
# per step, a small lateral end load $\varepsilon P$ ($\varepsilon = 10^{-4}$) as
# imperfection. The elastica
# (inextensible, tip rotation $\alpha$, $k = \sin(\alpha/2)$):
#
# $$ P/P_{cr} = (2K(k)/\pi)^2, \qquad \delta/L = 2k/K(k), \qquad x/L = 2E(k)/K(k) - 1 .$$
#
# Past $P_{cr}$ the straight beam is still an equilibrium, but an unstable one: Newton can
# settle on it. The steps therefore never grow beyond 1/`--steps` of the load, and the end
# state is checked for stability (the tangent's eigenvalue nearest 0, by SLEPc); an unstable end
# state is pushed along its unstable mode, scaled to the elastica's deflection, and solved
# again (branch switching); if Newton cannot follow, the path is redone with 4 times the
# steps (up to 256), and only then does the run stop with a clear message.
#
# With `--path arc-length` the load is an unknown beside $u$ (Crisfield's arc-length
# continuation, `fenics_nl.solvers.arclength`) and no closed form is used: the number of
# negative eigenvalues of the tangent (its inertia, from an $LDL^T$ factorization) is
# counted at every state; where it changes while the load keeps growing, the path has
# crossed a bifurcation, which is bracketed and left along the tangent's critical mode by
# one arc length. With `--imperfection 0` the beam is perfect and this is how it buckles.
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
from fenics_nl.io import cli
from fenics_nl.io.cli import say
from fenics_nl.io.parameters import Parameters, choice, number, switch
from fenics_nl.materials import kinematics, mixed
from fenics_nl.parallel import gather_rows
from fenics_nl.scenes import beam_pictures
from fenics_nl.scenes.beam import MATERIALS, Beam
from fenics_nl.theory import elastica

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

comm = MPI.COMM_WORLD
# -

# ### Parameters
#
# From the command line (`python demos/buckling_beam.py --help`); in a notebook, the
# defaults. PETSc options take the prefix `-beam_` (`-beam_full_ksp_view`, ...).

# +
@dataclass
class Buckling(Parameters):
    """Buckling of a compressed cantilever: SLEPc critical load and the post-buckling path
    against the elastica. Units are the user's, consistent (e.g. N, m, Pa)."""

    EPILOG = ("PETSc options take the prefix -beam_<newton>_ (Newton's KSP, e.g. "
              "-beam_full_ksp_view), -beam_buckling_ (SLEPc EPS of the critical loads), "
              "-beam_stability_ (EPS of the end state's stability), -beam_prestress_ (KSP of "
              "the pre-stress). An option no solver reads is an error.")
    OUTPUTS: ClassVar = {"output": "the displacement",
                         "png": "deformed shapes along the path, with the elastica's",
                         "plot": "P/P_cr against tip rotation and deflection"}

    length: float = number(1.0, "beam length L", unit="length", above=0)
    thickness: float = number(0.02, "beam height h", unit="length", above=0)
    E: float = number(1e3, "Young's modulus", unit="stress", above=0)
    nu: float = number(0.3, "Poisson's ratio", unit="-")
    plane: str = choice("stress", ["stress", "strain"], "plane stress or plane strain (unit "
                        "width)")
    material: str = choice("svk", ["svk", "neo-hookean"], "St Venant-Kirchhoff or "
                           "compressible neo-Hookean (plane strain)")
    load_ratio: float = number(1.5, "final load P / P_cr (Euler)", above=0, at_most=20)
    steps: int = number(40, "equal load steps to the final load (a failed step is cut in "
                        "half)", at_least=1)
    newton: str = choice("full", ["full", "modified", "periodic", "bfgs"],
                         "Newton variant of each load step", spelling=True)
    path: str = choice("load", ["load", "arc-length"], "load control (steps of P, end state "
                       "checked and switched with the elastica's deflection if unstable) or "
                       "arc-length continuation (bifurcation found by the tangent's inertia "
                       "and left along its mode: no closed form)")
    arc_length: float = number(0.2, "with --path arc-length: the first arc length "
                               "(dimensionless, about one load step of Δs/√2 P_Euler on the "
                               "straight branch)", unit="-", above=0)
    imperfection: float = number(1e-4, "lateral end load as a fraction of P, in [0, 0.1)",
                                 unit="-", at_least=0)
    refine: int = number(0, "mesh: 2·2^refine Q2 elements through the height, twice as long "
                         "elements", at_least=0)
    mixed: bool = switch("Q2-Q1 Taylor-Hood displacement-pressure elements, for a nearly or "
                         "exactly incompressible beam (nu up to 0.5; --plane strain)")

    def check(self):
        if not self.imperfection < 0.1:
            raise ValueError(f"--imperfection must be in [0, 0.1), got {self.imperfection}")
        if self.material == "neo-hookean" and self.plane == "stress":
            raise ValueError("neo-hookean is implemented in plane strain only (--plane strain)")
        if self.thickness > self.length / 5:
            raise ValueError(f"the beam must be slender: --thickness <= --length/5, got L/h = "
                             f"{self.length / self.thickness:.3g}")
        if self.mixed and self.plane == "stress":
            raise ValueError("--mixed needs --plane strain (in plane stress the out-of-plane "
                             "strain takes the volume change: nothing locks)")


args = cli.arguments(Buckling, prefixes={"beam_": "Newton, SLEPc and pre-stress solvers"})


# -

# ### The mesh and its tags
#
# Q2 quadrilaterals, 2·2^refine through the height and twice as long as high; the facets
# of the clamped end
# x = 0 and of the loaded end x = L are tagged CLAMPED and END.

# +
L, h = args.length, args.thickness
CLAMPED, END = 1, 2  # the facet tags
ny = 2 * 2**args.refine
nx = max(4, round(L / h * ny / 2))
msh = mesh.create_rectangle(comm, [[0, -h / 2], [L, h / 2]], [nx, ny],
                            mesh.CellType.quadrilateral)
clamped = mesh.locate_entities_boundary(msh, 1, lambda x: np.isclose(x[0], 0.0))
end = mesh.locate_entities_boundary(msh, 1, lambda x: np.isclose(x[0], L))
facets = np.concatenate([clamped, end])
values = np.hstack([np.full_like(clamped, CLAMPED), np.full_like(end, END)])
order = np.argsort(facets)  # meshtags takes sorted entities
facet_tags = mesh.meshtags(msh, 1, facets[order], values[order])
# -

# ### The function space and the boundary conditions
#
# Q2 displacements (with `--mixed`, the Q2–Q1 Taylor–Hood pair $(u, p)$). The end $x = 0$
# is clamped; the end $x = L$ carries the dead traction $t = (-P, \varepsilon P)/h$, a
# `fem.Constant` the load steps set.

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
bcs = [boundary.fixed(V, facet_tags.find(CLAMPED))]
ds = ufl.Measure("ds", domain=msh, subdomain_data=facet_tags)
t = fem.Constant(msh, np.zeros(2))


def set_load(P):
    """The dead end load: axial compression P and the lateral imperfection ε P."""
    t.value[:] = [-P / h, args.imperfection * P / h]


# -

# ### The material: a free energy of the Green–Lagrange strain
#
# St Venant–Kirchhoff, the course's finite-strain law, in $e = \frac12(F^TF - I)$:
#
# $$ \varphi(e) = \frac{\lambda}{2} (\mathrm{tr}\,e)^2 + \mu\, e : e, $$
#
# written below in UFL (in plane stress $\lambda$ becomes $2\lambda\mu/(\lambda + 2\mu)$,
# the out-of-plane stress being zero). The second Piola–Kirchhoff stress
# $S = \partial\varphi/\partial e$ is UFL's derivative of it. `--material neo-hookean`
# takes the library's compressible neo-Hookean energy instead (`NeoHookean.energy`).

# +
model = "plane_stress" if args.plane == "stress" else "plane_strain"
material = MATERIALS[args.material](args.E, args.nu)  # E, ν checked; the neo-Hookean's φ
mu, lmbda = material.mu, material.lmbda  # Lamé's constants (λ = ∞ at ν = 1/2)
if model == "plane_stress":  # σ_zz = 0: λ* = 2λμ/(λ + 2μ), 2μ at ν = 1/2
    lmbda = 2 * mu if math.isinf(lmbda) else 2 * lmbda * mu / (lmbda + 2 * mu)
elif not args.mixed:
    material.require_compressible()  # ν = 1/2 needs the pressure as an unknown


def svk_energy(e):
    """φ(e) of St Venant–Kirchhoff."""
    return lmbda / 2 * ufl.tr(e) ** 2 + mu * ufl.inner(e, e)


phi = svk_energy if args.material == "svk" else material.energy
# -

# ### The residual
#
# Total Lagrangian: $R(u; v) = \int_{\Omega_0} F S(e) : \nabla v\,d\Omega_0 -
# \int_{end} t \cdot v\,dS_0$, $F S$ the first Piola–Kirchhoff stress. In plane strain the
# gradients are 3×3 with a zero third row and column (`kinematics.displacement_gradient`).
# With `--mixed` the first term is the variation of the perturbed Lagrangian
# $\Pi(u, p) = \int \tilde\varphi(e) + p\,g(e) - p^2/(2k)$ (`fenics_nl.materials.mixed`).

# +
dx = kinematics.quadrature_measure("dx", msh, 4)
if args.mixed:
    internal = mixed.internal_work(material, u, p, v, q, model)
else:
    H = kinematics.displacement_gradient(u, model)
    F = ufl.Identity(H.ufl_shape[0]) + H
    e = ufl.variable((H + H.T + H.T * H) / 2)  # Green–Lagrange
    S = ufl.diff(phi(e), e)
    internal = ufl.inner(F * S, kinematics.displacement_gradient(v, model))
residual = internal * dx - ufl.dot(t, v) * ds(END)
# -

# ### What is measured: the tip
#
# Means over the end face: the axial and lateral displacement, and the rotation α of the
# end section from its deformed tangent $F e_y$.

# +
F_plane = ufl.Identity(2) + ufl.grad(u)  # the in-plane F: the end's tangent F e_y
tip_forms = [fem.form(f * ds(END)) for f in (u[0] / h, u[1] / h, F_plane[0, 1], F_plane[1, 1])]


def tip():
    """{"axial", "lateral", "rotation"} of the end face."""
    ux, uy, t0, t1 = (comm.allreduce(fem.assemble_scalar(f)) for f in tip_forms)
    return {"axial": ux, "lateral": uy, "rotation": math.atan2(-t0, t1)}


beam = Beam(residual, mixed.unknown_of(w), bcs, material=material, model=model, length=L,
            thickness=h, dx=dx, ds_end=ds(END), set_load=set_load, tip=tip, clamp=clamped)
say(f"beam L/h = {L / h:g}, {beam.dofs} unknowns, {args.material}, plane {args.plane}"
    f"{', mixed Q2-Q1' if args.mixed else ''}")
# -

# ### Linear buckling (SLEPc) against Euler
#
# $(K + \lambda K_G)\varphi = 0$ around the straight state: $K$ is the residual's tangent at
# $u = 0$ (Hooke's law: the small-strain limit of the energy), $K_G$ the geometric stiffness of
# the pre-stress of a unit load (`Beam.critical_loads`, SLEPc shift-and-invert).

# +
loads, _ = beam.critical_loads(3)
P_cr = loads[0]
say(f"critical loads (SLEPc): {', '.join(f'{x:.6g}' for x in loads)}; Euler "
    f"{beam.P_euler:.6g} ({100 * (P_cr / beam.P_euler - 1):+.3f} %)")
# -

# ### The post-buckling path
#
# Load steps to $r P_{Euler}$ (never larger than $1/n$ of it, cut on failure), then the
# stability check of the end state and, if needed, branch switching (`Beam.solve_path`).

# +
def progress(message):
    """The path's step lines (about ten of them: `progress_every`), every cut or switch."""
    say("  " + message)


def centreline(beam):
    """Deformed centreline points (x + u) of the dofs on y = 0, gathered, sorted by x."""
    d = beam.fields.displacement()
    X = d.function_space.tabulate_dof_coordinates()
    on = np.isclose(X[:, 1], 0.0)
    u = d.x.array.reshape(-1, 2)[on]
    rows = gather_rows(comm, X[on, 0], X[on, :2] + u)
    if rows is None:
        return None
    x0, pts = rows
    return pts[np.argsort(x0)]


history, shapes = [(0.0, 0.0, 0.0, 0.0)], []


def record(t, result):
    r = t * args.load_ratio
    # a redone path, or the branch-switched end state, replaces what it passes again
    while len(history) > 1 and history[-1][0] >= r:
        history.pop()
    while shapes and shapes[-1][0] >= r:
        shapes.pop()
    tip = beam.tip()
    history.append((r, math.degrees(abs(tip["rotation"])), abs(tip["lateral"]),
                    tip["axial"]))
    cli.converged_step({"load_factor": t, "load_ratio": r, "tip_rotation_deg": history[-1][1],
                        "tip_deflection": history[-1][2], "tip_axial": history[-1][3],
                        "newton_iterations": result.iterations},
                       fields=lambda: [beam.fields.displacement(),
                                       *([beam.fields.pressure()] if args.mixed else [])])
    if args.png:
        shapes.append((r, centreline(beam)))


redone, critical = [], []
if args.path == "load":
    say(f"load path to P/P_cr = {args.load_ratio:g} in steps of at most 1/{args.steps}")
    path, switched = beam.solve_path(args.load_ratio, args.steps, args.newton,
                                     on_step=record, progress=progress,
                                     progress_every=max(1, args.steps // 10))
    if beam.path_steps != args.steps:
        redone.append(f"the {args.steps}-step path ended on the straight (unstable) branch; "
                      f"it was redone with {beam.path_steps} steps")
else:  # λ = P/P_Euler is an unknown of the arc-length path
    say(f"arc-length path to P/P_Euler = {args.load_ratio:g} (first arc {args.arc_length:g})")
    path = beam.solve_arc_length(args.load_ratio, args.newton, arc_length=args.arc_length,
                                 on_step=lambda lam, r: record(lam / args.load_ratio, r),
                                 progress=progress, progress_every=4)
    switched = path.switched
    critical = [{"kind": c.kind, "load_ratio": c.factor, "between": list(c.between)}
                for c in path.critical_points]
# -

# ### Against the elastica
#
# Tip rotation, lateral deflection and axial displacement at the last load.

# +
end = tip()  # the end state's
alpha = math.degrees(abs(end["rotation"]))
alpha_el = math.degrees(elastica.tip_rotation(args.load_ratio))
d_el, x_el = elastica.tip_position(args.load_ratio)
say(f"P/P_cr = {args.load_ratio:g}: tip rotation {alpha:.3f} deg (elastica "
    f"{alpha_el:.3f}), lateral deflection {abs(end['lateral']):.5g} (elastica "
    f"{d_el * args.length:.5g}), axial displacement {end['axial']:.5g} (elastica "
    f"{(x_el - 1) * args.length:.5g}); {len(path.factors)} steps, "
    f"{path.iterations} Newton iterations, {path.failures} step cuts")
out = {
    "critical_load": P_cr, "critical_loads": loads, "euler_critical_load": beam.P_euler,
    "critical_load_rel_error": P_cr / beam.P_euler - 1, "load_ratio": args.load_ratio,
    "tip_rotation_deg": alpha, "tip_deflection": abs(end["lateral"]),
    "tip_axial_displacement": end["axial"], "elastica_tip_rotation_deg": alpha_el,
    "elastica_tip_deflection": d_el * args.length,
    "elastica_tip_axial_displacement": (x_el - 1) * args.length,
    "load_steps": len(path.factors), "step_cuts": path.failures,
    "newton_iterations": sum(r.iterations for r in path.results),
    "factorizations": path.work.factorizations, "branch_switched": switched,
    "path_control": args.path, "critical_points": critical,
    "inertia_factorizations": getattr(path, "inertia_factorizations", 0),
    "newton": args.newton, "mixed": args.mixed, "reactions": beam.reactions(),
    "reactions_of": "the beam, per unit width", "dofs": beam.dofs, "ranks": comm.size,
    "path": [{"load_ratio": h[0], "tip_rotation_deg": h[1], "tip_deflection": h[2]}
             for h in history],
    "warnings": ["the elastica is inextensible and shear-free: the FE beam differs from it "
                 "by O((h/L)²)", *redone],
}
# -

# ## Outputs
#
# The JSON (above), and when asked the final displacement for ParaView, the load path
# against the elastica and the deformed shapes.


writers = []  # (--output: the fields of every converged step were written as they came)
if args.plot:
    writers.append(lambda: beam_pictures.path_against_elastica(
        history, args.length, args.thickness, args.imperfection, args.load_ratio, args.plot))
if args.png:
    writers.append(lambda: beam_pictures.shapes_against_elastica(
        shapes, args.length, args.imperfection, args.load_ratio, args.png))
cli.results(out, writers)
