"""The coarse level of icc's normal fits on dense surfaces (:func:`meshcurv.estimators.icc._coarse_level`).

Oracles: NumPy's own ``unique`` over rows, which the packed keys of the coarse level replace (the same groups in
the same order, so the fits are those of the rows' ``unique`` to the bit), and the definition of the coarse level
(each group one point at the area-weighted centroid of its vertices, linked to the groups a mesh edge joins it to).
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import shapes
from meshcurv.estimators import icc
from meshcurv.topology import MeshTopology


@pytest.mark.parametrize("top", [5, 2**19, 2**21])
def test_packed_row_groups_are_those_of_unique_over_rows(top):
    # 2**21 exceeds the 20 bits of a column: the rows' own unique is taken, with the same answer
    rng = np.random.default_rng(7)
    rows = np.column_stack([rng.integers(0, top, 5000) for _ in range(3)] + [rng.integers(0, 6, 5000)])
    rows[2500:] = rows[:2500]  # repeated rows: groups of several
    expected = np.unique(rows, axis=0, return_inverse=True)[1].ravel()
    np.testing.assert_array_equal(icc._row_groups(rows, (20, 20, 20, 3)), expected)


def test_packed_pairs_are_those_of_unique_over_rows():
    rng = np.random.default_rng(8)
    a, b = rng.integers(0, 300, 4000), rng.integers(0, 300, 4000)
    np.testing.assert_array_equal(icc._unique_pairs(a, b, 300), np.unique(np.column_stack([a, b]), axis=0))
    assert icc._unique_pairs(a[:0], b[:0], 300).shape == (0, 2)


def test_each_group_is_the_area_weighted_centroid_of_its_vertices_linked_along_the_edges():
    pytest.importorskip("skimage")
    mesh = shapes.voxel_sphere(4.0, (0.2, 0.2, 0.2), seed=1)
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    topology = MeshTopology.from_faces(mesh.faces, vertices.shape[0])
    n = vertices.shape[0]
    normals = np.asarray(mesh.normals, dtype=np.float64)
    areas = np.ones(n)
    radius = 2.0 * icc.COARSE_EDGES * icc._median_edge(vertices, topology.neighbour_lists)
    points, _, allowed, (indptr, indices), weights = icc._coarse_level(
        vertices, normals, radius, areas, None, topology.neighbour_lists
    )
    np.testing.assert_array_equal(points[:n], vertices)
    assert not allowed[:n].any() and allowed[n:].all()
    # each vertex links to its own group only; the groups' weights count their vertices (areas of 1)
    own = indices[indptr[:n]]
    np.testing.assert_array_equal(np.diff(indptr)[:n], 1)
    np.testing.assert_array_equal(np.bincount(own - n, minlength=points.shape[0] - n), weights[n:])
    centroid = np.stack([np.bincount(own - n, weights=vertices[:, k]) for k in range(3)], axis=1) / weights[n:, None]
    np.testing.assert_allclose(points[n:], centroid, rtol=0, atol=1e-12 * np.abs(vertices).max())
    # two groups are linked exactly when a mesh edge joins a vertex of one to a vertex of the other
    edges = topology.edges
    joined = {(int(x), int(y)) for x, y in zip(own[edges[:, 0]], own[edges[:, 1]]) if x != y}
    joined |= {(y, x) for x, y in joined}
    heads = np.repeat(np.arange(indptr.size - 1), np.diff(indptr))[indptr[n] :]
    assert {(int(x), int(y)) for x, y in zip(heads, indices[indptr[n] :])} == joined


def _pilot_normals(mesh, monkeypatch=None, **constants):
    """The fitted normals of icc's voxel pilot at its centres (two voxels: its radius in the default), and the
    analytic normals there."""
    from meshcurv._prepared import prepare_mesh
    from meshcurv.radius import scale_centres

    for name, value in constants.items():
        monkeypatch.setattr(icc, name, value)
    prepared = prepare_mesh(mesh.vertices, mesh.faces[:, ::-1], orient="outward", weld=False)
    valid = scale_centres(
        prepared.vertices, prepared.topology, prepared.start(boundary=True)[1], prepared.vertex_normals
    )
    start = np.where(valid[:, None], prepared.vertex_normals, [0.0, 0.0, 1.0])
    centres = icc._pilot_centres(prepared.vertices, prepared.topology, valid)
    radius = icc.NORMAL_RADIUS_RATIO * 2.01 * max(mesh.spacing)
    return icc._pilot_normals(prepared, start, radius, centres), np.asarray(mesh.normals)[centres]


def _angles(normals, exact):
    return np.degrees(np.arccos(np.clip(np.abs(np.einsum("ij,ij->i", normals, exact)), -1.0, 1.0)))


def test_the_pilot_fits_anisotropic_voxels_on_the_coarse_level_as_well_as_on_the_vertices(monkeypatch):
    # a sphere at 0.5 x 0.2 x 0.2 (the confocal spacing of benchmarks/dense_voxel.py): the pilot's normal fits span
    # 11 median edges, over PILOT_COARSE_EDGES; on cubes of a fifth of their radius the fitted normals are as close
    # to the sphere's as the fits over every vertex (median 0.56 against 0.57 degrees, 95th percentile 1.8
    # against 2.2), at a third of the CPU time (benchmarks/dense_voxel.md)
    pytest.importorskip("skimage")
    mesh = shapes.voxel_sphere(4.0, (0.5, 0.2, 0.2), seed=3)
    coarse, exact = _pilot_normals(mesh)
    every, _ = _pilot_normals(mesh, monkeypatch, PILOT_COARSE_EDGES=np.inf)
    assert not np.array_equal(coarse, every)  # the coarse level was taken
    on_coarse, on_every = _angles(coarse, exact), _angles(every, exact)
    assert np.median(on_coarse) < 1.1 * np.median(on_every)
    assert np.percentile(on_coarse, 95) < 1.1 * np.percentile(on_every, 95)


def test_the_pilot_of_isotropic_voxels_fits_over_the_vertices(monkeypatch):
    # isotropic voxels: the pilot's fits span 6 median edges, under PILOT_COARSE_EDGES: fitted over the vertices
    pytest.importorskip("skimage")
    mesh = shapes.voxel_sphere(3.0, (0.25, 0.25, 0.25), seed=4)
    default, _ = _pilot_normals(mesh)
    every, _ = _pilot_normals(mesh, monkeypatch, PILOT_COARSE_EDGES=np.inf)
    np.testing.assert_array_equal(default, every)
