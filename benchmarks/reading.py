"""Which method when: the reading of the benchmarks in docs/benchmarks.md, from their results.

Every figure and every choice ("fastest", "gave up at") is computed from the JSON files in
benchmarks/results/, so the text stays true when `make bench` is run again. A benchmark
whose result file is missing is left out.

    python benchmarks/reading.py [--update-docs]
"""

from __future__ import annotations

import argparse
import json
from itertools import pairwise
from pathlib import Path

from common import outside_kernels, update_docs

RESULTS = Path(__file__).resolve().parent / "results"


def load(name: str) -> dict | None:
    path = RESULTS / f"{name}.json"
    return json.loads(path.read_text()) if path.exists() else None


def fastest(rows: dict, time_key: str, exclude: str = "\0") -> str:
    return min((k for k in rows if exclude not in k), key=lambda k: rows[k][time_key])


def kilo(dofs: int) -> str:
    return f"{round(dofs / 1000)}k"


def newton(n: dict) -> str:
    v = n["variants"]
    full, best = v["full"], fastest(v, "wall_time_s", exclude="SNES")
    mod, snes = v["modified"], v["SNES newtonls"]

    def fact(r):
        return r["phase_time_s"]["factorization"]

    return (
        f"* **A smoothly non-linear material with a direct solver** (power-law cantilever, "
        f"{n['dofs']} unknowns, one load step, MUMPS): **{best}** is the fastest, "
        f"{v[best]['wall_time_s']:.1f} s against {full['wall_time_s']:.1f} s for full Newton "
        f"({n['ratio_best_over_full']:.2f}x) with {v[best]['factorizations']} factorization(s) "
        f"for {v[best]['iterations']} iterations, where full Newton needs "
        f"{full['iterations']} iterations and as many factorizations. Modified Newton's "
        f"{mod['iterations']} iterations on one factorization cost "
        f"{mod['wall_time_s'] / full['wall_time_s']:.2f}x full Newton. The hand-written loop "
        f"costs {n['ratio_full_over_snes']:.2f}x SNES `newtonls` ({full['iterations']} "
        f"against {snes['iterations']} iterations); MUMPS took {fact(full):.1f} s against "
        f"{fact(snes):.1f} s to factorize the same matrices, and outside the assembly and "
        f"solver kernels the hand-written loop spent {outside_kernels(full):.2f} s, SNES "
        f"{outside_kernels(snes):.2f} s.")


def bracket(b: dict, large: dict | None) -> list[str]:
    out = []
    ranking = []
    for row in b["refinement"]:
        v = {k: x for k, x in row["variants"].items() if "1 step" not in k}
        best = fastest(v, "solve_time_s")
        ranking.append(f"{kilo(row['dofs'])}: {best} "
                       f"{v['full']['solve_time_s'] / v[best]['solve_time_s']:.1f}x faster")
    rows = b["refinement"] + (large["refinement"][-1:] if large else [])
    ratios = [r["variants"]["bfgs, 1 step"]["over_linear"] for r in rows]
    one = [f"{x:.1f} at {kilo(r['dofs'])}" for x, r in zip(ratios, rows, strict=True)]
    trend = (", falling as the mesh grows (the one factorization takes a larger share)"
             if all(x > y for x, y in pairwise(ratios)) else "")
    out.append(
        "* **The same on a 3D part** (bracket, P2, 4 load steps): the fastest four-step "
        f"variant and its gain on full Newton per mesh: {'; '.join(ranking)}. The power law "
        "is hyperelastic, so one load step is legitimate: quasi-Newton on a single "
        f"factorization then costs {', '.join(one)} linear solves{trend}.")
    if "iterative" in b:
        g = b["iterative"]
        v = g["variants"]
        best = fastest(v, "solve_time_s")
        items = ", ".join(f"{k} {x['solve_time_s']:.1f} s ({x['newton_iterations']} its, "
                          f"{x['krylov_iterations']} CG)" for k, x in v.items())
        out.append(
            f"* **With CG + GAMG** (bracket, {kilo(g['linear']['dofs'])} unknowns, one "
            f"step) the ranking turns over: {items}; **{best}** wins. With no factorization to "
            "amortize, every iteration costs a Krylov solve, so the fewest iterations win; "
            "the inexact-Newton forcing term keeps the early CG solves loose. Keeping the "
            "step's first AMG hierarchy, what a frozen tangent saves with a direct solver, "
            "saves little here"
            + (f" ({lag['factorizations']} set-ups for {lag['newton_iterations']} "
               f"iterations, {lag['solve_time_s']:.1f} s against "
               f"{fresh['solve_time_s']:.1f} s with one per tangent: GAMG reuses its "
               "interpolation, so a set-up is cheap)"
               if (lag := v.get("full")) and (fresh := v.get("full, AMG per tangent"))
               else "") + ".")
    extrapolated = [r for r in (b, large) if r and r["richardson"]]
    if extrapolated:  # the finest meshes extrapolate best
        r = extrapolated[-1]
        finest, rich = r["refinement"][-1], r["richardson"]
        u = [x["load_point_displacement"] for x in finest["variants"].values()]
        text = (f"* **Accuracy of the bracket** ({kilo(finest['dofs'])}): the variants agree "
                f"on |u_load| to {(max(u) - min(u)) / max(u):.0e}, so its error is the mesh's: "
                f"{abs(u[0] / rich['extrapolated'] - 1):.1%} from the Richardson value "
                f"{rich['extrapolated']:.4f} mm (observed order {rich['order']:.2f}; the "
                "clamped bolt-hole edges are singular)")
        if len(extrapolated) == 2:
            coarse = b["richardson"]["extrapolated"]
            text += (f". The coarser meshes of `make bench` extrapolate to {coarse:.4f} mm, "
                     f"{abs(coarse / rich['extrapolated'] - 1):.1%} lower: they are not yet "
                     "in the asymptotic range, so their error column is optimistic")
        out.append(text + ".")
    sp = [f"{k} **{p['speedup']:.2f}** at {kilo(p['1']['dofs'])}"
          for r in (b, large or {}) for k, p in r.get("parallel", {}).items()]
    if sp:
        out.append(f"* **2 ranks against 1** (MUMPS, bracket): speed-up {'; '.join(sp)}.")
    if large and "large" in large:
        g = large["large"]
        f = g["full, 1 step"]
        out.append(
            f"* **Beyond a direct solver** ({f['dofs']} unknowns, CG + GAMG, 2 ranks): full "
            f"Newton in one step, {f['solve_time_s']:.0f} s, {g['over_linear']:.1f} linear "
            f"solves, {f['peak_memory_mb']:.0f} MB per rank.")
    return out


def buckling(k: dict) -> str:
    v = k["variants"]
    gave_up = [f"{m} after {x['failed_at_load_ratio']:.3f} P_cr" for m, x in v.items()
               if x["failed_at_load_ratio"] is not None]
    through = [f"{m} ({x['mean_iterations_away']:.1f} iterations per step away from it, "
               f"{x['mean_iterations_near']:.1f} near)" for m, x in v.items()
               if x["failed_at_load_ratio"] is None]
    s = k["step_control"]
    quick = min(s, key=lambda m: s[m]["wall_time_s"])
    q1 = [x for x in k["refinement"] if x["degree"] == 1][-1]
    q2 = next(x for x in k["refinement"] if x["degree"] == 2)
    fixed = s["fixed, 40 steps"]
    return (
        "* **Through a bifurcation** (buckling beam, 40 steps to 2 P_cr; the tangent is "
        f"singular at P_cr): gave up: {'; '.join(gave_up) or 'none'}; went through: "
        f"{' and '.join(through) or 'none'}. "
        f"Cheapest path: {quick}, {s[quick]['wall_time_s']:.2f} s against "
        f"{fixed['wall_time_s']:.2f} s for 40 fixed steps, tip rotation "
        f"{s[quick]['tip_rotation_error_deg']:+.3f}° from the elastica against "
        f"{fixed['tip_rotation_error_deg']:+.3f}°. Elements: Q2 at "
        f"{q2['dofs']} unknowns gives P_cr to {100 * abs(q2['critical_load_rel_error']):.3f} % "
        f"where Q1 at {q1['dofs']} is {100 * q1['critical_load_rel_error']:+.1f} % (locking).")


def contact(c: dict) -> str:
    m = c["same_mesh"]
    elim = m["active set, elimination (new rows on one factorization)"]
    lin = m["linear solve"]["wall_time_s"]
    each, vi = m["active set, elimination, a factorization per iteration"], m[
        "SNES VI (vinewtonrsls)"]
    pen = {k: x for k, x in m.items() if k.startswith("penalty")}
    close = [k for k, x in pen.items() if abs(x["force"] / elim["force"] - 1) < 1e-3]
    first = close[0] if close else None
    pen_text = (f"penalty needs {first.removeprefix('penalty ')} to come within 0.1 % of it "
                f"({pen[first]['wall_time_s'] / elim['wall_time_s']:.1f}x the time, "
                f"{pen[first]['iterations']} Newton iterations)" if first else
                "no penalty tried comes within 0.1 % of it")
    ratios = {model: [r["wall_time_s"] / r["linear_solve_time_s"] for r in c[model]]
              for model in ("axisymmetric", "3d")}
    return (
        "* **Frictionless contact** (axisymmetric punch, same mesh): the active set with "
        f"elimination takes {elim['wall_time_s']:.2f} s ({elim['iterations']} iterations, "
        f"{elim['factorizations']} factorization(s): the later sets are a bordered solve on "
        f"it; {each['factorizations']} and {each['wall_time_s']:.2f} s with one per "
        f"iteration), {elim['wall_time_s'] / lin:.1f} linear solves (over the refinements: "
        f"axisymmetric {min(ratios['axisymmetric']):.1f}–{max(ratios['axisymmetric']):.1f}, "
        f"3D {min(ratios['3d']):.1f}–{max(ratios['3d']):.1f}); SNES VI reaches the same "
        f"force in {vi['wall_time_s'] / elim['wall_time_s']:.1f}x the time; {pen_text}. "
        "The multiplier form gives the same force to "
        f"{abs(m['active set, multipliers']['force'] / elim['force'] - 1):.0e} in "
        f"{m['active set, multipliers']['wall_time_s'] / elim['wall_time_s']:.1f}x the time, "
        "with the contact pressure as an unknown.")


def factorizations(full: dict) -> str:
    """Full Newton's factorization count, and why it is below its iterations."""
    if full["factorizations"] >= full["newton_iterations"]:
        return "as many factorizations"
    return (f"{full['factorizations']} factorizations: a tangent equal to one factorized "
            "already, as Hooke's wherever no point yields, is not factorized again")


def plasticity(p: dict) -> list[str]:
    """J2: the Newton variants on the sphere and the bracket, near the limit, 1 vs 2 ranks."""
    out = []
    for scene, steps, where in (("sphere", p["sphere_steps"], "thick sphere to 0.9 p_lim"),
                                ("bracket", p["bracket_steps"], "bracket, 8 kN")):
        rows = p[scene]
        finest = max(r["dofs"] for r in rows)
        v = {r["newton"]: r for r in rows if r["dofs"] == finest}
        full, mod, snes = v["full"], v["modified"], v["snes"]
        best = fastest(v, "solve_time_s")
        ratio = mod["solve_time_s"] / full["solve_time_s"]
        verdict = (f"{ratio:.2f}x the time of full Newton" if ratio > 1 else
                   f"{1 / ratio:.2f}x faster than full Newton")
        if ratio > 1 and "phase_time_s" in mod:
            res, fac = mod["phase_time_s"]["residual"], full["phase_time_s"]["factorization"]
            verdict += (f": its {mod['newton_iterations']} residual assemblies (the return map "
                        f"at every quadrature point) took {res:.1f} s, "
                        f"{'more than' if res > fac else 'against'} the {fac:.1f} s of full "
                        f"Newton's {full['factorizations']} factorizations")
        out.append(
            f"* **J2 plasticity, {where}** ({finest} unknowns, {steps} steps, MUMPS): "
            f"**{best}** is the fastest, {v[best]['solve_time_s']:.2f} s "
            f"({v[best]['newton_iterations']} iterations, {v[best]['factorizations']} "
            f"factorization(s)) against {full['solve_time_s']:.2f} s for full Newton "
            f"({full['newton_iterations']} iterations, {factorizations(full)}; "
            f"{full['solve_time_s'] / steps / full['linear_solve_s']:.1f} linear solves per "
            f"step). The course's modified Newton, the elastic tangent factorized once, is "
            f"{verdict}. SNES `newtonls` on the same residual and tangent: "
            f"{snes['newton_iterations']} iterations, "
            f"{snes['solve_time_s'] / full['solve_time_s']:.2f}x the hand-written loop.")
    if p.get("near_limit"):
        rows = {r["newton"]: r for r in p["near_limit"]}
        ok = {k: r for k, r in rows.items() if not r["failed"]}
        full = ok.get("full")
        items = []
        for k, r in rows.items():
            if r["failed"]:
                items.append(f"{k} failed ({r['failed']})")
            else:
                ratio = (f", {r['solve_time_s'] / full['solve_time_s']:.1f}x full"
                         if full and k != "full" else "")
                items.append(f"{k} {r['solve_time_s']:.2f} s ({r['newton_iterations']} "
                             f"iterations, {r['step_cuts']} step cuts{ratio})")
        out.append(
            f"* **Near the limit load** (sphere to {p['near_limit'][0]['ratio']:g} p_lim, "
            f"{kilo(next(iter(ok.values()))['dofs']) if ok else '?'} unknowns): "
            f"{'; '.join(items)}. Perfect plasticity near its limit load leaves the structure "
            "almost no tangent stiffness: the consistent tangent knows it, the elastic one does "
            "not, and modified Newton's convergence factor approaches 1.")
    if p.get("parallel"):
        sp = [f"{r['scene']} {r['newton']} **{r['speedup']:.2f}** at {kilo(r['dofs'])}"
              for r in p["parallel"]]
        out.append(f"* **J2 on 2 ranks against 1** (MUMPS): speed-up {'; '.join(sp)}; the "
                   "2-rank answers equal the serial ones to "
                   f"{max(r['agree'] for r in p['parallel']):.0e}.")
    return out


def plasticity_peer(q: dict) -> str:
    """Ours against dolfinx-external-operator on the largest common mesh."""
    r = q["rows"][-1]
    ours, peer, plain = r["ours"], r["peer"], r["peer, newtonls"]
    ours_ldl, plain_ldl = r.get("ours, LDLᵀ"), r.get("peer, newtonls, LDLᵀ")

    def other(c):  # loop time outside the residual, tangent, factorization, solve phases
        return c["time_s"] - sum(c["phase_time_s"].values())

    text = (f"* **Against dolfinx-external-operator** (J2 thick cylinder with hardening, "
            f"{r['dofs']} unknowns, 19 increments, same mesh and stopping test): ours "
            f"{ours['time_s']:.1f} s ({ours['newton_iterations']} Newton iterations); the "
            f"package's set-up (Numba return map, SNES `vinewtonrsls`) "
            f"{peer['time_s']:.1f} s ({peer['newton_iterations']}), "
            f"**{peer['time_s'] / ours['time_s']:.2f}x** ours, with the same u(a) to "
            f"{abs(peer['inner_displacement'] / ours['inner_displacement'] - 1):.0e}. Of that, "
            f"{other(peer):.1f} s is spent outside PETSc's residual, Jacobian, factorization "
            f"and solve events (the VI solver's own work), {other(plain):.1f} s with "
            f"`newtonls`, which takes {plain['time_s']:.1f} s "
            f"({plain['time_s'] / ours['time_s']:.2f}x ours). The Numba return map itself "
            f"costs {peer['phase_time_s']['return map (Numba)']:.1f} s; ours evaluates the "
            f"radial return inside the tangent kernel, assembled on one rank into DOLFINx's "
            f"CSR matrix that MUMPS reads: {ours['phase_time_s']['tangent']:.1f} s of tangent "
            f"assembly against the peer's {plain['phase_time_s']['tangent']:.1f} s.")
    ldl = all("ours, LDLᵀ" in row and "peer, newtonls, LDLᵀ" in row for row in q["rows"])
    text += (" The peer's `newtonls` over ours on every mesh ("
             + ", ".join(f"{row['dofs']}" for row in q["rows"]) + " unknowns): LU "
             + ", ".join(f"{row['peer, newtonls']['time_s'] / row['ours']['time_s']:.2f}"
                         for row in q["rows"])
             + ("; LDLᵀ against LDLᵀ " + ", ".join(
                 f"{row['peer, newtonls, LDLᵀ']['time_s'] / row['ours, LDLᵀ']['time_s']:.2f}"
                 for row in q["rows"]) if ldl else "")
             + (f" (each code's fastest of {q['rows'][0]['repeat']} rounds)."
                if q["rows"][0].get("repeat", 1) > 1 else "."))
    if ours_ldl and plain_ldl:
        gain = (ours["phase_time_s"]["factorization"]
                / ours_ldl["phase_time_s"]["factorization"])
        text += (f" Both tangents are symmetric, and MUMPS's LDLᵀ factorizes them {gain:.2f}x "
                 f"faster than its LU: ours with it {ours_ldl['time_s']:.1f} s, "
                 f"{plain['time_s'] / ours_ldl['time_s']:.2f}x faster than the peer's `newtonls` "
                 f"with LU and {plain_ldl['time_s'] / ours_ldl['time_s']:.2f}x faster than the "
                 f"peer's `newtonls` with LDLᵀ too (like for like). The factorizations are "
                 f"{ours_ldl['phase_time_s']['factorization'] / ours_ldl['time_s']:.0%} of "
                 f"our run: a faster kernel moves the ratio only that far.")
    return text


def near_incompressible(x: dict) -> str:
    """Displacement against mixed at each ν, on the punch and the neo-Hookean cylinder."""
    def row(name, nu, form):
        return next((r for r in x[name] if r["nu"] == nu and r["formulation"] == form
                     and not r.get("failed")), None)

    parts = []
    # the cylinder's closed form is the incompressible one: below ν = 0.5 its gap is also the
    # material's compressibility, so only 0.499 and 0.5 are read there
    for name, what in (("punch", "the punch's force"),
                       ("cylinder", "the neo-Hookean cylinder's p(a)")):
        d, m = row(name, 0.499, "displacement"), row(name, 0.499, "mixed")
        m5 = row(name, 0.5, "mixed")
        if not (d and m and m5):
            continue
        d3, m3 = row(name, 0.3, "displacement"), row(name, 0.3, "mixed")
        parts.append(f"{what} at ν = 0.499 is {100 * d['error']:+.2f} % off with displacements "
                     f"({d['dofs']} unknowns, {d['time_s']:.2f} s) and {100 * m['error']:+.3f} % "
                     f"with Taylor–Hood ({m['dofs']}, {m['time_s']:.2f} s), "
                     f"{100 * m5['error']:+.3f} % at ν = 0.5"
                     + (f"; at ν = 0.3: {100 * d3['error']:+.3f} % in {d3['time_s']:.2f} s "
                        f"against {100 * m3['error']:+.3f} % in {m3['time_s']:.2f} s"
                        if d3 and m3 and name == "punch" else ""))
    p2 = next((r for r in x.get("punch_p2", []) if r["nu"] == 0.499), None)
    m = row("punch", 0.499, "mixed")
    if p2 and m:
        close = abs(p2["error"]) < 2 * abs(m["error"]) + 1e-3
        bd, bm = row("beam", 0.499, "displacement"), row("beam", 0.499, "mixed")
        fine = x.get("beam_fine")
        bending = (f" (the beam's P_cr at ν = 0.499: {100 * bd['error']:+.2f} % with Q2, "
                   f"{100 * bm['error']:+.2f} % with Q2–Q1"
                   + (f", {100 * fine[0]['error']:+.2f} % with Q2–Q1 at "
                      f"{fine[0]['dofs']} unknowns: the clamp's 2D effect" if fine else "")
                   + ")" if bd and bm else "")
        parts.append(f"on the punch at ν = 0.499, P2 displacements give "
                     f"{100 * p2['error']:+.3f} % ({p2['dofs']} unknowns, "
                     f"{p2['time_s']:.2f} s)"
                     + (": there the degree alone cures P1's locking, but P2 still locks in "
                        f"bending{bending} and in nearly isochoric flow (the power-law "
                        "bracket), and only the mixed form takes ν = 0.5"
                        if close else ", far from Taylor–Hood's"))
    if f := x.get("punch_factorizations"):
        lu, ldlt = f
        parts.append(f"MUMPS LDLᵀ on the mixed punch's saddle point takes "
                     f"{ldlt['time_s'] / lu['time_s']:.2f}x the time of LU")
    rows = x.get("linear_solvers") or []
    if rows:
        h = min(r["h"] for r in rows)
        it = [r for r in rows if r["h"] == h and r["linear"] == "gamg"]
        lu = [r for r in rows if r["h"] == h and r["linear"] == "lu"]
        counts = [r["krylov_iterations"] for r in it]
        parts.append(f"MINRES with the block preconditioner takes {min(counts)} to "
                     f"{max(counts)} iterations from ν = {it[0]['nu']} to {it[-1]['nu']} "
                     f"({it[0]['dofs']} unknowns), "
                     f"{sum(r['time_s'] for r in it) / sum(r['time_s'] for r in lu):.1f}x the "
                     "time of MUMPS on this 2D problem")
    return ("* **Near-incompressible** (`--mixed`): " + "; ".join(parts) + ".") if parts else ""


def friction(x: dict) -> str:
    """The active set against the penalty peer on Cattaneo–Mindlin."""
    a, pen = x["active_set"], x["penalty"]
    close = next((r for r in pen if r["q_vs_active_set"] < 0.01), None)
    peer = (f"the penalty peer comes within 1 % of its nodal traction at "
            f"{close['method'].removeprefix('penalty ')} ({close['time_s'] / a['time_s']:.1f}x "
            f"the time, {close['newton_iterations']} Newton iterations, each a "
            f"factorization)" if close else "no penalty tried comes within 1 % of its traction")
    return ("* **Coulomb friction** (Cattaneo–Mindlin cylinder, ν = 1/2, "
            f"{a['dofs']} unknowns): the active set takes {a['time_s']:.1f} s "
            f"({a['status_iterations'][0]} + {a['status_iterations'][1]} status iterations, "
            f"{a['factorizations']} factorizations) for a traction within "
            f"{100 * a['traction_error']:.1f} % of f p0 of the closed form; " + peer
            + f"; force control needs {x['force_control']['positions']} punch positions. "
            "Pick the active set: exact conditions, no parameter; the penalty's k trades "
            "accuracy for Newton iterations.")


def continuation(x: dict) -> str:
    """Arc-length against load control on the arch (limit points) and the beam
    (bifurcation)."""
    rows = x["rows"]

    def done(problem, control):
        return [r for r in rows if r["problem"] == problem and r["control"] == control
                and "steps" in r]

    def names(rs):
        return ", ".join(r["newton"] for r in rs) or "none"

    arc_arch, load_arch = done("arch", "arc-length"), done("arch", "load")
    arc_beam, load_beam = done("beam", "arc-length"), done("beam", "load")
    cheapest = min(arc_arch, key=lambda r: r["time_s"]) if arc_arch else None
    text = (f"* **Through limit points and bifurcations** (shallow arch to {x['target']:g} "
            f"limit loads, perfect beam to {x['target']:g} P_cr): arc-length continuation "
            f"traces the arch's whole path with {names(arc_arch)} Newton")
    if cheapest:
        text += (f" ({cheapest['newton']} the fastest, {cheapest['time_s']:.1f} s, "
                 f"{cheapest['factorizations']} factorizations for "
                 f"{cheapest['iterations']} iterations, "
                 f"{cheapest['unstable_states']} states on the unstable branch)")
    text += (f"; load control reaches the target with {names(load_arch)} only by jumping "
             "over the snap (no state between the limit points, none of them found)")
    text += (f". On the perfect beam arc-length finds the bifurcation by the tangent's "
             f"inertia and leaves it along its mode with {names(arc_beam)}, where load control "
             f"gets there with {names(load_beam)} and only by a kick sized by the elastica. "
             "Pick arc-length for a path with limit points or a bifurcation to find; full or "
             "periodic Newton for it on a beam, whose flat post-buckling branch takes the "
             "constant-tangent variants many short steps.")
    return text


def damage(d: dict, peer: dict | None) -> str:
    """Alternate minimization, plain and Anderson-accelerated; against phasefieldx."""
    surf = {r["scheme"]: r for r in d["rows"] if r["problem"] == "surfing"}
    plain, fast = surf["none"], surf["anderson"]
    text = (f"* **Gradient damage** (alternate minimization, the damage bounded by SNES VI): "
            f"on the surfing crack Anderson acceleration takes {fast['alternate_iterations']} "
            f"alternate iterations where the plain iteration takes "
            f"{plain['alternate_iterations']}, {fast['time_s']:.1f} s against "
            f"{plain['time_s']:.1f} s, the same crack "
            f"({abs(fast['answer'] / plain['answer'] - 1):.0e} in its release rate)")
    if peer:
        rows = [r for r in peer["rows"] if r["ell"] == min(r["ell"] for r in peer["rows"])]
        by = {r["scheme"]: r for r in rows}
        ours, other = by["anderson"], by["phasefieldx"]
        text += (f"; on Miehe's notched square (AT2, ℓ = {ours['ell']:g} mm, "
                 f"{ours['dofs']} unknowns, {ours['steps']} steps) it takes "
                 f"{ours['time_s']:.1f} s against phasefieldx's {other['time_s']:.1f} s "
                 f"(**{other['time_s'] / ours['time_s']:.1f}x** ours) for a peak force "
                 f"{100 * (other['peak_force'] / ours['peak_force'] - 1):+.1f} % from ours and "
                 f"the same straight crack; the peer's history field dissipates "
                 f"{other['dissipated_energy'] / ours['dissipated_energy']:.2f} times our "
                 f"bounded damage's energy")
    return text + (". Pick Anderson where a crack grows: its guard (an iterate is kept only "
                   "if it lowers the energy) costs one u-solve when it refuses one.")


def forming(x: dict) -> str:
    """The upsetting's Newton variants and size, the necking bar's mesh study."""
    rows = {(r["problem"], r["variant"]): r for r in x["variants"]}
    lines = []
    for problem in dict.fromkeys(r["problem"] for r in x["variants"]):
        full = rows[(problem, "full")]
        parts = []
        for variant in ("full, point forces", "modified", "bfgs"):
            r = rows.get((problem, variant))
            if r is None:
                continue
            parts.append(f"{variant} does not converge ({r['failed'].split(': ', 1)[-1]})"
                         if "failed" in r else
                         f"{variant} {r['time_s'] / full['time_s']:.2f}x its time")
        lines.append(f"{problem}: full Newton {full['time_s']:.1f} s "
                     f"({full['step_in_linear_solves']:.0f} linear solves a step), "
                     + ", ".join(parts))
    one, two = (next(r for r in x["size"] if r["ranks"] == k) for k in (1, 2))
    free = sorted((r for r in x["necking"] if not r.get("gripped") and "failed" not in r),
                  key=lambda r: r["dofs"])
    n, coarser = free[-1], free[-2]
    change = max(abs(v - coarser["radius_ratio"][u]) for u, v in n["radius_ratio"].items())
    ratios = ", ".join(f"{float(u):g} mm {v:.3f}" for u, v in n["radius_ratio"].items())
    best = {problem: min((r for r in x["variants"]
                          if r["problem"] == problem and "failed" not in r),
                         key=lambda r: r["time_s"])["variant"]
            for problem in dict.fromkeys(r["problem"] for r in x["variants"])}
    fastest = "; ".join(f"{p}: {v} is the fastest" for p, v in best.items())
    return ("* **Forming at finite strain** (J2 with the die's active set): "
            + "; ".join(lines) + f". {fastest}. The 50 % upsetting with friction at "
            f"{one['dofs']} unknowns takes {one['wall_time_s'] / 60:.1f} min on 1 rank, "
            f"{two['wall_time_s'] / 60:.1f} min on 2 "
            f"({one['wall_time_s'] / two['wall_time_s']:.2f}x). The necking bar's neck radius "
            f"r/r0 ({n['cells']} cells; at most {change:.3f} from {coarser['cells']} cells): "
            f"{ratios} a end; its peak force {n['peak_force_kN']:.2f} kN, "
            f"Considère's for the neck section {x['considere_force_kN']:.2f} kN.")


def run_times(names) -> str:
    parts = [(n, d["benchmark_time_s"]) for n in names
             if (d := load(n)) and "benchmark_time_s" in d]
    total = sum(t for _, t in parts)
    each = ", ".join(f"{n} {t / 60:.1f}" for n, t in parts)
    return f"Run time of these benchmarks on this machine: {total / 60:.0f} min ({each} min)."


def iterative(it: dict) -> str:
    """Every capability on CG + GAMG: Krylov per Newton iteration and cost, coarse to fine."""
    first, last = it["meshes"][0], it["meshes"][-1]
    parts = []
    for name, r in last["capabilities"].items():
        c = first["capabilities"][name]
        parts.append(f"{name} {c['krylov_per_newton']:.0f} → {r['krylov_per_newton']:.0f} "
                     f"Krylov its per Newton it, {r['over_linear']:.1f} linear solves")
    worst = max(abs(r.get("direct_rel_difference", 0)) for r in first["capabilities"].values())
    return (f"* **Every capability on the iterative path** (bracket, CG + GAMG, {it['ranks']} "
            f"ranks, {kilo(first['linear']['dofs'])} → {kilo(last['linear']['dofs'])} "
            f"unknowns): {'; '.join(parts)}. The answers are MUMPS's to {worst:.0e}. A step of "
            "a smooth problem costs a few linear solves; contact and friction cost one Newton "
            "solve per active-set iteration, each with its AMG set-up.")


def arch_iterative(a: dict) -> str:
    """Arc-length on GMRES + GAMG against MUMPS: the arch's K₀ solve and its first steps."""
    coarse, fine = a["linear"][0], a["linear"][-1]
    lu, gamg = ({r["kind"]: r for r in a["paths"]}[k] for k in ("lu", "gamg"))
    reach = "past the first limit point" if gamg["past_the_limit_point"] else (
        f"to λ = {gamg['largest_load_factor']:.4f}, short of the limit point")
    return (f"* **Arc-length on the iterative path** (the shallow arch, L/h = 200): one solve of "
            f"its tangent takes CG + GAMG {coarse['gamg']['iterations']} → "
            f"{fine['gamg']['iterations']} iterations ({kilo(coarse['dofs'])} → "
            f"{kilo(fine['dofs'])} unknowns) where MUMPS takes {fine['lu']['time_s']:.2f} s at "
            f"the finest; {a['steps']} path steps take GMRES + GAMG {gamg['wall_time_s']:.0f} s "
            f"({gamg['work']['krylov_iterations']} Krylov its) {reach}, MUMPS "
            f"{lu['wall_time_s']:.1f} s. Pick the direct solver for a thin 2D body's path: "
            "its bending modes defeat smoothed aggregation.")


def reading() -> str:
    lines = []
    if n := load("newton"):
        lines.append(newton(n))
    if b := load("bracket"):
        lines += bracket(b, load("bracket_large"))
    if it := load("iterative"):
        lines.append(iterative(it))
    if k := load("buckling"):
        lines.append(buckling(k))
    if c := load("contact"):
        lines.append(contact(c))
    if p := load("plasticity"):
        if "parallel" in p:  # results of the earlier, sphere-only benchmark are skipped
            lines += plasticity(p)
    if q := load("plasticity_peer"):
        if "peer, newtonls" in q["rows"][-1]:
            lines.append(plasticity_peer(q))
    if x := load("mixed"):
        lines.append(near_incompressible(x))
    if f := load("friction"):
        lines.append(friction(f))
    if c := load("continuation"):
        lines.append(continuation(c))
    if a := load("arch_iterative"):
        lines.append(arch_iterative(a))
    if d := load("damage"):
        lines.append(damage(d, load("damage_peer")))
    if f := load("forming"):
        lines.append(forming(f))
    lines += ["", run_times(["newton", "contact", "buckling", "bracket", "iterative",
                             "arch_iterative", "plasticity", "plasticity_peer", "mixed",
                             "friction", "continuation", "damage", "damage_peer",
                             "identification", "forming"])]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--update-docs", action="store_true")
    args = ap.parse_args()
    text = reading()
    print(text)
    if args.update_docs:
        update_docs("reading", text)


if __name__ == "__main__":
    main()
