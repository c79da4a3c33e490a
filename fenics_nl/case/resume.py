"""A case's checkpoint: what a restart needs to go on exactly as the run would have.

After a converged step: the unknown (with the pressure of the mixed form), the internal
variables at the quadrature points (J2's plastic strain and cumulated plastic strain), the
contact's active set, the load-step driver's increments and predictor state, the segment of
the load path (or, under arc-length control, the continuation's `ArcState`), the step
records of the JSON, the work counted so far, and Newton's force
reference. The identity is the case file's content (its hash), the ranks and the unknowns;
each rank adds the size and a hash of its dof coordinates, so a restart needs the same case,
the same mesh and the same partition (`io.checkpoint` says why).
"""

from __future__ import annotations

import dataclasses
import hashlib

import numpy as np

from fenics_nl.io.checkpoint import CheckpointError, Checkpoints, fingerprint
from fenics_nl.solvers.arclength import ArcState
from fenics_nl.solvers.loading import DriverState
from fenics_nl.solvers.result import WorkCounts


@dataclasses.dataclass
class Resumed:
    """Where a restarted case goes on from."""

    segment: int  # index of the load segment (0 for equal steps)
    driver: DriverState | None  # None: the segment was complete, start the next one
    steps: list[dict]
    work: WorkCounts  # of the load-controlled segments (an arc's is in its state's path)
    arc: ArcState | None = None  # under arc-length control: where the path goes on from


class CaseCheckpoints:
    """Save the state of a case's run after converged steps, and read it back."""

    def __init__(self, problem, folder: str, every: int = 1):
        self.problem = problem
        comm = problem.mesh.comm
        # the case file's content, not its name: a copy elsewhere restarts, an edit does not
        identity = {"case file": hashlib.sha256(problem.case.path.read_bytes()).hexdigest(),
                    "ranks": comm.size, "dofs": problem.dofs}
        self.store = Checkpoints(folder, comm, identity, every)
        # this rank's unknowns and mesh nodes (a mixed space tabulates no dof coordinates)
        msh = problem.mesh
        nodes = msh.geometry.index_map().size_local
        self.local = {"unknown": int(problem.unknown.x.array.size),
                      "coordinates": fingerprint(msh.geometry.x[:nodes])}

    # -- what is saved -----------------------------------------------------------------

    def _functions(self) -> dict:
        """The Functions of the state by name: the unknown and the internal variables."""
        functions = {"unknown": self.problem.unknown}
        if getattr(self.problem.material, "path_dependent", False):
            functions.update(self.problem.material.state_functions())
        return functions

    def _newton(self):
        """The Newton solver whose force reference a restart restores (None for SNES)."""
        solver = self.problem.solver
        if self.problem.contact is not None:
            solver = solver.contact.system.newton
        return solver if hasattr(solver, "force_reference") else None

    def save(self, segment: int, driver: DriverState, steps: list[dict],
             work: WorkCounts) -> None:
        """The state after the converged step that ended with `driver` (collective)."""
        arrays = {} if driver.previous is None else {"previous": driver.previous}
        self._save({"segment": segment, "t": driver.t, "dt": driver.dt,
                    "dt_previous": driver.dt_previous,
                    "has_previous": driver.previous is not None,
                    "work": dataclasses.asdict(work)}, arrays, steps)

    def save_arc(self, arc: ArcState, steps: list[dict]) -> None:
        """The state after a converged step of arc-length control (collective)."""
        self._save({"arc": arc.scalars()}, arc.arrays(), steps)

    def _save(self, state: dict, arrays: dict, steps: list[dict]) -> None:
        """`state` and `arrays` with the unknown, the internal variables, the contact's."""
        arrays.update({k: f.x.array for k, f in self._functions().items()})
        if self.problem.contact is not None:
            arrays["active"] = self.problem.solver.contact.active.astype(np.uint8)
        newton = self._newton()
        state.update(steps=steps, force_reference=newton.force_reference if newton else None)
        self.store.save(len(steps), state, arrays, self.local)

    # -- what a restart reads ----------------------------------------------------------

    def restore(self) -> Resumed:
        """Put the saved state back into the problem; where the path goes on from."""
        state, arrays = self.store.load(self.local)
        for name, f in self._functions().items():
            if name not in arrays or arrays[name].size != f.x.array.size:
                raise CheckpointError(f"checkpoint {self.store.folder} has no {name} of this "
                                      "run's size: it is another run's")
            f.x.array[:] = arrays[name]
            f.x.scatter_forward()
        if self.problem.contact is not None:
            self.problem.solver.contact.active = arrays["active"].astype(bool)
        newton = self._newton()
        if newton is not None and state["force_reference"] is not None:
            newton.force_reference = state["force_reference"]
        if "arc" in state:
            return Resumed(0, None, state["steps"], WorkCounts(),
                           ArcState.saved(state["arc"], arrays))
        driver = DriverState(state["t"], state["dt"], state["dt_previous"],
                             arrays["previous"] if state["has_previous"] else None)
        work = WorkCounts(**state["work"])
        if driver.t >= 1.0 - 1e-12:  # the segment was complete: the next one from its start
            return Resumed(state["segment"] + 1, None, state["steps"], work)
        return Resumed(state["segment"], driver, state["steps"], work)
