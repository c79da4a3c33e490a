"""J2 plasticity against a peer: dolfinx-external-operator, same problem, same meshes.

The thick cylinder of dolfinx-external-operator's von Mises demo, in plane strain: a = 1,
b = 1.3, E = 70e3, ν = 0.3, σ0 = 250, linear isotropic hardening with tangent modulus
E_t = E/100 (H = E E_t/(E − E_t)), internal pressure in 19 increments
p_i = q_lim √(1.1 i/19) up to 1.1 q_lim, q_lim = (2/√3) σ0 ln(b/a).

* **ours**: `fenics_nl` as a user writes it: `J2Plasticity`'s condensed energy in UFL, the
  consistent tangent by UFL's derivative, the hand-written full Newton (MUMPS LU).
* **peer**: the same problem through dolfinx-external-operator's public API
  (`FEMExternalOperator`, `replace_external_operators`, `evaluate_operands`,
  `evaluate_external_operators`, `petsc.assemble_residual_with_callback`): the radial
  return and its tangent in Numba at the quadrature points, SNES `vinewtonrsls` with a basic
  line search (the package's choice), MUMPS LU as ours. Written here from the package's API
  documentation, not from its demo.

Both on the very same mesh (P2 displacement, degree-2 quadrature: three points per
triangle, the peer's choice), the same increments, each started from the last converged
state, and the same stopping test ‖R‖ ≤ max(1e-8 ‖R₀‖, 1e-8). Times are of the load loop only,
after a warm-up run that compiles the forms and the Numba kernel. There is no closed form
with hardening (the limit pressure and c(p) are for perfect plasticity, c(p) for ν = 1/2
only), so the error is that of the inner displacement u(a) at the final load against a
reference: ours on a mesh twice finer than the finest compared (and the peer's agreement
with ours on each mesh is shown). The first increment is elastic: its u(a) is checked
against Lamé's closed form.

Needs the optional benchmark dependencies (`make bench` installs them):
`pip install -e ".[bench]"` and `pip install --no-deps dolfinx-external-operator==0.11.0`
(its declared dependency `fenics-dolfinx` is the same DOLFINx as our wheel under another
name).

    python benchmarks/plasticity_peer.py [--quick] [--update-docs]
"""

from __future__ import annotations

import argparse
import json
import math
import time
from functools import partial
from importlib.metadata import version
from pathlib import Path

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

# Before any UFL algorithm runs: UFL's transformers size their tables by the expression
# classes defined when they are first used, and the package defines a new one.
try:
    import dolfinx_external_operator as peer_package
    import numba
except ImportError as err:
    raise SystemExit("benchmarks/plasticity_peer.py needs the bench extra: pip install -e "
                     "'.[bench]' && pip install --no-deps dolfinx-external-operator==0.11.0"
                     ) from err

# isort: split

import numpy as np
import plasticity
import ufl
from common import elapsed, machine, update_docs
from mpi4py import MPI
from plasticity_problems import ThickVessel, thick_vessel

from fenics_nl.materials import kinematics
from fenics_nl.materials.plasticity import J2Plasticity
from fenics_nl.solvers.newton import NewtonSolver
from fenics_nl.solvers.snes import EventCounter, all_event_names, petsc_work, solver_options

HERE = Path(__file__).resolve().parent
A, B, E, NU, SIGMA0 = 1.0, 1.3, 70e3, 0.3, 250.0
E_T = E / 100
H = E * E_T / (E - E_T)
Q_LIM = 2 / math.sqrt(3) * SIGMA0 * math.log(B / A)
LOADS = Q_LIM * np.sqrt(np.linspace(0.0, 1.1, 20))[1:]  # the zero load is skipped: u = 0
QUADRATURE = 2
TOL = 1e-8
MU, LMBDA = E / (2 * (1 + NU)), E * NU / ((1 + NU) * (1 - 2 * NU))


def lame_inner_displacement(p: float) -> float:
    """u(a) of the elastic thick cylinder in plane strain (Lamé)."""
    return p * A * (1 + NU) / E * ((1 - 2 * NU) * A**2 + B**2) / (B**2 - A**2)


def body(h: float) -> ThickVessel:
    return thick_vessel("cylinder", A, B, size=h)


def linear_solve_time(vb: ThickVessel) -> float:
    """One elastic solve of the mesh (assemble, factorize, solve) on the forms' rule."""
    dx = kinematics.quadrature_measure("dx", vb.mesh, QUADRATURE)
    return plasticity.linear_solve_time(vb, E, NU, LOADS[0], dx=dx, prefix="peer_linear_")


def ours(vb: ThickVessel, linear_solver: str = "lu") -> dict:
    """fenics_nl: the condensed energy in UFL, its UFL tangent, full Newton."""
    material = J2Plasticity(E, NU, sigma0=SIGMA0, H=H)
    material.bind(vb.mesh, QUADRATURE)
    dx = kinematics.quadrature_measure("dx", vb.mesh, QUADRATURE)
    u, v = vb.u, ufl.TestFunction(vb.V)
    u.x.array[:] = 0.0
    residual = (material.internal_work(u, v, vb.model) * dx
                + vb.pressure * ufl.dot(vb.normal, v) * vb.ds_inner)
    solver = NewtonSolver(residual, u, vb.supports, rtol=TOL, atol=TOL, force_scale=1.0,
                          prefix="peer_ours_", linear_solver=linear_solver)
    iterations, path, phases = [], [], {}
    t0 = time.perf_counter()
    for q in LOADS:
        vb.pressure.value = q
        result = solver.solve()
        iterations.append(result.iterations)
        for k, t in result.work.time.items():
            phases[k] = phases.get(k, 0.0) + t
        material.commit(u, vb.model)
        path.append(vb.inner_displacement())
    return {"time_s": time.perf_counter() - t0, "iterations": iterations, "path": path,
            "phase_time_s": phases}


@numba.njit(cache=False)
def radial_return(deps, sigma_n, p_n, lmbda, mu, sigma0, hardening):
    """Stress, tangent and Δp at every point, Mandel vectors (xx, yy, zz, √2 xy).

    Scalar loops, no temporaries: the kernel must not be what slows the peer down.
    """
    n = deps.shape[0]
    sigma = np.empty((n, 4))
    tangent = np.empty((n, 4, 4))
    dp = np.zeros(n)
    trial, s = np.empty(4), np.empty(4)
    for i in range(n):
        tr = deps[i, 0] + deps[i, 1] + deps[i, 2]
        for k in range(4):
            trial[k] = sigma_n[i, k] + 2 * mu * deps[i, k] + (lmbda * tr if k < 3 else 0.0)
        mean = (trial[0] + trial[1] + trial[2]) / 3
        norm2 = 0.0
        for k in range(4):
            s[k] = trial[k] - (mean if k < 3 else 0.0)
            norm2 += s[k] * s[k]
        q = math.sqrt(1.5 * norm2)
        f = q - sigma0 - hardening * p_n[i]
        beta, gamma = 0.0, 0.0  # σ = trial − β s; C = C_e − 2μβ I_dev − 2μγ n̂⊗n̂
        if f > 0.0:
            dp[i] = f / (3 * mu + hardening)
            beta = 3 * mu * dp[i] / q
            gamma = 3 * mu / (3 * mu + hardening) - beta
        for k in range(4):
            sigma[i, k] = trial[k] - beta * s[k]
            for m in range(4):
                elastic = (lmbda if k < 3 and m < 3 else 0.0) + (2 * mu if k == m else 0.0)
                dev = (1.0 if k == m else 0.0) - (1.0 / 3.0 if k < 3 and m < 3 else 0.0)
                unit = s[k] * s[m] / norm2 if f > 0.0 else 0.0
                tangent[i, k, m] = elastic - 2 * mu * beta * dev - 2 * mu * gamma * unit
    return sigma, tangent, dp


def peer(vb: ThickVessel, snes_type: str = "vinewtonrsls", factorization: str = "lu") -> dict:
    """dolfinx-external-operator: the return map in Numba behind a FEMExternalOperator."""
    import basix.ufl
    from dolfinx import fem
    from dolfinx.fem.petsc import NonlinearProblem
    from dolfinx_external_operator.petsc import assemble_residual_with_callback

    msh, V = vb.mesh, vb.V
    kernel = [0.0]  # seconds in the Numba return map
    cell = msh.topology.cell_name()
    S = fem.functionspace(msh, basix.ufl.quadrature_element(cell, degree=QUADRATURE,
                                                            value_shape=(4,)))
    P = fem.functionspace(msh, basix.ufl.quadrature_element(cell, degree=QUADRATURE))
    du, u = fem.Function(V), fem.Function(V)
    sigma_n, p_n, dp = fem.Function(S), fem.Function(P), fem.Function(P)

    def mandel(w):
        g = ufl.grad(w)
        return ufl.as_vector([g[0, 0], g[1, 1], 0.0, (g[0, 1] + g[1, 0]) / math.sqrt(2)])

    sigma = peer_package.FEMExternalOperator(mandel(du), function_space=S)

    def evaluate(derivatives):
        if derivatives != (1,):
            raise NotImplementedError(derivatives)

        def tangent_and_state(deps):
            t = time.perf_counter()
            s, c, d = radial_return(deps.reshape(-1, 4), sigma_n.x.array.reshape(-1, 4),
                                    p_n.x.array, LMBDA, MU, SIGMA0, H)
            kernel[0] += time.perf_counter() - t
            return c.reshape(-1), s.reshape(-1), d

        return tangent_and_state

    sigma.external_function = evaluate
    v = ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=msh, metadata={"quadrature_degree": QUADRATURE})
    F = ufl.inner(sigma, mandel(v)) * dx + vb.pressure * ufl.dot(vb.normal, v) * vb.ds_inner
    J = ufl.derivative(F, du, ufl.TrialFunction(V))
    F_hat, F_ops = peer_package.replace_external_operators(F)
    J_hat, J_ops = peer_package.replace_external_operators(J)

    def update():
        (_, s_new, dp_new), = peer_package.evaluate_external_operators(
            J_ops, peer_package.evaluate_operands(F_ops))
        F_ops[0].ref_coefficient.x.array[:] = s_new
        dp.x.array[:] = dp_new

    options = {"snes_type": snes_type, "snes_linesearch_type": "basic",
               "snes_rtol": TOL, "snes_atol": TOL, "snes_stol": 0.0, "snes_max_it": 50,
               "ksp_type": "preonly", "pc_type": factorization,
               "pc_factor_mat_solver_type": "mumps"}
    with solver_options("peer_eo_", options) as passed:  # none left behind (see snes.py)
        problem = NonlinearProblem(F_hat, du, J=J_hat, bcs=vb.supports,
                                   petsc_options_prefix="peer_eo_", petsc_options=passed)
    if factorization == "cholesky":  # its tangent is symmetric too: MUMPS LDLᵀ (SYM=2)
        problem.A.setOption(problem.A.Option.SYMMETRIC, True)
        problem.A.setOption(problem.A.Option.SYMMETRY_ETERNAL, True)
    problem.solver.setFunction(partial(assemble_residual_with_callback, problem.u, problem.F,
                                       problem.J, vb.supports, update, []), problem.b)
    iterations, path = [], []
    counter = EventCounter(all_event_names())
    t0 = time.perf_counter()
    for q in LOADS:
        vb.pressure.value = q
        du.x.array[:] = 0.0  # from the last converged state
        problem.solve()
        if problem.solver.getConvergedReason() <= 0:
            raise SystemExit(f"peer: SNES diverged at p = {q:.4g}")
        iterations.append(problem.solver.getIterationNumber())
        u.x.array[:] += du.x.array
        p_n.x.array[:] += dp.x.array
        sigma_n.x.array[:] = F_ops[0].ref_coefficient.x.array
        path.append(vb.probes.continuous(u)[0][0])
    spent = time.perf_counter() - t0
    phases = petsc_work(counter).time  # PETSc's events: residual (with the callback), ...
    phases["residual"] -= kernel[0]  # ... of which the Numba return map
    phases["return map (Numba)"] = kernel[0]
    return {"time_s": spent, "iterations": iterations, "path": path, "phase_time_s": phases}


def compare(h: float, repeat: int = 1) -> dict:
    """Every code on the mesh of size `h`, `repeat` rounds in turn, each code's fastest run:
    a burst of the VM's load then slows one round, not one code."""
    vb = body(h)
    row = {"h": h, "dofs": vb.dofs, "linear_solve_s": linear_solve_time(vb),
           "repeat": repeat}
    codes = (("ours", ours), ("ours, LDLᵀ", partial(ours, linear_solver="cholesky")),
             ("peer", peer), ("peer, newtonls", partial(peer, snes_type="newtonls")),
             ("peer, newtonls, LDLᵀ",
              partial(peer, snes_type="newtonls", factorization="cholesky")))
    fastest = {}
    for _ in range(repeat):
        for name, run in codes:
            r = run(vb)
            if name not in fastest or r["time_s"] < fastest[name]["time_s"]:
                fastest[name] = r
    for name, r in fastest.items():
        row[name] = {"time_s": r["time_s"], "newton_iterations": sum(r["iterations"]),
                     "iterations_per_increment": r["iterations"],
                     "inner_displacement": r["path"][-1],
                     "elastic_error": r["path"][0] / lame_inner_displacement(LOADS[0]) - 1,
                     **({"phase_time_s": r["phase_time_s"]} if "phase_time_s" in r else {})}
    return row


CODES = ("ours", "ours, LDLᵀ", "peer", "peer, newtonls", "peer, newtonls, LDLᵀ")


def phases(c: dict) -> str:
    """Where a code's loop time went, largest first; "other" is the rest of the loop
    (ours: commit and probes; SNES: its own work, e.g. a VI solver's sub-matrices and their
    symbolic factorizations)."""
    parts = dict(c["phase_time_s"])
    parts["other"] = c["time_s"] - sum(parts.values())
    return ", ".join(f"{k} {t:.1f} s" for k, t in sorted(parts.items(), key=lambda kv: -kv[1])
                     if t >= 0.05)


def table(rows: list[dict], reference: dict) -> str:
    lines = [f"Thick cylinder a = 1, b = 1.3, plane strain, E_t = E/100, 19 increments to "
             f"1.1 q_lim, P2, 3 quadrature points per triangle, MUMPS LU (LDLᵀ where named: "
             f"the tangent is symmetric, MUMPS's symmetric factorization); the reference "
             f"u_ref(a) = {reference['inner_displacement']:.7g} is ours on h = "
             f"{reference['h']:g} ({reference['dofs']} unknowns). "
             "`python benchmarks/plasticity_peer.py`.", "",
             "| h | unknowns | code | Newton iterations | time (s) | / one linear solve | "
             "/ ours | u(a): vs ours, same mesh | vs u_ref | elastic step vs Lamé |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    ref = reference["inner_displacement"]
    for r in rows:
        ours = r["ours"]
        for name in CODES:
            c = r[name]
            lines.append(
                f"| {r['h']:g} | {r['dofs']} | {name} | {c['newton_iterations']} | "
                f"{c['time_s']:.2f} | {c['time_s'] / r['linear_solve_s']:.0f} | "
                f"{c['time_s'] / ours['time_s']:.2f} | "
                f"{abs(c['inner_displacement'] / ours['inner_displacement'] - 1):.0e} | "
                f"{abs(c['inner_displacement'] / ref - 1):.1e} | {c['elastic_error']:+.1e} |")
    finest = rows[-1]
    lines += ["", f"Where the time goes at {finest['dofs']} unknowns (ours: our work counters; "
              "the peer: PETSc's events, its residual minus the Numba return map):", ""]
    lines += [f"* {name}: {phases(finest[name])}" for name in CODES]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="two coarse meshes, nothing written")
    ap.add_argument("--update-docs", action="store_true")
    ap.add_argument("--repeat", type=int, default=3,
                    help="rounds of every code on each mesh; each code's fastest is kept")
    args = ap.parse_args()
    sizes = [0.04, 0.02] if args.quick else [0.02, 0.01, 0.007]
    compare(0.05)  # warm-up: forms and the Numba kernel compiled
    rows = [compare(h, args.repeat) for h in sizes]
    h_ref = sizes[-1] / 2
    vb = body(h_ref)
    reference = {"h": h_ref, "dofs": vb.dofs, **ours(vb)}
    reference["inner_displacement"] = reference["path"][-1]
    text = table(rows, reference)
    if MPI.COMM_WORLD.rank == 0:
        print(text)
    if not args.quick and MPI.COMM_WORLD.rank == 0:
        (HERE / "results" / "plasticity_peer.json").write_text(json.dumps(
            {"machine": {**machine(MPI.COMM_WORLD.size),
                         "dolfinx_external_operator": version("dolfinx-external-operator"),
                         "numba": numba.__version__}, "rows": rows,
             "reference": {k: reference[k] for k in ("h", "dofs", "inner_displacement",
                                                     "time_s")},
             "benchmark_time_s": elapsed()}, indent=2))
        if args.update_docs:
            update_docs("plasticity_peer", text)


if __name__ == "__main__":
    main()
