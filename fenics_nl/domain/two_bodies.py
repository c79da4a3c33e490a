"""Two bodies: a sphere (or a cylinder) on a block or on another one; a shaft in its bearing.

The section of an axisymmetric model (x = r, y = z) or of a plane-strain one: the upper
body is the quarter disc of radius R1 whose lowest point is the origin (centre (0, R1)),
cut at its equator; the lower body is the quarter disc of radius R2 whose highest point is
the origin, cut at its equator, or a block [0, width] × [−depth, 0] (R2 = None). The two
share no node: they touch at the origin only, and the gap between them opens as
r²/(2R) there (1/R = 1/R1 + 1/R2). Triangles of size h within 1.5 a of the origin (a the
contact radius the mesh is made for), growing by `growth` per unit distance.

Cell tags ``upper``, ``lower``; facet tags ``upper_contact`` (the upper body's arc),
``upper_top`` (its equator, where it is pushed), ``upper_axis``, ``lower_contact`` (the
lower arc or the block's top), ``lower_bottom`` (the equator or the block's bottom),
``lower_axis``, and ``lower_side`` (the block's).

`shaft_in_bearing`: the half (x ≥ 0; or the whole) of a shaft of radius R1 around its hub
(a rigid core of radius R1/5, where it is driven) in a housing of bore R2 = R1 + clearance
and outer radius R3, all centred at the origin (plane strain): they do not touch; pushed
down, the shaft's lowest point meets the bore's. Triangles of size h along the
lower halves of both circles (where the contact arc grows), growing away from them.
"""

from __future__ import annotations

import gmsh
from dolfinx.io import gmsh as gmshio
from mpi4py import MPI

from fenics_nl.domain.meshes import (
    _graded_size_field,
    distributed,
    size_by_field,
    start_model,
    threshold_field,
)

__all__ = ["BALL_TAGS", "BEARING_TAGS", "PIN_TAGS", "TWO_BODY_TAGS", "ball_on_block",
           "pin_on_flat", "shaft_in_bearing", "sphere_on_body"]

TOL = 1e-6  # gmsh's model works in units of the contact's size: a point on a line


def _name_groups(bodies: dict[str, tuple[int, int]], names: tuple[str, ...], name_of
                 ) -> dict[str, list[int]]:
    """The physical groups of two (or more) bodies: their cells, and their boundaries'.

    Each body (its gmsh (dim, tag)) is a cell group numbered in order, 1, 2, ...; each
    entity of its boundary is in the facet group `name_of(body, entity)`, one of `names`,
    numbered in the order of `names` (an empty one left out).

    Returns:
        The entities of each name (for size fields near some of them).
    """
    groups = {name: [] for name in names}
    for body, (dim, tag) in bodies.items():
        _, boundary = gmsh.model.getAdjacencies(dim, tag)
        for entity in boundary:
            groups[name_of(body, entity)].append(entity)
    for i, (name, tags) in enumerate(groups.items(), start=1):
        if tags:
            gmsh.model.addPhysicalGroup(dim - 1, tags, i, name=name)
    for i, (body, (dim, tag)) in enumerate(bodies.items(), start=1):
        gmsh.model.addPhysicalGroup(dim, [tag], i, name=body)
    return groups


TWO_BODY_TAGS = ("upper_contact", "upper_top", "upper_axis", "lower_contact", "lower_bottom",
                 "lower_axis", "lower_side")


def sphere_on_body(comm: MPI.Comm, R1: float, a: float, *, R2: float | None = None,
                   block: float = 4.0, fine: float = 20.0, growth: float = 0.05,
                   both_sides: bool = False) -> gmshio.MeshData:
    """The upper quarter disc on the lower one (or on a block), touching at the origin.

    Args:
        comm: the communicator.
        R1: the upper body's radius.
        a: the contact radius (half-width) the mesh is made for.
        R2: the lower body's radius (None: a block, width and depth `block` R1).
        block: the block's size in R1.
        fine: a/h near the origin.
        growth: the elements' growth per unit distance beyond 1.5 a.
        both_sides: the half discs on both sides of the axis (plane strain under a
            tangential load: no ``upper_axis``, ``lower_axis``).

    Returns:
        The mesh with its cell tags (``upper`` 1, ``lower`` 2) and facet tags (module).
    """
    unit = a  # gmsh's tolerances are absolute: it works in units of a
    r1, r2 = R1 / unit, None if R2 is None else R2 / unit
    width = depth = block * r1
    if comm.rank == 0:
        start_model("two_bodies")
        occ = gmsh.model.occ
        k = 2 if both_sides else 1  # the rectangles' width, in radii
        upper = occ.intersect([(2, occ.addDisk(0, r1, 0, r1, r1))],
                              [(2, occ.addRectangle(-(k - 1) * r1, 0, 0, k * r1, r1))])[0]
        if r2 is None:
            lower = [(2, occ.addRectangle(-(k - 1) * width, -depth, 0, k * width, depth))]
        else:
            lower = occ.intersect([(2, occ.addDisk(0, -r2, 0, r2, r2))],
                                  [(2, occ.addRectangle(-(k - 1) * r2, -r2, 0, k * r2, r2))])[0]
        if both_sides:  # a vertex of each body at the origin (apart: they share no node)
            upper = [e for e in occ.fragment(upper, [(0, occ.addPoint(0, 0, 0))])[0]
                     if e[0] == 2]
            lower = [e for e in occ.fragment(lower, [(0, occ.addPoint(0, 0, 0))])[0]
                     if e[0] == 2]
        occ.synchronize()

        def name_of(body, c):
            x, y, _ = occ.getCenterOfMass(1, c)
            if abs(x) < TOL and not both_sides:
                return f"{body}_axis"
            if body == "upper":
                return "upper_top" if abs(y - r1) < TOL else "upper_contact"
            if r2 is None:
                return "lower_contact" if abs(y) < TOL else "lower_bottom" \
                    if abs(y + depth) < TOL else "lower_side"
            return "lower_bottom" if abs(y + r2) < TOL else "lower_contact"

        _name_groups({"upper": upper[0], "lower": lower[0]}, TWO_BODY_TAGS, name_of)
        far = max(width, depth, r1, r2 or 0.0)
        _graded_size_field(a / fine / unit, 1.5, a / fine / unit + growth * far, far)
        gmsh.model.mesh.generate(2)
    return distributed(comm, unit)


BEARING_TAGS = ("shaft_surface", "shaft_symmetry", "hub", "bore", "housing_outer",
                "housing_symmetry")


def shaft_in_bearing(comm: MPI.Comm, R1: float, clearance: float, R3: float, h: float,
                     growth: float = 0.15, full: bool = False) -> gmshio.MeshData:
    """The half shaft (around its hub) in the half housing, refined along the lower arcs.

    Args:
        comm: the communicator.
        R1: the shaft's radius.
        clearance: the radial clearance R2 − R1 (> 0).
        R3: the housing's outer radius (> R1 + clearance).
        h: the element size along the lower halves of the shaft's surface and the bore.
        growth: the elements' growth per unit distance beyond.
        full: the whole shaft and housing (no symmetry lines): a load that is not along
            the symmetry line, a torque.

    Returns:
        The mesh with its cell tags (``shaft`` 1, ``housing`` 2) and facet tags
        (`BEARING_TAGS`; without the symmetry lines if `full`).
    """
    if not (clearance > 0 and R3 > R1 + clearance):
        raise ValueError(f"need clearance > 0 and R3 > R1 + clearance, got clearance = "
                         f"{clearance}, R1 = {R1}, R3 = {R3}")
    unit = R1
    r1, r2, r3, hh, hub = 1.0, (R1 + clearance) / unit, R3 / unit, h / unit, 0.2
    if comm.rank == 0:
        start_model("bearing")
        occ = gmsh.model.occ

        def annulus(disc_out, disc_in):
            """The annulus between two radii (its half x ≥ 0 unless `full`)."""
            ring = occ.cut([(2, occ.addDisk(0, 0, 0, disc_out, disc_out))],
                           [(2, occ.addDisk(0, 0, 0, disc_in, disc_in))])[0]
            if full:
                return ring
            return occ.intersect(ring, [(2, occ.addRectangle(0, -r3, 0, r3, 2 * r3))])[0]

        shaft, housing = annulus(r1, hub), annulus(r3, r2)
        occ.synchronize()

        def name_of(body, c):
            x, _, _ = occ.getCenterOfMass(1, c)
            if abs(x) < TOL and not full:
                return f"{body}_symmetry"
            lo, hi = gmsh.model.getParametrizationBounds(1, c)
            px, py, _ = gmsh.model.getValue(1, c, [0.5 * (lo[0] + hi[0])])
            r = (px * px + py * py) ** 0.5
            if body == "shaft":
                return "hub" if abs(r - hub) < 1e-3 else "shaft_surface"
            return "bore" if abs(r - r2) < 1e-3 else "housing_outer"

        groups = _name_groups({"shaft": shaft[0], "housing": housing[0]}, BEARING_TAGS,
                              name_of)
        field = gmsh.model.mesh.field
        near = threshold_field(hh, 2 * hh, hh + growth * r3, r3,
                               curves=groups["shaft_surface"] + groups["bore"])
        lower = field.add("MathEval")  # fine within 60° of the lowest points only
        field.setString(lower, "F", f"{hh} + {growth} * max(y + 0.5, 0)")
        coarser = field.add("Max")
        field.setNumbers(coarser, "FieldsList", [near, lower])
        size_by_field(coarser)
        gmsh.model.mesh.generate(2)
    return distributed(comm, unit)


BALL_TAGS = ("upper_contact", "upper_top", "upper_symmetry_x", "upper_symmetry_y",
             "lower_contact", "lower_bottom", "lower_symmetry_x", "lower_symmetry_y",
             "lower_side")


def ball_on_block(comm: MPI.Comm, R: float, a: float, *, block: float = 4.0,
                  fine: float = 5.0, growth: float = 0.2, half: bool = False
                  ) -> gmshio.MeshData:
    """A ball on a block in 3D, the quarter x ≥ 0, y ≥ 0 (or the half y ≥ 0).

    The lower half of the ball of radius R centred at (0, 0, R), on the block
    [0, L]² × [−L, 0] (L = `block` R; half: [−L, L] × [0, L] × [−L, 0]). They touch at
    the origin and share no node. Tetrahedra of a/`fine` within 1.5 a of the origin,
    growing by `growth` per unit distance.

    Args:
        comm: the communicator.
        R: the ball's radius.
        a: the contact radius the mesh is made for.
        block: the block's size in R.
        fine: a/h near the origin.
        growth: the elements' growth per unit distance beyond 1.5 a.
        half: the half y ≥ 0 (a tangential load along x keeps its symmetry) instead of
            the quarter.

    Returns:
        The mesh with its cell tags (``upper`` 1, ``lower`` 2) and facet tags
        (`BALL_TAGS`: each body's symmetry planes x = 0 and y = 0, the ball's curved
        surface and equator, the block's top, bottom and outer sides).
    """
    unit = a  # gmsh's tolerances are absolute: it works in units of a
    r, L = R / unit, block * R / unit
    if comm.rank == 0:
        start_model("ball_on_block")
        occ = gmsh.model.occ
        x0 = -1.0 if half else 0.0  # the boxes' lower x, in their sizes
        ball = occ.intersect([(3, occ.addSphere(0, 0, r, r))],
                             [(3, occ.addBox(x0 * r, 0, 0, (1 - x0) * r, r, r))])[0]
        lower = [(3, occ.addBox(x0 * L, 0, -L, (1 - x0) * L, L, L))]
        occ.synchronize()

        def name_of(body, f):
            x, y, z = occ.getCenterOfMass(2, f)
            if abs(y) < TOL:
                return f"{body}_symmetry_y"
            if abs(x) < TOL and not half:
                return f"{body}_symmetry_x"
            if body == "upper":
                return "upper_top" if gmsh.model.getType(2, f) == "Plane" else "upper_contact"
            return "lower_contact" if abs(z) < TOL else "lower_bottom" \
                if abs(z + L) < TOL else "lower_side"

        _name_groups({"upper": ball[0], "lower": lower[0]}, BALL_TAGS, name_of)
        _graded_size_field(1.0 / fine, 1.5, 1.0 / fine + growth * L, L)
        gmsh.model.mesh.generate(3)
    return distributed(comm, unit, dim=3)


PIN_TAGS = ("pin_face", "pin_top", "pin_sides", "flat_top", "flat_bottom", "flat_sides")


def pin_on_flat(comm: MPI.Comm, width: float, height: float, h: float,
                flat: float = 4.0, growth: float = 0.2) -> gmshio.MeshData:
    """A flat pin [−w/2, w/2] × [0, height] on a flat [−L, L] × [−L, 0] (plane strain).

    Args:
        comm: the communicator.
        width: the pin's width w.
        height: its height.
        h: the element size along the pin's face and under it.
        flat: the flat's half-width and depth L, in pin widths.
        growth: the elements' growth per unit distance from the pin's face.

    Returns:
        The mesh with its cell tags (``pin`` 1, ``flat`` 2) and facet tags (`PIN_TAGS`).
    """
    unit = width
    w, H, L, hh = 1.0, height / unit, flat, h / unit
    if comm.rank == 0:
        start_model("pin_on_flat")
        occ = gmsh.model.occ
        pin = occ.addRectangle(-w / 2, 0, 0, w, H)
        base = occ.addRectangle(-L, -L, 0, 2 * L, L)
        occ.synchronize()

        def name_of(body, c):
            _, y, _ = occ.getCenterOfMass(1, c)
            if body == "pin":
                return "pin_face" if abs(y) < TOL else "pin_top" if abs(y - H) < TOL \
                    else "pin_sides"
            return "flat_top" if abs(y) < TOL else "flat_bottom" if abs(y + L) < TOL \
                else "flat_sides"

        groups = _name_groups({"pin": (2, pin), "flat": (2, base)}, PIN_TAGS, name_of)
        size_by_field(threshold_field(hh, 0.05, hh + growth * L, L,
                                      curves=groups["pin_face"], sampling=200))
        gmsh.model.mesh.generate(2)
    return distributed(comm, unit)
