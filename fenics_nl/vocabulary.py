"""One spelling for each concept: in the library, the command lines, the case files, the JSON.

Words: `bfgs` (the quasi-Newton variant), `plane_strain` and `plane_stress` (the 2D models),
`lu` and `gamg` (MUMPS LU and CG + GAMG). Names: `max_it` (an iteration limit: PETSc's own
name, as in `-snes_max_it`; the flag `--max-it`) and `linear_solver` (the flag
`--linear-solver`). Older spellings are still read, with one line that says the new one,
and never written.
"""

from __future__ import annotations

import sys

from mpi4py import MPI

__all__ = ["OLD_NAMES", "OLD_SPELLINGS", "canonical", "renamed", "say_renamed"]

OLD_SPELLINGS = {
    "quasi-newton": "bfgs",
    "plane-strain": "plane_strain",
    "plane-stress": "plane_stress",
    "direct": "lu",
    "iterative": "gamg",
}


# old name -> the one name (a case file's key, a demo's flag with its dashes as underscores)
OLD_NAMES = {
    "max_iterations": "max_it",
    "maxit": "max_it",
    "linear": "linear_solver",
    "solver": "linear_solver",
}


def say_renamed(old: str, new: str) -> None:
    """The one line that says an old name was read (stderr, rank 0)."""
    if MPI.COMM_WORLD.rank == 0:
        print(f"note: {old} is now spelt {new} (the old spelling is still read)",
              file=sys.stderr, flush=True)


def renamed(table: dict, where: str, names) -> dict:
    """`table` with its keys in the one spelling, for the `names` it may hold.

    Each old key read is said (`where`: the table's name in that line).
    """
    out = {}
    for key, value in table.items():
        new = OLD_NAMES.get(key)
        if new in names and new not in table:
            say_renamed(f"{where}.{key}", f"{where}.{new}")
            key = new
        out[key] = value
    return out


def canonical(word, where: str):
    """`word` in the one spelling; an old one is said on stderr (rank 0) and replaced.

    `where` names the input (a flag, a case file's key) in that line.
    """
    new = OLD_SPELLINGS.get(word) if isinstance(word, str) else None
    if new is None:
        return word
    if MPI.COMM_WORLD.rank == 0:
        print(f"note: {where} {word!r} is now spelt {new!r} (the old spelling is still read)",
              file=sys.stderr, flush=True)
    return new
