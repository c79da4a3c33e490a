"""Instrumented indentation as a forward model: a J2 block's load–depth curve, and dP/dθ.

The derivatives with respect to the law's parameters are taken through the whole load path.

A rigid sphere (radius R) or cone (half-angle α) is pressed into an axisymmetric J2 block
(the course's active set, `contact.ActiveSetContact`, on the block of
`domain.meshes.punch_block`) through a list of depths, loading then unloading; the force P
at each converged step is the curve. The law's parameters — E, σ0, the isotropic hardening H
and the kinematic C — are `fem.Constant` objects, so one compiled set of forms serves every
run of an identification, and each run from the virgin state may carry the sensitivities
dP/dθ by direct differentiation (`solvers.sensitivity`): for each parameter one solve per
step with the step's converged tangent.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.contact.active_set import ActiveSetContact
from fenics_nl.contact.obstacles import BERKOVICH, Indentation, RigidPunch
from fenics_nl.domain import boundary
from fenics_nl.domain.meshes import PUNCH_GROWTH, punch_block
from fenics_nl.io import output
from fenics_nl.materials import kinematics
from fenics_nl.materials.mixed import unknowns
from fenics_nl.materials.plasticity import J2Plasticity
from fenics_nl.solvers.sensitivity import PathSensitivity
from fenics_nl.theory import hertz

__all__ = ["PARAMETERS", "POSITIVE", "Curve", "IndentationTest", "check_value"]

# the parameters of the curve, by the name a user writes (CLI, JSON), and J2Plasticity's field
PARAMETERS = {"sigma0": "sigma0", "hardening": "H", "E": "E", "kinematic": "C"}
POSITIVE = ("sigma0", "E")  # > 0; the others >= 0


def check_value(name: str, value: float) -> None:
    """ValueError unless `value` is finite and in the range of parameter `name`."""
    if name not in PARAMETERS:
        raise ValueError(f"unknown parameter {name!r}: the curve's parameters are "
                         f"{', '.join(PARAMETERS)}")
    strict = name in POSITIVE
    if not (math.isfinite(value) and (value > 0 if strict else value >= 0)):
        raise ValueError(f"{name} must be {'> 0' if strict else '>= 0'} and finite, got "
                         f"{value:g}")


@dataclass
class Curve:
    """A computed load–depth curve: P at each depth, and dP/dθ for the parameters asked."""

    depth: np.ndarray
    force: np.ndarray  # the whole body's
    derivatives: dict[str, np.ndarray] = field(default_factory=dict)  # dP/dθ by name
    states: list[Indentation] = field(default_factory=list)
    wall_time: float = 0.0


class IndentationTest:
    """The axisymmetric J2 block under a rigid sphere or cone, run through given depths.

    Args:
        E, nu, sigma0, hardening, kinematic: the law's starting values (`set` changes E,
            σ0, H and C between runs, without recompiling anything).
        max_depth: the deepest indentation, for the mesh: the contact radius it is graded
            for is √(R δ) (sphere) or 2 δ tan α / π (cone, Sneddon's), with pile-up room.
        radius: the sphere's radius R; `cone_angle`: a cone of this half-angle (degrees)
            instead of the sphere. `gap`: the sphere's shape, ``parabola`` (Hertz's, as
            `demos/indentation.py` by default) or ``sphere`` (exact).
        refine, block: the block's mesh (`domain.meshes.punch_block`: h = a/(20·2^refine)
            under the indenter, the block `block` contact radii deep and wide).
        differentiate: the parameters whose dP/dθ a run with sensitivities carries.
    """

    def __init__(self, *, E: float, nu: float, sigma0: float, hardening: float,
                 kinematic: float = 0.0, max_depth: float, radius: float = 1.0,
                 cone_angle: float | None = None, gap: str = "parabola",
                 refine: int = 0, block: float = 1000.0,
                 growth: float | None = None, quadrature_degree: int | None = None,
                 differentiate: tuple[str, ...] = ("sigma0", "hardening"),
                 comm: MPI.Comm = MPI.COMM_WORLD):
        unknown = sorted(set(differentiate) - set(PARAMETERS))
        if unknown:
            raise ValueError(f"unknown parameter(s) {', '.join(unknown)}: the curve's "
                             f"parameters are {', '.join(PARAMETERS)}")
        if not max_depth > 0:
            raise ValueError(f"the largest depth must be > 0, got {max_depth!r}")
        # what `finer` builds again, on a finer mesh
        self._options = {"E": E, "nu": nu, "sigma0": sigma0, "hardening": hardening,
                         "kinematic": kinematic, "max_depth": max_depth, "radius": radius,
                         "cone_angle": cone_angle, "gap": gap, "refine": refine,
                         "block": block, "growth": growth,
                         "quadrature_degree": quadrature_degree, "comm": comm}
        if cone_angle is None:
            a = math.sqrt(radius * max_depth)
        else:
            a = 2 * max_depth * math.tan(math.radians(cone_angle)) / math.pi
        self.growth = PUNCH_GROWTH["axisymmetric"] if growth is None else growth
        data, _ = punch_block(comm, "axisymmetric", a, refine=refine, size=block,
                              growth=self.growth)
        msh = data.mesh

        def tagged(name):
            return data.facet_tags.find(data.physical_groups[name].tag)

        self.fields = unknowns(msh, 1)  # P1 displacements
        self.u = u = self.fields.u
        V = u.function_space
        bcs = [boundary.component(V, 0, tagged("symmetry_x")),
               boundary.component(V, 1, tagged("bottom"))]
        values = {"E": E, "sigma0": sigma0, "hardening": hardening, "kinematic": kinematic}
        self.constants = {k: fem.Constant(msh, float(v)) for k, v in values.items()}
        c = self.constants
        # checked at their current values; later ones by `set`
        self.material = J2Plasticity(c["E"], nu, sigma0=c["sigma0"], H=c["hardening"],
                                     C=c["kinematic"])
        degree = quadrature_degree or 2
        self.material.bind(msh, degree)
        dx = kinematics.quadrature_measure("dx", msh, degree)
        residual = self.fields.internal_work(self.material, "axisymmetric") * dx
        self.weight = kinematics.measure_weight(msh, "axisymmetric")  # 2πr
        self.obstacle = RigidPunch(radius, 2, gap if cone_angle is None else "cone",
                                   cone_angle or BERKOVICH)
        # Newton's force scale: Hertz's force for the expected a (sphere P = 4/3 E* a³/R,
        # cone P = π/2 E* a² cot α)
        E_star = hertz.effective_modulus(E, nu)
        force = (4 / 3 * E_star * a**3 / radius if cone_angle is None
                 else np.pi / 2 * E_star * a * a / math.tan(math.radians(cone_angle)))
        self.contact = ActiveSetContact(
            residual, u, bcs, tagged("contact"), self.obstacle.gap(0.0), normal_axis=1,
            initial="penetrating", newton_options={"line_search": True, "force_scale": force},
            prefix="punch_axisymmetric_")
        self.differentiate = tuple(differentiate)
        self.sensitivity = PathSensitivity(
            residual, u, self.contact.newton, self.material.state_functions(),
            self.material.state_update(kinematics.small_strain(u, "axisymmetric")),
            {k: c[k] for k in self.differentiate}) if differentiate else None

    def finer(self) -> IndentationTest:
        """The same model on a finer mesh, without sensitivities.

        h halved under the indenter (refine + 1), the far field graded twice as finely
        (growth / 2).
        """
        o = dict(self._options)
        o["growth"] = self.growth / 2
        o["refine"] += 1
        return IndentationTest(**o, differentiate=())

    @property
    def dofs(self) -> int:
        """Global number of unknowns of the block."""
        return output.dofs(self.u.function_space)

    def values(self) -> dict[str, float]:
        """The parameters' current values by name."""
        return {k: float(c.value) for k, c in self.constants.items()}

    def set(self, **values: float) -> None:
        """New parameter values (by name): E > 0, σ0 > 0, H >= 0, C >= 0."""
        for name, value in values.items():
            check_value(name, value)
            self.constants[name].value = float(value)

    def run(self, depths, *, sensitivities: bool = True) -> Curve:
        """P at each depth of the path from the virgin state, and dP/dθ if asked.

        SolveError (from the active set or Newton) if a step does not converge.
        """
        t0 = time.perf_counter()
        material, contact = self.material, self.contact
        self.u.x.array[:] = 0.0
        material.reset()
        contact.set_gap(self.obstacle.gap(0.0))
        contact.restart()
        sens = self.sensitivity if sensitivities else None
        if sens is not None:
            sens.reset()
        curve = Curve(np.asarray(depths, dtype=float), np.zeros(len(depths)),
                      {k: np.zeros(len(depths)) for k in (self.differentiate if sens else ())})
        for n, delta in enumerate(curve.depth):
            state = self.obstacle.press(contact, float(delta), weight=self.weight)
            curve.states.append(state)
            curve.force[n] = state.force
            if sens is not None:
                for name, dR in zip(sens.names, sens.step(), strict=True):
                    curve.derivatives[name][n] = self._force_of(dR)
            material.commit(self.u, "axisymmetric")
        curve.wall_time = time.perf_counter() - t0
        return curve

    def _force_of(self, reactions: np.ndarray) -> float:
        """The whole body's contact force of the nodal reactions `reactions` (as P)."""
        c = self.contact  # axisymmetric: the whole body's (2πr in the residual)
        return c.total_force(c.surface.sign * reactions[c.surface.dofs_V])
