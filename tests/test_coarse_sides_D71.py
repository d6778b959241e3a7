"""The sides of the coarse level's groups on a voxel surface (:func:`meshcurv.estimators.icc._side_normals`).

Oracle: the analytic sphere's own normals. Grouped by cube and by the side of the sphere's normal, a cube of a
marching-cubes sphere whose radius of curvature is many cubes holds one sheet, so about one group; the staircase's
vertex normals (treads and risers) split a cube into two or three sides where the sphere has one. The sides read
from the normals summed over a few rings follow the sphere's.
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import shapes
from meshcurv.estimators import icc
from meshcurv.geometry import vertex_normals
from meshcurv.topology import MeshTopology


def _groups(vertices, normals, radius, areas, adjacency):
    points = icc._coarse_level(vertices, normals, radius, areas, None, adjacency)[0]
    return points.shape[0] - vertices.shape[0]


@pytest.mark.parametrize("spacing", [(0.5, 0.2, 0.2), (0.2, 0.2, 0.2)])
def test_voxel_sphere_groups_follow_the_sides_of_the_sphere(spacing, monkeypatch):
    pytest.importorskip("skimage")
    mesh = shapes.voxel_sphere(6.0, spacing, seed=0)
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces)[:, ::-1]  # outward
    adjacency = MeshTopology.from_faces(faces, vertices.shape[0]).neighbour_lists
    normals = vertex_normals(vertices, faces)
    areas = np.ones(vertices.shape[0])
    # the main pass's normal radius there (three measure radii of about 2.7): cubes of 0.79
    radius = 7.9
    exact = (vertices - mesh.center) / np.linalg.norm(vertices - mesh.center, axis=1, keepdims=True)
    found = _groups(vertices, normals, radius, areas, adjacency)
    # the sphere's own sides (no ring: its normals are smooth already)
    monkeypatch.setattr(icc, "SIDE_RINGS", 0, raising=False)
    sphere = _groups(vertices, exact, radius, areas, adjacency)
    # (each vertex's own normal: 1,991 and 2,588 groups against the sphere's 1,100 and 1,144; over two rings 1,227
    # and 1,271)
    assert found <= 1.15 * sphere
    # no cube merged across a side the sphere has: at least its groups' number of cubes
    assert found >= 0.95 * sphere
