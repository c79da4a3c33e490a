"""Arc-length continuation: the von Mises truss's exact curve, the beam's bifurcation."""

import math

import basix.ufl
import numpy as np
import pytest
import ufl
from continuation_problems import BucklingBeam
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.solvers.arclength import ArcLength, ContinuationError
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.theory import elastica
from fenics_nl.theory import truss as exact

A, H, EA = 1.0, 0.1, 1e6  # half-span, rise (a shallow truss: it snaps through), EA


class VonMisesTruss:
    """The von Mises truss: two P1 bars in the plane, pinned, one dead apex load.

    Half-span `a`, rise `h`, axial stiffness `EA`, reference apex load `P` (downwards). Each
    bar is one interval element of a mesh embedded in 2D; its free energy is EA/2 e² per
    unit reference length, e = (|t + ∂u/∂S|² − 1)/2 the Green–Lagrange strain along the bar
    (t its unit tangent, S its arc length). P1 is exact here: the strain of a straight
    two-node bar is uniform, so `theory.truss`'s curve is the model's. The apex load λ P is
    a nodal force (`NewtonSolver.nodal`).
    """

    def __init__(self, a, h, EA, P, comm=MPI.COMM_WORLD):
        self.a, self.h, self.EA, self.P = a, h, EA, P
        points = np.array([[-a, 0.0], [0.0, h], [a, 0.0]]) if comm.rank == 0 else np.zeros((0, 2))
        cells = (np.array([[0, 1], [1, 2]], dtype=np.int64) if comm.rank == 0
                 else np.zeros((0, 2), dtype=np.int64))
        line = ufl.Mesh(basix.ufl.element("Lagrange", "interval", 1, shape=(2,)))
        self.mesh = mesh.create_mesh(comm, cells, line, points)
        self.V = fem.functionspace(self.mesh, ("Lagrange", 1, (2,)))
        self.u = fem.Function(self.V, name="displacement")
        J = ufl.Jacobian(self.mesh)
        t = ufl.as_vector([J[0, 0], J[1, 0]])
        t = t / ufl.sqrt(ufl.dot(t, t))
        stretched = t + ufl.grad(self.u) * t  # ∂x/∂S: the deformed bar's tangent
        e = (ufl.dot(stretched, stretched) - 1) / 2
        energy = EA / 2 * e**2 * ufl.dx
        self.residual = ufl.derivative(energy, self.u, ufl.TestFunction(self.V))
        supports = mesh.locate_entities_boundary(self.mesh, 0, lambda x: np.isclose(x[1], 0))
        self.bcs = [boundary.fixed(self.V, supports)]
        X = self.V.tabulate_dof_coordinates()[: self.V.dofmap.index_map.size_local]
        apex = np.flatnonzero(np.isclose(X[:, 1], h) & np.isclose(X[:, 0], 0))
        self._apex_dof = (2 * apex + 1).astype(np.int32)  # its vertical component
        self.solver = None

    def newton(self, **options):
        """The Newton solver of the truss (its nodal load is set by `set_load`)."""
        self.solver = NewtonSolver(self.residual, self.u, self.bcs, **options)
        return self.solver

    def set_load(self, lam):
        """The apex load λ P, downwards."""
        self.solver.nodal.set_load(self._apex_dof, np.full(len(self._apex_dof), -lam * self.P))

    def apex_deflection(self):
        """w: the apex's downward displacement."""
        return self.mesh.comm.allreduce(-float(self.u.x.array[self._apex_dof].sum()))


def trace(method, scale=1.0, target=1.5, comm=MPI.COMM_WORLD, max_steps=60, **options):
    """The truss's path to λ = target (P_max units), lengths × `scale`; (truss, path, w, λ)."""
    truss = VonMisesTruss(A * scale, H * scale, EA, exact.limit_load(EA, A, H), comm=comm)
    solver = truss.newton(method=method, max_it=200, prefix=f"truss_{method}_")
    options = {"arc_length": 0.2, **options}
    arc = ArcLength(solver, truss.set_load, prefix="truss_arc_", **options)
    states = []
    path = arc.run(target, max_steps, on_step=lambda lam, r: states.append(
        (truss.apex_deflection() / scale, lam)))
    return truss, path, states


@pytest.mark.parametrize("method", ["full", "modified", "periodic", "bfgs"])
def test_the_truss_path_is_the_closed_form_through_both_limit_points(method):
    P_max = exact.limit_load(EA, A, H)
    _, path, states = trace(method)
    # every converged state on P(w) to 1e-8 of P_max: the bars' P1 strain is exact, so
    # this is the continuation's own accuracy (its tolerance is 1e-10 of the load, 1.1e-10
    # measured; 1e-8 leaves room for the tangent's conditioning near the limit points)
    errors = [abs(lam * P_max - exact.load(w, EA, A, H)) / P_max for w, lam in states]
    assert max(errors) < 1e-8
    w1, w2 = exact.limit_displacements(H)
    assert any(w1 < w < w2 for w, _ in states)  # on the unstable branch
    assert states[-1][1] == 1.5 and states[-1][0] > H * (1 + 2 / math.sqrt(3))  # inverted
    limits = [c for c in path.critical_points if c.kind == "limit"]
    assert [round(c.factor) for c in limits] == [1, -1]
    assert not [c for c in path.critical_points if c.kind == "bifurcation"]
    # bracketed by the sense of λ along the tangent, to 1/32 of the arc: λ'' Δs² is small
    assert abs(limits[0].factor - 1) < 1e-3 and abs(limits[1].factor + 1) < 1e-3
    # between the limit points the tangent has one negative eigenvalue, else none
    assert set(path.unstable) == {0, 1}
    if method == "modified":  # one tangent per step tried (+ the landing's), factorized
        # unless a step tried again from the same state (a cut, a bracketing step) has it
        tried = len(path.results) + path.failures + path.bracketing_steps
        assert path.work.tangent_assemblies == tried + 1
        assert path.work.factorizations < tried + 1 - path.bracketing_steps // 2
    if method == "full":  # the constraint costs back-solves, not factorizations
        assert path.work.linear_solves > path.work.factorizations


@pytest.mark.parametrize("method", ["full", "modified"])
def test_the_constraint_costs_back_solves_not_factorizations(method):
    # per converged step (the last one also lands, so it is left out): full Newton takes
    # the predictor's direction K(u_n)⁻¹q from the stability check at u_n (its LDLᵀ,
    # counted apart), except on the first step, then factorizes once per iteration and
    # solves twice (−R and q: the bordered solve); modified assembles K(u_n) once per
    # step (factorized, unless it is one factorized already), back-solves q once and −R
    # once per iteration
    _, path, _ = trace(method)
    assert path.inertia_factorizations == len(path.results) + path.bracketing_steps + 1
    for n, r in enumerate(path.results[:-1]):
        k, w = r.iterations, r.work
        if method == "full":
            first = int(n == 0)  # its predictor factorizes and solves
            assert (w.factorizations, w.linear_solves) == (k + first, 2 * k + first)
        else:
            assert (w.tangent_assemblies, w.linear_solves) == (1, 1 + k)
            assert w.factorizations <= 1


def test_without_stability_checks_limit_points_come_from_the_load_factor():
    # detect=False: no LDLᵀ per state; a limit point is where Δλ changes sign, at the
    # vertex of the parabola λ(s) through the last 3 states (arcs held at 0.1: 1e-5 here)
    _, path, _ = trace("full", detect=False, arc_length=0.1, max_arc_length=0.1,
                       max_steps=200)
    assert path.inertia_factorizations == 0
    limits = [c.factor for c in path.critical_points if c.kind == "limit"]
    assert len(limits) == len(path.critical_points) == 2
    assert abs(limits[0] - 1) < 1e-3 and abs(limits[1] + 1) < 1e-3


def test_the_same_truss_in_millimetres_takes_the_same_steps():
    _, metres, _ = trace("full")
    _, millimetres, _ = trace("full", scale=1e3)
    assert millimetres.factors == pytest.approx(metres.factors, rel=1e-8, abs=1e-10)
    assert [r.iterations for r in millimetres.results] == [
        r.iterations for r in metres.results]


def test_bad_input_and_unreachable_targets_are_clear_errors():
    truss = VonMisesTruss(A, H, EA, 1.0)
    solver = truss.newton()
    for bad in (0.0, -1.0, math.nan):
        with pytest.raises(ValueError, match="arc length must be"):
            ArcLength(solver, truss.set_load, arc_length=bad)
    with pytest.raises(ContinuationError, match="not reached in 3 steps"):
        trace("full", target=1e3, max_steps=3)
    # modified Newton with arcs held at 8, far from the target: past the second limit point
    # the corrector lands behind where the path came from; the step cannot be cut, the run
    # stops
    with pytest.raises(ContinuationError, match="doubles back onto itself"):
        trace("modified", target=1e3, arc_length=8.0, min_arc_length=8.0,
              max_arc_length=8.0)


@pytest.mark.parametrize("method", ["full", "modified", "bfgs"])
def test_the_beam_leaves_the_straight_branch_at_its_bifurcation(method):
    # a perfect beam (no imperfection): the straight path goes on past P_cr; the tangent's
    # inertia changes there, the path is bracketed and left along the critical mode (for
    # modified Newton and BFGS the constant tangent is taken after the kick, not at the
    # bifurcation, where it is singular along the mode)
    beam = BucklingBeam(1.0, 0.02, 1e3, 0.3, imperfection=0.0)
    P_cr = beam.critical_loads(1)[0][0] / beam.P_euler  # SLEPc, not a closed form
    path = beam.solve_arc_length(1.5, method)
    assert path.switched
    (bifurcation,) = path.critical_points
    low, high = bifurcation.between
    # bracketed to 1/32 of the arc of 0.8 it was met with: Δλ ≤ 0.025/√2 on the straight path
    assert bifurcation.kind == "bifurcation" and low < P_cr < high and high - low < 0.02
    tip = beam.tip()
    alpha = math.degrees(abs(tip["rotation"]))
    alpha_el = math.degrees(elastica.tip_rotation(1.5))
    assert abs(alpha - alpha_el) < max(0.5, 0.01 * alpha_el)
    assert abs(tip["lateral"]) == pytest.approx(elastica.tip_position(1.5)[0], rel=0.01)


@pytest.mark.mpi
def test_the_beam_path_on_two_ranks_is_the_serial_one():
    assert MPI.COMM_WORLD.size > 1

    def run(comm):
        beam = BucklingBeam(1.0, 0.02, 1e3, 0.3, imperfection=0.0, comm=comm)
        path = beam.solve_arc_length(1.2)
        return beam.tip(), path

    (tp, pp), (ts, ps) = run(MPI.COMM_WORLD), run(MPI.COMM_SELF)
    assert pp.switched and ps.switched
    # the same states up to the switch (after it, a step's iteration count can differ by
    # round-off, and with it the next arc); the mode's sign may differ: compare |α|
    switch = pp.critical_points[0].step
    assert pp.factors[:switch] == pytest.approx(ps.factors[:switch], rel=1e-8)
    assert pp.critical_points[0].between == pytest.approx(ps.critical_points[0].between,
                                                          rel=1e-8)
    assert abs(tp["rotation"]) == pytest.approx(abs(ts["rotation"]), rel=1e-6)


def test_a_residual_that_falls_onto_its_round_off_is_accepted_one_iteration_later():
    from fenics_nl.solvers.convergence import at_round_off as _at_round_off

    # the arch with 8 elements through its thickness (demos/snap_through.py --elements 8),
    # one step's |R|: full Newton reaches the internal forces' round-off (2e-13) in two
    # iterations, just above the tolerance 1e-8 |q|; before, 4 more iterations confirmed it
    # and the adaptive arc shrank on them until the path stalled (300 steps short of λ)
    largest, threshold = 1.6e-5, 1.1e-13
    falls = [1.6e-05, 1.3e-10, 2.1e-13]
    assert not _at_round_off(falls, largest, threshold)  # still falling fast
    assert _at_round_off([*falls, 2.1e-13], largest, threshold)
    # a fall onto a level far above the tolerance is not round-off, nor a slow linear rate
    # (that takes the 5 iterates of the modified variants' test)
    assert not _at_round_off([1.6e-5, 1.3e-8, 1.2e-8], largest, threshold)
    assert not _at_round_off([1e-11, 5e-12, 3e-12], largest, threshold)
