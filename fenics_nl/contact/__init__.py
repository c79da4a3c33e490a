"""Frictionless unilateral contact: the surface, the active-set loop, its formulations and peers."""
