"""What a prepared mesh keeps from its length scales, and the face pass made explicit (issue 31, helper S23).

``PreparedMesh.median_edge_length`` is the median length of every edge, the number the length scales of a mesh of
one scale are: kept from their computation, so that icc's coarse-level test does not take it again over the
3 E lengths (0.045 s of CPU at a million vertices). ``PreparedMesh._face_pass`` is the one pass over the faces
that finds the zero-area faces and, on a mesh without needles, sums the vertex normals and areas on its way:
asking for the zero-area faces fills nothing else.
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import shapes


def _lengths(vertices, edges):
    """Every edge's length, written out (the oracle: not the library's edge lengths)."""
    offsets = vertices[edges[:, 1]] - vertices[edges[:, 0]]
    return np.sqrt((offsets**2).sum(axis=1))


def _meshes():
    """One scale; two components 100 times apart (each its own scale); a double-sided mesh (one side kept, the
    length scales found by the weld's pass); faces that repeat a corner only (no edge)."""
    small = shapes.icosphere(6)
    large = shapes.icosphere(6, radius=100.0, center=(500.0, 0.0, 0.0))
    n = small.vertices.shape[0]
    return {
        "one scale": (small.vertices, small.faces),
        "two scales": (np.vstack([small.vertices, large.vertices]), np.vstack([small.faces, large.faces + n])),
        "double-sided": (small.vertices, np.vstack([small.faces, small.faces[:, ::-1]])),
        "no edge": (small.vertices[:3], np.array([[0, 0, 0], [1, 1, 1]])),
    }


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("name", list(_meshes()))
def test_the_median_edge_is_that_of_every_edge(name, backend):
    if backend == "numba":
        pytest.importorskip("numba")
    from meshcurv import _geometry
    from meshcurv._backend import use_backend
    from meshcurv._prepared import prepare_mesh

    vertices, faces = _meshes()[name]
    with use_backend(backend):
        prepared = prepare_mesh(vertices, faces, orient="keep", weld=True)
        median = prepared.median_edge_length
        edges = prepared.topology.edges
        assert isinstance(median, float)
        # to the bit: the median of the same lengths, as icc's coarse-level test took it (_geometry.median_edge_length)
        assert median == _geometry.median_edge_length(prepared.vertices, edges)
    if name == "no edge":
        assert edges.shape[0] == 0 and median == 0.0
        return
    assert median == pytest.approx(np.median(_lengths(prepared.vertices, edges)), rel=1e-14)
    if name == "two scales":  # each component its own scale; the median is over every edge of both
        assert np.unique(prepared.length_scales[prepared.topology.referenced_vertices]).size == 2
    else:  # one scale: the length scales are that median
        assert np.all(prepared.length_scales[prepared.topology.referenced_vertices] == median)
    if name == "double-sided":
        assert prepared.n_double_sided == faces.shape[0] // 2


def test_the_zero_area_faces_fill_nothing_else():
    """``degenerate`` returns the zero-area faces and sets no other field; the vertex normals asked first run the
    same one pass (no cross products built) and give the same arrays."""
    pytest.importorskip("numba")
    from meshcurv._prepared import PreparedMesh
    from meshcurv.topology import MeshTopology

    sphere = shapes.icosphere(5)
    vertices = np.ascontiguousarray(sphere.vertices, dtype=np.float64)
    topology = MeshTopology.from_faces(sphere.faces, vertices.shape[0])

    first = PreparedMesh.as_given(vertices, topology)
    degenerate = first.degenerate
    assert not degenerate.any()
    assert "_normals_and_areas" not in first.__dict__ and "vertex_normals" not in first.__dict__
    normals = first.vertex_normals

    second = PreparedMesh.as_given(vertices, topology)
    np.testing.assert_array_equal(second.vertex_normals, normals)  # asked before the zero-area faces
    assert second._face_pass.cross is None and "cross" not in second.__dict__
    np.testing.assert_array_equal(second.degenerate, degenerate)
    # a sphere's area-weighted normals point outward (the oracle: the radial direction, to the mesh's resolution)
    radial = vertices / np.linalg.norm(vertices, axis=1, keepdims=True)
    assert np.einsum("ij,ij->i", normals, radial).min() > 0.999


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("outlier", [False, True])
def test_robust_mean_edge_length_on_both_backends(outlier, backend):
    """The plain mean without an edge beyond OUTLIER_EDGE_RATIO sampled medians; the mean of the edges within it
    otherwise (one rule for both backends since the shared helper)."""
    if backend == "numba":
        pytest.importorskip("numba")
    from meshcurv import _geometry
    from meshcurv._backend import use_backend
    from meshcurv.topology import MeshTopology

    sphere = shapes.icosphere(12)
    vertices = np.ascontiguousarray(sphere.vertices, dtype=np.float64).copy()
    if outlier:  # a needle: one vertex flung far away
        vertices[sphere.faces[0, 0]] *= 1e5
    edges = MeshTopology.from_faces(sphere.faces, vertices.shape[0]).edges
    lengths = _lengths(vertices, edges)
    with use_backend(backend):
        got = _geometry.robust_mean_edge_length(vertices, edges)
        plain = _geometry.mean_edge_length(vertices, edges)
    kept = lengths[lengths <= _geometry.OUTLIER_EDGE_RATIO * np.median(lengths)]
    assert (kept.size < lengths.size) == outlier
    assert got == pytest.approx(kept.mean(), rel=1e-14)
    if not outlier:
        assert got == plain  # the plain mean of the backend, to the bit
