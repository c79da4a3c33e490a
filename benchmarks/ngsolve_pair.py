"""NGSolve peer: two elastic cylinders pressed together (Hertz, plane strain), penalty contact.

Run with a Python that has NGSolve (not the project's venv), e.g.::

    python -m venv /tmp/ngvenv && /tmp/ngvenv/bin/pip install ngsolve==6.2.2608
    /tmp/ngvenv/bin/python benchmarks/ngsolve_pair.py --json out.json

The problem is the project's two-cylinder pair (tests/test_pair.py, plane strain): the upper
body is the lower half of the disc of radius R1 = 1 centred at (0, R1) (E = 3, nu = 0.2), the
lower body the upper half of the disc of radius R2 = 2 centred at (0, -R2) (E = 1,
nu = 0.35); they touch at the origin. Only the half x >= 0 is modelled: u_x = 0 on x = 0 for
both bodies; the lower body's flat bottom y = -R2 is held in y (free in x), the upper body's
equator y = R1 is pushed down by delta = 0.012 (free in x). Small-strain linear elasticity,
frictionless contact between the two arcs.

NGSolve's feature: `ContactBoundary(master, minion)`, the upper arc as master (the
integration side), the lower arc as minion. For every integration point of the master arc,
`Update` finds the closest point of the minion arc (in the reference configuration: small
strain, the pairs are fixed for the run) and adds the pair to the BilinearForm as special
elements; `.Other()` evaluates a function at the paired point. The contact energy is the
penalty one, W = k/2 <-g_n>^2, g_n = (X.Other() + u.Other() - X - u) . n (n the master's
outward normal), written with `IfPos`, next to the elastic energy in one `Variation`
BilinearForm; NGSolve's `solvers.Newton` (sparse Cholesky) minimises it. The penalty makes
the problem piecewise quadratic: Newton ends exactly when the active set settles (its
iterations are the ones reported).

The two bodies must share no vertex at the origin (they would be glued there), so the upper
body is lifted by GAP0 = 1e-6 and pushed by delta + GAP0: a rigid shift, the same deformed
state in linear elasticity.

Penalty: k = alpha E* / h_contact (E* Hertz's pair modulus), alpha = 100 by default. The
penalty is a layer of stiffness k per unit length in series with the bodies: the surfaces
interpenetrate by p/k, which widens and lowers the pressure profile. --penalty-check solves
each mesh again with 10 alpha; from alpha = 100 to 1000 (order 1 and 2, h = A_MESH/5 to
A_MESH/40) P changes by at most 1e-3 relative, a by at most 0.12 and p0 by at most 0.11
points of percentage (order 1, h = 0.005: a -0.60 % / -0.60 %, p0 +0.29 % / +0.31 %), below
the discretisation error. Smaller alphas are penalty-dominated (same mesh: alpha = 1 gives
P -1.4 %, a +1.3 %, p0 -2.5 %; alpha = 10 gives a and p0 within 0.1 %, a cancellation of the
penalty's widening against the mesh's narrowing, not accuracy). Larger ones over-constrain
the pairs (several integration points per segment each pushed to g_n = 0): the pointwise
penalty pressure k <-g_n> at x = 0 oscillates (0.042, 0.045, 0.075, 0.24 for alpha = 1e2,
1e3, 1e4, 1e5 against a nodal pressure of 0.040 there), and Newton needs more iterations
(20, 31, 27, 29), while the nodal forces stay smooth; so the pressures are read as nodal
forces.

Reported per mesh: the force P per unit length (the full contact, twice the half model's
reaction at the pushed equator), the contact half-width a and peak pressure p0 from the
ellipse p^2 = p0^2 (1 - x^2/a^2) fitted to the nodal pressures (the master arc's nodal
contact forces over their lumped lengths) of the active nodes within 85 % of the outermost
(the project's definition), their relative errors against Hertz for the computed P
(a = sqrt(4 P R / (pi E*)), p0 = 2 P / (pi a), 1/R = 1/R1 + 1/R2), k <-g_n> at x = 0 and the
nodal pressure there, Newton's iterations, the contact solve's wall time (pairing, Newton,
assembly and factorizations) and the total (geometry, meshing, spaces, solve), all on one
thread.
"""

import argparse
import json
import math
import time

import numpy as np
from netgen.meshing import MeshingParameters
from netgen.occ import ArcOfCircle, Face, Glue, OCCGeometry, Pnt, Segment, Wire
from ngsolve import (
    BND,
    CF,
    H1,
    BilinearForm,
    ContactBoundary,
    GridFunction,
    IfPos,
    InnerProduct,
    LinearForm,
    Mesh,
    SetNumThreads,
    Sym,
    Trace,
    Variation,
    VectorH1,
    __version__,
    ds,
    dx,
    grad,
    solvers,
    x,
    y,
)

R1, E1, NU1 = 1.0, 3.0, 0.2  # upper body
R2, E2, NU2 = 2.0, 1.0, 0.35  # lower body
DELTA = 0.012
A_MESH = 0.1  # the half-width the mesh is made for (the project's): h_contact = A_MESH / fine
GAP0 = 1e-6
ES = 1.0 / ((1 - NU1**2) / E1 + (1 - NU2**2) / E2)
R = 1.0 / (1.0 / R1 + 1.0 / R2)


def hertz(P):
    """Hertz's half-width and peak pressure of two cylinders under P per unit length."""
    a = math.sqrt(4 * P * R / (math.pi * ES))
    return a, 2 * P / (math.pi * a)


def arc_y(radius, s, upper):
    """The height of the upper (lower) arc at x = s."""
    sag = radius - math.sqrt(radius**2 - s**2)
    return GAP0 + sag if upper else -sag


def quarter_disc(radius, upper, tag, h):
    """The body's half x >= 0: arc (split at 1.5 A_MESH, fine before), flat side, axis."""
    yc = GAP0 + radius if upper else -radius
    xs, s = 1.5 * A_MESH, math.sin(math.radians(60)) * radius
    pts = [Pnt(u, arc_y(radius, u, upper), 0) for u in (0.0, xs / 2, xs, s)]
    end, centre = Pnt(radius, yc, 0), Pnt(0, yc, 0)
    face = Face(Wire([ArcOfCircle(pts[0], pts[1], pts[2]), ArcOfCircle(pts[2], pts[3], end),
                      Segment(end, centre), Segment(centre, pts[0])]))
    face.name = tag
    for edge in face.edges:
        cx, cy = edge.center.x, edge.center.y
        edge.name = ("axis" if abs(cx) < 1e-12 else "flat" if abs(cy - yc) < 1e-12
                     else "arc") + tag
        if edge.name.startswith("arc") and cx < xs:
            edge.maxh = h
    return face


def make_mesh(h, order):
    """Both bodies, h within 1.5 A_MESH of the origin, then growing by 0.05 a unit length.

    The project's grading (fenics_nl.domain.two_bodies): the size is restricted on rings
    around the origin, netgen's grading does the rest.
    """
    mp = MeshingParameters(maxh=0.25)
    r = 0.0
    while r < R2:
        hr = h + 0.05 * max(0.0, r - 1.5 * A_MESH)
        for t in np.linspace(0, math.pi, max(2, int(math.pi * r / hr) + 1)):
            mp.RestrictH(x=r * math.sin(t), y=r * math.cos(t), z=0, h=hr)
        r += hr
    shape = Glue([quarter_disc(R1, True, "up", h), quarter_disc(R2, False, "lo", h)])
    mesh = Mesh(OCCGeometry(shape, dim=2).GenerateMesh(mp))
    if order > 1:
        mesh.Curve(order)
    return mesh


def elastic_energy(u, mesh):
    E = mesh.MaterialCF({"up": E1, "lo": E2})
    nu = mesh.MaterialCF({"up": NU1, "lo": NU2})
    mu, lam = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    eps = Sym(grad(u))
    return mu * InnerProduct(eps, eps) + lam / 2 * Trace(eps) ** 2


def solve(mesh, order, h, alpha):
    """The contact solve on `mesh`: P, a, p0, their errors, Newton's iterations, times."""
    k = alpha * ES / h
    fes = VectorH1(mesh, order=order, dirichletx="axisup|axislo", dirichlety="flatup|flatlo")
    u = fes.TrialFunction()
    elastic = BilinearForm(fes, symmetric=True)
    elastic += Variation(elastic_energy(u, mesh) * dx)
    a = BilinearForm(fes, symmetric=True)
    a += Variation(elastic_energy(u, mesh) * dx)
    contact = ContactBoundary(mesh.Boundaries("arcup"), mesh.Boundaries("arclo"))
    X = CF((x, y))
    gn = (X.Other() + u.Other() - X - u) * contact.normal
    contact.AddEnergy(IfPos(-gn, k / 2 * gn * gn, 0))
    gfu = GridFunction(fes)

    t0 = time.perf_counter()
    contact.Update(gfu, a, intorder=2 * order + 4, maxdist=3 * A_MESH)
    gfu.Set(CF((0, -(DELTA + GAP0))), definedon=mesh.Boundaries("flatup"))
    status, its = solvers.Newton(a, gfu, freedofs=fes.FreeDofs(), maxit=100, maxerr=1e-11,
                                 inverse="sparsecholesky", printing=False)
    solve_time = time.perf_counter() - t0
    if status != 0:
        raise RuntimeError(f"Newton did not converge in {its} iterations")

    # the internal forces: the reactions on held dofs, the contact forces on the arcs' nodes
    f = gfu.vec.CreateVector()
    elastic.Apply(gfu.vec, f)
    top = GridFunction(fes)
    top.Set(CF((0, 1)), definedon=mesh.Boundaries("flatup"))
    force = -2 * InnerProduct(f, top.vec)  # both halves
    x_nodes, p_nodes = nodal_pressures(mesh, fes, f)
    active = p_nodes > 1e-8 * p_nodes.max()  # above round-off
    inside = active & (x_nodes <= 0.85 * x_nodes[active].max())
    slope, intercept = np.polyfit(x_nodes[inside] ** 2, p_nodes[inside] ** 2, 1)
    p0_fit, a_fit = math.sqrt(intercept), math.sqrt(-intercept / slope)
    up, lo = gfu(mesh(0, GAP0)), gfu(mesh(0, 0))
    p_axis = k * max(0.0, -(GAP0 + up[1] - lo[1]))  # k <-g_n> at x = 0
    a_ref, p0_ref = hertz(force)
    return {"dofs": fes.ndof, "order": order, "penalty": k, "alpha": alpha, "force": force,
            "contact_half_width": a_fit, "max_pressure": p0_fit,
            "a_error": a_fit / a_ref - 1, "p0_error": p0_fit / p0_ref - 1,
            "hertz_half_width": a_ref, "hertz_max_pressure": p0_ref,
            "outermost_active_node": float(x_nodes[active].max()),
            "nodes_in_contact": int(active.sum()),
            "penalty_pressure_at_axis": p_axis, "nodal_pressure_at_axis": float(p_nodes[0]),
            "newton_iterations": its, "solve_time_s": solve_time}


def nodal_pressures(mesh, fes, f):
    """The master arc's vertices (x sorted) and pressures: -f . n over the lumped length."""
    scalar = H1(mesh, order=1)
    length = LinearForm(scalar)
    length += scalar.TestFunction() * ds("arcup")
    length.Assemble()
    nodes = sorted({v.nr for el in mesh.Elements(BND) if
                    el.mat == "arcup" for v in el.vertices})
    ny = fes.ndof // 2  # VectorH1: the x dofs, then the y dofs (vertices first in each)
    xs, ps = [], []
    for v in nodes:
        px, py = mesh.vertices[v].point
        n = np.array([px, py - GAP0 - R1]) / R1  # outward normal of the upper arc
        ps.append(-(f[v] * n[0] + f[ny + v] * n[1]) / length.vec[v])
        xs.append(px)
    order = np.argsort(xs)
    return np.array(xs)[order], np.array(ps)[order]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fine", type=float, nargs="+", default=[5, 10, 20, 40],
                        help="A_MESH / h_contact of the meshes (default 5 10 20 40)")
    parser.add_argument("--order", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--alpha", type=float, default=100.0,
                        help="penalty k = alpha E* / h_contact (default 100)")
    parser.add_argument("--penalty-check", action="store_true",
                        help="also solve each mesh with 10 alpha")
    parser.add_argument("--json", help="write the runs there")
    args = parser.parse_args()
    SetNumThreads(1)
    runs = []
    for order in args.order:
        for fine in args.fine:
            h = A_MESH / fine
            for alpha in [args.alpha, 10 * args.alpha] if args.penalty_check else [args.alpha]:
                t0 = time.perf_counter()
                mesh = make_mesh(h, order)
                run = {"h_contact": h, **solve(mesh, order, h, alpha)}
                run["total_time_s"] = time.perf_counter() - t0
                runs.append(run)
                print(f"order {order} h {h:.5f} alpha {alpha:g} dofs {run['dofs']:6d} "
                      f"P {run['force']:.6f} a {run['contact_half_width']:.5f} "
                      f"({run['a_error']:+.2%}) p0 {run['max_pressure']:.5f} "
                      f"({run['p0_error']:+.2%}) Newton {run['newton_iterations']:2d} "
                      f"solve {run['solve_time_s']:.2f} s total {run['total_time_s']:.2f} s",
                      flush=True)
    if args.json:
        method = ("NGSolve ContactBoundary (closest-point pairs on the master arc's "
                  "integration points, .Other()), penalty energy k/2 <-g_n>^2 with IfPos, "
                  "k = alpha E*/h_contact, solvers.Newton (sparsecholesky), VectorH1")
        with open(args.json, "w") as out:
            json.dump({"peer": f"NGSolve {__version__}", "method": method, "runs": runs},
                      out, indent=1)


if __name__ == "__main__":
    main()
