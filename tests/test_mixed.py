"""The displacement–pressure (Taylor–Hood) formulation against closed forms."""

import math

import numpy as np
import pytest
import ufl
from mpi4py import MPI
from plasticity_problems import thick_vessel  # benchmarks/, on the tests' path

from fenics_nl.domain.probes import Probes
from fenics_nl.materials import mixed
from fenics_nl.materials.laws import LinearElastic, NeoHookean, PowerLaw, StVenantKirchhoff
from fenics_nl.materials.plasticity import J2Plasticity
from fenics_nl.solvers.loading import solve_incrementally
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.theory import vessels

A, B, E = 1.0, 2.0, 3.0  # a thick cylinder, shear modulus μ = 1 at ν = 1/2


def test_every_energy_is_its_volumetric_split():
    # φ = φ̃ + k/2 g², evaluated at a strain with volume change and shear
    eps = ufl.as_matrix([[1e-2, 3e-3, 0.0], [3e-3, -4e-3, 2e-3], [0.0, 2e-3, 5e-3]])
    for law in (LinearElastic(E, 0.3), PowerLaw(E, 0.3, sigma0=1e-2, n=0.3),
                StVenantKirchhoff(E, 0.3), NeoHookean(E, 0.3), NeoHookean(E, 0.0)):
        rest, g, k = law.volumetric_split(eps)
        whole = float(ufl.algorithms.expand_derivatives(law.energy(eps)))
        assert float(rest + 0.5 * k * g**2) == pytest.approx(whole, rel=1e-13), law


def test_incompressible_law_without_the_mixed_formulation_is_one_clear_error():
    law = LinearElastic(E, 0.5)
    assert math.isinf(law.kappa) and law.mu == pytest.approx(1.0)
    with pytest.raises(ValueError, match="mixed"):
        law.energy(ufl.Identity(3))
    with pytest.raises(ValueError, match=r"nu must be in \(-1, 0.5\]"):
        LinearElastic(E, 0.51)


def cylinder(material, h, *, pressure=None, inner=None, steps=1):
    """The plane-strain thick cylinder, mixed, under a pressure or an inner displacement
    (in `steps` load steps); returns the body, the residual and the last step's result."""
    body = thick_vessel("cylinder", A, B, size=h, mixed=True)
    m = body.mixed
    R = mixed.internal_work(material, m.u, m.p, m.v, m.q, body.model) * ufl.dx(
        metadata={"quadrature_degree": 4})
    bcs = list(body.supports)
    if pressure is not None:
        R = R + body.pressure * ufl.dot(body.normal, m.v) * body.ds_inner

        def load(t):
            body.pressure.value = t * pressure
    else:
        bcs.append(body.inner_motion)

        def load(t):
            body.move_inner(t * inner)
    solver = NewtonSolver(R, m.w, bcs, rtol=1e-12, atol=1e-12, force_scale=material.mu * A,
                          max_it=30)
    path = solve_incrementally(solver, load, steps, adaptive=False)
    return body, R, path.results[-1]


def pressure_deviation(h):
    """ν = 1/2, plane strain, inner pressure: u = C/r, and the mean stress is the same
    everywhere, σ_m = p a²/(b² − a²). The P1 pressure's (max, rms) relative deviation from
    it over the nodes, and u(a) against Lamé."""
    p_in = 1e-3
    body, _, result = cylinder(LinearElastic(E, 0.5), h, pressure=p_in)
    assert result.iterations == 1  # a linear problem
    exact = p_in * A * A / (B * B - A * A)
    pressure = body.mixed.pressure()
    n = pressure.function_space.dofmap.index_map.size_local
    dev = np.abs(pressure.x.array[:n] / exact - 1)
    comm = body.mesh.comm
    rms = math.sqrt(comm.allreduce(float(np.sum(dev**2)), op=MPI.SUM)
                    / comm.allreduce(n, op=MPI.SUM))
    u_exact = p_in * vessels.elastic_inner_compliance("cylinder", A, B, E, 0.5)
    return comm.allreduce(dev.max(), op=MPI.MAX), rms, body.inner_displacement() / u_exact - 1


def test_incompressible_lame_cylinder_pressure_has_no_checkerboard():
    # a checkerboard mode would not shrink with h; the nodal pressure converges to the
    # constant (measured rms 3.1e-4 → 5.3e-5 from h = 0.1 to 0.05, max 2.6e-3 → 4.1e-4)
    worst, rms, u_error = pressure_deviation(0.1)
    worst_fine, rms_fine, _ = pressure_deviation(0.05)
    assert worst < 5e-3 and worst_fine < 1e-3
    assert rms_fine < rms / 4
    assert abs(u_error) < 1e-4  # measured 1.2e-5


def test_mixed_and_displacement_formulations_agree_at_nu_0_3():
    law, p_in, h = LinearElastic(E, 0.3), 1e-3, 0.1
    body, _, _ = cylinder(law, h, pressure=p_in)
    exact = p_in * vessels.elastic_inner_compliance("cylinder", A, B, E, 0.3)
    assert body.inner_displacement() == pytest.approx(exact, rel=1e-4)
    # and the pressure field is the mean stress κ tr ε = p a²/(b² − a²) · 2(1 + ν)/3
    probe = Probes(body.mesh, [[1.5, 0.0]])
    mean = probe.continuous(body.mixed.pressure())[0][0]
    assert mean == pytest.approx(p_in * A * A / (B * B - A * A) * 2 * 1.3 / 3, rel=1e-3)


def neo_hookean_cylinder_pressure(a_deformed: float, mu: float) -> float:
    """Incompressible neo-Hookean thick cylinder (plane strain): p(a) in closed form.

    σ_θ − σ_r = μ(λ² − λ⁻²), λ = r/R, r² = R² + c: p = μ ln(λ_a/λ_b) + μc/2 (1/a² − 1/b²).
    """
    c = a_deformed**2 - A * A
    b_deformed = math.sqrt(B * B + c)
    return (mu * math.log((a_deformed / A) / (b_deformed / B))
            + 0.5 * mu * c * (1 / a_deformed**2 - 1 / b_deformed**2))


def test_incompressible_neo_hookean_cylinder_inflation_closed_form():
    law, delta, h = NeoHookean(E, 0.5), 0.5 * A, 0.1
    # one step: Newton lifts the inner motion into its first correction (moving the inner
    # nodes alone crushed the first layer: it needed steps of h/5 before)
    body, R, result = cylinder(law, h, inner=delta, steps=1)
    # the pressure on the deformed inner surface (radius A + δ), from the wall's reaction
    p_fe = body.pressure_from(R, inner_radius=A + delta)
    # measured −3.4e-6 at h = a/10
    assert p_fe == pytest.approx(neo_hookean_cylinder_pressure(A + delta, law.mu), rel=1e-4)
    # Newton's rate stays quadratic in the incompressible limit
    r = result.residual_norms
    assert result.iterations <= 6  # measured 5
    orders = [math.log(r[k + 1] / r[k]) / math.log(r[k] / r[k - 1])
              for k in (len(r) - 3, len(r) - 2)]
    assert min(orders) > 1.8, r  # measured 2.7 and 2.3


def test_j2_in_the_mixed_formulation_reaches_the_cylinder_limit_load():
    # perfect plasticity is isochoric: the mixed form must give the exact limit pressure
    # (2/√3) σ0 ln(b/a) where the displacement form on coarse P2 overestimates it
    law = J2Plasticity(210e3, 0.3, sigma0=250.0)
    a, b, h = 100.0, 200.0, 12.5
    body = thick_vessel("cylinder", a, b, size=h, mixed=True)
    m = body.mixed
    law.bind(body.mesh, 4)
    from fenics_nl.materials import kinematics

    dx = kinematics.quadrature_measure("dx", body.mesh, 4)
    R = mixed.internal_work(law, m.u, m.p, m.v, m.q, body.model) * dx
    bcs = [*body.supports, body.inner_motion]
    p_lim = vessels.limit_pressure("cylinder", a, b, 250.0)
    solver = NewtonSolver(R, m.w, bcs, rtol=1e-10, atol=1e-10, force_scale=p_lim * a)
    for delta in np.linspace(0.2, 2.0, 10):
        body.move_inner(delta)
        solver.solve()
        law.commit(m.u, body.model)
    # measured +0.0004 % at h = 12.5, where the displacement formulation is +1.4 %
    assert body.pressure_from(R) == pytest.approx(p_lim, rel=1e-3)


@pytest.mark.parametrize("nu", ["0.499", "0.5"])
def test_punch_on_an_incompressible_block_is_hertz(demo, nu):
    # the default axisymmetric punch (R = 1, δ = 0.01, h = a/40), Taylor–Hood: Hertz's force
    # within 0.5 % (measured +0.047 % at both), where P1 displacements lock (+5.3 % at 0.499)
    d = demo.punch("--mixed", "--nu", nu)
    assert d["mixed"] and d["elements"].startswith("P2-P1")
    assert abs(d["force_rel_error"]) < 5e-3


def test_mixed_punch_bad_combinations_are_one_line(demo):
    for args, words in ((["--nu", "0.5"], "--mixed"),
                        (["--mixed", "--formulation", "multiplier", "--model", "3d"],
                         "elimination")):
        proc = demo.run(["punch.py", *args], check=False)
        lines = proc.stderr.strip().splitlines()
        assert proc.returncode == 2 and len(lines) == 1 and words in lines[0], proc.stderr


@pytest.mark.parametrize("model", ["axisymmetric", "plane_strain"])
def test_mixed_punch_multipliers_equal_the_elimination(demo, model):
    # P2 multipliers on S_C with Gauss-Lobatto's nodal rule: the same discrete problem as
    # the elimination (measured: the same force to 5e-15 and 8e-15, the same nodes)
    args = ("--mixed", "--nu", "0.5", "--refine", "0", "--model", model)
    e = demo.punch(*args)
    m = demo.punch(*args, "--formulation", "multiplier")
    assert m["force"] == pytest.approx(e["force"], rel=1e-9)
    assert m["nodes_in_contact"] == e["nodes_in_contact"]


@pytest.mark.parametrize("formulation", ["elimination", "multiplier"])
@pytest.mark.mpi
def test_mixed_punch_two_ranks_give_the_serial_answer(demo, formulation):
    ranks = 2
    # the arguments of `test_mixed_punch_multipliers_equal_the_elimination`: its serial runs
    # (kept by the serial suite) are the references
    args = ("--mixed", "--nu", "0.5", "--refine", "0", "--model", "axisymmetric",
            *(("--formulation", "multiplier") if formulation == "multiplier" else ()))
    s, p = demo.punch(*args), demo.punch(*args, ranks=ranks)
    assert p["ranks"] == ranks and p["dofs"] == s["dofs"]
    assert p["force"] == pytest.approx(s["force"], rel=1e-8)
    assert p["nodes_in_contact"] == s["nodes_in_contact"]


def test_mixed_j2_punch_writes_its_stress_field(demo, tmp_path):
    # σ_eq of a J2 state is read at its quadrature points, in the mixed form too (a block of
    # 10 contact radii: what is checked is the output, not Hertz's far field)
    demo.run(["indentation.py", "--mixed", "--refine", "0", "--block", "10", "--steps", "1",
              "--loading-only", "--output", "f"])
    for name in ("displacement", "pressure", "von_mises"):
        assert (tmp_path / "f" / f"{name}.bp").is_dir()


def test_mixed_bracket_removes_most_of_the_coarse_mesh_error(demo):
    # power law at 8 kN: ε_eq reaches 14 ε0, the flow is nearly isochoric. At 14 mm P2
    # displacements give 5.338 mm, 4.8 % below the Richardson value 5.6067 mm of the README's
    # refinement; Taylor–Hood on the same mesh gives 5.582 mm (−0.4 %)
    d = demo.bracket("--mixed", "--size", "14")
    assert d["load_point_displacement"] == pytest.approx(5.6067, rel=0.01)
    held = [sum(r[i] for r in d["reactions"].values()) for i in range(3)]
    assert held[0] == pytest.approx(-d["force"], rel=1e-9)


def test_mixed_bracket_bad_combinations_are_one_line(demo):
    for args, words in ((["--mixed", "--degree", "1"], "P2"),
                        (["--mixed", "--newton", "snes", "--linear-solver", "gamg"], "SNES")):
        proc = demo.run(["bracket.py", "--size", "14", *args], check=False)
        lines = proc.stderr.strip().splitlines()
        assert proc.returncode == 2 and len(lines) == 1 and words in lines[0], proc.stderr


def minres_iterations(nu, h=0.05):
    """Krylov iterations of the block-preconditioned MINRES on the Lamé cylinder, u(a) error."""
    law, p_in = LinearElastic(E, nu), 1e-3
    body = thick_vessel("cylinder", A, B, size=h, mixed=True)
    m = body.mixed
    dx = ufl.dx(metadata={"quadrature_degree": 4})
    R = (mixed.internal_work(law, m.u, m.p, m.v, m.q, body.model) * dx
         + p_in * ufl.dot(body.normal, m.v) * body.ds_inner)
    solver = NewtonSolver(R, m.w, body.supports, linear_solver="gamg", rtol=1e-10,
                          atol=1e-10, force_scale=law.mu * A, prefix=f"minres{nu}_",
                          preconditioner=mixed.preconditioner(law, m.W, body.model, dx))
    result = solver.solve()
    exact = p_in * vessels.elastic_inner_compliance("cylinder", A, B, E, nu)
    return result.work.krylov_iterations, body.inner_displacement() / exact - 1


def test_iterative_solve_does_not_degrade_as_nu_goes_to_half():
    # diag(2μ ε:ε, mass/μ) is spectrally equivalent to the saddle point for any κ: measured
    # 98, 111, 112, 112 MINRES iterations at ν = 0.3, 0.49, 0.499, 0.5 (h = 0.05), and
    # 104 → 120 at h = 0.025
    its_03, err_03 = minres_iterations(0.3)
    its_05, err_05 = minres_iterations(0.5)
    assert its_05 < 1.3 * its_03 < 200
    assert abs(err_03) < 1e-5 and abs(err_05) < 1e-5  # measured 1.4e-6, 1.6e-6


def test_incompressible_bracket_iterative_equals_direct(demo):
    # ν = 0.5, linear: MINRES with the block preconditioner (432 iterations measured) gives
    # the direct solve's |u_load| to its tolerance
    args = ("--mixed", "--size", "14", "--material", "linear", "--nu", "0.5", "--steps", "1")
    direct = demo.bracket(*args)
    iterative = demo.bracket(*args, "--linear-solver", "gamg")
    assert iterative["krylov_iterations"] > 0
    assert iterative["load_point_displacement"] == pytest.approx(
        direct["load_point_displacement"], rel=1e-8)


INCOMPRESSIBLE_BEAM = ("--mixed", "--plane", "strain", "--nu", "0.5")


def test_incompressible_beam_follows_the_elastica(demo, on_elastica):
    # Q2-Q1 at ν = 1/2 on the default mesh: P_cr +0.23 % from Euler (+0.16 % at --refine 2:
    # the clamp's 2D effect), α 0.4° from the elastica (in 20 steps as in 40: the run the
    # two-rank test compares with). Q2 displacements at ν = 0.499 lock in bending: P_cr
    # +1.14 % (+0.33 % at --refine 2) and α 2.3° short
    on_elastica(demo.beam(*INCOMPRESSIBLE_BEAM, "--load-ratio", "1.2", "--steps", "20"))
    locked = demo.beam("--plane", "strain", "--nu", "0.499", "--load-ratio", "1.2")
    assert locked["critical_load_rel_error"] > 0.008


def test_incompressible_beam_leaves_a_higher_branch(demo, on_elastica):
    # 40 steps to 10 P_cr end, at ν = 1/2, on an equilibrium with 52° of tip rotation whose
    # negative eigenvalue (−12.9) is far from 0, while the one nearest 0 is positive: the
    # inertia of the tangent (less one negative eigenvalue per pressure unknown) tells
    d = demo.beam(*INCOMPRESSIBLE_BEAM, "--load-ratio", "10")
    assert d["branch_switched"]
    on_elastica(d)


@pytest.mark.parametrize("ranks", [2])
@pytest.mark.mpi
def test_mixed_beam_two_ranks_give_the_serial_answer(demo, ranks):
    args = (*INCOMPRESSIBLE_BEAM, "--load-ratio", "1.2", "--steps", "20")
    s, p = demo.beam(*args), demo.beam(*args, ranks=ranks)
    assert p["ranks"] == ranks and p["dofs"] == s["dofs"]
    assert p["critical_load"] == pytest.approx(s["critical_load"], rel=1e-8)
    assert p["tip_rotation_deg"] == pytest.approx(s["tip_rotation_deg"], rel=1e-6)


def test_mixed_beam_in_plane_stress_is_one_line(demo):
    proc = demo.run(["buckling_beam.py", "--mixed"], check=False)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and "--plane strain" in lines[0]
