# # Rigid spherical punch on an elastic block: Hertz contact by the active-set method
#
# A rigid sphere of radius $R$ is pressed by $\delta$ into an elastic block (frictionless).
# The contact zone is unknown: the course's active-set algorithm finds it. Hertz's theory
# gives the answer for a half-space and a parabolic gap, which this demo checks.
#
# ## Problem definition
#
# On the top surface $S_C$ (outward normal $n = e_z$) the gap to the punch is
# $\gamma(r) = r^2/(2R) - \delta$, and
#
# $$ u_n - \gamma \le 0, \qquad T_n \le 0, \qquad (u_n - \gamma)\, T_n = 0 .$$
#
# Iteration $k$ solves linear elasticity with $u_n = \gamma$ on the active nodes and $T = 0$
# elsewhere; an active node in tension ($T_n > 0$) leaves, an inactive node that penetrates
# ($u_n - \gamma > 0$) joins; the set converges when nothing changes. Hertz, with
# $E^* = E/(1-\nu^2)$:
#
# $$ a = \sqrt{R\delta}, \qquad P = \tfrac43 E^* \sqrt{R}\, \delta^{3/2}, \qquad
#    p_0 = \frac{3P}{2\pi a^2}, \qquad p(r) = p_0\sqrt{1 - r^2/a^2}. $$
#
# In plane strain the punch is a cylinder and $\delta$ is not defined by Hertz (it depends
# on the block), so the half-width $a = \sqrt{4PR/(\pi E^*)}$ and $p_0 = 2P/(\pi a)$ are
# checked against the computed force per unit length $P$.
#
# The block must behave like a half-space: it is 1000 contact radii wide and deep (100 in
# 3D), with elements of a/40 under the punch (axisymmetric; plane strain a/80, 3D a/12)
# growing by 5 % of the distance away from it (3D: 10 %);
# on the axisymmetric model this keeps the block-size and far-field error near 0.15 %,
# below the 0.5 % asked of the force (the sizes are measured in `fenics_nl/scenes/punch.py`).
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

from fenics_nl.domain.probes import Probes
from fenics_nl.io import cli
from fenics_nl.io.cli import say
from fenics_nl.io.parameters import Parameters, choice, number, switch
from fenics_nl.materials.laws import LinearElastic, PowerLaw
from fenics_nl.materials.plasticity import J2Plasticity
from fenics_nl.parallel import global_max
from fenics_nl.scenes import punch_pictures
from fenics_nl.scenes.punch import Punch, PunchBlock, PunchLoad, check_contact_resolution
from fenics_nl.solvers.loading import solve_incrementally
from fenics_nl.theory import hertz, mindlin

comm = MPI.COMM_WORLD
MAX_REFINE = 6  # a/1280 under the punch (plane strain a/2560): ~1e6 unknowns
# -

# ### Parameters
#
# From the command line (`python demos/punch.py --help` lists them); in a notebook, the
# defaults. The PETSc options of the run's solver take the prefix
# `-punch_<model>_<form>_`.

# +
@dataclass
class PunchParameters(Parameters):
    """Rigid spherical punch on an elastic block (Hertz contact, the course's active set).
    Units are the user's, consistent (e.g. N, m, Pa or N, mm, MPa)."""

    EPILOG = ("PETSc options of this run's solver take the prefix -punch_<model>_<form>_, "
              "<model> = axisymmetric | 3d | plane_strain, <form> = elim (KSP of each "
              "active-set iteration) | mult (SNES and KSP of the saddle point), e.g. "
              "-punch_axisymmetric_elim_ksp_view. An option no solver reads is an error.")
    OUTPUTS: ClassVar = {
        "output": "displacement, von Mises stress (j2: plastic strains), contact pressure and "
                  "active set",
        "png": "the deformed contact zone (von Mises stress) beside the contact pressure, "
               "against Hertz",
        "plot": "force-indentation and pressure against Hertz"}
    CHECKPOINTS = True

    model: str = choice("axisymmetric", ["axisymmetric", "3d", "plane_strain"],
                        "axisymmetric (r,z), 3D quarter, plane strain", spelling=True)
    E: float = number(1.0, "Young's modulus", unit="stress", above=0)
    nu: float = number(0.3, "Poisson's ratio", unit="-")
    radius: float = number(1.0, "punch radius R", unit="length", above=0)
    indentation: float | None = number(None, "displacement control: indentation δ, non-zero "
                                       "(default 0.01 R; negative: the punch stays clear)",
                                       unit="length", group="load")
    force: float | None = number(None, "force control: total force P (per unit length in "
                                 "plane strain)", unit="force", above=0, group="load")
    steps: int = number(1, "load steps from 0 to the load", at_least=1)
    formulation: str = choice("elimination", ["elimination", "multiplier"], "active normal "
                              "displacements as Dirichlet rows, or Lagrange multipliers")
    mixed: bool = switch("Taylor–Hood P2–P1 displacement–pressure elements: no locking as "
                         "ν → 1/2, and ν = 0.5 exactly (with the elimination)")
    gap: str = choice("parabola", ["parabola", "sphere"], "punch shape: Hertz's parabola or "
                      "the exact sphere")
    material: str = choice("linear", ["linear", "power-law", "j2"], "linear elastic (Hertz "
                           "applies), the power law (Newton inside), or j2: von Mises "
                           "plasticity (path-dependent; --unload for the imprint)")
    sigma0: float | None = number(None, "power law: stress where it turns non-linear "
                                  "(default 0.01)", unit="stress", above=0)
    n: float | None = number(None, "power law exponent (default 0.3)", unit="-", above=0)
    hardening: float | None = number(None, "j2: linear isotropic hardening modulus H "
                                     "(default 0.1 E)", unit="stress")
    unload: bool = switch("take the punch back up in as many steps (displacement control): "
                          "the residual imprint")
    refine: int = number(1, "element size under the punch a/(20·2^refine) (3D: "
                         "a/(6·2^refine))", at_least=0, at_most=MAX_REFINE)
    block: float | None = number(None, "block size in contact radii, >= 10 (default 1000, 3D "
                                 "100)", above=0)
    friction: float | None = number(None, "Coulomb friction coefficient f (statuses open / "
                                    "stick / slip; default: frictionless)", at_least=0,
                                    metavar="F")
    tangential_ratio: float | None = number(
        None, "after the normal load, a tangential force Q = R f P along x, 0 <= R < 1 "
        "(Cattaneo-Mindlin partial slip)", at_least=0, group="tangential", metavar="R")
    tangential_force: float | None = number(
        None, "after the normal load, the tangential force Q (per unit length in plane "
        "strain), below f P", unit="force", at_least=0, group="tangential", metavar="Q")
    tangential_displacement: float | None = number(
        None, "after the normal load, move the punch by D along +x", unit="length", above=0,
        group="tangential", metavar="D")

    def check(self):
        # j2: σ0 = 0.3 p0 of the default indentation, so that a plastic zone forms
        cli.material_flags(self, power_law={"sigma0": 0.01, "n": 0.3},
                           j2={"sigma0": 0.02 * self.E, "hardening": 0.1 * self.E})
        if self.mixed and self.formulation == "multiplier" and self.model == "3d":
            raise ValueError("--mixed --formulation multiplier is 2D and axisymmetric only (no "
                             "nodal rule with positive weights on P2 triangles): use "
                             "--formulation elimination in 3d")
        if self.unload and self.force is not None:
            raise ValueError("--unload takes the punch back up under displacement control: "
                             "drop --force")
        if self.indentation is not None and self.indentation == 0:
            raise ValueError("--indentation must be non-zero (negative: the punch stays clear)")
        if self.indentation is None and self.force is None:
            self.indentation = 0.01 * self.radius
        if self.moved and self.friction is None:
            raise ValueError("a tangential load needs --friction F: without friction nothing "
                             "holds the punch")
        if self.moved and self.unload:
            raise ValueError("--unload lifts the punch: a tangential load is applied to the "
                             "loaded punch only (drop --unload)")
        if self.moved and self.model == "axisymmetric":
            raise ValueError("a tangential load breaks the axial symmetry: use --model "
                             "plane_strain or 3d")
        if self.friction is not None and self.formulation == "multiplier":
            raise ValueError("--friction is written for --formulation elimination")
        if self.tangential_ratio is not None and not self.tangential_ratio < 1:
            raise ValueError(f"--tangential-ratio must be in [0, 1), got "
                             f"{self.tangential_ratio} (at Q = f P the punch slides: no static "
                             "equilibrium)")

    @property
    def moved(self) -> list[float]:
        """The tangential load given (at most one)."""
        return [x for x in (self.tangential_ratio, self.tangential_force,
                            self.tangential_displacement) if x is not None]


args = cli.arguments(PunchParameters, prefixes=lambda a: {
    f"punch_{a.model}_{a.formulation[:4]}_":
        "KSP" if a.formulation == "elimination" else "SNES and KSP"})
moved = args.moved
# -

# ### The block
#
# A graded mesh, fine (h = a/40 axisymmetric by default) within 1.5 a of the axis, coarser
# away from it, in a block 1000 a wide (100 a in 3D) so that it behaves like Hertz's
# half-space. Its bottom slides on a rigid base; the symmetry planes carry their symmetry
# conditions; its top is the contact surface $S_C$. The contact radius the mesh is built
# for is Hertz's $a$ for the force (sphere, or the cylinder's half-width), else
# $\sqrt{R\delta}$ (for a cylinder, a safe overestimate).

# +
E, nu, R = args.E, args.nu, args.radius
if args.force is None:
    a = math.sqrt(R * abs(args.indentation))
elif args.model == "plane_strain":
    a = hertz.cylinder_from_force(E, nu, R, args.force)["contact_radius"]
else:
    a = hertz.sphere_from_force(E, nu, R, args.force)["contact_radius"]
size = args.block or (100.0 if args.model == "3d" else 1000.0)
say(f"meshing the {args.model} block ({size:g} contact radii) ...")
block = PunchBlock(args.model, a, refine=args.refine, block=size, mixed=args.mixed,
                   tangential=bool(moved))
# -

# ### The material
#
# A free energy $\varphi(\varepsilon)$; the stress $\sigma = \partial\varphi/\partial
# \varepsilon$ and the tangent are derived from it by UFL. Hertz's theory is linear
# elastic; the power law puts a Newton loop inside every active-set iteration.

if args.material == "j2":  # its state lives at the quadrature points of the block's rule
    material = J2Plasticity(E, nu, sigma0=args.sigma0, H=args.hardening)
    material.bind(block.mesh, block.quadrature_degree)
else:
    material = (LinearElastic(E, nu) if args.material == "linear"
                else PowerLaw(E, nu, sigma0=args.sigma0, n=args.n))

# ### The residual
#
# $R(u; v) = \int_\Omega \sigma(\varepsilon(u)) : \varepsilon(v)\,d\Omega$, and no
# external load: the punch acts only through the contact conditions. In the axisymmetric
# model $\varepsilon$ has the hoop strain $u_r/r$ and the weight is $2\pi r$, so that $R$
# is the whole body's. With `--mixed` the pressure p is an unknown too and the residual is
# the variation of $\Pi(u, p) = \int \tilde\varphi(\varepsilon) + p\,\mathrm{tr}\,
# \varepsilon - p^2/(2\kappa)$ (`fenics_nl.materials.mixed`), which holds at κ = ∞.

# +
u = block.u
residual = block.residual(material)  # block.fields.internal_work(material, model) * dx
# -

# ### The active-set loop, in load steps
#
# `Punch` gives the residual, the supports and the gap $\gamma$ to
# `fenics_nl.contact.active_set.ActiveSetContact`, which runs the course's loop: solve with
# $u_n = \gamma$ on the active nodes (rows eliminated, or Lagrange multipliers), then
# update the set (leave where $T_n > 0$, join where $u_n > \gamma$) until it stops
# changing. The load (δ, or the force P by a secant iteration on δ) grows in equal steps,
# each started from the last active set.

# +
punch = Punch(block, material, residual, R, formulation=args.formulation, gap=args.gap,
              friction=args.friction)
say(f"{args.model} punch, {args.formulation}, {punch.dofs} unknowns, h = {block.h:.3g}")
load = PunchLoad(punch, indentation=args.indentation, force=args.force,
                 first_guess=a * a / R)
states = load.states


def fields():
    """What --output writes at every converged step (a time series)."""
    state = [block.displacement(), *([block.fields.pressure()] if args.mixed else []),
             *punch.contact_fields(), punch.von_mises()]
    return state + (material.output_fields() if args.material == "j2" else [])


def report(t, result):
    s = states[-1]
    cli.converged_step({"load_factor": t if len(states) <= args.steps else 1 - t,
                        "indentation": s.indentation, "force": s.force,
                        "contact_radius": s.contact_radius, "max_pressure": s.max_pressure,
                        "active_set_iterations": s.active_set_iterations}, fields=fields)
    say(f"step {len(states)}/{args.steps * (2 if args.unload else 1)}: δ = "
        f"{s.indentation:.5g}, P = {s.force:.6g}, "
        f"a = {s.contact_radius:.5g}, p0 = {s.max_pressure:.5g}, "
        f"{s.active_set_iterations} active-set iterations")


plastic = args.material == "j2"
commit = (lambda: material.commit(u, block.kinematics)) if plastic else None
# --restart: the checkpoint's displacement, plastic state, contact statuses (and slip
# history) and states back; --checkpoint: saved after each converged step of the loading
checkpoints = cli.checkpointing(
    {"unknown": block.unknown, **(material.state_functions() if plastic else {})},
    newton=punch.contact.newton, contact=punch.contact, kept=load.record)
if checkpoints.kept is not None:
    load.take_back(checkpoints.kept)
solve_incrementally(load, load.set_load, args.steps, adaptive=False, predictor=False,
                    on_step=report, commit=commit, **checkpoints.options)
last = states[-1]  # the loaded state: what is checked
nodes = punch.nodes_in_contact()
imprint = None
if args.unload:  # back up in as many steps; the surface keeps an imprint
    solve_incrementally(load, lambda t: load.set_load(1 - t), args.steps, adaptive=False,
                        predictor=False, on_step=report, commit=commit)
    axis = [0.0] * (3 if args.model == "3d" else 2)
    imprint = -Probes(block.mesh, [axis]).continuous(block.displacement())[0][block.vertical]
    say(f"unloaded: residual imprint depth {imprint:.5g} at the axis (δ_max = "
        f"{last.indentation:.5g})")
# -

# ### Against Hertz
#
# The force (not for the cylinder: its indentation depends on the block, Hertz gives no
# $P(\delta)$), the radius of the outermost active node (within h of the true edge) and the
# largest nodal pressure, against Hertz's values for the computed state; with several steps,
# the exponent of $P \propto \delta^m$ (Hertz: 1.5). A contact zone the mesh cannot resolve
# (fewer than 4 nodes) is refused.

# +
warnings = check_contact_resolution(nodes, block.h, last)
ref = punch.hertz(last) if last.force > 0 else None
errors = {}
if ref is None:
    say("the punch does not touch the block: zero contact force")
else:
    errors = {k: getattr(last, k) / ref[k] - 1 for k in ("force", "contact_radius",
                                                         "max_pressure") if k in ref}
    checked = [f"{k.replace('_', ' ')} {getattr(last, k):.6g} (Hertz {ref[k]:.6g}, "
               f"{100 * e:+.3f} %)" for k, e in errors.items()]
    if args.model == "plane_strain":  # a cylinder: Hertz's a and p0 for the computed P
        checked.insert(0, f"P = {last.force:.6g} per unit length (not checked)")
    say("; ".join(checked) + f"; h = {block.h:.2g}")
exponent = None
loading = states[: args.steps]
if len(loading) >= 2 and all(s.force > 0 for s in loading):
    exponent = float(np.polyfit(np.log([s.indentation for s in loading]),
                                np.log([s.force for s in loading]), 1)[0])
    say(f"P ∝ δ^{exponent:.4f} over the steps" + ("" if args.model == "plane_strain"
                                                   else " (Hertz: 1.5)"))
# -

# ### The tangential load, with friction (Cattaneo–Mindlin)
#
# With `--friction`, every node of $S_C$ is open, sticking or slipping
# (`fenics_nl.contact.friction.FrictionalContact`): sticking nodes keep their position
# relative to the punch, slipping ones carry the tangential force $f |T_n|$ against their
# slip. After the normal load the punch moves along x, by a prescribed D or until the
# tangential force is Q (`Punch.pull`, secant steps on the punch's position). Partial slip
# against Cattaneo–Mindlin (exact at ν = 1/2, where the normal and tangential problems
# decouple): the stick half-width c = a √(1 − Q/(fP)) and the traction profile of the
# cylinder (plane strain), and in 3D the sphere's stick radius c = a (1 − Q/(fP))^(1/3),
# the tangential force inside each radius, Q(r), and its tangential displacement δ_t(Q).

# +
def mindlin_check(T, fP):
    """The stick radius, the traction and (3D) δ_t against Cattaneo–Mindlin's, for the
    computed P (a, p0 of Hertz for it)."""
    H = (hertz.sphere_from_force if args.model == "3d" else hertz.cylinder_from_force)(
        E, nu, R, T.normal_force)
    a_H, p0_H, f = H["contact_radius"], H["max_pressure"], args.friction
    if args.model == "3d":
        c_exact = mindlin.sphere_stick_radius(a_H, T.tangential_force, fP)
        # P2 nodal forces are no pointwise traction in 3D (a vertex's is about 0): the
        # force inside each radius r = k h, Q(r), is what they give
        radii = np.arange(1, int(1.5 * a_H / block.h) + 1) * block.h
        gap = punch.tangential_force_within(radii) - mindlin.sphere_tangential_force_within(
            radii, a_H, p0_H, f, c_exact)
        out = {"tangential_force_profile_max_error": float(np.abs(gap).max()
                                                           / T.tangential_force),
               **tangential_compliance(T, a_H, fP, bonded)}
        traction_said = (f"tangential force inside r within "
                         f"{100 * out['tangential_force_profile_max_error']:.2f} % of Q")
    else:
        c_exact = mindlin.cylinder_stick_half_width(a_H, T.tangential_force, fP)
        x_n, _, q_n, _ = punch.traction_profile() or (None,) * 4
        out = {}
        if comm.rank == 0:
            q_ex = mindlin.traction(x_n, a_H, p0_H, f, c_exact)
            # away from the stick-slip edges ±c, where the exact q has an infinite slope
            away = (np.abs(np.abs(x_n) - c_exact) > 2 * block.h) & (np.abs(x_n) < 1.5 * a_H)
            out["tangential_traction_max_error"] = float(np.abs(q_n - q_ex)[away].max()
                                                         / (f * p0_H))
        out = comm.bcast(out, root=0)
        traction_said = (f"tangential traction within "
                         f"{100 * out['tangential_traction_max_error']:.2f} % of f p0 "
                         f"(beyond 2 h of the stick-slip edges)")
    out["stick_radius_exact"] = c_exact
    say(f"Cattaneo-Mindlin: stick {'radius' if args.model == '3d' else 'half-width'} "
        f"{c_exact:.5g} (FE: (c - c_exact)/h = {(T.stick_radius - c_exact) / block.h:+.2f}); "
        + traction_said)
    return out


def tangential_compliance(T, a_H, fP, bonded):
    """δ_t against Mindlin's, with the far field's share taken out.

    The finite block (clamped bottom, free sides) adds a far-field compliance C_far to the
    half-space's; it does not depend on how the contact zone sticks or slips, so the
    punch's displacement less C_far Q compares with Mindlin's δ_t. C_far is the computed
    bonded compliance (a move before any slip) less the half-space's (2 − ν)/(8 G a).
    """
    G = E / (2 * (1 + nu))
    exact_bonded = (2 - nu) / (8 * G * a_H)
    delta = mindlin.sphere_tangential_displacement(a_H, T.tangential_force, fP, G, nu)
    local = T.tangential_displacement - (bonded - exact_bonded) * T.tangential_force
    say(f"Mindlin: δ_t = {delta:.5g}; FE {T.tangential_displacement:.5g}, less the far "
        f"field's {(bonded - exact_bonded) * T.tangential_force:.3g} (bonded compliance "
        f"{bonded:.4g} against the half-space's {exact_bonded:.4g}): "
        f"{100 * (local / delta - 1):+.2f} %")
    return {"tangential_displacement_exact": delta, "bonded_compliance": bonded,
            "bonded_compliance_exact": exact_bonded,
            "tangential_displacement_local": local,
            "tangential_displacement_rel_error": local / delta - 1}


traction, mindlin_checks = None, {}
if moved:
    if last.force <= 0:
        raise ValueError("the punch does not touch the block: no normal force holds it "
                         "against a tangential load")
    # 3D: the bonded compliance of this mesh and block, to take the far field's share out
    # of the punch's displacement (Mindlin's δ_t is the half-space's)
    bonded = punch.bonded_compliance() if args.model == "3d" else None
    if args.tangential_displacement is not None:
        traction = punch.shift(args.tangential_displacement)
    else:
        Q = (args.tangential_force if args.tangential_force is not None
             else args.tangential_ratio * args.friction * last.force)
        traction, _ = punch.pull(Q)
    punch.commit()
    T = traction
    fP = args.friction * T.normal_force  # P of this state (at ν < 1/2 Q changes it)
    say(f"tangential: d = {T.tangential_displacement:.5g}, Q = {T.tangential_force:.6g} = "
        f"{T.tangential_force / fP:.4f} f P; {T.stick_nodes} nodes stick, {T.slip_nodes} "
        f"slip, stick radius {T.stick_radius:.5g}; {T.status_iterations} status iterations")
    if ref is not None and 0 <= T.tangential_force < fP:
        mindlin_checks = mindlin_check(T, fP)


# -

# ## Outputs
#
# The JSON (every quantity above, the reactions of the supports, the work done) and, when
# asked, the fields for ParaView, the force-indentation curve and the picture.


def summary():
    """The quantities of the run, for --json."""
    out = {"model": args.model, "formulation": args.formulation, "material": args.material,
           "mixed": args.mixed, "elements": "P2-P1 (Taylor-Hood)" if args.mixed else "P1",
           "force": last.force, "indentation": last.indentation,
           "contact_radius": last.contact_radius, "max_pressure": last.max_pressure,
           "element_size": block.h, "nodes_in_contact": nodes,
           "active_set_iterations": sum(s.active_set_iterations for s in states),
           "newton_iterations": sum(s.newton_iterations for s in states),
           "factorizations": sum(s.factorizations for s in states),
           "steps": [{"indentation": s.indentation, "force": s.force,
                      "contact_radius": s.contact_radius,
                      "active_set_iterations": s.active_set_iterations} for s in states],
           "reactions": punch.reactions(),
           "reactions_of": {"axisymmetric": "the whole body (2πr in the residual)",
                            "3d": "the modelled half" if moved else "the modelled quarter",
                            "plane_strain": "the whole block, per unit length" if moved
                            else "the modelled half, per unit length"}[args.model],
           "dofs": punch.dofs, "ranks": comm.size, "warnings": warnings}
    if exponent is not None:
        out["fitted_exponent"] = exponent
    for k, e in errors.items():
        out[f"hertz_{k}"], out[f"{k}_rel_error"] = ref[k], e
    if args.material != "linear":
        warnings.append(f"{args.material} material: Hertz's values are the linear "
                        f"reference, not a check")
    if args.friction is not None:
        out["friction"] = args.friction
    if traction is not None:
        T = traction
        out.update({"tangential_force": T.tangential_force,
                    "tangential_displacement": T.tangential_displacement,
                    "stick_radius": T.stick_radius, "stick_nodes": T.stick_nodes,
                    "slip_nodes": T.slip_nodes, "status_iterations": T.status_iterations,
                    **mindlin_checks})
        if nu != 0.5:
            warnings.append(f"Cattaneo-Mindlin is exact for a rigid punch on an "
                            f"incompressible body (ν = 1/2, --mixed); at ν = {nu:g} the "
                            "normal and tangential problems couple")
    if imprint is not None:
        out["residual_imprint_depth"] = imprint
        out["unloading"] = [{"indentation": s.indentation, "force": s.force}
                            for s in states[args.steps:]]
    if plastic:
        pq = material.cumulated_plastic_strain
        n_owned = pq.function_space.dofmap.index_map.size_local
        out["max_cumulated_plastic_strain"] = global_max(comm, pq.x.array[:n_owned])
    if args.model == "plane_strain" and ref is not None:
        warnings.append("plane strain: the force is not checked (a cylinder's indentation "
                        "depends on the block, Hertz gives no P(δ)); half-width and p0 are "
                        "checked against Hertz for the computed P")
    return out


writers = []
vm = punch.von_mises() if args.png else None
# gathered on every rank's call (rank 0 keeps it) before the writers run on rank 0
traction_profile = None
if traction is not None and (args.png or args.plot):  # collective: on every rank
    if args.model == "3d":  # Q(r), the force inside r (see mindlin_check)
        rings = np.linspace(0.0, 1.5, 301) * last.contact_radius
        traction_profile = (rings, punch.tangential_force_within(rings))
    else:
        traction_profile = punch.traction_profile()
run = punch_pictures.PunchRun(
    punch, states, ref, E, nu, R, mixed=args.mixed, force_controlled=args.force is not None,
    friction=args.friction, traction=traction, traction_profile=traction_profile,
    stick_radius_exact=mindlin_checks.get("stick_radius_exact"))
if args.plot:  # (--output: the fields of every step were written as they converged)
    writers.append(lambda: punch_pictures.curves(run, args.plot))
if args.png:
    writers.append(lambda: punch_pictures.section_picture(run, vm, args.png))
cli.results(summary(), writers)
