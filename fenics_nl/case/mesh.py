"""The mesh of a case: a .msh read, or a .geo meshed by gmsh at run time, checked."""

from __future__ import annotations

import functools
from pathlib import Path

import gmsh
import numpy as np
from dolfinx.io import gmsh as gmshio
from mpi4py import MPI

from fenics_nl.case.spec import Case, CaseError
from fenics_nl.domain.mesh_check import check_cells
from fenics_nl.domain.meshes import gmsh_error, group_error, start_model

__all__ = ["geometry_dimension", "load_mesh"]


def load_mesh(case: Case, comm: MPI.Comm = MPI.COMM_WORLD) -> gmshio.MeshData:
    """MeshData of the case's mesh (physical groups by name), or CaseError naming the key."""
    data = _read(case, comm)
    if case.mesh_file.suffix == ".msh":
        check_cells(data.mesh, name=str(case.mesh_file))  # a file may hold anything
    if case.model == "axisymmetric":
        x = data.mesh.geometry.x
        x_min = comm.allreduce(float(x[:, 0].min(initial=np.inf)), MPI.MIN)
        size = comm.allreduce(float(np.ptp(x[:, :2], axis=0).max()) if len(x) else 0.0,
                              MPI.MAX)
        if x_min < -1e-12 * size:
            raise CaseError([f"mesh.model: axisymmetric meshes lie in x >= 0 (x is the "
                             f"radius); {case.mesh_file.name} reaches x = {x_min:g}"])
    return data


def geometry_dimension(path, comm: MPI.Comm = MPI.COMM_WORLD) -> int | None:
    """The dimension of the geometry or mesh in a .geo/.msh file (None if gmsh cannot say).

    Opened on rank 0 without meshing, once per file's version (the command reads a case
    twice): a file that cannot fit the model is told before the rest of the case is read
    against it. Collective on `comm`.
    """
    dim = _dimension_on_rank_0(str(path), Path(path).stat().st_mtime_ns) if (
        comm.rank == 0) else None
    dim = comm.bcast(dim, root=0)
    return dim if dim is not None and dim >= 0 else None


@functools.cache
def _dimension_on_rank_0(path: str, version: int) -> int | None:
    try:
        start_model("dimension")
        gmsh.open(path)
        return gmsh.model.getDimension()
    except Exception:  # said by `load_mesh`, with gmsh's words
        return None
    finally:
        try:
            if gmsh.model.list():
                gmsh.model.remove()
        except Exception:  # nothing to remove: the next model starts anew anyway
            pass


def _refine_near(refine: dict, dim: int, largest: float | None) -> str | None:
    """A gmsh size field for `mesh.refine_near`; the message of a group not there, or None.

    Cells of `size` within `distance` of the groups, then growing linearly to the mesh's
    own size over another `distance`. The mesh's own size: `largest` (mesh.size) if given,
    else the largest of the geometry's point sizes, else a tenth of its bounding box.
    """
    have = {gmsh.model.getPhysicalName(d, t): (d, t) for d, t in
            gmsh.model.getPhysicalGroups(dim - 1)}
    missing = [g for g in refine["groups"] if g not in have]
    if missing:
        return (f"mesh.refine_near.groups: {', '.join(map(repr, missing))} is not a boundary "
                f"group of the geometry (it has: {', '.join(sorted(have)) or 'none'})")
    entities = [e for g in refine["groups"]
                for e in gmsh.model.getEntitiesForPhysicalGroup(*have[g])]
    field = gmsh.model.mesh.field
    distance = field.add("Distance")
    field.setNumbers(distance, "CurvesList" if dim == 2 else "SurfacesList", entities)
    field.setNumber(distance, "Sampling", 200)
    threshold = field.add("Threshold")
    field.setNumber(threshold, "InField", distance)
    field.setNumber(threshold, "SizeMin", refine["size"])
    if largest is None:
        points = gmsh.model.getEntities(0)
        sizes = [v for v in gmsh.model.mesh.getSizes(points) if v > 0] if points else []
        box = np.array(gmsh.model.getBoundingBox(-1, -1))
        largest = max(sizes) if sizes else 0.1 * float(np.linalg.norm(box[3:] - box[:3]))
    field.setNumber(threshold, "SizeMax", max(largest, refine["size"]))
    field.setNumber(threshold, "DistMin", refine["distance"])
    field.setNumber(threshold, "DistMax", 2 * refine["distance"])
    field.setAsBackgroundMesh(threshold)
    return None


def _read(case: Case, comm: MPI.Comm) -> gmshio.MeshData:
    """The mesh, built and checked on rank 0, then distributed.

    A .msh is opened; a .geo is meshed with gmsh's default options, then the file's, then
    `size`.
    """
    error = None
    if comm.rank == 0:
        action = "mesh" if case.mesh_file.suffix == ".geo" else "read"
        try:
            start_model("case")
            error = _built(case, action)
        except Exception as err:  # gmsh raises Exception with its own message
            error = (f"mesh.file: gmsh cannot {action} {case.mesh_file.name}: "
                     f"{' '.join(str(err).split()) or type(err).__name__}")
    error = comm.bcast(error, root=0)
    if error is not None:
        if comm.rank == 0 and gmsh.model.list():
            gmsh.model.remove()
        raise CaseError([error])
    data = gmshio.model_to_mesh(gmsh.model, comm, 0, gdim=case.dim)
    if comm.rank == 0:
        gmsh.model.remove()
    return data


def _built(case: Case, action: str) -> str | None:
    """The case's mesh in gmsh's model (rank 0): what is wrong with it, or None.

    A .msh is read; a .geo is meshed, after `mesh.size` and `mesh.refine_near` (whose
    missing group is the message then).
    """
    name = case.mesh_file.name
    said = gmsh_error(lambda: gmsh.open(str(case.mesh_file)))
    dim = gmsh.model.getDimension() if said is None else -1
    if said is None and case.mesh_file.suffix == ".geo" and dim >= 0:
        if case.mesh_size is not None:
            gmsh.option.setNumber("Mesh.MeshSizeMax", case.mesh_size)
        if case.refine_near is not None:
            missing = _refine_near(case.refine_near, dim, case.mesh_size)
            if missing is not None:
                return missing
        said = gmsh_error(lambda: gmsh.model.mesh.generate(dim))
    if said is not None or dim < 0:
        return f"mesh.file: gmsh cannot {action} {name}: {said or 'no geometry in it'}"
    if dim != case.dim:
        return f"mesh.model: {case.model!r} needs a {case.dim}D mesh, {name} has {dim}D cells"
    if not any(len(gmsh.model.mesh.getElements(dim, t)[1])
               for _, t in gmsh.model.getEntities(dim)):
        return f"mesh.file: {name} has no {dim}D element"
    wrong = group_error(dim)
    return None if wrong is None else f"mesh.file: {name}: {wrong}"
