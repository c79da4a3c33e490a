"""Frictionless unilateral contact by the course's active-set algorithm.

On the candidate surface S_C (a facet tag; flat, with outward normal n = ±e_k) against a
rigid obstacle at gap γ(x) along n, the conditions are

    u_n − γ ≤ 0,   T_n ≤ 0,   (u_n − γ) T_n = 0,   T − T_n n = 0.

Iteration k solves the equilibrium with u_n = γ on the active part S_C^(k) and T = 0 on the
rest, then updates the set node by node, exactly as the course says:

* an active node with T_n > 0 (tension) leaves;
* an inactive node with u_n − γ > 0 (penetration) joins;

and stops when the set does not change. Two formulations of each iteration:

* ``elimination``: the active normal displacements are Dirichlet rows; the contact forces
  are the residual's reactions there. Symmetric positive definite, no extra unknowns.
* ``multiplier``: the course's saddle point [K −A; −Aᵀ 0]{U; T} = {F; −γ} with the
  multiplier (the contact pressure) on a facet submesh of S_C, coupled by a vertex
  quadrature so that the constraint is nodal, as in the elimination.

The nodes are the displacement dofs on S_C: vertices for P1, vertices and edge midpoints for
P2 (the multiplier formulation: P1, or P2 in 2D and axisymmetric models). Non-linear
materials: each active-set iteration is a full Newton solve (warm-started), so the set is
only updated from equilibrium states, where the course's rules are meaningful.
The active set is kept as DOLFINx meshtags: vertices (`active_vertices`) and the facets of
S_C whose vertices are all active (`active_facets`), ready to write out.
"""

from __future__ import annotations

import collections
import contextlib
import dataclasses
import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem, mesh
from dolfinx.fem import petsc
from petsc4py import PETSc

from fenics_nl.contact.surface import ContactSurface
from fenics_nl.errors import SolveError, SupportError
from fenics_nl.parallel import global_max
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.solvers.result import SolveResult, WorkCounts

__all__ = ["ActiveSetContact", "ContactError", "EliminationSystem", "StatusUpdate"]

log = logging.getLogger(__name__)

FORMULATIONS = ("elimination", "multiplier")


class ContactError(SolveError):
    """The active-set iteration cycled or did not settle within its limit."""


class EliminationSystem:
    """One active-set iteration with the active normal displacements as Dirichlet rows.

    The contact forces are the residual's reactions on S_C. With
    ``reuse_factorization`` (the default), a linear material's iterations are solved on
    the first one's factorization, the rows that changed as a bordered system
    (`solvers.row_update`); a non-linear material's iteration that changes at most
    SMALL_CHANGE nodes keeps the last factorization as a CG preconditioner: the new matrix
    differs by a few rows and columns, so CG needs about two iterations per changed node.
    """

    SMALL_CHANGE = 8

    def __init__(self, residual: ufl.Form, u: fem.Function, bcs: Sequence[fem.DirichletBC],
                 surface: ContactSurface, *, prefix: str, **newton_options):
        self.u, self.bcs, self.surface = u, list(bcs), surface
        self._R = fem.form(residual)
        self._reaction = petsc.create_vector(u.function_space)
        opts = {"reuse_factorization": True, **newton_options}
        self.newton = NewtonSolver(residual, u, self.bcs, prefix=prefix, **opts)
        # a saddle point's (u, p) GMRES needs about as many iterations per changed node as
        # a factorization costs back-solves (3D Taylor–Hood, measured): only new springs
        # on the same rows, which move the matrix a little, keep its factorization
        mixed = u.function_space.ufl_element().is_mixed  # a (u, p) saddle point
        self.small_change = 0 if mixed else self.SMALL_CHANGE

    def set_active(self, active: np.ndarray, changes: int | None,
                   extra_bcs: Sequence[fem.DirichletBC] = ()) -> None:
        """u_n = γ on the active nodes, T = 0 on the others (the next solve's conditions).

        Args:
            active: one flag per node of S_C: the nodes held at u_n = γ.
            changes: nodes changed since the last solve (None: unknown, many): a few keep the
                factorization (rows updated), more rebuild it.
            extra_bcs: more Dirichlet rows on S_C (friction's sticking tangential ones).
        """
        small = changes is not None and changes <= self.small_change
        self.newton.set_bcs([*self.bcs, self.surface.dirichlet(active), *extra_bcs],
                            small_change=small, new_path=changes is None)

    def solve(self) -> SolveResult:
        """Newton on the current set.

        Returns:
            Newton's SolveResult (iterations, residual norms, work counts).

        Raises:
            ConvergenceError: Newton did not converge.
        """
        return self.newton.solve()

    def reactions(self) -> np.ndarray:
        """f_int − f_ext at every local dof (owned and ghosts, the unknown's numbering).

        The residual without the constrained rows: at a constrained dof, the force the
        constraint puts on the body.

        Returns:
            The reactions, a new array (the last solve's residual if still at this u, else
            assembled afresh).
        """
        b = self._reaction
        if self.newton.copy_kept_residual(b):  # the last solve's, at this u
            with b.localForm() as loc:
                return loc.array_r.copy()
        with b.localForm() as loc:
            loc.set(0.0)
        petsc.assemble_vector(b, self._R)
        b.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
        b.ghostUpdate(PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        with b.localForm() as loc:
            return loc.array_r.copy()

    def normal_forces(self) -> np.ndarray:
        """T_n = n·(f_int − f_ext) at the S_C nodes: the residual without S_C's rows.

        Returns:
            T_n at each node of S_C (negative in compression).
        """
        return self.surface.sign * self.reactions()[self.surface.dofs_V]


@dataclass
class StatusUpdate:
    """What a status rule made of one solve: the next statuses are in the contact already."""

    changes: int  # nodes whose status changed
    settled: bool  # a fixed point: the loop ends
    state: tuple | str  # a fingerprint of the new statuses (for the cycle test)
    T_n: np.ndarray  # the solve's normal forces (the contact force, once settled)
    record: dict  # this iteration's counts, for the result's history
    summary: str  # the statuses in a few words, for the log and the messages


class _Loosened:
    """A Newton solver's tolerances raised to `tolerance` until `off()` (idempotent)."""

    def __init__(self, newton, tolerance: float | None):
        self.newton, self.on = newton, newton is not None and tolerance is not None
        if self.on:
            self.saved = test = newton.convergence
            newton.convergence = dataclasses.replace(
                test, rtol=max(test.rtol, tolerance), atol=max(test.atol, tolerance))

    def off(self) -> None:
        if self.on:
            self.newton.convergence = self.saved
            self.on = False


class ActiveSetContact:
    """The course's active-set loop over a contact surface and one formulation.

    The formulation (``elimination`` or ``multiplier``) solves one iteration for a given
    set: `set_active(active, changes)`, `solve() -> SolveResult`, `normal_forces()`.
    The loop, the set's update rules and its meshtags are written once, here.
    """

    def __init__(
        self,
        residual: ufl.Form,
        u: fem.Function,
        bcs: Sequence[fem.DirichletBC],
        facets: np.ndarray,
        gap: Callable[[np.ndarray], np.ndarray],
        *,
        normal_axis: int,
        normal_sign: int = 1,
        formulation: str = "elimination",
        initial: str = "all",
        max_it: int = 50,
        newton_options: dict | None = None,
        prefix: str = "contact_",
        displacement_space: fem.FunctionSpace | None = None,
    ):
        if formulation not in FORMULATIONS:
            raise ValueError(f"formulation must be one of {', '.join(FORMULATIONS)}, "
                             f"got {formulation!r}")
        if initial not in ("all", "none", "penetrating"):
            raise ValueError(f"initial must be all, none or penetrating, got {initial!r}")
        V = displacement_space or u.function_space
        self.u, self.formulation, self.max_it = u, formulation, max_it
        self.surface = ContactSurface(V, facets, gap, normal_axis=normal_axis,
                                      normal_sign=normal_sign,
                                      unknown_space=u.function_space)
        self.comm = self.surface.comm
        self.initial = initial
        self.active = self._initial_set(initial)
        self.force = 0.0  # total normal contact force of the last solve (compression > 0)
        opts = {"method": "full", "rtol": 1e-10, "max_it": 50, **(newton_options or {})}
        prefix += formulation[:4] + "_"  # each formulation reads its own PETSc options
        if formulation == "elimination":
            self.system = EliminationSystem(residual, u, bcs, self.surface, prefix=prefix, **opts)
        else:
            from fenics_nl.contact.multiplier import MultiplierSystem

            self.system = MultiplierSystem(residual, u, bcs, self.surface, prefix=prefix, **opts)
        self.system.set_active(self.active, None)

    def reusing_residual(self):
        """A block where the inner solves' last R(u) serves again while u stays.

        For the contact forces and the next solve's start: between inner solves only the
        conditions change (Dirichlet rows, nodal terms). `NewtonSolver`'s
        `reuse_residual_at_same_u`; nothing for the multiplier form (SNES).

        Returns:
            The context manager of that block (a null context for the multiplier form).
        """
        newton = self.newton
        return newton.reuse_residual_at_same_u() if newton else contextlib.nullcontext()

    @property
    def newton(self):
        """The Newton solver of the inner solves (None: the multiplier form's SNES)."""
        return self.system.newton if isinstance(self.system, EliminationSystem) else None

    # -- a checkpoint ------------------------------------------------------------------

    def checkpoint_arrays(self) -> dict[str, np.ndarray]:
        """What a restart needs of the contact after a converged step: the active nodes.

        Returns:
            This rank's flags of the S_C nodes (1 where active) under "active", for
            `restore_arrays`.
        """
        return {"active": self.active.astype(np.uint8)}

    def restore_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """The state of `checkpoint_arrays` back (the next solve starts from it).

        Args:
            arrays: what `checkpoint_arrays` gave.
        """
        self.active = arrays["active"].astype(bool)

    # -- the surface's quantities, for the current state --------------------------------

    @property
    def x(self) -> np.ndarray:
        """Coordinates of the S_C nodes."""
        return self.surface.x

    @property
    def owned(self) -> np.ndarray:
        """Mask of the S_C nodes this rank owns."""
        return self.surface.owned

    def normal_forces(self) -> np.ndarray:
        """Nodal normal contact forces T_n at the S_C nodes (negative in compression).

        Returns:
            T_n at each node of S_C, from the formulation's last solve.
        """
        return self.system.normal_forces()

    def normal_gap(self) -> np.ndarray:
        """u_n − γ at the S_C nodes (positive = penetration).

        Returns:
            u_n − γ at each node of S_C, for the current u and gap.
        """
        return self.surface.normal_gap(self.u)

    def pressure(self, weight=1.0) -> np.ndarray:
        """Nodal contact pressure p_j = −T_n,j / m_j (positive in compression).

        Args:
            weight: the measure's weight (2πr in the axisymmetric model).

        Returns:
            p_j at each node of S_C.
        """
        return -self.normal_forces() / self.surface.nodal_areas(weight)

    def total_force(self, T_n: np.ndarray | None = None) -> float:
        """−Σ T_n over S_C, summed over ranks (positive in compression).

        Args:
            T_n: the nodal forces (default: the last solve's).

        Returns:
            The contact force of the modelled part.
        """
        return 0.0 - self.surface.total(self.normal_forces() if T_n is None else T_n)

    def set_gap(self, gap: Callable[[np.ndarray], np.ndarray]) -> None:
        """New obstacle position (a load step); the active set is kept as a warm start.

        Args:
            gap: γ(x) for the points x (3 × n).
        """
        self.surface.set_gap(gap)  # the formulation reads γ at its next set_active

    def restart(self) -> None:
        """The initial set again, for the current gap and u (a new load path from rest)."""
        self.active = self._initial_set(self.initial)
        self.force = 0.0

    def add_penetrating(self) -> None:
        """Warm start for a new load: the current set, plus every node now penetrating."""
        self.active = self.surface.sync(self.active | (self.normal_gap() > 0))

    def fields(self, weight=1.0) -> list[fem.Function]:
        """Nodal contact pressure and active set (1/0) on S_C, to write out.

        Args:
            weight: the measure's weight (2πr in the axisymmetric model).

        Returns:
            [contact pressure, active set] as Functions on the normal component's space.
        """
        return [self.nodal_field(self.pressure(weight), "contact_pressure"),
                self.nodal_field(self.active.astype(float), "active_set")]

    def contact_areas(self, weight=1.0) -> tuple[float, float]:
        """Areas of S_C open (lifted off) and in contact, from `active_facets` (collective).

        A facet is in contact when all its vertices are active; the two add up to S_C's.

        Args:
            weight: the measure's weight (2πr in the axisymmetric model).

        Returns:
            (area open, area in contact).
        """
        ds = ufl.Measure("ds", domain=self.surface.mesh, subdomain_data=self.active_facets())
        return tuple(self.comm.allreduce(fem.assemble_scalar(fem.form(weight * ds(tag))))
                     for tag in (0, 1))

    def active_vertices(self) -> mesh.MeshTags:
        """Vertex meshtags of the active nodes (value 1).

        Returns:
            Vertex meshtags, value 1 on the active S_C nodes that are mesh vertices.
        """
        return self.surface.vertex_tags(self.active)

    def active_facets(self) -> mesh.MeshTags:
        """Facet meshtags of S_C: 1 where all the facet's vertices are active, else 0.

        Returns:
            Facet meshtags of every facet of S_C, valued 1 or 0 (what `contact_areas`
            integrates over).
        """
        return self.surface.facet_tags(self.active)

    def nodal_field(self, values: np.ndarray, name: str) -> fem.Function:
        """`values` at the S_C nodes as a function, for output.

        Args:
            values: one value per node of S_C.
            name: the Function's name.

        Returns:
            The Function (0 off S_C).
        """
        return self.surface.nodal_field(values, name)

    def _initial_set(self, initial: str) -> np.ndarray:
        n = len(self.surface.dofs_n)
        if initial == "all":  # the course's S_C^(0) = S_C
            return np.ones(n, dtype=bool)
        if initial == "none":
            return np.zeros(n, dtype=bool)
        return self.surface.sync(self.normal_gap() >= 0)

    def _unheld(self, err: SupportError, k: int) -> SupportError:
        """The free-body error, saying how many contact nodes hold the body at iteration k."""
        n = self.surface.count(self.active)
        if n:
            where = f"{n} active contact node(s) at active-set iteration {k} and the supports"
        else:
            where = (f"no contact node is active (active-set iteration {k}): contact does not "
                     "hold the body yet, and the supports")
        free = "; ".join(err.motions)
        return SupportError(
            f"{where} leave a rigid-body motion free ({free}); add a support or a symmetry "
            "condition, or hold the body by contact from the start (the obstacle touching, "
            "a prescribed displacement)", err.motions)

    # -- the loop ----------------------------------------------------------------------

    # what the loop settles (its messages), and how often a state may come back before it
    # is a cycle (the frictionless set: never)
    STATUSES, REVISITS = "active set", 1
    # the inner Newton solves' tolerances (rtol and atol) while the set is still moving
    # (None: the solver's own throughout). Only the signs of T_n and of the gap decide the
    # next set, so an iteration whose set will change need not be converged to 1e-10: once
    # the set settles, the same solve goes on to the solver's tolerance and the set is
    # checked again (the J2 punch of the identification: 158 Newton iterations a run down to
    # 115, the same active sets; 1e-6 saved 10). Friction's rules compare the slip forces
    # between solves at 1e-10: it keeps the tight solves.
    LOOSE_TOLERANCE: float | None = 1e-3

    def solve(self) -> SolveResult:
        """Run the course's loop to a fixed point of the statuses; ContactError if it cannot.

        Each iteration solves with the current statuses' conditions (`_set_conditions`),
        then lets the status rule (`_update_statuses`) set the next ones; the same loop for
        every rule (frictionless here, Coulomb in `friction`). The result counts the Newton
        iterations and the work of every inner solve, the loop's iterations, and keeps the
        last inner solve's residual history; the total contact force is left in `force`.

        Returns:
            The converged result, with the inner solves' iterations and work summed, the
            loop's iterations (`active_set_iterations`), the active set's size after each,
            and its `history`; on a failure, the ContactError's `result` instead.
        """
        t0 = time.perf_counter()
        seen = collections.Counter()
        res = SolveResult(False, self.STATUSES, 0, [], WorkCounts())
        changes = None  # nodes that changed since the last solve (None: unknown, many)
        loose = _Loosened(self.newton, self.LOOSE_TOLERANCE)
        with contextlib.ExitStack() as cleanup:
            cleanup.enter_context(self.reusing_residual())
            cleanup.callback(loose.off)
            for k in range(1, self.max_it + 1):
                self._set_conditions(changes)
                nr = self._inner_solve(k, res)
                update = self._update_statuses()
                if update.settled and loose.on:  # this set solved fully, and checked again
                    loose.off()  # (every later solve is full)
                    nr = self._inner_solve(k, res, nr.iterations)
                    update = self._update_statuses()
                changes = update.changes
                res.active_set_iterations = k
                res.active_sizes = [*res.active_sizes, self.surface.count(self.active)]
                res.history.append({**update.record, "newton_iterations": nr.iterations})
                log.info("%s iteration %d: %s, %d changes", self.STATUSES, k, update.summary,
                         changes)
                if update.settled:
                    self.force = self.total_force(update.T_n)
                    res.converged, res.reason = True, f"{self.STATUSES} fixed"
                    res.wall_time = time.perf_counter() - t0
                    return res
                if changes:
                    seen[update.state] += 1
                    if seen[update.state] > self.REVISITS and loose.on:
                        loose.off()  # loose solves may have led it round: full ones decide
                        seen.clear()
                    elif seen[update.state] > self.REVISITS:
                        raise ContactError(f"{self.STATUSES} cycles (iteration {k}: "
                                           f"{update.summary})", res)
        raise ContactError(f"{self.STATUSES} did not settle in {self.max_it} "
                           "iterations", res)

    def _inner_solve(self, k: int, res: SolveResult, before: int = 0) -> SolveResult:
        """One solve with the current conditions, counted into `res`.

        `before`: Newton iterations of this active-set iteration already counted, added to
        the returned result's (its history records the iteration's total).
        """
        try:
            nr = self.system.solve()
        except SupportError as err:
            raise self._unheld(err, k) from None
        except SolveError as err:  # the loop's work so far goes with it (the driver counts it)
            spent = getattr(err, "result", None)
            if spent is not None:
                res.iterations += spent.iterations
                res.work.add(spent.work)
            err.result = res
            raise
        res.iterations += nr.iterations
        res.work.add(nr.work)
        res.residual_norms = nr.residual_norms
        nr.iterations += before
        return nr

    def _set_conditions(self, changes: int | None) -> None:
        """The next solve's conditions from the statuses: u_n = γ on the active nodes."""
        self.system.set_active(self.active, changes)

    def _update_statuses(self) -> StatusUpdate:
        """The frictionless rule: leave where T_n > 0, join where u_n > γ."""
        S = self.surface
        T_n, d = self.normal_forces(), self.normal_gap()
        # thresholds from the problem's own scales: the largest contact force, and the
        # obstacle's gap or the motion itself
        scale_T = global_max(self.comm, np.abs(T_n))
        scale_u = max(global_max(self.comm, np.abs(S.gamma)), S.displacement_scale(self.u))
        leave = self.active & (T_n > 1e-10 * scale_T)
        join = ~self.active & (d > 1e-10 * scale_u)
        new = S.sync((self.active & ~leave) | join)
        changes = S.count(new != self.active)
        n_active = S.count(new)
        self.active = new
        return StatusUpdate(changes, changes == 0, S.fingerprint(new), T_n,
                            {"active": n_active, "left": S.count(leave),
                             "joined": S.count(join)}, f"{n_active} active nodes")
