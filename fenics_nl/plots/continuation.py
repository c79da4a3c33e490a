"""Equilibrium paths against their closed forms: the shallow arch's and the buckling beam's.

Each path is drawn twice: the load against a displacement (the computed states on the closed
form's curve) and the deformed centreline at states along it. The arch's states come from
arc-length continuation (`demos/snap_through.py`, against `theory.arch`), the beam's from
load steps or arc-length (`demos/buckling_beam.py`, against `theory.elastica`). Every
function takes plain values (the states as rows of numbers, centrelines as point arrays on
rank 0) and draws on rank 0.
"""

from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI

from fenics_nl.plots import figures
from fenics_nl.theory import arch, elastica

__all__ = ["arch_path", "arch_shapes", "path_against_elastica", "shapes_against_elastica"]


def arch_path(history, limits, q_limit: float, rise: float, slenderness: float, newton: str,
              path: str, comm=MPI.COMM_WORLD) -> None:
    """q0 against the midspan rise: the FE states on the shallow-arch cubic, the limit points.

    Args:
        history: (q0 in units of EI k⁴ r, midspan rise a/r) of every state, from rest.
        limits: the load factors of the limit points found, in the order met.
        q_limit: the closed form's limit load (EI k⁴ r).
        rise: e/r, the rise at rest over the section's radius of gyration.
        slenderness: L/h.
        newton: the corrector's Newton variant (the legend).
        path: the PNG to write.
        comm: the communicator (rank 0 draws).
    """
    if comm.rank != 0:
        return
    h = np.array(history)
    plt = figures.pyplot()
    fig, ax = plt.subplots(figsize=(7, 5))
    a = np.linspace(min(h[:, 1].min(), -rise) * 1.05, rise * 1.02, 400)
    ax.plot(a, [arch.load(x, rise) / q_limit for x in a], "-", color="k", lw=1,
            label="shallow-arch closed form")
    ax.plot(h[:, 1], h[:, 0] / q_limit, "o", ms=3, color="tab:blue",
            label=f"FE, arc-length ({newton} Newton)")
    at = {round(x, 12): a for x, a in history}  # the rise of each state, by its load
    for factor in limits:
        ax.plot(at.get(round(factor, 12), np.nan), factor / q_limit, "s", ms=9,
                mfc="none", color="tab:red")
    if limits:
        ax.plot([], [], "s", ms=9, mfc="none", color="tab:red", label="limit points found")
    ax.axhline(0, color="gray", lw=0.5)
    ax.invert_xaxis()  # the arch flattens and inverts as the load grows: read left to right
    ax.set_xlabel("midspan rise a / r (e/r at rest)")
    ax.set_ylabel("load q0 / q_limit (closed form)")
    err = f"{100 * (limits[0] / q_limit - 1):+.2f} %" if limits else "not met"
    ax.set_title(f"shallow arch e/r = {rise:g}, L/h = {slenderness:g}: limit load "
                 f"{err} from the closed form", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    figures.save_figure(fig, path)


def arch_shapes(history, shapes, q_limit: float, a_limit: float, rise: float,
                slenderness: float, span: float, path: str, comm=MPI.COMM_WORLD) -> None:
    """The arch's centreline at states along the path (dashed: the unstable ones).

    Args:
        history: (q0 in units of EI k⁴ r, midspan rise a/r) of every state, from rest.
        shapes: (q0, centreline points) of every state, on rank 0.
        q_limit: the closed form's limit load (EI k⁴ r).
        a_limit: the closed form's rise at the limit load (a/r): the states with a smaller
            |a| are unstable.
        rise: e/r at rest.
        slenderness: L/h.
        span: L (where the pins are drawn).
        path: the PNG to write.
        comm: the communicator (rank 0 draws).
    """
    if comm.rank != 0:
        return
    plt = figures.pyplot()
    fig, ax = plt.subplots(figsize=(9.5, 3.5))
    picks = shapes[:: max(1, len(shapes) // 8)] + shapes[-1:]
    cmap = plt.get_cmap("viridis")
    rise_at = dict(history)
    for i, (lam, pts) in enumerate(picks):
        a = rise_at[lam]
        where = "unstable" if abs(a) < a_limit else "stable"
        ax.plot(pts[:, 0], pts[:, 1], color=cmap(i / max(1, len(picks) - 1)), lw=1.5,
                ls="--" if where == "unstable" else "-",
                label=f"q0 = {lam / q_limit:.2f} q_limit, a/r = {a:.2f} ({where})")
    ax.plot([0, span], [0, 0], "k^", ms=8, label="pins")
    ax.set_xlabel("x [length]")
    ax.set_ylabel("y [length] (vertical scale exaggerated)")
    ax.set_title(f"the arch's centreline along the path, downward load q0 sin(πx/L) "
                 f"(e/r = {rise:g}, L/h = {slenderness:g})", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    figures.save_figure(fig, path)


def path_against_elastica(history, length: float, thickness: float, imperfection: float,
                          load_ratio: float, path: str, comm=MPI.COMM_WORLD) -> None:
    """P/P_cr against the tip rotation and the lateral deflection, FE on the elastica.

    Args:
        history: (P/P_cr, tip rotation in degrees, lateral tip deflection) of every state.
        length: the beam's L.
        thickness: its h.
        imperfection: the lateral end load as a fraction of P (the title).
        load_ratio: the last load P/P_cr.
        path: the PNG to write.
        comm: the communicator (rank 0 draws).
    """
    if comm.rank != 0:
        return
    plt = figures.pyplot()

    h = np.array(history)
    top = max(h[:, 0].max(), 1.1) * 1.05
    alpha_top = math.radians(min(179, 1.15 * max(h[:, 1].max(), 10)))
    alpha = np.linspace(1e-3, alpha_top, 300)
    ratio = np.array([elastica.load_ratio(a) for a in alpha])
    keep = ratio <= top
    k = np.sin(alpha / 2)
    from scipy.special import ellipk

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    a1.plot(np.degrees(alpha[keep]), ratio[keep], "-", label="elastica")
    a1.plot(h[:, 1], h[:, 0], "o", ms=3, label="finite strain FE")
    a1.set_xlabel("tip rotation α [deg]")
    a2.plot((2 * k / ellipk(k * k) * length)[keep], ratio[keep], "-", label="elastica")
    a2.plot(h[:, 2], h[:, 0], "o", ms=3, label="finite strain FE")
    a2.set_xlabel("lateral tip deflection [length]")
    for a in (a1, a2):
        a.axhline(1.0, color="gray", lw=0.5)
        a.set_ylim(0, top)
        a.set_xlim(left=0)
        a.set_ylabel("P / P_cr (Euler)")
        a.grid(alpha=0.3)
        a.legend()
    fig.suptitle(f"cantilever, L/h = {length / thickness:g}, imperfection "
                 f"{imperfection:g} P: P/P_cr = {load_ratio:g}, α = {h[-1, 1]:.2f}° "
                 f"(elastica {math.degrees(elastica.tip_rotation(load_ratio)):.2f}°)")
    figures.save_figure(fig, path)


def shapes_against_elastica(shapes, length: float, imperfection: float, load_ratio: float,
                            path: str, comm=MPI.COMM_WORLD) -> None:
    """Computed centrelines past P_cr (solid) on the elastica's (dashed), same colours.

    Args:
        shapes: (P/P_cr, centreline points sorted from the clamp) of the states, on rank 0.
        length: the beam's L.
        imperfection: the lateral end load as a fraction of P (the title).
        load_ratio: the last load P/P_cr.
        path: the PNG to write.
        comm: the communicator (rank 0 draws).
    """
    if comm.rank != 0:
        return
    plt = figures.pyplot()

    fig, ax = plt.subplots(figsize=(7, 6))
    L = length
    ax.plot([0, L], [0, 0], "k:", lw=0.8, label="undeformed")
    # below P_cr the beam stays straight: one shape stands for them all
    # past 1.05 P_cr: closer to P_cr the imperfect beam still lags behind the perfect
    # elastica (the imperfection's amplification), which would read as a disagreement
    buckled = [s for s in shapes if s[0] >= 1.05]
    picks = buckled[:: max(1, len(buckled) // 6)] + shapes[-1:]
    picks = list({round(r, 6): (r, pts) for r, pts in picks}.values())
    cmap = plt.get_cmap("viridis")
    top = max(s[0] for s in picks)
    sign = 1 if picks[-1][1][-1, 1] >= 0 else -1  # the side the beam buckled to, at the end
    # states the path left straight past P_cr (unstable: the end state was switched off it)
    straight = [r for r, pts in picks[:-1]
                if abs(pts[-1, 1]) < 0.01 * elastica.tip_position(r)[0] * L]
    for r, pts in picks:
        if r in straight:  # no buckled FE shape to set the elastica against
            continue
        colour = cmap(0.1 + 0.8 * (r - 1) / max(top - 1, 1e-9))
        ax.plot(pts[:, 0], pts[:, 1], color=colour, lw=2, label=f"FE, P/P_cr = {r:.3g}")
        xe, ye = elastica.shape(r)
        ax.plot(xe * L, sign * ye * L, "--", color="k", lw=0.8)
    if straight:
        ax.plot([0, L], [0, 0], color="tab:red", lw=2,
                label="FE, still straight (unstable) at P/P_cr = " + (
                    f"{straight[0]:.3g}" if len(straight) == 1
                    else f"{straight[0]:.3g}–{straight[-1]:.3g}"))
    ax.plot([], [], "--", color="k", lw=0.8, label="elastica (same loads)")
    ax.annotate("clamped", (0, 0), xytext=(-0.12 * L, -0.08 * L), fontsize=8,
                arrowprops={"arrowstyle": "->"})
    tip = picks[-1][1][-1]  # the dead load P at the last tip, along −x whatever the rotation
    ax.annotate(f"P = {picks[-1][0]:.3g} P_cr (dead)", tip, xytext=(tip[0] + 0.22 * L, tip[1]),
                fontsize=8, color="tab:red", va="center",
                arrowprops={"arrowstyle": "-|>", "color": "tab:red", "lw": 1.5})
    ax.set_aspect("equal")
    ax.set_xlabel("x [length]")
    ax.set_ylabel("y [length]")
    alpha = math.degrees(math.atan2(*np.diff(picks[-1][1][-2:], axis=0)[0][::-1]))
    ax.set_title(f"buckled cantilever, dead end load up to P/P_cr = {load_ratio:g} "
                 f"(imperfection {imperfection:g} P)\nend slope at the last load "
                 f"{abs(alpha):.1f}°, elastica "
                 f"{math.degrees(elastica.tip_rotation(load_ratio)):.1f}°", fontsize=10)
    ax.legend(fontsize=8, loc="best")
    ax.grid(alpha=0.3)
    figures.save_figure(fig, path)
