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
