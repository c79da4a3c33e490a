"""Meshes, their checks, and boundary conditions and reactions."""
