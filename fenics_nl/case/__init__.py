"""Case files: a problem as data (a gmsh mesh and a TOML file), run without code."""
