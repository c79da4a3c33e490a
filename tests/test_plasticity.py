"""J2 plasticity: parameters, a homogeneous uniaxial path against the closed form, the
consistent tangent's Taylor test in the plastic regime."""

import math

import numpy as np
import pytest
import ufl
from conftest import taylor_remainders
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.materials import kinematics
from fenics_nl.materials.plasticity import J2Plasticity
from fenics_nl.solvers.loading import solve_incrementally
from fenics_nl.solvers.newton import NewtonSolver

E, NU, S0 = 1000.0, 0.3, 1.0
EPS_Y = S0 / E


@pytest.mark.parametrize("kwargs,message", [
    ({"sigma0": 0.0}, "sigma0 must be in"), ({"sigma0": -1.0}, "sigma0 must be in"),
    ({"H": -1.0}, "H must be >= 0"), ({"C": -0.5}, "C must be >= 0"),
    ({"H": math.nan}, "H must be >= 0"), ({"sigma0": math.nan}, "sigma0 must be in"),
])
def test_bad_parameters_name_themselves(kwargs, message):
    with pytest.raises(ValueError, match=message):
        J2Plasticity(E, NU, **{"sigma0": S0, **kwargs})


def test_plane_stress_is_refused():
    m = mesh.create_unit_square(MPI.COMM_WORLD, 1, 1)
    law = J2Plasticity(E, NU, sigma0=S0)
    law.bind(m, 2)
    u = fem.Function(fem.functionspace(m, ("Lagrange", 1, (2,))))
    with pytest.raises(ValueError, match="plane-stress"):
        law.stress(kinematics.small_strain(u, "plane_stress"))


class Bar:
    """A unit cube in uniaxial stress: u_i = 0 on the planes x_i = 0, u_x = e on x = 1."""

    def __init__(self, law, n=1):
        self.mesh = m = mesh.create_unit_cube(MPI.COMM_WORLD, n, n, n)
        V = fem.functionspace(m, ("Lagrange", 1, (3,)))
        self.u = fem.Function(V)
        law.bind(m, 2)
        self.law = law
        dx = kinematics.quadrature_measure("dx", m, 2)
        v = ufl.TestFunction(V)
        self.residual = law.internal_work(self.u, v) * dx
        facets = [mesh.locate_entities_boundary(m, 2, lambda x, i=i: np.isclose(x[i], 0))
                  for i in range(3)]
        end = mesh.locate_entities_boundary(m, 2, lambda x: np.isclose(x[0], 1))
        self.pull = boundary.component(V, 0, end, 0.0)
        bcs = [boundary.component(V, i, f) for i, f in enumerate(facets)] + [self.pull]
        self.solver = NewtonSolver(self.residual, self.u, bcs, rtol=1e-13, atol=1e-13,
                                   force_scale=S0, max_it=20, prefix=f"bar{id(self)}_")
        self.stress = fem.form(law.stress(kinematics.small_strain(self.u))[0, 0] * dx)

    def go(self, strains):
        """σ_xx after each of the prescribed end strains (one load step each)."""
        out, previous = [], 0.0
        for e in strains:
            def load(t, a=previous, b=e):
                self.pull.g.x.array[:] = a + t * (b - a)

            solve_incrementally(self.solver, load, 1, adaptive=False, predictor=False,
                                commit=lambda: self.law.commit(self.u))
            out.append(self.mesh.comm.allreduce(fem.assemble_scalar(self.stress)))
            previous = e
        return np.array(out)


def uniaxial(strains, H, C):
    """The 1D closed form: backward-Euler radial return, exact for linear hardening."""
    eps_p = p = 0.0
    out = []
    for e in strains:
        trial = E * (e - eps_p)
        xi = trial - C * eps_p
        f = abs(xi) - (S0 + H * p)
        if f > 0:
            dp = f / (E + H + C)
            eps_p += dp * math.copysign(1.0, xi)
            p += dp
        out.append(E * (e - eps_p))
    return np.array(out)


@pytest.mark.parametrize("H,C", [(100.0, 0.0), (0.0, 100.0), (50.0, 50.0), (0.0, 0.0)])
def test_uniaxial_load_unload_reverse_is_the_closed_form(H, C):
    # up to 3 ε_y, back to 0, on to −3 ε_y: yield, elastic unloading, reverse yield
    strains = EPS_Y * np.array([0.5, 1.5, 2.0, 3.0, 2.0, 1.0, 0.0, -1.0, -2.0, -3.0])
    bar = Bar(J2Plasticity(E, NU, sigma0=S0, H=H, C=C))
    sigma = bar.go(strains)
    assert sigma == pytest.approx(uniaxial(strains, H, C), rel=1e-10, abs=1e-10 * S0)
    # the peak against the continuous closed form σ0 + E_t (ε − ε_y)
    E_t = E * (H + C) / (E + H + C)
    assert sigma[3] == pytest.approx(S0 + E_t * (3 * EPS_Y - EPS_Y), rel=1e-10)
    if H == 0 and C > 0:  # Bauschinger: reverse yield 2σ0 below the peak
        assert sigma[4] - sigma[3] == pytest.approx(-E * EPS_Y, rel=1e-10)  # elastic
        reverse = sigma[3] - 2 * S0
        assert sigma[6] == pytest.approx(reverse + E_t * (0.0 - (3 * EPS_Y - 2 * EPS_Y)),
                                         rel=1e-9)


def test_hookes_tangent_is_factorized_once_and_kept():
    # full Newton assembles the tangent at every iteration; below yield it is Hooke's each
    # time, the same matrix to the bit: factorized once
    bar = Bar(J2Plasticity(E, NU, sigma0=S0, H=100.0))
    elastic = EPS_Y * np.array([0.2, 0.4, 0.6, 0.8])
    assert bar.go(elastic) == pytest.approx(E * elastic, rel=1e-12)
    work = bar.solver.total
    assert work.tangent_assemblies >= 4 and work.factorizations == 1
    # a plastic step starts from the committed state, on the yield surface: its first
    # tangent is Hooke's again. The first plastic step still has it; the second, after
    # plastic tangents replaced it, factorizes it aside; the third and fourth solve with it
    assembled, factorized = work.tangent_assemblies, work.factorizations
    plastic = EPS_Y * np.array([1.5, 2.0, 2.5, 3.0])
    sigma = bar.go(plastic)
    assert sigma == pytest.approx(uniaxial(np.r_[elastic, plastic], 100.0, 0.0)[4:], rel=1e-10)
    assert work.factorizations - factorized == work.tangent_assemblies - assembled - 3


@pytest.mark.mpi
def test_uniaxial_closed_form_on_two_ranks():
    # the state lives at each rank's quadrature points; commit and assembly are collective
    assert MPI.COMM_WORLD.size > 1, "run under mpiexec -n 2"
    strains = EPS_Y * np.array([1.5, 3.0, 1.0, -2.0])
    sigma = Bar(J2Plasticity(E, NU, sigma0=S0, H=50.0, C=50.0), n=2).go(strains)
    assert sigma == pytest.approx(uniaxial(strains, 50.0, 50.0), rel=1e-10, abs=1e-10 * S0)


def test_consistent_tangent_taylor_slope_two_in_the_plastic_regime():
    law = J2Plasticity(E, NU, sigma0=S0, H=30.0, C=20.0)
    bar = Bar(law, n=2)
    bar.go([1.5 * EPS_Y, 3.0 * EPS_Y])  # committed plastic state
    bar.pull.g.x.array[:] = 4.0 * EPS_Y  # and a plastic step from it
    bar.solver.solve()
    errs, slopes = taylor_remainders(bar.residual, bar.u, EPS_Y * 0.05, seed=1)
    assert np.all(slopes > 1.9), (errs, slopes)


def test_two_groups_of_j2_keep_each_its_own_plastic_strain():
    # a unit square in shear, u = (γ y, 0), the left half σ0 = 1, the right σ0 = 2 (ByGroup
    # of two J2 laws): each law's state is committed on its own cells only, and there it is
    # the closed form of perfect plasticity in one step, p = (√3 μ γ − σ0) / (3μ); the other
    # half of each law's state stays 0, and the material's p per cell is its own law's
    from fenics_nl.materials.piecewise import ByGroup

    m = mesh.create_unit_square(MPI.COMM_WORLD, 4, 4)
    tdim = m.topology.dim
    n = m.topology.index_map(tdim).size_local + m.topology.index_map(tdim).num_ghosts
    left = mesh.compute_midpoints(m, tdim, np.arange(n, dtype=np.int32))[:, 0] < 0.5
    tags = mesh.meshtags(m, tdim, np.arange(n, dtype=np.int32), np.where(left, 1, 2))
    laws = {1: J2Plasticity(E, NU, sigma0=1.0), 2: J2Plasticity(E, NU, sigma0=2.0)}
    material = ByGroup(laws, tags)
    material.bind(m, 2)
    u = fem.Function(fem.functionspace(m, ("Lagrange", 1, (2,))))
    gamma = 6.0 / E  # σ_eq = √3 μ γ ≈ 4: both halves yield
    u.interpolate(lambda x: np.vstack([gamma * x[1], 0.0 * x[0]]))
    material.commit(u, "plane_strain")
    mu = E / (2 * (1 + NU))
    expected = {t: (math.sqrt(3) * mu * gamma - law.sigma0) / (3 * mu) for t, law in laws.items()}
    for tag, law in laws.items():
        p = law.cumulated_plastic_strain
        mine = np.isin(np.arange(n), tags.find(tag))
        at = p.x.array[p.function_space.dofmap.list]  # (cells, points)
        assert at[mine] == pytest.approx(expected[tag], rel=1e-12)
        assert np.all(at[~mine] == 0.0)
    per_cell = material.cumulated_plastic_strain_per_cell()
    values = per_cell.x.array[per_cell.function_space.dofmap.list[:, 0]]
    assert values[left] == pytest.approx(expected[1], rel=1e-12)
    assert values[~left] == pytest.approx(expected[2], rel=1e-12)
