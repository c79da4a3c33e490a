"""What is left of the scenes: bodies and solvers that some demos still hand their residual to.

Being dissolved (issue 56): the punch, bracket, buckling beam and snap-through demos write
their mesh, space, conditions, residual and solver themselves. Left: `punch` (the frictional,
J2 and identification punches), `beam` (linear buckling, the path and its stability, on the
pieces the buckling demo writes), `vessel` (thick sphere and cylinder in J2), `upsetting`,
the damage and crack scenes, `truss` (von Mises truss, for the scalar orders), and the
pictures of their demos.
"""
