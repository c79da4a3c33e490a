# # A 3D bracket in a non-linear material: Newton variants side by side
#
# An L-shaped steel-like bracket (gmsh geometry in `fenics_nl/scenes/bracket_geometry.py`) is
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

import ufl
from mpi4py import MPI

from fenics_nl.io import cli
from fenics_nl.io.cli import say
from fenics_nl.io.parameters import Parameters, choice, number, switch, text
from fenics_nl.materials.laws import LinearElastic, PowerLaw
from fenics_nl.materials.plasticity import J2Plasticity
from fenics_nl.scenes import bracket_run
from fenics_nl.scenes.bracket import THICKNESS_MM, Bracket, BracketPart
from fenics_nl.scenes.bracket_run import DEFAULT_SIZE_MM, MM
from fenics_nl.solvers.loading import LoadStepError, solve_incrementally
from fenics_nl.solvers.newton import stalled_at_round_off

comm = MPI.COMM_WORLD
VARIANTS = ("full", "modified", "periodic", "bfgs", "snes")
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
                                f" at most twice the {THICKNESS_MM:g} mm plate thickness",
                                above=0)
    degree: int = number(2, "Lagrange degree, 1 or 2 (P1 is far too stiff here: see the "
                         "benchmarks)", at_least=1, at_most=2)
    mixed: bool = switch("Taylor–Hood P2–P1 displacement–pressure elements (ν up to 0.5; "
                         "--solver gamg: MINRES with a block preconditioner)")
    mesh: str | None = text(None, "a .msh file with groups bolts, load, base (in --units; not "
                            "with --size)", metavar="MSH")
    solver: str = choice("lu", ["lu", "gamg"], "MUMPS LU, or CG + GAMG with rigid-body "
                         "near-nullspace (every support and material; a Newton solve keeps its "
                         "first AMG hierarchy while CG keeps up, the mixed form excepted)",
                         spelling=True)
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
        if self.mesh and self.size is not None:
            raise ValueError("--size and --mesh contradict each other: a mesh file has its "
                             "own sizes")
        mm = MM[self.units]
        self.E = self.E if self.E is not None else 200e3 / mm**2
        cli.material_flags(self, power_law={"sigma0": 200.0 / mm**2, "n": 0.2},
                           j2={"sigma0": 200.0 / mm**2, "hardening": 13e3 / mm**2})
        if self.friction is not None and self.support != "contact":
            raise ValueError("--friction acts between the base and the floor: add --support "
                             "contact")
        if self.size is not None and self.size > 2 * THICKNESS_MM * mm:
            raise ValueError(f"--size {self.size:g} {self.units} is more than twice the plate "
                             f"thickness ({THICKNESS_MM * mm:g} {self.units}): the plate's "
                             "bending is not resolved")


args = cli.arguments(BracketParameters, prefixes={
    "bracket_": "Newton's KSP; bracket_snes_: SNES; bracket_elim_: contact"})


# -

# ### The part
#
# The gmsh geometry (or the user's .msh) with its physical groups: the bolt holes are
# clamped, the loaded hole carries a uniform traction of total force F along +x.

# +
mm = MM[args.units]
size_mm = args.size / mm if args.size is not None else DEFAULT_SIZE_MM
say("reading " + args.mesh if args.mesh else f"meshing the bracket (size {size_mm:g} mm) ...")
part = BracketPart(size=size_mm, mesh_file=args.mesh, support=args.support,
                   degree=args.degree, length_scale=1.0 if args.mesh else mm, mixed=args.mixed)
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
# `--material j2` is von Mises plasticity instead (a history: the state committed per step),
# `--material linear` Hooke's law.

if args.material == "j2":  # its state lives at the quadrature points of the residual's rule
    material = J2Plasticity(args.E, args.nu, sigma0=args.sigma0, H=args.hardening)
    material.bind(part.mesh, part.quadrature_degree)
else:
    material = (PowerLaw(args.E, args.nu, sigma0=args.sigma0, n=args.n)
                if args.material == "power-law" else LinearElastic(args.E, args.nu))
plastic = args.material == "j2"

# ### The residual
#
# $R(u; v) = \int_\Omega \sigma(\varepsilon(u)) : \varepsilon(v)\,dx -
# \int_{S_{load}} t \cdot v\,ds$, the traction $t$ scaled by the load factor. With
# `--mixed` the first term is the variation of $\Pi(u, p)$ (`fenics_nl.materials.mixed`).

# +
u = part.u
v = part.fields.v  # the displacement's test function (a part of (v, q) if mixed)
internal = part.fields.internal_work(material, "3d")  # in either formulation
residual = internal * part.dx - ufl.dot(part.traction, v) * part.ds_load
# -

# ### The solver and the load steps
#
# `Bracket` builds the chosen Newton variant (`fenics_nl.solvers.newton.NewtonSolver`: full,
# modified, periodic, quasi-Newton; or PETSc SNES) on this residual, inside the active-set
# loop when the base rests on the floor; its absolute tolerance is `--tolerance` times the
# load. Equal load steps, each from the last converged state. With `--compare`, every
# variant runs on the same mesh from u = 0.
#
# What each variant costs per iteration is what decides between them: full Newton
# assembles and factorizes the tangent at every iteration (few iterations, quadratic);
# modified Newton factorizes once per step and then only back-substitutes (many cheap
# iterations, a linear rate); periodic refreshes every third iteration; quasi-Newton (BFGS)
# keeps the step's first factorization and corrects it by the last iterates' secant
# information (superlinear). With MUMPS a full iteration of this P2 mesh (assembly and
# factorization) costs about 14 modified ones (0.52 s against 0.037 s at 22k unknowns), so
# the frozen tangents win here, BFGS by 2.6x; with CG + GAMG (`--solver gamg`) nothing is
# factorized and the ranking turns over (the benchmarks page has both).

# +
def fields(b):
    """What --output writes at every converged step (a time series)."""
    state = [part.displacement(), *([part.mixed.pressure()] if args.mixed else []),
             b.von_mises(), *(b.contact_fields() if args.support == "contact" else [])]
    return state + (material.output_fields() if plastic else [])


def solve(newton):
    """Load steps with one Newton variant; returns the bracket and a record per step."""
    part.unknown.x.array[:] = 0.0
    if plastic:
        material.reset()
    b = Bracket(part, material, residual, newton=newton, force_scale=args.force,
                tolerance=args.tolerance, friction=args.friction,
                linear_solver=args.solver)
    say(f"{b.dofs} unknowns (P{args.degree}), {newton} Newton, {args.steps} load steps")
    total = 2 * args.steps if args.unload else args.steps
    record = bracket_run.StepRecord(b, newton, args.force, args.steps, total, args.units,
                                    fields=lambda: fields(b))
    steps = record.steps
    # --restart: the checkpoint's displacement, plastic state, floor contact and steps back;
    # --checkpoint: saved after each converged step of the loading
    contact = b.solver if args.support == "contact" else None
    checkpoints = cli.checkpointing(
        {"unknown": part.unknown, **(material.state_functions() if plastic else {})},
        newton=contact.newton if contact else (b.solver if newton != "snes" else None),
        contact=contact)
    steps += [{k: v for k, v in s.items() if k != "load_factor"} for s in checkpoints.steps]

    def commit():  # a converged step's state: plastic strains, the floor's slip history
        if plastic:
            material.commit(u)
        b.commit()

    t0 = time.perf_counter()
    try:
        solve_incrementally(b.solver, lambda t: b.set_load(t * args.force), args.steps,
                            adaptive=False, predictor=False, on_step=record, commit=commit,
                            **checkpoints.options)
        if args.unload:
            solve_incrementally(b.solver, lambda t: b.set_load((1 - t) * args.force),
                                args.steps, adaptive=False, predictor=False, on_step=record,
                                commit=commit)
    except LoadStepError as err:
        # a stall at round-off needs a looser tolerance, not smaller steps
        norms = err.result.residual_norms if err.result is not None else []
        advice = "raise --tolerance" if stalled_at_round_off(norms) else "take more --steps"
        k = len(steps) + 1
        raise LoadStepError(f"load step {k}/{args.steps} (F = {err.target * args.force:.4g} N), "
                            f"{newton} Newton: {err.__cause__}; {advice}", err.result) from err
    wall = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    return b, steps, wall


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
b, steps, wall = runs[args.newton if not args.compare else "full"]
reactions = b.reactions()
held = [sum(r[i] for r in reactions.values()) for i in range(3)]
final = 0.0 if args.unload else args.force  # the load at the end of the path
say(f"supports hold ({', '.join(f'{x:.6g}' for x in held)}) N against the load "
    f"({final:.6g}, 0, 0) N: imbalance {abs(held[0] + final) / args.force:.1e} F")
# -

# ## Outputs
#
# The JSON (the load-point displacement, the largest σ_eq and the strain it means, the
# work counts; with `--compare` one table of the variants) and, when asked, the fields for
# ParaView (written at every step as it converged), the load–displacement curve and the
# deformed part (`fenics_nl.scenes.bracket_run`).

if args.compare:
    cli.results(bracket_run.comparison(runs, args))
else:
    out, vm = bracket_run.summary(b, steps, wall, args)
    bracket_run.say_result(out, b, args.units)
    cli.results(out, bracket_run.writers(b, vm, steps, args))
