"""Sphinx configuration of meshcurv's reference (``make docs`` builds it into docs/_build/html)."""

import meshcurv

project = "meshcurv"
author = "the meshcurv developers"
copyright = "2026, the meshcurv developers"
release = version = meshcurv.__version__

extensions = ["sphinx.ext.autodoc", "sphinx.ext.autosummary", "numpydoc", "myst_parser"]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build"]
autosummary_generate = True
autodoc_typehints = "none"  # the numpydoc sections give the types
numpydoc_show_class_members = False
numpydoc_validation_checks = set()
myst_heading_anchors = 3
suppress_warnings = ["myst.xref_missing"]  # README links to files of the repository, not to pages
html_theme = "alabaster"
