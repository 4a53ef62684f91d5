# Two commands for a fresh machine:
#   make demo   set up .venv and run the headline scenario
#   make test   set up .venv and run the tests (what CI runs)
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
export MUJOCO_GL ?= egl

.PHONY: setup demo test test-fast test-render test-e2e regress bench figures docs clean

$(BIN)/headsim: pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e '.[test,batch,ros]'
	@touch $@

setup: $(BIN)/headsim

demo: setup
	$(BIN)/headsim run quickstart --out out/quickstart --rrd out/quickstart/recording.rrd
	@echo "open the recording with: $(BIN)/rerun out/quickstart/recording.rrd"

test: setup
	$(BIN)/ruff check headsim tests benchmarks tools
	$(BIN)/ruff format --check headsim tests benchmarks tools
	$(BIN)/mypy
	$(BIN)/python -m pytest -q -n auto

# The suite's tiers (pytest markers, assigned in tests/conftest.py; README "Tests" gives
# their times): fast (pure math, estimators, scenario checks; under a minute), render
# (components with real MuJoCo renders), e2e (the command line, procedures, studies, docs).
test-fast: setup
	$(BIN)/python -m pytest -q -n auto -m fast

test-render: setup
	$(BIN)/python -m pytest -q -n auto -m render

test-e2e: setup
	$(BIN)/python -m pytest -q -n auto -m e2e

# The regression suite CI runs after the tests: exits 1 on a regression.
regress: setup
	$(BIN)/headsim bench

# Every figure block of the documentation (docs/results.md, docs/findings.md) regenerated and checked (about 20 minutes; CI checks
# all but the longest): after an intended change, `python tools/readme_figures.py --write`.
figures: setup
	$(BIN)/python tools/readme_figures.py

# Every benchmark is a case of `headsim bench` (`headsim bench --list`): the regression
# cases, then every figures case of minutes (not run by CI). A long one runs by name:
# `headsim bench --case reach_and_zoom -- --targets 50`.
bench: setup
	$(BIN)/headsim bench --all

# The documentation site in out/site, warnings as errors (a broken link fails); the
# reference pages are made from the code at build time (tools/docs_pages.py).
docs: setup
	@$(BIN)/python -c "import mkdocs, material, mkdocstrings_handlers.python" 2>/dev/null \
		|| $(BIN)/pip install -q -e '.[docs]'
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict

clean:
	rm -rf $(VENV) out
