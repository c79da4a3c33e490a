"""The damage demos' pictures: a bar's stress against its strain, a crack's curve and field.

* `stress_strain` (`demos/damage_bar.py`): σ against ε with the law's homogeneous closed
  form; the local law's localized bars; the gradient laws' loss of stability and the
  finest crack's damage profile against its closed form.
* `notched_figure`, `surfing_figure` (`demos/crack.py`): the load curve, then the damage
  field at a few steps, the same on any number of ranks (each snapshot's mesh and damage
  gathered on rank 0, `output.gather_grid`, which draws).
"""

from __future__ import annotations

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.io import output
from fenics_nl.plots import figures

__all__ = ["notched_figure", "stress_strain", "surfing_figure"]

PANELS = "abcdefgh"


def stress_strain(path: str, law, model: str, strains, stresses, *, peak_strain: float,
                  peak_stress: float, table: list[dict], bifurcation: float | None = None,
                  bifurcation_exact: float | None = None) -> None:
    """σ/σ_peak against ε/ε_peak: the law's homogeneous closed form, the uniform bar, more.

    * local law: each localized bar of `table` by its end displacement over L (it snaps
      back);
    * gradient laws: where the homogeneous state stops being stable, and a second panel with
      the finest crack's damage profile against (1 − d/(2ℓ))² (AT1) or exp(−d/ℓ) (AT2).

    Args:
        path: the PNG written (by rank 0).
        law: the damage law (its `homogeneous_stress`).
        model: ``local``, ``at1`` or ``at2``.
        strains: the uniform bar's mean strain at each step.
        stresses: its stress at each step.
        peak_strain: the homogeneous response's peak strain (the x axis' unit).
        peak_stress: its peak stress (the y axis' unit).
        table: the meshes' rows; local law: `cells`, `mean_strain`, `stress`,
            `dissipated_energy`; gradient laws (the last row drawn): `profile` (`x`,
            `damage`, `damage_exact`), `h_over_ell`, `dissipated_energy`,
            `dissipated_energy_expected` and its `dissipated_energy_rel_error` (None: AT2).
        bifurcation: the strain where the uniform bar stopped being stable (gradient
            laws; None: it did not).
        bifurcation_exact: its closed form.
    """
    if MPI.COMM_WORLD.rank != 0:
        return
    plt = figures.pyplot()
    local = model == "local"
    fig, axes = plt.subplots(1, 1 if local else 2, figsize=(6.5 if local else 11, 4.5),
                             squeeze=False)
    ax = axes[0, 0]
    e = np.linspace(0.0, max(strains) / peak_strain, 400)
    closed = [law.homogeneous_stress(x * peak_strain) / peak_stress for x in e]
    ax.plot(e, closed, "k-", lw=1, label="homogeneous closed form"
            + (": σ = Eε, then w_c/ε" if local else f" ({model.upper()})"))
    ax.plot(np.array(strains) / peak_strain, np.array(stresses) / peak_stress, "o",
            color="C0", ms=5, label="uniform bar (displacement steps)")
    if local:
        for k, t in enumerate(table):
            ax.plot(np.array(t["mean_strain"]) / peak_strain,
                    np.array(t["stress"]) / peak_stress, "-", color=f"C{k + 1}", lw=1.5,
                    label=f"weak spot, h = L/{t['cells']}: D = {t['dissipated_energy']:.3g}")
        title = "the course's local damage law: the finer the mesh, the sooner the bar snaps back"
    else:
        if bifurcation is not None:
            ax.axvline(bifurcation / peak_strain, color="C3", lw=1, ls="--",
                       label=f"loss of stability: ε_b = {bifurcation:.4g} "
                             f"(closed form {bifurcation_exact:.4g})")
        title = f"{model.upper()}: the homogeneous bar, its loss of stability and its crack"
        _profile(axes[0, 1], table[-1])
    ax.set_xlim(0, e.max())
    ax.set_ylim(0, 1.1)
    ax.set_xlabel("mean strain ε / ε_peak  (end displacement / L)")
    ax.set_ylabel("stress σ / σ_peak")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    figures.save_figure(fig, path)


def _profile(ax, t: dict) -> None:
    """A crack's α(x) against its closed form."""
    p = t["profile"]
    ax.plot(p["x"], p["damage_exact"], "k-", lw=1, label="closed form beside a band of one "
                                                      "cell")
    ax.plot(p["x"], p["damage"], ".", color="C1", ms=4, label=f"computed, h = ℓ/"
                                                             f"{1 / t['h_over_ell']:.3g}")
    ax.set_xlabel("x (length)")
    ax.set_ylabel("damage α")
    ax.set_ylim(-0.02, 1.05)
    error = (100 * t["dissipated_energy_rel_error"]
             if t["dissipated_energy_rel_error"] is not None else None)
    ax.set_title(f"the crack: D = {t['dissipated_energy']:.4g}" + (
        f", G_c (1 + h/(c_w ℓ)) A = {t['dissipated_energy_expected']:.4g} ({error:+.2f} %)"
        if error is not None else " (AT2: damaged before it cracks)"), fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)


def notched_figure(path: str, space: fem.FunctionSpace, damage: list[np.ndarray],
                   shown: list[int], displacement, force, *, peak_force: float | None,
                   title: str) -> None:
    """The top's force against its displacement, then the damage at the steps `shown`.

    Collective: every rank gives its damage arrays, rank 0 draws.

    Args:
        path: the PNG written.
        space: the damage's space (P1).
        damage: each step's damage array (this rank's, `Function.x.array`).
        shown: the steps drawn (at most 8).
        displacement: the top's displacement at each step.
        force: the top's force at each step.
        peak_force: the peak marked (None: the force still rose at the last step).
        title: the curve's title.
    """
    x, y = np.array(displacement), np.array(force)

    def curve(ax):
        if peak_force is not None:
            k = int(np.argmax(y))
            ax.plot(x[k], y[k], "s", color="C3", ms=6,
                    label=f"peak {peak_force:.4g} kN at {x[k]:.3g} mm")
        ax.set_xlabel("top displacement U (mm)")
        ax.set_ylabel("top force F (kN per mm of thickness)")
        ax.set_title(title, fontsize=8)
        if peak_force is not None:
            ax.legend(fontsize=8)

    _crack_figure(path, space, damage, shown, x, y, curve,
                  lambda k: f"U = {x[k]:.3g} mm, F = {y[k]:.3g} kN")


def surfing_figure(path: str, space: fem.FunctionSpace, damage: list[np.ndarray],
                   shown: list[int], centres, tips, *, title: str) -> None:
    """The crack's tip against the K-field's centre, then the damage at the steps `shown`.

    Collective: every rank gives its damage arrays, rank 0 draws.

    Args:
        path: the PNG written.
        space: the damage's space (P1).
        damage: each step's damage array (this rank's, `Function.x.array`).
        shown: the steps drawn (at most 8).
        centres: the K-field's centre at each step.
        tips: the crack tip's x at each step.
        title: the curve's title.
    """
    x, y = np.array(centres), np.array(tips)

    def curve(ax):
        ax.plot(x, x, "k--", lw=1, label="the K-field's centre")
        ax.set_xlabel("K-field centre x_c (mm)")
        ax.set_ylabel("crack tip x (mm)")
        ax.set_title(title, fontsize=8)
        ax.legend(fontsize=8)

    _crack_figure(path, space, damage, shown, x, y, curve, lambda k: f"x_c = {x[k]:.3g} mm")


def _crack_figure(path, space, damage, shown, x, y, curve, label) -> None:
    """The curve (x, y) with the steps `shown` lettered, then their damage (collective)."""
    grids = _snapshots(space, [damage[k] for k in shown])
    if space.mesh.comm.rank != 0:  # gathered there
        return
    plt = figures.pyplot()
    from matplotlib.ticker import MaxNLocator

    fig, axes = plt.subplots(1, 1 + len(shown), figsize=(4.2 + 3.1 * len(shown), 3.9),
                             gridspec_kw={"width_ratios": [1.35] + [1] * len(shown)})
    ax = axes[0]
    ax.plot(x, y, "o-", ms=3, color="C0")
    for i, k in enumerate(shown):
        ax.annotate(PANELS[i], (x[k], y[k]), textcoords="offset points", xytext=(-9, 4),
                    color="C3", fontsize=9, annotation_clip=False)
    curve(ax)
    ax.xaxis.set_major_locator(MaxNLocator(5))
    ax.grid(alpha=0.3)
    for i, (k, grid) in enumerate(zip(shown, grids, strict=True)):
        image = _damage_panel(axes[1 + i], grid, f"({PANELS[i]}) {label(k)}")
    axes[1].set_ylabel("y (mm)")
    # beside the last panel, not taken from it: the panels keep one size
    bar = axes[-1].inset_axes([1.06, 0.0, 0.06, 1.0])
    fig.colorbar(image, cax=bar, label="damage α", ticks=np.linspace(0, 1, 5))
    figures.save_figure(fig, path)


def _snapshots(space: fem.FunctionSpace, damage: list[np.ndarray]) -> list:
    """The gathered grids (rank 0; None elsewhere) of each damage array (collective)."""
    alpha = fem.Function(space, name="damage")
    grids = []
    for a in damage:
        alpha.x.array[:] = a
        grids.append(output.gather_grid(space, {"damage": alpha}))
    return grids


def _damage_panel(ax, grid, title: str):
    """The damage on the cells (quadrilaterals split in two triangles), 0 white, 1 black."""
    import matplotlib.tri as mtri

    quads = grid.corner_cells()
    triangles = np.vstack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    tri = mtri.Triangulation(grid.points[:, 0], grid.points[:, 1], triangles)
    image = ax.tripcolor(tri, grid.point_data["damage"], cmap="Greys", vmin=0, vmax=1,
                         shading="gouraud", rasterized=True)
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=8)
    ax.set_xlabel("x (mm)")
    return image
