"""numpydoc's validator over the public API: the checks of ``[tool.numpydoc_validation]`` in pyproject.toml.

The public API is every name in the ``__all__`` of :mod:`meshcurv` and of
its public modules (no part of the dotted name starting with ``_``), and the
public methods and properties of those classes. A violation fails the test
unless it is listed in ``tests/numpydoc_baseline.txt`` (the violations
found when the check was turned on, ``<name> <code>`` per line, to be fixed
and removed from the list); a listed violation that is gone fails the test
too (unless the object is not in the API at all), so that the list only
shrinks.

One rule is relaxed for classes: a dataclass documents its fields under
``Attributes`` (what a reader looks up) rather than ``Parameters`` (what
only a constructor needs), so a field named there counts as documented for
PR01.
"""

import importlib
import inspect
import pathlib
import pkgutil
import re
import tomllib
import warnings

import pytest

import meshcurv

numpydoc_validate = pytest.importorskip("numpydoc.validate")
docscrape = pytest.importorskip("numpydoc.docscrape")

ROOT = pathlib.Path(__file__).resolve().parents[1]
BASELINE = ROOT / "tests" / "numpydoc_baseline.txt"
CONFIG = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["numpydoc_validation"]


def public_modules() -> list[str]:
    names = ["meshcurv"]
    for info in pkgutil.walk_packages(meshcurv.__path__, "meshcurv."):
        if not any(part.startswith("_") for part in info.name.split(".")):
            names.append(info.name)
    return names


def public_objects() -> dict[str, object]:
    """Qualified name -> object, each object once (under the first module that exports it)."""
    found: dict[str, object] = {}
    seen: set[int] = set()
    for module_name in public_modules():
        module = importlib.import_module(module_name)
        for name in getattr(module, "__all__", ()):
            value = getattr(module, name)
            if not (inspect.isfunction(value) or inspect.isclass(value)) or id(value) in seen:
                continue
            seen.add(id(value))
            qualified = f"{module_name}.{name}"
            found[qualified] = value
            if inspect.isclass(value):
                for attribute, member in vars(value).items():
                    if not attribute.startswith("_") and (
                        inspect.isfunction(member) or isinstance(member, (property, classmethod, staticmethod))
                    ):
                        found[f"{qualified}.{attribute}"] = member
    excluded = [re.compile(pattern) for pattern in CONFIG.get("exclude", [])]
    return {name: value for name, value in found.items() if not any(p.search(name) for p in excluded)}


def attributes_documented(value) -> set[str]:
    if not inspect.isclass(value):
        return set()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        parsed = docscrape.ClassDoc(value, config={"show_class_members": False})
    return {name.strip() for entry in parsed["Attributes"] for name in entry.name.split(",")}


def violations(name: str, value) -> list[str]:
    checks = set(CONFIG["checks"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # numpydoc's own warnings on sections it does not know
        errors = numpydoc_validate.validate(name)["errors"]
    found = []
    for code, message in errors:
        if code not in checks:
            continue
        if code == "PR01":
            missing = set(re.findall(r"'(\*{0,2}\w+)'", message))
            missing -= attributes_documented(value)
            missing = {parameter for parameter in missing if not parameter.lstrip("*").startswith("_")}
            if not missing:
                continue
            message = f"Parameters {sorted(missing)} not documented"
        found.append(f"{name} {code} {message}")
    return found


def baseline() -> set[str]:
    lines = BASELINE.read_text().splitlines() if BASELINE.exists() else []
    return {line for line in lines if line.strip() and not line.startswith("#")}


def test_the_configured_checks_include_the_contract_ones():
    assert {"GL08", "PR01", "PR02", "RT01"} <= set(CONFIG["checks"])


def test_public_api_docstrings_pass_numpydoc_validation():
    objects = public_objects()
    assert "meshcurv.principal_curvatures" in objects and "meshcurv.batch.run" in objects  # the walk sees the API
    found = {" ".join(line.split()[:2]): line for name, value in objects.items() for line in violations(name, value)}
    known = baseline()  # "<name> <code>": the message (which parameters) may change with the signature
    new = sorted(found[key] for key in set(found) - known)
    # a listed object that is not in the API (renamed, removed, or not yet committed) is not counted
    fixed = sorted(key for key in known - set(found) if key.split()[0] in objects)
    assert not new, "numpydoc violations (fix the docstring):\n" + "\n".join(new)
    assert not fixed, f"fixed, now remove these lines from {BASELINE.name}:\n" + "\n".join(fixed)


def test_a_violation_is_found(monkeypatch):
    """The check can fail: a public function whose docstring omits a parameter and its return value."""

    def undocumented(first, second):
        """Add two numbers."""
        return first + second

    undocumented.__module__ = "meshcurv"
    monkeypatch.setattr(meshcurv, "undocumented", undocumented, raising=False)
    found = violations("meshcurv.undocumented", undocumented)
    assert any(" PR01 " in line and "first" in line for line in found), found
    assert any(" RT01 " in line for line in found), found
