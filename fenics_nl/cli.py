"""Command-line helpers shared by the demos."""

from __future__ import annotations

import argparse


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
