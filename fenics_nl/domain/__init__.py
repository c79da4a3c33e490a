"""Meshes and what is written on them.

Meshes (`meshes`, gmsh), their checks (`mesh_check`), boundary conditions and reactions
(`boundary`), and point values of fields (`probes`).
"""
