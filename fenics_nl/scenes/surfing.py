"""The surfing test: a crack driven along a straight line by a moving mode-I K-field.

A strip [0, L] x [0, H] is the upper half of a cracked plate (plane strain), the crack on
y = 0: u_y = 0 there (the symmetric half; the crack's opening is the strain of its damaged
band, as in the whole plate), a pre-crack α = 1 on y = 0 up to x = `notch`, and on the rest
of the boundary Irwin's displacement field of a crack tip at (x_c, 0),

    u = K/(2μ) √(r/(2π)) (κ − cos θ) (cos(θ/2), sin(θ/2)),    κ = 3 − 4ν,

with K = √(G E/(1 − ν²)). Moving x_c step by step drags the crack along (Hossain et al.
2014). However the tip trails the field's centre, in steady propagation the elastic energy
only translates: the external work goes into the crack, whose dissipated energy grows by the
discrete toughness per unit length. In the half strip that is half of it:

    dD/da = G_h / 2,

G_h: the toughness of the mesh, here that of a crack along a line of nodes (the 1D half bar
cracked at its free end, `gradient_damage_bar`, gives it independently).

The mesh: square cells of h = ell/`resolution` up to `band` ell above the crack line, then
rows growing geometrically (ratio 1.3) up to H.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.domain.graded_grid import graded_axis, graded_rectangle
from fenics_nl.scenes.cracked_plate import CrackedPlate, CrackRecord

__all__ = ["Surfing", "SurfingRecord"]


@dataclass
class SurfingRecord(CrackRecord):
    """Every converged step: the field's centre and the crack tip.

    And `CrackRecord`'s: the half strip's dissipated energy, the damage, the work.
    """

    centre: list[float] = field(default_factory=list)
    tip: list[float] = field(default_factory=list)


class Surfing(CrackedPlate):
    """The half strip of a `GradientDamage` law (plane strain), its K-field and its crack.

    Args:
        law: the gradient damage law (E, ν, Gc, ell).
        length, height: L and H of the half strip.
        notch: the pre-crack's length (α = 1 on y = 0, x <= notch).
        resolution: ell/h along the crack's path.
        band: height of the uniform rows, in units of ell.
        load: G/G_h, the K-field's energy release rate over the mesh's toughness.
        toughness: G_h, the K-field's reference. By default Gc (1 + h/(c_w ell)), the band
            of a crack inside the mesh; a crack on this strip's symmetry line has twice the
            band, Gc (1 + 2h/(c_w ell)) (`gradient_damage_bar.end_crack`), so the default
            load is about 0.92 of that toughness.
    """

    def __init__(self, law, *, length: float = 1.0, height: float = 0.3, notch: float = 0.3,
                 resolution: float = 4.0, band: float = 3.0, load: float = 1.0,
                 toughness: float | None = None, acceleration: str = "none",
                 comm: MPI.Comm = MPI.COMM_WORLD):
        self.notch = notch
        self.h = h = law.ell / resolution
        xs = h * np.arange(round(length / h) + 1)  # steps of h: the field moves by whole cells
        self.length, self.height = length, height = xs[-1], height
        ys = graded_axis(height, h, (0.0, band * law.ell), through=0.0)
        msh = graded_rectangle(comm, xs, ys)
        self._plate(law, msh, lambda x: np.isclose(x[1], 0.0) & (x[0] <= notch + 1e-9 * length))
        V, A = self.V, self.A
        bottom = mesh.locate_entities_boundary(msh, 1, lambda x: np.isclose(x[1], 0.0))
        symmetry = boundary.component(V, 1, bottom)
        outer = fem.locate_dofs_geometrical(V, lambda x: (x[1] > 1e-12 * height) & (
            np.isclose(x[0], 0.0) | np.isclose(x[0], length) | np.isclose(x[1], height)))
        self.g = fem.Function(V)
        self.toughness = toughness or law.Gc * (1 + h / (law.c_w * law.ell))
        self.K = math.sqrt(load * self.toughness * law.E / (1 - law.nu**2))
        self._solver([symmetry, fem.dirichletbc(self.g, outer)], self.K * math.sqrt(h),
                     acceleration=acceleration)
        n = A.dofmap.index_map.size_local
        x = A.tabulate_dof_coordinates()[:n]
        self._path = np.flatnonzero(np.isclose(x[:, 1], 0.0))
        self._path_x = x[self._path, 0]

    def centres(self, count: int, flag: str = "count") -> np.ndarray:
        """`count` positions of the field's centre, 2h apart from the notch's tip.

        The centre stays a strip's height from its end (the K-field is the far field); more
        positions than the strip holds are a ValueError naming `flag`.
        """
        room = int((self.length - self.height - self.notch) / (2 * self.h)) + 1
        if count > room:
            raise ValueError(f"{flag}: the strip holds {room} positions of the field 2h "
                             f"apart at ell/h = {self.law.ell / self.h:g} (its centre "
                             f"{self.height:g} from the end at most)")
        return self.notch + 2 * self.h * np.arange(count)

    def k_field(self, centre: float) -> None:
        """Irwin's mode-I displacement around a tip at (centre, 0) into the boundary data."""
        E, nu, K = self.law.E, self.law.nu, self.K
        mu, kappa = E / (2 * (1 + nu)), 3 - 4 * nu

        def irwin(x):
            r = np.hypot(x[0] - centre, x[1])
            theta = np.arctan2(x[1], x[0] - centre)
            amplitude = K / (2 * mu) * np.sqrt(r / (2 * np.pi)) * (kappa - np.cos(theta))
            return np.vstack([amplitude * np.cos(theta / 2), amplitude * np.sin(theta / 2)])

        self.g.interpolate(irwin)

    def advance(self, centres, progress=None) -> SurfingRecord:
        """Move the field's centre through `centres`, minimizing and committing each step."""
        record = SurfingRecord()
        for k, centre in enumerate(centres):
            self.k_field(centre)
            self._step(record)
            record.centre.append(float(centre))
            record.tip.append(self.tip())
            if progress:
                progress(k, record)
        return record

    def tip(self, level: float = 0.5) -> float:
        """The crack tip: the largest x on the crack line where α >= `level`."""
        a = self.alpha.x.array[self._path]
        local = float(self._path_x[a >= level].max(initial=-np.inf))
        return self.mesh.comm.allreduce(local, op=MPI.MAX)



def release_rate(record: SurfingRecord, skip: int) -> tuple[float, float]:
    """(2 dD/da, the tip's lag behind the centre): least squares over the steps after `skip`."""
    tip = np.array(record.tip[skip:])
    D = np.array(record.dissipated_energy[skip:])
    slope = np.polyfit(tip, D, 1)[0]
    lag = float(np.mean(np.array(record.centre[skip:]) - tip))
    return 2 * slope, lag
