# Set-up and everyday commands. Each target creates .venv itself on a fresh machine.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test quick lint docs bench clean

DEMO_STAMP := $(VENV)/.installed-demo

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

# the tests: gyrocomp with every extra the suite reads
$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(STAMP)

# the demo needs only gyrocomp and matplotlib (its figures and report)
$(DEMO_STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[plot]'
	touch $(DEMO_STAMP)

demo: $(DEMO_STAMP)
	$(BIN)/gyrocomp demo -o demo-output
	@echo "gyrocomp is installed in $(VENV)/bin: run it as $(BIN)/gyrocomp, or after 'source $(BIN)/activate' as gyrocomp"

# gyrocomp's modules byte-compiled first: where PYTHONDONTWRITEBYTECODE is set (as on our machines) each of the
# suite's few hundred command-line runs would otherwise compile them anew (0.15 s a start)
COMPILE := $(BIN)/python -m compileall -q src

# two processes (pytest-xdist), each test file in one of them (its module fixtures built once)
test: $(STAMP)
	$(COMPILE)
	$(BIN)/python -m pytest -q -n 2 --dist loadfile

# the quick loop: the same without the tests marked slow (about 5 s or more each, or a slow fixture)
quick: $(STAMP)
	$(COMPILE)
	$(BIN)/python -m pytest -q -n 2 --dist loadfile -m "not slow"

# the linter and the formatter's check (ruff: pyflakes, pycodestyle, bugbear; pyproject.toml's [tool.ruff])
lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks tools examples
	$(BIN)/ruff format --check src tests benchmarks tools examples

# the documentation site (MkDocs, Material, mkdocstrings) into site/, warnings as errors
docs: $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[docs]'
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --quiet

bench: $(STAMP)
	$(BIN)/pip install -q -e '.[bench]'
	$(BIN)/python benchmarks/bench_apply.py
	$(BIN)/python benchmarks/bench_allan.py
	$(BIN)/python benchmarks/bench_simulate.py
	$(BIN)/python benchmarks/bench_report.py
	$(BIN)/python benchmarks/bench_fit.py
	$(BIN)/python benchmarks/bench_startup.py
	$(BIN)/python benchmarks/bench_fleet.py
	$(BIN)/python benchmarks/bench_prior.py
	$(BIN)/python benchmarks/bench_learner.py
	$(BIN)/python benchmarks/bench_apply_stream.py --rows 3e7 --skip-whole

clean:
	rm -rf $(VENV) demo-output build site src/*.egg-info
