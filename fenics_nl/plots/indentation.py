"""Pictures of a rigid punch pressed into a block, against Hertz and Cattaneo–Mindlin.

The force–indentation curve, the deformed contact zone in section, and the contact
pressure (or, with friction, the tangential traction) along the surface. They read plain
values (`PunchRun`): the converged states, the surface profile and the section gathered on
rank 0 (`ContactSurface.gathered`, `output.section`), the punch's shape as a function.
`curves` and `section_picture` draw on rank 0, the whole load path on the curve (loading,
and an unloading after it) and the drawn state on the rest: a run that is unloaded is drawn
at its largest load.

And two deformable bodies in contact (`pair_curves`: the contact half-width and peak
pressure against the force, and the pressure around the arc, against Hertz for the pair).

And the identification's picture (`identification_figure`): the measured and identified
curves, the course's figure, beside the misfit over (σ0, H) with the fit's iterates on it,
which shows how the fit got there (`misfit_grid` runs the model on a grid).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from mpi4py import MPI

from fenics_nl.errors import SolveError
from fenics_nl.plots import figures
from fenics_nl.theory import hertz, mindlin

__all__ = ["PunchRun", "curves", "identification_figure", "misfit_grid", "pair_curves",
           "section_picture"]


@dataclass
class PunchRun:
    """What the pictures read of a punch run: plain values, gathered on rank 0.

    Args:
        model: ``axisymmetric``, ``3d`` or ``plane_strain``.
        states: the converged load steps (records with `indentation`, `force`,
            `contact_radius`, `max_pressure`), loading then unloading; the last is drawn.
        ref: Hertz's values for the drawn state (None: no contact).
        E, nu, radius: the material and the punch radius.
        rank0: this rank draws (the others pass None profiles).
        profile: (r, p, active) of the surface nodes sorted by r, the drawn state's.
        section: `output.section` of the drawn state (σ_eq per cell), for `section_picture`.
        gap_at: γ(r, δ), the punch's height above the surface at r less δ.
        h: the element size under the punch (the zoom's smallest window).
        tangential: the block spans both sides of the punch (a tangential load).
        mixed: Taylor–Hood elements (for the title).
        force_controlled: the force was prescribed (the check is then on δ).
        friction: Coulomb's f, or None.
        traction: the tangential load's `Traction` record, or None.
        traction_profile: its gathered profile (`Punch.traction_profile`, or in 3D the
            radii and the force inside each), computed on every rank.
        stick_radius_exact: Cattaneo–Mindlin's c for the computed load, if known.
        loading_steps: the states that load the punch (those after it unload it).
        plastic: the block flows (J2): Hertz is the elastic reference, not a check.
    """

    model: str
    states: list
    ref: dict | None
    E: float
    nu: float
    radius: float
    rank0: bool
    profile: tuple | None
    section: tuple | None = None
    gap_at: Callable | None = None
    h: float = 0.0
    tangential: bool = False
    mixed: bool = False
    force_controlled: bool = False
    friction: float | None = None
    traction: object = None
    traction_profile: tuple | None = None
    stick_radius_exact: float | None = None
    loading_steps: int | None = None
    plastic: bool = False
    state: object = field(init=False)  # the drawn state: the last one given

    def __post_init__(self):
        self.state = self.states[-1]


def curves(run: PunchRun, path: str) -> None:
    """P(δ) of every step against Hertz, beside the pressure (or traction) panel."""
    if not run.rank0:
        return
    plt = figures.pyplot()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    n = len(run.states) if run.loading_steps is None else run.loading_steps
    d = np.array([0.0] + [s.indentation for s in run.states])
    P = np.array([0.0] + [s.force for s in run.states])
    ax1.plot(d[: n + 1], P[: n + 1], "o-", label="active set (FE)" + (", loading" if
                                                                      n < len(d) - 1 else ""))
    if n < len(d) - 1:
        ax1.plot(d[n:], P[n:], "s--", color="C2", label="unloading")
    if run.model != "plane_strain":
        dd = np.linspace(0, d.max(), 100)
        Es = hertz.effective_modulus(run.E, run.nu)
        ax1.plot(dd, 4 / 3 * Es * np.sqrt(run.radius) * dd**1.5, "-", label="Hertz")
    ax1.set_xlabel("indentation δ [length]")
    ax1.set_ylabel("force P [force]" + (" per unit length" if run.model == "plane_strain"
                                        else ""))
    ax1.legend()
    ax1.grid(alpha=0.3)
    _right_panel(ax2, run, run.profile, run.state)
    fig.suptitle(title(run, run.state))
    figures.save_figure(fig, path)


def title(run: PunchRun, state) -> str:
    """The elements, the load and the key figure, with what is checked against Hertz."""
    return (f"ν = {run.nu:g}, {'Taylor–Hood P2–P1' if run.mixed else 'P1'}: "
            + _checked(run, state))


def _checked(run: PunchRun, state) -> str:
    ref = run.ref
    if ref is None:
        return f"{run.model} punch: no contact (δ = {state.indentation:.3g})"
    a_err = 100 * (state.contact_radius / ref["contact_radius"] - 1)
    p_err = 100 * (state.max_pressure / ref["max_pressure"] - 1)
    if run.plastic and not run.force_controlled:  # Hertz: the elastic reference
        return (f"{run.model} J2 punch, δ = {state.indentation:.3g}: P = {state.force:.4g} "
                f"(the block flows)\nagainst elastic Hertz: P {state.force / ref['force']:.3f} ×,"
                f" contact radius {state.contact_radius / ref['contact_radius']:.3f} ×, peak "
                f"pressure {state.max_pressure / ref['max_pressure']:.3f} ×")
    if run.model == "plane_strain":
        return (f"plane-strain cylinder, P = {state.force:.4g} per unit length (not checked): "
                f"half-width {a_err:+.1f} %, p0 {p_err:+.1f} % from Hertz")
    if run.force_controlled:  # P prescribed: the check is on the indentation it needs
        d_ref = hertz.sphere_from_force(run.E, run.nu, run.radius, state.force)["indentation"]
        return (f"{run.model} punch, P = {state.force:.4g} (prescribed): δ = "
                f"{state.indentation:.3g} ({100 * (state.indentation / d_ref - 1):+.2f} % from "
                f"Hertz), a {a_err:+.1f} %, p0 {p_err:+.1f} %")
    return (f"{run.model} punch, δ = {state.indentation:.3g}: P = {state.force:.4g} "
            f"({100 * (state.force / ref['force'] - 1):+.2f} % from Hertz), a {a_err:+.1f} %, "
            f"p0 {p_err:+.1f} %")


def _right_panel(ax, run: PunchRun, profile, state) -> None:
    """The traction against Cattaneo–Mindlin with friction, else the pressure (Hertz)."""
    if run.ref is None:
        return
    if run.traction is None:
        pressure_panel(ax, profile, state, run.ref)
    elif run.model == "3d":
        sphere_traction_panel(ax, run)
    else:
        cylinder_traction_panel(ax, run)


def sphere_traction_panel(ax, run: PunchRun) -> None:
    """Q(r)/Q: the tangential force inside radius r, FE against Mindlin's."""
    T, f = run.traction, run.friction
    rings, within = run.traction_profile
    H = hertz.sphere_from_force(run.E, run.nu, run.radius, T.normal_force)
    a, p0 = H["contact_radius"], H["max_pressure"]
    Q = T.tangential_force
    ax.plot(rings / a, within / Q, "-", color="C0", lw=2, label="FE (sum of nodal forces)")
    c = run.stick_radius_exact
    if c is not None:
        ax.plot(rings / a, mindlin.sphere_tangential_force_within(rings, a, p0, f, c) / Q,
                "k--", lw=1, label="Mindlin")
        ax.axvline(c / a, color="k", ls=":", lw=0.8, label="stick radius c (Mindlin)")
    ax.axvline(T.stick_radius / a, color="C0", ls=":", lw=0.8, label="outermost stick node")
    ax.set_xlim(0, 1.5)
    ax.set_xlabel("r / a (Hertz for the computed P)")
    ax.set_ylabel("Q(r) / Q: tangential force inside r")
    ax.set_title(f"f = {f:g}, Q = {Q / (f * T.normal_force):.3g} f P, {T.stick_nodes} nodes "
                 f"stick, {T.slip_nodes} slip", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(alpha=0.3)


def cylinder_traction_panel(ax, run: PunchRun) -> None:
    """p/p0 and q/(f p0) along x through the axis, FE against Hertz and Cattaneo–Mindlin.

    The FE nodes by status (stick, slip); a and p0 of Hertz for the computed P.
    """
    x, p, q, status = run.traction_profile
    a, p0, f = run.ref["contact_radius"], run.ref["max_pressure"], run.friction
    c = run.stick_radius_exact
    xx = np.linspace(-1.5, 1.5, 601)
    ax.plot(xx, hertz.pressure_profile(1.0, 1.0, xx), color="0.6", lw=1, label="Hertz p/p0")
    ax.plot(x / a, p / p0, ".", color="0.6", ms=2, label="FE p/p0")
    if c is not None:
        ax.plot(xx, mindlin.traction(xx * a, a, p0, f, c) / (f * p0), "k-", lw=1,
                label="Cattaneo-Mindlin q/(f p0)")
        for side in (-1, 1):
            ax.axvline(side * c / a, color="k", ls=":", lw=0.8)
    for code, name, colour in ((1, "stick", "C0"), (2, "slip", "C1")):
        on = status == code
        ax.plot(x[on] / a, q[on] / (f * p0), "o", ms=3, color=colour, label=f"FE q, {name}")
    ax.set_xlim(-1.5, 1.5)
    ax.set_ylim(-0.05, 1.25)
    ax.set_xlabel("x / a (Hertz)")
    ax.set_ylabel("traction / p0, f p0")
    T = run.traction
    ax.set_title(f"f = {f:g}, Q = {T.tangential_force / (f * T.normal_force):.3g}"
                 f" f P: stick zone |x| < c (dotted: c of Cattaneo-Mindlin)", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(alpha=0.3)


def pressure_panel(ax, profile, state, ref) -> None:
    """p/p0 against r/a (Hertz's a and p0), FE nodes against Hertz's ellipse."""
    r, p, _ = profile
    a, p0 = ref["contact_radius"], ref["max_pressure"]
    ax.plot(r / a, p / p0, "o", ms=3, label="FE nodal pressure")
    rr = np.linspace(0, 1.5, 300)
    ax.plot(rr, hertz.pressure_profile(1.0, 1.0, rr), "-", label="Hertz")
    # Hertz's a drawn over the FE one (they coincide on a fine mesh): both stay visible
    ax.axvline(state.contact_radius / a, color="C3", ls="-", lw=2.5, alpha=0.6,
               label=f"last active node: a = {state.contact_radius:.3g}")
    ax.axvline(1.0, color="black", ls=(0, (3, 3)), lw=1.2, zorder=5,
               label=f"Hertz a = {a:.3g}")
    ax.set_xlim(0, 1.5)
    ax.set_ylim(-0.05, 1.25)
    ax.set_xlabel("r / a (Hertz)")
    ax.set_ylabel(f"contact pressure p / p0 (Hertz p0 = {p0:.3g})")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)


def section_picture(run: PunchRun, path: str) -> None:
    """The snapshot's deformed contact zone in section, coloured by σ_eq / p0, beside p(r)."""
    state, ref = run.state, run.ref
    if not run.rank0:
        return
    plt = figures.pyplot()
    x, z, u_x, u_z, triangles, vm = run.section
    a = max(state.contact_radius, ref["contact_radius"] if ref else 0.0, 4 * run.h)
    window = 2.5 * a
    # the rigid drop of the block is removed (the surface at the window's edge stays put),
    # and the dent is drawn about a/4 deep
    at_edge = np.argmin(np.hypot(x - window, z))
    drop = u_z[at_edge]
    dent = max(abs(state.indentation + drop), 1e-300)
    scale = max(1.0, 0.25 * a / dent)
    xd, zd = x + scale * u_x, z + scale * (u_z - drop)
    p0 = ref["max_pressure"] if ref else max(state.max_pressure, 1e-300)
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 4.8),
                                  gridspec_kw={"width_ratios": [1.25, 1]})
    tpc = ax.tripcolor(xd, zd, triangles, facecolors=vm / p0, cmap="viridis",
                       edgecolors="face", vmin=0)
    ax.triplot(xd, zd, triangles, color="white", lw=0.15, alpha=0.4)
    left = -window if run.tangential else 0
    rr = np.linspace(left, window, 600)
    gap = run.gap_at(np.abs(rr), state.indentation)
    ax.plot(rr, scale * (gap - drop), color="C3", lw=2, label="punch surface")
    ax.plot([state.contact_radius] * 2, [-0.15 * a, 0.15 * a], color="C3", lw=1)
    ax.annotate("a (FE)", (state.contact_radius, 0.17 * a), color="C3", ha="center", fontsize=8)
    if ref:
        ax.plot([ref["contact_radius"]] * 2, [-0.3 * a, -0.15 * a], color="k", lw=1)
        ax.annotate("a (Hertz)", (ref["contact_radius"], -0.38 * a), ha="center", fontsize=8)
    ax.set_xlim(left, window)
    ax.set_ylim(-2 * a, 0.5 * a)
    ax.set_aspect("equal")
    ax.set_xlabel("r [length]" if run.model == "axisymmetric" else "x [length]")
    ax.set_ylabel("z [length]" + (" (section y = 0)" if run.model == "3d" else ""))
    ax.set_title(f"displacement x{scale:.3g}" + (f", rigid drop {-drop:.3g} removed"
                                                 if abs(drop) > 0.05 * dent else ""),
                 fontsize=9)
    cb = fig.colorbar(tpc, ax=ax, shrink=0.8)
    cb.set_label("von Mises stress σ_eq / p0 (Hertz)")
    ax.legend(loc="lower right", fontsize=8)
    _right_panel(ax2, run, run.profile, state)
    fig.suptitle(title(run, state), fontsize=10)
    figures.save_figure(fig, path)

def misfit_grid(model, measured, iterates: np.ndarray, spread: np.ndarray, points: int):
    """(σ0 values, H values, ½‖r‖² on their grid): points × points model runs (collective).

    Each axis spans the iterates with a margin, its points packed around the solution (the
    last iterate) within ± `spread` (three standard deviations, say): the valley there is
    narrow, and an even grid of a few runs would miss it.
    """
    axes = []
    for k in range(2):
        best = iterates[-1, k]
        lo = min(iterates[:, k].min(), best - spread[k])
        hi = max(iterates[:, k].max(), best + spread[k])
        margin = 0.1 * (hi - lo)
        # σ0 > 0 (a model run refuses 0), H >= 0
        lo, hi = max(lo - margin, 0.05 * best if k == 0 else 0.0), hi + margin
        near = best + np.linspace(-1, 1, max(points - 2, 1)) * spread[k]
        axis = np.unique(np.clip(np.concatenate([[lo, hi], near]), lo, hi))
        axes.append(axis)
    s, h = axes
    misfit = np.full((len(h), len(s)), np.nan)
    for i, sigma0 in enumerate(s):
        for j, H in enumerate(h):
            model.set(sigma0=float(sigma0), hardening=float(H))
            try:
                force = model.run(measured.depth, sensitivities=False).force
            except SolveError:  # left out of the map (the fit refuses such steps too)
                continue
            misfit[j, i] = 0.5 * float(np.sum((force - measured.force) ** 2))
    return s, h, misfit


def identification_figure(out: dict, path: str, grid=None, *, labels: tuple[str, str]) -> None:
    """The curves (measured dots, identified line, the start dashed), and the misfit map.

    `grid`: `misfit_grid`'s answer, or None (one panel). Drawn on rank 0.
    """
    if MPI.COMM_WORLD.rank != 0:
        return
    plt = figures.pyplot()
    fig, axes = plt.subplots(1, 2 if grid is not None else 1,
                             figsize=(11.5 if grid is not None else 6, 4.6), squeeze=False)
    ax = axes[0, 0]
    c = out["curve"]
    ax.plot(c["depth"], c["initial"], "--", color="0.6", label="initial guess")
    ax.plot(c["depth"], c["fitted"], "-", color="C0", lw=2, label="fitted (the fit's mesh)")
    ax.plot(c["depth"], c["measured"], "o", color="C3", ms=5, label="measured")
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left")
    ax.set_title(_title(out), fontsize=9)
    if grid is not None:
        s, h, misfit = grid
        ax = axes[0, 1]
        # the grid's runs and the fit's own (the iterates, whose misfits are known), linear
        # between them on triangles: no minimum where no run was made (a spline through so
        # few runs of a narrow valley draws false ones)
        S, Hs = np.meshgrid(s, h)
        x = np.concatenate([S.ravel(), np.array(out["iterates"])[:, 0]])
        y = np.concatenate([Hs.ravel(), np.array(out["iterates"])[:, 1]])
        z = np.concatenate([misfit.ravel(), out["misfits"]])
        x, y, z = x[np.isfinite(z)], y[np.isfinite(z)], z[np.isfinite(z)]
        levels = np.geomspace(max(z.min(), 1e-300), z.max(), 14)
        cs = ax.tricontourf(x, y, np.log(z), levels=np.log(levels), cmap="viridis")
        bar = fig.colorbar(cs, ax=ax, label="misfit ½Σ(P − P_measured)²")
        bar.set_ticks(np.log(levels[::2]), labels=[f"{v:.0e}" for v in levels[::2]])
        ax.plot(S.ravel(), Hs.ravel(), ".", color="0.85", ms=3, label="model runs of the map")
        path_ = np.array(out["iterates"])
        ax.plot(path_[:, 0], path_[:, 1], "o-", color="w", ms=4, lw=1.2,
                label="Levenberg–Marquardt iterates")
        ax.plot(*path_[0], "s", color="w", ms=7)
        ax.plot(*path_[-1], "*", color="C3", ms=14, label="the fit's minimum (its mesh)")
        if out.get("sigma0_fit_model") is not None and None not in (out.get("sigma0"),
                                                                    out.get("hardening")):
            ax.plot(out["sigma0"], out["hardening"], "D", color="C1", ms=8,
                    label="reported (the finer mesh's)")
        if out.get("true_sigma0") is not None:
            ax.plot(out["true_sigma0"], out["true_hardening"], "+", color="k", ms=14, mew=2,
                    label="true (synthetic)")
        from matplotlib.ticker import MaxNLocator

        ax.xaxis.set_major_locator(MaxNLocator(5))
        ax.set_xlabel(f"yield stress σ0 ({out['stress_unit']})")
        ax.set_ylabel(f"hardening modulus H ({out['stress_unit']})")
        ax.legend(loc="upper right", fontsize=8)
        ax.set_title(f"misfit: {len(s)}×{len(h)} runs (dots) and the iterates', linear "
                     "between them", fontsize=9)
    figures.save_figure(fig, path)


def _title(out: dict) -> str:
    parts = []
    for name, symbol in (("sigma0", "σ0"), ("hardening", "H")):
        if out.get(name) is not None:
            parts.append(f"{symbol} = {out[name]:.4g} ± {out[f'{name}_std']:.2g}")
        elif name in out.get("fitted_parameters", []):
            parts.append(f"{symbol}: not identifiable")
    return (f"{', '.join(parts)}\n{out['iterations']} iterations, "
            f"{out['forward_solves']} model runs")


def pair_curves(steps: list[dict], title: str, path: str,
                comm: MPI.Comm = MPI.COMM_WORLD, torque: dict | None = None) -> None:
    """a and p0 against the force (log–log) and p around the arc, with Hertz's.

    Args:
        steps: each load step's record: `force`, `contact_radius`, `max_pressure`, their
            `_hertz` values, and `profile` (`s`, the arc length from the centre of the
            contact, and `pressure`), gathered on every rank.
        title: the figure's title.
        path: the PNG, written by rank 0 of `comm`.
        comm: the run's communicator.
        torque: a third panel, the friction torque against the rotation: `rotation`,
            `torque`, its Coulomb `limit` (f R Σλ_n) and the nodes `slipping` of those
            `in_contact`, per step.
    """
    if comm.rank != 0:
        return
    plt = figures.pyplot()
    fig, axes = plt.subplots(1, 3 if torque else 2, figsize=(18 if torque else 12, 4.8))
    P = np.array([s["force"] for s in steps])
    ax = axes[0]
    for key, name, colour in (("contact_radius", "half-width a", "C0"),
                              ("max_pressure", "peak pressure p0", "C3")):
        ax.loglog(P, [s[key] for s in steps], "o", color=colour, label=f"FE: {name}")
        ax.loglog(P, [s[f"{key}_hertz"] for s in steps], "-", color=colour, lw=1,
                  label=f"Hertz: {name}")
    ax.set_xlabel("force per unit length P [force/length]")
    ax.set_ylabel("a [length], p0 [stress]")
    ax.set_title("the contact against Hertz (fitted ellipse: see the demo)", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, which="both")
    ax = axes[1]
    colours = plt.get_cmap("viridis")(np.linspace(0.0, 0.9, len(steps)))
    for colour, st in zip(colours, steps, strict=True):
        prof = st["profile"]
        order = np.argsort(prof["s"])
        sv, pv = np.array(prof["s"])[order], np.array(prof["pressure"])[order]
        ax.plot(sv, pv, "o", ms=3, color=colour, label=f"FE, P = {st['force']:.3g}")
        grid = np.linspace(0.0, st["contact_radius_hertz"], 60)
        ax.plot(grid, hertz.pressure_profile(st["max_pressure_hertz"],
                                             st["contact_radius_hertz"], grid),
                "-", lw=0.8, color=colour)
    ax.set_xlabel("arc length from the lowest point s [length]")
    ax.set_ylabel("contact pressure [stress]")
    ax.set_title("pressure around the arc (lines: Hertz for the same P)", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    if torque:
        ax = axes[2]
        theta = [0.0, *torque["rotation"]]
        ax.plot(theta, [0.0, *torque["torque"]], "o-", color="C0", label="FE: torque T")
        ax.plot(torque["rotation"], torque["limit"], "--", color="C3",
                label="Coulomb limit f R Σλ_n")
        for th, t, k, m in zip(torque["rotation"], torque["torque"], torque["slipping"],
                               torque["in_contact"], strict=True):
            ax.annotate(f"{k}/{m}", (th, t), textcoords="offset points", xytext=(4, -12),
                        fontsize=7)
        ax.set_xlabel("rotation of the hub θ [rad]")
        ax.set_ylabel("torque resisting the turn [force·length/length]")
        ax.set_title("the friction torque (labels: nodes slipping / in contact)", fontsize=9)
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=11)
    figures.save_figure(fig, path)
