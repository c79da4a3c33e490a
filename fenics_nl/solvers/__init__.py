"""The solver core: Newton variants on KSP, SNES peers, load stepping, SLEPc eigenproblems."""
