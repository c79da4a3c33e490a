# # A circular excavation behind a diaphragm wall, dug in lifts in a Mohr–Coulomb ground
#
# The course's example of plasticity at the scale of a structure (the LCPC's excavation in
# Nantes, 2003): a cylindrical concrete wall is built in a ground at rest, then the soil
# inside it is dug out in lifts. The ground is Mohr–Coulomb (`MohrCoulomb`: cohesion $c$,
# friction angle $\varphi$, dilatancy angle $\psi$), under its geostatic stress
#
# $$ \sigma_v = -\gamma\,(0 - z), \qquad \sigma_h = K_0\,\sigma_v $$
#
# (tension positive, $z$ up, the surface at $z = 0$), in equilibrium with its weight before
# anything is done. Axisymmetric: the section $(r, z)$ turns about the axis $r = 0$.
#
# ## Problem definition
#
# Each **stage** changes the parts present: the wall's cells are soil at first; the stage
# "wall" removes that soil and puts the concrete in its place, stress-free; each "lift"
# removes a layer of the soil inside the wall. A removed part's stress and weight acted on
# what remains: at the stage's start they are frozen and applied as loads, so that the start
# is in equilibrium, then released as the stage's progress $s$ goes from 0 to 1
# (`fenics_nl.construction`):
#
# $$ R(u; v) = \sum_p \int \chi_p\,\sigma_p : \varepsilon(v) - \sum_p \int \chi_p
#    (1 - \alpha (1 - s))\,\gamma_p\, b \cdot v + (1 - s) \int \lambda\,(\sigma_{left} :
#    \varepsilon(v) - \gamma_{left}\,b \cdot v), $$
#
# $\chi_p$ the part's presence, $\alpha$ the cells arriving and $\lambda$ those leaving in
# this stage, $b = (0, -1)$ (all times $2\pi r$). The run checks that each stage starts in
# equilibrium ($R = 0$ at $s = 0$: what is frozen balances what left) and that at its end
# the supports carry the weight of what is present, to round-off (Kratos' check of its
# staged excavation).
#
# ## Implementation

# +
import math
import time
from dataclasses import dataclass
from typing import ClassVar

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import gmsh
import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.construction import Construction
from fenics_nl.domain import boundary, meshes
from fenics_nl.domain.probes import Probes
from fenics_nl.errors import SolveError
from fenics_nl.expression import Expression
from fenics_nl.io import cli, output
from fenics_nl.io.cli import say
from fenics_nl.io.parameters import Parameters, number
from fenics_nl.materials import LinearElastic, kinematics
from fenics_nl.materials.mohr_coulomb import MohrCoulomb
from fenics_nl.plots import plasticity as plasticity_pictures
from fenics_nl.solvers.loading import LoadStepError, solve_incrementally
from fenics_nl.solvers.newton import NewtonSolver

cli.run_script(__name__)  # as a script: this file runs under the demo contract, then exits

comm = MPI.COMM_WORLD
# -

# ### Parameters
#
# From the command line (`python demos/excavation.py --help`); in a notebook, the defaults.
# Units: m, kN, kPa.

# +
@dataclass
class Excavation(Parameters):
    """A circular excavation dug in lifts behind a diaphragm wall, in a Mohr–Coulomb ground
    under its geostatic stress (axisymmetric). Units: m, kN, kPa."""

    EPILOG = "PETSc options take the prefix -excavation_ (Newton's KSP)."
    OUTPUTS: ClassVar = {
        "plot": "the vertical displacement, σ_eq in the soil and the plastic strain on the "
                "section; the wall's deflection and bending moment and the surface "
                "settlement after each stage"}

    radius: float = number(10.0, "the excavation's radius (the wall's inner face)", unit="m",
                           above=0)
    wall_thickness: float = number(0.6, "the wall's thickness", unit="m", above=0)
    wall_depth: float = number(16.0, "the wall's depth below the surface", unit="m", above=0)
    lifts: int = number(3, "the lifts the soil inside is dug in", at_least=1)
    lift_depth: float = number(3.0, "each lift's depth", unit="m", above=0)
    E: float = number(30e3, "the soil's Young's modulus", unit="kPa", above=0)
    nu: float = number(0.3, "the soil's Poisson's ratio", unit="-", above=-1, at_most=0.49)
    c: float = number(5.0, "the soil's cohesion", unit="kPa", above=0)
    phi: float = number(30.0, "the soil's friction angle", unit="degrees", above=0,
                        at_most=60)
    psi: float = number(30.0, "the soil's dilatancy angle (φ: associated flow)",
                        unit="degrees", at_least=0)
    unit_weight: float = number(18.0, "the soil's unit weight", unit="kN/m³", above=0)
    K0: float | None = number(None, "the ground's horizontal/vertical stress ratio at rest "
                              "(default 1 − sin φ, Jáky)", above=0)
    wall_E: float = number(30e6, "the wall's Young's modulus (concrete)", unit="kPa", above=0)
    wall_nu: float = number(0.2, "the wall's Poisson's ratio", unit="-", above=-1, at_most=0.49)
    wall_unit_weight: float = number(24.0, "the wall's unit weight", unit="kN/m³", at_least=0)
    steps: int = number(4, "the load steps of each stage (its progress s from 0 to 1)",
                        at_least=1)
    size: float = number(0.75, "the element size along the wall and the dug soil", unit="m",
                         above=0)

    def check(self):
        if self.psi > self.phi:
            raise ValueError(f"--psi must be at most --phi = {self.phi:g}, got {self.psi:g}")
        if self.lifts * self.lift_depth >= self.wall_depth:
            raise ValueError(f"the lifts dig {self.lifts * self.lift_depth:g} m, as deep as "
                             f"the wall ({self.wall_depth:g} m): dig less or deepen the wall")
        if self.K0 is None:
            self.K0 = 1 - math.sin(math.radians(self.phi))


args = cli.arguments(Excavation, prefixes={"excavation_": "Newton's KSP"})
R, t_w, H_w = args.radius, args.wall_thickness, args.wall_depth
width, depth = 5 * R, 2.5 * H_w  # the ground kept: far enough not to hold what happens
# -

# ### The mesh and its tags
#
# gmsh's rectangles, fragmented so that each part is its own cell group: the `wall`
# ($R < r < R + t$, $-H_w < z < 0$), the lifts `lift_1`, ... (each $r < R$), the rest of the
# `ground`; the lines `axis` ($r = 0$), `far` ($r = 5R$) and `bottom` ($z = -2.5 H_w$).
# Triangles of `--size` along the wall and the dug soil, growing to 8 times that away;
# two through the wall's thickness.

# +
def build_section():
    """The (r, z) section meshed on rank 0 (P2 triangles), distributed with its tags."""
    meshes.start_model("excavation")
    if comm.rank == 0:
        occ = gmsh.model.occ
        ground = occ.addRectangle(0, -depth, 0, width, depth)
        wall = occ.addRectangle(R, -H_w, 0, t_w, H_w)
        lifts = [occ.addRectangle(0, -(k + 1) * args.lift_depth, 0, R, args.lift_depth)
                 for k in range(args.lifts)]
        occ.fragment([(2, ground)], [(2, wall)] + [(2, lift) for lift in lifts])
        occ.synchronize()
        lifts_named = [f"lift_{k + 1}" for k in range(args.lifts)]
        groups = {"wall": [], "ground": [], **{name: [] for name in lifts_named}}
        for _, s in gmsh.model.getEntities(2):
            r, z, _ = occ.getCenterOfMass(2, s)
            if R < r < R + t_w and z > -H_w:
                groups["wall"].append(s)
            elif r < R and z > -args.lifts * args.lift_depth:
                groups[f"lift_{int(-z // args.lift_depth) + 1}"].append(s)
            else:
                groups["ground"].append(s)
        for name, tags in groups.items():
            gmsh.model.addPhysicalGroup(2, tags, name=name)
        for name, box in (("axis", (-1, -depth - 1, -1, 1e-6, 1, 1)),
                          ("far", (width - 1e-6, -depth - 1, -1, width + 1, 1, 1)),
                          ("bottom", (-1, -depth - 1e-6, -1, width + 1, -depth + 1e-6, 1))):
            curves = [c for _, c in gmsh.model.getEntitiesInBoundingBox(*box, 1)]
            gmsh.model.addPhysicalGroup(1, curves, name=name)
        def edges(names):
            return [c for n in names for s in groups[n]
                    for _, c in gmsh.model.getBoundary([(2, s)], oriented=False)]

        # the wall bends: two elements through its thickness
        field = gmsh.model.mesh.field
        finest = field.add("Min")
        field.setNumbers(finest, "FieldsList", [
            meshes.threshold_field(args.size, 0.0, 8 * args.size, 4 * H_w,
                                   curves=edges(["wall", *lifts_named])),
            meshes.threshold_field(t_w / 2, 0.0, 8 * args.size, 8 * args.size,
                                   curves=edges(["wall"]))])
        meshes.size_by_field(finest)
        gmsh.option.setNumber("Mesh.ElementOrder", 2)
        gmsh.model.mesh.generate(2)
    return meshes.distributed(comm, 1.0)


mesh_data = build_section()
msh = mesh_data.mesh
group = {name: g.tag for name, g in mesh_data.physical_groups.items()}
lifts = [group[f"lift_{k + 1}"] for k in range(args.lifts)]


def tagged(name):
    """The facets of the physical group `name`."""
    return mesh_data.facet_tags.find(group[name])


# -

# ### The function space and the supports
#
# P2 displacements $(u_r, u_z)$. The axis and the far side hold $u_r = 0$, the bottom holds
# both components.

# +
V = fem.functionspace(msh, ("Lagrange", 2, (2,)))
u, v = fem.Function(V, name="displacement"), ufl.TestFunction(V)
supports = [boundary.component(V, 0, tagged("axis")), boundary.component(V, 0, tagged("far")),
            boundary.component(V, 0, tagged("bottom")),
            boundary.component(V, 1, tagged("bottom"))]
# -

# ### The materials, the parts and the residual
#
# The soil everywhere at first (the wall's cells too), with its geostatic stress; the wall's
# concrete (Hooke's law) absent until its stage, its strain then measured from the state it
# arrives in (`arrival_strain`). The residual is the one above, written with the parts'
# fields (`Construction`) and the axisymmetric weight $2\pi r$.

# +
soil = MohrCoulomb(args.E, args.nu, c=args.c, phi=args.phi, psi=args.psi, initial_stress={
    "unit_weight": args.unit_weight, "K0": args.K0, "surface": 0.0})
wall = LinearElastic(args.wall_E, args.wall_nu)
soil.bind(msh, 4)  # its state at the quadrature points of dx (degree 4: P2's 2 × 2)
parts = Construction(V, mesh_data.cell_tags,
                     {"soil": [group["ground"], group["wall"], *lifts], "wall": [group["wall"]]},
                     weights={"soil": args.unit_weight, "wall": args.wall_unit_weight},
                     absent={"wall": [group["wall"]]}, degree=4)
model = "axisymmetric"
dx = kinematics.quadrature_measure("dx", msh, 4)
weight = kinematics.measure_weight(msh, model)  # 2πr
eps, eps_v = (kinematics.small_strain(w, model) for w in (u, v))
down = ufl.as_vector([0.0, -1.0])
sigma = {"soil": soil.stress(eps), "wall": wall.stress(eps - parts.arrival_strain)}
residual = (sum(parts.present[p] * ufl.inner(sigma[p], eps_v) for p in sigma)
            - sum(ufl.dot(parts.body_force(p, down), v) for p in sigma)
            + parts.released(v, down, eps_v)) * weight * dx
# -

# ### The solver
#
# Full Newton: UFL's derivative of the residual through Mohr–Coulomb's return map (its
# planes, edges and apex, in closed form) is the consistent tangent (not symmetric when
# $\psi < \varphi$: LU). The absolute tolerance is relative to the weight of the ground.

# +
ground_weight = args.unit_weight * math.pi * width ** 2 * depth
solver = NewtonSolver(residual, u, supports, rtol=1e-10, atol=1e-10, force_scale=ground_weight,
                      max_it=40, prefix="excavation_")
# the ground at rest: R(0) = 0 (the supports' rows, their reactions, left out)
at_rest = boundary.out_of_balance(residual, supports) / ground_weight
dofs = output.dofs(V)
say(f"excavation R = {R:g} m, wall {t_w:g} x {H_w:g} m, {args.lifts} lifts of "
    f"{args.lift_depth:g} m; {dofs} unknowns; the ground at rest: |R(0)| = {at_rest:.1e} "
    "of its weight")
# -

# ### What is measured after each stage
#
# The supports' vertical reaction against the weight present; the wall's deflection
# $u_r$ on its axis and its bending moment $M = \int (r - r_m)\,\sigma_{zz}\,dr$ across its
# thickness (per unit length of its circumference; 3 Gauss points), at 40 depths; the
# surface's settlement $u_z$ outside the wall; the plastic zone of the soil present. (The
# floor heaves and the surface outside rises with it: the ground's elastic rebound as the
# dug weight leaves. One Young's modulus for the whole depth overstates it; a stiffness
# growing with depth, or a stiffer response to unloading, would keep the surface down.)

# +
depths = np.linspace(-0.98 * H_w, -0.02 * H_w, 40)
r_m, gauss = R + t_w / 2, np.polynomial.legendre.leggauss(3)
across = Probes(msh, [[r_m + 0.5 * t_w * g, z] for z in depths for g in gauss[0]])
axis_line = Probes(msh, [[r_m, z] for z in depths])
surface_r = np.linspace(R + t_w + 0.01, width - 0.01, 60)
surface = Probes(msh, [[r, 0.0] for r in surface_r])
floor = Probes(msh, [[0.0, -args.lifts * args.lift_depth]])
present_weight = fem.form(sum(parts.weights[p] * parts.present[p] for p in sigma) * weight * dx)
in_soil = fem.form(parts.present["soil"] * weight * dx)
yielded = fem.form(parts.present["soil"] * ufl.conditional(
    ufl.gt(soil.cumulated_plastic_strain, 0.0), 1.0, 0.0) * weight * dx)


def measured(name, path):
    """What a stage ends with (collective)."""
    reaction = boundary.reactions(residual, u, {"bottom": tagged("bottom")})["bottom"][1]
    present = comm.allreduce(fem.assemble_scalar(present_weight))
    # (DG2's Legendre points are the degree-4 quadrature's: the arrival strain, a
    # quadrature function, is read where it is)
    s_zz = np.array(across.discontinuous("s_zz", sigma["wall"][1, 1], 2)).reshape(-1, 3)
    moment = (s_zz * (0.5 * t_w * gauss[0]) * (0.5 * t_w * gauss[1])).sum(axis=1)
    deflection = np.array(axis_line.continuous(u))[:, 0]
    settlement = np.array(surface.continuous(u))[:, 1]
    p_in_soil = soil.cumulated_plastic_strain_per_cell()  # (the soil present only: the
    p_in_soil.x.array[:] *= parts.present["soil"].x.array  # dug cells keep theirs)
    n = msh.topology.index_map(msh.topology.dim).size_local
    return {"stage": name, "steps": len(path.results), "newton_iterations": path.iterations,
            "step_cuts": path.failures, "reaction": reaction, "weight_present": present,
            "reaction_error": reaction / present - 1,
            "wall_deflection": deflection.tolist(), "wall_moment": moment.tolist(),
            "surface_settlement": settlement.tolist(),
            "max_wall_deflection": float(np.abs(deflection).max()),
            "max_wall_moment": float(np.abs(moment).max()),
            "max_settlement": float(max(-settlement.min(), 0.0)),
            "max_surface_rise": float(max(settlement.max(), 0.0)),
            "floor_heave": floor.continuous(u)[0][1],
            "max_cumulated_plastic_strain": comm.allreduce(float(
                p_in_soil.x.array[:n].max(initial=0.0)), op=MPI.MAX),
            "plastic_volume_fraction": comm.allreduce(fem.assemble_scalar(yielded))
            / comm.allreduce(fem.assemble_scalar(in_soil))}


# -

# ### The stages
#
# Each stage begins where the last one ended (`parts.begin`: what leaves is frozen, what
# arrives is stress-free), the dofs no present cell touches are held where they are, and
# the progress $s$ goes from 0 to 1 in `--steps` load steps (cut in half if one fails);
# the soil's plastic state is committed when a step converges.

# +
stages = [("wall", {"soil": [group["wall"]]}, {"wall": [group["wall"]]})] + [
    (f"lift {k + 1}", {"soil": [tag]}, {}) for k, tag in enumerate(lifts)]
cli.known(dofs=dofs, ranks=comm.size, at_rest_residual=at_rest)
records, t0 = [], time.perf_counter()
for name, remove, add in stages:
    parts.begin(name, remove=remove, add=add, stresses=sigma, strain=eps)
    solver.set_bcs(supports + parts.held(u))
    # 0: the frozen forces hold what left
    at_start = boundary.out_of_balance(residual, solver.bcs) / ground_weight
    if at_start > 1e-10:
        raise SolveError(f"stage {name!r} does not start in equilibrium: |R| = "
                         f"{at_start:.2e} of the ground's weight")

    def progress(s):
        parts.progress.value = s

    try:
        path = solve_incrementally(  # each converged step in the JSON, kept if one fails
            solver, progress, args.steps, max_step=1.0 / args.steps,
            commit=lambda: soil.commit(u, model),
            on_step=lambda s, result, stage=name: cli.converged_step(
                {"stage": stage, "stage_progress": s, "newton_iterations": result.iterations}))
    except LoadStepError as err:
        raise SolveError(f"stage {name!r} failed at s = {float(parts.progress.value):.3g} "
                         f"(the ground cannot stand the dig, or refine --steps): {err}") from err
    parts.end()
    records.append(measured(name, path) | {"start_residual": at_start})
    r = records[-1]
    say(f"{name}: {r['newton_iterations']} Newton iterations in {r['steps']} steps; the wall "
        f"deflects {1e3 * r['max_wall_deflection']:.3g} mm, the surface settles "
        f"{1e3 * r['max_settlement']:.3g} mm and rises {1e3 * r['max_surface_rise']:.3g} mm, "
        f"the floor heaves {1e3 * r['floor_heave']:.3g} "
        f"mm; reaction / weight present − 1 = {r['reaction_error']:.1e}")
solve_time = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
worst = max(abs(r["reaction_error"]) for r in records)
if worst > 1e-9:  # the weight present is on the supports, or a load was lost
    raise SolveError(f"a stage ends with its reaction {worst:.2e} off the weight present")
# -

# ## Outputs


def summary():
    """The quantities of the run, for --json."""
    return {"stages": records, "depths": depths.tolist(), "surface_r": surface_r.tolist(),
            "at_rest_residual": at_rest, "max_reaction_error": worst,
            "newton_iterations": sum(r["newton_iterations"] for r in records),
            "dofs": dofs, "ranks": comm.size, "solve_time_s": solve_time,
            "warnings": ["no closed form for this scene: what is checked is each stage's "
                         "start in equilibrium and its end's reactions against the weight "
                         "present (Kratos' staged check)"]}


def stage_plot():
    """The fields on the section at the end, and the wall and the surface after each stage."""
    D0 = fem.functionspace(msh, ("DG", 0))
    u_z = fem.Function(D0)
    u_z.interpolate(Expression(1e3 * u[1], D0.element.interpolation_points))
    soil_vm, p_cell = soil.von_mises(u, model), soil.cumulated_plastic_strain_per_cell()
    for f in (soil_vm, p_cell):  # the soil's (the wall's cells hold soil's states too)
        f.x.array[:] *= parts.present["soil"].x.array
    present = fem.Function(D0)
    present.x.array[:] = sum(f.x.array for f in parts.present.values())
    by_stage = {key: {r["stage"]: (x, 1e3 * np.array(r[key]) if key != "wall_moment"
                                   else np.array(r[key])) for r in records}
                for key, x in (("wall_deflection", depths), ("wall_moment", depths),
                               ("surface_settlement", surface_r))}
    plasticity_pictures.fields_and_profiles(
        u, {"vertical displacement u_z (mm)": u_z, "σ_eq in the soil (kPa)": soil_vm,
            "cumulated plastic strain p": p_cell},
        [{"x": "z (m)", "y": "wall's deflection u_r (mm)", "vertical": True,
          "curves": by_stage["wall_deflection"]},
         {"x": "z (m)", "y": "wall's bending moment (kN m/m)", "vertical": True,
          "curves": by_stage["wall_moment"]},
         {"x": "r (m)", "y": "surface's u_z (mm)", "curves": by_stage["surface_settlement"]}],
        args.plot, f"excavation R = {R:g} m, {args.lifts} lifts of {args.lift_depth:g} m "
        f"behind a wall {t_w:g} x {H_w:g} m; c = {args.c:g} kPa, φ = {args.phi:g}°, "
        f"ψ = {args.psi:g}°", axes=("r (m)", "z (m)"), window=(0, 3 * R, -1.5 * H_w, 0),
        shown=present)


cli.results(summary(), [stage_plot] if args.plot else [])
