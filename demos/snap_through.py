# # Snap-through of a shallow arch: arc-length continuation through a limit point
#
# A shallow pinned arch under a downward load can carry it only up to a *limit point*; past
# it the equilibrium path turns back (the load falls while the arch flattens), goes through
# the flat and inverted shapes, and rises again once the arch hangs. Load control stops at
# the limit point: no state beyond it carries a larger load. Arc-length control follows
# the path by its length and traces the whole of it, the unstable branch included.
#
# ## Problem definition
#
# The arch of span $L$ and thickness $h$ follows $y_0 = e \sin(\pi x/L)$ and carries
# $q(x) = q_0 \sin(\pi x/L)$ per unit span. Shallow-arch theory (Fung & Kaplan 1952,
# NACA TN 2840; Simitses 1976, ch. 7) gives the midspan rise $a$ in closed form: with
# $k = \pi/L$, $r = h/\sqrt{12}$, $\bar a = a/r$, $\bar e = e/r$,
#
# $$ \frac{q_0}{EI k^4 r} = (\bar e - \bar a) + \frac{(\bar e^2 - \bar a^2)\,\bar a}{4}, $$
#
# a cubic whose maximum, at $\bar a = \sqrt{(\bar e^2 - 4)/3}$, is the limit load, for
# $2 < \bar e < \sqrt{22}$ (beyond it an antisymmetric bifurcation comes first). The model
# here is a 2D continuum (Q2, plane stress, St Venant–Kirchhoff at finite strain), pinned
# at the centreline of each end.
#
# Arc-length (Crisfield): the load factor $\lambda$ becomes an unknown with the constraint
# $\|\Delta u\|^2/u_{ref}^2 + \psi^2 \Delta\lambda^2 = \Delta s^2$; each corrector iteration
# is a bordered solve (two back-solves on the tangent of the chosen Newton variant). Limit
# points are told by the sign of $\dot\lambda$ along the path's tangent, and bracketed.
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
from dolfinx.fem import petsc
from mpi4py import MPI
from petsc4py import PETSc

from fenics_nl.io import cli, output
from fenics_nl.io.cli import say
from fenics_nl.io.parameters import Parameters, choice, number
from fenics_nl.materials import kinematics
from fenics_nl.materials.laws import StVenantKirchhoff
from fenics_nl.parallel import gather_rows
from fenics_nl.plots import continuation as continuation_pictures
from fenics_nl.solvers.arclength import ArcLength
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.theory import arch as theory

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

comm = MPI.COMM_WORLD
# -

# ### Parameters
#
# From the command line (`python demos/snap_through.py --help`); in a notebook, the
# defaults. PETSc options take the prefix `-arch_` (`-arch_full_ksp_view`, ...).

# +
@dataclass
class Arch(Parameters):
    """Snap-through of a shallow sinusoidal arch under a sinusoidal load, traced by
    arc-length continuation and checked against the shallow-arch closed form. Units are the
    user's, consistent (e.g. N, m, Pa)."""

    EPILOG = ("PETSc options take the prefix -arch_<newton>_ (Newton's KSP, e.g. "
              "-arch_full_ksp_view) and -arch_continuation_ (the stability checks' "
              "factorizations and eigensolver).")
    OUTPUTS: ClassVar = {"output": "the displacement",
                         "png": "the deformed arch at states along the path",
                         "plot": "load against midspan rise, FE and closed form"}
    CHECKPOINTS = True

    span: float = number(1.0, "span L", unit="length", above=0)
    slenderness: float = number(200.0, "L/h (the closed form is a thin-arch theory)",
                                unit="-", at_least=20)
    rise: float = number(3.0, "e/r: the rise over the section's radius of gyration "
                         "r = h/√12, in (2, √22 = 4.69): a symmetric snap-through", unit="-")
    E: float = number(1e3, "Young's modulus", unit="stress", above=0)
    nu: float = number(0.3, "Poisson's ratio", unit="-")
    load_ratio: float = number(1.5, "the path is followed until q0 = ratio × the closed "
                               "form's limit load (not 0)", unit="-")
    newton: str = choice("full", ["full", "modified", "periodic", "bfgs"],
                         "Newton variant of the corrector", spelling=True)
    arc_length: float = number(0.2, "first arc length Δs: dimensionless, on a linear path a "
                               "load increment of Δs/√(1+ψ²) in units of EI k⁴ r (k = π/L)",
                               unit="-", above=0)
    max_arc_length: float = number(1.0, "largest arc length (the adaptive Δs grows after "
                                   "easy steps), >= --arc-length", unit="-")
    psi: float = number(1.0, "weight of the load factor in the arc: 1 spherical, 0 "
                        "cylindrical", unit="-", at_least=0)
    max_steps: int = number(300, "steps before the run stops short of its target", at_least=1)
    elements: int = number(2, "Q2 elements through the thickness, even (a node on the "
                           "centreline)", at_least=2)
    aspect: float = number(4.0, "element length over element height along the span",
                           unit="-", above=0)

    def check(self):
        if not 2 < self.rise < math.sqrt(22):
            raise ValueError(f"--rise must be in (2, √22 = 4.69), got {self.rise}: at e/r <= 2 "
                             "the arch never snaps, beyond √22 it buckles antisymmetrically "
                             "before its limit point, where the closed form does not hold")
        if self.elements % 2:
            raise ValueError(f"--elements must be even (a node on the centreline), got "
                             f"{self.elements}")
        if not self.max_arc_length >= self.arc_length:
            raise ValueError(f"--max-arc-length must be >= --arc-length, got "
                             f"{self.max_arc_length}")
        if self.load_ratio == 0:
            raise ValueError("--load-ratio must not be 0 (the path starts there)")


args = cli.arguments(Arch, prefixes={"arch_": "Newton and the stability checks"})
# -

# ### The mesh and its tags
#
# Q2 quadrilaterals on the strip around $y_0$: a rectangle whose points are moved up by
# $e \sin(\pi x/L)$ (each section shifted vertically: the arch is shallow), `--elements`
# through the thickness and `--aspect` times as long along the span. The top face is
# tagged TOP: it carries the load.

# +
L, h = args.span, args.span / args.slenderness
r = h / math.sqrt(12)  # the section's radius of gyration
e = args.rise * r  # the rise
nx = max(8, 2 * round(L / (args.aspect * h / args.elements) / 2))  # even: a midspan node
msh = mesh.create_rectangle(comm, [[0, -h / 2], [L, h / 2]], [nx, args.elements],
                            mesh.CellType.quadrilateral)
msh.geometry.x[:, 1] += e * np.sin(np.pi * msh.geometry.x[:, 0] / L)
top = mesh.locate_entities_boundary(
    msh, 1, lambda x: np.isclose(x[1], h / 2 + e * np.sin(np.pi * x[0] / L)))
TOP = 1  # the facet tag of the loaded face
facet_tags = mesh.meshtags(msh, 1, top, np.full(len(top), TOP, dtype=np.int32))
# -

# ### The function space and the boundary conditions
#
# Q2 displacements; each end is pinned at its centreline node (both components held, free
# to rotate).

# +
V = fem.functionspace(msh, ("Lagrange", 2, (2,)))
u, v = fem.Function(V, name="displacement"), ufl.TestFunction(V)
pins = {name: fem.locate_dofs_geometrical(V, lambda x, x0=x0: np.isclose(x[0], x0)
                                          & np.isclose(x[1], 0.0))
        for name, x0 in (("left pin", 0.0), ("right pin", L))}
bcs = [fem.dirichletbc(np.zeros(2), dofs, V) for dofs in pins.values()]
# -

# ### The material and the residual
#
# St Venant–Kirchhoff in plane stress,
# $\varphi(e) = \frac{\lambda^*}{2}(\mathrm{tr}\,e)^2 + \mu\, e : e$ in the Green–Lagrange
# strain, $\lambda^* = 2\lambda\mu/(\lambda + 2\mu)$
# (`StVenantKirchhoff`: $S = \partial\varphi/\partial e$ and $P = F S$ derived by UFL). The
# dead load $\lambda\, q_0 \sin(\pi x/L)$ per unit span acts downwards on the top face:
# per unit length of the face it is that times $|n_y|$. The load factor $\lambda$ is a
# `fem.Constant`, in the theory's unit $EI k^4 r$:
#
# $$ R(u; v) = \int_{\Omega_0} F S : \nabla v\,d\Omega_0 +
#    \int_{top} \lambda\, EI k^4 r \sin(\pi x/L)\, |n_y|\, v_y\,dS_0 . $$

# +
material = StVenantKirchhoff(args.E, args.nu)
EI = args.E * h**3 / 12
k = np.pi / L
load_unit = EI * k**4 * r  # q0 per unit load factor, in force/length²
load_factor = fem.Constant(msh, 0.0)
X, n = ufl.SpatialCoordinate(msh), ufl.FacetNormal(msh)
q = load_factor * load_unit * ufl.sin(k * X[0]) * abs(n[1])
dx = kinematics.quadrature_measure("dx", msh, 4)
ds_top = ufl.Measure("ds", domain=msh, subdomain_data=facet_tags)(TOP)
P = material.first_piola(u, "plane_stress")
residual = ufl.inner(P, ufl.grad(v)) * dx + q * v[1] * ds_top


def set_load(lam):
    """q0 = λ EI k⁴ r: λ is the theory's dimensionless load."""
    load_factor.value = lam


# -

# ### What is measured: the midspan rise and the centreline
#
# $\bar a = (e + w_{mid})/r$ at the midspan centreline node; the deformed centreline for
# the pictures, gathered on rank 0.

# +
owned = V.dofmap.index_map.size_local
X_dofs = V.tabulate_dof_coordinates()[:owned]
mid = np.flatnonzero(np.isclose(X_dofs[:, 0], L / 2) & np.isclose(X_dofs[:, 1], e))
on_centreline = np.isclose(X_dofs[:, 1], e * np.sin(np.pi * X_dofs[:, 0] / L))


def midspan_rise():
    """ā = (e + w_mid)/r, the centreline's midspan rise in radii of gyration."""
    return (e + comm.allreduce(float(u.x.array[2 * mid + 1].sum()))) / r


def centreline():
    """Deformed centreline points (x + u), gathered on rank 0 and sorted by x."""
    moved = X_dofs[on_centreline, :2] + u.x.array[: 2 * owned].reshape(-1, 2)[on_centreline]
    rows = gather_rows(comm, X_dofs[on_centreline, 0], moved)
    return None if rows is None else rows[1][np.argsort(rows[0])]


q_limit = theory.limit_load(args.rise)  # in units of EI k⁴ r
say(f"arch L/h = {args.slenderness:g}, e/r = {args.rise:g}, {output.dofs(V)} unknowns; limit "
    f"load (closed form) q0 = {q_limit:.5g} EI k^4 r (k = π/L) at rise a/r = "
    f"{theory.limit_rise(args.rise):.4g}")
# -

# ### The path
#
# Arc-length continuation until $q_0$ reaches the target, with a stability check at each
# state (the tangent's inertia) that tells limit points from bifurcations.
#
# Why load control cannot pass a limit point: there $dq_0/da = 0$, the tangent stiffness
# $K_t$ is singular along the path's direction, and for a slightly larger load no nearby
# equilibrium exists; Newton at fixed load diverges or jumps to the far, inverted branch.
# Arc-length makes the load factor $\lambda$ an unknown and prescribes the step's length
# in $(u, \lambda)$ instead: each step predicts along the path's tangent $(\dot u, \dot
# \lambda)$, $K_t \dot u = \dot\lambda f$ with $\|\dot u\|^2/u_{ref}^2 + \psi^2 \dot\lambda^2 =
# \Delta s^2$, and corrects on the constraint. The bordered system stays regular at a limit
# point (the constraint row fills the missing direction), so the path goes round it and
# $\lambda$ falls on the unstable branch. Each corrector iteration needs two back-solves
# with the Newton variant's matrix: for the residual and for the load vector.
#
# The stability check counts the negative eigenvalues of $K_t$ (its inertia, from an
# $LDL^T$ factorization). It changes by one at a critical point; if $\dot\lambda$ changes
# sign there too it is a limit point, else a bifurcation. Between the two limit points the
# arch is unstable: one negative eigenvalue.

# +
# atol 1e-8: the arch's membrane forces are ~1e5 times its load, and their round-off is
# what the residual can reach
solver = NewtonSolver(residual, u, bcs, method=args.newton, rtol=1e-8,
                      atol=1e-8, max_it=30 if args.newton == "full" else 300,
                      prefix=f"arch_{args.newton}_")
continuation = ArcLength(solver, set_load, arc_length=args.arc_length, psi=args.psi,
                         max_arc_length=args.max_arc_length, prefix="arch_continuation_")
history = [(0.0, args.rise)]  # (q0 / (EI k⁴ r), a/r)
# the shapes the picture draws (kept without --png too: a restart may ask for the picture)
shapes = [(0.0, centreline())]


def record(lam, result):
    history.append((lam, midspan_rise()))
    cli.converged_step({"load_factor": lam, "midspan_rise": history[-1][1],
                        "newton_iterations": result.iterations}, fields=lambda: [u])
    shapes.append((lam, centreline()))


def progress(message):
    say("  " + message)


# --restart: the displacement, the continuation's state (the arc, the tangent's inertia,
# the last increment), the states so far and their shapes back; --checkpoint: saved after
# each converged step
checkpoints = cli.checkpointing(
    {"unknown": u}, newton=solver,
    kept=lambda: {"shapes": [(lam, None if x is None else x.tolist()) for lam, x in shapes]})
history += [(s["load_factor"], s["midspan_rise"]) for s in checkpoints.steps]
if checkpoints.kept is not None:
    shapes[:] = [(lam, None if comm.rank else np.array(x))
                 for lam, x in checkpoints.kept["shapes"]]
target = args.load_ratio * q_limit
say(f"arc-length path to q0 = {args.load_ratio:g} x the limit load ({args.newton} Newton)")
path = continuation.run(target, args.max_steps, on_step=record, progress=progress,
                        progress_every=10,
                        **checkpoints.arc_options)
# -

# ### Against the closed form
#
# The limit load, and the load at every computed state against the cubic at the same rise.

# +
limits = [c for c in path.critical_points if c.kind == "limit"]
states = np.array(history)  # (λ, ā) of every converged state
reference = np.array([theory.load(a, args.rise) for a in states[:, 1]])
path_error = float(np.max(np.abs(states[:, 0] - reference)) / q_limit)
a_limit = theory.limit_rise(args.rise)
# the cubic's maximum, then its minimum: the limit points in the order the path meets them
limits_reference = [q_limit, theory.load(-a_limit, args.rise)]
unstable = int(np.sum(np.abs(states[:, 1]) < a_limit))  # states between the limit points
warnings = []
if args.slenderness < 100:
    warnings.append("the closed form is a thin-arch theory: at L/h < 100 the continuum "
                    "differs from it by about 1 % or more")
first = limits[0].factor if limits else None
if first is None:
    warnings.append("no limit point was met before the target (is the target below it?)")
    say("no limit point met")
for c, ref in zip(limits, limits_reference, strict=False):
    # at e/r = 4 the second limit load is 0: its error is then said in units of q_limit
    off = (f"{100 * (c.factor / ref - 1):+.2f} %" if ref else
           f"{100 * (c.factor - ref) / q_limit:+.2f} % of q_limit")
    say(f"limit point: q0 = {c.factor:.5g} EI k^4 r (closed form {ref:.5g}, {off})")
say(f"{len(path.factors)} steps ({unstable} between the limit points), {path.iterations} "
    f"iterations, {path.work.factorizations} factorizations (+{path.inertia_factorizations} "
    f"for the stability checks), {path.failures} cuts; largest gap to the closed form along "
    f"the path {100 * path_error:.2f} % of the limit load")
b = petsc.assemble_vector(fem.form(residual))  # R(u) without its rows: the pins' forces
b.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
reactions = {name: [comm.allreduce(float(b.array_r[2 * dofs[dofs < owned] + i].sum()))
                    for i in range(2)] for name, dofs in pins.items()}
out = {
    "limit_load": first * load_unit if first is not None else None,
    "limit_load_reference": q_limit * load_unit,
    "limit_load_rel_error": first / q_limit - 1 if first is not None else None,
    "limit_loads": [c.factor * load_unit for c in limits],
    "limit_loads_reference": [r * load_unit for r in limits_reference[:len(limits)]],
    "limit_loads_rel_error": [c.factor / r - 1 if r else None  # None: a zero load
                              for c, r in zip(limits, limits_reference, strict=False)],
    "load_unit": load_unit, "load_unit_is": "EI k^4 r, k = pi/L, r = h/sqrt(12): q0 per "
    "unit load factor [force/length^2]", "initial_rise": args.rise,
    "slenderness": args.slenderness, "newton": args.newton, "critical_points": [
        {"kind": c.kind, "load_factor": c.factor, "step": c.step,
         "between": list(c.between)} for c in path.critical_points],
    "path_max_error": path_error, "unstable_states": unstable,
    "load_steps": len(path.factors), "iterations": path.iterations,
    "factorizations": path.work.factorizations,
    "inertia_factorizations": path.inertia_factorizations, "step_cuts": path.failures,
    "final_load_factor": path.factors[-1], "final_rise": history[-1][1],
    "reactions": reactions,
    "reactions_of": "the pins on the arch, per unit width", "dofs": output.dofs(V),
    "ranks": comm.size,
    "path": [{"load_factor": x, "rise": a, "negative_eigenvalues": n}
             for (x, a), n in zip(history, [0, *path.unstable], strict=True)],
    "warnings": warnings,
}
# -

# ## Outputs
#
# The JSON (above), and when asked the final displacement for ParaView, the path against the
# closed form and the deformed shapes.


writers = []  # (--output: the fields of every converged step were written as they came)
if args.plot:
    writers.append(lambda: continuation_pictures.arch_path(
        history, [c.factor for c in limits], q_limit, args.rise, args.slenderness,
        args.newton, args.plot))
if args.png:
    writers.append(lambda: continuation_pictures.arch_shapes(
        history, shapes, q_limit, a_limit, args.rise, args.slenderness, args.span, args.png))
cli.results(out, writers)
