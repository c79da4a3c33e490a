"""Coulomb friction on the active set: each node of S_C is open, sticking or slipping.

The course's law on the effective contact zone: T_t < f |T_n| sticks, T_t = f |T_n| slips,
T_t = ‖T − T_n n‖. Loading is quasi-static and incremental: within a step the rigid
obstacle moves tangentially by Δd (`set_motion`), and a node's slip increment is
Δg = Δu_t − Δd, its tangential displacement since the last committed state less the
obstacle's. Each iteration solves (elimination) with

* open nodes free;
* sticking nodes: u_n = γ and Δg = 0 (all their components are Dirichlet rows);
* slipping nodes: u_n = γ and the tangential nodal force f |T_n| s, s the unit direction of
  the friction force on the body (`NewtonSolver.nodal`, `solvers.nodal`), T_n from the last solve;

then updates the statuses by the course's rules, extended to friction:

* a closed node in tension (T_n > 0) opens; an open node that penetrates closes;
* a sticking node whose tangential reaction exceeds f |T_n| slips, s along that reaction;
* a slipping node whose slip increment goes along its friction force (Δg·s > 0, the
  friction would drive it) sticks;
* a node that touches down within the step joins slipping (it cannot stick where it was at
  the step's start), its friction against the way it moved in the step before it touched
  (s = −Δg/|Δg|, a guess: the next solve, in contact, gives s again, which must agree
  before the loop ends), or without friction until its first slip gives s if it had not
  moved;

In 3D the direction s of a slipping node is a unit vector, which the loop finds by Newton's
method rather than by substitution (s ← −Δg/|Δg| chatters): the node carries f |T_n| s
and a spring k (I − s sᵀ) against slip across s, k = f |T_n|/(−Δg·s) from the last
iterate (`NodalTerms.set_springs`), the linearization of −f |T_n| Δg/|Δg|; s then
turns to the node's total tangential force, and at the fixed point the slip is along −s.

The loop is `ActiveSetContact`'s, with this status rule (`_update_statuses`) and these
conditions (`_set_conditions`); it stops when no status changes and the friction forces
agree with the normal forces of the same solve. The slip history lives in the committed
tangential displacement; the driver commits it after a converged step (`commit`) or goes
back to it (`restore`).
"""

from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI

from fenics_nl.contact.active_set import ActiveSetContact, StatusUpdate
from fenics_nl.errors import SolveError
from fenics_nl.parallel import gather_rows, global_max

__all__ = ["FrictionalContact"]


class FrictionalContact(ActiveSetContact):
    """The active-set loop with Coulomb friction (coefficient `friction`), elimination only.

    Statuses: `active` (closed nodes, as in the frictionless loop) and `slip` (closed
    nodes that slip); `stick` = active and not slip. Everything else is ActiveSetContact's.
    """

    LOOSE_TOLERANCE = None  # the slip forces' settling is judged at 1e-10: tight solves

    # a status set may come back while the friction forces still move (they follow the
    # normal forces of the last solve); its third visit is a cycle
    STATUSES, REVISITS = "statuses", 2

    def __init__(self, *args, friction: float, consistent: bool | None = None,
                 sense_at_touchdown: bool = True, **kwargs):
        if not (math.isfinite(friction) and friction >= 0):
            raise ValueError(f"the friction coefficient must be a finite number >= 0, got "
                             f"{friction}")
        if kwargs.get("formulation", "elimination") != "elimination":
            raise ValueError("friction is written for the elimination formulation "
                             "(--formulation elimination)")
        super().__init__(*args, **kwargs)
        self.f = float(friction)
        # the slip forces follow T_n inside Newton (row couplings) where the tangent is
        # rebuilt anyway (a non-linear material); a linear one's iterations keep its
        # factorization with point forces from the last solve's T_n
        if consistent is None:
            consistent = not self.newton.linear
        self.consistent = bool(consistent) and self.newton.allow_unsymmetric()
        self.fallbacks = 0  # consistent steps taken again with point forces
        # False: a node touching down has no friction until its first slip (the rule before
        # the sense from its motion; kept to compare, benchmarks/forming.py)
        self.sense_at_touchdown = bool(sense_at_touchdown)
        S = self.surface
        self.axes = S.tangential_axes
        n, m = len(S.dofs_n), len(self.axes)
        self.slip = np.zeros(n, dtype=bool)
        self.direction = np.zeros((n, m))  # s: the friction force's direction on the body
        self.slip_force = np.zeros((n, m))
        # 3D: the stiffness k of a slipping node against slip across its force's direction
        self.spring = np.zeros(n)
        self._touched = np.zeros(n, dtype=bool)  # joined with a touchdown sense, last update
        self.motion = np.zeros(m)  # the obstacle's tangential displacement d
        # a component the body's own supports hold (a symmetry plane, the axis) is no
        # friction's: its reaction is the support's
        held = np.zeros(self.u.x.array.size, dtype=bool)
        for bc in self.system.bcs:
            held[bc.dof_indices()[0]] = True
        self.free = np.column_stack([~held[S.tangential(i)[0]] for i in self.axes])
        self.commit()

    # -- state -------------------------------------------------------------------------

    @property
    def stick(self) -> np.ndarray:
        """Mask of the sticking nodes."""
        return self.active & ~self.slip

    def _state(self):
        return (self.active.copy(), self.slip.copy(), self.direction.copy(),
                self.slip_force.copy(), self.spring.copy())

    def _set_state(self, state) -> None:
        """The statuses, directions, slip forces and springs of `_state()` back (copies)."""
        self.active, self.slip, self.direction, self.slip_force, self.spring = (
            a.copy() for a in state)
        self._touched = np.zeros_like(self.active)

    def commit(self) -> None:
        """The current state becomes the start of the next step's increments."""
        self._committed = self._state()
        self._u_t_committed = self.tangential_displacement()
        self.committed_motion = self.motion.copy()
        self.committed_tangential_force = self.tangential_force()

    def restore(self) -> None:
        """Back to the last committed statuses and obstacle position (after a failed step).

        The displacement is the caller's to restore (the driver keeps it).
        """
        self._set_state(self._committed)
        self.motion = self.committed_motion.copy()

    def checkpoint_arrays(self) -> dict[str, np.ndarray]:
        """What the next step's increments start from: the committed state.

        The statuses, slip directions and forces, the obstacle's position and the
        tangential force.

        Returns:
            The committed arrays by name (this rank's nodes of S_C; the statuses as 1/0),
            for `restore_arrays`.
        """
        active, slip, direction, slip_force, spring = self._committed
        return {"active": active.astype(np.uint8), "slip": slip.astype(np.uint8),
                "direction": direction, "slip_force": slip_force, "spring": spring,
                "motion": self.committed_motion,
                "tangential_force": self.committed_tangential_force}

    def restore_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """The state of `checkpoint_arrays` back, committed (u is the caller's, restored).

        Args:
            arrays: what `checkpoint_arrays` gave.
        """
        self.active, self.slip = arrays["active"].astype(bool), arrays["slip"].astype(bool)
        self.direction = arrays["direction"].copy()
        self.slip_force = arrays["slip_force"].copy()
        self.spring = arrays["spring"].copy()
        self.motion = arrays["motion"].copy()
        self._committed = self._state()
        self._u_t_committed = self.tangential_displacement()
        self.committed_motion = self.motion.copy()
        self.committed_tangential_force = arrays["tangential_force"].copy()

    def set_motion(self, d) -> None:
        """The obstacle's tangential displacement d (one value per tangential axis).

        Args:
            d: the obstacle's displacement along each tangential axis, from the start.
        """
        self.motion = np.asarray(d, dtype=float).reshape(len(self.axes))

    # -- the surface's tangential quantities ------------------------------------------

    def tangential_displacement(self) -> np.ndarray:
        """u_t at the nodes, one column per tangential axis.

        Returns:
            u_t at each node of S_C, read off the current u.
        """
        x = self.u.x.array
        return np.column_stack([x[self.surface.tangential(i)[0]] for i in self.axes])

    def tangential_forces(self, reactions: np.ndarray | None = None) -> np.ndarray:
        """T_t at the nodes (the obstacle's force on the body), one column per axis.

        Zero in a component the body's supports hold.

        Args:
            reactions: the residual's local array, if already assembled
                (`EliminationSystem.reactions`; else it is assembled).

        Returns:
            T_t at each node of S_C, one column per tangential axis.
        """
        r = self.system.reactions() if reactions is None else reactions
        return self.free * np.column_stack([r[self.surface.tangential(i)[0]]
                                            for i in self.axes])

    def slip_increment(self) -> np.ndarray:
        """Δg = Δu_t − Δd since the last committed state, at the nodes (0 where held).

        Returns:
            Δg at each node of S_C, one column per tangential axis.
        """
        return self.free * (self.tangential_displacement() - self._u_t_committed
                            - (self.motion - self.committed_motion))

    def tangential_force(self) -> np.ndarray:
        """Σ T_t over S_C (every rank's owned nodes), one value per axis.

        Returns:
            The tangential force of the modelled part, the same on every rank (collective).
        """
        T_t = self.tangential_forces()
        return np.array([self.surface.total(T_t[:, k]) for k in range(len(self.axes))])

    def force_within(self, distance: np.ndarray, radii) -> np.ndarray:
        """Q(r): the tangential force along the first tangential axis inside each radius.

        A sum of the nodal forces T_t of the S_C nodes at most r from an axis (every rank's
        owned nodes).

        Args:
            distance: each S_C node's distance from the axis.
            radii: the radii r.

        Returns:
            Q(r) for each r, of the modelled part.
        """
        T_x = np.where(self.owned, self.tangential_forces()[:, 0], 0.0)
        inside = np.array([T_x[distance <= r].sum() for r in radii])
        return self.comm.allreduce(inside, op=MPI.SUM)

    def traction_profile(self, weight=1.0, on: np.ndarray | None = None):
        """(x, p, q, status) of the S_C nodes `on`, gathered on rank 0 and sorted by x.

        Args:
            weight: the measure's weight (2πr in the axisymmetric model).
            on: a mask of the nodes (default all); this rank's owned ones are taken.

        Returns:
            On rank 0, the first coordinate x, the contact pressure p, the tangential
            traction q along the first tangential axis (nodal forces over nodal areas) and
            the status (0 open, 1 stick, 2 slip) of each node; None on the other ranks.
        """
        on = self.owned if on is None else self.owned & on
        areas = self.surface.nodal_areas(weight)
        status = np.where(self.slip, 2, np.where(self.active, 1, 0))
        rows = gather_rows(self.comm, self.x[on, 0], self.pressure(weight)[on],
                           (self.tangential_forces()[:, 0] / areas)[on], status[on])
        if rows is None:
            return None
        order = np.argsort(rows[0])
        return tuple(r[order] for r in rows)

    # -- the loop, consistent or not ---------------------------------------------------

    def solve(self):
        """The loop (`ActiveSetContact.solve`); if a consistent one fails, with point forces.

        The consistent tangent is not symmetric, and near singular where a slipping node's
        normal and tangential stiffnesses couple strongly (a plastic billet at finite
        strain): Newton then diverges. The step is taken again from where it began with
        point forces from the last solve's T_n (the fixed point, slower, robust) rather than
        cut; its iterations count the failed attempt's, and `fallbacks` counts these steps.
        """
        if not self.consistent:
            return super().solve()
        u0, state = self.u.x.array.copy(), self._state()
        try:
            return super().solve()
        except SolveError as err:
            spent = getattr(err, "result", None)
            self.u.x.array[:] = u0
            self._set_state(state)
            self.newton.nodal.set_couplings(np.zeros(0), np.zeros(0), np.zeros(0))
            self.fallbacks += 1
            self.consistent = False
            try:
                res = super().solve()
            except SolveError as again:  # both failed: the driver counts both
                if spent is not None and getattr(again, "result", None) is not None:
                    again.result.iterations += spent.iterations
                    again.result.work.add(spent.work)
                raise
            finally:
                self.consistent = True
                self.newton.nodal.set_load(np.zeros(0), np.zeros(0))
            if spent is not None:
                res.iterations += spent.iterations
                res.work.add(spent.work)
            res.history.insert(0, {"point_forces_after": str(err).split(";")[0]})
            return res

    # -- one iteration's conditions ---------------------------------------------------

    def _set_conditions(self, changes: int | None) -> None:
        S, stick = self.surface, self.stick
        target = self._u_t_committed + (self.motion - self.committed_motion)
        sticking = [S.tangential_dirichlet(i, stick & self.free[:, k], target[:, k])
                    for k, i in enumerate(self.axes)]
        self.system.set_active(self.active, changes, extra_bcs=sticking)
        loaded = [S.owned & self.slip & self.free[:, k] for k in range(len(self.axes))]
        dofs = [S.tangential(i)[0][on] for i, on in zip(self.axes, loaded, strict=True)]
        if self.consistent:
            # the friction force f |T_n| s with T_n = sign R_n, its normal dof's reaction
            # in Newton's own iteration: R_t − f (−sign R_n) s_t, a row coupling
            sources = np.concatenate([S.dofs_V[on] for on in loaded])
            c = np.concatenate([self.f * S.sign * self.direction[on, k]
                                for k, on in enumerate(loaded)])
            self.newton.nodal.set_couplings(np.concatenate(dofs), sources, c)
        else:  # a point force from the last solve's T_n
            values = np.concatenate([self.slip_force[on, k] for k, on in enumerate(loaded)])
            self.newton.nodal.set_load(np.concatenate(dofs), values)
        if len(self.axes) > 1:
            self._set_springs(target)

    def _set_springs(self, target: np.ndarray) -> None:
        """3D: k (I − s sᵀ) at each slipping node, against slip across its force.

        The force f|T_n| s with s = −Δg/|Δg| linearized in Δg (Newton on the direction)
        is f|T_n| s − k (I − s sᵀ) Δg with k = f|T_n|/(−Δg·s) (= f|T_n|/|Δg| at the fixed
        point), from the last iterate.
        """
        S = self.surface
        on = S.owned & self.slip & (self.spring > 0)
        s = self.direction[on]
        k = self.spring[on, None, None] * (np.eye(len(self.axes)) - s[:, :, None] * s[:, None, :])
        free = self.free[on]
        k *= free[:, :, None] * free[:, None, :]  # no spring on a component a support holds
        dofs = np.column_stack([S.tangential(i)[0][on] for i in self.axes])
        self.newton.nodal.set_springs(dofs, k, target[on])

    # -- the loop ----------------------------------------------------------------------

    @staticmethod
    def _against(g: np.ndarray, tol: float) -> np.ndarray:
        """−g/|g| for each row of `g`: a friction force's direction against that motion.

        None (0) where |g| ≤ `tol`.
        """
        moved = np.linalg.norm(g, axis=1)[:, None]
        return np.where(moved > tol, -g / np.where(moved > tol, moved, 1.0), 0.0)

    def _update_statuses(self) -> StatusUpdate:
        """Coulomb's rule on one solve: open/close as frictionless, stick/slip by |T_t| ≤ f|T_n|.

        Settled when no status changed and the slip forces stopped moving.
        """
        S = self.surface
        r = self.system.reactions()  # T_n and T_t from the last solve's R(u)
        T_n, T_t, g = S.sign * r[S.dofs_V], self.tangential_forces(r), self.slip_increment()
        scale_T = global_max(self.comm, np.abs(T_n))
        # lengths of the state itself (not the far gap, which grows with the block): the
        # body's motion and the obstacle's move in this step
        step = float(np.abs(self.motion - self.committed_motion).max(initial=0.0))
        tol_T, tol_u = 1e-10 * scale_T, 1e-10 * max(S.displacement_scale(self.u), step)
        bound = self.f * np.maximum(-T_n, 0.0)
        size = np.linalg.norm(T_t, axis=1)
        leave = self.active & (T_n > tol_T)
        join = ~self.active & (self.normal_gap() > tol_u)
        to_slip = self.stick & ~leave & (size > bound + tol_T)
        # the friction forces the solve had: consistent, they followed its own T_n
        # (`_set_conditions`); else they were the last solve's
        solved = np.where(self.slip[:, None], bound[:, None] * self.direction, 0.0) \
            if self.consistent else self.slip_force
        # (a node that slipped with no friction force, f = 0 or T_n = 0, has no reason to)
        back = (self.slip & ~leave & (np.linalg.norm(solved, axis=1) > tol_T)
                & (np.sum(g * self.direction, axis=1) > tol_u))
        active = S.sync((self.active & ~leave) | join)
        # a node touching down within the step cannot stick where it was at the step's
        # start: it joins slipping, against the way it moved in the step (a guess of the
        # slip it goes on with, which the next update takes again from a solve in contact)
        slip = S.sync(((self.slip & ~back) | to_slip | join) & active)
        direction = self.direction.copy()
        sensed = np.any(direction, axis=1)  # slipping nodes that have a sense already
        direction[to_slip] = T_t[to_slip] / size[to_slip, None]
        slid = np.linalg.norm(g, axis=1)
        direction[join] = 0.0
        if self.sense_at_touchdown:  # (a motion at round-off gives no sense)
            direction[join] = self._against(
                g[join], max(tol_u, 1e-6 * global_max(self.comm, slid)))
        # a first sense, from a solve in contact; a touched-down node's is taken again
        # (its guess was from before the contact: what changes it drives another solve)
        first = slip & self.slip & (~sensed | self._touched) & (slid > tol_u)
        direction[first] = self._against(g[first], tol_u)
        spring = np.zeros_like(self.spring)
        if len(self.axes) > 1:  # 3D: the force turns with the spring's share
            kept = slip & self.slip & sensed & ~self._touched & (size > tol_T)
            direction[kept] = T_t[kept] / size[kept, None]
            along = -np.sum(g * direction, axis=1)
            # a node that barely slides (below 1e-6 of the largest slip) gets no spring:
            # k = f|T_n|/slip would amplify round-off in u into the residual
            floor = 1e-6 * global_max(self.comm, np.where(kept, along, 0.0))
            moving = kept & (along > max(tol_u, floor))
            spring[moving] = bound[moving] / along[moving]
        slip_force = np.where(slip[:, None], bound[:, None] * direction, 0.0)
        # consistent: what moves the friction forces is a new direction (a first sense, or
        # one turning in 3D); else they follow T_n from solve to solve
        drift = global_max(self.comm, np.abs(slip_force - solved))
        changes = S.count(active != self.active) + S.count(slip != self.slip)
        n_slip, n_stick = S.count(slip), S.count(active & ~slip)
        self.active, self.slip, self.direction = active, slip, direction
        self.slip_force, self.spring = slip_force, spring
        self._touched = join & slip & np.any(direction, axis=1)
        # a state: the closed set, the slipping set and its slip senses
        state = (S.fingerprint(active), S.fingerprint(slip),
                 S.fingerprint(slip & (direction[:, 0] > 0)))
        record = {"stick": n_stick, "slip": n_slip, "changes": changes,
                  "to_slip": S.count(to_slip), "to_stick": S.count(back),
                  "opened": S.count(leave), "closed": S.count(join),
                  "friction_force_change": drift}
        settled = changes == 0 and drift <= 1e-9 * self.f * scale_T
        return StatusUpdate(changes, settled, state, T_n, record,
                            f"{n_stick} stick, {n_slip} slip, friction force change "
                            f"{drift:.3e}")
