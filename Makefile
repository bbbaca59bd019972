# Two commands do everything on a fresh machine (see README):
#   make run   - create .venv, install, start the studio on the container crane (its simulated plant
#                ready in the curve recorder) and print its URL (with the token it requires)
#   make test  - create .venv, install dev extras and system packages, run ruff, mypy, pytest
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
# pyfuzzylite, scikit-fuzzy and simpful pin numpy < 2: the tests and benchmarks drive them in a
# venv of their own, never in .venv (which has the numpy users get)
PEERS  := .venv-peers

.PHONY: run simulate docs docs-img studio-img test fuzz lint typecheck pytest system-deps clean
STUDIO_PORT ?= 8770

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip

$(VENV)/.installed: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install -q -e .
	touch $@

$(VENV)/.installed-dev: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install -q -e '.[dev]'
	touch $@ $(VENV)/.installed

$(PEERS)/.installed: tests/peers/requirements.txt
	$(PYTHON) -m venv $(PEERS)
	$(PEERS)/bin/python -m pip install -q -r tests/peers/requirements.txt
	touch $@

system-deps:
	@bash scripts/system-deps.sh

run: $(VENV)/.installed
	@echo "crane demo: open the URL printed below (the curve recorder; it holds the studio's token) and press Start (simulated process)"
	$(BIN)/fuzzyctl studio examples/crane.fcl --port $(STUDIO_PORT) --view recorder

# The crane demo without a browser: CSV, PNG and HTML in build/sim.
simulate: $(VENV)/.installed
	$(BIN)/fuzzyctl simulate examples/crane.toml --out-dir build/sim

# The plot in the README: generated from the crane example, never drawn by hand.
docs-img: $(VENV)/.installed
	$(BIN)/fuzzyctl simulate examples/crane.toml --png docs/img/crane.png --no-csv --no-html

# The screenshots of docs/studio.md: taken by the studio's browser tests (1400x900, headless
# Debian chromium), written to docs/img/studio/ as well as test-artifacts/studio/.
studio-img: $(VENV)/.installed-dev system-deps
	FUZZYCTL_STUDIO_DOCS=1 $(BIN)/pytest -q tests/studio -k browser

lint: $(VENV)/.installed-dev
	$(BIN)/ruff check src tests benchmarks

typecheck: $(VENV)/.installed-dev
	$(BIN)/mypy

# both cores (pytest-xdist); the last line says which extra suites (tests/extras.py) ran
pytest: $(VENV)/.installed-dev $(PEERS)/.installed system-deps
	$(BIN)/pytest -n auto $(PYTEST_ARGS)

test: lint typecheck pytest

# Property tests with fresh random examples (make test replays a fixed set), then the mutation
# and differential fuzzer (issues 14.5, 25.2) on FUZZ_MUTANTS mutants of the examples, the vendored
# files and, when ../shared is there, the real-world corpus, then FUZZ_SYSTEMS random systems:
# every backend, explain, the CLI and generated C against the reference interpreter (make test
# runs a fixed sample of 80 + 16). A failure prints a one-line replay command.
FUZZ_MUTANTS ?= 3000
FUZZ_SYSTEMS ?= 300
FUZZ_SEED ?= $(shell date +%s)
fuzz: $(VENV)/.installed-dev $(PEERS)/.installed system-deps
	HYPOTHESIS_PROFILE=fuzz $(BIN)/pytest -q $$(grep -rl '@given' tests)
	$(BIN)/python -m tests.fuzz.campaign --mutants $(FUZZ_MUTANTS) --systems $(FUZZ_SYSTEMS) --seed $(FUZZ_SEED) \
		$$($(BIN)/python -c 'import tests.extras as e; print("--corpus" if e.suite("corpus").available else "")' 2>/dev/null) \
		--save build/fuzz-failures

clean:
	rm -rf $(VENV) $(PEERS) .pytest_cache .mypy_cache .ruff_cache

# The API reference (docstrings, mkdocstrings) with docs/*.md as its guide pages, in build/site;
# strict: a broken link or cross-reference fails (tests/test_api_docs.py builds it too).
docs: $(VENV)/.installed-dev
	$(BIN)/python -m mkdocs build --strict
