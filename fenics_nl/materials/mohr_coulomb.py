"""Mohr–Coulomb plasticity of soils, returned exactly to its planes, edges and apex.

Stresses are positive in tension; σ1 ≥ σ2 ≥ σ3 are the principal stresses. The yield
function and the flow potential (de Souza Neto, Perić & Owen, *Computational Methods for
Plasticity*, 2008, §8.2: the same planes, written here for our sign) are

    f = (σ1 − σ3) + (σ1 + σ3) sinφ − 2c cosφ,      g = (σ1 − σ3) + (σ1 + σ3) sinψ,

a hexagonal pyramid about the hydrostatic axis with its apex at p = c cotφ. A triaxial
compression test fails at q = 6c cosφ/(3 − sinφ) + 6 p' sinφ/(3 − sinφ) (p' = −p), where
Drucker–Prager's compression cone touches it.

The return (perfect plasticity) is the multi-surface one in principal stresses: from the
sorted trial stresses, onto the main plane (f = 0 with σ1 ≥ σ2 ≥ σ3 kept); if that breaks
the order, onto the edge it crosses (σ1 = σ2 or σ2 = σ3: the two planes that meet there,
two multipliers); if the edge's point passes the apex, the apex (the stress c cotφ I, the
plastic strain C⁻¹ : (σ_tr − σ), volumetric even when ψ = 0, whose potential has no apex:
de Souza Neto's choice too). Each is a linear system
of constant coefficients (the elastic moduli, φ and ψ), solved once in Python: the return
is a closed form of the trial principal stresses, written in UFL, and its UFL derivative the
consistent tangent (not symmetric when ψ < φ). The principal directions do not turn: the
plastic strain is C⁻¹ : (σ_tr − σ) and shares them.

Models: plane strain and axisymmetric, whose third direction (z, or the hoop) is principal
(the in-plane pair a 2x2 eigenproblem in closed form, `principal`), and 3D (`principal_3d`:
the principal stress farthest from the others by the trigonometric closed form, the other
two as a pair about it, as accurate as the stress where they meet: a triaxial state, a K0
ground). Where two principal stresses meet (an edge) their directions are not defined: the
edges' returns are written so that the pair stays exactly equal, and then need only the
third direction. Under stresses prescribed on both sides of such a state (a 3D triaxial
test under a confining pressure) the plateau is a mechanism: how the flow splits between
the edge's two planes is free, and the tangent singular; in the axisymmetric model the
hoop strain ties them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import ufl

from fenics_nl.materials.plasticity import YIELD_TOLERANCE
from fenics_nl.materials.soil import SoilPlasticity

__all__ = ["MohrCoulomb"]

# the planes of the sorted principal stresses (σ1, σ2, σ3), by the pair they join: "13"
# the main plane, "23" (σ2 in σ1's place) crossed at the edge σ1 = σ2, "12" (σ2 in σ3's
# place) at the edge σ2 = σ3
PLANES = {"13": (0, 2), "23": (1, 2), "12": (0, 1)}


# the tension cut-off's planes σ_i ≤ t, by the sorted stress they bound
CUTS = {"T1": 0, "T2": 1, "T3": 2}
# the active sets a return with a cut-off tries, in order (the first whose multipliers are
# ≥ 0 and whose stress breaks no plane): the faces, the edges between them, the corners.
# Four planes meet at the corner σ1 = σ2 = t on Mohr–Coulomb's (13, 23, T1, T2): its flow
# is in the cone of their four flows, that is of three of them (Carathéodory), the same
# stress for each three
CUT_OFF_SETS = (("13",), ("T1",), ("13", "23"), ("13", "12"), ("13", "T1"), ("T1", "T2"),
                ("13", "T1", "T2"), ("13", "23", "T1"), ("13", "23", "T2"), ("23", "T1", "T2"),
                ("13", "12", "T1"), ("T1", "T2", "T3"))


def plane(pair: str, sine: float) -> np.ndarray:
    """The normal of a plane in principal stresses: Mohr–Coulomb's or the cut-off's.

    (σ_i − σ_j) + (σ_i + σ_j) sin a for a pair "13", "23", "12"; e_i for the cut-off's
    σ_i ≤ t ("T1", "T2", "T3": its normal and its flow).
    """
    k = np.zeros(3)
    if pair in CUTS:
        k[CUTS[pair]] = 1.0
        return k
    i, j = PLANES[pair]
    k[i], k[j] = 1.0 + sine, -(1.0 - sine)
    return k


@dataclass(frozen=True, eq=False)
class MohrCoulomb(SoilPlasticity):
    """Mohr–Coulomb plasticity (perfect): cohesion c > 0, angles φ and ψ in degrees.

    0 < φ < 90°, 0 ≤ ψ ≤ φ (ψ = None: φ, associated). Models: 3D, plane strain and
    axisymmetric (module docstring). `tension`: a cut-off t, no principal stress above it
    (0 ≤ t ≤ c cotφ; None: none, the pyramid's apex c cotφ the most a point bears).
    """

    tension: float | None = None

    def __post_init__(self):
        super().__post_init__()
        if self.tension is not None and not 0 <= self.tension <= self.apex:
            raise ValueError(f"tension must be in [0, c cotφ = {self.apex:.6g}] (the cut-off "
                             f"below the apex), got {self.tension!r}")

    @property
    def yield_scale(self) -> float:
        """2c cosφ, f's constant term (the tolerances' scale)."""
        return 2.0 * self.c * math.cos(math.radians(self.phi))

    @property
    def apex(self) -> float:
        """The mean stress p = c cotφ at the pyramid's apex (tension: the most it bears)."""
        return self.c / math.tan(math.radians(self.phi))

    def yield_function(self, sigma):
        """f(σ) = (σ1 − σ3) + (σ1 + σ3) sinφ − 2c cosφ (UFL): ≤ 0 inside.

        Args:
            sigma: a symmetric stress (UFL, 3x3).
        """
        s1, _, s3 = principal_3d(sigma)[0]
        sine = math.sin(math.radians(self.phi))
        f = (s1 - s3) + (s1 + s3) * sine - self.yield_scale
        if self.tension is None:
            return f
        return ufl.max_value(f, s1 - self.tension)  # (the cut-off's own scale: a stress)

    def return_map(self, eps):
        """(ε_p, p̄, Δp̄) at the strain ε from the committed state (UFL; module docstring).

        Args:
            eps: the small strain ε (UFL, 3x3) of a plane-strain or axisymmetric model.

        Returns:
            (plastic strain ε_p, cumulated plastic strain p̄, its increment), UFL.
        """
        self.require_3x3(eps)
        from ufl.domain import extract_unique_domain

        s0 = self.initial_stress
        three_d = extract_unique_domain(eps).geometric_dimension == 3
        if not three_d and s0 is not None and not isinstance(s0, dict) and (
                s0[0][2] != 0 or s0[1][2] != 0):
            raise ValueError("initial_stress: in plane strain and axisymmetric models the "
                             "third direction is principal: the shears σ_xz, σ_yz must be 0, "
                             f"got {s0!r}")
        sigma_tr = self.trial(eps)
        (s1, s2, s3), back = (principal_3d if three_d else principal)(sigma_tr)
        s = ufl.as_vector([s1, s2, s3])
        sphi, spsi = (math.sin(math.radians(a)) for a in (self.phi, self.dilatancy))
        f = ufl.dot(ufl.as_vector(plane("13", sphi)), s) - self.yield_scale
        # a point left on the surface by the last step starts the next one elastic (as
        # Drucker–Prager's: round-off of the terms f is made of)
        tolerance = YIELD_TOLERANCE * (self.yield_scale + sphi * abs(s1 + s3))
        plastic = ufl.gt(f, tolerance)
        if self.tension is not None:
            plastic = ufl.Or(plastic, ufl.gt(s1 - self.tension, tolerance))
            returned = self._cut_off_return(s, sphi, spsi, tolerance)
        else:
            main = self._returned(s, ("13",), sphi, spsi)
            ordered = ufl.And(ufl.ge(main[0], main[1]), ufl.ge(main[1], main[2]))
            # the edge the main return crosses first: σ1 = σ2 (planes 13 and 23) if σ1 − σ2
            # closes before σ2 − σ3, else σ2 = σ3 (planes 13 and 12)
            edge_12_first = ufl.lt((1 - spsi) * (s1 - s2), (1 + spsi) * (s2 - s3))
            edge = [ufl.conditional(edge_12_first, a, b) for a, b in zip(
                self._returned(s, ("13", "23"), sphi, spsi),
                self._returned(s, ("13", "12"), sphi, spsi), strict=True)]
            below_apex = ufl.ge(edge[0], edge[2])
            at_apex = (self.apex,) * 3 + (0.0, 0.0)
            returned = [ufl.conditional(ordered, main[i], ufl.conditional(
                below_apex, edge[i], at_apex[i])) for i in range(5)]
        if three_d:  # the returned stress from its principal values (module docstring)
            sigma = back(returned[:3], returned[3:])
            return self._flowed(ufl.conditional(plastic, sigma_tr - sigma, 0 * sigma_tr),
                                plastic)
        # (2D: the correction σ_tr − σ along the directions, whose pair's ratio is 1 − the
        # returned pair's)
        return self._flowed(back([ufl.conditional(plastic, s[i] - returned[i], 0.0)
                                  for i in range(3)],
                                 [ufl.conditional(plastic, 1 - r, 0.0) for r in returned[3:]]),
                            plastic)

    def _flowed(self, d_sigma, plastic):
        """(ε_p, p̄, Δp̄) of the step's stress correction σ_tr − σ: Δε_p = C⁻¹ : it."""
        G, K = self.mu, self.kappa
        d_eps_p = ufl.dev(d_sigma) / (2 * G) + ufl.tr(d_sigma) / (9 * K) * ufl.Identity(3)
        return (self._bound().eps_p + d_eps_p, *self.cumulated(d_eps_p, plastic))

    def _cut_off_return(self, s, sphi, spsi, tolerance):
        """The sorted stresses returned with the cut-off, and the pairs' ratios (5 values).

        The first of `CUT_OFF_SETS` (the main plane, its edges, the cut-off's planes and
        their corners) whose multipliers are ≥ 0 and whose stress breaks no plane.
        """
        every = ("13", "23", "12", "T1", "T2", "T3")
        chosen = None
        for planes in reversed(CUT_OFF_SETS):  # the last is the fallback, the first wins
            stress, gammas = self._returned(s, planes, sphi, spsi, multipliers=True)
            sigma = ufl.as_vector(stress[:3])
            admissible = [ufl.le(self._plane_value(sigma, p, sphi), tolerance) for p in every
                          if p not in planes] + [ufl.ge(g, 0.0) for g in gammas]
            if chosen is None:
                chosen = stress
                continue
            valid = admissible[0]
            for condition in admissible[1:]:
                valid = ufl.And(valid, condition)
            chosen = [ufl.conditional(valid, a, b) for a, b in zip(stress, chosen,
                                                                   strict=True)]
        return chosen

    def _plane_value(self, sigma, pair, sphi):
        """k · σ − its bound: a plane's value (≤ 0 inside), UFL."""
        bound = self.tension if pair in CUTS else self.yield_scale
        return ufl.dot(ufl.as_vector(plane(pair, sphi)), sigma) - bound

    def _returned(self, s, pairs, sphi, spsi, multipliers=False):
        """The sorted principal stresses returned onto the planes `pairs`, and two ratios.

        σ = σ_tr − D Σ Δγ_a n_a with k_b · σ = r_b on each plane b (r = 2c cosφ on
        Mohr–Coulomb's, t on the cut-off's): the multipliers solve M Δγ = k · σ_tr − r,
        M_ba = k_b · D n_a (constants, solved here). `multipliers`: also the Δγ_a.
        The stress is written σ = A σ_tr + b, its rows that must be equal (an edge: σ1 = σ2;
        a corner of the cut-off) made exactly equal: a pair split by round-off would have
        its own directions (3D: ill-defined there). The ratios: how the returned pair's
        difference follows the trial's, (σ1 − σ2)/(σ1_tr − σ2_tr) and (σ2 − σ3)/(σ2_tr −
        σ3_tr) as the trial's pair meets (0 where the return makes them equal, 1 where it
        moves them alike: the cut-off's face): `principal_3d`'s `back` needs them there.
        Returns 5 values (UFL and numbers).
        """
        lam, G = self.kappa - 2.0 * self.mu / 3.0, self.mu
        D = 2.0 * G * np.eye(3) + lam * np.ones((3, 3))
        k = np.array([plane(p, sphi) for p in pairs])
        n = np.array([plane(p, spsi) for p in pairs])
        inverse = np.linalg.inv(k @ D @ n.T)
        L = D @ n.T @ inverse  # Δσ = L (k σ_tr − r)
        bounds = np.array([self.tension if p in CUTS else self.yield_scale for p in pairs])
        A, b = np.eye(3) - L @ k, L @ bounds
        A[np.abs(A) < 1e-13] = 0.0
        for i in range(3):
            same = [j for j in range(3) if np.allclose(A[j], A[i], rtol=0, atol=1e-12)
                    and math.isclose(b[j], b[i], rel_tol=1e-12, abs_tol=1e-12 * self.c)]
            A[same], b[same] = A[same].mean(axis=0), b[same].mean()
        stress = [sum(float(A[i, j]) * s[j] for j in range(3) if A[i, j] != 0) + float(b[i])
                  for i in range(3)]
        stress += [float((A[i, i] - A[i, j]) - (A[j, i] - A[j, j])) / 2
                   for i, j in ((0, 1), (1, 2))]
        if not multipliers:
            return stress
        f = [self._plane_value(s, p, sphi) for p in pairs]
        return stress, [sum(float(inverse[a, c]) * f[c] for c in range(len(pairs)))
                        for a in range(len(pairs))]


def principal(sigma):
    """The sorted principal values of a stress whose third direction is principal (UFL).

    The in-plane pair is m ± R, R = √(((σ_xx − σ_yy)/2)² + σ_xy²); σ_zz (the third)
    takes its rank among them.

    Args:
        sigma: a stress (UFL, 3x3) with σ_xz = σ_yz = 0.

    Returns:
        ((σ1, σ2, σ3), back): `back(values, ratios)` turns three values along the sorted
        directions into the 3x3 tensor with the stress's principal directions (UFL);
        `ratios` as `principal_3d`'s.
    """
    a, b, xy, z = sigma[0, 0], sigma[1, 1], sigma[0, 1], sigma[2, 2]
    m, half = (a + b) / 2, (a - b) / 2
    square = half * half + xy * xy
    # R's root has no derivative at 0 (an in-plane pair that coincides): below round-off
    # of the stress it is taken as that round-off (the pair's directions are then the
    # tangent's business: `ratios`)
    tiny = (1e-14 * (abs(a) + abs(b) + abs(xy))) ** 2 + 1e-300
    big = ufl.gt(square, tiny)
    R = ufl.sqrt(ufl.conditional(big, square, tiny))
    hi, lo = m + R, m - R
    z_first, z_last = ufl.ge(z, hi), ufl.lt(z, lo)
    s1 = ufl.conditional(z_first, z, hi)
    s3 = ufl.conditional(z_last, z, lo)
    s2 = ufl.conditional(z_first, hi, ufl.conditional(z_last, lo, z))

    def back(values, ratios=(0.0, 0.0)):
        v1, v2, v3 = values
        v_hi = ufl.conditional(z_first, v2, v1)
        v_lo = ufl.conditional(z_last, v2, v3)
        v_z = ufl.conditional(z_first, v1, ufl.conditional(z_last, v3, v2))
        # the in-plane pair along the pair's directions: its mean, and its half-difference
        # along (σ − m I) / R; where the pair meets, the given ratio (`principal_3d`'s)
        limit = ufl.conditional(z_first, ratios[1], ratios[0])
        ratio = ufl.conditional(big, (v_hi - v_lo) / (2 * R), limit)
        mean = (v_hi + v_lo) / 2
        return ufl.as_matrix([[mean + ratio * half, ratio * xy, 0],
                              [ratio * xy, mean - ratio * half, 0],
                              [0, 0, v_z]])

    return (s1, s2, s3), back


# how close to a meridian (a triaxial state, cos 3θ = ±1) the Lode angle's arccos is taken:
# its derivative is infinite there (what it gives is used there only through the simple
# principal stress, flat in θ, and the pair's square gap, 0 and stationary there)
CLIP = 1e-15


def principal_3d(sigma):
    """The sorted principal values of a symmetric 3x3 stress, and its projections (UFL).

    As `principal`'s: one principal stress σ_s, simple, and a pair m ± h about it, the pair
    found from σ_s's projection E_s, so that a pair that (nearly) coincides is as accurate
    as the stress. σ_s is the one farthest from the others (σ1 if J3 ≥ 0, else σ3), from
    the trigonometric form σ_k = p + 2 √(J2/3) cos(θ − 2πk/3), cos 3θ = (3√3/2) J3/J2^(3/2)
    (accurate for σ_s: flat in θ where the others meet); with m = (tr σ − σ_s)/2,
    d = σ_s − m and h0 the trigonometric form's half-gap,
    E_s = ((σ − m I)² − h0² I)/(d² − h0²) (Sylvester's), N = σ − m I − d E_s = h (E_a − E_b)
    and h = √(N : N / 2), each entry of N to round-off of the stress (h0 alone would be
    √ε ≈ 1e-8 of it off: the closed form's cancellation where two values meet).

    Args:
        sigma: a symmetric stress (UFL, 3x3).

    Returns:
        ((σ1, σ2, σ3), back): `back(values, ratios)` turns three values along the sorted
        directions into the 3x3 tensor with the stress's principal directions (UFL);
        `ratios`: (σ1 − σ2, σ2 − σ3)'s to the stress's where that pair meets (the
        tangent's there; `MohrCoulomb._returned`).
    """
    identity = ufl.Identity(3)
    p = ufl.tr(sigma) / 3
    s = sigma - p * identity
    # a stress with (nearly) no deviator has no Lode angle: J2 below round-off of the stress
    # is taken as that round-off (the three values then meet, and `back` gives their mean)
    size = sum(abs(sigma[i, j]) for i in range(3) for j in range(3))
    # (the floor: J2^(3/2) of it is no underflow, σ = 0 no 0/0)
    tiny = (1e-14 * size) ** 2 + 1e-150
    j2 = ufl.inner(s, s) / 2
    j2 = ufl.conditional(ufl.gt(j2, tiny), j2, tiny)
    j3 = ufl.det(s)
    cos3 = 3 * math.sqrt(3) / 2 * j3 / j2 ** 1.5
    theta = ufl.acos(ufl.max_value(ufl.min_value(cos3, 1 - CLIP), -1 + CLIP)) / 3
    r = 2 * ufl.sqrt(j2 / 3)
    t1, t2, t3 = (p + r * ufl.cos(theta - 2 * math.pi * k / 3) for k in range(3))
    major = ufl.ge(j3, 0.0)  # σ1 the simple one (θ ≤ π/6), else σ3
    simple = ufl.conditional(major, t1, t3)
    h0 = ufl.conditional(major, t2 - t3, t1 - t2) / 2
    m = (ufl.tr(sigma) - simple) / 2
    d = simple - m
    B = sigma - m * identity
    gap = d * d - h0 * h0  # (σ_s − σ_a)(σ_s − σ_b): 0 only if the three meet
    apart = ufl.gt(gap, tiny)
    E_s = ufl.conditional(apart, 1.0, 0.0) * (ufl.dot(B, B) - h0 * h0 * identity) / (
        ufl.conditional(apart, gap, 1.0))
    N = B - d * E_s
    square = ufl.inner(N, N) / 2
    # h's root has no derivative at 0 (a pair that coincides): below round-off it is taken
    # as that round-off (as `principal`'s R)
    big = ufl.gt(square, tiny)
    h = ufl.sqrt(ufl.conditional(big, square, tiny))
    s1 = ufl.conditional(major, simple, m + h)
    s2 = ufl.conditional(major, m + h, m - h)
    s3 = ufl.conditional(major, m - h, simple)

    def back(values, ratios=(0.0, 0.0)):
        v1, v2, v3 = values
        v_s = ufl.conditional(major, v1, v3)
        v_hi, v_lo = ufl.conditional(major, v2, v1), ufl.conditional(major, v3, v2)
        # the pair along its directions: its mean, and its half-difference along N / h;
        # where the trial's pair meets (h below round-off: no directions), the given ratio,
        # the limit of the returned pair's difference to the trial's (its value is then
        # times N ≈ 0; its derivative's is the tangent's)
        limit = ufl.conditional(major, ratios[1], ratios[0])
        ratio = ufl.conditional(big, (v_hi - v_lo) / (2 * h), limit)
        return v_s * E_s + (v_hi + v_lo) / 2 * (identity - E_s) + ratio * N

    return (s1, s2, s3), back
