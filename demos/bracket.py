# # A 3D bracket in a non-linear material: Newton variants side by side
#
# An L-shaped steel-like bracket (gmsh geometry in `fenics_nl/domain/bracket.py`) is
# bolted through its base and pulled at a hole in its arm. The material is the power law
# of `fenics_nl`: linear (E, ν) at small strain,
# $\sigma_{eq} \approx \sigma_0 (\varepsilon_{eq}/\varepsilon_0)^n$ beyond
# $\varepsilon_0 = \sigma_0/(3\mu)$. The default 8 kN is about 1.3 times the load at which
# a perfectly plastic base plate would hinge ($M_p = \sigma_0 b t^2/4$ against
# $F \times 50$ mm): the whole plate between the arm and the bolts is past $\sigma_0$, and
# beside the bolt holes (the net section) $\sigma_{eq} \approx 1.7\,\sigma_0$, i.e.
# $\varepsilon_{eq} \approx 14\,\varepsilon_0$, where the tangent shear stiffness is
# ~2.5 % of the elastic one. Quadratic (P2) tetrahedra by default: at these strains the
# secant shear modulus is a fraction of the bulk modulus and P1 tetrahedra, two through
# the plate, lock (half the displacement; see the mesh-convergence table of the benchmarks page).
#
# ## Problem definition
#
# $$ \int_\Omega \sigma(\varepsilon(u)) : \varepsilon(v)\, dx = \int_{S_{load}} t \cdot v\, ds,
#    \qquad \sigma = \frac{\partial \varphi}{\partial \varepsilon}, $$
#
# solved in load steps by Newton's method: full (tangent every iteration), modified (the
# tangent of the step's start, factorized once per step), periodic (every 3 iterations),
# quasi-Newton (BFGS on the step's first factorization) or PETSc SNES. Supports:
# `clamped` (bolt holes fixed) or `contact` (bolts fixed and the base on a rigid floor,
# frictionless unless `--friction F`, free to lift off: the course's combination of
# non-linearities).
#
# ## Implementation

# +
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
from fenics_nl.domain.bracket import THICK, bracket_mesh
from fenics_nl.io import cli, output
from fenics_nl.io.cli import say
from fenics_nl.io.parameters import Parameters, choice, number, switch, text
from fenics_nl.materials import kinematics, mixed
from fenics_nl.materials.laws import LinearElastic, PowerLaw
from fenics_nl.materials.plasticity import J2Plasticity
from fenics_nl.parallel import global_max
from fenics_nl.plots import deformed, figures
from fenics_nl.solvers import LoadStepError, NewtonSolver, SnesSolver, solve_incrementally

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

comm = MPI.COMM_WORLD
VARIANTS = ("full", "modified", "periodic", "bfgs", "snes")
MM = {"mm": 1.0, "m": 1e-3}  # the length of 1 mm in the chosen unit
DEFAULT_SIZE_MM = 6.0  # P2: |u_load| 3.7 % below the extrapolated value (benchmarks page)
# -

# ### Parameters
#
# From the command line (`python demos/bracket.py --help`); in a notebook, the defaults.
# PETSc options take the prefix `-bracket_` (Newton's KSP), `-bracket_snes_` or
# `-bracket_elim_` (the floor contact).

# +
@dataclass
class BracketParameters(Parameters):
    """3D L-bracket in a power-law material, Newton variants side by side. Lengths in
    --units (mm or m), forces in N, stresses in N per unit length squared (MPa or Pa)."""

    EPILOG = ("PETSc options take the prefix -bracket_ (Newton's KSP), -bracket_snes_ "
              "(--newton snes) or -bracket_elim_ (--support contact), e.g. -bracket_ksp_view. "
              "An option no solver reads is an error.")
    OUTPUTS: ClassVar = {
        "output": "displacement, von Mises stress (j2: plastic strains), with --support "
                  "contact the floor pressure and active set",
        "png": "deformed bracket coloured by von Mises stress (j2: by the cumulated plastic "
               "strain), load and supports drawn",
        "plot": "load against load-point displacement"}
    CHECKPOINTS = True

    support: str = choice("clamped", ["clamped", "contact"], "bolt holes fixed, or also the "
                          "base on a rigid floor (unilateral)")
    newton: str | None = choice(None, VARIANTS, "non-linear solver (default full)",
                                spelling=True)
    compare: bool = switch("run every variant on the same mesh and print one table")
    force: float = number(8e3, "total load on the arm's hole", unit="N", above=0)
    steps: int = number(4, "equal load steps", at_least=1)
    tolerance: float = number(1e-9, "Newton stops at |R| <= tolerance x force (or 1e-10 "
                              "|R0|)")
    units: str = choice("mm", list(MM), "length unit of the geometry, --size and the results")
    size: float | None = number(None, f"largest element size (default {DEFAULT_SIZE_MM:g} mm),"
                                f" at most twice the {THICK:g} mm plate thickness",
                                above=0)
    degree: int = number(2, "Lagrange degree, 1 or 2 (P1 is far too stiff here: see the "
                         "benchmarks)", at_least=1, at_most=2)
    mixed: bool = switch("Taylor–Hood P2–P1 displacement–pressure elements (ν up to 0.5; "
                         "--linear-solver gamg: MINRES with a block preconditioner)")
    mesh: str | None = text(None, "a .msh file with groups bolts, load, base (in --units; not "
                            "with --size)", metavar="MSH")
    linear_solver: str = choice("lu", ["lu", "gamg"], "MUMPS LU, or CG + GAMG with "
                                "rigid-body near-nullspace (every support and material; a "
                                "Newton solve keeps its first AMG hierarchy while CG keeps up, "
                                "the mixed form excepted)", spelling=True)
    material: str = choice("power-law", ["power-law", "j2", "linear"], "the power law below; "
                           "j2: von Mises plasticity (sigma0, --hardening), path-dependent; or "
                           "linear elasticity (E, nu)")
    E: float | None = number(None, "Young's modulus (default 200 GPa, in N/unit²)", above=0)
    nu: float = number(0.3, "Poisson's ratio", unit="-")
    sigma0: float | None = number(None, "power law: reference stress (default 200 MPa, in "
                                  "N/unit²)", above=0)
    n: float | None = number(None, "power law exponent (default 0.2)", unit="-", above=0)
    hardening: float | None = number(None, "j2: linear isotropic hardening modulus H (default "
                                     "13 GPa: the power law's secant at its peak strain, "
                                     "14 ε0; in N/unit²)")
    friction: float | None = number(None, "Coulomb friction coefficient f between the base "
                                    "and the floor (--support contact; default: "
                                    "frictionless)", at_least=0)
    unload: bool = switch("unload in as many steps after loading: the permanent displacement")

    def check(self):
        if self.compare and self.newton:
            raise ValueError("--compare runs every Newton variant: drop --newton")
        if self.compare and (self.png or self.plot or self.output):
            raise ValueError("--compare prints a table of the variants: --png, --plot and "
                             "--output go with one --newton")
        if self.compare and (self.unload or self.checkpoint or self.restart):
            raise ValueError("--unload, --checkpoint and --restart go with one --newton, not "
                             "--compare")
        self.newton = self.newton or "full"
        if self.newton == "snes" and self.support == "contact":
            raise ValueError("--newton snes works with --support clamped only (the floor runs "
                             "the hand-written active-set loop)")
        if self.mixed and self.degree < 2:
            raise ValueError("--mixed is Taylor–Hood: P2 displacements (--degree 2)")
        if not 0 < self.tolerance < 1:
            raise ValueError(f"--tolerance must be in (0, 1), got {self.tolerance!r}")
        if self.mesh and self.size is not None:
            raise ValueError("--size and --mesh contradict each other: a mesh file has its "
                             "own sizes")
        mm = MM[self.units]
        self.E = self.E if self.E is not None else 200e3 / mm**2
        self.material_flags(power_law={"sigma0": 200.0 / mm**2, "n": 0.2},
                            j2={"sigma0": 200.0 / mm**2, "hardening": 13e3 / mm**2})
        if self.friction is not None and self.support != "contact":
            raise ValueError("--friction acts between the base and the floor: add --support "
                             "contact")
        if self.size is not None and self.size > 2 * THICK * mm:
            raise ValueError(f"--size {self.size:g} {self.units} is more than twice the plate "
                             f"thickness ({THICK * mm:g} {self.units}): the plate's "
                             "bending is not resolved")


args = cli.arguments(BracketParameters, prefixes={
    "bracket_": "Newton's KSP; bracket_snes_: SNES; bracket_elim_: contact"})


# -

# ### The mesh and its tags
#
# The gmsh geometry (or the user's .msh) with its physical groups as DOLFINx meshtags:
# `bolts` (the two bolt holes), `load` (the arm's hole), `base` (the bottom face).

# +
mm = MM[args.units]
size_mm = args.size / mm if args.size is not None else DEFAULT_SIZE_MM
say("reading " + args.mesh if args.mesh else f"meshing the bracket (size {size_mm:g} mm) ...")
data = bracket_mesh(comm, size_mm, args.mesh, 1.0 if args.mesh else mm)
msh, facet_tags = data.mesh, data.facet_tags


def tagged(name):
    """The facets of the physical group `name`."""
    return facet_tags.find(data.physical_groups[name].tag)


# -

# ### The function space and the boundary conditions
#
# Lagrange P`degree` displacements (with `--mixed`, Taylor–Hood: P2 displacements and a
# P1 pressure). The bolt holes are clamped; the loaded hole carries a uniform traction
# $t$ of total force F along +x, a `fem.Constant` the load steps scale.

# +
if args.mixed:
    W = mixed.taylor_hood(msh, args.degree)
    w = fem.Function(W, name="displacement_pressure")
    (u, p), (v, q) = ufl.split(w), ufl.TestFunctions(W)
    V = W.sub(0)  # the displacement part: its dofs are numbered in w
else:
    V = fem.functionspace(msh, ("Lagrange", args.degree, (3,)))
    w = u = fem.Function(V, name="displacement")
    v = ufl.TestFunction(V)
parts = mixed.unknown_of(w)  # u (and p) as Functions of their own, to write out and draw
bcs = [boundary.fixed(V, tagged("bolts"))]
ds = ufl.Measure("ds", domain=msh, subdomain_data=facet_tags)
ds_load = ds(data.physical_groups["load"].tag)
load_area = comm.allreduce(fem.assemble_scalar(fem.form(1.0 * ds_load)))
t = fem.Constant(msh, np.zeros(3))


def set_load(force):
    """Total force `force` [N] along +x, spread uniformly over the loaded hole."""
    t.value[:] = [force / load_area, 0.0, 0.0]


mean_u = [fem.form(u[i] * ds_load) for i in range(3)]


def load_point_motion():
    """The loaded hole's mean displacement vector."""
    return np.array([comm.allreduce(fem.assemble_scalar(f)) / load_area for f in mean_u])


# -

# ### The material
#
# The power law is a free energy of the strain alone (deformation theory: non-linear
# elasticity, no history),
#
# $$ \varphi(\varepsilon) = \frac{\kappa}{2} (\mathrm{tr}\,\varepsilon)^2 +
#    \frac{\sigma_0 \varepsilon_0}{n+1}\Big[\big(1 + \varepsilon_{eq}^2/\varepsilon_0^2
#    \big)^{(n+1)/2} - 1\Big], \qquad
#    \varepsilon_{eq}^2 = \tfrac23\, \mathrm{dev}\,\varepsilon : \mathrm{dev}\,\varepsilon, $$
#
# smooth at zero strain (there its tangent is Hooke's) and convex for every $n > 0$, so the
# equilibrium is the unique minimiser of the potential energy and every Newton variant has a
# well-posed target. $\sigma = \partial\varphi/\partial\varepsilon$ and the tangent
# $\partial^2\varphi/\partial\varepsilon^2$ are UFL's derivatives of this one expression.
# `--material j2` is von Mises plasticity instead (a history: its state at the quadrature
# points, committed per step), `--material linear` Hooke's law.

# +
dx = kinematics.quadrature_measure("dx", msh, 2 * args.degree)  # exact for Hooke's part
plastic = args.material == "j2"
if plastic:
    material = J2Plasticity(args.E, args.nu, sigma0=args.sigma0, H=args.hardening)
    material.bind(msh, 2 * args.degree)  # its state lives at dx's quadrature points
elif args.material == "power-law":
    material = PowerLaw(args.E, args.nu, sigma0=args.sigma0, n=args.n)
else:
    material = LinearElastic(args.E, args.nu)
# -

# ### The residual
#
# $R(u; v) = \int_\Omega \sigma(\varepsilon(u)) : \varepsilon(v)\,dx -
# \int_{S_{load}} t \cdot v\,ds$. With `--mixed` the first term is the variation of
# $\Pi(u, p) = \int \tilde\varphi(\varepsilon) + p\,\mathrm{tr}\,\varepsilon - p^2/(2\kappa)$.

# +
eps = ufl.sym(ufl.grad(u))
if args.mixed:
    internal = mixed.internal_work(material, u, p, v, q, "3d")
else:
    internal = ufl.inner(material.stress(eps), ufl.sym(ufl.grad(v)))
residual = internal * dx - ufl.dot(t, v) * ds_load
# -

# ### One solver per Newton variant, on the same residual
#
# `NewtonSolver` runs the course's loop with the chosen tangent: `full` (assembled and
# factorized every iteration), `modified` (the step's first tangent, factorized once per
# step), `periodic` (refreshed every 3 iterations), `bfgs` (the first factorization
# corrected by the last iterates' secant pairs); `snes` is the same problem through PETSc
# SNES. Newton stops at $\|R\| \le$ `--tolerance` $\times F$. With `--support contact`
# the base rests on the rigid floor z = 0 and the variant runs inside the course's
# active-set loop (`ActiveSetContact`; with `--friction`, Coulomb's statuses).
#
# What each variant costs per iteration is what decides between them: with MUMPS a full
# iteration of the default P2 mesh (assembly and factorization) costs about 14 modified
# ones (0.52 s against 0.037 s at 22k unknowns), so the frozen tangents win here, BFGS by
# 2.6x; with CG + GAMG (`--linear-solver gamg`) nothing is factorized and the ranking turns over
# (the benchmarks page has both).

# +
# a stale tangent converges linearly: modified and quasi-Newton get many cheap iterations
# (367 for one step to 8 kN); full Newton not converged in 50 is lost (a step too large)
MAX_IT = {"full": 50, "snes": 50, "periodic": 150, "modified": 800, "bfgs": 800}


def solver_for(variant):
    """The non-linear solver of `residual` with the Newton variant `variant`."""
    if variant == "snes":
        return SnesSolver(residual, w, bcs, prefix="bracket_snes_", rtol=1e-10,
                          atol=args.tolerance, force_scale=args.force, max_it=MAX_IT[variant],
                          linear_solver=args.linear_solver)
    options = dict(method=variant, rtol=1e-10, atol=args.tolerance, force_scale=args.force,
                   max_it=MAX_IT[variant], linear_solver=args.linear_solver)
    if args.linear_solver == "gamg" and args.mixed:  # MINRES, a block preconditioner
        options["preconditioner"] = mixed.preconditioner(material, W, "3d", dx)
    if variant in ("modified", "bfgs"):  # what they keep: for J2, Hooke's tangent
        options["constant_tangent"] = (mixed.modified_newton_tangent(material, w, "3d", dx)
                                       if args.mixed else
                                       material.modified_newton_tangent(u, "3d", dx))
    if args.support == "clamped":
        return NewtonSolver(residual, w, bcs, prefix="bracket_", **options)
    # the floor z = 0 under the base: outward normal −e_z, no node active before it presses
    floor = dict(normal_axis=2, normal_sign=-1, initial="none", prefix="bracket_",
                 newton_options=options, displacement_space=V if args.mixed else None)
    if args.friction is None:
        return ActiveSetContact(residual, w, bcs, tagged("base"), floor_gap, **floor)
    return FrictionalContact(residual, w, bcs, tagged("base"), floor_gap,
                             friction=args.friction, **floor)


def floor_gap(x):
    """γ = 0: the base rests on the floor z = 0 (its outward normal −e_z)."""
    return np.zeros(x.shape[1])


# -

# ### The load steps, for each variant
#
# Equal load steps from u = 0, each from the last converged state; a converged step
# commits the plastic state and the floor's slip history. With `--unload` as many steps
# back to F = 0. With `--compare`, every variant runs on the same mesh.

# +
def fields(solver):
    """What --output writes at every converged step (a time series)."""
    return [parts.displacement(), *([parts.pressure()] if args.mixed else []), von_mises(),
            *(solver.fields() if args.support == "contact" else []),
            *(material.output_fields() if plastic else [])]


def von_mises():
    """σ_eq per cell (DG0); the mixed form's from its pressure unknown."""
    return parts.von_mises(material, "3d")


def solve(variant):
    """Load steps with one Newton variant; returns its solver, a record per step, the time."""
    w.x.array[:] = 0.0
    if plastic:
        material.reset()
    solver = solver_for(variant)
    say(f"{output.dofs(w.function_space)} unknowns (P{args.degree}), {variant} Newton, "
        f"{args.steps} load steps")
    total, steps = (2 if args.unload else 1) * args.steps, []

    def record(t, r):
        """Keep and say the step just converged at load factor `t` (result `r`)."""
        if len(steps) >= args.steps:  # unloading
            t = 1.0 - t
        steps.append({"force": t * args.force,
                      "load_point_displacement": float(np.linalg.norm(load_point_motion())),
                      "newton_iterations": r.iterations,
                      "active_set_iterations": r.active_set_iterations,
                      "factorizations": r.work.factorizations,
                      "tangent_assemblies": r.work.tangent_assemblies,
                      "krylov_iterations": r.work.krylov_iterations,
                      "residual_norms": list(r.residual_norms)})
        cli.converged_step({"load_factor": t, **steps[-1]}, fields=lambda: fields(solver))
        sets = (f" in {r.active_set_iterations} active-set iterations"
                if r.active_set_iterations else "")
        say(f"  {variant}: step {len(steps)}/{total}, F = {t * args.force:.4g} N, "
            f"{r.iterations} Newton iterations{sets}, |u_load| = "
            f"{steps[-1]['load_point_displacement']:.6g} {args.units}")

    def commit():  # a converged step's state: plastic strains, the floor's slip history
        if plastic:
            material.commit(u)
        if args.friction is not None:
            solver.commit()

    # --restart: the checkpoint's displacement, plastic state, floor contact and steps back;
    # --checkpoint: saved after each converged step of the loading
    contact = solver if args.support == "contact" else None
    checkpoints = cli.checkpointing(
        {"unknown": w, **(material.state_functions() if plastic else {})},
        newton=contact.newton if contact else (solver if variant != "snes" else None),
        contact=contact)
    steps += [{k: v for k, v in s.items() if k != "load_factor"} for s in checkpoints.steps]
    t0 = time.perf_counter()
    try:
        solve_incrementally(solver, lambda t: set_load(t * args.force), args.steps,
                            adaptive=False, predictor=False, on_step=record, commit=commit,
                            **checkpoints.options)
        if args.unload:
            solve_incrementally(solver, lambda t: set_load((1 - t) * args.force), args.steps,
                                adaptive=False, predictor=False, on_step=record, commit=commit)
    except LoadStepError as err:  # a stall at round-off needs a looser tolerance
        stalled = err.result is not None and err.result.reason == "round_off"
        advice = "raise --tolerance" if stalled else "take more --steps"
        back = len(steps) >= args.steps  # the failed step unloads
        F = (1 - err.target if back else err.target) * args.force
        raise LoadStepError(f"load step {len(steps) + 1}/{total} (F = {F:.4g} N), {variant} "
                            f"Newton: {err.__cause__}; {advice}", err.result) from err
    return solver, steps, comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)


variants = [n for n in VARIANTS if not (n == "snes" and args.support == "contact")]
if args.compare and args.support == "contact":
    say("  (snes skipped: the floor contact runs the hand-written active-set loop)")
runs = {n: solve(n) for n in (variants if args.compare else [args.newton])}
# -

# ### Equilibrium
#
# There is no closed form for this part (its |u_load| is checked by mesh convergence in the
# benchmarks page); what must hold is equilibrium: the bolts (and the floor) hold the load,
# $\sum R = (-F, 0, 0)$ to the solver's tolerance.

# +
groups = {"bolts": tagged("bolts"), **({"base": tagged("base")}
                                       if args.support == "contact" else {})}
reactions = boundary.reactions(residual, w, groups, space=V if args.mixed else None)
held = [sum(r[i] for r in reactions.values()) for i in range(3)]
final = 0.0 if args.unload else args.force  # the load at the end of the path
imbalance = np.linalg.norm(np.subtract(held, [-final, 0.0, 0.0])) / args.force
say(f"supports hold ({', '.join(f'{x:.6g}' for x in held)}) N against the load "
    f"({final:.6g}, 0, 0) N: imbalance {imbalance:.1e} F")
# -

# ## Outputs
#
# The JSON (the load-point displacement, the largest σ_eq and the strain it means, the
# work counts; with `--compare` one table of the variants) and, when asked, the fields for
# ParaView (written at every step as it converged), the load–displacement curve and the
# deformed part.

# +
def warnings():
    """What the mesh cannot promise (the convergence checks: the benchmarks page)."""
    notes = ["no closed form for this part: |u_load| is checked by mesh convergence "
             "(docs/benchmarks.md), σ_eq peaks at the singular clamped bolt-hole edges"]
    if args.mesh:
        notes.append(f"user mesh {args.mesh}: its resolution is not checked")
    elif size_mm > DEFAULT_SIZE_MM:
        notes.append(f"elements coarser than the default {DEFAULT_SIZE_MM:g} mm: |u_load| is "
                     f"more than 4 % below its converged value (measured: -5 % at 10 mm, "
                     f"-10 % at 20 mm)")
    if args.degree == 1:
        notes.append("P1 tetrahedra lock in this bending problem (about half the displacement)")
    if args.unload:
        notes.append("unloaded: max_von_mises and the reactions are those of the residual "
                     "state")
    return notes


def summary(solver, steps, wall):
    """The JSON of one variant's run (its state is the last one solved)."""
    vm_max = global_max(comm, von_mises().x.array)
    tdim = msh.topology.dim
    cells = np.arange(msh.topology.index_map(tdim).size_local, dtype=np.int32)
    out = {"support": args.support, "force": args.force, "length_unit": args.units,
           "load_point_displacement": steps[args.steps - 1]["load_point_displacement"],
           "max_von_mises": vm_max,
           **{k: sum(s[k] for s in steps) for k in ("newton_iterations", "factorizations",
                                                    "tangent_assemblies",
                                                    "krylov_iterations")},
           "residual_norms": steps[-1]["residual_norms"],
           "steps": [{k: v for k, v in s.items() if k != "residual_norms"} for s in steps],
           "reactions": boundary.reactions(residual, w, groups,
                                           space=V if args.mixed else None),
           "largest_cell": global_max(comm, msh.h(tdim, cells)),
           "dofs": output.dofs(w.function_space), "ranks": comm.size, "solve_time_s": wall,
           "peak_memory_mb": output.peak_memory_mb(comm), "warnings": warnings()}
    if args.material == "power-law":  # the strain the peak stress means
        out["max_eps_eq_over_eps0"] = material.strain_ratio(vm_max)
    if plastic:
        out.update(material.plastic_zone(dx))
    if args.unload:  # what the load leaves behind
        out["permanent_load_point_displacement"] = steps[-1]["load_point_displacement"]
    if args.support == "contact":
        c = solver
        out["lifted_off_area"], out["contact_area"] = c.contact_areas()
        out["active_set_iterations"] = sum(s["active_set_iterations"] for s in steps)
        out["max_floor_pressure"] = global_max(comm, c.pressure()[c.active])
        if args.friction is not None:  # Coulomb on the whole floor: |T_t| <= f T_n
            fx, fy, fz = out["reactions"]["base"]
            out.update(friction=args.friction, stick_nodes=c.surface.count(c.stick),
                       slip_nodes=c.surface.count(c.slip),
                       floor_friction_ratio=np.hypot(fx, fy) / (args.friction * fz)
                       if args.friction > 0 and fz > 0 else 0.0)
    return out


if args.compare:  # one table; the JSON is full Newton's, every variant's under `variants`
    rows = {n: summary(*r) for n, r in runs.items()}  # (each variant's last state: the same)
    ref = rows["full"]["load_point_displacement"]
    say(f"\n| Newton | iterations per step | factorizations | tangent assemblies | time (s) "
        f"| |u_load| ({args.units}) | rel. diff. to full |\n|---|---|---|---|---|---|---|")
    for name, r in rows.items():
        its = ", ".join(str(s["newton_iterations"]) for s in r["steps"])
        say(f"| {name} | {its} | {r['factorizations']} | {r['tangent_assemblies']} | "
            f"{r['solve_time_s']:.2f} | {r['load_point_displacement']:.9g} | "
            f"{abs(r['load_point_displacement'] / ref - 1):.1e} |")
    cli.results({**rows["full"], "variants": rows})
else:
    solver, steps, wall = runs[args.newton]
    out = summary(solver, steps, wall)
    strain = (f" (ε_eq ≈ {out['max_eps_eq_over_eps0']:.3g} ε0)"
              if "max_eps_eq_over_eps0" in out else "")
    lifted = (f", lifted-off area {out['lifted_off_area']:.4g} {args.units}²"
              if "lifted_off_area" in out else "")
    say(f"|u_load| = {out['load_point_displacement']:.6g} {args.units}, max σ_eq = "
        f"{out['max_von_mises']:.4g} N/{args.units}²{strain}, {out['newton_iterations']} "
        f"Newton iterations, {out['factorizations']} factorizations, {out['dofs']} unknowns"
        + lifted)

    def curve():
        """The load against the load-point displacement, every converged step."""
        if comm.rank == 0:
            plt = figures.pyplot()
            fig, ax = plt.subplots(figsize=(5, 4))
            ax.plot([0] + [s["load_point_displacement"] for s in steps],
                    [0] + [s["force"] / 1e3 for s in steps], "o-")
            ax.set(xlabel=f"load-point displacement |u| [{args.units}]", ylabel="force [kN]",
                   title=f"bracket, {args.support} support, {args.material}"
                   + (f" n = {args.n}" if args.material == "power-law" else ""))
            ax.grid(alpha=0.3)
            figures.save_figure(fig, args.plot)

    def picture():
        """The deformed part, coloured by σ_eq (J2: by the cumulated plastic strain)."""
        field = material.cumulated_plastic_strain_per_cell() if plastic else von_mises()
        deformed.bracket_picture(
            parts.displacement(), field, args.png,
            clamped=tagged("bolts"), loaded=tagged("load"), load_motion=load_point_motion(),
            units=args.units, force=args.force, support=args.support, unloaded=args.unload,
            floor=(solver.x[solver.owned], solver.active[solver.owned])
            if args.support == "contact" else None,
            label="cumulated plastic strain p (largest of each cell)" if plastic else None)
        say(f"wrote {args.png}")

    cli.results(out, [*([curve] if args.plot else []), *([picture] if args.png else [])])
