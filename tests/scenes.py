"""Running the demos as a user does (a subprocess, serially or under mpiexec), for the tests."""

import itertools
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DEMOS = ROOT / "demos"
MPIEXEC = Path(sys.executable).parent / "mpiexec"
_runs = itertools.count()


def run(args, tmp_path, check=True, ranks=1):
    """The command `python args...` in `tmp_path` (under mpiexec -n ranks if ranks > 1)."""
    cmd = [sys.executable, *args]
    if ranks > 1:
        cmd = [MPIEXEC, "-n", str(ranks), *cmd]
    proc = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True, timeout=900)
    if check:
        assert proc.returncode == 0, proc.stderr
    return proc


def scene(demo, tmp_path, *args, ranks=1) -> dict:
    """Run demos/`demo` with `args` and return its JSON."""
    out = tmp_path / f"{Path(demo).stem}{next(_runs)}.json"
    run([DEMOS / demo, *args, "--json", out], tmp_path, ranks=ranks)
    return json.loads(out.read_text())


def punch(tmp_path, *args, ranks=1):
    return scene("punch.py", tmp_path, *args, ranks=ranks)


def beam(tmp_path, *args, ranks=1):
    return scene("buckling_beam.py", tmp_path, *args, ranks=ranks)


def bracket(tmp_path, *args, ranks=1):
    return scene("bracket.py", tmp_path, *args, ranks=ranks)


def assert_on_elastica(d):
    """The beam's JSON against Euler and the elastica, to the demo's tolerances."""
    assert abs(d["critical_load_rel_error"]) < 0.005
    da = abs(d["tip_rotation_deg"] - d["elastica_tip_rotation_deg"])
    assert da < max(0.5, 0.01 * d["elastica_tip_rotation_deg"]), d
    assert d["tip_deflection"] == pytest.approx(d["elastica_tip_deflection"], rel=0.01)
    assert all(math.isfinite(p["tip_rotation_deg"]) for p in d["path"])
