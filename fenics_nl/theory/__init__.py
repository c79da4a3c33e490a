"""Closed forms to validate against, each from its source.

`hertz` (sphere and cylinder contact), `mindlin` (Cattaneo–Mindlin partial slip),
`elastica` (Euler's load and the post-buckling elastica), `vessels` (thick sphere and
cylinder in perfect plasticity), `truss` (von Mises truss), `arch` (shallow arch,
Fung–Kaplan).
"""
