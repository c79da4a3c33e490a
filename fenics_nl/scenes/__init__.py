"""The scenes, composed from the pieces above: punch, buckling beam, bracket."""
