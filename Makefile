# Two commands on a fresh machine: `make demo` and `make test` (and `make docs` for the site).
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
# pytest-xdist workers; 2 cores on CI
WORKERS ?= auto

.PHONY: demo test bench docs venv clean browser mujoco

# Packages are installed with uv where uv itself installs (the test extras in about 16 s on 2 cores, where pip
# takes 85 s), with pip otherwise; neither compiles every installed module's bytecode up front (half of pip's
# time: Python compiles what is imported, once)
INSTALL = install() { $(BIN)/python -m uv pip install --quiet --python $(BIN)/python "$$@" || \
	$(BIN)/python -m pip install --quiet --no-compile "$$@"; }; install

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	@$(BIN)/python -m pip install --quiet uv || echo "uv is not available here: installing with pip"

$(VENV)/.installed-all: pyproject.toml | $(BIN)/python
	$(INSTALL) -e '.[all]'
	@touch $@

$(VENV)/.installed-test: pyproject.toml | $(BIN)/python
	$(INSTALL) -e '.[test]'
	@touch $@ $(VENV)/.installed-all $(VENV)/.installed-docs

$(VENV)/.installed-docs: pyproject.toml | $(BIN)/python
	$(INSTALL) -e '.[docs]'
	@touch $@ $(VENV)/.installed-all

venv: $(VENV)/.installed-test

# the warm-up compiles every numba kernel into its on-disk cache once (under a minute on two cores the first
# time, seconds after): later runs start without compiling (issue 15, cold start)
demo: $(VENV)/.installed-all
	$(BIN)/eulerpoisson warmup
	$(BIN)/eulerpoisson demo --out out

# Chromium for the animation's browser test: installed where possible (Debian, as root),
# otherwise that one test is skipped with its reason.
browser:
	@command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1 || \
	  ( [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1 && \
	    timeout 300 sh -c 'apt-get update -qq >/dev/null 2>&1; DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends chromium >/dev/null 2>&1' && \
	    echo "installed chromium for the browser test" ) || \
	  echo "chromium is not available: the browser test will be skipped"

# MuJoCo and PyBullet for the oracle's engine tests (tests/test_oracle_mujoco.py, the reduced conformance report
# of tests/test_conformance.py): installed where possible (wheels only), otherwise those tests are skipped with their reason.
mujoco: $(VENV)/.installed-test
	@$(BIN)/python -c "import mujoco" >/dev/null 2>&1 || \
	  ( timeout 300 sh -c '$(INSTALL) mujoco' >/dev/null 2>&1 && \
	    echo "installed mujoco for the oracle test" ) || \
	  echo "mujoco is not available: the MuJoCo oracle test will be skipped"
	@$(BIN)/python -c "import pybullet" >/dev/null 2>&1 || \
	  ( timeout 300 sh -c '$(INSTALL) --only-binary :all: pybullet' >/dev/null 2>&1 && \
	    echo "installed pybullet for the conformance test" ) || \
	  echo "pybullet is not available: its conformance tests will be skipped"

# the numba kernels are compiled once, two groups at a time, before the tests (which then load them from the cache
# instead of compiling the same kernels in each pytest-xdist worker); Chromium (mostly a download: about 30 s) is
# installed meanwhile from the start, MuJoCo and PyBullet during the warm-up
test:
	@$(MAKE) --no-print-directory browser & \
	$(MAKE) --no-print-directory $(VENV)/.installed-test && \
	{ $(MAKE) --no-print-directory mujoco & $(BIN)/eulerpoisson warmup; }; \
	status=$$?; wait; exit $$status
	$(BIN)/python -m pytest -n $(WORKERS) --dist loadgroup -q

# optional peers of the benchmark (heyoka, MuJoCo): installed where possible, skipped otherwise
$(VENV)/.installed-peers: | $(VENV)/.installed-test
	-$(INSTALL) heyoka mujoco || echo "optional benchmark peers unavailable"
	@touch $@

bench: $(VENV)/.installed-test $(VENV)/.installed-peers
	$(BIN)/python benchmarks/run.py

# the conformance report (issue 23): the physics engines of the report installed from the package index where
# they can be (best effort, like the peers of `make bench`; one that does not install is a row saying why) into
# their own environment, out/engines-venv (some pin packages the project also uses), then
# `eulerpoisson conformance` over all of them: the table and the figures into docs/user_guide/conformance/,
# the cells into out/conformance-cells (a rerun skips the cells done; under 30 minutes on two cores)
ENGINES_VENV := out/engines-venv
CONFORMANCE_ENGINES ?= mujoco mujoco-mjx pybullet drake dartpy bsk newton sapien genesis-world
.PHONY: conformance
conformance: | $(BIN)/python
	@test -x $(ENGINES_VENV)/bin/python || $(BIN)/python -m venv $(ENGINES_VENV)
	$(ENGINES_VENV)/bin/python -m pip install --quiet -e '.[plot]'
	@for p in $(CONFORMANCE_ENGINES); do \
	  timeout 300 $(ENGINES_VENV)/bin/python -m pip install --quiet --only-binary :all: $$p >/dev/null 2>&1 && \
	    echo "installed $$p for the conformance report" || \
	    echo "$$p is not available: the report says why"; \
	done
	MPLBACKEND=Agg $(ENGINES_VENV)/bin/eulerpoisson conformance --jobs 2 --out docs/user_guide/conformance \
	  --cells out/conformance-cells

# the release check (issue 22): python -m build (an sdist and a wheel, LICENSE in both), the wheel installed
# into a fresh virtual environment, away from the source tree, running eulerpoisson --version, warmup, demo
# and the README's tour (tests/test_release.py). Minutes, and the package index: not part of make test.
.PHONY: release-check
release-check: $(VENV)/.installed-test
	EULERPOISSON_RELEASE_CHECK=1 $(BIN)/python -m pytest -n 0 -q -p no:cacheprovider tests/test_release.py

# the documentation site into docs/_build/html: Sphinx, warnings and broken references are errors; runs the
# gallery (examples/) and the paper's audit (SPHINXOPTS="-D plot_gallery=0 -D eulerpoisson_run_audit=0" skips both)
SPHINXOPTS ?=
docs: $(VENV)/.installed-docs
	MPLBACKEND=Agg $(BIN)/python -m sphinx -b html -n -W --keep-going $(SPHINXOPTS) docs docs/_build/html
	@echo "open docs/_build/html/index.html"

clean:
	rm -rf $(VENV) out .pytest_cache .hypothesis docs/_build docs/auto_examples docs/api/generated \
	  docs/api/eulerpoisson*.rst docs/api/modules.rst.inc docs/theory/audit_report.md
