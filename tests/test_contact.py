import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.contact.active_set import ActiveSetContact
from fenics_nl.domain import boundary
from fenics_nl.domain.meshes import graded_block
from fenics_nl.materials import kinematics
from fenics_nl.materials.laws import LinearElastic, PowerLaw
from fenics_nl.theory import hertz


def spring_over_support(m, k=100.0, g=9.81, gap=0.05, formulation="elimination"):
    """The course's 1-DOF example: a mass m on a spring k, the support γ below it.

    A one-element bar of stiffness k (EA/L = k) fixed at x = 0; the weight mg pulls the free
    end x = 1 towards the support, which stands at distance γ along +x.
    """
    bar = mesh.create_unit_interval(MPI.COMM_SELF, 1)
    V = fem.functionspace(bar, ("Lagrange", 1, (1,)))
    u, v = fem.Function(V), ufl.TestFunction(V)
    fdim = 0
    top = mesh.locate_entities_boundary(bar, fdim, lambda x: np.isclose(x[0], 0))
    end = mesh.locate_entities_boundary(bar, fdim, lambda x: np.isclose(x[0], 1))
    tags = mesh.meshtags(bar, fdim, end, np.ones(len(end), dtype=np.int32))
    ds = ufl.Measure("ds", domain=bar, subdomain_data=tags)
    R = k * ufl.inner(ufl.grad(u), ufl.grad(v)) * ufl.dx - m * g * v[0] * ds(1)
    c = ActiveSetContact(R, u, [boundary.fixed(V, top)], end, lambda x: np.full(x.shape[1], gap),
                         normal_axis=0, normal_sign=1, formulation=formulation)
    res = c.solve()
    return res, c, float(u.x.array[-1] if np.isclose(V.tabulate_dof_coordinates()[-1, 0], 1)
                         else u.x.array[0])


@pytest.mark.parametrize("m", [0.2, 0.5, 0.5097, 0.6, 2.0])  # kγ/g = 0.50968...
def test_course_mass_spring_example(m):
    k, g, gap = 100.0, 9.81, 0.05
    _, c, u_end = spring_over_support(m, k, g, gap)
    if m >= k * gap / g:  # contact, reaction R = mg − kγ
        assert c.force == pytest.approx(m * g - k * gap, rel=1e-10, abs=1e-12)
        assert u_end == pytest.approx(gap, rel=1e-12)
        assert c.active.all()
    else:  # hangs free at mg/k above the support
        assert c.force == pytest.approx(0.0, abs=1e-12)
        assert u_end == pytest.approx(m * g / k, rel=1e-12)
        assert not c.active.any()


def axisymmetric_punch(formulation, comm=MPI.COMM_WORLD, E=1.0, nu=0.3, R=1.0, delta=0.01,
                       material=None, h_over_a=0.05, block=300.0, degree=1):
    a = np.sqrt(R * delta)
    data = graded_block(comm, 2, block * a, block * a, h_over_a * a, 1.5 * a, 0.05)
    V = fem.functionspace(data.mesh, ("Lagrange", degree, (2,)))
    u, v = fem.Function(V), ufl.TestFunction(V)
    material = material or LinearElastic(E, nu)
    dx = kinematics.quadrature_measure("dx", data.mesh, 2 * degree)
    res_form = material.internal_work(u, v, "axisymmetric") * dx
    tag = lambda name: data.facet_tags.find(data.physical_groups[name].tag)  # noqa: E731
    bcs = [boundary.component(V, 0, tag("symmetry_x")), boundary.component(V, 1, tag("bottom"))]
    c = ActiveSetContact(res_form, u, bcs, tag("contact"), lambda x: x[0] ** 2 / (2 * R) - delta,
                         normal_axis=1, normal_sign=1, formulation=formulation,
                         initial="penetrating", prefix=f"ax{formulation}{id(u)}_",
                         newton_options={"line_search": True})
    return c, c.solve()


def test_formulations_agree_to_solver_precision():
    ce, re = axisymmetric_punch("elimination")
    cm, rm = axisymmetric_punch("multiplier")
    # the elimination's later sets are solved on its first factorization (row_update)
    assert re.work.factorizations == 1 and re.work.update_columns > 0
    # one assembly of R(u) per iterate: the contact forces and the next set's first residual
    # are the last solve's (Te below is a new assembly, after the loop)
    assert re.work.residual_assemblies == re.iterations + 1
    assert re.active_sizes == rm.active_sizes
    assert np.array_equal(ce.active, cm.active)
    Te, Tm = ce.normal_forces(), cm.normal_forces()
    assert np.max(np.abs(Te - Tm)) < 1e-9 * np.max(np.abs(Te))
    assert abs(ce.force - cm.force) < 1e-9 * ce.force


def test_axisymmetric_punch_matches_hertz_coarse():
    # A quick version of the demo's check (the demo runs the finer default mesh):
    # h = a/20 and a 300a block: force within 1 % (+0.45 % block-size error measured).
    c, _ = axisymmetric_punch("elimination")
    ref = hertz.sphere_from_indentation(1.0, 0.3, 1.0, 0.01)
    assert c.force == pytest.approx(ref["force"], rel=1e-2)
    a_h = c.comm.allreduce(float(np.max(c.x[c.active, 0], initial=0.0)), op=MPI.MAX)
    assert abs(a_h - ref["contact_radius"]) <= 0.05 * ref["contact_radius"]  # one element


def test_quadratic_elements_use_every_surface_node():
    # P2: the set is decided on vertex and edge-midpoint nodes by the same rules; the
    # solution must still be Hertz's (same 1 % as P1) and satisfy the contact conditions.
    c, _ = axisymmetric_punch("elimination", degree=2)
    ref = hertz.sphere_from_indentation(1.0, 0.3, 1.0, 0.01)
    assert c.force == pytest.approx(ref["force"], rel=1e-2)
    assert len(c.surface.dofs_n) > 1.9 * axisymmetric_punch("elimination")[0].surface.dofs_n.size
    T_n, gap = c.normal_forces(), c.normal_gap()
    assert np.all(T_n[c.active] <= 1e-10 * np.abs(T_n).max())
    assert np.all(gap[~c.active] <= 1e-12)
    # P2 multipliers with Gauss-Lobatto's nodal rule: the elimination's discrete problem
    cm, _ = axisymmetric_punch("multiplier", degree=2)
    assert np.array_equal(c.active, cm.active)
    Te, Tm = c.normal_forces(), cm.normal_forces()
    assert np.max(np.abs(Te - Tm)) < 1e-9 * np.max(np.abs(Te))


def test_multipliers_on_p2_triangles_are_refused():
    # a P2 triangle has no nodal quadrature with positive weights: the constraint could not
    # stay nodal, so 3D P2 takes the elimination
    msh = mesh.create_unit_cube(MPI.COMM_WORLD, 2, 2, 2)
    V = fem.functionspace(msh, ("Lagrange", 2, (3,)))
    u, v = fem.Function(V), ufl.TestFunction(V)
    top = mesh.locate_entities_boundary(msh, 2, lambda x: np.isclose(x[2], 1.0))
    with pytest.raises(ValueError, match="use the elimination"):
        ActiveSetContact(ufl.inner(ufl.grad(u), ufl.grad(v)) * ufl.dx, u, [], top,
                         lambda x: 0 * x[0], normal_axis=2, formulation="multiplier")


def test_nonlinear_material_runs_newton_inside_each_iteration():
    # Power law softer than Hooke beyond ε0: the same indentation needs less force.
    c_lin, _ = axisymmetric_punch("elimination")
    c_pl, r_pl = axisymmetric_punch("elimination", material=PowerLaw(1.0, 0.3, 2e-3, 0.3))
    assert r_pl.iterations > 2 * r_pl.active_set_iterations  # real Newton solves inside
    assert 0.2 * c_lin.force < c_pl.force < 0.95 * c_lin.force


def test_missing_surface_is_a_clear_error():
    with pytest.raises(ValueError, match="2D or 3D"):
        spring_over_support(1.0, formulation="multiplier")
    bar = mesh.create_unit_interval(MPI.COMM_SELF, 1)
    V = fem.functionspace(bar, ("Lagrange", 1, (1,)))
    u = fem.Function(V)
    R = ufl.inner(ufl.grad(u), ufl.grad(ufl.TestFunction(V))) * ufl.dx
    with pytest.raises(ValueError, match="no facets"):
        ActiveSetContact(R, u, [], np.array([], dtype=np.int32), lambda x: 0 * x[0],
                         normal_axis=0)


@pytest.mark.mpi
@pytest.mark.parametrize("formulation", ["elimination", "multiplier"])
def test_parallel_contact_matches_serial(formulation):
    assert MPI.COMM_WORLD.size > 1
    cp, rp = axisymmetric_punch(formulation, comm=MPI.COMM_WORLD)
    cs, rs = axisymmetric_punch(formulation, comm=MPI.COMM_SELF)
    assert rp.active_sizes == rs.active_sizes
    assert abs(cp.force - cs.force) < 1e-9 * cs.force


@pytest.mark.stress
@pytest.mark.parametrize("nu", [0.45, 0.49, 0.499])
def test_near_incompressibility_p2_keeps_hertz_p1_locks(nu):
    # measured force errors against Hertz (axisymmetric, h = a/20): P1 +0.50 %, +1.37 %,
    # +8.7 % for ν = 0.45, 0.49, 0.499 (volumetric locking); P2 +0.18 % throughout
    ref = hertz.sphere_from_indentation(1.0, nu, 1.0, 0.01)["force"]
    p2, _ = axisymmetric_punch("elimination", nu=nu, degree=2)
    p1, _ = axisymmetric_punch("elimination", nu=nu, degree=1)
    assert abs(p2.force / ref - 1) < 5e-3
    assert abs(p2.force / ref - 1) < abs(p1.force / ref - 1)


def test_a_cone_matches_sneddon():
    # the Berkovich-equivalent cone (70.3°) on the elastic axisymmetric block (h = a/20,
    # 300a): Sneddon's P = 2 E* δ² tan α / π and a = 2 δ tan α / π; the tip's pressure is
    # singular (logarithmically), the force is not: measured +0.34 % (the block's finite
    # size and mesh, as for the sphere), radius −0.3 %
    from punch_problem import BERKOVICH, build_punch

    from fenics_nl.materials.laws import LinearElastic

    delta = 0.01
    ref = hertz.cone_from_indentation(1.0, 0.3, 1 / np.tan(np.radians(BERKOVICH)), delta)
    punch = build_punch("axisymmetric", LinearElastic(1.0, 0.3), 1.0, ref["contact_radius"],
                        refine=0, block=300.0, gap="cone")
    state = punch.indent(delta)
    assert state.force == pytest.approx(ref["force"], rel=1e-2)
    assert abs(state.contact_radius - ref["contact_radius"]) <= punch.block.h


def test_a_kept_residual_is_the_assembly_at_the_same_u_and_only_there():
    # the active-set loop's forces come from Newton's last assembly of R(u): the same vector
    # as a new assembly while u stays; none once u moved, or outside the block
    from dolfinx.fem import petsc
    from petsc4py import PETSc

    c, _ = axisymmetric_punch("elimination")
    newton = c.newton
    kept, fresh = newton.b.duplicate(), newton.b.duplicate()
    with newton.reuse_residual_at_same_u():
        assert not newton.copy_kept_residual(kept)  # nothing assembled in the block yet
        newton.solve()
        with newton.reuse_residual_at_same_u():  # nested: the outer block's kept R stays
            pass
        assert newton.copy_kept_residual(kept)
        fresh.set(0.0)
        petsc.assemble_vector(fresh, newton._R)  # (the form the solver assembles)
        fresh.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
        assert np.array_equal(kept.array_r, fresh.array_r)
        newton.u.x.array[0] += 1e-6
        assert not newton.copy_kept_residual(kept)
    assert not newton.copy_kept_residual(kept)
