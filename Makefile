# make demo: the torus example (its curvatures against the exact ones, a picture, a summary)
# make test: the test suite
# Both create a local virtual environment (.venv) on first use, each installing what it needs:
# the demo meshcurv and matplotlib, the tests every optional part and the test tools.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
PIP := $(BIN)/python -m pip --disable-pip-version-check
# each installs its own part into the one environment, so that `make demo` then `make test` (or the
# other way round) both work
STAMP := $(VENV)/.installed
DEMO_STAMP := $(VENV)/.installed-demo

.PHONY: demo test quick test-minimal lint docs pictures package-check bench-accuracy clean

$(BIN)/python:
	@$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else "meshcurv needs Python 3.11 or newer: make PYTHON=python3.11 ...")'
	$(PYTHON) -m venv $(VENV)

# pip's progress stays visible: the environment weighs 550 MB after make demo, 1.6 GB after make test
$(DEMO_STAMP): pyproject.toml | $(BIN)/python
	@echo "make demo: installing meshcurv and matplotlib into $(VENV) (about 550 MB, once)"
	$(PIP) install --progress-bar on -e '.[plot]'
	@touch $(DEMO_STAMP)

$(STAMP): pyproject.toml | $(BIN)/python
	@echo "make test: installing meshcurv, its optional parts and the test tools into $(VENV) (1.6 GB in all, once)"
	$(PIP) install --progress-bar on -e '.[all,batch,test]'
	@touch $(STAMP)

demo: $(DEMO_STAMP)
	$(BIN)/meshcurv demo --overwrite demo-output/torus_gaussian.png

test: $(STAMP)
	$(BIN)/python -m pytest

# the suite without the tests marked slow (3 minutes on 2 cores, kernels cached)
quick: $(STAMP)
	$(BIN)/python -m pytest -q -m "not slow"

# the suite on a plain install without its extras (no matplotlib, pyvista, dask, scikit-image, ...),
# numba then removed: what needs an extra is skipped, and the NumPy backend (the reference) runs
MINIMAL := .venv-minimal
$(MINIMAL)/.installed: pyproject.toml
	$(PYTHON) -m venv $(MINIMAL)
	$(MINIMAL)/bin/python -m pip install --quiet --disable-pip-version-check -e '.[test]'
	$(MINIMAL)/bin/python -m pip uninstall --quiet --yes numba llvmlite
	@touch $@

test-minimal: $(MINIMAL)/.installed
	$(MINIMAL)/bin/python -m pytest -q -m "not slow"

# the user guide (docs/guide) and the API reference (docs/_build/html/index.html); warnings are errors
docs: $(STAMP)
	$(PIP) install --quiet -e '.[docs]'
	$(BIN)/python -m sphinx -W --keep-going -b html -q docs docs/_build/html

# the pictures of the user guide, made with meshcurv's own plotting (docs/make_pictures.py)
pictures: $(STAMP)
	$(BIN)/python docs/make_pictures.py
	$(BIN)/python docs/cells_example.py

# the packages as users get them: wheel and sdist built and checked (twine), the wheel installed in a
# clean environment (not editable) and run on a mesh of the repository, then the README's install
# from the clone (pip install .) in another clean environment
PKG := .venv-package
package-check: $(STAMP)
	rm -rf dist $(PKG) $(PKG)-clone
	$(BIN)/python -m pip install build twine --quiet --disable-pip-version-check
	$(BIN)/python -m build --outdir dist .
	$(BIN)/python -m twine check --strict dist/*
	$(PYTHON) -m venv $(PKG)
	$(PKG)/bin/python -m pip install dist/meshcurv-*.whl --disable-pip-version-check
	cd /tmp && $(CURDIR)/$(PKG)/bin/meshcurv --version
	cd /tmp && $(CURDIR)/$(PKG)/bin/meshcurv compute $(CURDIR)/tests/data/matgeom/spot.npz
	$(PYTHON) -m venv $(PKG)-clone
	$(PKG)-clone/bin/python -m pip install . --quiet --disable-pip-version-check
	cd /tmp && $(CURDIR)/$(PKG)-clone/bin/meshcurv --version
	rm -rf $(PKG) $(PKG)-clone

# ruff check and format (the files written before it excepted: [tool.ruff.format]), mypy on src/meshcurv
# ([tool.mypy]), numpydoc's validation of the public API ([tool.numpydoc_validation], tests/test_docstrings.py)
lint: $(STAMP)
	$(PIP) install --quiet 'ruff>=0.6' 'mypy>=1.10' 'numpydoc>=1.6'
	$(BIN)/ruff check src tests benchmarks conftest.py docs
	$(BIN)/ruff format --check --force-exclude src tests benchmarks conftest.py
	$(BIN)/mypy
	$(BIN)/python -m pytest -q -p no:randomly tests/test_docstrings.py

bench-accuracy: $(STAMP)
	$(PIP) install --quiet -e '.[bench]'
	$(BIN)/python benchmarks/accuracy.py

clean:
	rm -rf $(VENV) .venv-minimal .venv-package .venv-package-clone dist demo-output docs/_build docs/api
