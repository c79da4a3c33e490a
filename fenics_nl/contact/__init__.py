"""Unilateral contact, frictionless and Coulomb: the surface and the course's active-set loop.

`surface`: `ContactSurface` (its nodes, gap, areas, statuses as meshtags); `active_set`:
`ActiveSetContact`, the loop (solve with u_n = γ on the active nodes and T = 0 elsewhere,
update the set, until it stops changing) over a formulation, `EliminationSystem` (rows
eliminated) or `multiplier.MultiplierSystem` (Lagrange multipliers on a facet submesh);
`friction`: `FrictionalContact`, the same loop with Coulomb's statuses (open, stick, slip).

    from fenics_nl.contact import ActiveSetContact, FrictionalContact
"""

from fenics_nl.contact.active_set import ActiveSetContact, ContactError, EliminationSystem
from fenics_nl.contact.friction import FrictionalContact
from fenics_nl.contact.multiplier import MultiplierSystem
from fenics_nl.contact.surface import ContactSurface

__all__ = ["ActiveSetContact", "ContactError", "ContactSurface", "EliminationSystem",
           "FrictionalContact", "MultiplierSystem"]
