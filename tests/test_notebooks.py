"""Every demo runs as a notebook, as the README says: converted by jupytext and executed in
a Jupyter kernel (nbclient), cell by cell, with the flags a user puts in FENICS_NL_ARGS;
its results are those of the same demo run as a script (`docs/notebooks.py`, which makes
the documentation's pages the same way)."""

import pytest
from conftest import DEMOS
from demo_snapshot import differences
from notebooks import SMALL, execute, page_args, save_page
from test_demos import identification_recovers_sigma0_and_hardening_within_their_spread
from test_friction import cattaneo_mindlin_partial_slip_of_a_cylinder

# what a page's run must show, beyond running: its checks against theory (on the run the
# page makes: the same flags again elsewhere would make it a second time)
CHECKS = {"punch_friction.py": cattaneo_mindlin_partial_slip_of_a_cylinder,
          "indentation_identification.py":
              identification_recovers_sigma0_and_hardening_within_their_spread}


def test_every_demo_is_run_as_a_notebook():
    assert set(SMALL) == {p.name for p in DEMOS.glob("*.py")}


@pytest.mark.parametrize("name", sorted(SMALL))
def test_the_demo_runs_as_a_notebook_with_the_scripts_answer(name, demo, tmp_path):
    # the script first: its run is shared with the tests that ask for the same flags, which
    # then find it (pytest's cache) instead of running it again while the notebook runs
    as_script = demo.json(name, *SMALL[name])
    # with the documentation page's flags (its pictures too): the notebook is the page
    nb, in_notebook = execute(name, page_args(name), tmp_path)
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
              if o.output_type == "error"]
    assert not errors, errors
    shown = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
             if "image/png" in o.get("data", {})]
    assert len(shown) == len(page_args(name)[len(SMALL[name]):]) // 2  # every picture
    assert in_notebook and differences(
        {k: as_script[k] for k in in_notebook}, in_notebook, name) == []
    CHECKS.get(name, lambda d: None)(as_script)
    save_page(nb, name, tmp_path)  # `make docs` then executes it no more


def test_a_notebook_refuses_what_only_a_script_writes(tmp_path):
    # --json (or --output, checkpoints, PETSc options) in FENICS_NL_ARGS would be silently
    # dropped in a kernel: it is an error instead, naming the flag
    from nbclient.exceptions import CellExecutionError

    with pytest.raises(CellExecutionError, match="--json: only when the demo runs as a"):
        execute("newton_scalar.py", ["--json", "x.json"], tmp_path)
