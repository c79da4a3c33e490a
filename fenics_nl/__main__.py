"""``python -m fenics_nl run CASE.toml`` (or ``fenics-nl run``): a problem from a case file.

``run`` solves it (JSON, VTX fields and a picture on request, PETSc options under the
prefix ``-case_``); ``check`` reads the file and the mesh and reports every mistake at once
without solving.
"""

from __future__ import annotations

import argparse
import sys
import time

import fenics_nl  # first: loads the wheel's MPI/PETSc before dolfinx

# isort: split

from mpi4py import MPI

from fenics_nl.case.spec import FORMAT, CaseError, read_case
from fenics_nl.io import cli
from fenics_nl.io.cli import say


class _Help(cli.HelpFormatter, argparse.RawDescriptionHelpFormatter):
    """Defaults once, and the format reference as written."""


def parser() -> argparse.ArgumentParser:
    """The command line: `run` or `check`, a case file, outputs and PETSc options."""
    p = cli.ArgumentParser(
        prog="fenics-nl", formatter_class=_Help,
        description="Solve a solid-mechanics problem described by a case file (a gmsh mesh "
                    "with named physical groups and a TOML file), or check the file without "
                    "solving. Units are the user's, consistent (e.g. N, mm, MPa).",
        epilog="Case file format (TOML; every key shown, unknown keys are errors):\n\n"
               + FORMAT + "\nPETSc options take the prefix -case_ (Newton's KSP: "
               "-case_ksp_view; SNES: -case_snes_; contact: -case_elim_).")
    p.add_argument("command", choices=["run", "check"], help="solve the case, or only check it")
    p.add_argument("case", help="the case file (.toml)")
    cli.add_outputs(p, json="the steps (load factor, iterations, probes, reactions) and "
                            "totals",
                    output="displacement, von Mises stress (the mixed form's pressure, J2's "
                           "plastic strains, the contact pressure and active set)",
                    png="the deformed body coloured by von Mises stress",
                    plot="each probe's displacement and von Mises stress, and each support's "
                         "reaction, against the load factor (in time: against time, "
                         "logarithmic) (matplotlib)")
    p.add_argument("--checkpoint", metavar="DIR",
                   help="save the state after every converged step (or every "
                        "--checkpoint-every N) in DIR, to restart from")
    p.add_argument("--checkpoint-every", metavar="N", type=cli.at_least(1), default=1,
                   help="save one converged step out of N")
    p.add_argument("--restart", metavar="DIR",
                   help="go on from the last checkpoint in DIR (the same case file, mesh "
                        "and number of ranks)")
    return p


def main(argv=None) -> int:
    """The command; returns the exit status (0, or 1/2 on a failed output/bad input)."""
    fenics_nl.tune_kernel_flags()  # the command opts in to the faster kernels
    p = parser()
    args, petsc = cli.parse_with_petsc_options(p, argv)
    if args.command == "check" and (args.json or args.output or args.png or args.plot
                                    or petsc or args.checkpoint or args.restart):
        p.error("check takes the case file only")
    try:  # an output that cannot be written is said now, not after the solve
        inputs = [args.case]
        try:  # the mesh file too, when the case names one (its mistakes are said below)
            inputs.append(read_case(args.case).mesh_file)
        except (CaseError, OSError):
            pass
        cli.check_output_paths(json=args.json, png=args.png, plot=args.plot,
                               output=args.output, inputs=inputs)
        cli.check_restart_paths(args.checkpoint, args.restart, args.output)
    except ValueError as err:
        p.error(str(err))
    t0 = time.perf_counter()
    try:
        from fenics_nl.case.problem import CaseProblem

        case = read_case(args.case)
        problem = CaseProblem(case)
    except CaseError as err:
        for line in err.problems:
            cli.error(line)
        return 2
    built = time.perf_counter() - t0  # the mesh, the spaces, the forms' UFL
    n, ranks = len(case.factors), MPI.COMM_WORLD.size
    say(f"{case.path.name}: {case.model}, P{case.degree}, {problem.dofs} unknowns, "
        f"{case.law_name}, " + (f"arc-length to load factor {case.arc['target']:g}" if case.arc
                            else f"in time to {case.time['end']:g}"
                            + (", steps sized by their error" if case.time["adaptive"]
                               else f", {case.time['steps']} equal steps")
                            if case.time else f"{n} load factor{'s' * (n != 1)}")
        + f", {ranks} rank{'s' * (ranks != 1)}")
    if args.command == "check":
        for line in problem.apart:  # a run says it with its results
            say(f"warning: {line}")
        say("check: the case is complete and consistent with its mesh")
        return 0

    def solve():
        from fenics_nl.case.run import solve_case, write_outputs

        cli.known(case=str(case.path), model=case.model, law=case.law_name, dofs=problem.dofs)
        # a run that fails still draws its converged steps (the last converged state)
        cli.on_failure(lambda failed: write_outputs(problem, failed, args.png, args.plot))
        out = solve_case(problem, checkpoint=args.checkpoint,
                         checkpoint_every=args.checkpoint_every, restart=args.restart)
        restarted = [(k.removeprefix("restarted_after_").replace("_", " "), v)
                     for k, v in out.items() if k.startswith("restarted_after_")]
        if args.output and restarted:
            out["warnings"].append(
                f"restarted: this --output time series begins after {restarted[0][0]} "
                f"{restarted[0][1]:.6g}, where the restart took the run up; the steps "
                "before are in the first run's folder")
        # before the first step: the problem, then the solver (its forms compiled)
        out["setup_time_s"] = built + out.pop("solver_setup_time_s")
        return out, write_outputs(problem, out, args.png, args.plot)

    what = "Newton's KSP (case_), SNES (case_snes_), contact (case_elim_)"
    return cli.run_scene(solve, petsc_argv=petsc, json_path=args.json, output=args.output,
                         prefixes={"case_": what})


if __name__ == "__main__":
    sys.exit(main())
