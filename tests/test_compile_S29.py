"""What the default compiles and allocates (issue 31, helper S29): one compiled normal fit for the grid's and
the surface-connected balls, the grid's column sort without numba's argsort, the ball sums' scratch from numba's
allocator (no huge-page advice: the first writes to numpy's large arrays waited for memory to be compacted).
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

pytest.importorskip("numba")


@pytest.mark.parametrize("seed", range(4))
def test_merge_sort_column_is_numpys_stable_sort(seed):
    from meshcurv._kernels.neighborhoods import _merge_sort_column

    rng = np.random.default_rng(seed)
    for _ in range(50):
        n = int(rng.integers(1, 200))
        first = int(rng.integers(0, 4))
        total = first + n + 3  # the column inside a longer array: the rest untouched
        levels = rng.integers(-3, int(rng.integers(1, 12)), total).astype(np.int64)  # many ties
        order = rng.permutation(total).astype(np.int64)
        expected_levels, expected_order = levels.copy(), order.copy()
        by_level = np.argsort(levels[first : first + n], kind="stable")
        expected_levels[first : first + n] = levels[first : first + n][by_level]
        expected_order[first : first + n] = order[first : first + n][by_level]
        _merge_sort_column(levels, order, first, first + n)
        np.testing.assert_array_equal(levels, expected_levels)
        np.testing.assert_array_equal(order, expected_order)


def test_ball_sum_scratch_is_numbas_memory_and_stamped():
    from meshcurv._backend import numba_kernels
    from meshcurv.neighborhoods import _face_sum_scratch

    kernels = numba_kernels("neighborhoods")
    scratch = _face_sum_scratch(2, 50, 96, kernels=kernels)
    for array in scratch:
        base = array
        while isinstance(base.base, np.ndarray):
            base = base.base
        assert not base.flags.owndata  # numba's memory object owns it, not numpy
    seen, mark, known = scratch[:3]
    assert seen.shape == (2, 96) and mark.shape == known.shape == (2, 50)
    assert (seen == -1).all() and (mark == -1).all() and (known == -1).all()
    assert scratch[3].dtype == np.float64 and scratch[3].shape == (2, 50)


@pytest.mark.slow
def test_one_compiled_fit_for_grid_and_connected_balls(tmp_path):
    # in a fresh process on an empty cache (a cached caller loads without its callees' signatures), where the
    # signatures a test session compiled elsewhere (the nested fits') are not counted
    code = textwrap.dedent(
        """
        import numpy as np
        from meshcurv import jets, shapes
        from meshcurv.topology import as_topology
        from meshcurv._kernels import jets as kernels

        mesh = shapes.icosphere(6)
        vertices = np.array(mesh.vertices)  # writable, as a user's
        normals = vertices / np.linalg.norm(vertices, axis=1, keepdims=True)
        lists = as_topology(mesh.faces, vertices.shape[0]).neighbour_lists
        grid = jets.fit_jets(vertices, normals, 0.4)
        connected = jets.fit_jets(vertices, normals, 0.4, adjacency=lists)
        assert np.isfinite(grid[0]).all() and np.isfinite(connected[0]).all()  # every fit made, on both paths
        print(len(kernels._fit_one.signatures))
        """
    )
    environment = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=environment)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split()[-1] == "1"
