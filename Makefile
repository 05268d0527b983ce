# jaxbearing: every target creates .venv if missing and installs the project into it.
PYTHON ?= python3.11
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test test-slow lint format bench install clean

$(BIN)/python:
	@command -v $(PYTHON) >/dev/null 2>&1 || { echo "error: $(PYTHON) not found (set PYTHON=...)"; exit 1; }
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

# two test processes (one per core of the 2-core CI machine), a whole file per process so that
# module fixtures and compiled programs are built once per file
test: $(STAMP) lint
	MPLBACKEND=Agg $(BIN)/python -m pytest -q -n 2 --dist loadfile

test-slow: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -q -m slow

bench: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python benchmarks/run_all.py

clean:
	rm -rf $(VENV) build *.egg-info
