"""The two reductions the demos, drivers and pictures need, so that no rank decides alone."""

from __future__ import annotations

import numpy as np
from mpi4py import MPI


def global_max(comm: MPI.Comm, values: np.ndarray) -> float:
    """max of `values` over every rank (0 where there are none)."""
    return comm.allreduce(float(np.max(values, initial=0.0)), op=MPI.MAX)


def gather_rows(comm: MPI.Comm, *arrays: np.ndarray) -> tuple[np.ndarray, ...] | None:
    """Each array's rows from every rank, concatenated on rank 0 (None elsewhere)."""
    parts = comm.gather(arrays, root=0)
    if comm.rank != 0:
        return None
    return tuple(np.concatenate([p[i] for p in parts]) for i in range(len(arrays)))
