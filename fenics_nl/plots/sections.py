"""Cell fields on a 2D section, beside profiles along lines, with matplotlib (rank 0 draws).

`fields_and_profiles`: each field (DG0) on the undeformed section, one panel each,
then one panel per set of profiles (a quantity along a line after each stage or step, a
curve each). Fields come from `output.section` (gathered on rank 0), profiles are plain
arrays the same on every rank.
"""

from __future__ import annotations

from dolfinx import fem

from fenics_nl.io import output
from fenics_nl.plots import figures

__all__ = ["fields_and_profiles"]


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
