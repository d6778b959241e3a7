"""Exact folds: two faces lying on each other, their normals opposite (issue 29, class 10).

A closed mesh flattened onto a plane (every vertex's coordinate on one axis set to 0) folds back on
itself along its rim: the two faces of a rim edge coincide, so the sine of their dihedral angle is
an exact zero, of either sign, depending on the order in which a backend multiplies the coordinates'
zeros, and ``atan2(+-0, -1)`` is ``+-pi``. The angle's range is ``(-pi, pi]`` on both backends: an
exact fold reads ``pi`` whatever the signs of its zeros, so that ``normal_cycle`` gives one answer
with and without numba (found by ``benchmarks/fuzz_api.py --seed 232``, cases 192 and 294).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import geometry, shapes
from meshcurv._backend import use_backend
from meshcurv.geometry import face_normals
from meshcurv.topology import MeshTopology

#: Relative agreement of the two backends, of the largest |k| (as in tests/test_backend_parity.py).
RTOL = 1e-6


@pytest.mark.parametrize("zero", [0.0, -0.0])
@pytest.mark.parametrize("mirror", [1.0, -1.0])
def test_an_exact_fold_reads_pi_whatever_the_signs_of_its_zeros(zero, mirror):
    # two triangles on the edge (0, 1) along x, the second folded flat onto the first (its third corner a
    # vertex of its own at the first's place): the dihedral angle is pi, in either mirror image
    vertices = np.array([[0.0, 0, zero], [1, 0, zero], [0.5, 1, zero], [0.5, 1, zero]]) * [1, 1, mirror]
    faces = np.array([[0, 1, 2], [1, 0, 3]])
    top = MeshTopology.from_faces(faces, 4)
    usable = top.interior_edges.copy()
    beta, _, _ = geometry.edge_dihedral_angles(vertices, top, face_normals(vertices, faces), usable)
    shared = np.flatnonzero(usable)
    assert shared.size == 1
    assert beta[shared[0]] == np.pi


def _flattened(mesh, axis: int):
    vertices = np.array(mesh.vertices, dtype=float)
    vertices[:, axis] = 0.0  # +0.0 everywhere: the rim's faces lie exactly on each other
    return vertices, np.asarray(mesh.faces)


FLATTENED = {
    f"{name}, axis {axis}": (mesh, axis)
    for name, mesh in (
        ("icosphere", shapes.icosphere(subdivisions=6)),
        ("uv sphere", shapes.uv_sphere(n_longitude=12, n_latitude=8)),
    )
    for axis in range(3)
}


@pytest.mark.parametrize("method", ["normal_cycle", "normal_cycle_ball"])
@pytest.mark.parametrize("name", sorted(FLATTENED))
def test_a_flattened_closed_mesh_gives_one_answer_on_both_backends(name, method):
    pytest.importorskip("numba")
    vertices, faces = _flattened(*FLATTENED[name])
    results = {}
    for backend in ("numba", "numpy"):
        with use_backend(backend), warnings.catch_warnings():
            warnings.simplefilter("ignore")  # zero-area faces and their vertices, counted in one warning
            results[backend] = meshcurv.principal_curvatures(vertices, faces, method=method)
    compiled, reference = results["numba"], results["numpy"]
    np.testing.assert_array_equal(compiled.valid, reference.valid)
    assert compiled.valid.any()
    valid = compiled.valid
    unit = max(float(np.abs(reference.k_max[valid]).max()), float(np.abs(reference.k_min[valid]).max()))
    assert unit > 0  # the rim's folds are curved: a zero here would compare nothing
    for field in ("k_min", "k_max", "mean", "gaussian"):
        gap = np.abs(getattr(compiled, field)[valid] - getattr(reference, field)[valid]).max()
        assert gap <= RTOL * unit * (unit if field == "gaussian" else 1.0), (field, gap, unit)
