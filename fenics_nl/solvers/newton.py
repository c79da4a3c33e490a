"""The Newton family on PETSc KSP: full, modified, periodic and BFGS, in one loop.

Solves {R(U)} = {0} for a UFL residual with Dirichlet conditions, as in the course::

    K δU = −R,   U ← U + δU,   until ‖R‖ ≤ max(rtol ‖R₀‖, atol F).

Both tolerances are relative: F is a force of the problem (the load; by default the
largest first residual the solver has seen, the first load increment's imbalance), so the
same problem gives the same iterations in any units.
The variants differ only by *when the tangent K is rebuilt*:

* ``full``: every iteration (quadratic convergence);
* ``modified``: never within a solve: the tangent at the start of the solve
  (``constant_tangent="initial"``) or the elastic tangent K(0), assembled and factorized
  once for the solver's lifetime (``"elastic"``, the course's choice); linear convergence;
* ``periodic``: every ``period`` iterations (the course's compromise);
* ``bfgs``: the constant tangent of ``modified`` corrected by inverse BFGS updates
  (Matthies–Strang), superlinear convergence for one factorization.

New boundary values (a prescribed motion, a contact node made active) enter through the
first correction, not by moving the boundary nodes alone: δU = g − U on the Dirichlet dofs
and the interior answers through the tangent's columns (lifting), so the first iterate is
the linearised response of the whole body. Moving the nodes first would crush (or plastify)
the elements along the boundary, and Newton could diverge from there. Every later
correction is homogeneous on the Dirichlet dofs. A tangent is only reassembled
when the method asks for it; the matrix keeps its sparsity pattern, so PETSc/MUMPS redo the
numeric factorization only and reuse the symbolic analysis.
"""

from __future__ import annotations

import contextlib
import logging
import math
import time
from collections.abc import Sequence
from typing import Literal

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc
from mpi4py import MPI
from petsc4py import PETSc
from ufl.algorithms import expand_derivatives
from ufl.algorithms.analysis import extract_constants

from fenics_nl.errors import SolveError
from fenics_nl.solvers.convergence import ConvergenceTest, at_round_off
from fenics_nl.solvers.factorizations import Factorizations
from fenics_nl.solvers.form_matrix import FormMatrix
from fenics_nl.solvers.linear_solver import (
    LinearSolver,
    allow_unsymmetric,
    block_preconditioned_ksp,
    create_ksp,
    rigid_body_modes,
)
from fenics_nl.solvers.nodal import NodalTerms
from fenics_nl.solvers.result import SolveResult, WorkCounts
from fenics_nl.solvers.row_update import RowUpdate
from fenics_nl.solvers.supports import RigidMotions, check_supports, constrained_dofs
from fenics_nl.solvers.tangent_policy import InverseBFGS, TangentPolicy

__all__ = [
    "ConvergenceError",
    "LinearSolveError",
    "NewtonSolver",
    "forcing_term",
]

log = logging.getLogger(__name__)

METHODS = ("full", "modified", "periodic", "bfgs")
Method = Literal["full", "modified", "periodic", "bfgs"]  # the Newton variant


class ConvergenceError(SolveError):
    """A non-linear solve failed; `result` holds what was done up to the failure."""


def forcing_term(relative_residual: float, threshold_ratio: float = 0.0) -> float:
    """Relative tolerance of an iterative Newton correction (inexact Newton).

    η = 1e-3 min(1, ‖R_k‖/‖R_0‖): loose far from the solution, where CG iterations are
    wasted, tighter as the residual drops so that the last iterations stay close to
    exact Newton. Not looser than 1e-3: an inexact solve leaves its error in the soft
    (bending) modes, where a small linear residual hides a large displacement error.
    Not tighter than a tenth of `threshold_ratio` = (the residual convergence asks)/‖R_k‖
    either: the correction then leaves a linear residual a tenth of that threshold, and
    Newton's own quadratic term is smaller still near the solution, so the digits beyond
    buy nothing (Kelley's floor η ≥ c τ/‖R_k‖). On the 3D forging's first 22 iterations
    (19632 unknowns, Newton to 1e-8, commit a4a330f) GMRES took 448 Krylov iterations with
    it, 648 without.

    Args:
        relative_residual: ‖R_k‖/‖R_0‖.
        threshold_ratio: the residual norm convergence asks, over ‖R_k‖ (0: no floor).

    Returns:
        η, the Krylov solver's relative tolerance for the next correction δU.
    """
    return min(1e-3, max(1e-3 * min(1.0, max(relative_residual, 1e-11)), 0.1 * threshold_ratio))


def _adaptive_lag(prefix: str) -> bool:
    """GAMG's set-up lagged adaptively, unless ``-{prefix}snes_lag_preconditioner 1``."""
    name = f"{prefix}snes_lag_preconditioner"
    if not PETSc.Options().hasName(name):
        return True
    lag = PETSc.Options().getInt(name)
    if lag != 1:
        raise ValueError(f"-{name} {lag}: only 1 (an AMG set-up for every tangent) is read; "
                         "without it the set-up is lagged adaptively")
    return False


class _Timer:
    def __init__(self, work: WorkCounts, phase: str):
        self.work, self.phase = work, phase

    def __enter__(self):
        self.t0 = time.perf_counter()

    def __exit__(self, *exc):
        self.work.time[self.phase] += time.perf_counter() - self.t0


class LinearSolveError(Exception):
    """The KSP did not converge (`reason`: its negative converged reason)."""

    def __init__(self, reason: int):
        super().__init__(f"linear solver failed (KSP reason {reason})")
        self.reason = reason


class NewtonSolver:
    """Hand-written Newton loop for R(u; v) = 0; `solve()` updates `u` in place.

    Converged when ‖R‖ ≤ max(rtol ‖R₀‖, atol F), R₀ the residual at the start of the solve
    and F = `force_scale`, a force of the problem (the load), or by default the largest R₀
    this solver has seen (the imbalance of its first load increment). ‖R‖ cannot fall
    below the round-off of the internal forces (~1e-16 of them, times the number of
    contributions), and a small increment, or an active-set iteration that restarts close
    to equilibrium, makes rtol ‖R₀‖ smaller still: atol F is the floor, in the problem's
    own units, so that the same problem converges the same way in N–mm–MPa or N–m–Pa.

    `reuse_factorization`: a new tangent (or new Dirichlet rows, as in contact) is not
    refactorized; CG on it is preconditioned by the last factorization, which is renewed
    only when CG needed more than REUSE_ITERATIONS iterations. Where the tangent changes by
    a low-rank term (a few constrained rows), CG converges in a handful of iterations.
    A linear material's new Dirichlet rows (a contact's active set), however many, are
    solved on the last factorization by a bordered solve on the rows that changed
    (`solvers.row_update`) while its columns cost less than a factorization.

    The options, keyword-only, come in three groups, in this order below: the variant (which
    tangent, when it is rebuilt: `method` to `line_search`), convergence (`rtol` to
    `max_it`, held in `convergence`, the `ConvergenceTest` arc-length and SNES use too) and
    the linear solver (`linear_solver` to `prefix`). The rest is tuned through PETSc's
    options under `prefix`, with PETSc's names: ``-{prefix}ksp_*``, ``-{prefix}pc_*``,
    ``-{prefix}snes_qn_m`` (the pairs BFGS keeps, 30), ``-{prefix}snes_divergence_tolerance``
    (1e8), ``-{prefix}snes_lag_preconditioner 1`` (with ``gamg``, an AMG set-up for every
    tangent instead of the adaptive lag below); ``-{prefix}snes_rtol``, ``snes_max_it`` and
    ``snes_atol`` (then an absolute force, as PETSc's) override `rtol`, `max_it`, `atol`
    (`ConvergenceTest.with_options`, which SNES reads too).

    Args:
        residual: the residual form R(u; v), linear in the test function v.
        u: the unknown; its current value is the starting point and holds the solution.
        bcs: Dirichlet conditions; new values enter through the first correction (lifted).
        method: ``full``, ``modified``, ``periodic`` or ``bfgs`` (see the module).
        tangent: the tangent form; by default ∂R/∂u by UFL.
        constant_tangent: for ``modified`` and ``bfgs``: ``initial`` (the tangent at the
            start of each solve), ``elastic`` (K(0), factorized once for the solver's life),
            or a bilinear form, assembled and factorized once for the solver's life (a
            material with internal variables gives its elastic tangent this way: K(0) would
            read its current state).
        period: iterations between tangent rebuilds of ``periodic`` (PETSc's lag).
        line_search: True (or ``residual``): backtracking (halving, at most 10 times) until
            ‖R‖ falls; ``slope``: the full step if ‖R‖ fell, else secant steps to the
            energy's minimum along the step (for a minimised smooth energy, a hyperelastic
            law: see `_step`).
        force_scale: F, a force of the problem (the load); default the largest ‖R₀‖ seen.
        rtol: convergence when ‖R‖ ≤ rtol ‖R₀‖ ...
        atol: ... or ‖R‖ ≤ atol F (relative too).
        max_it: iterations before ConvergenceError.
        divergence_tol: ConvergenceError as soon as ‖R‖ > divergence_tol ‖R₀‖, R₀ this
            solve's own first residual (PETSc's ``snes_divergence_tolerance``, whose default
            is 1e4; where a failed solve is cut by the load driver, a low one stops a lost
            Newton early).
        linear_solver: ``lu``, ``cholesky`` (MUMPS) or ``gamg`` (CG + GAMG, inexact Newton;
            within a solve, the AMG hierarchy of its first tangent serves the later ones
            while CG needs at most twice the iterations per digit it took on it: an adaptive
            lag, measured in benchmarks/bracket.py).
        reuse_factorization: keep the last factorization as a CG preconditioner (see above).
        indefinite: the tangent may be indefinite (a path past a limit point; a mixed
            displacement–pressure unknown always is): a reused factorization, or GAMG,
            preconditions GMRES, not CG, which may diverge there.
        preconditioner: with ``gamg`` on a mixed (u, p) unknown, the block-diagonal
            preconditioner's form (`materials.mixed.preconditioner`): MINRES on it.
        prefix: PETSc options prefix of the linear solver (``-{prefix}ksp_view``,
            ``-{prefix}pc_type``, ...: the command line overrides the linear solver's choices)
            and of the ``-{prefix}snes_*`` options above.

    Terms that no integral gives (point forces, the springs of friction's slip) reach the
    tangent and the residual through one hook, `nodal` (`solvers.nodal.NodalTerms`), owned
    by whoever sets them.

    Example::

        solver = NewtonSolver(material.internal_work(u, v) * dx - f * v[2] * ds, u, bcs,
                              method="bfgs", force_scale=load)
        result = solver.solve()  # SolveResult: iterations, residual_norms, work
    """

    def __init__(
        self,
        residual: ufl.Form,
        u: fem.Function,
        bcs: Sequence[fem.DirichletBC] = (),
        *,
        # the variant
        method: Method = "full",
        tangent: ufl.Form | None = None,
        constant_tangent: str | ufl.Form = "initial",
        period: int = 3,
        line_search: bool | str = False,
        # convergence
        force_scale: float | None = None,
        rtol: float = 1e-10,
        atol: float = 1e-10,
        max_it: int = 50,
        divergence_tol: float = 1e8,
        # the linear solver
        linear_solver: LinearSolver = "lu",
        reuse_factorization: bool = False,
        indefinite: bool = False,
        preconditioner: ufl.Form | None = None,
        prefix: str = "newton_",
    ):
        if method not in METHODS:
            raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
        given = isinstance(constant_tangent, ufl.Form)
        if not given and constant_tangent not in ("initial", "elastic"):
            raise ValueError("constant_tangent must be 'initial', 'elastic' or a form, "
                             f"got {constant_tangent!r}")
        if period < 1:
            raise ValueError(f"period must be >= 1, got {period}")
        if force_scale is not None and not (force_scale > 0 and math.isfinite(force_scale)):
            raise ValueError(f"force_scale must be a finite force > 0, got {force_scale!r}")
        self.u, self.bcs, self.method = u, list(bcs), method
        self._force_scale = force_scale
        self._largest_r0 = 0.0  # the default force scale
        opts = PETSc.Options()
        self.convergence = ConvergenceTest(rtol, atol, max_it,
                                           divergence_tol).with_options(prefix)
        if line_search not in (False, True, "residual", "slope"):
            raise ValueError("line_search must be False, True, 'residual' or 'slope', got "
                             f"{line_search!r}")
        self._line_search = line_search
        V = u.function_space
        J = ufl.derivative(residual, u) if tangent is None else tangent
        self.tangent_form = J  # UFL, for a stability analysis of the current state
        self._R = fem.form(residual)
        self._K = fem.form(J)
        # A tangent with no coefficients (linear material) is assembled once; new Dirichlet
        # rows are then applied to a copy instead of reassembling.
        J_expanded = expand_derivatives(J)
        fixed = not (J_expanded.coefficients() or extract_constants(J_expanded))
        self.linear = fixed  # the tangent does not depend on u (a linear material)
        self._K_fixed = None  # K without Dirichlet rows, kept after its first assembly
        self._A_stale = False  # A is K_fixed with older rows (see `_fixed_tangent`)
        self._A_factorized = False  # A is the matrix last factorized (no rows, springs since)
        for_life = (given or constant_tangent == "elastic") and method in ("modified", "bfgs")
        # the tangent that is assembled: K(u), K(0) (the same form at a zero displacement),
        # or the given one
        if for_life and given:
            self._K_used = fem.form(constant_tangent)
        elif for_life:
            self._K_used = fem.form(ufl.replace(J, {u: fem.Function(V)}))
        else:
            self._K_used = self._K
        self._constant = method in ("modified", "bfgs")
        # on one rank with MUMPS the tangent is filled by DOLFINx's CSR assembler (form_matrix)
        # (the pattern of the form assembled: K, or a given constant tangent)
        self._matrix = FormMatrix(self._K_used, native=linear_solver in ("lu", "cholesky"))
        self.A = self._matrix.mat
        # reuse: the factorized matrix P lags behind A and preconditions CG on A
        reuse = reuse_factorization and linear_solver in ("lu", "cholesky")
        self._P = None  # with reuse: a copy of the last factorized tangent, made on first use
        # with reuse and a linear material: new Dirichlet rows solved on the last
        # factorization, by a bordered solve on the rows that changed (made with K)
        self._rows: RowUpdate | None = None
        self.b = petsc.create_vector(V)
        self.du = petsc.create_vector(V)
        # R(u) as assembled (owned rows summed; no Dirichlet rows, lifting or nodal terms),
        # and, within `reuse_residual_at_same_u`, the u it was assembled at (None: not kept)
        self._R_raw = petsc.create_vector(V)
        self._R_raw_at: np.ndarray | None = None
        self._keep_R_raw = False
        self._lifting: PETSc.Vec | None = None
        # point forces and nodal springs (friction, a truss's apex load): the one hook for
        # terms that no integral gives
        self.nodal = NodalTerms(V, V.mesh.comm)
        self._nodal_version = 0  # the springs the tangent was built with
        self._M = None  # the block preconditioner of a mixed unknown's iterative solve
        if linear_solver == "gamg" and V.ufl_element().is_mixed:
            if preconditioner is None:
                raise ValueError("an iterative solve of a mixed displacement-pressure unknown "
                                 "needs its block preconditioner (materials.mixed."
                                 "preconditioner)")
            self._M_form = fem.form(preconditioner)
            self._M = petsc.create_matrix(self._M_form)
            self._ksp = block_preconditioned_ksp(self.A, self._M, V, prefix, rtol=1e-12)
        else:
            nullspace = rigid_body_modes(V) if linear_solver == "gamg" else None
            self._ksp = create_ksp(self.A, linear_solver, prefix, nullspace,
                                  P=self.A if reuse else None, rtol=1e-12,
                                  indefinite=indefinite or V.ufl_element().is_mixed)
        # the block preconditioner is built from its own matrix: always set up again
        self._factorizations = None if self._M is not None or reuse else Factorizations(
            self.A, self._ksp, lambda A, kind: create_ksp(A, kind, prefix, rtol=1e-12))
        # inexact Newton with CG + GAMG: solve each correction only as well as the current
        # residual deserves, unless the command line fixed -{prefix}ksp_rtol; a linear
        # problem (fixed tangent) is solved once, to the Newton tolerance
        own_rtol = linear_solver == "gamg" and not PETSc.Options().hasName(f"{prefix}ksp_rtol")
        self._forcing = own_rtol and not fixed
        if own_rtol and fixed:
            self._ksp.setTolerances(rtol=1e-11)
        if reuse and self._ksp.getType() == "preonly":
            # options turned CG off: a lagging factorization would then give wrong solves
            log.warning("%sksp_type preonly: factorization reuse disabled", prefix)
            reuse = False
        # the block preconditioner's matrix is assembled with the tangent: not lagged
        lag = linear_solver == "gamg" and self._M is None and _adaptive_lag(prefix)
        self._policy = TangentPolicy(method, period, fixed=fixed, for_life=for_life, reuse=reuse,
                                    lag=lag)
        memory = opts.getInt(f"{prefix}snes_qn_m", 30)
        self.bfgs = InverseBFGS(memory) if method == "bfgs" else None
        self.total = WorkCounts()
        self._motions = RigidMotions.of(V)  # None: not a displacement (sub-)space
        self._supports_checked = False  # for the current Dirichlet rows (and springs)

    @property
    def force_reference(self) -> float:
        """The largest first residual seen: the default force scale (kept by a checkpoint)."""
        return self._largest_r0

    @force_reference.setter
    def force_reference(self, value: float) -> None:
        self._largest_r0 = float(value)

    @property
    def dofs(self) -> int:
        """Global number of scalar unknowns."""
        imap = self.u.function_space.dofmap.index_map  # scalar unknowns, all ranks
        return imap.size_global * self.u.function_space.dofmap.index_map_bs

    def allow_unsymmetric(self) -> bool:
        """Let the tangent lose its symmetry (friction's couplings); whether it may.

        A reused factorization then preconditions GMRES instead of CG
        (`linear_solver.allow_unsymmetric`); not with Cholesky, nor a block preconditioner.

        Returns:
            Whether the linear solver takes a tangent that is not symmetric.
        """
        if self._M is not None:
            return False
        return allow_unsymmetric(self._ksp)

    def set_bcs(self, bcs: Sequence[fem.DirichletBC], small_change: bool = False,
                new_path: bool = False) -> None:
        """Replace the Dirichlet conditions (their rows change, so the tangent is stale).

        Args:
            bcs: the new Dirichlet conditions.
            small_change: only a few rows differ from the last factorized tangent, so with
                `reuse_factorization` CG on the new tangent, preconditioned by it, is cheap.
            new_path: a change of unknown size (a load step's start): a linear material's
                tangent is factorized afresh rather than updated (`solvers.row_update`), as a
                run restarted there would: both then take the same path, work counts
                included.
        """
        if new_path and self._rows is not None:
            self._rows.factor = None
            self._rows.serving = False  # no solve on it before the next factorization
        # a small change of no row at all (an active set that settled, new values on the
        # same rows): the same matrix, nothing to rebuild. (A change of unknown size, as
        # at a load step's start, refactorizes as before: a restart, which has no
        # factorization, then takes the uninterrupted run's path, work counts included.)
        same = small_change and self.A.comm.tompi4py().allreduce(  # on every rank's rows
            np.array_equal(constrained_dofs(bcs), constrained_dofs(self.bcs)), op=MPI.LAND)
        self.bcs = list(bcs)
        if same:
            return
        self._policy.bcs_changed(small_change)
        self._supports_checked = False

    # -- the loop --------------------------------------------------------------------

    def solve(self) -> SolveResult:
        """Run the loop from the current `u`; raise ConvergenceError on failure.

        Returns:
            The converged result, with its iterations, residual norms and work (also added
            to `total`); on a failure, the ConvergenceError's `result` instead.
        """
        t_start = time.perf_counter()
        work = WorkCounts()
        self.start_solve()
        lift = self._boundary_moved()  # the first correction carries g − U (see the module)
        norms = [self.residual(work, lift=lift)]
        elapsed = [time.perf_counter() - t_start]
        k = 0

        def result(converged: bool, reason: str) -> SolveResult:
            self.total.add(work)
            return SolveResult(converged, reason, k, norms, work, time.perf_counter() - t_start,
                                elapsed)

        while True:  # (i) the residual R(U_k) is in `b`, its norm in `norms`
            rnorm = norms[-1]
            log.info("  Newton %s it %d |R| = %.3e", self.method, k, rnorm)
            reason = self.convergence.reason(norms, self._force(norms[0]))
            if reason == "converged" and not lift:  # (ii) small enough: U_k is the answer
                return result(True, reason)
            if reason not in (None, "converged"):
                if reason == "max_it" and self._at_round_off(norms):
                    reason = "round_off"  # not a bad method: a tolerance below round-off
                raise ConvergenceError(self._failure(reason, norms), result(False, reason))
            try:  # (iii) the tangent, as the variant's policy says, and δU = −K⁻¹R
                self.update_tangent(k, work)
                self.set_forcing(rnorm, norms[0], floor=True)
                b_old = self.b.copy() if self.bfgs else None
                self.solve_linear(self.b, self.du, work)
            except LinearSolveError as err:
                raise ConvergenceError(f"{err} at iteration {k}", result(False, "ksp")) from None
            alpha, rnorm_new = self._step(rnorm, work, full_step=lift)  # (iv) U += α δU
            norms.append(rnorm_new)
            elapsed.append(time.perf_counter() - t_start)
            if self.bfgs:
                if not lift:  # the lifted step's rhs is not a residual difference
                    self.bfgs.store(self.du, alpha, b_old, self.b)
                b_old.destroy()
            lift = False
            k += 1

    # -- the step interface: what `solve`, arc-length and any other driver are written on --

    def start_solve(self) -> None:
        """A new solve begins: the variant's tangent policy restarts, BFGS forgets its pairs."""
        self._policy.start_solve()
        if self.bfgs:
            self.bfgs.clear()

    def residual(self, work: WorkCounts, lift: bool = False) -> float:
        """Assemble R(u) into `residual_vector` (u − g on the Dirichlet rows); its ‖·‖.

        Within `reuse_residual_at_same_u`, an assembly at the same u serves again: the
        caller promises that nothing else R reads (a load factor, a state) changes there.

        Args:
            work: the counts the assembly (and its time) is added to.
            lift: also b −= K (u − g) on the Dirichlet columns, so that the correction
                δU = −K⁻¹b moves the boundary to g and the interior with it.

        Returns:
            ‖R‖, taken off the Dirichlet rows (a force, the equilibrium imbalance).
        """
        with _Timer(work, "residual"):
            if not self._R_raw_is_current():
                with self._R_raw.localForm() as loc:
                    loc.set(0.0)
                petsc.assemble_vector(self._R_raw, self._R)
                self._R_raw.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
                work.residual_assemblies += 1
                if self._keep_R_raw:
                    self._R_raw_at = self.u.x.array.copy()
            self._R_raw.copy(self.b)
            x = self.u.x.petsc_vec
            if lift:
                self.b.axpy(1.0, self._lifting_vector(x))
            self.nodal.add_to_residual(self.u.x.array, self.b.array)
            petsc.set_bc(self.b, self.bcs, x0=x, alpha=-1.0)
            return self._force_norm()

    @contextlib.contextmanager
    def reuse_residual_at_same_u(self):
        """Within this block, R's form and everything it reads but u stay as they are.

        Only the Dirichlet rows and the `nodal` terms may change (an active-set loop): an
        R(u) assembled at the same u then serves again, for the next solve's first residual
        and for `copy_kept_residual` (the contact forces), instead of a new assembly
        (the axisymmetric punch: 3 assemblies an active-set iteration down to 1).
        """
        outer = self._keep_R_raw
        self._keep_R_raw = True
        try:
            yield
        finally:
            self._keep_R_raw = outer
            if not outer:
                self._R_raw_at = None

    def copy_kept_residual(self, out: PETSc.Vec) -> bool:
        """Copy R(u) as assembled, ghosts updated, into `out` if it is current; whether it was.

        Current within `reuse_residual_at_same_u` while u is where it was assembled; else the
        caller assembles it (collective: every rank answers alike).

        Args:
            out: receives R(u), without Dirichlet rows, lifting or `nodal` terms.

        Returns:
            Whether R(u) was current, and so copied.
        """
        if not self._R_raw_is_current():
            return False
        self._R_raw.copy(out)
        out.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        return True

    def _R_raw_is_current(self) -> bool:
        """Whether the kept R(u) is at the current u on every rank."""
        if not self._keep_R_raw:
            return False
        here = self._R_raw_at is not None and np.array_equal(self._R_raw_at, self.u.x.array)
        return self.b.comm.tompi4py().allreduce(here, op=MPI.LAND)

    def _lifting_vector(self, x: PETSc.Vec) -> PETSc.Vec:
        """−K (u − g) on the Dirichlet columns, owned rows summed (the lifted step's share)."""
        if self._lifting is None:
            self._lifting = self.b.duplicate()
        with self._lifting.localForm() as loc:
            loc.set(0.0)
        petsc.apply_lifting(self._lifting, [self._K_used], bcs=[self.bcs], x0=[x], alpha=-1.0)
        self._lifting.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
        return self._lifting

    @property
    def residual_vector(self) -> PETSc.Vec:
        """The residual of the last `residual` call (read it, do not keep it)."""
        return self.b

    def update_tangent(self, k: int, work: WorkCounts) -> bool:
        """Rebuild (and factorize) the tangent at iteration `k` if the variant says so.

        full: always; modified and bfgs: at k = 0 of a solve, or never (a tangent for the
        solver's life); periodic: every `period` iterations.

        Args:
            k: the iteration within the solve (0: its first).
            work: the counts the assembly and factorization are added to.

        Returns:
            Whether the tangent K was rebuilt.
        """
        if self.nodal.version != self._nodal_version:  # new springs: the tangent is stale
            # but near the last one (friction's springs follow the slip directions as they
            # converge): with reuse, the last factorization preconditions CG first; not
            # with couplings (rows not symmetric: no CG)
            self._nodal_version = self.nodal.version
            self._policy.bcs_changed(small=self.nodal.couplings is None)
            self._supports_checked = False
        if not self._policy.needs_tangent(k):
            return False
        self._assemble_tangent(work)
        return True

    def set_forcing(self, rnorm: float, first: float, floor: bool = False) -> None:
        """Inexact Newton (CG or GMRES + GAMG): the next corrections' relative tolerance.

        From ‖R_k‖/‖R_0‖ = rnorm/first (`forcing_term`); a frozen operator's (modified,
        BFGS) from 1: its own error is about its contraction, a tighter solve buys nothing.

        Args:
            rnorm: ‖R_k‖, the current residual's norm.
            first: ‖R_0‖, the solve's first (0: taken as a frozen operator's).
            floor: this solve stops by `convergence` (its threshold from `first`): the
                tolerance is then no tighter than reaching it needs, where the Krylov
                solver stops on the true residual ‖K δU + R‖ (CG, right-preconditioned
                GMRES; not MINRES, whose preconditioned norm may be far from it).
        """
        if self._forcing:
            frozen = self.method in ("modified", "bfgs") or not first
            if frozen:
                self._ksp.setTolerances(rtol=forcing_term(1.0))
                return
            true_residual = self._ksp.getNormType() == PETSc.KSP.NormType.UNPRECONDITIONED
            ratio = (self.convergence.threshold(first, self._force(first)) / rnorm
                     if floor and true_residual and rnorm > 0 else 0.0)
            self._ksp.setTolerances(rtol=forcing_term(rnorm / first, ratio))

    def solve_linear(self, rhs: PETSc.Vec, out: PETSc.Vec, work: WorkCounts) -> None:
        """out = K⁻¹ rhs with the current operator (BFGS: its corrected inverse H rhs).

        The Newton correction of a residual b is −K⁻¹b.

        Args:
            rhs: the right-hand side (a residual b, or the load vector q).
            out: receives K⁻¹ rhs.
            work: the counts the solve is added to.

        Raises:
            LinearSolveError: if the KSP fails.
        """
        if self.bfgs:
            self.bfgs.direction(rhs, self.du, lambda b: self._linear_solve(b, work))
        else:
            self._linear_solve(rhs, work)
        if out is not self.du:
            self.du.copy(out)

    def assemble_exact_tangent(self, work: WorkCounts) -> None:
        """K(u) at the current u for `tangent_solve` (factorized if the solver would).

        Assembled again: a converged solve's last tangent is at its last-but-one iterate,
        off by the last correction (using it bends a Taylor test's slope below 2 at small
        relative steps, as seen on the indentation). With `reuse_factorization` the
        factorization already made preconditions CG on it: back-solves only.

        Args:
            work: the counts the assembly and factorization are added to.

        Raises:
            ValueError: for a tangent kept for the solver's life (not K(u)).
        """
        if self._policy.for_life:
            raise ValueError("a constant tangent for the solver's life is not K(u): "
                             "tangent solves need method full, periodic, or initial tangents")
        self._assemble_tangent(work)

    def tangent_solve(self, rhs: PETSc.Vec, out: PETSc.Vec, work: WorkCounts) -> None:
        """out = K⁻¹ rhs with the tangent of `assemble_exact_tangent` and the current rows.

        Args:
            rhs: the right-hand side, zero on the Dirichlet rows (a homogeneous problem).
            out: receives K⁻¹ rhs.
            work: the counts the solve is added to.

        Raises:
            LinearSolveError: if the KSP fails.
        """
        self._linear_solve(rhs, work)
        self.du.copy(out)

    def add_secant_pair(self, s: PETSc.Vec, y: PETSc.Vec) -> None:
        """BFGS: keep the pair of a correction, s = δu and y = δR.

        The solver then owns both vectors (the other variants destroy them).

        Args:
            s: δu, the correction made.
            y: δR, the change of the residual it made.
        """
        if self.bfgs:
            self.bfgs.store_pair(s, y)
        else:
            s.destroy()
            y.destroy()

    # -- pieces ----------------------------------------------------------------------

    def _force(self, r0: float) -> float:
        """F: `force_scale`, or the largest finite first residual seen (this one included)."""
        if math.isfinite(r0):  # an infinite one would make every later test pass
            self._largest_r0 = max(self._largest_r0, r0)
        return self._force_scale or self._largest_r0

    def _failure(self, reason: str, norms: list[float]) -> str:
        """The one line that says why the solve failed at its last iteration."""
        k, r0, r = len(norms) - 1, norms[0], norms[-1]
        if reason == "nan":
            return f"residual is not finite at iteration {k}"
        if reason == "diverged":
            return f"Newton diverged: |R| grew from {r0:.3e} to {r:.3e} at iteration {k}"
        hint = ""
        if reason == "round_off":
            hint = (f"; |R| stalls at {min(norms[-5:]):.1e}, the round-off of the internal "
                    "forces: raise atol (relative to the force scale) above it")
        return f"no convergence in {k} iterations (|R| = {r:.3e}, |R0| = {r0:.3e}){hint}"

    def _at_round_off(self, norms: list[float]) -> bool:
        """Whether ‖R‖ stalls at the round-off of the internal forces (`at_round_off`)."""
        threshold = self.convergence.threshold(norms[0], self._force(norms[0]))
        return at_round_off(norms, self._largest_r0, threshold)

    def _boundary_moved(self) -> bool:
        """Whether U differs from g on a Dirichlet dof (on any rank).

        Every step leaves U = g exactly there (`_step`), so any difference is a new value:
        no threshold, hence nothing that depends on the units (or on a pressure unknown).
        """
        x = self.u.x.petsc_vec
        gap = x.duplicate()
        gap.set(0.0)
        petsc.set_bc(gap, self.bcs, x0=x, alpha=-1.0)  # u − g on the Dirichlet dofs
        moved = gap.norm(PETSc.NormType.NORM_INFINITY)
        gap.destroy()
        return moved > 0

    def _force_norm(self) -> float:
        """‖b‖ without the Dirichlet rows: the equilibrium imbalance.

        In force units; the constraint rows of a mixed unknown are volumes, small next to
        them.
        """
        n = self.b.getLocalSize()
        values = self.b.array_r[:n].copy()
        for bc in self.bcs:
            owned, count = bc.dof_indices()
            values[owned[:count]] = 0.0
        comm = self.b.comm.tompi4py()
        # scaled by the largest entry: the sum of squares neither overflows nor underflows
        scale = comm.allreduce(float(np.max(np.abs(values), initial=0.0)), op=MPI.MAX)
        if scale == 0 or not math.isfinite(scale):
            return scale
        values /= scale
        return scale * math.sqrt(comm.allreduce(float(values @ values)))

    def _assemble_tangent(self, work: WorkCounts) -> None:
        with _Timer(work, "tangent"):
            if self._policy.fixed and not self._constant:
                self._fixed_tangent(work)
            elif self.nodal.couplings is not None:  # the source rows first, then Dirichlet's
                self._matrix.assemble(self._K_used)
                work.tangent_assemblies += 1
                self._couple_then_set_dirichlet_rows()
            else:
                self._matrix.assemble(self._K_used, self.bcs)
                work.tangent_assemblies += 1
            self.nodal.add_to_tangent(self.A)
            if self._M is not None:  # its Dirichlet rows follow the tangent's
                self._M.zeroEntries()
                petsc.assemble_matrix(self._M, self._M_form, bcs=self.bcs, diag=1.0)
                self._M.assemble()
        if not self._supports_checked and self._motions is not None:
            # a free rigid motion makes K singular: refused before any factorization
            # (K's own rows resist what A's do: `free_motions` reads neither's Dirichlet rows)
            check_supports(self._K_fixed if self._A_stale else self.A, self._motions, self.bcs)
            self._supports_checked = True
        if self._rows is not None:
            self._rows.serving = False
        if self._rows is not None and self.nodal.plain:
            # a linear material's new rows: on the last factorization while that pays
            with _Timer(work, "solve"):  # its columns are back-solves
                serves = self._rows.set_rows(constrained_dofs(self.bcs), work)
            if not serves:  # a factorization reads A
                self._apply_rows_to_fixed_tangent()
                self._factorize(work)
        elif self._policy.needs_factorization():
            self._factorize(work)
        else:  # an older tangent's factorization (reuse) or AMG hierarchy (lag) serves
            if self._policy.lag:
                self._ksp.getPC().setReusePreconditioner(True)
            self._policy.stale = True
        self._policy.assembled()

    def _fixed_tangent(self, work: WorkCounts) -> None:
        """K assembled once; A = K with the current Dirichlet rows, now or when it is read.

        The row update's solves read K and the base's factors, not A: while it may serve, A
        stays the base's matrix, the last one factorized (what the KSP solves with on the
        base's own rows), until the next factorization (`_apply_rows_to_fixed_tangent`): a
        copy of K and a sweep of its columns saved per active-set iteration (a part of a
        linear solve's time on the axisymmetric punch).
        """
        if self._K_fixed is None:
            self._matrix.assemble(self._K)
            work.tangent_assemblies += 1
            self._K_fixed = self.A.copy()
            if self._policy.reuse:
                self._rows = RowUpdate(self._K_fixed)
        self._A_stale = True
        # deferred only while A is the base's matrix: springs added since (and gone again)
        # or other rows applied without a factorization leave another matrix in A
        if (self._rows is None or self._rows.factor is None or not self.nodal.plain
                or not self._A_factorized):
            self._apply_rows_to_fixed_tangent()

    def _apply_rows_to_fixed_tangent(self) -> None:
        """A = K with the Dirichlet rows and columns replaced by the identity (no assembly)."""
        if not self._A_stale:
            return
        self._K_fixed.copy(self.A, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        self._couple_then_set_dirichlet_rows()
        self._A_stale = self._A_factorized = False

    def _couple_then_set_dirichlet_rows(self) -> None:
        """A (K without Dirichlet rows): the nodal couplings, then the identity's rows.

        The couplings read K's source rows, which the Dirichlet rows then replace.
        """
        self.nodal.couple_rows(self.A)
        rows = constrained_dofs(self.bcs)
        self.A.zeroRowsColumnsLocal(rows.astype(PETSc.IntType), diag=1.0)

    def _factorize(self, work: WorkCounts) -> None:
        """Numeric factorization of the current tangent (the symbolic one is reused).

        None if the tangent is one already factorized (`Factorizations`).
        """
        with _Timer(work, "factorization"):
            if self._factorizations is not None:
                work.factorizations += self._factorizations.factorize(
                    self.A, self._ksp.getPC().setUp)
            else:
                if self._policy.reuse and self._P is None:
                    self._P = self.A.copy()
                    self._ksp.setOperators(self.A, self._P)
                elif self._policy.reuse:
                    self.A.copy(self._P, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
                self._ksp.getPC().setUp()
                work.factorizations += 1
        self._A_factorized = True
        self._policy.factorized()
        if self._rows is not None:  # the next rows are solved on this factorization
            pc = self._ksp.getPC()
            if pc.getFactorSolverType() != "mumps":  # (the options chose another package)
                self._rows = None
            elif self.nodal.plain:
                self._rows.rebase(pc.getFactorMatrix(), constrained_dofs(self.bcs))
            else:  # its K would miss the springs and couplings
                self._rows.factor = None

    def _linear_solve(self, rhs: PETSc.Vec, work: WorkCounts, retry: bool = True) -> None:
        """du = K⁻¹ rhs (the Newton correction is −du)."""
        if self._rows is not None and self._rows.serving and self._rows.size:
            # (the base's own rows go through the KSP: its options, -ksp_view, apply; A is
            # the base's matrix then, the last one factorized)
            with _Timer(work, "solve"):
                self._rows.solve(rhs, self.du)
                work.linear_solves += 1
            return
        ksp = self._factorizations.ksp if self._factorizations else self._ksp
        with _Timer(work, "solve"):
            ksp.solve(rhs, self.du)
            work.linear_solves += 1
        reason = ksp.getConvergedReason()
        its = ksp.getIterationNumber()
        if ksp.getType() != "preonly":
            work.krylov_iterations += its
        lagging = self._policy.reuse or self._policy.lag
        if lagging and reason < 0 and retry and self._policy.stale:
            # the old factorization no longer helps: refactorize, solve once more
            self._factorize(work)
            return self._linear_solve(rhs, work, retry=False)
        if reason < 0:
            raise LinearSolveError(reason)
        if lagging:  # many iterations: cheaper to refactorize next time
            self._policy.krylov_iterations(its, ksp.getTolerances()[0])

    def _step(self, rnorm: float, work: WorkCounts, full_step: bool = False
              ) -> tuple[float, float]:
        """u ← u − α du with α = 1, or a line search if it is on.

        ``residual`` (True): backtracking until ‖R‖ falls (Armijo on ‖R‖, halving at most
        10 times). ``slope``: for a smooth energy Π (a hyperelastic law), whose gradient R
        is: the step is kept when ‖R‖ fell, else α goes to the energy's minimum along the
        line, where its slope s(α) = R(u − α du)·du vanishes, by secant steps on s (PETSc's
        critical-point search). The norm alone rejects good Newton steps: a cantilever's
        linear predictor bends it by a fair part of its length, ‖R‖ is far above the first
        there, and halving crawled (tiny α, no convergence, where the full steps without a
        search converge; the figures are in docs/cases.md, "Newton takes the steps a
        hyperelastic energy needs"). Not for a residual with kinks (a penalty switching on, a
        yield surface): the slope says nothing across a kink, and the norm's test is what
        keeps such iterations from cycling. `full_step`: α = 1 whatever (the lifted step must
        reach the boundary values). Returns α and the new ‖R‖.
        """
        if full_step or not self._line_search:
            return 1.0, self._move(1.0, 0.0, work)
        if self._line_search == "slope":
            return self._critical_point(rnorm, work)
        alpha = 1.0
        norm = self._move(alpha, 0.0, work)
        for _ in range(10):
            if math.isfinite(norm) and norm <= (1 - 1e-4 * alpha) * rnorm:
                break
            norm = self._move(alpha / 2, alpha, work)
            alpha /= 2
        return alpha, norm

    def _move(self, alpha: float, current: float, work: WorkCounts) -> float:
        """From u − current·du to u − alpha·du (U = g on the Dirichlet dofs); the new ‖R‖."""
        x = self.u.x.petsc_vec
        x.axpy(current - alpha, self.du)
        # U = g on the Dirichlet dofs exactly, whatever the linear solver's accuracy (an
        # inexact CG leaves them off by its tolerance): the residual drops those rows
        petsc.set_bc(x, self.bcs)
        x.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        return self.residual(work)

    def _critical_point(self, rnorm: float, work: WorkCounts) -> tuple[float, float]:
        """The ``slope`` search of `_step`: α where R(u − α du)·du = 0 (secant, ≤ 6 steps).

        s(0) = R·du > 0 along a descent direction. Stops when ‖R‖ fell below its start, or
        |s| fell below 1e-2 s(0) (the minimum along the line, to a few per cent of the
        step), and keeps α in [1e-3, 1].
        """
        s0 = self.b.dot(self.du)
        points = [(0.0, s0)]
        alpha = 1.0
        norm = self._move(alpha, 0.0, work)
        for _ in range(6):
            s = self.b.dot(self.du) if math.isfinite(norm) else math.nan
            if math.isfinite(norm) and (norm <= (1 - 1e-4 * alpha) * rnorm
                                        or abs(s) <= 1e-2 * abs(s0)):
                break
            if not math.isfinite(s):  # beyond where the energy exists: back off
                new = alpha / 2
            else:
                (a0, s_a0), (a1, s_a1) = points[-1], (alpha, s)
                new = a1 - s_a1 * (a1 - a0) / (s_a1 - s_a0) if s_a1 != s_a0 else alpha / 2
                new = min(1.0, max(1e-3, new)) if math.isfinite(new) else alpha / 2
                points.append((alpha, s))
            norm = self._move(new, alpha, work)
            alpha = new
        return alpha, norm
