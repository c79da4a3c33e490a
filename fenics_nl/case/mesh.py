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
from fenics_nl.domain.meshes import start_model

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
    `size`. gmsh reports a bad file in its log, not by an exception: the log is read.
    """
    error, name = None, case.mesh_file.name
    action = "mesh" if case.mesh_file.suffix == ".geo" else "read"
    if comm.rank == 0:
        try:
            start_model("case")
            gmsh.logger.start()
            gmsh.open(str(case.mesh_file))
            dim = gmsh.model.getDimension()
            if case.mesh_file.suffix == ".geo" and dim >= 0:
                if case.mesh_size is not None:
                    gmsh.option.setNumber("Mesh.MeshSizeMax", case.mesh_size)
                if case.refine_near is not None:
                    error = _refine_near(case.refine_near, dim, case.mesh_size)
                if error is None:
                    gmsh.model.mesh.generate(dim)
            logged = [line for line in gmsh.logger.get() if line.startswith("Error")]
            gmsh.logger.stop()
            if error is not None:  # said already
                logged = []
            elif logged or dim < 0:
                error = (f"mesh.file: gmsh cannot {action} {name}: "
                         f"{logged[0] if logged else 'no geometry in it'}")
            elif dim != case.dim:
                error = (f"mesh.model: {case.model!r} needs a {case.dim}D mesh, {name} has "
                         f"{dim}D cells")
            elif not any(len(gmsh.model.mesh.getElements(dim, t)[1])
                         for _, t in gmsh.model.getEntities(dim)):
                error = f"mesh.file: {name} has no {dim}D element"
            elif not gmsh.model.getPhysicalGroups(dim):
                error = (f"mesh.file: {name} has no {dim}D physical group (dolfinx keeps only "
                         f"the cells of physical groups)")
            elif wrong := _not_one_group(dim):
                error = f"mesh.file: {name}: {wrong} (each cell takes one group)"
        except Exception as err:  # gmsh raises Exception with its own message
            error = (f"mesh.file: gmsh cannot {action} {name}: "
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


def _not_one_group(dim: int) -> str | None:
    """What is wrong with the first `dim`D entity not in one physical group, or None."""
    seen: dict[int, str] = {}
    for _, tag in gmsh.model.getPhysicalGroups(dim):
        group = gmsh.model.getPhysicalName(dim, tag) or str(tag)
        for entity in map(int, gmsh.model.getEntitiesForPhysicalGroup(dim, tag)):
            if entity in seen:
                return (f"the {dim}D entity {entity} is in the physical groups "
                        f"{seen[entity]!r} and {group!r}")
            seen[entity] = group
    bare = [t for _, t in gmsh.model.getEntities(dim) if t not in seen]
    if bare:
        return (f"the {dim}D entit{'ies' if len(bare) > 1 else 'y'} "
                f"{', '.join(map(str, bare))} {'are' if len(bare) > 1 else 'is'} in no "
                "physical group")
    return None
