"""``matgeom`` on a voxel staircase: matGeom's numbers kept, none marked valid (issue 29: never a valid wrong number).

matGeom's ring of faces reads a marching-cubes staircase as curvature: on ``voxel_sphere(10)`` its H is off the
sphere's 1 / R by about 120% at the median, and every vertex was ``valid``, with no warning. The vertices are now
``valid=False`` with a warning that says why, while the numbers stay matGeom's (its compatibility promise: number
for number); smooth meshes keep their valid vertices.
"""

import numpy as np
import pytest

import meshcurv
from meshcurv import principal_curvatures, shapes
from meshcurv.defects import INVALID_REASONS, STAIRCASE

RADIUS = 10.0


def _matgeom(mesh):
    with pytest.warns(UserWarning, match="staircase") as caught:
        result = principal_curvatures(mesh.vertices, mesh.faces, method="matgeom")
    return result, " ".join(str(w.message) for w in caught)


def test_voxel_sphere_none_valid_numbers_kept(monkeypatch):
    pytest.importorskip("skimage")
    mesh = shapes.voxel_sphere(radius=RADIUS)
    result, message = _matgeom(mesh)
    assert not result.valid.any()
    assert "valid=False" in message and "matGeom" in message
    # each vertex says why: the staircase, not an undefined estimate (its numbers are finite)
    assert set(result.invalid_counts()) == {INVALID_REASONS[STAIRCASE]}
    assert INVALID_REASONS[STAIRCASE].startswith("voxel staircase")
    # the numbers are there, and they are why nothing is valid: far from the sphere's H (matGeom's outputs are
    # dimensionless: H relative to the mean edge; the median of |H - H_exact| / |H_exact| over the vertices)
    k_min, k_max = result.k_min, result.k_max
    assert np.isfinite(k_min).all() and np.isfinite(k_max).all()
    # matGeom's numbers are kept exactly: the same call without the staircase rule gives the same arrays
    monkeypatch.setattr(meshcurv.estimators.matgeom, "on_staircase", lambda *a, **k: False)
    plain = principal_curvatures(mesh.vertices, mesh.faces, method="matgeom")
    assert plain.valid.mean() > 0.9  # what it was: valid wrong numbers
    np.testing.assert_array_equal(plain.k_min, k_min)
    np.testing.assert_array_equal(plain.k_max, k_max)
    np.testing.assert_array_equal(plain.normals, result.normals)


def test_voxel_sphere_matgeom_is_off():
    """Why: matGeom's mean curvature on the staircase, rescaled to 1/length by the mean edge, is far from 1 / R."""
    pytest.importorskip("skimage")
    mesh = shapes.voxel_sphere(radius=RADIUS)
    result, _ = _matgeom(mesh)
    edges = np.concatenate([mesh.faces[:, [0, 1]], mesh.faces[:, [1, 2]], mesh.faces[:, [2, 0]]])
    mean_edge = np.linalg.norm(mesh.vertices[edges[:, 0]] - mesh.vertices[edges[:, 1]], axis=1).mean()
    h = np.abs(0.5 * (result.k_min + result.k_max)) / mean_edge
    assert np.median(np.abs(h * RADIUS - 1.0)) > 0.5


@pytest.mark.parametrize("make", [lambda: shapes.icosphere(4), lambda: shapes.torus()])
def test_smooth_meshes_keep_valid(make):
    mesh = make()
    result = principal_curvatures(mesh.vertices, mesh.faces, method="matgeom")
    assert result.valid.all()
