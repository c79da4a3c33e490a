"""Every demo as an executed notebook, as a user runs it: the script converted by jupytext
and executed cell by cell in a Jupyter kernel (nbclient), with its flags in FENICS_NL_ARGS.

    python docs/notebooks.py          # docs/demos/<demo>.ipynb, executed, and its pictures

`make docs` runs it before Sphinx (which then executes nothing); tests/test_notebooks.py
runs the same `execute` and compares each notebook's results with the script's.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEMOS = ROOT / "demos"
OUT = ROOT / "docs" / "demos"

# each demo at a small size (the one its tests use): the pages show what a laptop runs in
# seconds; the demos' --help gives the sizes of the README's figures
SMALL = {
    "newton_scalar.py": [],
    "punch.py": ["--refine", "0"],
    "bracket.py": ["--size", "20", "--steps", "1"],
    "buckling_beam.py": ["--load-ratio", "1.2", "--steps", "10"],
    "pressure_vessel.py": [],
    "snap_through.py": [],
}
# the pictures each page shows (the demo's own --png and --plot)
PICTURES = {"newton_scalar.py": ["--plot"]}

_RESULTS_CELL = ("import json\nfrom fenics_nl.io import cli\n"
                 "print(json.dumps(cli.notebook_results()))")


def pictures(name: str) -> list[str]:
    """The flags that make demo `name` draw its pictures next to its notebook."""
    stem = Path(name).stem
    flags = PICTURES.get(name, ["--png", "--plot"])
    return [a for f in flags for a in (f, f"{stem}{'' if f == '--png' else '_plot'}.png")]


def execute(name: str, args: list[str], cwd: Path, timeout: int = 900):
    """Run demos/`name` as a notebook in `cwd` with `args`: (the notebook, its results)."""
    import jupytext
    import nbformat
    from nbclient import NotebookClient

    nb = jupytext.read(DEMOS / name)
    nb.cells.append(nbformat.v4.new_code_cell(_RESULTS_CELL))
    before = os.environ.get("FENICS_NL_ARGS")
    os.environ["FENICS_NL_ARGS"] = " ".join(args)  # the kernel inherits it
    try:
        NotebookClient(nb, timeout=timeout, kernel_name="python3",
                       resources={"metadata": {"path": str(cwd)}}).execute()
    finally:
        if before is None:
            os.environ.pop("FENICS_NL_ARGS")
        else:
            os.environ["FENICS_NL_ARGS"] = before
    last = nb.cells.pop()  # the results cell is the harness's, not the page's
    printed = "".join(o.get("text", "") for o in last.outputs if o.output_type == "stream")
    return nb, json.loads(printed)


def main() -> int:
    import nbformat

    OUT.mkdir(parents=True, exist_ok=True)
    for name, args in SMALL.items():
        print(f"executing {name} {' '.join(args)}", flush=True)
        nb, _ = execute(name, args + pictures(name), OUT)
        nbformat.write(nb, OUT / f"{Path(name).stem}.ipynb")
    return 0


if __name__ == "__main__":
    sys.exit(main())
