"""Coulomb friction: the active set against the regularised (penalty) peer, on Cattaneo–Mindlin.

The plane-strain cylinder of `tests/test_friction.py`: a rigid punch (R = 1) pressed by
δ = 0.01 into an incompressible block (Taylor–Hood, ν = 1/2, h = a/24, 100 a wide), f = 0.3,
then moved by D = 0.0023 along x (Q ≈ f P / 2). Same mesh, same two steps:

* the active set (`FrictionalContact`): status iterations per step, factorizations, time,
  the stick half-width against a √(1 − Q/(fP)) and the traction against Cattaneo–Mindlin;
* the penalty peer (`peers.solve_friction_penalty`) at k = 1, 10, 100, 1000 E/h: its
  distance to the active set's answer (Q, nodal traction) as k grows, and its cost;
* force control (`Punch.pull`, Q = f P / 2): how many positions the secant steps need.

And in 3D, the P1 sphere at ν = 0.3 (h = a/6, a block 10 a wide, f = 0.3) pressed by δ and
moved by 0.002: the active set (slip directions by Newton, a spring across each slip)
against the vector penalty peer at k = 10, 100, 1000 E/h.

    python benchmarks/friction.py [--quick] [--update-docs]
"""

from __future__ import annotations

import math
import time

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import numpy as np
from common import machine, options, publish
from peers import solve_friction_penalty
from punch_problem import build_punch

from fenics_nl.materials.laws import LinearElastic
from fenics_nl.theory import hertz, mindlin

R, DELTA, F, SHIFT = 1.0, 0.01, 0.3, 0.0023


def cylinder(refine: int):
    return build_punch("plane_strain", LinearElastic(1.0, 0.5), R, math.sqrt(R * DELTA),
                       refine=refine, block=100.0, mixed=True, tangential=True, friction=F)


def mindlin_errors(punch, x, q, P, Q, stick_radius=None) -> dict:
    """The nodal traction's largest error against Cattaneo–Mindlin (beyond 2 h of ±c, over
    f p0), and the stick half-width's error over h."""
    H = hertz.cylinder_from_force(1.0, 0.5, R, P)
    a, p0 = H["contact_radius"], H["max_pressure"]
    c = mindlin.cylinder_stick_half_width(a, Q, F * P)
    h = punch.block.h
    away = (np.abs(np.abs(x) - c) > 2 * h) & (np.abs(x) < 1.5 * a)
    out = {"traction_error": float(np.abs(q - mindlin.traction(x, a, p0, F, c))[away].max()
                                   / (F * p0)), "f_p0": F * p0}
    if stick_radius is not None:
        out["stick_radius_error_over_h"] = (stick_radius - c) / h
    return out


def active_set(refine: int) -> tuple[dict, np.ndarray]:
    punch = cylinder(refine)
    t0 = time.perf_counter()
    pressed = punch.indent(DELTA)
    punch.commit()
    t1 = time.perf_counter()
    moved = punch.shift(SHIFT)
    t2 = time.perf_counter()
    c = punch.contact
    q = (c.tangential_forces()[:, 0] / c.surface.nodal_areas())[c.owned]
    x = c.x[c.owned, 0]
    row = {"method": "active set", "dofs": punch.dofs, "time_s": t2 - t0,
           "press_s": t1 - t0, "shift_s": t2 - t1,
           "status_iterations": [pressed.active_set_iterations, moved.status_iterations],
           "newton_iterations": pressed.newton_iterations + moved.newton_iterations,
           "factorizations": pressed.factorizations + moved.factorizations,
           "force": moved.normal_force, "tangential_force": moved.tangential_force,
           "stick_nodes": moved.stick_nodes, "slip_nodes": moved.slip_nodes,
           **mindlin_errors(punch, x, q, moved.normal_force, moved.tangential_force,
                            moved.stick_radius)}
    order = np.argsort(x)
    return row, (punch, x[order], q[order])


def penalty(punch, kappa: float, reference: dict, x_ref, q_ref) -> dict:
    r = solve_friction_penalty(punch, DELTA, SHIFT, kappa * 1.0 / punch.block.h, F)
    order = np.argsort(r["x"])
    x, q = r["x"][order], r["traction"][order]
    if not np.allclose(x, x_ref):
        raise RuntimeError("the peer's nodes differ from the active set's")
    return {"method": f"penalty k = {kappa:g} E/h", "kappa": kappa, "dofs": punch.dofs,
            "time_s": r["wall_time_s"], "newton_iterations": r["iterations"],
            "factorizations": r["factorizations"], "force": r["force"],
            "tangential_force": r["tangential_force"],
            "q_vs_active_set": float(np.abs(q - q_ref).max() / reference["f_p0"]),
            "Q_vs_active_set": r["tangential_force"] / reference["tangential_force"] - 1,
            "max_penetration": r["max_penetration"],
            **mindlin_errors(punch, x, q, r["force"], r["tangential_force"])}


def force_control(refine: int) -> dict:
    punch = cylinder(refine)
    pressed = punch.indent(DELTA)
    punch.commit()
    t0 = time.perf_counter()
    moved, positions = punch.pull(0.5 * F * pressed.force)
    return {"positions": positions, "time_s": time.perf_counter() - t0,
            "tangential_force": moved.tangential_force, "force": moved.normal_force}


def sphere(kappas) -> dict:
    """The 3D rows: active set and penalty peers on the same P1 sphere."""
    punch = build_punch("3d", LinearElastic(1.0, 0.3), R, math.sqrt(R * DELTA), refine=0,
                        block=10.0, tangential=True, friction=F)
    t0 = time.perf_counter()
    pressed = punch.indent(DELTA)
    punch.commit()
    moved = punch.shift(0.002)
    c = punch.contact
    q = (c.tangential_forces()[:, 0] / c.surface.nodal_areas())[c.owned]
    out = {"dofs": punch.dofs, "time_s": time.perf_counter() - t0,
           "status_iterations": [pressed.active_set_iterations, moved.status_iterations],
           "factorizations": pressed.factorizations + moved.factorizations,
           "tangential_force": moved.tangential_force, "penalty": []}
    for kappa in kappas:
        r = solve_friction_penalty(punch, DELTA, 0.002, kappa / punch.block.h, F)
        out["penalty"].append({
            "kappa": kappa, "time_s": r["wall_time_s"], "newton_iterations": r["iterations"],
            "factorizations": r["factorizations"],
            "Q_vs_active_set": r["tangential_force"] / moved.tangential_force - 1,
            "q_vs_active_set": float(np.abs(r["traction"] - q).max() / np.abs(q).max())})
        print(out["penalty"][-1], flush=True)
    return out


def table(out: dict) -> str:
    a = out["active_set"]
    lines = [f"Cattaneo–Mindlin cylinder, ν = 1/2 (Taylor–Hood), f = {F}, D = {SHIFT} "
             f"(Q = {a['tangential_force'] / (F * a['force']):.3f} f P), {a['dofs']} "
             "unknowns, 1 rank.", "",
             "| method | time (s) | Newton iterations | factorizations | Q vs active set | "
             "q vs active set (/ f p0) | q vs Cattaneo–Mindlin (/ f p0) |",
             "|---|---|---|---|---|---|---|",
             f"| active set ({a['status_iterations'][0]} + {a['status_iterations'][1]} "
             f"status iterations) | {a['time_s']:.2f} | {a['newton_iterations']} | "
             f"{a['factorizations']} | — | — | {100 * a['traction_error']:.2f} % |"]
    for r in out["penalty"]:
        lines.append(f"| {r['method']} | {r['time_s']:.2f} | {r['newton_iterations']} | "
                     f"{r['factorizations']} | {r['Q_vs_active_set']:+.1e} | "
                     f"{100 * r['q_vs_active_set']:.3f} % | {100 * r['traction_error']:.2f} % |")
    fc = out["force_control"]
    lines += ["", f"Stick half-width of the active set: (c − c_exact)/h = "
              f"{a['stick_radius_error_over_h']:+.2f}; traction errors are taken beyond 2 h "
              "of the stick–slip edges. Force control (Q = f P / 2) took "
              f"{fc['positions']} punch positions, {fc['time_s']:.1f} s after pressing. "
              "`python benchmarks/friction.py`"]
    sp = out["sphere"]
    lines += ["", f"3D: the P1 sphere, ν = 0.3, f = {F}, moved by 0.002 after pressing, "
              f"{sp['dofs']} unknowns, 1 rank.", "",
              "| method | time (s) | iterations | factorizations | Q vs active set | "
              "q vs active set (/ largest) |", "|---|---|---|---|---|---|",
              f"| active set | {sp['time_s']:.2f} | {sp['status_iterations'][0]} + "
              f"{sp['status_iterations'][1]} status iterations | {sp['factorizations']} | — "
              "| — |"]
    for r in sp["penalty"]:
        lines.append(f"| penalty k = {r['kappa']:g} E/h | {r['time_s']:.2f} | "
                     f"{r['newton_iterations']} Newton | {r['factorizations']} | "
                     f"{r['Q_vs_active_set']:+.1e} | {100 * r['q_vs_active_set']:.2f} % |")
    return "\n".join(lines)


def main():
    args = options(__doc__, "two penalty values, nothing written")
    out = {"machine": machine()}
    out["active_set"], (punch, x, q) = active_set(0)
    print(out["active_set"], flush=True)
    kappas = (1.0, 100.0) if args.quick else (1.0, 10.0, 100.0, 1000.0)
    out["penalty"] = []
    for kappa in kappas:
        out["penalty"].append(penalty(punch, kappa, out["active_set"], x, q))
        print(out["penalty"][-1], flush=True)
    out["force_control"] = force_control(0)
    out["sphere"] = sphere((10.0, 100.0) if args.quick else (10.0, 100.0, 1000.0))
    publish("friction", out, table, args)


if __name__ == "__main__":
    main()
