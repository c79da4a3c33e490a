"""Command-line plumbing shared by the demos: argument types, PETSc options, the run itself.

A demo parses its flags with `parser(...)` (every default shown once, numeric flags that
refuse NaN and infinities by name), passes the rest to `PetscOptions` (only options under
the run's own prefixes are accepted; an option no solver read ends the run with an error),
and hands its work to `run_scene`, which turns the library's errors into one line and a
non-zero exit, writes the JSON first and then every other output, each on its own, so that
a failing picture never loses the numbers.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import sys
import time
import traceback
from collections.abc import Callable, Sequence
from pathlib import Path

from mpi4py import MPI

from fenics_nl.errors import SolveError

# Errors that end a run with one line: bad parameters, solvers that cannot converge, a load
# that cannot be reached (and PETSc refusing an option). Anything else is a bug and keeps
# its traceback.
EXPECTED_ERRORS: tuple[type[BaseException], ...] = (ValueError, SolveError)


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Show the default once: not when it is None, nor when the help already states it."""

    def _get_help_string(self, action):
        text = action.help or ""
        if action.default is None or "default" in text or action.default is argparse.SUPPRESS:
            return text
        return super()._get_help_string(action)


class ArgumentParser(argparse.ArgumentParser):
    """Bad input is one line on stderr (`--help` has the usage), exit status 2."""

    def error(self, message):
        """Print `prog: error: message` alone (rank 0) and exit with status 2."""
        text = f"{self.prog}: error: {message} (see --help)\n"
        self.exit(2, text if MPI.COMM_WORLD.rank == 0 else None)


def parser(description: str, epilog: str | None = None) -> ArgumentParser:
    """An argument parser with the demos' help format and one-line errors."""
    return ArgumentParser(description=description, epilog=epilog, formatter_class=HelpFormatter)


def add_outputs(p: argparse.ArgumentParser, *, json: str = "the quantities of interest",
                output: str | None = None, png: str | None = None, plot: str | None = None
                ) -> None:
    """The output flags of a demo: --json always, --output/--png/--plot where it has them."""
    p.add_argument("--json", metavar="PATH", help=f"write {json} as JSON")
    if output:
        p.add_argument("--output", metavar="DIR", help=f"{output} (ADIOS2 VTX, for ParaView)")
    for flag, text in (("--png", png), ("--plot", plot)):
        if text:
            p.add_argument(flag, metavar="PATH", help=text)


def finite(text: str) -> float:
    """argparse type: a finite float (NaN and infinities are refused)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
    return value


def positive(text: str) -> float:
    """argparse type: a finite float > 0."""
    value = finite(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
    return value


def at_least(minimum: int):
    """argparse type: an integer >= `minimum`."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be >= {minimum}, got {value}")
        return value

    parse.__name__ = f"integer >= {minimum}"
    return parse


def power_law_flags(parser: argparse.ArgumentParser, args, **defaults) -> None:
    """Fill --sigma0/--n with their defaults; giving them with a linear material is an error."""
    given = [f"--{k}" for k in defaults if getattr(args, k) is not None]
    if args.material == "linear" and given:
        parser.error(f"{', '.join(given)} set the power law, not --material linear")
    for k, v in defaults.items():
        if getattr(args, k) is None:
            setattr(args, k, v)


def parse_with_petsc_options(parser: argparse.ArgumentParser, argv=None):
    """The demo's own arguments, and the PETSc options (``-name [value]``) to pass through.

    Anything else (an unknown ``--flag``, a stray word) is an argparse error: one line,
    exit status 2.
    """
    args, rest = parser.parse_known_args(argv)
    unknown, after_option = [], False
    for a in rest:
        is_option = a.startswith("-") and not a.startswith("--") and not _is_number(a)
        if a.startswith("--") or not (is_option or after_option):
            unknown.append(a)
        after_option = is_option  # an option's value follows it; a value ends it
    if unknown:
        parser.error(f"unrecognized arguments: {' '.join(unknown)}")
    return args, rest


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


class PetscOptions:
    """The PETSc options of one run, checked against the prefixes its solvers read.

    `prefixes` maps each options prefix of the run to what reads it. An option outside
    them is refused before anything is computed; after the run, an option that no solver
    read (a misspelt suffix) is reported by `unused()`.
    """

    def __init__(self, argv: Sequence[str], prefixes: dict[str, str]):
        self.names = [a[1:] for a in argv if a.startswith("-") and not _is_number(a)]
        self.prefixes = prefixes
        stray = [n for n in self.names if not any(n.startswith(p) for p in prefixes)]
        if stray:
            raise ValueError(f"PETSc option -{stray[0]} is read by no solver of this run; "
                             f"its options prefixes are {self.describe()}")
        from petsc4py import PETSc

        PETSc.Options().insertString(" ".join(argv))

    def describe(self) -> str:
        """'-prefix_ (what reads it), ...' for messages and --help."""
        return ", ".join(f"-{p} ({what})" for p, what in self.prefixes.items())

    def unused(self) -> list[str]:
        """The options no solver read, removed from PETSc's database."""
        from petsc4py import PETSc

        opts = PETSc.Options()
        left = [n for n in self.names if not opts.used(n)]
        for n in self.names:
            opts.delValue(n)
        return left


def say(*args) -> None:
    """print on rank 0 only."""
    if MPI.COMM_WORLD.rank == 0:
        print(*args, flush=True)


def error(message: str) -> None:
    """One line on stderr, rank 0 only."""
    if MPI.COMM_WORLD.rank == 0:
        print(f"error: {message}", file=sys.stderr, flush=True)


def run_scene(solve: Callable[[], tuple[dict, Sequence[Callable[[], None]]]], *,
              petsc_argv: Sequence[str] = (), prefixes: dict[str, str] | None = None,
              json_path: str | None = None) -> int:
    """Run a scene: `solve()` returns (quantities for the JSON, output writers).

    Errors of the library end the run with one line and exit status 2. The JSON is written
    first (with `wall_time_s` and `warnings`), then each writer runs on its own: a failing
    writer is reported (exit status 1) without losing the others. PETSc options that no
    solver read end the run with exit status 2.
    """
    from petsc4py import PETSc

    t0 = time.perf_counter()
    options = None
    try:
        options = PetscOptions(petsc_argv, prefixes or {})
        out, writers = solve()
    except (*EXPECTED_ERRORS, PETSc.Error) as err:
        error(_one_line(err))
        if options is not None:
            options.unused()  # leaves PETSc's database as it was
        return 2
    out["wall_time_s"] = time.perf_counter() - t0
    out.setdefault("warnings", [])
    for w in out["warnings"]:
        say(f"warning: {w}")
    status = 0
    try:  # on every rank, so that every rank stops here together
        text = json.dumps(out, indent=2, allow_nan=False)
    except ValueError:  # a NaN among the results: a defect, never a silent answer
        error("a result is not a finite number: no output written")
        options.unused()
        return 2
    if json_path and MPI.COMM_WORLD.rank == 0:
        try:
            Path(json_path).write_text(text)
        except OSError as err:
            error(f"cannot write {json_path}: {err.strerror}")
            status = 1
    for write in writers:
        try:
            write()
        except Exception as err:  # an output must never take the others down
            error(f"writing an output failed: {_one_line(err)}")
            if MPI.COMM_WORLD.rank == 0 and "FENICS_NL_DEBUG" in os.environ:
                traceback.print_exc()
            status = 1
    left = options.unused()
    if left:
        error(f"PETSc option -{left[0]} was read by no solver (misspelt?); this run's options "
              f"prefixes are {options.describe()}")
        return 2
    say(f"wall time {out['wall_time_s']:.2f} s on {MPI.COMM_WORLD.size} rank(s)")
    return status


def _one_line(err: BaseException) -> str:
    from petsc4py import PETSc

    text = " ".join(str(err).split())
    if isinstance(err, PETSc.Error):
        # PETSc's stack: keep its messages, drop the "function() at file:line" frames
        parts = [p.strip() for p in re.split(r"\[\d+\]", text)]
        text = "; ".join(p for p in parts if p and " at /" not in p)
        return f"PETSc rejected an option or failed: {text}"
    return text or type(err).__name__
