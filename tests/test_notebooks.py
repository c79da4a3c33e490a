"""Every demo runs as a notebook, as the README says: converted by jupytext and executed in
a Jupyter kernel (nbclient), cell by cell, with the flags a user puts in FENICS_NL_ARGS;
its results are those of the same demo run as a script."""

import json

import jupytext
import nbformat
import pytest
from conftest import DEMOS
from demo_snapshot import differences

# each demo at the small size its other tests use
SMALL = {
    "newton_scalar.py": [],
    "punch.py": ["--refine", "0", "--block", "10"],
    "bracket.py": ["--size", "20", "--steps", "1"],
    "buckling_beam.py": ["--load-ratio", "1.2", "--steps", "10"],
    "pressure_vessel.py": [],
    "snap_through.py": [],
}


def test_every_demo_is_run_as_a_notebook():
    assert set(SMALL) == {p.name for p in DEMOS.glob("*.py")}


@pytest.mark.parametrize("name", sorted(SMALL))
def test_the_demo_runs_as_a_notebook_with_the_scripts_answer(name, demo, tmp_path,
                                                             monkeypatch):
    from nbclient import NotebookClient

    nb = jupytext.read(DEMOS / name)
    nb.cells.append(nbformat.v4.new_code_cell(
        "import json\nfrom fenics_nl.io import cli\nprint(json.dumps(cli.notebook_results()))"))
    monkeypatch.setenv("FENICS_NL_ARGS", " ".join(SMALL[name]))
    NotebookClient(nb, timeout=600, kernel_name="python3",
                   resources={"metadata": {"path": str(tmp_path)}}).execute()
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
              if o.output_type == "error"]
    assert not errors, errors
    printed = "".join(o.get("text", "") for o in nb.cells[-1].outputs
                      if o.output_type == "stream")
    in_notebook = json.loads(printed)
    as_script = demo.json(name, *SMALL[name])
    assert in_notebook and differences(
        {k: as_script[k] for k in in_notebook}, in_notebook, name) == []
