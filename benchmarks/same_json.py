"""Two runs' JSON compared key by key: what a refactoring must leave as it was.

    python benchmarks/same_json.py OLD.json NEW.json [--rtol 1e-9]

Numbers within `rtol` (relative; 1e-14 absolute near zero), everything else equal; the
measured times (`*time*_s` keys) and the peak memory are skipped. Exit 0 when they agree,
1 with the differences listed.
"""

import argparse
import json
import math
import sys

SKIPPED = ("peak_memory_mb",)


def differences(a, b, rtol: float, path: str = "") -> list[str]:
    """Where `a` and `b` differ, one line each."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = []
        for k in sorted(set(a) | set(b)):
            if k in SKIPPED or ("time" in k and k.endswith("_s")):
                continue
            if k not in a or k not in b:
                out.append(f"{path}/{k}: only in the {'new' if k not in a else 'old'} run")
            else:
                out += differences(a[k], b[k], rtol, f"{path}/{k}")
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{path}: {len(a)} items, then {len(b)}"]
        return [d for i, (x, y) in enumerate(zip(a, b, strict=True))
                for d in differences(x, y, rtol, f"{path}[{i}]")]
    numbers = all(isinstance(x, int | float) and not isinstance(x, bool) for x in (a, b))
    if numbers and (isinstance(a, float) or isinstance(b, float)):
        return [] if math.isclose(a, b, rel_tol=rtol, abs_tol=1e-14) else [
            f"{path}: {a!r} -> {b!r}"]
    return [] if a == b else [f"{path}: {a!r} -> {b!r}"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--rtol", type=float, default=1e-9)
    args = ap.parse_args()
    with open(args.old) as f, open(args.new) as g:
        found = differences(json.load(f), json.load(g), args.rtol)
    print(f"{args.new}: " + ("the same as " + args.old if not found else
                             f"{len(found)} differences"))
    for line in found:
        print("  " + line)
    sys.exit(1 if found else 0)


if __name__ == "__main__":
    main()
