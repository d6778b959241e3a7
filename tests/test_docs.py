"""The user guide (docs/guide): its examples run, each page has a picture, Sphinx builds it without a warning."""

import doctest
import importlib.util
import pathlib
import re
import shutil
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
GUIDE = DOCS / "guide"
PAGES = sorted(GUIDE.glob("*.md"))

# the pages of the guide the README's list names (other pages may join through the toctree's glob)
NAMED = [
    "methods",
    "meshes",
    "label_images",
    "point_clouds",
    "integrals",
    "batch",
    "files",
    "cli",
    "speed",
    "matgeom",
    "development",
    "worked_example_cells",
    "label_statistics",
]

# the modules beyond the core that the examples of a page need (skipped without them)
NEEDS = {
    "meshes": ("trimesh", "pyvista", "pandas"),
    "label_images": ("skimage", "pandas"),
    "files": ("matplotlib",),
}


def test_the_guide_has_its_pages_and_the_index_takes_every_page():
    assert {page.stem for page in PAGES} >= set(NAMED)
    index = (DOCS / "index.rst").read_text(encoding="utf-8")
    assert ":glob:" in index and "guide/*" in index  # the pages of other authors too


@pytest.mark.parametrize("name", NAMED)
def test_each_page_has_a_title_and_a_picture(name):
    text = (GUIDE / f"{name}.md").read_text(encoding="utf-8")
    assert text.startswith("# ")
    pictures = re.findall(r"!\[[^\]]+\]\(([^)]+)\)", text)
    assert pictures, f"{name}.md has no picture"
    for picture in pictures:
        assert (GUIDE / picture).resolve().is_file(), picture


@pytest.mark.parametrize("name", NAMED)
def test_the_guide_speaks_to_users(name):
    text = (GUIDE / f"{name}.md").read_text(encoding="utf-8").lower()
    for word in ("issue", "seed", "closing note"):
        assert word not in text, word


# pages whose examples take several seconds (pictures, label images): in the slow set; the README's
# examples cover the same calls in the quick one
SLOW_PAGES = {"files", "label_images"}


def _pages_with_examples():
    return [
        pytest.param(page.stem, marks=[pytest.mark.slow] if page.stem in SLOW_PAGES else [])
        for page in PAGES
        if ">>> " in page.read_text(encoding="utf-8")
    ]


@pytest.mark.parametrize("name", _pages_with_examples())
def test_the_examples_of_the_page_run(name, tmp_path, monkeypatch):
    for module in NEEDS.get(name, ()):
        pytest.importorskip(module)
    monkeypatch.chdir(tmp_path)
    text = (GUIDE / f"{name}.md").read_text(encoding="utf-8")
    parser = doctest.DocTestParser()
    test = parser.get_doctest(text, {"__name__": f"guide_{name}"}, f"{name}.md", str(GUIDE / f"{name}.md"), 0)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    report = []
    runner.run(test, out=report.append)
    assert runner.failures == 0, "".join(report)
    assert runner.tries > 0


@pytest.mark.slow  # a Sphinx build: a minute on 2 cores
def test_make_docs_builds_without_a_warning(tmp_path):
    for module in ("sphinx", "myst_parser", "numpydoc"):
        if importlib.util.find_spec(module) is None:
            pytest.skip(f"the docs need {module}: pip install '.[docs]'")
    source = tmp_path / "docs"
    shutil.copytree(DOCS, source, ignore=shutil.ignore_patterns("_build", "api"))
    shutil.copy(ROOT / "README.md", tmp_path / "README.md")
    result = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html", "-q", str(source), str(tmp_path / "html")],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stderr
    built = {path.stem for path in (tmp_path / "html" / "guide").glob("*.html")}
    assert built >= set(NAMED)
