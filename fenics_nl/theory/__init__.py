"""Closed forms to validate against: Hertz, Euler and the elastica."""
