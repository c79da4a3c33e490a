"""Pictures: functions that take DOLFINx objects and plain values and write a PNG.

Each module draws one kind of result for the demos that compute it; none reads a
command-line namespace.
"""
