"""Write the bracket of `fenics_nl.domain.bracket` (dimensions in mm) to a .msh file.

python meshes/bracket.py --size 4 -o bracket.msh
"""

import argparse

import gmsh

from fenics_nl.domain.bracket import build


def main():
    """Write the bracket mesh to a .msh file."""
    ap = argparse.ArgumentParser(description=__doc__ + build.__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--size", type=float, default=5.0, help="largest element size [mm]")
    ap.add_argument("-o", "--output", default="bracket.msh", help="mesh file to write")
    args = ap.parse_args()
    gmsh.initialize()
    build(args.size)
    gmsh.write(args.output)
    print(f"wrote {args.output}: {len(gmsh.model.mesh.getNodes()[0])} nodes")
    gmsh.finalize()


if __name__ == "__main__":
    main()
