"""Case files against closed forms, through `python -m fenics_nl` only."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import read_series, run_and_kill, same_answer

CASES = Path(__file__).resolve().parents[1] / "cases"

BAR_GEO = """SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 10, 1, 2};
Physical Surface("x0") = Surface In BoundingBox{-0.1, -0.1, -0.1, 0.1, 1.1, 2.1};
Physical Surface("end") = Surface In BoundingBox{9.9, -0.1, -0.1, 10.1, 1.1, 2.1};
Physical Surface("y0") = Surface In BoundingBox{-0.1, -0.1, -0.1, 10.1, 0.1, 2.1};
Physical Surface("z0") = Surface In BoundingBox{-0.1, -0.1, -0.1, 10.1, 1.1, 0.1};
Physical Volume("bar") = {1};
Mesh.MeshSizeMax = 0.5;
"""

BAR = """[mesh]
file = "bar.geo"
model = "3d"

[material]
law = "linear-elastic"
E = 1000.0
nu = 0.25

[[boundary]]
group = "x0"
displacement = [0.0, "free", "free"]

[[boundary]]
group = "y0"
displacement = ["free", 0.0, "free"]

[[boundary]]
group = "z0"
displacement = ["free", "free", 0.0]

[[boundary]]
group = "end"
traction = [50.0, 0.0, 0.0]

[loading]
steps = 2

[[probe]]
name = "corner"
point = [10.0, 1.0, 2.0]
"""


def write(tmp_path, name, text):
    (tmp_path / name).write_text(text)
    return tmp_path / name


def test_bar_in_tension_is_exact(tmp_path, demo):
    # σ = 50 on the end: u = (σx/E, −νσy/E, −νσz/E), linear, so P1 is exact
    write(tmp_path, "bar.geo", BAR_GEO)
    d = demo.case(write(tmp_path, "bar.toml", BAR))
    ux, uy, uz = d["probes"]["corner"]["displacement"]
    assert [ux, uy, uz] == pytest.approx([0.5, -0.0125, -0.025], rel=1e-9)
    assert d["probes"]["corner"]["von_mises"] == pytest.approx(50.0, rel=1e-9)
    # half the load at the first of the two steps
    assert d["steps"][0]["probes"]["corner"]["displacement"][0] == pytest.approx(0.25, rel=1e-9)
    # each support reports the components it holds: x0 takes the whole σ A = 100, also at
    # the edges it shares with y0 and z0
    assert d["reactions"]["x0"] == pytest.approx([-100.0, 0.0, 0.0], abs=1e-9 * 100)
    for name in ("y0", "z0"):
        assert d["reactions"][name] == pytest.approx([0.0, 0.0, 0.0], abs=1e-9 * 100)


def lame(r, a=10.0, b=20.0, p=100.0, E=210000.0, nu=0.3):
    """Radial displacement of a thick cylinder under internal pressure (plane strain)."""
    A, B = p * a * a / (b * b - a * a), p * a * a * b * b / (b * b - a * a)
    return (1 + nu) / E * ((1 - 2 * nu) * A * r + B / r)


def test_thick_cylinder_plane_strain_matches_lame(demo):
    d = demo.case(CASES / "thick_cylinder.toml")
    # P2 on curved (quadratic) edges, h = 1.5 mm: measured 6e-5 and 9e-6 relative
    assert d["probes"]["inner"]["displacement"][0] == pytest.approx(lame(10.0), rel=3e-4)
    assert d["probes"]["outer"]["displacement"][0] == pytest.approx(lame(20.0), rel=3e-4)
    # σ_eq at the bore and the outer surface (Lamé, σ_z = ν(σ_r + σ_θ)): measured −0.46 %
    # and −0.08 % (σ interpolated cell by cell at the P2 degree, evaluated at the point)
    for name, r in (("inner", 10.0), ("outer", 20.0)):
        A, B = 100.0 * 100 / 300, 100.0 * 100 * 400 / 300
        sr, st = A - B / r**2, A + B / r**2
        sz = 0.3 * (sr + st)
        vm = math.sqrt(0.5 * ((sr - st) ** 2 + (st - sz) ** 2 + (sz - sr) ** 2))
        assert d["probes"][name]["von_mises"] == pytest.approx(vm, rel=0.01)
    # the quarter's symmetry planes carry the pressure's resultant p a = 1000 N/mm
    assert d["reactions"]["symmetry_x"][0] == pytest.approx(-1000.0, rel=1e-9)
    assert d["reactions"]["symmetry_y"][1] == pytest.approx(-1000.0, rel=1e-9)


AXI_GEO = """a = 10; b = 20; H = 4; h = 1;
Point(1) = {a, 0, 0, h}; Point(2) = {b, 0, 0, h}; Point(3) = {b, H, 0, h}; Point(4) = {a, H, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Physical Curve("bottom") = {1}; Physical Curve("outer") = {2};
Physical Curve("top") = {3}; Physical Curve("inner") = {4};
Physical Surface("wall") = {1};
"""

AXI = """[mesh]
file = "ring.geo"
model = "axisymmetric"
degree = 2

[material]
law = "linear-elastic"
E = 210000.0
nu = 0.3

[[boundary]]
group = "bottom"
displacement = ["free", 0.0]

[[boundary]]
group = "top"
displacement = ["free", 0.0]

[[boundary]]
group = "inner"
pressure = 100.0

[loading]
steps = 1

[[probe]]
name = "inner"
point = [10.0, 2.0]

[[probe]]
name = "outer"
point = [20.0, 2.0]
"""


def test_incompressible_thick_cylinder_in_the_mixed_formulation(tmp_path, demo):
    # the same case at ν = 0.5: a one-line error without the mixed formulation, Lamé with it
    text = (CASES / "thick_cylinder.toml").read_text().replace("nu = 0.3", "nu = 0.5")
    (tmp_path / "thick_cylinder.geo").write_text((CASES / "thick_cylinder.geo").read_text())
    plain = demo.run(["-m fenics_nl", "check", write(tmp_path, "c.toml", text)], check=False)
    assert plain.returncode != 0 and 'formulation = "mixed"' in plain.stderr
    mixed = text.replace("degree = 2", 'degree = 2\nformulation = "mixed"')
    d = demo.case(write(tmp_path, "m.toml", mixed))
    for name, r in (("inner", 10.0), ("outer", 20.0)):
        assert d["probes"][name]["displacement"][0] == pytest.approx(lame(r, nu=0.5), rel=3e-4)
    # and iteratively (MINRES, block preconditioner): the same answer
    iterative = mixed.replace("[loading]", '[solver]\nlinear_solver = "gamg"\n\n[loading]')
    i = demo.case(write(tmp_path, "i.toml", iterative))
    assert i["probes"]["inner"]["displacement"][0] == pytest.approx(
        d["probes"]["inner"]["displacement"][0], rel=1e-7)


def test_thick_cylinder_axisymmetric_matches_lame(tmp_path, demo):
    # ends held axially: plane strain, the same u_r(r) as the 2D case
    write(tmp_path, "ring.geo", AXI_GEO)
    d = demo.case(write(tmp_path, "ring.toml", AXI))
    assert d["probes"]["inner"]["displacement"][0] == pytest.approx(lame(10.0), rel=3e-4)
    assert d["probes"]["outer"]["displacement"][0] == pytest.approx(lame(20.0), rel=3e-4)
    # each end holds σ_zz = 2νA over π(b² − a²): 2ν p a² π, whole revolution
    axial = 2 * 0.3 * 100.0 * 100.0 * math.pi
    assert d["reactions"]["top"][1] == pytest.approx(axial, rel=1e-3)
    assert d["reactions"]["bottom"][1] == pytest.approx(-axial, rel=1e-3)


PUNCH = """[mesh]
file = "block.msh"
model = "axisymmetric"

[material]
law = "linear-elastic"
E = 1.0
nu = 0.3

[[boundary]]
group = "symmetry_x"
displacement = [0.0, "free"]

[[boundary]]
group = "bottom"
displacement = ["free", 0.0]

[[boundary]]
group = "contact"
contact = { obstacle = "sphere", center = [0.0, 1.0], radius = 1.0, displacement = [0.0, -0.01] }

[loading]
steps = 1
"""


def test_hertz_punch_as_a_case_equals_the_demo(tmp_path, demo):
    # the demo's mesh (axisymmetric, --refine 0: h = a/20, 1000 a wide, 5 % growth), written
    # to a .msh by the same gmsh code, and the sphere pressed by δ = 0.01 R
    from mpi4py import MPI

    from fenics_nl.domain.meshes import graded_block

    a = 0.1
    graded_block(MPI.COMM_WORLD, 2, 1000 * a, 1000 * a, a / 20, 1.5 * a, 0.05,
                 msh_file=tmp_path / "block.msh")
    case = demo.case(write(tmp_path, "punch.toml", PUNCH))
    ref = demo.punch("--refine", "0", "--gap", "sphere")
    assert case["dofs"] == ref["dofs"]
    assert case["contact_force"] == pytest.approx(ref["force"], rel=1e-8)
    assert case["steps"][-1]["nodes_in_contact"] == ref["nodes_in_contact"]
    # the supports balance the contact force, which the contact group's reaction is
    r = case["reactions"]
    assert r["contact"][1] == pytest.approx(-case["contact_force"], rel=1e-8)
    assert r["symmetry_x"][1] + r["bottom"][1] == pytest.approx(case["contact_force"], rel=1e-8)


@pytest.mark.parametrize("path", sorted(CASES.glob("*.toml")), ids=lambda p: p.stem)
def test_every_shipped_case_checks(demo, path):
    proc = demo.run(["-m fenics_nl", "check", path])
    assert "the case is complete" in proc.stdout


@pytest.mark.mpi
def test_two_ranks_give_the_serial_answer(demo):
    s = demo.case(CASES / "thick_cylinder.toml")
    p = demo.case(CASES / "thick_cylinder.toml", ranks=2)
    assert p["ranks"] == 2
    for name in ("inner", "outer"):
        assert p["probes"][name]["displacement"] == pytest.approx(
            s["probes"][name]["displacement"], rel=1e-9, abs=1e-15)
        assert p["probes"][name]["von_mises"] == pytest.approx(s["probes"][name]["von_mises"],
                                                               rel=1e-9)
    assert p["reactions"]["symmetry_x"] == pytest.approx(s["reactions"]["symmetry_x"],
                                                         rel=1e-9, abs=1e-9)


def check(demo, tmp_path, text, geo=None):
    if geo is not None:
        write(tmp_path, "part.geo", geo)
    proc = demo.run(["-m fenics_nl", "check", write(tmp_path, "bad.toml", text)], check=False)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    return proc.stderr.strip().splitlines()


def test_every_mistake_of_a_file_at_once(tmp_path, demo):
    text = BAR.replace('file = "bar.geo"', 'file = "bar.geo"\nsise = 2.0')
    text = text.replace("nu = 0.25", "nu = 0.7").replace("[50.0, 0.0, 0.0]", "[50.0, 0.0]")
    text = text.replace("steps = 2", "step = 2").replace('law = "linear-elastic"',
                                                         'law = "linear-elastic"\nsigma0 = 1.0')
    write(tmp_path, "bar.geo", BAR_GEO)
    lines = check(demo, tmp_path, text)
    expected = ["mesh.sise: unknown key", "material.nu: must be in (-1, 0.5], got 0.7",
                "material.sigma0: unknown key", "boundary[4].traction: must be a list of 3",
                "loading.step: unknown key", "loading.steps: missing"]
    for e in expected:
        assert sum(e in line for line in lines) == 1, (e, lines)
    assert len(lines) == len(expected)
    assert "did you mean 'size'?" in next(line for line in lines if "mesh.sise" in line)


def test_a_load_too_large_for_floating_point_names_its_key(tmp_path, demo):
    write(tmp_path, "bar.geo", BAR_GEO)
    lines = check(demo, tmp_path, BAR.replace("[50.0, 0.0, 0.0]", "[1e308, 1e308, 0.0]"))
    assert len(lines) == 1 and lines[0].startswith("error: boundary[4].traction: "), lines
    assert "overflows floating point" in lines[0]


def test_a_misspelt_key_beside_the_missing_one_is_named(tmp_path, demo):
    write(tmp_path, "bar.geo", BAR_GEO)
    lines = check(demo, tmp_path, BAR.replace('law = "linear-elastic"', 'lawe = "j2"'))
    assert any("material.law: missing" in line for line in lines), lines
    assert any("material.lawe: unknown key (did you mean 'law'?" in line for line in lines)


def test_a_2d_model_on_a_3d_mesh_is_one_line(tmp_path, demo):
    write(tmp_path, "bar.geo", BAR_GEO)
    text = """[mesh]\nfile = "bar.geo"\nmodel = "plane_strain"\n[material]\nlaw = "linear-elastic"
E = 1.0\nnu = 0.3\n[[boundary]]\ngroup = "x0"\ndisplacement = [0.0, 0.0]\n[loading]\nsteps = 1\n"""
    lines = check(demo, tmp_path, text)
    assert lines == ["error: mesh.model: 'plane_strain' needs a 2D mesh, bar.geo has 3D cells"]


def test_a_3d_model_on_a_2d_mesh_is_that_line_alone(tmp_path, demo):
    # the 2D cylinder's vectors have 2 components: counted against "3d" they were wrong
    # too, and said first; the mesh's dimension is the one thing to say
    text = (CASES / "thick_cylinder.toml").read_text().replace('"plane_strain"', '"3d"')
    (tmp_path / "thick_cylinder.geo").write_text((CASES / "thick_cylinder.geo").read_text())
    lines = check(demo, tmp_path, text)
    assert lines == ["error: mesh.model: '3d' needs a 3D mesh, thick_cylinder.geo has 2D "
                     "cells"]


@pytest.mark.parametrize("change,message", [
    (('group = "end"', 'group = "tip"'), "'tip' is not a boundary group of the mesh (it has: "
                                         "end, x0, y0, z0)"),
    (("point = [10.0, 1.0, 2.0]", "point = [10.0, 1.0, 2.5]"), "probe[1].point: [10.0, 1.0, "
                                                                "2.5] is outside the mesh"),
    (('file = "bar.geo"', 'file = "broken.geo"'), "mesh.file: gmsh cannot mesh broken.geo"),
    (('file = "bar.geo"', 'file = "nowhere.msh"'), "nowhere.msh not found"),
])
def test_a_mistake_against_the_mesh_is_one_line(tmp_path, demo, change, message):
    write(tmp_path, "bar.geo", BAR_GEO)
    write(tmp_path, "broken.geo", "Point(1) = {0, 0, 0;\n")
    lines = check(demo, tmp_path, BAR.replace(*change))
    assert len(lines) == 1 and message in lines[0], lines


SPLIT_GEO = """Point(1) = {0, 0, 0, 0.25}; Point(2) = {1, 0, 0, 0.25}; Point(3) = {1, 1, 0, 0.25};
Point(4) = {0, 1, 0, 0.25}; Point(5) = {0.5, 0, 0, 0.25}; Point(6) = {0.5, 1, 0, 0.25};
Line(1) = {1, 5}; Line(2) = {5, 2}; Line(3) = {2, 3}; Line(4) = {3, 6}; Line(5) = {6, 4};
Line(6) = {4, 1}; Line(7) = {5, 6};
Curve Loop(1) = {1, 7, 5, 6}; Plane Surface(1) = {1};
Curve Loop(2) = {2, 3, 4, -7}; Plane Surface(2) = {2};
Physical Curve("left") = {6}; Physical Curve("middle") = {7};
Physical Surface("body") = {1, 2};
"""

SQUARE = """[mesh]
file = "part.geo"
model = "plane_strain"

[material]
law = "linear-elastic"
E = 1.0
nu = 0.3

[[boundary]]
group = "left"
displacement = [0.0, 0.0]

[[boundary]]
group = "middle"
traction = [1.0, 0.0]

[loading]
steps = 1
"""


@pytest.mark.parametrize("change,message", [
    (("", ""), "boundary[2].group: 4 facet(s) of 'middle' are inside the body"),
    (('law = "linear-elastic"', 'law = "power-law"'), "material.sigma0: missing"),
    (('group = "left"\ndisplacement = [0.0, 0.0]', 'group = "left"\ntraction = [0.0, 1.0]'),
     "boundary: no displacement or contact condition: nothing holds the body"),
    (('group = "middle"\ntraction = [1.0, 0.0]', 'group = "left"\ndisplacement = [0.5, "free"]'),
     "boundary[2].displacement: u_x of group 'left' is already prescribed by "
     "boundary[1].displacement"),
    (('model = "plane_strain"', 'model = "axisymmetric"'),
     "4 facet(s) of 'middle' are inside the body"),
])
def test_what_a_file_cannot_mean_is_refused(tmp_path, demo, change, message):
    lines = check(demo, tmp_path, SQUARE.replace(*change), geo=SPLIT_GEO)
    assert any(message in line for line in lines), lines


def test_an_off_axis_sphere_is_refused_in_the_axisymmetric_model(tmp_path, demo):
    text = PUNCH.replace("center = [0.0, 1.0]", "center = [0.5, 1.0]")
    (tmp_path / "block.msh").write_text("")
    lines = check(demo, tmp_path, text)
    assert lines == ["error: boundary[3].contact.center: axisymmetric: the sphere is centred "
                     "on the axis (r = 0); off the axis it would be a torus"]


def test_the_console_script_is_installed(tmp_path):
    import subprocess
    import sys

    script = Path(sys.executable).parent / "fenics-nl"
    proc = subprocess.run([script, "--help"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and "[[boundary]]" in proc.stdout


def test_j2_bar_loaded_and_unloaded_keeps_its_permanent_strain(tmp_path, demo):
    # traction 1.5 σ0 with hardening H, then 0: ε_p = (σ − σ0)(1/E_t − 1/E), E_t = EH/(E + H)
    write(tmp_path, "bar.geo", BAR_GEO)
    text = BAR.replace('law = "linear-elastic"\nE = 1000.0\nnu = 0.25',
                       'law = "j2"\nE = 1000.0\nnu = 0.25\nsigma0 = 40.0\nH = 100.0\nC = 0.0')
    text = text.replace("traction = [50.0, 0.0, 0.0]", "traction = [60.0, 0.0, 0.0]")
    text = text.replace("steps = 2", "steps = [0.5, 1.0, 0.0]")
    d = demo.case(write(tmp_path, "j2.toml", text))
    E_t = 1000.0 * 100.0 / 1100.0
    loaded = 40.0 / 1000.0 + 20.0 / E_t
    permanent = 20.0 * (1 / E_t - 1 / 1000.0)
    ux = [s["probes"]["corner"]["displacement"][0] for s in d["steps"]]
    assert [s["load_factor"] for s in d["steps"]] == [0.5, 1.0, 0.0]
    assert ux == pytest.approx([10 * 30.0 / 1000.0, 10 * loaded, 10 * permanent], rel=1e-9)
    assert d["reactions"]["x0"][0] == pytest.approx(0.0, abs=1e-9 * 60)


def test_j2_at_finite_strain_bar_pulled_to_a_log_strain_of_0_3(tmp_path, demo):
    # ln λ = 0.3 = p + σ_y(p)/E (Hencky), τ = σ_y(p); the end's reaction τ A0/λ (the plastic
    # flow keeps the volume, the elastic J cancels between σ = τ/J and the area), σ_eq = τ/J
    write(tmp_path, "bar.geo", BAR_GEO)
    stretch = math.exp(0.3)
    text = BAR.replace('law = "linear-elastic"\nE = 1000.0\nnu = 0.25',
                       'law = "j2-finite"\nE = 1000.0\nnu = 0.25\nsigma0 = 40.0\nH = 100.0')
    text = text.replace("traction = [50.0, 0.0, 0.0]",
                        f'displacement = [{10 * (stretch - 1)}, "free", "free"]')
    text = text.replace("steps = 2", "steps = 10")
    d = demo.case(write(tmp_path, "j2_finite.toml", text))
    p = (0.3 - 40.0 / 1000.0) / (1 + 100.0 / 1000.0)
    tau = 40.0 + 100.0 * p
    assert d["reactions"]["x0"][0] == pytest.approx(-tau * 2.0 / stretch, rel=1e-8)
    J = math.exp(tau * (1 - 2 * 0.25) / 1000.0)
    assert d["probes"]["corner"]["von_mises"] == pytest.approx(tau / J, rel=1e-8)


def test_arc_length_control_follows_the_arch_through_its_snap(demo):
    # load control stops at the limit point; the arc-length path goes through it, down the
    # unstable branch and up the inverted one, to the target
    d = demo.case(CASES / "shallow_arch.toml")
    loads = [s["load_factor"] for s in d["steps"]]
    assert d["load_factor"] == 3.0 and max(loads) < 3.0 + 1e-12
    top = next(k for k in range(len(loads) - 1) if loads[k + 1] < loads[k])
    assert min(loads[top:]) < 0.5 * loads[top]  # the load fell past the limit point
    limits = [c for c in d["critical_points"] if c["kind"] == "limit"]
    assert len(limits) == 2
    # the first is the largest load before the fall, the second the smallest after it
    assert limits[0]["load_factor"] >= max(loads[:top + 1]) - 1e-12
    assert limits[1]["load_factor"] <= min(loads[top:]) + 1e-12
    crown = d["probes"]["crown"]["displacement"][1]
    assert crown < -2 * 30.0  # inverted: below the chord, as far as it rose above it
    # an antisymmetric bifurcation comes first: passed on the symmetric branch, and said
    assert d["critical_points"][0]["kind"] == "bifurcation"
    # every critical point is bracketed (to 1/32 of the arc it was met with)
    assert all(abs(c["between"][1] - c["between"][0]) < 0.02 * max(loads)
               for c in d["critical_points"])
    assert any("bifurcation" in w for w in d["warnings"]) and d["control"] == "arc-length"
    assert d["steps"][0]["negative_eigenvalues"] == 0 == d["steps"][-1]["negative_eigenvalues"]
    assert max(s["negative_eigenvalues"] for s in d["steps"]) >= 1


def test_arc_length_control_on_a_linear_problem_is_load_control(tmp_path, demo):
    # no critical point on the thick cylinder: the arc lands on the same state
    text = (CASES / "thick_cylinder.toml").read_text().replace(
        "[loading]\nsteps = 1", '[loading]\ncontrol = "arc-length"\ntarget = 1.0')
    (tmp_path / "thick_cylinder.geo").write_text((CASES / "thick_cylinder.geo").read_text())
    arc = demo.case(write(tmp_path, "arc.toml", text))
    load = demo.case(CASES / "thick_cylinder.toml")
    assert arc["critical_points"] == []
    for name in ("inner", "outer"):
        assert arc["probes"][name]["displacement"] == pytest.approx(
            load["probes"][name]["displacement"], rel=1e-8, abs=1e-15)


@pytest.mark.parametrize("change,message", [
    ("steps = 2\ncontrol = \"arc-length\"", 'loading.steps: not with control = "arc-length"'),
    ('control = "arc-length"\narc_length = 0.0', "loading.arc_length: must be > 0"),
    ('control = "arc-length"\ntarget = 0.0', "loading.target: must not be 0"),
    ('control = "arc-length"\nmax_arc_length = 0.01', "loading.max_arc_length: must be >= "),
    ("steps = 2\ntarget = 2.0", 'loading.target: only with control = "arc-length"'),
])
def test_arc_length_parameters_are_checked(tmp_path, demo, change, message):
    write(tmp_path, "bar.geo", BAR_GEO)
    lines = check(demo, tmp_path, BAR.replace("steps = 2", change))
    assert any(message in line for line in lines), lines


def test_arc_length_refuses_what_it_cannot_scale(tmp_path, demo):
    lines = check(demo, tmp_path, SQUARE.replace(
        "steps = 1", 'control = "arc-length"').replace(
        'group = "middle"\ntraction = [1.0, 0.0]', 'group = "middle"\ndisplacement = [0.1, '
                                                  '"free"]'), geo=SPLIT_GEO)
    assert any("arc-length control scales loads only" in line for line in lines), lines


def without_symmetry_y(tmp_path):
    text = (CASES / "thick_cylinder.toml").read_text()
    tables = text.split("[[boundary]]")
    text = "[[boundary]]".join(t for t in tables if "symmetry_y" not in t)
    (tmp_path / "thick_cylinder.geo").write_text((CASES / "thick_cylinder.geo").read_text())
    return write(tmp_path, "free.toml", text)


def test_a_body_its_supports_leave_free_is_one_line(tmp_path, demo):
    # the quarter cylinder without its symmetry_y support slides along y
    proc = demo.run(["-m fenics_nl", "run", without_symmetry_y(tmp_path), "--json",
                     tmp_path / "free.json"], check=False)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert "translation along y" in lines[0] and "support or a symmetry condition" in lines[0]
    assert not (tmp_path / "free.json").exists()  # bad input: nothing was solved


def test_the_stress_at_a_probe_is_lame(demo):
    # Lamé at the bore: σ_r = −p, σ_θ = p (b² + a²)/(b² − a²), σ_z = ν(σ_r + σ_θ); the same
    # P2 evaluation as von Mises above (measured −0.2 %, −0.9 %, −2.5 % of p)
    d = demo.case(CASES / "thick_cylinder.toml")
    s = d["probes"]["inner"]["stress"]
    sr, st = -100.0, 100.0 * 500 / 300
    assert [s[0][0], s[1][1], s[2][2]] == pytest.approx([sr, st, 0.3 * (sr + st)], abs=3.0)
    assert abs(s[0][1]) < 0.02 * 100.0  # on the symmetry line y = 0: no shear


def test_a_case_loaded_past_its_limit_keeps_every_converged_step(tmp_path, demo):
    # p_lim = 2 × 120 ln 2 / √3 = 96.05: factors 0.5 and 0.8 (80) converge, 1.2 (120) has no
    # equilibrium; the message gives the case's own load factors, not a segment's fraction
    text = (CASES / "thick_cylinder.toml").read_text()
    text = text.replace('law = "linear-elastic"', 'law = "j2"\nsigma0 = 120.0')
    text = text.replace("steps = 1", "steps = [0.5, 0.8, 1.2]\nadaptive = false")
    (tmp_path / "thick_cylinder.geo").write_text((CASES / "thick_cylinder.geo").read_text())
    out, fields = tmp_path / "run.json", tmp_path / "fields"
    proc = demo.run(["-m fenics_nl", "run", write(tmp_path, "j2.toml", text), "--json", out,
                     "--output", fields, "--plot", tmp_path / "path.png"], check=False)
    assert proc.returncode == 2
    error = [line for line in proc.stderr.splitlines() if line.startswith("error")]
    assert len(error) == 1 and "load factor 1.2 not reached" in error[0], proc.stderr
    assert "last converged load factor is 0.8 " in error[0]
    assert 'control = "arc-length"' in error[0]  # a pressure: it can take it
    d = json.loads(out.read_text())
    assert d["status"] == "failed" and d["message"] in error[0]
    assert d["load_factor"] == 0.8 and d["converged_steps"] == 2
    # the totals it can give, and the curves of its converged steps
    assert d["newton_iterations"] == sum(s["newton_iterations"] for s in d["steps"])
    assert d["probes"] == d["steps"][-1]["probes"]
    assert (tmp_path / "path.png").stat().st_size > 20_000
    assert [s["load_factor"] for s in d["steps"]] == [0.5, 0.8]
    # the steps are the converged states: σ_r(a) = −p at each
    for s in d["steps"]:
        sr = s["probes"]["inner"]["stress"][0][0]
        assert sr == pytest.approx(-100.0 * s["load_factor"], rel=0.01)
    # the fields of both converged steps, the load factor as time
    times, _ = read_series(fields / "displacement.bp", "displacement")
    assert times == [0.5, 0.8]
    times, p = read_series(fields / "cumulated_plastic_strain.bp", "cumulated_plastic_strain")
    assert times == [0.5, 0.8] and p[0].max() == 0.0 < p[1].max()  # 0.8 > p_e = 0.52 p_lim


def test_every_step_of_a_case_is_a_time_series(tmp_path, demo):
    # the elastic cylinder in two steps: the displacement at 0.5 is half that at 1.0
    text = (CASES / "thick_cylinder.toml").read_text().replace("steps = 1", "steps = 2")
    (tmp_path / "thick_cylinder.geo").write_text((CASES / "thick_cylinder.geo").read_text())
    demo.case(write(tmp_path, "two.toml", text), "--output", tmp_path / "fields", "--plot",
              tmp_path / "path.png")
    times, u = read_series(tmp_path / "fields" / "displacement.bp", "displacement")
    assert times == [0.5, 1.0]
    assert np.abs(u[0] - 0.5 * u[1]).max() < 1e-12 * np.abs(u[1]).max()
    assert (tmp_path / "path.png").stat().st_size > 20_000  # probes and reactions drawn


def test_an_output_path_that_cannot_be_written_is_refused_before_the_solve(tmp_path, demo):
    for flag, path in (("--json", tmp_path / "missing" / "x.json"),
                       ("--png", tmp_path / "missing" / "x.png"),
                       ("--output", tmp_path / "file.txt" / "fields"),
                       ("--json", "/proc/x.json"),  # a folder that takes no file
                       ("--png", tmp_path / "x.txt"),  # no picture type
                       ("--json", CASES / "thick_cylinder.toml"),  # the input itself
                       ("--json", CASES / "thick_cylinder.geo")):
        (tmp_path / "file.txt").write_text("")
        proc = demo.run(["-m fenics_nl", "run", CASES / "thick_cylinder.toml", flag, path],
                        check=False)
        assert proc.returncode == 2 and "load factor" not in proc.stdout, proc.stdout
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and flag in lines[0], proc.stderr


# -- checkpoint and restart --------------------------------------------------------------

def j2_path_case(tmp_path, steps=20):
    """The J2 cylinder (σ0 = 100, p_lim = 80.05) to p = 75 in equal steps: path-dependent."""
    text = (CASES / "thick_cylinder.toml").read_text()
    text = text.replace('law = "linear-elastic"', 'law = "j2"\nsigma0 = 100.0')
    text = text.replace("steps = 1", f"steps = {steps}").replace("pressure = 100.0",
                                                                 "pressure = 75.0")
    (tmp_path / "thick_cylinder.geo").write_text((CASES / "thick_cylinder.geo").read_text())
    return write(tmp_path, "path.toml", text)


def test_a_killed_run_restarts_from_its_checkpoint_to_the_same_answer(tmp_path, demo):
    import sys

    case = j2_path_case(tmp_path)
    whole = demo.case(case)
    run_and_kill([sys.executable, "-m", "fenics_nl", "run", case, "--checkpoint", "ck"],
                 tmp_path, "load factor 0.15:")
    latest = json.loads((tmp_path / "ck" / "latest.json").read_text())["step"]
    assert 2 <= int(latest.split("-")[1]) < 20  # killed in the middle of the path
    resumed = demo.case(case, "--restart", tmp_path / "ck")
    same_answer(whole, resumed)


def test_a_checkpoint_every_n_steps_and_one_line_for_a_bad_one(tmp_path, demo):
    case = j2_path_case(tmp_path, steps=6)
    demo.case(case, "--checkpoint", tmp_path / "ck", "--checkpoint-every", "4")
    assert json.loads((tmp_path / "ck" / "latest.json").read_text())["step"] == "step-000004"

    def refused(path, message, other=case):
        proc = demo.run(["-m fenics_nl", "run", other, "--restart", path], check=False)
        lines = proc.stderr.strip().splitlines()
        assert proc.returncode == 2 and len(lines) == 1 and message in lines[0], proc.stderr

    refused(tmp_path / "none", "no checkpoint folder")
    (tmp_path / "empty").mkdir()
    refused(tmp_path / "empty", "holds no complete checkpoint")
    other = write(tmp_path, "other.toml", case.read_text().replace("75.0", "70.0"))
    refused(tmp_path / "ck", "is of another run: its case file differs", other)
    (tmp_path / "fields" / "displacement.bp").mkdir(parents=True)  # the first run's
    proc = demo.run(["-m fenics_nl", "run", case, "--restart", tmp_path / "ck", "--output",
                     tmp_path / "fields"], check=False)
    assert proc.returncode == 2 and "holds fields already" in proc.stderr
    arrays = tmp_path / "ck" / "step-000004" / "rank0.npz"
    arrays.write_bytes(arrays.read_bytes()[:100])  # truncated
    refused(tmp_path / "ck", "is damaged")


@pytest.mark.spawns_mpi
def test_a_killed_run_on_two_ranks_restarts_to_the_same_answer(tmp_path, demo):
    import sys

    from conftest import MPIEXEC

    case = j2_path_case(tmp_path)
    whole = demo.case(case, ranks=2)
    run_and_kill([MPIEXEC, "-n", "2", sys.executable, "-m", "fenics_nl", "run", case,
                  "--checkpoint", "ck"], tmp_path, "load factor 0.15:")
    latest = json.loads((tmp_path / "ck" / "latest.json").read_text())["step"]
    assert 2 <= int(latest.split("-")[1]) < 20
    assert sorted(p.name for p in (tmp_path / "ck" / latest).iterdir()) == [
        "rank0.npz", "rank1.npz", "state.json"]
    resumed = demo.case(case, "--restart", tmp_path / "ck", ranks=2)
    same_answer(whole, resumed)
    # another number of ranks is another partition: refused in one line
    proc = demo.run(["-m fenics_nl", "run", case, "--restart", tmp_path / "ck"], check=False)
    assert proc.returncode == 2 and "its ranks is 2, this run's 1" in proc.stderr


def test_a_killed_arc_length_run_restarts_on_the_same_path(tmp_path, demo):
    # killed while a limit point is being bracketed (the arc halved, the walk's inertia, sense
    # and last increment in the checkpoint): the restart meets the same critical points and
    # takes the same steps, through the snap to the target
    import sys

    for name in ("shallow_arch.toml", "shallow_arch.geo"):
        (tmp_path / name).write_text((CASES / name).read_text())
    case = tmp_path / "shallow_arch.toml"
    whole = demo.case(case)
    run_and_kill([sys.executable, "-m", "fenics_nl", "run", case, "--checkpoint", "ck"],
                 tmp_path, "load factor 0.2752:")
    latest = json.loads((tmp_path / "ck" / "latest.json").read_text())["step"]
    assert 3 <= int(latest.split("-")[1]) < len(whole["steps"]) // 2
    resumed = demo.case(case, "--restart", tmp_path / "ck")
    same_answer(whole, resumed)
    assert resumed["critical_points"] == whole["critical_points"]
    assert [s["negative_eigenvalues"] for s in resumed["steps"]] == [
        s["negative_eigenvalues"] for s in whole["steps"]]


# -- J2 in plane stress ------------------------------------------------------------------

PLATE_GEO = """// quarter of a plate with a central hole: halves W, H; hole radius a
SetFactory("OpenCASCADE");
a = 1; W = 4; H = 4; e = 0.01;
Rectangle(1) = {0, 0, 0, W, H};
Disk(2) = {0, 0, 0, a};
BooleanDifference(3) = {Surface{1}; Delete;}{Surface{2}; Delete;};
Physical Curve("x0") = Curve In BoundingBox{-e, -e, -e, e, H + e, e};
Physical Curve("y0") = Curve In BoundingBox{-e, -e, -e, W + e, e, e};
Physical Curve("right") = Curve In BoundingBox{W - e, -e, -e, W + e, H + e, e};
Physical Surface("plate") = {3};
Field[1] = Distance;
Field[1].CurvesList = {Curve In BoundingBox{-e, -e, -e, a + e, a + e, e}};
Field[2] = Threshold; Field[2].InField = 1; Field[2].DistMin = 0; Field[2].DistMax = 2;
Field[2].SizeMin = 0.15; Field[2].SizeMax = 0.6;
Background Field = 2;
"""

PLATE3D_GEO = """// the same quarter, half its thickness t2 = a/10 (symmetry on z = 0), one layer
SetFactory("OpenCASCADE");
a = 1; W = 4; H = 4; t2 = 0.1; e = 0.01;
Rectangle(1) = {0, 0, 0, W, H};
Disk(2) = {0, 0, 0, a};
BooleanDifference(3) = {Surface{1}; Delete;}{Surface{2}; Delete;};
Extrude {0, 0, t2} { Surface{3}; Layers{1}; }
Physical Surface("x0") = Surface In BoundingBox{-e, -e, -e, e, H + e, t2 + e};
Physical Surface("y0") = Surface In BoundingBox{-e, -e, -e, W + e, e, t2 + e};
Physical Surface("z0") = Surface In BoundingBox{-e, -e, -e, W + e, H + e, e};
Physical Surface("right") = Surface In BoundingBox{W - e, -e, -e, W + e, H + e, t2 + e};
Physical Volume("plate") = {1};
Field[1] = Distance;
Field[1].CurvesList = {Curve In BoundingBox{-e, -e, -e, a + e, a + e, t2 + e}};
Field[2] = Threshold; Field[2].InField = 1; Field[2].DistMin = 0; Field[2].DistMax = 2;
Field[2].SizeMin = 0.15; Field[2].SizeMax = 0.6;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
"""

PLATE = """[mesh]
file = "plate.geo"
model = "plane_stress"
degree = 2

[material]
law = "j2"
E = 1000.0
nu = 0.3
sigma0 = 1.0
H = 10.0

[[boundary]]
group = "x0"
displacement = [0.0, "free"]

[[boundary]]
group = "y0"
displacement = ["free", 0.0]

[[boundary]]
group = "right"
traction = [0.6, 0.0]

[loading]
steps = 4

[[probe]]
name = "corner"
point = [4.0, 4.0]

[[probe]]
name = "hole"
point = [0.0, 1.0]
"""

PLATE3D = """[mesh]
file = "plate3d.geo"
model = "3d"
degree = 2

[material]
law = "j2"
E = 1000.0
nu = 0.3
sigma0 = 1.0
H = 10.0

[[boundary]]
group = "x0"
displacement = [0.0, "free", "free"]

[[boundary]]
group = "y0"
displacement = ["free", 0.0, "free"]

[[boundary]]
group = "right"
traction = [0.6, 0.0, 0.0]

[loading]
steps = 4

[[probe]]
name = "corner"
point = [4.0, 4.0, 0.0]

[[probe]]
name = "hole"
point = [0.0, 1.0, 0.0]

[[boundary]]
group = "z0"
displacement = ["free", "free", 0.0]
"""


def test_a_thin_plate_in_j2_is_the_plane_stress_model(tmp_path, demo):
    # a quarter plate with a hole (W = 4a) pulled to 0.6 σ0: the hole's edge yields (σ_eq =
    # σ0 + H p > σ0). The plane-stress model (ε_zz an unknown at the quadrature points)
    # against a 3D plate of thickness a/5 with its mid-plane symmetry: they differ by the
    # through-thickness stresses near the hole, O(t/a)² at most; measured 4e-5 on u_x at the
    # far corner, 0.4 % on u_y there and at the hole, 0.3 % on σ_eq at the hole
    write(tmp_path, "plate.geo", PLATE_GEO)
    write(tmp_path, "plate3d.geo", PLATE3D_GEO)
    flat = demo.case(write(tmp_path, "plate.toml", PLATE))
    thin = demo.case(write(tmp_path, "plate3d.toml", PLATE3D))
    for d in (flat, thin):
        assert d["probes"]["hole"]["von_mises"] > 1.02  # plastic at the hole
        assert d["reactions"]["x0"][0] == pytest.approx(-0.6 * 4.0 * (1 if d is flat else 0.1),
                                                        rel=1e-9)
    (ux, uy), (vx, vy) = (flat["probes"]["corner"]["displacement"],
                          thin["probes"]["corner"]["displacement"][:2])
    assert vx == pytest.approx(ux, rel=1e-3) and vy == pytest.approx(uy, rel=0.01)
    hole_2d, hole_3d = flat["probes"]["hole"], thin["probes"]["hole"]
    assert hole_3d["displacement"][1] == pytest.approx(hole_2d["displacement"][1], rel=0.01)
    assert hole_3d["von_mises"] == pytest.approx(hole_2d["von_mises"], rel=0.01)
    assert len(hole_2d["stress"]) == 2  # plane stress reports the in-plane components


def test_a_hyperelastic_case_takes_its_newton_steps_whole(tmp_path):
    # the neo-Hookean bracket: from the elastic predictor, ‖R‖ grows 28-fold on the step
    # that converges next (the clamped holes' singular edges), so backtracking until ‖R‖
    # falls crawls (19 iterations); the energy's slope along the step says the step is good
    # (4 iterations, the same answer)
    from fenics_nl.case.problem import CaseProblem
    from fenics_nl.case.spec import read_case
    from fenics_nl.solvers.newton import NewtonSolver

    text = (CASES / "bracket.toml").read_text().replace("size = 6.0", "size = 20.0")
    text = text.replace('law = "power-law"', 'law = "neo-hookean"')
    text = text.replace("sigma0 = 200.0\n", "").replace("n = 0.2\n", "")
    (tmp_path / "bracket.geo").write_text((CASES / "bracket.geo").read_text())
    p = CaseProblem(read_case(write(tmp_path, "nh.toml", text)))
    p.set_load(0.25)
    solved = {}
    for line_search in (True, "slope"):
        p.unknown.x.array[:] = 0.0
        s = NewtonSolver(p.residual, p.unknown, p.bcs, line_search=line_search,
                         force_scale=p.force_scale, max_it=40, prefix=f"nh_{line_search}_")
        solved[line_search] = (s.solve(), p.unknown.x.array.copy())
    (by_norm, u_norm), (by_slope, u_slope) = solved[True], solved["slope"]
    assert by_slope.iterations <= 5 < 15 <= by_norm.iterations
    assert by_slope.residual_norms[1] > 10 * by_slope.residual_norms[0]  # the step it keeps
    assert np.abs(u_slope - u_norm).max() < 1e-8 * np.abs(u_norm).max()
    assert p.line_search() == "slope"  # what the case runner uses for this law


CANTILEVER_GEO = """SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 10, 1};
Physical Curve("clamped") = Curve In BoundingBox{-0.01, -0.01, -0.01, 0.01, 1.01, 0.01};
Physical Curve("tip") = Curve In BoundingBox{9.99, -0.01, -0.01, 10.01, 1.01, 0.01};
Physical Surface("beam") = {1};
Mesh.MeshSizeMax = 0.25;
"""


@pytest.mark.parametrize("law", ["neo-hookean", "saint-venant-kirchhoff"])
@pytest.mark.parametrize("nu", [0.0, 0.3])
def test_a_bent_cantilever_converges_alike_for_every_poisson_ratio(tmp_path, demo, law, nu):
    # PL²/EI = 0.6 in two steps: the linear predictor of the first bends the beam by 20 % of
    # its length, where ‖R‖ is 200 times the first; backtracking on ‖R‖ crawled there
    # (29 iterations at ν = 0 in a user's trial; no convergence in 30 here). The energy's
    # slope finds the step (measured 8 and 5 iterations, whatever ν and the law)
    write(tmp_path, "beam.geo", CANTILEVER_GEO)
    text = f"""[mesh]
file = "beam.geo"
model = "plane_strain"
degree = 2
[material]
law = "{law}"
E = 1000.0
nu = {nu}
[[boundary]]
group = "clamped"
displacement = [0.0, 0.0]
[[boundary]]
group = "tip"
traction = [0.0, -0.5]
[loading]
steps = 2
"""
    d = demo.case(write(tmp_path, "beam.toml", text))
    iterations = [s["newton_iterations"] for s in d["steps"]]
    assert len(iterations) == 2 and iterations[0] <= 10 and iterations[1] <= 6, iterations
    # equilibrium: the clamp holds the tip's load P = 0.5 (per unit thickness)
    assert d["reactions"]["clamped"][1] == pytest.approx(0.5, rel=1e-8)


def rewound(folder):
    """The checkpoint folder as a run killed one saved step earlier would have left it."""
    steps = sorted(p.name for p in folder.iterdir() if p.name.startswith("step-"))
    (folder / "latest.json").write_text(json.dumps({"step": steps[-2]}))
    return steps[-2]


@pytest.mark.parametrize("case", ["contact", "frictional pair", "worn pin", "plane-stress j2"])
def test_a_restart_with_contact_or_a_mixed_unknown_is_the_same_path(tmp_path, demo, case):
    # the Hertz punch (the active set and its warm start), the ball on the block with
    # friction (a pair's statuses, forces and committed slip), the worn pin (a pair's wear:
    # the depths, the gaps they opened, the worn volume and the sliding distance, in time)
    # and the plane-stress J2 plate (a mixed unknown with ε_zz; adaptive steps grown by the
    # driver) restarted a step short
    if case == "contact":
        path = CASES / "hertz_punch.toml"
    elif case == "worn pin":
        path = CASES / "worn_pin.toml"
    elif case == "frictional pair":
        write(tmp_path, "ball_on_block.geo", (CASES / "ball_on_block.geo").read_text())
        path = write(tmp_path, "ball.toml", (CASES / "ball_on_block.toml").read_text().replace(
            "friction = 0.0", "friction = 0.3"))
    else:
        write(tmp_path, "plate.geo", PLATE_GEO)
        path = write(tmp_path, "plate.toml", PLATE.replace("steps = 4", "steps = 3"))
    whole = demo.case(path, "--checkpoint", tmp_path / "ck")
    assert rewound(tmp_path / "ck") == f"step-{len(whole['steps']) - 1:06d}"
    resumed = demo.case(path, "--restart", tmp_path / "ck")
    same_answer(whole, resumed)
    if case in ("frictional pair", "worn pin"):  # the pair's record: force, set, pressure
        a, b = whole["steps"][-1]["contact_pairs"][0], resumed["steps"][-1]["contact_pairs"][0]
        assert a["nodes_in_contact"] == b["nodes_in_contact"]
        assert b["force"] == pytest.approx(a["force"], rel=1e-10, abs=1e-16)
        assert b["max_pressure"] == pytest.approx(a["max_pressure"], rel=1e-10)
        for key in {"wear_volume", "max_wear_depth", "sliding_distance"} & set(a):
            assert b[key] == pytest.approx(a[key], rel=1e-12), key


def test_a_case_file_in_the_old_spellings_reads_in_the_new_ones(tmp_path):
    from fenics_nl.case.spec import read_case

    text = (CASES / "thick_cylinder.toml").read_text().replace('"plane_strain"', '"plane-strain"')
    text += '\n[solver]\nnewton = "quasi-newton"\nlinear = "iterative"\nmax_iterations = 9\n'
    (tmp_path / "thick_cylinder.geo").write_text((CASES / "thick_cylinder.geo").read_text())
    case = read_case(write(tmp_path, "old.toml", text))
    assert (case.model, case.newton, case.linear_solver, case.max_it) == (
        "plane_strain", "bfgs", "gamg", 9)


def test_old_flag_names_are_read_and_said(demo):
    # --maxit (newton_scalar) and --solver (bracket) are now --max-it and --linear-solver
    proc = demo.run(["newton_scalar.py", "--maxit", "0"], check=False)
    assert proc.returncode == 2 and "--maxit: must be >= 1" in proc.stderr
    proc = demo.run(["newton_scalar.py", "--maxit", "40", "--help"])
    assert "--maxit" not in proc.stdout and "--max-it" in proc.stdout  # hidden from --help
    proc = demo.run(["newton_scalar.py", "--maxit", "400"])
    assert "note: --maxit is now spelt --max-it" in proc.stderr


def test_a_damage_case_follows_the_homogeneous_closed_form(demo):
    # cases/damage_strip.toml: AT2, a strip in uniaxial stress to 0.9 of its peak strain,
    # stable and homogeneous: α, σ and the dissipated energy (Gc/2) α²/ell × area against
    # the closed form of the same energy at each step (P1 is exact for a uniform state:
    # measured 1e-14; 1e-9 asked, above the alternate minimization's stop on max |Δα|, 1e-6,
    # which a uniform state meets exactly)
    from fenics_nl.materials.gradient_damage import AT2

    law = AT2(210000.0, 0.0, Gc=2.7, ell=0.1, residual_stiffness=1e-6)
    d = demo.case(CASES / "damage_strip.toml")
    assert d["law"] == "at2" and d["warnings"] == [] and len(d["steps"]) == 4
    # the work: the u-solves' factorizations and one per damage SNES iteration
    assert d["factorizations"] >= sum(s["damage_iterations"] for s in d["steps"]) > 0
    for s in d["steps"]:
        eps = s["load_factor"] * 0.0118 / 2.0
        alpha, sigma = law.homogeneous_damage(eps), law.homogeneous_stress(eps)
        assert s["largest_damage"] == pytest.approx(alpha, rel=1e-9)
        assert s["probes"]["middle"]["stress"][0][0] == pytest.approx(sigma, rel=1e-9)
        assert s["reactions"]["right"][0] == pytest.approx(sigma * 0.2, rel=1e-9)
        assert s["dissipated_energy"] == pytest.approx(2.7 / 2 * alpha**2 / 0.1 * 2.0 * 0.2,
                                                       rel=1e-9)


@pytest.mark.parametrize("change,message", [
    (('model = "plane_strain"', 'model = "plane_stress"'),
     "mesh.model: at2 has no plane-stress form"),
    (("nu = 0.0", 'nu = 0.0\nsplit = "spectral"'), "material.split: 'spectral' is not one of"),
    (("ell = 0.1 ", "ell = -0.1 "), "material.ell"),
    (("Gc = 2.7 ", "# "), "material.Gc: missing"),
    (("steps = 4", 'steps = 4\n\n[solver]\nnewton = "modified"'),
     "solver.newton: at2 is solved by alternate minimization"),
])
def test_what_a_damage_case_cannot_be_is_one_line_each(tmp_path, demo, change, message):
    text = (CASES / "damage_strip.toml").read_text()
    assert change[0] in text
    write(tmp_path, "damage_strip.geo", (CASES / "damage_strip.geo").read_text())
    lines = check(demo, tmp_path, text.replace(*change))
    assert any(message in line for line in lines), lines


def sphere_path(d):
    """(λ_a, p/μ) at every step of the inflated sphere: λ_a = 1 + u_r(A)/A, p = λ μ."""
    return (np.array([1 + s["probes"]["inner"]["displacement"][0] for s in d["steps"]]),
            np.array([s["load_factor"] for s in d["steps"]]))


def sphere_case(tmp_path, change):
    """The shipped sphere, meshed finer (cells ≤ 0.04) or in the displacement formulation."""
    text = (CASES / "inflated_sphere.toml").read_text()
    (tmp_path / "inflated_sphere.geo").write_text((CASES / "inflated_sphere.geo").read_text())
    if change == "fine":
        text = text.replace("degree = 2\n", "degree = 2\nsize = 0.04\n")
    elif change == "displacement":  # ν = 0.4999: compressible enough for P2 at h = 0.05
        text = text.replace('formulation = "mixed"', "").replace("nu = 0.5", "nu = 0.4999")
        text = text.replace("degree = 2\n", "degree = 2\nsize = 0.05\n")
    return write(tmp_path, f"{change}.toml", text)


@pytest.mark.parametrize("change", ["coarse", "fine", "displacement"])
def test_the_inflated_sphere_passes_its_pressure_maximum_onto_the_falling_branch(
        tmp_path, demo, change):
    # the incompressible neo-Hookean sphere (theory.vessels): arc-length through the limit
    # point, down the falling branch until the stop condition u_r(A) = 1 (λ_a = 2). Each
    # step on the closed form p(λ_a): measured 2.6e-5 (coarse), 3.0e-6 (fine), 2.9e-4
    # (displacement, ν = 0.4999: its p is not the incompressible one to 1e-4)
    from fenics_nl.theory.vessels import neo_hookean_sphere_maximum, neo_hookean_sphere_pressure

    d = demo.case(CASES / "inflated_sphere.toml" if change == "coarse"
                  else sphere_case(tmp_path, change))
    assert d["status"] == "ok" and d["ended_by"] == "stop"
    stretch, p = sphere_path(d)
    assert np.all(np.diff(stretch) > 0)  # never back down the loading branch
    assert 2.0 <= stretch[-1] < 2.1  # stopped at the first step past u_r = 1
    exact = np.array([neo_hookean_sphere_pressure(s, 1.0, 1.2, 1.0) for s in stretch])
    assert p == pytest.approx(exact, rel=1e-3)
    (limit,) = d["critical_points"]
    stretch_max, p_max = neo_hookean_sphere_maximum(1.0, 1.2, 1.0)
    assert limit["kind"] == "limit" and limit["load_factor"] == pytest.approx(p_max, rel=1e-3)
    # stable up to the maximum, one unstable direction (the pressure's) past it
    k = limit["step"]
    negative = [s["negative_eigenvalues"] for s in d["steps"]]
    assert negative == [0] * (k - 1) + [1] * (len(negative) - k + 1)
    assert stretch[k - 2] < stretch_max * 1.01 and stretch[k - 1] > stretch_max * 0.99


@pytest.mark.mpi
def test_the_inflated_sphere_on_two_ranks_follows_the_serial_path(demo):
    from fenics_nl.theory.vessels import neo_hookean_sphere_pressure

    # the same limit point and the same closed form along the path; the steps themselves
    # agree to the solver's tolerance while both take the same iterations (docs/cases.md)
    s = demo.case(CASES / "inflated_sphere.toml")
    p = demo.case(CASES / "inflated_sphere.toml", ranks=2)
    assert p["ranks"] == 2 and p["status"] == "ok" and p["ended_by"] == "stop"
    assert p["critical_points"][0]["load_factor"] == pytest.approx(
        s["critical_points"][0]["load_factor"], rel=1e-8)
    stretch, load = sphere_path(p)
    assert np.all(np.diff(stretch) > 0) and stretch[-1] >= 2.0
    exact = [neo_hookean_sphere_pressure(s, 1.0, 1.2, 1.0) for s in stretch]
    assert load == pytest.approx(exact, rel=1e-3)  # on the same curve, wherever the steps
    serial = dict(zip(*sphere_path(s), strict=True))
    for a, b in zip(sphere_path(s)[0], stretch, strict=False):
        if a != pytest.approx(b, rel=1e-8):  # the paths' steps parted: same curve still
            break
        assert load[list(stretch).index(b)] == pytest.approx(serial[a], rel=1e-8)


def test_a_failed_arc_length_run_keeps_its_critical_points(tmp_path, demo):
    # stopped by max_steps past the limit point: status failed, and the JSON still has the
    # limit point met and every step's negative eigenvalues
    text = (CASES / "inflated_sphere.toml").read_text().replace("max_steps = 100",
                                                                 "max_steps = 22")
    text = "\n".join(line for line in text.splitlines() if not line.startswith("stop ="))
    (tmp_path / "inflated_sphere.geo").write_text((CASES / "inflated_sphere.geo").read_text())
    out = tmp_path / "failed.json"
    proc = demo.run(["-m fenics_nl", "run", write(tmp_path, "short.toml", text), "--json",
                     out], check=False)
    assert proc.returncode == 2 and "not reached in 22 steps" in proc.stderr
    d = json.loads(out.read_text())
    assert d["status"] == "failed" and len(d["steps"]) == 22
    (limit,) = d["critical_points"]
    assert limit["kind"] == "limit" and limit["load_factor"] == pytest.approx(0.22514, rel=1e-3)
    negative = [s["negative_eigenvalues"] for s in d["steps"]]
    assert negative[0] == 0 and negative[-1] == 1


@pytest.mark.parametrize("stop,message", [
    ('{ probe = "outer", component = "r", value = 1.0 }',
     "loading.stop.probe: 'outer' is not a [[probe]] of the case (it has: inner)"),
    ('{ probe = "inner", component = "x", value = 1.0 }',
     "loading.stop.component: 'x' is not a displacement component of the axisymmetric "
     "model (one of r, z)"),
    ('{ probe = "inner", component = "rz", value = 1.0 }',
     "loading.stop.component: 'rz' is not a displacement component of the axisymmetric "
     "model (one of r, z)"),
    ('{ probe = "inner", component = "r", value = 0.0 }', "loading.stop.value: must not be 0"),
    ('{ probe = "inner", component = "r" }', "loading.stop.value: missing"),
])
def test_a_stop_condition_is_checked(tmp_path, demo, stop, message):
    text = (CASES / "inflated_sphere.toml").read_text()
    text = "\n".join(f"stop = {stop}" if line.startswith("stop =") else line
                     for line in text.splitlines())
    (tmp_path / "inflated_sphere.geo").write_text((CASES / "inflated_sphere.geo").read_text())
    lines = check(demo, tmp_path, text)
    assert len(lines) == 1 and message in lines[0], lines


def test_arc_length_is_advised_only_where_a_case_can_take_it(tmp_path, demo):
    # a neo-Hookean cylinder driven by its bore's displacement, one Newton iteration a step:
    # the step fails, and arc-length (which scales loads only) is not advised
    text = (CASES / "thick_cylinder.toml").read_text()
    text = text.replace('law = "linear-elastic"', 'law = "neo-hookean"')
    text = text.replace("group = \"inner\"\npressure = 100.0",
                        "group = \"inner\"\ndisplacement = [1.0, \"free\"]")
    text = text.replace("steps = 1", "steps = 1\nadaptive = false") + (
        "\n[solver]\nmax_it = 1\n")
    (tmp_path / "thick_cylinder.geo").write_text((CASES / "thick_cylinder.geo").read_text())
    proc = demo.run(["-m fenics_nl", "run", write(tmp_path, "pulled.toml", text)],
                    check=False)
    error = [line for line in proc.stderr.splitlines() if line.startswith("error")]
    assert proc.returncode == 2 and len(error) == 1, proc.stderr
    assert "load factor 1 not reached" in error[0] and "arc-length" not in error[0]


@pytest.mark.parametrize("command", ["check", "run"])
def test_loads_that_can_do_no_work_are_refused(tmp_path, demo, command):
    # a pressure on the axis of an axisymmetric model (r = 0: no area), a traction along a
    # held component, a pressure on a flat group held along its normal: each one line, in
    # check as in run (before anything is solved)
    text = (CASES / "inflated_sphere.toml").read_text() + (
        '\n[[boundary]]\ngroup = "axis"\npressure = 1.0\n'
        '\n[[boundary]]\ngroup = "equator"\ntraction = [0.5, 1.0]\n'
        '\n[[boundary]]\ngroup = "equator"\npressure = 1.0\n')
    (tmp_path / "inflated_sphere.geo").write_text((CASES / "inflated_sphere.geo").read_text())
    proc = demo.run(["-m fenics_nl", command, write(tmp_path, "idle.toml", text)],
                    check=False)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert lines == [
        "error: boundary[4].pressure: 'axis' has no area in the axisymmetric model (r = 0 on "
        "it): the load can do no work there",
        "error: boundary[5].traction: its z component on 'equator', where a displacement "
        "condition holds u_z, can do no work (it would only change that support's "
        "reaction); set it to 0 or free u_z",
        "error: boundary[6].pressure: 'equator' has u_z prescribed by a displacement "
        "condition: the pressure there can do no work (it would only change that support's "
        "reaction); remove it or free u_z"], lines


def test_every_key_of_the_format_is_in_the_documented_table():
    # the documentation's table (spec.KEYS) and the annotated format (FORMAT, --help) name
    # the same keys
    import re

    from fenics_nl.case.spec import FORMAT, KEYS, key_table

    written = set(re.findall(r"^\s*#?\s*([a-zA-Z_0-9]+)\s*=", FORMAT, re.M))
    named = {key for _, key, *_ in KEYS}
    assert written <= named, written - named
    for key in named:  # the laws' parameters are named in FORMAT's prose
        assert re.search(rf"\b{key}\b", FORMAT), key
    table = key_table().splitlines()
    assert len(table) == 2 + len(KEYS) and all(line.count("|") == 5 for line in table)


def test_a_case_refines_its_mesh_near_named_groups(tmp_path, demo):
    # cells of 0.3 within 1 of the bore, the mesh's own 1.5 beyond: more unknowns, the same
    # Lamé answer closer (measured 5e-5 -> below), and a group that is not there named
    text = (CASES / "thick_cylinder.toml").read_text().replace(
        "degree = 2", 'degree = 2\nrefine_near = { groups = ["inner"], size = 0.3, '
                      "distance = 1.0 }")
    (tmp_path / "thick_cylinder.geo").write_text((CASES / "thick_cylinder.geo").read_text())
    fine = demo.case(write(tmp_path, "near.toml", text))
    plain = demo.case(CASES / "thick_cylinder.toml")
    assert fine["dofs"] > 2 * plain["dofs"]
    exact = lame(10.0)
    u_fine = fine["probes"]["inner"]["displacement"][0]
    u_plain = plain["probes"]["inner"]["displacement"][0]
    assert abs(u_fine / exact - 1) < abs(u_plain / exact - 1)
    lines = check(demo, tmp_path, text.replace('groups = ["inner"]', 'groups = ["bore"]'))
    assert lines == ["error: mesh.refine_near.groups: 'bore' is not a boundary group of the "
                     "geometry (it has: inner, outer, symmetry_x, symmetry_y)"], lines


def test_loads_that_do_work_beside_a_support_are_accepted(tmp_path, demo):
    # a traction along the free component of a held group, and a pressure on a curved group
    # whose facets are held in part: both do work, and the case checks
    text = (CASES / "thick_cylinder.toml").read_text() + (
        '\n[[boundary]]\ngroup = "symmetry_y"\ntraction = [1.0, 0.0]\n'
        '\n[[boundary]]\ngroup = "outer"\ndisplacement = [0.0, "free"]\n'
        '\n[[boundary]]\ngroup = "outer"\npressure = 1.0\n')
    (tmp_path / "thick_cylinder.geo").write_text((CASES / "thick_cylinder.geo").read_text())
    proc = demo.run(["-m fenics_nl", "check", write(tmp_path, "working.toml", text)])
    assert "the case is complete" in proc.stdout
