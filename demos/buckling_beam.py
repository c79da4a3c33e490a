# # Buckling of a compressed cantilever: Euler's load and the elastica
#
# A slender beam (length $L$, height $h$), clamped at $x = 0$, carries a dead compressive
# load $P$ at its free end. Finite strain (St Venant–Kirchhoff in the Green–Lagrange strain,
# as in the course's practical). First the linear buckling load, then the post-buckling
# path, both checked against closed forms.
#
# ## Problem definition
#
# Linear buckling around the pre-stressed straight state: $(K + \lambda K_G)\,\varphi = 0$,
# $K_G$ the geometric stiffness of the stress of a unit load, solved by SLEPc
# (shift-and-invert). Euler: $P_{cr} = \pi^2 E I / (4 L^2)$, $I = h^3/12$ (plane stress;
# $E/(1-\nu^2)$ in plane strain).
#
# Post-buckling: load steps from 0 to $P = r P_{cr}$, a Newton solve per step, a small
# lateral end load $\varepsilon P$ ($\varepsilon = 10^{-4}$) as imperfection. The elastica
# (inextensible, tip rotation $\alpha$, $k = \sin(\alpha/2)$):
#
# $$ P/P_{cr} = (2K(k)/\pi)^2, \qquad \delta/L = 2k/K(k), \qquad x/L = 2E(k)/K(k) - 1 .$$
#
# Past $P_{cr}$ the straight beam is still an equilibrium, but an unstable one: Newton can
# settle on it. The steps therefore never grow beyond $1/n$ of the load, and the end state is
# checked for stability (the tangent's eigenvalue nearest 0, by SLEPc); an unstable end
# state is pushed along its unstable mode, scaled to the elastica's deflection, and solved
# again (branch switching), or the run stops with a clear message.
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

from fenics_nl import elastica
from fenics_nl.beam import Beam
from fenics_nl.cli import parse_with_petsc_options
from fenics_nl.loading import LoadStepError
from fenics_nl.newton import ConvergenceError

comm = MPI.COMM_WORLD


def say(*args):
    if comm.rank == 0:
        print(*args, flush=True)
# -


def parse_args(argv=None):
    p = argparse.ArgumentParser(
        description="Buckling of a compressed cantilever: SLEPc critical load and the "
                    "post-buckling path against the elastica.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
        epilog="PETSc options (-ksp_view, -buckling_eps_view, ...) are passed through.")
    p.add_argument("--length", type=float, default=1.0, help="beam length L [m]")
    p.add_argument("--thickness", type=float, default=0.02, help="beam height h [m]")
    p.add_argument("--E", type=float, default=1e3, help="Young's modulus [Pa]")
    p.add_argument("--nu", type=float, default=0.3, help="Poisson's ratio [-]")
    p.add_argument("--plane", choices=["stress", "strain"], default="stress",
                   help="plane stress or plane strain (unit width)")
    p.add_argument("--material", choices=["svk", "neo-hookean"], default="svk",
                   help="St Venant-Kirchhoff or compressible neo-Hookean (plane strain)")
    p.add_argument("--load-ratio", type=float, default=1.5, help="final load P / P_cr (Euler)")
    p.add_argument("--steps", type=int, default=40,
                   help="load steps (the largest step; cut in half on failure)")
    p.add_argument("--newton", choices=["full", "modified", "periodic", "bfgs"], default="full",
                   help="Newton variant of each load step")
    p.add_argument("--imperfection", type=float, default=1e-4,
                   help="lateral end load as a fraction of P [-]")
    p.add_argument("--refine", type=int, default=0,
                   help="mesh: 2·2^refine Q2 elements through the height, square elements")
    p.add_argument("--json", metavar="PATH", help="write the quantities of interest as JSON")
    p.add_argument("--output", metavar="DIR", help="write the final displacement (XDMF)")
    p.add_argument("--png", metavar="PATH", help="deformed shapes along the load path")
    p.add_argument("--plot", metavar="PATH", help="P/P_cr against tip rotation and deflection")
    args, petsc_args = parse_with_petsc_options(p, argv)
    if args.steps < 1:
        p.error(f"--steps must be >= 1, got {args.steps}")
    if not 0 < args.load_ratio <= 20:
        p.error(f"--load-ratio must be in (0, 20], got {args.load_ratio}")
    if not 0 <= args.imperfection < 0.1:
        p.error(f"--imperfection must be in [0, 0.1), got {args.imperfection}")
    return args, petsc_args


def main(argv=None) -> int:
    args, petsc_args = parse_args(argv)
    from petsc4py import PETSc

    PETSc.Options().insertString(" ".join(petsc_args))
    t0 = time.perf_counter()
    try:
        out = run(args)
    except (ValueError, ConvergenceError, LoadStepError, RuntimeError) as err:
        if comm.rank == 0:
            print(f"error: {err}", file=sys.stderr)
        return 2
    out["wall_time_s"] = time.perf_counter() - t0
    say(f"wall time {out['wall_time_s']:.2f} s on {comm.size} rank(s)")
    if args.json and comm.rank == 0:
        Path(args.json).write_text(json.dumps(out, indent=2))
    return 0


def run(args):
    beam = Beam(args.length, args.thickness, args.E, args.nu, material=args.material,
                plane=args.plane, refine=args.refine, imperfection=args.imperfection)
    say(f"beam L/h = {args.length / args.thickness:g}, {beam.dofs} unknowns, "
        f"{args.material}, plane {args.plane}")

    # Linear buckling (SLEPc) against Euler.
    # +
    loads, _ = beam.critical_loads(3)
    P_cr = loads[0]
    say(f"critical loads (SLEPc): {', '.join(f'{x:.6g}' for x in loads)}; Euler "
        f"{beam.P_euler:.6g} ({100 * (P_cr / beam.P_euler - 1):+.3f} %)")
    # -

    # Post-buckling path: load steps to r·P_Euler (never larger than 1/n, cut on failure),
    # then the stability check of the end state and, if needed, branch switching.
    # +
    history, shapes = [(0.0, 0.0, 0.0, 0.0)], []

    def record(t, result):
        r = t * args.load_ratio
        # a redone path, or the branch-switched end state, replaces what it passes again
        while len(history) > 1 and history[-1][0] >= r:
            history.pop()
        while shapes and shapes[-1][0] >= r:
            shapes.pop()
        tip = beam.tip()
        history.append((r, math.degrees(abs(tip["rotation"])), abs(tip["lateral"]),
                        tip["axial"]))
        if args.png:
            shapes.append((r, centreline(beam)))

    path, switched = beam.solve_path(args.load_ratio, args.steps, args.newton,
                                     on_step=record, progress=lambda m: say("  " + m))
    # -

    tip = beam.tip()
    alpha = math.degrees(abs(tip["rotation"]))
    alpha_el = math.degrees(elastica.tip_rotation(args.load_ratio))
    d_el, x_el = elastica.tip_position(args.load_ratio)
    say(f"P/P_cr = {args.load_ratio:g}: tip rotation {alpha:.3f} deg (elastica "
        f"{alpha_el:.3f}), lateral deflection {abs(tip['lateral']):.5g} (elastica "
        f"{d_el * args.length:.5g}), axial displacement {tip['axial']:.5g} (elastica "
        f"{(x_el - 1) * args.length:.5g}); {len(path.factors)} steps, "
        f"{path.iterations} Newton iterations, {path.failures} step cuts")
    out = {
        "critical_load": P_cr, "critical_loads": loads, "euler_critical_load": beam.P_euler,
        "critical_load_rel_error": P_cr / beam.P_euler - 1, "load_ratio": args.load_ratio,
        "tip_rotation_deg": alpha, "tip_deflection": abs(tip["lateral"]),
        "tip_axial_displacement": tip["axial"], "elastica_tip_rotation_deg": alpha_el,
        "elastica_tip_deflection": d_el * args.length,
        "elastica_tip_axial_displacement": (x_el - 1) * args.length,
        "load_steps": len(path.factors), "step_cuts": path.failures,
        "newton_iterations": sum(r.iterations for r in path.results),
        "factorizations": path.work.factorizations, "branch_switched": switched,
        "newton": args.newton, "dofs": beam.dofs, "ranks": comm.size,
        "path": [{"load_ratio": h[0], "tip_rotation_deg": h[1], "tip_deflection": h[2]}
                 for h in history],
    }
    if args.output:
        from dolfinx.io import XDMFFile

        Path(args.output).mkdir(parents=True, exist_ok=True)
        with XDMFFile(comm, Path(args.output) / "beam.xdmf", "w") as f:
            f.write_mesh(beam.mesh)
            f.write_function(beam.u)
        say(f"wrote {Path(args.output) / 'beam.xdmf'}")
    if args.plot and comm.rank == 0:
        plot(history, args)
    if args.png:
        picture(shapes, args)
    return out


def centreline(beam):
    """Deformed centreline points (x + u) of this rank's dofs on y = 0, sorted by x."""
    X = beam.V.tabulate_dof_coordinates()
    on = np.isclose(X[:, 1], 0.0)
    u = beam.u.x.array.reshape(-1, 2)[on]
    pts = X[on, :2] + u
    parts = comm.gather((X[on, 0], pts), root=0)
    if comm.rank != 0:
        return None
    x0 = np.concatenate([p[0] for p in parts])
    pts = np.concatenate([p[1] for p in parts])
    return pts[np.argsort(x0)]


def plot(history, args):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    h = np.array(history)
    alpha = np.linspace(1e-3, math.radians(min(170, 2 * max(h[:, 1].max(), 10))), 300)
    ratio = np.array([elastica.load_ratio(a) for a in alpha])
    k = np.sin(alpha / 2)
    from scipy.special import ellipk

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    a1.plot(np.degrees(alpha), ratio, "-", label="elastica")
    a1.plot(h[:, 1], h[:, 0], "o", ms=3, label="finite strain FE")
    a1.set_xlabel("tip rotation α [deg]")
    a1.set_ylabel("P / P_cr")
    a2.plot(2 * k / ellipk(k * k) * args.length, ratio, "-", label="elastica")
    a2.plot(h[:, 2], h[:, 0], "o", ms=3, label="finite strain FE")
    a2.set_xlabel("lateral tip deflection [m]")
    for a in (a1, a2):
        a.axhline(1.0, color="gray", lw=0.5)
        a.set_ylim(0, max(h[:, 0].max(), 1.1) * 1.05)
        a.grid(alpha=0.3)
        a.legend()
    fig.suptitle(f"cantilever, L/h = {args.length / args.thickness:g}, "
                 f"imperfection {args.imperfection:g} P")
    fig.tight_layout()
    fig.savefig(args.plot, dpi=120)
    print(f"wrote {args.plot}")


def picture(shapes, args):
    if comm.rank != 0:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 6))
    ax.plot([0, args.length], [0, 0], "k--", lw=0.8, label="undeformed")
    picks = shapes[:: max(1, len(shapes) // 8)] + shapes[-1:]
    cmap = plt.get_cmap("viridis")
    top = max(s[0] for s in picks)
    for r, pts in picks:
        ax.plot(pts[:, 0], pts[:, 1], color=cmap(r / top), label=f"P/P_cr = {r:.2f}")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.png, dpi=120)
    print(f"wrote {args.png}")


if __name__ == "__main__":
    sys.exit(main())
