"""Pictures of plastic bodies against their closed forms: the thick vessel and the upsetting.

The deformed body coloured by the cumulated plastic strain (each cell's largest), with
what it is compared with drawn on it: the closed form's plastic radius in the vessel's
quarter (`vessel_plastic_zone`), the die and the contact statuses on the billet
(`billet_picture`). And the load against the motion: the vessel's pressure against its
inner displacement with Lamé and the perfectly plastic sphere (`vessel_pressure_curve`),
the die's force against the height reduction with the homogeneous compression and the slab
method (`upsetting_force_curve`). `demos/pressure_vessel.py` and `demos/upsetting.py` draw
them. And the vessel creeping under a held pressure (`demos/creep_vessel.py`): its stress
profiles at several times against Lamé's and the stationary closed form, the bore's stresses
and displacement against time (`creep_vessel_figure`). And any 2D section's cell fields
(plastic strain, σ_eq, a displacement) beside profiles along lines after each stage or step
(`fields_and_profiles`: `demos/excavation.py`). And a closed-die forging in 3D: the part
mirrored whole from its computed eighth, coloured by p, with the die cavity's outline
(`forging_picture`), and its load against the stroke (`forging_load_curve`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.io import output
from fenics_nl.plots import deformed, figures
from fenics_nl.theory import vessels

__all__ = ["VesselRun", "billet_picture", "creep_vessel_figure", "fields_and_profiles",
           "forging_load_curve", "forging_picture", "upsetting_force_curve",
           "vessel_plastic_zone", "vessel_pressure_curve"]


@dataclass
class VesselRun:
    """What the pictures read of a vessel run (pressures and lengths in the run's units).

    Args:
        shape: ``sphere`` or ``cylinder``.
        a: the inner radius.
        b: the outer radius.
        E: Young's modulus.
        nu: Poisson's ratio.
        sigma0: the yield stress.
        path: (pressure, u(a)) after each converged step, from (0, 0).
        loaded: the peak pressure (also after unloading).
        unload: whether the run unloaded from it.
        p_lim: the closed form's limit pressure.
        p_e: the closed form's yield-onset pressure.
        c_fe: the plastic radius computed.
        c_exact: the plastic radius of the closed form.
        compliance: Lamé's elastic u(a)/p.
        exact_curve: the closed form holds along the whole loading (sphere, perfect
            plasticity, below the limit).
        inner: u(a) at the peak, computed.
        inner_exact: u(a) at the peak, of the closed form (None if not `exact_curve`).
    """

    shape: str
    a: float
    b: float
    E: float
    nu: float
    sigma0: float
    path: list
    loaded: float
    unload: bool
    p_lim: float
    p_e: float
    c_fe: float
    c_exact: float
    compliance: float
    exact_curve: bool
    inner: float
    inner_exact: float | None

    def title(self, sep: str = ", ") -> str:
        """What the run ends in, loaded or unloaded from its peak.

        Args:
            sep: what goes before the plastic radius (a new line in the curve's title).

        Returns:
            The title of both pictures.
        """
        # plain "nu": pyvista's font has no Greek letters (the picture shares this title)
        closed = "closed form" + (" for nu = 1/2" if self.shape == "cylinder" else "")
        radius = f"plastic radius {self.c_fe:.4g} ({closed} {self.c_exact:.4g})"
        if self.unload:
            return (f"{self.shape}: unloaded from {self.loaded / self.p_lim:.3f} p_lim, "
                    f"permanent u(a) = {self.path[-1][1]:.4g}{sep}{radius}")
        return f"{self.shape}: p = {self.loaded / self.p_lim:.3f} p_lim{sep}{radius}"


def vessel_pressure_curve(run: VesselRun, path: str, comm: MPI.Comm = MPI.COMM_WORLD) -> None:
    """p(u(a)) of the run against the closed forms (loading and elastic unloading).

    Args:
        run: the run's values.
        path: the PNG, written by rank 0 of `comm`.
        comm: the run's communicator.
    """
    if comm.rank != 0:
        return
    plt = figures.pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4.8))
    q, d = np.array(run.path).T
    p_lim, loaded = run.p_lim, run.loaded
    if run.exact_curve:  # the monotonic loading, exact up to the limit
        ps = np.linspace(0.0, loaded, 200)
        us = [vessels.sphere_inner_displacement(run.a, run.b, run.E, run.nu, run.sigma0, x)
              for x in ps]
        ax.plot(us, ps / p_lim, "k-", lw=1, label="closed form (loading)")
    else:  # Lamé up to the yield onset
        ps = np.array([0.0, min(run.p_e, loaded)])
        ax.plot(ps * run.compliance, ps / p_lim, "k-", lw=1, label="Lamé (elastic)")
    if run.unload:  # from the closed-form peak (else the computed one), Lamé's compliance
        peak = run.inner_exact if run.inner_exact is not None else run.inner
        # the sphere unloads elastically up to 2 p_e (σ_eq(a) goes from σ0 to −σ0); the
        # cylinder's bound is close to it (exact for ν = 1/2)
        reverse = loaded > 2 * run.p_e
        ax.plot([peak, peak - loaded * run.compliance], [loaded / p_lim, 0.0], "k--", lw=1,
                label="elastic unloading (Lamé" + (", reverse yield ignored)" if reverse
                                                   else ")"))
    ax.plot(d, q / p_lim, "o", ms=4, mfc="none", color="C0", label="FE, J2 (each step)")
    ax.axhline(1.0, color="C3", ls="--", lw=1, label=f"limit pressure {p_lim:.4g}")
    ax.axhline(run.p_e / p_lim, color="gray", ls=":", lw=1, label="yield onset")
    ax.set_xlabel("inner radial displacement u(a) [length]")
    ax.set_ylabel("p / p_lim")
    ax.set_ylim(0, 1.08)
    ax.set_xlim(left=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    ax.set_title(f"b/a = {run.b / run.a:g}, " + run.title("\n"), fontsize=9)
    figures.save_figure(fig, path)


def vessel_plastic_zone(run: VesselRun, displacement: fem.Function,
                        plastic_strain_per_cell: fem.Function, path: str) -> None:
    """The deformed quarter coloured by each cell's largest cumulated plastic strain.

    The closed form's plastic radius drawn over it. Collective; rank 0 writes `path`.

    Args:
        run: the run's values.
        displacement: u (a Function of its own space).
        plastic_strain_per_cell: p, each cell's largest (DG0).
        path: the PNG.
    """
    theta = np.linspace(0.0, 0.5 * np.pi, 91)
    c = run.c_exact
    arc = {f"closed-form plastic radius {c:.4g}"
           + (" (for nu = 1/2)" if run.shape == "cylinder" else ""):
           np.column_stack([c * np.cos(theta), c * np.sin(theta)])}
    deformed.deformed_picture(displacement, plastic_strain_per_cell, path, run.title(),
                              label="cumulated plastic strain", curves=arc)


def billet_picture(displacement: fem.Function, plastic_strain_per_cell: fem.Function,
                   path: str, title: str, *, die_height: float,
                   marked: dict[str, np.ndarray]) -> None:
    """The deformed half billet coloured by p, the die and the nodes on it.

    True scale (the die is drawn where it is). Collective; rank 0 writes `path`.

    Args:
        displacement: u (a Function of its own space), the (r, z) half section's.
        plastic_strain_per_cell: p, each cell's largest (DG0).
        path: the PNG.
        title: the picture's title.
        die_height: the die's current height: the plane z = `die_height`.
        marked: a name → this rank's nodes to draw at their current (r, z) (the sticking
            and the slipping ones, or those on the die).
    """
    deformed.deformed_picture(
        displacement, plastic_strain_per_cell, path, title, marked=marked,
        label="cumulated plastic strain p", axes=("r (length)", "z (length)"),
        obstacle={"obstacle": "plane", "point": [0.0, die_height], "normal": [0.0, 1.0]})


def upsetting_force_curve(history: list[dict], friction: float, path: str, title: str) -> None:
    """F against the reduction, with the frictionless closed form and the slab estimate.

    Args:
        history: each converged step's ``reduction``, ``force``,
            ``force_frictionless_exact`` and (with friction) ``force_slab_estimate``.
        friction: Coulomb's coefficient f (0: no slab estimate drawn).
        path: the PNG (call on one rank).
        title: the figure's title.
    """
    plt = figures.pyplot()
    r = np.array([0.0] + [h["reduction"] for h in history])
    fig, ax = plt.subplots(figsize=(7, 4.8))
    ax.plot(100 * r, [0.0] + [h["force"] for h in history], "o-", ms=3,
            label=f"computed, f = {friction:g}")
    ax.plot(100 * r, [0.0] + [h["force_frictionless_exact"] for h in history], "k--",
            label="frictionless, homogeneous: σ_y(p) π R0² h0/h")
    if friction > 0:
        ax.plot(100 * r, [0.0] + [h["force_slab_estimate"] for h in history], "g:",
                label="slab method: (1 + 2fR/3h) × frictionless")
    ax.set_xlabel("height reduction 1 − h/h0 (%)")
    ax.set_ylabel("die force F (force units)")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend()
    figures.save_figure(fig, path)


def creep_vessel_figure(shape: str, a: float, b: float, p: float, n: float, tau: float,
                        profiles: dict, times: list, bore_hoop: list, outer_hoop: list,
                        bore_u: list, rate_exact: float, path: str,
                        comm: MPI.Comm = MPI.COMM_WORLD) -> None:
    """A creeping vessel: stress profiles, the hoop stresses and the bore against time.

    Args:
        shape: ``cylinder`` or ``sphere``.
        a: the inner radius.
        b: the outer radius.
        p: the pressure.
        n: Norton's exponent.
        tau: the relaxation time (the time axis's unit).
        profiles: time → (σ_rr, σ_θθ) at equally spaced radii from a to b.
        times: the accepted steps' times, from 0.
        bore_hoop: the hoop stress at the bore at those times.
        outer_hoop: the hoop stress outside at those times.
        bore_u: the bore's radial displacement at those times.
        rate_exact: the stationary closed form's u̇(a).
        path: the PNG, written by rank 0 of `comm`.
        comm: the run's communicator.
    """
    if comm.rank != 0:
        return
    plt = figures.pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(15, 5.6))
    r = np.linspace(a, b, 200)
    lame = vessels.stationary_creep_stresses(shape, a, b, p, 1.0, r)
    final = vessels.stationary_creep_stresses(shape, a, b, p, n, r)
    ax = axes[0]
    for k, (name, style) in enumerate((("σ_rr", "--"), ("σ_θθ", "-"))):
        ax.plot(r, lame[k] / p, "k" + style, lw=0.8, alpha=0.5,
                label=f"{name}: Lamé (elastic)")
        ax.plot(r, final[k] / p, "C3" + style, lw=1.2, label=f"{name}: stationary creep")
    colours = plt.get_cmap("viridis")(np.linspace(0.0, 0.9, len(profiles)))
    for colour, (t, (sr, st)) in zip(colours, sorted(profiles.items()), strict=True):
        radii = np.linspace(a, b, len(st))
        ax.plot(radii, np.array(sr) / p, "s", ms=3, mfc="none", color=colour)
        ax.plot(radii, np.array(st) / p, "o", ms=4, color=colour,
                label=f"FE at t = {t / tau:.2g} τ")
    ax.set_xlabel("radius r [length]")
    ax.set_ylabel("stress / p")
    ax.set_title("profiles along y = 0 (FE: circles σ_θθ, squares σ_rr)", fontsize=9)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2)
    ax.grid(alpha=0.3)
    t = np.array(times[1:]) / tau
    ax = axes[1]
    ax.semilogx(t, np.array(bore_hoop[1:]) / p, "o-", ms=3, label="FE: σ_θθ at the bore")
    ax.semilogx(t, np.array(outer_hoop[1:]) / p, "s-", ms=3, label="FE: σ_θθ outside")
    for k, style in ((0, "-"), (-1, "--")):
        ax.axhline(final[1][k] / p, color="C3", ls=style, lw=1,
                   label="stationary: " + ("bore" if k == 0 else "outside"))
        ax.axhline(lame[1][k] / p, color="k", ls=style, lw=0.8, alpha=0.5,
                   label="Lamé: " + ("bore" if k == 0 else "outside"))
    ax.set_xlabel("time / τ (τ = 1/(E A pⁿ⁻¹); each marker a time step)")
    ax.set_ylabel("hoop stress / p")
    ax.set_title("the redistribution", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, which="both")
    ax = axes[2]
    ax.plot(np.array(times) / tau, bore_u, "o-", ms=3, label="FE: u(a)")
    t_line = np.array([times[len(times) // 2], times[-1]])
    ax.plot(t_line / tau, bore_u[-1] + rate_exact * (t_line - times[-1]), "C3--", lw=1.2,
            label=f"stationary rate (closed form): {rate_exact * tau:.4g} per τ")
    ax.set_xlabel("time / τ")
    ax.set_ylabel("bore displacement u(a) [length]")
    ax.set_title("the bore's creep", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.suptitle(f"{shape}, b/a = {b / a:g}, Norton n = {n:g}: from Lamé to stationary creep "
                 f"(bore σ_θθ {bore_hoop[-1] / p:.3f} p, stationary {final[1][0] / p:.3f} p)",
                 fontsize=11)
    figures.save_figure(fig, path)


def fields_and_profiles(u: fem.Function, fields: dict[str, fem.Function],
                        profiles: list[dict], path: str, title: str,
                        axes: tuple[str, str] = ("x", "y"), window=None,
                        shown: fem.Function | None = None) -> None:
    """The section's fields (one panel each), then the profiles (one panel each).

    Collective; rank 0 writes `path`.

    Args:
        u: the displacement (drawn undeformed: the fields' panels show the section itself).
        fields: a colour bar's label → a DG0 Function on u's mesh.
        profiles: panels of curves, each {"x": label, "y": label, "curves": {name: (x, y)},
            "vertical": True to draw y along the vertical axis (a profile with depth)}.
        path: the PNG.
        title: the figure's title.
        axes: the section's axis titles.
        window: (x0, x1, y0, y1) of the section drawn (None: all of it).
        shown: a DG0 Function, > 0 on the cells drawn (None: all; the cells present of a
            staged construction).
    """
    sections = {label: output.section(u, f) for label, f in fields.items()}
    mask = output.section(u, shown) if shown is not None else None  # (collective)
    if u.function_space.mesh.comm.rank != 0:
        return
    drawn = mask[5] > 0 if mask is not None else None
    plt = figures.pyplot()
    n = len(fields) + len(profiles)
    columns = min(n, 3)
    rows = -(-n // columns)
    fig, grid = plt.subplots(rows, columns, figsize=(5.2 * columns, 4.2 * rows), squeeze=False)
    panels = list(grid.ravel())
    for ax, (label, (x, z, _, _, triangles, values)) in zip(panels, sections.items(),
                                                             strict=False):
        if drawn is not None:
            triangles, values = triangles[drawn], values[drawn]
        tpc = ax.tripcolor(x, z, triangles, facecolors=values, cmap="viridis",
                           edgecolors="face")
        if window is not None:
            ax.set_xlim(window[0], window[1])
            ax.set_ylim(window[2], window[3])
        ax.set_aspect("equal")
        ax.set_xlabel(axes[0])
        ax.set_ylabel(axes[1])
        fig.colorbar(tpc, ax=ax, shrink=0.8).set_label(label)
    for ax, panel in zip(panels[len(fields):], profiles, strict=False):
        for name, (x, y) in panel["curves"].items():
            if panel.get("vertical"):
                ax.plot(y, x, label=name)
            else:
                ax.plot(x, y, label=name)
        ax.set_xlabel(panel["y"] if panel.get("vertical") else panel["x"])
        ax.set_ylabel(panel["x"] if panel.get("vertical") else panel["y"])
        (ax.axvline if panel.get("vertical") else ax.axhline)(0.0, color="k", lw=0.5)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    for ax in panels[n:]:
        ax.set_visible(False)
    fig.suptitle(title, fontsize=10)
    figures.save_figure(fig, path)


def forging_picture(displacement: fem.Function, plastic_strain_per_cell: fem.Function,
                    path: str, title: str, *, outline: np.ndarray, land: float) -> None:
    """The forged part, whole (its eighth mirrored), coloured by p; the cavity's outline.

    At true scale, seen from above at an angle and from above: the flash is the metal
    beyond the outline. Collective; rank 0 writes `path`.

    Args:
        displacement: u on the eighth x, y, z ≥ 0 (a 3D vector Lagrange Function).
        plastic_strain_per_cell: p, each cell's largest (DG0).
        path: the PNG.
        title: the picture's title.
        outline: the cavity's outline in plan, (n, 2) points of its quarter x, y ≥ 0.
        land: the lands' height z above the mid-plane (the outline is drawn there).
    """
    u1 = output.vertex_interpolant(displacement)
    grid = output.gather_grid(u1.function_space, {"u": u1},
                              {"p": output.owned_cell_values(plastic_strain_per_cell)})
    if grid is None:
        return
    pv = figures.off_screen()
    part = grid.pyvista().warp_by_vector("u")
    for normal in ((1, 0, 0), (0, 1, 0), (0, 0, 1)):  # the eighth to the whole part
        part = part.merge(part.reflect(normal, point=(0, 0, 0)))
    quarter = np.column_stack([outline, np.full(len(outline), land)])
    ring = np.vstack([quarter, quarter[::-1] * [-1, 1, 1], quarter * [-1, -1, 1],
                      quarter[::-1] * [1, -1, 1]])
    pl = pv.Plotter(off_screen=True, window_size=(1700, 800), shape=(1, 2))
    for view in range(2):
        pl.subplot(0, view)
        pl.add_mesh(part.copy(), scalars="p", cmap="turbo", show_scalar_bar=view == 0,
                    scalar_bar_args={"title": "cumulated plastic strain p",
                                     "position_x": 0.2, "position_y": 0.03, "width": 0.6,
                                     "fmt": "%.2g"})
        pl.add_lines(np.vstack([ring, ring[:1]]), color="black", width=3, connected=True)
        if view == 0:
            pl.view_vector((1.0, -1.4, 1.1))
            pl.add_text(title, font_size=11, position="upper_left")
        else:
            pl.view_xy()
            pl.add_text("from above; black: the cavity's outline (beyond it, the flash)",
                        font_size=10, position="upper_left")
    pl.screenshot(path)
    pl.close()


def forging_load_curve(history: list[dict], slab: float, path: str, title: str) -> None:
    """The die's load against its stroke, the flat start's closed form and the slab estimate.

    Args:
        history: each converged step's ``stroke``, ``force``, ``force_flat_die_exact``,
            ``under_ceiling_alone`` (the closed form holds, frictionless) and ``die_fill``.
        slab: the flash's slab estimate of the last load.
        path: the PNG (call on one rank).
        title: the figure's title.
    """
    plt = figures.pyplot()
    d = np.array([0.0] + [h["stroke"] for h in history])
    fig, (ax, fill) = plt.subplots(1, 2, figsize=(12, 4.8))
    ax.plot(d, [0.0] + [h["force"] for h in history], "o-", ms=3, label="computed")
    flat = [0] + [i + 1 for i, h in enumerate(history) if h["under_ceiling_alone"]]
    ax.plot(d[flat], [0.0] + [history[i - 1]["force_flat_die_exact"] for i in flat[1:]],
            "k--", label="under the flat ceiling alone, frictionless: σ_y(p) π R0² h0/h")
    ax.plot([d[-1]], [slab], "g*", ms=12, label="the flash's slab estimate")
    ax.set_xlabel("die stroke d (length)")
    ax.set_ylabel("load F (force units)")
    ax.set_title(title, fontsize=10)
    fill.plot(d[1:], [h["die_fill"] for h in history], "o-", ms=3)
    fill.set_xlabel("die stroke d (length)")
    fill.set_ylabel("die fill: the ceiling's area in contact")
    fill.set_ylim(0, 1.05)
    for a in (ax, fill):
        a.grid(alpha=0.3)
    ax.legend()
    figures.save_figure(fig, path)
