"""The library's run-time error family.

`SolveError` is the base of every failure a user can meet while solving (no convergence,
a load that cannot be reached, an active set that cycles): a demo reports it in one line.
Bad parameters are `ValueError`. Anything else is a bug and keeps its traceback.
"""


class SolveError(RuntimeError):
    """A solve failed: the problem as posed could not be solved by the chosen method.

    `result` (a `fenics_nl.solvers.result.SolveResult`, or None) holds what was done up to the
    failure: iterations, work counts, residual history.
    """

    def __init__(self, message: str, result=None):
        super().__init__(message)
        self.result = result
