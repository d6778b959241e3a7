"""The clusters of faces of the dense balls' sums, compiled (issue 30): the same clusters, spheres, sums and links
as the NumPy lines (SciPy's connected components), to the bit; and the pair estimate of every ball computation,
computed in blocks of centres, against a count of the distances themselves.

The clusters are what ``coarse_face_sums`` and ``clustered_face_sums`` add; their numbering decides the order of
those additions, so a cluster numbered otherwise would move the sums by round-off: the test asks for equality.
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import neighborhoods, shapes
from conftest import chosen_backend

pytest.importorskip("numba")


def _defects():
    """An icosphere with defects: zero-area and repeated-vertex faces, a non-manifold fin, a flipped face, a hole,
    unreferenced vertices and a lone far triangle a thousand times smaller."""
    sphere = shapes.icosphere(8)
    vertices, faces = sphere.vertices.copy(), sphere.faces.copy()
    vertices[faces[0, 2]] = vertices[faces[0, 0]]
    faces[100] = faces[100, ::-1]
    faces = np.delete(faces, range(200, 206), axis=0)
    n = vertices.shape[0]
    extra = [[faces[50, 0], faces[50, 1], 0], [faces[7, 1], faces[7, 1], faces[9, 2]], [n + 2, n + 3, n + 4]]
    far = np.vstack([[[5.0, 5.0, 5.0], [-5.0, 0.0, 1.0]], 1e-3 * np.eye(3) + 10.0])
    return np.vstack([vertices, far]), np.vstack([faces, extra])


def _inputs(name):
    if name == "defects":
        vertices, faces = _defects()
    else:
        if name.startswith("voxel"):  # (marching cubes: scikit-image; the other meshes need no extra)
            pytest.importorskip("skimage")
        mesh = {
            "voxel sphere": lambda: shapes.voxel_sphere(3.0, (0.25, 0.1, 0.1), seed=2),
            "voxel torus": lambda: shapes.voxel_torus(3.0, 1.0, (0.3, 0.2, 0.2), seed=0),
            "thin ellipsoid": lambda: shapes.ellipsoid((3.0, 3.0, 0.15), subdivisions=16),
        }[name]()
        vertices, faces = mesh.vertices, mesh.faces
    return np.asarray(vertices, dtype=np.float64), np.ascontiguousarray(faces, dtype=np.int64)


@pytest.mark.parametrize("name", ["voxel sphere", "voxel torus", "defects", "thin ellipsoid"])
@pytest.mark.parametrize("size", [5, 32, 400])
def test_compiled_clusters_are_the_numpy_ones_to_the_bit(name, size):
    vertices, faces = _inputs(name)
    rng = np.random.default_rng(size)
    values = rng.standard_normal((faces.shape[0], 3))
    usable = rng.random(faces.shape[0]) > 0.1
    centres, reach = neighborhoods.cell_centres(vertices, faces)
    with chosen_backend("numba"):
        compiled = neighborhoods._face_clusters(vertices, faces, centres, reach, values, usable, size=size)
    with chosen_backend("numpy"):
        plain = neighborhoods._face_clusters(vertices, faces, centres, reach, values, usable, size=size)
    assert len(compiled) == len(plain) == 9
    for mine, theirs in zip(compiled[:8], plain[:8]):
        assert mine.dtype == theirs.dtype
        np.testing.assert_array_equal(mine, theirs)
    assert compiled[8] == plain[8]
    # the numbering of SciPy's components: clusters in the order of their first face
    of = compiled[0]
    firsts = np.array([np.flatnonzero(of == c)[0] for c in range(int(of.max()) + 1)])
    assert np.all(np.diff(firsts) > 0)


def _counted(points, centres, radii):
    """Points within each centre's radius, the distances computed one centre at a time in long double."""
    offsets = points[None, :, :].astype(np.longdouble) - centres[:, None, :].astype(np.longdouble)
    return ((offsets**2).sum(axis=2) <= np.asarray(radii, np.longdouble).reshape(-1, 1) ** 2).sum(axis=1)


@pytest.mark.parametrize("per_centre", [False, True])
def test_pair_estimates_in_blocks_count_the_points_within_each_ball(per_centre):
    # a cloud and centres no larger than the sample: the estimate is the exact count (the docstring's promise),
    # here over 27 centres (54 probes with one radius each: the sample and the widest), blocks of PROBE_ROWS and a
    # last partial one; the radii lie far from every distance (no tie for round-off to tip)
    rng = np.random.default_rng(3)
    points = rng.random((3000, 3)) * 10.0
    centres = rng.random((27, 3)) * 10.0
    radii = rng.uniform(1.0, 4.0, centres.shape[0]) if per_centre else np.full(centres.shape[0], 2.5)
    distances = np.linalg.norm(points[None] - centres[:, None], axis=2)
    assert np.min(np.abs(distances - radii[:, None])) > 1e-9
    mean, largest = neighborhoods.estimate_ball_pairs(points, radii if per_centre else 2.5, centres)
    counts = _counted(points, centres, radii)
    assert largest == counts.max()
    assert mean == pytest.approx(counts.mean(), rel=1e-15)
