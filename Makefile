# `make demo`, `make test`, `make bench`: each creates .venv when it is missing.
SHELL := /bin/bash
VENV := .venv
PY := $(VENV)/bin/python
MPIEXEC := $(VENV)/bin/mpiexec
# Python >= 3.12 from pyenv (the dolfinx wheel needs it); PYTHON=... overrides.
PYTHON ?= $(firstword $(wildcard $(shell pyenv root 2>/dev/null)/versions/3.1[2-9]*/bin/python3) \
	$(wildcard $(HOME)/.pyenv/versions/3.1[2-9]*/bin/python3) $(shell command -v python3.12))

.PHONY: demo test test-serial test-mpi docs docs-check bench bench-large lint clean

# Python keeps the bytecode it compiles (in __pycache__, git-ignored) even where the
# environment says not to: every test's notebook kernel, mpiexec rank and worker imports
# dolfinx, UFL and matplotlib, 5.0 s from source against 1.4 s from bytecode (measured)
export PYTHONDONTWRITEBYTECODE :=

# uv installs the pinned packages in 7-15 s where pip takes 40 (the same versions); pip is the
# fallback if uv cannot be installed or cannot install (PIP_FIND_LINKS is passed on to uv)
UV := uv==0.13.9
define install
$(VENV)/bin/uv pip install --quiet --python $(PY) $(foreach l,$(PIP_FIND_LINKS),--find-links $(l)) $(1) \
	  || $(PY) -m pip install --quiet $(1)
endef

# the PyPI wheel of DOLFINx (the package itself runs on any DOLFINx 0.11) and the tests
# tools; a variable, since a comma would split make's `call`
EXTRAS := wheel,test
$(VENV)/.installed: pyproject.toml
	@if [ -z "$(PYTHON)" ]; then \
	  echo "error: no Python >= 3.12 found; install one (e.g. 'pyenv install 3.12') or run 'make PYTHON=/path/to/python3.12'"; exit 1; fi
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	-$(PY) -m pip install --quiet $(UV)
	$(call install,-e ".[$(EXTRAS)]")
	@# `import dolfinx` first works in this venv too (see the file)
	cp fenics_nl/_import_order.pth "$$($(PY) -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')/fenics_nl_import_order.pth"
	@touch $@

# the documentation's extra: Sphinx, MyST-NB, the theme, MathJax's files, Playwright
# (the extra's requirements only: the package itself is installed already)
$(VENV)/.docs-installed: $(VENV)/.installed
	$(call install,$$($(PY) -c "import tomllib; print(' '.join(tomllib.load( \
	  open('pyproject.toml', 'rb'))['project']['optional-dependencies']['docs']))"))
	@touch $@

# the benchmarks' extra and the peers, with --no-deps (see pyproject.toml's bench extra):
# the J2 peer and the phase-field peer (it declares nothing; it needs pandas, in the extra)
PEER := dolfinx-external-operator==0.11.0 phasefieldx==0.4.1
# the two-body contact peer (benchmarks/ngsolve_pair.py) in a venv of its own: NGSolve
# brings its own OpenBLAS and OpenCASCADE, kept apart from PETSc's and gmsh's; it runs in
# its own process anyway (benchmarks/contact_pair.py finds it by NGSOLVE_PYTHON)
NGSOLVE := .venv-ngsolve/bin/python
$(NGSOLVE):
	$(PY) -m venv .venv-ngsolve
	.venv-ngsolve/bin/python -m pip install --quiet ngsolve==6.2.2608

$(VENV)/.bench-installed: $(VENV)/.installed $(NGSOLVE)
	$(call install,-e ".[bench]")
	$(call install,--no-deps $(PEER))
	@touch $@

# the three scenes at small sizes, the snap-through and the scalar demo, pictures and JSON
# in results/
# (about 2 min on 2 cores; the bracket runs on 2 ranks)
demo: $(VENV)/.installed
	@mkdir -p results
	$(PY) demos/punch.py --steps 4 --png results/punch.png --plot results/punch_curves.png \
	  --json results/punch.json
	$(PY) demos/punch_friction.py --png results/punch_friction.png \
	  --plot results/punch_friction_curves.png --json results/punch_friction.json
	$(PY) demos/indentation.py --png results/indentation_section.png \
	  --plot results/indentation.png --json results/indentation.json
	$(PY) demos/buckling_beam.py --load-ratio 2 --png results/beam.png \
	  --plot results/beam_path.png --json results/beam.json
	$(MPIEXEC) -n 2 $(PY) demos/bracket.py --support contact --size 8 --png results/bracket.png \
	  --plot results/bracket_curve.png --json results/bracket.json
	$(PY) demos/newton_scalar.py --plot results/newton_orders.png --json results/newton.json \
	  > results/newton_scalar.txt
	$(PY) demos/snap_through.py --plot results/snap_through.png --png results/snap_shapes.png \
	  --json results/snap_through.json
	$(PY) demos/crack.py --plot results/crack.png --json results/crack.json
	$(PY) demos/upsetting.py --friction 0.3 --cells 8 --png results/upsetting.png \
	  --plot results/upsetting_force.png --json results/upsetting.json
	$(PY) -m fenics_nl run cases/thick_cylinder.toml --png results/thick_cylinder.png \
	  --json results/thick_cylinder.json
	@echo "make demo: pictures (*.png) and results (*.json) in $(CURDIR)/results/"

test: test-serial test-mpi

# one BLAS thread per process: the tests run two processes (xdist workers or MPI ranks) on
# two cores, and OpenBLAS's own threads (MUMPS's dense kernels) would fight them for the
# cores: the serial suite 5:14 -> 4:41 on 2 cores
test-serial test-mpi: export OPENBLAS_NUM_THREADS = 1
test-serial test-mpi: export OMP_NUM_THREADS = 1

# the serial suite on both cores (pytest-xdist), then the tests that start mpiexec
# themselves, alone (their ranks need the cores), then the mpi suite under mpiexec
test-serial: $(VENV)/.installed
	$(PY) -m pytest -m "not mpi and not spawns_mpi" -q -n 2 --dist worksteal --durations=25
	$(PY) -m pytest -m "spawns_mpi" -q --durations=10

test-mpi: $(VENV)/.installed
	$(MPIEXEC) -n 2 $(PY) -m pytest -m mpi -q -p no:cacheprovider

# every benchmark at sizes for 2 cores (about 85 min), results in benchmarks/results/, the
# README tables and the "which method when" reading regenerated from them;
# `make bench QUICK=1`: small meshes, a smoke run that writes nothing (about 1 min);
# `make bench-large`: the bracket at 234k, 300k (1 vs 2 ranks) and ~1M unknowns (about 75 min),
# and every capability on the iterative path at ~1M (about an hour more)
BENCHMARKS := newton contact contact_pair buckling bracket iterative arch_iterative plasticity sphere_ranks \
	plasticity_peer mixed secant \
	friction continuation newtonal damage damage_peer identification forming creep slope soil_3d
bench: $(VENV)/.bench-installed
	@for b in $(BENCHMARKS); do echo "== benchmarks/$$b.py"; \
	  NGSOLVE_PYTHON=$(NGSOLVE) $(PY) benchmarks/$$b.py $(if $(QUICK),--quick,--update-docs) \
	  || exit 1; done
	$(if $(QUICK),,$(PY) benchmarks/reading.py --update-docs)

bench-large: $(VENV)/.installed
	$(PY) benchmarks/bracket.py --large --update-docs
	$(PY) benchmarks/iterative.py --large --update-docs
	$(PY) benchmarks/reading.py --update-docs

# the site in docs/_build/html (open index.html): every demo executed as a notebook first
# (docs/notebooks.py, ~20 s), then Sphinx, warnings as errors; no network needed
docs: $(VENV)/.docs-installed
	$(PY) docs/notebooks.py
	$(PY) -m sphinx -b html -q -W --keep-going -j 2 docs docs/_build/html
	@echo "make docs: open $(CURDIR)/docs/_build/html/index.html"

# every page of the built site in headless Chromium (Debian's package chromium): failed
# requests, images that do not load, formulas not typeset, broken links; screenshots of the
# landing page and a demo page in docs/screenshots/
docs-check: docs
	$(PY) docs/check.py

lint: $(VENV)/.installed
	$(VENV)/bin/ruff check .

clean:
	rm -rf $(VENV) .venv-ngsolve *.egg-info results docs/_build docs/demos docs/screenshots
