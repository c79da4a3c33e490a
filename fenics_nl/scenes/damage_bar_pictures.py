"""The damage bar's picture: stress against mean strain, the closed form and the bars."""

from __future__ import annotations

import numpy as np
from mpi4py import MPI

from fenics_nl.io import pictures

__all__ = ["stress_strain"]


def stress_strain(out: dict, path: str, E: float, w_c: float) -> None:
    """σ/σ_c against ε/ε_c: the law's closed form, the uniform bar, the localized bars.

    Each localized bar of the mesh table by its end displacement over L: it snaps back.
    """
    if MPI.COMM_WORLD.rank != 0:
        return
    plt = pictures.pyplot()
    eps_c, sigma_c = out["critical_strain"], out["critical_stress"]
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    e = np.linspace(0.0, max(out["strain_history"]) / eps_c, 400)
    ax.plot(e, np.where(e <= 1, e, 1 / np.maximum(e, 1e-300)), "k-", lw=1,
            label="closed form: σ = Eε, then w_c/ε")
    ax.plot(np.array(out["strain_history"]) / eps_c, np.array(out["stress_history"]) / sigma_c,
            "o", color="C0", ms=5, label="uniform bar (displacement steps)")
    for k, t in enumerate(out["mesh_table"]):
        ax.plot(np.array(t["mean_strain"]) / eps_c, np.array(t["stress"]) / sigma_c, "-",
                color=f"C{k + 1}", lw=1.5,
                label=f"weak spot, h = L/{t['cells']}: D = {t['dissipated_energy']:.3g}")
    ax.set_xlim(0, e.max())
    ax.set_ylim(0, 1.1)
    ax.set_xlabel("mean strain ε / ε_c  (end displacement / L)")
    ax.set_ylabel("stress σ / σ_c")
    ax.set_title("the course's local damage law: the finer the mesh, the sooner the bar "
                 "snaps back", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    pictures.save_figure(fig, path)
