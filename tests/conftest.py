"""Shared test fixtures; loads the dolfinx wheel's MPI/PETSc first (fenics_nl imports
dolfinx_solver).

Under mpiexec, PETSc objects on the world communicator must be destroyed by every rank at
the same point. Python's cyclic garbage collector runs whenever one rank's allocations
cross a threshold, so it can destroy a SNES (dolfinx's NonlinearProblem lives in a
reference cycle) on rank 0 while rank 1 waits in another collective: the mpi suite hung in
3 runs out of 4 that way. So, on several ranks, collect only between tests, all together.
"""

import copy
import fcntl
import gc
import hashlib

import fenics_nl

# isort: split

import itertools
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from mpi4py import MPI

fenics_nl.tune_kernel_flags()  # the kernels the demos and the case command compile
ROOT = Path(__file__).resolve().parents[1]
DEMOS = ROOT / "demos"
# the ready-made problems and the contact peers that tests share with the benchmarks
sys.path.append(str(ROOT / "benchmarks"))
sys.path.append(str(ROOT / "docs"))  # notebooks.py: the demos run as notebooks
MPIEXEC = Path(sys.executable).parent / "mpiexec"
# pytest's cache, where the serial suite keeps its demo runs (Demos.json); the mpi suite runs
# without the cache plugin (two ranks would write its files at once) and reads them here
CACHE = ROOT / ".pytest_cache" / "v"
# what MPICH's launcher tells a process: without it, a process started by a rank is a
# serial run of its own (an MPI singleton), not a third rank of this one
LAUNCHER_VARIABLES = ("PMI_", "HYDRA_", "MPI_LOCALNRANKS", "MPI_LOCALRANKID")

if MPI.COMM_WORLD.size > 1:
    gc.disable()

    @pytest.fixture(autouse=True)
    def _collect_on_every_rank_together():
        yield
        gc.collect()


_runs = itertools.count()
_serial_references: dict[tuple, dict] = {}  # see Demos.json


from notebooks import source_digest  # noqa: E402

SOURCE_DIGEST = source_digest()


def _python(name: str) -> list[str]:
    """The command that runs demos/`name` ("-m fenics_nl": the case-file command)."""
    return [sys.executable, *(["-m", "fenics_nl"] if name == "-m fenics_nl"
                              else [str(DEMOS / name)])]


class Demos:
    """Runs demos/<name> as a user does, in `tmp_path`.

    On as many ranks as this pytest has (1 in the serial suite, 2 in the mpi suite) the
    demo's cells run in this process through `cli.run_file`, under the same contract as the
    script (scikit-fem's test_examples style: no interpreter start, forms stay compiled).
    From the serial suite, other ranks run under `mpiexec -n ranks` in a subprocess
    (`spawns_mpi` tests); from the mpi suite, a serial run is a subprocess of rank 0 (or the
    serial suite's, from its cache: see `json`). Either way the result is a CompletedProcess
    with the exit status, stdout and stderr (captured at the file descriptors, so PETSc's
    own output is in it), the same on every rank but for an in-process run's output.
    """

    def __init__(self, tmp_path, capfd, monkeypatch, request):
        self.tmp_path, self.capfd, self.monkeypatch = tmp_path, capfd, monkeypatch
        self.spawns_mpi = request.node.get_closest_marker("spawns_mpi") is not None
        self.cache = getattr(request.config, "cache", None)  # the mpi suite has none
        self.world = MPI.COMM_WORLD

    def run(self, args, check=True, ranks=1) -> subprocess.CompletedProcess:
        """`python demos/args[0] args[1:]`; with `check`, a non-zero exit fails the test.

        args[0] = "-m fenics_nl" runs the case-file command instead of a demo.
        """
        name, argv = str(args[0]), [str(a) for a in args[1:]]
        if ranks == self.world.size:
            proc = self._in_process(name, argv)
        elif self.world.size == 1:
            proc = self._mpiexec(name, argv, ranks)
        elif ranks == 1:
            proc = self._serial_on_rank_0(name, argv)
        else:
            raise ValueError(f"the mpi suite runs on {self.world.size} ranks or 1, not {ranks}")
        if check:
            assert proc.returncode == 0, proc.stderr
        return proc

    def refuses(self, args, message, ranks=1) -> None:
        """The run of `args` must refuse its input: a non-zero exit, one line on stderr
        that says `message`, no traceback (the scene contract's error)."""
        proc = self.run(args, check=False, ranks=ranks)
        lines = proc.stderr.strip().splitlines()
        assert proc.returncode != 0, args
        assert len(lines) == 1 and message in lines[0], proc.stderr

    def case(self, *args, ranks=1) -> dict:
        """`python -m fenics_nl run args...` and its JSON."""
        return self._run_json("-m fenics_nl", ["run", *args], ranks)

    def _in_process(self, name, argv):
        if name == "-m fenics_nl":
            from fenics_nl.__main__ import main
        else:
            from fenics_nl.io.cli import run_file

            def main(argv):
                return run_file(DEMOS / name, argv)
        from petsc4py import PETSc

        self.capfd.readouterr()
        before = set(PETSc.Options().getAll())
        with self.monkeypatch.context() as m:
            m.chdir(self.tmp_path)
            try:
                code = main(argv)
            except SystemExit as stop:  # argparse: --help, or a bad flag
                code = stop.code if isinstance(stop.code, int) else int(stop.code is not None)
            finally:  # what a failed run may leave behind must not reach the next one
                for name in set(PETSc.Options().getAll()) - before:
                    PETSc.Options().delValue(name)
                import matplotlib.pyplot as plt

                plt.close("all")
        out, err = self.capfd.readouterr()
        return subprocess.CompletedProcess([name, *argv], code, out, err)

    def _mpiexec(self, name, argv, ranks):
        # its ranks need the cores: `make test` runs these tests after the parallel
        # (pytest-xdist) serial suite, alone; MPICH's busy-waiting ranks crawl when
        # oversubscribed
        assert self.spawns_mpi, "a test that runs mpiexec must be marked spawns_mpi"
        cmd = [str(MPIEXEC), "-n", str(ranks), *_python(name), *argv]
        env = dict(os.environ)
        if ranks > (os.cpu_count() or 1):
            # more ranks than cores: MPICH's progress engine then polls less often, which
            # halves the 3-rank runs on 2 cores (measured: bracket 7.5 s -> 4.5 s)
            env.setdefault("MPIR_CVAR_CH4_PROGRESS_THROTTLE", "1")
        return subprocess.run(cmd, cwd=self.tmp_path, capture_output=True, text=True,
                              timeout=900, env=env)

    def _serial_on_rank_0(self, name, argv):
        # the other ranks sleep meanwhile: MPICH's busy wait in a collective would take the
        # core the serial run needs
        proc = None
        if self.world.rank == 0:
            env = {k: v for k, v in os.environ.items() if not k.startswith(LAUNCHER_VARIABLES)}
            proc = subprocess.run([*_python(name), *argv], cwd=self.tmp_path,
                                  capture_output=True, text=True, timeout=900, env=env)
        done = self.world.Ibarrier()
        while not done.Test():
            time.sleep(0.05)
        return self.world.bcast(proc)

    def json(self, name, *args, ranks=1) -> dict:
        """Run demos/`name` with `args` and return its JSON.

        A serial run is made once per code: two tests that ask for the same serial run
        (a scene's test and its notebook's, whose script run has the page's flags; a test
        of ranks, whose serial reference the serial suite ran just before on both cores)
        share it. Runs are kept in this process and in pytest's cache (the other xdist
        worker's, an earlier session's) under the digest of the library, the demos and the
        pins, so a shared run is never one of other code; one that writes files (--png,
        --output, checkpoints) is not shared.
        """
        key = (name, *map(str, args))
        cache_key = f"fenics_nl/serial/{SOURCE_DIGEST}/{'_'.join(key)}"
        shared = ranks == 1 and not any(
            str(a).startswith(("--png", "--plot", "--output", "--checkpoint", "--restart"))
            for a in args)
        if not shared:
            return self._run_json(name, args, ranks)
        if key in _serial_references:
            return copy.deepcopy(_serial_references[key])
        if self.world.size > 1:  # the mpi suite: the serial suite's run, or one made now
            result = self._cached_on_rank_0(cache_key)
            if result is None:
                result = self._run_json(name, args, ranks)
                self._cache_on_rank_0(cache_key, result)
        else:
            # the other xdist worker may be making this very run: wait for it rather than
            # make it twice (a lock per run, held while it is made)
            lock = self.cache.mkdir("fenics_nl_locks") / hashlib.sha1(
                cache_key.encode()).hexdigest()
            with open(lock, "w") as held:
                fcntl.flock(held, fcntl.LOCK_EX)
                result = self.cache.get(cache_key, None)
                if result is None:
                    result = self._run_json(name, args, ranks)
                    self.cache.set(cache_key, result)
        _serial_references[key] = copy.deepcopy(result)
        return result

    def _cached_on_rank_0(self, cache_key):
        path = CACHE / cache_key
        found = json.loads(path.read_text()) if self.world.rank == 0 and path.is_file() else None
        return self.world.bcast(found)

    def _cache_on_rank_0(self, cache_key, result):
        # as pytest's cache.set writes it, so that the serial suite finds it too
        if self.world.rank == 0:
            (CACHE / cache_key).parent.mkdir(parents=True, exist_ok=True)
            (CACHE / cache_key).write_text(json.dumps(result, indent=2, sort_keys=True))

    def _run_json(self, name, args, ranks) -> dict:
        # rank 0 writes the JSON: every rank names its file and reads it from rank 0
        stem = "case" if name == "-m fenics_nl" else Path(name).stem
        out = self.world.bcast(self.tmp_path / f"{stem}{next(_runs)}.json")
        self.run([name, *args, "--json", out], ranks=ranks)
        return self.world.bcast(json.loads(out.read_text()) if self.world.rank == 0 else None)

    def punch(self, *args, ranks=1) -> dict:
        return self.json("punch.py", *args, ranks=ranks)

    def punch_friction(self, *args, ranks=1) -> dict:
        return self.json("punch_friction.py", *args, ranks=ranks)

    def indentation(self, *args, ranks=1) -> dict:
        return self.json("indentation.py", *args, ranks=ranks)

    def beam(self, *args, ranks=1) -> dict:
        return self.json("buckling_beam.py", *args, ranks=ranks)

    def bracket(self, *args, ranks=1) -> dict:
        return self.json("bracket.py", *args, ranks=ranks)


@pytest.fixture
def demo(tmp_path, capfd, monkeypatch, request) -> Demos:
    """Run the demos in `tmp_path` (see `Demos`)."""
    return Demos(tmp_path, capfd, monkeypatch, request)


@pytest.fixture
def on_elastica():
    """The check of a beam JSON against Euler and the elastica, to the demo's tolerances."""

    def check(d):
        assert abs(d["critical_load_rel_error"]) < 0.005
        da = abs(d["tip_rotation_deg"] - d["elastica_tip_rotation_deg"])
        assert da < max(0.5, 0.01 * d["elastica_tip_rotation_deg"]), d
        assert d["tip_deflection"] == pytest.approx(d["elastica_tip_deflection"], rel=0.01)
        assert all(math.isfinite(p["tip_rotation_deg"]) for p in d["path"])

    return check


def read_series(path, name):
    """(times, values per step) of one VTX field."""
    import adios2
    import numpy as np

    times, values = [], []
    with adios2.Stream(str(path), "r") as f:
        for _ in f.steps():
            times.append(float(np.ravel(f.read("step"))[0]))
            values.append(np.asarray(f.read(name)))
    return times, values


def taylor_remainders(residual, w, scale: float, seed: int,
                      steps=(1e-2, 5e-3, 2.5e-3, 1.25e-3)):
    """(‖R(w + h dw) − R(w) − h K dw‖ for each h, their slopes) along a random dw.

    dw = `scale` × standard normal entries; K = UFL's derivative of the residual form. A
    consistent tangent gives slope 2. `w` is left at its value on entry plus the last h dw.
    """
    import numpy as np
    import ufl
    from dolfinx import fem
    from dolfinx.fem import petsc
    from petsc4py import PETSc

    rng = np.random.default_rng(seed)
    w0 = w.x.array.copy()
    dw = fem.Function(w.function_space)
    dw.x.array[:] = scale * rng.standard_normal(dw.x.array.size)
    R, K = fem.form(residual), fem.form(ufl.derivative(residual, w))

    def residual_at(h):
        w.x.array[:] = w0 + h * dw.x.array
        b = petsc.assemble_vector(R)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        return b

    r0 = residual_at(0.0)
    A = petsc.assemble_matrix(K)
    A.assemble()
    Kdw = r0.duplicate()
    A.mult(dw.x.petsc_vec, Kdw)
    errs = []
    for h in steps:
        rh = residual_at(h)
        rh.axpy(-1.0, r0)
        rh.axpy(-h, Kdw)
        errs.append(rh.norm())
    return errs, np.diff(np.log(errs)) / np.diff(np.log(steps))


# -- killed runs and their restarts ------------------------------------------------------

def run_and_kill(cmd, cwd, after_line: str, ranks=1):
    """Start `cmd`, SIGKILL it (and its ranks) once its stdout shows `after_line`."""
    proc = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    for line in proc.stdout:
        if line.startswith(after_line):
            os.killpg(proc.pid, signal.SIGKILL)
            break
    proc.wait(timeout=600)
    assert proc.returncode == -signal.SIGKILL, proc.stderr.read()


def same_answer(a, b, rel=1e-10):
    """Every step's load factor, iterations, probes and reactions agree (to `rel` of the
    largest value): the restart took the same path (predictor, force reference, statuses)."""
    for key in ("load_factor", "newton_iterations", "active_set_iterations", "stage",
                "stage_progress"):
        assert [s.get(key) for s in a["steps"]] == [s.get(key) for s in b["steps"]], key
    import numpy as np

    for sa, sb in zip(a["steps"], b["steps"], strict=True):
        for key in ("probes", "reactions"):
            x, y = np.array(flatten(sa[key])), np.array(flatten(sb[key]))
            assert x.shape == y.shape, key
            assert np.abs(x - y).max(initial=0.0) <= rel * np.abs(x).max(initial=0.0), key


def flatten(x):
    if isinstance(x, dict):
        return [v for k in sorted(x) for v in flatten(x[k])]
    if isinstance(x, list):
        return [v for item in x for v in flatten(item)]
    return [float(x)]



# the serial suite's longest tests (each demo executed as a notebook, and its script run)
# go first: started last, they would leave one of the two cores idle at the end
FIRST = ("test_notebooks.py",)


def pytest_collection_modifyitems(config, items):
    items.sort(key=lambda item: item.nodeid.split("::")[0].rsplit("/", 1)[-1] not in FIRST)
