# robodyn: set-up, demo, tests and benchmarks.  `make demo` and `make test` are all you need.

PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
# test processes (pytest-xdist): one per core, at most 4 (each may hold ~1 GB); JOBS=1 runs serially
JOBS   ?= $(shell $(PYTHON) -c 'import os; print(max(1, min(4, len(os.sched_getaffinity(0)))))' 2>/dev/null || echo 1)
PYTEST := $(BIN)/pytest -q -n $(JOBS) --dist loadfile

.PHONY: venv demo test quick bench clean distclean

## venv: create .venv and install robodyn (editable) with its test tools; reruns are instant
venv: $(STAMP)

$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; sys.exit(sys.version_info < (3, 11))' || { \
	    echo "robodyn needs Python 3.11 or newer; $(PYTHON) is $$($(PYTHON) --version 2>&1)." \
	         "Run e.g. 'make PYTHON=python3.12 demo'."; exit 1; }
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $(STAMP)

## demo: PUMA 560 three ways; equations, comparison and report in out/ (open out/report.html)
demo: $(STAMP)
	$(BIN)/robodyn demo -o out
	@echo "next: open out/report.html; run robodyn as $(BIN)/robodyn --help" \
	      "(or '. $(BIN)/activate' first, then plain 'robodyn'); sample input files in examples/"

## test: lint, then the test suite on JOBS processes, a test file per process at a time (tests
## needing a missing oracle/tool skip one by one and are counted at the end;
## ROBODYN_REQUIRE_ALL=1 make test turns those skips into failures, as in CI)
test: $(STAMP)
	$(BIN)/ruff check src tests benchmarks && $(PYTEST)

## quick: lint, then the suite without the tests marked slow (each over ~3 s: large models
## compiled, whole command-line workflows); the full `make test` is what CI runs
quick: $(STAMP)
	$(BIN)/ruff check src tests benchmarks && $(PYTEST) -m "not slow"

## bench: timing suites in benchmarks/; bench_kernels.py, bench_simulation.py and bench_hydro.py
## merge theirs into benchmarks/results/<machine>.json (CPU, flags, load, min/median of every
## figure), then README's marked sections are rendered from it
bench: $(STAMP)
	@set -e; for f in benchmarks/bench_*.py; do echo "== $$f"; $(BIN)/python $$f; done
	$(BIN)/python benchmarks/render_readme.py --results "$$($(BIN)/python benchmarks/results.py)"

## clean: remove generated files (keeps .venv)
clean:
	rm -rf out build dist .pytest_cache .ruff_cache src/*.egg-info
	find src tests benchmarks tools -name __pycache__ -type d -prune -exec rm -rf {} +

## distclean: clean, and remove .venv too
distclean: clean
	rm -rf $(VENV) benchmarks/.build
