"""A body its supports do not hold is refused, in every solver path, and the motion named.

The plate is a unit square (plane strain, linear elastic) loaded by a traction on its right
edge. With u_x = 0 on its left edge only, it is free to slide along y: MUMPS factorizes the
singular stiffness all the same, so without the check Newton "converges" to an answer with
an arbitrary vertical motion in it.
"""

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from dolfinx.fem import petsc
from mpi4py import MPI

from fenics_nl.contact.active_set import ActiveSetContact
from fenics_nl.domain import boundary
from fenics_nl.errors import SupportError
from fenics_nl.materials.laws import LinearElastic, NeoHookean
from fenics_nl.solvers.arclength import ArcLength
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.solvers.snes import SnesSolver
from fenics_nl.solvers.supports import RigidMotions, free_motions


class Plate:
    """The square of side L, E in the units given, loaded on its right edge."""

    def __init__(self, L=1.0, E=1e3, material=None, model="plane_strain", dim=2, n=6,
                 comm=MPI.COMM_WORLD):
        if dim == 2:
            self.mesh = mesh.create_rectangle(comm, [[0, 0], [L, L]], [n, n])
        else:
            self.mesh = mesh.create_box(comm, [[0, 0, 0], [L, L, L]], [n, n, n])
        self.L, self.dim = L, dim
        self.V = fem.functionspace(self.mesh, ("Lagrange", 1, (dim,)))
        self.u = fem.Function(self.V)
        v = ufl.TestFunction(self.V)
        material = material or LinearElastic(E=E, nu=0.3)
        self.t = fem.Constant(self.mesh, 1.0)
        right = self.facets(lambda x: np.isclose(x[0], L))
        left = self.facets(lambda x: np.isclose(x[0], 0.0))
        facets = np.concatenate([right, left])
        order = np.argsort(facets)
        values = np.concatenate([np.ones_like(right), 2 * np.ones_like(left)])
        tags = mesh.meshtags(self.mesh, dim - 1, facets[order], values[order])
        self.ds = ds = ufl.Measure("ds", self.mesh, subdomain_data=tags)
        load = ufl.as_vector([1e-3 * E * self.t] + [0.0] * (dim - 1))
        self.weight = 1.0
        if model == "axisymmetric":
            self.weight = ufl.SpatialCoordinate(self.mesh)[0]
        self.residual = (material.internal_work(self.u, v, model) * self.weight * ufl.dx
                         - ufl.dot(load, v) * self.weight * ds(1))
        self.v = v

    def facets(self, where):
        return mesh.locate_entities_boundary(self.mesh, self.dim - 1, where)

    def holds(self, *supports):
        """Dirichlet conditions: ('x', i) u_i = 0 on x = 0; ('point', i) u_i = 0 at 0."""
        bcs = []
        for kind, i in supports:
            if kind == "x":
                facets = self.facets(lambda x: np.isclose(x[0], 0.0))
                bcs.append(boundary.component(self.V, i, facets))
            elif kind == "bottom":
                facets = self.facets(lambda x: np.isclose(x[1], 0.0))
                bcs.append(boundary.component(self.V, i, facets))
            else:  # one vertex at the origin
                Vi, _ = self.V.sub(i).collapse()
                dofs = fem.locate_dofs_geometrical(
                    (self.V.sub(i), Vi), lambda x: np.isclose(x[0], 0) & np.isclose(x[1], 0)
                    & (np.isclose(x[2], 0) if self.dim == 3 else True))
                bcs.append(fem.dirichletbc(fem.Function(Vi), dofs, self.V.sub(i)))
        return bcs


def refused(solve) -> str:
    with pytest.raises(SupportError) as err:
        solve()
    return str(err.value)


@pytest.mark.parametrize("method", ["full", "modified", "periodic", "bfgs"])
def test_every_newton_variant_refuses_a_plate_free_to_slide(method):
    p = Plate()
    solver = NewtonSolver(p.residual, p.u, p.holds(("x", 0)), method=method,
                          prefix=f"free_{method}_")
    message = refused(solver.solve)
    assert "translation along y" in message and "rotation" not in message
    assert "support or a symmetry condition" in message


def test_iterative_and_snes_paths_refuse_it_too():
    p = Plate()
    gamg = NewtonSolver(p.residual, p.u, p.holds(("x", 0)), linear_solver="gamg",
                        prefix="free_gamg_")
    assert "translation along y" in refused(gamg.solve)
    p = Plate()
    snes = SnesSolver(p.residual, p.u, p.holds(("x", 0)), prefix="free_snes_")
    assert "translation along y" in refused(snes.solve)


def test_the_decision_does_not_depend_on_the_units():
    # the same plate in N-mm-MPa (E = 2e5, L = 1000) and in N-m-Pa (E = 2e11, L = 1):
    # free when it slides, held when both symmetry supports are there
    for L, E in ((1000.0, 2e5), (1.0, 2e11), (1e-3, 1e-3)):
        p = Plate(L=L, E=E)
        solver = NewtonSolver(p.residual, p.u, p.holds(("x", 0)), prefix="units_")
        assert "translation along y" in refused(solver.solve)
        p = Plate(L=L, E=E)
        NewtonSolver(p.residual, p.u, p.holds(("x", 0), ("bottom", 1)),
                     prefix="units_").solve()


def test_a_pinned_plate_may_rotate_about_its_pin():
    p = Plate()
    solver = NewtonSolver(p.residual, p.u, p.holds(("point", 0), ("point", 1)),
                          prefix="pin_")
    message = refused(solver.solve)
    assert "rotation about z through (0, 0)" in message and "translation" not in message


def test_a_box_on_a_frictionless_floor_names_its_three_free_motions():
    p = Plate(dim=3, n=3)
    bottom = p.facets(lambda x: np.isclose(x[2], 0.0))
    bcs = [boundary.component(p.V, 2, bottom)]
    message = refused(NewtonSolver(p.residual, p.u, bcs, prefix="box_").solve)
    assert "translation along x" in message and "translation along y" in message
    assert "rotation about z through (" in message
    assert message.count("rotation") == 1


@pytest.mark.parametrize("L,E", [(1.0, 1e3), (1000.0, 2e5)])
def test_a_soft_foundation_holds_a_body_in_any_units(L, E):
    # k = 1e-6 E per unit area on one edge: weak next to the body (its resistance to a
    # rigid motion ~1e-7 of max K_ii), yet it holds: accepted, 1000 times above the threshold
    p = Plate(L=L, E=E)
    spring = 1e-6 * E / L * ufl.dot(p.u, p.v) * p.ds(2)
    # (the soft support makes K ill-conditioned: ‖R‖ stops at ~2e-9 of its start)
    result = NewtonSolver(p.residual + spring, p.u, [], rtol=1e-8, atol=1e-8,
                          prefix="soft_").solve()
    assert result.converged


def test_what_holds_a_body_without_a_dirichlet_row_is_accepted():
    # an elastic foundation k u.v on the left edge: no support, yet nothing is free; and the
    # axisymmetric model, whose radial "translation" strains the hoops: held by u_z alone
    p = Plate()
    spring = 1e3 * ufl.dot(p.u, p.v) * p.ds(2)  # on the left edge
    NewtonSolver(p.residual + spring, p.u, [], prefix="spring_").solve()
    p = Plate(model="axisymmetric")
    NewtonSolver(p.residual, p.u, p.holds(("bottom", 1)), prefix="axi_").solve()
    p = Plate(model="axisymmetric")
    message = refused(NewtonSolver(p.residual, p.u, [], prefix="axi_free_").solve)
    assert "translation along y" in message and "along x" not in message


def test_arc_length_refuses_a_free_body_and_keeps_telling_a_limit_point_apart():
    p = Plate(material=NeoHookean(E=1e3, nu=0.3), model="plane_strain")
    solver = NewtonSolver(p.residual, p.u, p.holds(("x", 0)), prefix="free_arc_")

    def set_load(t):
        p.t.value = t

    assert "translation along y" in refused(
        lambda: ArcLength(solver, set_load, arc_length=0.1).run(1.0, 5))


def test_the_active_set_says_contact_does_not_hold_the_body_yet():
    # the plate above a floor at a gap, pushed down by a traction; nothing else holds it
    # vertically: with no node active at the start, it is free to fall
    p = Plate()
    bottom = p.facets(lambda x: np.isclose(x[1], 0.0))
    x_held = p.holds(("x", 0))
    contact = ActiveSetContact(p.residual, p.u, x_held, bottom, lambda x: 0.0 * x[0] + 0.01,
                               normal_axis=1, normal_sign=-1, initial="none",
                               prefix="free_contact_")
    message = refused(contact.solve)
    assert "contact does not hold the body yet" in message
    assert "translation along y" in message


@pytest.mark.mpi
def test_two_ranks_make_the_same_decision():
    p = Plate(n=8)
    message = refused(NewtonSolver(p.residual, p.u, p.holds(("point", 0), ("point", 1)),
                                   prefix="pin_mpi_").solve)
    assert "rotation about z through (0, 0)" in message
    p = Plate(n=8)
    assert "translation along y" in refused(
        NewtonSolver(p.residual, p.u, p.holds(("x", 0)), prefix="free_mpi_").solve)
    p = Plate(n=8)
    NewtonSolver(p.residual, p.u, p.holds(("x", 0), ("bottom", 1)), prefix="held_mpi_").solve()


def test_the_tangent_without_its_dirichlet_rows_names_the_same_motions():
    # the row update leaves a linear material's K without the active set's rows: its supports
    # are checked on K itself, which must name what the tangent with identity rows names
    p = Plate()
    form = fem.form(ufl.derivative(p.residual, p.u))
    K = petsc.assemble_matrix(form)
    K.assemble()
    motions = RigidMotions.of(p.V)
    for supports, named in ((["x", 0], ["translation along y"]),
                            (["point", 0, "point", 1], ["rotation about z through (0, 0)"]),
                            (["x", 0, "bottom", 1], [])):
        bcs = p.holds(*zip(supports[::2], supports[1::2], strict=True))
        A = petsc.assemble_matrix(form, bcs=bcs)
        A.assemble()
        assert free_motions(K, motions, bcs) == free_motions(A, motions, bcs) == named
