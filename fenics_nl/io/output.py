"""What a run hands to its user: VTX fields for ParaView, whole meshes for pictures.

* `write_fields`: one ADIOS2 VTX file per function (any Lagrange degree, on any mesh
  degree: P2 on quadrilaterals included), which ParaView opens directly.
* `FieldSeries`: the same files as a time series, one time per converged load step (the
  load factor as time, Σ|Δt| on a path that comes back, plus each construction stage's
  progress), written as the steps converge: a run that fails keeps them.
* `gather_grid`: the mesh of a Lagrange space, its nodal and cell fields, collected from
  every rank on rank 0, so that a picture shows the whole body whatever the number of ranks.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from dolfinx import fem

__all__ = [
    "FieldSeries",
    "Grid",
    "dofs",
    "gather_grid",
    "owned_cell_values",
    "peak_memory_mb",
    "section",
    "vertex_interpolant",
    "write_fields",
]


def dofs(V: fem.FunctionSpace) -> int:
    """Global number of scalar unknowns of V (what a run reports as `dofs`)."""
    return V.dofmap.index_map.size_global * V.dofmap.index_map_bs


def peak_memory_mb(comm) -> float:
    """The largest resident memory of the ranks so far, in MiB (collective)."""
    import resource

    from mpi4py import MPI

    return comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, op=MPI.MAX)


def write_fields(folder: str | Path, functions: list[fem.Function]) -> list[Path]:
    """`folder`/<name>.bp for each function (collective); returns the paths."""
    from dolfinx.io import VTXWriter

    folder = Path(folder)
    comm = functions[0].function_space.mesh.comm
    folder.mkdir(parents=True, exist_ok=True)  # every rank: an error is raised on all of them
    paths = []
    for f in functions:
        path = folder / f"{f.name}.bp"
        with VTXWriter(comm, path, [f]) as w:
            w.write(0.0)
        paths.append(path)
    return paths


class FieldSeries:
    """`folder`/<name>.bp for each function, one time per converged step (`write(t)`).

    The time is the load-path time τ = Σ |Δt| of the load factors t given: the load factor
    itself while it grows, and still increasing when the path comes back (an unloading), as
    ParaView needs; a construction stage's steps (at one load factor) add their progress.
    `functions()` gives the fields of the current state (new Function objects each call are
    fine: their values are copied into the series' own). Each file is written at every
    step. Collective; `close()` at the end.
    """

    def __init__(self, folder: str | Path):
        self.folder = Path(folder)
        self._series: dict[str, tuple] = {}  # name -> (writer, its own copy of the field)
        self.times: list[float] = []
        self._last = 0.0  # the last load factor
        self._progress = 0.0  # the last stage step's progress
        self._tau = 0.0  # the last step's time

    def write(self, t: float, functions, time: float | None = None,
              progress: float | None = None) -> None:
        """Every field of the current state, `functions()`, at load factor t.

        Its time in the files is Σ|Δt| of the load factors so far, or `time` if given (a
        viscous law's own time); a stage's step (`progress` s in (0, 1]) adds its Δs (a
        stage begins at s = 0).
        """
        from dolfinx.io import VTXWriter

        tau = self.advance(t, time, progress)
        for f in functions():
            if f.name not in self._series:
                self.folder.mkdir(parents=True, exist_ok=True)
                copy = fem.Function(f.function_space, name=f.name)
                writer = VTXWriter(f.function_space.mesh.comm, self.folder / f"{f.name}.bp",
                                   [copy])
                self._series[f.name] = (writer, copy)
            writer, copy = self._series[f.name]
            copy.x.array[:] = f.x.array
            writer.write(tau)
        self.times.append(tau)

    def advance(self, t: float, time: float | None = None, progress: float | None = None
                ) -> float:
        """The time of a step at load factor t (`write`'s), counted without writing it.

        A restart's steps before it count so, and its fields go on at their times.
        """
        step = abs(t - self._last)
        if progress is not None:
            step += progress - (self._progress if progress > self._progress else 0.0)
            self._progress = progress
        self._tau = time if time is not None else self._tau + step
        self._last = t
        return self._tau

    @property
    def paths(self) -> list[Path]:
        """The files written so far."""
        return [self.folder / f"{name}.bp" for name in self._series]

    def close(self) -> None:
        """Close every file (collective)."""
        for writer, _ in self._series.values():
            writer.close()
        self._series.clear()


@dataclass
class Grid:
    """A whole mesh on rank 0: VTK cells (n, i0, i1, ...), VTK cell types, points, fields."""

    cells: np.ndarray
    cell_types: np.ndarray
    points: np.ndarray  # (N, 3)
    point_data: dict[str, np.ndarray]
    cell_data: dict[str, np.ndarray]

    def pyvista(self):
        """The grid as a pyvista UnstructuredGrid."""
        import pyvista

        grid = pyvista.UnstructuredGrid(self.cells, self.cell_types, self.points)
        for k, v in self.point_data.items():
            grid.point_data[k] = v
        for k, v in self.cell_data.items():
            grid.cell_data[k] = v
        return grid

    def corner_cells(self) -> np.ndarray:
        """(n_cells, k) node indices of each cell's vertices (the first k VTK nodes)."""
        n = self.cells[0]
        table = self.cells.reshape(-1, n + 1)[:, 1:]
        corners = {6: 3, 9: 4, 10: 4, 3: 3, 4: 4}.get(n, n)  # P2/Q2 nodes list corners first
        return table[:, :corners]


def gather_grid(V: fem.FunctionSpace, point_data: dict[str, fem.Function] | None = None,
                cell_data: dict[str, np.ndarray] | None = None) -> Grid | None:
    """The mesh of the Lagrange space V with fields, gathered on rank 0 (None elsewhere).

    `point_data`: functions on V (any block size); `cell_data`: arrays over this rank's
    owned cells. Nodes on partition boundaries appear once per rank that holds them, which
    a picture does not mind.
    """
    from dolfinx import plot

    comm = V.mesh.comm
    topology, types, x = plot.vtk_mesh(V)
    n_cells = len(types)
    cells = topology.reshape(n_cells, V.dofmap.dof_layout.num_dofs + 1)  # also for 0 cells
    bs = V.dofmap.index_map_bs
    points = {k: f.x.array.reshape(-1, bs) if bs > 1 else f.x.array.copy()
              for k, f in (point_data or {}).items()}
    local = (cells, types, x, points, {k: np.asarray(v)[:n_cells]
                                       for k, v in (cell_data or {}).items()})
    parts = comm.gather(local, root=0)
    if comm.rank != 0:
        return None
    offset, all_cells = 0, []
    for c, _, xx, _, _ in parts:
        c = c.copy()
        c[:, 1:] += offset
        all_cells.append(c)
        offset += len(xx)
    return Grid(np.concatenate(all_cells).ravel(), np.concatenate([p[1] for p in parts]),
                np.concatenate([p[2] for p in parts]),
                {k: np.concatenate([p[3][k] for p in parts]) for k in parts[0][3]},
                {k: np.concatenate([p[4][k] for p in parts]) for k in parts[0][4]})


def owned_cell_values(f: fem.Function) -> np.ndarray:
    """A DG0 function's values on this rank's owned cells, in cell order."""
    tdim = f.function_space.mesh.topology.dim
    n = f.function_space.mesh.topology.index_map(tdim).size_local
    return f.x.array[f.function_space.dofmap.list[:n, 0]]


def vertex_interpolant(u: fem.Function) -> fem.Function:
    """u itself if it is P1, else its interpolant in the vector P1 space (for pictures)."""
    if u.function_space.element.basix_element.degree == 1:
        return u
    msh = u.function_space.mesh
    u1 = fem.Function(fem.functionspace(msh, ("Lagrange", 1, (msh.geometry.dim,))))
    u1.interpolate(u)
    return u1


def section(u: fem.Function, cell_field: fem.Function, normal_axis: int | None = None):
    """A plane picture of the body on rank 0 (None elsewhere), for matplotlib.

    2D meshes as they are; 3D meshes cut by the plane x_{normal_axis} = 0⁺ (just inside a
    symmetry plane). Returns (x, z, u_x, u_z, triangles, values): in-plane coordinates and
    displacement of the nodes, triangles, and `cell_field` (DG0) on each triangle. `u`
    is drawn through its vertex values (P1).
    """
    u = vertex_interpolant(u)
    V = u.function_space
    msh = V.mesh
    grid = gather_grid(V, {"u": u}, {"f": owned_cell_values(cell_field)})
    if grid is None:
        return None
    dim = msh.geometry.dim
    if dim == 2:
        cells = grid.corner_cells()
        values = grid.cell_data["f"]
        if cells.shape[1] == 4:  # quadrilaterals (VTK order): two triangles each
            cells = np.vstack([cells[:, [0, 1, 2]], cells[:, [0, 2, 3]]])
            values = np.concatenate([values, values])
        pts, disp = grid.points, grid.point_data["u"]
        return pts[:, 0], pts[:, 1], disp[:, 0], disp[:, 1], cells, values
    vtk = grid.pyvista()
    extent = np.ptp(grid.points[:, normal_axis])
    origin = [0.0, 0.0, 0.0]
    origin[normal_axis] = 1e-7 * extent
    normal = [0.0, 0.0, 0.0]
    normal[normal_axis] = 1.0
    cut = vtk.slice(normal=normal, origin=origin).triangulate()
    tri = cut.faces.reshape(-1, 4)[:, 1:]
    inplane = [i for i in range(3) if i != normal_axis]
    pts, disp = cut.points, cut.point_data["u"]
    return (pts[:, inplane[0]], pts[:, inplane[1]], disp[:, inplane[0]], disp[:, inplane[1]],
            tri, cut.cell_data["f"])
