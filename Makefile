# jaxbearing: every target creates .venv if missing and installs the project into it.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test test-slow lint format bench install clean docs notebooks figures

$(BIN)/python:
	@command -v $(PYTHON) >/dev/null 2>&1 || { echo "error: $(PYTHON) not found (set PYTHON=...)"; exit 1; }
	@$(PYTHON) -c 'import sys; sys.exit(sys.version_info < (3, 11))' || { echo "error: $(PYTHON) is Python $$($(PYTHON) -c 'import platform; print(platform.python_version())'); jaxbearing needs Python >= 3.11 (set PYTHON=python3.12, for example)"; exit 1; }
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip

$(STAMP): $(BIN)/python pyproject.toml
	$(BIN)/python -m pip install -q -e ".[test]"
	@touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	MPLBACKEND=Agg $(BIN)/jaxbearing demo

lint: $(STAMP)
	$(BIN)/ruff check jaxbearing optimise tests benchmarks
	$(BIN)/ruff format --check jaxbearing optimise tests benchmarks

format: $(STAMP)
	$(BIN)/ruff check --fix jaxbearing optimise tests benchmarks
	$(BIN)/ruff format jaxbearing optimise tests benchmarks

# two test processes (one per core of the 2-core CI machine), each taking whole groups of files
# (tests/conftest.py: a file, or files that compile the same programs) slowest first, so that
# module fixtures and compiled programs are built once
test: $(STAMP) lint
	MPLBACKEND=Agg $(BIN)/python -m pytest -q -n 2 --dist loadfile

test-slow: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -q -m slow

bench: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python benchmarks/run_all.py

# the documentation site: the tutorials executed (short setting) into build/notebooks, then
# mkdocs with --strict (a broken link or a missing reference fails); the site is build/site
DOCS_STAMP := $(VENV)/.installed-docs
$(DOCS_STAMP): $(STAMP)
	$(BIN)/python -m pip install -q -e ".[docs]"
	@touch $(DOCS_STAMP)

docs: $(DOCS_STAMP)
	$(BIN)/python docs/_execute_notebooks.py build/notebooks
	JAXBEARING_DOCS_NOTEBOOKS=build/notebooks $(BIN)/mkdocs build --strict
	@echo "site: build/site/index.html (or: $(BIN)/mkdocs serve)"

# every measured figure quoted on the user pages rewritten from its results file (docs/figures.toml);
# `python docs/_figures.py` without --write only checks them (tests/test_figures.py does too)
figures: $(STAMP)
	$(BIN)/python docs/_figures.py --write

# JupyterLab on the notebooks (the notebooks extra); set JAXBEARING_NOTEBOOK_SHORT=1 for the short setting
NOTEBOOKS_STAMP := $(VENV)/.installed-notebooks
$(NOTEBOOKS_STAMP): $(STAMP)
	$(BIN)/python -m pip install -q -e ".[notebooks]"
	@touch $(NOTEBOOKS_STAMP)

notebooks: $(NOTEBOOKS_STAMP)
	cd notebooks && ../$(BIN)/jupyter lab

clean:
	rm -rf $(VENV) build *.egg-info
