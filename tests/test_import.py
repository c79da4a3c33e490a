"""The package on any DOLFINx 0.11: `import fenics_nl` without the PyPI wheel's loader, and
DOLFINx's global JIT options left as they were (the faster kernel flags are opt-in)."""

import subprocess
import sys
import textwrap

# a plane-strain square pulled by T on x = 1, held by symmetry on x = 0 and y = 0: u is
# linear, u_x = T (1 − ν²) x / E and u_y = −T ν (1 + ν) y / E, exact for P1
SOLVE = """
import numpy as np
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from fenics_nl.domain import boundary
from fenics_nl.materials.laws import LinearElastic
from fenics_nl.solvers.newton import NewtonSolver

msh = mesh.create_unit_square(MPI.COMM_WORLD, 4, 4)
V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
u, v = fem.Function(V), ufl.TestFunction(V)
E, nu, T = 100.0, 0.3, 2.0
facets = {name: mesh.locate_entities_boundary(msh, 1, where) for name, where in
          {"left": lambda x: np.isclose(x[0], 0), "bottom": lambda x: np.isclose(x[1], 0),
           "right": lambda x: np.isclose(x[0], 1)}.items()}
tags = mesh.meshtags(msh, 1, facets["right"], np.full(len(facets["right"]), 1, np.int32))
ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
residual = (LinearElastic(E, nu).internal_work(u, v, "plane_strain") * ufl.dx
            - T * v[0] * ds(1))
bcs = [boundary.component(V, 0, facets["left"]), boundary.component(V, 1, facets["bottom"])]
NewtonSolver(residual, u, bcs).solve()
x = V.tabulate_dof_coordinates()[:, :2]
exact = np.column_stack([T * (1 - nu**2) / E * x[:, 0], -T * nu * (1 + nu) / E * x[:, 1]])
assert np.allclose(u.x.array.reshape(-1, 2), exact, atol=1e-12), "wrong answer"
print("solved")
"""


def run(code: str) -> str:
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout


def test_the_package_imports_and_solves_without_the_wheels_loader():
    # a DOLFINx from conda-forge, Docker or Spack has no `dolfinx_solver`: its libraries
    # are loaded here (this venv's DOLFINx needs them), then the module is made unimportable
    out = run(textwrap.dedent("""
        import sys
        import dolfinx_solver  # noqa: F401
        sys.modules["dolfinx_solver"] = None  # `import dolfinx_solver` now fails
        # (and this venv's finder that imports it before dolfinx, fenics_nl_import_order.pth,
        # is not there either: it is `make`'s, for the wheel)
        sys.meta_path[:] = [f for f in sys.meta_path if type(f).__name__ != "_DolfinxFirst"]
        try:
            import dolfinx_solver  # noqa: F401, F811
        except ModuleNotFoundError:
            print("hidden")
        import fenics_nl  # noqa: F401
        """) + SOLVE)
    assert out.split() == ["hidden", "solved"]


def test_importing_the_package_leaves_dolfinx_jit_options_as_they_were():
    # they are global: changed, they would change every form compiled in a user's process;
    # the faster kernels are an explicit call (the demos, the tests, the benchmarks make it)
    out = run(textwrap.dedent("""
        import copy
        import dolfinx_solver  # noqa: F401
        from dolfinx import jit

        before = copy.deepcopy(jit.DOLFINX_DEFAULT_JIT_OPTIONS)
        import fenics_nl

        print(jit.DOLFINX_DEFAULT_JIT_OPTIONS == before)
        tuned = fenics_nl.tune_kernel_flags()
        print(tuned, jit.DOLFINX_DEFAULT_JIT_OPTIONS == before)
        """))
    unchanged, tuned, still = out.split()
    assert unchanged == "True"
    assert (tuned, still) in (("True", "False"), ("False", "True"))  # a CPU without AVX2


def test_the_solvers_import_nothing_of_io_and_the_parameters_not_the_run():
    # io (the run, its files) builds on solvers, never the other way; io.parameters builds
    # on io.flags, not on io.cli (which reads a demo's parameters: one direction)
    import ast
    from pathlib import Path

    root = Path(__file__).resolve().parents[1] / "fenics_nl"

    def imports(path):
        out = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module:
                out |= {node.module, *(f"{node.module}.{a.name}" for a in node.names)}
            elif isinstance(node, ast.Import):
                out |= {a.name for a in node.names}
        return {m for m in out if m.startswith("fenics_nl")}

    for path in (root / "solvers").glob("*.py"):
        assert not {m for m in imports(path) if m.startswith("fenics_nl.io")}, path.name
    assert not {m for m in imports(root / "io" / "parameters.py") if ".cli" in m}
    assert imports(root / "io" / "flags.py") <= {"fenics_nl.vocabulary",
                                                 "fenics_nl.vocabulary.canonical"}


def test_no_two_subpackages_import_each_other():
    # the layout's directions (docs/architecture.md): a subpackage that imports another is
    # never imported back by it, function-level imports included
    import ast
    from pathlib import Path

    root = Path(__file__).resolve().parents[1] / "fenics_nl"
    packages = {p.name for p in root.iterdir() if (p / "__init__.py").exists()}
    uses = {name: set() for name in packages}
    for name in packages:
        for path in (root / name).rglob("*.py"):
            for node in ast.walk(ast.parse(path.read_text())):
                module = (node.module if isinstance(node, ast.ImportFrom) else None) or ""
                names = [module] if module else (
                    [a.name for a in node.names] if isinstance(node, ast.Import) else [])
                for m in names:
                    parts = m.split(".")
                    if parts[0] == "fenics_nl" and len(parts) > 1 and parts[1] in packages:
                        uses[name].add(parts[1])
    assert "scenes" not in packages
    both = {tuple(sorted((a, b))) for a in uses for b in uses[a] if b != a and a in uses[b]}
    assert not both, both
