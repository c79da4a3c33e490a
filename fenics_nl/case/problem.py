"""A case file turned into the library's pieces: a residual, supports, a solver, probes.

The same composition as a scene: mesh → displacement space → material → residual
R(u; v) = ∫ internal work − ∫ loads → Dirichlet conditions → a Newton variant (or the
active-set loop when a group touches an obstacle) → load steps. Every load of the case
(prescribed displacements, tractions, pressures, the obstacle's motion) is scaled by one
load factor.
"""

from __future__ import annotations

import math

import numpy as np
import ufl
from dolfinx import fem
from dolfinx import mesh as dmesh
from mpi4py import MPI

from fenics_nl.case.damage import DamageSteps
from fenics_nl.case.mesh import load_mesh
from fenics_nl.case.spec import COMPONENTS, Case, CaseError, Condition
from fenics_nl.contact.active_set import ActiveSetContact
from fenics_nl.contact.pair import ArchardWear, ContactPair, FrictionalPair, PairContact
from fenics_nl.domain import boundary
from fenics_nl.domain.probes import Probes
from fenics_nl.errors import SolveError
from fenics_nl.io import output
from fenics_nl.materials import kinematics, laws, plane_stress
from fenics_nl.materials import mixed as mixed_form
from fenics_nl.materials.gradient_damage import DamagedElastic, GradientDamage
from fenics_nl.materials.laws import von_mises_of
from fenics_nl.materials.mixed import unknowns
from fenics_nl.materials.piecewise import ByGroup
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.solvers.result import SolveResult
from fenics_nl.solvers.snes import SnesSolver

__all__ = ["CaseProblem", "ContactSteps", "PairSteps"]

PREFIX = "case_"
FLOAT_RANGE = 1e150  # a load beyond it has no square in double precision (max ~1.8e308)


class CaseProblem:
    """Build a case (without solving): every mesh-related mistake raises CaseError."""

    def __init__(self, case: Case, comm: MPI.Comm = MPI.COMM_WORLD):
        self.case = case
        data = load_mesh(case, comm)
        self.mesh = msh = data.mesh
        self.model = case.model
        self.facets, problems = self._groups(data)
        self.apart: list[str] = []  # `_bodies_apart`'s warning, if any
        self.probes, outside = self._locate_probes()
        self.material, unset = self._material(data)
        if problems + outside + unset:
            raise CaseError(problems + outside + unset)
        if isinstance(self.material, GradientDamage):  # its damage field: a state
            self.material = DamagedElastic(self.material)
        # 2 × degree: exact for the linear part of every law on affine cells (bracket's table)
        q = 2 * case.degree
        # `unknown`: what the solver updates; `u`: the displacement in forms (its part, if
        # mixed, or beside J2's out-of-plane strain in plane stress); `displacement()`: a
        # Function of it to probe, draw and write
        self.plane_stress = None
        if case.model == "plane_stress" and self.material.path_dependent:
            f = self.plane_stress = plane_stress.PlaneStressUnknown(msh, case.degree, q)
        else:
            f = unknowns(msh, case.degree, case.formulation == "mixed")
        self.fields = f
        self.mixed = f if f.mixed else None
        self.V, self.unknown, self.u = f.V, f.w, f.u
        self.t = fem.Constant(msh, 0.0)  # the load factor
        tags = data.facet_tags
        self.dx = kinematics.quadrature_measure("dx", msh, q)
        self.ds = kinematics.quadrature_measure("ds", msh, q + 1, subdomain_data=tags)
        self.weight = kinematics.measure_weight(msh, self.model)
        if self.material.path_dependent:  # its state on dx's points
            self.material.bind(msh, q)
        self.residual = self._residual(data)
        areas = self._loaded_areas(data)
        self.force_scale = self._load_magnitude(areas)
        idle = self._idle_loads(areas)
        if idle:
            raise CaseError(idle)
        self.bcs, self._prescribed = self._dirichlet()
        self._initial_equilibrium()
        self.contact = self._contact()
        self.supports, self.held = self._supports()
        self.solver = None  # make_solver(): compiling the forms is for a run, not a check

    # -- the pieces ---------------------------------------------------------------------

    def _groups(self, data) -> tuple[dict[str, np.ndarray], list[str]]:
        """Facets of every group the conditions name, and what is wrong with them.

        A group must be a boundary group of the mesh, all on the boundary: a load on an
        interior facet would silently do nothing (ds integrates exterior facets only).
        """
        msh = data.mesh
        fdim = msh.topology.dim - 1
        msh.topology.create_connectivity(fdim, fdim + 1)
        exterior = dmesh.exterior_facet_indices(msh.topology)
        have = {n: g.tag for n, g in data.physical_groups.items() if g.dim == fdim}
        problems, out = [], {}
        named = [(c.group, c.key.rsplit(".", 1)[0] + ".group") for c in self.case.conditions]
        named += [(p[side], f"{p['key']}.{side}") for p in self.case.pairs
                  for side in ("slave", "master")]
        for group, where in named:
            if group not in have:
                problems.append(f"{where}: {group!r} is not a boundary group of the mesh "
                                f"(it has: {', '.join(sorted(have)) or 'none'})")
                continue
            out[group] = facets = data.facet_tags.find(have[group])
            inside = msh.comm.allreduce(int(np.isin(facets, exterior, invert=True).sum()))
            if inside:
                problems.append(f"{where}: {inside} facet(s) of {group!r} are inside the "
                                f"body; conditions act on its boundary")
        return out, problems

    def _material(self, data) -> tuple[laws.Material, list[str]]:
        """The case's material ([[material]]: `ByGroup` on the cell groups), and what is wrong.

        Every named group must be a cell group of the mesh, and every cell in one of them.
        """
        if self.case.groups is None:
            return self.case.material(), []
        msh = data.mesh
        tdim = msh.topology.dim
        have = {n: g.tag for n, g in data.physical_groups.items() if g.dim == tdim}
        problems, by_part, tags = [], {}, set()
        for part, law in self.case.laws():
            group = part["group"]
            if group not in have:
                i = next(k for k, g in enumerate(self.case.groups, start=1) if g[0] == group)
                problems.append(f"material[{i}].group: {group!r} is not a cell group of the "
                                f"mesh (it has: {', '.join(sorted(have)) or 'none'})")
            else:
                by_part[part["name"]] = ([have[group]], law)
                tags.add(have[group])
        if problems:
            return None, problems
        material = ByGroup(by_part, data.cell_tags)
        n = msh.topology.index_map(tdim).size_local
        bare = msh.comm.allreduce(len(material.cells_without(n)))
        if bare:
            named = [g for g, t in have.items() if t not in tags]
            problems.append(f"material: {bare} cells are in no [[material]] group (cell groups "
                            f"without one: {', '.join(sorted(named)) or 'none'})")
        self.apart = self._bodies_apart(data, {t: g for g, t in have.items() if t in tags})
        return material, problems

    def _bodies_apart(self, data, names: dict[int, str]) -> list[str]:
        """A warning if the cell groups make bodies that share no node and no pair holds apart.

        Bodies meshed apart (each its own nodes) touch only through [[contact]] pairs:
        without one they pass through each other unopposed, which nothing else would say.
        """
        if self.case.pairs or len(names) < 2:
            return []
        msh = data.mesh
        tdim = msh.topology.dim
        msh.topology.create_connectivity(tdim, 0)
        c2v = msh.topology.connectivity(tdim, 0)
        n_vertices = (msh.topology.index_map(0).size_local
                      + msh.topology.index_map(0).num_ghosts)
        groups_of = [set() for _ in range(n_vertices)]
        for tag in names:
            for cell in data.cell_tags.find(tag):
                for v in c2v.links(cell):
                    groups_of[v].add(tag)
        links = {tuple(sorted(g)) for g in groups_of if len(g) > 1}
        links = set().union(*msh.comm.allgather(links))
        body = {t: t for t in names}  # union–find of the groups joined by shared nodes

        def root(t):
            while body[t] != t:
                t = body[t]
            return t

        for shared in links:
            for t in shared[1:]:
                body[root(t)] = root(shared[0])
        parts: dict[int, list[str]] = {}
        for t, name in sorted(names.items()):
            parts.setdefault(root(t), []).append(name)
        if len(parts) < 2:
            return []
        bodies = "; ".join(", ".join(p) for p in parts.values())
        return [f"the cell groups make {len(parts)} bodies that share no node ({bodies}) and "
                "no [[contact]] pair keeps them apart: they pass through each other "
                "unopposed"]

    def _residual(self, data) -> ufl.Form:
        """R(u; v) = internal work − tractions − pressures, loads scaled by the factor t."""
        tag = {n: g.tag for n, g in data.physical_groups.items()}
        v = self.fields.v  # the displacement's test function (a part, if mixed)
        loads = 0
        w = self.weight
        for c in self.case.conditions:
            ds = self.ds(tag[c.group])
            if c.kind == "traction":
                T = self._ramped(ufl.as_vector(c.value), c.start and ufl.as_vector(c.start))
                loads -= ufl.dot(T, v) * w * ds
            elif c.kind == "pressure":
                loads += self._ramped(c.value, c.start) * ufl.dot(
                    self._pressure_direction(c), v) * w * ds
        gravity = self._gravity()
        self.construction = self._construction(data, gravity)
        if gravity is not None and self.construction is None:  # a geostatic initial
            loads -= ufl.dot(gravity, v) * w * self.dx  # stress: the ground's weight, held
        self._loads = loads
        stages = self.construction
        by_group = isinstance(self.material, ByGroup)
        if by_group and stages is not None:
            self.material.follow(stages)  # χ_p: the parts present; arrivals stress-free
        if by_group:  # each law on its cells (χ_p: its presence, when stages follow)
            internal = self.material.work(self.u, v, self.model, self.dx)
        else:
            internal = self.fields.internal_work(self.material, self.model)
            present = 1 if stages is None else stages.present["body"]
            internal = present * internal * self.dx
        if stages is None:
            return internal + loads
        self._internal = internal
        # the parts present; what a stage digs out, released; what it builds, weighing in
        down = ufl.as_vector([-1.0 if i == self.mesh.geometry.dim - 1 else 0.0
                              for i in range(self.mesh.geometry.dim)])
        self._released = stages.released(v, down, kinematics.small_strain(v, self.model)
                                          ) * w * self.dx
        weights = sum(ufl.dot(stages.body_force(p, down), v) for p in stages.parts)
        return internal - weights * w * self.dx + self._released + loads

    def _construction(self, data, gravity):
        """The stages' parts (`fenics_nl.construction`): each [[material]] table, or the body.

        Each part weighs its unit weight ([initial_stress]'s if not given); the parts a stage
        adds are absent until then.
        """
        if not self.case.stages:
            return None
        from fenics_nl.construction import Construction

        tdim = self.mesh.topology.dim
        have = {n: g.tag for n, g in data.physical_groups.items() if g.dim == tdim}
        wrong = [f"stage[{i}].remove: {g!r} is not a cell group of the mesh (it has: "
                 f"{', '.join(sorted(have)) or 'none'})"
                 for i, st in enumerate(self.case.stages, start=1) for g in st["remove"]
                 if g not in have]
        if wrong:
            raise CaseError(wrong)
        self._stage_tags = {g: have[g] for g in have}
        ground = 0.0 if gravity is None else self.case.initial_stress["unit_weight"]
        degree = 2 * self.case.degree
        if self.case.parts is None:
            stages = Construction(self.V, data.cell_tags, {"body": sorted(set(have.values()))},
                                  weights={"body": ground}, degree=degree)
            stages.present["body"].x.array[:] = 1.0  # every cell, in a group or not
            return stages
        parts = {p["name"]: [have[p["group"]]] for p in self.case.parts}
        weights = {p["name"]: ground if p["unit_weight"] is None else p["unit_weight"]
                   for p in self.case.parts}
        absent = {p["name"]: parts[p["name"]] for p in self.case.parts if not p["start"]}
        return Construction(self.V, data.cell_tags, parts, weights=weights, absent=absent,
                            degree=degree)

    def resume_stage(self, stage: dict) -> None:
        """Go on inside `stage` from a checkpoint, its fields restored.

        Its progress is the driver's; the dofs no present cell touches are held where they are.
        """
        self.construction.stage = stage["name"]
        self.solver.set_bcs(self.bcs + self.construction.held(self.u))

    def begin_stage(self, stage: dict) -> None:
        """Start `stage` at equilibrium (s = 0): what it digs out frozen, what it builds in.

        The groups dug out leave, their forces frozen; those built are present, stress-free.
        """
        # what the last step left (Newton's tolerance), which the stage adds to
        before = boundary.out_of_balance(self.residual, self.solver.bcs)
        eps = kinematics.small_strain(self.u, self.model)
        if self.case.parts is None:
            remove = {"body": [self._stage_tags[g] for g in stage["remove"]]}
            add, stresses = {}, {"body": self.material.stress(eps)}
        else:
            remove, add = ({part: [self._stage_tags[g]] for part, g in stage[key]}
                           for key in ("leave", "arrive"))
            law = self.material.laws
            stresses = {part: law[part].stress(self.material.law_strain(eps)) for part in remove}
        self.construction.begin(stage["name"], remove=remove, add=add, stresses=stresses,
                                strain=eps)
        self.solver.set_bcs(self.bcs + self.construction.held(self.u))
        # the stage starts in equilibrium: the frozen forces hold what the dug cells did,
        # the parts that arrive carry nothing (to 1e-9 of the frozen forces and the body's
        # internal forces, beyond what the last step left)
        left = boundary.out_of_balance(self.residual, self.solver.bcs)
        scale = max(boundary.out_of_balance(f, self.solver.bcs)
                    for f in (self._released, self._internal))
        if left > before + 1e-9 * scale:
            raise SolveError(f"stage {stage['name']!r} does not start in equilibrium: "
                             f"{left:.3g} unbalanced, against the last step's {before:.3g} "
                             f"and the frozen and internal forces' {scale:.3g}")

    def _gravity(self):
        """The body force of a geostatic initial stress, −γ along the last axis (or None)."""
        s0 = self.case.initial_stress
        if not isinstance(s0, dict):
            return None
        dim = self.mesh.geometry.dim
        return ufl.as_vector([-s0["unit_weight"] if i == dim - 1 else 0.0
                              for i in range(dim)])

    def _initial_admissible(self) -> None:
        """Refuse an initial stress outside the yield surface at a quadrature point.

        The first step would project it onto the surface, as if a load had done so.
        """
        from mpi4py import MPI

        from fenics_nl.expression import Expression

        Q = self.material.quadrature_space()
        eps_v = kinematics.small_strain(self.fields.v, self.model)
        geostatic = isinstance(self.case.initial_stress, dict)
        # (a uniform one as a Constant of the mesh: compiled, as the geostatic one; UFL's
        # own evaluation of a 3D principal stress's graph takes minutes)
        stress = self.material.initial(eps_v) if geostatic else fem.Constant(
            self.mesh, np.array(self.case.initial_stress, dtype=float))
        # f / its scale (c cos φ ...), of each soil's part present (−1 elsewhere)
        if isinstance(self.material, ByGroup):
            soils = [(self.material.indicator(self.mesh, key), law)
                     for key, law in self.material.laws.items() if hasattr(law, "initial")]
            excess = sum(chi * (law.yield_function(stress) / law.yield_scale + 1)
                         for chi, law in soils) - 1
        else:
            law = self.material
            excess = law.yield_function(stress) / law.yield_scale
        at_points = fem.Function(Q)
        at_points.interpolate(Expression(excess, Q.element.interpolation_points))
        values = at_points.x.array[:Q.dofmap.index_map.size_local]
        worst = self.mesh.comm.allreduce(float(values.max(initial=-np.inf)), op=MPI.MAX)
        if worst > 1e-9:
            outside = self.mesh.comm.allreduce(int((values > 1e-9).sum()))
            where = (f"at {outside} quadrature point(s)" if geostatic
                     else "(uniform: everywhere)")
            raise CaseError([f"initial_stress: outside the yield surface {where} (the "
                             f"largest f is {worst:.3g} of f's constant term): the "
                             "ground could not stand in it (a K0 below the active limit, a "
                             "surface below the mesh's top?)"])

    def _ramped(self, value, start):
        """A load at the load factor t: t × value, or start + t (value − start) ({ from, to })."""
        return self.t * value if start is None else start + self.t * (value - start)

    def _initial_equilibrium(self) -> None:
        """Refuse an initial stress out of balance with the loads at 0 and the supports.

        R(u = 0) at load factor 0 must vanish (to 1e-9 of the initial stress's own nodal
        forces, the supports' rows left out), or the first step would carry the imbalance
        as if it were a load. At construction u is 0.
        """
        if self.case.initial_stress is None:
            return
        saved = float(self.t.value)
        self.t.value = 0.0
        eps_v = kinematics.small_strain(self.fields.v, self.model)
        own = ufl.inner(self.material.initial(eps_v), eps_v) * self.weight * self.dx
        # (σ0's own forces with the supports' rows: a scale that is not round-off when
        # they hold all of them)
        norms = [boundary.out_of_balance(self.residual, self.bcs),
                 boundary.out_of_balance(own)]
        self.t.value = saved
        self._initial_admissible()
        if norms[0] > 1e-9 * max(norms[1], 1e-300):
            raise CaseError([f"initial_stress: not in equilibrium with the loads at load "
                             f"factor 0 and the supports: they leave {norms[0]:.3g} of its "
                             f"own nodal forces {norms[1]:.3g} unbalanced (give each loaded "
                             "group its in-situ traction at 0, e.g. pressure = { from = "
                             "p0, to = ... })"])

    def load_potential(self):
        """The dead loads' potential, −(their work); 0 without loads.

        The residual's load terms with the displacement for the test function.
        """
        if isinstance(self._loads, int):
            return 0
        return ufl.replace(self._loads, {self.fields.v: self.u})

    def _loaded_areas(self, data) -> dict[str, float]:
        """The weighted area (2πr in the axisymmetric model) of each loaded group (collective).

        What the loads' size (`_load_magnitude`) and the idle loads (`_idle_loads`) read.
        """
        tag = {n: g.tag for n, g in data.physical_groups.items()}
        return {c.group: self.mesh.comm.allreduce(fem.assemble_scalar(fem.form(
                    self.weight * self.ds(tag[c.group]))))
                for c in self.case.conditions if c.kind in ("traction", "pressure")}

    def _load_magnitude(self, areas: dict[str, float]) -> float | None:
        """Σ |traction| or |pressure| × area over the loaded groups at load factor 1.

        The force Newton's absolute tolerance is relative to (None: displacements or an
        obstacle drive the body, and the first residual sets the scale).
        """
        total = 0.0
        for c in self.case.conditions:
            if c.kind in ("traction", "pressure"):
                # hypot: no overflow warning for a huge component; { from, to }: the larger
                size = max(math.hypot(*v) if c.kind == "traction" else abs(v)
                           for v in (c.value, c.start) if v is not None)
                total += size * areas[c.group]
                if not total < FLOAT_RANGE:  # inf and NaN too
                    raise CaseError([f"{c.key}: the load it gives (its size {size:.3g} × the "
                                     f"group's area) is beyond {FLOAT_RANGE:.0e}: its square "
                                     "(in norms and energies) overflows floating point; use "
                                     "other units"])
        if isinstance(self.case.initial_stress, dict):  # the ground's weight
            total += self.case.initial_stress["unit_weight"] * self.mesh.comm.allreduce(
                fem.assemble_scalar(fem.form(self.weight * self.dx)))
        return total or None

    def _idle_loads(self, areas: dict[str, float]) -> list[str]:
        """A line for each traction or pressure that can do no work, and why.

        On a group of zero measure (the axis of an axisymmetric model, where r = 0), or on
        a component that a displacement condition prescribes on every facet of the group
        (it would only shift that support's reaction). A pressure acts along the normal:
        idle where every component is held, or where a flat group's normal is along a held
        axis. (Facets inside the body are refused with the groups.)
        """
        comm, names = self.mesh.comm, COMPONENTS[self.model]
        boundary = comm.allreduce(fem.assemble_scalar(fem.form(self.weight * self.ds)))
        out = []
        for c in self.case.conditions:
            if c.kind not in ("traction", "pressure"):
                continue
            if not areas[c.group] > 1e-12 * boundary:  # dimensionless: a share of the boundary
                where = " (r = 0 on it)" if self.model == "axisymmetric" else ""
                out.append(f"{c.key}: {c.group!r} has no area in the {self.model} model"
                           f"{where}: the load can do no work there")
                continue
            held = self._held_everywhere(c.group)
            if c.kind == "traction":
                idle = [i for i, v in enumerate(c.value) if (v or (c.start and c.start[i]))
                        and i in held]
            else:
                _, normal = self.mean_normal(c.group)
                flat = [i for i, n in enumerate(normal) if abs(n) > 1 - 1e-9]
                idle = (sorted(held) if len(held) == self.case.dim
                        else [i for i in flat if i in held])
            if idle and c.kind == "traction":
                comps = ", ".join(names[i] for i in idle)
                held_ = ", ".join(f"u_{names[i]}" for i in idle)
                out.append(f"{c.key}: its {comps} component on {c.group!r}, where a "
                           f"displacement condition holds {held_}, can do no work (it would "
                           f"only change that support's reaction); set it to 0 or free "
                           f"{held_}")
            elif idle:
                held_ = ", ".join(f"u_{names[i]}" for i in idle)
                out.append(f"{c.key}: {c.group!r} has {held_} prescribed by a displacement "
                           f"condition: the pressure there can do no work (it would only "
                           f"change that support's reaction); remove it or free {held_}")
        return out

    def _held_everywhere(self, group: str) -> set[int]:
        """The components that displacement conditions prescribe on every facet of `group`."""
        comm, facets = self.mesh.comm, self.facets[group]
        held = set()
        for i in range(self.case.dim):
            covered = np.zeros(len(facets), dtype=bool)
            for c in self.case.conditions:
                if c.kind == "displacement" and c.value[i] is not None:
                    covered |= np.isin(facets, self.facets[c.group])
            if comm.allreduce(int((~covered).sum())) == 0:
                held.add(i)
        return held

    def _pressure_direction(self, c: Condition):
        """The reference normal N (dead), or J F⁻ᵀ N (follower) of the 2D or 3D model."""
        N = ufl.FacetNormal(self.mesh)
        if not c.follower:
            return N
        F = kinematics.deformation_gradient(self.u, self.model)
        if F.ufl_shape[0] == len(N):  # 3D, plane stress
            return ufl.det(F) * ufl.inv(F).T * N
        n3 = ufl.det(F) * ufl.inv(F).T * ufl.as_vector([N[0], N[1], 0])
        return ufl.as_vector([n3[0], n3[1]])

    def _dirichlet(self):
        """One condition per prescribed component; its value follows the load factor."""
        bcs, prescribed = [], []
        for c in self.case.conditions:
            if c.kind != "displacement":
                continue
            for i, value in enumerate(c.value):
                if value is not None:
                    bc = boundary.component(self.V, i, self.facets[c.group], 0.0)
                    bcs.append(bc)
                    prescribed.append((bc.g.x.array, value))
        return bcs, prescribed

    def _supports(self):
        """The groups whose reactions are reported, and the components each holds.

        The contact group first: a node on it and on a support (the axis under a punch)
        carries the contact force. Axisymmetric: the radial resultant of a revolution is
        zero by symmetry, so only the axial one is reported.
        """
        groups, held = {}, {}
        for c in sorted(self.case.conditions, key=lambda c: c.kind != "contact"):
            if c.kind == "displacement":
                comps = [i for i, v in enumerate(c.value) if v is not None]
            elif c.kind == "contact":
                comps = [self.contact[2]]
            else:
                continue
            if self.model == "axisymmetric":
                comps = [i for i in comps if i != 0]
            groups[c.group] = self.facets[c.group]
            held[c.group] = sorted(set(held.get(c.group, [])) | set(comps))
        return groups, held

    def _contact(self):
        """The contact group's obstacle, or None: (condition, facets, axis, sign)."""
        c = next((c for c in self.case.conditions if c.kind == "contact"), None)
        if c is None:
            return None
        axis, sign = self._flat_normal(c)
        if c.value["obstacle"] == "plane" and c.value["normal"][axis] == 0:
            raise CaseError([f"{c.key}.normal: the plane is parallel to the contact group's "
                             f"normal (axis {axis}): the group can never meet it"])
        return c, self.facets[c.group], axis, sign

    def _flat_normal(self, c: Condition) -> tuple[int, int]:
        """The group's outward normal ±e_axis, or CaseError if it is not flat and aligned."""
        area, mean = self.mean_normal(c.group)
        if area <= 0:
            raise CaseError([f"{c.key}: group {c.group!r} has no facet on the boundary"])
        axis = int(np.argmax(np.abs(mean)))
        if abs(abs(mean[axis]) - 1) > 1e-8:
            raise CaseError([f"{c.key}: the contact group must be flat with its outward "
                             f"normal along an axis (mean normal {np.round(mean, 4).tolist()})"
                             f"; the active set constrains one displacement component"])
        return axis, int(np.sign(mean[axis]))

    def mean_normal(self, group: str) -> tuple[float, np.ndarray]:
        """(∫ ds, ∫ n ds / ∫ ds) of a group: its area and mean outward normal (collective).

        The normal is 0 for a closed surface, and for a group with no area.
        """
        comm = self.mesh.comm
        f = np.sort(self.facets[group])
        mt = dmesh.meshtags(self.mesh, self.mesh.topology.dim - 1, f,
                            np.ones(len(f), dtype=np.int32))
        ds = ufl.Measure("ds", domain=self.mesh, subdomain_data=mt)(1)
        n = ufl.FacetNormal(self.mesh)
        area = comm.allreduce(fem.assemble_scalar(fem.form(1.0 * ds)))
        total = np.array([comm.allreduce(fem.assemble_scalar(fem.form(n[i] * ds)))
                          for i in range(self.case.dim)])
        return area, total / area if area > 0 else np.zeros(self.case.dim)

    def obstacle_at(self, t: float) -> dict:
        """The contact obstacle at load factor t (moved by t × its displacement)."""
        ob = dict(self.contact[0].value)
        key = "center" if ob["obstacle"] == "sphere" else "point"
        ob[key] = (np.asarray(ob[key]) + t * np.asarray(ob["displacement"])).tolist()
        return ob

    def gap(self, t: float):
        """γ(x) at load factor t: distance from S_C to the obstacle along the outward normal."""
        _, _, axis, sign = self.contact
        ob = self.obstacle_at(t)

        def plane(x):
            p, m = np.asarray(ob["point"]), np.asarray(ob["normal"])
            return ((p[:, None] - x[: len(p)]) * m[:, None]).sum(axis=0) / (sign * m[axis])

        def sphere(x):
            centre, R = np.asarray(ob["center"]), ob["radius"]
            d = x[: len(centre)] - centre[:, None]
            a = sign * d[axis]  # along the outward normal, negative when facing the sphere
            r2 = np.maximum((d * d).sum(axis=0) - a * a, 0.0)
            # beside the sphere (r >= R) nothing is met before its far pole's level
            return np.where(r2 < R * R, -a - np.sqrt(np.maximum(R * R - r2, 0.0)), R - a)

        return plane if ob["obstacle"] == "plane" else sphere

    def line_search(self):
        """Backtracking for a non-linear law; on the energy's slope for a hyperelastic one.

        A hyperelastic energy is smooth, so its slope along a Newton step says whether the
        step is good even when ‖R‖ grows (`NewtonSolver._step`). Only where R is the
        gradient of an energy that is minimised: not the mixed form (a saddle point: the
        pressure rows' slope can cancel the displacement's), not a follower pressure (no
        potential); J2 (at small and finite strain) and the power law keep the test on ‖R‖
        (a kink in R).
        """
        if self.material.is_linear:
            return False
        follower = any(c.kind == "pressure" and c.follower for c in self.case.conditions)
        minimised = (self.material.finite_strain and not self.material.path_dependent
                     and not self.mixed and not follower)
        return "slope" if minimised else True

    def make_solver(self):
        """The case's solver (compiles the forms; reads the PETSc options under ``case_``)."""
        self.solver = self._solver()
        return self.solver

    def _solver(self):
        case = self.case
        if self.damage:
            return DamageSteps(self, PREFIX + "damage_")
        method, linear = case.newton, case.linear_solver
        opts = {"rtol": 1e-10, "atol": case.tolerance, "max_it": case.max_it,
                "line_search": self.line_search(), "force_scale": self.force_scale}
        if linear == "gamg" and self.mixed:  # MINRES with the block preconditioner
            opts["preconditioner"] = mixed_form.preconditioner(self.material, self.mixed.W,
                                                               self.model, self.dx)
        if method in ("modified", "bfgs"):  # J2: the course's elastic tangent, once
            opts["constant_tangent"] = self.fields.constant_tangent(self.material, self.model,
                                                                    self.dx)
        if case.pairs:
            return PairSteps(self)
        # a part a stage adds is absent until then: its dofs no present cell touches held
        bcs = self.bcs + ([] if self.construction is None else self.construction.held(self.u))
        if self.contact is not None:
            _, facets, axis, sign = self.contact
            contact = ActiveSetContact(
                self.residual, self.unknown, self.bcs, facets, self.gap(0.0), normal_axis=axis,
                normal_sign=sign, initial="penetrating", prefix=PREFIX,
                newton_options={"method": method, **opts},
                displacement_space=self.V if self.mixed or self.plane_stress else None)
            return ContactSteps(contact, self)
        if case.newton == "snes":
            return SnesSolver(self.residual, self.unknown, bcs, prefix=PREFIX + "snes_",
                              rtol=opts["rtol"], atol=case.tolerance,
                              force_scale=self.force_scale, max_it=case.max_it,
                              linear_solver=linear)
        return NewtonSolver(self.residual, self.unknown, bcs, method=method, prefix=PREFIX,
                            linear_solver=linear, **opts)

    # -- loads and results --------------------------------------------------------------

    @property
    def damage(self) -> bool:
        """Whether the case is in gradient damage (its solver: alternate minimization)."""
        return isinstance(self.material, DamagedElastic)

    @property
    def dofs(self) -> int:
        """Global number of scalar unknowns (with the pressure's, if mixed; the damage's)."""
        damage = output.dofs(self.material.alpha.function_space) if self.damage else 0
        return output.dofs(self.unknown.function_space) + damage

    def displacement(self) -> fem.Function:
        """The displacement as a Function (a copy of the mixed unknown's part)."""
        return self.fields.displacement()

    def set_load(self, t: float) -> None:
        """Scale every load of the case by t."""
        self.t.value = t
        for array, value in self._prescribed:
            array[:] = t * value

    def reactions(self) -> dict[str, list[float]]:
        """Resultant force of each displacement (and the contact) group on the body.

        Each group reports the components it holds (0 elsewhere; axisymmetric: the axial
        resultant of the whole revolution). A node component held by two groups counts in
        the contact group, else in the first listed.
        """
        return boundary.reactions(self.residual, self.unknown, self.supports, self.held,
                                  space=self.V)

    def von_mises(self) -> fem.Function:
        """σ_eq per cell (Cauchy stress; DG0)."""
        if self.mixed:
            return self.mixed.von_mises(self.material, self.model)
        if self.plane_stress:  # J2: at its quadrature points
            return self.material.cell_mean(von_mises_of(self._stress()), "von_mises")
        return self.material.von_mises(self.u, self.model)

    def _stress(self):
        """The Cauchy stress (UFL): 3x3, or 2x2 in plane stress."""
        if self.mixed:
            return mixed_form.cauchy_stress(self.material, self.u, self.mixed.p, self.model)
        if self.plane_stress:
            return plane_stress.stress(self.material, self.plane_stress)
        return self.material.cauchy_stress(self.u, self.model)

    def commit(self) -> None:
        """Commit a path-dependent law's state at the converged step."""
        if self.plane_stress:
            self.material.commit_strain(self.plane_stress.strain())
        else:
            self.material.commit(self.u, self.model)

    def _locate_probes(self):
        """The probes located in the mesh, and a line for each one outside it."""
        probes = Probes(self.mesh, [p.point for p in self.case.probes])
        return probes, [f"{self.case.probes[i].key}: {self.case.probes[i].point} is outside "
                        f"the mesh" for i in probes.outside]

    def probe_values(self) -> dict[str, dict]:
        """Displacement, von Mises and Cauchy stress at every probe (see `domain.probes`).

        The stress in the model's components: 3x3 in (x, y, z); plane strain (x, y, z) with
        σ_zz; plane stress 2x2; axisymmetric (r, z, θ).
        """
        if not self.case.probes:
            return {}
        u = self.probes.continuous(self.displacement())
        stress = self._stress()
        vm = self.probes.discontinuous("von_mises", von_mises_of(stress), self.case.degree)
        if self.plane_stress:  # the in-plane components, as the other plane-stress laws
            stress = ufl.as_tensor([[stress[i, j] for j in range(2)] for i in range(2)])
        sigma = self.probes.discontinuous("stress", stress, self.case.degree)
        return {p.name: {"displacement": d, "von_mises": s, "stress": t}
                for p, d, s, t in zip(self.case.probes, u, vm, sigma, strict=True)}


class ContactSteps:
    """The active-set loop as a load-step solver: each step moves the obstacle first."""

    def __init__(self, contact: ActiveSetContact, problem: CaseProblem):
        self.contact, self.problem, self.u = contact, problem, problem.unknown

    def solve(self) -> SolveResult:
        """The contact state at the current load factor, from the last active set."""
        c = self.contact
        c.set_gap(self.problem.gap(float(self.problem.t.value)))
        c.add_penetrating()
        return c.solve()


class PairSteps:
    """The active set on the case's contact pairs as a load-step solver (`contact.pair`).

    Each [[contact]] table is a `ContactPair` (its slave nodes projected once on its master
    facets: small sliding); one active set runs over them all, frictionless or, when a pair
    has friction, with Coulomb's statuses (committed at each converged step). A linear law
    keeps one factorization of K for the run (`contact.condensed`).
    """

    def __init__(self, problem: CaseProblem):
        self.problem, self.u = problem, problem.unknown
        pairs = [ContactPair(problem.V, problem.facets[p["slave"]],
                             problem.facets[p["master"]], weight=problem.weight)
                 for p in problem.case.pairs]
        options = {"atol": problem.case.tolerance, "force_scale": problem.force_scale,
                   "max_it": problem.case.max_it,  # linear laws: K factorized once
                   "linear": problem.material.is_linear}
        joined = ContactPair.joined(pairs)
        friction = [p["friction"] for p in problem.case.pairs]
        if any(friction):
            self.contact = FrictionalPair(problem.residual, problem.unknown, problem.bcs, joined,
                                          friction, **options)
        else:
            self.contact = PairContact(problem.residual, problem.unknown, problem.bcs, joined,
                                       **options)
        wear = [p["wear"] for p in problem.case.pairs]
        self.wear = ArchardWear(self.contact, wear) if any(wear) else None
        # each pair's sliding speed (a pair that does not wear: any, its k is 0)
        self.speed = np.array([p["speed"] or 1.0 for p in problem.case.pairs])

    def solve(self) -> SolveResult:
        """The pairs' contact at the current load factor, from the last statuses."""
        return self.contact.solve()

    def slide(self, dt: float) -> SolveResult:
        """The pairs' contact at the current load factor after sliding for `dt` (wear)."""
        return self.wear.slide(self.speed * dt)

    def commit(self) -> None:
        """A converged step: the next step's slip is measured from here (friction)."""
        if isinstance(self.contact, FrictionalPair):
            self.contact.commit()

    def checkpoint_arrays(self) -> dict[str, np.ndarray]:
        """The pairs' statuses and forces, and their wear (a restart's)."""
        out = self.contact.checkpoint_arrays()
        if self.wear is not None:
            out |= {f"wear.{k}": v for k, v in self.wear.checkpoint_arrays().items()}
        return out

    def restore_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """The state of `checkpoint_arrays` back."""
        self.contact.restore_arrays({k: v for k, v in arrays.items()
                                     if not k.startswith("wear.")})
        if self.wear is not None:
            self.wear.restore_arrays({k[len("wear."):]: v for k, v in arrays.items()
                                      if k.startswith("wear.")})

    def summaries(self) -> list[dict]:
        """Each pair's force, nodes in contact, contact radius and largest pressure.

        With wear also its worn volume, largest wear depth and sliding distance.
        """
        axisymmetric = self.problem.model == "axisymmetric"
        out = [{"slave": p["slave"], "master": p["master"]}
               | self.contact.summary(k, axisymmetric)
               for k, p in enumerate(self.problem.case.pairs)]
        if self.wear is not None:
            w, part, comm = self.wear, self.contact.pair.part, self.contact.pair.comm
            volumes = w.volumes()
            distance = np.broadcast_to(w.distance, (len(out),))
            for k, (record, p) in enumerate(zip(out, self.problem.case.pairs, strict=True)):
                if p["wear"]:
                    record |= {"wear_volume": float(volumes[k]),
                               "max_wear_depth": comm.allreduce(float(w.depth[
                                   part == k].max(initial=0.0)), op=MPI.MAX),
                               "sliding_distance": float(distance[k])}
        return out
