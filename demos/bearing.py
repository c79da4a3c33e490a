# # A shaft in its bearing: contact between two deformable bodies by the active set
#
# A steel shaft of radius $R_1$ sits in a bronze housing whose bore is larger by a radial
# clearance $c$; the shaft is pushed down, radially, in steps. Both bodies deform, and
# where they touch is not known in advance: the course's active-set algorithm finds it, on
# a *pair* of surfaces (the shaft's, the slave; the bore, the master), and this demo
# writes its loop out. At light load the contact is Hertz's between two cylinders, one in
# the other; as the load grows the arc spreads over a good part of the circumference, where
# Hertz's half-spaces no longer describe either body: the computed arc stays narrower than
# Hertz's, its pressure higher. Then, with Coulomb friction between them, the shaft is
# turned by its hub: the torque the contact holds grows while part of the arc sticks, and
# stays at the Coulomb limit once all of it slips.
#
# ## Problem definition
#
# Each slave node $s$ is projected on the master surface (closest point, the bore's
# outward normal $n$ there, small sliding); the gap is
#
# $$ g_s(u) = \gamma_s + (u_s - u_m)\cdot n \ \ge 0, \qquad \lambda_s \ge 0, \qquad
#    g_s \lambda_s = 0, $$
#
# with $\gamma_s$ the initial gap, $u_m$ the master surface's displacement at the projection
# and $\lambda_s$ the normal force the bore exerts on node $s$. Iteration $k$ solves the
# equilibrium with $g_s = 0$ on the active nodes and no force on the others (Lagrange
# multipliers: the course's saddle point, the matrix $B$ of the gaps coupling both
# bodies); then an active node in tension ($\lambda_s < 0$) leaves the set, an inactive
# node that penetrates ($g_s < 0$) joins it, until the set repeats.
#
# Hertz for a cylinder in a hole (plane strain, force $P$ per unit length):
# $1/R = 1/R_1 - 1/R_2$, $1/E^* = (1-\nu_1^2)/E_1 + (1-\nu_2^2)/E_2$,
# $a = \sqrt{4PR/(\pi E^*)}$ and $p_0 = 2P/(\pi a)$: valid while $a \ll R_1$, that is
# at light load: with a clearance of 1 % of the radius, $R = 101 R_1$, and a modest force
# already spreads the arc over tens of degrees.
#
# ## Implementation

# +
import math
import time
from dataclasses import dataclass
from typing import ClassVar

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc
from mpi4py import MPI
from petsc4py import PETSc

from fenics_nl.contact.pair import ContactPair, FrictionalPair, PairContact
from fenics_nl.domain import boundary
from fenics_nl.domain.two_bodies import shaft_in_bearing
from fenics_nl.errors import SolveError
from fenics_nl.io import cli, output
from fenics_nl.io.cli import say
from fenics_nl.io.parameters import Parameters, number
from fenics_nl.materials import kinematics
from fenics_nl.materials.laws import LinearElastic, von_mises_of
from fenics_nl.plots import indentation as indentation_pictures
from fenics_nl.solvers.result import WorkCounts
from fenics_nl.theory import hertz

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

comm = MPI.COMM_WORLD
# -

# ### Parameters
#
# From the command line (`python demos/bearing.py --help`); in a notebook, the defaults
# (N, mm, MPa).

# +
@dataclass
class Bearing(Parameters):
    """A shaft pushed radially into its bearing (plane strain, two elastic bodies, a
    radial clearance): the contact arc and the pressure around it against Hertz for a
    cylinder in a hole, and their departure from it as the load grows. Units are the
    user's, consistent (e.g. N, mm, MPa)."""

    OUTPUTS: ClassVar = {"png": "von Mises stress in the shaft and the housing, the contact "
                                "arc drawn",
                         "plot": "the contact half-width and peak pressure against the "
                                 "force, and the pressure around the arc, with Hertz's"}

    radius: float = number(10.0, "the shaft's radius R1", unit="length", above=0)
    clearance: float = number(0.1, "the radial clearance c = R2 - R1", unit="length",
                              above=0)
    outer_radius: float = number(20.0, "the housing's outer radius (held)", unit="length",
                                 above=0)
    E_shaft: float = number(210e3, "the shaft's Young's modulus", unit="stress", above=0)
    nu_shaft: float = number(0.3, "the shaft's Poisson's ratio", unit="-")
    E_housing: float = number(110e3, "the housing's Young's modulus (bronze)", unit="stress",
                              above=0)
    nu_housing: float = number(0.34, "the housing's Poisson's ratio", unit="-")
    push: float = number(0.05, "how far the shaft's hub is pushed beyond the clearance at "
                         "the last step", unit="length", above=0)
    steps: int = number(6, "load steps, the push growing geometrically from push/100",
                        at_least=2)
    size: float = number(0.025, "element size along the shaft's surface and the bore within "
                         "60° of their lowest points", unit="length", above=0)
    friction: float = number(0.2, "Coulomb's coefficient between shaft and bore, for the "
                             "torque (0: no torque part)", unit="-", at_least=0)
    turn: float = number(0.01, "the hub's last rotation, in radians, under the last push",
                         unit="rad", above=0)
    turn_steps: int = number(5, "steps of the rotation", at_least=1)

    def check(self):
        if not self.outer_radius > self.radius + self.clearance:
            raise ValueError("--outer-radius must exceed --radius + --clearance")


args = cli.arguments(Bearing, prefixes={})
R1, c = args.radius, args.clearance
# -

# ### The mesh and its tags
#
# The half $x \ge 0$ of both bodies (the load is along the symmetry line), from gmsh
# (`shaft_in_bearing`): cell tags `shaft` and `housing`, facet tags `shaft_surface` (the
# slave), `bore` (the master), `hub`, `housing_outer`, and the symmetry lines; triangles
# of `--size` along both surfaces within 60° of their lowest points, where the arc grows.

# +
mesh_data = shaft_in_bearing(comm, R1, c, args.outer_radius, args.size)
msh = mesh_data.mesh


def tagged(name, data=mesh_data):
    """The facets of the physical group `name` (of the half model, or of `data`)."""
    return data.facet_tags.find(data.physical_groups[name].tag)


# -

# ### The function space and the boundary conditions
#
# P1 displacements on both bodies (one space: they share no node). The symmetry lines hold
# $u_x = 0$; the housing's outer surface is held; the shaft is driven by its hub (a rigid
# core of radius $R_1/5$), pushed down by $c + \delta$ (`push`, a Dirichlet value).

# +
V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
u, v = fem.Function(V, name="displacement"), ufl.TestFunction(V)
push = boundary.component(V, 1, tagged("hub"))  # its value: the hub's motion
bcs = [push, boundary.component(V, 0, tagged("hub")),
       boundary.component(V, 0, np.concatenate([tagged("shaft_symmetry"),
                                                tagged("housing_symmetry")])),
       boundary.component(V, 0, tagged("housing_outer")),
       boundary.component(V, 1, tagged("housing_outer"))]
# -

# ### The materials and the residual
#
# Hooke's law in each cell group, $R(u; v) = \sum_g \int_{\Omega_g} \sigma_g(\varepsilon(u))
# : \varepsilon(v)\,dx$: a steel shaft, a bronze housing.

# +
dx = ufl.Measure("dx", msh, subdomain_data=mesh_data.cell_tags)
shaft_tag, housing_tag = (mesh_data.physical_groups[n].tag for n in ("shaft", "housing"))
materials = {shaft_tag: LinearElastic(args.E_shaft, args.nu_shaft),
             housing_tag: LinearElastic(args.E_housing, args.nu_housing)}
eps, eps_v = (kinematics.small_strain(w, "plane_strain") for w in (u, v))
residual = sum(ufl.inner(law.stress(eps), eps_v) * dx(group)
               for group, law in materials.items())
# -

# ### The contact pair
#
# `ContactPair` projects each node of the shaft's surface on the bore's segments (closest
# point and outward normal, once: small sliding) and keeps the gap $g = \gamma + B u$;
# `PairContact.equilibrium(active)` solves the saddle point
# $[K\ -B_A^T;\ -B_A\ 0]$ for a set, its multipliers the forces $\lambda_s$. Hooke's law
# is linear (`linear=True`): $K$ is factorized once for the run and the saddle point solved
# by its Schur complement on the active rows, $S_{AA} = B_A K^{-1} B_A^T$, a dense system of
# the nodes in contact; $K^{-1} b_j$ is solved once per node, the first time it is active
# (`contact.condensed`). An active-set iteration is then a small dense solve and, in the
# loop written out below (it reads the gaps at u), one back-substitution to move u;
# `PairContact.solve` reads them off $S$ instead and moves u once a step.

pair = ContactPair(V, tagged("shaft_surface"), tagged("bore"))
contact = PairContact(residual, u, bcs, pair, force_scale=args.E_housing * c, linear=True)
say(f"shaft R1 = {R1:g} in a bore of R2 = {R1 + c:g}: {output.dofs(V)} unknowns, "
    f"{pair.size} slave nodes")


# ### The active-set loop, written out
#
# From the last step's set (none at first): solve, then the two rules, until the set
# repeats. Every rank takes the same decision (the counts are summed over ranks).

def active_set_loop(active):
    """The course's loop from `active`: the set it settles on, its count, Newton's."""
    newton = 0
    for k in range(1, 51):
        newton += contact.equilibrium(active, work)
        g = pair.gaps(u)
        leave = active & (contact.lam < 0)  # in tension
        join = ~active & (g < -1e-12 * R1)  # penetrating (beyond round-off)
        if comm.allreduce(int(leave.sum() + join.sum())) == 0:
            return active, k, newton
        active = (active & ~leave) | join
    raise SolveError("the active set did not settle in 50 iterations")


# ### Load steps
#
# The push grows geometrically from a hundredth of `--push` beyond the clearance to it;
# each step starts from the last step's set and displacement. The force per unit length
# of the whole shaft is twice the half's contact force (the sum of the $\lambda_s n_y$).

# +
work, history, active = WorkCounts(), [], np.zeros(len(pair.slave), dtype=bool)
Es = hertz.pair_modulus(args.E_shaft, args.nu_shaft, args.E_housing, args.nu_housing)
R = hertz.relative_radius(R1, -(R1 + c))  # the hole: a negative radius
t0 = time.perf_counter()
for delta in args.push * np.geomspace(1e-2, 1.0, args.steps):
    push.g.x.array[:] = -(c + delta)
    active, iterations, newton = active_set_loop(active)
    P = 2 * contact.force()[1]
    x, p = contact.profile()  # the nodes in contact, gathered: x, pressure
    if len(p) == 0:
        raise SolveError(f"no contact with the shaft's hub pushed by c + {delta:.3g}: "
                         "the bodies' own compliance takes it (a larger --push)")
    s = R1 * np.arctan2(np.abs(x[:, 0]), -x[:, 1])  # arc length from the lowest point
    inner = s < 0.85 * s.max()
    p0, a = (hertz.fitted_ellipse(s[inner], p[inner]) if inner.sum() >= 3
             else (p.max(), s.max()))
    ref = hertz.cylinder_from_force(Es, 0.0, R, P)
    history.append({"push": c + delta, "force": P, "iterations": iterations,
                    "arc_degrees": math.degrees(s.max() / R1), "contact_radius": a,
                    "max_pressure": p0, "contact_radius_hertz": ref["contact_radius"],
                    "max_pressure_hertz": ref["max_pressure"], "nodes": len(s),
                    "profile": {"s": s.tolist(), "pressure": p.tolist()}})
    cli.converged_step({"load_factor": delta / args.push, "force": P,
                        "active_set_iterations": iterations, "newton_iterations": newton})
    say(f"  push c + {delta:.4g}: P = {P:.5g} per unit length, arc "
        f"±{history[-1]['arc_degrees']:.2f}°, a = {a:.4g} (Hertz {ref['contact_radius']:.4g}), "
        f"p0 = {p0:.5g} (Hertz {ref['max_pressure']:.5g}), {iterations} active-set "
        "iterations")
solve_time = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
# -

# ### Against Hertz
#
# The lightest step against Hertz for its force (a and $p_0$ fitted to the computed
# pressures: $p^2 = p_0^2(1 - s^2/a^2)$ over the nodes in contact within 85 % of the
# outermost's arc length), and
# how far the heaviest has left it. The nodal pressures jump where the two surfaces'
# nodes come in and out of line: with the same element size h on both, the bore's nodes
# drift against the shaft's by a node spacing every $R_2/c \approx 100$ nodes (every ~2.2
# of arc here), and single nodes there are off by up to 50 to 90 % at the heavier loads
# (node-to-segment contact does not pass the patch test; a mortar method, integrating the
# gap over the segments, would smooth it). The light loads' arcs are shorter than that
# and their fits clean; the heavy loads' fits go through the jumps. The largest
# $\sigma_{eq}$ of the picture is at the hub, where the load enters the shaft; around the
# arc both bodies carry the contact stresses.

# +
light, heavy = history[0], history[-1]
errors = {k: light[k] / light[f"{k}_hertz"] - 1 for k in ("contact_radius", "max_pressure")}
say(f"lightest step: a {100 * errors['contact_radius']:+.2f} %, p0 "
    f"{100 * errors['max_pressure']:+.2f} % from Hertz ({light['nodes']} nodes in contact, "
    f"h = {args.size:g}); heaviest: a/a_Hertz = "
    f"{heavy['contact_radius'] / heavy['contact_radius_hertz']:.3f}, p0/p0_Hertz = "
    f"{heavy['max_pressure'] / heavy['max_pressure_hertz']:.3f} at an arc of "
    f"±{heavy['arc_degrees']:.1f}°")
# -

# ## Turning the shaft: the friction torque
#
# With Coulomb friction $f$ between the bodies (`--friction`), a torque on the shaft is
# held by the contact until every node in contact slips. A turn is not symmetric about the
# load's line: the whole shaft and housing now, with elements twice as large along the
# arcs (the torque, a sum over the arc, needs less: its limit moves by 0.06 % from the
# `--size` mesh's), pushed by the last push at once, then the hub turned by small angles
# $\theta$ ($u = \theta\, e_z \times x$ plus the push on the hub). Small sliding: each
# slave node keeps the master segment it was projected on at the start; the shaft slides
# by $R_1\theta$ = 0.1 at the last turn, 2 elements, so its forces reach the bore's nodes
# up to 0.1 from where they act, 1.4 % of the arc (what the torque, a sum over the arc,
# hardly feels). A node in contact is stuck (no relative
# tangential displacement since the last step, $|\lambda_t| \le f \lambda_n$) or slipping
# ($\lambda_t = f \lambda_n$ against its slip): the course's statuses on the pair
# (`FrictionalPair`, on one factorization as above, the stuck nodes' slips rows of their
# own). The torque of the bore on the shaft, $T = \sum_s x_s \times (\lambda_n n +
# \lambda_t t)$, grows with $\theta$ while a stick zone remains, then stays at the Coulomb
# limit $T = f R_1 \sum_s \lambda_{n,s}$: more than $f R_1 P$, since around a conforming
# arc the normal forces add up to more than their resultant $P$ (the arc's "friction
# factor" $\sum \lambda_n / P$; $4/\pi$ for a cosine pressure over a half circle).

# +
torque = None
if args.friction > 0:
    whole = shaft_in_bearing(comm, R1, c, args.outer_radius, 2 * args.size, full=True)

    W = fem.functionspace(whole.mesh, ("Lagrange", 1, (2,)))
    w, w_v = fem.Function(W, name="displacement"), ufl.TestFunction(W)
    hub = [boundary.component(W, k, tagged("hub", whole)) for k in (0, 1)]
    hub_x = hub[0].g.function_space.tabulate_dof_coordinates()  # the hub's rigid motion
    bcs_whole = [*hub, *(boundary.component(W, k, tagged("housing_outer", whole)) for k in (0, 1))]
    dxw = ufl.Measure("dx", whole.mesh, subdomain_data=whole.cell_tags)
    e, e_v = (kinematics.small_strain(x, "plane_strain") for x in (w, w_v))
    residual_whole = sum(ufl.inner(law.stress(e), e_v) * dxw(whole.physical_groups[name].tag)
                         for name, law in (("shaft", materials[shaft_tag]),
                                           ("housing", materials[housing_tag])))
    ring = ContactPair(W, tagged("shaft_surface", whole), tagged("bore", whole))
    turning = FrictionalPair(residual_whole, w, bcs_whole, ring, args.friction,
                             force_scale=args.E_housing * c, linear=True)

    def move_hub(drop, theta):
        """The hub pushed down by `drop` and turned by `theta` (counter-clockwise)."""
        hub[0].g.x.array[:] = -theta * hub_x[:, 1]
        hub[1].g.x.array[:] = -drop + theta * hub_x[:, 0]

    def resisting_torque():
        """−Σ x × (λ_n n + λ_t t): the bore's torque against the turn (every rank's)."""
        F = turning.nodal_forces()
        return -ring.total(ring.x[:, 0] * F[:, 1] - ring.x[:, 1] * F[:, 0])

    internal = fem.form(residual_whole)
    hub_nodes = fem.locate_dofs_topological(W, 1, tagged("hub", whole))
    hub_nodes = hub_nodes[hub_nodes < W.dofmap.index_map.size_local]

    def hub_torque():
        """Σ x × R at the hub's nodes: the torque the hub turns the shaft with, from its
        reaction (R the internal forces; the check of the contact's torque by the
        shaft's equilibrium, independent of λ and of the normals)."""
        R = petsc.assemble_vector(internal)
        R.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
        r, x = R.array.reshape(-1, 2)[hub_nodes], W.tabulate_dof_coordinates()[hub_nodes]
        return comm.allreduce(float(np.sum(x[:, 0] * r[:, 1] - x[:, 1] * r[:, 0])))

    torque = {"rotation": [], "torque": [], "hub": [], "limit": [], "slipping": [],
              "in_contact": []}
    move_hub(c + args.push, 0.0)  # the last push at once: each node lands and sticks
    turning.solve()             # where it lands, which the loading path hardly changes
    turning.commit()
    for theta in np.linspace(0.0, args.turn, args.turn_steps + 1)[1:]:
        move_hub(c + args.push, theta)
        result = turning.solve()
        turning.commit()
        closed = turning.active
        torque["rotation"].append(theta)
        torque["torque"].append(resisting_torque())
        torque["hub"].append(hub_torque())
        torque["limit"].append(args.friction * R1 * ring.total(turning.lam[closed]))
        torque["slipping"].append(comm.allreduce(int((closed & turning.slip).sum())))
        torque["in_contact"].append(comm.allreduce(int(closed.sum())))
        say(f"  turned by {theta:.4g} rad: T = {torque['torque'][-1]:.5g}, "
            f"f R1 Σλ_n = {torque['limit'][-1]:.5g}, {torque['slipping'][-1]} of "
            f"{torque['in_contact'][-1]} nodes slipping, {result.active_set_iterations} "
            "status iterations")
    torque["friction_factor"] = torque["limit"][-1] / (args.friction * R1
                                                       * turning.force()[1])
    torque["saturation"] = torque["torque"][-1] / torque["limit"][-1]
    say(f"the friction torque saturates at {torque['saturation']:.6f} of f R1 Σλ_n (the "
        f"chords' normals are not quite radial); the arc's friction factor Σλ_n/P = "
        f"{torque['friction_factor']:.4f}")
# -

# ## Outputs


def summary():
    """The quantities of the run, for --json."""
    out = {"radius": R1, "clearance": c, "relative_radius": R, "modulus": Es,
           "steps": history, "contact_radius_error": errors["contact_radius"],
           "max_pressure_error": errors["max_pressure"], "force": heavy["force"],
           "active_set_iterations": sum(h["iterations"] for h in history),
           "factorizations": work.factorizations, "linear_solves": work.linear_solves,
           "update_columns": work.update_columns, "dofs": output.dofs(V), "ranks": comm.size,
           "solve_time_s": solve_time, "torque": torque, "warnings": []}
    if light["nodes"] < 10:
        out["warnings"].append(f"{light['nodes']} nodes in contact at the lightest step: "
                               "a and p0 are coarse there (refine --size)")
    return out


def plot():
    """a and p0 against P, the pressure around the arc, with Hertz's; the torque."""
    indentation_pictures.pair_curves(
        history, f"a shaft (R1 = {R1:g}) in a bore with a clearance of {c:g}: Hertz at "
        f"light load (a {100 * errors['contact_radius']:+.1f} %, p0 "
        f"{100 * errors['max_pressure']:+.1f} %), then departing from it", args.plot,
        torque=torque)


def picture():
    """σ_eq in both bodies, on the deformed halves, the contact arc drawn on them."""
    from fenics_nl.plots.deformed import deformed_picture

    Q = fem.functionspace(msh, ("DG", 0))
    vm = fem.Function(Q, name="von_mises")
    for group, law in materials.items():  # each body's law in its cells
        vm.interpolate(fem.Expression(von_mises_of(law.stress(eps)),
                                      Q.element.interpolation_points),
                       cells0=mesh_data.cell_tags.find(group))
    x_contact, _ = contact.profile()  # every rank's, drawn where the deformation takes them
    arc = x_contact[np.argsort(np.arctan2(x_contact[:, 0], -x_contact[:, 1]))]
    deformed_picture(u, vm, args.png, f"P = {heavy['force']:.4g} per unit length, arc "
                     f"±{heavy['arc_degrees']:.1f}°", curves={"the contact arc": arc},
                     label="von Mises stress [stress]", axes=("x (length)", "y (length)"),
                     true_scale=True)  # magnified, the shaft would pass into the bore
    say(f"wrote {args.png}")


cli.results(summary(), [*([plot] if args.plot else []), *([picture] if args.png else [])])
