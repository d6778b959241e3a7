"""The compiled kernels' fresh outputs come from numba's allocator, not numpy's (issue 31, helper S24).

NumPy advises huge pages for every array of 4 MB or more; where the kernel gives them to advised memory only,
the first write to each 2 MB of a fresh buffer waits for memory to be compacted: 0.15-0.29 s of system time per
1M-vertex call for the face measures alone (``benchmarks/faults_S24.py``). The outputs written once by the
kernels are taken from numba's allocator instead (:func:`meshcurv._kernels.geometry._unadvised_empty`), which
gives no advice: an array numpy allocated owns its data, one numba allocated is owned by numba's memory object.
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


def test_allocations_are_numbas_and_as_asked():
    from meshcurv._kernels.geometry import _unadvised_empty, _unadvised_zeros

    empty = _unadvised_empty((5, 9), np.float64)
    zeros = _unadvised_zeros((2, 7, 3))
    assert empty.shape == (5, 9) and empty.dtype == np.float64 and empty.flags.c_contiguous
    assert zeros.shape == (2, 7, 3) and zeros.dtype == np.float64 and not zeros.any()
    assert not _numpy_owned(empty) and not _numpy_owned(zeros)
    assert _numpy_owned(np.empty((5, 9)))  # the check tells numpy's memory from numba's


def test_face_measures_and_curvatures_are_written_to_numbas_memory():
    from meshcurv._kernels import icc

    mesh = shapes.icosphere(6)
    vertices = np.ascontiguousarray(mesh.vertices)
    faces = np.ascontiguousarray(mesh.faces, dtype=np.int64)
    normals = vertices / np.linalg.norm(vertices, axis=1, keepdims=True)
    measures = icc.face_measures(vertices, faces, normals)
    assert not _numpy_owned(measures)
    # every element written: the corrected area of a face of the unit sphere with its exact normals is positive
    assert np.isfinite(measures).all() and (measures[:, 0] > 0).all()
    summed = np.zeros((vertices.shape[0], 9))
    np.add.at(summed, faces.ravel(), np.repeat(measures, 3, axis=0) / 3)
    outputs = icc.curvatures_from_measures(summed, normals)
    assert not any(_numpy_owned(field) for field in outputs)
    k_min, k_max = outputs[:2]
    # a unit sphere: k = 1 at every vertex, to the discretisation of a 6-times subdivided icosahedron
    np.testing.assert_allclose(k_min, 1.0, atol=0.05)
    np.testing.assert_allclose(k_max, 1.0, atol=0.05)
