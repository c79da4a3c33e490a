"""J2 plasticity: the course's Newton choices on the thick sphere, against mesh size.

Every number comes from `demos/pressure_vessel.py --json` (run in this process through
`cli.run_file`, after a warm-up run that compiles the forms): the default sphere (a = 100,
b = 200, perfect plasticity) loaded to 0.9 p_lim in 10 steps, each Newton variant on the
same meshes. The error is the plastic radius's against the closed form, in element sizes;
the time ratio is against full Newton on the same mesh.

    python benchmarks/plasticity.py [--quick] [--update-readme]
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import fenics_nl  # noqa: F401  (first: loads the wheel's MPI/PETSc before dolfinx)

# isort: split

from common import elapsed, machine, update_readme

from fenics_nl.io import cli

HERE = Path(__file__).resolve().parent
DEMO = HERE.parent / "demos" / "pressure_vessel.py"
VARIANTS = ("full", "modified", "bfgs")


def run(size: float, newton: str, tmp: Path) -> dict:
    out = tmp / f"{size}_{newton}.json"
    status = cli.run_file(DEMO, ["--size", str(size), "--newton", newton, "--pressure-ratio",
                                 "0.9", "--json", str(out)])
    if status:
        raise SystemExit(f"pressure_vessel.py --size {size} --newton {newton} failed")
    d = json.loads(out.read_text())
    return {"size": size, "newton": newton, "dofs": d["dofs"], "wall_time_s": d["wall_time_s"],
            "newton_iterations": d["newton_iterations"],
            "factorizations": d["factorizations"],
            "plastic_radius_error_over_h": (d["plastic_radius"] - d["plastic_radius_exact"])
            / d["element_size"],
            "yield_onset_rel_error": d["yield_onset_pressure"] / d["yield_onset_pressure_exact"]
            - 1}


def table(rows: list[dict]) -> str:
    full = {r["size"]: r["wall_time_s"] for r in rows if r["newton"] == "full"}
    lines = ["Thick sphere a = 100, b = 200, perfect J2 plasticity, P2, 0.9 p_lim in 10 steps; "
             "`python benchmarks/plasticity.py`.", "",
             "| h | unknowns | Newton | iterations | factorizations | time (s) | / full | "
             "(c − c_exact)/h | yield onset error |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['size']:g} | {r['dofs']} | {r['newton']} | {r['newton_iterations']} "
                     f"| {r['factorizations']} | {r['wall_time_s']:.2f} | "
                     f"{r['wall_time_s'] / full[r['size']]:.2f} | "
                     f"{r['plastic_radius_error_over_h']:+.3f} | "
                     f"{100 * r['yield_onset_rel_error']:+.2f} % |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="one coarse mesh")
    ap.add_argument("--update-readme", action="store_true")
    args = ap.parse_args()
    sizes = [12.5] if args.quick else [12.5, 6.25, 3.125]
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        run(sizes[0], "full", tmp)  # warm-up: the forms' JIT
        rows = [run(s, n, tmp) for s in sizes for n in VARIANTS]
    text = table(rows)
    print(text)
    if not args.quick:
        (HERE / "results" / "plasticity.json").write_text(json.dumps(
            {"machine": machine(), "rows": rows, "benchmark_time_s": elapsed()}, indent=2))
        if args.update_readme:
            update_readme("plasticity", text)


if __name__ == "__main__":
    main()
