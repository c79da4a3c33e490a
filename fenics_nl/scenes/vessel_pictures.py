"""The vessel's pictures, against the closed forms of the thick vessels.

The pressure against the inner displacement, and the deformed quarter coloured by the
cumulated plastic strain.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from fenics_nl.io import pictures
from fenics_nl.theory import vessels

__all__ = ["VesselRun", "plastic_zone", "pressure_curve"]


@dataclass
class VesselRun:
    """What the pictures read of a vessel run (pressures and lengths in the run's units).

    Args:
        shape: ``sphere`` or ``cylinder``; a, b: inner and outer radii.
        E, nu, sigma0: the material.
        path: (pressure, u(a)) after each converged step, from (0, 0).
        loaded: the peak pressure (also after unloading); unload: whether it unloaded.
        p_lim, p_e: the closed forms' limit and yield-onset pressures.
        c_fe, c_exact: the plastic radius computed and of the closed form.
        compliance: Lamé's elastic u(a)/p.
        exact_curve: the closed form holds along the whole loading (sphere, perfect
            plasticity, below the limit); inner, inner_exact: u(a) at the peak, computed
            and of the closed form (None if not `exact_curve`).
    """

    shape: str
    a: float
    b: float
    E: float
    nu: float
    sigma0: float
    path: list
    loaded: float
    unload: bool
    p_lim: float
    p_e: float
    c_fe: float
    c_exact: float
    compliance: float
    exact_curve: bool
    inner: float
    inner_exact: float | None

    def title(self, sep: str = ", ") -> str:
        """What the run ends in, loaded or unloaded from its peak; `sep` before the radius."""
        # plain "nu": pyvista's font has no Greek letters (the picture shares this title)
        closed = "closed form" + (" for nu = 1/2" if self.shape == "cylinder" else "")
        radius = f"plastic radius {self.c_fe:.4g} ({closed} {self.c_exact:.4g})"
        if self.unload:
            return (f"{self.shape}: unloaded from {self.loaded / self.p_lim:.3f} p_lim, "
                    f"permanent u(a) = {self.path[-1][1]:.4g}{sep}{radius}")
        return f"{self.shape}: p = {self.loaded / self.p_lim:.3f} p_lim{sep}{radius}"


def pressure_curve(run: VesselRun, path: str, comm=MPI.COMM_WORLD) -> None:
    """p(u(a)) of the run against the closed forms (loading and elastic unloading)."""
    if comm.rank != 0:
        return
    plt = pictures.pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4.8))
    q, d = np.array(run.path).T
    p_lim, loaded = run.p_lim, run.loaded
    if run.exact_curve:  # the monotonic loading, exact up to the limit
        ps = np.linspace(0.0, loaded, 200)
        us = [vessels.sphere_inner_displacement(run.a, run.b, run.E, run.nu, run.sigma0, x)
              for x in ps]
        ax.plot(us, ps / p_lim, "k-", lw=1, label="closed form (loading)")
    else:  # Lamé up to the yield onset
        ps = np.array([0.0, min(run.p_e, loaded)])
        ax.plot(ps * run.compliance, ps / p_lim, "k-", lw=1, label="Lamé (elastic)")
    if run.unload:  # from the closed-form peak (else the computed one), Lamé's compliance
        peak = run.inner_exact if run.inner_exact is not None else run.inner
        # the sphere unloads elastically up to 2 p_e (σ_eq(a) goes from σ0 to −σ0); the
        # cylinder's bound is close to it (exact for ν = 1/2)
        reverse = loaded > 2 * run.p_e
        ax.plot([peak, peak - loaded * run.compliance], [loaded / p_lim, 0.0], "k--", lw=1,
                label="elastic unloading (Lamé" + (", reverse yield ignored)" if reverse
                                                   else ")"))
    ax.plot(d, q / p_lim, "o", ms=4, mfc="none", color="C0", label="FE, J2 (each step)")
    ax.axhline(1.0, color="C3", ls="--", lw=1, label=f"limit pressure {p_lim:.4g}")
    ax.axhline(run.p_e / p_lim, color="gray", ls=":", lw=1, label="yield onset")
    ax.set_xlabel("inner radial displacement u(a) [length]")
    ax.set_ylabel("p / p_lim")
    ax.set_ylim(0, 1.08)
    ax.set_xlim(left=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    ax.set_title(f"b/a = {run.b / run.a:g}, " + run.title("\n"), fontsize=9)
    pictures.save_figure(fig, path)


def plastic_zone(run: VesselRun, displacement, plastic_strain_per_cell, path: str) -> None:
    """The deformed quarter coloured by each cell's largest cumulated plastic strain.

    The closed form's plastic radius drawn over it (collective).
    """
    theta = np.linspace(0.0, 0.5 * np.pi, 91)
    c = run.c_exact
    arc = {f"closed-form plastic radius {c:.4g}"
           + (" (for nu = 1/2)" if run.shape == "cylinder" else ""):
           np.column_stack([c * np.cos(theta), c * np.sin(theta)])}
    pictures.deformed_picture(displacement, plastic_strain_per_cell, path, run.title(),
                              label="cumulated plastic strain", curves=arc)
