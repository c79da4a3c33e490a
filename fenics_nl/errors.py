"""The library's run-time error family.

`SolveError` is the base of every failure a user can meet while solving (no convergence,
a load that cannot be reached, an active set that cycles): a demo reports it in one line.
Bad parameters are `ValueError`, and so is `SupportError` (a body its supports do not hold).
Anything else is a bug and keeps its traceback.
"""


class SolveError(RuntimeError):
    """A solve failed: the problem as posed could not be solved by the chosen method.

    `result` (a `fenics_nl.solvers.result.SolveResult`, or None) holds what was done up to the
    failure: iterations, work counts, residual history.
    """

    def __init__(self, message: str, result=None):
        super().__init__(message)
        self.result = result


class SupportError(ValueError):
    """The supports leave a rigid-body motion free: the problem as posed has no unique answer.

    Bad input, not a solver failure: a step cut cannot mend it. `motions` names each free
    motion ('translation along y', 'rotation about z through (0, 0)').
    """

    def __init__(self, message: str, motions: list[str] | None = None):
        super().__init__(message)
        self.motions = list(motions or [])
