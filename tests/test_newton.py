import dataclasses
import math

import dolfinx
import numpy as np
import pytest
import ufl
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc
from problems import cantilever_3d

from fenics_nl.materials.laws import PowerLaw
from fenics_nl.solvers.convergence import ConvergenceTest
from fenics_nl.solvers.loading import LoadStepError, solve_incrementally
from fenics_nl.solvers.newton import ConvergenceError, NewtonSolver
from fenics_nl.solvers.snes import EventCounter, SnesSolver

# Power law far into its non-linear range: at this load ε_eq reaches ~20 ε0 at the clamp.
MATERIAL = PowerLaw(E=1e3, nu=0.3, sigma0=1.0, n=0.3)
LOAD = -0.05
CELLS = (16, 3, 3)


def tip(problem):
    value = fem.assemble_scalar(fem.form(problem.observed))
    return problem.u.function_space.mesh.comm.allreduce(value)


def solve(solver_cls, comm=MPI.COMM_WORLD, lag=True, **kwargs):
    p = cantilever_3d(MATERIAL, cells=CELLS, traction=LOAD, comm=comm)
    prefix = f"t{id(p)}_"
    if not lag:  # PETSc's option: an AMG set-up for every tangent
        PETSc.Options()[f"{prefix}snes_lag_preconditioner"] = 1
    try:
        solver = solver_cls(p.residual, p.u, p.bcs, prefix=prefix, max_it=200, **kwargs)
    finally:
        PETSc.Options().delValue(f"{prefix}snes_lag_preconditioner")
    counter = EventCounter(["MatLUFactorNum"])
    result = solver.solve()
    result.petsc_factorizations = counter.stop()["MatLUFactorNum"][0]
    return p, result


@pytest.fixture(scope="module")
def snes_reference():
    p, r = solve(SnesSolver, method="full")
    assert r.converged
    return p.u.x.array.copy(), tip(p)


@pytest.mark.parametrize("method", ["full", "modified", "periodic", "bfgs"])
def test_hand_written_newton_matches_snes(method, snes_reference):
    u_ref, tip_ref = snes_reference
    p, r = solve(NewtonSolver, method=method)
    assert r.converged
    assert abs(tip(p) - tip_ref) < 1e-8 * abs(tip_ref)
    assert np.linalg.norm(p.u.x.array - u_ref) < 1e-8 * np.linalg.norm(u_ref)


def test_iterative_linear_solver_gives_the_same_solution(snes_reference):
    # CG + GAMG with rigid-body near-nullspace in place of MUMPS: the inexact Newton
    # forcing term against CG solved tightly (a fixed -ksp_rtol from the command line)
    _, tip_ref = snes_reference
    _, exact = solve(NewtonSolver, method="full")
    p, inexact = solve(NewtonSolver, method="full", linear_solver="gamg")
    assert abs(tip(p) - tip_ref) < 1e-7 * abs(tip_ref)
    opts = PETSc.Options()
    opts["tight_ksp_rtol"] = 1e-10
    try:
        q = cantilever_3d(MATERIAL, cells=CELLS, traction=LOAD)
        tight = NewtonSolver(q.residual, q.u, q.bcs, prefix="tight_", linear_solver="gamg")
        assert not tight._forcing  # the command line fixed the rtol
        tight.solve()
    finally:
        del opts["tight_ksp_rtol"]
    assert abs(tip(q) - tip_ref) < 1e-7 * abs(tip_ref)
    # loose early solves save CG iterations without costing Newton iterations
    assert inexact.iterations <= exact.iterations + 1
    assert inexact.work.krylov_iterations < 0.85 * tight.total.krylov_iterations


def test_the_last_corrections_are_solved_no_tighter_than_convergence_needs(monkeypatch):
    # at a Newton tolerance of 1e-6, 1e-3 ‖R_k‖/‖R_0‖ asks the last corrections for digits
    # the convergence test never reads: η ≥ 0.1 (its threshold)/‖R_k‖ saves their Krylov
    # iterations, with the same Newton iterations and a residual below the threshold
    from fenics_nl.solvers import newton

    runs = {}
    plain = newton.forcing_term
    for floor in (True, False):
        if not floor:  # the forcing term without its floor
            monkeypatch.setattr(newton, "forcing_term", lambda rel, threshold_ratio=0.0: plain(rel))
        p, r = solve(NewtonSolver, method="full", linear_solver="gamg", rtol=1e-6, atol=0)
        runs[floor] = r, tip(p)
    (floored, tip_floored), (plain_run, tip_plain) = runs[True], runs[False]
    assert floored.converged and floored.residual_norms[-1] <= 1e-6 * floored.residual_norms[0]
    assert floored.iterations == plain_run.iterations
    # measured 98 against 122 Krylov iterations, 5 Newton iterations each
    assert floored.work.krylov_iterations < 0.9 * plain_run.work.krylov_iterations
    assert abs(tip_floored - tip_plain) < 1e-5 * abs(tip_plain)


def test_an_amg_hierarchy_is_built_once_per_solve_and_lags_behind_the_tangent(
        snes_reference):
    # full Newton on CG + GAMG keeps the first tangent's hierarchy (PETSc counts its
    # set-ups) while CG needs at most twice its first count; the same answer, the same
    # Newton iterations, fewer set-ups than with a hierarchy per tangent
    _, tip_ref = snes_reference
    counted = ["PCSetUp_GAMG+"]
    runs = {}
    for lag in (True, False):
        counter = EventCounter(counted)
        p, r = solve(NewtonSolver, method="full", linear_solver="gamg", lag=lag)
        runs[lag] = r, counter.stop()[counted[0]][0]
        assert abs(tip(p) - tip_ref) < 1e-7 * abs(tip_ref)
    (lagged, lagged_setups), (fresh, fresh_setups) = runs[True], runs[False]
    assert fresh_setups == fresh.work.factorizations == fresh.iterations == 5
    assert lagged_setups == lagged.work.factorizations == 1  # measured; CG kept up
    assert lagged.iterations == fresh.iterations
    # a new solve (the next load increment) sets a hierarchy up on its first tangent
    p = cantilever_3d(MATERIAL, cells=CELLS, traction=LOAD)
    solver = NewtonSolver(p.residual, p.u, p.bcs, prefix="lagnext_", linear_solver="gamg")
    solver.solve()
    p.load.value *= 1.1
    assert solver.solve().work.factorizations >= 1


@pytest.mark.parametrize("method", ["modified", "bfgs"])
def test_a_frozen_operator_on_cg_solves_no_tighter_than_it_converges(method, snes_reference):
    # modified Newton and BFGS converge linearly (superlinearly) whatever the solve's
    # accuracy below their own contraction: CG to 1e-3 throughout, not tightened with the
    # residual as full Newton's corrections are; the same answer
    _, tip_ref = snes_reference
    p, r = solve(NewtonSolver, method=method, linear_solver="gamg")
    _, direct = solve(NewtonSolver, method=method)
    assert abs(tip(p) - tip_ref) < 1e-7 * abs(tip_ref)
    assert r.iterations <= direct.iterations + 1  # the loose solves cost no iterations
    # measured 12-13 CG iterations per correction (30 when tightened with the residual)
    assert r.work.krylov_iterations < 20 * r.iterations


def test_full_newton_is_quadratic_and_snes_agrees_iteration_by_iteration():
    _, r = solve(NewtonSolver, method="full")
    _, s = solve(SnesSolver, method="full")
    assert r.order > 1.8
    assert r.iterations == s.iterations
    # same algorithm: the residual histories agree to round-off until the last iterate
    np.testing.assert_allclose(r.residual_norms[:-1], s.residual_norms[:-1], rtol=1e-6)
    assert r.work.factorizations == r.iterations == r.petsc_factorizations
    # each residual norm has its time stamp (the benchmarks plot error against time)
    for x in (r, s):
        assert len(x.elapsed) == len(x.residual_norms)
        assert np.all(np.diff(x.elapsed) > 0) and x.elapsed[-1] <= x.wall_time


def test_modified_newton_is_linear_and_factorizes_once():
    _, r = solve(NewtonSolver, method="modified")
    assert r.iterations > 10
    assert r.orders[-1] == pytest.approx(1.0, abs=0.1)
    assert r.work.factorizations == r.work.tangent_assemblies == 1
    assert r.petsc_factorizations == 1  # PETSc's own count: no refactorization
    assert r.work.linear_solves == r.iterations


def test_elastic_tangent_is_factorized_once_for_the_whole_load_history():
    p = cantilever_3d(MATERIAL, cells=CELLS, traction=0.0)
    solver = NewtonSolver(p.residual, p.u, p.bcs, method="modified",
                          constant_tangent="elastic", max_it=300, prefix="elastic_")
    counter = EventCounter(["MatLUFactorNum"])
    path = solve_incrementally(solver, lambda t: p.load.value.__setitem__(2, t * LOAD), steps=3,
                               adaptive=False)
    assert len(path.results) == 3
    assert path.work.factorizations == 1 == counter.stop()["MatLUFactorNum"][0]


@pytest.mark.parametrize("period", [2, 3])
def test_periodic_newton_refactorizes_every_period(period):
    _, r = solve(NewtonSolver, method="periodic", period=period)
    assert r.work.factorizations == math.ceil(r.iterations / period) == r.petsc_factorizations


def test_bfgs_beats_modified_newton_with_one_factorization():
    _, m = solve(NewtonSolver, method="modified")
    _, b = solve(NewtonSolver, method="bfgs")
    assert b.work.factorizations == 1 == b.petsc_factorizations
    assert b.iterations < 0.6 * m.iterations


def test_snes_lagged_jacobian_reproduces_modified_newton():
    _, r = solve(NewtonSolver, method="modified")
    _, s = solve(SnesSolver, method="modified")
    assert s.work.factorizations == 1 and s.iterations == r.iterations


def test_failures_raise_clear_errors_and_load_stepping_recovers():
    # 40x the default load in one step needs more than 4 full Newton iterations.
    p = cantilever_3d(MATERIAL, cells=CELLS, traction=0.0)
    solver = NewtonSolver(p.residual, p.u, p.bcs, method="full", max_it=4, prefix="div_")
    p.load.value[2] = 40 * LOAD
    with pytest.raises(ConvergenceError, match="no convergence in 4 iterations") as err:
        solver.solve()
    assert not err.value.result.converged and err.value.result.reason == "max_it"
    # adaptive steps from the unloaded state reach the same load
    p.u.x.array[:] = 0.0
    solver.convergence = dataclasses.replace(solver.convergence, max_it=6)
    path = solve_incrementally(solver, lambda t: p.load.value.__setitem__(2, t * 40 * LOAD),
                               steps=1)
    assert path.failures >= 1 and path.factors[-1] == pytest.approx(1.0)
    assert all(r.converged for r in path.results)
    # a non-finite residual is caught, not iterated on
    p.load.value[2] = np.nan
    with pytest.raises(ConvergenceError, match="not finite"):
        solver.solve()


def test_load_stepping_refuses_clearly_below_min_step():
    p = cantilever_3d(MATERIAL, cells=CELLS, traction=0.0)
    solver = NewtonSolver(p.residual, p.u, p.bcs, method="full", max_it=1, prefix="min_")
    with pytest.raises(LoadStepError, match="not reached"):
        solve_incrementally(solver, lambda t: p.load.value.__setitem__(2, t * LOAD),
                            steps=1, min_step=0.2)
    assert np.all(np.isfinite(p.u.x.array))


def test_bad_options_are_value_errors():
    p = cantilever_3d(MATERIAL, cells=(2, 1, 1))
    with pytest.raises(ValueError, match="method"):
        NewtonSolver(p.residual, p.u, p.bcs, method="halley")
    with pytest.raises(ValueError, match="period"):
        NewtonSolver(p.residual, p.u, p.bcs, method="periodic", period=0)


@pytest.mark.mpi
@pytest.mark.parametrize("method", ["full", "bfgs"])
def test_parallel_solve_matches_serial(method):
    comm = MPI.COMM_WORLD
    assert comm.size > 1, "run under mpiexec -n 2"
    p, r = solve(NewtonSolver, comm=comm, method=method)
    ps, rs = solve(NewtonSolver, comm=MPI.COMM_SELF, method=method)
    assert abs(tip(p) - tip(ps)) < 1e-8 * abs(tip(ps))
    assert r.iterations == rs.iterations


@pytest.mark.mpi
def test_lagged_amg_on_two_ranks_gives_the_serial_answer():
    # the decision to keep a hierarchy (CG's iteration count) is the same on every rank
    comm = MPI.COMM_WORLD
    assert comm.size > 1, "run under mpiexec -n 2"
    p, r = solve(NewtonSolver, comm=comm, linear_solver="gamg")
    ps, rs = solve(NewtonSolver, comm=MPI.COMM_SELF, linear_solver="gamg")
    assert abs(tip(p) - tip(ps)) < 1e-7 * abs(tip(ps))
    assert r.work.factorizations < r.iterations and rs.work.factorizations < rs.iterations
    # every rank counted the same set-ups (a decision that differed would hang or differ)
    assert comm.allgather(r.work.factorizations) == [r.work.factorizations] * comm.size


def test_linear_solver_failure_keeps_the_residual_history():
    # CG without preconditioner, 2 iterations: the first correction fails; the error says
    # so and its result holds the first residual, as every other failure does
    p = cantilever_3d(MATERIAL, cells=CELLS, traction=LOAD)
    opts = PETSc.Options()
    for k, v in {"kspfail_ksp_type": "cg", "kspfail_pc_type": "none",
                 "kspfail_ksp_max_it": "2"}.items():
        opts[k] = v
    try:
        s = NewtonSolver(p.residual, p.u, p.bcs, prefix="kspfail_")
        with pytest.raises(ConvergenceError, match=r"linear solver failed .* at iteration 0") as e:
            s.solve()
    finally:
        for k in ("kspfail_ksp_type", "kspfail_pc_type", "kspfail_ksp_max_it"):
            opts.delValue(k)
    assert e.value.result.reason == "ksp" and len(e.value.result.residual_norms) == 1


def test_bfgs_keeps_at_most_its_memory():
    p = cantilever_3d(MATERIAL, cells=CELLS, traction=LOAD)
    opts = PETSc.Options()
    opts["bfgsmem_snes_qn_m"] = 3  # PETSc's name of the L-BFGS memory
    try:
        s = NewtonSolver(p.residual, p.u, p.bcs, prefix="bfgsmem_", method="bfgs", max_it=200)
    finally:
        opts.delValue("bfgsmem_snes_qn_m")
    r = s.solve()
    assert r.iterations > 3 and len(s.bfgs.pairs) == 3


def test_a_snes_solver_leaves_no_option_behind_for_the_next_one():
    # dolfinx writes a problem's options into PETSc's global database and deleted them by
    # their unprefixed names: they stayed, and the next SnesSolver under the same prefix took
    # them for the user's, so a modified Newton after a full one refactorized every iteration
    # (a flaky test: the prefixes here are made of id(), which Python reuses)
    p = cantilever_3d(MATERIAL, cells=CELLS, traction=LOAD)
    SnesSolver(p.residual, p.u, p.bcs, prefix="reused_", method="full")
    assert not [k for k in PETSc.Options().getAll() if k.startswith("reused_")]
    p.u.x.array[:] = 0.0
    modified = SnesSolver(p.residual, p.u, p.bcs, prefix="reused_", method="modified",
                          max_it=200).solve()
    assert modified.converged and modified.work.factorizations == 1


def test_the_convergence_test_newton_arc_length_and_snes_share():
    # ‖R‖ ≤ max(rtol ‖R0‖, atol F); max_it; divergence after the first iteration only, and
    # off for a tolerance <= 0 (PETSc's -snes_divergence_tolerance -1)
    t = ConvergenceTest(rtol=1e-6, atol=1e-8, max_it=3, divergence_tol=1e4)
    assert t.reason([1.0], 1.0) is None
    assert t.reason([1.0, 2e-6, 9e-7], 1.0) == "converged"  # rtol ‖R0‖
    assert t.reason([1.0, 2e-3], 1e5) is None and t.reason([1.0, 9e-4], 1e5) == "converged"
    assert t.reason([1.0, 0.5, 0.4, 0.3], 1.0) == "max_it"
    assert t.reason([1.0, 2e4], 1.0) == "diverged" and t.reason([1.0, 9e3], 1.0) is None
    assert t.reason([1.0, math.nan], 1.0) == "nan" and t.reason([math.inf], 1.0) == "nan"
    assert ConvergenceTest(divergence_tol=-1).reason([1.0, 1e12], 1.0) is None


def test_the_command_line_tolerances_are_petscs_for_newton_and_snes():
    # -<prefix>snes_rtol, snes_max_it override the code's values for the hand-written Newton
    # as for SNES; -<prefix>snes_atol is then a force, as PETSc's (F = 1)
    opts = PETSc.Options()
    opts["cl_snes_rtol"], opts["cl_snes_max_it"], opts["cl_snes_atol"] = 1e-3, 7, 2.0
    try:
        t = ConvergenceTest(rtol=1e-10, atol=1e-10, max_it=50).with_options("cl_")
        assert (t.rtol, t.max_it, t.atol, t.absolute) == (1e-3, 7, 2.0, True)
        assert t.threshold(1.0, 1e6) == 2.0  # not atol · F
        interval = dolfinx.mesh.create_unit_interval(MPI.COMM_WORLD, 2)
        u = fem.Function(fem.functionspace(interval, ("Lagrange", 1)))
        v = ufl.TestFunction(u.function_space)
        newton = NewtonSolver((u - 1.0) * v * ufl.dx, u, prefix="cl_")
        assert newton.convergence == t
        assert ConvergenceTest().with_options("other_") == ConvergenceTest()
    finally:
        for k in ("rtol", "max_it", "atol"):
            opts.delValue(f"cl_snes_{k}")


def test_row_couplings_enter_the_residual_and_its_tangent_alike():
    # friction's consistent slip force as `NodalTerms` writes it: a row t takes c times a
    # Dirichlet row s, R_t + c R_s, on a neo-Hookean square (its tangent depends on u) held
    # at its bottom and at one top node's vertical dof s, t that node's horizontal one. The
    # tangent the solver assembles (K_t + c K_s, K_s read before the Dirichlet rows are
    # set) is that residual's derivative: Taylor remainders of slope 2 off the Dirichlet
    # rows; the tangent without the coupling gives slope 1 (the test sees the coupling)
    from dolfinx import mesh

    from fenics_nl.materials.laws import NeoHookean
    from fenics_nl.solvers.result import WorkCounts
    from fenics_nl.solvers.supports import constrained_dofs

    m = mesh.create_unit_square(MPI.COMM_SELF, 4, 4)
    V = fem.functionspace(m, ("Lagrange", 1, (2,)))
    u, v = fem.Function(V), ufl.TestFunction(V)
    rng = np.random.default_rng(7)
    u.x.array[:] = 0.05 * rng.standard_normal(u.x.array.size)
    residual = NeoHookean(1.0, 0.3).internal_work(u, v, "plane_strain") * ufl.dx
    corner = mesh.locate_entities_boundary(m, 0, lambda x: np.isclose(x[0], 1) & np.isclose(
        x[1], 1))
    bottom = mesh.locate_entities_boundary(m, 1, lambda x: np.isclose(x[1], 0))
    held = [fem.dirichletbc(np.zeros(2), fem.locate_dofs_topological(V, 1, bottom), V),
            fem.dirichletbc(0.0, fem.locate_dofs_topological(V.sub(1), 0, corner), V.sub(1))]
    for bc in held:  # (u where it is held: 0)
        bc.set(u.x.array)
    node = fem.locate_dofs_topological(V, 0, corner)[0]
    t, s = 2 * node, 2 * node + 1
    solver = NewtonSolver(residual, u, held, prefix="couplings_")
    work, u0 = WorkCounts(), u.x.array.copy()
    du = 0.05 * rng.standard_normal(u.x.array.size)
    fixed = constrained_dofs(held)
    du[fixed] = 0.0
    free = np.setdiff1d(np.arange(u.x.array.size), fixed)

    def remainders(coupled_tangent):
        solver.nodal.set_couplings([t] if coupled_tangent else [], [s] if coupled_tangent
                                   else [], [0.3] if coupled_tangent else [])
        u.x.array[:] = u0
        solver.assemble_exact_tangent(work)
        Kdu = solver.A.createVecLeft()
        x = solver.A.createVecRight()
        x.array[:] = du
        solver.A.mult(x, Kdu)
        solver.nodal.set_couplings([t], [s], [0.3])  # the residual is always coupled
        solver.residual(work)
        b0 = solver.residual_vector.array.copy()
        out = []
        for h in (1e-3, 5e-4, 2.5e-4, 1.25e-4):
            u.x.array[:] = u0 + h * du
            solver.residual(work)
            r = solver.residual_vector.array - b0 - h * Kdu.array
            out.append(np.linalg.norm(r[free]))
        return np.log2(np.array(out[:-1]) / np.array(out[1:]))

    assert remainders(True) == pytest.approx(2.0, abs=0.05)
    assert remainders(False)[-1] == pytest.approx(1.0, abs=0.15)
