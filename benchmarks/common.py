"""What every benchmark shares: the machine facts and run time stored with its results,
the documentation's section it regenerates between `<!-- bench:NAME -->` markers
(docs/benchmarks.md, a page of `make docs`), plotting."""

from __future__ import annotations

import os
import platform
import time
from pathlib import Path

import fenics_nl  # first: loads the wheel's MPI/PETSc before dolfinx

fenics_nl.tune_kernel_flags()  # the kernels the demos compile (`import fenics_nl` does not)
_START = time.perf_counter()

ROOT = Path(__file__).resolve().parents[1]
TABLES = ROOT / "docs" / "benchmarks.md"  # where --update-docs writes the tables


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


def options(doc: str, quick: str):
    """The flags every benchmark takes: --quick (`quick` says what it runs) and
    --update-docs; `doc` is the benchmark's docstring."""
    import argparse

    ap = argparse.ArgumentParser(description=doc.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help=quick)
    ap.add_argument("--update-docs", action="store_true")
    return ap.parse_args()


def publish(name: str, out: dict, table, args, say=print) -> None:
    """The end of a benchmark: its run time into `out`, `table(out)` shown, and unless
    --quick the results file benchmarks/results/`name`.json and, with --update-docs,
    the section `name` of docs/benchmarks.md."""
    import json

    out["benchmark_time_s"] = elapsed()
    text = table(out)
    say(text)
    if not args.quick:
        (ROOT / "benchmarks" / "results" / f"{name}.json").write_text(
            json.dumps(out, indent=2))
        if args.update_docs:
            update_docs(name, text)


def update_docs(name: str, text: str) -> None:
    """Replace the generated section `name` of docs/benchmarks.md with `text`."""
    src = TABLES.read_text()
    start, end = f"<!-- bench:{name} -->", f"<!-- /bench:{name} -->"
    i, j = src.index(start) + len(start), src.index(end)
    TABLES.write_text(src[:i] + "\n" + text + "\n" + src[j:])


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
    # between decades only 2 and 5 (0.6, 0.7, 0.8, 0.9 ran together on the contact plot)
    two_five = FuncFormatter(lambda v, _: f"{v:g}" if _mantissa(v) in (2, 5) else "")
    for ax in fig.axes:
        for axis, scale, (lo, hi) in ((ax.xaxis, ax.get_xscale(), ax.get_xlim()),
                                      (ax.yaxis, ax.get_yscale(), ax.get_ylim())):
            if scale != "log":
                continue
            if math.log10(hi / lo) <= 1.5:
                axis.set_major_formatter(plain)
                axis.set_minor_formatter(two_five)
            else:
                axis.set_minor_formatter(NullFormatter())
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"wrote {path}", flush=True)


def _mantissa(v: float) -> int:
    """The leading digit of v > 0 (2 for 0.2, 20, 2e-3)."""
    import math

    return round(v / 10 ** math.floor(math.log10(v) + 1e-9))


def timed_linear_solve(a, L, bcs, kind: str, prefix: str, x=None) -> float:
    """Seconds (slowest rank) to assemble K and F, factorize (or set up GAMG) and solve once.

    The reference of every benchmark's ratio: what one linear solve of the same mesh costs.
    """
    import fenics_nl  # noqa: F401

    # isort: split
    from dolfinx.fem import petsc
    from mpi4py import MPI
    from petsc4py import PETSc

    from fenics_nl.solvers.form_matrix import FormMatrix
    from fenics_nl.solvers.linear_solver import create_ksp

    comm = MPI.COMM_WORLD
    comm.Barrier()
    t0 = time.perf_counter()
    matrix = FormMatrix(a, native=kind in ("lu", "cholesky"))  # the solvers' own assembly
    matrix.assemble(a, bcs)
    A = matrix.mat
    b = petsc.assemble_vector(L)
    b.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
    petsc.set_bc(b, bcs)
    ksp = create_ksp(A, kind, prefix=prefix)
    x = b.duplicate() if x is None else x
    ksp.solve(b, x)
    seconds = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    for obj in (ksp, A, b):
        obj.destroy()
    return seconds
