"""The library's run-time error family.

`SolveError` is the base of every failure a user can meet while solving (no convergence,
a load that cannot be reached, an active set that cycles): a demo reports it in one line.
Bad parameters are `ValueError`. Anything else is a bug and keeps its traceback.
"""


class SolveError(RuntimeError):
    """A solve failed: the problem as posed could not be solved by the chosen method."""
