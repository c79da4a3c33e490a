"""The command line's flags: the parser, the output flags, the argparse types.

The parser with one-line errors and its help format, the output and checkpoint flags, and
the argparse types of the demos' values: what `io.cli` (the run) and `io.parameters` (a
demo's declared parameters) both build on. It imports nothing else of the package's but
`vocabulary`, so they depend on it, not on each other.
"""

from __future__ import annotations

import argparse
import math

from mpi4py import MPI

__all__ = [
    "ArgumentParser",
    "HelpFormatter",
    "add_checkpoints",
    "add_outputs",
    "at_least",
    "finite",
    "parser",
    "positive",
    "spelling",
]


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Show the default once: not when it is None, nor when the help already states it."""

    def _get_help_string(self, action):
        text = action.help or ""
        if action.default is None or "default" in text or action.default is argparse.SUPPRESS:
            return text
        return super()._get_help_string(action)


class ArgumentParser(argparse.ArgumentParser):
    """Bad input is one line on stderr (`--help` has the usage), exit status 2.

    A flag is taken whole: argparse's abbreviations would let an old or misspelt flag
    (`--slip` once a length, now `--slip-ratio`) mean another one silently.
    """

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)

    def error(self, message):
        """Print `prog: error: message` alone (rank 0) and exit with status 2."""
        text = f"{self.prog}: error: {message} (see --help)\n"
        self.exit(2, text if MPI.COMM_WORLD.rank == 0 else None)

    def print_help(self, file=None):
        """The help, once: on rank 0 (under mpiexec every rank parses --help)."""
        if MPI.COMM_WORLD.rank == 0:
            super().print_help(file)


def parser(description: str, epilog: str | None = None) -> ArgumentParser:
    """An argument parser with the demos' help format and one-line errors."""
    return ArgumentParser(description=description, epilog=epilog, formatter_class=HelpFormatter)


def add_outputs(p: argparse.ArgumentParser, *, json: str = "the quantities of interest",
                output: str | None = None, png: str | None = None, plot: str | None = None
                ) -> None:
    """The output flags of a demo: --json always, --output/--png/--plot where it has them."""
    p.add_argument("--json", metavar="PATH", help=f"write {json} as JSON")
    if output:
        p.add_argument("--output", metavar="DIR",
                       help=f"{output}, at every converged step (ADIOS2 VTX time series, the "
                            "load factor as time, for ParaView)")
    for flag, text in (("--png", png), ("--plot", plot)):
        if text:
            p.add_argument(flag, metavar="PATH", help=text)


def add_checkpoints(p: argparse.ArgumentParser) -> None:
    """--checkpoint, --checkpoint-every and --restart: a demo with a path-dependent load path."""
    p.add_argument("--checkpoint", metavar="DIR",
                   help="save the state after every converged step of the loading (or every "
                        "--checkpoint-every N) in DIR, to restart from")
    p.add_argument("--checkpoint-every", metavar="N", type=at_least(1), default=1,
                   help="with --checkpoint: save one converged step out of N")
    p.add_argument("--restart", metavar="DIR",
                   help="go on from the last checkpoint in DIR (the same parameters, mesh and "
                        "number of ranks); the steps after it are the uninterrupted run's")


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


def spelling(flag: str):
    """argparse type: the word in the one spelling (`vocabulary`); an old one is said."""
    from fenics_nl.vocabulary import canonical

    def parse(text: str) -> str:
        return canonical(text, flag)

    parse.__name__ = "word"
    return parse


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
