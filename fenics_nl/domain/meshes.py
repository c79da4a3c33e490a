"""gmsh meshes built on rank 0 and distributed by `dolfinx.io.gmsh.model_to_mesh`."""

from __future__ import annotations

from collections.abc import Callable

import gmsh
from dolfinx.io import gmsh as gmshio
from mpi4py import MPI

__all__ = ["PUNCH_GROWTH", "distributed", "gmsh_error", "graded_block", "group_error",
           "punch_block", "punch_block_size", "quarter_annulus", "quarter_cylinder",
           "size_by_field", "start_model", "threshold_field"]


def start_model(name: str) -> None:
    """A new model `name` in gmsh, with gmsh's default options.

    Mesh options are global in gmsh: a bracket's MeshSizeMin, left over, made a punch meshed
    next in the same session 40 times too coarse under the punch. Every model starts here.
    """
    if not gmsh.isInitialized():
        gmsh.initialize(interruptible=False)
    gmsh.option.restoreDefaults()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add(name)


def gmsh_error(step: Callable[[], object]) -> str | None:
    """Run `step` (gmsh calls) with gmsh's log read: the first error it logged or raised.

    gmsh logs a corrupt file's error and raises on some only; with its terminal off
    (`start_model`) the user reads the error once, in the caller's sentence.

    Returns:
        The error's text (without gmsh's ``Error :``), or None.
    """
    gmsh.logger.start()
    try:
        step()
        logged = [line for line in gmsh.logger.get() if line.startswith("Error")]
    except Exception as err:  # gmsh raises Exception with its own message
        return " ".join(str(err).split()) or type(err).__name__
    finally:
        gmsh.logger.stop()
    return logged[0].split(":", 1)[1].strip() if logged else None


def group_error(dim: int) -> str | None:
    """Why dolfinx cannot take the model's cells of dimension `dim` as grouped, or None.

    dolfinx reads the cells of physical groups, each cell in exactly one: a file with no
    group, an entity in two groups or in none is refused here, in a sentence that names
    the groups and entities (dolfinx refuses the last two with a count of cells, and a cell
    type met only outside the groups with a KeyError on rank 0 alone, the other ranks
    waiting).
    """
    if not gmsh.model.getPhysicalGroups(dim):
        return f"no {dim}D physical group (dolfinx keeps only the cells of physical groups)"
    seen: dict[int, str] = {}
    for _, tag in gmsh.model.getPhysicalGroups(dim):
        group = gmsh.model.getPhysicalName(dim, tag) or str(tag)
        for entity in map(int, gmsh.model.getEntitiesForPhysicalGroup(dim, tag)):
            if entity in seen:
                return (f"the {dim}D entity {entity} is in the physical groups "
                        f"{seen[entity]!r} and {group!r} (each cell takes one group)")
            seen[entity] = group
    bare = [t for _, t in gmsh.model.getEntities(dim) if t not in seen]
    if bare:
        return (f"the {dim}D entit{'ies' if len(bare) > 1 else 'y'} "
                f"{', '.join(map(str, bare))} {'are' if len(bare) > 1 else 'is'} in no "
                "physical group (each cell takes one group)")
    return None


def threshold_field(h_fine: float, fine_radius: float, h_coarse: float, far: float, *,
                    points=(), curves=(), sampling: int = 400) -> int:
    """A gmsh size field: h_fine near points or curves, growing linearly to h_coarse.

    gmsh's Distance and Threshold: h_fine within `fine_radius`, h_coarse from `far` on.

    Args:
        h_fine: the size near them.
        fine_radius: the distance within which it is h_fine.
        h_coarse: the size from `far` on.
        far: the distance from which it is h_coarse.
        points: the gmsh points (tags) the distance is measured from.
        curves: the gmsh curves (tags) the distance is measured from.
        sampling: the points per curve the distance is measured at.

    Returns:
        The field's tag.
    """
    field = gmsh.model.mesh.field
    dist = field.add("Distance")
    if points:
        field.setNumbers(dist, "PointsList", list(points))
    if curves:
        field.setNumbers(dist, "CurvesList", list(curves))
        field.setNumber(dist, "Sampling", sampling)
    thr = field.add("Threshold")
    field.setNumber(thr, "InField", dist)
    field.setNumber(thr, "SizeMin", h_fine)
    field.setNumber(thr, "SizeMax", h_coarse)
    field.setNumber(thr, "DistMin", fine_radius)
    field.setNumber(thr, "DistMax", far)
    return thr


def size_by_field(tag: int) -> None:
    """Mesh by the size field `tag` alone (not the points' sizes, boundary's, curvature's)."""
    gmsh.model.mesh.field.setAsBackgroundMesh(tag)
    for opt in ("MeshSizeExtendFromBoundary", "MeshSizeFromPoints", "MeshSizeFromCurvature"):
        gmsh.option.setNumber(f"Mesh.{opt}", 0)


def distributed(comm: MPI.Comm, unit: float, dim: int = 2) -> gmshio.MeshData:
    """The model meshed on rank 0, distributed, removed from gmsh, scaled back by `unit`.

    Args:
        comm: the communicator.
        unit: the length gmsh worked in (its tolerances are absolute).
        dim: the geometric dimension.

    Returns:
        DOLFINx's mesh with its tags.
    """
    data = gmshio.model_to_mesh(gmsh.model, comm, 0, gdim=dim)
    if comm.rank == 0:
        gmsh.model.remove()
    data.mesh.geometry.x[:] *= unit
    return data


def _graded_size_field(h_fine: float, fine_radius: float, h_coarse: float, far: float):
    """Element size h_fine within `fine_radius` of the origin, growing linearly to h_coarse."""
    origin = gmsh.model.getEntitiesInBoundingBox(-1e-9, -1e-9, -1e-9, 1e-9, 1e-9, 1e-9, 0)
    size_by_field(threshold_field(h_fine, fine_radius, h_coarse, far,
                                  points=[tag for _, tag in origin]))


def graded_block(comm: MPI.Comm, dim: int, width: float, depth: float, h_fine: float,
                 fine_radius: float, growth: float = 0.15, msh_file: str | None = None,
                 both_sides: bool = False) -> gmshio.MeshData:
    """A block under a surface load near the origin, refined there.

    2D: [0, width] x [-depth, 0] (axisymmetric or half plane-strain model).
    3D: [0, width]² x [-depth, 0] (quarter model). The top (z = 0, or y = 0 in 2D) is the
    physical group ``contact``; ``symmetry_x`` (x = 0), ``symmetry_y`` (3D, y = 0),
    ``bottom`` and ``side`` complete it. Element size h_fine inside `fine_radius` of the
    origin, then growing by `growth` per unit distance (geometric-like grading).
    `both_sides`: x runs from -width to width (no ``symmetry_x``), for a load along x.

    gmsh works in units of `fine_radius` (its tolerances are absolute) and the coordinates
    are scaled back, so the mesh is the same, up to scale, in any unit system. `msh_file`:
    also write the mesh there (in the caller's units), e.g. for a case file.
    """
    unit = fine_radius
    width, depth, h_fine, fine_radius = width / unit, depth / unit, h_fine / unit, 1.0
    if comm.rank == 0:
        start_model(f"block{dim}d")
        occ = gmsh.model.occ
        x0, wx = (-width, 2 * width) if both_sides else (0.0, width)
        if dim == 2:
            body = occ.addRectangle(x0, -depth, 0, wx, depth)
        else:
            body = occ.addBox(x0, 0, -depth, wx, width, depth)
        if both_sides:  # a vertex at the origin, which the size field is measured from
            occ.fragment([(dim, body)], [(0, occ.addPoint(0, 0, 0))])
        occ.synchronize()
        up = 1 if dim == 2 else 2  # index of the vertical coordinate
        groups = {"contact": [], "symmetry_x": [], "symmetry_y": [], "bottom": [], "side": []}
        for d, tag in gmsh.model.getEntities(dim - 1):
            c = occ.getCenterOfMass(d, tag)
            if abs(c[up]) < 1e-9 * depth:
                groups["contact"].append(tag)
            elif abs(c[up] + depth) < 1e-9 * depth:
                groups["bottom"].append(tag)
            elif abs(c[0]) < 1e-9 * width and not both_sides:
                groups["symmetry_x"].append(tag)
            elif dim == 3 and abs(c[1]) < 1e-9 * width:
                groups["symmetry_y"].append(tag)
            else:
                groups["side"].append(tag)
        for i, (name, tags) in enumerate(groups.items(), start=1):
            if tags:
                gmsh.model.addPhysicalGroup(dim - 1, tags, i, name=name)
        gmsh.model.addPhysicalGroup(dim, [t for _, t in gmsh.model.getEntities(dim)], 1,
                                    name="solid")
        far = max(width, depth)
        _graded_size_field(h_fine, fine_radius, h_fine + growth * far, far)
        gmsh.model.mesh.generate(dim)
    data = gmshio.model_to_mesh(gmsh.model, comm, 0, gdim=dim)
    if msh_file is not None and comm.rank == 0:
        gmsh.model.mesh.affineTransform([unit, 0, 0, 0, 0, unit, 0, 0, 0, 0, unit, 0])
        gmsh.option.setNumber("Mesh.Binary", 1)  # the coordinates to the last bit
        gmsh.write(str(msh_file))
    if comm.rank == 0:
        gmsh.model.remove()
    data.mesh.geometry.x[:] *= unit
    return data


# a rigid punch's block: a/h at refine 0 under the punch (plane strain: the half-width is
# about half of √(Rδ), so the mesh is twice as fine), and the far field's grading: what the
# axisymmetric force-indentation law (the half-space's) needs, 5 % (at 10 % its error
# doubles to 0.28 %, 0.92 % at 20 %); plane strain has no such law (the indentation depends
# on the block) and what it checks is local, so 20 % (Cattaneo-Mindlin: 76k unknowns
# instead of 160k, the same errors); 3D 10 % (benchmarks/contact.py)
PUNCH_FINE = {"axisymmetric": 20, "3d": 6, "plane_strain": 40}
PUNCH_GROWTH = {"axisymmetric": 0.05, "3d": 0.10, "plane_strain": 0.20}


def punch_block(comm: MPI.Comm, model: str, a: float, *, refine: int = 1, size: float = 1000.0,
                growth: float | None = None, both_sides: bool = False
                ) -> tuple[gmshio.MeshData, float]:
    """The block under a rigid punch, made for its contact radius `a` (`graded_block`).

    Elements of h = a/(20·2^refine) (plane strain a/40, 3D a/6) within 1.5 a of the axis,
    growing by 5 % of the distance (plane strain 20 %, 3D 10 %) out to `size` a.

    Args:
        comm: the communicator.
        model: ``axisymmetric``, ``3d`` (a quarter, or with `both_sides` a half) or
            ``plane_strain`` (a half, or the whole width with `both_sides`).
        a: the expected contact radius (half-width in plane strain).
        refine: halves h this many times.
        size: the block's width and depth in contact radii.
        growth: the far field's grading (default by model, above).
        both_sides: the block spans both sides of the axis (a tangential load).

    Returns:
        (the mesh with its facet tags ``contact``, ``bottom``, ``side``, ``symmetry_x``
        unless `both_sides`, ``symmetry_y`` in 3D; h).
    """
    dim = 3 if model == "3d" else 2
    h = a / (PUNCH_FINE[model] * 2**refine)
    growth = PUNCH_GROWTH[model] if growth is None else growth
    return graded_block(comm, dim, size * a, size * a, h, 1.5 * a, growth,
                        both_sides=both_sides), h


def punch_block_size(model: str, block: float | None = None) -> float:
    """The punch's block size in contact radii.

    Args:
        model: ``axisymmetric``, ``3d`` or ``plane_strain``.
        block: the size asked for, or None.

    Returns:
        `block`, else 1000 (3D: 100, where the far field's tetrahedra cost the most).
    """
    return block or (100.0 if model == "3d" else 1000.0)


def quarter_annulus(comm: MPI.Comm, a: float, b: float, size: float, order: int = 2
                    ) -> gmshio.MeshData:
    """The quarter a < |x| < b, x, y ≥ 0, triangles of `size`, curved edges of `order`.

    Physical groups: ``inner`` (|x| = a), ``outer`` (|x| = b), ``x0`` (x = 0), ``y0``
    (y = 0), ``body``. For a sphere in the axisymmetric model (x = r, y = z) or a cylinder
    in plane strain. Meshed in units of `a` (gmsh's tolerances are absolute), scaled back.
    """
    if comm.rank == 0:
        start_model("annulus")
        g = gmsh.model.geo
        s, B = size / a, b / a
        o = g.addPoint(0, 0, 0, s)
        p = [g.addPoint(1, 0, 0, s), g.addPoint(B, 0, 0, s), g.addPoint(0, B, 0, s),
             g.addPoint(0, 1, 0, s)]
        curves = [g.addLine(p[0], p[1]), g.addCircleArc(p[1], o, p[2]), g.addLine(p[2], p[3]),
                  g.addCircleArc(p[3], o, p[0])]
        surface = g.addPlaneSurface([g.addCurveLoop(curves)])
        g.synchronize()
        for tag, (curve, name) in enumerate(zip(curves, ("y0", "outer", "x0", "inner"),
                                                strict=True), start=1):
            gmsh.model.addPhysicalGroup(1, [curve], tag, name=name)
        gmsh.model.addPhysicalGroup(2, [surface], 1, name="body")
        gmsh.option.setNumber("Mesh.ElementOrder", order)
        gmsh.model.mesh.generate(2)
    return distributed(comm, a)


def quarter_cylinder(comm: MPI.Comm, radius: float, height: float, size: float,
                     order: int = 2) -> gmshio.MeshData:
    """The quarter cylinder x, y ≥ 0, x² + y² < R², 0 < z < `height`: tetrahedra of `size`.

    For a billet with three planes of symmetry (an eighth of it: `height` is half the
    billet's). Curved faces of `order` (2: the round side is a curved P2 surface whose
    nodes are on the cylinder: the quarter disc's area is πR²/4 to 2e-6 at R/5). Physical
    groups: ``top`` (z = height), ``mid`` (z = 0), ``side`` (the round face), ``x0`` (the
    plane x = 0), ``y0`` (y = 0), ``body``.
    Meshed in units of R (gmsh's tolerances are absolute), scaled back.
    """
    if comm.rank == 0:
        start_model("quarter_cylinder")
        occ = gmsh.model.occ
        H = height / radius
        cylinder = occ.addCylinder(0, 0, 0, 0, 0, H, 1.0)
        occ.intersect([(3, cylinder)], [(3, occ.addBox(0, 0, 0, 2, 2, 2 * H))])
        occ.synchronize()
        groups: dict[str, list[int]] = {}
        for _, tag in gmsh.model.getEntities(2):
            x, y, z = occ.getCenterOfMass(2, tag)
            name = ("top" if abs(z - H) < 1e-9 else "mid" if abs(z) < 1e-9
                    else "x0" if abs(x) < 1e-9 else "y0" if abs(y) < 1e-9 else "side")
            groups.setdefault(name, []).append(tag)
        for tag, name in enumerate(("top", "mid", "side", "x0", "y0"), start=1):
            gmsh.model.addPhysicalGroup(2, groups[name], tag, name=name)
        gmsh.model.addPhysicalGroup(3, [t for _, t in gmsh.model.getEntities(3)], 1,
                                    name="body")
        for option in ("MeshSizeMin", "MeshSizeMax"):  # uniform: not the points' sizes
            gmsh.option.setNumber(f"Mesh.{option}", size / radius)
        gmsh.option.setNumber("Mesh.ElementOrder", order)
        gmsh.model.mesh.generate(3)
    return distributed(comm, radius, 3)
