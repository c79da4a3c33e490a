import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from dolfinx.fem import petsc
from mpi4py import MPI

from fenics_nl.materials import kinematics
from fenics_nl.materials.laws import LinearElastic, NeoHookean, PowerLaw, StVenantKirchhoff

E, NU = 1000.0, 0.3


def _space(model):
    if model == "3d":
        m = mesh.create_unit_cube(MPI.COMM_SELF, 3, 3, 3)
    else:  # axisymmetric: keep r > 0 so u_r / r is finite
        m = mesh.create_rectangle(MPI.COMM_SELF, [[0.5, 0.0], [1.5, 1.0]], [4, 4])
    return fem.functionspace(m, ("Lagrange", 2, (m.geometry.dim,)))


def _vector(form):
    b = petsc.assemble_vector(fem.form(form))
    b.ghostUpdate()
    return b


def _random(V, scale, seed):
    f = fem.Function(V)
    f.x.array[:] = scale * np.random.default_rng(seed).uniform(-1, 1, f.x.array.size)
    return f


@pytest.mark.parametrize("model", ["3d", "axisymmetric"])
@pytest.mark.parametrize("material,scale", [
    (LinearElastic(E, NU), 1e-2),
    (PowerLaw(E, NU, sigma0=1.0, n=0.3), 1e-2),  # ε ~ 10 ε0: far in the non-linear range
    (PowerLaw(E, NU, sigma0=1.0, n=3.0), 1e-2),
    (StVenantKirchhoff(E, NU), 0.02),  # nodal noise 0.02 over h = 1/6: ∇u ~ 0.2, finite strain
    (NeoHookean(E, NU), 0.02),
])
def test_taylor_remainder_is_second_order(material, scale, model):
    # ‖R(u + h du) − R(u) − h K(u) du‖ = O(h²) proves K is the derivative of R.
    V = _space(model)
    u, du, v = _random(V, scale, 1), _random(V, scale, 2), ufl.TestFunction(V)
    dx = kinematics.quadrature_measure("dx", V.mesh, degree=4)
    R = material.internal_work(u, v, model) * dx
    Kdu = ufl.action(ufl.derivative(R, u), du)
    R0, K0 = _vector(R), _vector(Kdu)
    u0 = u.x.array.copy()
    hs = [1e-2, 5e-3, 2.5e-3, 1.25e-3]  # h du ≪ u: asymptotic range, far above round-off
    rem = []
    for h in hs:
        u.x.array[:] = u0 + h * du.x.array
        rem.append((_vector(R) - R0 - h * K0).norm())
    slopes = np.diff(np.log(rem)) / np.diff(np.log(hs))
    if isinstance(material, LinearElastic):
        assert max(rem) < 1e-10 * K0.norm()  # linear: the remainder is round-off
    else:
        assert min(slopes) > 1.9, (slopes, rem)


def test_linear_elastic_energy_gives_hooke_exactly():
    V = _space("3d")
    u = _random(V, 1e-2, 3)
    mat = LinearElastic(E, NU)
    eps = kinematics.small_strain(u)
    hooke = mat.lmbda * ufl.tr(eps) * ufl.Identity(3) + 2 * mat.mu * eps
    diff = mat.stress(eps) - hooke
    err = fem.assemble_scalar(fem.form(ufl.inner(diff, diff) * ufl.dx))
    ref = fem.assemble_scalar(fem.form(ufl.inner(hooke, hooke) * ufl.dx))
    assert err <= 1e-28 * ref
    # tangent A_ijkl = λ δij δkl + μ (δik δjl + δil δjk), at any strain
    i, j, k, m = ufl.indices(4)
    d = ufl.Identity(3)
    C = ufl.as_tensor(mat.lmbda * d[i, j] * d[k, m]
                      + mat.mu * (d[i, k] * d[j, m] + d[i, m] * d[j, k]), (i, j, k, m))
    # ∂²φ/∂ε∂ε treats ε as a general tensor: only its action on symmetric tensors is defined
    B = ufl.sym(ufl.as_matrix([[1.0, 2.0, -3.0], [0.5, -1.0, 4.0], [2.0, 1.0, 0.25]]))
    AB = ufl.as_tensor(mat.tangent(eps)[i, j, k, m] * B[k, m], (i, j))
    CB = ufl.as_tensor(C[i, j, k, m] * B[k, m], (i, j))
    dx = ufl.dx(domain=V.mesh)
    errA = fem.assemble_scalar(fem.form(ufl.inner(AB - CB, AB - CB) * dx))
    assert errA <= 1e-24 * fem.assemble_scalar(fem.form(ufl.inner(CB, CB) * dx))


@pytest.mark.parametrize("model", ["3d", "axisymmetric"])
def test_power_law_with_n_one_is_linear_elasticity(model):
    V = _space(model)
    u, v = _random(V, 5e-2, 4), ufl.TestFunction(V)
    lin = _vector(LinearElastic(E, NU).internal_work(u, v, model) * ufl.dx)
    pw = _vector(PowerLaw(E, NU, sigma0=7.0, n=1.0).internal_work(u, v, model) * ufl.dx)
    assert (pw - lin).norm() <= 1e-12 * lin.norm()


def test_power_law_far_field_follows_the_power_law():
    # Pure shear γ: ε_eq = γ/√3; for ε_eq ≫ ε0, σ_eq ≈ σ0 (ε_eq/ε0)^n.
    mat = PowerLaw(E, NU, sigma0=2.0, n=0.25)
    m = mesh.create_unit_cube(MPI.COMM_SELF, 1, 1, 1)
    gamma = 1e3 * mat.eps0
    eps = ufl.as_matrix([[0, gamma / 2, 0], [gamma / 2, 0, 0], [0, 0, 0]])
    s = mat.stress(eps)
    seq = fem.assemble_scalar(fem.form(ufl.sqrt(1.5 * ufl.inner(ufl.dev(s), ufl.dev(s)))
                                       * ufl.dx(domain=m)))
    x = gamma / np.sqrt(3) / mat.eps0
    assert seq == pytest.approx(mat.sigma0 * x * (1 + x * x) ** ((mat.n - 1) / 2), rel=1e-12)
    assert seq == pytest.approx(mat.sigma0 * x**mat.n, rel=1e-5)


def test_plane_stress_svk_uses_plane_stress_lame():
    m = mesh.create_unit_square(MPI.COMM_SELF, 2, 2)
    mat = StVenantKirchhoff(E, NU)
    e = ufl.as_matrix([[1e-3, 0], [0, 0]])
    s = mat.second_piola(e)
    s11 = fem.assemble_scalar(fem.form(s[0, 0] * ufl.dx(domain=m)))
    s22 = fem.assemble_scalar(fem.form(s[1, 1] * ufl.dx(domain=m)))
    assert s11 == pytest.approx(E / (1 - NU**2) * 1e-3, rel=1e-12)
    assert s22 == pytest.approx(NU * E / (1 - NU**2) * 1e-3, rel=1e-12)
    with pytest.raises(ValueError, match="plane-stress"):
        NeoHookean(E, NU).energy(e)


@pytest.mark.parametrize("kwargs,name", [
    ({"E": -1.0, "nu": 0.3}, "E"), ({"E": 1.0, "nu": 0.6}, "nu"),
    ({"E": 1.0, "nu": -1.0}, "nu"), ({"E": 1.0, "nu": 0.3, "n": 0.0}, "n"),
    ({"E": 1.0, "nu": 0.3, "sigma0": -2.0}, "sigma0"),
])
def test_bad_parameters_raise_value_error_naming_them(kwargs, name):
    with pytest.raises(ValueError, match=rf"^{name} must be in"):
        PowerLaw(**kwargs)
    if set(kwargs) == {"E", "nu"}:
        for cls in (LinearElastic, StVenantKirchhoff, NeoHookean):
            with pytest.raises(ValueError, match=rf"^{name} must be in"):
                cls(**kwargs)


def test_a_stress_kernel_is_named_after_the_law_not_after_the_labels_made_before_it():
    # the kernel cache is keyed by this name: before renumbering, a law built after other
    # `ufl.variable`s (another test, another order) was compiled again under a new name
    import ffcx.naming

    from fenics_nl.expression import renumber_labels

    V = _space("3d")
    points = fem.functionspace(V.mesh, ("DG", 0)).element.interpolation_points

    def name(expr):
        return ffcx.naming.compute_signature([(expr, points)], "")

    def stress():
        return NeoHookean(E, NU).von_mises_expression(fem.Function(V))

    first = stress()
    ufl.variable(ufl.as_ufl(1.0))  # moves the process-wide label counter
    second = stress()
    assert name(first) != name(second)  # what FFCx would see without renumbering
    assert name(renumber_labels(first)) == name(renumber_labels(second))
