# # Rigid spherical punch on an elastic block: Hertz contact by the active-set method
#
# A rigid sphere of radius $R$ is pressed by $\delta$ into an elastic block (frictionless).
# The contact zone is unknown: the course's active-set algorithm finds it. Hertz's theory
# gives the answer for a half-space and a parabolic gap, which this demo checks.
#
# ## Problem definition
#
# On the top surface $S_C$ (outward normal $n = e_z$) the gap to the punch is
# $\gamma(r) = r^2/(2R) - \delta$, and
#
# $$ u_n - \gamma \le 0, \qquad T_n \le 0, \qquad (u_n - \gamma)\, T_n = 0 .$$
#
# Iteration $k$ solves linear elasticity with $u_n = \gamma$ on the active nodes and $T = 0$
# elsewhere; an active node in tension ($T_n > 0$) leaves, an inactive node that penetrates
# ($u_n - \gamma > 0$) joins; the set converges when nothing changes. Hertz, with
# $E^* = E/(1-\nu^2)$:
#
# $$ a = \sqrt{R\delta}, \qquad P = \tfrac43 E^* \sqrt{R}\, \delta^{3/2}, \qquad
#    p_0 = \frac{3P}{2\pi a^2}, \qquad p(r) = p_0\sqrt{1 - r^2/a^2}. $$
#
# In plane strain the punch is a cylinder and $\delta$ is not defined by Hertz (it depends
# on the block), so the half-width $a = \sqrt{4PR/(\pi E^*)}$ and $p_0 = 2P/(\pi a)$ are
# checked against the computed force per unit length $P$.
#
# The block must behave like a half-space: it is 1000 contact radii wide and deep (300 in
# 3D), with elements of a/40 under the punch growing by 5 % of the distance away from it;
# on the axisymmetric model this keeps the block-size and far-field error near 0.15 %,
# below the 0.5 % asked of the force (the sizes are measured in `fenics_nl/punch.py`).
#
# ## Implementation

# +
import argparse
import json
import math
import sys
import time
from pathlib import Path

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
from mpi4py import MPI

from fenics_nl import hertz
from fenics_nl.cli import parse_with_petsc_options
from fenics_nl.contact import ContactError
from fenics_nl.materials import LinearElastic, PowerLaw
from fenics_nl.newton import ConvergenceError
from fenics_nl.punch import Punch

comm = MPI.COMM_WORLD


def say(*args):
    if comm.rank == 0:
        print(*args, flush=True)
# -


def parse_args(argv=None):
    p = argparse.ArgumentParser(
        description="Rigid spherical punch on an elastic block (Hertz contact, active set).",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
        epilog="PETSc options (-ksp_view, ...) are passed through.")
    p.add_argument("--model", choices=["axisymmetric", "3d", "plane-strain"],
                   default="axisymmetric", help="axisymmetric (r,z), 3D quarter, plane strain")
    p.add_argument("--E", type=float, default=1.0, help="Young's modulus [Pa]")
    p.add_argument("--nu", type=float, default=0.3, help="Poisson's ratio [-]")
    p.add_argument("--radius", type=float, default=1.0, help="punch radius R [m]")
    load = p.add_mutually_exclusive_group()
    load.add_argument("--indentation", type=float, default=None,
                      help="displacement control: indentation δ [m] (default 0.01 R)")
    load.add_argument("--force", type=float, default=None,
                      help="force control: total force P [N] (per unit length in plane strain)")
    p.add_argument("--steps", type=int, default=1, help="load steps from 0 to the load")
    p.add_argument("--formulation", choices=["elimination", "multiplier"], default="elimination",
                   help="active normal displacements as Dirichlet rows, or Lagrange multipliers")
    p.add_argument("--gap", choices=["parabola", "sphere"], default="parabola",
                   help="punch shape: Hertz's parabola or the exact sphere")
    p.add_argument("--material", choices=["linear", "power-law"], default="linear",
                   help="linear elastic (Hertz applies), or the power law (Newton inside)")
    p.add_argument("--sigma0", type=float, default=0.01,
                   help="power law: stress where it turns non-linear [Pa]")
    p.add_argument("--n", type=float, default=0.3, help="power law exponent [-]")
    p.add_argument("--refine", type=int, default=1,
                   help="element size under the punch a/(20·2^refine) (3D: a/(6·2^refine))")
    p.add_argument("--block", type=float, default=None,
                   help="block size in contact radii (default 1000, 3D 100)")
    p.add_argument("--json", metavar="PATH", help="write the quantities of interest as JSON")
    p.add_argument("--output", metavar="DIR", help="write displacement and active set (XDMF)")
    p.add_argument("--png", metavar="PATH", help="picture of the deformed contact zone")
    p.add_argument("--plot", metavar="PATH", help="force-indentation and pressure against Hertz")
    args, petsc_args = parse_with_petsc_options(p, argv)
    if args.steps < 1:
        p.error(f"--steps must be >= 1, got {args.steps}")
    if args.force is not None and args.force <= 0:
        p.error(f"--force must be > 0, got {args.force}")
    return args, petsc_args


def main(argv=None) -> int:
    args, petsc_args = parse_args(argv)
    from petsc4py import PETSc

    PETSc.Options().insertString(" ".join(petsc_args))
    t0 = time.perf_counter()
    try:
        material = (LinearElastic(args.E, args.nu) if args.material == "linear"
                    else PowerLaw(args.E, args.nu, sigma0=args.sigma0, n=args.n))
        if not args.radius > 0:
            raise ValueError(f"radius must be > 0, got {args.radius}")
        out = run(args, material)
    except (ValueError, ContactError, ConvergenceError, RuntimeError) as err:
        if comm.rank == 0:
            print(f"error: {err}", file=sys.stderr)
        return 2
    out["wall_time_s"] = time.perf_counter() - t0
    say(f"wall time {out['wall_time_s']:.2f} s on {comm.size} rank(s)")
    if args.json and comm.rank == 0:
        Path(args.json).write_text(json.dumps(out, indent=2))
    return 0


# The scene: the contact radius expected from the load sets the mesh (Hertz's a for a
# sphere; for the cylinder √(Rδ) is a safe overestimate of the half-width).

def expected_radius(args):
    E, nu, R = args.E, args.nu, args.radius
    if args.force is not None:
        if args.model == "plane-strain":
            return hertz.cylinder_from_force(E, nu, R, args.force)["contact_radius"]
        return hertz.sphere_from_force(E, nu, R, args.force)["contact_radius"]
    return math.sqrt(R * abs(args.indentation))


def run(args, material):
    if args.indentation is None and args.force is None:
        args.indentation = 0.01 * args.radius
    if args.indentation is not None and args.indentation == 0:
        raise ValueError("indentation must be non-zero (negative: the punch stays clear)")
    a = expected_radius(args)
    block = args.block or (100.0 if args.model == "3d" else 1000.0)
    punch = Punch(args.model, material, args.radius, a, refine=args.refine, block=block,
                  formulation=args.formulation, gap=args.gap)
    say(f"{args.model} punch, {args.formulation}, {punch.dofs} unknowns, h = {punch.h:.3g}, "
        f"block {block:g} a")

    # Load steps: δ (or P) grows linearly; each step starts from the last active set.
    # +
    states = []
    for k in range(1, args.steps + 1):
        t = k / args.steps
        if args.force is not None:
            guess = states[-1].indentation * t ** (2 / 3) / ((k - 1) / args.steps) ** (2 / 3) \
                if states else a * a / args.radius * t ** (2 / 3)
            s, _ = punch.push(t * args.force, guess)
        else:
            s = punch.indent(t * args.indentation)
        states.append(s)
        say(f"step {k}/{args.steps}: δ = {s.indentation:.5g}, P = {s.force:.6g}, "
            f"a = {s.contact_radius:.5g}, p0 = {s.max_pressure:.5g}, "
            f"{s.active_set_iterations} active-set iterations")
    # -

    last = states[-1]
    if last.force == 0.0:
        say("the punch does not touch the block: zero contact force")
    ref = punch.hertz(last) if last.force > 0 else {"force": 0.0, "contact_radius": 0.0,
                                                     "max_pressure": 0.0}

    def rel(x, y):
        return (x - y) / y if y else (0.0 if x == y else None)

    out = {
        "model": args.model, "formulation": args.formulation, "material": args.material,
        "force": last.force, "indentation": last.indentation,
        "contact_radius": last.contact_radius, "max_pressure": last.max_pressure,
        "hertz_force": ref["force"], "hertz_contact_radius": ref["contact_radius"],
        "hertz_max_pressure": ref["max_pressure"],
        "force_rel_error": rel(last.force, ref["force"]),
        "contact_radius_rel_error": rel(last.contact_radius, ref["contact_radius"]),
        "max_pressure_rel_error": rel(last.max_pressure, ref["max_pressure"]),
        "element_size": punch.h,
        "active_set_iterations": sum(s.active_set_iterations for s in states),
        "newton_iterations": sum(s.newton_iterations for s in states),
        "factorizations": sum(s.factorizations for s in states),
        "steps": [{"indentation": s.indentation, "force": s.force,
                   "contact_radius": s.contact_radius,
                   "active_set_iterations": s.active_set_iterations} for s in states],
        "dofs": punch.dofs, "ranks": comm.size,
    }
    if len(states) >= 2 and all(s.force > 0 for s in states):
        d = np.log([s.indentation for s in states])
        f = np.log([s.force for s in states])
        out["fitted_exponent"] = float(np.polyfit(d, f, 1)[0])
        say(f"P ∝ δ^{out['fitted_exponent']:.4f} over the steps (Hertz: 1.5)")
    if ref["force"] > 0:
        err = 100 * out["force_rel_error"]
        say(f"force {last.force:.6g} (Hertz {ref['force']:.6g}, {err:+.3f} %)"
            f"; radius {last.contact_radius:.5g} (Hertz {ref['contact_radius']:.5g}, h = "
            f"{punch.h:.2g}); p0 {last.max_pressure:.5g} (Hertz {ref['max_pressure']:.5g}, "
            f"{100 * out['max_pressure_rel_error']:+.2f} %)")
    if args.output:
        write_fields(punch, args.output)
    if args.plot:
        plot(punch, states, ref, args)
    if args.png:
        picture(punch, last, args.png)
    return out


def write_fields(punch, folder):
    from dolfinx.io import XDMFFile

    Path(folder).mkdir(parents=True, exist_ok=True)
    path = Path(folder) / "punch.xdmf"
    with XDMFFile(comm, path, "w") as f:
        f.write_mesh(punch.mesh)
        f.write_function(punch.u)
        f.write_meshtags(punch.contact.active_facets(), punch.mesh.geometry)
    say(f"wrote {path} (displacement, active facets: open in ParaView)")


def _gather_surface(punch):
    """(r, p) of every S_C node, gathered on rank 0 and sorted by r."""
    c = punch.contact
    owned = c._owned()
    r = punch._radius(c.x[owned].T)
    p = c.pressure(punch.weight)[owned]
    parts = comm.gather((r, p), root=0)
    if comm.rank != 0:
        return None, None
    r = np.concatenate([x[0] for x in parts])
    p = np.concatenate([x[1] for x in parts])
    order = np.argsort(r)
    return r[order], p[order]


def plot(punch, states, ref, args):
    r, p = _gather_surface(punch)
    if comm.rank != 0:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    d = np.array([0.0] + [s.indentation for s in states])
    P = np.array([0.0] + [s.force for s in states])
    ax1.plot(d, P, "o", label="active set (FE)")
    if args.model != "plane-strain":
        dd = np.linspace(0, d.max(), 100)
        Es = args.E / (1 - args.nu**2)
        ax1.plot(dd, 4 / 3 * Es * np.sqrt(args.radius) * dd**1.5, "-", label="Hertz")
    ax1.set_xlabel("indentation δ [m]")
    ax1.set_ylabel("force P [N]" + (" per m" if args.model == "plane-strain" else ""))
    ax1.legend()
    ax1.grid(alpha=0.3)
    a = ref["contact_radius"]
    ax2.plot(r / a, p / ref["max_pressure"], "o", ms=3, label="nodal pressure (FE)")
    rr = np.linspace(0, 1.5, 300)
    ax2.plot(rr, hertz.pressure_profile(1.0, 1.0, rr), "-", label="Hertz")
    ax2.set_xlim(0, 1.5)
    ax2.set_xlabel("r / a (Hertz)")
    ax2.set_ylabel("p / p0 (Hertz)")
    ax2.legend()
    ax2.grid(alpha=0.3)
    fig.suptitle(f"{args.model} punch, {states[-1].force:.4g} N, "
                 f"error {100 * (states[-1].force / ref['force'] - 1):+.2f} % on P")
    fig.tight_layout()
    fig.savefig(args.plot, dpi=120)
    print(f"wrote {args.plot}")


def picture(punch, state, path):
    """Vertical displacement near the contact, deformed (exaggerated), with the punch."""
    import pyvista
    from dolfinx import plot as dplot

    pyvista.OFF_SCREEN = True
    V = punch.u.function_space
    topology, cells, x = dplot.vtk_mesh(V)
    grid = pyvista.UnstructuredGrid(topology, cells, x)
    dim = punch.mesh.geometry.dim
    u = punch.u.x.array.reshape(-1, dim)
    vec = np.zeros((len(x), 3))
    vec[:, :dim] = u
    grid.point_data["u_z"] = u[:, dim - 1]
    a = max(state.contact_radius, punch.h)
    scale = 0.6 * a / max(abs(u[:, dim - 1]).max(), 1e-300)  # the dent: 0.6 a deep on screen
    grid.point_data["vec"] = vec
    warped = grid.warp_by_vector("vec", factor=scale)
    box = [0, 3 * a, -3 * a, 0, -1, 1] if dim == 2 else [0, 3 * a, 0, 3 * a, -3 * a, 0]
    clipped = warped.clip_box(box, invert=False)
    if comm.size > 1:
        say("--png draws rank 0's part only under MPI")
    pl = pyvista.Plotter(off_screen=True, window_size=(1000, 800))
    pl.add_mesh(clipped, scalars="u_z", show_edges=True, edge_color="gray", line_width=0.3,
                cmap="viridis", scalar_bar_args={"title": "u_z [m]", "vertical": True,
                                                 "position_x": 0.85, "position_y": 0.2})
    if dim == 2:
        r = np.linspace(0, 3 * a, 400)
        z = (r**2 / (2 * punch.R) - state.indentation) * scale
        r, z = r[z < 0.5 * a], z[z < 0.5 * a]
        pl.add_lines(np.column_stack([r, z, np.full_like(r, 0.01)]), color="red", width=3,
                     connected=True)
        pl.view_xy()
    else:
        pl.view_isometric()
    pl.add_text(f"{punch.model} punch (red), displacement x{scale:.3g}; "
                f"contact radius {state.contact_radius:.3g} m", font_size=10)
    pl.screenshot(path)
    say(f"wrote {path}")


if __name__ == "__main__":
    sys.exit(main())
