"""A vertex in no face changes no value (issue 29, fuzz round 15, seed 264 case 4318).

On a mesh whose balls are wide against its edges (a crumpled icosphere: noise of the vertices' spread), ``icc``
fits its normals on a coarse level at one sample per cube, the cubes starting at the corner of the vertices; a
vertex in no face beyond that corner moved the cubes, and k_max of the referenced vertices moved by up to 0.31
of its largest value. The cubes now start at the corner of the vertices measured.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from meshcurv import principal_curvatures, shapes
from meshcurv._backend import use_backend


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_a_vertex_in_no_face_changes_no_value_on_a_crumpled_mesh(backend):
    if backend == "numba":
        pytest.importorskip("numba")
    mesh = shapes.icosphere(subdivisions=4)
    rng = np.random.default_rng(5)
    vertices = mesh.vertices + rng.normal(size=mesh.vertices.shape) * mesh.vertices.std()
    edge = np.median(np.linalg.norm(vertices[mesh.faces[:, 0]] - vertices[mesh.faces[:, 1]], axis=1))
    extra = vertices.min(axis=0) - 0.3 * edge  # beyond the vertices' corner: the case that moved the cubes
    with use_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        alone = principal_curvatures(vertices, mesh.faces, method="icc")
        beside = principal_curvatures(np.vstack([vertices, extra]), mesh.faces, method="icc")
    n = vertices.shape[0]
    for field in ("k_min", "k_max", "normals"):
        np.testing.assert_array_equal(getattr(beside, field)[:n], getattr(alone, field))
    assert not beside.valid[n]
