"""A rigid punch on an elastic block in one object, for the tests and the benchmarks.

The demos write this construction out in their own cells (`demos/punch.py`,
`punch_friction.py`, `indentation.py`): the block of `domain.meshes.punch_block`, its space
and supports, the residual, `contact.obstacles.RigidPunch` and the active set. The tests
and benchmarks that press a punch many times (mesh studies, friction's tangential path,
the mixed form's locking) build it here from those same public pieces.

A sphere, or a cylinder in plane strain.

Models: ``axisymmetric`` (r, z), ``3d`` (quarter block, symmetry planes x = 0 and y = 0),
``plane_strain`` (half block, symmetry x = 0; a cylinder). The block's top z = 0 (y = 0 in
2D) is the candidate contact surface S_C, its bottom slides on a rigid base (vertical
displacement 0). The obstacle's gap along the outward normal +e_z is the parabola
γ(r) = r²/(2R) − δ of Hertz's theory, the exact sphere R − √(R² − r²) − δ, or a cone of
half-angle α, r cot α − δ (Sneddon's; instrumented indentation's Berkovich tip is the cone of
70.3°, `BERKOVICH`).

Sizes are set from the expected contact radius a = √(Rδ): element size h = a/(20·2^refine)
(plane strain a/(40·2^refine), 3D a/(6·2^refine)) within 1.5a of the axis, growing linearly
away from it (5 % of the distance in 2D, 10 % in 3D), in a block of `block` x a. The finite
block is stiffer than Hertz's half-space by O(a/L) and the coarse far field stiffens it too;
measured on the axisymmetric model (R = 1, δ = 0.01, h = a/40): L = 100a gives +0.86 %,
300a +0.45 %, 1000a +0.30 % with 10 % growth and +0.14 % with 5 % growth, the default.
In 3D the far-field grading of the P1 tetrahedra dominates: +2.2 % at 15 % growth, +1.6 %
at 10 % (the default, L = 100a, h = a/12).
"""

from __future__ import annotations

import math

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.contact.active_set import ActiveSetContact
from fenics_nl.contact.friction import FrictionalContact
from fenics_nl.contact.obstacles import BERKOVICH, Indentation, RigidPunch, Traction
from fenics_nl.domain import boundary
from fenics_nl.domain.meshes import PUNCH_GROWTH, punch_block
from fenics_nl.io import output
from fenics_nl.materials import kinematics
from fenics_nl.materials.mixed import unknowns
from fenics_nl.parallel import global_max
from fenics_nl.solvers.force_control import reach_load
from fenics_nl.theory import hertz

__all__ = ["BERKOVICH", "Punch", "PunchBlock", "build_punch"]

MODELS = ("axisymmetric", "3d", "plane_strain")


class PunchBlock:
    """The block under the punch: graded mesh, displacement space, supports, S_C.

    Element size h = a/(20·2^refine) (plane strain a/40, 3D a/6) within 1.5a of the axis;
    `a` is the expected contact radius. Everything a residual is written with is public:
    `u`, `V`, `kinematics` (the strain model), `dx` (of degree 2·`degree`, exact for the
    linear law) and `weight` (2πr in the axisymmetric model, else 1). `degree`: of the
    displacement, P1 by default. `quadrature_degree` of `dx`: 2·`degree` by default.

    `mixed=True`: the Taylor–Hood pair (u, p) of `materials.mixed` (P2–P1) on the same
    mesh; `unknown` is the Function a solver updates (u itself otherwise), `u` and `p` the
    parts for forms, `displacement()` a Function of u to probe and draw.

    `tangential=True` (a tangential load along x): the block spans both sides of the punch,
    x in [−L, L], and its bottom is clamped (u = 0) instead of sliding; the 3D model is
    then the half y >= 0.
    """

    def __init__(self, model: str, a: float, *, refine: int = 1, block: float = 1000.0,
                 growth: float | None = None, mixed: bool = False, degree: int | None = None,
                 tangential: bool = False, quadrature_degree: int | None = None,
                 comm: MPI.Comm = MPI.COMM_WORLD):
        if model not in MODELS:
            raise ValueError(f"model must be one of {', '.join(MODELS)}, got {model!r}")
        if tangential and model == "axisymmetric":
            raise ValueError("a tangential load breaks the axial symmetry: use --model "
                             "plane_strain or 3d")
        if refine < 0 or block < 10:
            raise ValueError("refine must be >= 0 and block >= 10 (block size in contact radii)")
        self.model, self.a = model, a
        dim = 3 if model == "3d" else 2
        self.vertical = dim - 1
        self.growth = PUNCH_GROWTH[model] if growth is None else growth
        data, self.h = punch_block(comm, model, a, refine=refine, size=block,
                                   growth=self.growth, both_sides=tangential)
        self.tangential = tangential
        self.mesh = data.mesh
        degree = degree or (2 if mixed else 1)
        self.fields = f = unknowns(self.mesh, degree, mixed)
        self.mixed = f if mixed else None
        self.V, self.unknown, self.u, self.p = f.V, f.w, f.u, f.p
        self.kinematics = ("axisymmetric" if model == "axisymmetric"
                           else "3d" if dim == 3 else "plane_strain")
        self.weight = kinematics.measure_weight(self.mesh, self.kinematics)
        self.quadrature_degree = quadrature_degree or 2 * degree
        self.dx = kinematics.quadrature_measure("dx", self.mesh, self.quadrature_degree)

        def facets(name):
            return data.facet_tags.find(data.physical_groups[name].tag)

        # the constrained groups, whose reactions are reported (the side is free)
        names = (["contact", "bottom"] + ([] if tangential else ["symmetry_x"])
                 + (["symmetry_y"] if dim == 3 else []))
        self.groups = {name: facets(name) for name in names}
        if tangential:
            self.bcs = [boundary.fixed(self.V, facets("bottom"))]
        else:
            self.bcs = [boundary.component(self.V, 0, facets("symmetry_x")),
                        boundary.component(self.V, self.vertical, facets("bottom"))]
        if dim == 3:
            self.bcs.append(boundary.component(self.V, 1, facets("symmetry_y")))
        self.contact_facets = facets("contact")
        # force of the whole body from the modelled part (2πr is in the weight)
        self.symmetry_factor = {"axisymmetric": 1.0, "3d": 4.0, "plane_strain": 2.0}[model]
        if tangential:
            self.symmetry_factor /= 2

    def residual(self, material) -> ufl.Form:
        """R(u; v) of `material` in this block's unknown and model, with no external load.

        The unknown's internal work (`materials.mixed`): δΠ(u, p) in the mixed formulation,
        σ(ε(u)) : ε(v) (times 2πr in the axisymmetric model) in the displacement one.
        """
        return self.fields.internal_work(material, self.kinematics) * self.dx

    def displacement(self) -> fem.Function:
        """The displacement as a Function (a copy of the mixed unknown's part)."""
        return self.fields.displacement()

    def radius_of(self, x):
        """Distance from the punch axis (the x coordinate in plane strain)."""
        return np.sqrt(x[0] ** 2 + x[1] ** 2) if self.model == "3d" else np.abs(x[0])


def build_punch(model: str, material, radius: float, a: float, *, refine: int = 1,
                block: float = 1000.0, growth: float | None = None, mixed: bool = False,
                degree: int | None = None, tangential: bool = False,
                comm: MPI.Comm = MPI.COMM_WORLD, **options) -> Punch:
    """The block and the punch's active set in one call (as `demos/punch.py` composes them).

    `options` go to `Punch` (formulation, gap, friction, newton_options).
    """
    body = PunchBlock(model, a, refine=refine, block=block, growth=growth, comm=comm,
                      mixed=mixed, degree=degree, tangential=tangential)
    return Punch(body, material, body.residual(material), radius, **options)


class Punch:
    """The active-set solver of a block's residual against the rigid punch.

    `indent(δ)` or `push(P)`, each warm-started from the last active set.

    Args:
        block: the mesh, space and supports (`PunchBlock`).
        material: its E and ν give Hertz's reference and the force scale of the tolerances.
        residual: the block's residual R(u; v) (UFL form), zero external load: the punch
            acts through the contact conditions only.
        radius: the punch radius R.
        formulation: ``elimination`` or ``multiplier`` (see `ActiveSetContact`).
        gap: ``parabola`` (Hertz's), ``sphere`` (exact) or ``cone`` (of `cone_angle`, the
            radius then unused; axisymmetric and 3D).
        cone_angle: the cone's half-angle α in degrees, in (0, 90).
        friction: Coulomb's coefficient f (`FrictionalContact`), or None: frictionless.
        newton_options: passed to the Newton solver of each active-set iteration.
    """

    def __init__(self, block: PunchBlock, material, residual, radius: float, *,
                 formulation: str = "elimination", gap: str = "parabola",
                 cone_angle: float = BERKOVICH, friction: float | None = None,
                 newton_options: dict | None = None):
        self.obstacle = RigidPunch(radius, 3 if block.model == "3d" else 2, gap, cone_angle)
        if gap == "cone" and block.model == "plane_strain":
            raise ValueError("a cone is axisymmetric or 3D: use --model axisymmetric or 3d")
        self.block, self.material, self.residual = block, material, residual
        self.R, self.gap_shape = radius, gap
        self.cot = 1 / math.tan(math.radians(cone_angle))  # the cone's slope
        self.model, self.mesh, self.bcs = block.model, block.mesh, block.bcs
        self.u = block.unknown  # the Function the active-set loop updates
        # the force scale of Newton's absolute tolerance: Hertz's force for the expected a
        # (sphere P = 4/3 E* a³/R; cylinder P = π E* a²/(4R) per unit length; cone
        # P = π/2 E* a² cot α); E may be a fem.Constant (a parameter being identified)
        a, model = block.a, block.model
        E_star = hertz.effective_modulus(float(material.E), float(material.nu))
        if gap == "cone":
            force = np.pi / 2 * E_star * a * a * self.cot
        elif model == "plane_strain":
            force = np.pi / 4 * E_star * a * a / radius
        else:
            force = 4 / 3 * E_star * a**3 / radius
        opts = {"line_search": not material.is_linear,
                "force_scale": force / self.block.symmetry_factor}
        if block.mixed and formulation == "elimination":  # a symmetric saddle point: MUMPS
            opts["linear_solver"] = "cholesky"  # LDLᵀ (benchmarks/mixed.py)
        opts.update(newton_options or {})
        contact = dict(normal_axis=self.block.vertical, normal_sign=1, formulation=formulation,
                       initial="penetrating", newton_options=opts,
                       prefix=f"punch_{model}_",
                       displacement_space=block.V if block.mixed else None)
        self.friction = friction
        if friction is None:
            self.contact = ActiveSetContact(residual, self.u, self.bcs,
                                            self.block.contact_facets, self.gap(0.0), **contact)
        else:
            self.contact = FrictionalContact(residual, self.u, self.bcs,
                                             self.block.contact_facets, self.gap(0.0),
                                             friction=friction, **contact)

    @property
    def dofs(self) -> int:
        """Global number of unknowns (displacement, and pressure if mixed)."""
        return output.dofs(self.u.function_space)

    def gap_at(self, r, delta: float):
        """γ(r) = the punch's height above the undeformed surface at distance r, minus δ."""
        return self.obstacle.height(r) - delta

    def gap(self, delta: float):
        """γ(x) of the punch pressed by δ, for the contact surface."""
        return self.obstacle.gap(delta)

    def indent(self, delta: float) -> Indentation:
        """Press the punch down by δ (from the last state's active set)."""
        return self.obstacle.press(self.contact, delta, weight=self.block.weight,
                                   symmetry=self.block.symmetry_factor)

    # -- tangential load (with friction) ----------------------------------------------

    def _frictional(self):
        if self.friction is None or not self.block.tangential:
            raise ValueError("a tangential load needs friction (--friction) and a block on "
                             "both sides of the punch (tangential=True)")
        return self.contact

    def commit(self) -> None:
        """The current state becomes the start of the next load step (friction's history)."""
        if self.friction is not None:
            self.contact.commit()

    def shift(self, d: float) -> Traction:
        """Move the pressed punch to the tangential position d (along x).

        From the last committed state, the statuses of the last solve as a warm start.
        """
        c = self._frictional()
        c.set_motion([d] + [0.0] * (len(c.axes) - 1))
        res = c.solve()
        stick = c.stick
        r = self.block.radius_of(c.x[stick].T) if stick.any() else np.zeros(0)
        k = self.block.symmetry_factor
        return Traction(d, k * c.tangential_force()[0], k * c.force,
                        global_max(self.mesh.comm, r), c.surface.count(stick),
                        c.surface.count(c.slip), res.active_set_iterations, res.iterations,
                        res.work.factorizations)

    def pull(self, force: float, rtol: float = 1e-8, max_it: int = 60
             ) -> tuple[Traction, int]:
        """Tangential force control: the position d with Q(d) = `force`, by secant steps.

        From the committed state, Q(d) moves away from its committed value and bends as
        nodes slip (concave for a monotone load from stick): secant steps from the
        full-stick slope approach the root from its side and do not overshoot. Q >= f P
        has no static equilibrium (gross sliding): a ValueError.
        """
        c = self._frictional()
        P = self.block.symmetry_factor * c.force
        if not (math.isfinite(force) and 0 <= force < self.friction * P):
            raise ValueError(f"tangential force {force:g} must be in [0, f P) = [0, "
                             f"{self.friction * P:.6g}): at f P the punch slides (no static "
                             "equilibrium under force control)")
        d0 = float(c.committed_motion[0])
        q0 = self.block.symmetry_factor * float(c.committed_tangential_force[0])
        first = d0 + (1.0 if force >= q0 else -1.0) * 1e-6 * self.block.a  # full stick
        return reach_load(self.shift, force, (d0, q0), first, atol=rtol * self.friction * P,
                          max_it=max_it,
                          of=lambda t: (t.tangential_displacement, t.tangential_force))

    def _probe(self, sense: float = 1.0) -> Traction:
        """A move of 1e-6 a from the committed position: no node slips yet (full stick)."""
        return self.shift(float(self.contact.committed_motion[0]) + sense * 1e-6 * self.block.a)

    def bonded_compliance(self) -> float:
        """dd/dQ at the committed state, before any slip (the statuses are left warm)."""
        c = self._frictional()
        s = self._probe()
        q0 = self.block.symmetry_factor * float(c.committed_tangential_force[0])
        return (s.tangential_displacement - float(c.committed_motion[0])) / (
            s.tangential_force - q0)

    def traction_profile(self):
        """(x, p, q, status) of the S_C nodes on y = 0 (3D) or all (2D), on rank 0 sorted by x.

        Else None (`FrictionalContact.traction_profile`).
        """
        c = self._frictional()
        on = np.abs(c.x[:, 1]) <= 1e-9 * self.block.h if self.model == "3d" else None
        return c.traction_profile(self.block.weight, on)

    def tangential_force_within(self, radii) -> np.ndarray:
        """Q(r): the tangential force (along x, the whole body's) within each distance r."""
        c = self._frictional()
        return self.block.symmetry_factor * c.force_within(self.block.radius_of(c.x.T), radii)
