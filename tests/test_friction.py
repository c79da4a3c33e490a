"""Coulomb friction on the active set: statuses open / stick / slip (`contact.friction`)."""

import math

import basix.ufl
import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.contact.friction import FrictionalContact

# the plane-strain cylinder of Cattaneo-Mindlin (`demos/punch_friction.py`'s defaults: a
# rigid punch, R = 1, δ = 0.01, on an incompressible Taylor-Hood block 100 a wide, f = 0.3)
# on a compressible P1 block: cheap, but not Cattaneo-Mindlin's (Spence's coupling)
COMPRESSIBLE_CYLINDER = ("--nu", "0.3", "--refine", "0", "--block", "100")
# the axisymmetric punch with friction: a normal load only
AXISYMMETRIC = ("--model", "axisymmetric", "--nu", "0.3", "--refine", "0", "--block", "100")


def jenkins_element(k_n, k_t, delta, f):
    """A 2-node spring (axial k_n, transverse k_t) whose foot touches a rigid floor with
    friction f, its head pressed down by δ: a spring in series with a Coulomb slider of
    threshold F = f k_n δ. Returns (contact, the head's Dirichlet values)."""
    domain = ufl.Mesh(basix.ufl.element("Lagrange", "interval", 1, shape=(2,)))
    msh = mesh.create_mesh(MPI.COMM_SELF, np.array([[0, 1]], dtype=np.int64), domain,
                           np.array([[0.0, 0.0], [0.0, 1.0]]))
    V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
    u, v = fem.Function(V), ufl.TestFunction(V)
    R = (k_n * u[1].dx(1) * v[1].dx(1) + k_t * u[0].dx(1) * v[0].dx(1)) * ufl.dx
    head = mesh.locate_entities_boundary(msh, 0, lambda x: np.isclose(x[1], 1.0))
    foot = mesh.locate_entities_boundary(msh, 0, lambda x: np.isclose(x[1], 0.0))
    g = fem.Function(V)
    bc = fem.dirichletbc(g, fem.locate_dofs_topological(V, 0, head))
    contact = FrictionalContact(R, u, [bc], foot, lambda x: 0 * x[0], normal_axis=1,
                                normal_sign=-1, friction=f, initial="all",
                                prefix=f"jenkins{id(u)}_")
    return contact, g


def test_a_spring_on_a_rough_floor_follows_the_exact_stick_slip_cycle():
    # the head moves 0 -> W -> -W -> W in steps of 0.03, which never land on a stick-slip
    # corner; the foot's force is the Jenkins element's at every step, and the energy
    # dissipated over the closed cycle, Σ |Q| |Δs|, is the loop's area 4 F (W − F/k)
    k_n, k_t, delta, f = 2.0, 0.5, 0.05, 0.5
    F, W, dw = f * k_n * delta, 0.3, 0.03
    contact, head = jenkins_element(k_n, k_t, delta, f)
    path = [0.0]
    for target in (W, -W, W):
        while abs(path[-1] - target) > 1e-12:
            path.append(path[-1] + math.copysign(min(dw, abs(target - path[-1])),
                                                 target - path[-1]))
    s, forces, feet = 0.0, [], []
    for i, w in enumerate(path):
        head.interpolate(lambda x, w=w: np.vstack([w + 0 * x[0], -delta + 0 * x[0]]))
        contact.solve()
        contact.commit()
        Q = -contact.tangential_force()[0]  # the spring's force on the floor
        trial = k_t * (w - s)  # the exact element: stick, or slip back to the threshold
        if abs(trial) > F:
            s = w - math.copysign(F / k_t, trial)
        assert Q == pytest.approx(k_t * (w - s), abs=1e-12 * F), (i, w)
        assert contact.force == pytest.approx(k_n * delta, rel=1e-12)
        forces.append(Q)
        feet.append(contact.tangential_displacement()[0, 0])
    first_peak = round(W / dw)  # the cycle W -> -W -> W starts there
    dissipated = sum(abs(forces[i]) * abs(feet[i] - feet[i - 1])
                     for i in range(first_peak + 1, len(path)))
    assert dissipated == pytest.approx(4 * F * (W - F / k_t), rel=1e-12)


def test_bad_coefficients_and_formulations_are_refused():
    for f in (-0.1, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="friction coefficient"):
            jenkins_element(1.0, 1.0, 0.1, f)
    msh = mesh.create_unit_square(MPI.COMM_WORLD, 2, 2)
    V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
    u, v = fem.Function(V), ufl.TestFunction(V)
    bottom = mesh.locate_entities_boundary(msh, 1, lambda x: np.isclose(x[1], 0.0))
    with pytest.raises(ValueError, match="elimination formulation"):
        FrictionalContact(ufl.inner(ufl.grad(u), ufl.grad(v)) * ufl.dx, u, [], bottom,
                          lambda x: 0 * x[0], normal_axis=1, normal_sign=-1, friction=0.3,
                          formulation="multiplier")
    assert jenkins_element(1.0, 1.0, 0.1, 0.3)[0].f == 0.3  # a valid one builds


def cattaneo_mindlin_partial_slip_of_a_cylinder(d):
    """What `demos/punch_friction.py`'s default run must show (checked on that run, the one
    its documentation page makes, in `tests/test_notebooks.py`: one run for both).

    The punch moved by d = 0.0023 after pressing it: Q = 0.4983 f P. Measured (h = a/24):
    the stick half-width 0.07 h from a √(1 − Q/(fP)), and the tangential traction within
    1.9 % of f p0 of (f p0/a)(√(a² − x²) − √(c² − x²)) except within 2 h of the stick-slip
    edges ±c, where its slope is infinite (3.3 % from 1 h to 2 h of them).
    """
    assert d["friction"] == 0.3 and d["stick_nodes"] > 0 and d["slip_nodes"] > 0
    assert 0.4 < d["tangential_force"] / (0.3 * d["force"]) < 0.6
    assert abs(d["stick_radius"] - d["stick_radius_exact"]) < d["element_size"]
    assert d["tangential_traction_max_error"] < 0.03


def test_force_control_reaches_the_tangential_force_and_coulombs_law_holds():
    # Q = f P / 2 by secant steps, then Coulomb's law node by node: |T_t| <= f |T_n| where
    # the node sticks, = f |T_n| and against its slip where it slips, compression where
    # closed, no penetration where open
    from punch_problem import build_punch

    from fenics_nl.materials.laws import LinearElastic

    f = 0.3
    punch = build_punch("plane_strain", LinearElastic(1.0, 0.3), 1.0, 0.1, refine=0,
                        block=100.0, tangential=True, friction=f)
    pressed = punch.indent(0.01)
    punch.commit()
    moved, positions = punch.pull(0.5 * f * pressed.force)
    assert moved.tangential_force == pytest.approx(0.5 * f * pressed.force, rel=3e-8)
    c = punch.contact
    T_n, T_t, g = c.normal_forces(), c.tangential_forces()[:, 0], c.slip_increment()[:, 0]
    scale = np.abs(T_n).max()
    assert moved.slip_nodes > 0 and moved.stick_nodes > 0 and positions < 10
    assert np.all(np.abs(T_t[c.stick]) <= f * np.abs(T_n[c.stick]) + 1e-9 * scale)
    assert np.allclose(np.abs(T_t[c.slip]), f * np.abs(T_n[c.slip]), atol=1e-9 * scale)
    assert np.all(T_t[c.slip] * g[c.slip] <= 1e-12)  # the force opposes the slip
    assert np.all(T_n[c.active] <= 1e-9 * scale)
    assert np.all(c.normal_gap()[~c.active] <= 1e-9 * 0.01)


def test_cattaneo_mindlin_partial_slip_of_a_sphere():
    # 3D half block (y >= 0), Taylor-Hood at ν = 1/2, h = a/6, far field graded by 60 %
    # (26k unknowns; at 30 %, 38k, the same checks pass, in twice the time):
    # pressed by δ = 0.01 R, then moved by d = 0.002 R (Q = 0.531 f P). Measured:
    # * the stick radius 0.12 h outside c = a (1 − Q/(fP))^(1/3) (0.16 h at 30 %);
    # * the tangential force inside r, Q(r), within 0.75 % of Q of Mindlin's at every r = k h
    #   (P2 nodal forces are not a pointwise traction in 3D: a vertex's is about 0);
    # * the displacement, less the far field's share, 0.59 % from Mindlin's δ_t (raw: +4.7 %;
    #   the share, C_far Q, is the block's bonded compliance less the half-space's, since
    #   the far field does not see how the contact zone slips)
    from punch_problem import build_punch

    from fenics_nl.materials.laws import LinearElastic
    from fenics_nl.theory import hertz, mindlin

    f, nu, E = 0.3, 0.5, 1.0
    punch = build_punch("3d", LinearElastic(E, nu), 1.0, 0.1, refine=0, block=10.0,
                        growth=0.6, mixed=True, tangential=True, friction=f)
    pressed = punch.indent(0.01)
    punch.commit()
    bonded = punch.bonded_compliance()
    moved = punch.shift(0.002)
    P, Q, h = moved.normal_force, moved.tangential_force, punch.block.h
    # ν = 1/2: Q leaves the pressure alone (measured 1e-5: the FE's own coupling)
    assert P == pytest.approx(pressed.force, rel=1e-4)
    ref = hertz.sphere_from_force(E, nu, 1.0, P)
    a, p0 = ref["contact_radius"], ref["max_pressure"]
    assert 0.4 < Q / (f * P) < 0.6 and moved.slip_nodes > 0 and moved.stick_nodes > 0
    c = mindlin.sphere_stick_radius(a, Q, f * P)
    assert abs(moved.stick_radius - c) < h
    radii = np.arange(1, 9) * h
    within = punch.tangential_force_within(radii)
    exact = mindlin.sphere_tangential_force_within(radii, a, p0, f, c)
    assert np.abs(within - exact).max() < 0.015 * Q
    G = E / (2 * (1 + nu))
    far = bonded - (2 - nu) / (8 * G * a)  # > 0: the 10 a block's free sides are soft
    delta = mindlin.sphere_tangential_displacement(a, Q, f * P, G, nu)
    assert 0.02 < far * Q / delta < 0.1
    assert abs((0.002 - far * Q) / delta - 1) < 0.01


def test_coulombs_law_holds_node_by_node_in_3d():
    # ν = 0.3: the normal load alone makes the surface slip inward (Spence), and in 3D the
    # slip directions are vectors, found by Newton's method (the spring across the slip);
    # two normal steps and a tangential move settle, and every node obeys Coulomb's law
    from punch_problem import build_punch

    from fenics_nl.materials.laws import LinearElastic

    f = 0.3
    punch = build_punch("3d", LinearElastic(1.0, 0.3), 1.0, 0.1, refine=0, block=10.0,
                        tangential=True, friction=f)
    for delta in (0.005, 0.01):
        punch.indent(delta)
        punch.commit()
    moved = punch.shift(0.002)
    c = punch.contact
    T_n, T_t, g = c.normal_forces(), c.tangential_forces(), c.slip_increment()
    scale, size = np.abs(T_n).max(), np.linalg.norm(T_t, axis=1)
    slid = np.linalg.norm(g, axis=1)
    assert moved.slip_nodes > 0 and moved.stick_nodes > 0
    assert np.all(size[c.stick] <= f * np.abs(T_n[c.stick]) + 1e-9 * scale)
    assert np.allclose(size[c.slip], f * np.abs(T_n[c.slip]), atol=1e-9 * scale)
    # the force opposes the slip: T_t = −|T_t| Δg/|Δg| where the node has moved
    moving = c.slip & (slid > 1e-6 * slid.max())
    cosine = np.sum(T_t[moving] * g[moving], axis=1) / (size[moving] * slid[moving])
    assert moving.sum() > 0.5 * moved.slip_nodes and np.all(cosine < -1 + 1e-8)
    assert np.all(T_n[c.active] <= 1e-9 * scale)
    assert np.all(c.normal_gap()[~c.active] <= 1e-9 * 0.01)


def test_vanishing_friction_is_frictionless_and_large_friction_sticks(demo):
    free = demo.punch("--refine", "0", "--block", "100")
    smooth = demo.punch_friction(*AXISYMMETRIC, "--friction", "0")
    assert smooth["force"] == pytest.approx(free["force"], rel=1e-9)
    # f = 0.3 at ν = 0.3: friction holds the surface back from its inward slip (Spence), so
    # the same δ needs more force (measured +1.7 %); the axis node's radial reaction is its
    # support's, not friction's, and takes no part in the statuses
    sticky = demo.punch_friction(*AXISYMMETRIC, "--friction", "0.3")
    assert free["force"] < sticky["force"] < 1.05 * free["force"]
    # f = 10 and Q = 1e-4 f P: no node slips
    rough = demo.punch_friction(*COMPRESSIBLE_CYLINDER, "--friction", "10", "--tangential-ratio",
                                "1e-4")
    assert rough["slip_nodes"] == 0 and rough["stick_nodes"] == rough["nodes_in_contact"]


@pytest.mark.mpi
def test_friction_two_ranks_give_the_serial_answer(demo):
    # a block 10 a wide: there the partition cuts the contact zone (both ranks own stick
    # and slip nodes: `test_friction_on_a_cut_contact_zone` checks it)
    args = ("--nu", "0.3", "--refine", "0", "--block", "10", "--tangential-displacement",
            "0.002")
    s, p = demo.punch_friction(*args), demo.punch_friction(*args, ranks=2)
    assert p["ranks"] == 2
    assert p["tangential_force"] == pytest.approx(s["tangential_force"], rel=1e-8)
    assert (p["stick_nodes"], p["slip_nodes"]) == (s["stick_nodes"], s["slip_nodes"])


@pytest.mark.parametrize("args,words", [
    (["--friction", "-0.1"], "--friction: must be >= 0"),
    (["--friction", "0", "--tangential-ratio", "0.5"], "needs --friction"),
    (["--model", "axisymmetric", "--tangential-ratio", "0.5"], "axial symmetry"),
    (["--formulation", "multiplier"], "elimination"),
    (["--tangential-ratio", "1"], "slides"),
    ([*COMPRESSIBLE_CYLINDER, "--tangential-force", "1"], "slides"),
    ([*COMPRESSIBLE_CYLINDER, "--indentation", "-0.01", "--tangential-displacement", "0.001"],
     "does not touch"),
])
def test_friction_bad_input_is_one_line(demo, args, words):
    demo.refuses(["punch_friction.py", *args], words)


@pytest.mark.parametrize("model,block,growth,Q_bound,q_bound", [
    # the two steps with the contact and friction regularised by k: measured Q +3.1e-4 and
    # +2.5e-5, traction 5.4 % and 0.58 % of the largest at k = 10 and 100 E/h
    ("plane_strain", 100.0, None, 1e-4, 0.01),
    # 3D, the vector law (the trial force returned to the disc f p_n) on the P1 sphere, far
    # field graded by 30 % (5k unknowns): measured Q +2.6e-3 and +2.3e-4, traction 17 % and
    # 1.4 % (at the default 10 %, 16k unknowns and 6 times the time: +2.5e-3, +2.3e-4,
    # 12 %, 1.5 %)
    ("3d", 10.0, 0.3, 1e-3, 0.03),
])
def test_the_penalty_peer_converges_to_the_active_set(model, block, growth, Q_bound, q_bound):
    # pressed in one step (ν = 0.3), then moved: the nodal traction and Q of the penalty
    # peer approach the active set's answer as k grows
    from peers import solve_friction_penalty  # benchmarks/peers.py
    from punch_problem import build_punch

    from fenics_nl.materials.laws import LinearElastic

    punch = build_punch(model, LinearElastic(1.0, 0.3), 1.0, 0.1, refine=0, block=block,
                        growth=growth, tangential=True, friction=0.3)
    punch.indent(0.01)
    punch.commit()
    moved = punch.shift(0.002)
    c = punch.contact
    q = (c.tangential_forces()[:, 0] / c.surface.nodal_areas())[c.owned]
    gaps = []
    for kappa in (10.0, 100.0):
        r = solve_friction_penalty(punch, 0.01, 0.002, kappa / punch.block.h, 0.3)
        gaps.append((abs(r["tangential_force"] / moved.tangential_force - 1),
                     np.abs(r["traction"] - q).max() / np.abs(q).max()))
    (Q10, q10), (Q100, q100) = gaps
    assert Q100 < 0.2 * Q10 and q100 < 0.2 * q10 and Q100 < Q_bound and q100 < q_bound


@pytest.mark.mpi
@pytest.mark.parametrize("model", ["plane_strain", "3d"])
def test_friction_on_a_cut_contact_zone(model):
    # plane strain: the partition cuts S_C inside the contact zone, so sticking and
    # slipping nodes are owned by both ranks and ghosts carry statuses; the answer is the
    # serial one
    from punch_problem import build_punch

    from fenics_nl.materials.laws import LinearElastic

    assert MPI.COMM_WORLD.size > 1

    def run(comm):
        punch = build_punch(model, LinearElastic(1.0, 0.3), 1.0, 0.1, refine=0,
                            block=10.0, tangential=True, friction=0.3, comm=comm)
        punch.indent(0.01)
        punch.commit()
        return punch, punch.shift(0.002)

    (cp, tp), (_, ts) = run(MPI.COMM_WORLD), run(MPI.COMM_SELF)
    c = cp.contact
    # in 3D the contact zone falls on one rank: the other has no slipping node and must
    # still join the collective tangent rebuild of the springs (it hung before)
    for mask in ([] if model == "3d" else [c.stick, c.slip]):
        assert MPI.COMM_WORLD.allreduce(int(np.any(mask & c.owned)), op=MPI.MIN) == 1
    if model == "3d":  # what this case is for (coarser far fields cut the zone)
        assert MPI.COMM_WORLD.allreduce(int(np.any(c.slip & c.owned)), op=MPI.MIN) == 0
    assert tp.tangential_force == pytest.approx(ts.tangential_force, rel=1e-8)
    assert (tp.stick_nodes, tp.slip_nodes) == (ts.stick_nodes, ts.slip_nodes)


BRACKET_ON_FLOOR = ("--support", "contact", "--size", "20", "--steps", "2")


def test_bracket_on_a_rough_floor(demo):
    # f = 0 is the frictionless floor (here on the iterative path: the friction loop's inner
    # solves by CG + GAMG); at f = 0.3 the floor takes a tangential force (the bolts no
    # longer hold exactly the pull), within Coulomb's cone as a whole, and holds the base
    # back: the arm moves less (measured at 10 mm: 5.284 mm against 5.292 mm)
    free = demo.bracket(*BRACKET_ON_FLOOR)
    smooth = demo.bracket(*BRACKET_ON_FLOOR, "--friction", "0", "--linear-solver", "gamg")
    rough = demo.bracket(*BRACKET_ON_FLOOR, "--friction", "0.3")
    assert smooth["load_point_displacement"] == pytest.approx(free["load_point_displacement"],
                                                              rel=1e-9)
    assert rough["stick_nodes"] > 0 and rough["slip_nodes"] > 0
    (bx, by, bz), (fx, fy, fz) = rough["reactions"]["bolts"], rough["reactions"]["base"]
    assert bx + fx == pytest.approx(-8e3, rel=1e-8) and abs(fx) > 1e-3 * 8e3
    assert abs(by + fy) < 1e-8 * 8e3 and abs(bz + fz) < 1e-8 * 8e3
    assert 0 < rough["floor_friction_ratio"] <= 1 + 1e-9
    assert rough["load_point_displacement"] < free["load_point_displacement"]


@pytest.mark.mpi
def test_bracket_on_a_rough_floor_on_two_ranks(demo):
    rough = demo.bracket(*BRACKET_ON_FLOOR, "--friction", "0.3")
    two = demo.bracket(*BRACKET_ON_FLOOR, "--friction", "0.3", ranks=2)
    assert two["load_point_displacement"] == pytest.approx(rough["load_point_displacement"],
                                                           rel=1e-8)
    assert (two["stick_nodes"], two["slip_nodes"]) == (rough["stick_nodes"], rough["slip_nodes"])


def test_bracket_friction_needs_the_floor(demo):
    demo.refuses(["bracket.py", "--friction", "0.3"], "--support contact")

