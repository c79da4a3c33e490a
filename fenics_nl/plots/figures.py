"""What every picture module draws with: matplotlib on Agg, and pyvista off-screen.

Figures are files: no display is needed, and a figure is closed once written (runs in one
process add up).
"""

from __future__ import annotations

import os

__all__ = ["off_screen", "pyplot", "save_figure"]


def pyplot():
    """matplotlib.pyplot on the Agg backend: figures are files, no display is needed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path) -> None:
    """Lay out, write and close a matplotlib figure (closed: runs in one process add up)."""
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    pyplot().close(fig)
    print(f"wrote {path}")


def off_screen():
    """pyvista, set for off-screen rendering without the VTK X-server noise."""
    os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
    import pyvista
    import vtk

    vtk.vtkObject.GlobalWarningDisplayOff()  # "bad X server connection" is not an error
    pyvista.OFF_SCREEN = True
    return pyvista
