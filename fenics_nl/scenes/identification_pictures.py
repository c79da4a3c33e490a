"""The identification's picture: the measured curve and the identified one, and the misfit
over (σ0, H) with the fit's iterates on it (the course's figure, and how the fit got there)."""

from __future__ import annotations

import numpy as np
from mpi4py import MPI

from fenics_nl.io import pictures

__all__ = ["identification_figure", "misfit_grid"]


def misfit_grid(model, measured, iterates: np.ndarray, points: int):
    """(σ0 values, H values, ½‖r‖² on their grid): `points`² model runs (collective).

    The grid spans the iterates with a margin; σ0 and H only (the others at their values).
    """
    lo, hi = iterates.min(axis=0), iterates.max(axis=0)
    span = np.maximum(hi - lo, 0.05 * np.abs(hi))
    s = np.linspace(max(lo[0] - 0.15 * span[0], 0.5 * lo[0]), hi[0] + 0.15 * span[0], points)
    h = np.linspace(max(lo[1] - 0.15 * span[1], 0.0), hi[1] + 0.15 * span[1], points)
    misfit = np.full((points, points), np.nan)
    for i, sigma0 in enumerate(s):
        for j, H in enumerate(h):
            model.set(sigma0=float(sigma0), hardening=float(H))
            force = model.run(measured.depth, sensitivities=False).force
            misfit[j, i] = 0.5 * float(np.sum((force - measured.force) ** 2))
    return s, h, misfit


def identification_figure(out: dict, path: str, grid=None, *, units: tuple[str, str]) -> None:
    """The curves (measured dots, identified line, the start dashed), and the misfit map.

    `grid`: `misfit_grid`'s answer, or None (one panel). Drawn on rank 0.
    """
    if MPI.COMM_WORLD.rank != 0:
        return
    plt = pictures.pyplot()
    length, force = units
    fig, axes = plt.subplots(1, 2 if grid is not None else 1,
                             figsize=(11.5 if grid is not None else 6, 4.6), squeeze=False)
    ax = axes[0, 0]
    c = out["curve"]
    ax.plot(c["depth"], c["initial"], "--", color="0.6", label="initial guess")
    ax.plot(c["depth"], c["fitted"], "-", color="C0", lw=2, label="identified")
    ax.plot(c["depth"], c["measured"], "o", color="C3", ms=5, label="measured")
    ax.set_xlabel(f"depth δ ({length})")
    ax.set_ylabel(f"force P ({force})")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left")
    ax.set_title(_title(out), fontsize=9)
    if grid is not None:
        s, h, misfit = grid
        ax = axes[0, 1]
        levels = np.geomspace(max(np.nanmin(misfit), 1e-300), np.nanmax(misfit), 14)
        cs = ax.contourf(s, h, misfit, levels=levels, cmap="viridis",
                         norm=_log_norm(levels))
        fig.colorbar(cs, ax=ax, label=f"misfit ½Σ(P − P_measured)² ({force}²)",
                     format="%.0e")
        path_ = np.array(out["iterates"])
        ax.plot(path_[:, 0], path_[:, 1], "o-", color="w", ms=4, lw=1.2,
                label="Levenberg–Marquardt iterates")
        ax.plot(*path_[0], "s", color="w", ms=7)
        ax.plot(*path_[-1], "*", color="C3", ms=14, label="identified")
        if out.get("true_sigma0") is not None:
            ax.plot(out["true_sigma0"], out["true_hardening"], "+", color="k", ms=14, mew=2,
                    label="true (synthetic)")
        ax.set_xlabel(f"yield stress σ0 ({out['stress_unit']})")
        ax.set_ylabel(f"hardening modulus H ({out['stress_unit']})")
        ax.legend(loc="upper right", fontsize=8)
        ax.set_title(f"the misfit over (σ0, H): {len(s)}×{len(h)} model runs", fontsize=9)
    pictures.save_figure(fig, path)


def _log_norm(levels):
    from matplotlib.colors import LogNorm

    return LogNorm(vmin=levels[0], vmax=levels[-1])


def _title(out: dict) -> str:
    parts = []
    for name, symbol in (("sigma0", "σ0"), ("hardening", "H")):
        if out.get(name) is not None:
            parts.append(f"{symbol} = {out[name]:.4g} ± {out[f'{name}_std']:.2g}")
        elif name in out.get("fitted_parameters", []):
            parts.append(f"{symbol}: not identifiable")
    return (f"{', '.join(parts)}; {out['iterations']} iterations, "
            f"{out['forward_solves']} model runs")
