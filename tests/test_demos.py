"""Run each demo as a user would (a subprocess), serially and under mpiexec."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DEMOS = ROOT / "demos"


def run(args, tmp_path, check=True):
    proc = subprocess.run([sys.executable, *args], cwd=tmp_path, capture_output=True, text=True,
                          timeout=600)
    if check:
        assert proc.returncode == 0, proc.stderr
    return proc


def test_newton_scalar_orders(tmp_path):
    out = tmp_path / "scalar.json"
    run([DEMOS / "newton_scalar.py", "--json", out], tmp_path)
    data = json.loads(out.read_text())
    for method, order in [("newton", 2.0), ("modified", 1.0), ("secant", (1 + 5**0.5) / 2)]:
        assert abs(data[method]["order"] - order) < 0.15, (method, data[method])
        assert data[method]["iterations"] > 0
    assert data["modified"]["iterations"] > 5 * data["newton"]["iterations"]


def test_newton_scalar_plot_in_double_precision(tmp_path):
    png = tmp_path / "orders.png"
    run([DEMOS / "newton_scalar.py", "--function", "kepler", "--digits", "16", "--plot", png],
        tmp_path)
    assert png.stat().st_size > 10_000


@pytest.mark.parametrize("args,message", [
    (["--digits", "3"], "--digits"),
    (["--function", "nope"], "invalid choice"),
    (["--slope", "0"], "--slope"),
    (["--function", "hardening"], "modified"),  # modified Newton diverges: one clear line
])
def test_newton_scalar_bad_input(tmp_path, args, message):
    proc = run([DEMOS / "newton_scalar.py", *args], tmp_path, check=False)
    assert proc.returncode != 0
    assert message in proc.stderr and "Traceback" not in proc.stderr
