"""The flags every punch demo shares: the block, the punch, its normal load, the solver.

`demos/punch.py` (Hertz), `demos/punch_friction.py` (Cattaneo–Mindlin) and
`demos/indentation.py` (J2: load, unload, imprint) each subclass `PunchParameters` with
their own material or tangential load, and name their solver's PETSc prefix by `prefixes`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from fenics_nl.io.parameters import Parameters, choice, number, switch

__all__ = ["MAX_REFINE", "PunchParameters", "prefixes"]

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
    """The PETSc prefix of a punch's solver, and what reads it.

    Args:
        model: ``axisymmetric``, ``3d`` or ``plane_strain``.
        formulation: ``elimination`` or ``multiplier``.

    Returns:
        {prefix: what reads it}, as `cli.arguments` takes it.
    """
    return {f"punch_{model}_{formulation[:4]}_":
            "Newton's KSP and -snes_* options" if formulation == "elimination"
            else "SNES and KSP"}
