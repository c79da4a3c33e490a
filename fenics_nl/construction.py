"""Construction stages: cell groups that leave (excavation) and arrive (a wall, a strut).

One mesh holds every stage. Each *part* (the cells of one law: "soil", "wall") has a
presence indicator χ_p (DG0, 1 where the part is present), and the residual is written
with them (the demo writes it: `demos/excavation.py`):

    R(u; v) = Σ_p ∫ χ_p σ_p : ε(v) − Σ_p ∫ χ_p (1 − α (1 − s)) γ_p b · v
              + (1 − s) ∫ λ (σ_left : ε(v) − γ_left b · v),

s ∈ [0, 1] the stage's progress, b the unit body force (down), α (DG0) the cells arriving
this stage, λ (DG0) the cells leaving it. A stage begins at equilibrium: the leaving cells'
stress σ_left (at the quadrature points) and weight γ_left are frozen and their forces on
the rest are applied as loads, released as s goes from 0 to 1 (the same end state whatever
the number of steps, for a path-independent law); an arriving part's weight comes in with
s, and its strain is measured from the state it arrives in (`arrival_strain`: stress-free
when it arrives). The degrees of freedom no present cell touches are held where they are
(`held`): the removed soil's nodes, a wall's before it is built.

The residual is 0 at a stage's start (the frozen forces balance what the leaving cells
did), and at its end the vertical reactions are the weight of what is present, to
round-off (the internal forces of any cell are self-equilibrated: a check that the stage
converged and was released whole, not of the frozen stress itself).
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem, la

from fenics_nl.expression import Expression
from fenics_nl.materials.plasticity import quadrature_spaces

__all__ = ["Construction"]


class Construction:
    """The parts present at each stage, and the fields the staged residual reads.

    Args:
        V: the displacement's space.
        cell_tags: the mesh's cell tags (meshtags).
        parts: each part's cell tags (a tag may be in two parts: soil where the wall will
            be, then the wall).
        weights: each part's unit weight γ_p (0 if left out).
        absent: each part's tags absent at the start (a wall not yet built).
        degree: the quadrature degree of the residual.
    """

    def __init__(self, V, cell_tags, parts: dict[str, list[int]],
                 weights: dict[str, float] | None = None,
                 absent: dict[str, list[int]] | None = None, degree: int = 2):
        self.V, self.cell_tags, self.parts = V, cell_tags, dict(parts)
        self.weights = {p: float((weights or {}).get(p, 0.0)) for p in parts}
        msh = V.mesh
        D0 = fem.functionspace(msh, ("DG", 0))
        self._cell_dof = D0.dofmap.list[:, 0]

        def indicator(name):
            return fem.Function(D0, name=name)

        self.present = {p: indicator(f"present_{p}") for p in parts}
        self.arriving, self.leaving = indicator("arriving"), indicator("leaving")
        self.left_weight = indicator("left_weight")
        self.progress = fem.Constant(msh, 0.0)
        tensors, _ = quadrature_spaces(msh, degree)
        self.left_stress = fem.Function(tensors, name="left_stress")
        self.arrival_strain = fem.Function(tensors, name="arrival_strain")
        self.stage = None  # the running stage's name
        for p, tags in parts.items():
            gone = set((absent or {}).get(p, ()))
            self._set(self.present[p], [t for t in tags if t not in gone], 1.0)
        self._one_part_a_cell()

    def _cells(self, tags) -> np.ndarray:
        found = [self.cell_tags.find(t) for t in tags]
        return np.unique(np.concatenate(found)) if found else np.zeros(0, np.int32)

    def _set(self, f, tags, value) -> None:
        f.x.array[self._cell_dof[self._cells(tags)]] = value
        f.x.scatter_forward()

    def body_force(self, part: str, down):
        """γ_p (1 − α (1 − s)) χ_p b: the part's weight as present (an arriving part's with s).

        Args:
            part: the part's name.
            down: the unit body force b (UFL vector, e.g. (0, −1)).
        """
        ramp = 1 - self.arriving * (1 - self.progress)
        return self.weights[part] * self.present[part] * ramp * down

    def released(self, v, down, strain):
        """(1 − s) λ (σ_left : ε(v) − γ_left b · v): the leaving cells' forces, let go with s.

        Args:
            v: the test function.
            down: the unit body force b (UFL vector).
            strain: ε(v) (UFL, 3x3, the model's).
        """
        return (1 - self.progress) * self.leaving * (
            ufl.inner(self.left_stress, strain) - self.left_weight * ufl.dot(down, v))

    def begin(self, name: str, remove: dict[str, list[int]] | None = None,
              add: dict[str, list[int]] | None = None, stresses=None, strain=None) -> None:
        """Start a stage at s = 0: the removed parts leave, the added ones arrive.

        Call it at equilibrium (the last stage's end): the residual is then 0 at s = 0.

        Args:
            name: the stage's name.
            remove: each part's tags that leave.
            add: each part's tags that arrive.
            stresses: each leaving part's stress (UFL, 3x3) at the present displacement.
            strain: the strain ε(u) (UFL, 3x3), the arriving cells' starting strain.
        """
        remove, add = remove or {}, add or {}
        self.end()
        self.stage = name
        self.progress.value = 0.0
        self.left_weight.x.array[:] = 0.0
        for p, tags in remove.items():
            self._freeze(p, tags, stresses[p])
            self._set(self.present[p], tags, 0.0)
        for p, tags in add.items():
            self._set(self.present[p], tags, 1.0)
            self._set(self.arriving, tags, 1.0)
            self._store(self.arrival_strain, strain, self._cells(tags))
        self._one_part_a_cell()

    def _one_part_a_cell(self) -> None:
        """Refuse two parts present in one cell (their stiffness and weight would add)."""
        if max((sum(f.x.array for f in self.present.values())).max(initial=0.0), 0.0) > 1.0:
            raise ValueError("two parts are present in one cell: a cell group in two parts "
                             "must be absent from one of them (absent=) until a stage "
                             "removes it from the other")

    def _freeze(self, part, tags, stress) -> None:
        cells = self._cells(tags)
        self._set(self.leaving, tags, 1.0)
        self.left_weight.x.array[self._cell_dof[cells]] = self.weights[part]
        self.left_weight.x.scatter_forward()
        self._store(self.left_stress, stress, cells)

    @staticmethod
    def _store(target, expression, cells) -> None:
        """`expression` at the quadrature points of `cells` into `target` (others kept)."""
        Q = target.function_space
        new = fem.Function(Q)
        new.interpolate(Expression(expression, Q.element.interpolation_points))
        dofs = (Q.dofmap.list[cells][:, :, None] * Q.dofmap.bs
                + np.arange(Q.dofmap.bs)).ravel()
        target.x.array[dofs] = new.x.array[dofs]

    def state_functions(self) -> dict:
        """The fields a checkpoint keeps to go on inside a stage (by name).

        The parts present, what arrives and leaves, the frozen stress and weight, the
        arrival strain.
        """
        out = {f"present_{p}": f for p, f in self.present.items()}
        for f in (self.arriving, self.leaving, self.left_weight, self.left_stress,
                  self.arrival_strain):
            out[f.name] = f
        return out

    def end(self) -> None:
        """The stage done (s = 1): nothing leaving or arriving any more."""
        self.progress.value = 1.0
        for f in (self.leaving, self.arriving):
            f.x.array[:] = 0.0

    def held(self, u) -> list:
        """Dirichlet conditions holding, where they are, the dofs no present cell touches.

        Args:
            u: the displacement (its present values are held).

        Returns:
            A list of one DirichletBC (on no dof if every dof is touched).
        """
        V = self.V
        imap = V.dofmap.index_map
        touched = la.vector(imap, 1)
        present = sum(f.x.array for f in self.present.values())
        cells = np.nonzero(present[self._cell_dof] > 0)[0]
        touched.array[:] = 0.0
        touched.array[np.unique(V.dofmap.list[cells])] = 1.0
        touched.scatter_reverse(la.InsertMode.add)
        touched.scatter_forward()
        free = np.nonzero(touched.array == 0)[0].astype(np.int32)
        g = fem.Function(V)
        g.x.array[:] = u.x.array
        return [fem.dirichletbc(g, free)]
