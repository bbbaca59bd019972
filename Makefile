# Two commands do everything on a fresh machine (see README):
#   make run   - create .venv, install, simulate the container crane demo (CSV, PNG, HTML in build/sim)
#   make test  - create .venv, install dev extras and system packages, run ruff, mypy, pytest
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin

.PHONY: run docs-img test fuzz lint typecheck pytest system-deps clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip

$(VENV)/.installed: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install -q -e .
	touch $@

$(VENV)/.installed-dev: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install -q -e '.[dev]'
	touch $@ $(VENV)/.installed

system-deps:
	@bash scripts/system-deps.sh

run: $(VENV)/.installed
	$(BIN)/fuzzyctl simulate examples/crane.toml --out-dir build/sim

# The plot in the README: generated from the crane example, never drawn by hand.
docs-img: $(VENV)/.installed
	$(BIN)/fuzzyctl simulate examples/crane.toml --png docs/img/crane.png --no-csv --no-html

lint: $(VENV)/.installed-dev
	$(BIN)/ruff check src tests benchmarks

typecheck: $(VENV)/.installed-dev
	$(BIN)/mypy

pytest: $(VENV)/.installed-dev system-deps
	$(BIN)/pytest

test: lint typecheck pytest

# Property tests with fresh random examples (make test replays a fixed set).
fuzz: $(VENV)/.installed-dev system-deps
	HYPOTHESIS_PROFILE=fuzz $(BIN)/pytest -q $$(grep -rl '@given' tests)

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache
