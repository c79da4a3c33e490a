"""The thick sphere and cylinder in perfect J2 plasticity against the closed forms."""

import json
import math
import subprocess
import sys

import numpy as np
import pytest
from conftest import DEMOS

from fenics_nl.theory import vessels

A, B, E, NU, SIGMA0 = 100.0, 200.0, 210e3, 0.3, 250.0


def test_sphere_displacement_closed_form_against_hill():
    # written independently (Hill 1950, The Mathematical Theory of Plasticity, the
    # expanding spherical shell): u(a) = σ0 a/E [(1 − ν) c³/a³ − ⅔(1 − 2ν)(1 − c³/b³
    # + 3 ln(c/a))], from the yield onset up to the limit (c = b) included
    p_e = vessels.yield_onset_pressure("sphere", A, B, SIGMA0)
    p_lim = vessels.limit_pressure("sphere", A, B, SIGMA0)
    for p in np.linspace(p_e, p_lim, 7):
        c = vessels.plastic_radius("sphere", A, B, SIGMA0, p)
        hill = SIGMA0 * A / E * ((1 - NU) * c**3 / A**3 - 2 / 3 * (1 - 2 * NU)
                                 * (1 - c**3 / B**3 + 3 * math.log(c / A)))
        assert vessels.sphere_inner_displacement(A, B, E, NU, SIGMA0, p) == pytest.approx(
            hill, rel=1e-12)
    # below the onset, Lamé's line, which the plastic branch meets at p_e
    lame = p_e * vessels.elastic_inner_compliance("sphere", A, B, E, NU)
    assert vessels.sphere_inner_displacement(A, B, E, NU, SIGMA0, p_e * (1 + 1e-12)) == \
        pytest.approx(lame, rel=1e-9)
    with pytest.raises(ValueError, match="beyond the limit"):
        vessels.sphere_inner_displacement(A, B, E, NU, SIGMA0, 1.01 * p_lim)


def test_no_residual_stress_below_the_yield_onset():
    # an elastic loading is undone by the unloading: σ_θ(a) = 0 (the plastic-zone formula
    # gave 0.29 σ0 at 0.72 p_e); just past the onset the formula takes over, continuously
    p_e = vessels.yield_onset_pressure("sphere", A, B, SIGMA0)
    assert vessels.residual_hoop_stress_inner(A, B, SIGMA0, 0.72 * p_e) == 0.0
    at_onset = vessels.residual_hoop_stress_inner(A, B, SIGMA0, p_e * (1 + 1e-9))
    assert abs(at_onset) < 1e-6 * SIGMA0


def test_sphere_onset_plastic_radius_and_residual_stress(demo):
    # p = 0.8 p_lim < 2 p_e: the unloading stays elastic (no reverse yielding)
    d = demo.json("pressure_vessel.py", "--pressure-ratio", "0.8", "--unload", "--steps", "5")
    assert d["yield_onset_pressure"] == pytest.approx(d["yield_onset_pressure_exact"],
                                                      rel=5e-3)  # measured +0.15 %
    assert abs(d["plastic_radius"] - d["plastic_radius_exact"]) < d["element_size"]
    assert d["inner_displacement"] == pytest.approx(d["inner_displacement_exact"],
                                                    rel=1e-3)  # measured -0.015 %
    assert d["residual_hoop_stress_inner"] == pytest.approx(
        d["residual_hoop_stress_inner_exact"], rel=0.01)  # measured 0.3 %
    assert d["permanent_inner_displacement"] > 0


def test_sphere_displacement_control_reaches_the_limit_pressure(demo):
    d = demo.json("pressure_vessel.py", "--inner-displacement", "1.0", "--steps", "5")
    assert d["pressure"] == pytest.approx(d["limit_pressure_exact"], rel=2e-3)  # -0.01 %
    assert abs(d["plastic_radius"] - 200.0) < d["element_size"]


def test_cylinder_onset_and_limit(demo):
    d = demo.json("pressure_vessel.py", "--shape", "cylinder", "--inner-displacement", "2.0",
                  "--steps", "5")
    assert d["yield_onset_pressure"] == pytest.approx(d["yield_onset_pressure_exact"],
                                                      rel=5e-3)
    assert d["pressure"] == pytest.approx(d["limit_pressure_exact"], rel=2e-3)  # measured -0.001 %


def test_beyond_the_limit_load_is_one_line(demo):
    # (h = 12.5: the discrete limit is 1.4 % above the exact one; at h = 25, 4 elements
    # through the wall, it is more than 20 % above: P2 locks in the incompressible flow)
    proc = demo.run(["pressure_vessel.py", "--pressure-ratio", "1.1", "--steps", "5",
                     "--size", "12.5", "--json", "failed.json"],
                    check=False)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "the limit load was reached" in lines[0]
    # and the steps that converged are kept: every one below the (discrete) limit pressure
    d = json.loads((demo.tmp_path / "failed.json").read_text())
    assert d["status"] == "failed" and d["message"] in lines[0]
    assert d["converged_steps"] == len(d["steps"]) >= 5
    p_lim = d["limit_pressure_exact"]
    pressures = [s["pressure"] for s in d["steps"]]
    assert pressures == sorted(pressures) and p_lim * 0.9 < pressures[-1] < 1.02 * p_lim
    assert d["load_factor"] == pytest.approx(pressures[-1] / (1.1 * p_lim), rel=1e-12)


@pytest.mark.parametrize("ranks", [2])
@pytest.mark.mpi
def test_two_ranks_give_the_serial_answer(demo, ranks):
    args = ("--pressure-ratio", "0.8", "--unload", "--steps", "5")  # as the serial suite's
    s, p = demo.json("pressure_vessel.py", *args), demo.json("pressure_vessel.py", *args,
                                                             ranks=ranks)
    assert p["ranks"] == ranks
    for k in ("yield_onset_pressure", "plastic_radius", "inner_displacement"):
        assert p[k] == pytest.approx(s[k], rel=1e-8), k


def test_a_locking_mesh_past_the_limit_is_refused_in_one_line(demo):
    # h = 25, 4 elements through the wall: 1.2 p_lim "converges" to u(a) = 27 a
    proc = demo.run(["pressure_vessel.py", "--pressure-ratio", "1.2", "--size", "25"],
                    check=False)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and "the mesh locks" in lines[0]


def test_mixed_elements_do_not_lock_on_the_same_coarse_mesh(demo):
    # Taylor–Hood on h = 25: the reaction at u(a) = 20 is the limit pressure (measured
    # +0.06 %), where P2 displacements read +0.18 % and rising (refused above)
    d = demo.json("pressure_vessel.py", "--mixed", "--inner-displacement", "20", "--size",
                  "25", "--steps", "10")
    assert d["mixed"]
    assert d["pressure"] == pytest.approx(d["limit_pressure_exact"], rel=1e-3)


# -- checkpoint and restart of a demo ----------------------------------------------------

VESSEL_PATH = ["--pressure-ratio", "0.95", "--steps", "12", "--unload"]  # yields in reverse


def same_run(a, b):
    """Key by key the same JSON, times and memory aside: the restart took the same path.

    Counts and words exactly, a number to 1e-10 of its size, a vector's components to
    1e-10 of its largest (`benchmarks/demo_snapshot.py`'s comparison). Two uninterrupted
    runs on 2 ranks already differ in the last digit: the order of parallel sums.
    """
    from demo_snapshot import differences  # benchmarks/, on the tests' path

    assert differences(a, b, "json") == []


def test_a_killed_vessel_restarts_to_the_uninterrupted_answer(tmp_path, demo):
    # J2 is path-dependent: the plastic strains at the quadrature points, the predictor's
    # last two states and Newton's force scale come back with the displacement
    import sys

    from conftest import DEMOS, run_and_kill

    whole = demo.json("pressure_vessel.py", *VESSEL_PATH, "--checkpoint", tmp_path / "peak")
    # killed while it unloads, a run leaves the peak's checkpoint (the unloading is not
    # saved): the uninterrupted run's own, restarted, redoes the unloading
    assert json.loads((tmp_path / "peak" / "latest.json").read_text())["step"] == "step-000012"
    same_run(whole, demo.json("pressure_vessel.py", *VESSEL_PATH, "--restart",
                              tmp_path / "peak"))
    # killed in the middle of the loading
    run_and_kill([sys.executable, DEMOS / "pressure_vessel.py", *VESSEL_PATH, "--checkpoint",
                  "ck"], tmp_path, "  step 5:")
    latest = int(json.loads((tmp_path / "ck" / "latest.json").read_text())["step"][5:])
    assert 4 <= latest < 12
    same_run(whole, demo.json("pressure_vessel.py", *VESSEL_PATH, "--restart", tmp_path / "ck"))
    # other parameters, or no checkpoint: one line
    for args, message in ((["--steps", "10"], "is of another run: its command line"),
                          (["--restart", tmp_path / "none"], "no checkpoint folder")):
        proc = demo.run(["pressure_vessel.py", *VESSEL_PATH, "--restart", tmp_path / "ck",
                         *args], check=False)
        lines = proc.stderr.strip().splitlines()
        assert proc.returncode == 2 and len(lines) == 1 and message in lines[0], proc.stderr


@pytest.mark.spawns_mpi
def test_a_killed_vessel_on_two_ranks_restarts_to_the_same_answer(tmp_path, demo):
    import sys

    from conftest import DEMOS, MPIEXEC, run_and_kill

    whole = demo.json("pressure_vessel.py", *VESSEL_PATH, ranks=2)
    run_and_kill([MPIEXEC, "-n", "2", sys.executable, DEMOS / "pressure_vessel.py",
                  *VESSEL_PATH, "--checkpoint", "ck"], tmp_path, "  step 5:")
    resumed = demo.json("pressure_vessel.py", *VESSEL_PATH, "--restart", tmp_path / "ck",
                        ranks=2)
    same_run(whole, resumed)


def test_as_a_script_a_failed_run_is_one_line_and_keeps_its_steps(tmp_path):
    # the demo run by `python`, as a user does (the other tests run its cells in-process):
    # the script's own run (io.cli.arguments) ends a library error with one line, status 2
    # and the JSON of the steps that converged
    proc = subprocess.run([sys.executable, str(DEMOS / "pressure_vessel.py"),
                           "--pressure-ratio", "1.1", "--steps", "5", "--size", "12.5",
                           "--json", "failed.json"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert "the limit load was reached" in lines[0]
    d = json.loads((tmp_path / "failed.json").read_text())
    assert d["status"] == "failed" and d["converged_steps"] == len(d["steps"]) >= 5


@pytest.mark.parametrize("args,words", [
    (["--inner-radius", "300"], "--inner-radius must be below --outer-radius"),  # check()
    (["--steps", "0"], "--steps: must be >= 1"),  # a bound of the field
    (["--E", "nan"], "--E: must be a finite number"),
    (["--hardening", "-1"], "--hardening: must be >= 0"),
    (["--pressure-ratio", "0.5", "--inner-displacement", "1"], "not allowed with"),  # group
    (["--shape", "cube"], "invalid choice"),
])
def test_bad_parameters_are_one_line_naming_the_flag(demo, args, words):
    # the demo's parameters are one dataclass (io.parameters): its fields' bounds, groups
    # and check() give these errors before anything is solved
    proc = demo.run(["pressure_vessel.py", *args], check=False)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and words in lines[0], proc.stderr
