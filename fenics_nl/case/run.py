"""Run a case: load steps through the library's driver, a record per converged step."""

from __future__ import annotations

import numpy as np
from mpi4py import MPI

from fenics_nl.case.problem import CaseProblem
from fenics_nl.io import output
from fenics_nl.io.cli import say
from fenics_nl.parallel import global_max
from fenics_nl.solvers.arclength import ArcLength
from fenics_nl.solvers.loading import solve_incrementally
from fenics_nl.solvers.result import WorkCounts


def solve_case(problem: CaseProblem) -> dict:
    """Visit the case's load factors in order; returns the JSON record of the run.

    Each segment between two factors starts as one step and is cut in half on failure
    (`loading.adaptive`); every converged step is recorded with its load factor, Newton
    (and active-set) iterations, probes, reactions and, with contact, the contact force.
    """
    case, steps, work = problem.case, [], WorkCounts()
    solver = problem.make_solver()

    commit = None
    if getattr(problem.material, "path_dependent", False):  # committed when a step converges
        def commit():
            problem.material.commit(problem.u, case.model)

    def show(message):  # step cuts; the converged steps are reported by step_record
        if not message.startswith("step "):
            say("  " + message)

    critical = None
    if case.arc is not None:  # the load factor is an unknown: through limit points
        critical = _follow_path(problem, solver, steps, work, commit, show)
    elif case.equal_steps:  # one pass: the predictor extrapolates from the last two steps
        n = len(case.factors)
        path = solve_incrementally(solver, problem.set_load, n, adaptive=case.adaptive,
                                   max_step=1.0 / n, progress=show, commit=commit,
                                   on_step=lambda t, r: steps.append(step_record(problem, t, r)))
        work.add(path.work)
    else:  # from factor to factor, each segment one step (cut in half on failure)
        previous = 0.0
        for target in case.factors:
            def load(s, a=previous, b=target):
                problem.set_load(a + s * (b - a))

            def record(s, result, a=previous, b=target):  # the target itself when reached
                steps.append(step_record(problem, b if s == 1 else a + s * (b - a), result))

            path = solve_incrementally(solver, load, 1, adaptive=case.adaptive,
                                       on_step=record, progress=show, commit=commit)
            work.add(path.work)
            previous = target
    last = steps[-1]
    out = {"case": str(case.path), "model": case.model, "law": case.law,
           "dofs": problem.dofs, "ranks": problem.mesh.comm.size, "steps": steps,
           "load_factor": last["load_factor"],
           "newton_iterations": sum(s["newton_iterations"] for s in steps),
           "factorizations": work.factorizations, "tangent_assemblies": work.tangent_assemblies,
           "probes": last["probes"], "reactions": last["reactions"],
           "warnings": warnings(problem)}
    if critical is not None:
        out["control"] = "arc-length"
        out["critical_points"] = critical
        passed = [c for c in critical if c["kind"] == "bifurcation"]
        if passed:  # the case runner does not switch branches
            out["warnings"].append(
                f"the path passed {len(passed)} bifurcation(s) (the first at load factor "
                f"{passed[0]['load_factor']:.4g}) and stayed on its branch (the case runner "
                "does not switch): its states with negative_eigenvalues > 0 are unstable, "
                "the structure would leave them for another branch")
    if problem.contact is not None:
        out["active_set_iterations"] = sum(s["active_set_iterations"] for s in steps)
        out["contact_force"] = last["contact_force"]
    return out


def _follow_path(problem: CaseProblem, solver, steps: list, work: WorkCounts, commit,
                 show) -> list[dict]:
    """`loading.control = "arc-length"`: the path to the target; its critical points."""
    arc = problem.case.arc
    mixed = problem.mixed
    continuation = ArcLength(
        solver, problem.set_load, arc_length=arc["arc_length"],
        max_arc_length=arc["max_arc_length"], commit=commit, prefix="case_continuation_",
        metric_dofs=mixed.displacement_dofs if mixed else None,
        multipliers=mixed.pressure_dofs if mixed else 0)
    path = continuation.run(arc["target"], arc["max_steps"], progress=show,
                            on_step=lambda t, r: steps.append(step_record(problem, t, r)))
    work.add(path.work)
    for record, negative in zip(steps, path.unstable, strict=True):
        record["negative_eigenvalues"] = negative  # of the tangent: 0 where stable
    for c in path.critical_points:
        say(f"  {c.kind} point at load factor {c.factor:.6g} (between {c.between[0]:.6g} "
            f"and {c.between[1]:.6g}, step {c.step})")
    return [{"kind": c.kind, "load_factor": c.factor, "between": list(c.between),
             "step": c.step} for c in path.critical_points]


def step_record(problem: CaseProblem, t: float, result) -> dict:
    """What one converged step reports (collective)."""
    rec = {"load_factor": t, "newton_iterations": result.iterations,
           "probes": problem.probe_values(), "reactions": problem.reactions()}
    if problem.contact is not None:
        c = problem.solver.contact
        rec["active_set_iterations"] = result.active_set_iterations
        rec["contact_force"] = c.force
        rec["nodes_in_contact"] = c.surface.count(c.active)
    extra = (f", {result.active_set_iterations} active-set iterations"
             if problem.contact is not None else "")
    say(f"load factor {t:.4g}: {result.iterations} Newton iterations{extra}")
    return rec


def warnings(problem: CaseProblem) -> list[str]:
    """What the results cannot promise."""
    notes = []
    comm = problem.mesh.comm
    x = problem.mesh.geometry.x
    size = comm.allreduce(float(np.ptp(x, axis=0).max()) if len(x) else 0.0, op=MPI.MAX)
    u = problem.displacement().x.array
    u_max = global_max(comm, np.linalg.norm(u.reshape(-1, problem.case.dim), axis=1))
    if not problem.material.finite_strain and u_max > 0.05 * size:
        notes.append(f"the largest displacement is {100 * u_max / size:.0f} % of the body's "
                     f"size: a small-strain law ({problem.case.law}) is not valid there")
    return notes


def write_outputs(problem: CaseProblem, folder: str | None, png: str | None):
    """Writers for run_scene: VTX fields and the picture, each on its own."""
    vm = problem.von_mises() if folder or png else None
    writers = []
    if folder:
        def fields():
            functions = [problem.displacement(), vm]
            if problem.mixed:
                functions.append(problem.mixed.pressure())
            if problem.contact is not None:
                functions += problem.solver.contact.fields(problem.weight)
            paths = output.write_fields(folder, functions)
            say(f"wrote {', '.join(str(p) for p in paths)} (ADIOS2 VTX: open in ParaView)")
        writers.append(fields)
    if png:
        def picture():
            from fenics_nl.io.pictures import deformed_picture, facet_points

            marked = {}
            for c in problem.case.conditions:
                if c.kind == "displacement":
                    held = "fixed" if None not in c.value else "partly fixed"
                    marked[f"{c.group} ({held})"] = facet_points(problem.mesh,
                                                                problem.facets[c.group])
            arrows = {f"{c.group} (traction)": (facet_points(problem.mesh,
                                                             problem.facets[c.group]), c.value)
                      for c in problem.case.conditions if c.kind == "traction" and any(c.value)}
            title = (f"{problem.case.path.name}: load factor {float(problem.t.value):.3g}, "
                     f"{problem.case.law}, {problem.case.model}")
            focus = obstacle = None
            if problem.contact is not None:
                c, S = problem.solver.contact, problem.solver.contact.surface
                axis = problem.contact[2]
                moved = c.x.copy()  # the nodes in contact where they are now
                moved[:, axis] += S.sign * S.normal_displacement(problem.unknown)
                focus = moved[c.owned & c.active][:, : problem.case.dim]
                obstacle = problem.obstacle_at(float(problem.t.value))
                title += f", {S.count(c.active)} nodes in contact"
            deformed_picture(problem.displacement(), vm, png, title, marked, arrows, focus,
                             obstacle)
            say(f"wrote {png}")
        writers.append(picture)
    return writers
