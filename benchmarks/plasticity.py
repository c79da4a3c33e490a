"""J2 plasticity: the course's Newton choices on the thick sphere and the bracket.

Every number comes from the demos' `--json`, each Newton variant on the same meshes:

* **sphere** (`demos/pressure_vessel.py`, run in this process through `cli.run_file`, after a
  warm-up run that compiles the forms): a = 100, b = 200, perfect plasticity, loaded to
  0.9 p_lim in 10 steps on four meshes (1.7k to 91k unknowns). Errors against the closed
  forms: u(a) (exact for the monotonic loading, `vessels.sphere_inner_displacement`) and
  the plastic radius, in element sizes;
* **near the limit**: the sphere to 0.99 p_lim on the second mesh, where the material's
  tangent stiffness tends to zero and the elastic one does not: where the variants part;
* **bracket** (`demos/bracket.py --material j2`, a process per run as in
  `benchmarks/bracket.py`): 8 kN in 4 steps; no closed form, the variants must agree;
* **one linear solve** of each mesh (assemble, factorize, solve: MUMPS LU) is the time unit
  of "time per load step";
* **1 vs 2 ranks**: full Newton and BFGS on the finest sphere and the finer bracket.

Variants: full (consistent tangent, from UFL), modified (the course's choice: the elastic
tangent factorized once for the run), BFGS (on that same factorization), SNES newtonls on
the same residual and consistent tangent.

    python benchmarks/plasticity.py [--quick] [--update-docs]
"""

from __future__ import annotations

import contextlib
import io
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

import bracket as bracket_benchmark
import ufl
from common import machine, options, publish
from petsc4py import PETSc
from plasticity_problems import ThickVessel, thick_vessel

from fenics_nl.io import cli
from fenics_nl.materials.laws import LinearElastic
from fenics_nl.solvers.form_matrix import FormMatrix
from fenics_nl.solvers.linear_solver import create_ksp

HERE = Path(__file__).resolve().parent
VESSEL = HERE.parent / "demos" / "pressure_vessel.py"
MPIEXEC = Path(sys.executable).parent / "mpiexec"
SPHERE_VARIANTS = ("full", "modified", "bfgs", "snes")
BRACKET_VARIANTS = {"full": "full", "modified": "modified", "bfgs": "bfgs", "snes": "snes"}
SPHERE_STEPS, BRACKET_STEPS = 10, 4


def say(*a):
    print(*a, flush=True)


def linear_solve_time(body: ThickVessel, E: float, nu: float, pressure: float, dx=None,
                      prefix: str = "linear_") -> float:
    """One elastic solve of the vessel's mesh: assemble K and the load, factorize (MUMPS LU),
    solve; the second of two runs (the first compiles). `dx`: the non-linear forms' rule
    (default the body's)."""
    from dolfinx import fem
    from dolfinx.fem import petsc

    du, v = ufl.TrialFunction(body.V), ufl.TestFunction(body.V)
    K = fem.form(ufl.derivative(LinearElastic(E, nu).internal_work(body.u, v, body.model)
                                * (dx or body.dx), body.u, du))
    L = fem.form(-pressure * ufl.dot(body.normal, v) * body.weight * body.ds_inner)
    x = fem.Function(body.V)

    def solve() -> float:
        t0 = time.perf_counter()
        form_matrix = FormMatrix(K)  # the solvers' own assembly
        form_matrix.assemble(K, body.supports)
        matrix = form_matrix.mat
        b = petsc.assemble_vector(L)
        petsc.apply_lifting(b, [K], [body.supports])
        b.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
        petsc.set_bc(b, body.supports)
        ksp = create_ksp(matrix, "lu", prefix=prefix)
        ksp.solve(b, x.x.petsc_vec)
        spent = time.perf_counter() - t0
        for obj in (ksp, matrix, b):
            obj.destroy()
        return spent

    solve()
    return solve()


def vessel(size: float, newton: str, ranks: int = 1, ratio: float = 0.9,
           may_fail: bool = False, separate: bool = False) -> dict:
    """One sphere run to `ratio` p_lim: in this process, or a process per run (`separate`,
    always on 2 ranks and more).

    `may_fail`: a failed run is a result ({"failed": the demo's error line}), not an error.
    """
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out.json"
        argv = ["--size", str(size), "--newton", newton, "--pressure-ratio", str(ratio),
                "--steps", str(SPHERE_STEPS), "--json", str(out)]
        if ranks == 1 and not separate:
            errors = io.StringIO()
            with contextlib.redirect_stderr(errors):
                failed = cli.run_file(VESSEL, argv)
            message = errors.getvalue().strip()
        else:
            cmd = [sys.executable, str(VESSEL), *argv]
            cmd = [str(MPIEXEC), "-n", str(ranks), *cmd] if ranks > 1 else cmd
            proc = subprocess.run(cmd, capture_output=True, text=True)
            failed, message = proc.returncode, proc.stderr.strip()
        if failed and may_fail:
            return {"size": size, "newton": newton, "failed": message.splitlines()[-1]}
        if failed:
            raise SystemExit(f"pressure_vessel.py {' '.join(argv)} on {ranks} rank(s) "
                             f"failed:\n{message}")
        d = json.loads(out.read_text())
    return {"size": size, "newton": newton, "dofs": d["dofs"], "ranks": d["ranks"],
            "failed": False, "iterations_per_step": d["iterations_per_step"],
            "step_cuts": d["step_cuts"], "phase_time_s": d["phase_time_s"],
            "solve_time_s": d["solve_time_s"], "newton_iterations": d["newton_iterations"],
            "factorizations": d["factorizations"],
            "inner_displacement_rel_error": d["inner_displacement"]
            / d["inner_displacement_exact"] - 1,
            "plastic_radius_error_over_h": (d["plastic_radius"] - d["plastic_radius_exact"])
            / d["element_size"]}


def sphere(sizes) -> list[dict]:
    rows = []
    for size in sizes:
        body = thick_vessel("sphere", 100.0, 200.0, size=size)
        linear = linear_solve_time(body, 210e3, 0.3, 100.0)
        for newton in SPHERE_VARIANTS:
            r = vessel(size, newton)
            r["linear_solve_s"] = linear
            rows.append(r)
            say(f"sphere h = {size:g} ({r['dofs']} unknowns) {newton:9s} "
                f"{r['solve_time_s']:7.2f} s {r['newton_iterations']:4d} its "
                f"{r['factorizations']:3d} fact; linear solve {linear:.3f} s")
    return rows


def near_limit(size: float, ratio: float) -> list[dict]:
    """The sphere to `ratio` p_lim (close to 1), where the variants part: the material's
    tangent stiffness tends to zero, the elastic one does not."""
    rows = []
    for newton in SPHERE_VARIANTS:
        r = vessel(size, newton, ratio=ratio, may_fail=True)
        r["ratio"] = ratio
        rows.append(r)
        say(f"sphere to {ratio} p_lim, h = {size:g}, {newton}: " + (
            f"failed: {r['failed']}" if r["failed"] else
            f"{r['solve_time_s']:.2f} s, iterations per step {r['iterations_per_step']}"))
    return rows


def bracket(sizes) -> list[dict]:
    rows = []
    for size in sizes:
        lin = bracket_benchmark.record(bracket_benchmark.run(
            "--size", size, "--material", "linear", "--steps", 1))
        for name, newton in BRACKET_VARIANTS.items():
            r = bracket_benchmark.record(bracket_benchmark.run(
                "--size", size, "--material", "j2", "--newton", newton,
                "--steps", BRACKET_STEPS))
            r.update(size=size, newton=name, linear_solve_s=lin["solve_time_s"])
            rows.append(r)
            say(f"bracket {size:g} mm ({r['dofs']} unknowns) {name:9s} "
                f"{r['solve_time_s']:7.2f} s {r['newton_iterations']:4d} its "
                f"{r['factorizations']:3d} fact |u| {r['load_point_displacement']:.9f}")
    return rows


def parallel(sphere_size: float, bracket_size: float) -> list[dict]:
    rows = []
    for newton in ("full", "bfgs"):
        one, two = (vessel(sphere_size, newton, ranks=n, separate=True) for n in (1, 2))
        rows.append({"scene": "sphere", "newton": newton, "dofs": one["dofs"],
                     "time_1_s": one["solve_time_s"], "time_2_s": two["solve_time_s"],
                     "agree": abs(two["inner_displacement_rel_error"]
                                  - one["inner_displacement_rel_error"])})
        one, two = (bracket_benchmark.record(bracket_benchmark.run(
            "--size", bracket_size, "--material", "j2", "--newton",
            BRACKET_VARIANTS[newton], "--steps", BRACKET_STEPS, ranks=n)) for n in (1, 2))
        rows.append({"scene": "bracket", "newton": newton, "dofs": one["dofs"],
                     "time_1_s": one["solve_time_s"], "time_2_s": two["solve_time_s"],
                     "agree": abs(two["load_point_displacement"]
                                  / one["load_point_displacement"] - 1)})
    for r in rows:
        r["speedup"] = r["time_1_s"] / r["time_2_s"]
        say(f"{r['scene']} {r['newton']} ({r['dofs']} unknowns): 1 rank {r['time_1_s']:.2f} s, "
            f"2 ranks {r['time_2_s']:.2f} s, speed-up {r['speedup']:.2f}")
    return rows


def per_step(r: dict) -> str:
    """Time per converged load step, in linear solves of the same mesh."""
    return f"{r['solve_time_s'] / len(r['iterations_per_step']) / r['linear_solve_s']:.1f}"


def table(s: dict) -> str:
    lines = [f"**Sphere** a = 100, b = 200, perfect plasticity, P2, 0.9 p_lim in "
             f"{SPHERE_STEPS} steps:", "",
             "| h | unknowns | Newton | iterations | factorizations | time (s) | / full | "
             "per step / linear solve | u(a) error | (c − c_exact)/h |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    full = {(r["size"]): r["solve_time_s"] for r in s["sphere"] if r["newton"] == "full"}
    for r in s["sphere"]:
        lines.append(f"| {r['size']:g} | {r['dofs']} | {r['newton']} | "
                     f"{r['newton_iterations']} | {r['factorizations']} | "
                     f"{r['solve_time_s']:.2f} | {r['solve_time_s'] / full[r['size']]:.2f} | "
                     f"{per_step(r)} | "
                     f"{100 * r['inner_displacement_rel_error']:+.3f} % | "
                     f"{r['plastic_radius_error_over_h']:+.3f} |")
    lines += ["", f"**Bracket** (`--material j2`, σ0 = 200 MPa, H = 13 GPa), P2, 8 kN in "
              f"{BRACKET_STEPS} steps:", "",
              "| size (mm) | unknowns | Newton | iterations | factorizations | time (s) | / full "
              "| per step / linear solve | \\|u_load\\| (mm) |",
              "|---|---|---|---|---|---|---|---|---|"]
    full = {(r["size"]): r["solve_time_s"] for r in s["bracket"] if r["newton"] == "full"}
    for r in s["bracket"]:
        lines.append(f"| {r['size']:g} | {r['dofs']} | {r['newton']} | "
                     f"{r['newton_iterations']} | {r['factorizations']} | "
                     f"{r['solve_time_s']:.2f} | {r['solve_time_s'] / full[r['size']]:.2f} | "
                     f"{per_step(r)} | {r['load_point_displacement']:.6f} |")
    if s.get("near_limit"):
        rows = s["near_limit"]
        lines += ["", f"Near the limit load: the sphere to {rows[0]['ratio']:g} p_lim, "
                  f"h = {rows[0]['size']:g}, {SPHERE_STEPS} steps (a step that fails is "
                  "halved):", "", "| Newton | iterations per converged step | step cuts | "
                  "factorizations | time (s) | u(a) error |", "|---|---|---|---|---|---|"]
        for r in rows:
            if r["failed"]:
                lines.append(f"| {r['newton']} | failed: {r['failed']} | | | | |")
            else:
                lines.append(f"| {r['newton']} | {', '.join(map(str, r['iterations_per_step']))}"
                             f" | {r['step_cuts']} | {r['factorizations']} | "
                             f"{r['solve_time_s']:.2f} | "
                             f"{100 * r['inner_displacement_rel_error']:+.3f} % |")
    if s.get("parallel"):
        lines += ["", "1 vs 2 ranks (MUMPS):", "",
                  "| scene | unknowns | Newton | 1 rank (s) | 2 ranks (s) | speed-up | "
                  "2 ranks vs 1: result |", "|---|---|---|---|---|---|---|"]
        lines += [f"| {r['scene']} | {r['dofs']} | {r['newton']} | {r['time_1_s']:.2f} | "
                  f"{r['time_2_s']:.2f} | **{r['speedup']:.2f}** | {r['agree']:.0e} |"
                  for r in s["parallel"]]
    lines += ["", "`python benchmarks/plasticity.py`; times are of the load steps (solve "
              "only); one linear solve = assemble, factorize, solve on the same mesh."]
    return "\n".join(lines)


def main():
    args = options(__doc__, "coarse meshes, nothing written")
    sphere_sizes = [12.5] if args.quick else [12.5, 6.25, 3.125, 1.5625]
    bracket_sizes = [14.0] if args.quick else [9.0, 6.0]
    with tempfile.TemporaryDirectory() as d:
        cli.run_file(VESSEL, ["--size", "12.5", "--json", str(Path(d) / "warm.json")])
    out = {"machine": machine(), "sphere_steps": SPHERE_STEPS, "bracket_steps": BRACKET_STEPS,
           "sphere": sphere(sphere_sizes),
           "bracket": bracket(bracket_sizes)}
    if not args.quick:
        out["near_limit"] = near_limit(sphere_sizes[1], 0.99)
        out["parallel"] = parallel(sphere_sizes[-1], bracket_sizes[-1])
    publish("plasticity", out, table, args, say=say)


if __name__ == "__main__":
    main()
