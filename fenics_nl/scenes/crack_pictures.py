"""The crack demo's picture: its load curve, and the damage field at a few steps.

The same picture on any number of ranks: each snapshot's mesh and damage are gathered on
rank 0 (`output.gather_grid`), which draws.
"""

from __future__ import annotations

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from fenics_nl.io import output, pictures

__all__ = ["crack_figure"]


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


def crack_figure(out: dict, space: fem.FunctionSpace, damage: list[np.ndarray],
                 steps: list[int], path: str) -> None:
    """The load curve, then the damage at `steps` (collective).

    The load curve: the top's force against its displacement, or the surfing crack's tip
    against the field's centre.
    """
    grids = _snapshots(space, [damage[k] for k in steps])
    if MPI.COMM_WORLD.rank != 0:
        return
    plt = pictures.pyplot()
    from matplotlib.ticker import MaxNLocator

    fig, axes = plt.subplots(1, 1 + len(steps), figsize=(4.2 + 3.1 * len(steps), 3.9),
                             gridspec_kw={"width_ratios": [1.35] + [1] * len(steps)})
    ax = axes[0]
    surfing = out["test"] == "surfing"
    x = np.array(out["centre_history"] if surfing else out["displacement_history"])
    y = np.array([t[0] for t in out["crack_tip_history"]] if surfing
                 else out["force_history"])
    ax.plot(x, y, "o-", ms=3, color="C0")
    for i, k in enumerate(steps):
        ax.annotate("abcdefgh"[i], (x[k], y[k]), textcoords="offset points", xytext=(-9, 4),
                    color="C3", fontsize=9, annotation_clip=False)
    if surfing:
        ax.plot(x, x, "k--", lw=1, label="the K-field's centre")
        ax.set_xlabel("K-field centre x_c (mm)")
        ax.set_ylabel("crack tip x (mm)")
        ax.set_title(f"surfing: 2 dD/da = {out['energy_release_rate']:.4g} kN/mm "
                     f"(mesh toughness {out['mesh_toughness']:.4g})", fontsize=8)
        ax.legend(fontsize=8)
    else:
        if out["peak_force"] is not None:
            k = int(np.argmax(y))
            ax.plot(x[k], y[k], "s", color="C3", ms=6,
                    label=f"peak {out['peak_force']:.4g} kN at {x[k]:.3g} mm")
        ax.set_xlabel("top displacement U (mm)")
        ax.set_ylabel("top force F (kN per mm of thickness)")
        ax.set_title(f"{out['test']}: {out['model'].upper()}, ℓ = {out['ell']:g} mm, "
                     f"h = ℓ/{out['ell'] / out['h']:.3g}", fontsize=8)
        if out["peak_force"] is not None:
            ax.legend(fontsize=8)
    ax.xaxis.set_major_locator(MaxNLocator(5))
    ax.grid(alpha=0.3)
    for i, (k, grid) in enumerate(zip(steps, grids, strict=True)):
        label = (f"x_c = {x[k]:.3g} mm" if surfing
                 else f"U = {x[k]:.3g} mm, F = {y[k]:.3g} kN")
        image = _damage_panel(axes[1 + i], grid, f"({'abcdefgh'[i]}) {label}")
    axes[1].set_ylabel("y (mm)")
    # beside the last panel, not taken from it: the panels keep one size
    bar = axes[-1].inset_axes([1.06, 0.0, 0.06, 1.0])
    fig.colorbar(image, cax=bar, label="damage α", ticks=np.linspace(0, 1, 5))
    pictures.save_figure(fig, path)
