"""Run a case: load steps through the library's driver, a record per converged step."""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from fenics_nl.case.damage import cell_sizes
from fenics_nl.case.problem import CaseProblem
from fenics_nl.case.resume import case_checkpoints
from fenics_nl.case.spec import COMPONENTS, arc_length_obstacles
from fenics_nl.errors import SolveError
from fenics_nl.io import cli
from fenics_nl.io.cli import say
from fenics_nl.io.restart import PathCheckpoints, Resumed
from fenics_nl.parallel import global_max
from fenics_nl.solvers.arclength import ArcLength, ArcState
from fenics_nl.solvers.loading import DriverState, LoadStepError, solve_incrementally
from fenics_nl.solvers.result import WorkCounts
from fenics_nl.solvers.time_stepping import LoadHistory, solve_in_time

__all__ = ["fields", "load_path_plot", "solve_case", "step_record", "warnings", "write_outputs"]


def solve_case(problem: CaseProblem, *, checkpoint: str | None = None,
               checkpoint_every: int = 1, restart: str | None = None) -> dict:
    """Visit the case's load factors in order; returns the JSON record of the run.

    Each segment between two factors starts as one step and is cut in half on failure
    (`loading.adaptive`); every converged step is recorded with its load factor, Newton
    (and active-set) iterations, probes, reactions and, with contact, the contact force,
    and handed to `cli.converged_step` with its fields (a run that fails later keeps both;
    with --output the fields of every step are a time series).
    `checkpoint`: a folder where the state after every `checkpoint_every`-th converged step
    is saved; `restart`: a folder to go on from (the same case, mesh and ranks).
    """
    t0 = time.perf_counter()
    solver = problem.make_solver()
    setup = time.perf_counter() - t0
    saving = case_checkpoints(problem, checkpoint, checkpoint_every) if checkpoint else None
    resumed = case_checkpoints(problem, restart).restore() if restart else None
    # the step the restart goes on from (before `_solve` extends resumed.steps)
    last = resumed.steps[-1] if resumed is not None and resumed.steps else None
    if resumed is not None:
        where = "" if last is None else (f", time {last['time']:.6g}" if "time" in last else
                                         f", load factor {last['load_factor']:.6g}")
        say(f"restarted from {restart}: {len(resumed.steps)} converged steps{where}")
    out = _solve(problem, solver, saving, resumed)
    out["solver_setup_time_s"] = setup
    if last is not None:
        if "time" in last:  # in time, the load factor may stay the same step after step
            out["restarted_after_time"] = last["time"]
        else:
            out["restarted_after_load_factor"] = last["load_factor"]
    return out


def fields(problem: CaseProblem) -> list:
    """The fields written at each step: displacement, von Mises, and what the case has."""
    functions = [problem.displacement(), problem.von_mises()]
    if problem.mixed:
        functions.append(problem.mixed.pressure())
    if problem.material.path_dependent:
        functions += problem.material.output_fields()
    if problem.contact is not None:
        functions += problem.solver.contact.fields(problem.weight)
    return functions


def _solve(problem: CaseProblem, solver, saving: PathCheckpoints | None,
           resumed: Resumed | None) -> dict:
    """The load path of `solve_case`, from its start or from where `resumed` left it."""
    case, steps, work = problem.case, [], WorkCounts()
    first, start = 0, None  # the segment to begin with, and the driver's state in it
    if resumed is not None:
        steps, first, start = resumed.steps, resumed.phase, resumed.driver
        if case.time is None and start is not None and start.t >= 1.0 - 1e-12:  # complete
            first, start = first + 1, None
        work.add(resumed.work)
        for record in steps:
            cli.converged_step(record)

    def converged(t, result, **extra):
        steps.append(step_record(problem, t, result, extra.get("time")) | extra)
        cli.converged_step(steps[-1], fields=lambda: fields(problem))

    def save(segment):  # after each converged step, with the driver's state
        if saving is None:
            return None

        def checkpoint(driver, path):  # the work so far: the segments before, and this one's
            if case.time is not None:  # one segment: the path itself (its work, its times)
                saving.save(segment, driver, steps, WorkCounts(), path)
                return
            total = WorkCounts()
            total.add(work)
            total.add(path.work)
            saving.save(segment, driver, steps, total)

        return checkpoint

    commit = None
    if problem.material.path_dependent:  # committed when a step converges
        def commit():
            problem.commit()
    elif problem.case.pairs:  # friction's slip is from the last converged step
        commit = solver.commit

    def show(message):  # step cuts; the converged steps are reported by step_record
        if not message.startswith("step "):
            say("  " + message)

    critical, ended_by, in_time = None, None, None
    # the stages' phases follow the loading's: its segments (one for equal steps)
    loading = 1 if case.equal_steps else len(case.factors)
    if case.stages and first >= loading:  # a restart in the stages: the loading's end
        problem.set_load(steps[-1]["load_factor"])
    if case.time is not None and getattr(solver, "wear", None) is not None:
        _wear_in_time(problem, solver, converged, steps, work, saving, start)
    elif case.time is not None:  # a rate-dependent law: time is the load parameter
        axis = case.time
        in_time = solve_in_time(
            solver, problem.material, problem.set_load, LoadHistory(axis["factor"]),
            axis["end"], axis["steps"], commit=problem.commit, adaptive=axis["adaptive"],
            tolerance=axis["tolerance"], stationary=axis["stationary"],
            on_step=lambda at, f, result: converged(f, result, time=at),
            progress=lambda line: say(line) if line.startswith("  ") else None,  # cuts
            start=start, path_so_far=resumed.path if resumed is not None else None,
            on_state=save(0))
        work.add(in_time.work)
    elif case.arc is not None:  # the load factor is an unknown: through limit points
        critical, ended_by = _follow_path(problem, solver, converged, steps, work, commit, show,
                                saving, resumed.arc if resumed else None)
    elif case.equal_steps:  # one pass: the predictor extrapolates from the last two steps
        n = len(case.factors)
        if first == 0:
            try:
                path = solve_incrementally(solver, problem.set_load, n, adaptive=case.adaptive,
                                           max_step=1.0 / n, progress=show, commit=commit,
                                           on_step=converged, start=start, on_state=save(0))
            except LoadStepError as err:  # heading for the next of the n equal steps
                asked = min(1.0, (math.floor(err.reached * n + 1e-9) + 1) / n)
                raise _not_reached(err, asked, err.target, steps, case) from err
            work.add(path.work)
    else:  # from factor to factor, each segment one step (cut in half on failure)
        previous = 0.0
        for k, target in enumerate(case.factors):
            if k < first:  # done before the restart
                previous = target
                continue

            def load(s, a=previous, b=target):
                problem.set_load(a + s * (b - a))

            def record(s, result, a=previous, b=target):  # the target itself when reached
                converged(b if s == 1 else a + s * (b - a), result)

            try:
                path = solve_incrementally(solver, load, 1, adaptive=case.adaptive,
                                           on_step=record, progress=show, commit=commit,
                                           start=start if k == first else None,
                                           on_state=save(k))
            except LoadStepError as err:  # err's factors are fractions of the segment
                raise _not_reached(err, target, previous + err.target * (target - previous),
                                   steps, case) from err
            work.add(path.work)
            previous = target
    for k, stage in enumerate(case.stages, start=loading):  # at the loading's last factor
        if k >= first:
            _dig(problem, solver, stage, steps, work, commit, show, save(k),
                 start if k == first else None)
        elif k == first - 1 and start is None:  # a restart after a complete stage
            problem.construction.end()
    last = steps[-1]
    out = {"case": str(case.path), "model": case.model, "law": case.law_name,
           "dofs": problem.dofs, "ranks": problem.mesh.comm.size, "steps": steps,
           "load_factor": last["load_factor"],
           "newton_iterations": sum(s["newton_iterations"] for s in steps),
           "factorizations": work.factorizations, "tangent_assemblies": work.tangent_assemblies,
           "probes": last["probes"], "reactions": last["reactions"],
           "warnings": warnings(problem)}
    if case.time is not None and in_time is None:  # a pair's wear, in equal steps
        out |= {"time": last["time"], "time_steps": len(steps)}
    if in_time is not None:
        out |= {"time": last["time"], "time_steps": len(in_time.times),
                "time_steps_undone": in_time.rejected,
                "stationary_since": in_time.stationary_since}
    if critical is not None:
        out["control"] = "arc-length"
        out["critical_points"], out["ended_by"] = critical, ended_by
        passed = [c for c in critical if c["kind"] == "bifurcation"]
        if passed:  # the case runner does not switch branches
            out["warnings"].append(
                f"the path passed {len(passed)} bifurcation(s) (the first at load factor "
                f"{passed[0]['load_factor']:.4g}) and stayed on its branch (the case runner "
                "does not switch): its states with negative_eigenvalues > 0 are unstable, "
                "the structure would leave them for another branch")
    if problem.contact is not None or problem.case.pairs:
        out["active_set_iterations"] = sum(s["active_set_iterations"] for s in steps)
    if problem.contact is not None:
        out["contact_force"] = last["contact_force"]
    if problem.case.pairs:
        out["contact_pairs"] = last["contact_pairs"]
    return out


def _dig(problem: CaseProblem, solver, stage: dict, steps: list[dict], work, commit,
         show, on_state=None, start=None) -> None:
    """One construction stage: its groups dug out (their forces released) and built.

    `on_state`: the checkpoints' (after each converged step); `start`: where a restart goes
    on inside the stage (its fields restored).
    """
    if start is None:
        problem.begin_stage(stage)
    else:
        problem.resume_stage(stage)
    t = steps[-1]["load_factor"] if steps else 1.0

    def release(s):
        problem.construction.progress.value = s

    def record(s, result):
        steps.append(step_record(problem, t, result, stage=(stage["name"], s)))
        cli.converged_step(steps[-1], fields=lambda: fields(problem))

    done = [f"{', '.join(stage[key])} {what}" for key, what in (("remove", "dug out"),
                                                                 ("add", "built"))
            if stage[key]]
    say(f"stage {stage['name']!r}: {' and '.join(done)} in {stage['steps']} step(s)"
        + ("" if start is None else f", from {start.t:.4g} of it (restarted)"))
    try:
        path = solve_incrementally(solver, release, stage["steps"], adaptive=True,
                                   max_step=1.0 / stage["steps"], progress=show,
                                   commit=commit, on_step=record, on_state=on_state,
                                   start=start)
    except LoadStepError as err:
        raise SolveError(f"stage {stage['name']!r} stopped at {err.reached:.4g} of its "
                         f"release: {err}") from err
    problem.construction.end()
    work.add(path.work)


def _wear_in_time(problem: CaseProblem, solver, converged, steps: list[dict],
                  work: WorkCounts, saving: PathCheckpoints | None, start) -> None:
    """A pair's wear in time: equal steps, each slides the pairs by speed · Δt.

    The load factor follows [loading] factor against time; the load at time 0, if any, is
    applied first without sliding (recorded at time 0). Each step's wear is that of its
    end pressure (`ArchardWear.slide`: backward Euler, stable at any step). A checkpoint
    after each step; a restart goes on from its time (`start.t`). The steps' work is
    added to `work` (the run's so far).
    """
    axis = problem.case.time
    history, end, n = LoadHistory(axis["factor"]), axis["end"], axis["steps"]
    dt = end / n

    def step(t, result):
        work.add(result.work)
        solver.commit()
        converged(history(t), result, time=t)
        if saving is not None:
            saving.save(0, DriverState(t, dt), steps, work)

    def failed(t, err):
        reached = steps[-1]["time"] if steps else 0.0
        return LoadStepError(f"time {t:.6g} not reached: the last converged time is "
                             f"{reached:.6g} ({len(steps)} converged steps): {err}",
                             getattr(err, "result", None), reached=reached, target=t)

    done = 0 if start is None else round(start.t / dt)
    if start is None and history(0.0) != 0:  # the load at once, before any sliding
        problem.set_load(history(0.0))
        try:
            step(0.0, solver.solve())
        except SolveError as err:
            raise failed(0.0, err) from err
    for k in range(done + 1, n + 1):
        t = end if k == n else k * dt
        problem.set_load(history(t))
        try:
            step(t, solver.slide(dt))
        except SolveError as err:
            raise failed(t, err) from err


def _not_reached(err: LoadStepError, asked: float, failed: float, steps: list[dict],
                 case) -> LoadStepError:
    """The driver's failure in the case's own load factors (a segment's are fractions).

    `asked` is the factor of the case the path was heading for, `failed` the cut step's.
    Arc-length control is advised only to a case that could take it.
    """
    reached = steps[-1]["load_factor"] if steps else 0.0
    cause = str(err.__cause__ or err).split(": ", 1)[-1] if err.__cause__ else str(err)
    return LoadStepError(
        f"load factor {asked:.6g} not reached: the last converged load factor is "
        f"{reached:.6g} ({len(steps)} converged steps); the step to {failed:.6g} failed "
        f"({cause}): the limit load is reached, or the solver cannot take the step"
        + ("" if arc_length_obstacles(case.law, case.newton, case.conditions) else
           '; past a limit point, follow the path with [loading] control = "arc-length"'),
        err.result, reached=reached, target=asked)


def _follow_path(problem: CaseProblem, solver, converged, steps: list[dict],
                 work: WorkCounts, commit, show, saving: PathCheckpoints | None,
                 resume: ArcState | None) -> tuple[list[dict], str]:
    """`loading.control = "arc-length"`: the path to the target or the stop condition.

    Returns its critical points and what ended it ("target" or "stop"). Each step's record
    has the tangent's negative eigenvalues there, and the critical points met so far are in
    any JSON written (`cli.known`): a run that fails later keeps both.
    `saving`: checkpoints of the continuation's state; `resume`: the state to go on from.
    """
    arc = problem.case.arc
    mixed = problem.mixed
    continuation = ArcLength(
        solver, problem.set_load, arc_length=arc["arc_length"],
        max_arc_length=arc["max_arc_length"], commit=commit, prefix="case_continuation_",
        metric_dofs=mixed.displacement_dofs if mixed else None,
        multipliers=mixed.pressure_dofs if mixed else 0)

    def on_step(t, result):
        path = continuation.path
        converged(t, result, negative_eigenvalues=path.unstable[-1])  # 0 where stable
        cli.known(critical_points=_critical_points(path))

    on_state = None
    if saving is not None:
        def on_state(state):
            saving.save_arc(state, steps)
    path = continuation.run(arc["target"], arc["max_steps"], progress=show, on_step=on_step,
                            resume=resume, on_state=on_state,
                            stop=_stop_condition(arc["stop"], steps, problem.case.model))
    work.add(path.work)
    for c in path.critical_points:
        say(f"  {c.kind} point at load factor {c.factor:.6g} (between {c.between[0]:.6g} "
            f"and {c.between[1]:.6g}, step {c.step})")
    if path.stopped:
        s = arc["stop"]
        say(f"  stopped: probe {s['probe']!r} u_{s['component']} = "
            f"{_probe_component(steps[-1], s, problem.case.model):.6g} has reached "
            f"{s['value']:g}")
    return _critical_points(path), "stop" if path.stopped else "target"


def _critical_points(path) -> list[dict]:
    return [{"kind": c.kind, "load_factor": c.factor, "between": list(c.between),
             "step": c.step} for c in path.critical_points]


def _probe_component(record: dict, stop: dict, model: str) -> float:
    """The stop condition's displacement component in a step's record."""
    i = COMPONENTS[model].index(stop["component"])
    return record["probes"][stop["probe"]]["displacement"][i]


def _stop_condition(stop: dict | None, steps: list[dict], model: str):
    """Whether the last converged step has reached `loading.stop` (None: no condition).

    Reached: the component has gone from 0 to the value or beyond it, on its side.
    """
    if stop is None:
        return None
    return lambda: _probe_component(steps[-1], stop, model) / stop["value"] >= 1.0


def step_record(problem: CaseProblem, t: float, result, at: float | None = None,
                stage: tuple[str, float] | None = None) -> dict:
    """What one converged step reports (collective).

    `at`: in time, the step's time; `stage`: a construction stage's (name, progress).
    """
    rec = {"load_factor": t, "newton_iterations": result.iterations,
           "probes": problem.probe_values(), "reactions": problem.reactions()}
    if stage is not None:
        rec |= {"stage": stage[0], "stage_progress": stage[1]}
    if problem.damage:
        d = problem.solver
        rec |= {"alternate_iterations": d.last.iterations,
                "damage_iterations": d.last.damage_iterations,
                "dissipated_energy": d.dissipated_energy(),
                "largest_damage": global_max(problem.mesh.comm, d.alpha.x.array)}
    if problem.material.path_dependent and hasattr(problem.material, "plastic_zone"):
        # the largest p̄, the plastic share
        rec |= problem.material.plastic_zone(problem.dx)
    if problem.contact is not None:
        c = problem.solver.contact
        rec["active_set_iterations"] = result.active_set_iterations
        rec["contact_force"] = c.force
        rec["nodes_in_contact"] = c.surface.count(c.active)
    if problem.case.pairs:
        rec["active_set_iterations"] = result.active_set_iterations
        rec["contact_pairs"] = problem.solver.summaries()
    extra = (f", {result.active_set_iterations} active-set iterations"
             if problem.contact is not None or problem.case.pairs else "")
    if problem.damage:
        extra = (f" in {rec['alternate_iterations']} alternate iterations, largest damage "
                 f"{rec['largest_damage']:.3g}")
    when = "" if at is None else f"time {at:.6g}, "
    where = f"load factor {t:.4g}" if stage is None else \
        f"stage {stage[0]!r} at {stage[1]:.4g}"
    say(f"{when}{where}: {result.iterations} Newton iterations{extra}")
    return rec


def warnings(problem: CaseProblem) -> list[str]:
    """What the results cannot promise."""
    notes = list(problem.apart)
    comm = problem.mesh.comm
    x = problem.mesh.geometry.x
    size = comm.allreduce(float(np.ptp(x, axis=0).max()) if len(x) else 0.0, op=MPI.MAX)
    u = problem.displacement().x.array
    u_max = global_max(comm, np.linalg.norm(u.reshape(-1, problem.case.dim), axis=1))
    if not problem.material.finite_strain and u_max > 0.05 * size:
        notes.append(f"the largest displacement is {100 * u_max / size:.0f} % of the body's "
                     f"size: a small-strain law ({problem.case.law_name}) is not valid there")
    if problem.damage:
        law = problem.material.law
        h = comm.allreduce(float(cell_sizes(problem.mesh).max(initial=0.0)), op=MPI.MAX)
        if law.ell < 2 * h:  # the band of a crack is then a visible share of its cost
            notes.append(f"ell is smaller than two cells (ell/h = {law.ell / h:.3g}, h the "
                         f"largest cell): a crack there dissipates Gc (1 + h/(c_w ell)) = "
                         f"{law.Gc * (1 + h / (law.c_w * law.ell)):.4g}, not Gc = {law.Gc:g}")
    return notes


def load_path_plot(out: dict, path: str) -> None:
    """Each probe's displacement and σ_eq, and each reaction, against the load factor.

    Read from the JSON's step records (rank 0 draws); components that stay zero are left
    out. Units are the case's own: a length, a stress, a force.
    """
    if MPI.COMM_WORLD.rank != 0:
        return
    from fenics_nl.plots import figures

    steps = out["steps"]
    in_time = bool(steps) and "time" in steps[0]  # a viscous law's: against time
    if in_time:  # on a logarithmic axis, from the first step after time 0
        steps = [s for s in steps if s["time"] > 0]
        t = [s["time"] for s in steps]
    else:  # from the unloaded start
        t = [0.0] + [s["load_factor"] for s in steps]
    plt = figures.pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2))
    names = COMPONENTS[out["model"]]
    curves = [{}, {}, {}]
    for s in steps:
        for name, probe in s["probes"].items():
            for i, value in enumerate(probe["displacement"]):
                curves[0].setdefault(f"{name}: u_{names[i]}", []).append(value)
            curves[1].setdefault(f"{name}", []).append(probe["von_mises"])
        for group, force in s["reactions"].items():
            for i, value in enumerate(force):
                curves[2].setdefault(f"{group}: R_{names[i]}", []).append(value)
    titles = ("probe displacements [length]", "probe von Mises stress [stress]",
              "support reactions [force]")
    for ax, series, title in zip(axes, curves, titles, strict=True):
        peak = max((abs(v) for values in series.values() for v in values), default=0.0)
        for label, values in series.items():
            if max(abs(v) for v in values) > 1e-9 * peak:
                ax.plot(t, values if in_time else [0.0, *values], "o-", ms=3, label=label)
        if in_time:  # a creep transient is short against the hold: a logarithmic axis
            ax.set_xscale("log")
        ax.set_xlabel("time (logarithmic; the case's unit)" if in_time else "load factor")
        ax.set_title(title, fontsize=10)
        ax.grid(alpha=0.3)
        if ax.lines:
            ax.legend(fontsize=7)
        else:
            ax.text(0.5, 0.5, "none in this case", ha="center", transform=ax.transAxes)
    fig.suptitle(f"{Path(out['case']).name}: {out['law']}, {out['model']}, "
                 f"{len(out['steps'])} converged steps, " + (f"time {out['time']:.4g}"
                                                              if in_time else
                                         f"load factor {out['load_factor']:.4g}"),
                 fontsize=11)
    figures.save_figure(fig, path)


def write_outputs(problem: CaseProblem, out: dict, png: str | None, plot: str | None = None):
    """Writers for run_scene: the picture and the load-path plot.

    The fields were written step by step (`cli.converged_step`).
    """
    vm = problem.von_mises() if png else None
    writers = [lambda: load_path_plot(out, plot)] if plot else []
    if png:
        def picture():
            from fenics_nl.plots.deformed import deformed_picture, facet_points

            marked = {}
            for c in problem.case.conditions:
                if c.kind == "displacement":
                    held = "fixed" if None not in c.value else "partly fixed"
                    marked[f"{c.group} ({held})"] = facet_points(problem.mesh,
                                                                problem.facets[c.group])
            t = float(problem.t.value)
            arrows = {}  # the loads as they are now: none at load factor 0
            for c in problem.case.conditions:
                if c.kind == "traction" and any(c.value) and t != 0:
                    arrows[f"{c.group} (traction)"] = (
                        facet_points(problem.mesh, problem.facets[c.group]),
                        t * np.asarray(c.value))
                elif c.kind == "pressure" and c.value and t != 0:
                    _, normal = problem.mean_normal(c.group)  # a closed surface has none
                    if np.linalg.norm(normal) > 1e-6:
                        arrows[f"{c.group} (pressure)"] = (
                            facet_points(problem.mesh, problem.facets[c.group]),
                            -t * c.value * normal)
            labels = {}  # each probe's σ_eq at its point: not a cell's mean, as the colours
            if problem.case.probes and out["steps"]:
                values = out["steps"][-1]["probes"]
                labels = {f"{p.name}: {values[p.name]['von_mises']:.4g} at the point": p.point
                          for p in problem.case.probes}
            when = (f"time {out['time']:.4g}" if "time" in out else f"load factor {t:.3g}")
            title = (f"{problem.case.path.name}: {when}, "
                     f"{problem.case.law_name}, {problem.case.model}")
            focus = obstacle = None
            if problem.contact is not None:
                c, S = problem.solver.contact, problem.solver.contact.surface
                axis = problem.contact[2]
                moved = c.x.copy()  # the nodes in contact where they are now
                moved[:, axis] += S.sign * S.normal_displacement(problem.unknown)
                focus = moved[c.owned & c.active][:, : problem.case.dim]
                obstacle = problem.obstacle_at(float(problem.t.value))
                title += f", {S.count(c.active)} nodes in contact"
            names = COMPONENTS[problem.model]
            deformed_picture(problem.displacement(), vm, png, title, marked, arrows, focus,
                             obstacle, label="von Mises stress (the mean over each cell)",
                             labels=labels, detail=focus is None,
                             axes=(f"{names[0]} (length)", f"{names[1]} (length)"),
                             true_scale=bool(problem.case.pairs))  # bodies in contact
            say(f"wrote {png}")
        writers.append(picture)
    return writers
