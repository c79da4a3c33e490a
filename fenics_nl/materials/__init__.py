"""Materials as free energies, and the strain measures they are written in."""
