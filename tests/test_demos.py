"""Each demo as a user runs it: serially (in-process) and under mpiexec, against theory."""

import json
import math

import numpy as np
import pytest
from notebooks import SMALL
from test_friction import BRACKET_ON_FLOOR


def test_newton_scalar_orders(tmp_path, demo):
    out = tmp_path / "scalar.json"
    demo.run(["newton_scalar.py", "--json", out])
    data = json.loads(out.read_text())
    for method, order in [("newton", 2.0), ("modified", 1.0), ("secant", (1 + 5**0.5) / 2)]:
        assert abs(data[method]["order"] - order) < 0.15, (method, data[method])
        assert data[method]["iterations"] > 0
    assert data["modified"]["iterations"] > 5 * data["newton"]["iterations"]


def test_newton_scalar_plot_in_double_precision(tmp_path, demo):
    png = tmp_path / "orders.png"
    demo.run(["newton_scalar.py", "--function", "kepler", "--digits", "16", "--plot", png])
    assert png.stat().st_size > 10_000


@pytest.mark.parametrize("args,message", [
    (["--digits", "3"], "--digits"),
    (["--function", "nope"], "invalid choice"),
    (["--slope", "0"], "--slope"),
    (["--max-it", "0"], "--max-it: must be >= 1"),
    (["--u0", "nan"], "--u0: must be a finite number"),
])
def test_newton_scalar_bad_input(args, message, demo):
    demo.refuses(["newton_scalar.py", *args], message)  # one line, no usage block


def test_newton_scalar_divergence_is_a_result(tmp_path, demo):
    # modified Newton with K = r'(u0) = 1.75 on u + u³ = 3 (r'(u*) = 5.4): the rate
    # 1 − r'(u*)/K = −2.1 diverges; the table shows it, the others converge as usual
    out = tmp_path / "h.json"
    proc = demo.run(["newton_scalar.py", "--function", "hardening", "--json", out,
                     "--plot", tmp_path / "h.png"])
    d = json.loads(out.read_text())
    assert not d["modified"]["converged"] and "diverges" in d["modified"]["failure"]
    assert "diverges" in proc.stdout
    assert d["newton"]["converged"] and abs(d["newton"]["order"] - 2) < 0.15
    assert abs(d["secant"]["order"] - (1 + 5**0.5) / 2) < 0.15


@pytest.mark.parametrize("name", ["newton_scalar.py", "punch.py", "punch_friction.py",
                                  "indentation.py", "buckling_beam.py",
                                  "pressure_vessel.py", "snap_through.py",
                                  "bracket.py", "indentation_identification.py",
                                  "creep_vessel.py", "bearing.py", "excavation.py"])
def test_help_describes_the_demo_and_states_defaults_once(demo, name):
    text = demo.run([name, "--help"]).stdout
    assert "(default: None)" not in text and len(text.split("\n\n")[1]) > 40
    prefix = {"punch.py": "-punch_axisymmetric_elim_ksp_view",
              "punch_friction.py": "-punch_axisymmetric_elim_ksp_view",
              "indentation.py": "-punch_axisymmetric_elim_ksp_view",
              "indentation_identification.py": "-punch_axisymmetric_elim_",
              "buckling_beam.py":
              "-beam_buckling_", "bracket.py": "-bracket_elim_",
              "snap_through.py": "-arch_continuation_", "creep_vessel.py": "-creep_ksp_view",
              "excavation.py": "-excavation_"
              }.get(name)
    if prefix:  # the PETSc options prefixes are documented
        assert prefix in " ".join(text.split())


def test_punch_axisymmetric_default_matches_hertz(demo):
    d = demo.punch("--steps", "4")
    assert abs(d["force_rel_error"]) < 0.005
    assert abs(d["contact_radius"] - d["hertz_contact_radius"]) <= d["element_size"]
    assert abs(d["max_pressure_rel_error"]) < 0.03
    assert abs(d["fitted_exponent"] - 1.5) < 0.02
    assert d["active_set_iterations"] >= 4 and d["dofs"] > 0 and d["ranks"] == 1


@pytest.mark.parametrize("E,nu,R,delta", [
    (210e9, 0.25, 0.02, 2e-5),  # steel ball, 20 mm, 20 µm
    (3e6, 0.45, 5.0, 0.2),  # rubber-like block, large punch
])
def test_punch_accuracy_holds_for_other_parameters(E, nu, R, delta, demo):
    d = demo.punch("--E", str(E), "--nu", str(nu), "--radius", str(R),
              "--indentation", str(delta))
    assert abs(d["force_rel_error"]) < 0.005
    assert abs(d["contact_radius"] - d["hertz_contact_radius"]) <= d["element_size"]
    assert abs(d["max_pressure_rel_error"]) < 0.03


def test_punch_plane_strain_half_width_and_pressure(demo):
    d = demo.punch("--model", "plane_strain")
    assert abs(d["contact_radius_rel_error"]) < 0.02
    assert abs(d["max_pressure_rel_error"]) < 0.02
    # the force is not compared with itself: no Hertz force, and the JSON says why
    assert "force_rel_error" not in d and "hertz_force" not in d
    assert any("force is not checked" in w for w in d["warnings"])


def test_punch_force_control_at_a_realistic_modulus(demo):
    # steel-like E with a 100 N load: Newton's absolute floor scales with the load
    d = demo.punch("--E", "210e9", "--radius", "0.01", "--force", "100")
    assert d["force"] == pytest.approx(100, rel=1e-9)
    assert abs(d["force_rel_error"]) < 0.005


def test_punch_reactions_balance_the_contact_force(demo):
    d = demo.punch("--nu", "0.25")
    # vertical equilibrium of the block: the base holds what the punch pushes
    assert d["reactions"]["bottom"][1] == pytest.approx(d["force"], rel=1e-8)
    assert d["warnings"] == []


def test_punch_petsc_option_reaches_its_solver(demo):
    proc = demo.run(["punch.py", "--refine", "0", "-punch_axisymmetric_elim_ksp_view"])
    assert "KSP Object: (punch_axisymmetric_elim_)" in proc.stdout


def test_punch_every_output_is_written(tmp_path, demo):
    out = tmp_path / "o.json"
    demo.run(["punch.py", "--refine", "0", "--json", out, "--output", tmp_path / "f",
              "--png", tmp_path / "p.png", "--plot", tmp_path / "c.png"])
    for name in ("displacement", "contact_pressure", "active_set", "von_mises"):
        assert (tmp_path / "f" / f"{name}.bp").is_dir()
    assert (tmp_path / "p.png").stat().st_size > 20_000 and out.exists()


def test_output_is_a_time_series_of_every_converged_step(tmp_path, demo):
    from conftest import read_series

    demo.indentation("--refine", "0", "--steps", "3", "--loading-only", "--output",
                     tmp_path / "f")
    times, u = read_series(tmp_path / "f" / "displacement.bp", "displacement")
    assert times == pytest.approx([1 / 3, 2 / 3, 1.0], rel=1e-12)
    assert np.abs(u[0]).max() < np.abs(u[1]).max() < np.abs(u[2]).max()
    times, p = read_series(tmp_path / "f" / "cumulated_plastic_strain.bp",
                           "cumulated_plastic_strain")
    assert len(times) == 3 and p[-1].max() > 0  # J2 writes its state too


def test_a_failing_picture_keeps_the_json(tmp_path, demo, monkeypatch):
    from fenics_nl.plots import figures

    def broken(*args, **kwargs):
        raise RuntimeError("the renderer crashed")

    monkeypatch.setattr(figures, "save_figure", broken)
    proc = demo.run(["punch.py", "--refine", "0", "--json", "o.json", "--png", "p.png"],
                    check=False)
    assert proc.returncode == 1 and "writing an output failed" in proc.stderr
    assert "the renderer crashed" in proc.stderr and "Traceback" not in proc.stderr
    assert json.loads((tmp_path / "o.json").read_text())["force"] > 0


@pytest.mark.parametrize("flag", ["--json", "--png", "--plot", "--output"])
def test_an_unwritable_output_is_refused_before_the_solve(tmp_path, demo, flag):
    (tmp_path / "a_file").write_text("")
    path = "a_file/sub" if flag == "--output" else "no/such/dir/x"
    proc = demo.run(["punch.py", "--refine", "0", flag, path], check=False)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and flag in lines[0], proc.stderr
    assert proc.stdout == ""  # nothing was solved


def test_punch_refuses_a_contact_zone_the_mesh_cannot_resolve():
    # the check behind every punch report, on a state with 3 nodes in contact (the CLI's
    # --refine bound keeps a default run far from it)
    from types import SimpleNamespace

    from fenics_nl.contact.surface import check_contact_resolution

    state = SimpleNamespace(force=1.0, contact_radius=0.1)
    with pytest.raises(ValueError, match=r"only 3 node.* cannot resolve the contact zone"):
        check_contact_resolution(3, 0.05, state)
    assert "only 7 nodes" in check_contact_resolution(7, 0.05, state)[0]
    assert check_contact_resolution(12, 0.05, state) == []


@pytest.mark.spawns_mpi
def test_punch_outputs_options_and_picture_on_two_ranks(tmp_path, demo):
    import matplotlib.image as mpimg

    proc = demo.run(["punch.py", "--refine", "0", "--output", "f", "--png", "p2.png",
                     "--plot", "c.png", "--json", "o.json", "-punch_axisymmetric_elim_ksp_type",
                     "cg"], ranks=2)
    assert proc.stdout.count("wall time") == 1  # rank 0 speaks
    for name in ("displacement", "contact_pressure", "active_set"):
        assert (tmp_path / "f" / f"{name}.bp").is_dir()
    assert json.loads((tmp_path / "o.json").read_text())["ranks"] == 2
    # the picture is the serial one: the whole mesh on both ranks; only anti-aliasing at
    # duplicated partition nodes may differ
    demo.run(["punch.py", "--refine", "0", "--png", tmp_path / "p1.png"])
    one, two = (mpimg.imread(tmp_path / f"p{n}.png") for n in (1, 2))
    assert one.shape == two.shape
    assert np.mean(np.abs(one - two)) < 2e-3
    bad = demo.run(["punch.py", "-ksp_view"], check=False, ranks=2)
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1


def test_punch_3d_quarter_model(demo):
    d = demo.punch("--model", "3d")
    assert abs(d["force_rel_error"]) < 0.02


def test_punch_force_control_reaches_the_force(demo):
    d = demo.punch("--force", "0.0015")
    assert d["force"] == pytest.approx(0.0015, rel=1e-9)
    assert abs(d["force_rel_error"]) < 0.005  # P against Hertz at the δ found


def test_punch_formulations_agree(demo):
    e = demo.punch("--formulation", "elimination")
    m = demo.punch("--formulation", "multiplier")
    assert m["force"] == pytest.approx(e["force"], rel=1e-9)
    assert m["contact_radius"] == e["contact_radius"]


@pytest.mark.mpi
def test_punch_two_ranks_match_serial(demo):
    s = demo.punch("--steps", "2")
    p = demo.punch("--steps", "2", ranks=2)
    assert p["ranks"] == 2
    assert p["force"] == pytest.approx(s["force"], rel=1e-8)
    assert p["contact_radius"] == pytest.approx(s["contact_radius"], rel=1e-12)
    for group, r in s["reactions"].items():  # summed over the ranks' owned nodes
        assert np.allclose(p["reactions"][group], r, rtol=1e-8, atol=1e-10 * s["force"])


@pytest.mark.mpi
def test_indentation_two_ranks_match_serial(demo):
    # J2 under the punch, loaded and unloaded: the plastic state, the active set and the
    # imprint of 2 ranks are the serial run's
    args = ("--refine", "0", "--steps", "2")
    s, p = demo.indentation(*args), demo.indentation(*args, ranks=2)
    assert p["ranks"] == 2 and p["nodes_in_contact"] == s["nodes_in_contact"]
    for k in ("force", "residual_imprint_depth", "max_cumulated_plastic_strain"):
        assert p[k] == pytest.approx(s[k], rel=1e-8)


def test_punch_that_never_touches_gives_zero_force(tmp_path, demo):
    proc = demo.run(["punch.py", "--indentation", "-0.01", "--json", tmp_path / "z.json"])
    d = json.loads((tmp_path / "z.json").read_text())
    assert d["force"] == 0.0 and d["contact_radius"] == 0.0
    assert "does not touch" in proc.stdout


@pytest.mark.parametrize("args,message", [
    (["--nu", "0.6"], "nu must be in"), (["--nu", "0.5"], "needs the mixed"),
    (["--radius", "-1"], "--radius: must be > 0"),
    (["--E", "-3"], "--E: must be > 0"), (["--steps", "0"], "--steps"),
    (["--bogus", "1"], "unrecognized"), (["--force", "-1"], "--force"),
    (["--indentation", "nan"], "--indentation: must be a finite number"),
    (["--E", "inf"], "--E: must be a finite number"),
    (["--refine", "30"], "--refine: must be <= 6"),
    (["--n", "0.5"], "--n set the power law, not --material linear"),
    (["-ksp_view"], "-ksp_view is read by no solver of this run; its options prefixes are "
                    "-punch_axisymmetric_elim_"),
    (["-punch_axisymmetric_elim_ksp_veiw"], "was read by no solver (misspelt?)"),
    (["-punch_axisymmetric_elim_pc_type", "nonsense"], "nonsense"),
])
def test_punch_bad_input_one_clear_line(args, message, demo):
    demo.refuses(["punch.py", *args], message)


@pytest.mark.parametrize("ratio", ["1.05", "1.2", "2.0"])
def test_beam_follows_the_elastica(ratio, demo, on_elastica):
    on_elastica(demo.beam("--load-ratio", ratio))


@pytest.mark.parametrize("args", [
    ["--length", "2", "--thickness", "0.02", "--E", "210e9", "--nu", "0.25"],  # L/h = 100
    # ν = 0.45 stiffens 2 Q2 elements through the height (P_cr +0.46 %, α −0.78°):
    # one refinement halves it, so this case runs at --refine 1
    ["--plane", "strain", "--E", "5e6", "--nu", "0.45", "--refine", "1"],
    ["--plane", "strain", "--material", "neo-hookean"],
])
def test_beam_accuracy_holds_for_other_parameters(args, demo, on_elastica):
    on_elastica(demo.beam(*args, "--load-ratio", "1.2"))


def test_beam_every_output_and_the_clamp_reaction(tmp_path, demo):
    # --output used to crash at the end (XDMF cannot hold P2 on quadrilaterals), losing
    # the other outputs of the run
    d = demo.beam("--load-ratio", "1.2", "--output", "f", "--png", "b.png",
             "--plot", "c.png")
    assert (tmp_path / "f" / "displacement.bp").is_dir()
    assert (tmp_path / "b.png").exists() and (tmp_path / "c.png").exists()
    P = 1.2 * d["euler_critical_load"]
    rx, ry = d["reactions"]["clamp"]
    assert rx == pytest.approx(P, rel=1e-7) and ry == pytest.approx(-1e-4 * P, rel=1e-4)


def test_beam_below_euler_stays_straight(demo):
    # Only the imperfection bends it: linear theory gives α ≈ ε r π²/8 / (1 − r) rad.
    d = demo.beam("--load-ratio", "0.9")
    eps, r = 1e-4, 0.9
    amplified = math.degrees(eps * r * math.pi**2 / 8 / (1 - r))
    assert 0.5 * amplified < d["tip_rotation_deg"] < 1.5 * amplified
    assert d["tip_rotation_deg"] < 0.1


@pytest.mark.parametrize("args", [["--steps", "1"], ["--load-ratio", "10"]])
def test_beam_stress_cases_land_on_the_right_branch(args, demo, on_elastica):
    # One huge step converges to the unstable straight beam; the stability check sees it
    # and switches branch. r = 10 is deep in the post-buckling range (α ≈ 177°).
    on_elastica(demo.beam(*args))


def test_beam_arc_length_buckles_the_perfect_beam_without_the_elastica(demo, on_elastica):
    # no imperfection: the path stays straight past P_cr until the tangent's inertia
    # changes; the bifurcation is bracketed there and left along the critical mode
    d = demo.beam("--path", "arc-length", "--imperfection", "0", "--load-ratio", "1.2")
    on_elastica(d)
    assert d["branch_switched"] and d["path_control"] == "arc-length"
    (c,) = d["critical_points"]
    ratio = d["critical_load"] / d["euler_critical_load"]  # SLEPc's, in P_Euler
    assert c["kind"] == "bifurcation" and c["between"][0] < ratio < c["between"][1]
    assert d["inertia_factorizations"] >= d["load_steps"]


def test_snap_through_follows_the_shallow_arch_through_both_limit_points(tmp_path, demo):
    d = demo.json("snap_through.py", "--plot", "p.png", "--png", "s.png")
    # the continuum against thin shallow-arch theory at L/h = 200: -0.48 % (-1.06 % at 100,
    # -0.45 % at 400): the continuum model (pinned at one node, loaded on its top face)
    # against the theory; 2 % is the bound
    assert abs(d["limit_load_rel_error"]) < 0.02
    assert d["path_max_error"] < 0.02  # every state, on the cubic at its own rise
    assert [c["kind"] for c in d["critical_points"]] == ["limit", "limit"]
    ref = d["limit_load_reference"] / d["load_unit"]
    assert d["final_load_factor"] == pytest.approx(1.5 * ref, rel=1e-12)
    assert d["final_rise"] < -d["initial_rise"]  # inverted, past the second limit point
    from fenics_nl.theory.arch import limit_rise

    a_lim = limit_rise(d["initial_rise"])
    unstable = [p for p in d["path"] if abs(p["rise"]) < a_lim]
    assert len(unstable) == d["unstable_states"] >= 5  # the branch between the limit points
    # the tangent has one negative eigenvalue there, none elsewhere (within 0.05 r of the
    # closed form's limit rises: the continuum's own limit points are a little off them)
    counts = {abs(p["rise"]) < a_lim - 0.05: set() for p in d["path"]}
    for p in d["path"]:
        if abs(abs(p["rise"]) - a_lim) > 0.05:
            counts[abs(p["rise"]) < a_lim].add(p["negative_eigenvalues"])
    assert counts == {True: {1}, False: {0}}
    assert all(abs(e) < 0.02 for e in d["limit_loads_rel_error"])  # the minimum too

    (lx, ly), (rx, ry) = d["reactions"]["left pin"], d["reactions"]["right pin"]
    q_total = 2 / math.pi * 1.5 * d["limit_load_reference"]  # ∫ q0 sin(πx/L) dx, L = 1
    assert ly + ry == pytest.approx(q_total, rel=1e-6) and lx == pytest.approx(-rx, rel=1e-6)
    assert (tmp_path / "p.png").stat().st_size > 10_000 and (tmp_path / "s.png").exists()


def test_an_arch_whose_second_limit_load_is_zero_says_its_error_in_q_limit(demo):
    # e/r = 4: the shallow-arch cubic's minimum is q0 = 0 exactly, where a relative error
    # has no meaning (it raised ZeroDivisionError); the JSON has None there. Arcs up to 3
    # (37 steps, not 247): the same limit loads to 1e-7
    d = demo.json("snap_through.py", "--rise", "4", "--max-arc-length", "3")
    assert len(d["limit_loads"]) == 2 and d["limit_loads_reference"][1] == 0.0
    assert d["limit_loads_rel_error"][1] is None and abs(d["limit_loads_rel_error"][0]) < 0.02
    assert abs(d["limit_loads"][1]) < 0.02 * d["limit_load_reference"]


@pytest.mark.mpi
def test_snap_through_two_ranks_match_serial(demo):
    args = ("--slenderness", "100", "--load-ratio", "1.1")
    s, p = demo.json("snap_through.py", *args), demo.json("snap_through.py", *args, ranks=2)
    assert p["ranks"] == 2
    assert p["limit_load"] == pytest.approx(s["limit_load"], rel=1e-8)
    assert p["final_rise"] == pytest.approx(s["final_rise"], rel=1e-6)


def test_a_killed_snap_through_restarts_on_the_same_path(tmp_path, demo):
    # arc-length: killed between its two limit points, the restart goes on with the saved
    # arc, inertia, sense and last increment, and the shapes its picture draws
    import sys

    from conftest import DEMOS, run_and_kill
    from test_vessel import same_run

    whole = demo.json("snap_through.py", "--png", "whole.png")
    run_and_kill([sys.executable, DEMOS / "snap_through.py", "--checkpoint", "ck"], tmp_path,
                 "  step 20:")
    latest = int(json.loads((tmp_path / "ck" / "latest.json").read_text())["step"][5:])
    assert 19 <= latest < len(whole["steps"]) - 5
    resumed = demo.json("snap_through.py", "--png", "resumed.png", "--restart", "ck")
    same_run(whole, resumed)
    # the killed run drew nothing, the restart's picture has every state all the same
    assert (tmp_path / "resumed.png").read_bytes() == (tmp_path / "whole.png").read_bytes()


@pytest.mark.parametrize("args,message", [
    (["--arc-length", "0"], "--arc-length: must be > 0"), (["--rise", "1.5"], "--rise"),
    (["--rise", "5"], "antisymmetrically"), (["--elements", "3"], "--elements must be even"),
    (["--max-steps", "3"], "not reached in 3 steps"), (["--slenderness", "5"], "slenderness"),
    (["-arch_full_ksp_veiw"], "was read by no solver"),
])
def test_snap_through_bad_input_one_clear_line(args, message, demo):
    demo.refuses(["snap_through.py", *args], message)


@pytest.mark.mpi
def test_beam_two_ranks_match_serial(demo):
    # the notebook's run (tests/test_notebooks.py): the serial answer is made there
    s = demo.beam("--load-ratio", "1.2", "--steps", "10")
    p = demo.beam("--load-ratio", "1.2", "--steps", "10", ranks=2)
    assert p["ranks"] == 2
    assert p["critical_load"] == pytest.approx(s["critical_load"], rel=1e-8)
    assert p["tip_rotation_deg"] == pytest.approx(s["tip_rotation_deg"], rel=1e-6)


@pytest.mark.parametrize("args,message", [
    (["--thickness", "0.5"], "slender"), (["--nu", "0.6"], "nu must be in"),
    (["--load-ratio", "-1"], "--load-ratio"), (["--steps", "0"], "--steps"),
    (["--material", "neo-hookean"], "plane strain only"), (["--oops"], "unrecognized"),
    (["--E", "nan"], "--E: must be a finite number"), (["-ksp_view"], "-beam_"),
])
def test_beam_bad_input_one_clear_line(args, message, demo):
    demo.refuses(["buckling_beam.py", *args], message)


def test_bracket_newton_variants_agree(demo):
    # 20 mm elements (11.6k unknowns, ε_eq still 11 ε0) and 2 steps to the same end state:
    # the variants agree on any mesh and path
    d = demo.bracket("--compare", "--size", "20", "--steps", "2")
    ref = d["variants"]["full"]["load_point_displacement"]
    for name, v in d["variants"].items():
        assert abs(v["load_point_displacement"] / ref - 1) < 1e-7, name
    steps = len(d["steps"])
    assert d["variants"]["modified"]["factorizations"] == steps  # once per load step
    assert d["variants"]["bfgs"]["factorizations"] == steps
    assert d["max_eps_eq_over_eps0"] > 10  # strongly non-linear, as the demo says


def test_bracket_contact_support_lifts_off(tmp_path, demo):
    # equilibrium and the floor's one-sidedness hold on any mesh: the runs the suite makes
    # anyway (the bracket on its floor, the clamped bracket's page; hyperelastic: the same
    # end state in 1 or 2 steps)
    c = demo.bracket(*BRACKET_ON_FLOOR)
    k = demo.bracket(*SMALL["bracket.py"])
    assert c["lifted_off_area"] > 0 and c["contact_area"] > 0  # it lifts off, not all of it
    # both make up the meshed base: the plate less two bolt holes meshed as octagons (their
    # 37.7 mm circumference over gmsh's smallest element at 20 mm, size/4 = 5 mm:
    # domain.bracket), to round-off
    r, n = 6.0, 8
    octagons = 2 * n / 2 * r**2 * math.sin(2 * math.pi / n)
    meshed = c["lifted_off_area"] + c["contact_area"]
    assert meshed == pytest.approx(100 * 60 - octagons, rel=1e-9)
    # equilibrium: the bolts take the pull, the frictionless floor pushes only upwards, and
    # bolts and floor balance vertically (a node on both counts with the bolts)
    (bx, by, bz), (fx, fy, fz) = c["reactions"]["bolts"], c["reactions"]["base"]
    assert bx == pytest.approx(-8e3, rel=1e-8) and fz > 0
    assert max(abs(by), abs(fx), abs(fy), abs(bz + fz)) < 1e-8 * 8e3
    assert 0 < c["max_floor_pressure"] < 1e4  # finite at the P2 vertices too (HRZ areas)
    # the floor only adds support: the arm moves less than with the bolts alone
    assert c["load_point_displacement"] < k["load_point_displacement"]


def test_bracket_outputs_and_bolt_reaction(tmp_path, demo):
    proc = demo.run(["bracket.py", "--size", "20", "--steps", "1", "--output", "f",
                     "--png", "b.png", "--plot", "c.png", "--json", "b.json"])
    assert "X server" not in proc.stderr and proc.stderr == ""  # off-screen, no VTK noise
    d = json.loads((tmp_path / "b.json").read_text())
    assert (tmp_path / "f" / "displacement.bp").is_dir()
    assert (tmp_path / "f" / "von_mises.bp").is_dir()
    assert (tmp_path / "b.png").stat().st_size > 50_000 and (tmp_path / "c.png").exists()
    fx, fy, fz = d["reactions"]["bolts"]  # the bolts hold the whole 8 kN along -x
    assert fx == pytest.approx(-8e3, rel=1e-8) and max(abs(fy), abs(fz)) < 1e-8 * 8e3
    assert any("coarser than the default" in w for w in d["warnings"])


def test_bracket_iterative_solver_matches_direct(demo):
    # CG + GAMG (inexact Newton corrections) must land on MUMPS's answer: the Newton
    # loop stops on the same residual tolerance whatever the linear solver (on the page's
    # mesh, whose direct run the suite makes anyway: 11.6k unknowns, three GAMG levels)
    args = tuple(SMALL["bracket.py"])
    d = demo.bracket(*args)
    g = demo.bracket(*args, "--linear-solver", "gamg")
    assert d["krylov_iterations"] == 0 and g["krylov_iterations"] > g["newton_iterations"]
    assert g["load_point_displacement"] == pytest.approx(d["load_point_displacement"], rel=1e-7)


BRACKET_ON_FLOOR_GAMG = (*BRACKET_ON_FLOOR, "--linear-solver", "gamg")


def test_bracket_on_its_floor_on_the_iterative_path_gives_the_direct_answer(demo):
    # the active-set loop with CG + GAMG inner solves: the same active set (the same lifted
    # and contact areas, to the bit: the same facets), the same answer within Newton's
    # tolerance; an AMG hierarchy is set up at each inner solve's start, and again within
    # it only when CG slows down: fewer set-ups than Newton iterations
    d = demo.bracket(*BRACKET_ON_FLOOR)
    g = demo.bracket(*BRACKET_ON_FLOOR_GAMG)
    assert g["active_set_iterations"] == d["active_set_iterations"]
    assert (g["lifted_off_area"], g["contact_area"]) == (d["lifted_off_area"],
                                                         d["contact_area"])
    assert g["load_point_displacement"] == pytest.approx(d["load_point_displacement"], rel=1e-8)
    assert g["max_floor_pressure"] == pytest.approx(d["max_floor_pressure"], rel=1e-8)
    assert g["krylov_iterations"] > g["newton_iterations"] > g["factorizations"]


# the serial runs the serial suite makes (the clamped bracket's page, the bracket on its floor
# of tests/test_friction.py, and on the iterative path): their answers are the references
@pytest.mark.parametrize("args", [tuple(SMALL["bracket.py"]), BRACKET_ON_FLOOR,
                                  BRACKET_ON_FLOOR_GAMG], ids=["clamped", "contact", "gamg"])
@pytest.mark.mpi
def test_bracket_two_ranks_match_serial(args, demo):
    # 20 mm elements (11.6k unknowns): the partition still cuts the holes and the floor
    s = demo.bracket(*args)
    p = demo.bracket(*args, ranks=2)
    assert p["ranks"] == 2 and p["dofs"] == s["dofs"]
    assert p["load_point_displacement"] == pytest.approx(s["load_point_displacement"], rel=1e-8)
    for group, r in s["reactions"].items():
        assert np.allclose(p["reactions"][group], r, rtol=1e-7, atol=1e-9 * 8e3)


def _box_without_groups(path, fold=False):
    import gmsh

    from fenics_nl.domain.meshes import start_model

    start_model("box")  # gmsh's defaults: no mesh size left over from an earlier bracket
    gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
    gmsh.model.occ.synchronize()
    gmsh.model.addPhysicalGroup(3, [1], 1, name="solid")
    gmsh.model.addPhysicalGroup(2, [1], 2, name="bolts")
    gmsh.model.mesh.generate(3)
    if fold:  # push the node nearest the centre through its neighbours
        tags, x, _ = gmsh.model.mesh.getNodes()
        x = x.reshape(-1, 3)
        i = np.argmin(np.linalg.norm(x - 0.5, axis=1))
        gmsh.model.mesh.setNode(int(tags[i]), list(x[i] + [0.4, 0, 0]), [])
    gmsh.write(str(path))
    gmsh.finalize()


def _two_boxes_one_tagged_twice(path):
    import gmsh

    from fenics_nl.domain.meshes import start_model

    start_model("boxes")
    gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
    gmsh.model.occ.addBox(1, 0, 0, 1, 1, 1)
    gmsh.model.occ.fragment([(3, 1)], [(3, 2)])
    gmsh.model.occ.synchronize()
    gmsh.model.addPhysicalGroup(3, [1, 2], 1, name="solid")
    gmsh.model.addPhysicalGroup(3, [2], 2, name="again")  # dolfinx refuses a cell in two
    gmsh.model.mesh.generate(3)
    gmsh.write(str(path))
    gmsh.finalize()


def test_bracket_bad_mesh_input_one_clear_line(tmp_path, demo):
    (tmp_path / "corrupt.msh").write_text("$MeshFormat\nthis is not a mesh\n")
    _box_without_groups(tmp_path / "box.msh")
    _box_without_groups(tmp_path / "folded.msh", fold=True)
    _two_boxes_one_tagged_twice(tmp_path / "twice.msh")
    for args, message in [(["--mesh", "nowhere.msh"], "mesh file not found"),
                          (["--mesh", "corrupt.msh"], "cannot read mesh file"),
                          (["--mesh", "box.msh"], "no physical group load, base"),
                          (["--mesh", "twice.msh"], "is in the physical groups"),
                          (["--mesh", "folded.msh"], "inverted (folded over a neighbour)"),
                          (["--support", "contact", "--newton", "snes"], "clamped only"),
                          (["--nu", "0.6"], "nu must be in"), (["--size", "0"], "--size"),
                          (["--tolerance", "0"], "tolerance must be in"),
                          (["--size", "1e6"], "more than twice the plate thickness"),
                          (["--mesh", "box.msh", "--size", "3"], "contradict"),
                          (["--compare", "--png", "x.png"], "--compare"),
                          (["--force", "nan"], "--force: must be a finite number"),
                          (["--material", "linear", "--sigma0", "100"], "set the power law"),
                          (["--compare", "--newton", "modified"], "drop --newton")]:
        demo.refuses(["bracket.py", *args], message)


def test_bracket_j2_loaded_and_unloaded(demo):
    # von Mises plasticity to 8 kN and back: a permanent set, no force left on the bolts
    d = demo.bracket("--material", "j2", "--size", "20", "--steps", "2", "--unload")
    assert 0 < d["permanent_load_point_displacement"] < d["load_point_displacement"]
    assert max(abs(x) for x in d["reactions"]["bolts"]) < 1e-6 * d["force"]
    assert d["max_cumulated_plastic_strain"] > 0 and 0 < d["plastic_volume_fraction"] < 1


def test_a_bracket_on_the_floor_in_j2_restarts_on_the_same_path(tmp_path, demo):
    # the plastic state, the floor's active set and the steps so far come back: restarted
    # one saved step short of the loading's end, the same JSON key by key (times aside)
    import json

    from test_vessel import same_run

    args = ["--material", "j2", "--support", "contact", "--size", "20", "--steps", "2"]
    whole = demo.bracket(*args, "--checkpoint", tmp_path / "ck")
    (tmp_path / "ck" / "latest.json").write_text(json.dumps({"step": "step-000001"}))
    resumed = demo.bracket(*args, "--restart", tmp_path / "ck")
    assert len(resumed["steps"]) == 2
    same_run(whole, resumed)
    proc = demo.run(["bracket.py", *args, "--compare", "--restart", tmp_path / "ck"],
                    check=False)
    assert proc.returncode == 2 and "not --compare" in proc.stderr


def restarted_one_step_short(run, tmp_path, args, steps):
    """A punch demo's run (`run`: `demo.punch`, ...) with --checkpoint, and again restarted
    one saved step short of its loading's end: both JSONs."""
    import json

    whole = run(*args, "--steps", str(steps), "--checkpoint", tmp_path / "ck")
    (tmp_path / "ck" / "latest.json").write_text(json.dumps({"step": f"step-{steps - 1:06d}"}))
    return whole, run(*args, "--steps", str(steps), "--restart", tmp_path / "ck")


def test_a_frictional_punch_restarts_on_the_same_path(tmp_path, demo):
    # the slip history, then the tangential load redone: the same JSON, key by key, to
    # 1e-10 (the frictionless elastic punch has no history: it takes no --checkpoint)
    from test_vessel import same_run

    args = ["--nu", "0.3", "--block", "10", "--tangential-ratio", "0.5", "--refine", "0"]
    same_run(*restarted_one_step_short(demo.punch_friction, tmp_path, args, 2))


def test_punch_j2_load_unload_leaves_an_imprint(tmp_path, demo):
    # von Mises plasticity under the punch: the force stays below elastic Hertz, the
    # unloaded surface keeps a dent, the punch leaves it with no force
    from test_vessel import same_run

    d, resumed = restarted_one_step_short(demo.indentation, tmp_path, ["--refine", "0"], 2)
    same_run(d, resumed)  # the plastic state comes back with a restart; the unloading redone
    assert d["force"] < d["hertz_force"]
    assert 0 < d["residual_imprint_depth"] < d["indentation"]
    assert abs(d["unloading"][-1]["force"]) < 1e-9 * d["force"]
    assert d["max_cumulated_plastic_strain"] > 0
    # the curve of every converged step, loading and unloading
    assert d["indentation_history"] == [s["indentation"] for s in d["steps"]]
    assert d["force_history"] == [s["force"] for s in d["steps"]]
    assert len(d["force_history"]) == 4 and d["force_history"][1] == d["force"]


def identification_recovers_sigma0_and_hardening_within_their_spread(d):
    """What `demos/indentation_identification.py`'s page run must show (checked on that
    run in `tests/test_notebooks.py`: one run for both).

    The demo's synthetic experiment: a curve on another mesh with 1 % noise, the fit started
    a factor 2 off; σ0 and H within their standard deviations (the seed is fixed: about two
    seeds in three do so for both, as for any 1σ interval), the curve's fit as good as its
    noise, H strongly anti-correlated with σ0; the values the finer model's, the deviations
    the noise's and the shift to it.
    """
    assert d["converged"] and d["synthetic"]
    for name in ("sigma0", "hardening"):
        assert abs(d[f"{name}_error_in_std"]) <= 1, d
        assert 0 < d[f"{name}_std"] < 0.5 * d[name]
        assert d[name] == pytest.approx(d[f"{name}_fit_model"]
                                        - d[f"{name}_discretisation_shift"])
        assert d[f"{name}_std"] == pytest.approx(math.hypot(
            d[f"{name}_noise_std"], d[f"{name}_discretisation_shift"]))
    assert -1 < d["correlation"] < -0.9
    assert d["noise"] == pytest.approx(0.01 * max(d["curve"]["measured"]), rel=0.5)
    assert d["forward_solves"] <= 12 and d["iterations"] >= 3
    assert d["sensitivity_solves"] == 2 * len(d["curve"]["depth"]) * d["forward_solves"]


@pytest.mark.parametrize("args,message", [
    (["--fit", "sigma0,yield"], "unknown parameter yield: choose among sigma0, hardening"),
    (["--initial", "0.02"], "--initial '0.02': 1 value(s) for 2 parameter(s)"),
    (["--true=-0.02,0.1"], "--true: sigma0 must be > 0"),
    (["--curve", "one.csv"], "one.csv: 1 column(s); the curve needs two, depth and force"),
    (["--curve", "negative.csv"], "depth must be >= 0 (point 2 has -0.01)"),
    (["--curve", "missing.csv"], "curve file missing.csv does not exist"),
    (["--curve", "one.csv", "--true", "1,1"], "--true is for the synthetic experiment"),
    (["--curve", "one.csv", "--noise", "0"], "--noise is for the synthetic experiment"),
    (["--curve", "bare.csv"], "bare.csv: its first line is numbers; the curve needs a header"),
    (["--curve", "few.csv", "--fit", "sigma0,hardening,E"],
     "the curve has 3 points of non-zero depth for 3 parameters"),
])
def test_indentation_identification_bad_input_one_clear_line(args, message, demo, tmp_path):
    (tmp_path / "one.csv").write_text("depth\n0.01\n0.02\n0.03\n")
    (tmp_path / "negative.csv").write_text("depth,force\n0.01,1\n-0.01,2\n0.02,3\n")
    (tmp_path / "bare.csv").write_text("0.01,1\n0.02,2\n0.03,3\n")
    (tmp_path / "few.csv").write_text("depth,force\n0.01,1\n0.02,2\n0.015,1\n")
    demo.refuses(["indentation_identification.py", *args], message)


def test_punch_demos_loop_is_the_librarys_active_set(demo):
    # the demo writes the course's loop out; `ActiveSetContact.solve` (the friction, case
    # and identification runs' loop) must settle on the same set, force and iterations
    from punch_problem import build_punch

    from fenics_nl.materials.laws import LinearElastic

    d = demo.punch("--refine", "0")
    state = build_punch("axisymmetric", LinearElastic(1.0, 0.3), 1.0, 0.1, refine=0).indent(0.01)
    assert state.force == pytest.approx(d["force"], rel=1e-12)
    assert state.contact_radius == d["contact_radius"]
    assert state.active_set_iterations == d["active_set_iterations"]
