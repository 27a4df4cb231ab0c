# Tasks of the project, run with the venv .ci/run makes (.venv; `make VENV=/path/to/venv …` for
# another). A missing venv is made first, with the test and bench extras and the linters.
# The test server: as for pytest itself (see CONTRIBUTING.md); the benchmarks and the golden
# files take DATABASE_URL (admin URL), else the server on 127.0.0.1:5432.
VENV ?= .venv
PYTHON ?= $(VENV)/bin/python
PYTEST = $(PYTHON) -m pytest -q -p no:cacheprovider $(WORKERS)
WORKERS ?= -n 2 --dist worksteal   # pytest-xdist, as .ci/run; `make test WORKERS=` for one process
unexport PYTHONDONTWRITEBYTECODE   # the suite's workers reuse the compiled engine and rewritten tests (.ci/run)
BENCHMARKS = $(filter-out bench/_common.py bench/smoke.py,$(sort $(wildcard bench/*.py)))

.PHONY: test test-fast lint typecheck golden docs bench bench-smoke

test: | $(PYTHON)           ## the whole suite, as each leg of .ci/run runs it
	$(PYTEST)

test-fast: | $(PYTHON)      ## the suite without the tests marked slow
	$(PYTEST) -m "not slow"

lint: | $(PYTHON)
	$(PYTHON) -m ruff check .

typecheck: | $(PYTHON)
	$(PYTHON) -m mypy

golden: | $(PYTHON)         ## write tests/golden/ again; read the diff before committing it
	$(PYTHON) tests/golden/make_golden.py

docs: | $(PYTHON)           ## docs/cli.md from the commands' --help
	$(PYTHON) scripts/cli_reference.py

bench: | $(PYTHON)          ## every benchmark at its full size, one after the other (tens of minutes)
	@set -e; for script in $(BENCHMARKS); do echo "== $$script"; $(PYTHON) $$script; done

bench-smoke: | $(PYTHON)    ## every benchmark once at small sizes, figures not judged (as .ci/run)
	$(PYTHON) bench/smoke.py

$(PYTHON):
	python3 -m venv $(VENV)
	$(PYTHON) -m pip install --quiet --upgrade pip
	$(PYTHON) -m pip install --quiet -e '.[test,dev,bench]'
