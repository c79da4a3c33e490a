"""New Dirichlet rows solved on an old factorization (`solvers.row_update`)."""

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from dolfinx.fem import petsc
from mpi4py import MPI
from petsc4py import PETSc

from fenics_nl.solvers.result import WorkCounts
from fenics_nl.solvers.row_update import RowUpdate


def elastic_square(comm, n=12, modulus=1.0):
    """K of a plane elastic square; its bottom's rows, and its top's vertical rows by x."""
    domain = mesh.create_unit_square(comm, n, n)
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    eps = lambda w: ufl.sym(ufl.grad(w))  # noqa: E731
    a = fem.form(modulus * (2 * ufl.inner(eps(u), eps(v)) + ufl.div(u) * ufl.div(v)) * ufl.dx)
    fdim = domain.topology.dim - 1
    bottom = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[1], 0))
    top = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[1], 1))
    bottom_dofs = fem.locate_dofs_topological(V, fdim, bottom)
    top_dofs = fem.locate_dofs_topological(V.sub(1), fdim, top)
    x_top = V.tabulate_dof_coordinates()[top_dofs // 2, 0]
    zero = np.zeros(2, dtype=PETSc.ScalarType)
    supports = fem.dirichletbc(zero, bottom_dofs, V)

    def rows(where):
        """Dirichlet conditions: the bottom, and the top's vertical rows where x is in it."""
        top_bc = fem.dirichletbc(PETSc.ScalarType(0), top_dofs[where(x_top)], V.sub(1))
        bcs = [supports, top_bc]
        owned = [bc.dof_indices()[0][: bc.dof_indices()[1]] for bc in bcs]
        return bcs, np.unique(np.concatenate(owned))

    K = petsc.assemble_matrix(a)
    K.assemble()
    return a, K, rows


def factorized(a, bcs):
    M = petsc.assemble_matrix(a, bcs=bcs)
    M.assemble()
    ksp = PETSc.KSP().create(M.comm)
    ksp.setOperators(M)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    ksp.setUp()
    return M, ksp


def check_rows_added_and_released(comm, modulus=1.0):
    a, K, rows = elastic_square(comm, modulus=modulus)
    base_bcs, base_rows = rows(lambda x: x < 0.55)
    new_bcs, new_rows = rows(lambda x: x > 0.3)  # adds x > 0.55, releases x < 0.3
    _, base = factorized(a, base_bcs)
    update = RowUpdate(K)
    update.rebase(base.getPC().getFactorMatrix(), base_rows)
    work = WorkCounts()
    assert update.set_rows(new_rows, work)
    changed = comm.allreduce(len(np.setxor1d(base_rows, new_rows)))
    assert work.update_columns == changed > 0 and changed <= update.budget
    M_new, direct = factorized(a, new_bcs)
    r, x, x_ref = (M_new.createVecRight() for _ in range(3))
    r.array[:] = np.random.default_rng(comm.rank).standard_normal(r.getLocalSize())
    update.solve(r, x)
    direct.solve(r, x_ref)
    # the bordered solve is exact: round-off of two MUMPS solves and a dense one
    assert (x - x_ref).norm() <= 1e-11 * x_ref.norm()
    # and back to the base's rows: no change, no column, the base's own solve
    assert update.set_rows(base_rows, work) and update.size == 0
    update.solve(r, x)
    base.solve(r, x_ref)
    assert (x - x_ref).norm() <= 1e-13 * x_ref.norm()


@pytest.mark.parametrize("modulus", [1.0, 2e11])  # the stiffness in N/m: steel in SI units
def test_rows_added_and_released_solve_as_a_new_factorization(modulus):
    # the capacitance system mixes compliances and stiffnesses: whether it is solved must
    # not depend on the units
    check_rows_added_and_released(MPI.COMM_SELF, modulus)


@pytest.mark.mpi
def test_rows_added_and_released_in_parallel():
    assert MPI.COMM_WORLD.size > 1  # the columns and the capacitance system span ranks
    check_rows_added_and_released(MPI.COMM_WORLD)


def test_columns_costing_more_than_a_factorization_are_declined():
    a, K, rows = elastic_square(MPI.COMM_SELF, n=40)
    base_bcs, base_rows = rows(lambda x: x < 0.1)
    _, base = factorized(a, base_bcs)
    update = RowUpdate(K)
    update.rebase(base.getPC().getFactorMatrix(), base_rows)
    work = WorkCounts()
    # 36 new rows, more than the columns its flops pay for (29 here, counted by MUMPS):
    # declined before any is made; the caller then factorizes (and rebases)
    assert 0 < update.budget < 36
    assert not update.set_rows(rows(lambda x: x >= 0)[1], work)
    assert not update.serving and work.update_columns == 0


def test_rows_that_leave_the_body_free_are_left_to_a_factorization():
    a, K, rows = elastic_square(MPI.COMM_SELF)
    base_bcs, base_rows = rows(lambda x: x < 0.55)
    _, base = factorized(a, base_bcs)
    update = RowUpdate(K)
    update.rebase(base.getPC().getFactorMatrix(), base_rows)
    update.budget = 10**6  # past the count of columns, to the capacitance system itself
    # the bottom released, the top's vertical rows kept: free to slide along x, M_B is
    # singular, so is the capacitance matrix: declined (its columns were made)
    bottom_rows = rows(lambda x: x < 0)[1]
    work = WorkCounts()
    assert not update.set_rows(np.setdiff1d(base_rows, bottom_rows), work)
    assert not update.serving and work.update_columns == len(bottom_rows)


def test_newton_on_changing_rows_and_back_to_its_base_matches_new_factorizations():
    # a linear material's solver with reuse: the changed rows are served on the first
    # factorization (its A left with the old rows), the base's rows again by its factors;
    # each answer against a solver that factorizes its rows afresh
    from fenics_nl.solvers.newton import NewtonSolver

    domain = mesh.create_unit_square(MPI.COMM_SELF, 12, 12)
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    eps = lambda w: ufl.sym(ufl.grad(w))  # noqa: E731
    fdim = 1
    bottom = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[1], 0))
    top = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[1], 1))
    Vy, _ = V.sub(1).collapse()
    x_top = lambda where: top[where(domain.geometry.x[  # noqa: E731
        mesh.entities_to_geometry(domain, fdim, top)[:, 0], 0])]

    def problem(prefix, reuse):
        u, v = fem.Function(V), ufl.TestFunction(V)
        residual = (2 * ufl.inner(eps(u), eps(v)) + ufl.div(u) * ufl.div(v)) * ufl.dx \
            - ufl.dot(ufl.as_vector((0.3, 0.0)), v) * ufl.dx
        return u, NewtonSolver(residual, u, [], prefix=prefix, reuse_factorization=reuse)

    def bcs(where):
        held = fem.dirichletbc(np.zeros(2), fem.locate_dofs_topological(V, fdim, bottom), V)
        dofs = fem.locate_dofs_topological((V.sub(1), Vy), fdim, x_top(where))
        g = fem.Function(Vy)
        g.x.array[:] = -0.01
        return [held, fem.dirichletbc(g, dofs, V.sub(1))]

    u, solver = problem("rows_reuse_", True)
    for k, where in enumerate((lambda x: x < 0.55, lambda x: x > 0.3, lambda x: x < 0.55)):
        solver.set_bcs(bcs(where))
        solver.solve()
        u_ref, direct = problem(f"rows_direct{k}_", False)
        direct.set_bcs(bcs(where))
        direct.solve()
        assert np.allclose(u.x.array, u_ref.x.array, rtol=0, atol=1e-10 * np.abs(
            u_ref.x.array).max())
    assert solver.total.factorizations == 1 and solver.total.update_columns > 0


def test_springs_come_and_go_on_a_reused_factorization():
    # springs added to A without a factorization, then removed: A must not keep them when
    # the rows are the base's again (the KSP solves with A, preconditioned by the base)
    from fenics_nl.solvers.newton import NewtonSolver

    domain = mesh.create_unit_square(MPI.COMM_SELF, 8, 8)
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    eps = lambda w: ufl.sym(ufl.grad(w))  # noqa: E731
    bottom = mesh.locate_entities_boundary(domain, 1, lambda x: np.isclose(x[1], 0))
    held = fem.dirichletbc(np.zeros(2), fem.locate_dofs_topological(V, 1, bottom), V)

    def problem(prefix, reuse, load):
        u, v = fem.Function(V), ufl.TestFunction(V)
        f = fem.Constant(domain, np.array(load))
        residual = (2 * ufl.inner(eps(u), eps(v)) + ufl.div(u) * ufl.div(v)) * ufl.dx \
            - ufl.dot(f, v) * ufl.dx
        return u, f, NewtonSolver(residual, u, [held], prefix=prefix,
                                  reuse_factorization=reuse)

    u, f, solver = problem("springs_reuse_", True, [0.3, 0.0])
    solver.solve()
    top = np.flatnonzero(np.isclose(V.tabulate_dof_coordinates()[:, 1], 1.0))
    dofs = np.column_stack([2 * top, 2 * top + 1])
    solver.nodal.set_springs(dofs, np.tile(np.eye(2), (len(top), 1, 1)), np.zeros((len(top), 2)))
    solver.solve()
    solver.nodal.set_springs(np.zeros((0, 2)), np.zeros((0, 2, 2)), np.zeros((0, 2)))
    f.value[:] = [0.0, -0.2]
    solver.solve()
    u_ref, _, direct = problem("springs_direct_", False, [0.0, -0.2])
    direct.solve()
    assert np.allclose(u.x.array, u_ref.x.array, rtol=0, atol=1e-10 * np.abs(
        u_ref.x.array).max())
