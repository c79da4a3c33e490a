"""A body drawn deformed and coloured by a field, with pyvista, from meshes gathered on rank 0.

`bracket_picture` (the 3D part, its supports and load) and `deformed_picture` (any 2D or 3D
body, a contact status and an obstacle if given) take DOLFINx Functions and plain values.
"""

from __future__ import annotations

import numpy as np
from dolfinx import fem

from fenics_nl.io.output import gather_grid, owned_cell_values, vertex_interpolant
from fenics_nl.parallel import gather_rows
from fenics_nl.plots.figures import off_screen

__all__ = ["bracket_picture", "deformed_picture", "facet_points"]


def facet_points(msh, facets: np.ndarray) -> np.ndarray:
    """Coordinates of the vertices of this rank's `facets`."""
    from dolfinx import mesh as dmesh

    fdim = msh.topology.dim - 1
    msh.topology.create_connectivity(fdim, 0)
    nodes = dmesh.entities_to_geometry(msh, fdim, facets)
    return msh.geometry.x[np.unique(nodes.ravel())]


def bracket_picture(u: fem.Function, field: fem.Function, path: str, *,
                    clamped: np.ndarray, loaded: np.ndarray, load_motion: np.ndarray,
                    units: str, force: float, support: str,
                    floor: tuple[np.ndarray, np.ndarray] | None = None,
                    label: str | None = None, unloaded: bool = False) -> None:
    """The deformed bracket in two views, coloured by a cell field (σ_eq by default).

    Args:
        u: the displacement.
        field: a cell field (DG0), clipped at its 99th percentile (said so).
        path: the picture (rank 0 writes it).
        clamped: the facets of the clamped bolt holes.
        loaded: the facets of the loaded hole.
        load_motion: the loaded hole's mean displacement (the arrow starts there).
        units: the length unit, for the labels.
        force: the load, for its label.
        support: ``clamped`` or ``contact``, for the title.
        floor: with a floor, this rank's owned base nodes: their coordinates and contact
            status (True: in contact); a third view from below shows them.
        label: the field's name.
        unloaded: the load was removed (the shape is the permanent one).

    Collective.
    """
    bar_title = label or f"von Mises stress [N/{units}²]"
    msh = u.function_space.mesh
    comm = msh.comm
    u1 = vertex_interpolant(u)
    grid = gather_grid(u1.function_space, {"u": u1}, {"vm": owned_cell_values(field)})
    bolts = gather_rows(comm, facet_points(msh, clamped))
    load = gather_rows(comm, facet_points(msh, loaded))
    status = gather_rows(comm, *floor) if floor is not None else None
    if comm.rank != 0:
        return
    pv = off_screen()
    mesh = grid.pyvista()
    size = np.ptp(grid.points, axis=0).max()
    u_max = np.abs(grid.point_data["u"]).max()
    scale = max(1.0, 0.05 * size / max(u_max, 1e-300))  # the largest motion ≥ 5 % of the part
    warped = mesh.warp_by_vector("u", factor=scale)
    vm_cells = grid.cell_data["vm"]
    top = float(np.percentile(vm_cells, 99)) or 1.0  # a zero field (nothing yielded) too
    views = [((1.0, -1.6, 0.9), "view from the front"), ((0.0, -1.0, 0.0), "side view (along y)")]
    if status is not None:
        views.append(((0.0, 0.0, -1.0),
                      "from below: base nodes in contact (blue), lifted off (orange)"))
    pl = pv.Plotter(off_screen=True, shape=(1, len(views)),
                    window_size=(800 * len(views), 750), border=False)
    for i, (direction, label) in enumerate(views):
        pl.subplot(0, i)
        if i == 2:
            _contact_status_view(pl, pv, warped, status, size)
        else:
            pl.add_mesh(mesh, style="wireframe", color="gray", opacity=0.08)
            pl.add_mesh(warped, scalars="vm", cmap="turbo", clim=(0, top), show_edges=False,
                        show_scalar_bar=i == 1, scalar_bar_args={
                            "title": f"{bar_title}\n(colours clipped at the "
                                     f"99th percentile; max {vm_cells.max():.4g})",
                            "vertical": False, "position_x": 0.15, "position_y": 0.04,
                            "width": 0.7, "height": 0.08, "title_font_size": 14,
                            "label_font_size": 12, "fmt": "%.3g"})
            centre = load[0].mean(axis=0) + scale * load_motion  # on the deformed hole
            # the pull on the hole, drawn from the hole along +x (seen past the arm)
            pl.add_arrows(centre[None, :], np.array([[1.0, 0, 0]]), mag=0.3 * size,
                          color="lightgray" if unloaded else "red")
            pl.add_point_labels([centre + np.array([0.15, 0.0, 0.05]) * size],
                                [f"F = {force / 1e3:.3g} kN" + (" (removed)" if unloaded
                                                                 else "")], font_size=16,
                                text_color="gray" if unloaded else "red",
                                shape=None, show_points=False)
            pl.add_points(bolts[0], color="black", point_size=6, render_points_as_spheres=True)
            if status is not None:
                lo, hi = grid.points.min(axis=0), grid.points.max(axis=0)
                pl.add_mesh(pv.Plane(center=((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, 0.0),
                                     i_size=1.3 * (hi[0] - lo[0]), j_size=1.3 * (hi[1] - lo[1])),
                            color="tan", opacity=0.5)
        pl.view_vector(direction)
        pl.add_axes(line_width=3, labels_off=False)  # which way is x, y, z in each view
        if i == 0:
            state = (f"unloaded from F = {force / 1e3:.3g} kN: permanent load-point "
                     f"displacement" if unloaded else
                     f"F = {force / 1e3:.3g} kN: load-point displacement")
            label = (f"bracket, {support} support, {state} "
                     f"{np.linalg.norm(load_motion):.3g} {units}\n{label}")
        pl.add_text(label, font_size=12 if i == 0 else 10, position="upper_left")
    pl.subplot(0, 0)
    legend = (f"deformed x{scale:.3g} (grey: undeformed); black: clamped bolt holes"
              + ("; floor: base nodes in contact blue, lifted off orange"
                 if status is not None else ""))
    pl.add_text(legend, font_size=10, position="lower_left")
    pl.screenshot(path)
    pl.close()


def _contact_status_view(pl, pv, warped, status, size) -> None:
    """The base seen from below, each floor-contact node marked in contact or lifted off."""
    x, active = status
    pl.add_mesh(warped, color="lightgray")
    for on, colour in ((True, "blue"), (False, "orange")):
        if np.any(active == on):
            pl.add_points(x[active == on] - [0, 0, 0.01 * size], color=colour, point_size=8,
                          render_points_as_spheres=True)


def deformed_picture(u: fem.Function, vm: fem.Function, path: str, title: str,
                     marked: dict[str, np.ndarray] | None = None,
                     arrows: dict[str, np.ndarray] | None = None,
                     focus: np.ndarray | None = None, obstacle: dict | None = None,
                     label: str = "von Mises stress", labels: dict | None = None,
                     detail: bool = False, curves: dict | None = None,
                     axes: tuple[str, str] | None = None, true_scale: bool = False) -> None:
    """The deformed body (2D or 3D) coloured by σ_eq (or the `label`led cell field `vm`).

    `marked`: name → this rank's points to draw (e.g. the nodes of each support group);
    `arrows`: name → (this rank's points of a loaded group, the load's direction);
    `focus`: this rank's points of what the picture is about (the nodes in contact, at
    their deformed positions): the view is cut to a box 2.5 times their extent around
    them, and they are drawn. `obstacle`: a rigid sphere (center, radius) or plane (point,
    normal) at its current position, drawn; the body is then drawn at true scale, since
    a magnified displacement would pass through the obstacle. `labels`: text → a point
    (the same on every rank), written there (a probe and its value). `detail`: when the
    cell of the largest value is a small feature (smaller than 3 % of the body: a hole, a
    notch), a second view beside the first zooms on it. `curves`: name → points of a line
    in the undeformed body (a closed form's boundary, the same on every rank), drawn where
    the deformation takes them. `axes`: a 2D body's axis titles (e.g. "r (length)",
    "z (length)"), drawn with their ticks.
    The displacement is magnified until the largest motion is 5 % of the body (said in
    the picture), unless `true_scale` (bodies in contact with each other: a magnified
    motion would pass one through the other) or an obstacle. Collective; rank 0 writes
    `path`.
    """
    comm = u.function_space.mesh.comm
    u1 = vertex_interpolant(u)
    grid = gather_grid(u1.function_space, {"u": u1}, {"vm": owned_cell_values(vm)})
    points = {k: gather_rows(comm, v) for k, v in (marked or {}).items()}
    loads = {k: (gather_rows(comm, x), d) for k, (x, d) in (arrows or {}).items()}
    focus = gather_rows(comm, focus) if focus is not None else None
    if comm.rank != 0:
        return
    pv = off_screen()
    mesh = grid.pyvista()
    disp = grid.point_data["u"]
    if disp.shape[1] == 2:  # a 2D body lies in z = 0
        disp = np.hstack([disp, np.zeros((len(disp), 1))])
    mesh.point_data["u"] = disp
    size = np.ptp(grid.points, axis=0).max()
    if focus is not None and len(focus[0]):
        pts = _as_3d(focus[0])
        half = 1.25 * (np.ptp(pts, axis=0).max() or 0.01 * size)  # one node: 1 % of the body
        lo, hi = pts.min(axis=0) - half, pts.max(axis=0) + half
        mesh = mesh.clip_box([lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]], invert=False)
        disp = mesh.point_data["u"]
        size = np.ptp(mesh.points, axis=0).max()

        def inside(rows):
            x = _as_3d(rows[0])
            return [x[np.all((x >= lo) & (x <= hi), axis=1)]]

        points = {k: inside(v) for k, v in points.items()}
        loads = {k: (inside(x), d) for k, (x, d) in loads.items()}
    u_max = np.linalg.norm(disp, axis=1).max()
    scale = 1.0 if obstacle or true_scale else max(1.0, 0.05 * size / max(u_max, 1e-300))
    warped = mesh.warp_by_vector("u", factor=scale)
    flat = bool(np.ptp(grid.points[:, 2]) == 0)
    zoom = _small_peak(mesh, warped, size) if detail else None
    pl = pv.Plotter(off_screen=True, window_size=(1700 if zoom else 1100, 850),
                    shape=(1, 2) if zoom else (1, 1))
    for view in range(2 if zoom else 1):
        pl.subplot(0, view)
        _draw_body(pl, mesh, warped, flat, size, label, bar=view == 0)
        if labels:
            pts = np.array([_as_3d(np.asarray(x, dtype=float)[None, :])[0] for x in
                            labels.values()])
            moved = pts + scale * np.array([_displacement_at(warped, mesh, x) for x in pts])
            pl.add_point_labels(moved, list(labels), point_size=9, font_size=12,
                                point_color="black", text_color="black",
                                render_points_as_spheres=True, always_visible=True)
        if view == 1:
            pl.add_text("zoom on the largest value", font_size=10, position="upper_left")
            if flat:
                pl.view_xy()
            else:
                pl.view_vector((1.0, -1.6, 0.9))
            pl.reset_camera(bounds=zoom)
    pl.subplot(0, 0)
    colours = ["black", "magenta", "blue", "orange", "green", "brown"]
    legend = []
    for (name, rows), colour in zip(points.items(), colours * 4, strict=False):
        pts = _as_3d(rows[0])
        if len(pts):
            pl.add_points(pts, color=colour, point_size=7, render_points_as_spheres=True)
            legend.append(f"{colour} dots: {name}")
    for name, (rows, direction) in loads.items():
        pts = _as_3d(rows[0])
        if len(pts):  # from the group's centre, along the load
            d = _as_3d(np.asarray(direction, dtype=float)[None, :])[0]
            pl.add_arrows(pts.mean(axis=0)[None, :], d[None, :],
                          mag=0.25 * size / np.linalg.norm(d), color="red")
            legend.append(f"red arrow: {name}")
    for (name, line), colour in zip((curves or {}).items(), ["white", "black"] * 4,
                                    strict=False):
        pts = _as_3d(np.asarray(line, dtype=float))
        moved = pv.PolyData(pts).sample(mesh)  # the displacement there, interpolated
        pl.add_lines(pts + scale * moved.point_data["u"], color=colour, width=3,
                     connected=True)
        legend.append(f"{colour} line: {name}")
    if focus is not None and len(focus[0]):
        pl.add_points(_as_3d(focus[0]), color="white", point_size=8,
                      render_points_as_spheres=True)
        legend.append("white dots: nodes in contact")
    if obstacle:
        _draw_obstacle(pl, pv, obstacle, flat, warped.bounds)  # the body as drawn
        legend.append(f"red: the rigid {obstacle['obstacle']}")
    if legend:
        pl.add_text("\n".join(legend), font_size=10, position="upper_right")
    if flat and axes:
        both = np.array([mesh.bounds, warped.bounds])  # the outline's and the body's
        box = [0.0 if abs(v) < 1e-9 * size else float(v) for v in  # no round-off at 0
               np.ravel([both[:, ::2].min(axis=0), both[:, 1::2].max(axis=0)], order="F")]
        pl.show_bounds(bounds=box, xtitle=axes[0], ytitle=axes[1],
                       show_zaxis=False, show_zlabels=False, location="outer", font_size=12,
                       color="black", n_xlabels=5, n_ylabels=5, fmt="%.3g")
    if flat:
        pl.view_xy()
    else:
        pl.view_vector((1.0, -1.6, 0.9))
    if flat and axes:  # the body up a little and smaller: its axes' titles above the bar
        cam = pl.camera
        shift = np.array([0.0, 0.12 * (box[3] - box[2]), 0.0])
        cam.focal_point = np.array(cam.focal_point) - shift
        cam.position = np.array(cam.position) - shift
        cam.zoom(0.85)
    pl.add_text(f"{title}\ndeformed x{scale:.3g} (grey: undeformed); largest displacement "
                f"{u_max:.3g}", font_size=11, position="upper_left")
    pl.screenshot(path)
    pl.close()


def _draw_body(pl, mesh, warped, flat: bool, size: float, label: str, bar: bool) -> None:
    """The undeformed outline (2D) or wireframe (3D) and the deformed body, coloured."""
    if flat:  # the undeformed outline; cell edges only while they do not hide the colours
        # (clean: the gathered mesh repeats the nodes of partition interfaces)
        merged = mesh.clean(tolerance=1e-9 * size)
        outline = merged.extract_feature_edges(boundary_edges=True, feature_edges=False,
                                               manifold_edges=False, non_manifold_edges=False)
        pl.add_mesh(outline, color="gray", line_width=1.5)
    else:
        pl.add_mesh(mesh, style="wireframe", color="gray", opacity=0.25)
    pl.add_mesh(warped.copy(), scalars="vm", cmap="turbo",
                show_edges=flat and mesh.n_cells < 3000, edge_color="white", line_width=0.2,
                show_scalar_bar=bar, scalar_bar_args={
                    "title": label, "vertical": False, "position_x": 0.2,
                    "position_y": 0.03, "width": 0.6, "fmt": "%.3g"})


def _small_peak(mesh, warped, size: float):
    """Bounds of a box around the cell of the largest value, if that cell is small.

    Its size is read on the undeformed mesh (a magnified motion stretches cells), its
    centre on the deformed one (where the picture shows it).
    """
    k = int(np.argmax(warped.cell_data["vm"]))
    extent = np.ptp(mesh.extract_cells([k]).points, axis=0).max()
    if extent >= 0.03 * size:
        return None
    c = warped.extract_cells([k]).points.mean(axis=0)
    half = 12 * extent
    return [c[0] - half, c[0] + half, c[1] - half, c[1] + half, c[2] - half, c[2] + half]


def _displacement_at(warped, mesh, x: np.ndarray) -> np.ndarray:
    """The displacement of the node of `mesh` nearest to x (to place a label)."""
    return mesh.point_data["u"][mesh.find_closest_point(x)]


def _as_3d(points: np.ndarray) -> np.ndarray:
    """(n, 2) points in the plane z = 0 as (n, 3); (n, 3) unchanged."""
    return np.hstack([points, np.zeros((len(points), 3 - points.shape[1]))])


def _draw_obstacle(pl, pv, ob: dict, flat: bool, bounds) -> None:
    """A rigid sphere or plane, within the picture's bounds (a circle or a line in 2D)."""
    lo, hi = np.array(bounds[::2]), np.array(bounds[1::2])
    span = float(np.max(hi - lo))
    if ob["obstacle"] == "sphere":
        c = _as_3d(np.asarray(ob["center"], dtype=float)[None, :])[0]
        if flat:  # the arc within the picture
            t = np.linspace(0, 2 * np.pi, 4001)
            ring = c + ob["radius"] * np.stack([np.cos(t), np.sin(t), 0 * t], axis=1)
            near = np.all((ring >= lo - 0.1 * span) & (ring <= hi + 0.1 * span), axis=1)
            if near.sum() > 1:
                pl.add_mesh(pv.lines_from_points(ring[near]), color="red", line_width=3)
        else:
            pl.add_mesh(pv.Sphere(radius=ob["radius"], center=c, theta_resolution=60,
                                  phi_resolution=60), color="red", opacity=0.35)
        return
    p0 = _as_3d(np.asarray(ob["point"], dtype=float)[None, :])[0]
    n = _as_3d(np.asarray(ob["normal"], dtype=float)[None, :])[0]
    n /= np.linalg.norm(n)
    if flat:  # across the body's width only: a die ends where the body does (the axis)
        d = np.array([-n[1], n[0], 0.0])
        corners = [np.array([x, y, 0.0]) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])]
        ends = [float((x - p0) @ d) for x in corners]  # the box's extent along the line
        pl.add_mesh(pv.Line(p0 + min(ends) * d, p0 + max(ends) * d), color="red",
                    line_width=3)
    else:
        pl.add_mesh(pv.Plane(center=p0, direction=n, i_size=2 * span, j_size=2 * span),
                    color="red", opacity=0.35)
