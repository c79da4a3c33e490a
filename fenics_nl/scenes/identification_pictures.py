"""The identification's picture: the measured and identified curves, and the misfit map.

The curves are the course's figure; the misfit over (σ0, H) with the fit's iterates on it
shows how the fit got there.
"""

from __future__ import annotations

import numpy as np
from mpi4py import MPI

from fenics_nl.errors import SolveError
from fenics_nl.io import pictures

__all__ = ["identification_figure", "misfit_grid"]


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
    plt = pictures.pyplot()
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
    pictures.save_figure(fig, path)


def _title(out: dict) -> str:
    parts = []
    for name, symbol in (("sigma0", "σ0"), ("hardening", "H")):
        if out.get(name) is not None:
            parts.append(f"{symbol} = {out[name]:.4g} ± {out[f'{name}_std']:.2g}")
        elif name in out.get("fitted_parameters", []):
            parts.append(f"{symbol}: not identifiable")
    return (f"{', '.join(parts)}\n{out['iterations']} iterations, "
            f"{out['forward_solves']} model runs")
