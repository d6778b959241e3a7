"""Collection rules for the doctests of ``src/meshcurv`` (``--doctest-modules``).

The modules below import an optional extra at module level (the CLI needs
click, the compiled kernels numba). On an install without that extra they are
not collected, so that ``pytest`` on a minimal install (``pip install .[test]``)
skips what it cannot run instead of failing at collection; the tests that use
them skip through ``pytest.importorskip``.
"""

import importlib.util

_NEEDS = {
    "click": ["src/meshcurv/cli"],
    "numba": ["src/meshcurv/_kernels"],
}

collect_ignore = [
    path for module, paths in _NEEDS.items() if importlib.util.find_spec(module) is None for path in paths
]

# The README's examples use the optional extras (marching cubes, the command line, files through
# meshio, pictures): on an install without one of them its doctest is skipped, not failed.
_README_NEEDS = ("skimage", "click", "meshio", "matplotlib", "pandas")


# The modules whose doctests draw pictures.
_DOCTEST_NEEDS = {"src/meshcurv/plotting.py": "matplotlib"}


def pytest_collection_modifyitems(config, items):
    import pytest

    missing = [module for module in _README_NEEDS if importlib.util.find_spec(module) is None]
    for item in items:
        if missing and item.nodeid.startswith("README.md"):
            item.add_marker(pytest.mark.skip(reason=f"the README's examples need {', '.join(missing)}"))
        for path, module in _DOCTEST_NEEDS.items():
            if item.nodeid.startswith(path) and importlib.util.find_spec(module) is None:
                item.add_marker(pytest.mark.skip(reason=f"the example needs {module}"))
