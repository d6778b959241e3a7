"""Sphinx configuration of meshcurv's user guide and API reference (``make docs`` builds it into docs/_build/html)."""

import re

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
suppress_warnings = ["myst.xref_missing"]  # links to files of the repository (benchmarks/...), not to pages
html_theme = "alabaster"
# wide enough for the examples' lines (up to 110 characters) without a scroll bar
html_theme_options = {
    "page_width": "1320px",
    "sidebar_width": "230px",
    "body_max_width": "none",
    "code_font_size": "0.85em",
}


def _readme_links(app, relative_path, parent_docname, content):
    """The README's links into the guide (``docs/guide/x.md``) made relative to docs/readme.md."""
    if parent_docname == "readme":
        content[0] = re.sub(r"\]\(docs/(guide/[\w.-]+\.md)", r"](\1", content[0])


def setup(app):
    app.connect("include-read", _readme_links)
