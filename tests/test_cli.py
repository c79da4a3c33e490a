import argparse

import pytest

from fenics_nl.io.cli import parse_with_petsc_options


def parser():
    p = argparse.ArgumentParser()
    p.add_argument("--steps", type=int, default=1)
    return p


def test_petsc_options_and_their_values_pass_through():
    argv = ["--steps", "3", "-ksp_monitor", "-pc_type", "lu", "-ksp_rtol", "1e-6",
            "-snes_linesearch_damping", "-0.5", "-log_view"]
    args, petsc = parse_with_petsc_options(parser(), argv)
    assert args.steps == 3
    assert petsc == argv[2:]


@pytest.mark.parametrize("argv", [["--stepz", "3"], ["stray"], ["-ksp_rtol", "1e-6", "stray"]])
def test_anything_else_is_one_clear_error(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        parse_with_petsc_options(parser(), argv)
    assert exc.value.code == 2
    assert "unrecognized arguments" in capsys.readouterr().err


def test_a_dolfinx_script_that_imports_dolfinx_first_runs_in_the_venv(tmp_path):
    # make installs a finder that loads the wheel's MPI before dolfinx's compiled modules
    import subprocess
    import sys

    script = tmp_path / "user.py"
    script.write_text("import dolfinx\nfrom dolfinx import mesh\nfrom mpi4py import MPI\n"
                      "m = mesh.create_unit_square(MPI.COMM_WORLD, 2, 2)\n"
                      "print(m.topology.index_map(2).size_global)\n")
    proc = subprocess.run([sys.executable, script], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0 and proc.stdout.strip() == "8", proc.stderr


def test_an_old_spelling_is_read_said_once_and_never_written(tmp_path, demo):
    # one vocabulary (fenics_nl.vocabulary): plane_strain, bfgs, lu/gamg; the old spellings
    # still read, each with one note, and the outputs use the new one
    import json

    from fenics_nl.vocabulary import OLD_SPELLINGS, canonical

    proc = demo.run(["punch.py", "--model", "plane-strain", "--refine", "0", "--json",
                     tmp_path / "p.json"])
    notes = [line for line in proc.stderr.splitlines() if line.startswith("note:")]
    assert len(notes) == 1 and "'plane_strain'" in notes[0], proc.stderr
    assert json.loads((tmp_path / "p.json").read_text())["model"] == "plane_strain"
    assert {canonical(old, "x") for old in OLD_SPELLINGS} == {"bfgs", "plane_strain",
                                                              "plane_stress", "lu", "gamg"}
    assert canonical("full", "x") == "full"
