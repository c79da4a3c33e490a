"""Checkpoints of a load path, and the restart that goes on exactly as the run would have.

After a converged step a checkpoint holds the Functions of the state (the unknown, with the
pressure of a mixed form; the internal variables at the quadrature points), the contact's
active set, Newton's force reference, the step records of the run's JSON, and where the
driver stands: `loading.DriverState` under load control (with the load path so far, its
phase: a demo's loading and unloading, a case's segment), `time_stepping.TimeState` in time
(with the last step's viscous strain rate and σ_eq, which size the next step), or
`arclength.ArcState` under arc-length control. A restart puts all of it back; the steps
after it are then those of the uninterrupted run, to round-off.

The identity (JSON-able, the same on every rank: what the run is) and each rank's layout
(the size of its unknowns and a hash of its mesh nodes) are checked on reading: a restart
needs the same problem, the same mesh and the same partition (`io.checkpoint` says why).
"""

from __future__ import annotations

import dataclasses

from dolfinx import fem

from fenics_nl.io.checkpoint import CheckpointError, Checkpoints, fingerprint
from fenics_nl.solvers.arclength import ArcState
from fenics_nl.solvers.loading import DriverState, LoadPath
from fenics_nl.solvers.result import SolveResult, WorkCounts
from fenics_nl.solvers.time_stepping import TimePath, TimeState

__all__ = ["PathCheckpoints", "Resumed"]


@dataclasses.dataclass
class Resumed:
    """Where a restarted run goes on from."""

    phase: int  # the phase (or segment) of the load path the checkpoint was taken in
    driver: DriverState | TimeState | None  # where in it (None under arc-length control)
    steps: list[dict]  # the step records of the JSON so far
    work: WorkCounts  # of the load-controlled phases (an arc's is in its state's path)
    arc: ArcState | None = None  # under arc-length control: where the path goes on from
    path: LoadPath | TimePath | None = None  # the phase's path so far (its totals go on)
    kept: dict | None = None  # what the run's `kept` gave


class PathCheckpoints:
    """Save the state of a run after converged steps in `folder`, and read it back.

    Args:
        folder: where the checkpoints go (or come from, for a restart).
        identity: what the run is (JSON-able, the same on every rank): a checkpoint with
            another identity is refused.
        functions: the Functions of the state by name (the unknown first).
        every: save one converged step out of `every`.
        newton: the Newton solver whose force reference is kept (None: SNES, nothing kept).
        contact: an active-set contact (frictionless or Coulomb) whose state is kept
            (`checkpoint_arrays`: its statuses, and with friction the slip history).
        kept: a function giving what else the run needs back (JSON-able: a demo's list of
            states), returned by `restore` as `Resumed.kept`.
    """

    def __init__(self, folder: str, identity: dict, functions: dict[str, fem.Function], *,
                 every: int = 1, newton=None, contact=None, kept=None):
        self.functions, self.newton, self.contact, self.kept = functions, newton, contact, kept
        unknown = next(iter(functions.values()))
        msh = unknown.function_space.mesh
        self.store = Checkpoints(folder, msh.comm, {**identity, "ranks": msh.comm.size}, every)
        # this rank's unknowns and mesh nodes (a mixed space tabulates no dof coordinates)
        nodes = msh.geometry.index_map().size_local
        self.local = {"unknown": int(unknown.x.array.size),
                      "coordinates": fingerprint(msh.geometry.x[:nodes])}

    # -- what is saved -----------------------------------------------------------------

    def save(self, phase: int, driver: DriverState | TimeState, steps: list[dict],
             work: WorkCounts, path: LoadPath | TimePath | None = None) -> None:
        """The state after the converged step that ended with `driver` (collective).

        `work`: of the phases before this one; `path`: this phase's so far.
        """
        if isinstance(driver, TimeState):
            self._save({"phase": phase, "time": driver.t, "dt": driver.dt,
                        "stationary_since": driver.stationary_since,
                        "held_since": driver.held_since,
                        "work": dataclasses.asdict(work),
                        "path": None if path is None else _path_record(path)},
                       {"rate": driver.rate, "stress": driver.stress}, steps)
            return
        arrays = {} if driver.previous is None else {"previous": driver.previous}
        self._save({"phase": phase, "t": driver.t, "dt": driver.dt,
                    "dt_previous": driver.dt_previous,
                    "has_previous": driver.previous is not None,
                    "work": dataclasses.asdict(work),
                    "path": None if path is None else _path_record(path)}, arrays, steps)

    def save_arc(self, arc: ArcState, steps: list[dict]) -> None:
        """The state after a converged step of arc-length control (collective)."""
        self._save({"arc": arc.scalars()}, arc.arrays(), steps)

    def _save(self, state: dict, arrays: dict, steps: list[dict]) -> None:
        """`state` and `arrays` with the Functions, the contact's nodes, the force scale."""
        arrays.update({k: f.x.array for k, f in self.functions.items()})
        if self.contact is not None:
            arrays.update({f"contact.{k}": v for k, v in
                           self.contact.checkpoint_arrays().items()})
        state.update(steps=steps, force_reference=self.newton.force_reference
                     if self.newton is not None else None,
                     kept=self.kept() if self.kept is not None else None)
        self.store.save(len(steps), state, arrays, self.local)

    # -- what a restart reads ----------------------------------------------------------

    def restore(self) -> Resumed:
        """Put the saved state back (collective); where the path goes on from.

        CheckpointError (one line, on every rank) for a missing, damaged or foreign one.
        """
        state, arrays = self.store.load(self.local)
        for name, f in self.functions.items():
            if name not in arrays or arrays[name].size != f.x.array.size:
                raise CheckpointError(f"checkpoint {self.store.folder} has no {name} of this "
                                      "run's size: it is another run's")
            f.x.array[:] = arrays[name]
            f.x.scatter_forward()
        if self.contact is not None:
            self.contact.restore_arrays({k[len("contact."):]: v for k, v in arrays.items()
                                         if k.startswith("contact.")})
        if self.newton is not None and state["force_reference"] is not None:
            self.newton.force_reference = state["force_reference"]
        if "arc" in state:
            return Resumed(0, None, state["steps"], WorkCounts(),
                           ArcState.saved(state["arc"], arrays), kept=state["kept"])
        if "time" in state:
            driver = TimeState(state["time"], state["dt"], arrays["rate"], arrays["stress"],
                               state["stationary_since"], state["held_since"])
        else:
            driver = DriverState(state["t"], state["dt"], state["dt_previous"],
                                 arrays["previous"] if state["has_previous"] else None)
        work = WorkCounts(**state["work"])
        path = None if state.get("path") is None else _path_from(state["path"])
        return Resumed(state["phase"], driver, state["steps"], work, path=path,
                       kept=state["kept"])


def _path_record(path: LoadPath) -> dict:
    """What a restart needs of a load path so far (its steps' iterations, not their norms)."""
    record = {"factors": path.factors, "iterations": [r.iterations for r in path.results],
              "failures": path.failures, "work": dataclasses.asdict(path.work)}
    if isinstance(path, TimePath):
        record["time"] = {"times": path.times, "errors": path.errors,
                          "rejected": path.rejected, "stationary_since": path.stationary_since,
                          "stationary_after": path.stationary_after, "change": path.change}
    return record


def _path_from(record: dict) -> LoadPath:
    common = (list(record["factors"]),
              [SolveResult.restored(its) for its in record["iterations"]],
              record["failures"], WorkCounts(**record["work"]))
    if "time" not in record:
        return LoadPath(*common)
    t = record["time"]
    return TimePath(*common, list(t["times"]), list(t["errors"]), t["rejected"],
                    t["stationary_since"], t["stationary_after"], t["change"])
