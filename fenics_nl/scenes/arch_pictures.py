"""The arch's pictures, against the shallow-arch closed form (Fung–Kaplan).

The arc-length path in load against midspan rise, and the centreline at states along it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from fenics_nl.io import pictures
from fenics_nl.theory import arch as theory

__all__ = ["ArchRun", "path_against_theory", "shapes_along_the_path"]


@dataclass
class ArchRun:
    """What the pictures read of a snap-through run.

    Args:
        history: (q0 in units of EI k⁴ r, midspan rise a/r) of every state, from rest.
        shapes: (q0, centreline points) of every state, on rank 0.
        limits: the limit points found (`CriticalPoint` records); first_limit: the first one's
            load factor, or None.
        q_limit, a_limit: the closed form's limit load and its rise.
        rise, slenderness, span: the arch (e/r, L/h, L); newton: the corrector's variant.
    """

    history: list
    shapes: list
    limits: list
    first_limit: float | None
    q_limit: float
    a_limit: float
    rise: float
    slenderness: float
    span: float
    newton: str


def path_against_theory(run: ArchRun, path: str, comm=MPI.COMM_WORLD) -> None:
    """q0 against the midspan rise: the FE states on the closed form, the limit points."""
    if comm.rank != 0:
        return
    history, limits, q_limit, rise = run.history, run.limits, run.q_limit, run.rise
    h = np.array(history)
    plt = pictures.pyplot()
    fig, ax = plt.subplots(figsize=(7, 5))
    a = np.linspace(min(h[:, 1].min(), -rise) * 1.05, rise * 1.02, 400)
    ax.plot(a, [theory.load(x, rise) / q_limit for x in a], "-", color="k", lw=1,
            label="shallow-arch closed form")
    ax.plot(h[:, 1], h[:, 0] / q_limit, "o", ms=3, color="tab:blue",
            label=f"FE, arc-length ({run.newton} Newton)")
    at = {round(x, 12): a for x, a in history}  # the rise of each state, by its load
    for c in limits:
        ax.plot(at.get(round(c.factor, 12), np.nan), c.factor / q_limit, "s", ms=9,
                mfc="none", color="tab:red")
    if limits:
        ax.plot([], [], "s", ms=9, mfc="none", color="tab:red", label="limit points found")
    ax.axhline(0, color="gray", lw=0.5)
    ax.invert_xaxis()  # the arch flattens and inverts as the load grows: read left to right
    ax.set_xlabel("midspan rise a / r (e/r at rest)")
    ax.set_ylabel("load q0 / q_limit (closed form)")
    first = run.first_limit
    err = f"{100 * (first / q_limit - 1):+.2f} %" if first is not None else "not met"
    ax.set_title(f"shallow arch e/r = {rise:g}, L/h = {run.slenderness:g}: limit load "
                 f"{err} from the closed form", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    pictures.save_figure(fig, path)


def shapes_along_the_path(run: ArchRun, path: str, comm=MPI.COMM_WORLD) -> None:
    """The centreline at states along the path (dashed: the unstable ones)."""
    if comm.rank != 0:
        return
    history, shapes, q_limit, a_limit = run.history, run.shapes, run.q_limit, run.a_limit
    rise = run.rise
    plt = pictures.pyplot()
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
    ax.plot([0, run.span], [0, 0], "k^", ms=8, label="pins")
    ax.set_xlabel("x [length]")
    ax.set_ylabel("y [length] (vertical scale exaggerated)")
    ax.set_title(f"the arch's centreline along the path, downward load q0 sin(πx/L) "
                 f"(e/r = {rise:g}, L/h = {run.slenderness:g})", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    pictures.save_figure(fig, path)
