"""The penalty die (`contact.penalty`): its gap, normal and friction, and their tangent."""

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from dolfinx.fem import petsc
from mpi4py import MPI

from fenics_nl.contact import penalty


def _assembled(form, bilinear=False):
    """A form assembled on one rank, as numpy (dense for a matrix: the mesh is tiny)."""
    if bilinear:
        A = petsc.assemble_matrix(fem.form(form))
        A.assemble()
        return A.convert("dense").getDenseArray().copy()
    b = petsc.assemble_vector(fem.form(form))
    return b.array.copy()


def test_a_flat_die_gap_is_the_height_above_the_point_and_its_normal_is_vertical():
    m = mesh.create_unit_cube(MPI.COMM_SELF, 1, 1, 1)
    x = ufl.SpatialCoordinate(m)
    g, n = penalty.die_gap(x, lambda lateral: 0 * lateral[0], 2.0)
    assert fem.assemble_scalar(fem.form(g * ufl.dx(domain=m))) == pytest.approx(1.5, rel=1e-14)
    assert fem.assemble_scalar(fem.form(ufl.dot(n, n) * ufl.dx(domain=m))) == pytest.approx(1.0)
    assert fem.assemble_scalar(fem.form(n[2] * ufl.dx(domain=m))) == pytest.approx(1.0)
    # a plane of slope 1/2 along x: the distance is the vertical gap times cos θ
    g, n = penalty.die_gap(x, lambda lateral: 0.5 * lateral[0], 2.0)
    cos = 1 / np.sqrt(1.25)
    assert fem.assemble_scalar(fem.form(g * ufl.dx(domain=m))) == pytest.approx(
        (2.0 + 0.25 - 0.5) * cos, rel=1e-14)
    assert fem.assemble_scalar(fem.form(n[0] * ufl.dx(domain=m))) == pytest.approx(-0.5 * cos)


def test_the_penalty_and_friction_tangent_is_the_residuals_derivative():
    # a box pressed into a curved die with friction (every quadrature point penetrating and
    # slipping, away from the kinks): the tangent UFL derives, non-symmetric, gives Taylor
    # remainders of slope 2; without the friction's derivative, slope 1 (the test sees it)
    m = mesh.create_box(MPI.COMM_SELF, [[0, 0, 0], [1, 1, 0.5]], [2, 2, 1])
    V = fem.functionspace(m, ("Lagrange", 2, (3,)))
    u, v, du_trial = fem.Function(V), ufl.TestFunction(V), ufl.TrialFunction(V)
    rng = np.random.default_rng(3)
    u.x.array[:] = 0.02 * rng.standard_normal(u.x.array.size)
    x = ufl.SpatialCoordinate(m) + u
    g, n = penalty.die_gap(x, lambda lat: 0.1 * ufl.sin(2 * lat[0]) * ufl.cos(lat[1]), 0.3)
    p = penalty.pressure(g, 50.0)
    slip = u - ufl.as_vector([0.01, -0.02, 0.0])  # the step's start u0 = (0.01, −0.02, 0)
    friction = penalty.friction_traction(p, n, slip, 0.3, 1e-2)
    top = mesh.locate_entities_boundary(m, 2, lambda X: np.isclose(X[2], 0.5))
    tags = mesh.meshtags(m, 2, np.sort(top), np.ones(len(top), dtype=np.int32))
    ds = ufl.Measure("ds", m, subdomain_data=tags, metadata={"quadrature_degree": 4})(1)
    work = ufl.derivative(penalty.penalty_energy(g, 50.0) * ds, u, v)
    residual = work - ufl.dot(friction, v) * ds
    # every point of the top 0.05 deep at least: no point crosses g = 0 in the test
    assert fem.assemble_scalar(fem.form(ufl.conditional(ufl.gt(g, -0.05), 1, 0) * ds)) == 0
    K = _assembled(ufl.derivative(residual, u, du_trial), bilinear=True)
    K_frictionless = _assembled(ufl.derivative(work, u, du_trial), bilinear=True)
    assert np.abs(K - K.T).max() > 1e-3 * np.abs(K).max()  # friction: not symmetric
    u0, R0 = u.x.array.copy(), _assembled(residual)
    step = 0.01 * rng.standard_normal(u0.size)

    def slopes(tangent):
        out = []
        for h in (1e-2, 5e-3, 2.5e-3):
            u.x.array[:] = u0 + h * step
            out.append(np.linalg.norm(_assembled(residual) - R0 - h * tangent @ step))
        u.x.array[:] = u0
        return np.log2(np.array(out[:-1]) / np.array(out[1:]))

    assert slopes(K) == pytest.approx(2.0, abs=0.05)
    assert slopes(K_frictionless)[-1] == pytest.approx(1.0, abs=0.1)


def test_friction_opposes_the_slip_on_the_die_and_the_dies_own_motion_is_no_slip():
    # a flat die over a unit cube's top: the body slips by s along +x (s ≫ ε), the die
    # moves down by ΔZ: the traction on the body is −f p e_x (Coulomb's, against the slip),
    # and the die's vertical motion, normal to it, adds no friction
    m = mesh.create_unit_cube(MPI.COMM_SELF, 2, 2, 2)
    top = mesh.locate_entities_boundary(m, 2, lambda X: np.isclose(X[2], 1.0))
    tags = mesh.meshtags(m, 2, np.sort(top), np.ones(len(top), dtype=np.int32))
    ds = ufl.Measure("ds", m, subdomain_data=tags)(1)
    V = fem.functionspace(m, ("Lagrange", 1, (3,)))
    u = fem.Function(V)
    u.interpolate(lambda X: np.vstack([np.full(X.shape[1], 0.1), 0 * X[0], 0 * X[0] - 0.01]))
    g, n = penalty.die_gap(ufl.SpatialCoordinate(m) + u, lambda lat: 0 * lat[0], 0.97)
    p = penalty.pressure(g, 100.0)  # 0.02 deep: p = 2
    for dZ in (0.0, -0.03):
        slip = u - ufl.as_vector([0.0, 0.0, dZ])  # from u0 = 0, the die moved by dZ
        t = penalty.friction_traction(p, n, slip, 0.3, 1e-6)
        force = [fem.assemble_scalar(fem.form(t[i] * ds)) for i in range(3)]
        assert force == pytest.approx([-0.3 * 2.0, 0.0, 0.0], abs=1e-9)
