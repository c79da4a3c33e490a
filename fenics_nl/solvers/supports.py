"""Are the supports enough? The rigid-body motions a tangent leaves free, found and named.

A body that nothing holds in some direction has a singular stiffness. A direct solver may
still factorize it (MUMPS returns a solution with an arbitrary rigid motion added) and
Newton then converges to a wrong answer, or it fails step after step without saying why.
The test here is the same for every solver path (direct or iterative, our Newton or SNES):

1. *Kinematic*: the rigid motions r = t + ω × (x − c) that vanish on every constrained dof
   (the Dirichlet rows, active contact nodes included) are the null space of a small Gram
   matrix (3 × 3 in 2D, 6 × 6 in 3D), each mode scaled to unit norm: dimensionless, so the
   decision does not depend on the units.
2. *Energetic*: such a motion is free only if the assembled tangent does not resist it,
   ‖K r‖ ≤ 1e-10 ‖r‖ max|K_ii|, the diagonal over the displacement rows (an elastic K
   gives round-off, ~1e-15; springs, a penalty or a saddle point's constraint rows give
   far more, also when they act on few of many dofs: a spring k on n_b of N dofs gives
   ~(k/K_ii)(n_b/N)^½). This keeps out what holds a body
   without a Dirichlet row, and the modes that are not motions of the model (a radial
   translation in the axisymmetric model strains the hoops).

A tangent singular at a limit point or a bifurcation is not flagged: its null vector is a
deformation, not a rigid motion (the arc-length driver and the buckling analysis treat it).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from fenics_nl.errors import SupportError

__all__ = ["RigidMotions", "check_supports", "constrained_dofs", "free_motions"]

KINEMATIC_TOL = 1e-10  # normalized Gram eigenvalue of a motion the constraints do not touch
ENERGY_TOL = 1e-10  # ‖K r‖ / (‖r‖ max|K_ii|) of a motion the tangent does not resist
AXES = "xyz"


class RigidMotions:
    """The rigid motions of a displacement (sub-)space, in the unknown's vector layout.

    `V` is the unknown's space; `sub` the displacement sub-space of a mixed unknown (the
    modes are zero on the other fields). Translations along each axis, then rotations
    about each axis through the body's centroid, divided by its size L: every column has
    the units of a length, so their combinations mean something.
    """

    def __init__(self, V: fem.FunctionSpace, sub: fem.FunctionSpace | None = None):
        from fenics_nl.materials.mixed import collapsed

        comm = V.mesh.comm
        self.comm = comm
        self.gdim = gdim = V.mesh.geometry.dim
        n_owned = V.dofmap.index_map.size_local * V.dofmap.index_map_bs
        if sub is None:
            space, dofs = V, np.arange(n_owned, dtype=np.int32)
        else:
            space, dofs = collapsed(sub)
        bs = space.dofmap.index_map_bs
        nodes = space.dofmap.index_map.size_local
        x = space.tabulate_dof_coordinates()[:nodes, :gdim]
        dofs = dofs[: nodes * bs].reshape(nodes, bs)  # owned nodes' dofs in V's numbering
        count = comm.allreduce(len(x))
        self.centre = comm.allreduce(x.sum(axis=0)) / max(count, 1)
        lo, hi = x.min(axis=0, initial=np.inf), x.max(axis=0, initial=-np.inf)
        comm.Allreduce(MPI.IN_PLACE, lo, op=MPI.MIN)
        comm.Allreduce(MPI.IN_PLACE, hi, op=MPI.MAX)
        self.size = float(np.max(hi - lo)) or 1.0
        y = x - self.centre
        # (nodes, gdim) field of each mode
        fields = [np.tile(np.eye(gdim)[i], (len(x), 1)) for i in range(gdim)]
        self.rotation_axes = [2] if gdim == 2 else [0, 1, 2]
        for axis in self.rotation_axes:
            w = np.zeros(3)
            w[axis] = 1.0
            y3 = np.zeros((len(x), 3))
            y3[:, :gdim] = y
            fields.append(np.cross(w, y3)[:, :gdim] / self.size)
        self.modes = np.zeros((n_owned, len(fields)))  # columns, owned rows of V
        for k, f in enumerate(fields):
            self.modes[dofs, k] = f[:, :bs]
        self.n_owned = n_owned

    @classmethod
    def of(cls, V: fem.FunctionSpace) -> RigidMotions | None:
        """The rigid motions of a displacement unknown, plain or mixed (its sub-space 0).

        Args:
            V: the unknown's function space.

        Returns:
            Its rigid motions, or None for an unknown that is not a displacement (a scalar
            field).
        """
        gdim = V.mesh.geometry.dim
        if V.ufl_element().is_mixed:
            sub = V.sub(0)
            return cls(V, sub) if sub.dofmap.index_map_bs == gdim or \
                sub.element.num_sub_elements == gdim else None
        return cls(V) if V.dofmap.index_map_bs == gdim and gdim > 1 else None

    def unconstrained(self, constrained: np.ndarray) -> np.ndarray:
        """Columns (combinations of the modes) that vanish on the `constrained` owned dofs.

        Args:
            constrained: the owned local dofs (unrolled) the Dirichlet rows hold.

        Returns:
            The combinations in the modes' coefficients, one column each (an orthonormal
            basis of the null space of the normalized Gram matrix of the constrained rows).
        """
        T = self.modes
        full = self.comm.allreduce(T.T @ T)
        held = T[constrained]
        gram = self.comm.allreduce(held.T @ held)
        scale = 1 / np.sqrt(np.diag(full))
        values, vectors = np.linalg.eigh(scale[:, None] * gram * scale[None, :])
        return scale[:, None] * vectors[:, values < KINEMATIC_TOL]

    def canonical(self, free: np.ndarray) -> list[np.ndarray]:
        """A basis of the span of `free` (mode coefficients) made of the simplest motions.

        Translations along an axis first, then rotations about an axis (through whatever
        point the span gives), then whatever is left.

        Args:
            free: the motions' mode coefficients, one column each (as from `unconstrained`).

        Returns:
            The basis, one coefficient vector per column of `free`.
        """
        if free.shape[1] == 0:
            return []
        basis, span = [], free
        simple = [np.eye(len(free))[i] for i in range(self.gdim)]  # translations
        for j in range(len(self.rotation_axes)):  # a rotation about axis j, any translation
            rot = span[self.gdim:]
            a, *_ = np.linalg.lstsq(rot, np.eye(len(self.rotation_axes))[j], rcond=None)
            if np.linalg.norm(rot @ a - np.eye(len(self.rotation_axes))[j]) < 1e-6:
                simple.append(span @ a)
        for c in simple:
            a, *_ = np.linalg.lstsq(span, c, rcond=None)
            inside = np.linalg.norm(span @ a - c) < 1e-6 * np.linalg.norm(c)
            independent = np.linalg.matrix_rank(np.column_stack([*basis, c]), 1e-6) \
                > len(basis)
            if inside and independent:
                basis.append(c)
        for c in free.T:  # what no simple motion spans
            if np.linalg.matrix_rank(np.column_stack([*basis, c]), 1e-6) > len(basis):
                basis.append(c)
        return basis[: free.shape[1]]

    def describe(self, coefficients: np.ndarray) -> str:
        """A free motion in words: 'translation along y', 'rotation about z through (..)'.

        Args:
            coefficients: the motion's mode coefficients.

        Returns:
            The motion in words.
        """
        gdim = self.gdim
        t = np.zeros(3)
        t[:gdim] = coefficients[:gdim]
        w = np.zeros(3)
        w[self.rotation_axes] = coefficients[gdim:] / self.size
        if np.linalg.norm(w) * self.size < 1e-6 * np.linalg.norm(t):
            return f"translation along {_direction(t)}"
        point = self.centre.copy() if gdim == 3 else np.append(self.centre, 0.0)
        point = point + np.cross(w, t) / (w @ w)  # the axis: t = −ω × (p − c)
        point[np.abs(point) < 1e-9 * self.size] = 0.0  # round-off of the body's size: 0
        where = ", ".join(f"{v:.4g}" for v in point[:gdim])
        return f"rotation about {_direction(w)} through ({where})"


def _direction(v: np.ndarray) -> str:
    """'x' for an axis, else the unit vector."""
    v = v / np.linalg.norm(v)
    k = int(np.argmax(np.abs(v)))
    if abs(abs(v[k]) - 1) < 1e-6:
        return AXES[k]
    return "(" + ", ".join(f"{c:.3g}" for c in v) + ")"


def constrained_dofs(bcs: Sequence[fem.DirichletBC]) -> np.ndarray:
    """The owned local dofs (unrolled) that a Dirichlet condition holds.

    Args:
        bcs: the Dirichlet conditions.

    Returns:
        Their owned local dofs, sorted, each once.
    """
    rows = [bc.dof_indices()[0][: bc.dof_indices()[1]] for bc in bcs]
    return np.unique(np.concatenate(rows)) if rows else np.zeros(0, dtype=np.int32)


def free_motions(A: PETSc.Mat, motions: RigidMotions, bcs: Sequence[fem.DirichletBC]
                 ) -> list[str]:
    """The rigid motions that neither the Dirichlet rows of `bcs` nor `A` resist, named.

    Collective.

    Args:
        A: the tangent K as assembled, with the Dirichlet rows set to the identity, or
            without them: its Dirichlet rows and columns are not read.
        motions: the unknown's rigid motions.
        bcs: the Dirichlet conditions.

    Returns:
        Each free motion in words (`RigidMotions.describe`); empty if the body is held.
    """
    held = constrained_dofs(bcs)
    C = motions.unconstrained(held)
    if C.shape[1] == 0:
        return []
    comm = motions.comm
    T = motions.modes
    # an orthonormal basis of the candidate motions (in the dofs' Euclidean metric)
    values, vectors = np.linalg.eigh(comm.allreduce((T @ C).T @ (T @ C)))
    C = C @ vectors / np.sqrt(values)
    diag = A.getDiagonal()
    d = np.abs(diag.array_r[: motions.n_owned]).copy()
    d[held] = 0.0
    d[~np.any(T != 0, axis=1)] = 0.0  # displacement rows only: a pressure's are other units
    stiffness = comm.allreduce(float(d.max(initial=0.0)), op=MPI.MAX)
    r, Kr = A.createVecRight(), A.createVecLeft()
    KR = np.zeros((motions.n_owned, C.shape[1]))
    for k in range(C.shape[1]):
        r.array[:] = T @ C[:, k]
        r.array[held] = 0.0  # (≈ 0 already): the Dirichlet columns are not read either
        A.mult(r, Kr)
        KR[:, k] = Kr.array_r[: motions.n_owned]
    KR[held] = 0.0  # A's identity rows or K's own: the same P K P r either way
    for v in (diag, r, Kr):
        v.destroy()
    # the combinations of the candidates that K does not resist: ‖K r‖ ≤ tol max|K_ii| ‖r‖
    values, vectors = np.linalg.eigh(comm.allreduce(KR.T @ KR))
    free = C @ vectors[:, values <= (ENERGY_TOL * stiffness) ** 2]
    return [motions.describe(c) for c in motions.canonical(free)]


def check_supports(A: PETSc.Mat, motions: RigidMotions, bcs: Sequence[fem.DirichletBC],
                   context: str = "") -> None:
    """Raise SupportError naming every free rigid motion of the tangent `A` (collective).

    Args:
        A: the tangent K, as for `free_motions`.
        motions: the unknown's rigid motions.
        bcs: the Dirichlet conditions.
        context: added to the message (e.g. that contact does not hold the body yet).

    Raises:
        SupportError: if a rigid motion is free.
    """
    free = free_motions(A, motions, bcs)
    if free:
        raise SupportError(
            f"the supports leave a rigid-body motion free ({'; '.join(free)}): the stiffness "
            "is singular and the answer would be arbitrary; hold it with a support or a "
            f"symmetry condition{context}", free)
