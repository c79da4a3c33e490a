"""Every demo as an executed notebook, as a user runs it: the script converted by jupytext
and executed cell by cell in a Jupyter kernel (nbclient), with its flags in FENICS_NL_ARGS.

    python docs/notebooks.py          # docs/demos/<demo>.ipynb, executed, and its pictures

`make docs` runs it before Sphinx (which then executes nothing); tests/test_notebooks.py
runs the same `execute`, compares each notebook's results with the script's and keeps the
executed notebook as the page (`save_page`): a page made from the same code (the digest of
the library, the demos and the pins) with the same flags is not executed again.
"""

from __future__ import annotations

import json
import os
import shlex
import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEMOS = ROOT / "demos"
OUT = ROOT / "docs" / "demos"

# each demo at a small size (the one its tests use): the pages show what a laptop runs in
# seconds; the README's figures are `make demo`'s runs (the Makefile gives their flags)
SMALL = {
    "newton_scalar.py": [],
    "punch.py": ["--refine", "0"],
    # its defaults but the tangential load by the punch's position (16 s, not 28 s)
    "punch_friction.py": ["--tangential-displacement", "0.0023"],
    "indentation.py": ["--refine", "0", "--steps", "2"],
    "bracket.py": ["--size", "20", "--steps", "1"],
    "buckling_beam.py": ["--load-ratio", "1.2", "--steps", "10"],
    "pressure_vessel.py": [],
    "creep_vessel.py": [],
    "bearing.py": [],
    "excavation.py": [],
    "upsetting.py": [],
    "forging.py": [],
    "snap_through.py": [],
    "damage_bar.py": [],
    "crack.py": ["--ell", "0.05", "--steps", "8"],
    # the misfit map of its page from 3×3 runs (the default 5×5)
    "indentation_identification.py": ["--map", "3"],
}
# the pictures each page shows (the demo's own --png and --plot)
PICTURES = {"newton_scalar.py": ["--plot"], "damage_bar.py": ["--plot"], "crack.py": ["--plot"],
            "indentation_identification.py": ["--plot"], "excavation.py": ["--plot"]}

_RESULTS_CELL = ("import json\nfrom fenics_nl.io import cli\n"
                 "print(json.dumps(cli.notebook_results()))")


def pictures(name: str) -> list[str]:
    """The flags that make demo `name` draw its pictures next to its notebook."""
    stem = Path(name).stem
    flags = PICTURES.get(name, ["--png", "--plot"])
    return [a for f in flags for a in (f, f"{stem}{'' if f == '--png' else '_plot'}.png")]


def execute(name: str, args: list[str], cwd: Path, timeout: int = 900):
    """Run demos/`name` as a notebook in `cwd` with `args`: (the notebook, its results)."""
    OUT.mkdir(parents=True, exist_ok=True)
    import jupytext
    import nbformat
    from nbclient import NotebookClient

    nb = jupytext.read(DEMOS / name)
    nb.cells.append(nbformat.v4.new_code_cell(_RESULTS_CELL))
    before = os.environ.get("FENICS_NL_ARGS")
    os.environ["FENICS_NL_ARGS"] = shlex.join(args)  # the kernel inherits it
    try:
        NotebookClient(nb, timeout=timeout, kernel_name="python3",
                       resources={"metadata": {"path": str(cwd)}}).execute()
    finally:
        if before is None:
            os.environ.pop("FENICS_NL_ARGS")
        else:
            os.environ["FENICS_NL_ARGS"] = before
    last = nb.cells.pop()  # the results cell is the harness's, not the page's
    printed = "".join(o.get("text", "") for o in last.outputs
                      if o.output_type == "stream" and o.get("name") == "stdout")
    return nb, json.loads(printed)


def source_digest() -> str:
    """A digest of what a demo's answer depends on: the library, the demos, the pins."""
    import hashlib

    h = hashlib.sha256()
    for path in sorted([*ROOT.glob("fenics_nl/**/*.py"), *DEMOS.glob("*.py"),
                        ROOT / "pyproject.toml"]):
        h.update(path.relative_to(ROOT).as_posix().encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def page_args(name: str) -> list[str]:
    """The flags of the documentation's page of demo `name`: its small size, its pictures."""
    return SMALL[name] + pictures(name)


def save_page(nb, name: str, cwd: Path) -> None:
    """Keep `nb`, executed in `cwd` with `page_args(name)`, and its pictures as the page."""
    import nbformat

    OUT.mkdir(parents=True, exist_ok=True)
    for picture in pictures(name)[1::2]:
        if cwd != OUT:
            shutil.copyfile(cwd / picture, OUT / picture)
    nb.metadata["fenics_nl"] = {"digest": source_digest(), "args": page_args(name)}
    nbformat.write(nb, OUT / f"{Path(name).stem}.ipynb")


def is_current(name: str) -> bool:
    """Whether the page of `name` was made by this code with these flags."""
    import nbformat

    path = OUT / f"{Path(name).stem}.ipynb"
    if not path.is_file() or not all((OUT / p).is_file() for p in pictures(name)[1::2]):
        return False
    made = nbformat.read(path, as_version=4).metadata.get("fenics_nl", {})
    return made == {"digest": source_digest(), "args": page_args(name)}


def main() -> int:
    for name in SMALL:
        if is_current(name):
            print(f"{name}: its page is current (executed by the tests)")
            continue
        print(f"executing {name} {' '.join(page_args(name))}", flush=True)
        nb, _ = execute(name, page_args(name), OUT)
        save_page(nb, name, OUT)
    return 0


if __name__ == "__main__":
    sys.exit(main())
