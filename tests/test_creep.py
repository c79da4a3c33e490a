"""Norton creep against its uniaxial closed forms (issue 57).

A cube of one hexahedron in uniaxial stress (each face x, y, z = 0 holds its normal
component, the face x = 1 pulled or held): the stress and strain are uniform, so the finite
element is exact in space and what is measured is the law and its time integration.
"""

import itertools
import math

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.materials import kinematics, mixed
from fenics_nl.materials.creep import NEWTON_STEPS, NortonCreep
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.solvers.time_stepping import LoadHistory, solve_in_time

E, NU, A = 200.0, 0.3, 1e-3


def cube(material, *, stress=None):
    """The cube, its residual's Newton solver, and a reader of the uniform σ_xx and ε_xx.

    `stress`: a traction σ on x = 1 (creep); else the face's u_x is a Dirichlet value
    (relaxation); the returned `pull` sets the one or the other.
    """
    msh = mesh.create_unit_cube(MPI.COMM_WORLD, 1, 1, 1, mesh.CellType.hexahedron)
    V = fem.functionspace(msh, ("Lagrange", 1, (3,)))
    u, v = fem.Function(V), ufl.TestFunction(V)
    faces = {k: mesh.locate_entities_boundary(msh, 2, lambda x, k=k: np.isclose(x[k], 0.0))
             for k in range(3)}
    bcs = [boundary.component(V, k, faces[k]) for k in range(3)]
    right = mesh.locate_entities_boundary(msh, 2, lambda x: np.isclose(x[0], 1.0))
    material.bind(msh, 2)
    dx = kinematics.quadrature_measure("dx", msh, 2)
    eps = kinematics.small_strain(u, "3d")
    residual = ufl.inner(material.stress(eps), kinematics.small_strain(v, "3d")) * dx
    pulled = boundary.component(V, 0, right)
    if stress is None:
        bcs.append(pulled)
    else:
        tags = mesh.meshtags(msh, 2, np.sort(right), np.ones(len(right), dtype=np.int32))
        ds = ufl.Measure("ds", msh, subdomain_data=tags)
        traction = fem.Constant(msh, float(stress))
        residual -= traction * v[0] * ds(1)
    solver = NewtonSolver(residual, u, bcs, rtol=1e-12, atol=1e-13, force_scale=E)
    sigma_xx = fem.form(material.stress(eps)[0, 0] * dx)
    eps_xx = fem.form(eps[0, 0] * dx)

    def read():
        return (msh.comm.allreduce(fem.assemble_scalar(sigma_xx)),
                msh.comm.allreduce(fem.assemble_scalar(eps_xx)))

    def pull(value):  # the end's displacement u_x = ε_xx, or the traction
        if stress is None:
            pulled.g.x.array[:] = value
        else:
            traction.value = value

    return solver, read, pull, u


@pytest.mark.parametrize("n", [1.0, 3.0, 5.0])
def test_creep_at_constant_stress_is_the_closed_form(n):
    # ε(t) = σ/E + A σⁿ t: at a constant stress backward Euler integrates ε̇ᵛ = A σⁿ exactly
    sigma, dt = 2.0, 0.5
    law = NortonCreep(E, NU, A=A, n=n)
    solver, read, _, u = cube(law, stress=sigma)
    law.set_time_step(0.0)  # the load applied at once: Hooke's response
    solver.solve()
    law.commit(u)
    for k in range(1, 9):
        law.set_time_step(dt)
        result = solver.solve()
        s, e = read()  # the step's state, before it becomes the committed one
        law.commit(u)
        assert s == pytest.approx(sigma, rel=1e-10)
        assert e == pytest.approx(sigma / E + A * sigma**n * k * dt, rel=1e-10)
        assert quadratic(result.residual_norms)  # the consistent tangent


def quadratic(norms):
    """Newton's last three residuals above round-off fall at an order of 2 (within 10 %)."""
    r = [x for x in norms if x > 1e-12 * norms[0]][-3:]
    if len(r) < 3:
        return True  # converged in one or two iterations: nothing to fit
    return math.log(r[2] / r[1]) / math.log(r[1] / r[0]) > 1.8


def relaxation_error(n, steps, t_end, strain):
    """The largest relative error of σ(t) over `steps` backward-Euler steps to t_end."""
    law = NortonCreep(E, NU, A=A, n=n)
    solver, read, pull, u = cube(law)
    pull(strain)
    law.set_time_step(0.0)
    solver.solve()
    sigma1 = read()[0]
    law.commit(u)
    assert sigma1 == pytest.approx(E * strain, rel=1e-12)  # uniaxial stress: σ = E ε
    law.set_time_step(t_end / steps)
    worst, quadratic_steps = 0.0, []
    for k in range(1, steps + 1):
        quadratic_steps.append(quadratic(solver.solve().residual_norms))
        sigma = read()[0]
        law.commit(u)
        t = k * t_end / steps
        exact = (sigma1 ** (1 - n) + (n - 1) * E * A * t) ** (1 / (1 - n)) if n != 1 \
            else sigma1 * math.exp(-E * A * t)
        worst = max(worst, abs(sigma / exact - 1))
    return worst, all(quadratic_steps)


@pytest.mark.parametrize("n", [1.0, 3.0])
def test_relaxation_converges_to_the_closed_form_at_first_order(n):
    # σ(t) = [σ1^(1−n) + (n−1) E A t]^(1/(1−n)) at a held strain (σ1 e^(−EAt) at n = 1),
    # followed until σ has fallen to a fifth; backward Euler is first order in Δt: halving
    # the steps halves the error (measured 1.995 at n = 1, 1.92 at n = 3; within 10 % of 2:
    # a limit other than the closed form would not halve). Its size with 160 equal steps,
    # 0.81 % (n = 1) and 1.98 % (n = 3, whose first steps relax fastest), bounded at 2.5 %:
    # equal steps are what the time driver's adaptive steps will improve on
    strain, sigma1 = 0.01, E * 0.01
    t_end = ((sigma1 / 5) ** (1 - n) - sigma1 ** (1 - n)) / ((n - 1) * E * A) if n != 1 \
        else math.log(5) / (E * A)
    coarse, quadratic_coarse = relaxation_error(n, 80, t_end, strain)
    fine, _ = relaxation_error(n, 160, t_end, strain)
    assert coarse / fine == pytest.approx(2.0, rel=0.1)
    assert fine < 0.025
    assert quadratic_coarse


def adaptive_relaxation(tolerance, adaptive=True, steps=10):
    """Relaxation at n = 3 to a fifth of σ1 (the strain held from time 0) by the time
    driver: its path, the largest relative error of σ over its steps, and the cube."""
    n, strain = 3.0, 0.01
    sigma1 = E * strain
    t_end = ((sigma1 / 5) ** (1 - n) - sigma1 ** (1 - n)) / ((n - 1) * E * A)
    law = NortonCreep(E, NU, A=A, n=n)
    solver, read, pull, u = cube(law)
    errors = []

    def on_step(t, f, result):  # between steps the law's Δt is 0: σ is the committed one
        exact = (sigma1 ** (1 - n) + (n - 1) * E * A * t) ** (1 / (1 - n))
        errors.append(abs(read()[0] / exact - 1))

    path = solve_in_time(solver, law, lambda f: pull(f * strain), LoadHistory([(0.0, 1.0)]),
                         t_end, steps, adaptive=adaptive, tolerance=tolerance,
                         commit=lambda: law.commit(u), on_step=on_step)
    return path, max(errors), (law, solver, read, pull, u)


def test_steps_sized_by_their_error_follow_relaxation_in_half_the_steps():
    # the time driver's local error (half the change of the viscous strain rate over a
    # step, over the largest σ_eq): measured 84 steps and 1.47 % at 1e-3, 31 steps and
    # 4.17 % at 1e-2, where 160 equal steps give 1.98 % (the test above). A first-order
    # method's error with steps sized to a local error tol grows as √tol: the ratio of the
    # two is 2.84, bounded within 20 % of √10 = 3.16
    path, fine = adaptive_relaxation(1e-3)[:2]
    coarse = adaptive_relaxation(1e-2)[1]
    assert len(path.times) <= 90 and fine < 0.0198
    assert coarse / fine == pytest.approx(math.sqrt(10), rel=0.2)


def test_a_step_undone_for_its_error_leaves_no_trace():
    # each time a step is undone (6 in this run), the displacement and the law's state are
    # those of the last accepted step, bit for bit; and the accepted steps retaken by hand
    # on a fresh cube end at the same stress, to round-off
    n, strain = 3.0, 0.01
    law = NortonCreep(E, NU, A=A, n=n)
    solver, read, pull, u = cube(law)
    accepted, undone = {}, []

    def on_step(t, f, result):
        accepted["u"] = u.x.array.copy()
        accepted["state"] = [g.x.array.copy() for g in law.state_functions().values()]

    def progress(line):
        if "undone" in line:
            undone.append(np.array_equal(u.x.array, accepted["u"]) and all(
                np.array_equal(g.x.array, kept) for g, kept in
                zip(law.state_functions().values(), accepted["state"], strict=True)))

    sigma1 = E * strain
    t_end = ((sigma1 / 5) ** (1 - n) - sigma1 ** (1 - n)) / ((n - 1) * E * A)
    path = solve_in_time(solver, law, lambda f: pull(f * strain), LoadHistory([(0.0, 1.0)]),
                         t_end, 10, tolerance=1e-2, commit=lambda: law.commit(u),
                         on_step=on_step, progress=progress)
    assert len(undone) == path.rejected > 0 and all(undone)
    again = NortonCreep(E, NU, A=A, n=n)
    by_hand, read_again, pull_again, u_again = cube(again)
    pull_again(strain)
    for t0, t1 in itertools.pairwise(path.times):
        again.set_time_step(t1 - t0)
        by_hand.solve()
        again.commit(u_again)
    again.set_time_step(0.0)
    assert read_again()[0] == pytest.approx(read()[0], rel=1e-12)


def test_creep_under_a_ramped_load_is_stationary_once_the_load_is_held():
    # σ = the traction, so σ_eq stops changing the moment the ramp ends: the first step
    # after it is stationary (and the steps land on the ramp's end); from there the
    # strain grows at A σⁿ, the rate backward Euler integrates exactly
    sigma, n, t_ramp = 2.0, 3.0, 1.0
    law = NortonCreep(E, NU, A=A, n=n)
    solver, read, pull, u = cube(law, stress=0.0)
    strains = []
    path = solve_in_time(solver, law, lambda f: pull(f * sigma),
                         LoadHistory([(0.0, 0.0), (t_ramp, 1.0)]), 10.0, 4,
                         commit=lambda: law.commit(u),
                         on_step=lambda t, f, result: strains.append(read()[1]))
    first_held = path.times.index(t_ramp) + 1
    assert path.stationary_since == path.times[first_held]
    slope = (strains[-1] - strains[first_held]) / (path.times[-1] - path.times[first_held])
    assert slope == pytest.approx(A * sigma**n, rel=1e-10)


def test_perzyna_relaxes_to_its_yield_stress_as_the_closed_form():
    # m = 1, a strain held above yield: the overstress y = σ − σ0 − H p relaxes as
    # y0 exp(−(E + H) t/K) (uniaxially ṗ = y/K, σ = E(ε − p)), to σ0 + H p∞; through the
    # time driver at a local error of 1e-4 (192 steps): its largest error along the way
    # 0.29 % of y0 (0.87 % at 1e-3: ∝ √tol), bounded at 0.5 %; the stationary state said
    # once y has gone
    from fenics_nl.materials.creep import PerzynaViscoplasticity

    sigma0, H, K, strain = 1.0, 20.0, 2.0, 3.0 / E
    law = PerzynaViscoplasticity(E, NU, sigma0=sigma0, H=H, K=K, m=1.0)
    solver, read, pull, u = cube(law)
    y0 = E * strain - sigma0
    rate = (E + H) / K
    errors = []

    def on_step(t, f, result):
        exact = sigma0 + H * (y0 - y0 * math.exp(-rate * t)) / (E + H) \
            + y0 * math.exp(-rate * t)
        errors.append(abs(read()[0] - exact) / y0)

    path = solve_in_time(solver, law, lambda f: pull(f * strain), LoadHistory([(0.0, 1.0)]),
                         40 / rate, 10, tolerance=1e-4, commit=lambda: law.commit(u),
                         on_step=on_step)
    assert max(errors) < 5e-3
    assert path.stationary_since is not None
    assert read()[0] == pytest.approx(sigma0 + H * y0 / (E + H), rel=1e-6)


def test_the_local_equation_is_solved_to_round_off_over_24_decades():
    # q + c qⁿ = q_tr by the law's Newton steps from min(q_tr, (q_tr/c)^(1/n)), against
    # bisection: the iteration the UFL expression unrolls, at its NEWTON_STEPS
    for n in (1.0, 1.5, 3.0, 5.0, 12.0):
        for c in np.logspace(-12, 12, 49):
            q_tr = 1.0
            q = min(q_tr, (q_tr / c) ** (1 / n))
            for _ in range(NEWTON_STEPS):
                q -= (q + c * q**n - q_tr) / (1 + n * c * q ** (n - 1))
            lo, hi = 0.0, q_tr
            for _ in range(200):
                mid = 0.5 * (lo + hi)
                lo, hi = (lo, mid) if mid + c * mid**n > q_tr else (mid, hi)
            assert q == pytest.approx(lo, rel=4e-15), (n, c)


def test_parameters_are_checked_in_one_line():
    for kwargs, words in (({"A": 0.0}, "A must be > 0"), ({"n": 0.5}, "n must be >= 1")):
        with pytest.raises(ValueError, match=words):
            NortonCreep(E, NU, **kwargs)
    law = NortonCreep(E, NU)
    with pytest.raises(ValueError, match="bind"):
        law.set_time_step(1.0)


def stationary_vessel(shape, n, size, comm=MPI.COMM_WORLD):
    """A thick vessel (a = 1, b = 2) of Norton's law under an inner pressure held until its
    stresses stop changing: the largest errors of σ_rr and σ_θθ against the stationary
    closed form (over p), at the quadrature points nearest the bore, mid-wall and outside.

    Taylor–Hood (u, p): stationary creep is an incompressible flow whose strain grows
    without bound, which P2 displacements alone cannot follow (on this cylinder at n = 1
    their hoop stress at the bore drifted from 1.65 p by −0.03 p at every step of Δt = 10,
    where Taylor–Hood holds 1.6502 p against Lamé's 1.6493 p).
    """
    from plasticity_problems import thick_vessel

    from fenics_nl.expression import Expression
    from fenics_nl.materials import mixed
    from fenics_nl.materials.plasticity import quadrature_spaces

    p, a, b = 0.1, 1.0, 2.0
    vessel = thick_vessel(shape, a, b, size=size, mixed=True, comm=comm)
    law = NortonCreep(1.0, 0.3, A=1.0, n=n)
    law.bind(vessel.mesh, vessel.quadrature_degree)
    m = vessel.mixed
    residual = (mixed.internal_work(law, m.u, m.p, m.v, m.q, vessel.model) * vessel.dx
                + vessel.pressure * ufl.dot(vessel.normal, m.v) * vessel.weight
                * vessel.ds_inner)  # the traction −p n pushes the bore outwards
    solver = NewtonSolver(residual, vessel.unknown, vessel.supports, rtol=1e-11, atol=1e-10,
                          force_scale=p * a)
    # σ_rr and the hoop stress at the quadrature points, of the committed state (Δt = 0:
    # Hooke's of it), and their radii
    x = ufl.SpatialCoordinate(vessel.mesh)
    r = ufl.sqrt(x[0] ** 2 + x[1] ** 2)
    e_r = ufl.as_vector([x[0] / r, x[1] / r, 0])
    e_t = ufl.as_vector([-x[1] / r, x[0] / r, 0])
    sigma = mixed.cauchy_stress(law, m.u, m.p, vessel.model)
    hoop = sigma[2, 2] if shape == "sphere" else ufl.dot(e_t, sigma * e_t)
    _, Q = quadrature_spaces(vessel.mesh, vessel.quadrature_degree)
    points = Q.element.interpolation_points
    values = {name: fem.Function(Q) for name in ("rr", "tt", "r")}
    values["r"].interpolate(Expression(r, points))
    hoop_at, radial_at = Expression(hoop, points), Expression(ufl.dot(e_r, sigma * e_r), points)

    # the pressure applied at once (Δt = 0: Lamé's stresses), then held; the steps sized by
    # their local error, the run ended at the first step over which σ_eq changes by less
    # than 1e-9 of its largest value, long before 1000 relaxation times at the bore's
    # stress, 1/(E A pⁿ⁻¹)
    end = 1000 / (law.E * law.A * p ** (n - 1))
    path = solve_in_time(solver, law, lambda f: setattr(vessel.pressure, "value", f * p),
                         LoadHistory([(0.0, 1.0)]), end, 100, tolerance=1e-2,
                         stationary=1e-9, until_stationary=True,
                         commit=lambda: law.commit(m.u, vessel.model))
    assert path.stationary_since is not None, "no stationary state"
    values["tt"].interpolate(hoop_at)
    values["rr"].interpolate(radial_at)
    k = (2.0 if shape == "cylinder" else 3.0) / n
    rq = values["r"].x.array
    ratio = (b / rq) ** k
    exact_rr = -p * (ratio - 1) / ((b / a) ** k - 1)
    exact_tt = p * (((k - 1) if shape == "cylinder" else (k / 2 - 1)) * ratio + 1) / (
        (b / a) ** k - 1)
    errors = {}
    owned = Q.dofmap.index_map.size_local
    for where, r0 in (("bore", a), ("mid", 0.5 * (a + b)), ("outside", b)):
        distance = np.abs(rq[:owned] - r0)
        near = distance <= comm.allreduce(float(distance.min(initial=np.inf)), op=MPI.MIN) \
            + 1e-12
        error = max(np.abs(values["rr"].x.array[:owned][near] - exact_rr[:owned][near])
                    .max(initial=0.0),
                    np.abs(values["tt"].x.array[:owned][near] - exact_tt[:owned][near])
                    .max(initial=0.0))
        errors[where] = comm.allreduce(error, op=MPI.MAX) / p
    return errors, len(path.times)


@pytest.mark.parametrize("shape,n", [("cylinder", 3.0), ("cylinder", 5.0), ("sphere", 3.0),
                                     ("sphere", 5.0)])
def test_a_creeping_vessel_reaches_the_stationary_closed_form(shape, n):
    # the stationary stresses (the hoop stress falls at the bore, rises outside) against
    # the closed forms, k = 2/n (tube, plane strain) or 3/n (sphere); measured at h = 0.1
    # (P2–P1): at most 0.09 %, 0.07 %, 0.11 %, 0.09 % of p at the bore (cylinder n = 3,
    # 5; sphere n = 3, 5), 0.06 % mid-wall, 0.012 % outside, reached in 34 to 51 steps
    # (local error 1e-2); bounded at 0.25 % of p: the mesh's share, O(h²) (at h = 0.05: 0.024 %,
    # 0.007 %, 0.003 %)
    errors, steps = stationary_vessel(shape, n, 0.1)
    assert max(errors.values()) < 2.5e-3, errors
    assert steps < 60


def test_perzyna_tends_to_j2_as_the_step_outgrows_the_relaxation_time():
    # one step to 3 ε_y: as Δt → ∞ the overstress y ≈ K (f_tr/((3μ + H) Δt))^(1/m)
    # vanishes and Δp becomes J2's radial return; at m = 2, 1e4 times the step divides
    # the difference from J2 by 100
    from fenics_nl.materials import J2Plasticity
    from fenics_nl.materials.creep import PerzynaViscoplasticity

    def sigma(law, dt=None):
        solver, read, pull, _ = cube(law)
        if dt is not None:
            law.set_time_step(dt)
        pull(3 * 1.0 / E)
        solver.solve()
        return read()[0]

    j2 = sigma(J2Plasticity(E, NU, sigma0=1.0, H=5.0))
    assert j2 > 1.0  # yielded: σ = σ0 + H p
    gaps = [sigma(PerzynaViscoplasticity(E, NU, sigma0=1.0, H=5.0, K=0.5, m=2.0), dt) - j2
            for dt in (1e8, 1e12)]
    assert gaps[0] > gaps[1] > 0 and gaps[1] < 1e-7 * j2
    assert gaps[0] / gaps[1] == pytest.approx(100.0, rel=0.01)


@pytest.mark.parametrize("m", [1.0, 3.0])
def test_perzyna_at_a_constant_strain_rate_reaches_its_overstress_plateau(m):
    # ε = ε̇ t held up (H = 0): once the elastic strain stops changing, ṗ = ε̇ and the stress
    # is σ0 + K ε̇^(1/m), which backward Euler reproduces exactly there
    from fenics_nl.materials.creep import PerzynaViscoplasticity

    rate, dt, sigma0, K = 1e-3, 1.0, 1.0, 0.5
    law = PerzynaViscoplasticity(E, NU, sigma0=sigma0, H=0.0, K=K, m=m)
    solver, read, pull, u = cube(law)
    law.set_time_step(dt)
    history = []
    for k in range(1, 400):
        pull(rate * k * dt)
        solver.solve()
        history.append(read()[0])
        law.commit(u)
        if k > 10 and abs(history[-1] - history[-2]) < 1e-13:
            break
    assert history[-1] == pytest.approx(sigma0 + K * rate ** (1 / m), rel=1e-10)


@pytest.mark.mpi
def test_a_creeping_vessel_on_two_ranks_gives_the_serial_answer():
    # the same steps to the stationary state and the same errors at the bore, mid-wall and
    # outside (their points' stresses) as one rank's run of the same mesh
    assert MPI.COMM_WORLD.size > 1
    parallel, steps = stationary_vessel("cylinder", 3.0, 0.1, MPI.COMM_WORLD)
    serial, serial_steps = stationary_vessel("cylinder", 3.0, 0.1, MPI.COMM_SELF)
    assert steps == serial_steps
    for where in serial:
        assert parallel[where] == pytest.approx(serial[where], abs=1e-9)


# -- the demo ------------------------------------------------------------------------------

def test_the_creep_vessel_demo_goes_from_lame_to_the_stationary_state(demo):
    # its defaults (cylinder, n = 5, 10 elements through the wall, 40 relaxation times):
    # measured along y = 0 at nine radii (boundary points included), σ_rr and σ_θθ within
    # 0.43 % of p of Lamé at the end of the ramp (0.01 h: 8e-5 relaxation times, but 2e-3
    # of the bore's own, where σ_eq is 2.3 p and the flow 28 times faster) and 0.12 % of
    # the stationary closed form at the end; the bore's stationary rate within 0.003 %
    # (backward Euler is exact at a constant rate: the mesh's error only; bounded at 0.02 %)
    d = demo.json("creep_vessel.py")
    assert d["profile_error_lame"] < 0.006 and d["profile_error_stationary"] < 0.0025
    assert abs(d["bore_displacement_rate_error"]) < 2e-4
    assert d["stationary_since"] is not None and not d["warnings"]
    assert d["bore_hoop_stress"] < d["bore_hoop_stress_lame"] / 2  # it fell, and outside
    assert d["outer_hoop_stress"] > 1.2 * d["pressure"]  # it rose (Lamé: 0.667 p)


def test_a_killed_creep_run_restarts_to_the_uninterrupted_answer(tmp_path, demo):
    # killed after its 20th time step, restarted from its last checkpoint: the same steps
    # (the driver's last viscous strain rate and σ_eq come back with the state), the same
    # profiles and the same answer
    import sys

    from conftest import DEMOS, run_and_kill
    from demo_snapshot import differences

    flags = ["--end", "1000", "--tolerance", "1e-2"]
    whole = demo.json("creep_vessel.py", *flags)
    run_and_kill([sys.executable, DEMOS / "creep_vessel.py", *flags, "--checkpoint", "ck"],
                 tmp_path, "  step 20:")
    resumed = demo.json("creep_vessel.py", *flags, "--restart", tmp_path / "ck")
    assert differences(whole, resumed, "json") == []


# -- case files --------------------------------------------------------------------------

def test_a_creep_case_file_reaches_the_stationary_stresses(demo):
    # cases/creeping_cylinder.toml (n = 5, 30 MPa held for 5000 h, h = 1.5 mm on a 10 mm
    # wall): its probes' hoop stresses at the bore and outside within 0.1 % of p of the
    # stationary closed form (measured 0.02 % and 0.03 %), every step with its time, the
    # ramp's end among them, and the stationary state said
    from test_case import CASES

    from fenics_nl.theory import vessels

    d = demo.case(CASES / "creeping_cylinder.toml")
    p = 30.0
    _, st = vessels.stationary_creep_stresses("cylinder", 10.0, 20.0, p, 5.0,
                                               np.array([10.0, 20.0]))
    for name, exact in (("inner", st[0]), ("outer", st[1])):
        assert d["probes"][name]["stress"][1][1] == pytest.approx(exact, abs=1e-3 * p)
    times = [s["time"] for s in d["steps"]]
    assert 0.01 in times and times[-1] == d["time"] == 5000.0
    assert d["stationary_since"] is not None and d["law"] == "norton"


def test_a_creep_case_restarts_in_time_to_the_same_path(tmp_path, demo):
    # the case restarted one checkpoint short of its end: the same times, steps, probes and
    # totals (the steps taken and undone, the Newton iterations, the stationary state)
    from conftest import same_answer
    from test_case import CASES, rewound

    path = CASES / "creeping_cylinder.toml"
    whole = demo.case(path, "--checkpoint", tmp_path / "ck")
    assert rewound(tmp_path / "ck") == f"step-{len(whole['steps']) - 1:06d}"
    resumed = demo.case(path, "--restart", tmp_path / "ck")
    # (in time the load factor stays 1 step after step: the restart says its time)
    assert resumed["restarted_after_time"] == whole["steps"][-2]["time"]
    same_answer(whole, resumed)
    assert [s["time"] for s in whole["steps"]] == [s["time"] for s in resumed["steps"]]
    for key in ("time", "time_steps", "time_steps_undone", "stationary_since",
                "newton_iterations", "factorizations"):
        assert resumed[key] == whole[key], key


def test_a_perzyna_case_at_rest_is_j2s_answer(tmp_path, demo):
    # the creeping cylinder in Perzyna's law (σ0 = 40, perfect plasticity, K = 2e5, m = 1:
    # an overstress relaxation time K/(3μ) of about 1 h) held to rest, against the same
    # case in J2 reached in 10 load steps: the overstress gone, the same plastic state.
    # Measured: σ_eq at the bore 39.991 (J2: 40.000), the hoop stresses within 0.13 % of p,
    # u_r within 9e-4 (what remains: the paths differ, relaxing from Lamé's state against
    # loading step by step, and a perfectly plastic cylinder at ν = 0.3 keeps some of its
    # path in σ_zz)
    from test_case import CASES

    (tmp_path / "thick_cylinder.geo").write_text((CASES / "thick_cylinder.geo").read_text())
    text = (CASES / "creeping_cylinder.toml").read_text().replace(
        'law = "norton"', 'law = "perzyna"').replace("A = 5e-14\nn = 5.0",
        "sigma0 = 40.0\nK = 2.0e5\nm = 1.0")
    (tmp_path / "pz.toml").write_text(text)
    (tmp_path / "j2.toml").write_text(text.replace('law = "perzyna"', 'law = "j2"').replace(
        "K = 2.0e5\nm = 1.0\n", "").replace(
        "time = { end = 5000.0, steps = 20, tolerance = 1e-2 }\n"
        "factor = [[0.0, 0.0], [0.01, 1.0]]", "steps = 10"))
    viscous, plastic = demo.case(tmp_path / "pz.toml"), demo.case(tmp_path / "j2.toml")
    assert viscous["stationary_since"] is not None
    for name in ("inner", "outer"):
        a, b = viscous["probes"][name], plastic["probes"][name]
        assert a["von_mises"] == pytest.approx(b["von_mises"], rel=1e-3)
        assert a["stress"][1][1] == pytest.approx(b["stress"][1][1], abs=5e-3 * 30.0)
        assert a["displacement"][0] == pytest.approx(b["displacement"][0], rel=2e-3)
    assert plastic["probes"]["inner"]["von_mises"] == pytest.approx(40.0, rel=1e-9)  # yielded


@pytest.mark.parametrize("change,words", [
    (("time = { end = 5000.0, steps = 20, tolerance = 1e-2 }\nfactor = [[0.0, 0.0], "
      "[0.01, 1.0]]", "steps = 4"), "loading.time: missing: norton is rate-dependent"),
    (('law = "norton"', 'law = "j2"\nsigma0 = 100.0'), "loading.time: only with a rate-"),
    (("[0.01, 1.0]]", "[0.01, 0.0]]"), "no load is applied"),
    (("[0.01, 1.0]]", "[6000.0, 1.0]]"), "its last time 6000 is past the end 5000"),
    (("steps = 20,", "stpes = 20,"), "loading.time.stpes: unknown key (did you mean 'steps'?"),
    (('formulation = "mixed"\n', ""), 'mesh.formulation: norton needs "mixed"'),
])
def test_a_creep_case_file_refuses_what_has_no_meaning(tmp_path, change, words):
    # a rate-dependent law without time, time for a law without rate, a load factor 0 at
    # every time (nothing is loaded), a history past the end, a misspelt key, Norton on P2
    # displacements alone (they lock: the test below)
    import re

    from test_case import CASES

    from fenics_nl.case.spec import CaseError, read_case

    text = (CASES / "creeping_cylinder.toml").read_text().replace(*change)
    (tmp_path / "thick_cylinder.geo").write_text((CASES / "thick_cylinder.geo").read_text())
    (tmp_path / "c.toml").write_text(text)
    with pytest.raises(CaseError, match=re.escape(words)):
        read_case(tmp_path / "c.toml")


@pytest.mark.parametrize("biaxial", [False, True])
def test_creep_in_plane_stress_is_the_closed_form(biaxial):
    # the unit square of tests/test_plane_stress.py (ε_zz an unknown at each quadrature
    # point), under a held traction σ on x = 1 (and on y = 1): uniaxially
    # ε_xx = σ/E + A σⁿ t, equibiaxially (σ_eq = σ, s_xx = σ/3) ε_xx = (1 − ν) σ/E +
    # A σⁿ t/2, and σ_zz = 0 at every point; to 1e-10 (exact in space, and backward Euler
    # exact at a constant stress), through the time driver's adaptive steps
    from test_plane_stress import Sheet

    sigma, n = 2.0, 3.0
    law = NortonCreep(E, NU, A=A, n=n)
    sheet = Sheet(law, sigma, sigma if biaxial else 0.0)
    sheet.t.value = 1.0
    path = solve_in_time(sheet.solver, law, lambda f: setattr(sheet.t, "value", f),
                         LoadHistory([(0.0, 1.0)]), 10.0, 4,
                         commit=lambda: law.commit_strain(sheet.w.strain()))
    t = path.times[-1]
    elastic = (1 - NU) * sigma / E if biaxial else sigma / E
    flow = A * sigma**n * t * (0.5 if biaxial else 1.0)
    assert sheet.mean("exx") == pytest.approx(elastic + flow, rel=1e-10)
    assert sheet.largest_szz() < 1e-10 * sigma


def test_p2_displacements_alone_drift_under_stationary_creep():
    # why the demo and the case take Taylor–Hood: the cylinder (a = 1, b = 2, h = 0.1) at
    # n = 1, whose stationary stresses are Lamé's, held for 4 steps of 10 relaxation times
    # after the pressure applied at once: on P2 displacements alone the hoop stress at the
    # bore (at the probe on y = 0) drifts by −0.037 p at every step, on Taylor–Hood it
    # stays where it was (to 1.2e-6 p; 0.0024 p from Lamé's, the mesh's error at that point)
    from plasticity_problems import thick_vessel

    from fenics_nl.theory import vessels

    p = 0.1
    lame = vessels.elastic_stresses("cylinder", 1.0, 2.0, p, 1.0)[1]

    def hoops(with_pressure):
        vessel = thick_vessel("cylinder", 1.0, 2.0, size=0.1, mixed=with_pressure)
        law = NortonCreep(1.0, 0.3, A=1.0, n=1.0)
        law.bind(vessel.mesh, vessel.quadrature_degree)
        f = vessel.fields
        if with_pressure:
            internal = mixed.internal_work(law, f.u, f.p, f.v, f.q, vessel.model)
            sigma = mixed.cauchy_stress(law, f.u, f.p, vessel.model)
        else:
            eps = kinematics.small_strain(f.u, vessel.model)
            internal = ufl.inner(law.stress(eps), kinematics.small_strain(f.v, vessel.model)) \
                * vessel.weight
            sigma = law.stress(eps)
        residual = internal * vessel.dx + vessel.pressure * ufl.dot(
            vessel.normal, f.v) * vessel.weight * vessel.ds_inner
        vessel.pressure.value = p
        solver = NewtonSolver(residual, vessel.unknown, vessel.supports, rtol=1e-11,
                              atol=1e-10, force_scale=p)
        out = []
        for dt in (0.0, 10.0, 10.0, 10.0, 10.0):
            law.set_time_step(dt)
            solver.solve()
            law.commit(f.u, vessel.model)
            law.set_time_step(0.0)
            out.append(vessel.probes.discontinuous("hoop", sigma[1, 1], 2)[0] / p)
        return np.array(out)

    drift = np.diff(hoops(False))
    held = hoops(True)
    assert (drift < -0.01).all(), drift
    assert np.abs(np.diff(held)).max() < 1e-5 and np.abs(held - lame / p).max() < 5e-3, held
