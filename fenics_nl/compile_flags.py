"""The C flags of the kernels FFCx generates: -O3 and AVX2/FMA where the CPU has them.

DOLFINx compiles each form with `-O2` for a generic x86-64, which leaves the vector units
idle in the element loops. With `-O3 -march=x86-64-v3` the bracket's P2 power-law tangent
assembles in 0.125 s instead of 0.163 s (measured, 2891 tetrahedra; `-march=native` with
AVX-512 is no faster), and the suite's heaviest tests run about 15 % faster. The level is
named, not `native`: the flags are part of the kernel cache's key, so a cache shared by
different machines never hands one a kernel for instructions it lacks. A CPU without AVX2
and FMA, another architecture, or a user's own `dolfinx_jit_options.json` (which DOLFINx
reads after these defaults) keeps its own choice.

Opt-in: `import fenics_nl` leaves DOLFINx's options alone (they are global: they would
change every other form compiled in a user's process); the demos, the case command, the
tests and the benchmarks call `tune_kernel_flags()`.
"""

from __future__ import annotations

import platform

__all__ = ["tune_kernel_flags"]

FLAGS = ["-O3", "-g0", "-march=x86-64-v3"]


def _has_avx2_and_fma() -> bool:
    try:
        from numpy._core._multiarray_umath import __cpu_features__ as cpu
    except ImportError:  # numpy's runtime CPU detection moved: keep DOLFINx's default
        return False
    return bool(cpu.get("AVX2") and cpu.get("FMA3"))


def tune_kernel_flags() -> bool:
    """Make FLAGS DOLFINx's default compile flags where the CPU runs them; whether it did.

    Global to the process (`dolfinx.jit.DOLFINX_DEFAULT_JIT_OPTIONS`): every form compiled
    after the call takes them. Example::

        import fenics_nl

        fenics_nl.tune_kernel_flags()  # before the first form is compiled
    """
    if platform.machine().lower() not in ("x86_64", "amd64") or not _has_avx2_and_fma():
        return False
    from dolfinx import jit

    _, doc = jit.DOLFINX_DEFAULT_JIT_OPTIONS["cffi_extra_compile_args"]
    jit.DOLFINX_DEFAULT_JIT_OPTIONS["cffi_extra_compile_args"] = (list(FLAGS), doc)
    return True
