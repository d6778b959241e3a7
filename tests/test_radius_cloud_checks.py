"""The last unchecked public rules of meshcurv.radius: ``cloud_noise_level`` and ``vertex_radii`` (issue 33).

Before (9840e16) they took their arrays as given: a float or 2-d ``centres``, a ``spacing`` given as a
string, an empty ``groups``, members out of range or a negative ``n_vertices`` ended in numpy's IndexError,
TypeError, AttributeError or ValueError; a NaN or negative spacing, a NaN, negative or string radius, a
negative member or a (1, 2) members array gave an answer (0, or radii of NaN, -1 or 'x'). Each now raises
InvalidMeshError (arrays) or InvalidOptionError (numbers) naming the argument, as the rules checked in
485086a (tests/test_radius_defects_checks.py).
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import radius, shapes
from meshcurv.errors import InvalidMeshError, InvalidOptionError

SPHERE = shapes.icosphere(2)
POINTS = np.ascontiguousarray(SPHERE.vertices, dtype=np.float64)
N = POINTS.shape[0]
NORMALS = POINTS / np.linalg.norm(POINTS, axis=1)[:, None]
CENTRES = np.arange(N)
USABLE = np.ones(N, dtype=bool)
SPACING = 0.3


def _noise(points=POINTS, normals=NORMALS, spacing=SPACING, centres=CENTRES, usable=USABLE, facing=None) -> float:
    return radius.cloud_noise_level(points, normals, spacing, centres, usable, facing=facing)


def _nan_point() -> np.ndarray:
    points = POINTS.copy()
    points[3, 1] = np.nan
    return points


@pytest.mark.parametrize(
    ("given", "message"),
    [
        ({"points": _nan_point()}, "`points` has NaN or infinite coordinates at 1 vertices"),
        ({"points": POINTS[:, :2]}, r"`points` must have shape \(V, 3\); got \(42, 2\)"),
        ({"normals": NORMALS[:10]}, r"`normals` must be a real array of shape \(42, 3\); got float64 \(10, 3\)"),
        ({"normals": NORMALS.T}, r"`normals` must be a real array of shape \(42, 3\)"),
        ({"centres": CENTRES + 5}, "`centres` has vertex index 46 out of range for 42 vertices"),
        ({"centres": CENTRES - 5}, "`centres` has negative vertex indices"),
        ({"centres": CENTRES + 0.5}, "`centres` has non-integer values"),
        ({"centres": CENTRES.reshape(-1, 2)}, r"`centres` must be a 1-d array of vertex indices; got shape \(21, 2\)"),
        ({"usable": USABLE[:10]}, r"`usable` must be a bool array of shape \(42,\); got bool \(10,\)"),
        ({"usable": USABLE.astype(np.int64)}, r"`usable` must be a bool array of shape \(42,\); got int64"),
        ({"usable": None}, r"`usable` must be a bool array of shape \(42,\)"),
        ({"facing": NORMALS[:10]}, r"`facing` must be a real array of shape \(42, 3\); got float64 \(10, 3\)"),
    ],
    ids=[
        "nan-point",
        "2-columns",
        "short-normals",
        "transposed-normals",
        "centre-beyond",
        "negative-centre",
        "float-centres",
        "2d-centres",
        "short-usable",
        "int-usable",
        "no-usable",
        "short-facing",
    ],
)
def test_cloud_noise_level_refuses_arrays_that_do_not_fit(given, message):
    with pytest.raises(InvalidMeshError, match=message):
        _noise(**given)


@pytest.mark.parametrize("spacing", [np.nan, np.inf, -1.0, "0.3", None, True])
def test_cloud_noise_level_refuses_a_spacing_that_is_not_a_length(spacing):
    with pytest.raises(InvalidOptionError, match="`spacing` must be a finite number >= 0"):
        _noise(spacing=spacing)


def test_cloud_noise_level_of_a_plane_is_zero_and_of_coincident_points_is_zero():
    # points of the plane z = 0 on a jittered grid: every degree-2 jet fits them exactly (c00 = 0 to round-off)
    rng = np.random.default_rng(3)
    x, y = np.meshgrid(np.arange(12.0), np.arange(12.0))
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    points[:, :2] += 0.2 * rng.uniform(-1, 1, (x.size, 2))
    normals = np.tile([0.0, 0.0, 1.0], (x.size, 1))
    usable = np.ones(x.size, dtype=bool)
    level = radius.cloud_noise_level(points, normals, 1.0, list(range(x.size)), usable)  # a list of ids: taken
    assert 0.0 <= level < 1e-9
    # a spacing of 0 (every point on another): no ball to fit, the defined answer 0
    assert radius.cloud_noise_level(points, normals, 0, np.arange(x.size), usable) == 0.0


def test_vertex_radii_give_each_group_its_radius():
    # by definition: the one group of every vertex, or each vertex the radius of its group, NaN outside
    np.testing.assert_array_equal(radius.vertex_radii([(0.5, None)], 4), [0.5] * 4)
    radii = radius.vertex_radii([(0.5, np.array([0, 2])), (2.0, [3])], 5)
    np.testing.assert_array_equal(radii, [0.5, np.nan, 0.5, 2.0, np.nan])
    np.testing.assert_array_equal(radius.vertex_radii([(0, None)], 2), [0.0, 0.0])  # a mesh without edges


@pytest.mark.parametrize(
    ("groups", "n_vertices", "error", "message"),
    [
        ([], 5, InvalidOptionError, r"`groups` must be a non-empty list of \(radius, members\) pairs; got \[\]"),
        (0.3, 5, InvalidOptionError, r"`groups` must be a non-empty list of \(radius, members\) pairs"),
        ([0.3], 5, InvalidOptionError, r"`groups` must hold \(radius, members\) pairs; got 0.3"),
        ([(0.3, None), (0.5, [1])], 5, InvalidOptionError, "members None .* only allowed in a list of one group"),
        ([(np.nan, None)], 5, InvalidOptionError, "`radius` must be a finite number >= 0; got nan"),
        ([(-1.0, None)], 5, InvalidOptionError, "`radius` must be a finite number >= 0; got -1.0"),
        ([("x", None)], 5, InvalidOptionError, "`radius` must be a finite number >= 0; got 'x'"),
        ([(0.3, None)], -1, InvalidOptionError, "`n_vertices` must be an integer between 1 and"),
        ([(0.3, None)], 2.5, InvalidOptionError, "`n_vertices` must be an integer between 1 and"),
        ([(0.3, np.array([0, 7]))], 5, InvalidMeshError, "`members` has vertex index 7 out of range for 5 vertices"),
        ([(0.3, np.array([-1]))], 5, InvalidMeshError, "`members` has negative vertex indices"),
        ([(0.3, np.array([0.5]))], 5, InvalidMeshError, "`members` has non-integer values"),
        ([(0.3, np.array([[0, 1]]))], 5, InvalidMeshError, r"`members` must be a 1-d array of vertex indices"),
        ([(0.3, np.ones(5, dtype=bool))], 5, InvalidMeshError, "`members` must hold integer vertex indices"),
    ],
    ids=[
        "empty",
        "not-a-list",
        "not-pairs",
        "none-among-groups",
        "nan-radius",
        "negative-radius",
        "string-radius",
        "negative-count",
        "float-count",
        "member-beyond",
        "negative-member",
        "float-members",
        "2d-members",
        "bool-members",
    ],
)
def test_vertex_radii_refuse_groups_that_do_not_fit(groups, n_vertices, error, message):
    with pytest.raises(error, match=message):
        radius.vertex_radii(groups, n_vertices)
