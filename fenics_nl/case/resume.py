"""A case's checkpoints: `io.restart.PathCheckpoints` of its problem.

The state is the unknown (with the pressure of the mixed form), the internal variables at
the quadrature points (J2's plastic strain and cumulated plastic strain), the contact's
active set (a pair's: its statuses, forces and committed slip), the construction stages'
fields (the parts present, the frozen stress and weight of what a stage digs out) and
Newton's force reference; the identity is the case file's content (its hash, not its name:
a copy elsewhere restarts, an edit does not) and the unknowns. The phases of the path are
the case's load segments (0 for equal steps), then its stages.
"""

from __future__ import annotations

import hashlib

from fenics_nl.io.restart import PathCheckpoints

__all__ = ["case_checkpoints"]


def case_checkpoints(problem, folder: str, every: int = 1) -> PathCheckpoints:
    """The checkpoints of `problem`'s run in `folder` (to save in, or restart from)."""
    identity = {"case file": hashlib.sha256(problem.case.path.read_bytes()).hexdigest(),
                "dofs": problem.dofs}
    functions = {"unknown": problem.unknown}
    if problem.material.path_dependent:
        functions.update(problem.material.state_functions())
    if getattr(problem, "construction", None) is not None:
        functions.update({f"construction.{k}": f for k, f in
                          problem.construction.state_functions().items()})
    solver = problem.solver
    # the rigid obstacle's active set, or the pairs' (their statuses and wear)
    contact = solver.contact if problem.contact is not None else solver if \
        problem.case.pairs else None
    newton = contact.newton if problem.contact is not None else solver
    return PathCheckpoints(folder, identity, functions, every=every, contact=contact,
                           newton=newton if hasattr(newton, "force_reference") else None)
