"""What every benchmark shares: the machine facts and run time stored with its results,
the README section it regenerates between `<!-- bench:NAME -->` markers, plotting."""

from __future__ import annotations

import os
import platform
import time
from pathlib import Path

_START = time.perf_counter()

README = Path(__file__).resolve().parents[1] / "README.md"


def machine(ranks: int = 1) -> dict:
    """Cores, ranks and versions, so that a result file says where it was measured."""
    import fenics_nl  # noqa: F401  (first: loads the wheel's MPI before dolfinx)

    # isort: split
    import dolfinx
    from petsc4py import PETSc

    return {"cores": os.cpu_count(), "ranks": ranks, "platform": platform.platform(),
            "python": platform.python_version(), "dolfinx": dolfinx.__version__,
            "petsc": ".".join(map(str, PETSc.Sys.getVersion()))}


def elapsed() -> float:
    """Seconds since the benchmark started (this module's import): its run time."""
    return time.perf_counter() - _START


def outside_kernels(r: dict) -> float:
    """Wall time of a Newton run (newton.json) not spent assembling, factorizing or
    solving: the loop's own cost."""
    return r["wall_time_s"] - sum(r["phase_time_s"].values())


def update_readme(name: str, text: str) -> None:
    """Replace the README's generated section `name` with `text`."""
    src = README.read_text()
    start, end = f"<!-- bench:{name} -->", f"<!-- /bench:{name} -->"
    i, j = src.index(start) + len(start), src.index(end)
    README.write_text(src[:i] + "\n" + text + "\n" + src[j:])


def pyplot():
    """matplotlib's pyplot without a display."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path: Path) -> None:
    """Write `fig`. Log axes: short plain labels when they span up to 1.5 decades,
    decade labels only when they span more (minor labels would overlap)."""
    import math

    from matplotlib.ticker import FuncFormatter, NullFormatter

    plain = FuncFormatter(lambda v, _: f"{v:g}")
    for ax in fig.axes:
        for axis, scale, (lo, hi) in ((ax.xaxis, ax.get_xscale(), ax.get_xlim()),
                                      (ax.yaxis, ax.get_yscale(), ax.get_ylim())):
            if scale != "log":
                continue
            if math.log10(hi / lo) <= 1.5:
                axis.set_major_formatter(plain)
                axis.set_minor_formatter(plain)
            else:
                axis.set_minor_formatter(NullFormatter())
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"wrote {path}", flush=True)
