"""Norton creep against its uniaxial closed forms (issue 57).

A cube of one hexahedron in uniaxial stress (each face x, y, z = 0 holds its normal
component, the face x = 1 pulled or held): the stress and strain are uniform, so the finite
element is exact in space and what is measured is the law and its time integration.
"""

import math

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.materials import kinematics
from fenics_nl.materials.creep import NEWTON_STEPS, NortonCreep
from fenics_nl.solvers.newton import NewtonSolver

E, NU, A = 200.0, 0.3, 1e-3


def cube(material, *, stress=None):
    """The cube, its residual's Newton solver, and a reader of the uniform σ_xx and ε_xx.

    `stress`: a traction σ on x = 1 (creep); else the face's u_x is a Dirichlet value
    (relaxation), the returned `pull` sets it.
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
        residual -= stress * v[0] * ds(1)
    solver = NewtonSolver(residual, u, bcs, rtol=1e-12, atol=1e-13, force_scale=E)
    sigma_xx = fem.form(material.stress(eps)[0, 0] * dx)
    eps_xx = fem.form(eps[0, 0] * dx)

    def read():
        return (msh.comm.allreduce(fem.assemble_scalar(sigma_xx)),
                msh.comm.allreduce(fem.assemble_scalar(eps_xx)))

    def pull(strain):
        pulled.g.x.array[:] = strain

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
