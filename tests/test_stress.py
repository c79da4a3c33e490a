"""Numerical-stability stress cases: each ends in the right answer (checked) or a clear error.

The stress table of docs/validation.md lists every case with its expected and observed
behaviour.
"""

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI
from problems import cantilever_3d

from fenics_nl.contact.active_set import ActiveSetContact
from fenics_nl.domain import boundary
from fenics_nl.domain.mesh_check import bad_cells
from fenics_nl.materials.laws import LinearElastic, PowerLaw
from fenics_nl.solvers.loading import LoadStepError, solve_incrementally
from fenics_nl.solvers.newton import ConvergenceError, NewtonSolver

pytestmark = pytest.mark.stress

# the power-law cantilever of test_newton: ε_eq reaches ~20 ε0 at the clamp
MATERIAL = PowerLaw(E=1e3, nu=0.3, sigma0=1.0, n=0.3)
LOAD = -0.05
CELLS = (16, 3, 3)


def tip(p):
    return p.u.function_space.mesh.comm.allreduce(fem.assemble_scalar(fem.form(p.observed)))


def loaded(problem, factor):
    problem.load.value[2] = factor * LOAD


def solved(material=MATERIAL, cells=CELLS, steps=10, method="full", **options):
    """The cantilever taken to LOAD in `steps` equal (adaptive) increments."""
    p = cantilever_3d(material, cells=cells, traction=LOAD)
    s = NewtonSolver(p.residual, p.u, p.bcs, prefix=f"s{id(p)}_", method=method, **options)
    path = solve_incrementally(s, lambda t: loaded(p, t), steps)
    return p, path


@pytest.fixture(scope="module")
def reference():
    """Tip displacement from 10 full-Newton steps (the default increment is LOAD/10)."""
    p, _ = solved()
    return tip(p)


@pytest.mark.parametrize("steps", [10, 1])  # the default increment, ×10
def test_large_increments_reach_the_same_answer(reference, steps):
    p, path = solved(steps=steps)
    assert abs(tip(p) - reference) < 1e-8 * abs(reference)
    assert path.failures == 0  # full Newton takes the whole load in one step


def test_hundredfold_increment_reaches_the_answer():
    # ×100: the load 10 LOAD in one step (ε_eq ~ 10^3 ε0 at the clamp for n = 0.3):
    # full Newton on this convex energy takes it at once (adaptive stepping would cut the
    # step otherwise); the answer is checked against
    # the same load reached in 40 small steps. Residuals stall at ~1e-12 at this load, so
    # the force scale is the load (atol 1e-10 |F_ext|), not the first small increment's R0.
    scale = dict(atol=1e-10, force_scale=abs(10 * LOAD))
    p = cantilever_3d(MATERIAL, cells=CELLS, traction=LOAD)
    s = NewtonSolver(p.residual, p.u, p.bcs, prefix="x100_", max_it=30, **scale)
    solve_incrementally(s, lambda t: loaded(p, 10 * t), 1)
    q = cantilever_3d(MATERIAL, cells=CELLS, traction=LOAD)
    sq = NewtonSolver(q.residual, q.u, q.bcs, prefix="x100ref_", max_it=30, **scale)
    solve_incrementally(sq, lambda t: loaded(q, 10 * t), 40, adaptive=False)
    assert abs(tip(p) - tip(q)) < 1e-8 * abs(tip(q))  # (measured: 6 iterations, no cut)


def test_round_off_stall_is_named_in_the_error():
    q = cantilever_3d(MATERIAL, cells=CELLS, traction=LOAD)
    # atol 1e-14 of the first increment's imbalance: below the round-off at 10x the load
    sq = NewtonSolver(q.residual, q.u, q.bcs, prefix="stall_", max_it=30, atol=1e-14)
    with pytest.raises(LoadStepError, match=r"stalls at .* round-off of the internal forces"):
        solve_incrementally(sq, lambda t: loaded(q, 10 * t), 40, adaptive=False)


def test_modified_newton_without_adaptivity_refuses_clearly():
    # modified Newton on the initial (elastic) tangent cannot take ×100 in 20 iterations
    p = cantilever_3d(MATERIAL, cells=CELLS, traction=LOAD)
    s = NewtonSolver(p.residual, p.u, p.bcs, prefix="noadapt_", method="modified", max_it=20)
    with pytest.raises(LoadStepError, match="load factor 1 not reached from 0: no conv"):
        solve_incrementally(s, lambda t: loaded(p, 10 * t), 1, adaptive=False)
    assert np.all(np.isfinite(p.u.x.array))


@pytest.mark.parametrize("scale", [1, 100])
def test_poor_initial_guess(reference, scale):
    # u0 = random nodal values `scale` times the solution's size: full Newton with
    # backtracking finds the solution (26 and 37 iterations measured); without it, it
    # wanders (|R| ~ 1e10) and stops with a clear error (no convergence, or blown up).
    # The stopping test is absolute (1e-10 |F_ext|): relative to the huge ‖R0‖ of such a
    # guess it would stop too early.
    for line_search in (True, False):
        p = cantilever_3d(MATERIAL, cells=CELLS, traction=LOAD)
        rng = np.random.default_rng(0)
        p.u.x.array[:] = scale * abs(reference) * rng.standard_normal(p.u.x.array.size)
        s = NewtonSolver(p.residual, p.u, p.bcs, prefix=f"guess{scale}{line_search}_",
                         max_it=60, line_search=line_search, rtol=0.0,
                         atol=1e-10, force_scale=abs(LOAD))
        if line_search:
            assert s.solve().converged
            assert abs(tip(p) - reference) < 1e-8 * abs(reference)
        else:
            with pytest.raises(ConvergenceError,
                               match=r"no convergence in 60 iterations|Newton diverged"):
                s.solve()


@pytest.mark.parametrize("n", [0.1, 0.5])
def test_tangent_singular_at_zero_strain_for_n_below_one(n):
    # For n < 1 the unregularised law has an infinite tangent at ε = 0; the energy's
    # regularisation keeps it Hooke's there. Full Newton from u = 0 and BFGS (a different
    # algorithm on a different matrix) must agree.
    m = PowerLaw(E=1e3, nu=0.3, sigma0=1.0, n=n)
    p_full, _ = solved(m, steps=1, line_search=True)
    p_bfgs, _ = solved(m, steps=1, method="bfgs", max_it=300)
    assert abs(tip(p_full) - tip(p_bfgs)) < 1e-7 * abs(tip(p_full))


def test_very_coarse_mesh_converges():
    # one element through the thickness: a stiff discrete answer, reached without trouble
    p, path = solved(cells=(4, 1, 1), steps=1)
    assert path.failures == 0 and np.isfinite(tip(p))


def distorted_tip(cells, amplitude):
    """P2 cantilever, interior nodes moved at random by up to `amplitude` element sizes."""
    p = cantilever_3d(MATERIAL, cells=cells, traction=LOAD, degree=2)
    x = p.u.function_space.mesh.geometry.x
    size = np.array([10.0, 1.0, 1.0])
    inner = np.all((x > 1e-9) & (x < size - 1e-9), axis=1)
    rng = np.random.default_rng(1)
    x[inner] += amplitude * size / np.array(cells) * rng.uniform(-1, 1, (inner.sum(), 3))
    assert all(len(c) == 0 for c in bad_cells(p.u.function_space.mesh).values())
    s = NewtonSolver(p.residual, p.u, p.bcs, prefix=f"distorted{id(p)}_")
    solve_incrementally(s, lambda t: loaded(p, t), 1)
    return tip(p)


def test_distorted_mesh_moves_the_answer_less_than_refinement_does():
    # P2 (P1 locks: the 16x3x3 P1 tip is 3x too stiff, so any change would hide in it).
    # Measured: 30 % distortion moves the tip by 0.3 %, one refinement step by 11 %.
    straight, distorted = distorted_tip(CELLS, 0.0), distorted_tip(CELLS, 0.3)
    coarser = distorted_tip((8, 2, 2), 0.0)
    assert abs(distorted - straight) < 0.1 * abs(straight - coarser)


def test_inverted_cell_is_found():
    p = cantilever_3d(MATERIAL, cells=CELLS, traction=LOAD, comm=MPI.COMM_SELF)
    x = p.u.function_space.mesh.geometry.x
    i = np.argmin(np.linalg.norm(x - [5.0, 0.5, 0.5], axis=1))
    x[i, 0] += 1.2  # through two layers of neighbours
    assert len(bad_cells(p.u.function_space.mesh)["folded"]) > 0


# -- contact -----------------------------------------------------------------------------

def compressed_square(push, gap, formulation, initial="all"):
    """Unit square on lateral rollers, top pushed down by `push`, floor `gap` below.

    The bottom is S_C with u_n = −u_y. While push > gap the state is a uniform uniaxial
    strain and the floor's reaction is exactly M (push − gap), M = λ + 2μ (P1 is exact).
    """
    E, nu = 1.0, 0.3
    square = mesh.create_unit_square(MPI.COMM_WORLD, 6, 6)
    V = fem.functionspace(square, ("Lagrange", 1, (2,)))
    u, v = fem.Function(V), ufl.TestFunction(V)
    on = lambda axis, value: mesh.locate_entities_boundary(  # noqa: E731
        square, 1, lambda x: np.isclose(x[axis], value))
    top = on(1, 1.0)
    bcs = [boundary.component(V, 0, on(0, 0.0)), boundary.component(V, 0, on(0, 1.0)),
           boundary.component(V, 0, top), boundary.component(V, 1, top, -push)]
    R = LinearElastic(E, nu).internal_work(u, v, "plane_strain") * ufl.dx
    c = ActiveSetContact(R, u, bcs, on(1, 0.0), lambda x: np.full(x.shape[1], gap),
                         normal_axis=1, normal_sign=-1, formulation=formulation,
                         initial=initial, prefix=f"sq{id(u)}_")
    lmbda, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    return c, c.solve(), (lmbda + 2 * mu) * max(push - gap, 0.0)


@pytest.mark.parametrize("formulation", ["elimination", "multiplier"])
@pytest.mark.parametrize("push,gap,case", [
    (0.0, 0.0, "grazing: touching everywhere, no load"),
    (0.01, 1e-15, "gap at round-off level"),
    (0.0, -0.01, "initial penetration, no load"),
    (0.01, 0.02, "never touches"),
    (0.01, 0.01 - 1e-15, "touches by round-off"),
])
def test_contact_limit_cases(formulation, push, gap, case):
    for initial in ("all", "none"):
        c, r, exact = compressed_square(push, gap, formulation, initial)
        assert abs(c.force - exact) <= 1e-10 * max(exact, 1e-3), (case, initial, c.force)
        assert r.active_set_iterations <= 3, case  # no cycling: one update decides
        assert np.all(np.isfinite(c.u.x.array))


# -- near incompressibility ------------------------------------------------------------

# -- load increments through each scene's command line -------------------------------------

@pytest.mark.parametrize("args", [
    ["--steps", "4"],  # ×10 the default increment (1.5 P_cr in 40 steps)
    ["--load-ratio", "3.75", "--steps", "1"],  # ×100: 3.75 P_cr in one step
])
def test_beam_large_increments_land_on_the_elastica(args, demo, on_elastica):

    on_elastica(demo.beam(*args))


def test_punch_tenfold_increment_power_law(demo):
    # ×10 the default indentation (0.01 R, one step) in one step, non-linear material:
    # frictionless contact on a convex energy has one solution, whatever the path (four
    # steps reach the same one)

    common = ["--material", "power-law", "--indentation", "0.1", "--refine", "0"]
    one, four = demo.punch(*common, "--steps", "1"), demo.punch(*common, "--steps", "4")
    assert one["force"] == pytest.approx(four["force"], rel=1e-8)
    assert one["contact_radius"] == four["contact_radius"]


def test_punch_hundredfold_increment_stays_on_hertz(demo):
    # ×100: δ = R in one step, contact radius a = R. With Hertz's parabola the linear
    # problem scales with a (the mesh is built in units of a, up to gmsh's rounding: 13536
    # against 13390 unknowns), so Hertz holds to the same discretisation error as at
    # δ = 0.01 R (measured +0.17 % and +0.20 %). The exact sphere lies above the parabola
    # (more gap) out there: less force.

    small = demo.punch("--refine", "0")
    big = demo.punch("--refine", "0", "--indentation", "1")
    sphere = demo.punch("--refine", "0", "--indentation", "1", "--gap", "sphere")
    for d in (small, big):
        assert abs(d["force_rel_error"]) < 0.005  # the tolerance of the default punch test
        assert abs(d["contact_radius"] - d["hertz_contact_radius"]) < d["element_size"]
    assert 0.5 * big["force"] < sphere["force"] < big["force"]


def test_bracket_tenfold_increment_gives_the_same_answer(demo):
    # ×10: 20 kN (ε_eq ~ 800 ε0) in one step, ten times the default 2 kN step, against
    # four steps (the path does not matter to this elastic law: the end state is the same)

    common = ["--size", "20", "--force", "20000"]  # 11.6k unknowns: the same on any mesh
    one, four = demo.bracket(*common, "--steps", "1"), demo.bracket(*common, "--steps", "4")
    assert one["load_point_displacement"] == pytest.approx(four["load_point_displacement"],
                                                           rel=1e-8)


def test_bracket_hundredfold_increment_refuses_clearly(demo):
    # ×100: 200 kN in one step. Full Newton crawls (damped by the line search); after 50
    # iterations the demo stops and says which step failed and what to do.

    proc = demo.run(["bracket.py", "--size", "20", "--force", "200000", "--steps", "1"],
                    check=False)
    assert proc.returncode == 2
    assert proc.stderr.startswith("error: load step 1/1 (F = 2e+05 N), full Newton: no "
                                  "convergence in 50 iterations")
    assert "take more --steps" in proc.stderr and "Traceback" not in proc.stderr


# -- the same problem in two unit systems ------------------------------------------------
# N–mm–MPa against N–m–Pa: lengths ×1e-3, moduli ×1e6, forces unchanged. Every tolerance is
# relative to a force or a length of the problem, so the dimensionless answers agree to the
# solvers' tolerances (1e-10), far inside 1e-6.

def test_punch_gives_the_same_answer_in_mm_and_in_m(demo):

    common = ["--force", "100", "--refine", "0", "--steps", "2"]
    mm = demo.punch(*common, "--E", "1e5", "--radius", "1")
    m = demo.punch(*common, "--E", "1e11", "--radius", "1e-3")
    assert m["force_rel_error"] == pytest.approx(mm["force_rel_error"], abs=1e-6)
    assert m["contact_radius"] / 1e-3 == pytest.approx(mm["contact_radius"], rel=1e-6)
    assert m["indentation"] / 1e-3 == pytest.approx(mm["indentation"], rel=1e-6)
    # p0 is the axis node's force over its area: with the 2πr weight that force is ~1e-5 of
    # P, so the solvers' floor (1e-10 of P, reached by different paths) shows at 1e-6 there
    assert m["max_pressure"] * 1e-6 == pytest.approx(mm["max_pressure"], rel=2e-5)


def test_beam_gives_the_same_answer_in_mm_and_in_m(demo):

    common = ["--load-ratio", "1.2", "--steps", "20"]
    mm = demo.beam(*common, "--length", "1000", "--thickness", "20", "--E", "1e3")
    m = demo.beam(*common, "--length", "1", "--thickness", "0.02", "--E", "1e9")
    # P_cr / P_Euler, α: dimensionless
    assert 1 + m["critical_load_rel_error"] == pytest.approx(1 + mm["critical_load_rel_error"],
                                                             rel=1e-6)
    assert m["tip_rotation_deg"] == pytest.approx(mm["tip_rotation_deg"], rel=1e-6)
    assert m["tip_deflection"] * 1e3 == pytest.approx(mm["tip_deflection"], rel=1e-6)


def test_bracket_gives_the_same_answer_in_mm_and_in_m(demo):

    common = ["--steps", "1", "--support", "contact"]
    mm = demo.bracket(*common, "--size", "20")
    m = demo.bracket(*common, "--units", "m", "--size", "0.02")
    assert m["load_point_displacement"] * 1e3 == pytest.approx(mm["load_point_displacement"],
                                                               rel=1e-6)
    assert m["lifted_off_area"] * 1e6 == pytest.approx(mm["lifted_off_area"], rel=1e-6)
    assert m["max_von_mises"] * 1e-6 == pytest.approx(mm["max_von_mises"], rel=1e-6)


# -- three ranks ---------------------------------------------------------------------------

@pytest.mark.parametrize("scene,args,keys", [
    ("punch", ["--steps", "2"], ["force", "contact_radius"]),
    ("beam", ["--load-ratio", "1.2", "--steps", "10"], ["critical_load", "tip_rotation_deg"]),
    # one load step: three ranks on two cores are slow, and the partition is what is tested
    # the serial run of test_bracket_gives_the_same_answer_in_mm_and_in_m, flag for flag
    ("bracket", ["--steps", "1", "--support", "contact", "--size", "20"],
     ["load_point_displacement", "lifted_off_area"]),
])
@pytest.mark.spawns_mpi
def test_three_ranks_give_the_serial_answer(demo, scene, args, keys):
    run = getattr(demo, scene)
    s, p = run(*args), run(*args, ranks=3)
    assert p["ranks"] == 3
    for k in keys:  # the 2-rank tests use the same tolerances
        assert p[k] == pytest.approx(s[k], rel=1e-6 if k == "tip_rotation_deg" else 1e-8), k
