"""A voxel surface with faces detached beyond the weld is still read as a voxel surface (issue 29).

Faces detached from a marching-cubes sphere by a tenth of an edge (their own corners, too far for the weld
across cracks) are fragments: faces alone, on no surface, invalid for ``icc``. They are off the voxel grid, and
the whole mesh was read as an ordinary one: the rest of the staircase was measured at a smooth mesh's radius,
a vertex up to 0.54 of the curvature off, valid (fuzz_api seed 352, case 1144). The grid is now read again
without the fragments.
"""

import numpy as np
import pytest

from meshcurv import principal_curvatures, shapes
from test_orient_holey_inward import _holey

RADIUS = 4.0


def _detached(seed: int, gap: float = 0.091):
    mesh = shapes.voxel_sphere(radius=RADIUS)
    vertices, faces = np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)
    return _holey(vertices, faces, seed=seed, detach=True, offset=gap)  # half of the faces, as there


@pytest.mark.parametrize("seed", [20, 25])
def test_detached_voxel_sphere_read_on_its_grid(seed):
    pytest.importorskip("skimage")
    vertices, faces = _detached(seed)
    with pytest.warns(UserWarning):
        result = principal_curvatures(vertices, faces)
    assert result.parameters["surface"] == "voxel"
    assert result.valid.sum() > 100
    mean = 0.5 * (result.k_min + result.k_max)[result.valid]
    # the staircase's own spread stays far below half of the curvature 1 / R
    assert np.max(np.abs(mean - 1.0 / RADIUS)) * RADIUS < 0.5
