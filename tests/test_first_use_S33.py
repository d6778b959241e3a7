"""A fresh process's first default call imports no module it does not use (issue 31's warm start).

``scipy.spatial`` (with the ``scipy.special`` and ``scipy.spatial.transform`` it imports) costs a fresh process
about 0.13 s of CPU, an eighth of what is left of the warm start once numba is loaded. The default call on a
closed mesh of one part builds no k-d tree: the nesting of closed parts (``orient._nesting_depth``) returns at
once for one part, the boundary balls (``radius._holed_factor``) for a mesh without boundary, and the Euclidean
rows of the patch levels (``radius._patch_levels``) are only for vertices of small rings. The test records the
imports made from meshcurv's frames during the call (``builtins.__import__`` runs for every ``import``
statement, the module cached or not), so that the modules other tests loaded do not hide them.
"""

from __future__ import annotations

import builtins

import pytest
from conftest import chosen_backend

import meshcurv


def _imports_during(call) -> list[str]:
    """The modules named by the ``import`` statements of meshcurv's own code while ``call()`` runs."""
    seen: list[str] = []
    original = builtins.__import__

    def recording(name, module_globals=None, module_locals=None, fromlist=(), level=0):
        caller = (module_globals or {}).get("__name__", "")
        if caller.startswith("meshcurv") and level == 0:
            seen.append(name)
        return original(name, module_globals, module_locals, fromlist, level)

    builtins.__import__ = recording
    try:
        call()
    finally:
        builtins.__import__ = original
    return seen


@pytest.mark.parametrize("surface", ["torus", "icosphere"])
def test_default_call_on_one_closed_part_builds_no_tree(surface):
    shape = meshcurv.shapes.torus() if surface == "torus" else meshcurv.shapes.icosphere(2)
    with chosen_backend("numba"):
        imported = _imports_during(lambda: meshcurv.principal_curvatures(shape.vertices, shape.faces))
    assert not [name for name in imported if name.startswith("scipy.spatial")], imported
