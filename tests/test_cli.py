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
