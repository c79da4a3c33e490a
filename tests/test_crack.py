"""Cracks that propagate (`demos/crack.py`): Miehe's notched square, the surfing crack."""

import itertools
import math

import pytest

# the documentation page's size (docs/notebooks.py SMALL): AT1, ell = 0.05 mm, h = ell/2,
# 8 displacement steps; its serial run is shared with the notebook's test
TENSION = ("--ell", "0.05", "--steps", "8")


def mesh_toughness(d):
    """Gc (1 + h/(c_w ell)): a crack of the mesh, a band of one cell at α = 1 (AT1)."""
    return 2.7e-3 * (1 + d["h"] / (8 / 3 * d["ell"]))


def test_a_notched_square_in_tension_breaks_straight_and_dissipates_the_mesh_toughness(demo):
    # once the crack has crossed the square its dissipated energy per unit width is the
    # mesh's toughness: -0.01 % measured, 1 % asked (the damage spread off the crack, which
    # grows as the broken square is pulled further: +0.6 % at three times the displacement)
    d = demo.json("crack.py", *TENSION)
    assert d["broken"] and d["crack_tip_history"][-1][0] == pytest.approx(1.0)
    assert d["crack_straightness"] <= d["h"] / 2 + 1e-12  # its tip stays on the band
    assert d["mesh_toughness"] == pytest.approx(mesh_toughness(d), rel=1e-12)
    assert d["dissipated_energy_per_width"] == pytest.approx(d["mesh_toughness"], rel=0.01)
    assert d["dissipated_energy_per_width_rel_error"] == pytest.approx(
        d["dissipated_energy_per_width"] / d["mesh_toughness"] - 1, rel=1e-12)
    # (D_end − D_1)/Δa: low by the damage ahead of the notch's tip, about Gc ell
    assert d["energy_release_rate_rel_error"] == pytest.approx(
        d["energy_release_rate"] / d["mesh_toughness"] - 1, rel=1e-12)
    F = d["force_history"]
    k = F.index(max(F))
    assert 0 < k < len(F) - 1 and d["peak_force"] == F[k]
    assert all(b > a for a, b in itertools.pairwise(F[:k + 1]))  # rising to the peak
    # broken, and pulled two steps further: the top is free, its force finite (the residual
    # stiffness's), no NaN anywhere
    assert F.index(F[-1]) >= k + 2 and all(math.isfinite(f) for f in F)
    assert F[-2] < 0.01 * F[k] and F[-1] < 0.01 * F[k]
    # the supports are in equilibrium with each other (no load on the body)
    top, bottom = d["reactions"]["top"], d["reactions"]["bottom"]
    assert top[1] == pytest.approx(F[-1], rel=1e-12)
    assert top[1] + bottom[1] == pytest.approx(0, abs=1e-9 * F[k])
    assert d["warnings"] == [] and d["dofs"] > 0 and d["newton_iterations"] > 0


def test_a_notched_square_in_shear_cracks_downwards(demo):
    # the volumetric split keeps the compressed upper side from damaging: the crack leaves
    # the notch towards the lower right and reaches the right side below the notch's line,
    # where the tension test's stays on it within h/2 (ell = 0.05 mm: at y = 0.44, 2.5 h
    # below; at the demo's ell = 0.03 mm, y = 0.22: the larger ell, the flatter the path)
    d = demo.json("crack.py", "--test", "shear", "--ell", "0.05", "--steps", "8")
    x, y = d["crack_tip_history"][-1]
    assert d["broken"] and x == pytest.approx(1.0)
    assert y < 0.5 - 2 * d["h"]
    assert all(b[1] <= a[1] + 1e-12 for a, b in itertools.pairwise(d["crack_tip_history"]))
    assert d["force_history"][-1] < 0.02 * d["peak_force"]
    # its length, and so its release rate, are not measured (it turns within a step)
    assert d["energy_release_rate"] is None and d["crack_straightness"] is None


def test_a_surfing_crack_in_the_demo_dissipates_the_mesh_toughness(demo):
    # the demo's defaults (AT1, ell = 0.03 mm, h = ell/2, 13 positions 2h apart): 2 dD/da
    # against Gc (1 + 2h/(c_w ell)) (a crack on the strip's symmetry line): -1.4 %, 2 % asked
    d = demo.json("crack.py", "--test", "surfing")
    assert d["mesh_toughness"] == pytest.approx(2.7e-3 * (1 + 2 * 0.015 / (8 / 3 * 0.03)),
                                                rel=1e-12)
    assert abs(d["energy_release_rate_rel_error"]) < 0.02 and d["warnings"] == []
    centres, tips = d["centre_history"], [x for x, _ in d["crack_tip_history"]]
    lags = [c - t for c, t in zip(centres[4:], tips[4:], strict=True)]
    assert max(lags) - min(lags) < 1e-9 and 0 <= d["tip_lag"] <= 2 * d["h"]


@pytest.mark.parametrize("args, words", [
    (["--ell", "0"], "--ell"),
    (["--Gc", "-1"], "--Gc"),
    (["--test", "bend"], "--test"),
    (["--ell", "0.05", "--steps", "1"], "--steps"),
    (["--resolution", "0.5"], "--resolution"),
    (["--test", "surfing", "--displacement", "0.01"], "moves its K-field"),
    (["--test", "surfing", "--steps", "30"], "the strip holds 14 positions"),
])
def test_crack_bad_input_is_one_line(demo, args, words):
    proc = demo.run(["crack.py", *args], check=False)
    assert proc.returncode == 2 and words in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_a_crack_coarser_than_two_cells_warns_with_what_it_costs(demo):
    # ell/h = 1.5: the warning names what a crack costs on this mesh, Gc (1 + h/(c_w ell)) =
    # 3.375e-3, and the broken square dissipates it (+0.2 %)
    d = demo.json("crack.py", "--ell", "0.05", "--resolution", "1.5", "--steps", "8")
    assert len(d["warnings"]) == 1 and "0.003375" in d["warnings"][0]
    assert d["broken"]
    assert d["dissipated_energy_per_width"] == pytest.approx(d["mesh_toughness"], rel=0.01)


@pytest.mark.mpi
def test_the_notched_square_on_two_ranks_is_the_serial_one(demo):
    s, p = demo.json("crack.py", *TENSION), demo.json("crack.py", *TENSION, ranks=2)
    assert p["ranks"] == 2 and p["crack_tip_history"] == s["crack_tip_history"]
    peak = s["peak_force"]  # the broken square's force is 1e-3 of it: compared to the peak
    assert p["force_history"] == pytest.approx(s["force_history"], rel=1e-6, abs=1e-6 * peak)
    assert p["dissipated_energy_history"] == pytest.approx(s["dissipated_energy_history"],
                                                           rel=1e-7)
