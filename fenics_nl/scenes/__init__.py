"""The scenes, composed from the pieces above: each a body and the solver of a residual on it.

`punch` (Hertz contact, friction, indentation), `bracket` (the 3D gmsh part; its geometry in
`bracket_geometry`), `beam` (the buckling cantilever in finite strain), `arch` (the shallow
arch's snap-through), `vessel` (thick sphere and cylinder in J2), `truss` (von Mises truss,
for the scalar orders).
"""
