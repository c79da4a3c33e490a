"""Meshes and what is written on them.

Meshes with their tags (`meshes` by gmsh; `bracket`, `strips`, `axisymmetric`,
`damage_specimens`, `graded_grid`), their checks (`mesh_check`), boundary conditions and
reactions (`boundary`), and point values of fields (`probes`).
"""
