"""The course's local brittle damage law (`materials.damage`) on the bar (`demos/damage_bar.py`)."""

import math
from itertools import pairwise

import pytest


def test_the_uniform_bar_follows_the_closed_form_and_the_weak_spot_localizes(demo):
    d = demo.json("damage_bar.py")
    # σ = Eε, then w_c/ε: measured 2.8e-13 over 12 steps to 4 ε_c (a uniform state has no
    # discretization error; the homogeneous branch is kept because every point of the
    # threshold starts its step with the damaged secant)
    assert d["uniform_max_rel_error"] < 1e-10
    assert d["critical_stress"] == pytest.approx(math.sqrt(1e-4), rel=1e-12)
    assert max(d["stress_history"]) == pytest.approx(d["critical_stress"], rel=1e-10)
    # the weak first cell takes all the damage, and dissipates one cell's A h w_c ln(1/ρ):
    # measured -0.009 % on every mesh (the external work's trapezoid rule over the steps)
    table = d["mesh_table"]
    assert d["localized"] and [t["damaged_cells"] for t in table] == [1, 1, 1]
    for t in table:
        assert abs(t["dissipated_energy_rel_error"]) < 1e-3
        assert t["peak_stress"] <= d["weak_critical_stress"] * (1 + 1e-9)
    # halving h halves the energy it takes to break the bar: no length scale
    for coarse, fine in pairwise(table):
        assert fine["dissipated_energy"] / coarse["dissipated_energy"] == pytest.approx(
            0.5, rel=1e-3)


@pytest.mark.parametrize("args,words", [
    (["--weak", "1.5"], "--weak: must be <= 0.999"),
    (["--cells", "2"], "--cells: must be >= 3"),
    (["--stress-ratio", "0"], "--stress-ratio: must be > 0"),
    (["--wc", "-1"], "--wc: must be > 0"),
])
def test_damage_bar_bad_input_is_one_line(demo, args, words):
    proc = demo.run(["damage_bar.py", *args], check=False)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and words in lines[0], proc.stderr


def test_the_course_damage_law_refuses_what_it_cannot_be():
    from fenics_nl.materials.damage import CourseDamage

    with pytest.raises(ValueError, match="w_c"):
        CourseDamage(1.0, 0.0, w_c=0.0)
    law = CourseDamage(1.0, 0.0, w_c=1e-4)
    with pytest.raises(ValueError, match="bind"):
        law.energy(None)
    assert law.critical_strain == pytest.approx(1e-2) and law.critical_stress == pytest.approx(
        1e-2)


def test_damage_bar_at1_bifurcates_and_cracks_as_the_closed_forms_say(demo):
    # the demo's AT1 run, in 10 steps to 4 eps_c (no step at eps_c): the bar of L = 10 ell is
    # unstable as soon as it damages; the onset is where the driving force of the elastic
    # steps, affine in eps², vanishes, and the peak the elastic branch extended to it (both
    # exact for the homogeneous bar: measured 7e-14). A crack in a held bar dissipates
    # Gc (1 + h/(c_w ell)) per unit section: measured +0.035, -0.008, -0.011 % at h = ell/5.1,
    # ell/10.1, ell/20.1 (12 steps)
    d = demo.json("damage_bar.py", "--model", "at1", "--steps", "10")
    assert d["critical_stress"] == pytest.approx(d["critical_stress_exact"], rel=1e-9)
    assert d["critical_stress_exact"] == pytest.approx(math.sqrt(3 * 1.0 / (8 * 0.1)),
                                                       rel=2e-6)  # (1 + k), k = 1e-6
    assert d["uniform_max_rel_error"] < 1e-9
    assert d["bifurcation_strain"] == pytest.approx(d["bifurcation_strain_exact"], rel=1e-9)
    assert d["bifurcation_strain_exact"] == pytest.approx(d["critical_strain"], rel=1e-12)
    assert d["localized"] and max(d["largest_damage_history"]) > 0.99
    for t in d["mesh_table"]:
        assert abs(t["dissipated_energy_rel_error"]) < 0.01 and t["profile_max_error"] < 0.01
    assert d["warnings"] == []


@pytest.mark.parametrize("args,words", [
    (["--model", "at1", "--ell", "0"], "--ell: must be > 0"),
    (["--model", "at2", "--Gc", "-1"], "--Gc: must be > 0"),
    (["--model", "at3"], "--model"),
])
def test_gradient_damage_bar_bad_input_is_one_line(demo, args, words):
    proc = demo.run(["damage_bar.py", *args], check=False)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and words in lines[0], proc.stderr


def test_ell_below_two_elements_is_said_with_its_effective_toughness(demo):
    # ell = 1.5 h: a warning with Gc (1 + h/(c_w ell)) = 1.25, and that is what the crack
    # dissipates (per unit section, within 1 %): the answer is right, its Gc is not the user's
    d = demo.json("damage_bar.py", "--model", "at1", "--resolution", "1.5",
                  "--refinements", "1", "--steps", "6")
    t = d["mesh_table"][0]
    effective = 1 + t["h"] / (8 / 3 * 0.1)  # h = L/17: 1.225
    assert len(d["warnings"]) == 1 and f"{effective:.4g}" in d["warnings"][0]
    assert t["dissipated_energy"] / d["cross_section"] == pytest.approx(effective, rel=0.01)


@pytest.mark.mpi
def test_damage_bar_two_ranks_give_the_serial_answer(demo):
    s, p = demo.json("damage_bar.py"), demo.json("damage_bar.py", ranks=2)
    assert p["ranks"] == 2 and p["localized"]
    for a, b in zip(s["mesh_table"], p["mesh_table"], strict=True):
        assert b["dissipated_energy"] == pytest.approx(a["dissipated_energy"], rel=1e-8)
        assert b["steps"] == a["steps"]
    assert p["stress_history"] == pytest.approx(s["stress_history"], rel=1e-10)


@pytest.mark.parametrize("model", ["at1", "at2"])
def test_gradient_damage_homogeneous_bar_is_its_closed_form(model):
    homogeneous_gradient_damage_bar(model)


@pytest.mark.mpi
def test_gradient_damage_homogeneous_bar_on_two_ranks():
    homogeneous_gradient_damage_bar("at1")  # the same closed form, the bar cut in two


@pytest.mark.parametrize("model", ["at1", "at2"])
def test_the_volumetric_split_spares_compression_as_its_closed_form_says(model):
    # the bar held laterally (uniaxial strain; at ν = 0 the same state as uniaxial stress
    # while intact): in compression only the deviatoric energy (2/3 of E ε²/2) is degraded,
    # so AT1 damages from √(3/2) ε_c and keeps κ = E/3 when broken; in tension the split
    # changes nothing. Without the lateral hold a broken bar would carry no compression
    # either: with no shear stiffness left it bulges freely (tr ε = 0)
    homogeneous_gradient_damage_bar(model, split="volumetric", sign=-1)
    homogeneous_gradient_damage_bar(model, split="volumetric", sign=1, steps=3)


def homogeneous_gradient_damage_bar(model, split="none", sign=1, steps=10):
    # the uniform bar (plane strain at ν = 0, one cell high: uniaxial stress, ∇α = 0) pulled
    # in 10 steps to 2 ε_c (AT2: to 2 × the peak's strain) by alternate minimization with
    # the bound αⁿ ≤ α ≤ 1: σ and α against the closed form of the same energy, to 1e-9
    # (measured 2e-12 for AT1); AT1 elastic up to σ_c = √(3 Gc E / (8 ell)) (1 + k) exactly
    import numpy as np
    import ufl
    from dolfinx import fem
    from mpi4py import MPI

    from fenics_nl.domain import boundary
    from fenics_nl.domain.damage_specimens import BOTTOM, LEFT, RIGHT, TOP, bar_strip
    from fenics_nl.materials.gradient_damage import GradientDamage
    from fenics_nl.solvers.alternate import AlternateMinimization

    law = GradientDamage(1.0, 0.0, Gc=1.0, ell=0.1, model=model, residual_stiffness=1e-6,
                         split=split)
    msh, tags = bar_strip(MPI.COMM_WORLD, 1.0, 10)  # 0.1 high
    V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
    u = fem.Function(V)
    alpha = fem.Function(fem.functionspace(msh, ("Lagrange", 1)))
    energy = law.energy(u, alpha, "plane_strain") * ufl.dx
    solver = AlternateMinimization(energy, u, alpha, force_scale=law.critical_stress * 0.1)
    peak = law.critical_strain if model == "at1" else math.sqrt(law.Gc / law.ell / 3)
    assert law.critical_stress == pytest.approx(
        law.homogeneous_stress(peak), rel=1e-14)
    if model == "at1":
        assert law.critical_stress == pytest.approx(
            (1 + 1e-6) * math.sqrt(3 * 1.0 * 1.0 / (8 * 0.1)), rel=1e-14)
    supports = [boundary.component(V, 0, tags.find(LEFT)),
                boundary.component(V, 1, tags.find(BOTTOM))]
    lateral = [boundary.component(V, 1, tags.find(TOP))] if split != "none" else []
    for strain in sign * np.linspace(0, 2 * peak, steps + 1)[1:]:
        end = boundary.component(V, 0, tags.find(RIGHT), strain)  # L = 1
        solver.solve([*supports, end, *lateral])
        solver.commit()
        held = boundary.reactions(solver.residual_u, u, {"right": tags.find(RIGHT)},
                                  {"right": [0]}, space=V)["right"][0]
        sigma = held / 0.1
        assert sigma == pytest.approx(law.homogeneous_stress(strain), rel=1e-9)
        assert alpha.x.array == pytest.approx(law.homogeneous_damage(strain), abs=1e-9)


def _gradient_law(model, ell):
    from fenics_nl.materials.gradient_damage import GradientDamage

    return GradientDamage(1.0, 0.0, Gc=1.0, ell=ell, model=model, residual_stiffness=1e-6)


def _peak_strain(law):
    return law.critical_strain or math.sqrt(law.Gc / law.ell / (3 * law.E))


def crack_in_a_held_bar(comm):
    # AT1, ell = L/10, h = ell/5 and ell/10 (odd cells: a band of one cell at α = 1 in the
    # middle), pulled to twice the peak's strain
    import numpy as np
    from damage_problems import crack

    law = _gradient_law("at1", 0.1)
    strains = _peak_strain(law) * np.array([0.99, 1.1, 1.25, 1.5, 2.0])
    return [crack(law, 1.0, cells, strains, comm=comm) for cells in (49, 101)]


def test_a_crack_in_a_bar_dissipates_gc_and_one_band():
    # Gc (1 + h/(c_w ell)) per unit section: measured -0.19 % and -0.12 % (the band's nodes
    # at α = 0.998, 0.999: the last load's residual stress); the issue asks 1 % at h <= ell/5.
    # The profile on each side is (1 - d/(2 ell))²: measured within 2.2e-3 and 1.0e-3, the
    # band's shortfall from 1 (0.01 allows twice the P1 interpolation error at h = ell/5)
    from mpi4py import MPI

    for c in crack_in_a_held_bar(MPI.COMM_WORLD):
        assert abs(c["dissipated_energy_rel_error"]) < 0.01, c["h_over_ell"]
        assert c["band_width"] == pytest.approx(c["h"], rel=1e-9)
        assert c["profile_max_error"] < 0.01
        assert c["largest_damage"] > 0.99


@pytest.mark.parametrize("model", ["at1", "at2"])
def test_the_homogeneous_bar_bifurcates_where_its_second_variation_says(model):
    # L = 2 ell: the homogeneous bar is stable past its peak; its second variation on the
    # damage's inactive set turns negative at 3 E ε_b² = (Gc/c_w)(w''/ell + 2 ell π²/L²)
    # (AT1: 1.2825 ε_c; AT2: 1.8621 × its peak strain). Measured on 40 cells: +0.06 %, +0.05 %
    # (the P1 cosine mode's gradient energy); the bar then leaves its branch along the
    # critical mode and breaks at an end
    bar, record = _pulled_short_bar(model, "none")
    law = bar.law
    assert record.bifurcation_strain == pytest.approx(law.bifurcation_strain(1.0), rel=5e-3)
    stable = record.bifurcation_step
    for strain, stress in zip(record.strain[:stable], record.stress[:stable], strict=True):
        assert stress == pytest.approx(law.homogeneous_stress(strain), rel=1e-6)
    assert record.largest_damage[-1] > 0.99
    assert record.stress[-1] < 0.1 * law.homogeneous_stress(record.strain[-1])


def _pulled_short_bar(model, acceleration, comm=None):
    import numpy as np
    from damage_problems import GradientBar, pull
    from mpi4py import MPI

    law = _gradient_law(model, 0.5)
    bar = GradientBar(law, 1.0, 40, acceleration=acceleration, comm=comm or MPI.COMM_WORLD)
    record = pull(bar, _peak_strain(law) * np.linspace(0, 2, 21)[1:])
    return bar, record


def test_accelerated_alternate_minimization_finds_the_plain_answer():
    # the short AT1 bar through its bifurcation and its crack: over-relaxed and Anderson
    # iterations end where the plain one does (stress to 1e-5, measured 1.8e-6 past the
    # crack, where σ is (1 - α)² E ε and the stop is |Δα| < 1e-8; dissipated energy to 1e-6):
    # their energy safeguard keeps them off the unstable homogeneous
    # state, where an unguarded Anderson iteration converged (stress 0.108 instead of 0.0033)
    plain_bar, plain = _pulled_short_bar("at1", "none")
    for name in ("overrelaxed", "anderson"):
        bar, record = _pulled_short_bar("at1", name)
        assert record.bifurcation_strain == pytest.approx(plain.bifurcation_strain, rel=1e-9)
        assert record.stress == pytest.approx(plain.stress, rel=1e-5)
        assert bar.dissipated_energy() == pytest.approx(plain_bar.dissipated_energy(),
                                                        rel=1e-6)


@pytest.mark.mpi
def test_gradient_damage_crack_and_bifurcation_on_two_ranks():
    # the bar cut in two against the same bar on one rank (each rank computes it alone)
    from mpi4py import MPI

    for cut, whole in zip(crack_in_a_held_bar(MPI.COMM_WORLD),
                          crack_in_a_held_bar(MPI.COMM_SELF), strict=True):
        assert cut["dissipated_energy"] == pytest.approx(whole["dissipated_energy"], rel=1e-7)
        assert cut["profile"]["damage"] == pytest.approx(whole["profile"]["damage"], abs=1e-7)
    _, cut = _pulled_short_bar("at1", "anderson")
    _, whole = _pulled_short_bar("at1", "anderson", MPI.COMM_SELF)
    assert cut.bifurcation_strain == pytest.approx(whole.bifurcation_strain, rel=1e-9)
    assert cut.stress == pytest.approx(whole.stress, rel=1e-5)


def surfing_run(comm, steps):
    # AT1, ell = 0.04, h = ell/4 along the path, a K-field moved by 2h per step
    # (Anderson-accelerated alternate minimization: 15 iterations a step, the plain one 136,
    # the same crack to 1e-8 in G)
    from damage_problems import surfing

    from fenics_nl.materials.gradient_damage import GradientDamage

    law = GradientDamage(1.0, 0.3, Gc=1.0, ell=0.04, model="at1", residual_stiffness=1e-6)
    return surfing(law, steps, resolution=4, acceleration="anderson", comm=comm)


def test_a_surfing_crack_follows_its_k_field_and_dissipates_the_mesh_toughness():
    # the toughness of the mesh for a crack along a line of nodes, from the 1D half bar
    # cracked at its free end (a band of one cell at α = 1 on the half: Gc (1 + 2h/(c_w ell))
    # = 1.1875, measured 1.1867); the surfing crack's 2 dD/da over its steady steps: -1.4 %
    # (the issue asks 2 %). The tip trails the field's centre by a constant, h or 2h
    import numpy as np
    from damage_problems import end_crack, release_rate
    from mpi4py import MPI

    bar_law = _gradient_law("at1", 0.04)
    strains = bar_law.critical_strain * np.array([0.99, 1.1, 1.5, 2, 3])
    half = end_crack(bar_law, 0.4, 40, strains)
    assert 2 * half == pytest.approx(1 + 2 * 0.01 / (8 / 3 * 0.04), rel=2e-3)
    record = surfing_run(MPI.COMM_WORLD, 10)
    G, lag = release_rate(record, skip=4)
    assert G == pytest.approx(2 * half, rel=0.02)
    lags = np.array(record.centre[4:]) - np.array(record.tip[4:])
    assert np.ptp(lags) < 1e-9 and 0 <= lag <= 2 * record.h * (1 + 1e-12)  # 2h: measured


@pytest.mark.mpi
def test_a_surfing_crack_on_two_ranks_is_the_serial_one():
    from mpi4py import MPI

    cut = surfing_run(MPI.COMM_WORLD, 4)
    whole = surfing_run(MPI.COMM_SELF, 4)
    assert cut.tip == whole.tip
    assert cut.dissipated_energy == pytest.approx(whole.dissipated_energy, rel=1e-7)


def test_a_damage_bar_that_fails_keeps_its_converged_steps(demo, tmp_path):
    # the damage SNES allowed one iteration: the first damaged step fails; the JSON says so
    # and keeps the two elastic steps before it (status 2, one line)
    out = tmp_path / "f.json"
    proc = demo.run(["damage_bar.py", "--model", "at1", "-damage_snes_max_it", "1",
                     "--json", out], check=False)
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1
    import json

    d = json.loads(out.read_text())
    assert d["status"] == "failed" and d["converged_steps"] == 2
    assert [s["strain"] for s in d["steps"]] == pytest.approx(
        [math.sqrt(3 / 0.8) * k / 3 for k in (1, 2)], rel=1e-12)
