"""The topology's and the zero-area pass's large arrays come from numba's allocator, not numpy's (issue 31, S25).

NumPy advises huge pages for every array of 4 MB or more; where the kernel gives them to advised memory only, the
first write to each 2 MB of a fresh buffer waits for memory to be compacted (``tests/test_unadvised_S24.py``). At
4M vertices the topology build spent 0.7-0.9 s of system time on its numpy arrays, the zero-area faces' pass 0.2 s
(``benchmarks/faults_S24.py``). An array numpy allocated owns its data (or views one that does); one from numba's
allocator is owned by numba's memory object.
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import shapes

pytest.importorskip("numba")


def _numpy_owned(array: np.ndarray) -> bool:
    """Whether numpy allocated the memory of ``array`` (its own, or that of the numpy array it views)."""
    while isinstance(array.base, np.ndarray):
        array = array.base
    return bool(array.flags.owndata)


@pytest.mark.parametrize("dtype", [np.int32, np.int64, np.float64, np.bool_])
@pytest.mark.parametrize("shape", [0, 7, (5, 3), (2, 0), (3, 4, 2)])
def test_unadvised_arrays_have_the_shape_and_type_asked(shape, dtype):
    from meshcurv._kernels.geometry import _unadvised_array

    expected = (shape,) if np.ndim(shape) == 0 else shape
    empty = _unadvised_array(shape, dtype)
    zeros = _unadvised_array(shape, dtype, zero=True)
    for array in (empty, zeros):
        assert array.shape == expected and array.dtype == dtype and array.flags.c_contiguous
        assert array.flags.writeable and array.ctypes.data % np.dtype(dtype).itemsize == 0
        assert not _numpy_owned(array)
    assert not zeros.any()
    empty[...] = 1  # writable over its whole extent
    assert empty.all()


def test_topology_arrays_are_numbas():
    from meshcurv._backend import use_backend
    from meshcurv.topology import MeshTopology

    mesh = shapes.icosphere(8)
    with use_backend("numba"):
        topology = MeshTopology._build(np.ascontiguousarray(mesh.faces, dtype=np.int64), mesh.vertices.shape[0])
    for name in ("edges", "face_edges", "edge_faces", "edge_face_counts", "_edge_forward_counts", "_first_sides"):
        assert not _numpy_owned(getattr(topology, name)), name
    # an icosphere: every edge between two faces run both ways, every vertex referenced by 5 or 6 faces
    assert (topology.edge_face_counts == 2).all() and (topology._edge_forward_counts == 1).all()
    assert topology.n_edges == 3 * topology.n_faces // 2 and (topology._first_sides >= 0).all()
    assert set(np.unique(topology._corner_counts)) == {5, 6}
    with use_backend("numba"):
        indptr, indices = topology.neighbour_lists
    assert not _numpy_owned(indptr) and not _numpy_owned(indices)
    # every vertex's neighbours: the other ends of its edges, each list increasing
    degrees = np.bincount(topology.edges.ravel(), minlength=topology.n_vertices)
    np.testing.assert_array_equal(np.diff(indptr), degrees)
    assert indptr[0] == 0 and indices.size == 2 * topology.n_edges
    for v in (0, 11, 300, topology.n_vertices - 1):
        around = topology.edges[(topology.edges == v).any(axis=1)]
        np.testing.assert_array_equal(indices[indptr[v] : indptr[v + 1]], np.sort(around[around != v]))


def test_zero_area_pass_writes_numbas_memory():
    from meshcurv._backend import use_backend
    from meshcurv._prepared import prepare_mesh

    mesh = shapes.icosphere(8)
    with use_backend("numba"):
        prepared = prepare_mesh(mesh.vertices, mesh.faces, orient="keep", weld=False)
        normals, areas, degenerate = prepared.vertex_normals, prepared.vertex_areas, prepared.degenerate
    assert not any(_numpy_owned(array) for array in (normals, areas, degenerate))
    # a sphere centred on the origin: the vertex normals point outward, the faces have area, and the vertex areas
    # (a third of each face's) add up to the mesh's
    radial = mesh.vertices / np.linalg.norm(mesh.vertices, axis=1, keepdims=True)
    assert (np.einsum("ij,ij->i", normals, radial) > 0.99).all() and not degenerate.any()
    corners = mesh.vertices[mesh.faces]
    total = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1).sum()
    np.testing.assert_allclose(areas.sum(), total, rtol=1e-12)


def _sample_as_written(points, local, size):
    """radius._intrinsic_sample as its docstring defines it, one numpy temporary per operation (its code before
    the buffers of issue 31): the keys, their hash and the classes taken."""
    m = points.shape[0]
    if m <= size:
        return np.ones(m, dtype=bool)
    if not local.mean() > 0:
        local = np.ones(m)
    guess = np.einsum("ij->j", points) / m
    squared = np.zeros(m)
    for axis in range(3):
        offsets = points[:, axis] - guess[axis]
        offsets -= offsets.sum() / m
        squared += offsets * offsets
    spread = squared.mean()
    first = np.rint(np.minimum(local / (local.mean() * 2.0**-10), 2.0**40)).astype(np.int64)
    second = np.rint(np.minimum(squared / (spread * 2.0**-16), 2.0**40)) if spread > 0 else np.zeros(m)
    with np.errstate(over="ignore"):
        keys = first.view(np.uint64) * np.uint64(0x9E3779B97F4A7C15) + second.astype(np.uint64)
        for shift, factor in ((30, 0xBF58476D1CE4E5B9), (27, 0x94D049BB133111EB), (31, 1)):
            keys ^= keys >> np.uint64(shift)
            keys *= np.uint64(factor)
    return keys <= np.partition(keys, size - 1)[size - 1]


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_intrinsic_sample_in_buffers_is_the_sample_as_written(backend):
    from meshcurv._backend import use_backend
    from meshcurv.radius import SAMPLE_DISTANCE_STEP, SAMPLE_LOCAL_STEP, _intrinsic_sample

    assert (SAMPLE_LOCAL_STEP, SAMPLE_DISTANCE_STEP) == (2.0**-10, 2.0**-16)  # the steps written out above
    rng = np.random.default_rng(25)
    for trial in range(24):
        m = int(rng.integers(20, 20000))
        points = rng.normal(size=(m, 3)) * 10.0 ** rng.uniform(-6, 6) + rng.normal(size=3) * 10.0 ** rng.uniform(-3, 8)
        if trial % 6 == 0:
            points[:] = points[0]  # no spread: the local lengths alone
        if trial % 5 == 1:
            points = points[::2]  # not contiguous
            m = points.shape[0]
        local = rng.uniform(0.5, 2, m) * 10.0 ** rng.uniform(-4, 4)
        if trial % 4 == 2:
            local[: m // 3] *= 1e14  # beyond 2^40 steps: capped
        if trial % 7 == 3:
            local[:] = 0.0  # no length: the distances alone
        if trial % 3 == 0:
            local = np.round(local, 1)  # ties: whole classes
        size = int(rng.integers(1, m + 3))
        given = local.copy()
        with use_backend(backend):
            chosen = _intrinsic_sample(points, local, size)
        np.testing.assert_array_equal(chosen, _sample_as_written(points, given, size))
        np.testing.assert_array_equal(local, given)  # not changed
