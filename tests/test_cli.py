import argparse
import sys

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


def test_a_flag_is_taken_whole(capsys):
    # argparse's abbreviations would read an old flag as a new one: `--slip` (a length)
    # became `--slip-ratio` in demos/forging.py, and `--slip 0.01` ran as a ratio
    from fenics_nl.io import flags

    p = flags.parser("x")
    p.add_argument("--slip-ratio", type=float, default=0.05)
    with pytest.raises(SystemExit) as exc:
        parse_with_petsc_options(p, ["--slip", "0.01"])
    assert exc.value.code == 2 and "unrecognized arguments: --slip" in capsys.readouterr().err
    assert parse_with_petsc_options(p, ["--slip-ratio", "0.01"])[0].slip_ratio == 0.01


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


FORGETFUL = '''from dataclasses import dataclass

import fenics_nl  # noqa: F401
from fenics_nl.io import cli
from fenics_nl.io.parameters import Parameters, number


@dataclass
class P(Parameters):
    """A script that solves and never reports."""

    x: float = number(1.0, "x")


cli.run_script(__name__)
args = cli.arguments(P, prefixes={})
print("solved", args.x)
'''


def test_a_script_that_never_reports_its_results_fails(tmp_path):
    # nothing written, nothing said: a status 0 would be a lie
    import subprocess

    script = tmp_path / "forgetful.py"
    script.write_text(FORGETFUL)
    proc = subprocess.run([sys.executable, script], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 1 and "solved 1.0" in proc.stdout
    assert "ended without reporting its results" in proc.stderr, proc.stderr
    helped = subprocess.run([sys.executable, script, "--help"], capture_output=True,
                            text=True, timeout=300)
    assert helped.returncode == 0 and "never reports" in helped.stdout, helped.stderr


def test_a_script_that_forgot_run_script_refuses_its_flags(tmp_path):
    # without the run, the flags would be ignored and nothing written, with status 0
    import subprocess

    script = tmp_path / "norun.py"
    script.write_text(FORGETFUL.replace("cli.run_script(__name__)\n", ""))
    proc = subprocess.run([sys.executable, script, "--x", "2"], capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode != 0 and "cli.run_script(__name__)" in proc.stderr, proc.stderr


LONELY = '''from dataclasses import dataclass

import fenics_nl  # noqa: F401
from mpi4py import MPI

from fenics_nl.io import cli
from fenics_nl.io.parameters import Parameters

@dataclass
class P(Parameters):
    """A run whose rank 1 fails alone while rank 0 waits in a collective."""


cli.run_script(__name__)
args = cli.arguments(P, prefixes={})
if MPI.COMM_WORLD.rank == 1:
    raise ValueError("rank 1 alone")
MPI.COMM_WORLD.barrier()
cli.results({})
'''


@pytest.mark.spawns_mpi
def test_an_error_on_one_rank_stops_the_run_instead_of_hanging(tmp_path):
    # the failing rank waits for the others (FAILURE_WAIT_S: 1 s here), then ends them all
    import os
    import subprocess

    from conftest import MPIEXEC

    script = tmp_path / "lonely.py"
    script.write_text(LONELY)
    proc = subprocess.run([str(MPIEXEC), "-n", "2", sys.executable, script],
                          capture_output=True, text=True, timeout=240,
                          env={**os.environ, "FENICS_NL_FAILURE_WAIT_S": "1"})
    assert proc.returncode != 0
    assert "rank 1 alone (on rank 1 only: the run is stopped)" in proc.stderr, proc.stderr


@pytest.mark.spawns_mpi
def test_help_is_printed_once_on_two_ranks(demo):
    proc = demo.run(["newton_scalar.py", "--help"], ranks=2)
    assert proc.stdout.count("usage:") == 1, proc.stdout


def test_several_ranks_get_one_blas_thread_each_unless_the_user_set_it():
    # the spinning BLAS threads of two ranks on two cores had made the J2 sphere's 2-rank
    # run 1.24x rather than 1.54x (fenics_nl.threads)
    from fenics_nl.threads import one_thread_per_rank

    serial = {}
    assert not one_thread_per_rank(serial) and serial == {}
    two = {"PMI_SIZE": "2"}
    assert one_thread_per_rank(two)
    assert two["OPENBLAS_NUM_THREADS"] == two["OMP_NUM_THREADS"] == "1"
    mine = {"OMPI_COMM_WORLD_SIZE": "4", "OMP_NUM_THREADS": "2"}
    assert one_thread_per_rank(mine) and mine["OMP_NUM_THREADS"] == "2"


def test_an_integer_flag_whose_default_is_none_reads_an_integer():
    # `steps: int | None = number(None, ...)`: the default says nothing of the type, the
    # annotation does; read as a float, `--steps 3` broke np.linspace with a traceback
    from dataclasses import dataclass

    from fenics_nl.io.parameters import Parameters, number, parser_of

    @dataclass
    class Run(Parameters):
        steps: int | None = number(None, "steps", at_least=2)
        scale: float | None = number(None, "a scale", above=0)

    ns = parser_of(Run).parse_args(["--steps", "3", "--scale", "2"])
    assert type(ns.steps) is int and ns.steps == 3
    assert type(ns.scale) is float
    with pytest.raises(SystemExit):
        parser_of(Run).parse_args(["--steps", "2.5"])
