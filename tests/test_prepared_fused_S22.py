"""The one-pass vertex normals of a prepared mesh and the column-wise finite test (issue 31, helper S22).

``PreparedMesh.degenerate`` on a mesh without needles finds the zero-area faces and sums the vertex normals
and areas in one compiled pass (no (F, 3) cross products in memory). The sums must be those of the two passes
it replaces, to the bit: the same cross products, the same test, the same additions in face order.
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import shapes
from meshcurv._geometry import finite_rows


def _with_zero_area_faces():
    """An icosphere with two zero-area faces (a vertex moved onto another) and a face repeating a corner."""
    sphere = shapes.icosphere(6)
    vertices, faces = sphere.vertices.copy(), sphere.faces.copy()
    vertices[faces[0, 2]] = vertices[faces[0, 0]]
    faces = np.vstack([faces, [[faces[7, 1], faces[7, 1], faces[9, 2]]]])
    return vertices, faces


@pytest.mark.parametrize("mesh", ["icosphere", "torus", "zero-area faces"])
def test_one_pass_normals_equal_the_two_passes(mesh):
    pytest.importorskip("numba")
    from meshcurv import _geometry
    from meshcurv._backend import use_backend
    from meshcurv._prepared import PreparedMesh
    from meshcurv.topology import MeshTopology

    if mesh == "zero-area faces":
        vertices, faces = _with_zero_area_faces()
    else:
        shape = shapes.icosphere(5) if mesh == "icosphere" else shapes.torus()
        vertices, faces = np.ascontiguousarray(shape.vertices), shape.faces
    topology = MeshTopology.from_faces(faces, vertices.shape[0])
    prepared = PreparedMesh.as_given(np.ascontiguousarray(vertices, dtype=np.float64), topology)
    assert not prepared.needles.any()
    degenerate = prepared.degenerate
    assert "_spare_cross" not in prepared.__dict__  # the one pass ran: no cross products kept

    # the two passes it replaces, on the NumPy backend (the kernels' twins)
    with use_backend("numpy"):
        cross, expected_degenerate = _geometry.cross_and_degenerate(
            prepared.vertices, topology.faces, prepared.length_scales, _geometry.DEGENERATE_AREA_RATIO
        )
        sums, areas = _geometry.vertex_normal_and_area_sums(
            cross, topology.faces, expected_degenerate, vertices.shape[0]
        )
    np.testing.assert_array_equal(degenerate, expected_degenerate)
    assert expected_degenerate.sum() == (3 if mesh == "zero-area faces" else 0)
    # the compiled sums add in face order, as np.bincount: the same numbers to the bit
    np.testing.assert_array_equal(prepared.vertex_areas, areas)
    np.testing.assert_array_equal(prepared.vertex_normals, _geometry.normalize_normal_sums.numpy(sums))
    # and the cross products, asked for afterwards, are the faces' own
    np.testing.assert_array_equal(prepared.cross, cross)


def test_finite_rows_is_isfinite_all():
    rng = np.random.default_rng(0)
    array = rng.normal(size=(1000, 3))
    array[rng.integers(0, 1000, 50), rng.integers(0, 3, 50)] = np.nan
    array[rng.integers(0, 1000, 20), rng.integers(0, 3, 20)] = np.inf
    array[5] = [1e308, 1e308, 1e308]  # finite entries whose sum overflows: a finite row
    expected = np.isfinite(array).all(axis=1)
    np.testing.assert_array_equal(finite_rows(array), expected)
    assert finite_rows(array)[5] and not expected.all()
    assert finite_rows(np.zeros((4, 0))).all()


@pytest.mark.parametrize("outlier", [False, True])
def test_robust_mean_edge_length_one_pass(outlier):
    """The compiled path (a sample's median, then the mean and the longest edge in one pass) gives the mean of
    ``mean_edge_length`` to the bit, and without the outliers where an edge is beyond the ratio."""
    pytest.importorskip("numba")
    from meshcurv import _geometry
    from meshcurv.topology import MeshTopology

    sphere = shapes.icosphere(12)
    vertices = np.ascontiguousarray(sphere.vertices, dtype=np.float64)
    faces = np.asarray(sphere.faces)
    if outlier:  # a needle: one vertex flung far away
        vertices = vertices.copy()
        vertices[faces[0, 0]] *= 1e5
    edges = MeshTopology.from_faces(faces, vertices.shape[0]).edges
    got = _geometry.robust_mean_edge_length(vertices, edges)
    lengths = np.sqrt(((vertices[edges[:, 1]] - vertices[edges[:, 0]]) ** 2).sum(axis=1))
    if outlier:
        kept = lengths[lengths <= _geometry.OUTLIER_EDGE_RATIO * np.median(lengths)]
        assert kept.size < lengths.size
        assert got == pytest.approx(kept.mean(), rel=1e-14)
    else:
        assert got == _geometry.mean_edge_length(vertices, edges)  # the kernel's ordered sums: the same bits
        assert got == pytest.approx(lengths.mean(), rel=1e-14)
