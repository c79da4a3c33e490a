"""Command-line plumbing shared by the demos: argument types, PETSc options, the run itself.

A demo is a plain script of top-level cells (jupytext's light format), run once, top to
bottom. After its imports it calls ``run_script(__name__)``: run as a script, that executes
the demo's cells under the scene contract and ends the process with the run's status (the
library's errors: one line and status 2; the JSON first and then every other output, each
on its own, so that a failing picture never loses the numbers; a PETSc option that no solver
read reported). Its first cell then calls `arguments` (flags from `parser(...)`: every
default shown once, numeric flags that refuse NaN and infinities by name; PETSc options
accepted only under the run's own prefixes), its last `results`. In a notebook the same
cells run with the defaults (or the flags in the environment variable FENICS_NL_ARGS).
`run_file` runs a demo's cells in this process under the same contract (the tests do).

Nothing computed is lost: the output paths are checked before anything is solved, and each
converged step a scene reports (`converged_step`) is kept, so that a run that fails after
some steps still writes its JSON, with ``"status": "failed"``, the message, every converged
step and the last converged load factor.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import runpy
import shlex
import sys
import time
import traceback
from collections.abc import Callable, Sequence
from pathlib import Path

from mpi4py import MPI

from fenics_nl.errors import SolveError
from fenics_nl.io.flags import (  # the run's flags, here for the demos and the command
    ArgumentParser,
    HelpFormatter,
    add_checkpoints,
    add_outputs,
    at_least,
    finite,
    parser,
    positive,
    spelling,
)

__all__ = [
    "ArgumentParser",
    "Checkpointing",
    "HelpFormatter",
    "PetscOptions",
    "add_checkpoints",
    "add_outputs",
    "arguments",
    "at_least",
    "check_output_paths",
    "check_restart_paths",
    "checkpointing",
    "converged_step",
    "error",
    "finite",
    "known",
    "notebook_results",
    "on_failure",
    "parse_with_petsc_options",
    "parser",
    "positive",
    "results",
    "run_file",
    "run_scene",
    "run_script",
    "say",
    "spelling",
]

# Errors that end a run with one line: bad parameters, solvers that cannot converge, a load
# that cannot be reached (and PETSc refusing an option). Anything else is a bug and keeps
# its traceback.
EXPECTED_ERRORS: tuple[type[BaseException], ...] = (ValueError, SolveError)


def parse_with_petsc_options(parser: argparse.ArgumentParser, argv=None):
    """The demo's own arguments, and the PETSc options (``-name [value]``) to pass through.

    Anything else (an unknown ``--flag``, a stray word) is an argparse error: one line,
    exit status 2.
    """
    args, rest = parser.parse_known_args(argv)
    unknown, after_option = [], False
    for a in rest:
        is_option = a.startswith("-") and not a.startswith("--") and not _is_number(a)
        if a.startswith("--") or not (is_option or after_option):
            unknown.append(a)
        after_option = is_option  # an option's value follows it; a value ends it
    if unknown:
        parser.error(f"unrecognized arguments: {' '.join(unknown)}")
    return args, rest


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


class PetscOptions:
    """The PETSc options of one run, checked against the prefixes its solvers read.

    `prefixes` maps each options prefix of the run to what reads it. An option outside
    them is refused before anything is computed; after the run, an option that no solver
    read (a misspelt suffix) is reported by `unused()`.
    """

    def __init__(self, argv: Sequence[str], prefixes: dict[str, str]):
        self.names = [a[1:] for a in argv if a.startswith("-") and not _is_number(a)]
        self.prefixes = prefixes
        stray = [n for n in self.names if not any(n.startswith(p) for p in prefixes)]
        if stray:
            raise ValueError(f"PETSc option -{stray[0]} is read by no solver of this run; "
                             f"its options prefixes are {self.describe()}")
        from petsc4py import PETSc

        PETSc.Options().insertString(" ".join(argv))

    def describe(self) -> str:
        """``-prefix_ (what reads it), ...`` for messages and --help."""
        return ", ".join(f"-{p} ({what})" for p, what in self.prefixes.items())

    def unused(self) -> list[str]:
        """The options no solver read, removed from PETSc's database."""
        from petsc4py import PETSc

        opts = PETSc.Options()
        left = [n for n in self.names if not opts.used(n)]
        for n in self.names:
            opts.delValue(n)
        return left


def say(*args) -> None:
    """print on rank 0 only."""
    if MPI.COMM_WORLD.rank == 0:
        print(*args, flush=True)


def error(message: str) -> None:
    """One line on stderr, rank 0 only."""
    if MPI.COMM_WORLD.rank == 0:
        print(f"error: {message}", file=sys.stderr, flush=True)


class _Run:
    """A run in progress: its command line, PETSc options, converged steps, results, writers."""

    def __init__(self, argv: Sequence[str]):
        self.argv = list(argv)
        self.t0 = time.perf_counter()
        self.options: PetscOptions | None = None
        self.json_path: str | None = None
        self.out: dict | None = None
        self.writers: Sequence[Callable[[], None]] = ()
        self.steps: list[dict] = []  # every converged step, as the scene reported it
        self.known: dict = {}  # quantities set before the solve (dofs, references)
        self.output: str | None = None  # --output: the fields of every converged step
        self.series = None  # their time series, opened at the first step
        self.failure_writers = None  # out -> writers of a failed run (its pictures)
        self.path: Path | None = None  # the demo file (a checkpoint's identity)
        self.args: argparse.Namespace | None = None  # its parameters
        # a script's own communicator, to tell whether a failure is every rank's
        self.failure_comm: MPI.Comm | None = None

    def close_series(self) -> None:
        """Close the fields' time series, saying what it holds (collective)."""
        if self.series is None or not self.series.times:
            self.series = None
            return
        paths = self.series.paths
        self.series.close()
        say(f"wrote {', '.join(str(p) for p in paths)} ({len(self.series.times)} steps, the "
            "load factor as time; ADIOS2 VTX: open in ParaView)")
        self.series = None


_current: _Run | None = None


def converged_step(record: dict, fields: Callable[[], list] | None = None) -> None:
    """Keep one converged step's quantities (a dict with its ``load_factor``).

    They go to the JSON as ``steps``, and stay there if a later step fails. With --output,
    `fields()` (the Functions of the state) are written as one more time of the run's time
    series (`output.FieldSeries`). Outside a run (a notebook, an import) nothing is kept.
    Collective when `fields` is given.
    """
    run = _current
    if run is None:
        return
    run.steps.append(dict(record))
    if run.output:
        if run.series is None:
            from fenics_nl.io.output import FieldSeries

            run.series = FieldSeries(run.output)
        at = (record["load_factor"], record.get("time"), record.get("stage_progress"))
        if fields is None:  # a step not written (a restart's before it): its time counts
            run.series.advance(*at)
        else:
            run.series.write(at[0], fields, *at[1:])


def on_failure(writers: Callable[[dict], Sequence[Callable[[], None]]]) -> None:
    """What a failed run still draws: `writers(out)` gets the failed run's JSON record.

    The state is then the last converged one (the load driver restores it), so its pictures
    and curves are those of the converged steps.
    """
    if _current is not None:
        _current.failure_writers = writers


def known(**quantities) -> None:
    """Quantities known before the solve (``dofs``, reference values): in any JSON written."""
    if _current is not None:
        _current.known.update(quantities)


IMAGE_TYPES = {"--png": (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff"),
               "--plot": (".png", ".pdf", ".svg", ".jpg", ".jpeg", ".eps", ".ps", ".tif",
                          ".tiff", ".webp")}


def check_output_paths(json: str | None = None, png: str | None = None,
                       plot: str | None = None, output: str | None = None,
                       inputs: Sequence[str | Path] = ()) -> None:
    """Refuse an output path that cannot be written, before anything is solved (ValueError).

    Each file is opened for writing once (and removed if it was not there): a folder that
    exists but takes no file (/proc) is found now, not after the solve. A picture needs an
    extension its writer knows. No output may be an input (`inputs`: the case file, its
    mesh) or another output. `output`, a folder, is created now (and checked writable).
    """
    files = [(f, p) for f, p in (("--json", json), ("--png", png), ("--plot", plot)) if p]
    seen = {Path(p).resolve(): "input" for p in inputs}
    for flag, path in files + ([("--output", output)] if output else []):
        key = Path(path).resolve()
        if key in seen:
            raise ValueError(f"{flag} {path}: is also the {seen[key]}: it would be overwritten")
        seen[key] = flag
    for flag, path in files:
        target = Path(path)
        if target.is_dir():
            raise ValueError(f"{flag} {path}: is a folder, not a file")
        if not target.parent.is_dir():
            what = "is not a folder" if target.parent.exists() else "does not exist"
            raise ValueError(f"{flag} {path}: {target.parent} {what}")
        if flag in IMAGE_TYPES and target.suffix.lower() not in IMAGE_TYPES[flag]:
            raise ValueError(f"{flag} {path}: the picture needs one of the extensions "
                             f"{', '.join(IMAGE_TYPES[flag])}")
        _try_writing(flag, target)
    if output is not None:
        target = Path(output)
        existing = next(p for p in (target, *target.parents) if p.exists())
        if not existing.is_dir():
            raise ValueError(f"--output {output}: {existing} is a file, not a folder")
        try:
            target.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise ValueError(f"--output {output}: cannot create it ({err.strerror})") from None
        _try_writing("--output", target / ".fenics_nl_write_test")


def check_restart_paths(checkpoint: str | None, restart: str | None,
                        output: str | None) -> None:
    """A --checkpoint folder that can be written; no --output folder with fields to a restart.

    A restart's time series begins at the restart, and VTX files are rewritten, not appended
    to: an --output folder holding the first run's would lose them.
    """
    if restart and output and any(Path(output).glob("*.bp")):
        raise ValueError(f"--output {output} holds fields already (*.bp, the first run's?): "
                         "a restart writes its own series, give it another folder")
    if checkpoint:
        try:
            check_output_paths(output=checkpoint)
        except ValueError as err:
            raise ValueError(str(err).replace("--output", "--checkpoint", 1)) from None


def _try_writing(flag: str, target: Path) -> None:
    """Open `target` for appending on rank 0, removing it if it was not there (collective).

    The answer is broadcast, so that every rank refuses together.
    """
    comm = MPI.COMM_WORLD
    problem = None
    if comm.rank == 0:
        existed = target.exists()
        try:
            with open(target, "a"):
                pass
            if not existed:
                target.unlink()
        except OSError as err:
            problem = f"{flag} {target}: not writable ({err.strerror})"
    problem = comm.bcast(problem, root=0)
    if problem:
        raise ValueError(problem)


def run_file(path: str | Path, argv: Sequence[str] | None = None) -> int:
    """Run a demo file's top-level cells under the scene contract; returns the exit status.

    A demo is a script (jupytext light format) whose cells call `arguments` first and
    `results` last; this function executes it in this process (as ``__scene__``) with
    `argv` (default: the command line), as the tests do: its compiled forms stay loaded.
    Library errors end the run with one line and status 2; the JSON is written first, then
    every writer on its own (a failing one: status 1); a PETSc option no solver read:
    status 2, as when the demo runs as a script.

    Args:
        path: the demo file.
        argv: its flags and PETSc options.

    Returns:
        The exit status the script would have.
    """
    return _run(Path(path), sys.argv[1:] if argv is None else argv, script=False)


def run_script(name: str) -> None:
    """``python demos/x.py ...``: run the demo under the scene contract, then end the process.

    A demo calls ``cli.run_script(__name__)`` after its imports. Run as a script (`name` is
    ``__main__`` outside IPython), it executes the script's file (``__main__``'s) once more
    in this process, as `run_file` does, on every rank, and ends the process with the run's
    status: 0; 1 for a failed output or a bug (its traceback); 2 for a library error (one
    line, the JSON of the converged steps first) or a PETSc option that no solver read.
    Anywhere else (a notebook, `run_file`, an import) it does nothing.

    Args:
        name: the calling module's ``__name__``.
    """
    path = getattr(sys.modules.get("__main__"), "__file__", None)
    if name != "__main__" or _current is not None or _in_ipython() or path is None:
        return
    status = _run(Path(path), sys.argv[1:], script=True)
    sys.stdout.flush()
    sys.stderr.flush()
    if status == 2 and MPI.Is_initialized() and not MPI.Is_finalized():
        # a failed solve's objects are left undestroyed: their collective destruction at
        # the interpreter's exit could wait for a rank that failed elsewhere
        MPI.Finalize()
        os._exit(status)
    sys.exit(status)


def _run(path: Path, argv: Sequence[str], script: bool) -> int:
    """Execute the demo at `path` with `argv`; the exit status (see `run_file`, `run_script`).

    A script's library error is reported collectively (the JSON of what converged) only if
    every rank raised it; a rank alone in its error, or a bug under MPI, stops every rank.
    Elsewhere (`run_file`: the tests) a bug propagates.
    """
    global _current
    from petsc4py import PETSc

    run = _current = _Run(argv)
    run.path = path
    if script:
        run.failure_comm = MPI.COMM_WORLD.Dup()  # every rank starts the script here
    try:
        runpy.run_path(str(path), run_name="__scene__")
    except SystemExit as stop:  # argparse: --help, or a bad flag (already said)
        _forget(run.options)
        return stop.code if isinstance(stop.code, int) else int(stop.code is not None)
    except (*EXPECTED_ERRORS, PETSc.Error) as err:
        if script and not _every_rank_failed(run):  # the others go on: no collective way out
            print(f"error: {_one_line(err)} (on rank {MPI.COMM_WORLD.rank} only: the run "
                  "is stopped)", file=sys.stderr, flush=True)
            sys.stdout.flush()
            _abort(2)
        return _failed(run, err)
    except KeyboardInterrupt:
        if script and MPI.COMM_WORLD.size > 1:  # no collective clean-up: end every rank
            _abort(130)
        raise
    except Exception:
        if not script:
            raise
        traceback.print_exc()  # a bug: its traceback
        if MPI.COMM_WORLD.size > 1:  # the other ranks may not have failed: end them all
            sys.stderr.flush()
            _abort(1)
        _forget(run.options)
        return 1
    finally:
        _current = None
        run.close_series()  # the fields of every converged step, also after a failure
    if run.out is None:
        if not script:
            raise RuntimeError(f"{path} ended without calling cli.results")
        error(f"{path.name} ended without reporting its results (cli.results was never "
              "called): nothing was written")
        return 1
    return _finish(run)


NOTEBOOK_ARGS = "FENICS_NL_ARGS"  # a demo's flags in a notebook (e.g. "--size 20")


def arguments(parser, prefixes: dict[str, str] | Callable[[argparse.Namespace], dict[str, str]]):
    """The demo's parameters: its command line in a script or `run_file`, else the defaults.

    `parser`: a `parameters.Parameters` dataclass (its fields make the flags; an instance is
    returned, checked), or an argparse parser (a Namespace is returned).
    Within a run (`run_script`, `run_file`): its command line. In a notebook: the defaults,
    or the flags in the environment variable FENICS_NL_ARGS.
    `prefixes` (or a function of the parsed arguments giving them): the PETSc options
    prefixes of the run's solvers, with what reads each; an option outside them is refused.
    """
    from fenics_nl.compile_flags import tune_kernel_flags
    from fenics_nl.io import parameters

    tune_kernel_flags()  # a demo opts in to the faster kernels (`import fenics_nl` does not)
    declared = isinstance(parser, type) and issubclass(parser, parameters.Parameters)
    cls, parser = (parser, parameters.parser_of(parser)) if declared else (None, parser)
    global _notebook_args
    run = _current
    if run is None and not _in_ipython() and sys.argv[1:]:
        raise RuntimeError("a demo's flags are read within its run: call "
                           "cli.run_script(__name__) after the imports")
    argv = run.argv if run else shlex.split(os.environ.get(NOTEBOOK_ARGS, ""))
    args, petsc = parse_with_petsc_options(parser, argv)
    if declared:
        args = parameters.from_namespace(cls, parser, args)
    if run is None:
        _notebook_args = args
        # in a notebook the pictures are drawn and shown; what a script writes is refused
        # rather than silently dropped
        given = [f"--{k.replace('_', '-')}" for k in ("json", "output", "checkpoint",
                                                      "restart") if getattr(args, k, None)]
        if given or petsc:
            parser.error(f"{', '.join(given + petsc[:1])}: only when the demo runs as a "
                         f"script (in a notebook, {NOTEBOOK_ARGS} takes its parameters, "
                         "--png and --plot)")
    if run is not None:
        run.json_path = getattr(args, "json", None)
        run.output = getattr(args, "output", None)
        run.args = args
        try:
            check_output_paths(*(getattr(args, k, None) for k in ("json", "png", "plot",
                                                                   "output")))
            check_restart_paths(getattr(args, "checkpoint", None),
                                getattr(args, "restart", None), run.output)
        except ValueError as err:
            parser.error(str(err))
        run.options = PetscOptions(petsc, prefixes(args) if callable(prefixes) else prefixes)
    return args


class Checkpointing:
    """A demo's --checkpoint and --restart of its loading, as `solve_incrementally` takes them.

    `steps`: the step records a restart took back (they are the run's JSON steps too);
    `kept`: what the demo's `kept()` gave when the checkpoint was saved (None without a
    restart); `options`: start, path_so_far and on_state for `solve_incrementally`,
    `arc_options`: resume and on_state for `ArcLength.run` (empty without the flags: a
    notebook, or a run without them).
    """

    def __init__(self, steps: list[dict], options: dict, arc_options: dict,
                 kept: dict | None = None):
        self.steps, self.options, self.arc_options = steps, options, arc_options
        self.kept = kept


def checkpointing(functions: dict, *, newton=None, contact=None,
                  kept: Callable[[], dict] | None = None) -> Checkpointing:
    """--checkpoint / --restart of the loading of a demo, whose state is `functions`.

    Collective. With --restart the saved state is put back into `functions` (the unknown
    first, then the internal variables), `newton`'s force reference and `contact`'s state
    (its statuses, with friction its slip history) now; `kept()` gives what else the demo
    needs back (JSON-able). The checkpoint's identity is the demo file and its parameters
    (the output and checkpoint flags aside), the ranks and the unknowns.
    """
    import hashlib

    from fenics_nl.io.output import dofs
    from fenics_nl.io.restart import PathCheckpoints
    from fenics_nl.solvers.result import WorkCounts

    run = _current
    args = run.args if run is not None else None
    folder = getattr(args, "checkpoint", None)
    restart = getattr(args, "restart", None)
    if not (folder or restart):
        return Checkpointing([], {}, {})
    outputs = {"json", "png", "plot", "output", "checkpoint", "checkpoint_every", "restart"}
    params = json.dumps({k: v for k, v in sorted(vars(args).items()) if k not in outputs},
                        default=str)
    unknown = next(iter(functions.values()))
    identity = {"demo": run.path.name, "command line": hashlib.sha256(
        params.encode()).hexdigest(), "dofs": dofs(unknown.function_space)}

    def store(where, every=1):
        return PathCheckpoints(where, identity, functions, every=every, newton=newton,
                               contact=contact, kept=kept)

    options, arc_options, steps, restored = {}, {}, [], None
    if restart:
        resumed = store(restart).restore()
        steps, restored = resumed.steps, resumed.kept
        run.steps = [dict(s) for s in steps]
        options.update(start=resumed.driver, path_so_far=resumed.path)
        arc_options["resume"] = resumed.arc
        say(f"restarted from {restart}: {len(steps)} converged steps" + (
            f", load factor {steps[-1]['load_factor']:.6g}" if steps else ""))
    if folder:
        saving = store(folder, args.checkpoint_every)

        def on_state(driver, path):
            saving.save(0, driver, run.steps, WorkCounts(), path)

        options["on_state"] = on_state
        arc_options["on_state"] = lambda state: saving.save_arc(state, run.steps)
    return Checkpointing(steps, options, arc_options, restored)


def results(out: dict, writers: Sequence[Callable[[], None]] = ()) -> None:
    """The run's quantities (the JSON) and its output writers.

    Within a run (`run_script`, `run_file`) they are written when the demo's cells end: the
    JSON first, then each writer on its own. In a notebook the quantities are kept for
    `notebook_results` and the pictures asked for (--png, --plot in FENICS_NL_ARGS) are drawn
    and shown.
    """
    global _notebook_results
    run = _current
    if run is None:
        _notebook_results = out
        _show_in_notebook(writers)
        return
    run.out, run.writers = out, writers


_notebook_results: dict | None = None
_notebook_args: argparse.Namespace | None = None  # a notebook's parameters


def _in_ipython() -> bool:
    """Whether this runs in an IPython shell or kernel (a notebook, or its %run)."""
    ipython = sys.modules.get("IPython")
    return ipython is not None and ipython.get_ipython() is not None


def _show_in_notebook(writers: Sequence[Callable[[], None]]) -> None:
    """Run the writers, each on its own, and show the pictures they wrote (IPython)."""
    targets = [Path(p) for p in (getattr(_notebook_args, f, None) for f in ("png", "plot"))
               if p]
    for path in targets:  # a picture left by an earlier run is never shown as this one's
        path.unlink(missing_ok=True)
    _write_each(writers)  # a picture must not stop the notebook
    try:
        from IPython.display import Image, display
    except ImportError:
        return
    for path in targets:
        if path.suffix.lower() == ".png" and path.is_file():
            display(Image(filename=str(path)))


def notebook_results() -> dict | None:
    """The quantities the last demo run in this kernel gave `results` (None: none yet)."""
    return _notebook_results


def _abort(status: int) -> None:
    """MPI_Abort, once what this rank wrote has had time to reach mpiexec.

    Abort kills every rank at once; MPICH's mpiexec relays each rank's stderr through a pipe,
    and a line still in that pipe is lost with it (seen under load: the one-line error of a
    rank failing alone never printed).
    """
    time.sleep(0.5)
    MPI.COMM_WORLD.Abort(status)


# how long a failing rank waits for the others (a collective error is raised after a
# collective decision: its ranks arrive within milliseconds); FENICS_NL_FAILURE_WAIT_S sets it
FAILURE_WAIT_S = float(os.environ.get("FENICS_NL_FAILURE_WAIT_S", 5.0))


def _every_rank_failed(run: _Run, seconds: float = FAILURE_WAIT_S) -> bool:
    """Whether every rank reached this failure (an error raised collectively).

    A non-blocking barrier on the run's own communicator, waited for `seconds`: the ranks
    of a collective error arrive together; a rank alone in its error would wait for ever
    in the collective clean-up of `_failed`.
    """
    comm = run.failure_comm
    if comm is None or comm.size == 1:
        return True
    request = comm.Ibarrier()
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if request.Test():
            return True
        time.sleep(0.005)
    return False


def run_scene(solve: Callable[[], tuple[dict, Sequence[Callable[[], None]]]], *,
              petsc_argv: Sequence[str] = (), prefixes: dict[str, str] | None = None,
              json_path: str | None = None, output: str | None = None) -> int:
    """Run `solve()`, which returns quantities for the JSON and output writers.

    The same contract as `run_file` (one-line errors, the JSON first, PETSc options checked)
    for a command whose work is a function (the case files).
    """
    from petsc4py import PETSc

    global _current
    run = _current = _Run([])
    run.json_path, run.output = json_path, output
    try:
        run.options = PetscOptions(petsc_argv, prefixes or {})
        run.out, run.writers = solve()
    except (*EXPECTED_ERRORS, PETSc.Error) as err:
        return _failed(run, err)
    finally:
        _current = None
        run.close_series()
    return _finish(run)


def _forget(options: PetscOptions | None) -> None:
    """Leave PETSc's options database as it was before the run."""
    if options is not None:
        options.unused()


def _failed(run: _Run, err: BaseException) -> int:
    """One line, and the JSON of what converged if a solve failed or steps had converged.

    Bad input found before any step (a ValueError) writes nothing: nothing was solved.
    """
    message = _one_line(err)
    error(message)
    _forget(run.options)
    last = next((s["load_factor"] for s in reversed(run.steps) if "load_factor" in s), None)
    out = {**run.known, "status": "failed", "message": message,
           "converged_steps": len(run.steps), "load_factor": last, "steps": run.steps,
           "ranks": MPI.COMM_WORLD.size, "wall_time_s": time.perf_counter() - run.t0,
           "warnings": ["the run failed: the quantities are those of the last converged "
                        "step"] if run.steps else ["the run failed before any step "
                                                   "converged"], **_totals(run.steps)}
    if (isinstance(err, SolveError) or run.steps) and run.json_path:
        text = _encode(out)
        if text is not None and _write_json(text, run.json_path):
            say(f"wrote {run.json_path} (status failed, {len(run.steps)} converged step(s))")
    if run.steps and run.failure_writers is not None:
        _write_each(run.failure_writers(out))  # as after a run that succeeds
    return 2


def _write_each(writers: Sequence[Callable[[], None]]) -> bool:
    """Run every writer, each on its own: a failing output never takes the others down.

    Each failure is one line (its traceback too with FENICS_NL_DEBUG); False if any failed.
    """
    ok = True
    for write in writers:
        try:
            write()
        except Exception as err:
            error(f"writing an output failed: {_one_line(err)}")
            if MPI.COMM_WORLD.rank == 0 and "FENICS_NL_DEBUG" in os.environ:
                traceback.print_exc()
            ok = False
    return ok


def _totals(steps: list[dict]) -> dict:
    """The totals a failed run can give: iterations summed, the last step's quantities."""
    out = {}
    if steps and all("newton_iterations" in s for s in steps):
        out["newton_iterations"] = sum(s["newton_iterations"] for s in steps)
    for key in ("probes", "reactions", "contact_force"):
        if steps and key in steps[-1]:
            out[key] = steps[-1][key]
    return out


def _encode(out: dict) -> str | None:
    """`out` as JSON text; None, said in one line, if a result is not a finite number.

    On every rank, so that every rank takes the same way out.
    """
    try:
        return json.dumps(out, indent=2, allow_nan=False)
    except ValueError:  # a NaN among the results: a defect, never a silent answer
        error("a result is not a finite number: no output written")
        return None


def _write_json(text: str, json_path: str | None) -> bool:
    """The JSON `text` at `json_path` (rank 0); False, said in one line, if it cannot be."""
    if json_path and MPI.COMM_WORLD.rank == 0:
        try:
            Path(json_path).write_text(text)
        except OSError as err:
            error(f"cannot write {json_path}: {err.strerror}")
            return False
    return True


def _finish(run: _Run) -> int:
    """Warnings, the JSON (first), every writer on its own, unread PETSc options."""
    out, writers, options = run.out, run.writers, run.options
    out["wall_time_s"] = time.perf_counter() - run.t0
    out.setdefault("warnings", [])
    out.setdefault("status", "ok")
    if run.steps:
        out.setdefault("steps", run.steps)
    for key, value in run.known.items():
        out.setdefault(key, value)
    for w in out["warnings"]:
        say(f"warning: {w}")
    status = 0
    text = _encode(out)
    if text is None:
        _forget(options)
        return 2
    if not _write_json(text, run.json_path):
        status = 1
    elif run.json_path:
        say(f"wrote {run.json_path}")
    if not _write_each(writers):
        status = 1
    left = options.unused() if options is not None else []
    if left:
        error(f"PETSc option -{left[0]} was read by no solver (misspelt?); this run's options "
              f"prefixes are {options.describe()}")
        return 2
    say(f"wall time {out['wall_time_s']:.2f} s on {MPI.COMM_WORLD.size} rank(s)")
    return status


def _one_line(err: BaseException) -> str:
    from petsc4py import PETSc

    text = " ".join(str(err).split())
    if isinstance(err, PETSc.Error):
        # PETSc's stack: keep its messages, drop the "function() at file:line" frames
        parts = [p.strip() for p in re.split(r"\[\d+\]", text)]
        text = "; ".join(p for p in parts if p and " at /" not in p)
        return f"PETSc rejected an option or failed: {text}"
    return text or type(err).__name__
