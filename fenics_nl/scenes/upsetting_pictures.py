"""The upsetting's pictures.

The barrelled billet with the die and the statuses, and the force–reduction curve against
the frictionless closed form and the slab estimate.
"""

from __future__ import annotations

import numpy as np

from fenics_nl.io import pictures

__all__ = ["billet_picture", "force_curve"]


def billet_picture(up, path: str, title: str) -> None:
    """The deformed half billet coloured by p (cell max), the die, the statuses (collective).

    True scale (the die is drawn); sticking and slipping nodes at their current positions.
    """
    S = up.contact.surface
    x = up.contact.x[:, :2].copy()
    x[:, 0] = up.current_radius()
    x[:, 1] += up.u.x.array[S.dofs_V]  # u_z (S_C's normal component)
    owned = up.contact.owned & up.contact.active
    if up.friction > 0:
        marked = {"sticking nodes": x[owned & up.contact.stick],
                  "slipping nodes": x[owned & up.contact.slip]}
    else:
        marked = {"nodes on the die": x[owned]}
    top = 0.5 * up.billet.height * (1.0 - up.reduction)
    pictures.deformed_picture(
        up.billet.displacement(), up.material.cumulated_plastic_strain_per_cell(), path,
        title, marked=marked, label="cumulated plastic strain p",
        axes=("r (length)", "z (length)"),
        obstacle={"obstacle": "plane", "point": [0.0, top], "normal": [0.0, 1.0]})


def force_curve(history: list[dict], friction: float, path: str, title: str) -> None:
    """F against the reduction, with the frictionless closed form and the slab estimate."""
    plt = pictures.pyplot()
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
    pictures.save_figure(fig, path)
