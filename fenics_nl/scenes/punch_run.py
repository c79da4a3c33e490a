"""What the three punch demos share: flags, step report, Hertz's check, JSON, pictures.

`demos/punch.py` (Hertz), `demos/punch_friction.py` (Cattaneo–Mindlin) and
`demos/indentation.py` (J2: load, unload, imprint) each tell their own story; the block,
the load path and its report, the comparison with Hertz and the outputs are the same in
all three, and live here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from fenics_nl.io import cli, indentation_pictures, output
from fenics_nl.io.cli import say
from fenics_nl.io.parameters import Parameters, choice, number, switch
from fenics_nl.scenes.punch import Punch, PunchBlock
from fenics_nl.theory import hertz

__all__ = ["PunchParameters", "StepReport", "block_for", "checkpointing", "compare_with_hertz",
           "contact_radius_for", "pictures", "prefixes", "summary"]

MAX_REFINE = 6  # a/1280 under the punch (plane strain a/2560): ~1e6 unknowns


@dataclass
class PunchParameters(Parameters):
    """A rigid punch on a block, pressed by the course's active set.

    The flags of every punch demo: the block, the punch and its normal load, the solver.
    Units are the user's, consistent (e.g. N, m, Pa or N, mm, MPa).
    """

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
    refine: int = number(1, "element size under the punch a/(20·2^refine) (plane strain: "
                         "a/(40·2^refine), 3D: a/(6·2^refine))", at_least=0,
                         at_most=MAX_REFINE)
    block: float | None = number(None, "block size in contact radii, >= 10 (default 1000, 3D "
                                 "100)", above=0)

    def check(self):
        """The combinations the solvers refuse, and the default indentation (0.01 R)."""
        if self.mixed and self.formulation == "multiplier" and self.model == "3d":
            raise ValueError("--mixed --formulation multiplier is 2D and axisymmetric only (no "
                             "nodal rule with positive weights on P2 triangles): use "
                             "--formulation elimination in 3d")
        if self.indentation is not None and self.indentation == 0:
            raise ValueError("--indentation must be non-zero (negative: the punch stays clear)")
        if self.block is not None and self.block < 10:
            raise ValueError("--block must be >= 10 (block size in contact radii)")
        if self.indentation is None and self.force is None:
            self.indentation = 0.01 * self.radius


def prefixes(model: str, formulation: str) -> dict[str, str]:
    """The PETSc prefix of a punch's solver, and what reads it (`cli.arguments`)."""
    return {f"punch_{model}_{formulation[:4]}_":
            "KSP" if formulation == "elimination" else "SNES and KSP"}


def contact_radius_for(model: str, E: float, nu: float, radius: float,
                       indentation: float | None, force: float | None) -> float:
    """The contact radius a block's mesh is made for.

    Hertz's a for a prescribed force (sphere, or the cylinder's half-width), else √(Rδ)
    (for a cylinder, a safe overestimate of its half-width).
    """
    if force is None:
        return math.sqrt(radius * abs(indentation))
    law = hertz.cylinder_from_force if model == "plane_strain" else hertz.sphere_from_force
    return law(E, nu, radius, force)["contact_radius"]


def block_size(model: str, block: float | None) -> float:
    """The block's size in contact radii: `block`, else 1000 (3D: 100)."""
    return block or (100.0 if model == "3d" else 1000.0)


@dataclass
class StepReport:
    """The `on_step` of `solve_incrementally`: each converged state said and kept in the JSON.

    `loading_steps` steps load the punch; those after them (an unloading) count the load
    factor down. `fields()` gives what --output writes at the step.
    """

    states: list
    loading_steps: int
    total_steps: int
    fields: object

    def __call__(self, t, result) -> None:
        """Say and keep the state just converged at load factor `t`."""
        s = self.states[-1]
        cli.converged_step({"load_factor": t if len(self.states) <= self.loading_steps else 1 - t,
                            "indentation": s.indentation, "force": s.force,
                            "contact_radius": s.contact_radius, "max_pressure": s.max_pressure,
                            "active_set_iterations": s.active_set_iterations},
                           fields=self.fields)
        say(f"step {len(self.states)}/{self.total_steps}: δ = {s.indentation:.5g}, P = "
            f"{s.force:.6g}, a = {s.contact_radius:.5g}, p0 = {s.max_pressure:.5g}, "
            f"{s.active_set_iterations} active-set iterations")


@dataclass
class HertzCheck:
    """The loaded state against Hertz.

    `ref`: Hertz's values (None: no contact); `errors`: the relative ones; `exponent`: m of
    P ∝ δ^m fitted over the loading steps (None with fewer than two).
    """

    ref: dict | None
    errors: dict = field(default_factory=dict)
    exponent: float | None = None


def compare_with_hertz(loading: list, hertz_of, model: str, h: float) -> HertzCheck:
    """The last loading state's force, contact radius and largest pressure against Hertz.

    The force is not checked for the cylinder; the radius is the outermost active node's.
    Said in one line, and the fitted exponent in another.

    Args:
        loading: the converged loading states (`indentation`, `force`, `contact_radius`,
            `max_pressure`).
        hertz_of: Hertz's values for a state (`Punch.hertz`, or the demo's own).
        model: ``axisymmetric``, ``3d`` or ``plane_strain``.
        h: the element size under the punch.

    Returns:
        The check: Hertz's values, the relative errors, the fitted exponent.
    """
    last = loading[-1]
    if not last.force > 0:
        say("the punch does not touch the block: zero contact force")
        return HertzCheck(None)
    ref = hertz_of(last)
    errors = {k: getattr(last, k) / ref[k] - 1 for k in ("force", "contact_radius",
                                                         "max_pressure") if k in ref}
    checked = [f"{k.replace('_', ' ')} {getattr(last, k):.6g} (Hertz {ref[k]:.6g}, "
               f"{100 * e:+.3f} %)" for k, e in errors.items()]
    if model == "plane_strain":  # a cylinder: Hertz's a and p0 for the computed P
        checked.insert(0, f"P = {last.force:.6g} per unit length (not checked)")
    say("; ".join(checked) + f"; h = {h:.2g}")
    exponent = None
    if len(loading) >= 2 and all(s.force > 0 for s in loading):
        exponent = float(np.polyfit(np.log([s.indentation for s in loading]),
                                    np.log([s.force for s in loading]), 1)[0])
        say(f"P ∝ δ^{exponent:.4f} over the steps" + ("" if model == "plane_strain"
                                                       else " (Hertz: 1.5)"))
    return HertzCheck(ref, errors, exponent)


REACTIONS_OF = {"axisymmetric": ("the whole body (2πr in the residual)",) * 2,
                "3d": ("the modelled quarter", "the modelled half"),
                "plane_strain": ("the modelled half, per unit length",
                                 "the whole block, per unit length")}


def summary(punch: Punch, states: list, loading: list, nodes: int, check: HertzCheck,
            material: str, warnings: list[str], *, formulation: str) -> dict:
    """The JSON every punch run has: the loaded state, its check, the steps, the work."""
    block, last, mixed = punch.block, loading[-1], punch.block.mixed is not None
    out = {"model": punch.model, "formulation": formulation, "material": material,
           "mixed": mixed, "elements": "P2-P1 (Taylor-Hood)" if mixed else "P1",
           "force": last.force, "indentation": last.indentation,
           "contact_radius": last.contact_radius, "max_pressure": last.max_pressure,
           "element_size": block.h, "nodes_in_contact": nodes,
           "active_set_iterations": sum(s.active_set_iterations for s in states),
           "newton_iterations": sum(s.newton_iterations for s in states),
           "factorizations": sum(s.factorizations for s in states),
           # every converged step, loading and unloading: the curve P(δ)
           "indentation_history": [s.indentation for s in states],
           "force_history": [s.force for s in states],
           "steps": [{"indentation": s.indentation, "force": s.force,
                      "contact_radius": s.contact_radius,
                      "active_set_iterations": s.active_set_iterations} for s in states],
           "reactions": punch.reactions(),
           "reactions_of": REACTIONS_OF[punch.model][block.tangential],
           "dofs": punch.dofs, "ranks": punch.mesh.comm.size, "warnings": warnings}
    if check.exponent is not None:
        out["fitted_exponent"] = check.exponent
    for k, e in check.errors.items():
        out[f"hertz_{k}"], out[f"{k}_rel_error"] = check.ref[k], e
    if punch.model == "plane_strain" and check.ref is not None:
        warnings.append("plane strain: the force is not checked (a cylinder's indentation "
                        "depends on the block, Hertz gives no P(δ)); half-width and p0 are "
                        "checked against Hertz for the computed P")
    return out


def pictures(punch: Punch, states: list, check: HertzCheck, *, png: str | None,
             plot: str | None, force_controlled: bool = False, friction=None, traction=None,
             stick_radius_exact=None, plastic: bool = False) -> list:
    """The writers of the pictures asked for (`png`, `plot`: their paths, or None).

    They draw the state at hand (gathered now: collective); states added to `states` later
    (an unloading) join the curve only.
    """
    if not (png or plot):
        return []
    profile = None
    if traction is not None:
        if punch.model == "3d":  # Q(r), the force inside r
            rings = np.linspace(0.0, 1.5, 301) * states[-1].contact_radius
            profile = (rings, punch.tangential_force_within(rings))
        else:
            profile = punch.traction_profile()
    block = punch.block
    section = (output.section(block.displacement(), punch.von_mises(),
                              normal_axis=1 if block.vertical == 2 else None)
               if png else None)
    material = punch.material
    run = indentation_pictures.PunchRun(
        punch.model, states, check.ref, float(material.E), float(material.nu), punch.R,
        rank0=punch.mesh.comm.rank == 0, profile=punch.surface_profile(), section=section,
        gap_at=punch.gap_at, h=block.h, tangential=block.tangential,
        mixed=block.mixed is not None, force_controlled=force_controlled,
        friction=friction, traction=traction,
        traction_profile=profile, stick_radius_exact=stick_radius_exact,
        loading_steps=len(states), plastic=plastic)
    writers = []
    if plot:  # (--output: the fields of every step were written as they converged)
        writers.append(lambda: indentation_pictures.curves(run, plot))
    if png:
        writers.append(lambda: indentation_pictures.section_picture(run, png))
    return writers


def checkpointing(punch: Punch, load, state: dict | None = None) -> cli.Checkpointing:
    """--checkpoint / --restart of a punch's loading (`cli.checkpointing`).

    Saved after each converged step: the unknown, the law's `state` functions, the contact
    statuses (with friction its slip history) and the load's states; with --restart they
    are put back now, the states into `load`.
    """
    checkpoints = cli.checkpointing({"unknown": punch.block.unknown, **(state or {})},
                                    newton=punch.contact.newton, contact=punch.contact,
                                    kept=load.record)
    if checkpoints.kept is not None:
        load.take_back(checkpoints.kept)
    return checkpoints


def block_for(model: str, a: float, *, refine: int, block: float | None, mixed: bool,
              tangential: bool = False) -> PunchBlock:
    """The graded block for the expected contact radius `a` (said while it is made)."""
    size = block_size(model, block)
    say(f"meshing the {model} block ({size:g} contact radii) ...")
    return PunchBlock(model, a, refine=refine, block=size, mixed=mixed, tangential=tangential)
