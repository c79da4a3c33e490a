"""What the three punch demos share: their flags, the block's size, Hertz's check.

`demos/punch.py` (Hertz), `demos/punch_friction.py` (Cattaneo–Mindlin) and
`demos/indentation.py` (J2: load, unload, imprint) each build their block, residual,
contact and load steps in their own cells; their flags (`PunchParameters`), the contact
radius and block size the mesh is made for, and the comparison of a loaded state with
Hertz are the same in all three.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from fenics_nl.io.cli import say
from fenics_nl.io.parameters import Parameters, choice, number, switch
from fenics_nl.theory import hertz

__all__ = ["REACTIONS_OF", "HertzCheck", "PunchParameters", "block_size", "compare_with_hertz",
           "contact_radius_for", "prefixes"]

MAX_REFINE = 6  # a/1280 under the punch (plane strain a/2560): ~1e6 unknowns


@dataclass
class PunchParameters(Parameters):
    """A rigid punch on a block, pressed by the course's active set.

    The flags of every punch demo: the block, the punch and its normal load, the solver.
    Units are the user's, consistent (e.g. N, m, Pa or N, mm, MPa).
    """

    EPILOG = ("PETSc options of this run's solver take the prefix -punch_<model>_<form>_, "
              "<model> = axisymmetric | 3d | plane_strain, <form> = elim (the KSP and "
              "-snes_* options of each active-set iteration's Newton) | mult (SNES and KSP of "
              "the saddle point), e.g. -punch_axisymmetric_elim_ksp_view. An option no solver "
              "reads is an error.")
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
            "Newton's KSP and -snes_* options" if formulation == "elimination"
            else "SNES and KSP"}


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
        The check (Hertz's values, the relative errors, the fitted exponent).
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


