"""One spelling for each concept: in the library, the command lines, the case files, the JSON.

`bfgs` (the quasi-Newton variant), `plane_strain` and `plane_stress` (the 2D models), `lu`
and `gamg` (MUMPS LU and CG + GAMG). Older spellings are still read, with one line that
says the new one, and never written.
"""

from __future__ import annotations

import sys

from mpi4py import MPI

__all__ = ["OLD_SPELLINGS", "canonical"]

OLD_SPELLINGS = {
    "quasi-newton": "bfgs",
    "plane-strain": "plane_strain",
    "plane-stress": "plane_stress",
    "direct": "lu",
    "iterative": "gamg",
}


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
