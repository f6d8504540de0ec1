# microcyl: `make report` and `make test` work from a fresh clone (Python >= 3.11).
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: test report fits bench docs clean

$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else "microcyl needs Python >= 3.11, found " + sys.version.split()[0])'
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

# the suite on every CPU this process may use, plus one (pytest-xdist; nproc, not -n auto,
# which counts the physical cores of the whole host): many tests wait on a subprocess, a
# browser or a Dask worker, and a third worker keeps both cores of a 2-core machine busy;
# --dist loadscope keeps a module's tests on one worker, so its module-scoped fixtures (a
# report, a batch of fits) are built once, not once a worker. On the 2-core machine: 18.4 min
# with -n 2 (load distribution), 14.4 min with -n 3 --dist loadscope (2026-12-07).
# `make test WORKERS=0` runs it in one process
WORKERS ?= $(shell echo $$(( $$(nproc 2>/dev/null || echo 2) + 1 )))
test: $(STAMP)
	$(PY) -m pytest -n $(WORKERS) $(if $(filter 0,$(WORKERS)),,--dist loadscope)

# the report includes the measured-data fits when `make fits` has made them
report: $(STAMP)
	$(VENV)/bin/microcyl report --engine auto $(if $(wildcard fits/measured.json),--measured fits)

# fits of the RGL felts and CUReT fabrics (about 17 min on 2 cores; resumable: run it again)
fits: $(STAMP)
	$(VENV)/bin/microcyl fit-measured -o fits

bench: $(STAMP)
	for f in bench/bench_*.py; do echo "== $$f"; $(PY) $$f || exit 1; done

# the documentation site, from a clean state, warnings as errors (about 3 min on 2 cores)
DOCS_STAMP := $(VENV)/.installed-docs
$(DOCS_STAMP): $(STAMP)
	$(PY) -m pip install --quiet -e '.[dev,docs]'
	touch $(DOCS_STAMP)

docs: $(DOCS_STAMP)
	rm -rf docs/_build docs/_generated docs/tutorials docs/gallery docs/sg_execution_times.rst
	$(PY) -m sphinx -b html -W --keep-going -q docs docs/_build/html

clean:
	rm -rf $(VENV) report .pytest_cache docs/_build docs/_generated docs/tutorials docs/gallery
