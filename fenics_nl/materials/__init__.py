"""Materials as free energies in UFL, and the strain measures they are written in.

A law gives its energy φ(ε) (small strain) or φ(e) (Green–Lagrange); the stress and the
tangent are UFL's derivatives of it. `laws`: linear elastic, power law, St Venant–Kirchhoff,
neo-Hookean; `plasticity`: J2 with isotropic and kinematic hardening, its state at the
quadrature points; `finite_plasticity`: J2 at finite strain (F = Fe Fp, Hencky, the
exponential map, linear and Voce hardening); `creep`: Norton creep and Perzyna viscoplasticity,
their inelastic strain at the quadrature points, integrated by backward Euler over a time
step; `mixed`: the displacement–pressure
(Taylor–Hood) form of any of them; `plane_stress`: J2 in plane stress (ε_zz an unknown at
the quadrature points); `kinematics`: the strains of the 3D, plane and axisymmetric models.

    from fenics_nl.materials import J2Plasticity, LinearElastic, NeoHookean
"""

from fenics_nl.materials.creep import NortonCreep, PerzynaViscoplasticity
from fenics_nl.materials.finite_plasticity import FiniteJ2Plasticity
from fenics_nl.materials.laws import (
    FiniteStrain,
    LinearElastic,
    Material,
    NeoHookean,
    PowerLaw,
    SmallStrain,
    StVenantKirchhoff,
    von_mises_of,
)
from fenics_nl.materials.plasticity import J2Plasticity, PlasticState

__all__ = ["FiniteJ2Plasticity", "FiniteStrain", "J2Plasticity", "LinearElastic", "Material",
           "NeoHookean", "NortonCreep", "PerzynaViscoplasticity",
           "PlasticState", "PowerLaw", "SmallStrain",
           "StVenantKirchhoff", "von_mises_of"]
