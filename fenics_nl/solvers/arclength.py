"""Arc-length continuation (Crisfield): the load factor λ is an unknown beside u.

Load control fixes λ and solves R(u, λ) = F_int(u) − λ q = 0 for u; at a limit point (λ at
a maximum) no u exists beyond it and the steps are cut to nothing. Arc-length control adds
one equation, the distance from the last converged state (u_n, λ_n):

    ‖Δu‖²/u_ref² + ψ² Δλ² = Δs²,    Δu = u − u_n,  Δλ = λ − λ_n,

so the path is followed by its length, through limit points and snap-backs. u_ref is the
size of the linear response K₀⁻¹q to the reference load at the start: Δs is dimensionless
(the same in any units) and, on a linear path, about √(1 + ψ²) load increments. ψ = 1 is
Crisfield's spherical arc, ψ = 0 his cylindrical one.

Each corrector iteration is a bordered solve on the tangent K of the chosen Newton variant,
factorized as that variant says (every iteration, once per step, or BFGS-corrected):

    K δu_R = −R,   K δu_q = q,   δu = δu_R + δλ δu_q,

two back-solves and no factorization for the constraint; δλ is a root of the arc's
quadratic, the one whose increment turns least from the current one (Crisfield's rule).

Critical points (`detect`): at each converged state one MUMPS LDLᵀ factorization of the
tangent gives the number of its negative eigenvalues (its inertia) and, by one back-solve,
the path's tangent (K⁻¹q, 1), whose λ-component tells the sense of the load there. Where the
inertia changes, the path crossed a limit point if that sense changed too (the load passed
an extremum), else a bifurcation. Either is bracketed: the step is redone with half the
arc until it is 1/32 of its arc. With `switch`,
the first bifurcation where the count grows is left along its critical mode, the tangent's
eigenvector of its eigenvalue nearest 0 (SLEPc):
the next step starts from u_n + Δs φ at the same λ, and the arc keeps it from falling back.
Nothing of the problem's closed form is used: the size of the kick is the arc length the
path had. Without `detect`, limit points are where Δλ changes sign between steps.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from dolfinx.fem import petsc
from petsc4py import PETSc

from fenics_nl.errors import SolveError
from fenics_nl.solvers.buckling import mode_nearest_zero, unstable_directions
from fenics_nl.solvers.convergence import at_round_off
from fenics_nl.solvers.newton import LinearSolveError, NewtonSolver
from fenics_nl.solvers.result import SolveResult, WorkCounts

__all__ = ["ArcLength", "ArcState", "ContinuationError", "ContinuationPath", "CriticalPoint"]

log = logging.getLogger(__name__)

# eigenvalues of the tangent (on the displacement dofs) above −this fraction of its largest
# diagonal entry count as positive: near a bifurcation point round-off puts them on either
# side, and the inertia would flicker. A critical point is then found later by Δλ/λ ≈
# margin · max diag K / μ₀ (μ₀: the critical mode's eigenvalue at rest). A thin body's
# bending μ₀ falls with the mesh size (the arch's μ₀ ~1e-11 max diag at 106k unknowns): at
# 1e-12 its limit loads were 4.7 % low and 10 % high, at 1e-14 (Δλ/λ ~0.1 %) −1.2 % and
# +2.4 % (the continuum's gap to the closed form grows the same way at 27k). Round-off on
# an LDLᵀ's eigenvalues is c·ε·‖K‖ with c unmeasured here: 1e-14 is ~45 ε, and the beam's
# bifurcation and the arch's tests showed no flicker at it; the window between the two
# closes on still finer thin meshes (a margin scaled to μ₀ would be the cure)
INERTIA_MARGIN = 1e-14
# the iterations a step should take, per variant: fewer and the arc grows, more and it shrinks
DESIRED_ITERATIONS = {"full": 5, "periodic": 8, "bfgs": 12, "modified": 20}


class ContinuationError(SolveError):
    """The path could not be followed to the target; `reached` is the last load factor."""

    def __init__(self, message: str, result=None, *, reached: float = 0.0):
        super().__init__(message, result)
        self.reached = reached


class _StepFailed(Exception):
    """A step did not converge (or turned back): cut the arc and try again."""


class _TurnedBack(_StepFailed):
    """The step went back along the path it came by."""


@dataclass
class CriticalPoint:
    """A limit point or a bifurcation met between two converged steps."""

    kind: str  # "limit" or "bifurcation"
    factor: float  # λ there: a limit point's, the extremum of λ over the last 3 states
    # (without `detect`: the vertex of a parabola through the last 3); a bifurcation's, the
    # middle of the (bracketed) step that crossed it
    step: int  # the first converged step past it
    between: tuple[float, float]  # λ of the converged states either side


@dataclass
class ContinuationPath:
    """Converged states along the arc: load factors, solve results, what was met."""

    factors: list[float] = field(default_factory=list)
    results: list[SolveResult] = field(default_factory=list)
    arc_lengths: list[float] = field(default_factory=list)  # Δs of each converged step
    # negative eigenvalues at each state (with `detect`; the last: at the end of the step that
    # crossed the target, before the landing on it)
    unstable: list[int] = field(default_factory=list)
    critical_points: list[CriticalPoint] = field(default_factory=list)
    switched: bool = False  # left a bifurcation along its mode
    stopped: bool = False  # ended by `run`'s stop condition, not at the target
    failures: int = 0  # steps cut
    bracketing_steps: int = 0  # steps redone shorter to bracket a critical point
    inertia_factorizations: int = 0  # the stability checks' (not in `work`)
    work: WorkCounts = field(default_factory=WorkCounts)

    @property
    def iterations(self) -> int:
        """Corrector iterations summed over converged steps."""
        return sum(r.iterations for r in self.results)


@dataclass
class _Bracket:
    """A critical point being bracketed: the step that crosses it is redone shorter."""

    short: float  # the arc short enough to accept the crossing step
    arc: float  # the arc the path had: it goes on with it
    since: int = 0  # steps accepted since the last halving without meeting it


@dataclass
class _Walk:
    """Where the path is: its last converged state and what the next step needs."""

    lam: float
    ds: float  # the next arc length
    state: PETSc.Vec  # u there
    count: int = 0  # negative eigenvalues of the tangent there
    sense: float = 1.0  # the sign of λ along the path's tangent there
    previous: tuple | None = None  # the last step's (Δu, Δλ)
    last_dlam: float | None = None  # its Δλ (None past a branch switch)
    kick: PETSc.Vec | None = None  # a critical mode to leave along
    tangent: PETSc.Vec | None = None  # K⁻¹q there, from the stability check
    bracket: _Bracket | None = None  # while a critical point is being bracketed

    def destroy(self) -> None:
        """Destroy its vectors (collective)."""
        for v in (self.state, self.previous[0] if self.previous else None, self.kick,
                  self.tangent):
            if v is not None:
                v.destroy()


@dataclass
class _Corrector:
    """What the corrector iterations of one step hold fixed."""

    x0: PETSc.Vec  # u_n, where the step starts
    lam0: float  # λ_n
    q: PETSc.Vec  # the load vector q = −∂R/∂λ
    q_norm: float
    dq: PETSc.Vec | None  # K⁻¹q, renewed with the tangent (None at fixed λ)
    ds: float | None  # the arc (None: at fixed λ, Newton under load control)


@dataclass
class _Increment:
    """A converged increment from (u_n, λ_n), before it is classified."""

    du: PETSc.Vec
    dlam: float
    iterations: int
    ds: float | None  # the arc it used (shortened when aimed at the target)
    aimed: bool = False  # its predictor was aimed at the target


@dataclass
class _Step:
    """A converged step, classified, before it is accepted."""

    du: PETSc.Vec
    dlam: float
    lam: float  # where it ends
    its: int
    work: WorkCounts
    norms: list[float]
    t0: float
    count: int  # negative eigenvalues of the tangent at its end
    sense: float  # the sign of λ along the path's tangent there
    turned: bool  # a limit point inside it
    bifurcation: bool  # a bifurcation inside it
    leave: bool  # ... to be left along its mode
    tangent: PETSc.Vec | None = None  # K⁻¹q at its end (with `detect`)
    landed: bool = False  # it ends on the target


@dataclass
class ArcState:
    """Where an arc-length path stands after a converged step: enough to go on exactly.

    The walk (λ, the next arc, the tangent's inertia and sense there, the last increment, a
    critical point being bracketed), the method's scales (u_ref, the round-off scale), and
    the path so far. A checkpoint saves it (`scalars()` as JSON, `arrays()` per rank: a
    restart needs the same partition); `ArcLength.run(resume=...)` goes on from it, with
    u back in the solver.
    """

    lam: float
    ds: float
    count: int
    sense: float
    start: float  # λ where the path began
    sense0: float  # the first step's sense of λ
    scale: float | None  # 1/u_ref²
    largest: float
    last_dlam: float | None
    previous_dlam: float | None  # with previous_du: the last step's (Δu, Δλ)
    bracket: tuple[float, float, int] | None
    path: dict  # ContinuationPath's record (`_path_record`)
    previous_du: np.ndarray | None = None
    tangent: np.ndarray | None = None
    kick: np.ndarray | None = None

    VECTORS = ("previous_du", "tangent", "kick")

    def scalars(self) -> dict:
        """Everything but the vectors, JSON-able.

        Returns:
            Every field but those of `VECTORS`, by name.
        """
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)
                if f.name not in self.VECTORS}

    def arrays(self) -> dict[str, np.ndarray]:
        """This rank's vectors (those the walk has).

        Returns:
            The arrays of `VECTORS` that are not None, by name (the fields themselves).
        """
        return {k: getattr(self, k) for k in self.VECTORS if getattr(self, k) is not None}

    @classmethod
    def saved(cls, scalars: dict, arrays: dict[str, np.ndarray]) -> ArcState:
        """The state from `scalars()` and `arrays()` read back.

        Args:
            scalars: what `scalars()` gave (e.g. read back from JSON).
            arrays: what `arrays()` gave on this rank (a vector the walk had not is absent).

        Returns:
            The state, for `ArcLength.run(resume=...)`.
        """
        bracket = scalars["bracket"]
        return cls(**{**scalars, "bracket": tuple(bracket) if bracket else None},
                   **{k: arrays.get(k) for k in cls.VECTORS})


def _path_record(path: ContinuationPath) -> dict:
    """What a restart needs of the path so far (its steps' iterations, not their norms)."""
    return {"factors": path.factors, "iterations": [r.iterations for r in path.results],
            "arc_lengths": path.arc_lengths, "unstable": path.unstable,
            "critical_points": [dataclasses.asdict(c) for c in path.critical_points],
            "switched": path.switched, "failures": path.failures,
            "bracketing_steps": path.bracketing_steps,
            "inertia_factorizations": path.inertia_factorizations,
            "work": dataclasses.asdict(path.work)}


def _path_from(record: dict) -> ContinuationPath:
    return ContinuationPath(
        factors=list(record["factors"]),
        results=[SolveResult.restored(its) for its in record["iterations"]],
        arc_lengths=list(record["arc_lengths"]), unstable=list(record["unstable"]),
        critical_points=[CriticalPoint(c["kind"], c["factor"], c["step"], tuple(c["between"]))
                         for c in record["critical_points"]],
        switched=record["switched"], failures=record["failures"],
        bracketing_steps=record["bracketing_steps"],
        inertia_factorizations=record["inertia_factorizations"],
        work=WorkCounts(**record["work"]))


class ArcLength:
    """Crisfield's arc-length method on the Newton family of a `NewtonSolver`.

    Args:
        solver: the Newton solver of R(u, λ) (its variant, tangent policy, linear solver and
            tolerances are used; Dirichlet values must not depend on λ). A step has
            converged when ‖R‖ ≤ max(rtol ‖R₀‖, atol ‖q‖) (the reference load's ‖q‖), or
            when ‖R‖ stopped falling at the round-off of a nearly singular tangent.
        set_load: sets λ in the residual (as for `solve_incrementally`); R must be affine in
            λ: q = R(u, λ) − R(u, λ + 1), taken at the start of each step (exact for dead
            loads).
        arc_length: the first step's Δs (dimensionless, see the module), > 0.
        psi: weight of λ in the arc: 1 spherical, 0 cylindrical.
        min_arc_length, max_arc_length: bounds of the adaptive Δs (default Δs/1e4 and no
            bound); below the minimum the run stops with ContinuationError.
        desired_iterations: corrector iterations a step should take (per variant by default).
        detect: count the tangent's negative eigenvalues at each state (one LDLᵀ each).
        switch: leave the first bifurcation along its critical mode (needs `detect`).
        metric_dofs: local indices of the dofs the arc measures (default all): a mixed
            unknown gives its displacement's, so that a pressure's units do not count.
        mass: the stability eigenproblem's metric M in K φ = μ M φ (default the identity).
        multipliers: negative eigenvalues a saddle-point tangent always has (its pressure
            or multiplier dofs), not counted as unstable directions.
        prefix: PETSc options prefix of the stability checks.
        commit, restore: hooks after a converged step and after a cut (internal variables).
    """

    def __init__(self, solver: NewtonSolver, set_load: Callable[[float], None], *,
                 arc_length: float = 0.1, psi: float = 1.0,
                 min_arc_length: float | None = None, max_arc_length: float | None = None,
                 desired_iterations: int | None = None, detect: bool = True,
                 switch: bool = False, metric_dofs: np.ndarray | None = None, mass=None,
                 multipliers: int = 0, prefix: str = "continuation_",
                 commit: Callable[[], None] | None = None,
                 restore: Callable[[], None] | None = None):
        if not (arc_length > 0 and math.isfinite(arc_length)):
            raise ValueError(f"arc length must be a finite number > 0, got {arc_length!r}")
        if not (psi >= 0 and math.isfinite(psi)):
            raise ValueError(f"psi must be >= 0, got {psi!r}")
        if switch and not detect:
            raise ValueError("branch switching needs the stability checks (detect=True)")
        self.solver, self.set_load = solver, set_load
        self.arc_length, self.psi = arc_length, psi
        self.min_arc_length = arc_length * 1e-4 if min_arc_length is None else min_arc_length
        self.max_arc_length = math.inf if max_arc_length is None else max_arc_length
        if not 0 < self.min_arc_length <= arc_length <= self.max_arc_length:
            raise ValueError("arc lengths must satisfy 0 < min <= first <= max, got "
                             f"{self.min_arc_length}, {arc_length}, {self.max_arc_length}")
        self.desired = desired_iterations or DESIRED_ITERATIONS[solver.method]
        self.detect, self.switch = detect, switch
        self.mass, self.multipliers, self.prefix = mass, multipliers, prefix
        self.commit, self.restore = commit, restore
        self.metric_dofs = metric_dofs
        self._weights = None  # during a run: 1 on the metric's dofs, 0 elsewhere
        self._scale = None  # 1/u_ref², set on the first predictor
        self._q = None  # the load vector q = −∂R/∂λ of the current step
        self._largest = 0.0  # the largest first residual of a step: round-off's scale
        self._sense0 = 1.0  # the first step's sense of λ (towards the target)
        self._descending = False  # the target counts only when λ falls through it
        # the path `run` follows, as far as it went (read it in `on_step`, or after a
        # ContinuationError: its converged states and critical points stay)
        self.path: ContinuationPath | None = None

    # -- the metric --------------------------------------------------------------------

    def _dot(self, a: PETSc.Vec, b: PETSc.Vec) -> float:
        """a·b over the metric's dofs, times 1/u_ref²."""
        if self._weights is None:
            value = a.dot(b)
        else:
            w = a.copy()
            w.pointwiseMult(w, self._weights)
            value = w.dot(b)
            w.destroy()
        return value * (self._scale or 1.0)

    def _load_vector(self, lam: float, q: PETSc.Vec, work: WorkCounts) -> None:
        """q = R(u, λ) − R(u, λ + 1); leaves R(u, λ) in the solver's residual vector."""
        s = self.solver
        self.set_load(lam + 1.0)
        s.residual(work)
        s.residual_vector.copy(q)
        self.set_load(lam)
        s.residual(work)
        q.aypx(-1.0, s.residual_vector)

    # -- one step ----------------------------------------------------------------------

    def _step(self, lam0: float, ds: float, previous, kick, work: WorkCounts, norms: list,
              target: float | None = None, tangent: PETSc.Vec | None = None) -> _Increment:
        """From the converged (u_n, λ_n) to the next state at arc length ds.

        `previous`: the last step's (Δu, Δλ), for the predictor's sense and the root
        choice; `kick`: a mode to leave along (branch switching); a predictor that passes
        `target` is shortened to end there; `tangent`: K(u_n)⁻¹q if the stability check
        made it: full and periodic Newton, which build a new tangent at the first corrector
        iteration, then need no factorization for the predictor (modified Newton and BFGS
        factorize K(u_n) here anyway: it is their tangent for the step). Returns the
        converged increment.
        """
        s = self.solver
        x = s.u.x.petsc_vec
        s.start_solve()
        if self._q is None:
            self._q = x.duplicate()
        q, dq = self._q, x.duplicate()
        self._load_vector(lam0, q, work)
        q_norm = q.norm()
        if q_norm == 0:
            raise ValueError("the load does not depend on the load factor (q = 0)")
        du = x.duplicate()
        x0 = x.copy()
        if kick is not None:
            # along the critical mode, at the same λ; the tangent is taken there, not at
            # u_n, where it is singular along that very mode (a constant tangent would
            # amplify it without bound)
            kick.copy(du)
            du.scale(ds / math.sqrt(self._dot(kick, kick)))
            dlam = 0.0
            x.axpy(1.0, du)
            x.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        if kick is None and tangent is not None and s.method in ("full", "periodic"):
            tangent.copy(dq)  # the corrector's first iteration builds its own tangent
        else:
            s.update_tangent(0, work)
            # an iterative solver's tolerance: a predictor needs a direction (1e-3), but
            # the first one sets the arc's unit of displacement, as LU's would (1e-9)
            s.set_forcing(1e-6 if self._scale is None else 1.0, 1.0)
            s.solve_linear(q, dq, work)
        if self._scale is None:  # u_ref = ‖K₀⁻¹q‖: the arc's unit of displacement
            self._scale = 1.0 / self._dot(dq, dq)
        aimed = False
        if kick is None:  # along the tangent (dq, 1), in the sense of the last step
            sense = self._sense0
            if previous is not None:
                sense = math.copysign(1.0, self._dot(previous[0], dq)
                                      + self.psi**2 * previous[1])
            dlam = sense * ds / math.sqrt(self._dot(dq, dq) + self.psi**2)
            if (target is not None and (target - lam0) * (target - lam0 - dlam) < 0
                    and not (self._descending and dlam > 0)):
                # the predictor passes the target: aim at it, so that the landing is short
                ds *= (target - lam0) / dlam
                dlam, aimed = target - lam0, True
            dq.copy(du)
            du.scale(dlam)
        try:
            increment = self._correct(_Corrector(x0, lam0, q, q_norm, dq, ds), du, dlam,
                                      work, norms)
            increment.aimed = aimed
            return increment
        except _StepFailed:
            self._back_to(x0, lam0)
            du.destroy()
            raise
        finally:
            for v in (dq, x0):
                v.destroy()

    def _correct(self, c: _Corrector, du: PETSc.Vec, dlam: float, work: WorkCounts,
                 norms: list) -> _Increment:
        """Corrector iterations from the predictor (u_n + Δu, λ_n + Δλ) back onto the arc.

        At fixed λ (`c.ds` None) to equilibrium. Returns the converged increment (`du`,
        updated in place), or raises _StepFailed.
        """
        s = self.solver
        bfgs = s.method == "bfgs"
        x = s.u.x.petsc_vec
        c.x0.copy(x)
        x.axpy(1.0, du)
        x.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        self.set_load(c.lam0 + dlam)
        dr = x.duplicate()
        b_old, ddu, ddlam = None, None, 0.0  # the last correction, for a BFGS pair
        on_arc = True  # the predictor is on the arc
        try:
            test = s.convergence
            while True:
                rnorm = s.residual(work)
                b = s.residual_vector
                norms.append(rnorm)
                if b_old is not None:  # y = ΔF_int = ΔR + δλ q, s = δu
                    y = b.copy()
                    y.axpy(-1.0, b_old)
                    y.axpy(ddlam, c.q)
                    s.add_secant_pair(ddu, y)
                    b_old.destroy()
                    b_old = None
                k = len(norms) - 1
                if math.isfinite(norms[0]):
                    self._largest = max(self._largest, norms[0])
                reason = test.reason(norms, c.q_norm)  # F: the reference load's ‖q‖
                if reason in ("nan", "diverged"):
                    raise _StepFailed(f"the corrector diverged: |R| = {rnorm:.3e} at "
                                      f"iteration {k}")
                if on_arc and (reason == "converged" or at_round_off(
                        norms, self._largest, test.threshold(norms[0], c.q_norm))):
                    return _Increment(du, dlam, k, c.ds)
                if k >= test.max_it:  # converged off the arc counts too: no endless loop
                    raise _StepFailed(f"no convergence in {k} iterations (|R| = {rnorm:.3e})")
                s.set_forcing(rnorm, norms[0])  # an iterative solver's tolerance
                if s.update_tangent(k, work):
                    if c.ds is not None:
                        s.solve_linear(c.q, c.dq, work)
                elif bfgs and k > 0 and c.ds is not None:
                    s.solve_linear(c.q, c.dq, work)  # H changed with the last pair
                if bfgs:
                    b_old = b.copy()
                s.solve_linear(b, dr, work)  # the correction's part −K⁻¹R is −dr
                ddlam, on_arc = ((0.0, True) if c.ds is None else
                                 self._root(du, dlam, dr, c.dq, c.ds))
                step = dr.copy()
                step.scale(-1.0)
                if ddlam:
                    step.axpy(ddlam, c.dq)  # δu = −dr + δλ dq
                du.axpy(1.0, step)
                x.axpy(1.0, step)
                # U = g on the Dirichlet dofs exactly, whatever the linear solver's accuracy
                petsc.set_bc(x, s.bcs)
                x.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
                dlam += ddlam
                self.set_load(c.lam0 + dlam)
                if bfgs:
                    ddu = step
                else:
                    step.destroy()
        except LinearSolveError as err:
            raise _StepFailed(str(err)) from None
        finally:
            dr.destroy()
            if b_old is not None:
                b_old.destroy()

    def _root(self, du, dlam, dr, dq, ds) -> tuple[float, bool]:
        """δλ on the arc: the root of its quadratic that turns the increment the least.

        Returns δλ and whether the corrected state is on the arc.
        """
        psi2 = self.psi**2
        v = du.copy()
        v.axpy(-1.0, dr)  # Δu + δu_R
        a = self._dot(dq, dq) + psi2
        b = 2 * (self._dot(v, dq) + psi2 * dlam)
        c = self._dot(v, v) + psi2 * dlam**2 - ds**2
        v_du, dq_du = self._dot(v, du), self._dot(dq, du)
        v.destroy()
        disc = b * b - 4 * a * c
        if disc < 0:  # the linearized path misses the arc (a constant tangent often does):
            return -b / (2 * a), False  # its point nearest the arc; the next iterations
            # return to it
        roots = [(-b + sign * math.sqrt(disc)) / (2 * a) for sign in (1.0, -1.0)]
        turn = [v_du + r * dq_du + psi2 * (dlam + r) * dlam for r in roots]
        return roots[int(np.argmax(turn))], True

    # -- the path ----------------------------------------------------------------------

    def run(self, target: float, max_steps: int = 100, *, start: float = 0.0,
            on_step: Callable[[float, SolveResult], None] | None = None,
            progress: Callable[[str], None] | None = None,
            progress_every: int = 1,
            resume: ArcState | None = None,
            on_state: Callable[[ArcState], None] | None = None,
            descending: bool = False,
            stop: Callable[[], bool] | None = None) -> ContinuationPath:
        """Follow the path from λ = `start` (u converged there) until λ crosses `target`.

        The step that crosses the target is then solved at λ = target exactly (Newton at
        fixed λ, from the nearer of its two ends).

        Args:
            target: the load factor λ to reach.
            max_steps: the converged steps allowed.
            start: λ where the path begins (with `resume`: the state's own start instead).
            on_step: ``on_step(λ, result)`` after each converged step, with its SolveResult.
            progress: ``progress(message)``: a line for every `progress_every`-th converged
                step, and for every event (a limit point, a bifurcation, a cut arc).
            progress_every: how many converged steps between two `progress` lines.
            resume: go on from a state `on_state` gave (u, and the internal variables, back
                in place): the path then takes the steps the uninterrupted run would have
                taken.
            on_state: ``on_state(state)`` after each converged step but the last, with the
                `ArcState` a restart needs.
            descending: the target counts only where λ falls through it (a softening branch
                past its limit point: the way up through the same λ goes on).
            stop: ``stop()``, asked after each converged step (after `on_step`); True ends
                the path there, whatever λ (a condition on the state: a displacement reached
                on a falling branch, where λ alone cannot say which side of the limit point
                the path is on).

        Returns:
            The path followed (also kept in `self.path`), with its converged states,
            critical points and work; `stopped` is set if `stop` ended it.

        Raises:
            ContinuationError: if the target is not crossed within `max_steps` converged
                steps, or if the arc is cut below its minimum (a step that does not
                converge, or turns back onto the path it came along).
        """
        if not math.isfinite(target) or target == start:
            raise ValueError(f"target load factor must be finite and differ from the start "
                             f"{start}, got {target!r}")
        if max_steps < 1:
            raise ValueError(f"max_steps must be >= 1, got {max_steps}")
        say = progress or (lambda message: None)
        self._descending = descending
        if self.metric_dofs is not None:
            x = self.solver.u.x.petsc_vec
            self._weights = x.duplicate()
            self._weights.set(0.0)
            self._weights.array[self.metric_dofs[self.metric_dofs < x.getLocalSize()]] = 1.0
        if resume is None:
            path = self.path = ContinuationPath()
            self.set_load(start)
            self._largest = 0.0
            self._sense0 = math.copysign(1.0, target - start)  # the first step heads for it
            count = self._stability(path)[0] if self.detect else 0
            walk = _Walk(start, self.arc_length, self.solver.u.x.petsc_vec.copy(), count,
                         self._sense0)
        else:
            path, walk, start = _path_from(resume.path), self._walk_from(resume), resume.start
            self.path = path
            self.set_load(walk.lam)
        try:
            while len(path.factors) < max_steps:
                step = self._attempt(walk, path, target, say)
                if step is None:  # cut, or redone shorter to bracket a critical point
                    continue
                result = self._accept(walk, path, step, start, say, progress_every)
                if on_step:
                    on_step(walk.lam, result)
                if step.landed:
                    return path
                if stop is not None and stop():
                    path.stopped = True
                    return path
                self._next_arc(walk, step)
                if on_state:
                    on_state(self._state_of(walk, path, start))
        finally:
            walk.destroy()
            for v in (self._q, self._weights):
                if v is not None:
                    v.destroy()
            self._q = self._weights = None
        raise ContinuationError(f"load factor {target:g} not reached in {max_steps} steps "
                                f"(the path is at λ = {walk.lam:.6g})", reached=walk.lam)

    def _state_of(self, walk: _Walk, path: ContinuationPath, start: float) -> ArcState:
        """The walk after a converged step, and the path so far, as a restart needs them."""
        b = walk.bracket
        return ArcState(
            walk.lam, walk.ds, walk.count, walk.sense, start, self._sense0, self._scale,
            self._largest, walk.last_dlam, walk.previous[1] if walk.previous else None,
            (b.short, b.arc, b.since) if b else None, _path_record(path),
            walk.previous[0].array.copy() if walk.previous else None,
            walk.tangent.array.copy() if walk.tangent is not None else None,
            walk.kick.array.copy() if walk.kick is not None else None)

    def _walk_from(self, state: ArcState) -> _Walk:
        """The walk of a saved state; u is the solver's (restored by the caller)."""
        x = self.solver.u.x.petsc_vec
        self._sense0, self._scale, self._largest = state.sense0, state.scale, state.largest

        def vector(values):
            if values is None:
                return None
            v = x.duplicate()
            v.array[:] = values
            return v

        previous = (None if state.previous_du is None else
                    (vector(state.previous_du), state.previous_dlam))
        return _Walk(state.lam, state.ds, x.copy(), state.count, state.sense, previous,
                     state.last_dlam, vector(state.kick), vector(state.tangent),
                     _Bracket(*state.bracket) if state.bracket else None)

    def _attempt(self, walk: _Walk, path: ContinuationPath, target: float, say
                 ) -> _Step | None:
        """One step from the walk's state, classified; None if it was undone."""
        t0 = time.perf_counter()
        work, norms = WorkCounts(), []
        try:
            increment = self._step(walk.lam, walk.ds, walk.previous, walk.kick, work, norms,
                                   None if walk.bracket else target, walk.tangent)
            du, dlam, its, aimed = (increment.du, increment.dlam, increment.iterations,
                                    increment.aimed)
            walk.ds = increment.ds
            if walk.kick is None and walk.previous is not None and self._turns_back(
                    du, dlam, walk.previous):
                du.destroy()
                self._back_to(walk.state, walk.lam)
                raise _TurnedBack("the step turned back onto the path it came along")
        except _StepFailed as err:
            walk.ds = self._cut(path, work, norms, walk.ds, walk.lam, err, say)
            return None
        count, sense, tangent = (self._stability(path, du, dlam) if self.detect
                                 else (walk.count, walk.sense, None))
        # a change of inertia: a limit point if the path's tangent changed its sense of λ
        # as well, else a bifurcation (a sense that flips with the inertia unchanged is a
        # degenerate tangent's round-off: the symmetric beam's)
        changed = self.detect and walk.kick is None and count != walk.count
        turned = changed and walk.sense * sense < 0
        bifurcation = changed and not turned
        leave = bifurcation and self.switch and not path.switched and count > walk.count
        if changed and self._bracket(walk, path, work, du, turned, say):
            if tangent is not None:
                tangent.destroy()
            return None
        step = _Step(du, dlam, walk.lam + dlam, its, work, norms, t0, count, sense, turned,
                     bifurcation, leave, tangent)
        crosses = (walk.lam - target) * (step.lam - target) <= 0 and not (
            self._descending and step.lam >= walk.lam)
        if walk.kick is None and not leave and (aimed or crosses):
            # the step passes the target, or was aimed at it (the arc's corrector may stop
            # just short of it, and aiming again would shrink the arc without end): solve
            # there (or cut the arc if that fails)
            landing = self._land(target, walk.state, walk.lam, step.lam, work, norms)
            if landing is None:
                for v in (du, tangent):
                    if v is not None:
                        v.destroy()
                self._back_to(walk.state, walk.lam)
                walk.ds = self._cut(path, work, norms, walk.ds, walk.lam, _StepFailed(
                    f"Newton at fixed λ failed at λ = {target:g}"), say)
                return None
            step.its += landing
            step.dlam, step.lam, step.landed = target - walk.lam, target, True
        return step

    def _bracket(self, walk: _Walk, path: ContinuationPath, work: WorkCounts,
                 du: PETSc.Vec, turned: bool, say) -> bool:
        """A critical point inside this step: undo it, halve the arc; whether it was undone.

        The arc is halved until the step that crosses the point is 1/32 of its first arc.
        """
        if walk.bracket is None:
            walk.bracket = _Bracket(walk.ds / 32, walk.ds)
        if walk.ds <= walk.bracket.short:
            return False
        walk.bracket.since = 0
        du.destroy()
        self._back_to(walk.state, walk.lam)
        path.work.add(work)
        path.bracketing_steps += 1
        walk.ds /= 2
        say(f"  {'limit point' if turned else 'bifurcation'} within the step from λ = "
            f"{walk.lam:.6g}: bracketing it, arc {walk.ds:.3g}")
        return True

    def _accept(self, walk: _Walk, path: ContinuationPath, step: _Step, start: float,
                say, every: int) -> SolveResult:
        """Record a converged step and the critical point it crossed; move the walk on.

        `say` its line if it is an `every`-th step (or switched branch), and every event.
        """
        if self.commit:
            self.commit()
        between = (walk.lam, step.lam)
        walk.lam = step.lam
        switched = walk.kick is not None
        if switched:
            walk.kick.destroy()
            walk.kick, path.switched = None, True
        result = SolveResult(True, "converged", step.its, step.norms, step.work,
                             time.perf_counter() - step.t0)
        path.factors.append(step.lam)
        path.results.append(result)
        path.arc_lengths.append(walk.ds)
        path.unstable.append(step.count)
        path.work.add(step.work)
        if len(path.factors) % every == 0 or switched:
            say(f"step {len(path.factors)}: λ = {step.lam:.6g}, arc {walk.ds:.3g}, "
                f"{step.its} iterations" + (", branch switched" if switched else ""))
        if step.turned:  # the extremum of λ over the states around the bracketed step
            near = [start, *path.factors][-3:]
            peak = max(near) if walk.sense > 0 else min(near)
            path.critical_points.append(CriticalPoint("limit", peak, len(path.factors),
                                                      between))
            say(f"  limit point at λ = {peak:.6g}")
            walk.ds, walk.bracket = walk.bracket.arc, None
        elif (not self.detect and not switched and walk.last_dlam is not None
              and step.dlam * walk.last_dlam < 0
              and min(abs(step.dlam), abs(walk.last_dlam)) > 1e-6 * walk.ds):  # not noise
            self._limit_point(path, start)
        if step.bifurcation:  # bracketed: the path goes on with the arc it came with
            path.critical_points.append(CriticalPoint(
                "bifurcation", sum(between) / 2, len(path.factors), between))
            say(f"  bifurcation between λ = {between[0]:.6g} and {between[1]:.6g} "
                f"({walk.count} -> {step.count} negative eigenvalues)")
            walk.ds, walk.bracket = walk.bracket.arc, None
        if step.leave:  # along the critical mode
            walk.kick = self._critical_mode()
        walk.last_dlam = None if switched else step.dlam
        walk.count, walk.sense = step.count, step.sense
        if walk.tangent is not None:
            walk.tangent.destroy()
        walk.tangent = step.tangent
        if walk.previous is not None:
            walk.previous[0].destroy()
        walk.previous = (step.du, step.dlam)
        return result

    def _next_arc(self, walk: _Walk, step: _Step) -> None:
        """The converged state becomes the walk's; the next arc from this step's effort."""
        self.solver.u.x.petsc_vec.copy(walk.state)
        if walk.bracket is not None:
            walk.bracket.since += 1
            if walk.bracket.since > 3:  # the critical point did not come back: not there
                walk.ds, walk.bracket = walk.bracket.arc, None
        if walk.kick is None and walk.bracket is None:
            growth = math.sqrt(self.desired / max(step.its, 1))
            walk.ds = min(self.max_arc_length, walk.ds * min(2.0, max(0.5, growth)))

    def _cut(self, path, work, norms, ds, lam, err, say) -> float:
        """A failed step: restore, and half the arc; ContinuationError below its minimum."""
        path.failures += 1
        path.work.add(work)
        if self.restore:
            self.restore()
        if ds / 2 < self.min_arc_length:
            back = " (the path doubles back onto itself)" if isinstance(err, _TurnedBack) else ""
            raise ContinuationError(
                f"the path could not be followed beyond load factor {lam:.6g}: {err}{back}; "
                f"arc length cut below {self.min_arc_length:g}",
                SolveResult(False, "arc", len(norms), norms, work), reached=lam)
        say(f"  the step from λ = {lam:.4g} is not taken ({err}): retried with the arc "
            f"halved, {ds / 2:.3g}")
        return ds / 2

    def _stability(self, path: ContinuationPath, du: PETSc.Vec | None = None,
                   dlam: float = 0.0) -> tuple[int, float, PETSc.Vec | None]:
        """Negative eigenvalues of the tangent here, the path's sense of λ here, and t.

        One LDLᵀ of K(u) and one back-solve t = K⁻¹q: the path's tangent is ±(t, 1),
        oriented along the step (Δu, Δλ) just made; its λ-component's sign is the sense.
        t is also the next step's predictor direction.
        """
        path.inertia_factorizations += 1
        s = self.solver
        if du is None:
            return unstable_directions(s.tangent_form, s.bcs, self.prefix, self.multipliers,
                                       margin=INERTIA_MARGIN, rows=self._weights), 0.0, None
        t = du.duplicate()
        count = unstable_directions(s.tangent_form, s.bcs, self.prefix, self.multipliers,
                                    rhs=self._q, solution=t, margin=INERTIA_MARGIN,
                                    rows=self._weights)
        return count, self._dot(du, t) + self.psi**2 * dlam, t

    def _back_to(self, state: PETSc.Vec, lam: float) -> None:
        """u = state, λ = lam."""
        x = self.solver.u.x.petsc_vec
        state.copy(x)
        x.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        self.set_load(lam)

    def _turns_back(self, du: PETSc.Vec, dlam: float, previous) -> bool:
        """Whether the increment points against the last one (the path doubles back)."""
        return self._dot(du, previous[0]) + self.psi**2 * dlam * previous[1] < 0

    def _limit_point(self, path: ContinuationPath, start: float) -> None:
        """λ changed sense: a limit point, at the vertex of λ(s) through the last 3 states."""
        lams = [start, *path.factors][-3:]
        s = np.concatenate([[0.0], np.cumsum(path.arc_lengths)])[-3:]  # s of each state
        a, b, c = np.polyfit(s, lams, 2)
        # the vertex if it lies between the three states, else the middle one
        peak = c - b * b / (4 * a) if a != 0 and s[0] <= -b / (2 * a) <= s[2] else lams[1]
        path.critical_points.append(CriticalPoint("limit", float(peak), len(path.factors),
                                                  (lams[-2], lams[-1])))

    def _critical_mode(self) -> PETSc.Vec:
        """The tangent's eigenvector of its eigenvalue nearest 0 (SLEPc).

        Just past the bifurcation, that is the one that has just turned negative (not an
        older, more negative one, if the path was already unstable).
        """
        s = self.solver
        return mode_nearest_zero(s.tangent_form, s.bcs, s.u.function_space, self.prefix,
                                 mass=self.mass)

    def _land(self, target: float, before: PETSc.Vec, lam_old: float, lam: float,
              work: WorkCounts, norms: list) -> int | None:
        """Solve at λ = target under load control, from the nearer state; its iterations.

        The same Newton variant and corrector as the arc, with δλ = 0. Not from the
        interpolation of the two states: a chord between two rotated shapes of a slender
        body stretches it, and its membrane stiffness makes that a large residual.
        None (and u, λ as they were) if it fails.
        """
        s = self.solver
        x = s.u.x.petsc_vec
        end = x.copy()
        start = before if abs(target - lam_old) < abs(lam - target) else end
        self._back_to(start, target)
        s.start_solve()
        self._load_vector(target, self._q, work)
        du = x.duplicate()
        du.set(0.0)
        origin = start.copy()
        own = []  # its own residual history: its rtol and round-off tests start from it
        try:
            return self._correct(_Corrector(origin, target, self._q, self._q.norm(), None,
                                            None), du, 0.0, work, own).iterations
        except _StepFailed as err:
            log.info("landing at λ = %g failed: %s", target, err)
            self._back_to(end, lam)
            return None
        finally:
            norms.extend(own)
            for v in (du, end, origin):
                v.destroy()
