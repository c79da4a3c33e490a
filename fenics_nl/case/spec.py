"""The case-file format: a TOML file read into a `Case`, every mistake reported at once.

Read with the standard library's `tomllib`. Every key is checked: an unknown key is an
error (a misspelt optional key would otherwise be silently ignored), so is a missing
required one, a value of the wrong type or out of range. Each message names the key as
``table.key`` (``boundary[2].traction``: tables counted from 1) and what it accepts.
`FORMAT` below is the reference, printed by ``python -m fenics_nl --help``.
"""

from __future__ import annotations

import difflib
import itertools
import math
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path

from fenics_nl.materials import laws
from fenics_nl.materials.creep import NortonCreep, PerzynaViscoplasticity
from fenics_nl.materials.drucker_prager import FITS, DruckerPrager
from fenics_nl.materials.finite_plasticity import FiniteJ2Plasticity
from fenics_nl.materials.gradient_damage import AT1, AT2, SPLITS
from fenics_nl.materials.mohr_coulomb import MohrCoulomb
from fenics_nl.materials.plasticity import J2Plasticity
from fenics_nl.vocabulary import canonical, renamed

__all__ = ["KEYS", "Case", "CaseError", "Condition", "Probe", "arc_length_obstacles",
           "key_table", "read_case"]

FORMAT = """\
[mesh]
file = "part.geo"        # .msh, or .geo meshed by gmsh at run time (path relative to the case)
size = 2.0               # .geo only, optional: largest element size (gmsh Mesh.MeshSizeMax)
refine_near = { groups = ["inner"], size = 0.2, distance = 1.0 }   # .geo only, optional:
                         # cells of size 0.2 within 1.0 of these boundary groups, growing
                         # to the mesh's own size over another 1.0
model = "plane_strain"   # 3d | plane_strain | plane_stress | axisymmetric (x = r, y = z)
degree = 2               # Lagrange degree of the displacement (default 1)
formulation = "mixed"    # optional: displacement (default) | mixed (Taylor–Hood u–p: no
                         # locking as nu -> 0.5, nu = 0.5 allowed; degree >= 2, not plane stress)

[material]
law = "linear-elastic"   # linear-elastic | power-law | saint-venant-kirchhoff | neo-hookean | j2
                         # | j2-finite | drucker-prager | mohr-coulomb | at1 | at2 | norton
                         # | perzyna
E = 1000.0               # and the law's parameters: nu; power-law also sigma0, n; j2 (von
nu = 0.3                 # Mises plasticity) also sigma0, and optionally H (isotropic) and C
                         # (kinematic hardening modulus), each 0 by default (perfect plasticity);
                         # plane stress: linear-elastic, saint-venant-kirchhoff, j2, norton, perzyna
# drucker-prager, mohr-coulomb (soils; stresses positive in tension): E, nu, c (cohesion),
# phi (friction angle, degrees), optionally psi (dilatancy angle, default phi: associated);
# drucker-prager optionally fit ("compression": the cone through Mohr-Coulomb's compression
# meridian, or "plane_strain"); perfect plasticity; not plane stress, not mixed;
# mohr-coulomb optionally tension (a cut-off: no principal stress above it). Their in-situ
# stress, uniform:
# [initial_stress]
# stress = [[-10.0, 0.0, 0.0], [0.0, -10.0, 0.0], [0.0, 0.0, -10.0]]  # as the probes say it
# or geostatic, with the ground's weight (held): unit_weight = 18.0, K0 = 0.5, surface = 0.0
# j2-finite: J2 at finite strain (F = Fe Fp, Hencky, the exponential map): E, nu, sigma0,
# optionally H (linear hardening) and saturation, delta (Voce: sigma_y = sigma0 + H p +
# (saturation - sigma0)(1 - exp(-delta p))); not plane stress
# norton (creep: uniaxially de/dt = A sigma^n): E, nu, A (1/(stress^n time)), n; perzyna
# (viscoplasticity on J2: dp/dt = <(sigma_eq - sigma0 - H p)/K>^m): E, nu, sigma0,
# K (stress time^(1/m)), m, optionally H (default 0). Both are rate-dependent: [loading]
# takes a time axis, not steps. No contact. norton needs formulation = "mixed" (its flow is
# incompressible and grows without bound: P2 displacements alone lock), except in plane stress
# at1, at2 (gradient damage: a damage field 0 <= alpha <= 1 that never decreases, minimized
# with u at each step by alternate minimization, Anderson-accelerated): also Gc (toughness,
# energy per unit crack area) and ell (length; the mesh's cells at most ell/2 where a crack
# goes), and optionally residual_stiffness (default 1e-6: what a broken cell keeps) and
# split = "volumetric" (no damage under volumetric compression; default "none"). Small strain,
# not plane stress, no contact, no arc-length, newton = "full"; the JSON adds per step the
# dissipated energy and the largest damage

# or bodies of different materials: one [[material]] table per cell group (a physical
# group of the mesh's cells; every cell in one), laws without internal variables
# (linear-elastic, power-law, saint-venant-kirchhoff, neo-hookean), all small or all finite
# strain, and one plastic law of small strain (j2, drucker-prager or mohr-coulomb: soil
# layers, a wall in a ground), not in plane stress:
# [[material]]
# group = "ball"
# law = "linear-elastic"
# E = 3.0
# nu = 0.2
# unit_weight = 25.0      # a part a [[stage]] adds: its weight (default: the ground's)

[[boundary]]             # one table per condition, on a physical group of the mesh
group = "clamped"
displacement = [0.0, 0.0]     # a component may be "free"; values scale with the load factor

[[boundary]]
group = "loaded"
traction = [0.0, -1.0]        # force per unit area (per unit length in 2D), reference
                              # configuration (a dead load), scaled by the load factor

[[boundary]]
group = "inner"
pressure = 1.0                # normal pressure, positive pushing on the body; dead (along the
follower = false              # undeformed normal) unless follower = true (finite strain only)
# pressure = { from = 10.0, to = 1.0 }   # or a load from one value (load factor 0) to
                              # another (1): a cavity's support lowered from the in-situ stress

[[boundary]]                  # one contact group: rigid, frictionless, may separate
group = "top"                 # flat, its outward normal along an axis
contact = { obstacle = "plane", point = [0.0, 1.0], normal = [0.0, 1.0] }
# or { obstacle = "sphere", center = [0.0, 2.0], radius = 1.0, displacement = [0.0, -0.01] }:
# inside the braces, displacement moves the obstacle (scaled by the load factor). In the
# axisymmetric model a sphere is centred on the axis and a plane is normal to it.

# [[contact]]            # contact between two bodies (degree 1, displacement
# slave = "ball_surface" # formulation; 2D and 3D): the slave group's nodes against the
# master = "block_top"   # master group's facets (facet groups of the two bodies), small
# friction = 0.0         # sliding; optional Coulomb coefficient (default 0). One table per
#                        # pair; the JSON reports each pair's force, nodes in contact,
#                        # contact radius and largest pressure every step
# wear = 1e-3            # optional (frictionless pairs): Archard's dh = k p ds on the slave,
# speed = 0.1            # sliding at this speed (ds = speed dt) while [loading] runs in
#                        # time = { end, steps } (equal steps; the load factor against time
#                        # by factor, default: at once, then held); the JSON adds each
#                        # pair's wear_volume, max_wear_depth and sliding_distance

[loading]
steps = 10               # equal steps to the load factor 1 (cut in half on failure), or a
                         # list of load factors to visit, e.g. [0.5, 1.0, 0.0]
adaptive = true          # optional: false stops at the first failed step instead of cutting it
# or, for a rate-dependent law (norton, perzyna) or a pair's wear, time as the load parameter:
# time = { end = 200.0, steps = 40, adaptive = true }   # the first step end/steps (or less,
#                        # to land on factor's first point after 0); adaptive: each step's
#                        # local error (3 mu dt/2 times the change of the viscous strain
#                        # rate over it, over the largest sigma_eq: dimensionless) at most
#                        # `tolerance` (1e-3), a step above it undone and retaken shorter
#                        # (adaptive = false: equal steps); `stationary` (1e-6): the state is
#                        # stationary once sigma_eq, at its rate of change, would change by
#                        # less than this fraction of its largest value over the time the
#                        # load has been held
# factor = [[0.0, 0.0], [0.01, 1.0], [200.0, 1.0]]     # load factor against time, piecewise
#                        # linear, held after its last point (default [[0.0, 1.0]]: the load
#                        # at once, then held); every load scales with it
# or path following through limit points (loads only: no prescribed displacement, no
# contact, not snes; the load factor is an unknown, and the tangent's inertia is checked
# each step: the JSON lists the limit points and bifurcations met in "critical_points"; a
# bifurcation is passed on the same branch, not left, and warned about):
# control = "arc-length"
# target = 1.0           # the load factor to reach (the path may pass it going down first)
# arc_length = 0.1       # the first arc length, > 0 (dimensionless: about one load step)
# max_arc_length = 1.0   # optional: the largest (default: no bound)
# max_steps = 100        # optional: steps before the run stops short of the target
# stop = { probe = "inner", component = "r", value = 1.0 }   # optional: the run also ends
#                        # (status ok) at the first step where this probe's displacement
#                        # component has reached value: past a limit point, where λ falls

[solver]                 # every key optional
newton = "full"          # full | modified | periodic | bfgs | snes
linear_solver = "lu"     # lu (MUMPS) | gamg (CG + GAMG)
tolerance = 1e-9         # |R| <= tolerance x the force scale of the step ends Newton
max_it = 50              # Newton iterations per step

[[probe]]                # optional: displacement, von Mises and Cauchy stress (key stress, the
                         # model's components: (x, y, z), plane stress (x, y), axisymmetric
                         # (r, z, θ)) at a point, every step
name = "tip"
point = [10.0, 1.0]

# [[stage]]              # optional: construction stages after the loading, in order (its
# name = "lift 1"        # steps' JSON names it); remove: the cell groups dug out (their
# remove = ["soil_1"]    # stiffness and weight leave, their forces on the rest released
# add = ["wall"]         # over the steps); add: [[material]] groups built (their next
# steps = 10             # table's law, stress-free when they arrive, their weight coming
#                        # in over the steps); the laws linear-elastic, power-law, j2,
#                        # drucker-prager or mohr-coulomb; no contact, arc-length or time
"""

# every key of the format: (table, key, meaning, default, unit); the documentation's table
# (`key_table`), checked against FORMAT and the reader by the tests. Units are the case's
# own, consistent (N, mm, MPa or N, m, Pa, ...); "—": a number without one, or a word
KEYS = [
    ("mesh", "file", "the mesh: a .msh, or a .geo meshed by gmsh at run time (path relative "
     "to the case)", "required", "—"),
    ("mesh", "size", ".geo only: the largest element size (gmsh's Mesh.MeshSizeMax)",
     "the .geo's", "length"),
    ("mesh", "refine_near", ".geo only: `{ groups = [...], size, distance }`, cells of `size` "
     "within `distance` of these boundary groups, growing to the mesh's own size over "
     "another `distance`", "none", "length"),
    ("mesh", "model", "`3d`, `plane_strain`, `plane_stress` or `axisymmetric` (x = r, y = z)",
     "required", "—"),
    ("mesh", "degree", "the displacement's Lagrange degree: 1, 2 or 3", "1", "—"),
    ("mesh", "formulation", "`displacement`, or `mixed`: Taylor–Hood u–p (degree ≥ 2, not "
     "plane stress), no locking as ν → 0.5, ν = 0.5 allowed", "displacement", "—"),
    ("material", "law", "`linear-elastic`, `power-law`, `saint-venant-kirchhoff`, "
     "`neo-hookean`, `j2`, `j2-finite`, `drucker-prager`, `mohr-coulomb`, `at1`, `at2`, "
     "`norton` or "
     "`perzyna`", "required",
     "—"),
    ("material", "group", "[[material]] only: the cell group (a physical group of the mesh's "
     "cells) this law holds on; one table per group, every cell in one; a second table of a "
     "group arrives when a [[stage]] adds it (a wall in place of the soil)", "required there",
     "—"),
    ("material", "unit_weight", "[[material]] only, a part a [[stage]] adds: its unit weight "
     "(a wall's concrete)", "[initial_stress]'s unit_weight, or 0", "force/volume"),
    ("material", "E", "Young's modulus, > 0", "required", "stress"),
    ("material", "nu", "Poisson's ratio, −1 < ν ≤ 0.5 (0.5: the mixed formulation)",
     "required", "—"),
    ("material", "sigma0", "power-law: its reference stress; j2, j2-finite, perzyna: the "
     "yield stress", "required there", "stress"),
    ("material", "n", "power-law: its exponent (1: Hooke's law); norton: its exponent, ≥ 1 "
     "(1: linear viscosity)", "required there", "—"),
    ("material", "A", "norton: the creep coefficient, uniaxially dε/dt = A σⁿ",
     "required there", "1 / (stressⁿ time)"),
    ("material", "K", "perzyna: the viscous stress, dp/dt = ⟨(σ_eq − σ0 − H p)/K⟩^m",
     "required there", "stress time^(1/m)"),
    ("material", "m", "perzyna: the rate exponent, ≥ 1", "required there", "—"),
    ("material", "H", "j2, j2-finite, perzyna: the linear isotropic hardening modulus", "0",
     "stress"),
    ("material", "C", "j2: the kinematic hardening modulus", "0", "stress"),
    ("material", "c", "drucker-prager, mohr-coulomb: the cohesion", "required there",
     "stress"),
    ("material", "phi", "drucker-prager, mohr-coulomb: the friction angle φ, in (0, 90)",
     "required there", "degrees"),
    ("material", "psi", "drucker-prager, mohr-coulomb: the dilatancy angle ψ, in [0, φ] (φ: "
     "associated "
     "flow; below: not associated, the tangent not symmetric)", "phi", "degrees"),
    ("material", "tension", "mohr-coulomb: a tension cut-off t, no principal stress above "
     "it, in [0, c cotφ]", "none", "stress"),
    ("material", "fit", "drucker-prager: the cone through Mohr–Coulomb's `compression` "
     "meridian, or with its `plane_strain` collapse load", "compression", "—"),
    ("material", "saturation", "j2-finite: Voce's saturation stress, σ_y = σ0 + H p + "
     "(saturation − σ0)(1 − e^(−delta p))", "none", "stress"),
    ("material", "delta", "j2-finite: Voce's rate", "0", "—"),
    ("material", "Gc", "at1, at2: the toughness (energy per unit crack area)", "required there",
     "energy / area"),
    ("material", "ell", "at1, at2: the damage length (cells at most ell/2 where a crack goes)",
     "required there", "length"),
    ("material", "residual_stiffness", "at1, at2: what a broken cell keeps", "1e-6", "—"),
    ("material", "split", "at1, at2: `none`, or `volumetric` (no damage under volumetric "
     "compression)", "none", "—"),
    ("boundary", "group", "a boundary physical group of the mesh", "required", "—"),
    ("boundary", "displacement", "one value per component, or `\"free\"`; scaled by the load "
     "factor", "—", "length"),
    ("boundary", "traction", "force per unit area of the reference configuration (per unit "
     "length of a 2D model's boundary, per unit thickness), dead; scaled by the load factor",
     "—", "force / area"),
    ("boundary", "pressure", "normal pressure, positive pushing on the body; scaled by the "
     "load factor, or `{ from = A, to = B }`: A at load factor 0, B at 1 (a traction too, "
     "with vectors)", "—", "stress"),
    ("initial_stress", "stress", "drucker-prager, mohr-coulomb: the stress at zero strain "
     "(in situ), "
     "uniform, 3 rows of 3 in the model's components ((x, y, z); axisymmetric (r, z, θ)); "
     "in equilibrium with the loads at load factor 0 and the supports (checked)", "0",
     "stress"),
    ("initial_stress", "unit_weight", "or geostatic: the ground's unit weight γ; the "
     "vertical stress −γ × the depth below `surface` (on y in 2D, z in 3D), `K0` times it "
     "across, and the weight a body force, held from the start", "—", "force / volume"),
    ("initial_stress", "K0", "geostatic: the horizontal over the vertical stress", "—", "—"),
    ("initial_stress", "surface", "geostatic: the ground surface's height", "—", "length"),
    ("boundary", "follower", "the pressure follows the deformed normal (finite strain)",
     "false", "—"),
    ("boundary", "contact", "one rigid frictionless obstacle: `{ obstacle = \"plane\", point, "
     "normal }` or `{ obstacle = \"sphere\", center, radius }`, and a `displacement` "
     "scaled by the load factor", "—", "length"),
    ("contact", "slave", "[[contact]]: the facet group whose nodes are kept out of the "
     "master's facets (the finer surface)", "required", "—"),
    ("contact", "master", "[[contact]]: the facet group of the other body", "required", "—"),
    ("contact", "friction", "[[contact]]: Coulomb's coefficient f (stick and slip, as on a "
     "rigid obstacle)", "0", "—"),
    ("contact", "wear", "[[contact]]: Archard's wear coefficient k (over the hardness): the "
     "slave's surface wears by dh = k p ds as it slides over the master (frictionless "
     "pairs; [loading] in time)", "0", "length²/force"),
    ("contact", "speed", "[[contact]] with wear: the sliding speed, ds = speed dt (the "
     "track's distance, not a motion of the mesh)", "required there", "length/time"),
    ("loading", "steps", "load control: n equal steps to the load factor 1, or a list of "
     "load factors to visit", "required there", "—"),
    ("loading", "adaptive", "a failed step is cut in half (false: the run stops)", "true",
     "—"),
    ("loading", "time", "norton, perzyna, and pairs with wear (equal steps): the time axis "
     "`{ end, steps, "
     "adaptive, tolerance, stationary }`: the last time; the first step end/`steps` (20), "
     "or less to land on the first point of `factor`; `adaptive` (true) sizes the steps by "
     "their local error, at most `tolerance` (1e-3: 3μ Δt/2 times the change of the "
     "viscous strain rate over the step, over the largest σ_eq), false takes equal steps; "
     "`stationary` (1e-6): the state is stationary (the JSON's `stationary_since`) once "
     "σ_eq, at its rate of change, would change by less than that fraction over the time "
     "the load has been held", "required there", "time"),
    ("loading", "factor", "with time: the load factor against time, `[[t, f], ...]` from "
     "t = 0, piecewise linear, held after its last point; the steps land on its points",
     "[[0.0, 1.0]]", "time, —"),
    ("loading", "control", "`load`, or `arc-length` (loads only: the load factor an unknown, "
     "through limit points)", "load", "—"),
    ("loading", "target", "arc-length: the load factor that ends the run", "1", "—"),
    ("loading", "arc_length", "arc-length: the first arc (dimensionless: about one load "
     "step)", "0.1", "—"),
    ("loading", "max_arc_length", "arc-length: the largest arc", "no bound", "—"),
    ("loading", "max_steps", "arc-length: the converged steps after which a run that has not "
     "ended fails", "100", "—"),
    ("loading", "stop", "arc-length: `{ probe, component, value }`, the run also ends (status "
     "ok) at the first step where that probe's displacement component has reached `value`",
     "none", "length"),
    ("solver", "newton", "`full`, `modified`, `periodic`, `bfgs` or `snes`", "full", "—"),
    ("solver", "linear_solver", "`lu` (MUMPS) or `gamg` (CG + GAMG)", "lu", "—"),
    ("solver", "tolerance", "‖R‖ ≤ tolerance × the step's force scale ends Newton", "1e-9",
     "—"),
    ("solver", "max_it", "Newton iterations per step (PETSc's name, as in `-snes_max_it`)",
     "50", "—"),
    ("probe", "name", "the probe's name in the JSON", "required", "—"),
    ("probe", "point", "where displacement, von Mises and Cauchy stress are reported, every "
     "step", "required", "length"),
    ("stage", "name", "a construction stage, after the loading, in order: its name in the "
     "steps' JSON", "required", "—"),
    ("stage", "remove", "the cell groups it digs out: their stiffness and weight leave, the "
     "forces they exerted released over its steps (`fenics_nl.construction`)",
     "[] (remove or add required)", "—"),
    ("stage", "add", "the [[material]] groups it builds: each its group's next table, "
     "stress-free when it arrives, its weight coming in over the steps", "[]", "—"),
    ("stage", "steps", "its load steps (the release from 0 to 1; a step that fails is cut "
     "in half)", "1", "—"),
]


def key_table() -> str:
    """The format's keys as a Markdown table (the documentation's case page)."""
    lines = ["| key | meaning | default | unit |", "|---|---|---|---|"]
    for table, key, meaning, default, unit in KEYS:
        many = table in ("boundary", "probe", "contact", "stage") or (table, key) == ("material",
                                                                          "group")
        name = f"[[{table}]]" if many else f"[{table}]"
        lines.append(f"| `{name}` `{key}` | {meaning} | {default} | {unit} |")
    return "\n".join(lines) + "\n"


LAWS: dict[str, type[laws.Material]] = {
    "linear-elastic": laws.LinearElastic,
    "power-law": laws.PowerLaw,
    "saint-venant-kirchhoff": laws.StVenantKirchhoff,
    "neo-hookean": laws.NeoHookean,
    "j2": J2Plasticity,
    "j2-finite": FiniteJ2Plasticity,
    "drucker-prager": DruckerPrager,
    "mohr-coulomb": MohrCoulomb,
    "at1": AT1,
    "at2": AT2,
    "norton": NortonCreep,
    "perzyna": PerzynaViscoplasticity,
}
DAMAGE = ("at1", "at2")
SOILS = ("drucker-prager", "mohr-coulomb")
VISCOUS = ("norton", "perzyna")  # rate-dependent: driven in time ([loading] time)
# parameters a case may leave out, and their values: J2 without hardening is perfect
# plasticity; a broken cell of a damage law keeps 1e-6 of its stiffness (a body cut in two
# by a crack would otherwise have a singular tangent)
OPTIONAL = {"j2": {"H": 0.0, "C": 0.0}, "perzyna": {"H": 0.0},
            "drucker-prager": {"psi": None, "fit": "compression"},
            "mohr-coulomb": {"psi": None, "tension": None},
            "j2-finite": {"H": 0.0, "saturation": None, "delta": 0.0},
            **{law: {"residual_stiffness": 1e-6, "split": "none"} for law in DAMAGE}}
STATE_FREE = ("linear-elastic", "power-law", "saint-venant-kirchhoff", "neo-hookean")
# the plastic laws a [[material]] group takes (their state committed on its cells only)
GROUP_PLASTIC = ("j2", "drucker-prager", "mohr-coulomb")
WORDS = {"split": SPLITS, "fit": FITS}  # parameters that are words, and their choices
MODELS = ("3d", "plane_strain", "plane_stress", "axisymmetric")
NEWTON = ("full", "modified", "periodic", "bfgs", "snes")
LINEAR = ("lu", "gamg")
CONDITIONS = ("displacement", "traction", "pressure", "contact")
OBSTACLES = {"plane": ("point", "normal"), "sphere": ("center", "radius")}


class CaseError(ValueError):
    """Everything wrong with a case file, one problem per line."""

    def __init__(self, problems: list[str]):
        self.problems = problems
        super().__init__("\n".join(problems))


@dataclass
class Condition:
    """A boundary condition on a physical group."""

    group: str
    kind: str  # displacement | traction | pressure | contact
    value: object  # components (None = free), a vector, a pressure, or the obstacle table
    follower: bool = False
    key: str = ""  # where it is in the file, for messages
    start: object = None  # a load's value at load factor 0 ({ from, to }); None: 0


@dataclass
class Probe:
    """A point where displacement and von Mises stress are reported every step."""

    name: str
    point: list[float]
    key: str = ""


@dataclass
class Case:
    """A problem as data: mesh, material, conditions, load path, solver, probes."""

    path: Path
    mesh_file: Path
    mesh_size: float | None
    model: str
    degree: int
    law: str
    parameters: dict[str, float]
    conditions: list[Condition]
    factors: list[float]  # the load factors to reach, in order
    adaptive: bool
    equal_steps: bool  # factors are k/n (loading.steps = n)
    arc: dict | None = None  # control = "arc-length": target, arc_length, max_arc_length,
    # max_steps
    newton: str = "full"
    linear_solver: str = "lu"
    tolerance: float = 1e-9
    max_it: int = 50
    probes: list[Probe] = field(default_factory=list)
    formulation: str = "displacement"  # or "mixed": Taylor–Hood (u, p), materials.mixed
    refine_near: dict | None = None  # .geo: groups, size, distance (`case.mesh`)
    time: dict | None = None  # a viscous law's time axis: end, steps, adaptive, tolerance,
    # stationary, and factor (the load factor against time, [[t, f], ...])
    # [[material]]: (group, law, parameters, unit_weight or None), in the file's order
    groups: list[tuple[str, str, dict, float | None]] | None = None
    pairs: list[dict] = field(default_factory=list)  # [[contact]]: slave, master, friction, key
    # [initial_stress]: stress 3x3 (the model's components), or {unit_weight, K0, surface}
    initial_stress: list | dict | None = None
    # [[stage]]: name, remove, add (cell groups), steps; with [[material]] groups, leave
    # and arrive (the parts' names, `parts`)
    stages: list[dict] = field(default_factory=list)
    # [[material]] tables as parts (`_parts`): name, group, law, parameters, unit_weight,
    # start (present at the start); None with one [material]
    parts: list[dict] | None = None

    @property
    def law_name(self) -> str:
        """The law, or each group's: "linear-elastic (ball), neo-hookean (block)"."""
        if self.groups is None:
            return self.law
        return ", ".join(f"{law} ({group})" for group, law, _, _ in self.groups)

    def laws(self) -> list[tuple[dict | None, laws.Material]]:
        """(part, law) of each [[material]]; [(None, the material)] for [material].

        A part present at the start whose law takes an initial stress has the case's.
        """
        if self.parts is None:
            return [(None, self.material())]
        out = []
        for part in self.parts:
            extra = {}
            if part["start"] and part["law"] in INITIAL and self.initial_stress is not None:
                extra = {"initial_stress": self._initial_stress()}
            out.append((part, LAWS[part["law"]](**part["parameters"], **extra)))
        return out

    @property
    def dim(self) -> int:
        """Geometric dimension of the model."""
        return 3 if self.model == "3d" else 2

    def material(self) -> laws.Material:
        """The material law with its parameters (validated by the law).

        With its initial stress, if the case gives one.
        """
        extra = {} if self.initial_stress is None else {
            "initial_stress": self._initial_stress()}
        return LAWS[self.law](**self.parameters, **extra)

    def _initial_stress(self):
        s0 = self.initial_stress
        return dict(s0) if isinstance(s0, dict) else tuple(map(tuple, s0))


class _Reader:
    """Typed look-ups in the TOML tables, collecting problems instead of stopping."""

    def __init__(self):
        self.problems: list[str] = []

    def fail(self, key: str, message: str) -> None:
        self.problems.append(f"{key}: {message}")

    def table(self, data: dict, name: str, allowed: tuple[str, ...], required: bool = True):
        value = data.get(name)
        if value is None:
            if required:
                self.fail(name, "missing table")
            return {}
        if not isinstance(value, dict):
            self.fail(name, "must be a table [" + name + "]")
            return {}
        value = renamed(value, name, allowed)  # an old key is read, and said
        self.unknown(value, name, allowed)
        return value

    def tables(self, data: dict, name: str, each: str = "") -> list[dict]:
        """The [[name]] tables ([] if none, or if they are not tables: said)."""
        tables = data.get(name, [])
        if not isinstance(tables, list) or not all(isinstance(t, dict) for t in tables):
            self.fail(name, f"must be [[{name}]] tables{each}")
            return []
        return tables

    def unknown(self, table: dict, where: str, allowed: tuple[str, ...]) -> None:
        for k in table:
            if k not in allowed:
                near = difflib.get_close_matches(k, allowed, n=1)
                hint = f"did you mean {near[0]!r}? " if near else ""
                self.fail(f"{where}.{k}", f"unknown key ({hint}accepted: {', '.join(allowed)})")

    def get(self, table: dict, key: str, where: str, kind, *, default=None, required=False,
            choices=None, positive=False, minimum=None):
        name = f"{where}.{key}"
        if key not in table:
            if required:
                self.fail(name, "missing" + (f" (one of {', '.join(choices)})" if choices
                                             else ""))
            return default
        value = table[key]
        if kind is float and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if not isinstance(value, kind) or (isinstance(value, bool) and kind is not bool):
            self.fail(name, f"must be {_kind_name(kind)}, got {value!r}")
            return default
        if choices is not None:
            value = canonical(value, name)  # an old spelling is read, and said
        if choices is not None and value not in choices:
            self.fail(name, f"{value!r} is not one of {', '.join(choices)}")
            return default
        if kind is float and not math.isfinite(value):
            self.fail(name, f"must be a finite number, got {value!r}")
            return default
        if positive and not value > 0:
            self.fail(name, f"must be > 0, got {value!r}")
            return default
        if minimum is not None and value < minimum:
            self.fail(name, f"must be >= {minimum}, got {value!r}")
            return default
        return value

    def vector(self, value, name: str, n: int, free: bool = False):
        """A list of n finite numbers (or "free" where `free`); None if wrong."""
        if not isinstance(value, list) or len(value) != n:
            self.fail(name, f"must be a list of {n} components (the model is {n}D), got "
                            f"{value!r}")
            return None
        out = []
        for v in value:
            if free and v == "free":
                out.append(None)
            elif isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v):
                out.append(float(v))
            else:
                accepted = 'a finite number or "free"' if free else "a finite number"
                self.fail(name, f"component {v!r} is not {accepted}")
                return None
        return out


def _kind_name(kind) -> str:
    return {float: "a number", int: "an integer", str: "a string", bool: "true or false",
            list: "a list", dict: "a table"}.get(kind, kind.__name__)


def read_case(path: str | Path) -> Case:
    """The case in `path`, or CaseError listing every problem found in the file itself.

    What needs the mesh (group names, dimension, probe points) is checked by
    `fenics_nl.case.problem.CaseProblem`.
    """
    path = Path(path)
    if not path.is_file():
        raise CaseError([f"{path}: no such case file"])
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as err:
        raise CaseError([f"{path}: not valid TOML: {err}"]) from None
    r = _Reader()
    r.unknown(data, "case", ("mesh", "material", "initial_stress", "boundary", "contact",
                             "loading", "solver", "probe", "stage"))

    m = r.table(data, "mesh", ("file", "size", "model", "degree", "formulation",
                               "refine_near"))
    file = r.get(m, "file", "mesh", str, required=True)
    size = r.get(m, "size", "mesh", float, positive=True)
    model = r.get(m, "model", "mesh", str, required=True, choices=MODELS)
    degree = r.get(m, "degree", "mesh", int, default=1, minimum=1)
    mesh_file = None
    if file is not None:
        mesh_file = (path.parent / file).resolve()
        if mesh_file.suffix not in (".msh", ".geo"):
            r.fail("mesh.file", f"{file!r} must be a .msh or a .geo file")
        elif not mesh_file.is_file():
            r.fail("mesh.file", f"{mesh_file} not found")
        elif model is not None:
            _require_mesh_fits(mesh_file, model)
        if size is not None and mesh_file.suffix == ".msh":
            r.fail("mesh.size", "applies to a .geo only (a .msh is already meshed)")
    refine_near = _refine_near_table(r, m.get("refine_near"))
    if refine_near is not None and mesh_file is not None and mesh_file.suffix == ".msh":
        r.fail("mesh.refine_near", "applies to a .geo only (a .msh is already meshed)")
    if degree is not None and degree > 3:
        r.fail("mesh.degree", f"must be 1, 2 or 3, got {degree}")
    formulation = r.get(m, "formulation", "mesh", str, default="displacement",
                        choices=("displacement", "mixed"))
    if formulation == "mixed" and degree is not None and degree < 2:
        r.fail("mesh.formulation", f'"mixed" is Taylor–Hood: it needs degree >= 2, got {degree}')
    if formulation == "mixed" and model == "plane_stress":
        r.fail("mesh.formulation", '"mixed" has no plane-stress form (no volume constraint)')
    dim = 3 if model == "3d" else 2

    law, parameters, groups = _material(r, data, model)
    if groups is not None and formulation == "mixed":
        r.fail("mesh.formulation", '"mixed" takes one [material]: [[material]] groups are '
                                   "the displacement formulation's")
    if (law in ("j2", *VISCOUS) and model == "plane_stress" and degree is not None
            and degree > 2):
        # ε_zz needs one function per quadrature point (materials.plane_stress): P3's rule
        # on a triangle has 12 points, and no discontinuous space has 12 functions
        r.fail("mesh.degree", f"{law} in plane stress takes degree 1 or 2, got {degree}")
    if (parameters.get("nu") == 0.5 and formulation != "mixed" and model != "plane_stress"
            and groups is None):
        r.fail("material.nu", '0.5 (incompressible) needs mesh.formulation = "mixed"')
    conditions = _conditions(r, data, dim, law, model)
    factors, adaptive, arc = _loading(r, data)
    pairs = _pairs(r, data)
    tables = data.get("contact", [])  # wear given (even wrong: said once, where it is)
    wearing = isinstance(tables, list) and any(isinstance(t, dict) and "wear" in t
                                               for t in tables)
    time_axis = _time_axis(r, data, law, wearing)
    if law in SOILS and formulation == "mixed":
        r.fail("mesh.formulation", f'{law} takes the displacement formulation (its '
                                   "flow dilates: the mixed form's volumetric split is J2's)")
    if law == "norton" and formulation != "mixed" and model not in (None, "plane_stress"):
        r.fail("mesh.formulation", 'norton needs "mixed": its flow is incompressible and '
                                   "grows without bound, and P2 displacements alone lock "
                                   "(the stresses drift step after step)")
    if law in VISCOUS:
        for c in conditions:
            if c.kind == "contact":
                r.fail(c.key, f"{law}: no contact (an undone time step does not put the "
                              "active set back)")
    s = r.table(data, "solver", ("newton", "linear_solver", "tolerance", "max_it"),
                required=False)
    newton = r.get(s, "newton", "solver", str, default="full", choices=NEWTON)
    linear = r.get(s, "linear_solver", "solver", str, default="lu", choices=LINEAR)
    tolerance = r.get(s, "tolerance", "solver", float, default=1e-9, positive=True)
    if tolerance is not None and tolerance >= 1:
        r.fail("solver.tolerance", f"must be < 1 (relative to the force scale), got {tolerance}")
    max_it = r.get(s, "max_it", "solver", int, default=50, minimum=1)
    if newton == "snes" and any(c.kind == "contact" for c in conditions):
        r.fail("solver.newton", '"snes" cannot run the contact active-set loop: use full, '
                                "modified, periodic or bfgs")
    if arc is not None:
        for key, message in arc_length_obstacles(law, newton, conditions):
            r.fail(key, message)
    if law in DAMAGE:
        _damage_limits(r, law, model, formulation, newton, linear, conditions)
    unsymmetric = [(g[2]["psi"], g[2]["phi"]) for g in (groups or [(None, law, parameters)])
                   if g[1] in SOILS and g[2].get("psi") is not None
                   and g[2].get("phi") is not None and g[2]["psi"] < g[2]["phi"]]
    if unsymmetric:
        psi, phi = unsymmetric[0]
        # a tangent that is not symmetric: MUMPS's LU takes it, CG does not
        if linear == "gamg":
            r.fail("solver.linear_solver", f"gamg is CG: psi = {psi} < phi = {phi} makes the "
                                           "tangent not symmetric; use lu")
        for c in conditions:
            if c.kind == "contact":
                r.fail(c.key, f"psi = {psi} < phi = {phi} (a tangent not symmetric) with a "
                              "rigid obstacle: not built (its solves reuse a factorization "
                              "under CG)")
    if pairs:
        law_key = "material.law" if groups is None else next(
            f"material[{i}].law" for i, g in enumerate(groups, start=1) if g[1] == law)
        _pair_limits(r, pairs, degree, formulation, law, law_key, newton, linear,
                     conditions, arc)
    probes = _probes(r, data, dim)
    if arc is not None and arc["stop"] is not None and model is not None:
        tables = data.get("probe", [])
        names = [t.get("name") for t in tables if isinstance(t, dict)] if isinstance(
            tables, list) else []
        _check_stop(r, arc["stop"], [n for n in names if isinstance(n, str)], model)
    # (read before the problems are said: each table's own problems among them)
    initial_stress = _initial_stress(r, data, law, model, groups)
    stages = _stages(r, data, law, model, groups, formulation, conditions, pairs, arc,
                     time_axis)
    parts = _parts(r, groups, stages, initial_stress)
    if r.problems:
        raise CaseError(r.problems)
    equal = isinstance(data.get("loading", {}).get("steps"), int)
    return Case(path, mesh_file, size, model, degree, law, parameters, conditions, factors,
                adaptive, equal, arc, newton, linear, tolerance, max_it, probes, formulation,
                refine_near, time_axis, groups, pairs, initial_stress, stages, parts)


STAGED = ("linear-elastic", "power-law", "j2", *SOILS)  # the laws a case digs in


def _stages(r: _Reader, data: dict, law, model, groups, formulation, conditions, pairs, arc,
            time_axis) -> list[dict]:
    """[[stage]]: construction stages after the loading, each removing and adding groups."""
    tables = r.tables(data, "stage", ", one per stage")
    out, names = [], set()
    for i, t in enumerate(tables, start=1):
        where = f"stage[{i}]"
        r.unknown(t, where, ("name", "remove", "add", "steps"))
        name = r.get(t, "name", where, str, required=True)
        if name in names:
            r.fail(f"{where}.name", f"{name!r} names an earlier stage too")
        names.add(name)
        lists = {}
        for key in ("remove", "add"):
            value = lists[key] = t.get(key, [])
            if not (isinstance(value, list) and all(isinstance(g, str) for g in value)):
                r.fail(f"{where}.{key}", f"must be a list of cell groups, got {value!r}")
                lists[key] = []
        if not (lists["remove"] or lists["add"]) and "remove" in t:
            r.fail(where, "removes and adds nothing: give remove or add a cell group")
        elif not (lists["remove"] or lists["add"]):
            r.fail(f"{where}.remove", "missing: the cell groups it digs out (or add: those "
                                      "it builds)")
        steps = r.get(t, "steps", where, int, default=1, minimum=1)
        out.append({"name": name, **lists, "steps": steps})
    if not out:
        return out
    used = [law] if groups is None else [g[1] for g in groups]
    off = [name for name in dict.fromkeys(used) if name is not None and name not in STAGED]
    reasons = [(bool(off), f"the laws {', '.join(STAGED)} (not {', '.join(off)})"),
               (formulation == "mixed", "the displacement formulation"),
               (model == "plane_stress", "plane strain, axisymmetric or 3D models"),
               (bool(pairs) or any(c.kind == "contact" for c in conditions), "no contact"),
               (arc is not None, "load steps (not arc-length)"),
               (time_axis is not None, "no time axis")]
    for failed, needs in reasons:
        if failed:
            r.fail("stage", f"construction stages take {needs}")
    return out


def _parts(r: _Reader, groups, stages: list[dict], initial_stress) -> list[dict] | None:
    """The [[material]] tables as parts that come and go with the stages.

    A group's tables follow one another: the first is there from the start unless a stage
    adds the group as many times as it has tables; each `add` of the group brings its next
    table, once the one before has been removed (by that stage or an earlier one). Each
    stage gets `leave` and `arrive`: [(part name, group)]. None with one [material].
    """
    if groups is None:
        for i, st in enumerate(stages, start=1):
            if st["add"]:
                r.fail(f"stage[{i}].add", "needs [[material]] groups: what arrives is a cell "
                                          "group's [[material]] table (its law)")
        return None
    tables: dict[str, list[int]] = {}
    for k, (group, *_) in enumerate(groups):
        tables.setdefault(group, []).append(k)
    adds = {g: sum(g in st["add"] for st in stages) for g in tables}
    parts, present, coming = [], {}, {}
    for group, ks in tables.items():
        n, a = len(ks), adds[group]
        if a not in (n - 1, n):
            r.fail("material", f"{group!r} has {n} [[material]] table(s) and {a} stage(s) add "
                               "it: each table after the first arrives when a stage adds the "
                               "group (the first too, if stages add it once per table)")
            continue
        names = [group] if n == 1 else [f"{group}.{j}" for j in range(1, n + 1)]
        for name in names if n > 1 else []:  # (a part's name is its checkpoint's)
            if name in tables:
                r.fail("material", f"{group!r}'s tables are the parts {', '.join(names)}, "
                                   f"and {name!r} is a cell group too: rename it")
        for j, (k, name) in enumerate(zip(ks, names, strict=True)):
            _, law, parameters, gamma = groups[k]
            start = j == 0 and a == n - 1
            parts.append({"name": name, "group": group, "law": law, "parameters": parameters,
                          "unit_weight": gamma, "start": start})
            where = f"material[{k + 1}]"
            if start and gamma is not None:
                r.fail(f"{where}.unit_weight", "only for a part a [[stage]] adds (the ground "
                                               "present at the start weighs [initial_stress]'s "
                                               "unit_weight)")
            if start and initial_stress is not None and law not in INITIAL:
                r.fail(f"{where}.law", f"{law} takes no initial stress: its cells, present at "
                                       "the start, would be out of balance under "
                                       "[initial_stress] (make it arrive in a [[stage]], add)")
        present[group] = names[0] if a == n - 1 else None
        coming[group] = names[1:] if a == n - 1 else names
    if initial_stress is not None and tables and not any(
            p["start"] and p["law"] in INITIAL for p in parts):
        r.fail("initial_stress", f"no part present at the start takes it (a soil's law, "
                                 f"{', '.join(INITIAL)})")
    for i, st in enumerate(stages, start=1):
        st["leave"], st["arrive"] = [], []
        for key, to in (("remove", "leave"), ("add", "arrive")):
            for group in st[key]:
                if group not in present:
                    if group not in tables:
                        r.fail(f"stage[{i}].{key}", f"{group!r} is not a [[material]] group "
                                                    f"(they are: {', '.join(tables)})")
                    continue
                there = present[group]
                if key == "remove" and there is None:
                    r.fail(f"stage[{i}].remove", f"{group!r} is not there to remove (removed "
                                                 "already, or not yet added: a group the "
                                                 "stages add once per table is absent at the "
                                                 "start)")
                elif key == "add" and there is not None:
                    r.fail(f"stage[{i}].add", f"{group!r} is still there ({there}): remove it "
                                              "in this stage or an earlier one")
                elif key == "remove":
                    st[to].append((there, group))
                    present[group] = None
                else:
                    present[group] = coming[group].pop(0)
                    st[to].append((present[group], group))
    return parts


def arc_length_obstacles(law: str, newton: str, conditions: list[Condition]
                         ) -> list[tuple[str, str]]:
    """Why a case cannot take control = "arc-length": (key, message) pairs, [] if it can."""
    out = []
    if newton == "snes":
        out.append(("solver.newton", '"snes" has no arc-length control: use full, modified, '
                                     "periodic or bfgs"))
    for c in conditions:
        if c.kind == "contact" or (c.kind == "displacement" and any(c.value or [])):
            out.append((c.key, "arc-length control scales loads only: a contact or a "
                               "prescribed non-zero displacement cannot take part"))
    if law == "j2-finite":  # its commit may refuse a step, which only load steps cut
        out.append(("loading.control", 'j2-finite is driven by load steps (its commit may '
                                       'refuse a step too large, and a step is cut): remove '
                                       'control = "arc-length"'))
    if law in DAMAGE:
        out.append(("loading.control", f"{law}: the damage is irreversible and the load "
                                       "driven step by step: no arc-length control"))
    return out


def _pairs(r: _Reader, data: dict) -> list[dict]:
    """The [[contact]] pairs: slave and master facet groups, Coulomb's f."""
    tables = r.tables(data, "contact", ", one per pair")
    out = []
    for i, t in enumerate(tables, start=1):
        where = f"contact[{i}]"
        r.unknown(t, where, ("slave", "master", "friction", "wear", "speed"))
        slave = r.get(t, "slave", where, str, required=True)
        master = r.get(t, "master", where, str, required=True)
        f = r.get(t, "friction", where, float, default=0.0, minimum=0.0)
        wear = r.get(t, "wear", where, float, default=0.0, minimum=0.0)
        speed = r.get(t, "speed", where, float, default=None, positive=True)
        if wear and "speed" not in t:
            r.fail(f"{where}.speed", "missing: wear = k slides the slave over the master at "
                                     "this speed (distance per unit time: Archard's "
                                     "ds = speed dt)")
        if speed is not None and not wear and "wear" not in t:
            r.fail(f"{where}.speed", "only with wear = k (the sliding that wears)")
        if wear and f:
            r.fail(f"{where}.wear", "with friction: not built (the wear's compliance is in "
                                    "the frictionless loop): give friction = 0, or no wear")
        if slave is not None and slave == master:
            r.fail(f"{where}.master", f"{master!r} is the slave group too: a pair is two "
                                      "surfaces")
        if any((p["slave"], p["master"]) == (slave, master) for p in out):
            r.fail(where, f"the pair {slave!r} on {master!r} is given twice")
        elif slave is not None and master is not None and f is not None:
            out.append({"slave": slave, "master": master, "friction": f, "key": where,
                        "wear": wear or 0.0, "speed": speed})
    return out


def _pair_limits(r: _Reader, pairs, degree, formulation, law, law_key, newton, linear,
                 conditions, arc) -> None:
    """What a case with [[contact]] pairs cannot take, each said (`contact.pair`'s reach)."""
    if degree is not None and degree != 1:
        r.fail("mesh.degree", f"contact pairs take degree 1 (node to segment or triangle), "
                              f"got {degree}")
    if formulation == "mixed":
        r.fail("mesh.formulation", "contact pairs take the displacement formulation")
    if law is not None and law not in STATE_FREE:
        r.fail(law_key, f"{law}: contact pairs take laws without internal variables "
                               f"({', '.join(STATE_FREE)})")
    if newton not in (None, "full"):
        r.fail("solver.newton", "contact pairs run their own Newton on the saddle point "
                                '(full): remove newton or set "full"')
    if linear not in (None, "lu"):
        r.fail("solver.linear_solver", 'contact pairs solve their saddle point by "lu" '
                                       "(MUMPS)")
    for c in conditions:
        if c.kind == "contact":
            r.fail(c.key, "a rigid obstacle and [[contact]] pairs in one case: not yet (one "
                          "active set of either kind)")
    if arc is not None:
        r.fail("loading.control", "arc-length control scales loads only: contact pairs "
                                  "cannot take part")


def _require_mesh_fits(mesh_file: Path, model: str) -> None:
    """CaseError, alone, if the mesh's dimension does not fit the model.

    Every other line (the components of each vector, the supports) would count against the
    wrong dimension and mislead: this is the one thing to say.
    """
    from fenics_nl.case.mesh import geometry_dimension

    found, want = geometry_dimension(mesh_file), 3 if model == "3d" else 2
    if found is not None and found != want:
        raise CaseError([f"mesh.model: {model!r} needs a {want}D mesh, {mesh_file.name} has "
                         f"{found}D cells"])


def _damage_limits(r: _Reader, law: str, model, formulation, newton, linear, conditions
                   ) -> None:
    """What a gradient damage case cannot have: each one line."""
    if model == "plane_stress":
        r.fail("mesh.model", f"{law} has no plane-stress form: use plane_strain, 3d or "
                             "axisymmetric")
    if formulation == "mixed":
        r.fail("mesh.formulation", f"{law} is in the displacement formulation only")
    if newton != "full" or linear != "lu":
        r.fail("solver.newton" if newton != "full" else "solver.linear_solver",
               f"{law} is solved by alternate minimization, its u-solves by full Newton with "
               "LU: newton = \"full\", linear_solver = \"lu\"")
    for c in conditions:
        if c.kind == "contact":
            r.fail(f"{c.key}", f"{law}: no contact (the damage case has no active set)")


def _material(r: _Reader, data: dict, model: str | None):
    """(law, parameters, groups): one [material], or [[material]] tables by cell group.

    With groups, `law` and `parameters` are the plastic group's if one is (its law is the
    only plastic one), else the first group's: what the checks of a single law read (the
    state-free laws pass them all alike); `groups` lists (group, law, parameters,
    unit_weight); else `groups` is None.
    """
    m = data.get("material")
    if isinstance(m, list) and m and all(isinstance(t, dict) for t in m):
        return _materials_by_group(r, m, model)
    if not isinstance(m, dict):
        r.fail("material", "missing table" if m is None else
               "must be a table [material] or [[material]] tables, one per cell group")
        return None, {}, None
    return (*_one_material(r, m, "material", model), None)


def _materials_by_group(r: _Reader, tables: list[dict], model: str | None):
    groups = []
    for i, t in enumerate(tables, start=1):
        where = f"material[{i}]"
        group = r.get(t, "group", where, str, required=True)
        gamma = r.get(t, "unit_weight", where, float, minimum=0.0)
        law, parameters = _one_material(
            r, {k: v for k, v in t.items() if k not in ("group", "unit_weight")}, where, model)
        if law is not None and law not in (*STATE_FREE, *GROUP_PLASTIC):
            r.fail(f"{where}.law", f"{law} in a [[material]] group: not built (groups take "
                                   f"{', '.join(STATE_FREE + GROUP_PLASTIC)}); or one "
                                   "[material] for all")
        elif law in GROUP_PLASTIC and model == "plane_stress":
            r.fail(f"{where}.law", f"{law} in plane stress takes one [material] (its "
                                   "out-of-plane strain is an unknown of the whole mesh)")
        if parameters.get("nu") == 0.5 and model != "plane_stress":
            r.fail(f"{where}.nu", "0.5 needs the mixed formulation, which [[material]] groups "
                                  "do not take")
        if group is not None and law is not None:
            groups.append((group, law, parameters, gamma))
    plastic = list(dict.fromkeys(law for _, law, _, _ in groups if law in GROUP_PLASTIC))
    if len(plastic) > 1:
        r.fail("material", f"one plastic law in [[material]] groups, got {', '.join(plastic)}"
                           " (give the layers one law, each its parameters)")
    if len({LAWS[law].finite_strain for _, law, _, _ in groups}) > 1:
        kinds = {k: ", ".join(f"{law} ({g})" for g, law, _, _ in groups
                              if LAWS[law].finite_strain == (k == "finite"))
                 for k in ("small", "finite")}
        r.fail("material", f"all groups small strain or all finite strain (one kinematics "
                           f"for the bodies): small strain {kinds['small']}; finite strain "
                           f"{kinds['finite']} (saint-venant-kirchhoff and neo-hookean are "
                           "finite strain)")
    if not groups:
        return None, {}, None
    governing = next((g for g in groups if g[1] in GROUP_PLASTIC), groups[0])
    return governing[1], governing[2], groups


def _parameters(law) -> list:
    """A law's parameters a [material] table gives.

    Its init fields: not its state, nor what another table gives ([initial_stress]).
    """
    return [f for f in fields(law) if f.init and f.metadata.get("case", True)]


def _one_material(r: _Reader, m: dict, where: str, model: str | None):
    law = r.get(m, "law", where, str, required=True, choices=tuple(LAWS))
    if law is None:  # still name a misspelt key (lawe = ...) beside the missing law
        every = {f.name for cls in LAWS.values() for f in _parameters(cls)}
        r.unknown(m, where, ("law", *sorted(every)))
        return None, {}
    params = _parameters(LAWS[law])
    accepted = tuple(f.name for f in params)
    r.unknown(m, where, ("law", *accepted))
    parameters = {}
    defaults = OPTIONAL.get(law, {})
    for f in params:  # every parameter but a documented optional one: say it
        kind = str if f.name in WORDS else float
        value = r.get(m, f.name, where, kind, required=f.name not in defaults,
                      default=defaults.get(f.name), choices=WORDS.get(f.name))
        if value is not None:
            parameters[f.name] = value
    if all(f.name in parameters or f.name in defaults for f in params):
        try:
            LAWS[law](**parameters)
        except ValueError as err:  # the law's range check: "nu must be in (-1, 0.5], ..."
            name, _, rest = str(err).partition(" ")
            r.fail(f"{where}.{name}" if name in parameters else where, rest or name)
    if law in ("neo-hookean", "power-law", "j2-finite", *SOILS) and \
            model == "plane_stress":
        r.fail(f"{where}.law", f"{law} has no plane-stress form: use mesh.model = "
                               f"\"plane_strain\" or another law")
    return law, parameters


INITIAL = SOILS  # the laws that take an initial (in-situ) stress
GEOSTATIC = ("unit_weight", "K0", "surface")  # the ground's weight and stress ratio


def _initial_stress(r: _Reader, data: dict, law, model, groups) -> list | dict | None:
    """[initial_stress]: a uniform stress, or a geostatic one with the ground's weight.

    stress = 3x3 in the model's components (as the probes report it); or unit_weight, K0,
    surface: the vertical stress −γ times the depth below the surface, on the mesh's last
    axis, K0 times it across, and the ground's weight as a body force, held. The soils'
    laws (`INITIAL`); with [[material]] groups, the soil's parts present at the start (`_parts`
    refuses another law there). Its equilibrium with the loads at load factor 0 and
    the supports is the problem's to check (it has the mesh).
    """
    t = data.get("initial_stress")
    if t is None:
        return None
    where = "initial_stress"
    if not isinstance(t, dict):
        r.fail(where, "must be a table: stress = [[...], [...], [...]]")
        return None
    r.unknown(t, where, ("stress", *GEOSTATIC))
    if law is not None and law not in INITIAL:
        r.fail(where, f"taken by {', '.join(INITIAL)} (the soils' laws), not {law}")
    if model == "plane_stress":
        r.fail(where, "not in plane stress")
    rows = t.get("stress")
    if any(k in t for k in GEOSTATIC):
        if rows is not None:
            r.fail(f"{where}.stress", "or unit_weight, K0, surface: not both")
        out = {k: r.get(t, k, where, float, required=True, positive=k != "surface")
               for k in GEOSTATIC}
        return None if None in out.values() else out
    if rows is None:
        r.fail(f"{where}.stress", "missing: 3 rows of 3 components, (x, y, z); axisymmetric "
                                  "(r, z, θ); or a geostatic unit_weight, K0, surface")
        return None
    if not (isinstance(rows, list) and len(rows) == 3):
        r.fail(f"{where}.stress", f"must be 3 rows of 3 components, got {rows!r}")
        return None
    stress = [r.vector(row, f"{where}.stress", 3) for row in rows]
    if any(row is None for row in stress):
        return None
    if any(stress[i][j] != stress[j][i] for i in range(3) for j in range(3)):
        r.fail(f"{where}.stress", "must be symmetric")
    elif law == "mohr-coulomb" and model != "3d" and (stress[0][2] != 0 or stress[1][2] != 0):
        r.fail(f"{where}.stress", f"in {model} the third direction is principal: the shears "
                                  "with it (rows 1 and 2, column 3) must be 0")
    return stress


def _ramp(r: _Reader, table: dict, key: str, dim: int | None):
    """A load `{ from = A, to = B }`: (A, B), a vector each (traction) or a number (pressure).

    It moves from A at load factor 0 to B at 1 (an in-situ stress's pressure on a cavity
    lowered to its support's). (None, None) if wrong (said).
    """
    r.unknown(table, key, ("from", "to"))
    ends = []
    for end in ("from", "to"):
        if end not in table:
            r.fail(f"{key}.{end}", "missing (a load { from = A, to = B } moves from A to B "
                                   "with the load factor)")
            ends.append(None)
        elif dim is None:
            ends.append(r.get(table, end, key, float))
        else:
            ends.append(r.vector(table[end], f"{key}.{end}", dim))
    if None in ends:
        return None, None
    return tuple(ends)


def _conditions(r: _Reader, data: dict, dim: int, law: str | None, model: str | None
                ) -> list[Condition]:
    tables = r.tables(data, "boundary")
    if not data.get("boundary"):  # (not tables: said by r.tables)
        r.fail("boundary", "no [[boundary]] table: a body needs supports and loads")
    out = []
    for i, t in enumerate(tables, start=1):
        where = f"boundary[{i}]"
        r.unknown(t, where, ("group", *CONDITIONS, "follower"))
        group = r.get(t, "group", where, str, required=True)
        kinds = [k for k in CONDITIONS if k in t]
        if len(kinds) != 1:
            r.fail(where, f"needs exactly one of {', '.join(CONDITIONS)}, got "
                          f"{', '.join(kinds) or 'none'}")
            continue
        kind = kinds[0]
        key = f"{where}.{kind}"
        follower = r.get(t, "follower", where, bool, default=False)
        if "follower" in t and kind != "pressure":
            r.fail(f"{where}.follower", "applies to a pressure only")
        if follower and kind == "pressure" and law is not None and not LAWS[law].finite_strain:
            r.fail(f"{where}.follower", f"needs a finite-strain law ({law} is small strain: "
                                        f"its loads act on the undeformed body)")
        if follower and kind == "pressure" and model == "plane_stress":
            r.fail(f"{where}.follower", "not in plane stress (the thickness change is not "
                                        "modelled): use plane_strain or 3d")
        start = None  # a load's value at load factor 0, if it moves { from, to }
        if kind == "displacement":
            value = r.vector(t[kind], key, dim, free=True)
        elif kind in ("traction", "pressure") and isinstance(t[kind], dict):
            start, value = _ramp(r, t[kind], key, dim if kind == "traction" else None)
        elif kind == "traction":
            value = r.vector(t[kind], key, dim)
        elif kind == "pressure":
            value = r.get(t, "pressure", where, float)
        else:
            value = _obstacle(r, t[kind], key, dim)
        if start is not None and follower:
            r.fail(f"{where}.follower", "not with { from, to } (a dead load from one value "
                                        "to another)")
        if group is not None and value is not None:
            out.append(Condition(group, kind, value, bool(follower), key, start))
    contact = [c for c in out if c.kind == "contact"]
    if len(contact) > 1:
        r.fail(contact[1].key, "one contact group per case (the active-set loop takes one "
                               "surface)")
    held = {}
    for c in out:
        if c.kind == "displacement":
            for i, value in enumerate(c.value):
                if value is not None and (c.group, i) in held:
                    r.fail(c.key, f"u_{COMPONENTS.get(model, 'xyz')[i]} of group {c.group!r} "
                                  f"is already prescribed by {held[(c.group, i)]}")
                elif value is not None:
                    held[(c.group, i)] = c.key
    if tables and not held and not contact:
        r.fail("boundary", "no displacement or contact condition: nothing holds the body "
                           "(it would move as a rigid body)")
    if model == "axisymmetric":
        for c in contact:
            ob = c.value
            if ob["obstacle"] == "sphere" and ob["center"][0] != 0:
                r.fail(f"{c.key}.center", "axisymmetric: the sphere is centred on the axis "
                                          "(r = 0); off the axis it would be a torus")
            if ob["obstacle"] == "plane" and ob["normal"][0] != 0:
                r.fail(f"{c.key}.normal", "axisymmetric: the plane is normal to the axis "
                                          "(normal = [0, ±1]); tilted it would be a cone")
            if ob["displacement"][0] != 0:
                r.fail(f"{c.key}.displacement", "axisymmetric: the obstacle moves along the "
                                                "axis only")
    return out


def _obstacle(r: _Reader, table, key: str, dim: int):
    if not isinstance(table, dict):
        r.fail(key, 'must be a table, e.g. { obstacle = "plane", point = [...], normal = [...] }')
        return None
    shape = r.get(table, "obstacle", key, str, required=True, choices=tuple(OBSTACLES))
    if shape is None:
        return None
    r.unknown(table, key, ("obstacle", *OBSTACLES[shape], "displacement"))
    out = {"obstacle": shape, "displacement": [0.0] * dim}
    for k in (*OBSTACLES[shape], "displacement"):
        if k == "radius":
            out[k] = r.get(table, k, key, float, required=True, positive=True)
        elif k in table:
            out[k] = r.vector(table[k], f"{key}.{k}", dim)
        elif k != "displacement":
            r.fail(f"{key}.{k}", "missing")
            out[k] = None
    if shape == "plane" and out.get("normal") is not None and not any(out["normal"]):
        r.fail(f"{key}.normal", "must not be zero")
    return None if any(v is None for v in out.values()) else out


def _loading(r: _Reader, data: dict):
    t = r.table(data, "loading", ("steps", "adaptive", "control", "time", "factor", *ARC_KEYS))
    if "time" in t:
        for k in ("steps", "adaptive", "control", *ARC_KEYS):
            if k in t:
                r.fail(f"loading.{k}", "not with time (the time axis takes end, steps, "
                                       "adaptive, tolerance, stationary in its braces)")
        return [], True, None
    if "factor" in t:
        r.fail("loading.factor", "only with time = { end = ..., steps = ... } (the load "
                                 "factor against time)")
    control = r.get(t, "control", "loading", str, default="load",
                    choices=("load", "arc-length"))
    if control == "arc-length":
        return [], True, _arc_length(r, t)
    for k in ARC_KEYS:
        if k in t:
            r.fail(f"loading.{k}", 'only with control = "arc-length"')
    adaptive = r.get(t, "adaptive", "loading", bool, default=True)
    steps = t.get("steps")
    if steps is None:
        if t:
            r.fail("loading.steps", "missing")
        return [], adaptive, None
    if isinstance(steps, int) and not isinstance(steps, bool):
        if steps < 1:
            r.fail("loading.steps", f"must be >= 1, got {steps}")
            return [], adaptive, None
        return [k / steps for k in range(1, steps + 1)], adaptive, None
    factors = r.vector(steps, "loading.steps", len(steps)) if isinstance(steps, list) else None
    if factors is None:
        if not isinstance(steps, list):
            r.fail("loading.steps", f"must be an integer or a list of load factors, got "
                                    f"{steps!r}")
        return [], adaptive, None
    if not factors or any(a == b for a, b in zip([0.0, *factors], factors, strict=False)):
        r.fail("loading.steps", "load factors must be a non-empty list, each different from "
                                "the one before (the first from 0)")
    return factors, adaptive, None


ARC_KEYS = ("target", "arc_length", "max_arc_length", "max_steps", "stop")
STOP_KEYS = ("probe", "component", "value")
# the displacement components a stop condition names, per model (as in the load-path plot)
COMPONENTS = {"3d": "xyz", "plane_strain": "xy", "plane_stress": "xy", "axisymmetric": "rz"}


def _arc_length(r: _Reader, t: dict) -> dict | None:
    """The parameters of control = "arc-length" (`solvers.arclength.ArcLength`)."""
    for k in ("steps", "adaptive"):
        if k in t:
            r.fail(f"loading.{k}", 'not with control = "arc-length" (the arc adapts itself; '
                                   "give target, arc_length, max_arc_length, max_steps)")
    arc = {"target": r.get(t, "target", "loading", float, default=1.0),
           "arc_length": r.get(t, "arc_length", "loading", float, default=0.1, positive=True),
           "max_arc_length": r.get(t, "max_arc_length", "loading", float, default=None,
                                   positive=True),
           "max_steps": r.get(t, "max_steps", "loading", int, default=100, minimum=1)}
    if arc["target"] == 0:
        r.fail("loading.target", "must not be 0 (the path starts there)")
    arc["stop"] = _stop(r, t.get("stop"))
    top, first = arc["max_arc_length"], arc["arc_length"]
    if top is not None and first is not None and top < first:
        r.fail("loading.max_arc_length", f"must be >= arc_length ({first}), got {top}")
    return arc


TIME_KEYS = ("end", "steps", "adaptive", "tolerance", "stationary")


def _time_axis(r: _Reader, data: dict, law: str | None, wearing: bool = False
               ) -> dict | None:
    """`loading.time` and `loading.factor`: a viscous law's or a pair's wear's time axis.

    None: none given.
    """
    t = data.get("loading", {})
    table = t.get("time") if isinstance(t, dict) else None
    viscous = law in VISCOUS
    if table is None:
        if viscous:
            r.fail("loading.time", f"missing: {law} is rate-dependent, its load path is in "
                                   "time, e.g. time = { end = 100.0, steps = 20 }")
        if wearing:
            r.fail("loading.time", "missing: a pair's wear slides in time (ds = speed dt), "
                                   "e.g. time = { end = 10.0, steps = 20 }")
        return None
    if wearing and isinstance(table, dict):
        for k in ("adaptive", "tolerance", "stationary"):
            if k in table:
                r.fail(f"loading.time.{k}", "not with wear: its steps are equal (backward "
                                            "Euler in the sliding distance, stable at any "
                                            "step)")
        table = {k: v for k, v in table.items() if k not in ("adaptive", "tolerance",
                                                             "stationary")}
        table["adaptive"] = False
    elif law is not None and not viscous:
        r.fail("loading.time", f"only with a rate-dependent law ({', '.join(VISCOUS)}) or "
                               f"a [[contact]] pair's wear: {law} has no time; give steps")
    where = "loading.time"
    if not isinstance(table, dict):
        r.fail(where, "must be a table, e.g. { end = 100.0, steps = 20 }")
        return None
    r.unknown(table, where, TIME_KEYS)
    axis = {"end": r.get(table, "end", where, float, required=True, positive=True),
            "steps": r.get(table, "steps", where, int, default=20, minimum=1),
            "adaptive": r.get(table, "adaptive", where, bool, default=True),
            "tolerance": r.get(table, "tolerance", where, float, default=1e-3, positive=True),
            "stationary": r.get(table, "stationary", where, float, default=1e-6,
                                positive=True)}
    points = t.get("factor", [[0.0, 1.0]])
    if not (isinstance(points, list) and points and all(
            isinstance(q, list) and len(q) == 2 for q in points)):
        r.fail("loading.factor", f"must be a list of [time, load factor] pairs, e.g. "
                                 f"[[0.0, 0.0], [1.0, 1.0]], got {points!r}")
        return None
    pairs = [r.vector(q, "loading.factor", 2) for q in points]  # each bad number said once
    if any(q is None for q in pairs):
        return None
    times = [q[0] for q in pairs]
    if times[0] != 0 or any(b <= a for a, b in itertools.pairwise(times)):
        r.fail("loading.factor", f"its times must start at 0 and increase, got {times}")
    elif axis["end"] is not None and times[-1] > axis["end"]:
        r.fail("loading.factor", f"its last time {times[-1]:g} is past the end "
                                 f"{axis['end']:g}")
    if not any(f for _, f in pairs):
        r.fail("loading.factor", "is 0 at every time: no load is applied")
    axis["factor"] = pairs
    return axis


def _refine_near_table(r: _Reader, table) -> dict | None:
    """`mesh.refine_near`: cells of `size` within `distance` of named boundary groups.

    The groups are checked against the mesh when it is meshed (`case.mesh`).
    """
    if table is None:
        return None
    where = "mesh.refine_near"
    if not isinstance(table, dict):
        r.fail(where, 'must be a table, e.g. { groups = ["hole"], size = 0.1, distance = 1.0 }')
        return None
    r.unknown(table, where, ("groups", "size", "distance"))
    groups = table.get("groups")
    if not (isinstance(groups, list) and groups and all(isinstance(g, str) for g in groups)):
        r.fail(f"{where}.groups", "missing" if groups is None else
               f"must be a non-empty list of group names, got {groups!r}")
        groups = None
    size = r.get(table, "size", where, float, required=True, positive=True)
    distance = r.get(table, "distance", where, float, required=True, positive=True)
    if None in (groups, size, distance):
        return None
    return {"groups": groups, "size": size, "distance": distance}


def _stop(r: _Reader, table) -> dict | None:
    """`loading.stop`: a probe's displacement component that ends the path when reached.

    Its probe and component are checked against the probes and the model later
    (`_check_stop`).
    """
    if table is None:
        return None
    if not isinstance(table, dict):
        r.fail("loading.stop", 'must be a table, e.g. { probe = "tip", component = "y", '
                               "value = -1.0 }")
        return None
    r.unknown(table, "loading.stop", STOP_KEYS)
    stop = {"probe": r.get(table, "probe", "loading.stop", str, required=True),
            "component": r.get(table, "component", "loading.stop", str, required=True),
            "value": r.get(table, "value", "loading.stop", float, required=True)}
    if stop["value"] == 0:
        r.fail("loading.stop.value", "must not be 0 (every displacement starts there)")
    return None if None in stop.values() or stop["value"] == 0 else stop


def _check_stop(r: _Reader, stop: dict, names: list[str], model: str) -> None:
    """The stop condition's probe is one of the case's, its component one of the model's.

    `names`: those the [[probe]] tables give, whether or not their points are right (a bad
    point is said once, by the probe's own check).
    """
    if stop["probe"] not in names:
        r.fail("loading.stop.probe", f"{stop['probe']!r} is not a [[probe]] of the case "
                                     f"(it has: {', '.join(names) or 'none'})")
    if stop["component"] not in tuple(COMPONENTS[model]):  # a letter, not a substring
        r.fail("loading.stop.component", f"{stop['component']!r} is not a displacement "
                                         f"component of the {model} model (one of "
                                         f"{', '.join(COMPONENTS[model])})")


def _probes(r: _Reader, data: dict, dim: int) -> list[Probe]:
    tables = r.tables(data, "probe")
    out, names = [], set()
    for i, t in enumerate(tables, start=1):
        where = f"probe[{i}]"
        r.unknown(t, where, ("name", "point"))
        name = r.get(t, "name", where, str, required=True)
        point = r.vector(t["point"], f"{where}.point", dim) if "point" in t else None
        if "point" not in t:
            r.fail(f"{where}.point", "missing")
        if name in names:
            r.fail(f"{where}.name", f"{name!r} is used twice")
        names.add(name)
        if name is not None and point is not None:
            out.append(Probe(name, point, f"{where}.point"))
    return out
