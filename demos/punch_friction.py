# # A rigid punch pressed, then pulled sideways, with Coulomb friction: Cattaneo–Mindlin
#
# A rigid cylinder (plane strain) or sphere (3D) is pressed into an elastic block as in
# `punch.py`, and then pulled along $x$ by a tangential force $Q$ smaller than $fP$.
# The punch does not slide: the centre of the contact zone sticks while an annulus at its
# edge slips. Cattaneo (1938) and Mindlin (1949) found the size of the stick zone and the
# tractions; this demo computes them with the course's active set extended to friction,
# and checks them.
#
# ## Problem definition
#
# On $S_C$ the normal conditions of the frictionless punch hold, and Coulomb's law for the
# tangential traction $T_t$ and the slip $g_t$ (relative to the punch):
#
# $$ |T_t| \le f\,|T_n|, \qquad |T_t| < f|T_n| \Rightarrow g_t = 0, \qquad
#    |T_t| = f|T_n| \Rightarrow g_t = -\lambda\, T_t,\ \lambda \ge 0 .$$
#
# Every node of $S_C$ is **open**, **sticking** or **slipping**; each iteration solves the
# linear problem of its statuses (sticking nodes keep their place relative to the punch,
# slipping ones carry $f|T_n|$ against their slip) and updates the statuses, until they stop
# changing. For a rigid punch on an incompressible body ($\nu = 1/2$) the normal and
# tangential problems decouple and Cattaneo–Mindlin is exact: the stick half-width of the
# cylinder and the stick radius of the sphere are
#
# $$ c = a\sqrt{1 - Q/(fP)} \quad\text{(cylinder)}, \qquad
#    c = a\,(1 - Q/(fP))^{1/3} \quad\text{(sphere)}, $$
#
# and the cylinder's traction is $q(x) = f p_0 \sqrt{1 - x^2/a^2}$ in the slip zone, less
# $f p_0 (c/a)\sqrt{1 - x^2/c^2}$ inside the stick zone.
#
# ## Implementation

# +
from dataclasses import dataclass

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.contact import FrictionalContact
from fenics_nl.contact.obstacles import Indentation, RigidPunch, Traction
from fenics_nl.contact.surface import check_contact_resolution
from fenics_nl.domain import boundary
from fenics_nl.domain.meshes import punch_block, punch_block_size
from fenics_nl.io import cli, indentation_record, output
from fenics_nl.io.parameters import choice, number
from fenics_nl.io.punch_parameters import MAX_REFINE, PunchParameters, prefixes
from fenics_nl.materials import kinematics, mixed
from fenics_nl.materials.laws import LinearElastic
from fenics_nl.parallel import global_max
from fenics_nl.plots import indentation as indentation_pictures
from fenics_nl.solvers.force_control import MotionPath, reach_load
from fenics_nl.solvers.loading import solve_incrementally
from fenics_nl.theory import hertz, mindlin

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

# -

# ### Parameters
#
# The punch demos' common flags (`PunchParameters`: the block, the normal load,
# the solver) and the friction and tangential load. By default the plane-strain cylinder on
# an incompressible block, pulled to $Q = fP/2$.

# +
@dataclass
class CattaneoMindlin(PunchParameters):
    """A rigid punch pressed, then pulled sideways, with Coulomb friction (Cattaneo–Mindlin
    partial slip). Units are the user's, consistent (e.g. N, m, Pa or N, mm, MPa)."""

    model: str = choice("plane_strain", ["axisymmetric", "3d", "plane_strain"],
                        "plane strain (a cylinder), 3D half block (a sphere), or axisymmetric "
                        "(normal load only)", spelling=True)
    nu: float = number(0.5, "Poisson's ratio (at 1/2, where Cattaneo-Mindlin is exact, with "
                       "Taylor-Hood elements)", unit="-")
    refine: int = number(0, "element size under the punch a/(20·2^refine) (plane strain: "
                         "a/(40·2^refine), 3D: a/(6·2^refine))", at_least=0,
                         at_most=MAX_REFINE)
    block: float = number(100.0, "block size in contact radii, >= 10 (on both sides of the "
                          "punch with a tangential load)", above=0)
    friction: float = number(0.3, "Coulomb friction coefficient f (statuses open / stick / "
                             "slip)", at_least=0, metavar="F")
    tangential_ratio: float | None = number(
        None, "after the normal load, a tangential force Q = R f P along x, 0 < R < 1 "
        "(default 0.5; axisymmetric: none)", above=0, group="tangential", metavar="R")
    tangential_force: float | None = number(
        None, "after the normal load, the tangential force Q (per unit length in plane "
        "strain), below f P", unit="force", above=0, group="tangential", metavar="Q")
    tangential_displacement: float | None = number(
        None, "after the normal load, move the punch by D along +x", unit="length", above=0,
        group="tangential", metavar="D")

    def check(self):
        if self.nu == 0.5:  # the incompressible limit needs the pressure as an unknown
            self.mixed = True
        super().check()
        if self.formulation == "multiplier":
            raise ValueError("--friction is written for --formulation elimination")
        given = [x for x in (self.tangential_ratio, self.tangential_force,
                             self.tangential_displacement) if x is not None]
        if given and self.model == "axisymmetric":
            raise ValueError("a tangential load breaks the axial symmetry: use --model "
                             "plane_strain or 3d")
        if not given and self.model != "axisymmetric":
            self.tangential_ratio = 0.5
        if self.tangential_ratio is not None and not self.tangential_ratio < 1:
            raise ValueError(f"--tangential-ratio must be in [0, 1), got "
                             f"{self.tangential_ratio} (at Q = f P the punch slides: no static "
                             "equilibrium)")
        if self.moved and self.friction == 0:
            raise ValueError("a tangential load needs --friction F > 0: without friction "
                             "nothing holds the punch")

    @property
    def moved(self) -> bool:
        """A tangential load follows the normal one."""
        return self.model != "axisymmetric"


args = cli.arguments(CattaneoMindlin,
                     prefixes=lambda a: prefixes(a.model, a.formulation))
R, model, f = args.radius, args.model, args.friction
# -

# ### The mesh and its tags
#
# As for Hertz (`punch.py`): a block graded from elements of $h$ under the punch ($a/20$,
# plane strain $a/40$, 3D $a/6$, halved by each `--refine`), made for Hertz's contact
# radius $a$ of the load. A tangential load needs the block on both sides of the punch: it
# spans $-L \le x \le L$ and the 3D model is the half $y \ge 0$. `punch_block` tags the facets:
# `contact` ($S_C$), `bottom`, `symmetry_y` (3D), `side` (and `symmetry_x` without a
# tangential load).

# +
a = hertz.contact_radius_for(model, args.E, args.nu, R, args.indentation, args.force)
dim = 3 if model == "3d" else 2
vertical = dim - 1  # z in 3D, y in 2D: S_C's normal axis
size = punch_block_size(model, args.block)
cli.say(f"meshing the {model} block ({size:g} contact radii) ...")
mesh_data, h = punch_block(MPI.COMM_WORLD, model, a, refine=args.refine, size=size,
                           both_sides=args.moved)
msh = mesh_data.mesh


def tagged(name):
    """The facets of the physical group `name`."""
    return mesh_data.facet_tags.find(mesh_data.physical_groups[name].tag)


# the whole body's force over the modelled part's (2πr is in the axisymmetric residual)
symmetry = {"axisymmetric": 1.0, "3d": 4.0, "plane_strain": 2.0}[model] / (1 + args.moved)
# -

# ### The function space and the boundary conditions
#
# At $\nu = 1/2$ (the default) Taylor–Hood elements: P2 displacements and a P1 pressure
# $p$ (`--mixed`); else P1 displacements. Under a tangential load the bottom is clamped;
# for the normal load alone it slides on a rigid base and $x = 0$ is a symmetry plane. The
# 3D half block holds $u_y = 0$ on $y = 0$.

# +
degree = 2 if args.mixed else 1
if args.mixed:
    W = mixed.taylor_hood(msh, degree)
    w = fem.Function(W, name="displacement_pressure")
    (u, p), (v, q) = ufl.split(w), ufl.TestFunctions(W)
    V = W.sub(0)  # the displacement part: its dofs are numbered in w
else:
    V = fem.functionspace(msh, ("Lagrange", degree, (dim,)))
    w = u = fem.Function(V, name="displacement")
    v = ufl.TestFunction(V)
parts = mixed.unknown_of(w)  # u (and p) as Functions of their own, to write out
if args.moved:
    bcs = [boundary.fixed(V, tagged("bottom"))]
else:
    bcs = [boundary.component(V, 0, tagged("symmetry_x")),
           boundary.component(V, vertical, tagged("bottom"))]
if dim == 3:
    bcs.append(boundary.component(V, 1, tagged("symmetry_y")))
# -

# ### The material and the residual
#
# Hooke's law from its free energy (`LinearElastic`): $\sigma = \partial\varphi/\partial
# \varepsilon$ by UFL, $R(u; v) = \int_\Omega \sigma(\varepsilon(u)) : \varepsilon(v)
# \,d\Omega$ with no external load (with `--mixed`, the variation of
# $\int \tilde\varphi(\varepsilon) + p\,\mathrm{tr}\,\varepsilon - p^2/(2\kappa)$, which holds
# at $\nu = 1/2$).

# +
material = LinearElastic(args.E, args.nu)
kinematic = "3d" if dim == 3 else model  # the strain model: hoop strain if axisymmetric
dx = kinematics.quadrature_measure("dx", msh, 2 * degree)
weight = kinematics.measure_weight(msh, kinematic)  # 2πr, or 1
if args.mixed:
    residual = mixed.internal_work(material, u, p, v, q, kinematic) * dx
else:
    def eps(z):
        return kinematics.small_strain(z, kinematic)

    residual = ufl.inner(material.stress(eps(u)), eps(v)) * weight * dx
# -

# ### The frictional contact on the `contact` tag
#
# `FrictionalContact` is the course's active set extended to friction: every node of $S_C$
# is open, sticking or slipping. Each iteration solves the linear problem of the statuses
# ($u_n = \gamma$ on the closed nodes; a sticking node keeps its place relative to the
# punch, a slipping one carries $f|T_n|$ against its slip) and updates them: a closed node
# in tension opens, a penetrating one closes, a sticking node whose $|T_t|$ exceeds
# $f|T_n|$ slips, a slipping one whose slip turned back sticks; until they repeat. The
# slip history is committed at each converged step. The gap is the punch's, as in
# `punch.py` (`RigidPunch`); Newton's absolute tolerance is scaled by Hertz's force for the
# expected $a$.


# +
punch = RigidPunch(R, dim, args.gap)  # its height h(r) above S_C: Hertz's r²/(2R), or the sphere
gap = punch.gap  # γ(x) = h(r) − δ for the punch pressed by δ
radius_of = punch.distance  # r, the distance of points (n × 3) from the punch's axis


E_star = hertz.effective_modulus(args.E, args.nu)
P_scale = (np.pi / 4 * E_star * a * a / R if model == "plane_strain"
           else 4 / 3 * E_star * a**3 / R)
newton = {"line_search": False, "force_scale": P_scale / symmetry}
if args.mixed:  # a symmetric saddle point: LDLᵀ
    newton["linear_solver"] = "cholesky"
contact = FrictionalContact(residual, w, bcs, tagged("contact"), gap(0.0), friction=f,
                            normal_axis=vertical, formulation=args.formulation,
                            initial="penetrating", newton_options=newton,
                            prefix=f"punch_{model}_", displacement_space=V if args.mixed else None)
cli.say(f"{model} punch, {args.formulation}, {output.dofs(w.function_space)} unknowns, "
        f"h = {h:.3g}")
# -

# ### The normal load
#
# In equal steps of the indentation $\delta$ (or of the force, each $\delta$ then found by
# secant steps on $\ln P(\ln \delta)$), each from the last statuses plus every node that
# penetrates now; the converged step is committed (the slip history). With friction the
# surface under the punch is held back from its inward slip (Spence's problem) unless
# $\nu = 1/2$. `solve_incrementally` drives the steps (`MotionPath`: the load factor
# scales $\delta$, or $P$), so that `--checkpoint` and `--restart` can save and take back
# the state after each.

# +
def fields():
    """What --output writes: u (and p), the contact pressure and statuses, σ_eq."""
    return [parts.displacement(), *([parts.pressure()] if args.mixed else []),
            *contact.fields(weight), parts.von_mises(material, kinematic)]


def report(t, result):
    """Say and keep (JSON) the state just converged."""
    s = load.states[-1]
    cli.converged_step({"load_factor": t, "indentation": s.indentation, "force": s.force,
                        "contact_radius": s.contact_radius, "max_pressure": s.max_pressure,
                        "active_set_iterations": s.active_set_iterations}, fields=fields)
    cli.say(f"step {len(load.states)}/{args.steps}: δ = {s.indentation:.5g}, P = "
            f"{s.force:.6g}, a = {s.contact_radius:.5g}, p0 = {s.max_pressure:.5g}, "
            f"{s.active_set_iterations} active-set iterations")


# the load factor t scales δ (or P: δ by secant steps on ln P(ln δ), from δ ∝ t^(2/3))
def press(delta):
    """The state of the punch pressed by δ: the active-set loop, from the last set."""
    return punch.press(contact, delta, weight=weight, symmetry=symmetry)


load = MotionPath(press, w, displacement=args.indentation, force=args.force, guess=a * a / R)
# --checkpoint: the displacement, the statuses and slip history, the states after each step
checkpoints = cli.checkpointing({"unknown": w}, newton=contact.newton, contact=contact,
                                kept=load.record)
if checkpoints.kept is not None:  # --restart: they are back
    load.take_back(checkpoints.kept, Indentation)
solve_incrementally(load, load.set_load, args.steps, adaptive=False, predictor=False,
                    on_step=report, commit=contact.commit, **checkpoints.options)
pressed = load.states[-1]
nodes = contact.surface.count(contact.active)
warnings = check_contact_resolution(nodes, h, pressed)
# -

# ### The tangential load
#
# The punch moves along $x$ by a prescribed $D$, or until the tangential force is $Q$:
# secant steps on the punch's position $d$ (`reach_load`), from the full-stick slope (a
# move of $10^{-6} a$). $Q(d)$ bends as nodes slip, so the steps approach $Q$ from below and do not
# overshoot; $Q \ge fP$ has no static equilibrium. In 3D the compliance of this mesh and
# block before any slip is measured first: the finite block adds a far-field share to the
# punch's displacement that Mindlin's half-space has not, and it is taken out below.

# +
def shift(d):
    """The pressed punch moved to x = d: the statuses' loop from the last ones."""
    contact.set_motion([d] + [0.0] * (len(contact.axes) - 1))
    res = contact.solve()
    stick = contact.stick
    return Traction(d, symmetry * contact.tangential_force()[0], symmetry * contact.force,
                    global_max(msh.comm, radius_of(contact.x[stick])),
                    contact.surface.count(stick), contact.surface.count(contact.slip),
                    res.active_set_iterations, res.iterations, res.work.factorizations)


def committed():
    """(d, Q) of the last committed state."""
    return (float(contact.committed_motion[0]),
            symmetry * float(contact.committed_tangential_force[0]))


def pull(Q):
    """The state where the tangential force is Q (`reach_load`: secant steps on d)."""
    fP = f * symmetry * contact.force
    if not (np.isfinite(Q) and 0 <= Q < fP):
        raise ValueError(f"tangential force {Q:g} must be in [0, f P) = [0, {fP:.6g}): at "
                         "f P the punch slides (no static equilibrium under force control)")
    d0, q0 = committed()
    first = d0 + (1.0 if Q >= q0 else -1.0) * 1e-6 * a  # no node slips yet: full stick
    state, _ = reach_load(shift, Q, (d0, q0), first, atol=1e-8 * fP,
                          of=lambda s: (s.tangential_displacement, s.tangential_force))
    return state


T, bonded = None, None
if args.moved:
    if not pressed.force > 0:
        raise ValueError("the punch does not touch the block: no normal force holds it "
                         "against a tangential load")
    if model == "3d":  # dd/dQ before any slip: a move of 1e-6 a (the statuses stay warm)
        d0, q0 = committed()
        s = shift(d0 + 1e-6 * a)
        bonded = (s.tangential_displacement - d0) / (s.tangential_force - q0)
    if args.tangential_displacement is not None:
        T = shift(args.tangential_displacement)
    else:
        T = pull(args.tangential_force if args.tangential_force is not None
                 else args.tangential_ratio * f * pressed.force)
    contact.commit()
    fP = f * T.normal_force  # (at ν < 1/2 Q changes P)
    cli.say(f"tangential: d = {T.tangential_displacement:.5g}, Q = {T.tangential_force:.6g} "
            f"= {T.tangential_force / fP:.4f} f P; {T.stick_nodes} nodes stick, "
            f"{T.slip_nodes} slip, stick radius {T.stick_radius:.5g}; "
            f"{T.status_iterations} status iterations")
# -

# ## Against Hertz and Cattaneo–Mindlin
#
# The normal state against Hertz as in `punch.py` (the force is not checked for the
# cylinder: Hertz gives no $P(\delta)$ for it). Then, for the computed $P$ (and Hertz's
# $a$, $p_0$ for it): the stick half-width or radius $c$ (the outermost sticking node is
# within $h$ of it); the cylinder's tangential traction away from the stick–slip edges
# $\pm c$ (where the exact one has an infinite slope), $q_j = T_{t,j}/m_j$ at the nodes of
# the section; the sphere's tangential force inside each radius, $Q(r)$, and its
# displacement $\delta_t(Q)$, less the far field's share.

# +
def hertz_of(state):
    """Hertz's values: the cylinder's for the computed P, the sphere's for δ."""
    if model == "plane_strain":
        return hertz.cylinder_from_force(args.E, args.nu, R, state.force)
    return hertz.sphere_from_indentation(args.E, args.nu, R, state.indentation)


check = hertz.compare_with_hertz(load.states, hertz_of, model, h)
for line in check.lines:
    cli.say(line)
ref = check.ref
out = indentation_record.record(load.states, pressed, check, model=model,
                                formulation=args.formulation, material="linear",
                                mixed=args.mixed, h=h, nodes=nodes)


def traction_profile():
    """(x, p, q, status) along the section y = 0 (3D) or the whole S_C, on rank 0."""
    on = np.abs(contact.x[:, 1]) <= 1e-9 * h if dim == 3 else None
    return contact.traction_profile(weight, on)


def force_within(radii):
    """Q(r): the tangential force inside each radius r, the whole body's."""
    return symmetry * contact.force_within(radius_of(contact.x), radii)


checked = {}
if T is not None and ref is not None and 0 <= T.tangential_force < fP:
    Q, three_d = T.tangential_force, model == "3d"
    H = (hertz.sphere_from_force if three_d else hertz.cylinder_from_force)(
        args.E, args.nu, R, T.normal_force)
    aH, p0 = H["contact_radius"], H["max_pressure"]
    if three_d:
        c = mindlin.sphere_stick_radius(aH, Q, fP)
        radii = np.arange(1, int(1.5 * aH / h) + 1) * h
        error = np.abs(force_within(radii)
                       - mindlin.sphere_tangential_force_within(radii, aH, p0, f, c))
        checked["tangential_force_profile_max_error"] = float(error.max() / Q)
        # δ_t against Mindlin's: the far field's compliance (the bonded one measured, less
        # the half-space's (2 − ν)/(8 G a)) does not depend on the stick zone; taken out
        G = args.E / (2 * (1 + args.nu))
        exact_bonded = (2 - args.nu) / (8 * G * aH)
        delta_t = mindlin.sphere_tangential_displacement(aH, Q, fP, G, args.nu)
        far = (bonded - exact_bonded) * Q
        local = T.tangential_displacement - far
        cli.say(f"Mindlin: δ_t = {delta_t:.5g}; FE {T.tangential_displacement:.5g}, less the "
                f"far field's {far:.3g} (bonded compliance {bonded:.4g} against the "
                f"half-space's {exact_bonded:.4g}): {100 * (local / delta_t - 1):+.2f} %")
        checked.update(tangential_displacement_exact=delta_t, bonded_compliance=bonded,
                       bonded_compliance_exact=exact_bonded,
                       tangential_displacement_local=local,
                       tangential_displacement_rel_error=local / delta_t - 1)
        said = (f"tangential force inside r within "
                f"{100 * checked['tangential_force_profile_max_error']:.2f} % of Q")
    else:
        c = mindlin.cylinder_stick_half_width(aH, Q, fP)
        x, _, q, _ = traction_profile() or (None,) * 4
        if msh.comm.rank == 0:
            away = (np.abs(np.abs(x) - c) > 2 * h) & (np.abs(x) < 1.5 * aH)
            q_exact = mindlin.traction(x, aH, p0, f, c)
            checked["tangential_traction_max_error"] = float(
                np.abs(q - q_exact)[away].max() / (f * p0))
        checked = msh.comm.bcast(checked, root=0)
        said = (f"tangential traction within "
                f"{100 * checked['tangential_traction_max_error']:.2f} % of f p0 (beyond 2 h "
                "of the stick-slip edges)")
    checked["stick_radius_exact"] = c
    cli.say(f"Cattaneo-Mindlin: stick {'radius' if three_d else 'half-width'} {c:.5g} (FE: "
            f"(c - c_exact)/h = {(T.stick_radius - c) / h:+.2f}); " + said)
if T is not None and args.nu != 0.5:
    warnings.append(f"Cattaneo-Mindlin is exact for a rigid punch on an incompressible "
                    f"body (ν = 1/2, --mixed); at ν = {args.nu:g} the normal and tangential "
                    "problems couple")
if model == "plane_strain" and ref is not None:
    warnings.append("plane strain: the force is not checked (a cylinder's indentation "
                    "depends on the block, Hertz gives no P(δ)); half-width and p0 are "
                    "checked against Hertz for the computed P")
# -

# ## Outputs
#
# The JSON (the normal state as for Hertz, the tangential one, the checks, the supports'
# reactions), and when asked the fields of the normal load's steps for ParaView, the
# curves with the traction profile against Cattaneo–Mindlin's, and the deformed contact
# zone.

# +
groups = {name: tagged(name) for name in ("contact", "bottom")
          + (() if args.moved else ("symmetry_x",)) + (("symmetry_y",) if dim == 3 else ())}
out.update(
    reactions=boundary.reactions(residual, w, groups, space=V if args.mixed else None),
    reactions_of=indentation_record.REACTIONS_OF[model][args.moved],
    dofs=output.dofs(w.function_space), ranks=msh.comm.size, warnings=warnings, friction=f)
if T is not None:
    out.update({k: getattr(T, k) for k in ("tangential_force", "tangential_displacement",
                                           "stick_radius", "stick_nodes", "slip_nodes",
                                           "status_iterations")}, **checked)
drawn = None
if args.png or args.plot:
    rings = np.linspace(0.0, 1.5, 301) * pressed.contact_radius
    drawn = indentation_pictures.PunchRun(
        model, load.states, ref, args.E, args.nu, R, rank0=msh.comm.rank == 0,
        profile=contact.surface.gathered(radius_of(contact.x), contact.pressure(weight),
                                         contact.active),
        section=(output.section(parts.displacement(), parts.von_mises(material, kinematic),
                                normal_axis=1 if dim == 3 else None) if args.png else None),
        gap_at=lambda r, d: punch.height(r) - d, h=h, tangential=args.moved,
        mixed=args.mixed, force_controlled=args.force is not None, friction=f, traction=T,
        traction_profile=(None if T is None else (rings, force_within(rings)) if dim == 3
                          else traction_profile()),
        stick_radius_exact=checked.get("stick_radius_exact"), loading_steps=len(load.states))
cli.results(out, [*([lambda: indentation_pictures.curves(drawn, args.plot)] if args.plot
                    else []),
                  *([lambda: indentation_pictures.section_picture(drawn, args.png)]
                    if args.png else [])])
# -
