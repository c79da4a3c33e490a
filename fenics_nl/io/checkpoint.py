"""Checkpoints of a path-dependent run: its state after a converged step, to resume from.

A checkpoint folder holds one sub-folder per saved step, ``step-<n>/``, with this rank's
arrays (``rank<r>.npz``: the unknown, the internal variables at the quadrature points, the
contact statuses, the predictor's previous state) and, from rank 0, ``state.json``: the load
factor, the driver's increments, the step records of the JSON and the run's identity (the
case file's hash, the ranks, the unknowns, each rank's layout). ``latest.json`` names the
last complete step; it is replaced (atomically, `os.replace`) only once every rank has
written its arrays, so a run killed at any instant leaves a checkpoint to restart from.

Why not io4dolfinx: its h5py backend opens files with the MPI driver and refuses more than
one rank with the PyPI h5py (``h5py is not installed with MPI support``), its ADIOS2 backend
needs ADIOS2's Python bindings built with MPI (the PyPI adios2 wheel is serial), and a
parallel HDF5 from Debian would load a second MPI library beside the wheel's. A restart on the
same partition (same mesh, same number of ranks) needs no re-distribution, only each rank's
own arrays back, which these files are; the layout is checked on reading, so a checkpoint
of another case or another partition is refused in one line.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import zipfile
from pathlib import Path

import numpy as np
from mpi4py import MPI

__all__ = ["CheckpointError", "Checkpoints", "fingerprint", "layout"]

FORMAT = 2  # 2: a phase (was: segment) and the load path so far
KEEP = 2  # complete steps kept (the last one, and the one before in case it is damaged)


class CheckpointError(ValueError):
    """A checkpoint that cannot be used: missing, incomplete, or of another run."""


def layout(arrays: dict[str, np.ndarray]) -> dict[str, int]:
    """Each array's size on this rank: what a restart on the same partition must match."""
    return {k: int(np.asarray(v).size) for k, v in arrays.items()}


def fingerprint(x: np.ndarray) -> str:
    """A hash of an array (this rank's dof coordinates: the same mesh, the same partition)."""
    return hashlib.sha256(np.ascontiguousarray(x, dtype=np.float64).tobytes()).hexdigest()[:16]


class Checkpoints:
    """Save and load a run's state in `folder` (collective on `comm`).

    `identity` (JSON-able, the same on every rank) says which run this is: a checkpoint with
    another identity is refused. `every` saves one converged step out of `every`.
    """

    def __init__(self, folder: str | Path, comm: MPI.Comm, identity: dict, every: int = 1):
        if every < 1:
            raise ValueError(f"checkpoint every must be >= 1, got {every}")
        self.folder, self.comm, self.identity, self.every = Path(folder), comm, identity, every
        self._saved: list[Path] = []

    def save(self, step: int, state: dict, arrays: dict[str, np.ndarray],
             local_identity: dict) -> bool:
        """Step `step`'s state (rank 0's `state`, every rank's `arrays`); False if skipped.

        `local_identity` is this rank's part of the identity (its layout).
        """
        if step % self.every:
            return False
        target = self.folder / f"step-{step:06d}"

        def folder():
            shutil.rmtree(target, ignore_errors=True)
            target.mkdir(parents=True)

        self._together(folder if self.comm.rank == 0 else None)
        self._together(lambda: np.savez(target / f"rank{self.comm.rank}.npz", **arrays))
        ranks = self.comm.gather(local_identity, root=0)  # every rank's arrays are on disk

        def publish():  # state.json, then latest.json names the step: atomic (os.replace)
            meta = {"format": FORMAT, "identity": self.identity, "ranks_identity": ranks,
                    "step": step, **state}
            (target / "state.json").write_text(json.dumps(meta, allow_nan=False))
            tmp = self.folder / "latest.json.tmp"
            tmp.write_text(json.dumps({"step": target.name}))
            os.replace(tmp, self.folder / "latest.json")
            self._saved.append(target)
            for old in self._saved[:-KEEP]:
                shutil.rmtree(old, ignore_errors=True)
            self._saved = self._saved[-KEEP:]

        self._together(publish if self.comm.rank == 0 else None)
        return True

    def _together(self, write) -> None:
        """Run this rank's `write` (or nothing); if it fails on any rank, fail on every one.

        A rank-local error (a full disk on one rank) must not leave the others waiting in
        the next collective: CheckpointError everywhere, naming the first failure.
        """
        problem = None
        if write is not None:
            try:
                write()
            except (OSError, ValueError) as err:  # ValueError: a NaN in the state's JSON
                problem = f"rank {self.comm.rank}: {type(err).__name__}: {err}"
        problems = [p for p in self.comm.allgather(problem) if p]
        if problems:
            raise CheckpointError(f"cannot write the checkpoint in {self.folder} "
                                  f"({problems[0]})")

    def load(self, local_identity: dict) -> tuple[dict, dict[str, np.ndarray]]:
        """(rank 0's state, this rank's arrays) of the latest complete step.

        CheckpointError (the same on every rank) if the folder has none, if it is damaged,
        or if it is another run's.
        """
        problem, meta, arrays = None, None, {}
        if self.comm.rank == 0:
            try:
                meta = self._read_state()
            except CheckpointError as err:
                problem = str(err)
        problem = self.comm.bcast(problem, root=0)
        if problem:
            raise CheckpointError(problem)
        meta = self.comm.bcast(meta, root=0)
        folder = self.folder / meta["step_folder"]
        mine = meta["ranks_identity"][self.comm.rank]
        try:
            if mine != local_identity:
                raise CheckpointError(f"checkpoint {self.folder} is of another partition or "
                                      "mesh (this rank's unknowns or coordinates differ)")
            with np.load(folder / f"rank{self.comm.rank}.npz") as data:
                arrays = {k: data[k] for k in data.files}
        except (OSError, ValueError, EOFError, zipfile.BadZipFile) as err:  # a truncated .npz
            problem = (str(err) if isinstance(err, CheckpointError) else
                       f"checkpoint {folder} is damaged (rank {self.comm.rank}: "
                       f"{type(err).__name__}: {err})")
        problems = [p for p in self.comm.allgather(problem) if p]
        if problems:
            raise CheckpointError(problems[0])
        return meta, arrays

    def _read_state(self) -> dict:
        """state.json of the latest step, checked against this run (rank 0)."""
        latest = self.folder / "latest.json"
        if not self.folder.is_dir():
            raise CheckpointError(f"no checkpoint folder {self.folder}")
        try:
            name = json.loads(latest.read_text())["step"]
            meta = json.loads((self.folder / name / "state.json").read_text())
        except FileNotFoundError as err:
            raise CheckpointError(f"{self.folder} holds no complete checkpoint (missing "
                                  f"{Path(err.filename).name})") from None
        except (ValueError, KeyError, TypeError) as err:
            raise CheckpointError(f"checkpoint {self.folder} is damaged ({err})") from None
        if meta.get("format") != FORMAT:
            raise CheckpointError(f"checkpoint {self.folder} has format {meta.get('format')}, "
                                  f"this version reads {FORMAT}")
        theirs, ours = meta["identity"], self.identity
        for key in ours:
            if theirs.get(key) != ours[key]:
                what = (f"its {key} differs" if isinstance(ours[key], str) else
                        f"its {key} is {theirs.get(key)!r}, this run's {ours[key]!r}")
                raise CheckpointError(f"checkpoint {self.folder} is of another run: {what}")
        meta["step_folder"] = name
        return meta
