"""An L-shaped bracket in gmsh (OpenCASCADE), dimensions in mm: the mesh and its tags.

Base plate 100 x 60 x 10 on z = 0 with two bolt holes (Ø12) at x = 70; a vertical arm
10 x 60 x 80 at x = 0 with a loaded hole (Ø16) through it at z = 60; an 8 mm fillet
between them, where the stress concentrates. Physical groups:

    bolts (the two hole surfaces), load (the arm's hole surface), base (the bottom face
    z = 0), solid (the volume).

`bracket_mesh` gives DOLFINx's mesh with its cell and facet tags (the groups above), built
or read from a user's .msh file with the same groups. `meshes/bracket.py` writes it to a
file you can open in gmsh::

    python meshes/bracket.py --size 4 -o bracket.msh
"""

from __future__ import annotations

from pathlib import Path

import gmsh
from dolfinx.io import gmsh as gmshio
from mpi4py import MPI

from fenics_nl.domain.mesh_check import check_cells
from fenics_nl.domain.meshes import distributed, gmsh_error, group_error, start_model

__all__ = ["THICK", "bracket_mesh", "build"]

LENGTH, WIDTH, THICK, HEIGHT = 100.0, 60.0, 10.0, 80.0
FILLET, BOLT_R, BOLT_X, LOAD_R, LOAD_Z = 8.0, 6.0, 70.0, 8.0, 60.0
GROUPS = ("bolts", "load", "base")


def build(size: float) -> None:
    """Create the model `bracket` in gmsh (default options) and mesh it (tetrahedra)."""
    occ = gmsh.model.occ
    start_model("bracket")
    base = occ.addBox(0, 0, 0, LENGTH, WIDTH, THICK)
    arm = occ.addBox(0, 0, 0, THICK, WIDTH, HEIGHT)
    solid = occ.fuse([(3, base)], [(3, arm)])[0][0][1]
    occ.synchronize()
    # the inner edge between the base's top face and the arm's inner face: x = t, z = t
    inner = [tag for _, tag in gmsh.model.getEntities(1)
             if _is_line_at(occ.getCenterOfMass(1, tag), x=THICK, z=THICK)]
    solid = occ.fillet([solid], inner, [FILLET])[0][1]
    holes = [occ.addCylinder(BOLT_X, y, -1, 0, 0, THICK + 2, BOLT_R)
             for y in (WIDTH / 4, 3 * WIDTH / 4)]
    holes.append(occ.addCylinder(-1, WIDTH / 2, LOAD_Z, THICK + 2, 0, 0, LOAD_R))
    occ.cut([(3, solid)], [(3, h) for h in holes])
    occ.synchronize()
    groups = {name: [] for name in GROUPS}
    for _, tag in gmsh.model.getEntities(2):
        x, _, z = occ.getCenterOfMass(2, tag)
        if abs(z) < 1e-6 and occ.getMass(2, tag) > 100:
            groups["base"].append(tag)
        elif abs(x - BOLT_X) < 1e-6 and z < THICK:
            groups["bolts"].append(tag)
        elif abs(z - LOAD_Z) < 1e-6 and x < THICK + 1e-6:
            groups["load"].append(tag)
    for i, name in enumerate(GROUPS, start=1):
        gmsh.model.addPhysicalGroup(2, groups[name], i, name=name)
    gmsh.model.addPhysicalGroup(3, [t for _, t in gmsh.model.getEntities(3)], 1, name="solid")
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.MeshSizeMin", size / 4)
    # elements per 2π on holes and fillet: at least 12, and proportional to 1/size below
    # size 6 so that a smaller size refines the whole part (a true mesh-convergence study)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", max(12, round(72 / size)))
    gmsh.model.mesh.generate(3)


def _is_line_at(c, x, z):
    return abs(c[0] - x) < 1e-6 and abs(c[2] - z) < 1e-6


def bracket_mesh(comm: MPI.Comm, size: float | None = None, path: str | None = None,
                 length_scale: float = 1.0) -> gmshio.MeshData:
    """The bracket's mesh and tags: built (element size `size` in mm) or read from `path`.

    Args:
        comm: the communicator of the mesh (gmsh works on rank 0).
        size: the largest element size in mm, when the geometry is built.
        path: a .msh file with the groups ``bolts``, ``load`` and ``base``, read in its own
            units (the cells checked: a file may hold inverted ones).
        length_scale: the length of 1 mm in the user's unit (1e-3 for metres), for the
            built geometry.

    Returns:
        DOLFINx's MeshData: `mesh`, `facet_tags`, `physical_groups` (name → tag).

    Raises:
        ValueError: the file is missing, unreadable, or lacks a group.
    """
    if path is not None:
        if not Path(path).is_file():
            raise ValueError(f"mesh file not found: {path}")
        error = None
        if comm.rank == 0:  # gmsh's terminal off (start_model): its error is ours, one line
            try:
                error = _opened(path)
            except Exception as err:  # said on every rank, not left on rank 0 alone
                error = f"cannot read mesh file {path}: {err}"
        error = comm.bcast(error, root=0)
        if error is not None:
            raise ValueError(error)
        try:
            data = distributed(comm, 1.0, 3)  # in the file's own units
        except RuntimeError as err:  # dolfinx's other refusals (facets of prisms, say)
            if comm.rank == 0 and gmsh.model.list():  # (raised on every rank alike)
                gmsh.model.remove()
            raise ValueError(f"cannot read mesh file {path}: {err}") from None
        check_cells(data.mesh, name=path)
    else:
        if comm.rank == 0:
            build(size)
        data = distributed(comm, length_scale, 3)
    missing = [g for g in GROUPS if g not in data.physical_groups]
    if missing:
        raise ValueError(f"the mesh has no physical group {', '.join(missing)} "
                         f"(needs {', '.join(GROUPS)})")
    return data


def _opened(path) -> str | None:
    """Open the .msh `path` in gmsh (rank 0); what is wrong with it, or None."""
    start_model("bracket file")
    said = gmsh_error(lambda: gmsh.open(str(path)))
    if said is not None:
        error = f"cannot read mesh file {path}: {said}"
    elif (wrong := group_error(3)) is not None:
        error = f"{path}: {wrong}"
    else:
        return None
    gmsh.model.remove()
    return error
