# make demo: the seed's torus example (curvatures, a picture, a summary)
# make test: the test suite
# Both create a local virtual environment (.venv) on first use.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test quick test-minimal lint docs bench-accuracy bench-speed clean

$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else "meshcurv needs Python 3.11 or newer: make PYTHON=python3.11 ...")'
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e '.[all,batch,test]'
	@touch $(STAMP)

demo: $(STAMP)
	$(BIN)/meshcurv demo --overwrite demo-output/torus_gaussian.png

test: $(STAMP)
	$(BIN)/python -m pytest

# the suite without the tests marked slow (under a minute or two on 2 cores)
quick: $(STAMP)
	$(BIN)/python -m pytest -q -m "not slow"

# the suite on a plain install without its extras (no matplotlib, pyvista, dask, scikit-image, ...),
# numba then removed: what needs an extra is skipped, and the NumPy backend (the reference) runs
test-minimal:
	$(PYTHON) -m venv .venv-minimal
	.venv-minimal/bin/python -m pip install --quiet --disable-pip-version-check -e '.[test]'
	.venv-minimal/bin/python -m pip uninstall --quiet --yes numba llvmlite
	.venv-minimal/bin/python -m pytest -q -m "not slow"

# the API reference from the docstrings, with the README (docs/_build/html/index.html); warnings are errors
docs: $(STAMP)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e '.[docs]'
	$(BIN)/python -m sphinx -W --keep-going -b html -q docs docs/_build/html

# ruff, then mypy on src/meshcurv ([tool.mypy] in pyproject.toml)
lint: $(STAMP)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check 'ruff>=0.6' 'mypy>=1.10'
	$(BIN)/ruff check src tests benchmarks conftest.py
	$(BIN)/mypy

bench-accuracy: $(STAMP)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e '.[bench]'
	$(BIN)/python benchmarks/accuracy.py

clean:
	rm -rf $(VENV) .venv-minimal demo-output docs/_build docs/api
