"""The damage bar's picture: stress against mean strain, with the closed form.

For the gradient laws, also the crack's damage profile against its closed form.
"""

from __future__ import annotations

import numpy as np
from mpi4py import MPI

from fenics_nl.io import pictures

__all__ = ["stress_strain"]


def stress_strain(out: dict, path: str, law) -> None:
    """σ/σ_c against ε/ε_peak: the law's homogeneous closed form, the uniform bar, more.

    * local law: each localized bar of the mesh table by its end displacement over L (it
      snaps back);
    * gradient laws: where the homogeneous state stops being stable, and a second panel with
      the finest crack's damage profile against (1 − d/(2ℓ))² (AT1) or exp(−d/ℓ) (AT2).
    """
    if MPI.COMM_WORLD.rank != 0:
        return
    plt = pictures.pyplot()
    local = out["model"] == "local"
    eps_c, sigma_c = out["critical_strain_exact"], out["critical_stress_exact"]
    fig, axes = plt.subplots(1, 1 if local else 2, figsize=(6.5 if local else 11, 4.5),
                             squeeze=False)
    ax = axes[0, 0]
    e = np.linspace(0.0, max(out["strain_history"]) / eps_c, 400)
    closed = [law.homogeneous_stress(x * eps_c) / sigma_c for x in e]
    ax.plot(e, closed, "k-", lw=1, label="homogeneous closed form"
            + (": σ = Eε, then w_c/ε" if local else f" ({out['model'].upper()})"))
    ax.plot(np.array(out["strain_history"]) / eps_c, np.array(out["stress_history"]) / sigma_c,
            "o", color="C0", ms=5, label="uniform bar (displacement steps)")
    if local:
        for k, t in enumerate(out["mesh_table"]):
            ax.plot(np.array(t["mean_strain"]) / eps_c, np.array(t["stress"]) / sigma_c, "-",
                    color=f"C{k + 1}", lw=1.5,
                    label=f"weak spot, h = L/{t['cells']}: D = {t['dissipated_energy']:.3g}")
        title = "the course's local damage law: the finer the mesh, the sooner the bar snaps back"
    else:
        if out["bifurcation_strain"] is not None:
            ax.axvline(out["bifurcation_strain"] / eps_c, color="C3", lw=1, ls="--",
                       label=f"loss of stability: ε_b = {out['bifurcation_strain']:.4g} "
                             f"(closed form {out['bifurcation_strain_exact']:.4g})")
        title = (f"{out['model'].upper()}: the homogeneous bar, its loss of stability and "
                 f"its crack")
        _profile(axes[0, 1], out)
    ax.set_xlim(0, e.max())
    ax.set_ylim(0, 1.1)
    ax.set_xlabel("mean strain ε / ε_peak  (end displacement / L)")
    ax.set_ylabel("stress σ / σ_peak")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    pictures.save_figure(fig, path)


def _profile(ax, out: dict) -> None:
    """The finest crack's α(x) against its closed form."""
    t = out["mesh_table"][-1]
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
