"""J2 in plane stress (ε_zz an unknown at the quadrature points) against its closed forms.

A unit square, P1, loaded by tractions on x = 1 (and y = 1), held by its symmetry supports
u_x = 0 on x = 0 and u_y = 0 on y = 0: the field is homogeneous, so the discrete answer is
the material point's, and the closed forms of uniaxial and equibiaxial stress hold to
round-off along a proportional path (load, unload, reverse). Linear isotropic hardening H:
the von Mises stress of the path's peak is σ0 + H p.
"""

import math

import numpy as np
import pytest
import ufl
from conftest import taylor_remainders
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.expression import Expression
from fenics_nl.materials import kinematics, plane_stress
from fenics_nl.materials.plasticity import J2Plasticity
from fenics_nl.solvers.loading import solve_incrementally
from fenics_nl.solvers.newton import NewtonSolver

E, NU, S0, H = 1000.0, 0.3, 1.0, 100.0
Q = 2  # quadrature degree


class Sheet:
    """The square in plane stress, loaded by σ_xx = t s_x and σ_yy = t s_y (dead tractions)."""

    def __init__(self, law, sx, sy, n=2, method="full", graded=False, tol=1e-13, degree=1,
                 comm=MPI.COMM_WORLD):
        m = mesh.create_unit_square(comm, n, n)
        self.law, self.mesh = law, m
        self.q = q = 2 * degree  # the rule of the residual, of the state and of ε_zz's space
        law.bind(m, q)
        self.w = plane_stress.PlaneStressUnknown(m, degree, q)
        w = self.w
        facets = {k: mesh.locate_entities_boundary(m, 1, f) for k, f in {
            "x0": lambda x: np.isclose(x[0], 0), "y0": lambda x: np.isclose(x[1], 0),
            "x1": lambda x: np.isclose(x[0], 1), "y1": lambda x: np.isclose(x[1], 1)}.items()}
        order = np.concatenate([facets["x1"], facets["y1"]])
        values = np.concatenate([np.full(len(facets["x1"]), 1, np.int32),
                                 np.full(len(facets["y1"]), 2, np.int32)])
        keep = np.argsort(order)
        tags = mesh.meshtags(m, 1, order[keep], values[keep])
        ds = ufl.Measure("ds", m, subdomain_data=tags)
        self.dx = kinematics.quadrature_measure("dx", m, q)
        self.t = fem.Constant(m, 0.0)
        if graded:  # σ_xx growing along y on x = 1: no longer homogeneous
            sx = sx * (0.5 + ufl.SpatialCoordinate(m)[1])
        self.residual = (plane_stress.internal_work(law, w) * self.dx
                         - self.t * sx * w.v[0] * ds(1) - self.t * sy * w.v[1] * ds(2))
        bcs = [boundary.component(w.V, 0, facets["x0"]), boundary.component(w.V, 1, facets["y0"])]
        self.solver = NewtonSolver(self.residual, w.w, bcs, method=method, rtol=tol,
                                   atol=tol, force_scale=S0, max_it=30 if method == "full"
                                   else 300, prefix=f"sheet{id(self)}_",
                                   constant_tangent=plane_stress.elastic_tangent(law, w, self.dx))
        sigma = plane_stress.stress(law, w)
        eps = w.strain()
        self._means = {k: fem.form(f * self.dx) for k, f in {
            "sxx": sigma[0, 0], "syy": sigma[1, 1], "szz": sigma[2, 2], "exx": eps[0, 0],
            "eyy": eps[1, 1], "ezz": eps[2, 2], "|szz|": abs(sigma[2, 2])}.items()}

    def largest_szz(self):
        """max |σ_zz| over every quadrature point of the rule (every rank's cells)."""
        import basix

        points, _ = basix.make_quadrature(self.mesh.basix_cell(), self.q)
        expr = Expression(plane_stress.stress(self.law, self.w)[2, 2], points)
        cells = np.arange(self.mesh.topology.index_map(2).size_local, dtype=np.int32)
        values = expr.eval(self.mesh, cells)
        return self.mesh.comm.allreduce(float(np.abs(values).max(initial=0.0)), op=MPI.MAX)

    def mean(self, key):
        return self.mesh.comm.allreduce(fem.assemble_scalar(self._means[key]))

    def go(self, factors):
        """Each load factor in one step (committed); the mean fields after each."""
        out, previous = [], 0.0
        for f in factors:
            def load(s, a=previous, b=f):
                self.t.value = a + s * (b - a)

            solve_incrementally(self.solver, load, 1, adaptive=False, predictor=False,
                                commit=lambda: self.law.commit_strain(self.w.strain()))
            out.append({k: self.mean(k) for k in self._means})
            previous = f
        return out


def closed_form(stresses, direction):
    """ε_xx, ε_yy, ε_zz along a proportional path σ = s (dx, dy, 0), isotropic hardening.

    The radial return at a material point: σ_eq = |s| q(dx, dy), p grows while σ_eq exceeds
    σ0 + H p, along the flow n = (3/2) dev σ / σ_eq (fixed: the path is proportional).
    """
    dx, dy = direction
    sig = np.diag([dx, dy, 0.0])
    dev = sig - np.trace(sig) / 3 * np.eye(3)
    q = math.sqrt(1.5 * np.sum(dev * dev))
    n = 1.5 * dev / q
    p, eps_p, out = 0.0, np.zeros((3, 3)), []
    for s in stresses:
        f = abs(s) * q - (S0 + H * p)
        if f > 0:
            dp = f / H  # the stress is given: σ_eq = σ0 + H (p + dp)
            eps_p = eps_p + dp * math.copysign(1.0, s) * n
            p += dp
        elastic = ((1 + NU) * s * sig - NU * s * np.trace(sig) * np.eye(3)) / E
        total = elastic + eps_p
        out.append((total[0, 0], total[1, 1], total[2, 2]))
    return np.array(out)


PATH = np.array([0.5, 1.5, 2.0, 0.5, 0.0, -1.0, -2.5])  # × σ0: load, unload, reverse


@pytest.mark.parametrize("direction", [(1.0, 0.0), (1.0, 1.0), (1.0, -0.5)],
                         ids=["uniaxial", "equibiaxial", "shear-like"])
def test_proportional_paths_are_the_closed_form(direction):
    law = J2Plasticity(E, NU, sigma0=S0, H=H)
    sheet = Sheet(law, *direction)
    states = sheet.go(PATH * S0)
    exact = closed_form(PATH * S0, direction)
    for state, (exx, eyy, ezz), s in zip(states, exact, PATH * S0, strict=True):
        scale = abs(exact).max()
        assert [state["exx"], state["eyy"], state["ezz"]] == pytest.approx(
            [exx, eyy, ezz], abs=1e-10 * scale)
        assert state["sxx"] == pytest.approx(s * direction[0], abs=1e-10 * S0)
        assert state["syy"] == pytest.approx(s * direction[1], abs=1e-10 * S0)
        assert state["|szz|"] < 1e-10 * S0  # plane stress at every quadrature point
    assert law.cumulated_plastic_strain.x.array.max() > 0


def test_full_newton_converges_quadratically_and_modified_newton_agrees():
    # a graded traction: the plastic zone spreads across the sheet as the load grows
    law = J2Plasticity(E, NU, sigma0=S0, H=H)
    sheet = Sheet(law, 1.0, 0.3, n=6, graded=True)
    sheet.go([1.0 * S0])
    sheet.t.value = 1.4 * S0
    result = sheet.solver.solve()
    assert result.converged and result.iterations <= 8, result.residual_norms
    assert result.orders[-1] > 1.8, result.residual_norms  # the last iterations: quadratic
    # (modified Newton's residual stalls at ~1e-12, its round-off: a looser tolerance)
    other = Sheet(J2Plasticity(E, NU, sigma0=S0, H=H), 1.0, 0.3, n=6, graded=True,
                  method="modified", tol=1e-11)
    other.go([1.0 * S0, 1.4 * S0])
    for k in ("exx", "eyy", "ezz"):
        assert other.mean(k) == pytest.approx(sheet.mean(k), rel=1e-8)


@pytest.mark.parametrize("degree", [1, 2])
def test_sigma_zz_vanishes_at_every_quadrature_point_of_an_inhomogeneous_field(degree):
    # the graded load: strains vary inside the cells (P2) and from cell to cell; after a
    # plastic step, σ_zz at the rule's points is round-off (DG1 with 3 points, DG2 with 6)
    law = J2Plasticity(E, NU, sigma0=S0, H=H)
    sheet = Sheet(law, 1.0, 0.3, n=4, graded=True, degree=degree)
    sheet.go([1.0 * S0, 1.4 * S0])
    assert law.cumulated_plastic_strain.x.array.max() > 0
    assert sheet.largest_szz() < 1e-10 * S0


def test_consistent_tangent_taylor_slope_two_in_the_plastic_regime():
    law = J2Plasticity(E, NU, sigma0=S0, H=30.0, C=20.0)
    sheet = Sheet(law, 1.0, 0.4, n=3, graded=True)
    sheet.go([1.2 * S0])  # committed plastic state
    sheet.t.value = 1.6 * S0  # and a plastic step from it (inside the plastic zone: f > 0)
    sheet.solver.solve()
    errs, slopes = taylor_remainders(sheet.residual, sheet.w.w, 1e-3, seed=3)
    assert np.all(slopes > 1.9), (errs, slopes)


@pytest.mark.mpi
def test_the_uniaxial_path_on_two_ranks():
    states = Sheet(J2Plasticity(E, NU, sigma0=S0, H=H), 1.0, 0.0, n=4).go(PATH * S0)
    exact = closed_form(PATH * S0, (1.0, 0.0))
    got = np.array([[s["exx"], s["eyy"], s["ezz"]] for s in states])
    assert np.abs(got - exact).max() < 1e-10 * np.abs(exact).max()
