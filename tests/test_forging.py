"""The closed-die forging demo: a billet pressed into an oval cavity, in 3D, with a flash.

The flat start against the upsetting's closed form (exact at the penalty's penetration),
the forging's end (the ceiling covered, a flash, the load above the flat die's, the volume
kept to its elastic change), the
same answer on two ranks, one-line refusals.
"""

import math

import pytest

from fenics_nl.materials.finite_plasticity import FiniteJ2Plasticity
from fenics_nl.theory import forming

E, NU = 200e3, 0.3


def test_the_flat_start_is_the_homogeneous_closed_form_at_the_penetrated_height(demo):
    # frictionless, while the billet is under the cavity's flat ceiling alone (R < b − w
    # up to 17 % here): a homogeneous compression, but of a top that sits p/κ into the
    # die, p = F/(π R0²) the penalty's pressure on the reference face. At that height the
    # closed form holds to the area of the P2 mesh's quarter disc, whose arc its nodes
    # interpolate (measured −3.6e-6 at every step at the default size 2.5, asked 5e-6); at
    # the die's height it is off by the penetration's effect (about 1e-3)
    d = demo.json("forging.py", "--friction", "0", "--reduction", "0.15", "--steps", "3")
    law = FiniteJ2Plasticity(E, NU, sigma0=400.0, H=1000.0)
    assert d["flat_steps"] == len(d["force_history"])  # (the first step ramped up: 7)
    for r, F in zip(d["reduction_history"], d["force_history"], strict=True):
        penetration = F / (math.pi * 10.0**2) / d["penalty_stiffness"]
        at_top = r - 2 * penetration / 20.0
        assert F == pytest.approx(forming.frictionless_force(at_top, 10.0, law.yield_stress, E),
                                  rel=5e-6)
    assert 1e-5 < d["flat_force_error"] < 2e-3  # at the die's height: measured 9.0e-4
    # the homogeneous state at the top's height: the elastic volume change
    # J = exp(−σ_y (1 − 2ν)/E) of the mesh's own volume, and the top face's area in plan
    # J π R0² h0/h against the flat ceiling's, π a (b − w)²/b
    p = forming.homogeneous_plastic_strain(at_top, law.yield_stress, E)
    J = math.exp(-law.yield_stress(p) * (1 - 2 * NU) / E)
    assert d["volume_change"] == pytest.approx(J - 1, rel=1e-5)
    a, b, w = 15.5, 12.5, 1.5
    assert d["die_fill"] == pytest.approx(J * 10.0**2 / (1 - at_top) / (a * (b - w) ** 2 / b),
                                          rel=1e-5)
    assert d["flash_fraction"] == 0


def test_the_forging_fills_the_die_and_flashes(demo):
    # the defaults: the metal reaches the walls across, flows along the cavity and out
    # between the lands; the load rises above the flat die's as the flash holds it back.
    # The bounds are the run's figures (measured in comments) within what a change of mesh
    # moves them (benchmarks/forging.py: fill 0.88, 0.87, 0.84 at 3.4k, 7.4k, 19.6k
    # unknowns, the flash's reach 1.05–1.08, the load within 1.4 %; here 2205 unknowns)
    d = demo.json("forging.py")
    assert d["reduction"] == pytest.approx(0.42, rel=1e-12)
    assert d["die_fill"] > 0.8 and d["flash_reach"] > 0.8  # 0.928, 1.01
    assert 0.005 < d["flash_fraction"] < 0.05  # 0.013
    assert d["force"] > 1.3 * forming.frictionless_force(
        0.42, 10.0, FiniteJ2Plasticity(E, NU, sigma0=400.0, H=1000.0).yield_stress, E)  # 1.50
    # the flash's slab estimate, with the flash's own yield stress: measured 1.12
    assert 0.8 < d["force_over_slab"] < 1.4
    assert all(b > a for a, b in zip(d["force_history"][:-1], d["force_history"][1:],
                                     strict=True))
    # elastic only: −σ_m/K, K = 167 GPa and a mean pressure of about 0.8 GPa: −4.76e-3
    assert -1e-2 < d["volume_change"] < 0
    assert d["max_plastic_strain"] > 1.0


@pytest.mark.mpi
def test_two_ranks_give_the_serial_answer(demo):
    s, p = demo.json("forging.py"), demo.json("forging.py", ranks=2)
    assert p["ranks"] == 2
    for k in ("force", "die_fill", "max_plastic_strain", "volume_change"):
        assert p[k] == pytest.approx(s[k], rel=1e-7), k


@pytest.mark.parametrize("args,message", [
    (["--wall", "5"], "--wall must be below"), (["--reduction", "0.8"], "--reduction must be"),
    (["--cavity-length", "20"], "--cavity-length must be"), (["--friction", "-1"], "--friction"),
])
def test_bad_input_one_clear_line(args, message, demo):
    demo.refuses(["forging.py", *args], message)
