"""Every demo's JSON at a fixed small size, saved or compared key by key: a refactoring's check.

    python benchmarks/demo_snapshot.py save DIR      # before the change
    python benchmarks/demo_snapshot.py compare DIR   # after it: every key, times aside

Numbers agree to 1e-10 of their size (a vector's components to 1e-10 of its largest), counts
and words exactly; keys that are times or memory, and the case file's path, are left out.
Exit 1 on any difference, each said in one line.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RUNS = {  # name: the demo and its arguments (small meshes, every path the demo has)
    "newton_scalar": ["newton_scalar.py"],
    "punch": ["punch.py", "--refine", "0", "--steps", "2"],
    "punch_force_mixed": ["punch.py", "--refine", "0", "--force", "0.01", "--mixed"],
    "punch_j2": ["indentation.py", "--refine", "0", "--steps", "2"],
    "punch_friction": ["punch_friction.py", "--nu", "0.3", "--refine", "0", "--block", "1000"],
    "punch_friction_normal": ["punch_friction.py", "--model", "axisymmetric", "--nu", "0.3",
                              "--refine", "0", "--block", "1000"],
    "punch_friction_incompressible": ["punch_friction.py", "--refine", "0", "--block", "100",
                                      "--tangential-displacement", "0.0023"],
    "bracket_compare": ["bracket.py", "--compare", "--size", "20", "--steps", "2"],
    "bracket_j2_floor": ["bracket.py", "--material", "j2", "--support", "contact", "--size",
                         "20", "--steps", "2"],
    "bracket_iterative": ["bracket.py", "--linear-solver", "gamg", "--size", "20"],
    "beam": ["buckling_beam.py"],
    "vessel": ["pressure_vessel.py", "--steps", "6", "--unload"],
    "vessel_modified": ["pressure_vessel.py", "--newton", "modified", "--steps", "4"],
    "snap_through": ["snap_through.py"],
    "damage_bar": ["damage_bar.py"],
    "case_cylinder": ["-m", "fenics_nl", "run", str(ROOT / "cases" / "thick_cylinder.toml")],
    "case_arch": ["-m", "fenics_nl", "run", str(ROOT / "cases" / "shallow_arch.toml")],
}
# left out: times, memory, and the case file's path (the runs sit in other folders)
IGNORED_ENDINGS, IGNORED_KEYS = ("time_s", "_mb"), ("case",)


def run(name: str, args: list[str], folder: Path) -> None:
    out = folder / f"{name}.json"
    script = args if args[0] == "-m" else [str(ROOT / "demos" / args[0]), *args[1:]]
    proc = subprocess.run([sys.executable, *script, "--json", str(out)], cwd=folder,
                          capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit(f"{name}: exit {proc.returncode}: {proc.stderr.strip()[-300:]}")


def differences(a, b, where: str, scale: float = 0.0, rel: float = 1e-10):
    """Where `a` and `b` differ (a list of one-line descriptions)."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = [f"{where}: keys {sorted(set(a) ^ set(b))}"] if set(a) != set(b) else []
        for k in sorted(set(a) & set(b)):
            if not (k.endswith(IGNORED_ENDINGS) or k in IGNORED_KEYS):
                out += differences(a[k], b[k], f"{where}.{k}", rel=rel)
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{where}: {len(a)} items, now {len(b)}"]
        largest = max((abs(v) for v in a if isinstance(v, float)), default=0.0)
        return [d for i, (x, y) in enumerate(zip(a, b, strict=True))
                for d in differences(x, y, f"{where}[{i}]", largest, rel)]
    if isinstance(a, float) and isinstance(b, (int, float)):
        ok = abs(a - b) <= rel * max(abs(a), scale)
        return [] if ok else [f"{where}: {a!r}, now {b!r}"]
    return [] if a == b else [f"{where}: {a!r}, now {b!r}"]


def main() -> int:
    if len(sys.argv) != 3 or sys.argv[1] not in ("save", "compare"):
        sys.exit(__doc__)
    mode, folder = sys.argv[1], Path(sys.argv[2]).resolve()
    target = folder if mode == "save" else folder / "now"
    target.mkdir(parents=True, exist_ok=True)
    found = []
    for name, args in RUNS.items():
        run(name, args, target)
        if mode == "compare":
            before = json.loads((folder / f"{name}.json").read_text())
            now = json.loads((target / f"{name}.json").read_text())
            found += differences(before, now, name)
        print(f"{name}: done", flush=True)
    for line in found:
        print(line)
    print(f"{len(RUNS)} runs, {len(found)} differences" if mode == "compare" else
          f"{len(RUNS)} runs saved in {folder}")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
