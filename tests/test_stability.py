"""The stability test of an equilibrium: the tangent's inertia, then its lowest mode."""

import math

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.solvers.buckling import lowest_tangent_mode


def string_on_a_foundation(c):
    """∫ u'v' − c u v on (0, π), u = 0 at both ends, and the mass ∫ u v: the pencil's
    eigenvalues are n² − c, n = 1, 2, ... (P2, 40 cells: to ~1e-6)."""
    msh = mesh.create_interval(MPI.COMM_WORLD, 40, [0.0, math.pi])
    V = fem.functionspace(msh, ("Lagrange", 2))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    ends = mesh.locate_entities_boundary(msh, 0, lambda x: np.full(x.shape[1], True))
    bc = fem.dirichletbc(0.0, fem.locate_dofs_topological(V, 0, ends), V)
    a = (u.dx(0) * v.dx(0) - c * u * v) * ufl.dx
    return a, u * v * ufl.dx, [bc], V


@pytest.mark.parametrize("c,expected", [(3.0, -2.0), (0.5, 0.5), (1.2, -0.2)])
def test_the_lowest_eigenvalue_is_found_even_far_from_zero(c, expected):
    # c = 3: eigenvalues −2, 1, 6: the one nearest 0 is +1, a stable-looking answer; the
    # inertia counts one negative eigenvalue and the shifted search finds −2
    a, m, bcs, V = string_on_a_foundation(c)
    lam, mode = lowest_tangent_mode(a, bcs, V, "test_stability_", mass=m)
    assert lam == pytest.approx(expected, abs=1e-5)
    # the mode is sin x: one sign inside the interval
    inside = mode.x.array[np.abs(mode.x.array) > 1e-8]
    assert np.all(inside > 0) or np.all(inside < 0)


def test_multipliers_discount_their_negative_eigenvalues():
    # a saddle point's m constraints bring m negative eigenvalues that say nothing of
    # stability; declaring the c = 3 string's one negative eigenvalue a multiplier's makes
    # it count as stable: the eigenvalue nearest 0, +1, is returned
    a, m, bcs, V = string_on_a_foundation(3.0)
    lam, _ = lowest_tangent_mode(a, bcs, V, "test_stability_", mass=m, multipliers=1)
    assert lam == pytest.approx(1.0, abs=1e-5)
